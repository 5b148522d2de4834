/* pm_run_history: the run's history.csv (its columns and one row per
 * frame, with the frame itself) and the errors against the scene's
 * reference field. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_metrics.h"
#include "pm_output.h"
#include "pm_run_impl.h"
#include "pm_view.h"

#define RUN_FIELDS 16

/* The shared history columns, in order. */
static const char *const shared_cols[] = {
    "time",           "step",          "wall_seconds",    "dt",
    "kinetic_energy", "strain_energy", "internal_energy", "interface_energy",
    "external_work",  "dissipated",    "energy_error",    "residual",
    "min_jacobian"};
#define N_SHARED ((int)(sizeof shared_cols / sizeof *shared_cols))

/* ---- errors against the scene's reference field ------------------------- */

/* Serial: an expression is not thread-safe. */
void pm_run_fill_reference(pm_run_ctx *c, double t) {
  const pm_scene *s = c->s;
  for (int k = 0; k < 3; k++) {
    if (!(s->reference_mask >> k & 1u)) continue;
    for (long i = 0; i < c->pts.n; i++) {
      const double *X = c->pts.x + 3 * i;
      c->ref[3 * i + k] = pm_expr_eval(s->reference[k], X[0], X[1], X[2], t);
    }
  }
}

/* NRMSE (eq. 28) of each reference component, and of the field: one
 * component's own, or the vector form over the largest |reference|. */
void pm_run_compute_errors(pm_run_ctx *c, double t) {
  pm_outcome *o = c->o;
  const unsigned mask = c->s->reference_mask;
  int n_ref = 0;
  for (int k = 0; k < 3; k++) o->nrmse[k] = NAN;
  o->nrmse_vector = NAN;
  if (!c->ref) { /* across ranks without the whole displacement */
    if (mask && c->be->errors)
      c->be->errors(c->sim, o->nrmse, &o->nrmse_vector);
    return;
  }
  if (c->ref_time) pm_run_fill_reference(c, t);
  const double *u = c->be->displacement(c->sim);
  for (int k = 0; k < 3; k++) {
    if (!(mask >> k & 1u)) continue;
    o->nrmse[k] = pm_nrmse(c->pts.n, 3, u + k, c->ref + k);
    o->nrmse_vector = o->nrmse[k];
    n_ref++;
  }
  if (n_ref > 1) o->nrmse_vector = pm_nrmse_vector(c->pts.n, mask, u, c->ref);
}

/* ---- history ------------------------------------------------------------ */

static void add_col(pm_run_ctx *c, const char *name) {
  snprintf(c->names_buf[c->n_cols], sizeof c->names_buf[0], "%s", name);
  c->names[c->n_cols] = c->names_buf[c->n_cols];
  c->react_bc[c->n_cols] = -1;
  c->n_cols++;
}

/* A name for boundary condition b in columns and the summary. */
void pm_run_bc_label(const pm_scene *s, int b, char *buf, size_t size) {
  if (s->bcs[b].on == PM_ON_REGION)
    snprintf(buf, size, "boundary.%d", b);
  else
    snprintf(buf, size, "%s", s->bcs[b].surface);
}

pm_err pm_run_setup_columns(pm_run_ctx *c) {
  const pm_scene *s = c->s;
  const char *own[PM_HISTORY_MAX];
  for (int k = 0; k < N_SHARED; k++) add_col(c, shared_cols[k]);
  c->n_own = c->be->history_names
                 ? c->be->history_names(c->sim, own, PM_HISTORY_MAX)
                 : 0;
  for (int k = 0; k < c->n_own; k++) add_col(c, own[k]);
  PM_CHECK(s->n_bcs <= PM_FIGURES_MAX_BCS, PM_ERR_SCENE,
           "%s: boundary: expected at most %d conditions, got %d", s->path,
           PM_FIGURES_MAX_BCS, s->n_bcs);
  for (int b = 0; b < s->n_bcs; b++) {
    unsigned mask = s->bcs[b].disp_mask | s->bcs[b].velocity_mask;
    for (int k = 0; k < 3; k++) {
      if (!(mask >> k & 1u)) continue;
      char label[32], name[48];
      pm_run_bc_label(s, b, label, sizeof label);
      snprintf(name, sizeof name, "reaction_%s_%c", label, "xyz"[k]);
      add_col(c, name);
      c->react_bc[c->n_cols - 1] = b;
      c->react_comp[c->n_cols - 1] = k;
    }
  }
  for (int k = 0; k < 3; k++)
    if (s->reference_mask >> k & 1u) {
      char name[16];
      snprintf(name, sizeof name, "nrmse_u_%c", "xyz"[k]);
      add_col(c, name);
    }
  return PM_SUCCESS;
}

static pm_err write_row(pm_run_ctx *c) {
  pm_figures f;
  memset(&f, 0, sizeof f);
  c->be->figures(c->sim, &f, false);
  double *row = c->row;
  const double shared[N_SHARED] = {
      f.time,        (double)f.steps, pm_wtime() - c->t_start,
      f.dt,          f.kinetic,       f.strain,
      f.internal,    f.interface,     f.external_work,
      f.dissipated,  f.energy_error,  f.residual,
      f.min_jacobian};
  int k = 0;
  for (; k < N_SHARED; k++) row[k] = shared[k];
  if (c->n_own) c->be->history_values(c->sim, row + k);
  k += c->n_own;
  for (; k < c->n_cols && c->react_bc[k] >= 0; k++)
    row[k] = f.reaction[c->react_bc[k]][c->react_comp[k]];
  if (c->s->reference_mask) {
    pm_run_compute_errors(c, f.time);
    for (int comp = 0; comp < 3; comp++)
      if (c->s->reference_mask >> comp & 1u) row[k++] = c->o->nrmse[comp];
  }
  PM_CALL(pm_history_row(c->history, row));
  PM_CALL(pm_history_sync(c->history));
  c->history_rows++;
  return PM_SUCCESS;
}

pm_err pm_run_write_frame(pm_run_ctx *c, const pm_step_report *r) {
  /* Across ranks with frames in pieces, the ranks have written theirs. */
  const pm_view_pieces *pc = c->be->pieces ? c->be->pieces(c->sim) : NULL;
  if (pc) {
    PM_CALL(pm_results_join_pieces(c->results, r->step, r->t, pc->n, pc->counts,
                                   pc->n_fields, pc->fields));
    return write_row(c);
  }
  pm_field fields[RUN_FIELDS];
  int nf = c->be->fields(c->sim, c->s->output.fields, fields, RUN_FIELDS);
  PM_CALL(pm_results_write_frame(c->results, r->step, r->t, nf, fields));
  return write_row(c);
}
