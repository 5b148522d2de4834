/* mpm_motion: prescribed rigid motion of bodies. */
#include "mpm_motion.h"

#include <math.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_state.h"

void mpm_motion_velocity(const mpm_motion *mv, double t, double v[3]) {
  for (int c = 0; c < 3; c++)
    v[c] = mv->v[c] ? pm_expr_eval(mv->v[c], 0, 0, 0, t) : 0.0;
}

/* The body's velocity, or a failure at its first particle (recorded by
 * the rank that holds it: every rank stops, with one process's message). */
static bool velocity_at(const mpm_ctx *ctx, const mpm_motion *mv, double t,
                        double v[3]) {
  mpm_motion_velocity(mv, t, v);
  if (isfinite(v[0] + v[1] + v[2])) return true;
  const long *gid = ctx->model->gid;
  if (mv->end > mv->begin && (!gid || gid[mv->begin] == mv->first))
    mpm_fail(ctx->work, mv->begin,
             "the prescribed velocity of its body (motion.velocity) is not "
             "finite at t = %g s (|v|^2 = %g)",
             t, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return false;
}

/* Node i's velocity (in vel) blended towards the body's v by the body's
 * share of the node's mass rm[i], which is then marked as done; the work
 * that does (with book).  Nothing where neither has mass. */
static double blend(const mpm_nodes *nd, double *vel, double *rm, long i,
                    const double v[3], int dim, bool book) {
  if (!(rm[i] > 0) || !(nd->mass[i] > 0)) return 0;
  const double a = fmin(1.0, rm[i] / nd->mass[i]);
  double work = 0;
  rm[i] = -1;
  for (int c = 0; c < dim; c++) {
    double *vi = vel + 3 * i + c, set = *vi + a * (v[c] - *vi);
    if (book)
      work += nd->mass[i] * (set - *vi) * 0.5 * (nd->vel0[3 * i + c] + set);
    *vi = set;
  }
  return work;
}

/* The body's mass at the nodes its particles touch into rm (0 elsewhere
 * with `all`, else left as it was). */
static void body_mass(const mpm_model *m, const double *x, const mpm_motion *mv,
                      double *rm, bool all) {
  if (all) memset(rm, 0, sizeof(double) * (size_t)m->grid.n_nodes);
  for (long p = mv->begin; p < mv->end && !all; p++) {
    mpm_stencil st;
    mpm_stencil_at(&m->grid, x + 3 * p, MPM_STENCIL_W, &st);
    for (int k = 0; k < st.n; k++) rm[st.node[k]] = 0;
  }
  for (long p = mv->begin; p < mv->end; p++) {
    mpm_stencil st;
    mpm_stencil_at(&m->grid, x + 3 * p, MPM_STENCIL_W, &st);
    for (int k = 0; k < st.n; k++) rm[st.node[k]] += st.w[k] * m->mass[p];
  }
}

double mpm_motion_apply(const mpm_ctx *ctx, double *vel, bool book) {
  const mpm_model *m = ctx->model;
  const mpm_nodes *nd = &ctx->work->nodes;
  double *rm = ctx->work->rigid_mass;
  const double t = ctx->state->t, dt = ctx->state->dt, *x = ctx->state->x;
  const int dim = m->dim;
  double work = 0;
  /* Serial: a few thousand particles, and nodes shared between them. */
  for (int b = 0; b < m->n_moving; b++) {
    const mpm_motion *mv = &m->moving[b];
    double v[3];
    if (!velocity_at(ctx, mv, t + 0.5 * dt, v)) return 0;
    /* Each node once (its share then marked as done): the velocity blended
     * towards the body's by the body's share of the node's mass, so that a
     * node the body starts to touch takes its velocity gradually. */
    if (!mpm_xc_shared(m)) {
      body_mass(m, x, mv, rm, false);
      for (long p = mv->begin; p < mv->end; p++) {
        mpm_stencil st;
        mpm_stencil_at(&m->grid, x + 3 * p, MPM_STENCIL_W, &st);
        for (int k = 0; k < st.n; k++)
          work += blend(nd, vel, rm, st.node[k], v, dim, book);
      }
      continue;
    }
    /* Across ranks the body's particles near a node may be on other ranks:
     * its mass is summed over them, and every node that has some is
     * blended (the ghosts as their owners do; the owners book the work). */
    body_mass(m, x, mv, rm, true);
    if (mpm_xc_nodes_reduce(m, rm, MPM_XC_DOUBLE, MPM_XC_SUM)) return work;
    for (long i = 0; i < m->grid.n_nodes; i++) {
      const double wi = blend(nd, vel, rm, i, v, dim, book);
      if (mpm_node_owned(nd, i)) work += wi;
    }
  }
  return work;
}

pm_err mpm_stage_motion(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  double *dx = ctx->work->dx, work = 0;
  for (int b = 0; b < m->n_moving; b++) {
    const mpm_motion *mv = &m->moving[b];
    double vm[3], ve[3];
    if (!velocity_at(ctx, mv, s->t + 0.5 * s->dt, vm) ||
        !velocity_at(ctx, mv, s->t + s->dt, ve))
      break;
    /* What sets the body's velocity works on it: the change of its
     * particles' kinetic energy from what the grid gave them. */
    for (long p = mv->begin; p < mv->end; p++)
      for (int c = 0; c < 3; c++) {
        double *vp = s->v + 3 * p + c;
        work += 0.5 * m->mass[p] * (ve[c] * ve[c] - *vp * *vp);
        *vp = ve[c];
        dx[3 * p + c] = s->dt * vm[c];
      }
  }
  mpm_book_work(ctx, self, work);
  return mpm_stage_status(ctx, self);
}
