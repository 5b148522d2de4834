/* mpm_grip: grips, conditions that hold the particles of a region and
 * move the grid nodes they touch with them. */
#include "mpm_grip.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_state.h"

int mpm_grips_count(const mpm_bc *bcs, int n) {
  int k = 0;
  for (int b = 0; b < n; b++) k += bcs[b].grip;
  return k;
}

/* MPM_GRIP_SHARE (mpm_grip.h), the share of a node's mass from which a
 * grip holds it wholly: a node
 * the grip's particles weigh on moves with them (as a face condition holds
 * the nodes at and beyond its wall), one they barely touch only in part
 * (the rest of its velocity is the grid's), so that a node the grip comes
 * to touch takes its velocity gradually.  At equilibrium a node held in
 * part is free, so the share sets where the grip holds: a layer of 4 a
 * cell has 0.39 of the node at the body's face (held in part at 0.5: F3
 * 60% 7.7% low against FE; at 0.25, 0.8%).  With the node's share alone
 * (the rigid kind's rule) the body's particles next to the grip drag its
 * nodes and the grip lets go. */

/* Whether particle p (reference position x0) lies in the region of bc. */
static bool held_by(const mpm_bc *bc, const double x0[3]) {
  return pm_expr_eval(bc->region, x0[0], x0[1], x0[2], 0.0) > 0;
}

pm_err mpm_grips_create(const pm_scene *s, mpm_model *m) {
  for (int b = 0; b < m->n_bcs; b++) {
    mpm_bc *bc = &m->bcs[b];
    /* A named surface's particles are found with its tractions'
     * (mpm_tractions_create). */
    if (!bc->grip || s->bcs[b].on != PM_ON_REGION) continue;
    char p[64];
    snprintf(p, sizeof p, "boundary.%d.region", b);
    long n = 0, volume = 0;
    for (int pass = 0; pass < 2; pass++) {
      if (pass == 1) PM_CALL(PM_ALLOC(bc->held, n > 0 ? n : 1, "grip"));
      n = 0;
      for (int i = 0; i < s->n_bodies; i++) {
        if (mpm_body_role_of(&s->bodies[i]) != MPM_BODY_VOLUME) continue;
        for (long q = m->body_begin[i]; q < m->body_end[i]; q++) {
          volume += pass == 0;
          if (!held_by(bc, m->x0 + 3 * q)) continue;
          if (pass == 1) bc->held[n] = q;
          n++;
        }
      }
    }
    bc->n_held = n;
    if (n == 0)
      return pm_scene_fail(s, p, false,
                           "expected a region that holds particles of a "
                           "volume body (a grip that grips nothing), got "
                           "none of the %ld particles in it",
                           volume);
  }
  return PM_SUCCESS;
}

/* The velocity grip bc prescribes to its held particle p over the step in
 * v (components it does not prescribe 0); false where one is not finite. */
static bool held_velocity(const mpm_model *m, const mpm_bc *bc, long p,
                          double t, double dt, double v[3]) {
  unsigned mask = bc->disp_mask | bc->vel_mask;
  for (int c = 0; c < 3; c++)
    v[c] = (mask >> c & 1u) && c < m->dim
               ? mpm_bc_velocity(bc, c, m->x0 + 3 * p, t, dt)
               : 0.0;
  return isfinite(v[0] + v[1] + v[2]);
}

double mpm_grips_apply(const mpm_ctx *ctx, double *vel, bool reactions) {
  const mpm_model *m = ctx->model;
  const mpm_nodes *nd = &ctx->work->nodes;
  mpm_cond_work *cw = &ctx->work->cond;
  double *gm = cw->grip_mass, *gv = cw->grip_mom;
  const double t = ctx->state->t, dt = ctx->state->dt, *x = ctx->state->x;
  double work = 0;
  if (!gm) return 0;
  /* Serial: a layer of particles, and nodes shared between them. */
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    const unsigned mask = bc->disp_mask | bc->vel_mask;
    if (!bc->grip || !mask) continue;
    /* The grip's mass and prescribed momentum at the nodes it touches. */
    for (long k = 0; k < bc->n_held; k++) {
      mpm_stencil st;
      mpm_stencil_at(&m->grid, x + 3 * bc->held[k], MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++) {
        gm[st.node[j]] = 0;
        for (int c = 0; c < 3; c++) gv[3 * st.node[j] + c] = 0;
      }
    }
    for (long k = 0; k < bc->n_held; k++) {
      const long p = bc->held[k];
      double v[3];
      if (!held_velocity(m, bc, p, t, dt, v)) {
        mpm_fail(ctx->work, p,
                 "the velocity its grip prescribes is not finite at t = %g s "
                 "(|v|^2 = %g)",
                 t, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        return work;
      }
      mpm_stencil st;
      mpm_stencil_at(&m->grid, x + 3 * p, MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++) {
        const double wm = st.w[j] * m->mass[p];
        gm[st.node[j]] += wm;
        for (int c = 0; c < 3; c++) gv[3 * st.node[j] + c] += wm * v[c];
      }
    }
    /* Each node once (then marked done): blended towards the grip's mean
     * velocity there by the grip's share of its mass. */
    for (long k = 0; k < bc->n_held; k++) {
      mpm_stencil st;
      mpm_stencil_at(&m->grid, x + 3 * bc->held[k], MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++) {
        const long i = st.node[j];
        if (!(gm[i] > 0) || !(nd->mass[i] > 0)) continue;
        const double a = fmin(1.0, gm[i] / (MPM_GRIP_SHARE * nd->mass[i]));
        const bool whole = a > 1.0 - 1e-9;
        for (int c = 0; c < m->dim; c++) {
          if (!(mask >> c & 1u)) continue;
          double *vi = vel + 3 * i + c;
          const double set = *vi + a * (gv[3 * i + c] / gm[i] - *vi);
          if (reactions && mpm_node_owned(nd, i)) {
            const double R = nd->mass[i] * (set - *vi) / dt;
            cw->reaction[3 * b + c] += R;
            work += R * 0.5 * (nd->vel0[3 * i + c] + set) * dt;
            if (whole) cw->owner[3 * i + c] = (short)-(b + 1);
          }
          *vi = set;
        }
        gm[i] = -1;
      }
    }
  }
  return work;
}

pm_err mpm_stage_grips(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  double *dx = ctx->work->dx, work = 0;
  double *reaction = ctx->work->cond.reaction;
  const double t1 = s->t + s->dt;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->grip) continue;
    for (long k = 0; k < bc->n_held; k++) {
      const long p = bc->held[k];
      const double *X = m->x0 + 3 * p;
      double v[3];
      if (!held_velocity(m, bc, p, s->t, s->dt, v)) break;
      for (int c = 0; c < m->dim; c++) {
        double *vp = s->v + 3 * p + c;
        if (bc->disp[c]) {
          /* The prescribed position at the step's end: no drift. */
          const double u = mpm_bc_factor(bc, t1) *
                           pm_expr_eval(bc->disp[c], X[0], X[1], X[2], t1);
          dx[3 * p + c] = X[c] + u - s->x[3 * p + c];
        } else if (bc->velocity[c]) {
          dx[3 * p + c] = s->dt * v[c];
        } else {
          continue;
        }
        work += 0.5 * m->mass[p] * (v[c] * v[c] - *vp * *vp);
        /* What the grip gives the particle over what the grid gave it:
         * part of the force it exerts (none at equilibrium). */
        reaction[3 * b + c] += m->mass[p] * (v[c] - *vp) / s->dt;
        *vp = v[c];
      }
    }
  }
  mpm_book_work(ctx, self, work);
  return mpm_stage_status(ctx, self);
}
