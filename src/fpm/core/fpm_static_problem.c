/* fpm_static_problem: the problem FPM's static solve gives pm_newton: the
 * residual, the tangent's application and preparation, the loads at a load
 * factor, the figures and report of each converged load step, and the
 * set-up of it all over the free dofs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_contact.h"
#include "fpm_loads.h"
#include "fpm_static_impl.h"

/* The state at the free values x (prescribed dofs as set by set_load). */
long fpm_static_evaluate(fpm_static_ctx *c, const double *x) {
  if (x)
    for (long j = 0; j < c->nheld; j++) c->st->u[c->dof[j]] = x[j];
  long bad = fpm_force(c->m, c->st);
  /* the rigid bodies at lambda times their displacement at the end of the
   * ramps, as the supports */
  if (bad < 0 && c->m->contact)
    c->contact_fsq =
        fpm_contact_force_fixed(c->m, c->st, c->load_end, c->lambda);
  c->crossed_axis = -1;
  if (bad < 0) bad = fpm_symmetry_crossed(c->m, c->st, &c->crossed_axis);
  return bad;
}

static pm_err inadmissible(const fpm_static_ctx *c, long p) {
  if (c->crossed_axis >= 0)
    return fpm_symmetry_failure(c->m, c->st, p, c->crossed_axis, "");
  const double *x = c->m->x + 3 * p;
  return PM_ERROR(PM_ERR_UNSTABLE,
                  "point %ld at (%g, %g, %g): volume ratio J = %g%s",
                  fpm_point_id(c->m, p), x[0], x[1], x[2], c->st->J[p],
                  isfinite(c->st->J[p]) ? " (inverted subdomain)"
                                        : " (deformation not finite)");
}

/* The state just evaluated (bad: its first inadmissible point, or -1),
 * admissible on every rank or on none (the failure one process meets
 * first). */
pm_err fpm_static_admissible(const fpm_static_ctx *c, long bad) {
  pm_err e = bad >= 0 ? inadmissible(c, bad) : PM_SUCCESS;
  return fpm_exchange_agree(c->m->xc, e,
                            bad >= 0 ? fpm_point_id(c->m, bad) : 0);
}

pm_err fpm_static_evaluate_owned(fpm_static_ctx *c, const double *x,
                                 long *bad) {
  *bad = -1;
  if (c->m->xc) { /* x: the own unknowns; the ghosts' from their owners */
    PM_CALL(pm_newton_held_values(c->solver, x, c->held));
    x = c->held;
  }
  *bad = fpm_static_evaluate(c, x);
  return PM_SUCCESS;
}

static pm_err residual(void *ctx, const double *x, double *r) {
  fpm_static_ctx *c = ctx;
  long bad = fpm_static_evaluate(c, x);
  if (bad >= 0) return inadmissible(c, bad);
  const double *f = c->st->f;
  for (long j = 0; j < c->nf; j++) r[j] = f[c->dof[j]];
  /* (a rank's force on its own points is whole: nothing for the ghosts') */
  for (long j = c->nf; j < c->nheld; j++) r[j] = 0;
  return PM_SUCCESS;
}

static pm_err prepare(void *ctx, const double *x) {
  fpm_static_ctx *c = ctx;
  long bad = fpm_static_evaluate(c, x);
  if (bad >= 0) return inadmissible(c, bad);
  fpm_linear_prepare(c->m, c->st, c->lin);
  /* Sticking points that reached their body since the last iterate hold
   * on from here, anchored where they penetrate (the residual at x is the
   * same), and the tangent is the sticking one (k I) for them. */
  fpm_contact_touch_fixed(c->m, c->st, c->load_end, c->lambda);
  if (c->contact_K)
    fpm_contact_tangent_fixed(c->m, c->st, c->load_end, c->lambda,
                              c->contact_K);
  return PM_SUCCESS;
}

static pm_err apply(void *ctx, const double *x, const double *dx, double *dr) {
  fpm_static_ctx *c = ctx;
  (void)x;
  memset(c->du, 0, 3 * c->m->n * sizeof(double));
  for (long j = 0; j < c->nheld; j++) c->du[c->dof[j]] = dx[j];
  fpm_force_linear(c->m, c->lin, c->du, c->df);
  if (c->contact_K) /* the contact's blocks: dr_i += K_i du_i */
    for (long i = 0; i < c->m->n_own; i++) {
      const double *K = c->contact_K + 9 * i, *d = c->du + 3 * i;
      for (int a = 0; a < 3; a++)
        c->df[3 * i + a] +=
            K[3 * a] * d[0] + K[3 * a + 1] * d[1] + K[3 * a + 2] * d[2];
    }
  for (long j = 0; j < c->nf; j++) dr[j] = c->df[c->dof[j]];
  for (long j = c->nf; j < c->nheld; j++) dr[j] = 0;
  return PM_SUCCESS;
}

/* The loads at lambda on the model's own points (a condition's value not
 * finite: the failure, naming its point). */
static pm_err own_loads(fpm_static_ctx *c, double lambda, long *key) {
  const fpm_model *m = c->m;
  /* Proportional loading: the loads at the end of the ramps times lambda
   * (the path of a rate-independent solid does not depend on the ramps'
   * shape, and a proportional path is what the predictor extrapolates). */
  for (long k = 0; k < m->n_cdofs; k++) {
    double u = fpm_prescribed(m, k, c->load_end);
    if (!isfinite(u)) {
      *key = fpm_point_id(m, m->cd_point[k]);
      return fpm_condition_failure(m, false, k, -1, c->load_end);
    }
    c->st->u[3 * m->cd_point[k] + m->cd_comp[k]] = lambda * u;
  }
  long bad = fpm_update_tractions(m, c->st, c->load_end);
  if (bad >= 0) {
    *key = fpm_point_id(m, m->tf_point[bad / 3]);
    return fpm_condition_failure(m, true, bad, -1, c->load_end);
  }
  if ((bad = fpm_update_loads(m, c->st, c->load_end)) >= 0) {
    *key = bad;
    return fpm_load_failure(m, bad, -1, c->load_end);
  }
  fpm_loads_scale(m, c->st, lambda);
  return PM_SUCCESS;
}

/* The anchors are the first 3 doubles per pair of the contact's state. */
static size_t anchor_bytes(const fpm_contact *k) {
  return 3 * (size_t)k->pair_ptr[k->n_bodies] * sizeof(double);
}

void fpm_static_keep_anchors(fpm_static_ctx *c) {
  if (c->contact_kept)
    memcpy(c->contact_kept, c->st->contact, anchor_bytes(c->m->contact));
}

/* After a step's Newton solve (pm_newton_problem.settle): the sticking
 * points the solution x pulls off their body let go, their number in
 * *changed, the one farthest off named in buf; grazing ones held.  Contact
 * runs on one process (fpm_contact_refuse_ranks), so the count is the
 * whole problem's. */
static pm_err settle(void *ctx, const double *x, long *changed, char *buf,
                     long cap) {
  fpm_static_ctx *c = ctx;
  const fpm_model *m = c->m;
  PM_CALL(fpm_static_admissible(c, fpm_static_evaluate(c, x)));
  fpm_contact_touch_fixed(m, c->st, c->load_end, c->lambda);
  fpm_contact_release r;
  *changed = fpm_contact_release_fixed(m, c->st, c->load_end, c->lambda,
                                       c->contact_let_go, &r);
  if (*changed > 0) {
    const double *xp = m->x + 3 * r.first;
    snprintf(buf, (size_t)cap,
             "contact at lambda %.6g: %ld sticking points pulled off their "
             "body, the farthest point %ld at (%g, %g, %g), %.3g m off",
             c->lambda, *changed, fpm_point_id(m, r.first), xp[0], xp[1], xp[2],
             r.first_gap);
  } else {
    c->contact_frozen += r.frozen;
    c->contact_frozen_gap = fmax(c->contact_frozen_gap, r.frozen_gap);
  }
  return PM_SUCCESS;
}

pm_err fpm_static_set_load(void *ctx, double lambda) {
  fpm_static_ctx *c = ctx;
  const fpm_model *m = c->m;
  /* a new attempt at a step: the anchors of the last converged one */
  if (c->contact_kept) {
    memcpy(c->st->contact, c->contact_kept, anchor_bytes(m->contact));
    memset(c->contact_let_go, 0,
           (size_t)m->contact->pair_ptr[m->contact->n_bodies]);
  }
  c->t = lambda * c->load_end;
  c->lambda = lambda;
  long key = 0;
  pm_err e = own_loads(c, lambda, &key);
  if (m->xc) {
    /* A rank's failure is every rank's (the one one process meets first);
     * the ghosts' prescribed values (and, until the solver sets them,
     * their unknowns') come from their owners. */
    PM_CALL(fpm_exchange_agree(m->xc, e, key));
    fpm_exchange_ghosts(m->xc, c->st->u);
    double sq = c->st->fext_sq; /* the tractions of every rank's points */
    fpm_exchange_sum(m->xc, &sq, 1);
    c->st->fext_norm = lambda * sqrt(sq);
  }
  return e;
}

/* The figures of the state in c->st (its force just computed): energies,
 * the residual over the supports' forces, smallest J; the external work
 * by the trapezoidal rule from the last converged state. */
void fpm_static_figures(fpm_static_ctx *c, long step) {
  const fpm_model *m = c->m;
  fpm_state *st = c->st;
  const long n = m->n, n_own = m->n_own;
  double se = 0, rf = 0, jmin = INFINITY;
  for (long i = 0; i < n_own; i++) {
    se += m->dual->volume[i] * st->W[i];
    jmin = fmin(jmin, st->J[i]);
    for (int a = 0; a < 3; a++)
      if (!m->fixed[3 * i + a]) rf += st->f[3 * i + a] * st->f[3 * i + a];
  }
  for (long d = 0; d < 3 * n; d++) c->du[d] = st->u[d] - c->u_old[d];
  double rr;
  const double work = fpm_support_work(m, st, c->du, 1, &rr) +
                      fpm_contact_work_scaled(m, st, c->load_end, c->lambda);
  memcpy(c->u_old, st->u, 3 * n * sizeof(double));
  double bflux = st->bflux_norm, penalty = st->penalty_energy;
  double sums[6] = {se, rf, rr, work, st->bflux_sq, penalty};
  if (m->xc) { /* over every rank's own points */
    fpm_exchange_sum(m->xc, sums, 6);
    fpm_exchange_min(m->xc, &jmin, 1);
    se = sums[0], rf = sums[1], rr = sums[2], bflux = sqrt(sums[4]);
    penalty = sums[5];
  }
  *c->ext_work += sums[3];
  /* (contact runs on one process: its forces are all the model's) */
  double ref = sqrt(rr) + bflux + st->fext_norm + sqrt(c->contact_fsq);
  fpm_step_info *si = &c->si;
  si->step = step;
  si->t = c->t;
  si->kinetic = 0;
  si->strain = se;
  si->penalty = penalty;
  si->external_work = *c->ext_work;
  si->dissipated = 0;
  si->residual = ref > 0 ? sqrt(rf) / ref : sqrt(rf);
  si->damping = 0;
  si->min_jacobian = jmin;
  si->energy_error = fpm_energy_error(si);
  si->energy_checked = false; /* the load path's quadrature, not a check */
  si->converged = false;
}

static pm_err on_step(void *ctx, int step, double lambda, const double *x,
                      const pm_newton_report *report) {
  fpm_static_ctx *c = ctx;
  (void)report;
  c->t = lambda * c->load_end;
  long bad = -1;
  PM_CALL(fpm_static_evaluate_owned(c, x, &bad));
  PM_CALL(fpm_static_admissible(c, bad));
  /* the contact's state of this step: sticking points that touched anew
   * hold on from here (the residual at x is the same) */
  fpm_contact_commit(c->m, c->st, c->load_end, lambda);
  fpm_static_keep_anchors(c);
  fpm_static_figures(c, step);
  c->si.converged = lambda >= 1;
  c->si.last = c->si.converged;
  const double jlim = c->m->scene->stability.min_jacobian;
  if (c->si.min_jacobian <= jlim)
    return PM_ERROR(PM_ERR_UNSTABLE,
                    "load step %d (lambda %.6g): smallest volume ratio J = "
                    "%g <= stability.min_jacobian = %g",
                    step, lambda, c->si.min_jacobian, jlim);
  return c->observer ? c->observer(c->octx, c->m, c->st, &c->si, true)
                     : PM_SUCCESS;
}

/* Where the state x stands (pm_newton_problem.diagnose): the point of
 * largest out-of-balance force and the point of smallest J, with their
 * positions.  One process's models only (PM_ERR_UNSUPPORTED across
 * ranks, on every rank). */
static pm_err diagnose(void *ctx, const double *x, char *buf, long cap) {
  fpm_static_ctx *c = ctx;
  const fpm_model *m = c->m;
  PM_CHECK(!m->xc, PM_ERR_UNSUPPORTED, "diagnosis: one process only");
  long bad = fpm_static_evaluate(c, x);
  if (bad >= 0) {
    pm_err e = inadmissible(c, bad);
    snprintf(buf, (size_t)cap, "%s", pm_error_message());
    pm_error_clear();
    (void)e;
    return PM_SUCCESS;
  }
  long pf = 0, pj = 0;
  double f2max = -1, jmin = INFINITY;
  for (long i = 0; i < m->n_own; i++) {
    double f2 = 0;
    for (int a = 0; a < 3; a++)
      if (!m->fixed[3 * i + a]) f2 += c->st->f[3 * i + a] * c->st->f[3 * i + a];
    if (f2 > f2max) f2max = f2, pf = i;
    if (c->st->J[i] < jmin) jmin = c->st->J[i], pj = i;
  }
  const double *xf = m->x + 3 * pf, *xj = m->x + 3 * pj;
  snprintf(buf, (size_t)cap,
           "largest out-of-balance force %.3g N at point %ld (%g, %g, %g), "
           "J = %.4g there; smallest volume ratio J = %.4g at point %ld (%g, "
           "%g, %g)",
           sqrt(f2max), fpm_point_id(m, pf), xf[0], xf[1], xf[2], c->st->J[pf],
           jmin, fpm_point_id(m, pj), xj[0], xj[1], xj[2]);
  return PM_SUCCESS;
}

/* The mode's value at dof d (0 where d is prescribed). */
static double mode_at(const fpm_static_ctx *c, const double *v, long d) {
  const long k = c->free_of[d];
  return k >= 0 && k < c->nf ? v[k] : 0.0;
}

/* Where a mode v of the tangent stands: its largest point, and its
 * antisymmetric share about the cloud's mid-planes x and y (each point
 * against the point nearest its mirror image, within a third of the mean
 * spacing): 0 for a mode that keeps the mirror symmetry, 1 for one that
 * breaks it (a bifurcation's mode).  O(n^2): a diagnosis, run rarely. */
static pm_err describe_mode(void *ctx, const double *v, char *buf, long cap) {
  fpm_static_ctx *c = ctx;
  const fpm_model *m = c->m;
  const long n = m->n_own;
  PM_CHECK(!m->xc && n > 0, PM_ERR_UNSUPPORTED, "mode: one process only");
  double lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  long top = 0;
  double top2 = -1;
  for (long i = 0; i < n; i++) {
    double a2 = 0;
    for (int a = 0; a < 3; a++) {
      lo[a] = fmin(lo[a], m->x[3 * i + a]);
      hi[a] = fmax(hi[a], m->x[3 * i + a]);
      const double va = mode_at(c, v, 3 * i + a);
      a2 += va * va;
    }
    if (a2 > top2) top2 = a2, top = i;
  }
  const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  const double tol = cbrt(vol / (double)n) / 3;
  double anti[2] = {0, 0}, all[2] = {0, 0};
  long matched[2] = {0, 0};
  for (int ax = 0; ax < 2; ax++) {
    const double mid = lo[ax] + hi[ax];
    for (long i = 0; i < n; i++) {
      double y[3] = {m->x[3 * i], m->x[3 * i + 1], m->x[3 * i + 2]};
      y[ax] = mid - y[ax];
      long best = -1;
      double d2best = tol * tol;
      for (long j = 0; j < n; j++) {
        const double *xj = m->x + 3 * j;
        const double d2 = (xj[0] - y[0]) * (xj[0] - y[0]) +
                          (xj[1] - y[1]) * (xj[1] - y[1]) +
                          (xj[2] - y[2]) * (xj[2] - y[2]);
        if (d2 < d2best) d2best = d2, best = j;
      }
      if (best < 0) continue;
      matched[ax]++;
      for (int a = 0; a < 3; a++) {
        const double vi = mode_at(c, v, 3 * i + a);
        const double vj = (a == ax ? -1 : 1) * mode_at(c, v, 3 * best + a);
        anti[ax] += 0.25 * (vi - vj) * (vi - vj);
        all[ax] += vi * vi;
      }
    }
  }
  const double *xt = m->x + 3 * top;
  snprintf(buf, (size_t)cap,
           "largest at point %ld (%g, %g, %g); antisymmetric share about the "
           "mid-plane x %.3f, y %.3f (%ld, %ld of %ld points mirrored)",
           fpm_point_id(m, top), xt[0], xt[1], xt[2],
           all[0] > 0 ? anti[0] / all[0] : 0.0,
           all[1] > 0 ? anti[1] / all[1] : 0.0, matched[0], matched[1], n);
  return PM_SUCCESS;
}

void fpm_static_solve_free(fpm_static_solve *v) {
  fpm_linear_destroy(v->c.lin);
  fpm_static_tangent_free(&v->c.tg);
  fpm_static_coupled_free(&v->c.cp);
  fpm_static_support_free(&v->c.sp);
  free(v->c.dof);
  free(v->c.ghost);
  free(v->c.held);
  free(v->c.du);
  free(v->c.df);
  free(v->c.u_old);
  free(v->c.contact_K);
  free(v->c.contact_kept);
  free(v->c.contact_let_go);
  free(v->free_of);
  free(v->ptr);
  free(v->idx);
  free(v->x);
  free(v->rigid);
}

pm_err fpm_static_setup(const fpm_model *m, fpm_state *st,
                        fpm_static_solve *v) {
  const long n = m->n;
  fpm_static_ctx *c = &v->c;
  c->m = m;
  c->st = st;
  c->load_end = pm_scene_load_end(m->scene);
  PM_CALL(fpm_linear_create(m, &c->lin));
  PM_CALL(PM_ALLOC(v->free_of, 3 * n, "free dofs"));
  PM_CALL(PM_ALLOC(c->dof, 3 * n, "free dofs"));
  PM_CALL(PM_ALLOC(c->du, 3 * n, "displacement increment"));
  PM_CALL(PM_ALLOC(c->df, 3 * n, "force increment"));
  PM_CALL(PM_ALLOC(c->u_old, 3 * n, "converged displacement"));
  if (m->contact) {
    PM_CALL(PM_ALLOC(c->contact_K, 9 * m->n_own, "contact tangent"));
    PM_CALL(PM_ALLOC(c->contact_kept,
                     3 * m->contact->pair_ptr[m->contact->n_bodies],
                     "contact anchors"));
    PM_CALL(PM_ALLOC(c->contact_let_go,
                     m->contact->pair_ptr[m->contact->n_bodies],
                     "contact let go"));
    fpm_static_keep_anchors(c);
  }
  for (long d = 0; d < 3 * n; d++) {
    v->free_of[d] = -1;
    if (d < 3 * m->n_own && !m->fixed[d]) {
      v->free_of[d] = c->nf;
      c->dof[c->nf++] = d;
    }
  }
  c->nheld = c->nf;
  if (m->xc) PM_CALL(fpm_static_number_ghosts(m, v->free_of, c));
  long all = c->nf;
  fpm_exchange_sum_long(m->xc, &all, 1);
  PM_CHECK(all > 0, PM_ERR_SCENE, "%s: every displacement is prescribed",
           m->scene->path);
  PM_CALL(PM_ALLOC(v->x, c->nf + 1, "free displacements"));
  PM_CALL(PM_ALLOC(c->held, c->nheld + 1, "held displacements"));
  PM_CALL(
      fpm_static_pattern(m, v->free_of, c->nheld, &c->tg, &v->ptr, &v->idx));
  c->pat_ptr = v->ptr;
  c->free_of = v->free_of;
  PM_CALL(fpm_static_tangent_build(m, &c->tg));
  PM_CALL(PM_ALLOC(v->rigid, 6 * c->nf, "rigid motions"));
  const int n_rigid = fpm_static_rigid_modes(m, c->dof, c->nf, v->rigid);
  v->prob =
      (pm_newton_problem){.n = c->nf,
                          .ctx = c,
                          .residual = residual,
                          .jacobian_apply = apply,
                          .jacobian_prepare = prepare,
                          .jacobian_values = fpm_static_tangent_values,
                          .pat_ptr = v->ptr,
                          .pat_idx = v->idx,
                          .near_null_count = n_rigid,
                          .near_null = v->rigid,
                          .block_size = fpm_static_block_size(c->dof, c->nf),
                          .shared = m->xc != NULL,
                          .n_ghost = c->nheld - c->nf,
                          .ghost = c->ghost,
                          .set_load = fpm_static_set_load,
                          .on_step = on_step,
                          .diagnose = diagnose,
                          .describe_mode = describe_mode,
                          .settle = m->contact ? settle : NULL};
  return PM_SUCCESS;
}
