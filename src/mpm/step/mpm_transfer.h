/* mpm_transfer: particle to grid and back (section 7 of
 * papers/mpm-membrane-normals-without-connectivity.txt): mass, momentum and
 * internal force to the nodes, velocities and increments back, the MUSL
 * remap of momentum, and the move of the particles. */
#ifndef MPM_TRANSFER_H
#define MPM_TRANSFER_H

#include "mpm_stage.h"
#include "mpm_state.h"

/* What a particle-to-grid transfer moves (or-ed; a stage's mode). */
enum { MPM_P2G_MASS = 1, MPM_P2G_MOM = 2, MPM_P2G_FORCE = 4 };

/* A stage's mode bit: on one process (no nodal sums across ranks between
 * them), the grid stage that follows a transfer has its loop over the
 * nodes run by the transfer's parallel region, each thread right after its
 * share of the reduction (mpm_grid_nodes_fused).  Set on the transfer and
 * on the grid stage by the pipeline. */
enum { MPM_NODES_FUSED = 64 };

/* A stage's mode bit: the constitutive stage of the model's only group,
 * the last before the move, moves each particle once it has read its
 * position (mpm_move_particle), and the move stage has nothing left to
 * do: one pass over the particles fewer a step.  Set on both stages by the
 * pipeline when the group's kind can (mpm_kind.moves). */
enum { MPM_MOVE_FUSED = 128 };

/* x_p += dx_p, failing (mpm_fail) when the particle leaves the grid's
 * reach: the move stage's work for one particle. */
static inline void mpm_move_particle(const mpm_grid *g, mpm_work *w,
                                     double *restrict x,
                                     const double *restrict dx, long p) {
  double *xp = x + 3 * p;
  bool out = false;
  for (int c = 0; c < 3; c++) {
    xp[c] += dx[3 * p + c];
    out |= c < g->dim && !(xp[c] >= g->lo[c] && xp[c] < g->hi[c]);
  }
  if (__builtin_expect(out, 0))
    for (int c = 0; c < g->dim; c++)
      if (!(xp[c] >= g->lo[c] && xp[c] < g->hi[c]))
        mpm_fail(w, p,
                 "left the grid (%g is outside the grid's reach along this "
                 "axis, which ends at %g): enlarge domain.box",
                 xp[c], xp[c] < g->lo[c] ? g->lo[c] : g->hi[c]);
}

/* Particle to grid of what `mode` says into the nodal arrays: mass,
 * momentum, and the internal force -V sigma grad S (with the impedances
 * sum S m rho c when the grid has them).  Per-thread accumulators, reduced
 * in thread order: no atomics.  Across ranks, then summed over the ranks
 * (mpm_xc_sum_nodes; a PETSc failure is PM_ERR_LINALG). */
pm_err mpm_p2g(mpm_ctx *ctx, int mode);

/* Stages: p2g of self->mode; g2p (FLIP/PIC velocities and the position
 * increments); MUSL remap (momentum from the updated particles, then the
 * grid velocity with its conditions); move (x += dx, failing when a
 * particle leaves the grid's reach; nothing with MPM_MOVE_FUSED). */
pm_err mpm_stage_p2g(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_g2p(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_remap(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_move(mpm_ctx *ctx, const mpm_stage *self);

#endif
