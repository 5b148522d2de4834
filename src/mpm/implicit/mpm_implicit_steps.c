/* mpm_implicit_steps: the implicit MPM's converged load steps (the
 * particles committed, reactions and residual) and the run by load steps. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_implicit_impl.h"
#include "mpm_traction.h"
#include "mpm_kind.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* ---- converged steps ---------------------------------------------------- */

/* The particles at the converged unknowns x: position, F, stress and
 * volume; the reactions and the residual. */
static pm_err commit(mpm_implicit *im, const double *x, double lam_new) {
  const mpm_model *m = im->m;
  mpm_state *st = im->st;
  if (im->ranks) { /* the ghost nodes' unknowns too */
    PM_CALL(pm_newton_held_values(im->solver, x, im->x_held));
    x = im->x_held;
  }
  mpm_implicit_fill_u(im, x);
  if (!mpm_implicit_nodal_force(im, im->u, im->f))
    return PM_ERROR(PM_ERR_UNSTABLE, "%s", im->fail_msg);
  /* Across ranks: whole nodal sums, counted at the nodes a rank owns. */
  const unsigned char *own = im->ranks ? mpm_xc_owned(m) : NULL;
  if (im->ranks)
    PM_CALL(mpm_xc_nodes_reduce(m, im->f, MPM_XC_DOUBLE3, MPM_XC_SUM));
  for (int b = 0; b < 3 * m->n_bcs; b++) im->reaction[b] = 0;
  double sums[2] = {0, 0}; /* |r|^2, |reactions|^2 */
  /* A dof that follows an anchor moved t f onto it: (1 - t) f is the
   * condition's. */
  for (long k = 0; k < im->npre; k++) {
    if (own && !own[im->pre_dof[k] / 3]) continue;
    const double fk = (1 - im->pre_t[k]) * im->f[im->pre_dof[k]];
    im->reaction[3 * im->pre_bc[k] + im->pre_dof[k] % 3] += fk;
    sums[1] += fk * fk;
  }
  mpm_implicit_fold(im, im->f, im->df); /* the residual of the unknowns */
  for (long k = 0; k < im->nunk; k++) sums[0] += im->df[k] * im->df[k];
  if (im->ranks) {
    mpm_xc_sum(m, im->reaction, 3 * m->n_bcs);
    mpm_xc_sum(m, sums, 2);
    mpm_xc_min(m, &im->min_jacobian, 1);
  }
  const double rr = sums[0], rf = sums[1];
  im->residual = rf > 0 ? sqrt(rr / rf) : sqrt(rr);
  if (im->fbar) /* the stress from Fbar, before F_b changes */
    FOR_BUCKETS(im, {
      double Jbar, V;
      fbar_bucket_J(im, q0, q1, im->u, NULL, &Jbar, &V, NULL);
      for (long q = q0; q < q1; q++) {
        const long p = im->order[q];
        mpm_stencil stn;
        mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, &stn);
        double F[9], Fbar[9], P[9];
        particle_F(im, p, &stn, im->u, F);
        fbar_scale(im->dim, pow(Jbar / pm_t_det(F), 1.0 / im->dim), F, Fbar);
        const mpm_solid_view *v = &im->view[im->grp[p]];
        double W = 0;
        im->wbar[p] = 0;
        if (!pm_material_stress(v->mat, Fbar, model_state(im, p), P, &W, NULL))
          continue; /* nodal_force succeeded on the same state */
        im->wbar[p] = m->vol0[p] * W;
        double *sig = st->sigma + 9 * p;
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++)
            sig[3 * i + j] =
                (P[3 * i] * Fbar[3 * j] + P[3 * i + 1] * Fbar[3 * j + 1] +
                 P[3 * i + 2] * Fbar[3 * j + 2]) /
                Jbar;
      }
    })
  if (im->fbar) { /* in the particles' order: the same sum every run */
    const long np = im->n;
    const double *wb = im->wbar;
    double e = 0;
    PM_OMP(parallel for schedule(static) reduction(+ : e))
    for (long p = 0; p < np; p++) e += wb[p];
    if (im->ranks) mpm_xc_sum(m, &e, 1);
    im->strain_energy = e;
  }
  const long n = im->n;
  const double *u = im->u;
  st->external_work += mpm_tractions_work(m, &im->g, im->xb, u, im->trac_at,
                                          im->lambda, lam_new);
  long bad = -1;
  PM_OMP(parallel for schedule(static) reduction(max : bad))
  for (long p = 0; p < n; p++) {
    mpm_stencil stn;
    const double *xb = im->xb + 3 * p;
    mpm_stencil_at(&im->g, xb, MPM_STENCIL_W | MPM_STENCIL_GRAD, &stn);
    double F[9], P[9], J, xn[3] = {xb[0], xb[1], xb[2]};
    particle_F(im, p, &stn, u, F);
    for (int k = 0; k < stn.n; k++)
      for (int c = 0; c < 3; c++) xn[c] += stn.w[k] * u[3 * stn.node[k] + c];
    const int gi = im->grp[p];
    const mpm_solid_view *v = &im->view[gi];
    if (!pm_material_stress(v->mat, F, model_state(im, p), P, NULL, &J)) {
      bad = p > bad ? p : bad;
      continue;
    }
    double *sig = st->sigma + 9 * p;
    if (!im->fbar)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          sig[3 * i + j] = (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                            P[3 * i + 2] * F[3 * j + 2]) /
                           J;
    memcpy(v->F + 9 * (p - im->group_begin[gi]), F, sizeof F);
    st->vol[p] = m->vol0[p] * J;
    for (int c = 0; c < 3; c++) {
      st->x[3 * p + c] = xn[c];
      st->v[3 * p + c] = 0;
    }
  }
  PM_CHECK(bad < 0, PM_ERR_UNSTABLE,
           "particle %ld: no stress at the converged state",
           m->gid ? m->gid[bad] : bad);
  return PM_SUCCESS;
}

/* The observer's view of a converged step. */
static pm_err report_step(mpm_implicit *im, const pm_newton_report *r) {
  im->step++;
  double now = pm_wtime();
  mpm_implicit_step info = {.step = im->step,
                            .lambda = im->lambda,
                            .newton = r ? r->iterations : 0,
                            .linear = r ? r->linear_iterations : 0,
                            .cuts = im->rep.cuts,
                            .residual = im->residual,
                            .min_jacobian = im->min_jacobian,
                            .seconds = now - im->t_step,
                            .report = r};
  im->t_step = now;
  return im->obs ? im->obs(im->octx, &info) : PM_SUCCESS;
}

pm_err mpm_implicit_on_step(void *ctx, int step, double lambda, const double *x,
                            const pm_newton_report *report) {
  (void)step;
  mpm_implicit *im = ctx;
  if (im->mode == MPM_GRID_RESET && lambda < 1) return PM_SUCCESS;
  const double lam_new = im->lam0 + lambda * (im->lam1 - im->lam0);
  pm_err e = commit(im, x, lam_new);
  PM_CALL(im->ranks ? mpm_xc_agree(im->m, e) : e);
  im->lambda = lam_new;
  return report_step(im, report);
}

/* Add one load stepping's counters to the run's. */
static void add_report(pm_load_report *t, const pm_load_report *r) {
  t->steps += r->steps;
  t->cuts += r->cuts;
  t->newton_iterations += r->newton_iterations;
  t->linear_iterations += r->linear_iterations;
  t->time_residual += r->time_residual;
  t->time_assembly += r->time_assembly;
  t->time_linear += r->time_linear;
  t->time_total += r->time_total;
  if (r->steps > 0 && (t->dlambda_min == 0 || r->dlambda_min < t->dlambda_min))
    t->dlambda_min = r->dlambda_min;
  t->last = r->last;
}

pm_err mpm_implicit_run(mpm_implicit *im, mpm_implicit_observer obs,
                        void *ctx) {
  pm_err e = PM_SUCCESS;
  im->obs = obs;
  im->octx = ctx;
  im->t_step = pm_wtime();
  if (im->mode == MPM_GRID_KEPT) {
    im->lam0 = 0;
    im->lam1 = 1;
    e = pm_load_steps_from(im->solver, im->x_unk, &im->ls, &im->rep);
  } else {
    const int N = im->opt_steps;
    for (int k = (int)llround(im->lambda * N); k < N && !e; k++) {
      im->lam0 = (double)k / N;
      im->lam1 = (double)(k + 1) / N;
      im->lam_local = 0;
      if (im->built_for != k)
        e = mpm_implicit_rebuild(im); /* create built the first */
      im->built_for = -1;
      if (e) break;
      memset(im->x_unk, 0, sizeof(double) * (size_t)im->nunk);
      pm_load_report r = {0};
      e = pm_load_steps(im->solver, im->x_unk, &r);
      add_report(&im->rep, &r);
      if (e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", pm_error_message());
        e = PM_ERROR(e,
                     "load step %d of %d (lambda %.6g -> %.6g, grid reset, "
                     "increments from the step's start): %s",
                     k + 1, N, im->lam0, im->lam1, msg);
      }
    }
    im->rep.lambda = im->lambda;
  }
  im->obs = NULL;
  return e;
}
