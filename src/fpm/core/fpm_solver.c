/* fpm_solver: the explicit time loop.  Velocities live at half steps;
 * dynamic relaxation damps with the lowest-mode frequency estimated from
 * the Rayleigh quotient of the last increment. */
#include "fpm_solver.h"

#include <math.h>
#include <string.h>

#include "fpm_contact.h"
#include "fpm_loads.h"
#include "pm_backend.h"
#include "pm_omp.h"
#include "pm_progress.h"

void fpm_reaction(const fpm_model *m, const fpm_state *st, int b, double R[3]) {
  /* The force of the support on the body: the consistency flux P_i a_f of the
   * face's facets on the prescribed components (part of the operator), plus any
   * out-of-balance force left on the prescribed dofs. */
  const gm_dual *d = m->dual;
  const pm_scene_bc *bc = &m->scene->bcs[b];
  R[0] = R[1] = R[2] = 0;
  for (long e = m->bcf_ptr[b]; e < m->bcf_ptr[b + 1]; e++) {
    const long f = m->bcf_facet[e];
    const double *P = st->P + 9 * d->facet_point[f],
                 *a = d->facet_area_vec + 3 * f;
    for (int c = 0; c < 3; c++)
      if (bc->disp_mask & (1u << c))
        R[c] += P[3 * c] * a[0] + P[3 * c + 1] * a[1] + P[3 * c + 2] * a[2];
  }
  for (long k = 0; k < m->n_cdofs; k++)
    if (m->cd_bc[k] == b)
      R[m->cd_comp[k]] += st->f[3 * m->cd_point[k] + m->cd_comp[k]];
  fpm_contact_reaction(m, st, b, R);
}

double fpm_spectral_dt(const fpm_model *m, fpm_state *st, int iterations,
                       double *base, double *lambda) {
  const long nd = 3 * m->n;
  double *v = st->v, lam = 0;
  memset(st->u, 0, nd * sizeof(double));
  fpm_update_tractions(m, st, 0);
  fpm_update_loads(m, st, 0);
  fpm_force(m, st);
  memcpy(base, st->f, nd * sizeof(double));
  unsigned long long seed = 88172645463325252ull;
  double scale = 0;
  for (long k = 0; k < 3 * m->n; k++) scale = fmax(scale, fabs(m->x[k]));
  for (long k = 0; k < nd; k++) {
    seed ^= seed << 13;
    seed ^= seed >> 7;
    seed ^= seed << 17;
    v[k] = m->fixed[k] ? 0 : (double)(seed >> 11) / 9007199254740992.0 - 0.5;
  }
  for (int it = 0; it < iterations; it++) {
    double vmax = 0, num = 0, den = 0;
    for (long k = 0; k < nd; k++) vmax = fmax(vmax, fabs(v[k]));
    if (!(vmax > 0 && isfinite(vmax))) break;
    for (long k = 0; k < nd; k++) v[k] /= vmax;
    double eps = 1e-7 * (scale > 0 ? scale : 1);
    for (long k = 0; k < nd; k++) st->u[k] = eps * v[k];
    if (fpm_force(m, st) >= 0) break;
    for (long k = 0; k < nd; k++) {
      if (m->fixed[k]) continue;
      double Kv = (st->f[k] - base[k]) / eps, mk = m->mass[k / 3];
      num += v[k] * Kv;
      den += mk * v[k] * v[k];
      v[k] = Kv / mk;
    }
    lam = den > 0 ? num / den : 0;
  }
  memset(st->u, 0, nd * sizeof(double));
  memset(st->v, 0, nd * sizeof(double));
  fpm_force(m, st);
  if (lambda) *lambda = lam;
  return lam > 0 ? 2 / sqrt(lam) : INFINITY;
}

/* What a traction facet's traction works on: the displacement of its
 * point carried to the facet by the point's gradient, times the area,
 * |f| u_i + H_i |f| (c_f - X_i) (the force puts -t (x) tf_rel into the
 * point's flux tensor, whose conjugate is H).  Three per facet. */
static void traction_displacement(const fpm_model *m, const fpm_state *st,
                                  long k, double w[3]) {
  const long i = m->tf_point[k];
  const double *H = st->H + 9 * i, *rel = m->tf_rel + 3 * k;
  for (int a = 0; a < 3; a++)
    w[a] = m->tf_area[k] * st->u[3 * i + a] + H[3 * a] * rel[0] +
           H[3 * a + 1] * rel[1] + H[3 * a + 2] * rel[2];
}

void fpm_support_start(const fpm_model *m, fpm_state *st) {
  for (long k = 0; k < m->n_cdofs; k++)
    st->support_prev[k] = st->f[3 * m->cd_point[k] + m->cd_comp[k]];
  for (long k = 0; k < 3 * m->n_dpts; k++)
    st->support_prev[m->n_cdofs + k] = st->bflux[k];
  double *tp = st->support_prev + m->n_cdofs + 3 * m->n_dpts;
  double *wp = tp + 3 * m->n_tfacets;
  for (long k = 0; k < m->n_tfacets; k++) {
    memcpy(tp + 3 * k, st->tf_load + 3 * k, 3 * sizeof(double));
    traction_displacement(m, st, k, wp + 3 * k);
  }
  fpm_loads_start(m, st);
}

double fpm_support_work(const fpm_model *m, fpm_state *st, const double *du,
                        double scale, double *rr) {
  double work = 0, r2 = 0;
  double *prev = st->support_prev, *prev_b = prev + m->n_cdofs;
  for (long k = 0; k < m->n_cdofs; k++) {
    long dof = 3 * m->cd_point[k] + m->cd_comp[k];
    r2 += st->f[dof] * st->f[dof];
    work += 0.5 * (prev[k] + st->f[dof]) * du[dof] * scale;
    prev[k] = st->f[dof];
  }
  /* A share's ghosts' flux and tractions are their owners' work. */
  for (long p = 0; p < m->n_dpts; p++)
    for (int a = 0; a < 3; a++) {
      const double fb = st->bflux[3 * p + a];
      if (m->dpt_point[p] < m->n_own)
        work += 0.5 * (prev_b[3 * p + a] + fb) * du[3 * m->dpt_point[p] + a] *
                scale;
      prev_b[3 * p + a] = fb;
    }
  /* Tractions: the trapezoidal rule on what they work on (a ghost's facet
   * is its owner's work). */
  double *tp = prev_b + 3 * m->n_dpts, *wp = tp + 3 * m->n_tfacets;
  for (long k = 0; k < m->n_tfacets; k++) {
    double w[3];
    traction_displacement(m, st, k, w);
    for (int a = 0; a < 3; a++) {
      const double t = st->tf_load[3 * k + a];
      if (m->tf_point[k] < m->n_own)
        work += 0.5 * (tp[3 * k + a] + t) * (w[a] - wp[3 * k + a]);
      tp[3 * k + a] = t;
      wp[3 * k + a] = w[a];
    }
  }
  /* Body and point forces: the trapezoidal rule on the points' own
   * displacements. */
  work += fpm_loads_work(m, st, du, scale);
  if (rr) *rr = r2;
  return work;
}

double fpm_energy_error(const fpm_step_info *s) {
  return pm_energy_error(0, s->kinetic + s->strain + s->penalty, s->dissipated,
                         s->external_work);
}

/* Steps before the energy balance is checked against its bound. */
#define FPM_ENERGY_CHECK_AFTER 100

/* Set the prescribed dofs at time t; returns -1, or the first constrained
 * dof whose value is not finite. */
static long apply_prescribed(const fpm_model *m, fpm_state *st, double t,
                             double dt) {
  long bad = -1;
  for (long k = 0; k < m->n_cdofs; k++) {
    long dof = 3 * m->cd_point[k] + m->cd_comp[k];
    double ub = fpm_prescribed(m, k, t);
    if (!isfinite(ub) && bad < 0) bad = k;
    st->v[dof] = dt > 0 ? (ub - st->u[dof]) / dt : 0;
    st->u[dof] = ub;
  }
  return bad;
}

static pm_err unstable(const fpm_model *m, const fpm_state *st, long step,
                       double t, double dt, long p, double min_jacobian) {
  const double *x = m->x + 3 * p;
  double J = st->J[p];
  char why[96];
  const char *cause = why;
  if (!isfinite(J))
    cause = "deformation gradient is not finite";
  else if (J <= 0)
    cause = "volume ratio J <= 0 (inverted subdomain)";
  else if (J <= min_jacobian)
    snprintf(why, sizeof why, "volume ratio J <= stability.min_jacobian = %g",
             min_jacobian);
  else
    cause = "stress is not finite";
  return PM_ERROR(PM_ERR_UNSTABLE,
                  "step %ld, t = %.6g s: point %ld at (%g, %g, %g): %s "
                  "(J = %g); dt = %.4g s",
                  step, t, fpm_point_id(m, p), x[0], x[1], x[2], cause, J, dt);
}

/* Where a failure comes in one process's order (fpm_exchange_agree): the
 * prescribed dofs (by dof), then the tractions (by facet entry), then the
 * points' stresses (by point), each stage after the one before. */
#define KEY_STAGE (1L << 40)

/* The supports at time t (move_dt < 0: where they are, a resumed state's;
 * 0: at rest; > 0: moved over a step of move_dt) and the tractions, the
 * ghosts' displacements from their owners, and the force (its seconds
 * added to *seconds): PM_ERR_UNSTABLE naming the condition or the point of
 * the first failure, the same on every rank. */
static pm_err force_at(const fpm_model *m, fpm_state *st, long step, double t,
                       double dt, double move_dt, double *seconds,
                       void (*tail)(void *), void *ctx) {
  pm_err e = PM_SUCCESS;
  long key = 0;
  long bad = move_dt >= 0 ? apply_prescribed(m, st, t, move_dt) : -1;
  if (bad >= 0) {
    e = fpm_condition_failure(m, false, bad, step, t);
    key = 3 * fpm_point_id(m, m->cd_point[bad]) + m->cd_comp[bad];
  } else if ((bad = fpm_update_tractions(m, st, t)) >= 0) {
    e = fpm_condition_failure(m, true, bad, step, t);
    key = KEY_STAGE + 3 * (m->tf_gid ? m->tf_gid[bad / 3] : bad / 3) + bad % 3;
  } else if ((bad = fpm_update_loads(m, st, t)) >= 0) {
    e = fpm_load_failure(m, bad, step, t);
    /* after the tractions' keys: their facets number fewer than 2^39 */
    key = KEY_STAGE + (1L << 39) + bad;
  }
  fpm_exchange_ghosts(m->xc, st->u);
  if (e == PM_SUCCESS) {
    const double w = pm_wtime();
    /* The contact force adds to f after the force's region: then the
     * tail is a region of its own. */
    bad = fpm_force_then(m, st, m->contact ? NULL : tail, ctx);
    if (bad < 0) fpm_contact_force(m, st, t);
    if (bad < 0 && m->contact && tail) PM_OMP(parallel) tail(ctx);
    *seconds += pm_wtime() - w;
    int axis = -1;
    if (bad >= 0) {
      e = unstable(m, st, step, t, dt, bad, 0);
      key = 2 * KEY_STAGE + fpm_point_id(m, bad);
    } else if ((bad = fpm_symmetry_crossed(m, st, &axis)) >= 0) {
      char when[64];
      snprintf(when, sizeof when, "step %ld, t = %.6g s: ", step, t);
      e = fpm_symmetry_failure(m, st, bad, axis, when);
      key = 2 * KEY_STAGE + fpm_point_id(m, bad);
    }
  } else {
    fpm_force_skipped(m, st); /* (the other ranks' force is collective) */
  }
  return fpm_exchange_agree(m->xc, e, key);
}

/* The point of smallest J among the model's own (the first of them), as
 * the failure of stability.min_jacobian, the same on every rank (serial;
 * only on the way out). */
static pm_err below_min_jacobian(const fpm_model *m, const fpm_state *st,
                                 long step, double t, double dt, double jmin,
                                 double min_jacobian) {
  long best = -1;
  for (long i = 0; i < m->n_own && best < 0; i++)
    if (st->J[i] == jmin) best = i;
  pm_err e =
      best >= 0 ? unstable(m, st, step, t, dt, best, min_jacobian) : PM_SUCCESS;
  return fpm_exchange_agree(m->xc, e, best >= 0 ? fpm_point_id(m, best) : 0);
}

/* The sums a step's figures come from, over the model's own points and
 * summed over the ranks. */
enum {
  SUM_S1, /* du . f before the update (the Rayleigh quotient) */
  SUM_S2, /* m du^2 */
  SUM_SD, /* m v_mid^2 (the damping's work) */
  SUM_S3, /* dt v . f after it */
  SUM_RF, /* |f|^2 on free dofs */
  SUM_KIN,
  SUM_STRAIN,
  SUM_WORK, /* of the supports and tractions over the step */
  SUM_RR,   /* |f|^2 on prescribed dofs */
  SUM_BFLUX,
  SUM_FEXT,
  SUM_PENALTY,
  SUMS
};

/* A step's sums over the model's own points after the force: s3, rf,
 * kin, se start at zero and jmin at infinity; each thread adds its points'
 * parts as OpenMP's reduction clause would (one thread after another). */
typedef struct {
  const fpm_model *m;
  const fpm_state *st;
  double dt;
  double s3, rf, kin, se, jmin;
} step_sums;

/* The tail of the force's region (fpm_force_then): this thread's share of
 * the points, the same static share as the gather's, so no barrier. */
static void sums_after(void *ctx) {
  step_sums *ss = ctx;
  const fpm_model *m = ss->m;
  const long n = m->n_own;
  const double dt = ss->dt;
  const double *restrict mass = m->mass, *restrict vol = m->dual->volume;
  const unsigned char *restrict fixed = m->fixed;
  const double *restrict v = ss->st->v, *restrict f = ss->st->f,
                         *restrict W = ss->st->W, *restrict Jp = ss->st->J;
  double s3 = 0, rf = 0, kin = 0, se = 0, jmin = INFINITY;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    se += vol[i] * W[i];
    jmin = Jp[i] < jmin ? Jp[i] : jmin;
    for (int a = 0; a < 3; a++) {
      const long dof = 3 * i + a;
      /* Prescribed dofs move as the supports dictate: their kinetic
       * energy comes from outside the balance, like their inertia. */
      if (fixed[dof]) continue;
      kin += 0.5 * mass[i] * v[dof] * v[dof];
      s3 += dt * v[dof] * f[dof];
      rf += f[dof] * f[dof];
    }
  }
  PM_OMP(critical(fpm_step_sums)) {
    ss->s3 += s3;
    ss->rf += rf;
    ss->kin += kin;
    ss->se += se;
    if (jmin < ss->jmin) ss->jmin = jmin;
  }
}

/* Stop the loop at step, time t: the last figures and the stages'
 * seconds to the caller, and e. */
static pm_err stop_at(pm_err e, fpm_step_info *si, long step, double t,
                      fpm_step_info *info, double stage_seconds[2],
                      const double seconds[2]) {
  si->step = step;
  si->t = t;
  si->converged = false;
  if (info) *info = *si;
  if (stage_seconds) memcpy(stage_seconds, seconds, 2 * sizeof(double));
  return e;
}

pm_err fpm_run(const fpm_model *m, fpm_state *st, const fpm_run_options *opt,
               fpm_observer observer, void *ctx, fpm_step_info *info,
               double stage_seconds[2]) {
  const long n = m->n_own;
  const double dt = opt->dt;
  const double load_end = pm_scene_load_end(m->scene);
  const bool resumed = st->step > 0;
  double t = resumed ? st->t : 0;
  double c = resumed                    ? st->damping
             : opt->qs == PM_QS_DAMPING ? opt->damping
                                        : 0;
  double ext_work = resumed ? st->external_work : 0;
  double dissipated = resumed ? st->dissipated : 0;
  double seconds[2] = {0, 0}; /* force, the rest of the step */
  PM_CHECK(dt > 0 && isfinite(dt), PM_ERR_ARG, "time step must be > 0 (got %g)",
           dt);
  /* A resumed state has its supports in place: only the tractions and the
   * force (functions of u and t) are computed again. */
  PM_CALL(
      force_at(m, st, st->step, t, dt, resumed ? -1 : 0, seconds, NULL, NULL));
  fpm_support_start(m, st);
  fpm_contact_start(m, st, t);

  fpm_step_info si = {0};
  si.step = st->step;
  si.t = t;
  si.min_jacobian = INFINITY;
  for (long i = 0; i < n; i++)
    si.min_jacobian = fmin(si.min_jacobian, st->J[i]);
  fpm_exchange_min(m->xc, &si.min_jacobian, 1);
  /* The initial state, as a frame. */
  if (observer && !resumed) {
    pm_err e = observer(ctx, m, st, &si, true);
    if (e != PM_SUCCESS) {
      if (info) *info = si;
      return pm_error_trace(e, __FILE__, __LINE__, __func__, "observer");
    }
  }
  const double *restrict mass = m->mass;
  const unsigned char *restrict fixed = m->fixed;
  for (long step = st->step + 1;; step++) {
    double w0 = pm_wtime();
    double sum[SUMS] = {0};
    double s1 = 0, s2 = 0, sd = 0;
    const double cd2 = 0.5 * c * dt;
    const double damp_old = (1 - cd2) / (1 + cd2), damp_new = dt / (1 + cd2);
    double *restrict u = st->u, *restrict v = st->v;
    const double *restrict f = st->f;
    PM_OMP(parallel for schedule(static) default(none)
           reduction(+ : s1, s2, sd)
           shared(n, mass, fixed, u, v, f, damp_old, damp_new, dt))
    for (long i = 0; i < n; i++) {
      const double im = 1.0 / mass[i];
      for (int a = 0; a < 3; a++) {
        const long dof = 3 * i + a;
        if (fixed[dof]) continue;
        const double v_old = v[dof];
        v[dof] = damp_old * v_old - damp_new * f[dof] * im;
        const double v_mid = 0.5 * (v_old + v[dof]);
        sd += mass[i] * v_mid * v_mid;
        const double du = dt * v[dof];
        u[dof] += du;
        s1 += du * f[dof];
        s2 += mass[i] * du * du;
      }
    }
    t += dt;
    const double force_before = seconds[0];
    step_sums ss = {.m = m, .st = st, .dt = dt, .jmin = INFINITY};
    pm_err stop = force_at(m, st, step, t, dt, dt, seconds, sums_after, &ss);
    seconds[1] -= seconds[0] - force_before;
    if (stop != PM_SUCCESS) {
      seconds[1] += pm_wtime() - w0;
      return stop_at(stop, &si, step, t, info, stage_seconds, seconds);
    }
    double s3 = ss.s3, rf = ss.rf, kin = ss.kin, se = ss.se, jmin = ss.jmin;
    /* The supports' force on the body is the boundary consistency flux
     * plus the force left on prescribed dofs; its work (trapezoidal rule
     * over the step), and that of the tractions, give the external work. */
    sum[SUM_WORK] = fpm_support_work(m, st, st->v, dt, &sum[SUM_RR]) +
                    fpm_contact_work(m, st, t);
    sum[SUM_S1] = s1;
    sum[SUM_S2] = s2;
    sum[SUM_SD] = sd;
    sum[SUM_S3] = s3;
    sum[SUM_RF] = rf;
    sum[SUM_KIN] = kin;
    sum[SUM_STRAIN] = se;
    sum[SUM_BFLUX] = st->bflux_sq;
    sum[SUM_FEXT] = st->fext_sq;
    sum[SUM_PENALTY] = st->penalty_energy;
    fpm_exchange_sum(m->xc, sum, SUMS);
    fpm_exchange_min(m->xc, &jmin, 1);
    st->bflux_norm = sqrt(sum[SUM_BFLUX]);
    st->fext_norm = sqrt(sum[SUM_FEXT]);
    st->penalty_energy = sum[SUM_PENALTY];
    kin = sum[SUM_KIN];
    se = sum[SUM_STRAIN];
    ext_work += sum[SUM_WORK];
    /* The damping force c m (v_old + v_new) / 2 does work c m v_mid^2 dt
     * (exactly what the update takes from the kinetic energy). */
    dissipated += c * sum[SUM_SD] * dt;
    if (opt->qs == PM_QS_DYNAMIC_RELAXATION && sum[SUM_S2] > 0) {
      double w2r = (sum[SUM_S3] - sum[SUM_S1]) / sum[SUM_S2];
      if (w2r > 0 && isfinite(w2r)) c = 2 * sqrt(w2r);
      if (c * dt > 1.9) c = 1.9 / dt;
    }
    double ref = sqrt(sum[SUM_RR]) + st->bflux_norm + st->fext_norm;
    si.step = step;
    si.t = t;
    si.kinetic = kin;
    si.strain = se;
    si.penalty = st->penalty_energy;
    si.external_work = ext_work;
    si.dissipated = dissipated;
    si.residual = ref > 0 ? sqrt(sum[SUM_RF]) / ref : sqrt(sum[SUM_RF]);
    si.damping = c;
    si.min_jacobian = jmin;
    si.energy_error = fpm_energy_error(&si);
    /* The balance is checked once the loading is under way: in the first
     * steps of a ramp the energies are tiny and their quadrature error, of
     * relative order dt / t, dominates. */
    si.energy_checked =
        step >= FPM_ENERGY_CHECK_AFTER && t >= 0.1 * load_end && ext_work > 0;
    seconds[1] += pm_wtime() - w0;
    if (opt->max_energy_error > 0 && si.energy_checked &&
        fabs(si.energy_error) > opt->max_energy_error) {
      si.converged = false;
      if (info) *info = si;
      return PM_ERROR(
          PM_ERR_UNSTABLE,
          "step %ld, t = %.6g s: energy balance error %.3g exceeds "
          "stability.max_energy_error = %g (kinetic %.4g + strain %.4g + "
          "interface %.4g + dissipated %.4g J against external work %.4g J): "
          "the discretization is creating energy; smallest volume ratio J "
          "%.3g (the stable step is the reference state's, J = 1, and a "
          "subdomain compressed far stiffens past it); dt = %.4g s",
          step, t, si.energy_error, opt->max_energy_error, kin, se,
          st->penalty_energy, dissipated, ext_work, jmin, dt);
    }
    if (jmin <= opt->min_jacobian) {
      si.converged = false;
      if (info) *info = si;
      return below_min_jacobian(m, st, step, t, dt, jmin, opt->min_jacobian);
    }
    si.converged = opt->qs != PM_QS_NONE && t >= load_end &&
                   si.residual < opt->qs_tolerance;
    bool last = si.converged || t >= opt->t_end * (1 - 1e-12) ||
                (opt->max_steps > 0 && step >= opt->max_steps);
    bool frame = last || (opt->frame_every > 0 && step % opt->frame_every == 0);
    si.last = last;
    st->step = step;
    st->t = t;
    st->damping = c;
    st->external_work = ext_work;
    st->dissipated = dissipated;
    if (observer) {
      pm_err e = observer(ctx, m, st, &si, frame);
      if (e != PM_SUCCESS) {
        if (info) *info = si;
        return pm_error_trace(e, __FILE__, __LINE__, __func__, "observer");
      }
    }
    if (last) break;
  }
  if (info) *info = si;
  if (stage_seconds) memcpy(stage_seconds, seconds, sizeof seconds);
  return PM_SUCCESS;
}
