/* fpm_share: the partition of an FPM model's points among ranks, by a
 * graph partitioner on the supports, and a rank's share of the model: its
 * own points and the ghost points whose values their force reads, with
 * what every pass reads of them (fpm_model_subset).  Nothing
 * here communicates: every rank makes its own share from the whole model
 * it holds at setup, and pointmech plan --ranks N makes every rank's on one
 * process (fpm_par.h runs the shares across ranks).
 *
 * The ghosts are those that make a rank's force on its own points the
 * force one process computes, the same operations in the same order, with
 * the displacements as the only values taken from other ranks:
 *  - the gather of f_k reads T_i and r_i of k's support (and, with the
 *    quadratic jump, Zq_i of every fit that holds k): the flux is computed
 *    on those points (flux ghosts);
 *  - the flux of a point reads u, F, P (and the fit theta) of its
 *    support: the stress and the fit are computed on those (stress ghosts);
 *  - the stress reads u over the support, the fit over the fit's points
 *    (the support, or two rings): displacements only (displacement
 *    ghosts).
 * With the linear jump that is three rings of support around a rank's
 * points, with the quadratic up to five; the interfaces, boundary facets
 * and conditions of every point held come with it from the whole model,
 * computed once at setup.  fpm.volumetric: averaged needs no more rings:
 * the pressure of a stress ghost reads U'(Jbar) over its support, which
 * the force takes from the owners in a second exchange of one double a
 * ghost (fpm_volumetric.h), in place of two more rings of J and Jbar. */
#ifndef FPM_SHARE_H
#define FPM_SHARE_H

#include <stdio.h>

#include "fpm_model.h"

/* Partition the points of the cells d (of a whole model) among `parts`
 * ranks into owner (d->n_points ranks): Scotch (fpm_scotch.h) on the
 * support graph, each point weighted by its support's
 * entries (its work in the passes; the graph alone, so that a rank makes
 * the partition before any operator, fpm_region.h).
 * On one process and one thread of the partitioner, so that the partition
 * is the same wherever it is made (plan --ranks N on one process predicts
 * the run of N ranks, and a resumed run has the partition of the run it
 * continues).  parts 1: every point on rank 0, without Scotch.
 * Scotch's failures as fpm_scotch_part's. */
pm_err fpm_partition(const gm_dual *d, int parts, int *owner);

/* Rank r's share of model m (held whole) under partition owner: its
 * points are r's own, in one-process order, then its flux, stress and
 * displacement ghosts, each in one-process order (fpm_points), and its
 * model is fpm_model_subset's of them.  *out owns its arrays; m is left as
 * it is. */
pm_err fpm_share_create(const fpm_model *m, const int *owner, int r,
                        fpm_model **out);
/* The same share, m taken (fpm_model_subset_take: its records moved into
 * the share in place, its other arrays let go as the share copies them;
 * the caller destroys m whatever the outcome). */
pm_err fpm_share_take(fpm_model *m, const int *owner, int r, fpm_model **out);

/* What a share holds, for the plan and the summary. */
typedef struct {
  long own, flux_ghosts, stress_ghosts, u_ghosts;
  double bytes; /* its model and state */
} fpm_share_counts;
void fpm_share_count(const fpm_model *share, fpm_share_counts *c);

/* Support pairs (interfaces) whose points are on different ranks. */
long fpm_partition_edge_cut(const fpm_model *m, const int *owner);

/* Print the shares of `parts` ranks (counts[parts]) of model m under
 * partition owner: points and ghosts per rank, memory, the displacements
 * a rank receives per step, the balance and the edge cut. */
void fpm_share_print(const fpm_model *m, const int *owner, int parts,
                     const fpm_share_counts *counts, FILE *out);

/* The shares of `parts` ranks made on one process (plan --ranks N): the
 * partition and what each rank would hold, printed as fpm_share_print. */
pm_err fpm_share_predict(const fpm_model *m, int parts, FILE *out);

#endif
