/* mpm_history: the history columns of an MPM simulation of its own (bodies'
 * mass inside surfaces, pressures, normals' fits) and their values. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_par.h"
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

/* The whole run's ranges on one process: m's own (its groups' into gb,
 * ge), or across ranks without the whole model those its share knows
 * (mpm_par_whole_ranges). */
typedef struct {
  mpm_par_ranges w;
  long gb[MPM_MAX_GROUPS], ge[MPM_MAX_GROUPS];
} ranges;

static void whole_ranges(const mpm_sim *r, ranges *rg) {
  const mpm_model *m = r->model;
  mpm_par_ranges *w = &rg->w;
  long *gb = rg->gb, *ge = rg->ge;
  if (!m) {
    mpm_par_whole_ranges(r->local_model, w);
    return;
  }
  for (int gi = 0; gi < m->n_groups; gi++) {
    gb[gi] = m->group[gi].begin;
    ge[gi] = m->group[gi].end;
  }
  *w = (mpm_par_ranges){.n = m->n,
                        .gbegin = gb,
                        .gend = ge,
                        .bbegin = m->body_begin,
                        .bend = m->body_end};
}

/* The kind of scene body b's particles (m: a model of the run, the whole
 * or a share; w: the whole run's ranges). */
static const mpm_kind *body_kind(const mpm_model *m, const mpm_par_ranges *w,
                                 int b) {
  for (int gi = 0; gi < m->n_groups; gi++)
    if (w->bbegin[b] >= w->gbegin[gi] && w->bend[b] <= w->gend[gi])
      return m->group[gi].kind;
  return m->group[0].kind;
}

/* Whether body b has a history column of its own: a named volume body
 * with particles. */
static bool body_column(const pm_scene *s, const mpm_par_ranges *w, int b) {
  const pm_scene_body *body = &s->bodies[b];
  return body->name && body->shape != PM_BODY_MEMBRANE &&
         w->bend[b] > w->bbegin[b];
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
  const mpm_model *m = r->model ? r->model : r->local_model;
  const pm_scene *s = r->scene;
  ranges rg;
  whole_ranges(r, &rg);
  const mpm_par_ranges w = rg.w;
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
    if (!body_column(s, &w, b)) continue;
    for (int c = 0; c < m->dim; c++)
      add_hist(r, "%s_u%s", body->name, (const char[]){"xyz"[c], 0});
    if (body_kind(m, &w, b)->flags & MPM_KIND_INTERNAL_ENERGY)
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
        w.bend[b] > w.bbegin[b]) {
      const int mb = body->surface_body;
      add_hist(r, "mass_inside_%s_%s", s->bodies[mb].name,
               body->name ? body->name : s->materials[body->material].name);
      /* (a membrane keeps the whole model: pm_view_whole_needed) */
      if (!r->surface[mb] && m->dim == 3 && r->model)
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

void mpm_sim_body_sums(const mpm_model *m, const mpm_state *st, double *scratch,
                       int b, bool pressure, double *out) {
  double u[3] = {0, 0, 0}, mt = 0, pv = 0, v = 0;
  for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
    for (int c = 0; c < 3; c++)
      u[c] += m->mass[q] * (st->x[3 * q + c] - m->x0[3 * q + c]);
    mt += m->mass[q];
  }
  if (pressure) {
    double *sed = scratch, *p = sed + m->n, *e = p + m->n;
    for (int gi = 0; gi < m->n_groups; gi++) {
      const mpm_group *g = &m->group[gi];
      if (m->body_begin[b] < g->begin || m->body_end[b] > g->end) continue;
      g->kind->fields(m, st, g, sed, p, e);
    }
    for (long q = m->body_begin[b]; q < m->body_end[b]; q++) {
      pv += p[q] * st->vol[q];
      v += st->vol[q];
    }
  }
  const double sums[MPM_SUMS_BODY] = {u[0], u[1], u[2], mt, pv, v};
  memcpy(out, sums, sizeof sums);
}

void mpm_sim_history_values(void *p, double *v) {
  mpm_sim *r = p;
  const mpm_model *m = r->model ? r->model : r->local_model;
  const pm_scene *s = r->scene;
  const mpm_state *st = r->state;
  ranges rg;
  whole_ranges(r, &rg);
  const mpm_par_ranges w = rg.w;
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
    if (!body_column(s, &w, b)) continue;
    const bool pressure = body_kind(m, &w, b)->flags & MPM_KIND_INTERNAL_ENERGY;
    /* summed over the shares already where no rank keeps the whole */
    double own[MPM_SUMS_BODY];
    const double *u = r->sums.body + MPM_SUMS_BODY * b;
    if (r->model) {
      mpm_sim_body_sums(m, st, r->scratch, b, pressure, own);
      u = own;
    }
    for (int c = 0; c < m->dim; c++) v[k++] = u[c] / u[3];
    if (pressure) v[k++] = u[5] > 0 ? u[4] / u[5] : 0;
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
