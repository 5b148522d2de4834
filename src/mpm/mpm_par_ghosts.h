/* mpm_par_ghosts: across MPI ranks, the particles of other ranks that a
 * rank's particles read each step: a membrane point's normal reads its
 * neighbours' positions (its triangles' corners, or the points before and
 * after it along a curve), and its neighbours may live on another rank.
 *
 * The kinds say which they are (mpm_kind.ranks_link: the ghosts' one-process
 * indices, from the group's links); each rank asks the ranks whose boxes
 * touch its own for them, and those that hold them send their positions
 * once per step, after the migration (positions change only in the move,
 * so the ghosts are current for the whole of the next step).  The ghosts
 * and the links are made anew only when a linked point moved between
 * ranks; otherwise a step costs one neighbour exchange of 3 doubles per
 * ghost.  Internal to mpm_par. */
#ifndef MPM_PAR_GHOSTS_H
#define MPM_PAR_GHOSTS_H

#include <mpi.h>
#include <stdbool.h>

#include "mpm_model.h"
#include "mpm_state.h"

typedef struct mpm_ghosts mpm_ghosts;

/* The ghosts of local model m (*out NULL when no group's kind links its
 * points), exchanged with the ranks of the graph communicator near
 * (n_near of them, borrowed), and their first positions from state s
 * (collective).  PM_ERR_MEMORY, or PM_ERR_UNSTABLE when a ghost is on no
 * rank next to this one (see mpm_ghosts_update). */
pm_err mpm_ghosts_create(mpm_model *m, const mpm_state *s, MPI_Comm near,
                         int n_near, mpm_ghosts **out);
void mpm_ghosts_destroy(mpm_ghosts *gh);

/* After a migration: the links and ghosts made anew when `relink` (some
 * linked point moved between any two ranks), the sending lists placed anew
 * when this rank's particles changed (`reordered`), then the ghosts'
 * positions from their ranks (collective; every rank passes the same
 * relink).  PM_ERR_MEMORY; PM_ERR_UNSTABLE, naming the point by its
 * one-process index, when a ghost is held by no rank whose box touches
 * this rank's (the links reach farther than a box). */
pm_err mpm_ghosts_update(mpm_ghosts *gh, mpm_model *m, const mpm_state *s,
                         bool relink, bool reordered);

/* The positions of group gi's ghosts (3 each, in the order its kind's
 * ranks_link gave them), or NULL when it has none. */
const double *mpm_ghosts_x(const mpm_ghosts *gh, int gi);
/* Group gi's ghosts now, and their one-process indices (increasing). */
long mpm_ghosts_count(const mpm_ghosts *gh, int gi);
const long *mpm_ghosts_ids(const mpm_ghosts *gh, int gi);
/* Bytes this rank sent of the ghosts' positions and requests so far. */
double mpm_ghosts_bytes(const mpm_ghosts *gh);

#endif
