/* mpm_transfer: the transfers between particles and grid, each a loop
 * over a particle's stencil walked in place (MPM_STENCIL_FOR). */
#include "mpm_transfer.h"

#include <limits.h>
#include <math.h>
#include <string.h>

#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_exchange.h"
#include "mpm_state.h"
#include "pm_omp.h"

static inline int thread_id(void) {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

/* Widens [*first, *last] to the nodes of the stencil of axes ax (its first
 * node the smallest index, its last the largest). */
static inline __attribute__((always_inline)) void
touched(const mpm_grid *g, const mpm_axes *ax, const int dim, const int width,
        long *first, long *last) {
  const long reach =
      (width - 1) * (1 + g->stride[1] + (dim == 3 ? g->stride[2] : 0));
  if (ax->base < *first) *first = ax->base;
  if (ax->base + reach > *last) *last = ax->base + reach;
}

/* One thread's share of the particles of a group into its accumulators
 * acc.  Inline, so that each constant mode, dimension and width gets its
 * own loop. */
static inline __attribute__((always_inline)) void
p2g_group(const mpm_model *m, const mpm_state *s, const mpm_work *w,
          const mpm_group *gr, double *restrict acc, long span[2],
          const int mode, const bool imp, const int dim, const int width) {
  const mpm_grid *g = &m->grid;
  const int S = w->nodes.acc_stride;
  const double *restrict x = s->x, *restrict v = s->v, *restrict vol = s->vol,
                         *restrict sigma = s->sigma, *restrict mass = m->mass;
  const double *restrict cp_p = w->cp, *restrict cs_p = w->cs;
  long first = span[0], last = span[1];
  PM_OMP(for schedule(static) nowait)
  for (long p = gr->begin; p < gr->end; p++) {
    const double mp = mass[p];
    const double *vp = v + 3 * p;
    double sg[9] = {0};
    if (mode & MPM_P2G_FORCE)
      for (int k = 0; k < 9; k++) sg[k] = -vol[p] * sigma[9 * p + k];
    double cp = 0, cs = 0;
    if (imp) {
      /* Impedances rho c of the particle. */
      double rho = mp / vol[p];
      cp = cp_p[p] * rho;
      cs = cs_p[p] * rho;
    }
    /* Mass and momentum as one vector: w m (1, v) (a nil mass lane
     * without MPM_P2G_MASS); the force as the columns of -V sigma times
     * the gradient's components, summed in the scalar order, the pad lane
     * a copy of the third (not a zero: see MPM_STENCIL_FOR). */
    const pm_v4 mv = {mode & MPM_P2G_MASS ? 1.0 : 0.0, vp[0], vp[1], vp[2]};
    const pm_v4 s0 = {sg[0], sg[3], sg[6], sg[6]},
                s1 = {sg[1], sg[4], sg[7], sg[7]},
                s2 = {sg[2], sg[5], sg[8], sg[8]};
    mpm_axes ax;
    mpm_axes_at(g, x + 3 * p, &ax, dim, width);
    MPM_STENCIL_WALK(g, ax, dim, width, {
      double *r = acc + node * S;
      if (mode & MPM_P2G_MOM) {
        const pm_v4 r0 = pm_v4_load(r + MPM_ACC_M);
        pm_v4_store(r + MPM_ACC_M, r0 + wkv * mp * mv);
      } else if (mode & MPM_P2G_MASS) {
        r[MPM_ACC_M] += wk * mp;
      }
      if (mode & MPM_P2G_FORCE) {
        const pm_v4 r1 = pm_v4_load(r + MPM_ACC_F);
        pm_v4_store(r + MPM_ACC_F,
                    r1 + (s0 * MPM_LANE(gkv, 0) + s1 * MPM_LANE(gkv, 1) +
                          s2 * MPM_LANE(gkv, 2)));
        if (imp) {
          r[MPM_ACC_BASE + 0] += wk * mp * cp;
          r[MPM_ACC_BASE + 1] += wk * mp * cs;
        }
      }
    });
    touched(g, &ax, dim, width, &first, &last);
  }
  span[0] = first;
  span[1] = last;
}

/* Every group into acc, with a constant mode, dimension and width. */
static inline __attribute__((always_inline)) void
p2g_groups_dw(const mpm_model *m, const mpm_state *s, const mpm_work *w,
              double *acc, long span[2], const int mode, const bool imp,
              const int dim, const int width) {
  for (int gi = 0; gi < m->n_groups; gi++)
    p2g_group(m, s, w, &m->group[gi], acc, span, mode, imp, dim, width);
}

/* Every group into acc, with a constant mode. */
static inline __attribute__((always_inline)) void
p2g_groups(const mpm_model *m, const mpm_state *s, const mpm_work *w,
           double *acc, long span[2], const int mode, const bool imp) {
  MPM_STENCIL_DISPATCH(&m->grid, p2g_groups_dw, m, s, w, acc, span, mode, imp);
}

/* Joins this thread's span of touched nodes into the team's (shared,
 * empty at the region's start: {LONG_MAX, -1}) and waits for the team. */
static void join_span(long team[2], const long span[2]) {
  PM_OMP(critical(mpm_transfer_span)) {
    if (span[0] < team[0]) team[0] = span[0];
    if (span[1] > team[1]) team[1] = span[1];
  }
  PM_OMP(barrier)
}

/* The threads' accumulators summed in thread order into the nodal arrays
 * (inside the parallel region, as its last loop: the region's end is the
 * barrier after it).  The accumulators are zero but where the transfer
 * touched nodes, span[0] .. span[1] (every thread's): the sums are taken
 * there, and the records zeroed once read, while they are in cache, for
 * the next transfer; elsewhere the sums are zero without a read. */
static void reduce_nodes(mpm_nodes *nd, long nn, const long span[2], int mode,
                         bool imp) {
  const int S = nd->acc_stride;
  const int T = pm_omp_team();
  const long lo = span[0], hi = span[1];
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < nn; i++) {
    double sum[MPM_ACC_BASE + 2] = {0};
    if (i >= lo && i <= hi && S == MPM_ACC_BASE) {
      /* the record as two vectors: lane by lane the scalar sums */
      pm_v4 s0 = {0, 0, 0, 0}, s1 = s0;
      for (int t = 0; t < T; t++) {
        double *r = nd->acc + ((size_t)t * nn + i) * MPM_ACC_BASE;
        s0 += pm_v4_load(r);
        s1 += pm_v4_load(r + 4);
        memset(r, 0, sizeof(double) * MPM_ACC_BASE);
      }
      pm_v4_store(sum, s0);
      pm_v4_store(sum + 4, s1);
    } else if (i >= lo && i <= hi) {
      for (int t = 0; t < T; t++) {
        double *r = nd->acc + ((size_t)t * nn + i) * S;
        for (int k = 0; k < S; k++) sum[k] += r[k];
        memset(r, 0, sizeof(double) * S);
      }
    }
    if (mode & MPM_P2G_MASS) nd->mass[i] = sum[MPM_ACC_M];
    if (mode & MPM_P2G_MOM)
      for (int c = 0; c < 3; c++) nd->mom[3 * i + c] = sum[MPM_ACC_P + c];
    if (mode & MPM_P2G_FORCE) {
      for (int c = 0; c < 3; c++) nd->force[3 * i + c] = sum[MPM_ACC_F + c];
      if (imp) {
        nd->impedance[2 * i] = sum[MPM_ACC_BASE];
        nd->impedance[2 * i + 1] = sum[MPM_ACC_BASE + 1];
      }
    }
  }
}

/* mpm_p2g, with the grid update's node loop after the reduction when
 * `update` (mpm_grid_nodes_fused). */
static pm_err p2g_then(mpm_ctx *ctx, int mode, bool update) {
  const mpm_model *m = ctx->model;
  const mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  mpm_nodes *nd = &w->nodes;
  const bool imp = (mode & MPM_P2G_FORCE) && nd->impedance;
  const long nn = m->grid.n_nodes;
  if (imp)
    for (int gi = 0; gi < m->n_groups; gi++)
      m->group[gi].kind->wave_speeds(m, s, &m->group[gi], w->cp, w->cs);
  long team[2] = {LONG_MAX, -1};
  /* The accumulators were sized for nd->threads: run exactly that many.
   * They are zero here (mpm_nodes_create, then every reduce_nodes). */
  PM_OMP(parallel num_threads(nd->threads) default(none)
             shared(m, s, w, nd, nn, mode, imp, ctx, update, team)) {
    double *acc = nd->acc + (size_t)thread_id() * nn * nd->acc_stride;
    long span[2] = {LONG_MAX, -1};
    const int all = MPM_P2G_MASS | MPM_P2G_MOM | MPM_P2G_FORCE;
    if (mode == all && imp)
      p2g_groups(m, s, w, acc, span, all, true);
    else if (mode == all)
      p2g_groups(m, s, w, acc, span, all, false);
    else if (mode == MPM_P2G_MOM)
      p2g_groups(m, s, w, acc, span, MPM_P2G_MOM, false);
    else if (mode == (MPM_P2G_MASS | MPM_P2G_MOM))
      p2g_groups(m, s, w, acc, span, MPM_P2G_MASS | MPM_P2G_MOM, false);
    else
      p2g_groups(m, s, w, acc, span, mode, imp);
    join_span(team, span);
    reduce_nodes(nd, nn, team, mode, imp);
    /* the nodes this thread has just summed: the same static share */
    if (update) mpm_grid_update_nodes(ctx);
  }
  return mpm_xc_sum_nodes(m, nd, mode, imp);
}

pm_err mpm_p2g(mpm_ctx *ctx, int mode) { return p2g_then(ctx, mode, false); }

pm_err mpm_stage_p2g(mpm_ctx *ctx, const mpm_stage *self) {
  return p2g_then(ctx, self->mode & ~MPM_NODES_FUSED,
                  mpm_grid_nodes_fused(ctx, self->mode, true));
}

/* The FLIP/PIC velocities and the position increments of a group's
 * particles (this thread's share), for a constant dimension and width;
 * with `remap`, MUSL's momentum of the updated velocities scattered at the
 * same weights into acc (this thread's accumulators), as mpm_p2g's
 * MPM_P2G_MOM would: the same particles a thread, the same order. */
static inline __attribute__((always_inline)) void
g2p_group(mpm_work *w, const mpm_model *m, const mpm_group *gr, double dt,
          const double *restrict x, double *restrict v, double *restrict acc,
          long span[2], const bool remap, const int dim, const int width) {
  const mpm_grid *g = &m->grid;
  const double flip = m->opt.flip;
  const int S = w->nodes.acc_stride;
  const double *restrict vel_new = w->nodes.vel_new,
                         *restrict vel0 = w->nodes.vel0,
                         *restrict mass = m->mass;
  double *restrict dx = w->dx;
  long first = span[0], last = span[1];
  PM_OMP(for schedule(static) nowait)
  for (long p = gr->begin; p < gr->end; p++) {
    /* A node's three components read as four (the nodal arrays are
     * padded), the fourth lane unused; lane by lane the scalar sums. */
    pm_v4 vn4 = {0, 0, 0, 0}, dv4 = vn4;
    mpm_axes ax;
    mpm_axes_at(g, x + 3 * p, &ax, dim, width);
    MPM_STENCIL_WALK(g, ax, dim, width, {
      const pm_v4 v1 = pm_v4_load(vel_new + 3 * node);
      const pm_v4 v0 = pm_v4_load(vel0 + 3 * node);
      vn4 += wkv * v1;
      dv4 += wkv * (v1 - v0);
    });
    const double vn[3] = {vn4[0], vn4[1], vn4[2]},
                 dv[3] = {dv4[0], dv4[1], dv4[2]};
    double *vp = v + 3 * p;
    for (int c = 0; c < 3; c++) {
      vp[c] = flip * (vp[c] + dv[c]) + (1.0 - flip) * vn[c];
      dx[3 * p + c] = dt * vn[c];
    }
    if (!isfinite(vp[0] + vp[1] + vp[2]))
      mpm_fail(w, p, "velocity is not finite (|v|^2 = %g, v_x = %g)",
               vp[0] * vp[0] + vp[1] * vp[1] + vp[2] * vp[2], vp[0]);
    if (remap) {
      /* As mpm_p2g's w m (1, v): the mass lane is not read back. */
      const double mp = mass[p];
      const pm_v4 mv = {1.0, vp[0], vp[1], vp[2]};
      MPM_STENCIL_WALK(g, ax, dim, width, {
        double *r = acc + node * S;
        pm_v4_store(r + MPM_ACC_M, pm_v4_load(r + MPM_ACC_M) + wkv * mp * mv);
      });
      touched(g, &ax, dim, width, &first, &last);
    }
  }
  span[0] = first;
  span[1] = last;
}

/* Every group, for a constant dimension and width. */
static inline __attribute__((always_inline)) void
g2p_groups(mpm_work *w, const mpm_model *m, double dt, const double *x,
           double *v, double *acc, long span[2], const bool remap,
           const int dim, const int width) {
  for (int gi = 0; gi < m->n_groups; gi++)
    g2p_group(w, m, &m->group[gi], dt, x, v, acc, span, remap, dim, width);
}

pm_err mpm_stage_g2p(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  mpm_nodes *nd = &w->nodes;
  const mpm_grid *g = &m->grid;
  const long nn = g->n_nodes;
  const double dt = s->dt;
  const double *x = s->x;
  double *v = s->v;
  const bool remap = (self->mode & ~MPM_NODES_FUSED) == MPM_P2G_MOM;
  const bool velocity = remap && mpm_grid_nodes_fused(ctx, self->mode, false);
  long team[2] = {LONG_MAX, -1};
  PM_OMP(parallel num_threads(nd->threads) default(none)
             shared(m, w, nd, g, nn, dt, x, v, remap, velocity, ctx, team)) {
    double *acc = nd->acc + (size_t)thread_id() * nn * nd->acc_stride;
    long span[2] = {LONG_MAX, -1};
    if (remap) {
      MPM_STENCIL_DISPATCH(g, g2p_groups, w, m, dt, x, v, acc, span, true);
      join_span(team, span);
      reduce_nodes(nd, nn, team, MPM_P2G_MOM, false);
      if (velocity) mpm_grid_velocity_nodes(ctx);
    } else {
      MPM_STENCIL_DISPATCH(g, g2p_groups, w, m, dt, x, v, acc, span, false);
    }
  }
  if (remap) PM_CALL(mpm_xc_sum_nodes(m, nd, MPM_P2G_MOM, false));
  return mpm_stage_status(ctx, self);
}

pm_err mpm_stage_remap(mpm_ctx *ctx, const mpm_stage *self) {
  /* Mode 0: g2p scattered the momentum already. */
  if (self->mode & MPM_P2G_MOM) PM_CALL(mpm_p2g(ctx, MPM_P2G_MOM));
  mpm_grid_velocity_after(ctx, self->mode);
  return mpm_conditions_status(ctx);
}

pm_err mpm_stage_move(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_grid *g = &ctx->model->grid;
  mpm_work *w = ctx->work;
  const long n = ctx->model->n;
  double *restrict x = ctx->state->x;
  const double *restrict dx = w->dx;
  if (!(self->mode & MPM_MOVE_FUSED)) {
    PM_OMP(parallel for schedule(static) default(none) shared(g, w, n, x, dx))
    for (long p = 0; p < n; p++) mpm_move_particle(g, w, x, dx, p);
  }
  return mpm_stage_status(ctx, self);
}
