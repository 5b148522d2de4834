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
 * ghost.
 *
 * Points whose kind reads the points of the cells around their own (a
 * membrane's normals fitted per cell, from blocks of up to 8 cells a side)
 * have nearby points instead: every step each rank sends the ranks whose
 * boxes lie within that reach the points of those groups it holds within
 * the reach of their boxes (an exchange of counts and one of records).
 * Internal to mpm_par. */
#ifndef MPM_PAR_GHOSTS_H
#define MPM_PAR_GHOSTS_H

#include <mpi.h>
#include <stdbool.h>

#include "mpm_model.h"
#include "mpm_par.h"
#include "mpm_state.h"

typedef struct mpm_ghosts mpm_ghosts;

/* The ghosts of local model m of decomposition d (*out NULL when no
 * group's kind links its points or reads those around them; the groups'
 * ranges of one-process indices gbegin, gend), exchanged with the ranks of
 * the graph communicator near (n_near of them, borrowed), and their first
 * positions from state s (collective).  PM_ERR_MEMORY, or PM_ERR_UNSTABLE
 * when a ghost is on no rank next to this one (see mpm_ghosts_update). */
pm_err mpm_ghosts_create(mpm_model *m, const mpm_state *s, const mpm_decomp *d,
                         const long *gbegin, const long *gend, MPI_Comm near,
                         int n_near, mpm_ghosts **out);
void mpm_ghosts_destroy(mpm_ghosts *gh);

/* After a migration: the links and ghosts made anew when `relink` (some
 * linked point moved between any two ranks), the sending lists placed anew
 * when this rank's particles changed (`reordered`), then the ghosts'
 * positions from their ranks, and the nearby points (those of other ranks
 * within a group's reach of this rank's box, mpm_kind.ranks_reach) from
 * theirs (collective; every rank passes the same relink).  PM_ERR_MEMORY;
 * PM_ERR_UNSTABLE, naming the point by its one-process index, when a ghost is
 * held by no rank whose box touches this rank's (the links reach farther than a
 * box). */
pm_err mpm_ghosts_update(mpm_ghosts *gh, mpm_model *m, const mpm_state *s,
                         bool relink, bool reordered);

/* The positions of group gi's ghosts (3 each, in the order its kind's
 * ranks_link gave them), or NULL when it has none. */
const double *mpm_ghosts_x(const mpm_ghosts *gh, int gi);
/* Group gi's ghosts now, and their one-process indices (increasing). */
long mpm_ghosts_count(const mpm_ghosts *gh, int gi);
const long *mpm_ghosts_ids(const mpm_ghosts *gh, int gi);
/* Group gi's nearby points of other ranks: positions (3 each), their
 * one-process indices (increasing) in *ids, *n of them (NULL and 0 for a
 * group without a reach). */
const double *mpm_ghosts_nearby(const mpm_ghosts *gh, int gi, long *n,
                                const long **ids);
/* Bytes this rank sent of the ghosts' positions and requests so far. */
double mpm_ghosts_bytes(const mpm_ghosts *gh);

#endif
