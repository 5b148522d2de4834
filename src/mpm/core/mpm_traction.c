/* mpm_traction: nominal tractions on faces of MPM bodies, carried by their
 * surface particles. */
#include "mpm_traction.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_state.h"

int mpm_tractions_count(const mpm_bc *bcs, int n) {
  int k = 0;
  for (int b = 0; b < n; b++) k += bcs[b].traction_mask != 0;
  return k;
}

/* The plane of face f of body i (its box's for a box body, else the
 * domain's) and the body's particle spacing normal to it. */
static void body_face(const pm_scene *s, const mpm_model *m, int i, pm_face f,
                      double *plane, double *spacing) {
  const pm_scene_body *body = &s->bodies[i];
  const int a = pm_face_axis(f);
  *plane = pm_face_plane(f, s->box_min, s->box_max);
  if (body->shape == PM_BODY_BOX) *plane = pm_face_plane(f, body->a, body->b);
  const int ppc = body->n_ppc == 0   ? m->opt.ppc[a]
                  : body->n_ppc == 1 ? (int)body->ppc[0]
                                     : (int)body->ppc[a];
  *spacing = m->grid.h / ppc;
}

pm_err mpm_tractions_create(const pm_scene *s, mpm_model *m) {
  for (int b = 0; b < m->n_bcs; b++) {
    mpm_bc *bc = &m->bcs[b];
    if (!bc->traction_mask) continue;
    const pm_face f = s->bcs[b].face;
    const int a = pm_face_axis(f);
    const double out = bc->outward;
    long n = 0;
    for (int pass = 0; pass < 2; pass++) {
      if (pass == 1) {
        PM_CALL(PM_ALLOC(bc->held, n > 0 ? n : 1, "traction particles"));
        PM_CALL(PM_ALLOC(bc->area, n > 0 ? n : 1, "traction areas"));
        PM_CALL(PM_ALLOC(bc->reach, n > 0 ? n : 1, "traction areas"));
      }
      n = 0;
      for (int i = 0; i < s->n_bodies; i++) {
        if (mpm_body_role_of(&s->bodies[i]) != MPM_BODY_VOLUME) continue;
        double plane, hs;
        body_face(s, m, i, f, &plane, &hs);
        for (long q = m->body_begin[i]; q < m->body_end[i]; q++) {
          const double d = (plane - m->x0[3 * q + a]) * out;
          if (!(d >= 0 && d < hs * (1 - 1e-9))) continue;
          if (pass == 1) {
            bc->held[n] = q;
            bc->area[n] = m->vol0[q] / hs;
            bc->reach[n] = d;
          }
          n++;
        }
      }
    }
    bc->n_held = n;
    if (n == 0) {
      char p[64];
      return pm_scene_fail(s, PM_PATH(p, "boundary.%d.on", b), false,
                           "expected a face some volume body touches (its "
                           "particles carry the traction), got %s, where "
                           "no particle lies within a particle spacing",
                           s->bcs[b].surface);
    }
  }
  return PM_SUCCESS;
}

/* The point of the face over the k-th particle of traction bc: the
 * particle moved by its reference distance to the face along the face's
 * normal (at a particle the tractions would leave the nodes beyond it out
 * of balance: a residual of 1% on a bar). */
static void face_point(const mpm_model *m, const mpm_bc *bc, long k,
                       const double *x, double xs[3]) {
  for (int c = 0; c < 3; c++) xs[c] = x[3 * bc->held[k] + c];
  xs[bc->axis] += bc->outward * bc->reach[k];
  (void)m;
}

/* The force traction bc applies to its k-th particle at time t. */
static void particle_force(const mpm_model *m, const mpm_bc *bc, long k,
                           double t, double f[3]) {
  const double *X = m->x0 + 3 * bc->held[k];
  const double r = pm_ramp_factor(bc->ramp, bc->ramp_time, t) * bc->area[k];
  for (int c = 0; c < 3; c++)
    f[c] = bc->traction[c] && c < m->dim
               ? r * pm_expr_eval(bc->traction[c], X[0], X[1], X[2], t)
               : 0.0;
}

pm_err mpm_stage_tractions(mpm_ctx *ctx, const mpm_stage *self) {
  (void)self;
  const mpm_model *m = ctx->model;
  double *force = ctx->work->nodes.force;
  const double t = ctx->state->t, *x = ctx->state->x;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->traction_mask) continue;
    for (long k = 0; k < bc->n_held; k++) {
      double f[3];
      particle_force(m, bc, k, t, f);
      if (!isfinite(f[0] + f[1] + f[2])) {
        mpm_fail(ctx->work, bc->held[k],
                 "the traction on it is not finite at t = %g s (|f|^2 = %g)", t,
                 f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        return mpm_stage_status(ctx, self);
      }
      mpm_stencil st;
      double xs[3];
      face_point(m, bc, k, x, xs);
      mpm_stencil_at(&m->grid, xs, MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++)
        for (int c = 0; c < 3; c++) force[3 * st.node[j] + c] += st.w[j] * f[c];
    }
  }
  return PM_SUCCESS;
}

pm_err mpm_book_tractions(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  const mpm_nodes *nd = &ctx->work->nodes;
  double *reaction = ctx->work->cond.reaction;
  const double t = ctx->state->t, *x = ctx->state->x;
  double work = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->traction_mask) continue;
    for (int c = 0; c < 3; c++) reaction[3 * b + c] = 0;
    for (long k = 0; k < bc->n_held; k++) {
      double f[3];
      particle_force(m, bc, k, t, f);
      mpm_stencil st;
      double xs[3];
      face_point(m, bc, k, x, xs);
      mpm_stencil_at(&m->grid, xs, MPM_STENCIL_W, &st);
      for (int c = 0; c < 3; c++) reaction[3 * b + c] += f[c];
      for (int j = 0; j < st.n; j++) {
        const long i = st.node[j];
        for (int c = 0; c < 3; c++)
          work += st.w[j] * f[c] * 0.5 *
                  (nd->vel0[3 * i + c] + nd->vel_new[3 * i + c]);
      }
    }
  }
  mpm_book_work(ctx, self, work * ctx->state->dt);
  return PM_SUCCESS;
}

void mpm_tractions_nodal(const mpm_model *m, const mpm_grid *g,
                         const double *xb, double lam, double *f) {
  const double T = m->opt.t_load;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->traction_mask) continue;
    for (long k = 0; k < bc->n_held; k++) {
      double ft[3], xs[3];
      particle_force(m, bc, k, T, ft);
      face_point(m, bc, k, xb, xs);
      mpm_stencil st;
      mpm_stencil_at(g, xs, MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++)
        for (int c = 0; c < 3; c++)
          f[3 * st.node[j] + c] -= lam * st.w[j] * ft[c];
    }
  }
}
