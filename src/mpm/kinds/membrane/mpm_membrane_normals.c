/* mpm_membrane_normals: the membrane's normal stage: each point's normal
 * by its body's method, by connectivity here (the mean of its triangles'
 * normals, eq. 8, or along a curve perpendicular to its neighbours' chord)
 * or fitted per cell (mpm_membrane_fit.c). */
#include <stdio.h>
#include <string.h>

#include "gm_curve.h"
#include "mpm_membrane_impl.h"
#include "mpm_exchange.h"
#include "pm_omp.h"

/* Unit normals of the links' triangles into tn (3 each) from the
 * positions of the group's np points xo and of the ghosts xg; zero for a
 * degenerate triangle. */
void mpm_membrane_triangle_normals(const membrane_params *mp, const double *xo,
                                   const double *xg, long np, double *tn) {
  const long *tri = mp->tri, nt = mp->n_tris;
  PM_OMP(parallel for schedule(static) default(none)
         shared(tri, nt, xo, xg, np, tn))
  for (long t = 0; t < nt; t++) {
    const double *a = link_x(xo, xg, np, tri[3 * t]),
                 *b = link_x(xo, xg, np, tri[3 * t + 1]),
                 *c = link_x(xo, xg, np, tri[3 * t + 2]);
    double u[3], v[3], n[3];
    for (int i = 0; i < 3; i++) u[i] = b[i] - a[i], v[i] = c[i] - a[i];
    pm_v_cross(u, v, n);
    double len = pm_v_norm(n);
    for (int i = 0; i < 3; i++) tn[3 * t + i] = len > 0 ? n[i] / len : 0;
  }
}

/* Each point's new unit normal into nn (3 per point of the group, holding
 * the previous normals n0 on entry; a point without one keeps n0), by its
 * body's method.  tn: 3 per triangle of the links.  The bodies' points are
 * the model's (across ranks, the rank's), their neighbours on other ranks
 * the ghosts. */
pm_err mpm_membrane_group_normals(const mpm_model *m, const mpm_group *gr,
                                  const double *x, long step, iso_work *iw,
                                  double *tn, double *nn, iso_stats *st) {
  const membrane_params *mp = gr->params;
  const long np = gr->end - gr->begin;
  const double *xo = x + 3 * gr->begin, *xg = mpm_xc_ghost_x(m, gr->index);
  if (mp->n_tris > 0) mpm_membrane_triangle_normals(mp, xo, xg, np, tn);
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    const long b0 = m->body_begin[b->body] - gr->begin,
               b1 = m->body_end[b->body] - gr->begin;
    if (b->method != PM_NORMALS_CONNECTIVITY) {
      iso_cells cells;
      mpm_xc_cells(m, cells.nn, cells.lo, cells.hi);
      if (m->xc)
        PM_CALL(mpm_membrane_fit_ranks(m, gr, b, &cells, iw, b0, b1, xo, step,
                                       nn, st));
      else
        PM_CALL(mpm_membrane_fit(&m->grid, &cells, iw, b->body, b->method,
                                 b1 - b0, xo + 3 * b0, step, nn + 3 * b0, st));
      continue;
    }
    if (b->links == MPM_LINKS_TRIANGLES) {
      for (long k = b0; k < b1; k++) {
        double n1[3];
        if (point_normal(mp, k, tn, n1)) memcpy(nn + 3 * k, n1, sizeof n1);
      }
      continue;
    }
    /* A curve: perpendicular to the chord of the neighbours (a point whose
     * chord vanishes gets 0, and the stress stage keeps its normal). */
    const long *link = mp->link;
    for (long k = b0; k < b1; k++)
      gm_curve_normal(link_x(xo, xg, np, link[2 * k]),
                      link_x(xo, xg, np, link[2 * k + 1]), nn + 3 * k);
  }
  return PM_SUCCESS;
}

static const char *const method_words[] = {
    "connectivity", "isosurface least squares, linear B-splines",
    "isosurface least squares, quadratic B-splines",
    "isosurface least squares, hybrid (quadratic, linear, or merged cells)",
    "isosurface least squares, hybrid-quadratic (quadratic on the smallest "
    "block of cells with enough points)"};

void mpm_membrane_describe_normals(const mpm_model *m, const mpm_group *g,
                                   char *buf, size_t size) {
  (void)m;
  const membrane_params *mp = g->params;
  size_t used = 0;
  for (int bi = 0; bi < mp->n_bodies && used < size; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    const char *how = method_words[b->method];
    if (b->method == PM_NORMALS_CONNECTIVITY)
      how = b->links == MPM_LINKS_TRIANGLES
                ? "mean of the triangles' (eq. 8)"
                : "perpendicular to the neighbours' "
                  "chord";
    int len = snprintf(buf + used, size - used, "%sbodies.%d: %s",
                       bi ? "; " : "", b->body, how);
    if (len < 0) break;
    used += (size_t)len;
  }
}

/* The normal stage: each point's new normal into the group's workspace. */
pm_err mpm_membrane_normals(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const int gi = self->group;
  const mpm_group *gr = &m->group[gi];
  const long np = gr->end - gr->begin;
  double *nn = w->scratch[gi], *tn = nn + 3 * np;
  const double *frame = s->group[gi].array[MEM_FRAME].data;
  for (long k = 0; k < np; k++)
    for (int d = 0; d < 3; d++) nn[3 * k + d] = frame[9 * k + 6 + d];
  iso_stats st = {0};
  pm_err e = mpm_membrane_group_normals(m, gr, s->x, s->step, w->kind_work[gi],
                                        tn, nn, &st);
  /* Across ranks each cell is fitted by one rank: the fits' figures are
   * the ranks' summed (every rank then keeps the run's, as one process). */
  double v[8] = {(double)st.cells[0], (double)st.cells[1],
                 (double)st.cells[2], (double)st.cells[3],
                 (double)st.points,   (double)st.degenerate,
                 (double)st.draws,    st.max_condition};
  if (m->xc && ((const membrane_params *)gr->params)->iso) {
    mpm_xc_sum(m, v, 7);
    mpm_xc_max(m, v + 7, 1);
  }
  if (e) return e;
  for (int i = 0; i < 4; i++) s->iso.cells[i] += v[i];
  s->iso.points += v[4];
  s->iso.degenerate += v[5];
  s->iso.draws += v[6];
  s->iso.max_condition = v[7];
  return PM_SUCCESS;
}
