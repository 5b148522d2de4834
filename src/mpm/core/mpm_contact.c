/* mpm_contact: rigid plates and spheres in the grid's contact: which nodes
 * the particles bring to the body, and their velocities, reactions and
 * work. */
#include "mpm_contact.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_state.h"
#include "pm_omp.h"
#include "pm_rigid.h"

int mpm_contacts_count(const mpm_bc *bcs, int n) {
  int k = 0;
  for (int b = 0; b < n; b++) k += bcs[b].rigid != NULL;
  return k;
}

/* Whether the particles of group gi are in contact: not those of a body
 * that moves as prescribed. */
static bool in_contact(const mpm_model *m, int gi) {
  return m->group[gi].kind->stress != NULL;
}

pm_err mpm_contacts_check(const pm_scene *s, const mpm_model *m) {
  const double zero[3] = {0, 0, 0};
  for (int b = 0, k = 0; b < m->n_bcs; b++) {
    const pm_scene_bc *bc = m->bcs[b].rigid;
    if (!bc) continue;
    char key[64];
    PM_PATH(key, "boundary.%d.%s", b,
            bc->on == PM_ON_PLATE ? "plate" : "sphere");
    if (++k > MPM_CONTACT_MAX)
      return pm_scene_fail(s, key, true,
                           "expected at most %d rigid bodies for method mpm "
                           "(a bit of a node's flag each), got more",
                           MPM_CONTACT_MAX);
    long glued = 0, seen = 0;
    for (int gi = 0; gi < m->n_groups; gi++) {
      if (!in_contact(m, gi)) continue;
      for (long p = m->group[gi].begin; p < m->group[gi].end; p++) {
        const double *x = m->x0 + 3 * p;
        double n[3], g = pm_rigid_gap(bc, zero, x, n);
        seen++;
        glued += g - 0.5 * pow(m->vol0[p], 1.0 / m->dim) <= 1e-6 * m->grid.h;
        if (!(g < 0)) continue;
        return pm_scene_fail(
            s, key, false,
            "expected a rigid body outside the bodies at t = 0, got "
            "particle %ld (material %s) at (%g, %g, %g) %g m inside it",
            p, m->group[gi].name, x[0], x[1], x[2], -g);
      }
    }
    if (bc->contact == PM_CONTACT_GLUED && glued == 0)
      return pm_scene_fail(s, key, false,
                           "expected a glued plate on a body's face (a "
                           "particle within half its size of it at t = 0), "
                           "got none of the %ld particles there (a grip that "
                           "grips nothing)",
                           seen);
  }
  return PM_SUCCESS;
}

/* Mark in touched the nodes of the particles that reach rigid body bc
 * displaced by d: centre within half the particle's size of its surface
 * (1e-6 h of rounding allowed). */
static void mark_touched(const mpm_model *m, const mpm_state *s,
                         const pm_scene_bc *bc, const double d[3],
                         unsigned char *touched) {
  const mpm_grid *g = &m->grid;
  const double tol = 1e-6 * g->h, inv_dim = 1.0 / m->dim;
  for (long i = 0; i < g->n_nodes; i++) touched[i] &= (unsigned char)~1u;
  /* Serial: the particles near the body share nodes; the test is a dot
   * product a particle. */
  for (int gi = 0; gi < m->n_groups; gi++) {
    if (!in_contact(m, gi)) continue;
    for (long p = m->group[gi].begin; p < m->group[gi].end; p++) {
      double n[3];
      const double gap = pm_rigid_gap(bc, d, s->x + 3 * p, n);
      if (gap - 0.5 * pow(s->vol[p], inv_dim) > tol) continue;
      mpm_stencil st;
      mpm_stencil_at(g, s->x + 3 * p, MPM_STENCIL_W, &st);
      for (int j = 0; j < st.n; j++)
        if (st.w[j] > 0) touched[st.node[j]] |= 1u;
    }
  }
}

/* The axis a plate is normal to (its normal +-e_a), or -1 (a sphere, an
 * oblique plate). */
static int plate_axis(const pm_scene_bc *bc) {
  if (bc->on != PM_ON_PLATE) return -1;
  for (int a = 0; a < 3; a++)
    if (fabs(fabs(bc->rigid_normal[a]) - 1) < 1e-12) return a;
  return -1;
}

/* A rigid body over one step: its surface at mid-step (displacement dm),
 * its velocity V, the axis of a plate normal to one (else -1) and how far
 * inside it sets nodes. */
typedef struct {
  const pm_scene_bc *bc;
  double dm[3], V[3], reach;
  int axis;
  bool stick;
  bool glue;         /* glued: every node with mass within reach, pulling too */
  unsigned char bit; /* its bit in touched: the nodes in contact */
} body_step;

/* The anchor of node i (gap `gap`, normal n along axis a) in its column:
 * the first node at least h/2 inside (beyond the nodes in contact, whose
 * reach is 1e-6 h short of h/2, so no thread writes what another reads),
 * or -1 where there is none with mass (glued: none with a quarter of i's
 * mass or more, so that a light node at the body's fringe, whose velocity
 * the grid's force makes large, is not carried to the nodes in contact
 * by the line); its
 * distance k h from i in *k. */
static long anchor_of(const mpm_grid *g, const double *mass, long i, double gap,
                      const double n[3], int a, bool glue, long *k) {
  *k = (long)ceil((0.5 - 1e-9) - gap * g->inv_h);
  const long ia = i / g->stride[a] % g->nn[a];
  const long ja = ia + (n[a] > 0 ? *k : -*k);
  const long j = i + (ja - ia) * g->stride[a];
  if (*k < 1 || ja < 0 || ja >= g->nn[a] || !(mass[j] > 0)) return -1;
  if (glue && mass[j] < 0.25 * mass[i]) return -1;
  return j;
}

/* Whether node i is in contact with body b this step: a particle reaches
 * the body there, it has mass, and the velocity it takes (vc) pushes the
 * body away.  vc: on a plate normal to an axis, the line through V at the
 * surface and the anchor's velocity, v = V + (v_an - V) g / g_an, for the
 * nodes within h/2 inside and those past it; else V at and past the
 * surface.  Its normal into n, its anchor into *j (-1: none) with
 * T = g / g_an. */
static bool node_contact(const mpm_grid *g, const mpm_nodes *nd,
                         const unsigned char *touched, const double *vel,
                         const body_step *b, long i, double vc[3], double n[3],
                         long *j, double *T) {
  double x[3];
  *j = -1;
  *T = 0;
  if (!(nd->mass[i] > 0) || !(b->glue || (touched[i] & 1u))) return false;
  mpm_grid_node_position(g, i, x);
  const double gap = pm_rigid_gap(b->bc, b->dm, x, n);
  if (!(gap < b->reach)) return false;
  memcpy(vc, b->V, 3 * sizeof(double));
  long k;
  if (b->axis >= 0)
    *j = anchor_of(g, nd->mass, i, gap, n, b->axis, b->glue, &k);
  if (*j < 0 && gap > 0) return false;
  if (*j >= 0) {
    *T = gap / (gap + k * g->h);
    for (int c = 0; c < 3; c++) vc[c] += (vel[3 * *j + c] - b->V[c]) * *T;
  }
  if (b->glue) return true; /* it pulls as well */
  double push = 0;
  for (int c = 0; c < g->dim; c++) push += (vc[c] - vel[3 * i + c]) * n[c];
  return push > 0; /* else the body leaves it: no pull */
}

/* Whether component c is one the contact sets (sticking: all). */
static bool sets(const body_step *b, const double n[3], int c) {
  return b->stick || fabs(n[c]) > 1e-12;
}

/* Anchor j's share of the forces of the nodes in contact that follow it,
 * sum T f (the force of their components the contact sets), into fold
 * (3): their velocity follows j's by T, so j carries the shape functions
 * S_j + T S_i of the constrained space, as at a face condition. */
static void gather_fold(const mpm_ctx *ctx, const body_step *b, long j,
                        double fold[3]) {
  const mpm_grid *g = &ctx->model->grid;
  const mpm_nodes *nd = &ctx->work->nodes;
  const double *cf = ctx->work->cond.fold;
  const unsigned char *touched = ctx->work->cond.touched;
  const int a = b->axis;
  const double sign = b->bc->rigid_normal[a] > 0 ? 1 : -1;
  const long ja = j / g->stride[a] % g->nn[a];
  fold[0] = fold[1] = fold[2] = 0;
  for (long k = 1; k <= 3; k++) {
    const long ia = ja - (long)sign * k;
    if (ia < 0 || ia >= g->nn[a]) break;
    const long i = j + (ia - ja) * g->stride[a];
    if (!(touched[i] & b->bit)) continue;
    double x[3], n[3];
    long ki;
    mpm_grid_node_position(g, i, x);
    const double gap = pm_rigid_gap(b->bc, b->dm, x, n);
    if (anchor_of(g, nd->mass, i, gap, n, a, b->glue, &ki) != j) continue;
    const double T = gap / (gap + ki * g->h);
    for (int c = 0; c < g->dim; c++)
      if (sets(b, n, c)) fold[c] += T * (nd->force[3 * i + c] + cf[3 * i + c]);
  }
}

/* One rigid body's contact on vel: the nodes in contact (found with
 * reactions, in the grid update, and marked by the body's bit in touched;
 * the remap of MUSL later in the step keeps them), the anchors' folded
 * forces (with reactions), then the nodes' velocities.  Adds its force on
 * the body to R (3) and returns its work. */
static double body_contact(const mpm_ctx *ctx, const body_step *b, int bi,
                           double *vel, bool reactions, bool find,
                           double R[3]) {
  const mpm_grid *g = &ctx->model->grid;
  const mpm_nodes *nd = &ctx->work->nodes;
  mpm_cond_work *cw = &ctx->work->cond;
  unsigned char *touched = cw->touched;
  short *owner = cw->owner;
  double *cf = cw->fold;
  const double dt = ctx->state->dt, *mass = nd->mass, *vel0 = nd->vel0;
  const long nn = g->n_nodes;
  const int dim = g->dim;
  const short mark = (short)-(bi + 1);
  const bool fold = reactions && b->axis >= 0 && cf;
  double rx = 0, ry = 0, rz = 0, work = 0;
  if (find) {
    PM_OMP(parallel for schedule(static) default(none)
           shared(g, nd, touched, vel, b, nn))
    for (long i = 0; i < nn; i++) {
      double vc[3], n[3], T;
      long j;
      if (node_contact(g, nd, touched, vel, b, i, vc, n, &j, &T))
        touched[i] |= b->bit;
    }
  }
  if (fold) {
    PM_OMP(parallel for schedule(static) default(none)
           shared(ctx, b, nd, touched, vel, vel0, mass, cf, nn, dt, dim)
           reduction(+ : rx, ry, rz, work))
    for (long j = 0; j < nn; j++) {
      if ((touched[j] & b->bit) || !(mass[j] > 0)) continue;
      double f[3];
      gather_fold(ctx, b, j, f);
      for (int c = 0; c < dim; c++) {
        if (f[c] == 0) continue;
        vel[3 * j + c] += dt * f[c] / mass[j];
        cf[3 * j + c] += f[c];
        work += f[c] * 0.5 * (vel0[3 * j + c] + vel[3 * j + c]) * dt;
      }
      rx += f[0];
      ry += f[1];
      rz += f[2];
    }
  }
  PM_OMP(parallel for schedule(static) default(none)
         shared(g, nd, touched, owner, vel, vel0, mass, b, nn, dt, dim, mark,
                reactions) reduction(+ : rx, ry, rz, work))
  for (long i = 0; i < nn; i++) {
    if (!(touched[i] & b->bit) || !(mass[i] > 0)) continue;
    double x[3], n[3], vc[3], dv[3] = {0, 0, 0};
    long k;
    mpm_grid_node_position(g, i, x);
    const double gap = pm_rigid_gap(b->bc, b->dm, x, n);
    memcpy(vc, b->V, sizeof vc);
    const long j =
        b->axis >= 0 ? anchor_of(g, mass, i, gap, n, b->axis, b->glue, &k) : -1;
    if (j >= 0)
      for (int c = 0; c < 3; c++)
        vc[c] += (vel[3 * j + c] - b->V[c]) * gap / (gap + k * g->h);
    double *v = vel + 3 * i, push = 0;
    for (int c = 0; c < dim; c++) push += (vc[c] - v[c]) * n[c];
    for (int c = 0; c < dim; c++) {
      dv[c] = b->stick ? vc[c] - v[c] : push * n[c];
      v[c] += dv[c];
    }
    if (!reactions || !mpm_node_owned(nd, i)) continue;
    rx += mass[i] * dv[0] / dt;
    ry += mass[i] * dv[1] / dt;
    rz += mass[i] * dv[2] / dt;
    for (int c = 0; c < dim; c++) {
      work += mass[i] * dv[c] / dt * 0.5 * (vel0[3 * i + c] + v[c]) * dt;
      if (sets(b, n, c)) owner[3 * i + c] = mark;
    }
  }
  R[0] += rx;
  R[1] += ry;
  R[2] += rz;
  return work;
}

double mpm_contacts_apply(const mpm_ctx *ctx, double *vel, bool reactions) {
  const mpm_model *m = ctx->model;
  mpm_cond_work *cw = &ctx->work->cond;
  const double t = ctx->state->t, dt = ctx->state->dt;
  double work = 0;
  if (!cw->touched) return 0;
  /* The update finds the nodes in contact; MUSL's remap, after it in the
   * same step, keeps them, so that the velocities of the stress and of the
   * positions agree (USF's grid velocity, before the update, finds its
   * own). */
  const bool find = reactions || m->opt.update != MPM_MUSL;
  if (find) memset(cw->touched, 0, (size_t)m->grid.n_nodes);
  for (int b = 0, k = 0; b < m->n_bcs; b++) {
    const pm_scene_bc *bc = m->bcs[b].rigid;
    if (!bc) continue;
    body_step bs = {.bc = bc,
                    .axis = plate_axis(bc),
                    .stick = bc->contact != PM_CONTACT_FRICTIONLESS,
                    .glue = bc->contact == PM_CONTACT_GLUED,
                    .bit = (unsigned char)(2u << k++)};
    bs.reach = bs.axis >= 0 ? (0.5 - 1e-6) * m->grid.h : 0.0;
    double d0[3], d1[3];
    pm_rigid_displacement(bc, t, d0);
    pm_rigid_displacement(bc, t + dt, d1);
    for (int c = 0; c < 3; c++) {
      bs.V[c] = (d1[c] - d0[c]) / dt;
      bs.dm[c] = 0.5 * (d0[c] + d1[c]);
    }
    if (find && !bs.glue) mark_touched(m, ctx->state, bc, d1, cw->touched);
    double R[3] = {0, 0, 0};
    work += body_contact(ctx, &bs, b, vel, reactions, find, R);
    if (!reactions) continue;
    for (int c = 0; c < 3; c++) cw->reaction[3 * b + c] += R[c];
  }
  return work;
}
