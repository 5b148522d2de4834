/* mpm_grid_stages: the stages that work on the grid between the transfers
 * (gravity, absorbing faces, damping, the grid update with its conditions,
 * the USF grid velocity) and the stable time step. */
#ifndef MPM_GRID_STAGES_H
#define MPM_GRID_STAGES_H

#include "mpm_stage.h"

struct mpm_model;
struct mpm_state;

/* Nodal velocities from the momenta (null directions zero) with the
 * conditions applied, into the work's vel: the velocity USF and MUSL take
 * the stress from. */
void mpm_grid_velocity(mpm_ctx *ctx);
/* The same after a transfer of mode `mode`, whose region ran the
 * velocities' loop when fused (mpm_grid_nodes_fused). */
void mpm_grid_velocity_after(mpm_ctx *ctx, int mode);

/* Whether a stage of mode `mode` runs (as transfer) or left (as grid
 * stage) the grid stage's node loop in the transfer's region: the
 * MPM_NODES_FUSED bit on one process, and for the grid update (`update`)
 * no folded conditions (their fold comes before its loop). */
bool mpm_grid_nodes_fused(const mpm_ctx *ctx, int mode, bool update);

/* The node loops of the grid update (v and v^L from the nodal sums) and
 * of the grid velocity: this thread's static share of the nodes, no
 * barrier after (inside a parallel region, orphaned). */
void mpm_grid_update_nodes(const mpm_ctx *ctx);
void mpm_grid_velocity_nodes(const mpm_ctx *ctx);

/* Stable step: dt_safety h over the largest of (wave speed + |v|) and the
 * viscous and artificial viscous terms (LS-DYNA form), over all particles;
 * INFINITY when nothing moves and no particle has a wave speed.  cp:
 * scratch of one double per particle. */
double mpm_stable_dt(const struct mpm_model *m, const struct mpm_state *s,
                     double *cp);

/* Stage: the stable step into the state's dt, cut to end at time.end;
 * PM_ERR_UNSTABLE when there is none. */
pm_err mpm_stage_time_step(mpm_ctx *ctx, const mpm_stage *self);

/* Stage: m g on the nodes with mass. */
pm_err mpm_stage_gravity(mpm_ctx *ctx, const mpm_stage *self);
/* Hook of the gravity stage after the grid update: books its work over the
 * step, m g . (v0 + v^L) / 2 dt. */
pm_err mpm_book_gravity(mpm_ctx *ctx, const mpm_stage *self);

/* Stage: viscous tractions on the absorbing faces (implicit in v), their
 * dissipation booked. */
pm_err mpm_stage_absorbing(mpm_ctx *ctx, const mpm_stage *self);

/* Stage: mass-proportional damping, fixed or by dynamic relaxation (the
 * rate from the change of the force on the dofs left free in the last
 * step), its dissipation booked. */
pm_err mpm_stage_damping(mpm_ctx *ctx, const mpm_stage *self);
/* Hook of the damping stage after the grid update (dynamic relaxation with
 * conditions): the dofs the conditions set, into the state for the next
 * step's rate. */
pm_err mpm_remember_fixed(mpm_ctx *ctx, const mpm_stage *self);

/* Stage: v^L = v + dt f / m with null directions, the conditions (their
 * forces folded onto the anchors, their reactions, their work booked
 * here) and the quasi-static residual. */
pm_err mpm_stage_grid_update(mpm_ctx *ctx, const mpm_stage *self);

/* Stage (USF): mpm_grid_velocity. */
pm_err mpm_stage_grid_velocity(mpm_ctx *ctx, const mpm_stage *self);

#endif
