/* mpm_pressure: follower pressures on the points of a loaded surface. */
#include "mpm_pressure.h"

#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_state.h"
#include "pm_tensor.h"

/* Gauss points a facet: 2 a segment, 3 a triangle (mpm_traction.c). */
#define FACET_POINTS(dim) ((dim) == 2 ? 2 : 3)

/* The deformation gradient of the explicit state's particle p into F
 * (the identity for a particle that is no solid's). */
static void state_F(const mpm_model *m, mpm_state *st, long p, double F[9]) {
  for (int c = 0; c < 9; c++) F[c] = c % 4 == 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    mpm_solid_view v;
    if (p < g->begin || p >= g->end || !mpm_solid_access(g, st, &v)) continue;
    for (int c = 0; c < 9; c++) F[c] = v.F[9 * (p - g->begin) + c];
  }
}

/* The place of the particle at X (stencil st on the grid, with weights
 * and gradients) moved by the nodal displacements u (NULL: none) in x,
 * and the deformation gradient there in F. */
static void grid_place(const mpm_stencil *st, const double X[3],
                       const double *u, double x[3], double F[9]) {
  for (int c = 0; c < 9; c++) F[c] = c % 4 == 0;
  for (int c = 0; c < 3; c++) x[c] = X[c];
  if (!u) return;
  for (int j = 0; j < st->n; j++)
    for (int i = 0; i < 3; i++) {
      const double uj = u[3 * st->node[j] + i];
      x[i] += st->w[j] * uj;
      for (int J = 0; J < 3; J++) F[3 * i + J] += uj * st->grad[j][J];
    }
}

/* f += -pa cof(F) N: the force of pressure times area pa on the surface
 * deformed by F at reference normal N. */
static void add_cof(int dim, double pa, const double F[9], const double N[3],
                    double f[3]) {
  double C[9];
  pm_t_cofactor(F, C);
  for (int c = 0; c < dim; c++)
    f[c] -= pa * (C[3 * c] * N[0] + C[3 * c + 1] * N[1] + C[3 * c + 2] * N[2]);
}

/* The area vector of a facet with corners y (2: a segment's length turned
 * a quarter, 3: half the triangle's edges' cross product). */
static void area_vector(int dim, const double y[3][3], double a[3]) {
  double e1[3], e2[3];
  for (int c = 0; c < 3; c++) {
    e1[c] = y[1][c] - y[0][c];
    e2[c] = dim == 3 ? y[2][c] - y[0][c] : 0;
  }
  if (dim == 2) {
    a[0] = e1[1], a[1] = -e1[0], a[2] = 0;
    return;
  }
  a[0] = 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
  a[1] = 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
  a[2] = 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
}

/* f += the force of pressure pv on the facet with deformed corners y,
 * each of its points' share. */
static void add_facet(int dim, double pv, const double y[3][3], double f[3]) {
  double a[3];
  area_vector(dim, y, a);
  for (int c = 0; c < dim; c++) f[c] -= pv * a[c] / FACET_POINTS(dim);
}

void mpm_pressure_state(const mpm_model *m, mpm_state *st, const mpm_bc *bc,
                        long k, double pv, double f[3]) {
  double F[9], y[3][3];
  if (!bc->corner) {
    state_F(m, st, bc->held[k], F);
    add_cof(m->dim, pv * bc->area[k], F, bc->normal + 3 * k, f);
    return;
  }
  for (int i = 0; i < m->dim; i++) {
    const long p = bc->corner[3 * k + i];
    if (p < 0) return; /* a facet that carries nothing */
    const double *o = bc->coff + 9 * k + 3 * i;
    state_F(m, st, p, F);
    for (int c = 0; c < 3; c++)
      y[i][c] = st->x[3 * p + c] + F[3 * c] * o[0] + F[3 * c + 1] * o[1] +
                F[3 * c + 2] * o[2];
  }
  add_facet(m->dim, pv, y, f);
}

/* Corner i of the k-th point's facet of bc over the grid: its carrier's
 * stencil into st, and its deformed place into y. */
static void grid_corner(const mpm_grid *g, const double *xb, const double *u,
                        const mpm_bc *bc, long k, int i, mpm_stencil *st,
                        double y[3]) {
  const long p = bc->corner[3 * k + i];
  const double *o = bc->coff + 9 * k + 3 * i;
  double x[3], F[9];
  mpm_stencil_at(g, xb + 3 * p, MPM_STENCIL_W | MPM_STENCIL_GRAD, st);
  grid_place(st, xb + 3 * p, u, x, F);
  for (int c = 0; c < 3; c++)
    y[c] = x[c] + F[3 * c] * o[0] + F[3 * c + 1] * o[1] + F[3 * c + 2] * o[2];
}

void mpm_pressure_grid(const mpm_model *m, const mpm_grid *g, const double *xb,
                       const double *u, const mpm_bc *bc, long k, double pv,
                       double f[3]) {
  mpm_stencil st;
  double x[3], F[9], y[3][3];
  if (!bc->corner) {
    mpm_stencil_at(g, xb + 3 * bc->held[k], MPM_STENCIL_W | MPM_STENCIL_GRAD,
                   &st);
    grid_place(&st, xb + 3 * bc->held[k], u, x, F);
    add_cof(m->dim, pv * bc->area[k], F, bc->normal + 3 * k, f);
    return;
  }
  for (int i = 0; i < m->dim; i++) {
    if (bc->corner[3 * k + i] < 0) return;
    grid_corner(g, xb, u, bc, k, i, &st, y[i]);
  }
  add_facet(m->dim, pv, y, f);
}

/* The change of -f along a move dy of corner i (dy = e_c s) for the
 * facet with corners y: into d (3). */
static void facet_change(int dim, double pv, double y[3][3], int i, int c,
                         double s, double d[3]) {
  double a0[3], a1[3];
  area_vector(dim, y, a0);
  y[i][c] += s;
  area_vector(dim, y, a1);
  y[i][c] -= s;
  /* the area vector is linear in each corner: its change is exact */
  for (int r = 0; r < 3; r++) d[r] = pv * (a1[r] - a0[r]) / FACET_POINTS(dim);
}

void mpm_pressure_tangent(const mpm_model *m, const mpm_grid *g,
                          const double *xb, const double *u, const mpm_bc *bc,
                          long k, double pv, const double xs[3],
                          mpm_pressure_entry add, void *ctx) {
  const int dim = m->dim;
  mpm_stencil sr, sc[3];
  double x[3], F[9], y[3][3];
  mpm_stencil_at(g, xs, MPM_STENCIL_W, &sr);
  if (!bc->corner) {
    /* -pa cof(F) N: cof is quadratic, so its change along E = e_c (x)
     * grad_j is cof(F + E) - cof(F) - cof(E), exactly */
    const double pa = pv * bc->area[k], *N = bc->normal + 3 * k;
    mpm_stencil_at(g, xb + 3 * bc->held[k], MPM_STENCIL_W | MPM_STENCIL_GRAD,
                   &sc[0]);
    grid_place(&sc[0], xb + 3 * bc->held[k], u, x, F);
    double base[3] = {0, 0, 0};
    add_cof(dim, -1, F, N, base);
    for (int j = 0; j < sc[0].n; j++)
      for (int c = 0; c < dim; c++) {
        double FE[9], E[9] = {0}, d[3] = {0, 0, 0};
        for (int J = 0; J < 3; J++) E[3 * c + J] = sc[0].grad[j][J];
        for (int q = 0; q < 9; q++) FE[q] = F[q] + E[q];
        add_cof(dim, -1, FE, N, d);
        add_cof(dim, 1, E, N, d);
        for (int a = 0; a < sr.n; a++)
          for (int r = 0; r < dim; r++)
            add(ctx, 3 * sr.node[a] + r, 3 * sc[0].node[j] + c,
                pa * sr.w[a] * (d[r] - base[r]));
      }
    return;
  }
  for (int i = 0; i < dim; i++) {
    if (bc->corner[3 * k + i] < 0) return;
    grid_corner(g, xb, u, bc, k, i, &sc[i], y[i]);
  }
  for (int i = 0; i < dim; i++) {
    const double *o = bc->coff + 9 * k + 3 * i;
    for (int j = 0; j < sc[i].n; j++) {
      /* the corner moves by (w_j + grad_j . o) du_j */
      const double *gj = sc[i].grad[j];
      const double s = sc[i].w[j] + gj[0] * o[0] + gj[1] * o[1] + gj[2] * o[2];
      for (int c = 0; c < dim; c++) {
        double d[3];
        facet_change(dim, pv, y, i, c, s, d);
        for (int a = 0; a < sr.n; a++)
          for (int r = 0; r < dim; r++)
            add(ctx, 3 * sr.node[a] + r, 3 * sc[i].node[j] + c, sr.w[a] * d[r]);
      }
    }
  }
}
