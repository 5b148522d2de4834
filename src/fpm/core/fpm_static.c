/* fpm_static: Newton's method in load steps on the free dofs of an FPM
 * model.  Unknowns are the free displacement components; the prescribed
 * ones follow the load factor.  The Jacobian's pattern couples each point
 * with the points within reach of its force: the supports of the supports
 * of its supports (and, with the quadratic jump, the fits of those). */
#include "fpm_static.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_gfd.h"
#include "pm_omp.h"
#include "pm_progress.h"

/* The tangent assembled directly: K = E D Gamma + S, where
 *   H_j = sum_m u_m (x) gamma_jm        (gamma: GFD weights, self -gsum)
 *   f_k[c] = sum_j sum_s P_j[c][s] E^c_kj[s] + (penalty, linear in u)
 * E (constant: the interface and boundary geometry gathered by the GFD
 * weights) is built once per run, and so is the penalty's scalar matrix S
 * (the same for every component).  Per Newton iteration only the products
 * with the tangent moduli D are formed.  Exact for IIPG; with SIPG the
 * adjoint term's derivative is left out (the solve then multiplies by the
 * exact tangent matrix-free and preconditions with this one). */
typedef struct {
  long *R_ptr, *R_list; /* per point k: the points its force reaches */
  long *E_ptr, *E_j;    /* per point k: the points j whose stress reaches */
  double *E;            /* 9 per (k, j): E^c_kj[s] at 3 c + s */
  long *S_ptr, *S_m;    /* per point k: the penalty matrix's columns */
  double *S;
  double *Dg;   /* 27 per (j, m in S(j) and j): D_j gamma_jm */
  long *Dg_ptr; /* n + 1: point j's records start at Dg_ptr[j] */
  long max_reach;
  int threads;
  long *mark;   /* threads x n: a row's points */
  double *work; /* threads x 9 max_reach: a row's blocks */
} tangent;

typedef struct {
  const fpm_model *m;
  fpm_state *st;
  tangent tg;
  const long *pat_ptr;
  const long *free_of;
  fpm_linear *lin;
  /* The unknowns: the free dofs of the model's own points (nf; all its
   * points on one process), then across ranks those of its ghosts (nheld
   * in all), which the solver gives their owners' values. */
  long nf, nheld;
  long *dof;   /* nheld: their dof index */
  long *ghost; /* nheld - nf: the ghosts' unknowns' numbers over the ranks */
  pm_newton *solver;
  double *held;  /* nheld: the unknowns held, for a converged state */
  double *du;    /* 3 n work */
  double *df;    /* 3 n work */
  double *u_old; /* 3 n: the last converged displacement */
  double load_end, t;
  fpm_observer observer;
  void *octx;
  fpm_step_info si;
  double *ext_work; /* fpm_static_state.external_work */
} static_ctx;

/* The state at the free values x (prescribed dofs as set by set_load). */
static long evaluate(static_ctx *c, const double *x) {
  if (x)
    for (long j = 0; j < c->nheld; j++) c->st->u[c->dof[j]] = x[j];
  return fpm_force(c->m, c->st);
}

static pm_err inadmissible(const static_ctx *c, long p) {
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
static pm_err admissible(const static_ctx *c, long bad) {
  pm_err e = bad >= 0 ? inadmissible(c, bad) : PM_SUCCESS;
  return fpm_exchange_agree(c->m->xc, e,
                            bad >= 0 ? fpm_point_id(c->m, bad) : 0);
}

static pm_err residual(void *ctx, const double *x, double *r) {
  static_ctx *c = ctx;
  long bad = evaluate(c, x);
  if (bad >= 0) return inadmissible(c, bad);
  const double *f = c->st->f;
  for (long j = 0; j < c->nf; j++) r[j] = f[c->dof[j]];
  /* (a rank's force on its own points is whole: nothing for the ghosts') */
  for (long j = c->nf; j < c->nheld; j++) r[j] = 0;
  return PM_SUCCESS;
}

static pm_err prepare(void *ctx, const double *x) {
  static_ctx *c = ctx;
  long bad = evaluate(c, x);
  if (bad >= 0) return inadmissible(c, bad);
  fpm_linear_prepare(c->m, c->st, c->lin);
  return PM_SUCCESS;
}

static pm_err apply(void *ctx, const double *x, const double *dx, double *dr) {
  static_ctx *c = ctx;
  (void)x;
  memset(c->du, 0, 3 * c->m->n * sizeof(double));
  for (long j = 0; j < c->nheld; j++) c->du[c->dof[j]] = dx[j];
  fpm_force_linear(c->m, c->lin, c->du, c->df);
  for (long j = 0; j < c->nf; j++) dr[j] = c->df[c->dof[j]];
  for (long j = c->nf; j < c->nheld; j++) dr[j] = 0;
  return PM_SUCCESS;
}

/* The loads at lambda on the model's own points (a condition's value not
 * finite: the failure, naming its point). */
static pm_err own_loads(static_ctx *c, double lambda, long *key) {
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
  if (m->n_tfacets > 0) {
    long bad = fpm_update_tractions(m, c->st, c->load_end);
    if (bad >= 0) {
      *key = fpm_point_id(m, m->tf_point[bad / 3]);
      return fpm_condition_failure(m, true, bad, -1, c->load_end);
    }
    for (long k = 0; k < 3 * m->n_tfacets; k++) c->st->tf_value[k] *= lambda;
    c->st->fext_norm *= lambda;
  }
  return PM_SUCCESS;
}

static pm_err set_load(void *ctx, double lambda) {
  static_ctx *c = ctx;
  const fpm_model *m = c->m;
  c->t = lambda * c->load_end;
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
static void figures(static_ctx *c, long step) {
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
  const double work = fpm_support_work(m, st, c->du, 1, &rr);
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
  double ref = sqrt(rr) + bflux + st->fext_norm;
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
  static_ctx *c = ctx;
  (void)report;
  c->t = lambda * c->load_end;
  if (c->m->xc) { /* x: the own unknowns; the ghosts' from their owners */
    PM_CALL(pm_newton_held_values(c->solver, x, c->held));
    x = c->held;
  }
  PM_CALL(admissible(c, evaluate(c, x)));
  figures(c, step);
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

/* ---- The tangent, assembled directly ------------------------------------ */

/* The weight of u_m in H_j for the r-th member of j's closed support
 * (r = 0: j itself, -gsum_j; else its (r-1)-th neighbour), and that point. */
static inline long closed_member(const fpm_model *m, long j, long r,
                                 const double **w) {
  if (r == 0) {
    *w = m->gsum + 3 * j;
    return j;
  }
  long e = m->nbr_ptr[j] + r - 1;
  *w = m->g + 3 * e;
  return m->nbr[e];
}

static inline long closed_size(const fpm_model *m, long j) {
  return m->nbr_ptr[j + 1] - m->nbr_ptr[j] + 1;
}

static void tangent_free(tangent *t) {
  free(t->R_ptr);
  free(t->R_list);
  free(t->E_ptr);
  free(t->E_j);
  free(t->E);
  free(t->S_ptr);
  free(t->S_m);
  free(t->S);
  free(t->Dg);
  free(t->Dg_ptr);
  free(t->work);
  free(t->mark);
}

/* Adds the 3 x 3 geometry C^c_ij (rows s, columns q) of T_i = sum_j P_j C_ij
 * for component row c: member r of i's closed support. */
static void flux_geometry(const fpm_model *m, const long *dpt_of, long i,
                          long r, int c, double C[9], double cv[3]) {
  if (r == 0) {
    const double *Bm = m->p_mrel + 9 * i, *A = m->p_area + 3 * i;
    for (int a = 0; a < 9; a++) C[a] = -0.5 * Bm[a];
    for (int a = 0; a < 3; a++) {
      C[4 * a] += m->dual->volume[i];
      cv[a] = -0.5 * A[a];
    }
    long p = dpt_of[i];
    if (p >= 0) {
      const double *Ac = m->dpt_area + 9 * p + 3 * c,
                   *Bc = m->dpt_mrel + 27 * p + 9 * c;
      for (int a = 0; a < 9; a++) C[a] -= Bc[a];
      for (int a = 0; a < 3; a++) cv[a] -= Ac[a];
    }
    return;
  }
  const double *rec = m->erec + FPM_EREC * (m->nbr_ptr[i] + r - 1);
  const double *a = rec, *Mc = rec + 3, *di = rec + 12;
  for (int s = 0; s < 3; s++) {
    cv[s] = -0.5 * a[s];
    for (int q = 0; q < 3; q++)
      C[3 * s + q] = -0.5 * (Mc[3 * s + q] + a[s] * di[q]);
  }
}

/* E: per point k, the points j whose stress reaches f_k, with
 * E^c_kj[s] = sum_i C^c_ij[s] . gamma_ik + c^c_kj[s]. */
static pm_err build_E(const fpm_model *m, tangent *t) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own; /* (rows: the own points') */
  long *mark = NULL, *list = NULL, *dpt_of = NULL;
  PM_TRY(PM_ALLOC(mark, n, "tangent marks"));
  PM_TRY(PM_ALLOC(list, n, "tangent lists"));
  PM_TRY(PM_ALLOC(dpt_of, n, "prescribed-face points"));
  PM_TRY(PM_ALLOC(t->E_ptr, n + 1, "tangent geometry"));
  for (long i = 0; i < n; i++) mark[i] = dpt_of[i] = -1;
  for (long p = 0; p < m->n_dpts; p++) dpt_of[m->dpt_point[p]] = p;
  for (int pass = 0; pass < 2; pass++) {
    for (long k = 0; k < rows; k++) {
      long cnt = 0;
      /* i over k's closed support: gamma_ik is the weight of u_k in H_i */
      for (long ri = 0; ri < closed_size(m, k); ri++) {
        const double *dummy;
        long i = closed_member(m, k, ri, &dummy);
        for (long rj = 0; rj < closed_size(m, i); rj++) {
          long j = closed_member(m, i, rj, &dummy);
          if (mark[j] < 0) {
            mark[j] = cnt;
            list[cnt++] = j;
          }
        }
      }
      if (pass == 1) {
        double *E = t->E + 9 * t->E_ptr[k];
        for (long a = 0; a < cnt; a++) t->E_j[t->E_ptr[k] + a] = list[a];
        for (long ri = 0; ri < closed_size(m, k); ri++) {
          const double *w;
          long i = closed_member(m, k, ri, &w);
          double gik[3];
          if (ri == 0)
            for (int a = 0; a < 3; a++) gik[a] = -w[a];
          else {
            const double *g = m->g + 3 * m->mirror[m->nbr_ptr[k] + ri - 1];
            for (int a = 0; a < 3; a++) gik[a] = g[a];
          }
          for (long rj = 0; rj < closed_size(m, i); rj++) {
            const double *dummy;
            long j = closed_member(m, i, rj, &dummy);
            double *Ekj = E + 9 * mark[j];
            for (int c = 0; c < 3; c++) {
              double C[9], cv[3];
              flux_geometry(m, dpt_of, i, rj, c, C, cv);
              for (int s2 = 0; s2 < 3; s2++)
                Ekj[3 * c + s2] += C[3 * s2] * gik[0] + C[3 * s2 + 1] * gik[1] +
                                   C[3 * s2 + 2] * gik[2];
            }
          }
        }
        /* r_k = sum_j P_j c_kj over k's closed support */
        for (long rj = 0; rj < closed_size(m, k); rj++) {
          const double *dummy;
          long j = closed_member(m, k, rj, &dummy);
          for (int c = 0; c < 3; c++) {
            double C[9], cv[3];
            flux_geometry(m, dpt_of, k, rj, c, C, cv);
            for (int s2 = 0; s2 < 3; s2++)
              E[9 * mark[j] + 3 * c + s2] += cv[s2];
          }
        }
      } else {
        t->E_ptr[k + 1] = cnt;
      }
      for (long a = 0; a < cnt; a++) mark[list[a]] = -1;
    }
    if (pass == 0) {
      for (long k = 0; k < rows; k++) t->E_ptr[k + 1] += t->E_ptr[k];
      PM_TRY(PM_ALLOC(t->E_j, t->E_ptr[rows] + 1, "tangent geometry"));
      PM_TRY(PM_ALLOC(t->E, 9 * t->E_ptr[rows] + 1, "tangent geometry"));
    }
  }
done:
  free(mark);
  free(list);
  free(dpt_of);
  return ret;
}

/* The penalty's reconstruction weight of u_x in point i's field at offset
 * d (linear: H_i d; quadratic: theta_i phi(d)), for the r-th member of
 * i's reconstruction support; returns the member's point. */
static long recon_member(const fpm_model *m, long i, long r, const double d[3],
                         double *w) {
  if (m->q) {
    double phi[FPM_QFIT];
    fpm_gfd_phi(d, phi);
    const double *q;
    long x;
    if (r == 0) {
      q = m->qsum + FPM_QFIT * i;
      x = i;
    } else {
      q = m->q + FPM_QFIT * (m->qs_ptr[i] + r - 1);
      x = m->qs_nbr[m->qs_ptr[i] + r - 1];
    }
    double v = 0;
    for (int a = 0; a < FPM_QFIT; a++) v += q[a] * phi[a];
    *w = r == 0 ? -v : v;
    return x;
  }
  const double *g;
  long x = closed_member(m, i, r, &g);
  double v = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
  *w = r == 0 ? -v : v;
  return x;
}

static long recon_size(const fpm_model *m, long i) {
  return m->q ? m->qs_ptr[i + 1] - m->qs_ptr[i] + 1 : closed_size(m, i);
}

/* S: the penalty's scalar matrix, S_km = sum_i sum_(e of i) beta_e
 * t_ek J_em with [[u]]_e = sum_m J_em u_m and t_ek = d[[u]]_e / d u_k
 * through point i's side only (the force of the side's own field). */
static pm_err build_S(const fpm_model *m, tangent *t) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own;
  long *mark = NULL, *list = NULL;
  double *acc = NULL;
  PM_TRY(PM_ALLOC(mark, n, "penalty marks"));
  PM_TRY(PM_ALLOC(list, n, "penalty lists"));
  PM_TRY(PM_ALLOC(acc, n, "penalty row"));
  PM_TRY(PM_ALLOC(t->S_ptr, n + 1, "penalty matrix"));
  for (long i = 0; i < n; i++) mark[i] = -1;
  for (int pass = 0; pass < 2; pass++) {
    for (long k = 0; k < rows; k++) {
      long cnt = 0;
      /* the points i whose own field at their interfaces moves with u_k:
       * k itself and those whose reconstruction holds k */
      long ni = m->q ? 1 + m->qt_ptr[k + 1] - m->qt_ptr[k] : closed_size(m, k);
      for (long ii = 0; ii < ni; ii++) {
        long i;
        if (ii == 0)
          i = k;
        else if (m->q)
          i = m->qs_own[m->qt_entry[m->qt_ptr[k] + ii - 1]];
        else
          i = m->nbr[m->nbr_ptr[k] + ii - 1];
        for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
          const double *rec = m->erec + FPM_EREC * e;
          const double *di = rec + 12, *dk = rec + 15, be = rec[18];
          const long kk = m->nbr[e];
          /* t_ek: k's weight in u_i + recon_i(d_i) */
          double tk = 0;
          for (long r = 0; r < recon_size(m, i); r++) {
            double w;
            if (recon_member(m, i, r, di, &w) == k) tk += w;
          }
          if (k == i) tk += 1;
          if (tk == 0 || be == 0) continue;
          /* J_em over both sides */
          for (int side = 0; side < 2; side++) {
            long p = side ? kk : i;
            double sign = side ? -1 : 1;
            const double *d = side ? dk : di;
            for (long r = 0; r < recon_size(m, p); r++) {
              double w;
              long x = recon_member(m, p, r, d, &w);
              if (r == 0) w += 1;
              if (mark[x] < 0) {
                mark[x] = cnt;
                list[cnt++] = x;
                acc[mark[x]] = 0;
              }
              acc[mark[x]] += be * tk * sign * w;
            }
          }
        }
      }
      if (pass == 0)
        t->S_ptr[k + 1] = cnt;
      else
        for (long a = 0; a < cnt; a++) {
          t->S_m[t->S_ptr[k] + a] = list[a];
          t->S[t->S_ptr[k] + a] = acc[a];
        }
      for (long a = 0; a < cnt; a++) mark[list[a]] = -1;
    }
    if (pass == 0) {
      for (long k = 0; k < rows; k++) t->S_ptr[k + 1] += t->S_ptr[k];
      PM_TRY(PM_ALLOC(t->S_m, t->S_ptr[rows] > 0 ? t->S_ptr[rows] : 1,
                      "penalty matrix"));
      PM_TRY(PM_ALLOC(t->S, t->S_ptr[rows] > 0 ? t->S_ptr[rows] : 1,
                      "penalty matrix"));
    }
  }
done:
  free(mark);
  free(list);
  free(acc);
  return ret;
}

/* Rows are the own points' (a share's; all on one process), the products
 * D gamma those of the points whose stress they read. */
static pm_err tangent_build(const fpm_model *m, tangent *t) {
  const long n = m->n, ns = m->n_stress;
  PM_CALL(build_E(m, t));
  PM_CALL(build_S(m, t));
  PM_CALL(PM_ALLOC(t->Dg_ptr, ns + 1, "tangent products"));
  for (long j = 0; j < ns; j++)
    t->Dg_ptr[j + 1] = t->Dg_ptr[j] + closed_size(m, j);
  PM_CALL(PM_ALLOC(t->Dg, 27 * t->Dg_ptr[ns], "tangent products"));
  t->max_reach = 0;
  for (long k = 0; k < m->n_own; k++)
    if (t->R_ptr[k + 1] - t->R_ptr[k] > t->max_reach)
      t->max_reach = t->R_ptr[k + 1] - t->R_ptr[k];
  t->threads = pm_omp_threads();
  PM_CALL(PM_ALLOC(t->mark, (size_t)t->threads * n, "tangent marks"));
  for (long a = 0; a < (long)t->threads * n; a++) t->mark[a] = -1;
  PM_CALL(PM_ALLOC(t->work, (size_t)t->threads * 9 * t->max_reach,
                   "tangent blocks"));
  return PM_SUCCESS;
}

static pm_err tangent_values(void *ctx, const double *x, double *val) {
  static_ctx *c = ctx;
  (void)x;
  const fpm_model *m = c->m;
  tangent *t = &c->tg;
  const long n = m->n, ns = m->n_stress, rows = m->n_own;
  const double *D = fpm_linear_tangent(c->lin);
  /* D_j gamma_jm for every j (whose stress the rows read) and member m of
   * its closed support */
  PM_OMP(parallel for schedule(static) default(none) shared(ns, m, t, D))
  for (long j = 0; j < ns; j++) {
    const double *Dj = D + 81 * j;
    for (long r = 0; r < closed_size(m, j); r++) {
      const double *w;
      closed_member(m, j, r, &w);
      double g[3] = {w[0], w[1], w[2]};
      if (r == 0) g[0] = -g[0], g[1] = -g[1], g[2] = -g[2];
      double *out = t->Dg + 27 * (t->Dg_ptr[j] + r);
      for (int row = 0; row < 9; row++)
        for (int a = 0; a < 3; a++)
          out[3 * row + a] = Dj[9 * row + 3 * a] * g[0] +
                             Dj[9 * row + 3 * a + 1] * g[1] +
                             Dj[9 * row + 3 * a + 2] * g[2];
    }
  }
  const long *free_of = c->free_of, *pat = c->pat_ptr;
  PM_OMP(parallel default(none) shared(n, rows, m, t, free_of, pat, val)) {
    int th = 0;
#ifdef _OPENMP
    th = omp_get_thread_num();
#endif
    long *mark = t->mark + (size_t)th * n;
    double *blk = t->work + (size_t)th * 9 * t->max_reach;
    PM_OMP(for schedule(dynamic, 16))
    for (long k = 0; k < rows; k++) {
      const long r0 = t->R_ptr[k], nr = t->R_ptr[k + 1] - r0;
      for (long a = 0; a < nr; a++) mark[t->R_list[r0 + a]] = a;
      for (long a = 0; a < 9 * nr; a++) blk[a] = 0;
      for (long q = t->E_ptr[k]; q < t->E_ptr[k + 1]; q++) {
        const long j = t->E_j[q];
        const double *E = t->E + 9 * q;
        for (long r = 0; r < closed_size(m, j); r++) {
          const double *w;
          long mm = closed_member(m, j, r, &w);
          const double *Dg = t->Dg + 27 * (t->Dg_ptr[j] + r);
          double *b = blk + 9 * mark[mm];
          for (int cc = 0; cc < 3; cc++)
            for (int a = 0; a < 3; a++)
              b[3 * cc + a] += E[3 * cc] * Dg[3 * (3 * cc) + a] +
                               E[3 * cc + 1] * Dg[3 * (3 * cc + 1) + a] +
                               E[3 * cc + 2] * Dg[3 * (3 * cc + 2) + a];
        }
      }
      for (long q = t->S_ptr[k]; q < t->S_ptr[k + 1]; q++) {
        double *b = blk + 9 * mark[t->S_m[q]];
        for (int cc = 0; cc < 3; cc++) b[4 * cc] += t->S[q];
      }
      for (int cc = 0; cc < 3; cc++) {
        long row = free_of[3 * k + cc];
        if (row < 0) continue;
        long w = pat[row];
        for (long a = 0; a < nr; a++)
          for (int b = 0; b < 3; b++)
            if (free_of[3 * t->R_list[r0 + a] + b] >= 0)
              val[w++] = blk[9 * a + 3 * cc + b];
      }
      for (long a = 0; a < nr; a++) mark[t->R_list[r0 + a]] = -1;
    }
  }
  return PM_SUCCESS;
}

/* Marks the points of S(i) and i into list (marker: stamp). */
static long add_support(const fpm_model *m, long i, long *list, long cnt,
                        long *mark, long stamp) {
  if (mark[i] != stamp) {
    mark[i] = stamp;
    list[cnt++] = i;
  }
  for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
    long k = m->nbr[e];
    if (mark[k] != stamp) {
      mark[k] = stamp;
      list[cnt++] = k;
    }
  }
  return cnt;
}

static long add_fit(const fpm_model *m, long j, long *list, long cnt,
                    long *mark, long stamp) {
  if (!m->q) return cnt;
  for (long e = m->qs_ptr[j]; e < m->qs_ptr[j + 1]; e++) {
    long k = m->qs_nbr[e];
    if (mark[k] != stamp) {
      mark[k] = stamp;
      list[cnt++] = k;
    }
  }
  return cnt;
}

/* The points whose displacement reaches the force on point k, into reach
 * (returns the count). */
static long reach(const fpm_model *m, long k, long *reach_list, long *a_list,
                  long *mark_a, long *mark_r, long stamp) {
  long na = add_support(m, k, a_list, 0, mark_a, stamp);
  if (m->q)
    for (long t = m->qt_ptr[k]; t < m->qt_ptr[k + 1]; t++) {
      long i = m->qs_own[m->qt_entry[t]];
      if (mark_a[i] != stamp) {
        mark_a[i] = stamp;
        a_list[na++] = i;
      }
    }
  long nr = 0;
  for (long ia = 0; ia < na; ia++) {
    long i = a_list[ia];
    for (long e = m->nbr_ptr[i] - 1; e < m->nbr_ptr[i + 1]; e++) {
      long j = e < m->nbr_ptr[i] ? i : m->nbr[e];
      nr = add_support(m, j, reach_list, nr, mark_r, stamp);
      nr = add_fit(m, j, reach_list, nr, mark_r, stamp);
    }
  }
  return nr;
}

/* The Jacobian's pattern over the nf unknowns (free_of: dof -> unknown):
 * the rows of the own points' (a share's ghosts' rows are empty). */
static pm_err build_pattern(const fpm_model *m, const long *free_of, long nf,
                            tangent *tg, long **ptr_out, long **idx_out) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own;
  long *mark_a = NULL, *mark_r = NULL, *a_list = NULL, *r_list = NULL,
       *ptr = NULL, *idx = NULL;
  PM_TRY(PM_ALLOC(mark_a, n, "pattern marks"));
  PM_TRY(PM_ALLOC(mark_r, n, "pattern marks"));
  PM_TRY(PM_ALLOC(a_list, n, "pattern lists"));
  PM_TRY(PM_ALLOC(r_list, n, "pattern lists"));
  PM_TRY(PM_ALLOC(ptr, nf + 1, "Jacobian pattern"));
  PM_TRY(PM_ALLOC(tg->R_ptr, n + 1, "Jacobian reach"));
  for (long i = 0; i < n; i++) mark_a[i] = mark_r[i] = -1;
  /* Count, then fill. */
  for (int pass = 0; pass < 2; pass++) {
    for (long k = 0; k < rows; k++) {
      long nr = reach(m, k, r_list, a_list, mark_a, mark_r, pass * n + k);
      if (pass == 0)
        tg->R_ptr[k + 1] = nr;
      else
        for (long t = 0; t < nr; t++) tg->R_list[tg->R_ptr[k] + t] = r_list[t];
      long cols = 0;
      for (long t = 0; t < nr; t++)
        for (int a = 0; a < 3; a++) cols += free_of[3 * r_list[t] + a] >= 0;
      for (int c = 0; c < 3; c++) {
        long row = free_of[3 * k + c];
        if (row < 0) continue;
        if (pass == 0) {
          ptr[row + 1] = cols;
          continue;
        }
        long w = ptr[row];
        for (long t = 0; t < nr; t++)
          for (int a = 0; a < 3; a++) {
            long col = free_of[3 * r_list[t] + a];
            if (col >= 0) idx[w++] = col;
          }
      }
    }
    if (pass == 0) {
      for (long k = 0; k < rows; k++) tg->R_ptr[k + 1] += tg->R_ptr[k];
      PM_TRY(PM_ALLOC(tg->R_list, tg->R_ptr[rows] + 1, "Jacobian reach"));
      for (long r = 0; r < nf; r++) ptr[r + 1] += ptr[r];
      PM_TRY(PM_ALLOC(idx, ptr[nf] > 0 ? ptr[nf] : 1, "Jacobian pattern"));
    }
  }
  *ptr_out = ptr;
  *idx_out = idx;
  ptr = idx = NULL;
done:
  free(mark_a);
  free(mark_r);
  free(a_list);
  free(r_list);
  free(ptr);
  free(idx);
  return ret;
}

/* Everything a solve needs of the model: the free dofs, the Jacobian's
 * pattern, the directly assembled tangent's constant parts, the
 * linearisation's work space, and the problem for pm_newton.  Released by
 * solve_free (also after a failure here). */
typedef struct {
  static_ctx c;
  long *free_of, *ptr, *idx;
  double *x;
  double *rigid; /* the rigid motions on the free dofs (for multigrid) */
  pm_newton_problem prob;
} solve_t;

static void solve_free(solve_t *v) {
  fpm_linear_destroy(v->c.lin);
  tangent_free(&v->c.tg);
  free(v->c.dof);
  free(v->c.ghost);
  free(v->c.held);
  free(v->c.du);
  free(v->c.df);
  free(v->c.u_old);
  free(v->free_of);
  free(v->ptr);
  free(v->idx);
  free(v->x);
  free(v->rigid);
}

/* The rigid motions of the body restricted to the free dofs: translations
 * along each axis and rotations about the centroid (3 and 3 in 3D; x, y
 * and the rotation about z in 2D), into rigid (count x nf). */
static int rigid_modes(const fpm_model *m, const long *dof, long nf,
                       double *rigid) {
  double c[3] = {0, 0, 0};
  if (m->xc) { /* the body's centroid: every rank's own points */
    double sum[4] = {0, 0, 0, (double)m->n_own};
    for (long i = 0; i < m->n_own; i++)
      for (int a = 0; a < 3; a++) sum[a] += m->x[3 * i + a];
    fpm_exchange_sum(m->xc, sum, 4);
    for (int a = 0; a < 3; a++) c[a] = sum[a] / sum[3];
  } else {
    for (long i = 0; i < m->n; i++)
      for (int a = 0; a < 3; a++) c[a] += m->x[3 * i + a] / (double)m->n;
  }
  /* rotation about axis r: u = e_r x (x - c) */
  const int rots3[3] = {0, 1, 2}, rots2[1] = {2};
  const int nt = m->dim, nr = m->dim == 3 ? 3 : 1;
  const int *rots = m->dim == 3 ? rots3 : rots2;
  for (long j = 0; j < nf; j++) {
    const long i = dof[j] / 3;
    const int comp = (int)(dof[j] % 3);
    const double *x = m->x + 3 * i;
    for (int t = 0; t < nt; t++) rigid[t * nf + j] = comp == t ? 1 : 0;
    for (int q = 0; q < nr; q++) {
      const int r = rots[q], a = (r + 1) % 3, b = (r + 2) % 3;
      /* (e_r x d)_a = -d_b, (e_r x d)_b = d_a */
      double val = 0;
      if (comp == a) val = -(x[b] - c[b]);
      if (comp == b) val = x[a] - c[a];
      rigid[(nt + q) * nf + j] = val;
    }
  }
  return nt + nr;
}

/* Across ranks: the unknowns of the ghosts, numbered after the own ones,
 * and their numbers over all ranks (each rank's own unknowns follow the
 * ranks' before it; a ghost's are its owner's, by the exchange of the
 * displacements).  A ghost's dof is an unknown where its owner's is. */
static pm_err number_ghosts(const fpm_model *m, long *free_of, static_ctx *c) {
  const long n = m->n;
  double *g = c->du; /* 3 n: the numbers, exact in doubles */
  const long first = fpm_exchange_offset(m->xc, c->nf);
  for (long d = 0; d < 3 * n; d++)
    g[d] = free_of[d] >= 0 ? (double)(first + free_of[d]) : -1;
  fpm_exchange_ghosts(m->xc, g);
  long count = 0;
  for (long d = 3 * m->n_own; d < 3 * n; d++) count += g[d] >= 0;
  PM_CALL(PM_ALLOC(c->ghost, count + 1, "ghost unknowns"));
  for (long d = 3 * m->n_own; d < 3 * n; d++) {
    if (g[d] < 0) continue;
    c->ghost[c->nheld - c->nf] = (long)g[d];
    free_of[d] = c->nheld;
    c->dof[c->nheld++] = d;
  }
  return PM_SUCCESS;
}

static pm_err solve_setup(const fpm_model *m, fpm_state *st, solve_t *v) {
  const long n = m->n;
  static_ctx *c = &v->c;
  c->m = m;
  c->st = st;
  c->load_end = pm_scene_load_end(m->scene);
  PM_CALL(fpm_linear_create(m, &c->lin));
  PM_CALL(PM_ALLOC(v->free_of, 3 * n, "free dofs"));
  PM_CALL(PM_ALLOC(c->dof, 3 * n, "free dofs"));
  PM_CALL(PM_ALLOC(c->du, 3 * n, "displacement increment"));
  PM_CALL(PM_ALLOC(c->df, 3 * n, "force increment"));
  PM_CALL(PM_ALLOC(c->u_old, 3 * n, "converged displacement"));
  for (long d = 0; d < 3 * n; d++) {
    v->free_of[d] = -1;
    if (d < 3 * m->n_own && !m->fixed[d]) {
      v->free_of[d] = c->nf;
      c->dof[c->nf++] = d;
    }
  }
  c->nheld = c->nf;
  if (m->xc) PM_CALL(number_ghosts(m, v->free_of, c));
  long all = c->nf;
  if (m->xc) fpm_exchange_sum_long(m->xc, &all, 1);
  PM_CHECK(all > 0, PM_ERR_SCENE, "%s: every displacement is prescribed",
           m->scene->path);
  PM_CALL(PM_ALLOC(v->x, c->nf + 1, "free displacements"));
  PM_CALL(PM_ALLOC(c->held, c->nheld + 1, "held displacements"));
  PM_CALL(build_pattern(m, v->free_of, c->nheld, &c->tg, &v->ptr, &v->idx));
  c->pat_ptr = v->ptr;
  c->free_of = v->free_of;
  PM_CALL(tangent_build(m, &c->tg));
  PM_CALL(PM_ALLOC(v->rigid, 6 * c->nf, "rigid motions"));
  const int n_rigid = rigid_modes(m, c->dof, c->nf, v->rigid);
  v->prob = (pm_newton_problem){.n = c->nf,
                                .ctx = c,
                                .residual = residual,
                                .jacobian_apply = apply,
                                .jacobian_prepare = prepare,
                                .jacobian_values = tangent_values,
                                .pat_ptr = v->ptr,
                                .pat_idx = v->idx,
                                .near_null_count = n_rigid,
                                .near_null = v->rigid,
                                .shared = m->xc != NULL,
                                .n_ghost = c->nheld - c->nf,
                                .ghost = c->ghost,
                                .set_load = set_load,
                                .on_step = on_step};
  return PM_SUCCESS;
}

/* A force floor far below any load but above the force's round-off: the
 * stiffest modulus times the squared size of the body, times 1e-12. */
static double force_floor(const fpm_model *m) {
  double emax = 0, lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < m->n_mats; k++)
    emax = fmax(emax, m->mats[k].youngs_modulus);
  for (long i = 0; i < m->n_own; i++)
    for (int a = 0; a < 3; a++) {
      lo[a] = fmin(lo[a], m->x[3 * i + a]);
      hi[a] = fmax(hi[a], m->x[3 * i + a]);
    }
  if (m->xc) { /* the body's box: every rank's points (the same floor) */
    fpm_exchange_min(m->xc, lo, 3);
    for (int a = 0; a < 3; a++) hi[a] = -hi[a];
    fpm_exchange_min(m->xc, hi, 3);
    for (int a = 0; a < 3; a++) hi[a] = -hi[a];
  }
  double diag2 = 0;
  for (int a = 0; a < 3; a++) diag2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  return 1e-12 * emax * diag2;
}

void fpm_static_nodal(const fpm_model *m, const double *x, double *u) {
  long j = 0;
  for (long d = 0; d < 3 * m->n_own; d++) u[d] = m->fixed[d] ? 0 : x[j++];
}

void fpm_static_unknowns(const fpm_model *m, const double *u, double *x) {
  long j = 0;
  for (long d = 0; d < 3 * m->n_own; d++)
    if (!m->fixed[d]) x[j++] = u[d];
}

pm_err fpm_static_state_init(fpm_static_state *s, const fpm_model *m) {
  memset(s, 0, sizeof *s);
  for (long d = 0; d < 3 * m->n_own; d++) s->free_dofs += !m->fixed[d];
  return pm_load_state_init(&s->load, s->free_dofs > 0 ? s->free_dofs : 1);
}

void fpm_static_state_free(fpm_static_state *s) {
  pm_load_state_free(&s->load);
}

pm_err fpm_static_run(const fpm_model *m, fpm_state *st, fpm_observer observer,
                      void *ctx, fpm_step_info *info, fpm_static_report *rep) {
  fpm_static_state ss;
  PM_CALL(fpm_static_state_init(&ss, m));
  pm_err e = fpm_static_run_from(m, st, &ss, observer, ctx, info, rep);
  fpm_static_state_free(&ss);
  return e;
}

pm_err fpm_static_run_from(const fpm_model *m, fpm_state *st,
                           fpm_static_state *ss, fpm_observer observer,
                           void *ctx, fpm_step_info *info,
                           fpm_static_report *rep) {
  pm_err ret = PM_SUCCESS;
  solve_t v = {.c = {.observer = observer, .octx = ctx}};
  const pm_scene *s = m->scene;
  static_ctx *c = &v.c;
  pm_newton *solver = NULL;
  const bool resumed = ss->load.lambda > 0;
  const pm_load_report done_before = rep->load;
  memset(rep, 0, sizeof *rep);
  if (resumed) rep->load = done_before;
  c->ext_work = &ss->external_work;
  double w0 = pm_wtime();
  PM_TRY(solve_setup(m, st, &v));
  long sizes[2] = {c->nf, v.ptr[c->nheld]};
  if (m->xc) fpm_exchange_sum_long(m->xc, sizes, 2);
  rep->unknowns = sizes[0];
  rep->pattern_entries = sizes[1];
  PM_ENSURE(c->nf == ss->free_dofs, PM_ERR_ARG,
            "static state of %ld free dofs for a model of %ld", ss->free_dofs,
            c->nf);

  if (!resumed) {
    /* The initial state, as a frame. */
    memset(st->u, 0, 3 * m->n * sizeof(double));
    ss->external_work = 0;
    PM_TRY(set_load(c, 0));
  } else {
    /* The last converged state: its force gives the supports' forces the
     * work of the next step starts from, as in the first run. */
    PM_TRY(set_load(c, ss->load.lambda));
    c->t = ss->load.lambda * c->load_end;
    memcpy(v.x, ss->load.xc, (size_t)c->nf * sizeof *v.x);
  }
  /* (across ranks the state holds a resumed run's displacements on every
   * point, its ghosts' too) */
  PM_TRY(admissible(c, evaluate(c, resumed && !m->xc ? v.x : NULL)));
  fpm_support_start(m, st);
  memcpy(c->u_old, st->u, 3 * m->n * sizeof(double));
  /* The figures of the state (a resumed one's too, for a run that fails
   * before its next step); only the initial state is a frame. */
  figures(c, rep->load.steps);
  if (!resumed && observer) PM_TRY(observer(ctx, m, st, &c->si, true));

  pm_newton_options no = pm_newton_options_default();
  no.rtol = s->time.qs_tolerance;
  no.atol = force_floor(m);
  no.max_iter = (int)s->time.qs_max_iterations;
  /* A step Newton creeps through (short line-search steps from a state
   * outside its basin) is cut sooner than at max_iter. */
  no.stall_after = 6;
  no.linear = pm_newton_linear_of(s->time.qs_linear);
  no.load_steps = (int)s->time.qs_load_steps;
  no.predictor = true;
  no.petsc_options = s->time.qs_solver_options;
  /* SIPG: the assembled tangent lacks the adjoint term's derivative; it
   * preconditions the exact tangent applied matrix-free. */
  if (m->flux == FPM_FLUX_SIPG) no.op = PM_NEWTON_MATRIX_FREE;
  PM_TRY(pm_newton_create(&v.prob, &no, &solver));
  c->solver = solver;
  rep->setup_seconds = pm_wtime() - w0;
  ret = pm_load_steps_from(solver, v.x, &ss->load, &rep->load);
done:
  if (info) *info = c->si;
  pm_newton_destroy(&solver);
  solve_free(&v);
  return ret;
}

pm_err fpm_static_check_tangent(const fpm_model *m, fpm_state *st,
                                const double *u, double *assembled_error,
                                double *difference_error) {
  pm_err ret = PM_SUCCESS;
  solve_t v = {0};
  double *v1 = NULL, *v2 = NULL;
  pm_newton *direct = NULL, *colored = NULL;
  PM_TRY(solve_setup(m, st, &v));
  memcpy(st->u, u, 3 * m->n * sizeof(double));
  for (long j = 0; j < v.c.nf; j++) v.x[j] = u[v.c.dof[j]];
  pm_newton_options no = pm_newton_options_default();
  PM_TRY(pm_newton_create(&v.prob, &no, &direct));
  v.prob.jacobian_values = NULL;
  PM_TRY(pm_newton_create(&v.prob, &no, &colored));
  const long nv = v.ptr[v.c.nf];
  PM_TRY(PM_ALLOC(v1, nv, "tangent values"));
  PM_TRY(PM_ALLOC(v2, nv, "tangent values"));
  PM_TRY(pm_newton_jacobian_values(direct, v.x, v1));
  PM_TRY(pm_newton_jacobian_values(colored, v.x, v2));
  double dmax = 0, big = 0;
  for (long k = 0; k < nv; k++) {
    dmax = fmax(dmax, fabs(v1[k] - v2[k]));
    big = fmax(big, fabs(v2[k]));
  }
  *assembled_error = big > 0 ? dmax / big : dmax;
  if (difference_error) {
    long row, col;
    PM_TRY(pm_newton_check_jacobian(direct, v.x, 1e-7, difference_error, &row,
                                    &col));
  }
done:
  pm_newton_destroy(&direct);
  pm_newton_destroy(&colored);
  solve_free(&v);
  free(v1);
  free(v2);
  return ret;
}
