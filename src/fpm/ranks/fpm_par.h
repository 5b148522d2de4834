/* fpm_par: explicit FPM across MPI ranks.  The points are partitioned by
 * PT-Scotch on the support graph (fpm_share.h); each rank steps its share,
 * its own points and the ghosts whose values their force reads, so that
 * its force on its own points is the force one process computes, the same
 * operations in the same order.  A step on a rank is the step of one
 * process on its share, with:
 *  - one exchange: once the rank's own displacements are updated and the
 *    supports moved, the ghosts' displacements come from their owners
 *    (pm_halo, whose leaves are the ghosts and whose roots their owners'
 *    points); with fpm.volumetric: averaged a second, inside the
 *    force, of one double a ghost: the averaged pressure U'(Jbar) of the
 *    owners' points (fpm_volumetric.h);
 *  - sums over the own points (energies, the residual, the supports' work,
 *    dynamic relaxation's Rayleigh quotient) summed over the ranks, and
 *    the smallest J; every rank then holds the same figures, damping and
 *    energy accounts;
 *  - a failure (a condition's value not finite, J <= 0, a stress not
 *    finite) agreed by every rank: the one one process meets first wins,
 *    and every rank stops with its message, which names the point by its
 *    index on one process.
 * Only rank 0 meshes the domain and builds its cells, and no rank builds
 * the whole model but where it keeps it (pm_view.h); rank 0
 * keeps the whole model and gathers the state into it where the run
 * writes (another pm_halo, its own points to rank 0's whole arrays):
 * frames, history and checkpoints are those of one process.  The
 * functions below take a share (m->xc set by fpm_par_create); only
 * fpm_par_get_costs also takes a model on one process (all zero). */
#ifndef FPM_PAR_H
#define FPM_PAR_H

#include <stdio.h>

#include "fpm_model.h"
#include "fpm_share.h"

/* This rank's share of the model of scene sc (collective; every rank
 * returns the same error).  Rank 0 alone holds the whole mesh *mesh and
 * its cells *cells (NULL on the others): it partitions the points
 * (fpm_partition), cuts every other rank's part of the cells and sends it
 * (fpm_region.h), one at a time; every rank then makes its share and the
 * exchanges are set up: the share's exchange (fpm_exchange.h: the ghosts'
 * displacements, the sums and minima, the failures agreed) is this rank's.
 * whole: the whole model where this rank holds it (rank 0 only; the share
 * is cut from it), else NULL: the share is built on the rank's part, the
 * same model bit for bit.  Every rank without the whole model returns
 * with *mesh the names of the whole mesh's surfaces (fpm_mesh_names) and
 * *cells NULL: rank 0 lets its whole mesh and cells go once the parts are
 * sent.  *local owns its arrays and the exchanges (fpm_model_destroy). */
pm_err fpm_par_create(const pm_scene *sc, gm_mesh **mesh, gm_dual **cells,
                      const fpm_model *whole, fpm_model **local);
/* A share's state from the whole run's, which every rank holds (a
 * checkpoint read by every rank): displacements and velocities of every
 * point it holds, and what the time loop carries. */
void fpm_par_scatter(const fpm_model *m, const fpm_state *whole, fpm_state *st);

/* Gather the state of every rank's share into the whole run's state on
 * rank 0 (whole; NULL on the other ranks), in one process's order: u, v,
 * f, F - I, P, W, J and what the time loop carries (collective). */
pm_err fpm_par_gather(const fpm_model *m, const fpm_state *st,
                      fpm_state *whole);

/* Three values per own point of every rank's share (local) into rank 0's
 * array over the whole model's points (whole; NULL on the other ranks)
 * (collective). */
pm_err fpm_par_gather_points(const fpm_model *m, const double *local,
                             double *whole);

/* The partition (every point's rank) and every rank's counts of a
 * share: on rank 0 (NULL on the others). */
const int *fpm_par_owner(const fpm_model *m);
const fpm_share_counts *fpm_par_counts(const fpm_model *m);

/* What the exchanges cost this rank so far: bytes it received of ghost
 * values (displacements, and with fpm.volumetric: averaged the pressures
 * U'(Jbar)), the exchanges of displacements (one a step), and the seconds
 * of the exchanges and the gathers. */
typedef struct {
  double ghost_bytes, exchange_seconds, gather_seconds;
  long exchanges;
} fpm_par_costs;
void fpm_par_get_costs(const fpm_model *m, fpm_par_costs *c);

#endif
