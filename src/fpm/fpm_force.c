/* fpm_force: the net nodal force of the FPM discretization in three
 * gathers (stress per point, flux per point, force per point): no scatter,
 * no atomics, no allocation. */
#include <math.h>

#include "fpm_model.h"
#include "pm_material.h"
#include "pm_omp.h"
#include "pm_tensor.h"

/* Pass 1: F_i = I + sum_k (u_k - u_i) (x) g_ik, then P_i, W_i, J_i.
 * Returns the smallest inadmissible point id or -1. */
static long stress_pass(const fpm_model *m, fpm_state *st) {
  const long n = m->n;
  const long *restrict ptr = m->nbr_ptr;
  const int *restrict nbr = m->nbr;
  const double *restrict g = m->g, *restrict u = st->u;
  double *restrict H = st->H, *restrict P = st->P, *restrict W = st->W,
                   *restrict J = st->J;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const double *ms = m->mstate;
  const long mss = m->mstate_stride;
  long bad = n;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, nbr, g, u, H, P, W, J, mat, mats, ms, mss)
         reduction(min : bad))
  for (long i = 0; i < n; i++) {
    double h[9] = {0};
    const double u0 = u[3 * i], u1 = u[3 * i + 1], u2 = u[3 * i + 2];
    for (long e = ptr[i]; e < ptr[i + 1]; e++) {
      const long k = nbr[e];
      const double d0 = u[3 * k] - u0, d1 = u[3 * k + 1] - u1,
                   d2 = u[3 * k + 2] - u2;
      const double g0 = g[3 * e], g1 = g[3 * e + 1], g2 = g[3 * e + 2];
      h[0] += d0 * g0;
      h[1] += d0 * g1;
      h[2] += d0 * g2;
      h[3] += d1 * g0;
      h[4] += d1 * g1;
      h[5] += d1 * g2;
      h[6] += d2 * g0;
      h[7] += d2 * g1;
      h[8] += d2 * g2;
    }
    double F[9];
    for (int a = 0; a < 9; a++) {
      H[9 * i + a] = h[a];
      F[a] = h[a];
    }
    F[0] += 1;
    F[4] += 1;
    F[8] += 1;
    if (!pm_material_stress(&mats[mat[i]], F, ms ? ms + mss * i : NULL,
                            P + 9 * i, W + i, J + i) &&
        i < bad)
      bad = i;
  }
  return bad < n ? bad : -1;
}

/* Pass 2: per point i, over its interfaces e with outward area vector a,
 * d_i = x_e - X_i, d_k = x_e - X_k:
 *   [[u]] = u_i + H_i d_i - u_k - H_k d_k,  b = beta |e| [[u]],
 *   r_i = sum_e (b - P_e a),  Q_i = sum_e (P_e (M_e - a (x) X_i) - b (x) d_i)
 * with P_e = (P_i + P_k) / 2, and T_i = V_i P_i - Q_i.  With the moment
 * about the centroid, M_e - a (x) X_i = Mc + a (x) d_i, the neighbour's half
 * is  1/2 P_k Mc + w (x) d_i  with  w = 1/2 P_k a - b;  the P_i half uses
 * the precomputed sums of a and M_e - a (x) X_i.  Entry records stream in
 * order; only the neighbours' u, H, P are gathered.  Also the interface
 * energy 1/2 sum_e beta |e| [[u]]^2 (and, for SIPG, - sum_e {P} : K_e). */
static void flux_pass(const fpm_model *m, fpm_state *st) {
  const long n = m->n;
  const long *restrict ptr = m->nbr_ptr;
  const int *restrict nbr = m->nbr;
  const double *restrict erec = m->erec, *restrict pa = m->p_area,
                         *restrict pm = m->p_mrel,
                         *restrict vol = m->dual->volume;
  const double *restrict u = st->u, *restrict H = st->H, *restrict P = st->P;
  double *restrict T = st->T, *restrict r = st->r;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const double *ms = m->mstate;
  const long mss = m->mstate_stride;
  const bool sym = m->flux == FPM_FLUX_SIPG;
  double epen = 0;
  PM_OMP(parallel for schedule(static) default(none) reduction(+ : epen)
         shared(n, ptr, nbr, erec, pa, pm, vol, u, H, P, T, r, mat, mats, ms,
                mss, sym))
  for (long i = 0; i < n; i++) {
    const double *Pi = P + 9 * i, *Hi = H + 9 * i, *ui = u + 3 * i;
    double Q[9] = {0}, ri[3] = {0}, B[9] = {0};
    for (long e = ptr[i]; e < ptr[i + 1]; e++) {
      const long k = nbr[e];
      const double *rec = erec + FPM_EREC * e;
      const double *a = rec, *Mc = rec + 3, *di = rec + 12, *dk = rec + 15;
      const double be = rec[18];
      const double *Pk = P + 9 * k, *Hk = H + 9 * k, *uk = u + 3 * k;
      double w[3];
      for (int c = 0; c < 3; c++) {
        const double jump = ui[c] - uk[c] + Hi[3 * c] * di[0] +
                            Hi[3 * c + 1] * di[1] + Hi[3 * c + 2] * di[2] -
                            Hk[3 * c] * dk[0] - Hk[3 * c + 1] * dk[1] -
                            Hk[3 * c + 2] * dk[2];
        w[c] = 0.5 * (Pk[3 * c] * a[0] + Pk[3 * c + 1] * a[1] +
                      Pk[3 * c + 2] * a[2]) -
               be * jump;
        ri[c] -= w[c];
        epen += 0.25 * be * jump * jump; /* each interface is seen twice */
        if (sym) {
          /* K_e = int_e [[u]] (x) n = [[u]](c_e) (x) a + (H_i - H_k) Mc^T */
          const double h0 = Hi[3 * c] - Hk[3 * c],
                       h1 = Hi[3 * c + 1] - Hk[3 * c + 1],
                       h2 = Hi[3 * c + 2] - Hk[3 * c + 2];
          for (int q = 0; q < 3; q++) {
            const double K = jump * a[q] + h0 * Mc[3 * q] + h1 * Mc[3 * q + 1] +
                             h2 * Mc[3 * q + 2];
            B[3 * c + q] += K;
            /* -{P} : K_e, each interface seen twice */
            epen -= 0.25 * (Pi[3 * c + q] + Pk[3 * c + q]) * K;
          }
        }
      }
      for (int c = 0; c < 3; c++)
        for (int q = 0; q < 3; q++)
          Q[3 * c + q] += 0.5 * (Pk[3 * c] * Mc[q] + Pk[3 * c + 1] * Mc[3 + q] +
                                 Pk[3 * c + 2] * Mc[6 + q]) +
                          w[c] * di[q];
    }
    if (sym) {
      /* The adjoint term: -1/2 A_i : sum_e K_e, the derivative of
       * -sum_e {P} : K_e through P_i (A_i = dP/dF at F_i). */
      double F[9], dP[9];
      for (int k = 0; k < 9; k++) F[k] = Hi[k];
      F[0] += 1;
      F[4] += 1;
      F[8] += 1;
      pm_material_tangent(&mats[mat[i]], F, ms ? ms + mss * i : NULL, B, dP);
      for (int k = 0; k < 9; k++) Q[k] += 0.5 * dP[k];
    }
    const double *A = pa + 3 * i, *Bm = pm + 9 * i;
    for (int c = 0; c < 3; c++) {
      r[3 * i + c] = ri[c] - 0.5 * (Pi[3 * c] * A[0] + Pi[3 * c + 1] * A[1] +
                                    Pi[3 * c + 2] * A[2]);
      for (int q = 0; q < 3; q++)
        T[9 * i + 3 * c + q] =
            vol[i] * Pi[3 * c + q] - Q[3 * c + q] -
            0.5 * (Pi[3 * c] * Bm[q] + Pi[3 * c + 1] * Bm[3 + q] +
                   Pi[3 * c + 2] * Bm[6 + q]);
    }
  }
  st->penalty_energy = epen;
}

/* Boundary terms: the consistency flux on facets with displacement
 * conditions, projected on the prescribed components
 * (r_i -= Pi P_i a_f, T_i -= Pi P_i (M_f - a_f (x) X_i)), and prescribed
 * tractions (r_i -= t |f|, T_i -= t (x) |f| (c_f - X_i)). */
static void boundary_pass(const fpm_model *m, fpm_state *st) {
  const long nd = m->n_dpts;
  const long *restrict dp = m->dpt_point;
  const double *restrict da = m->dpt_area, *restrict dm = m->dpt_mrel;
  const double *restrict P = st->P;
  double *restrict T = st->T, *restrict r = st->r, *restrict bf = st->bflux;
  double norm2 = 0;
  PM_OMP(parallel for schedule(static) default(none) reduction(+ : norm2)
         shared(nd, dp, da, dm, P, T, r, bf))
  for (long p = 0; p < nd; p++) {
    const long i = dp[p];
    const double *Pi = P + 9 * i;
    for (int c = 0; c < 3; c++) {
      const double *A = da + 9 * p + 3 * c, *B = dm + 27 * p + 9 * c;
      const double flux =
          Pi[3 * c] * A[0] + Pi[3 * c + 1] * A[1] + Pi[3 * c + 2] * A[2];
      r[3 * i + c] -= flux;
      bf[3 * p + c] = flux;
      norm2 += flux * flux;
      for (int q = 0; q < 3; q++)
        T[9 * i + 3 * c + q] -= Pi[3 * c] * B[q] + Pi[3 * c + 1] * B[3 + q] +
                                Pi[3 * c + 2] * B[6 + q];
    }
  }
  st->bflux_norm = sqrt(norm2);
  /* Several facets share a point: serial (boundary only). */
  for (long k = 0; k < m->n_tfacets; k++) {
    const long i = m->tf_point[k];
    const double *t = st->tf_value + 3 * k, *rel = m->tf_rel + 3 * k;
    for (int c = 0; c < 3; c++) {
      r[3 * i + c] -= t[c] * m->tf_area[k];
      for (int q = 0; q < 3; q++) T[9 * i + 3 * c + q] -= t[c] * rel[q];
    }
  }
}

/* Pass 3: f_k = sum_{i in S(k)} T_i g_ik - T_k sum_j g_kj + r_k. */
static void gather_pass(const fpm_model *m, fpm_state *st) {
  const long n = m->n;
  const long *restrict ptr = m->nbr_ptr;
  const int *restrict nbr = m->nbr, *restrict mir = m->mirror;
  const double *restrict g = m->g, *restrict gs = m->gsum, *restrict T = st->T,
                         *restrict r = st->r;
  double *restrict f = st->f;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, nbr, mir, g, gs, T, r, f))
  for (long k = 0; k < n; k++) {
    const double *Tk = T + 9 * k, *s = gs + 3 * k;
    double fk[3];
    for (int c = 0; c < 3; c++)
      fk[c] = r[3 * k + c] -
              (Tk[3 * c] * s[0] + Tk[3 * c + 1] * s[1] + Tk[3 * c + 2] * s[2]);
    for (long e = ptr[k]; e < ptr[k + 1]; e++) {
      const double *Ti = T + 9 * nbr[e], *gik = g + 3 * mir[e];
      for (int c = 0; c < 3; c++)
        fk[c] += Ti[3 * c] * gik[0] + Ti[3 * c + 1] * gik[1] +
                 Ti[3 * c + 2] * gik[2];
    }
    f[3 * k] = fk[0];
    f[3 * k + 1] = fk[1];
    f[3 * k + 2] = fk[2];
  }
}

long fpm_force(const fpm_model *m, fpm_state *st) {
  long bad = stress_pass(m, st);
  if (bad >= 0) return bad;
  flux_pass(m, st);
  boundary_pass(m, st);
  gather_pass(m, st);
  return -1;
}
