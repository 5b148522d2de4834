/* mpm_history: the history columns of an MPM simulation of its own (bodies'
 * mass inside surfaces, pressures, normals' fits) and their values. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "gm_inside.h"
#include "gm_shape.h"
#include "pm_omp.h"

/* History columns: the energy iterations (kinds that iterate); each named
 * volume body's centroid displacement; with membranes, the failed points;
 * for each body inside or outside a membrane, the mass of its particles
 * that lies inside the membrane's current surface (does fluid leak
 * through?). */
static void add_hist(mpm_sim *r, const char *fmt, const char *a,
                     const char *b) {
  if (r->n_hist >= PM_HISTORY_MAX) return;
  snprintf(r->hist_store[r->n_hist], sizeof r->hist_store[0], fmt, a, b);
  r->hist_names[r->n_hist] = r->hist_store[r->n_hist];
  r->n_hist++;
}

/* The kind of scene body b's particles. */
static const mpm_kind *body_kind(const mpm_model *m, int b) {
  for (int gi = 0; gi < m->n_groups; gi++)
    if (m->body_begin[b] >= m->group[gi].begin &&
        m->body_end[b] <= m->group[gi].end)
      return m->group[gi].kind;
  return m->group[0].kind;
}

/* Whether some membrane's normals come by isosurface least squares. */
static bool iso_normals_used(const mpm_model *m) {
  for (int b = 0; b < m->n_bodies; b++)
    if (m->body_end[b] > m->body_begin[b] &&
        m->body_normals[b] != PM_NORMALS_CONNECTIVITY)
      return true;
  return false;
}

pm_err mpm_sim_history_setup(mpm_sim *r) {
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  r->n_hist = 0;
  PM_CALL(PM_ALLOC(r->surface, s->n_bodies, "membrane surfaces"));
  if (r->imp) {
    add_hist(r, "newton_iterations%s%s", "", "");
    add_hist(r, "linear_iterations%s%s", "", "");
    add_hist(r, "load_cuts%s%s", "", "");
  }
  if (m->kinds & MPM_KIND_ITERATES) {
    add_hist(r, "energy_iterations%s%s", "", "");
    add_hist(r, "energy_iterations_capped%s%s", "", "");
  }
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if (!body->name || body->shape == PM_BODY_MEMBRANE ||
        m->body_end[b] == m->body_begin[b])
      continue;
    for (int c = 0; c < m->dim; c++)
      add_hist(r, "%s_u%s", body->name, (const char[]){"xyz"[c], 0});
    if (body_kind(m, b)->flags & MPM_KIND_INTERNAL_ENERGY)
      add_hist(r, "%s_pressure%s", body->name, "");
  }
  if (m->kinds & MPM_KIND_MEMBRANE) add_hist(r, "failed_points%s%s", "", "");
  if (iso_normals_used(m)) {
    add_hist(r, "normals_max_condition%s%s", "", "");
    add_hist(r, "normals_degenerate%s%s", "", "");
    add_hist(r, "normals_merged_cells%s%s", "", "");
  }
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if ((body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE) &&
        m->body_end[b] > m->body_begin[b]) {
      const int mb = body->surface_body;
      add_hist(r, "mass_inside_%s_%s", s->bodies[mb].name,
               body->name ? body->name : s->materials[body->material].name);
      if (!r->surface[mb] && m->dim == 3)
        PM_CALL(mpm_triangles_local(m, m->body_tri_begin[mb],
                                    m->body_tri_end[mb], m->body_begin[mb],
                                    &r->surface[mb]));
    }
  }
  return PM_SUCCESS;
}

int mpm_sim_history_names(void *p, const char **names, int max) {
  mpm_sim *r = p;
  int n = r->n_hist < max ? r->n_hist : max;
  for (int k = 0; k < n; k++) names[k] = r->hist_names[k];
  return n;
}

/* In 2D: inside the region membrane body mb's curve encloses now. */
static double mass_inside_curve(const mpm_sim *r, int b, int mb) {
  const mpm_model *m = r->model;
  const double *x = r->state->x;
  gm_shape *in = NULL;
  if (gm_shape_from_curve(m->body_end[mb] - m->body_begin[mb],
                          x + 3 * m->body_begin[mb],
                          m->body_links[mb] == MPM_LINKS_LOOP, m->box_min,
                          m->box_max, false, &in) != PM_SUCCESS)
    return NAN;
  double sum = 0;
  for (long q = m->body_begin[b]; q < m->body_end[b]; q++)
    if (gm_shape_contains(in, x + 3 * q)) sum += m->mass[q];
  gm_shape_destroy(in);
  return sum;
}

/* The mass of body b's particles inside membrane body mb's current
 * surface (NAN when it cannot be built).  The inside test is built anew
 * for each history row: the surface moves. */
static double mass_inside(const mpm_sim *r, int b, int mb) {
  const mpm_model *m = r->model;
  const double *x = r->state->x;
  if (m->dim == 2) return mass_inside_curve(r, b, mb);
  const gm_trisurf sf = {.n_points = m->body_end[mb] - m->body_begin[mb],
                         .x = (double *)(x + 3 * m->body_begin[mb]),
                         .n_tris = m->body_tri_end[mb] - m->body_tri_begin[mb],
                         .tri = r->surface[mb]};
  gm_inside *in = NULL;
  if (gm_inside_create(&sf, &in) != PM_SUCCESS) return NAN;
  double sum = 0;
  const long begin = m->body_begin[b], end = m->body_end[b];
  const double *mp = m->mass;
  PM_OMP(parallel for schedule(static) default(none)
         shared(in, x, mp, begin, end) reduction(+ : sum))
  for (long q = begin; q < end; q++)
    if (gm_inside_contains(in, x + 3 * q)) sum += mp[q];
  gm_inside_destroy(in);
  return sum;
}

/* The mean pressure of body b's particles, weighted by their volumes. */
static double body_pressure(const mpm_sim *r, int b) {
  const mpm_model *m = r->model;
  const mpm_state *st = r->state;
  double *sed = r->scratch, *p = sed + m->n, *e = p + m->n, pv = 0, v = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    if (m->body_begin[b] < g->begin || m->body_end[b] > g->end) continue;
    g->kind->fields(m, st, g, sed, p, e);
  }
  for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
    pv += p[q] * st->vol[q];
    v += st->vol[q];
  }
  return v > 0 ? pv / v : 0;
}

void mpm_sim_history_values(void *p, double *v) {
  mpm_sim *r = p;
  const mpm_model *m = r->model;
  const pm_scene *s = r->scene;
  const mpm_state *st = r->state;
  int k = 0;
  if (r->imp) {
    v[k++] = r->imp_newton;
    v[k++] = r->imp_linear;
    v[k++] = mpm_implicit_report(r->imp)->cuts;
  }
  if (m->kinds & MPM_KIND_ITERATES) {
    v[k++] = r->iter_max_row;
    v[k++] = (double)(st->iter_capped_total - r->iter_capped_prev);
    r->iter_capped_prev = st->iter_capped_total;
    r->iter_max_row = 0;
  }
  for (int b = 0; b < s->n_bodies && k < r->n_hist; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if (!body->name || body->shape == PM_BODY_MEMBRANE ||
        m->body_end[b] == m->body_begin[b])
      continue;
    double u[3] = {0, 0, 0}, mt = 0;
    for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
      for (int c = 0; c < 3; c++)
        u[c] += m->mass[q] * (st->x[3 * q + c] - m->x0[3 * q + c]);
      mt += m->mass[q];
    }
    for (int c = 0; c < m->dim; c++) v[k++] = u[c] / mt;
    if (body_kind(m, b)->flags & MPM_KIND_INTERNAL_ENERGY)
      v[k++] = body_pressure(r, b);
  }
  if (m->kinds & MPM_KIND_MEMBRANE) {
    double *normal = r->scratch + 12 * m->n, *damage = normal + 3 * m->n,
           *failed = damage + m->n, nf = 0;
    memset(failed, 0, sizeof(double) * (size_t)m->n);
    for (int gi = 0; gi < m->n_groups; gi++)
      if (m->group[gi].kind->surface_fields)
        m->group[gi].kind->surface_fields(m, st, &m->group[gi], normal, damage,
                                          failed);
    for (long q = 0; q < m->n; q++) nf += failed[q];
    v[k++] = nf;
  }
  if (iso_normals_used(m)) {
    v[k++] = st->iso.max_condition;
    v[k++] = st->iso.degenerate;
    v[k++] = st->iso.cells[2] + st->iso.cells[3];
  }
  for (int b = 0; b < s->n_bodies && k < r->n_hist; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if ((body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE) &&
        m->body_end[b] > m->body_begin[b])
      v[k++] = mass_inside(r, b, body->surface_body);
  }
}
