/* mpm_traction: nominal tractions on faces of MPM bodies, carried by their
 * surface particles. */
#include "mpm_traction.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_gmsh.h"
#include "mpm_exchange.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_pressure.h"
#include "mpm_state.h"

int mpm_tractions_count(const mpm_bc *bcs, int n) {
  int k = 0;
  for (int b = 0; b < n; b++) k += MPM_BC_LOADS(&bcs[b]) != 0;
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

/* The carriers of traction bc on face f: the particles of the volume
 * bodies within one particle spacing of the face, each with its area (its
 * volume over its spacing normal to the face) and its offset to the face
 * along the face's normal (at a particle the tractions would leave the
 * nodes beyond it out of balance: a residual of 1% on a bar).  Counts
 * only when held is NULL. */
static long face_carriers(const pm_scene *s, const mpm_model *m, mpm_bc *bc,
                          pm_face f, long *held, double *area, double *offset) {
  const int a = pm_face_axis(f);
  long n = 0;
  for (int i = 0; i < s->n_bodies; i++) {
    if (mpm_body_role_of(&s->bodies[i]) != MPM_BODY_VOLUME) continue;
    double plane, hs;
    body_face(s, m, i, f, &plane, &hs);
    for (long q = m->body_begin[i]; q < m->body_end[i]; q++) {
      const double d = (plane - m->x0[3 * q + a]) * bc->outward;
      if (!(d >= 0 && d < hs * (1 - 1e-9))) continue;
      if (held) {
        held[n] = q;
        area[n] = m->vol0[q] / hs;
        for (int c = 0; c < 3; c++) {
          offset[3 * n + c] = c == a ? d * bc->outward : 0;
          bc->normal[3 * n + c] = c == a ? bc->outward : 0;
        }
      }
      n++;
    }
  }
  return n;
}

/* Room for n carriers of traction bc (n_held set). */
static pm_err carriers_alloc(mpm_bc *bc, long n) {
  bc->n_held = n;
  PM_CALL(PM_ALLOC(bc->held, n > 0 ? n : 1, "traction particles"));
  PM_CALL(PM_ALLOC(bc->area, n > 0 ? n : 1, "traction areas"));
  PM_CALL(PM_ALLOC(bc->offset, 3 * (n > 0 ? n : 1), "traction points"));
  PM_CALL(PM_ALLOC(bc->normal, 3 * (n > 0 ? n : 1), "traction normals"));
  return PM_SUCCESS;
}

/* Gauss points of a facet, in barycentric weights of its corners: 2 on a
 * segment (exact for cubic tractions along it), 3 on a triangle (exact for
 * quadratic ones). */
#define GAUSS_N(dim) ((dim) == 2 ? 2 : 3)
static void gauss_weights(int dim, int g, double w[3]) {
  if (dim == 2) {
    const double r = 0.5 / sqrt(3.0);
    w[0] = 0.5 + (g ? r : -r);
    w[1] = 1 - w[0];
    w[2] = 0;
    return;
  }
  for (int c = 0; c < 3; c++) w[c] = c == g ? 2.0 / 3.0 : 1.0 / 6.0;
}

/* The measure of a facet (a segment's length, a triangle's area), and its
 * unit normal in nu (either side). */
static double facet_measure(int dim, const double *p[3], double nu[3]) {
  double e1[3], e2[3];
  for (int c = 0; c < 3; c++) {
    e1[c] = p[1][c] - p[0][c];
    e2[c] = dim == 3 ? p[2][c] - p[0][c] : 0;
  }
  const double n[3] = {dim == 2 ? e1[1] : e1[1] * e2[2] - e1[2] * e2[1],
                       dim == 2 ? -e1[0] : e1[2] * e2[0] - e1[0] * e2[2],
                       dim == 2 ? 0 : e1[0] * e2[1] - e1[1] * e2[0]};
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int c = 0; c < 3; c++) nu[c] = len > 0 ? n[c] / len : 0;
  return dim == 2 ? len : 0.5 * len;
}

/* Particles [p0, p1) of a body in buckets of edge h: the nearest one to a
 * point, found in the buckets around it (a surface point's nearest
 * particle lies within a cell: particles fill their cells). */
typedef struct {
  double lo[3], h;
  long n[3], *start, *order;
  long p0;
} buckets;

static long bucket_of(const buckets *bk, const double *x, long off[3]) {
  long k = 0;
  for (int c = 2; c >= 0; c--) {
    long i = (long)floor((x[c] - bk->lo[c]) / bk->h) + (off ? off[c] : 0);
    if (i < 0 || i >= bk->n[c]) return -1;
    k = k * bk->n[c] + i;
  }
  return k;
}

static pm_err buckets_create(buckets *bk, const mpm_model *m, long p0, long p1,
                             double h) {
  *bk = (buckets){.h = h, .p0 = p0};
  double hi[3];
  for (int c = 0; c < 3; c++) bk->lo[c] = hi[c] = m->x0[3 * p0 + c];
  for (long q = p0; q < p1; q++)
    for (int c = 0; c < 3; c++) {
      bk->lo[c] = fmin(bk->lo[c], m->x0[3 * q + c]);
      hi[c] = fmax(hi[c], m->x0[3 * q + c]);
    }
  long nb = 1;
  for (int c = 0; c < 3; c++) {
    bk->n[c] = (long)floor((hi[c] - bk->lo[c]) / h) + 1;
    nb *= bk->n[c];
  }
  PM_CALL(PM_ALLOC(bk->start, nb + 1, "traction buckets"));
  PM_CALL(PM_ALLOC(bk->order, p1 - p0 > 0 ? p1 - p0 : 1, "traction buckets"));
  for (long q = p0; q < p1; q++)
    bk->start[bucket_of(bk, m->x0 + 3 * q, NULL) + 1]++;
  for (long k = 0; k < nb; k++) bk->start[k + 1] += bk->start[k];
  for (long q = p0; q < p1; q++)
    bk->order[bk->start[bucket_of(bk, m->x0 + 3 * q, NULL)]++] = q;
  for (long k = nb; k > 0; k--) bk->start[k] = bk->start[k - 1];
  bk->start[0] = 0;
  return PM_SUCCESS;
}

/* The particle nearest x (x clamped to the buckets' box), -1 for none. */
static long nearest(const buckets *bk, const mpm_model *m, const double *x) {
  double xc[3];
  for (int c = 0; c < 3; c++)
    xc[c] = fmin(fmax(x[c], bk->lo[c]), bk->lo[c] + (bk->n[c] - 0.5) * bk->h);
  long best = -1;
  double d2min = INFINITY;
  /* Past the ring where one is found, one more: a nearer one may lie
   * there. */
  for (int r = 1, last = 64; r <= last && r < 64; r++) {
    if (best >= 0 && last == 64) last = r;
    const int rz = bk->n[2] > 1 ? r : 0;
    for (long dz = -rz; dz <= rz; dz++)
      for (long dy = -r; dy <= r; dy++)
        for (long dx = -r; dx <= r; dx++) {
          long off[3] = {dx, dy, dz};
          const long k = bucket_of(bk, xc, off);
          if (k < 0) continue;
          for (long j = bk->start[k]; j < bk->start[k + 1]; j++) {
            const double *p = m->x0 + 3 * bk->order[j];
            const double d2 = (p[0] - x[0]) * (p[0] - x[0]) +
                              (p[1] - x[1]) * (p[1] - x[1]) +
                              (p[2] - x[2]) * (p[2] - x[2]);
            if (d2 < d2min) d2min = d2, best = bk->order[j];
          }
        }
  }
  return best;
}

/* The carriers of traction b on a named surface (3-D) or edge (2-D) of a
 * gmsh body: the Gauss points of the boundary facets of its physical group
 * (from the body's mesh at the seeding's element size), each with its
 * share of its facet's area, carried by the body's particle nearest it at
 * the offset from that particle to the point. */
static pm_err surface_carriers(const pm_scene *s, mpm_model *m, int b) {
  const char *name = s->bcs[b].surface;
  mpm_bc *bc = &m->bcs[b];
  const int dim = s->dimension, ng = GAUSS_N(dim);
  char p[64];
  for (int i = 0; i < s->n_bodies; i++) {
    const pm_scene_body *body = &s->bodies[i];
    if (body->shape != PM_BODY_MESH ||
        mpm_body_role_of(body) != MPM_BODY_VOLUME ||
        m->body_end[i] <= m->body_begin[i])
      continue;
    gm_gmsh_mesh mesh;
    PM_CALL(gm_gmsh_load(body->mesh, dim, 0.5 * s->mesh_size, GM_SIZES_REPLACE,
                         true, &mesh));
    int g = 0;
    while (g < mesh.n_groups && strcmp(mesh.group_name[g], name) != 0) g++;
    if (g == mesh.n_groups) {
      gm_gmsh_mesh_free(&mesh);
      continue;
    }
    const long f0 = mesh.group_ptr[g], f1 = mesh.group_ptr[g + 1];
    pm_err e = carriers_alloc(bc, (f1 - f0) * ng);
    if (!e && bc->pressure)
      e = PM_ALLOC(bc->corner, 3 * bc->n_held + 1, "pressure facets");
    if (!e && bc->pressure)
      e = PM_ALLOC(bc->coff, 9 * bc->n_held + 1, "pressure facets");
    buckets bk = {0};
    if (!e)
      e = buckets_create(&bk, m, m->body_begin[i], m->body_end[i], m->grid.h);
    for (long f = f0; !e && f < f1; f++) {
      /* A facet with a node no element uses lies on no element: it
       * carries nothing (its points sit at its first usable node). */
      const double *c[3] = {NULL, NULL, NULL};
      bool lone = false;
      for (int k = 0; k < dim; k++) {
        const long id = mesh.group_face[dim * f + k];
        lone = lone || id < 0;
        c[k] = id >= 0 ? mesh.x + 3 * id : NULL;
      }
      for (int k = 0; k < dim; k++)
        if (!c[k]) c[k] = c[(k + 1) % dim] ? c[(k + 1) % dim] : mesh.x;
      double nu[3] = {0, 0, 0}, out = 0;
      const double A = lone ? 0 : facet_measure(dim, c, nu) / ng;
      for (int q = 0; q < ng; q++) {
        double w[3], X[3] = {0, 0, 0};
        gauss_weights(dim, q, w);
        for (int k = 0; k < dim; k++)
          for (int a = 0; a < 3; a++) X[a] += w[k] * c[k][a];
        const long n = (f - f0) * ng + q, pq = nearest(&bk, m, X);
        bc->held[n] = pq < 0 ? m->body_begin[i] : pq;
        bc->area[n] = A;
        for (int a = 0; a < 3; a++) {
          bc->offset[3 * n + a] = X[a] - m->x0[3 * bc->held[n] + a];
          out += bc->offset[3 * n + a] * nu[a];
        }
      }
      /* Outward: the carriers lie inside the body, behind the facet. */
      for (int q = 0; q < ng; q++)
        for (int a = 0; a < 3; a++)
          bc->normal[3 * ((f - f0) * ng + q) + a] = out < 0 ? -nu[a] : nu[a];
      for (int k = 0; bc->corner && k < dim; k++) {
        /* the area vector of corners 0, 1 (, 2) is along nu: swapping
         * the first two turns it out */
        const int kk = out < 0 && k < 2 ? 1 - k : k;
        const long cc = nearest(&bk, m, c[kk]);
        for (int q = 0; q < ng; q++) {
          const long n = (f - f0) * ng + q;
          bc->corner[3 * n + k] = lone || cc < 0 ? -1 : cc;
          for (int a = 0; a < 3; a++)
            bc->coff[9 * n + 3 * k + a] =
                c[kk][a] - m->x0[3 * (cc < 0 ? bc->held[n] : cc) + a];
        }
      }
    }
    free(bk.start);
    free(bk.order);
    gm_gmsh_mesh_free(&mesh);
    return e;
  }
  return pm_scene_fail(s, PM_PATH(p, "boundary.%d.on", b), false,
                       "expected a face of domain.box or the name of a "
                       "physical %s of a gmsh body, got %s",
                       dim == 2 ? "curve" : "surface", name);
}

static int long_order(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* A motion on a named surface holds the particles that carry its Gauss
 * points (each once), as a grip holds those of its region: the same
 * particles a traction there would load, so the surface a user names is
 * held where it is loaded, whatever its slope to the grid. */
static pm_err surface_grip(const pm_scene *s, mpm_model *m, int b) {
  mpm_bc *bc = &m->bcs[b];
  PM_CALL(surface_carriers(s, m, b));
  qsort(bc->held, (size_t)bc->n_held, sizeof(long), long_order);
  long n = 0;
  for (long k = 0; k < bc->n_held; k++)
    if (n == 0 || bc->held[k] != bc->held[n - 1]) bc->held[n++] = bc->held[k];
  bc->n_held = n;
  free(bc->area);
  free(bc->offset);
  free(bc->normal);
  bc->area = bc->offset = bc->normal = NULL;
  return PM_SUCCESS;
}

pm_err mpm_tractions_create(const pm_scene *s, mpm_model *m) {
  for (int b = 0; b < m->n_bcs; b++) {
    mpm_bc *bc = &m->bcs[b];
    if (s->bcs[b].on == PM_ON_SURFACE && bc->grip) {
      PM_CALL(surface_grip(s, m, b));
      continue;
    }
    if (!MPM_BC_LOADS(bc)) continue;
    if (s->bcs[b].on == PM_ON_SURFACE) {
      PM_CALL(surface_carriers(s, m, b));
      continue;
    }
    const pm_face f = s->bcs[b].face;
    bc->axis = pm_face_axis(f);
    PM_CALL(carriers_alloc(bc, face_carriers(s, m, bc, f, NULL, NULL, NULL)));
    face_carriers(s, m, bc, f, bc->held, bc->area, bc->offset);
    if (bc->n_held == 0) {
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

/* The point of the surface the k-th carrier of traction bc stands for:
 * its particle at x moved by its reference offset. */
static void face_point(const mpm_bc *bc, long k, const double *x,
                       double xs[3]) {
  for (int c = 0; c < 3; c++)
    xs[c] = x[3 * bc->held[k] + c] + bc->offset[3 * k + c];
}

/* Where the k-th point of condition bc acts over the particles at x: its
 * surface point, or with a pressure its carrier particle.  A pressure
 * follows the deformed surface, which the grid gives only where particles
 * reach all the nodes of a point's stencil: at a surface point off the
 * grid's lines the nodes beyond the body hold no displacement (nor take a
 * force, which is lost); at its carrier the nodes are the body's. */
static void load_point(const mpm_bc *bc, long k, const double *x,
                       double xs[3]) {
  if (!bc->pressure) {
    face_point(bc, k, x, xs);
    return;
  }
  for (int c = 0; c < 3; c++) xs[c] = x[3 * bc->held[k] + c];
}

/* The stencil on grid g through which the k-th point of condition bc
 * acts over the particles at x: its load point's, on the nodes its
 * carrier's stencil shares, the weights scaled back to 1.  A point on a
 * surface off the grid's lines reaches nodes beyond the body that no
 * particle reaches: they hold no displacement, and a force there is lost
 * (the tapered panel on a grid shifted by 0.2 m lost 20% of its traction
 * at cells of 0.0625 m).  The carrier's nodes are the body's; where the
 * surface is a grid plane the point's weights there are already 1. */
static void load_stencil(const mpm_grid *g, const mpm_bc *bc, long k,
                         const double *x, mpm_stencil *st) {
  double xs[3];
  load_point(bc, k, x, xs);
  mpm_stencil_at(g, xs, MPM_STENCIL_W, st);
  if (bc->pressure) return; /* at its carrier */
  mpm_stencil sc;
  mpm_stencil_at(g, x + 3 * bc->held[k], MPM_STENCIL_W, &sc);
  int n = 0;
  double sum = 0;
  for (int j = 0; j < st->n; j++) {
    bool shared = false;
    for (int i = 0; i < sc.n && !shared; i++)
      shared = sc.node[i] == st->node[j];
    if (!shared || st->w[j] == 0) continue;
    st->node[n] = st->node[j];
    st->w[n++] = st->w[j];
    sum += st->w[j];
  }
  st->n = n;
  if (!(sum > 0)) {
    *st = sc;
    return;
  }
  for (int j = 0; j < n; j++) st->w[j] /= sum;
}

/* The force of condition bc's traction at its k-th point at time t
 * (dead: nominal), into f. */
static void traction_force(const mpm_model *m, const mpm_bc *bc, long k,
                           double t, double f[3]) {
  double X[3];
  face_point(bc, k, m->x0, X);
  const double r = mpm_bc_factor(bc, t) * bc->area[k];
  for (int c = 0; c < 3; c++)
    f[c] = bc->traction[c] && c < m->dim
               ? r * pm_expr_eval(bc->traction[c], X[0], X[1], X[2], t)
               : 0.0;
}

/* The pressure of condition bc at its k-th point at time t (full ramp
 * included), Pa (0 without a pressure). */
static double point_pressure(const mpm_model *m, const mpm_bc *bc, long k,
                             double t) {
  if (!bc->pressure) return 0;
  double X[3];
  face_point(bc, k, m->x0, X);
  return mpm_bc_factor(bc, t) * pm_expr_eval(bc->pressure, X[0], X[1], X[2], t);
}

/* The force condition bc applies at its k-th point at time t over the
 * explicit state st: its traction and its pressure. */
static void state_force(const mpm_model *m, mpm_state *st, const mpm_bc *bc,
                        long k, double t, double f[3]) {
  traction_force(m, bc, k, t, f);
  if (bc->pressure)
    mpm_pressure_state(m, st, bc, k, point_pressure(m, bc, k, t), f);
}

pm_err mpm_stage_tractions(mpm_ctx *ctx, const mpm_stage *self) {
  (void)self;
  const mpm_model *m = ctx->model;
  double *force = ctx->work->nodes.force;
  const double t = ctx->state->t, *x = ctx->state->x;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!MPM_BC_LOADS(bc)) continue;
    for (long k = 0; k < bc->n_held; k++) {
      double f[3];
      state_force(m, ctx->state, bc, k, t, f);
      if (!isfinite(f[0] + f[1] + f[2])) {
        mpm_fail(ctx->work, bc->held[k],
                 "the traction on it is not finite at t = %g s (|f|^2 = %g)", t,
                 f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        return mpm_stage_status(ctx, self);
      }
      mpm_stencil st;
      load_stencil(&m->grid, bc, k, x, &st);
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
    if (!MPM_BC_LOADS(bc)) continue;
    for (int c = 0; c < 3; c++) reaction[3 * b + c] = 0;
    for (long k = 0; k < bc->n_held; k++) {
      double f[3];
      state_force(m, ctx->state, bc, k, t, f);
      mpm_stencil st;
      load_stencil(&m->grid, bc, k, x, &st);
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
                         const double *xb, const double *u, double lam,
                         double *f) {
  const double T = m->opt.t_load;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!MPM_BC_LOADS(bc)) continue;
    for (long k = 0; k < bc->n_held; k++) {
      double ft[3];
      traction_force(m, bc, k, T, ft);
      if (bc->pressure)
        mpm_pressure_grid(m, g, xb, u, bc, k, point_pressure(m, bc, k, T), ft);
      mpm_stencil st;
      load_stencil(g, bc, k, xb, &st);
      for (int j = 0; j < st.n; j++)
        for (int c = 0; c < 3; c++)
          f[3 * st.node[j] + c] -= lam * st.w[j] * ft[c];
    }
  }
}

void mpm_pressures_tangent(const mpm_model *m, const mpm_grid *g,
                           const double *xb, const double *u, double lam,
                           mpm_pressure_entry add, void *ctx) {
  const double T = m->opt.t_load;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->pressure) continue;
    for (long k = 0; k < bc->n_held; k++) {
      double xs[3];
      load_point(bc, k, xb, xs);
      mpm_pressure_tangent(m, g, xb, u, bc, k,
                           lam * point_pressure(m, bc, k, T), xs, add, ctx);
    }
  }
}

long mpm_tractions_points(const mpm_model *m, const double *x, double *at) {
  long n = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!MPM_BC_LOADS(bc)) continue;
    for (long k = 0; k < bc->n_held; k++, n++) {
      if (!at) continue;
      load_point(bc, k, x, at + 6 * n);
      for (int c = 3; c < 6; c++) at[6 * n + c] = 0;
    }
  }
  return n;
}

double mpm_tractions_work(const mpm_model *m, const mpm_grid *g,
                          const double *xb, const double *u, double *at,
                          double lam_old, double lam_new) {
  const double T = m->opt.t_load, lam = 0.5 * (lam_old + lam_new);
  double work = 0;
  long n = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!MPM_BC_LOADS(bc)) continue;
    for (long k = 0; k < bc->n_held; k++, n++) {
      double ft[3], fp[3] = {0, 0, 0}, xs[3], *y = at + 6 * n;
      /* The traction's force is dead (the mean load's); the pressure's
       * follows the surface: the mean of its force at the step's two ends
       * (the one at its start kept in at). */
      traction_force(m, bc, k, T, ft);
      if (bc->pressure)
        mpm_pressure_grid(m, g, xb, u, bc, k,
                          lam_new * point_pressure(m, bc, k, T), fp);
      load_point(bc, k, xb, xs);
      mpm_stencil st;
      load_stencil(g, bc, k, xb, &st);
      for (int j = 0; j < st.n; j++)
        for (int c = 0; c < 3; c++) xs[c] += st.w[j] * u[3 * st.node[j] + c];
      for (int c = 0; c < 3; c++) {
        const double dx = xs[c] - y[c];
        work += (lam * ft[c] + 0.5 * (y[3 + c] + fp[c])) * dx;
        y[c] = xs[c];
        y[3 + c] = fp[c];
      }
    }
  }
  return work;
}
