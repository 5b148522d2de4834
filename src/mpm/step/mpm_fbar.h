/* mpm_fbar: F-bar against volumetric locking.  The volume ratio J of a
 * solid's particles is averaged over each grid cell (or over each node's
 * patch), and the stress is computed from F scaled to that average, so a
 * nearly incompressible solid has one volume constraint per cell instead of
 * one per particle.  The averages are here, apart from any solver: the
 * explicit solid stage (mpm_solid.c) and an implicit solver call the same
 * functions with their own particles' cells, J and reference volumes.
 *
 * What is averaged is q = J - 1 (the average is linear, so the mean of
 * J - 1 is Jbar - 1), which keeps its relative accuracy as J -> 1, as the
 * material models do.  The sums run over one thread's particles into that
 * thread's partial sums, which are added in thread order: no atomics, and
 * a result that repeats bit for bit on the same number of threads. */
#ifndef MPM_FBAR_H
#define MPM_FBAR_H

#include <math.h>
#include <stddef.h>

#include "mpm_grid.h"
#include "mpm_scene.h"
#include "pm_error.h"

/* Workspace of the averages, created once for a run and reused by every
 * step.  The slots are the grid's nodes: a cell is named by its lowest
 * node (mpm_fbar_cell), a patch by its node. */
typedef struct {
  int threads;     /* partial sums kept: the parallel regions run as many */
  long n_slots;    /* cells or nodes: the grid's n_nodes */
  double *partial; /* [threads][n_slots][2]: sum V0 q, sum V0 */
  double *mean;    /* n_slots: the average of q over each slot */
  /* Per particle (indexed like the caller's particles, n of them), for the
   * caller's use between its passes: */
  long n;
  double *jm1;  /* J - 1 of the particle */
  long *cell;   /* cell of the particle (mode cell) */
  double *qbar; /* the patch average at the particle (mode patch) */
} mpm_fbar_work;

/* Create the workspace of `mode` (not MPM_FBAR_NONE) for n particles on a
 * grid of n_slots nodes with `threads` partial sums (zeroed): the per-
 * particle arrays the mode needs (jm1 always; cell or qbar).  PM_ERR_MEMORY
 * on failure (what was allocated stays for mpm_fbar_work_destroy). */
pm_err mpm_fbar_work_create(mpm_fbar_work *fw, mpm_fbar_mode mode, long n,
                            long n_slots, int threads);
/* Release the workspace (and zero fw). */
void mpm_fbar_work_destroy(mpm_fbar_work *fw);
/* Bytes of its arrays. */
size_t mpm_fbar_work_bytes(const mpm_fbar_work *fw);

/* The cell of a particle at x (inside the grid's reach): the index of the
 * cell's lowest node.  The cells are the grid's, whatever its shape. */
static inline long mpm_fbar_cell(const mpm_grid *g, const double x[3]) {
  long c = 0;
  for (int k = 0; k < g->dim; k++)
    c += ((long)floor((x[k] - g->origin[k]) * g->inv_h) - g->offset[k]) *
         g->stride[k];
  return c;
}

/* Cell averages of q weighted by the reference volumes:
 *   mean[c] = sum_{p in c} V0_p q_p / sum_{p in c} V0_p
 * over the n particles p with cell[p] (slots of fw), q[p] and vol0[p]; 0 in
 * a cell without particles.  With q = J - 1 this is Jbar - 1 of the cell:
 * the current volume of its particles over their reference volume, less
 * one.  mean holds fw->n_slots values (fw->mean may be passed).  Opens its
 * own parallel region (fw->threads threads). */
void mpm_fbar_cell_average(mpm_fbar_work *fw, long n, const long *cell,
                           const double *q, const double *vol0, double *mean);

/* Patch averages at the particles: q carried to the nodes with the shape
 * weights w_Ip of grid g and the reference volumes,
 *   q_I = sum_p w_Ip V0_p q_p / sum_p w_Ip V0_p,
 * then back, qbar[p] = sum_I w_Ip q_I, for the n particles at x (3 per
 * particle).  fw->n_slots must be g->n_nodes; fw->mean receives q_I.
 * Opens its own parallel region (fw->threads threads). */
void mpm_fbar_patch_average(mpm_fbar_work *fw, const mpm_grid *g, long n,
                            const double *x, const double *q,
                            const double *vol0, double *qbar);

/* F-bar: Fbar = (Jbar / J)^(1/d) F on the first d rows and columns (d =
 * dim: in plane strain the out-of-plane stretch stays 1), so that
 * det Fbar = Jbar, from J - 1 (jm1) and Jbar - 1 (jbar_m1).  The factor is
 * formed from log1p and expm1, so that Fbar - I keeps the accuracy of
 * F - I as both J -> 1.  Returns the factor less one. */
static inline double mpm_fbar_apply(int dim, double jm1, double jbar_m1,
                                    const double F[9], double Fbar[9]) {
  const double am1 = expm1((log1p(jbar_m1) - log1p(jm1)) / dim);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Fbar[3 * i + j] =
          F[3 * i + j] + (i < dim && j < dim ? am1 * F[3 * i + j] : 0.0);
  return am1;
}

#endif
