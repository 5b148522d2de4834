/* fpm_view_sums: rank 0's figures of an FPM run across ranks that keeps no
 * whole model (pm_view_whole_needed false): the reactions, the supports'
 * conditioning, the errors against the scene's reference field and the
 * end's field figures, summed (or their extremes taken) over the ranks'
 * own points where a gathered run reads them of the whole model; the
 * whole model's counts for the summary; the reference positions for
 * results/mesh.h5.  A sum is a share's, in one process's order, then the
 * ranks' (pm_par_sum), so it agrees with one process's to round-off; an
 * extreme is one process's, the first in its order among equal values. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend_impl.h"
#include "fpm_gfd.h"
#include "fpm_par.h"
#include "pm_metrics.h"
#include "pm_par.h"
#include "pm_tensor.h"

/* The share's own points fitted over two rings (their fit holds more
 * points than their support) and those left linear (no quadratic weight
 * in their fit), as the whole model counts them (fpm_model.n_qwide,
 * n_qlinear). */
static void own_fits(const fpm_model *m, long *wide, long *linear) {
  *wide = *linear = 0;
  if (!m->q) return;
  for (long i = 0; i < m->n_own; i++) {
    *wide +=
        m->qs_ptr[i + 1] - m->qs_ptr[i] > m->nbr_ptr[i + 1] - m->nbr_ptr[i];
    bool quadratic = false;
    for (long e = m->qs_ptr[i]; e < m->qs_ptr[i + 1] && !quadratic; e++)
      for (int a = 3; a < FPM_QFIT; a++)
        quadratic |= m->q[FPM_QFIT * e + a] != 0;
    *linear += !quadratic;
  }
}

/* Support pairs from the share's own points to points of other ranks (its
 * ghosts), each counted from its point of lower index, as
 * fpm_partition_edge_cut counts them over the whole model. */
static long own_edge_cut(const fpm_model *m) {
  long cut = 0;
  for (long i = 0; i < m->n_own; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const long k = m->nbr[e];
      cut += k >= m->n_own && m->gid[k] > m->gid[i];
    }
  return cut;
}

pm_err fpm_view_sums_setup(fpm_sim *sim, const long whole_counts[3]) {
  const fpm_model *lm = sim->local_model;
  fpm_sums *u = &sim->sums;
  const long n_own = lm->n_own, rows = lm->nbr_ptr[n_own];
  pm_err e = PM_SUCCESS;
  u->cells = whole_counts[0];
  u->interfaces = whole_counts[1];
  u->facets = whole_counts[2];
  long counts[4] = {lm->n_cdofs, 0, 0, own_edge_cut(lm)};
  own_fits(lm, &counts[1], &counts[2]);
  pm_par_sum_long(counts, 4);
  u->cdofs = counts[0];
  u->qwide = counts[1];
  u->qlinear = counts[2];
  u->edge_cut = counts[3];
  for (int k = 0; k < 3; k++) u->nrmse[k] = NAN;
  u->nrmse_vector = NAN;
  /* The supports' rows of the own points as the conditioning reads them
   * (the share keeps its neighbours in 32 bits). */
  e = PM_ALLOC(sim->own_nbr, rows + 1, "the share's supports");
  for (long k = 0; !e && k < rows; k++) sim->own_nbr[k] = lm->nbr[k];
  if (!e && !sim->share_scratch)
    e = PM_ALLOC(sim->share_scratch, 14 * n_own + 1, "the share's output");
  if (!e && pm_par_root())
    e = PM_ALLOC(sim->mesh_x, 3 * sim->n_whole, "the points' positions");
  PM_CALL(pm_par_agree(e));
  return fpm_par_gather_points(lm, lm->x, sim->mesh_x);
}

/* The share's part of the errors against the scene's reference field at
 * time t (pm_nrmse_part).  Serial: an expression is not thread-safe. */
static void reference_part(const fpm_model *m, const fpm_state *st,
                           const pm_scene *s, double t, pm_nrmse_part *p) {
  const unsigned mask = s->reference_mask;
  pm_nrmse_part_init(p);
  for (long i = 0; i < m->n_own; i++) {
    const double *X = m->x + 3 * i;
    double ref[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++)
      if (mask >> k & 1u)
        ref[k] = pm_expr_eval(s->reference[k], X[0], X[1], X[2], t);
    pm_nrmse_part_add(p, mask, st->u + 3 * i, ref);
  }
}

bool fpm_backend_errors(void *p, double nrmse[3], double *vector) {
  const fpm_sim *sim = p;
  if (sim->whole) return false;
  memcpy(nrmse, sim->sums.nrmse, sizeof sim->sums.nrmse);
  *vector = sim->sums.nrmse_vector;
  return true;
}

/* The extreme over the ranks of each rank's value *v at its own point of
 * one-process index id (largest, or with most false smallest; own outside
 * the share's points: none): the first in one process's order among equal
 * values, its position into at and, where carry is not NULL, the value
 * *carry of the rank that has it into *carry, on every rank
 * (collective). */
static void extreme(const fpm_model *m, double *v, long own, bool most,
                    double at[3], double *carry) {
  double best = most ? *v : -*v;
  pm_par_max(&best, 1);
  const bool has = own >= 0 && own < m->n_own; /* (a share may own none) */
  const long id = has ? m->gid[own] : LONG_MAX;
  long first = has && (most ? *v : -*v) == best ? -id : -LONG_MAX;
  pm_par_max_long(&first, 1);
  const bool mine = has && -first == id;
  double buf[4];
  for (int a = 0; a < 3; a++) buf[a] = mine ? m->x[3 * own + a] : 0;
  buf[3] = mine && carry ? *carry : 0;
  /* (the one rank's position and value, plus zeros) */
  pm_par_sum(buf, carry ? 4 : 3);
  for (int a = 0; a < 3; a++) at[a] = buf[a];
  if (carry) *carry = buf[3];
  *v = most ? best : -best;
}

/* The end's field figures: the solids' mean strain energy density, the
 * largest von Mises stress and the smallest J, with where they are. */
static void field_sums(fpm_sim *sim) {
  const fpm_model *m = sim->local_model;
  const fpm_state *st = sim->local_state;
  const double *vol = m->dual->volume, *sig = sim->share_scratch;
  fpm_sums *u = &sim->sums;
  fpm_backend_cauchy_stress(m->n_own, st, sim->share_scratch);
  double sums[2] = {0, 0}, vm_most = -1, j_least = INFINITY;
  long vm_at = 0, j_at = 0;
  for (long i = 0; i < m->n_own; i++) {
    sums[0] += vol[i];
    sums[1] += vol[i] * st->W[i];
    const double vm = pm_t_von_mises(sig + 9 * i);
    if (vm > vm_most) {
      vm_most = vm;
      vm_at = i;
    }
    if (st->J[i] < j_least) {
      j_least = st->J[i];
      j_at = i;
    }
  }
  pm_par_sum(sums, 2);
  u->mean_sed = sums[0] > 0 ? sums[1] / sums[0] : 0;
  extreme(m, &vm_most, vm_at, true, u->max_von_mises_at, NULL);
  extreme(m, &j_least, j_at, false, u->end_min_jacobian_at, NULL);
  u->max_von_mises = vm_most;
  u->end_min_jacobian = j_least;
  fpm_tension tn;
  fpm_backend_tension(m, m->n_own, sig, sim->scene->dimension == 3, &tn);
  extreme(m, &tn.tension, tn.tension_at, true, u->max_tension_at, NULL);
  if (tn.ratio_at < 0) tn.ratio = -INFINITY;
  extreme(m, &tn.ratio, tn.ratio_at, true, u->cavitation_ratio_at, &tn.load);
  u->max_tension = tn.tension;
  u->cavitation_ratio = tn.load > 0 ? tn.ratio : 0;
  u->cavitation_load = tn.load;
}

pm_err fpm_view_sum(fpm_sim *sim, bool fields) {
  const fpm_model *m = sim->local_model;
  const fpm_state *st = sim->local_state;
  const pm_scene *s = sim->scene;
  fpm_sums *u = &sim->sums;
  const int n_bcs =
      s->n_bcs < PM_FIGURES_MAX_BCS ? s->n_bcs : PM_FIGURES_MAX_BCS;
  double v[3 * PM_FIGURES_MAX_BCS] = {0}, worst = 0;
  for (int b = 0; b < n_bcs; b++) fpm_reaction(m, st, b, v + 3 * b);
  long ill =
      fpm_gfd_deformed_condition(m->dim, m->n_own, m->x, st->u, m->nbr_ptr,
                                 sim->own_nbr, FPM_COND_MAX, &worst, NULL);
  if (n_bcs) pm_par_sum(v, 3 * n_bcs);
  pm_par_sum_long(&ill, 1);
  pm_par_max(&worst, 1);
  memcpy(u->reaction, v, sizeof(double) * 3 * (size_t)n_bcs);
  u->ill_conditioned = ill;
  u->worst_condition = worst;
  if (s->reference_mask) {
    pm_nrmse_part p;
    reference_part(m, st, s, st->t, &p);
    pm_par_sum(p.d2, 3);
    pm_par_min(p.lo, 3);
    pm_par_max(p.hi, 3);
    pm_par_max(&p.most, 1);
    pm_nrmse_parts(&p, sim->n_whole, s->reference_mask, u->nrmse,
                   &u->nrmse_vector);
  }
  if (fields) field_sums(sim);
  return PM_SUCCESS;
}
