/* pm_api_state: the state of a pointmech.h handle read back: points,
 * fields (copied into the caller's arrays), figures and reactions, during
 * a run (the observer's step) and after it. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "pm_api_impl.h"
#include "pm_backend.h"
#include "pm_error.h"
#include "pm_par.h"
#include "pm_view.h"

/* The simulation whose state is read: set up, and on rank 0 (the only one
 * holding the whole state across ranks). */
static pm_err readable(const pointmech *p, const char *what) {
  PM_CHECK(p, PM_ERR_ARG, "%s: p is NULL", what);
  PM_CHECK(p->sim, PM_ERR_ARG,
           "%s: no state yet (read during or after "
           "pointmech_run)",
           what);
  PM_CHECK(pm_par_root(), PM_ERR_ARG,
           "%s: across MPI ranks the state is read on rank 0", what);
  return PM_SUCCESS;
}

/* readable, and its arrays held whole on rank 0: not so across ranks with
 * frames and checkpoints in pieces (pm_view_whole_needed), where rank 0
 * holds its share and the run's figures alone. */
static pm_err readable_whole(const pointmech *p, const char *what) {
  PM_CALL(readable(p, what));
  PM_CHECK(!pm_par_active() || pm_view_whole_needed(p->s), PM_ERR_ARG,
           "%s: across MPI ranks with frames and checkpoints in pieces "
           "(output.ranks: auto or pieces) no rank holds the whole state "
           "(take output.ranks: gather)",
           what);
  return PM_SUCCESS;
}

long pointmech_point_count(const pointmech *p) {
  if (readable(p, "pointmech_point_count")) return 0;
  pm_points pts;
  p->s->backend->points(p->sim, &pts);
  return pts.n;
}

static pm_err points_impl(pointmech *p, double *xyz, size_t capacity) {
  PM_CALL(readable_whole(p, "pointmech_points"));
  pm_points pts;
  p->s->backend->points(p->sim, &pts);
  const size_t n = 3 * (size_t)pts.n;
  PM_CHECK(xyz && capacity >= n, PM_ERR_ARG,
           "pointmech_points: %zu doubles needed, %zu given", n, capacity);
  memcpy(xyz, pts.x, n * sizeof *xyz);
  return PM_SUCCESS;
}

/* Every field the state gives, into p->fields (borrowed until the next
 * call). */
static pm_err load_fields(pointmech *p, const char *what) {
  PM_CALL(readable_whole(p, what));
  const unsigned all = PM_FIELD_DISPLACEMENT | PM_FIELD_VELOCITY |
                       PM_FIELD_STRESS | PM_FIELD_STRAIN_ENERGY_DENSITY |
                       PM_FIELD_JACOBIAN | PM_FIELD_FORCE;
  p->n_fields = p->s->backend->fields(p->sim, all, p->fields, PM_API_FIELDS);
  return PM_SUCCESS;
}

int pointmech_field_count(pointmech *p) {
  return load_fields(p, "pointmech_field_count") ? 0 : p->n_fields;
}

const char *pointmech_field_name(pointmech *p, int k) {
  if (load_fields(p, "pointmech_field_name") || k < 0 || k >= p->n_fields)
    return NULL;
  return p->fields[k].name;
}

static pm_err find_field(pointmech *p, const char *name, const char *what,
                         const pm_field **f) {
  PM_CALL(load_fields(p, what));
  PM_CHECK(name, PM_ERR_ARG, "%s: name is NULL", what);
  char names[512] = "";
  for (int k = 0; k < p->n_fields; k++) {
    if (strcmp(p->fields[k].name, name) == 0) {
      *f = &p->fields[k];
      return PM_SUCCESS;
    }
    size_t len = strlen(names);
    snprintf(names + len, sizeof names - len, "%s%s", k ? ", " : "",
             p->fields[k].name);
  }
  return PM_ERROR(PM_ERR_ARG, "%s: no field %s (expected one of: %s)", what,
                  name, names);
}

static pm_err field_components_impl(pointmech *p, const char *name,
                                    int *components) {
  const pm_field *f = NULL;
  PM_CALL(find_field(p, name, "pointmech_field_components", &f));
  PM_CHECK(components, PM_ERR_ARG, "pointmech_field_components: NULL");
  *components = f->ncomp;
  return PM_SUCCESS;
}

static pm_err field_read_impl(pointmech *p, const char *name, double *dst,
                              size_t capacity) {
  const pm_field *f = NULL;
  PM_CALL(find_field(p, name, "pointmech_field_read", &f));
  pm_points pts;
  p->s->backend->points(p->sim, &pts);
  const size_t n = (size_t)pts.n * (size_t)f->ncomp;
  PM_CHECK(dst && capacity >= n, PM_ERR_ARG,
           "pointmech_field_read %s: %zu doubles needed, %zu given", name, n,
           capacity);
  memcpy(dst, f->data, n * sizeof *dst);
  return PM_SUCCESS;
}

/* The figures by their names in summary.json. */
typedef struct {
  const char *name;
  size_t offset;
  bool count;  /* a long, not a double */
  bool fields; /* a figure of the fields (costs a pass over them) */
} figure_entry;

#define FIG(n, m, c, f)                                                        \
  { n, offsetof(pm_figures, m), c, f }
static const figure_entry figures[] = {
    FIG("time", time, false, false),
    FIG("steps", steps, true, false),
    FIG("points", points, true, false),
    FIG("h", h, false, false),
    FIG("dt", dt, false, false),
    FIG("residual", residual, false, false),
    FIG("kinetic_energy", kinetic, false, false),
    FIG("strain_energy", strain, false, false),
    FIG("internal_energy", internal, false, false),
    FIG("external_work", external_work, false, false),
    FIG("dissipated", dissipated, false, false),
    FIG("energy_balance_error", energy_error, false, false),
    FIG("min_jacobian", min_jacobian, false, false),
    FIG("mean_strain_energy_density", mean_sed, false, true),
    FIG("max_von_mises", max_von_mises, false, true),
};
#undef FIG

/* The figures now: the run's outcome after it, the state's during it. */
static pm_err current_figures(pointmech *p, bool fields, pm_figures *f,
                              const char *what) {
  /* (the field figures during a run read the whole state) */
  PM_CALL(fields && p->running ? readable_whole(p, what) : readable(p, what));
  if (p->running)
    p->s->backend->figures(p->sim, f, fields);
  else
    *f = p->o.fig;
  return PM_SUCCESS;
}

static pm_err figure_impl(pointmech *p, const char *name, double *value) {
  PM_CHECK(name && value, PM_ERR_ARG, "pointmech_figure: NULL argument");
  const size_t n = sizeof figures / sizeof figures[0];
  for (size_t k = 0; k < n; k++) {
    if (strcmp(figures[k].name, name) != 0) continue;
    pm_figures f;
    PM_CALL(current_figures(p, figures[k].fields, &f, "pointmech_figure"));
    const char *at = (const char *)&f + figures[k].offset;
    *value = figures[k].count ? (double)*(const long *)at : *(const double *)at;
    return PM_SUCCESS;
  }
  return PM_ERROR(PM_ERR_ARG,
                  "pointmech_figure: no figure %s (time, steps, points, h, "
                  "dt, residual, kinetic_energy, strain_energy, "
                  "internal_energy, external_work, dissipated, "
                  "energy_balance_error, min_jacobian, "
                  "mean_strain_energy_density, max_von_mises)",
                  name);
}

static pm_err reaction_impl(pointmech *p, const char *label, double force[3]) {
  PM_CHECK(label && force, PM_ERR_ARG, "pointmech_reaction: NULL argument");
  pm_figures f;
  PM_CALL(current_figures(p, false, &f, "pointmech_reaction"));
  const pm_scene *s = p->s;
  char names[512] = "";
  for (int b = 0; b < s->n_bcs && b < PM_FIGURES_MAX_BCS; b++) {
    if (!(s->bcs[b].disp_mask | s->bcs[b].velocity_mask)) continue;
    char mine[32];
    pm_run_bc_label(s, b, mine, sizeof mine);
    if (strcmp(mine, label) == 0) {
      memcpy(force, f.reaction[b], 3 * sizeof *force);
      return PM_SUCCESS;
    }
    size_t len = strlen(names);
    snprintf(names + len, sizeof names - len, "%s%s", len ? ", " : "", mine);
  }
  return PM_ERROR(PM_ERR_ARG,
                  "pointmech_reaction: no prescribed condition %s (expected "
                  "one of: %s)",
                  label, names);
}

/* The interface's functions: the codes are pm_err's numbers. */
pointmech_code pointmech_points(pointmech *p, double *xyz, size_t capacity) {
  return pm_api_code(points_impl(p, xyz, capacity));
}

pointmech_code pointmech_field_components(pointmech *p, const char *name,
                                          int *components) {
  return pm_api_code(field_components_impl(p, name, components));
}

pointmech_code pointmech_field_read(pointmech *p, const char *name, double *dst,
                                    size_t capacity) {
  return pm_api_code(field_read_impl(p, name, dst, capacity));
}

pointmech_code pointmech_figure(pointmech *p, const char *name, double *value) {
  return pm_api_code(figure_impl(p, name, value));
}

pointmech_code pointmech_reaction(pointmech *p, const char *label,
                                  double force[3]) {
  return pm_api_code(reaction_impl(p, label, force));
}
