/* mpm_view_sums: rank 0's figures of an MPM run across ranks that keeps no
 * whole model (pm_view_whole_needed false): the energies and accounts, the
 * bodies' history columns and the end's field figures, summed (or their
 * extreme taken) over the ranks' shares where a run that keeps the whole
 * model gathers the shares into it.  The sums are a rank's share's, then
 * the ranks' (pm_par_sum), so they agree with one process's to round-off. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_par.h"
#include "pm_metrics.h"
#include "pm_par.h"

/* The buffer: the energies (3), the accounts (MPM_PAR_ACCOUNTS), the
 * bodies' sums (MPM_SUMS_BODY each), the fields' sums (2), the squared
 * differences from each reference component (3). */
static long sums_size(const pm_scene *s) {
  return 3 + MPM_PAR_ACCOUNTS + MPM_SUMS_BODY * s->n_bodies + 2 + 3;
}

/* The share's part of the errors against the scene's reference field at
 * time t (pm_nrmse_part).  Serial: an expression is not thread-safe. */
static void reference_sums(const mpm_model *m, const mpm_state *st,
                           const pm_scene *s, double t, pm_nrmse_part *p) {
  const unsigned mask = s->reference_mask;
  for (long q = 0; q < m->n; q++) {
    const double *X = m->x0 + 3 * q;
    double u[3], ref[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
      u[k] = st->x[3 * q + k] - X[k];
      if (mask >> k & 1u)
        ref[k] = pm_expr_eval(s->reference[k], X[0], X[1], X[2], t);
    }
    pm_nrmse_part_add(p, mask, u, ref);
  }
}

bool mpm_sim_errors(void *p, double nrmse[3], double *vector) {
  const mpm_sim *r = p;
  if (r->whole) return false;
  memcpy(nrmse, r->sums.nrmse, sizeof r->sums.nrmse);
  *vector = r->sums.nrmse_vector;
  return true;
}

pm_err mpm_view_sums_setup(mpm_sim *r) {
  const mpm_model *lm = r->local_model;
  mpm_par_ranges w;
  mpm_par_whole_ranges(lm, &w);
  r->sums.n = w.n;
  for (int k = 0; k < 3; k++) r->sums.nrmse[k] = NAN;
  r->sums.nrmse_vector = NAN;
  const mpm_decomp *d = mpm_par_decomp(lm);
  r->sums.grid_nodes = 1;
  for (int a = 0; a < lm->dim; a++) /* (cells: the nodes' less one) */
    r->sums.grid_nodes *= d->cells[a] + 1;
  pm_err e = PM_ALLOC(r->sums.buf, sums_size(r->scene), "the run's sums");
  if (!e)
    e = PM_ALLOC(r->sums.body, MPM_SUMS_BODY * r->scene->n_bodies + 1,
                 "the bodies' sums");
  if (!e && pm_par_root()) {
    e = PM_ALLOC(r->state, 1, "the run's scalars");
    if (!e) mpm_state_copy_values(r->state, r->local_state);
    /* (the implicit solver's figures are every rank's already) */
    if (!e && !r->work) e = mpm_sim_figures_work(lm, &r->work);
  }
  PM_CALL(pm_par_agree(e));
  return mpm_par_gather_x0(lm, &r->mesh_x0);
}

pm_err mpm_view_sum(mpm_sim *r, bool fields) {
  const mpm_model *lm = r->local_model;
  const mpm_state *ls = r->local_state;
  const pm_scene *s = r->scene;
  enum { n_acc = MPM_PAR_ACCOUNTS };
  const long n = sums_size(s);
  double *v = r->sums.buf, *acc = v + 3, *body = acc + n_acc,
         *field = body + MPM_SUMS_BODY * s->n_bodies, *d2 = field + 2;
  pm_nrmse_part part;
  pm_nrmse_part_init(&part);
  PM_CALL(pm_par_agree(mpm_sim_share_scratch(r, ls->step)));
  memset(v, 0, sizeof *v * (size_t)n);
  mpm_energies(lm, ls, v, v + 1, v + 2);
  memcpy(acc, ls->energy, sizeof ls->energy);
  acc[n_acc - 2] = ls->external_work;
  acc[n_acc - 1] = ls->dissipated;
  const bool pressure = lm->kinds & MPM_KIND_INTERNAL_ENERGY;
  for (int b = 0; b < s->n_bodies; b++)
    if (s->bodies[b].shape != PM_BODY_MEMBRANE)
      mpm_sim_body_sums(lm, ls, r->share_scratch, b, pressure,
                        body + MPM_SUMS_BODY * b);
  mpm_sums own;
  long at[2] = {0, 0};
  if (fields) {
    mpm_sim_field_sums(lm, ls, r->share_scratch, &own, at);
    field[0] = own.sed_volume;
    field[1] = own.volume0;
  }
  if (s->reference_mask) {
    reference_sums(lm, ls, s, ls->t, &part);
    memcpy(d2, part.d2, sizeof part.d2); /* (summed with the rest) */
    pm_par_min(part.lo, 3);
    pm_par_max(part.hi, 3);
    pm_par_max(&part.most, 1);
  }
  pm_par_sum(v, (int)n);
  if (fields) {
    mpm_par_extreme(lm, &own.max_von_mises, at[0], own.max_von_mises_at, true);
    mpm_par_extreme(lm, &own.min_jacobian, at[1], own.min_jacobian_at, false);
  }
  if (!pm_par_root()) return PM_SUCCESS;
  mpm_sums *u = &r->sums;
  u->kinetic = v[0];
  u->strain = v[1];
  u->internal = v[2];
  memcpy(u->body, body, sizeof *body * MPM_SUMS_BODY * (size_t)s->n_bodies);
  if (s->reference_mask) {
    memcpy(part.d2, d2, sizeof part.d2);
    pm_nrmse_parts(&part, u->n, s->reference_mask, u->nrmse, &u->nrmse_vector);
  }
  if (fields) {
    u->sed_volume = field[0];
    u->volume0 = field[1];
    u->max_von_mises = own.max_von_mises;
    u->min_jacobian = own.min_jacobian;
    memcpy(u->max_von_mises_at, own.max_von_mises_at,
           sizeof own.max_von_mises_at);
    memcpy(u->min_jacobian_at, own.min_jacobian_at, sizeof own.min_jacobian_at);
  }
  /* The run's scalars are rank 0's share's (every rank's agree), its
   * accounts the ranks' sums, as mpm_par_gather makes them. */
  mpm_state *st = r->state;
  mpm_state_copy_values(st, ls);
  memcpy(st->energy, acc, sizeof st->energy);
  st->external_work = acc[n_acc - 2];
  st->dissipated = acc[n_acc - 1];
  return PM_SUCCESS;
}
