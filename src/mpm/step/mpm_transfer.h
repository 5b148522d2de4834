/* mpm_transfer: particle to grid and back (section 7 of
 * papers/mpm-membrane-normals-without-connectivity.txt): mass, momentum and
 * internal force to the nodes, velocities and increments back, the MUSL
 * remap of momentum, and the move of the particles. */
#ifndef MPM_TRANSFER_H
#define MPM_TRANSFER_H

#include "mpm_stage.h"

/* What a particle-to-grid transfer moves (or-ed; a stage's mode). */
enum { MPM_P2G_MASS = 1, MPM_P2G_MOM = 2, MPM_P2G_FORCE = 4 };

/* A stage's mode bit: on one process (no nodal sums across ranks between
 * them), the grid stage that follows a transfer has its loop over the
 * nodes run by the transfer's parallel region, each thread right after its
 * share of the reduction (mpm_grid_nodes_fused).  Set on the transfer and
 * on the grid stage by the pipeline. */
enum { MPM_NODES_FUSED = 64 };

/* Particle to grid of what `mode` says into the nodal arrays: mass,
 * momentum, and the internal force -V sigma grad S (with the impedances
 * sum S m rho c when the grid has them).  Per-thread accumulators, reduced
 * in thread order: no atomics.  Across ranks, then summed over the ranks
 * (mpm_xc_sum_nodes; a PETSc failure is PM_ERR_LINALG). */
pm_err mpm_p2g(mpm_ctx *ctx, int mode);

/* Stages: p2g of self->mode; g2p (FLIP/PIC velocities and the position
 * increments); MUSL remap (momentum from the updated particles, then the
 * grid velocity with its conditions); move (x += dx, failing when a
 * particle leaves the grid's reach). */
pm_err mpm_stage_p2g(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_g2p(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_remap(mpm_ctx *ctx, const mpm_stage *self);
pm_err mpm_stage_move(mpm_ctx *ctx, const mpm_stage *self);

#endif
