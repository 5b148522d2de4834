/* mpm_conditions: face conditions on the grid columns, with anchored
 * (constrained) shape functions at moving walls. */
#include "mpm_conditions.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_state.h"
#include "mpm_exchange.h"

pm_err mpm_conditions_create(const pm_scene *s, const mpm_grid *g, mpm_bc **bcs,
                             int *n_bcs) {
  *n_bcs = 0;
  PM_CALL(PM_ALLOC(*bcs, s->n_bcs, "grid boundary conditions"));
  *n_bcs = s->n_bcs;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *sb = &s->bcs[b];
    mpm_bc *bc = &(*bcs)[b];
    bc->disp_mask = sb->disp_mask;
    bc->vel_mask = sb->velocity_mask;
    bc->traction_mask = sb->traction_mask;
    bc->pressure = sb->pressure;
    bc->ramp = sb->ramp;
    bc->ramp_time = sb->ramp_time;
    bc->curve = sb->curve;
    bc->absorbing = sb->absorbing;
    for (int c = 0; c < 3; c++) {
      bc->disp[c] = sb->disp[c];
      bc->velocity[c] = sb->velocity[c];
      bc->traction[c] = sb->traction[c];
      const pm_expr *e = sb->disp[c] ? sb->disp[c] : sb->velocity[c];
      bc->constant[c] = !e || (!pm_expr_uses(e, 'x') && !pm_expr_uses(e, 'y') &&
                               !pm_expr_uses(e, 'z'));
    }
    /* A rigid body has no columns: the contact finds its nodes. */
    if (PM_BC_RIGID(sb)) {
      bc->rigid = sb;
      continue;
    }
    /* A grip has no columns: its held particles act (on a region, or the
     * particles at a named surface that a motion holds); nor has a
     * traction on a named surface: the particles at it carry it. */
    bc->grip = sb->on == PM_ON_REGION ||
               (sb->on == PM_ON_SURFACE && !MPM_BC_LOADS(sb));
    bc->region = sb->region;
    if (sb->on != PM_ON_FACE) continue;
    bc->face = sb->face;
    bc->axis = pm_face_axis(sb->face);
    bc->plane = pm_face_plane(sb->face, s->box_min, s->box_max);
    bool is_max = sb->face == PM_FACE_XMAX || sb->face == PM_FACE_YMAX ||
                  sb->face == PM_FACE_ZMAX;
    bc->outward = is_max ? 1.0 : -1.0;
    /* Columns: every node of the face plane. */
    int a = bc->axis, t1 = (a + 1) % 3, t2 = (a + 2) % 3;
    long n1 = g->nn[t1], n2 = g->nn[t2];
    bc->n_cols = n1 * n2;
    PM_CALL(PM_ALLOC(bc->col, bc->n_cols, "boundary columns"));
    long ia =
        (long)llround((bc->plane - g->origin[a]) * g->inv_h) - g->offset[a];
    if (ia < 0 || ia >= g->nn[a]) { /* another rank's face */
      bc->n_cols = 0;
      continue;
    }
    for (long j2 = 0; j2 < n2; j2++)
      for (long j1 = 0; j1 < n1; j1++)
        bc->col[j1 + n1 * j2] =
            ia * g->stride[a] + j1 * g->stride[t1] + j2 * g->stride[t2];
  }
  return PM_SUCCESS;
}

void mpm_conditions_destroy(mpm_bc *bcs, int n_bcs) {
  for (int b = 0; b < n_bcs; b++) {
    free(bcs[b].col);
    free(bcs[b].held);
    free(bcs[b].area);
    free(bcs[b].offset);
    free(bcs[b].normal);
    free(bcs[b].corner);
    free(bcs[b].coff);
  }
  free(bcs);
}

pm_err mpm_cond_work_create(mpm_cond_work *cw, const mpm_grid *g,
                            const mpm_bc *bcs, int n_bcs) {
  if (n_bcs == 0) return PM_SUCCESS;
  const long n3 = 3 * g->n_nodes;
  bool grips = false, rigid = false;
  for (int b = 0; b < n_bcs; b++) {
    grips = grips || bcs[b].grip;
    rigid = rigid || bcs[b].rigid;
  }
  if (grips) {
    PM_CALL(PM_ALLOC(cw->grip_mass, g->n_nodes, "grip masses"));
    PM_CALL(PM_ALLOC(cw->grip_mom, n3, "grip momenta"));
  }
  if (rigid) PM_CALL(PM_ALLOC(cw->touched, g->n_nodes, "contact nodes"));
  PM_CALL(PM_ALLOC(cw->owner, n3, "constrained dof owners"));
  PM_CALL(PM_ALLOC(cw->fold, n3, "folded condition forces"));
  PM_CALL(PM_ALLOC(cw->fold_out, n3, "folded condition forces"));
  PM_CALL(PM_ALLOC(cw->reaction, 3 * n_bcs, "reactions"));
  return PM_SUCCESS;
}

void mpm_cond_work_destroy(mpm_cond_work *cw) {
  free(cw->owner);
  free(cw->fold);
  free(cw->fold_out);
  free(cw->reaction);
  free(cw->grip_mass);
  free(cw->grip_mom);
  free(cw->touched);
  memset(cw, 0, sizeof *cw);
}

size_t mpm_cond_work_bytes(const mpm_cond_work *cw, const mpm_grid *g) {
  if (!cw->owner) return 0;
  return (3 * sizeof(short) + (cw->touched ? 1 : 0) +
          (cw->grip_mass ? 10 : 6) * sizeof(double)) *
         (size_t)g->n_nodes;
}

double mpm_bc_velocity(const mpm_bc *bc, int c, const double x[3], double t,
                       double dt) {
  if (bc->disp[c]) {
    double u1 = mpm_bc_factor(bc, t + dt) *
                pm_expr_eval(bc->disp[c], x[0], x[1], x[2], t + dt);
    double u0 =
        mpm_bc_factor(bc, t) * pm_expr_eval(bc->disp[c], x[0], x[1], x[2], t);
    return (u1 - u0) / dt;
  }
  return mpm_bc_factor(bc, t + dt) *
         pm_expr_eval(bc->velocity[c], x[0], x[1], x[2], t + dt);
}

/* Current wall coordinate of the face at x: the plane moved by the
 * prescribed normal displacement. */
static double bc_wall(const mpm_bc *bc, const double x[3], double t) {
  int a = bc->axis;
  if (!bc->disp[a]) return bc->plane;
  return bc->plane +
         mpm_bc_factor(bc, t) * pm_expr_eval(bc->disp[a], x[0], x[1], x[2], t);
}

/* Record the first value of the run that is not finite: expression e at
 * face position x of the column of node, over the step from t to t + dt
 * (the end whose value is not finite). */
static void note_not_finite(mpm_cond_work *cw, const pm_expr *e, long node,
                            const double x[3], double t, double dt) {
  if (cw->bad_expr) return;
  cw->bad_expr = e;
  cw->bad_node = node;
  for (int c = 0; c < 3; c++) cw->bad_x[c] = x[c];
  cw->bad_t = isfinite(pm_expr_eval(e, x[0], x[1], x[2], t + dt)) ? t : t + dt;
}

pm_err mpm_conditions_status(const mpm_ctx *ctx) {
  const mpm_cond_work *cw = &ctx->work->cond;
  const double *x = cw->bad_x;
  if (!cw->bad_expr) return PM_SUCCESS;
  return pm_expr_fail_value(
      cw->bad_expr, pm_expr_eval(cw->bad_expr, x[0], x[1], x[2], cw->bad_t),
      ctx->state->step + 1, cw->bad_t, "node", cw->bad_node, x);
}

/* The dependent dofs of the conditions.  On each column of a face, a node
 * at or beyond the face's current wall is set from one free node of the
 * column (its anchor), v = T v_anchor + (1 - T) v_b:
 *  - prescribed components: the line through the anchor's velocity and the
 *    prescribed value at the wall, so a linear field stays linear through
 *    the wall wherever it is.  The anchor is the first inside node at least
 *    h/2 from the wall (nearer, the line's slope would amplify the anchor's
 *    noise); a node inside the wall but nearer than h/2 is then set too.
 *    On a wall at a node plane this is the odd reflection v = 2 v_b - v_in.
 *  - free components of a wall (normal prescribed): the first inside
 *    node's, as at a plane of symmetry (T = 1), beyond the wall.
 * With fold, instead of setting vel, the dependent dofs' forces are moved
 * onto their anchors (f_anchor += T f): the free dofs then carry the
 * shape functions of the constrained space, S_anchor + T S_ghost, and the
 * internal force is its Galerkin force (without it, a free node whose
 * support crosses the wall misses the ghost's share and feels the stress
 * at the wall as a spurious load).  With mark, record in owner which
 * condition set each dof (-(b + 1) prescribed, b + 1 reflected; a
 * prescription wins over a reflection). */
static void apply_once(const mpm_ctx *ctx, double *vel, bool mark,
                       const double *force, double *fold) {
  const mpm_model *m = ctx->model;
  const mpm_grid *g = &m->grid;
  const double *mass = ctx->work->nodes.mass;
  mpm_cond_work *cw = &ctx->work->cond;
  short *owner = cw->owner;
  double *fold_out = cw->fold_out;
  const double t = ctx->state->t, dt = ctx->state->dt;
  const double eps = 1e-9 * g->h;
  /* Folding visits the faces in reverse: a dof set by two faces follows
   * the last one's rule, as its velocity does. */
  for (int bb = 0; bb < m->n_bcs; bb++) {
    int b = fold ? m->n_bcs - 1 - bb : bb;
    const mpm_bc *bc = &m->bcs[b];
    unsigned mask = bc->disp_mask | bc->vel_mask;
    if (!mask || bc->grip || bc->rigid) continue;
    int a = bc->axis;
    double vconst[3] = {0, 0, 0}, wall_const = bc->plane;
    double xc[3];
    for (int c = 0; c < 3; c++) xc[c] = 0.5 * (m->box_min[c] + m->box_max[c]);
    xc[a] = bc->plane;
    for (int c = 0; c < 3; c++)
      if ((mask >> c & 1u) && bc->constant[c])
        vconst[c] = mpm_bc_velocity(bc, c, xc, t, dt);
    if (bc->constant[a]) wall_const = bc_wall(bc, xc, t);
    long step_a = g->stride[a];
    for (long k = 0; k < bc->n_cols; k++) {
      long col = bc->col[k];
      /* Face position of the column. */
      double x[3];
      mpm_grid_node_position(g, col, x);
      x[a] = bc->plane;
      double v[3] = {0, 0, 0};
      if (!fold)
        for (int c = 0; c < 3; c++) {
          if (!(mask >> c & 1u)) continue;
          v[c] = bc->constant[c] ? vconst[c] : mpm_bc_velocity(bc, c, x, t, dt);
          if (!isfinite(v[c]))
            note_not_finite(cw, bc->disp[c] ? bc->disp[c] : bc->velocity[c],
                            col, x, t, dt);
        }
      double wall = bc->constant[a] ? wall_const : bc_wall(bc, x, t);
      if (!isfinite(wall)) note_not_finite(cw, bc->disp[a], col, x, t, 0);
      /* The first node inside the wall, and the anchor of the prescribed
       * components. */
      long ia_face =
          (long)llround((bc->plane - g->origin[a]) * g->inv_h) - g->offset[a];
      long i_start = bc->outward > 0 ? g->nn[a] - 1 : 0;
      long di = bc->outward > 0 ? -1 : 1;
#define DIST(i)                                                                \
  ((g->origin[a] + ((i) + g->offset[a]) * g->h - wall) * bc->outward)
#define INSIDE(i) ((i) >= 0 && (i) < g->nn[a])
#define NODE(i) (col + ((i)-ia_face) * step_a)
      long i_in = i_start;
      while (INSIDE(i_in) && DIST(i_in) >= -eps) i_in += di;
      long i_an = i_in;
      if (INSIDE(i_an) && DIST(i_an) > -0.5 * g->h) i_an += di;
      /* The inside nodes count only where material is (a node without
       * mass has no velocity to extend). */
      long n_in = NODE(i_in), n_an = NODE(i_an);
      bool has_in = INSIDE(i_in) && mass[n_in] > 0;
      bool has_an = INSIDE(i_an) && mass[n_an] > 0;
      double d_an = INSIDE(i_an) ? DIST(i_an) : -g->h;
      long i_end = INSIDE(i_an) ? i_an : i_in;
      for (long i = i_start; i != i_end; i += di) {
        long node = NODE(i);
        double d = DIST(i);
        double mn = mass[node];
        for (int c = 0; c < 3; c++) {
          bool fixed = mask >> c & 1u;
          long anchor;
          double T;
          if (fixed) {
            /* v = v_an + (d - d_an) / -d_an (v_b - v_an) */
            anchor = has_an && fabs(d) > eps ? n_an : -1;
            T = anchor >= 0 ? 1.0 - (d - d_an) / -d_an : 0.0;
          } else {
            if (!(mask >> a & 1u) || !has_in || d <= eps) continue;
            anchor = n_in;
            T = 1.0;
          }
          if (fold) {
            short *o = &owner[3 * node + c];
            if (*o) continue; /* folded by a later face */
            *o = 1;
            if (anchor < 0 || mn <= 0) continue;
            double f = T * (force[3 * node + c] + fold[3 * node + c]);
            fold[3 * anchor + c] += f;
            fold_out[3 * node + c] = f;
            continue;
          }
          double vset =
              anchor >= 0 ? T * vel[3 * anchor + c] + (1.0 - T) * v[c] : v[c];
          if (mark && mn > 0) {
            short *o = &owner[3 * node + c];
            if (fixed)
              *o = (short)-(b + 1);
            else if (*o >= 0)
              *o = (short)(b + 1);
          }
          vel[3 * node + c] = vset;
        }
      }
#undef DIST
#undef INSIDE
#undef NODE
    }
  }
}

void mpm_conditions_fold(const mpm_ctx *ctx) {
  const mpm_cond_work *cw = &ctx->work->cond;
  if (!cw->fold) return;
  size_t n3 = 3 * (size_t)ctx->model->grid.n_nodes;
  memset(cw->fold, 0, n3 * sizeof(double));
  memset(cw->fold_out, 0, n3 * sizeof(double));
  memset(cw->owner, 0, n3 * sizeof(short));
  apply_once(ctx, NULL, false, ctx->work->nodes.force, cw->fold);
}

/* The conditions, twice: where two faces meet, one face's mirror reads
 * nodes the other sets, so the second pass sees them set.  With
 * reactions, then one pass over the constrained dofs: the force each
 * condition applies, R = m (v - v0) / dt - f - f_in + f_out, with f_in the
 * force folded onto the dof and f_out the force it folded onto its anchor
 * (the anchors' share of the internal force, not a reaction), counted
 * once per dof (to the condition that prescribes it, else the one that
 * reflects it); and the work of the conditions, m (v - v0) / dt - f times
 * (v0 + v) / 2 dt, over the constrained dofs and the anchors. */
double mpm_conditions_apply(const mpm_ctx *ctx, double *vel, bool reactions) {
  const mpm_model *m = ctx->model;
  const mpm_nodes *nd = &ctx->work->nodes;
  const mpm_cond_work *cw = &ctx->work->cond;
  const long n_nodes = m->grid.n_nodes;
  if (m->n_bcs == 0) return 0.0;
  if (reactions) memset(cw->owner, 0, 3 * sizeof(short) * (size_t)n_nodes);
  apply_once(ctx, vel, false, NULL, NULL);
  apply_once(ctx, vel, reactions, NULL, NULL);
  if (!reactions) return 0.0;
  memset(cw->reaction, 0, 3 * sizeof(double) * (size_t)m->n_bcs);
  double work = 0;
  const double dt = ctx->state->dt;
  for (long i = 0; i < 3 * n_nodes; i++) {
    short o = cw->owner[i];
    double fold = cw->fold ? cw->fold[i] : 0.0;
    if (!o && fold == 0) continue;
    long node = i / 3;
    if (!(nd->mass[node] > 0) || !mpm_node_owned(nd, node)) continue;
    double R = nd->mass[node] * (vel[i] - nd->vel0[i]) / dt - nd->force[i];
    if (o)
      cw->reaction[3 * ((o > 0 ? o : -o) - 1) + i % 3] +=
          R - fold + (cw->fold_out ? cw->fold_out[i] : 0.0);
    work += R * 0.5 * (nd->vel0[i] + vel[i]) * dt;
  }
  /* Every rank's share of the reactions: the residual's scale. */
  mpm_xc_sum(m, cw->reaction, 3 * m->n_bcs);
  return work;
}

bool mpm_supports_still(const mpm_bc *bcs, int n_bcs, const double lo[3],
                        const double hi[3], double t_end) {
  for (int b = 0; b < n_bcs; b++) {
    const mpm_bc *bc = &bcs[b];
    if (bc->vel_mask || bc->rigid) return false;
    for (int c = 0; c < 3; c++) {
      if (!bc->disp[c]) continue;
      for (int k = 0; k < 18; k++) { /* the corners and the centre */
        const int corner = k % 9;
        double x[3];
        for (int a = 0; a < 3; a++)
          x[a] = corner == 8 ? 0.5 * (lo[a] + hi[a])
                             : (corner >> a & 1 ? hi[a] : lo[a]);
        if (pm_expr_eval(bc->disp[c], x[0], x[1], x[2], k < 9 ? 0 : t_end) != 0)
          return false;
      }
    }
  }
  return true;
}
