/* mpm_grid_stages: forces on the nodes, the grid update and the stable
 * step. */
#include "mpm_grid_stages.h"

#include <math.h>
#include <string.h>

#include "mpm_conditions.h"
#include "mpm_contact.h"
#include "mpm_grip.h"
#include "mpm_kind.h"
#include "mpm_state.h"
#include "mpm_transfer.h"
#include "pm_omp.h"
#include "mpm_exchange.h"

/* ---- stable step -------------------------------------------------------- */

double mpm_stable_dt(const mpm_model *m, const mpm_state *s, double *cp) {
  const double h = m->grid.h, div = s->max_div_prev;
  const double *restrict v = s->v, *restrict vol = s->vol,
                         *restrict mass = m->mass;
  double worst = 0; /* largest effective speed */
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *gr = &m->group[gi];
    gr->kind->wave_speeds(m, s, gr, cp, NULL);
    /* The viscous term's dynamic viscosity, over the particle's density. */
    const double mu_v = gr->viscosity, c0 = gr->c0, c1 = gr->c1;
    const long begin = gr->begin, end = gr->end;
    double w = 0;
    PM_OMP(parallel for schedule(static) default(none)
           shared(begin, end, v, vol, mass, cp, mu_v, c0, c1, h, div)
           reduction(max : w))
    for (long p = begin; p < end; p++) {
      const double *vp = v + 3 * p;
      double nu = mu_v * vol[p] / mass[p];
      double Q = c1 * cp[p] + c0 * h * div + 2.0 * nu / h;
      double speed = Q + sqrt(Q * Q + cp[p] * cp[p]) +
                     sqrt(vp[0] * vp[0] + vp[1] * vp[1] + vp[2] * vp[2]);
      if (speed > w) w = speed; /* fmax's value, not its libm call */
    }
    worst = fmax(worst, w);
  }
  mpm_xc_max(m, &worst, 1);
  return worst > 0 ? m->opt.dt_safety * h / worst : INFINITY;
}

pm_err mpm_stage_time_step(mpm_ctx *ctx, const mpm_stage *self) {
  mpm_state *s = ctx->state;
  s->dt_stable = mpm_stable_dt(ctx->model, s, ctx->work->cp);
  if (!isfinite(s->dt_stable)) {
    mpm_fail(ctx->work, 0,
             "no stable step: no particle has a wave speed or a velocity "
             "(%g; %g)",
             s->dt_stable, s->t);
    return mpm_stage_status(ctx, self);
  }
  s->dt = s->dt_stable;
  double left = ctx->model->opt.t_end - s->t;
  if (left > 0 && s->dt > left) s->dt = left;
  return PM_SUCCESS;
}

/* ---- forces on the nodes ------------------------------------------------ */

pm_err mpm_stage_gravity(mpm_ctx *ctx, const mpm_stage *self) {
  (void)self;
  const long nn = ctx->model->grid.n_nodes;
  const double *gv = ctx->model->opt.gravity;
  const double *restrict mass = ctx->work->nodes.mass;
  double *restrict force = ctx->work->nodes.force;
  PM_OMP(parallel for schedule(static) default(none)
         shared(nn, gv, mass, force))
  for (long i = 0; i < nn; i++) {
    double m = mass[i];
    if (m <= 0) continue;
    for (int c = 0; c < 3; c++) force[3 * i + c] += m * gv[c];
  }
  return PM_SUCCESS;
}

/* The work of gravity over the step, with the mean velocity. */
pm_err mpm_book_gravity(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_nodes *nd = &ctx->work->nodes;
  const long nn = ctx->model->grid.n_nodes;
  const double *gv = ctx->model->opt.gravity;
  const double *restrict mass = nd->mass, *restrict vel0 = nd->vel0,
                         *restrict vel_new = nd->vel_new;
  double work = 0;
  PM_OMP(parallel for schedule(static) default(none)
         shared(nd, nn, gv, mass, vel0, vel_new) reduction(+ : work))
  for (long i = 0; i < nn; i++) {
    double m = mass[i];
    if (m <= 0 || !mpm_node_owned(nd, i)) continue;
    for (int k = 0; k < 3; k++)
      work += m * gv[k] * 0.5 * (vel0[3 * i + k] + vel_new[3 * i + k]);
  }
  mpm_book_work(ctx, self, work * ctx->state->dt);
  return PM_SUCCESS;
}

/* Viscous boundary: the traction t = -rho (c_p v_n n + c_s v_t) on the
 * face, with rho c the mass-weighted mean of the particles' impedances at
 * the node, spread as f_I = N_I(face) t A: the face node and (quadratic)
 * the node inside it; the light node beyond is left out. */
pm_err mpm_stage_absorbing(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  const mpm_grid *g = &m->grid;
  const mpm_nodes *nd = &ctx->work->nodes;
  const double dt = ctx->state->dt;
  const int dim = g->dim;
  double area = g->node_volume * g->inv_h, lost = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->absorbing) continue;
    const int a = bc->axis;
    const bool quad = g->shape == MPM_BASIS_QUADRATIC;
    const double share[2] = {quad ? 0.75 : 1.0, quad ? 0.125 : 0.0};
    PM_OMP(parallel for schedule(static) default(none)
           shared(bc, g, nd, a, share, dt, dim, area) reduction(+ : lost))
    for (long k = 0; k < bc->n_cols; k++)
      for (int l = 0; l < 2; l++) {
        if (share[l] == 0) continue;
        long node = bc->col[k] - (long)bc->outward * l * g->stride[a];
        double mn = nd->mass[node];
        if (mn <= 0) continue;
        double zp = share[l] * nd->impedance[2 * node] / mn;
        double zs = share[l] * nd->impedance[2 * node + 1] / mn;
        const double *p = nd->mom + 3 * node;
        for (int c = 0; c < dim; c++) {
          double v = p[c] / mn, z = c == a ? zp : zs;
          /* Implicit in v so that a light node cannot overshoot. */
          double keep = 1.0 / (1.0 + dt * z * area / mn);
          double f = -(1.0 - keep) * (mn * v / dt + nd->force[3 * node + c]);
          nd->force[3 * node + c] += f;
          if (mpm_node_owned(nd, node)) lost -= f * v * dt;
        }
      }
  }
  mpm_book_dissipated(ctx, self, lost);
  return PM_SUCCESS;
}

/* Mass-proportional damping (quasi-static): f -= c m v. */
pm_err mpm_stage_damping(mpm_ctx *ctx, const mpm_stage *self) {
  mpm_state *s = ctx->state;
  const mpm_nodes *nd = &ctx->work->nodes;
  const long nn = ctx->model->grid.n_nodes;
  const double dt = s->dt;
  const double *restrict mass = nd->mass, *restrict mom = nd->mom;
  double *restrict force = nd->force;
  if (s->force_prev) {
    /* Dynamic relaxation: c = 2 sqrt(v.K v / v.M v), with K v estimated by
     * the change of the internal force over the step.  Free dofs only
     * (those the conditions set in the previous step are left out: their
     * forces change by what the conditions impose). */
    double *restrict prev = s->force_prev;
    const unsigned char *restrict fixed = s->fixed;
    double sums[2] = {0, 0}, num = 0, den = 0;
    PM_OMP(parallel for schedule(static) default(none)
           shared(nd, nn, mass, mom, force, prev, fixed) reduction(+ : num, den))
    for (long i = 0; i < nn; i++) {
      double m = mass[i];
      if (m <= 0) continue;
      const bool own = mpm_node_owned(nd, i);
      for (int c = 0; c < 3; c++) {
        double v = mom[3 * i + c] / m;
        if (own && (!fixed || !fixed[3 * i + c])) {
          num += v * (prev[3 * i + c] - force[3 * i + c]);
          den += m * v * v;
        }
        prev[3 * i + c] = force[3 * i + c];
      }
    }
    sums[0] = num;
    sums[1] = den;
    mpm_xc_sum(ctx->model, sums, 2);
    num = sums[0];
    den = sums[1];
    if (den > 0 && s->step > 0) {
      double lambda = num / (dt * den);
      double c = lambda > 0 ? 2.0 * sqrt(lambda) : 0.0;
      /* Keep the rate well within what the step resolves. */
      double cmax = 0.2 / dt;
      s->damping = fmin(c, cmax);
    }
  }
  const double c = s->damping;
  double lost = 0;
  PM_OMP(parallel for schedule(static) default(none)
         shared(nd, nn, mass, mom, force, c, dt) reduction(+ : lost))
  for (long i = 0; i < nn; i++) {
    double m = mass[i];
    if (m <= 0) continue;
    const bool own = mpm_node_owned(nd, i);
    for (int k = 0; k < 3; k++) {
      double v = mom[3 * i + k] / m;
      force[3 * i + k] -= c * m * v;
      if (own) lost += c * m * v * v * dt;
    }
  }
  mpm_book_dissipated(ctx, self, lost);
  return PM_SUCCESS;
}

/* Dynamic relaxation: which dofs the conditions set in this step, for the
 * next step's rate. */
pm_err mpm_remember_fixed(mpm_ctx *ctx, const mpm_stage *self) {
  (void)self;
  unsigned char *fixed = ctx->state->fixed;
  const short *owner = ctx->work->cond.owner;
  if (!fixed) return PM_SUCCESS;
  const long n3 = 3 * ctx->model->grid.n_nodes;
  for (long i = 0; i < n3; i++) fixed[i] = owner[i] != 0;
  return PM_SUCCESS;
}

/* ---- grid update -------------------------------------------------------- */

/* Quasi-static residual: the out-of-balance force (without the damping) on
 * the free dofs, relative to the reactions (or, with none, to the forces
 * on all dofs). */
static double residual(const mpm_ctx *ctx) {
  const mpm_model *m = ctx->model;
  const mpm_nodes *nd = &ctx->work->nodes;
  const mpm_cond_work *cw = &ctx->work->cond;
  const unsigned nul = m->opt.null_velocity;
  const long nn = m->grid.n_nodes;
  const double c = ctx->state->damping;
  const double *fold = cw->fold;
  const short *owner = cw->owner;
  double r2 = 0, f2 = 0;
  PM_OMP(parallel for schedule(static) default(none)
         shared(nd, nul, nn, c, fold, owner) reduction(+ : r2, f2))
  for (long i = 0; i < nn; i++) {
    double m = nd->mass[i];
    if (m <= 0 || !mpm_node_owned(nd, i)) continue;
    for (int k = 0; k < 3; k++) {
      if (nul >> k & 1u) continue;
      double f = nd->force[3 * i + k] + c * m * nd->vel0[3 * i + k] +
                 (fold ? fold[3 * i + k] : 0.0);
      f2 += f * f;
      if (!owner || !owner[3 * i + k]) r2 += f * f;
    }
  }
  if (mpm_xc_shared(m)) {
    double sums[2] = {r2, f2};
    mpm_xc_sum(m, sums, 2);
    r2 = sums[0];
    f2 = sums[1];
  }
  double scale = 0;
  for (int b = 0; b < m->n_bcs; b++)
    for (int k = 0; k < 3; k++)
      scale += cw->reaction[3 * b + k] * cw->reaction[3 * b + k];
  if (!(scale > 0)) scale = f2;
  return scale > 0 ? sqrt(r2 / scale) : 0.0;
}

/* Nodal velocities before and after the Lagrangian update, null
 * directions, boundary conditions, reactions and the residual. */
bool mpm_grid_nodes_fused(const mpm_ctx *ctx, int mode, bool update) {
  return (mode & MPM_NODES_FUSED) && !mpm_xc_shared(ctx->model) &&
         !(update && ctx->work->cond.fold);
}

void mpm_grid_update_nodes(const mpm_ctx *ctx) {
  const mpm_model *m = ctx->model;
  mpm_nodes *nd = &ctx->work->nodes;
  const unsigned nul = m->opt.null_velocity;
  const long nn = m->grid.n_nodes;
  const double dt = ctx->state->dt;
  const double *fold = ctx->work->cond.fold;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < nn; i++) {
    double mi = nd->mass[i];
    for (int k = 0; k < 3; k++) {
      double v0 = 0, v1 = 0;
      if (mi > 0 && !(nul >> k & 1u)) {
        v0 = nd->mom[3 * i + k] / mi;
        double f = nd->force[3 * i + k] + (fold ? fold[3 * i + k] : 0.0);
        v1 = v0 + dt * f / mi;
      }
      nd->vel0[3 * i + k] = v0;
      nd->vel_new[3 * i + k] = v1;
    }
  }
}

pm_err mpm_stage_grid_update(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_nodes *nd = &ctx->work->nodes;
  if (ctx->work->cond.fold) mpm_conditions_fold(ctx);
  if (!mpm_grid_nodes_fused(ctx, self->mode, true)) {
    PM_OMP(parallel default(none) shared(ctx))
    mpm_grid_update_nodes(ctx);
  }
  double work = mpm_conditions_apply(ctx, nd->vel_new, true);
  work += mpm_grips_apply(ctx, nd->vel_new, true);
  if (m->n_moving > 0) work += mpm_motion_apply(ctx, nd->vel_new, true);
  work += mpm_contacts_apply(ctx, nd->vel_new, true);
  if (m->n_bcs > 0 || m->n_moving > 0) mpm_book_work(ctx, self, work);
  if (m->opt.qs != PM_QS_NONE) ctx->work->residual = residual(ctx);
  PM_CALL(mpm_stage_status(ctx, self));
  return mpm_conditions_status(ctx);
}

void mpm_grid_velocity_nodes(const mpm_ctx *ctx) {
  const mpm_nodes *nd = &ctx->work->nodes;
  const unsigned nul = ctx->model->opt.null_velocity;
  const long nn = ctx->model->grid.n_nodes;
  const double *restrict mass = nd->mass, *restrict mom = nd->mom;
  double *restrict vel = nd->vel;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < nn; i++) {
    double m = mass[i];
    for (int k = 0; k < 3; k++)
      vel[3 * i + k] = (m > 0 && !(nul >> k & 1u)) ? mom[3 * i + k] / m : 0.0;
  }
}

/* The conditions on the velocities of mpm_grid_velocity_nodes. */
static void grid_velocity_conditions(mpm_ctx *ctx) {
  mpm_nodes *nd = &ctx->work->nodes;
  mpm_conditions_apply(ctx, nd->vel, false);
  mpm_grips_apply(ctx, nd->vel, false);
  if (ctx->model->n_moving > 0) mpm_motion_apply(ctx, nd->vel, false);
  mpm_contacts_apply(ctx, nd->vel, false);
}

void mpm_grid_velocity(mpm_ctx *ctx) { mpm_grid_velocity_after(ctx, 0); }

void mpm_grid_velocity_after(mpm_ctx *ctx, int mode) {
  if (!mpm_grid_nodes_fused(ctx, mode, false)) {
    PM_OMP(parallel default(none) shared(ctx))
    mpm_grid_velocity_nodes(ctx);
  }
  grid_velocity_conditions(ctx);
}

pm_err mpm_stage_grid_velocity(mpm_ctx *ctx, const mpm_stage *self) {
  (void)self;
  mpm_grid_velocity(ctx);
  return mpm_conditions_status(ctx);
}
