/* fpm_force: the net nodal force of the FPM discretization in three
 * gathers (stress per point, flux per point, force per point): no scatter,
 * no atomics, no allocation.  The force is linear in (u, H, P, theta) but
 * for P(F) and the SIPG adjoint term, so the same passes applied to
 * (du, dH, dP, dtheta) give its exact linearisation (fpm_force_linear). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_stream.h"
#include "fpm_gfd.h"
#include "fpm_linear_impl.h"
#include "fpm_loads.h"
#include "fpm_model.h"
#include "fpm_volumetric.h"
#include "fpm_penalty_terms.h"
#include "pm_material.h"
#include "pm_omp.h"
#include "pm_tensor.h"

/* The arrays one evaluation of the passes reads and writes: the state's
 * for the force, a fpm_linear's for its linearisation. */
typedef struct {
  const double *u, *H, *P, *theta; /* in */
  double *T, *r, *zq, *Zq, *f;     /* out */
  double *bflux;                   /* out, force only (else NULL) */
  /* linearisation only: u and H of the state linearised about (NULL for
   * the force) */
  const double *bu, *bH;
  /* fpm.volume_penalty's phi per point (the state's, or the base's), its
   * increments (linearisation only), and the base's fits (quadratic
   * stiffening's linearisation only) */
  const double *vphi, *vdphi, *btheta;
  /* the loads: the pressures and body and point forces (the state's; the
   * linearisation's pressures, whose forces do not change) */
  const double *tf_p, *fload;
  /* the team's sums (shared, zero at the region's start): the interface
   * energy, the boundary flux's squared norm */
  double *sums;
} fields;

/* Adds this thread's part to *sum (shared) and waits for the team; every
 * thread then reads the whole.  The parts are added one thread after
 * another as OpenMP's reduction clause adds them, so the sum has the bits
 * of the reduction it replaces. */
static inline double team_sum(double *sum, double part) {
  PM_OMP(atomic)
  *sum += part;
  PM_OMP(barrier)
  return *sum;
}

/* Pass 1: F_i = I + sum_k (u_k - u_i) (x) g_ik, then P_i, W_i, J_i.
 * Lowers *bad (shared, the model's own count at the region's start) to the
 * smallest inadmissible point of the model's own (a ghost's is its
 * owner's to find); every thread sees the result after the pass. */
static void stress_pass(const fpm_model *m, fpm_state *st, long *bad_all) {
  const long n = m->n_stress, n_own = m->n_own;
  const double *restrict u = st->u;
  double *restrict H = st->H, *restrict P = st->P, *restrict W = st->W,
                   *restrict J = st->J;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const double *ms = m->mstate;
  const long mss = m->mstate_stride;
  long bad = n_own;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    double h[9];
    fpm_stream_gradient(m, u, i, h);
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
  PM_OMP(critical(fpm_force_bad))
  if (bad < *bad_all) *bad_all = bad;
  PM_OMP(barrier)
}

/* With fpm.jump: quadratic, the fit of each point:
 * theta_i = sum_m (u_m - u_i) (x) q_im (3 x FPM_QFIT) (no barrier after it). */
static void fit_pass(const fpm_model *m, const double *restrict u,
                     double *restrict th) {
  const long n = m->n_stress;
  const long *restrict ptr = m->qs_ptr;
  const int *restrict nbr = m->qs_nbr;
  const double *restrict q = m->q;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    double t[27] = {0};
    const double *ui = u + 3 * i;
    for (long e = ptr[i]; e < ptr[i + 1]; e++) {
      const double *uk = u + 3 * nbr[e], *qe = q + FPM_QFIT * e;
      for (int c = 0; c < 3; c++) {
        const double d = uk[c] - ui[c];
        for (int a = 0; a < FPM_QFIT; a++) t[FPM_QFIT * c + a] += d * qe[a];
      }
    }
    for (int a = 0; a < 27; a++) th[27 * i + a] = t[a];
  }
}

/* The jump of the linear fields at an interface: u_i + H_i d_i - u_k -
 * H_k d_k. */
static inline void linear_jump(const double *ui, const double *uk,
                               const double *Hi, const double *Hk,
                               const double *di, const double *dk, double *j) {
  for (int c = 0; c < 3; c++)
    j[c] = ui[c] - uk[c] + Hi[3 * c] * di[0] + Hi[3 * c + 1] * di[1] +
           Hi[3 * c + 2] * di[2] - Hk[3 * c] * dk[0] - Hk[3 * c + 1] * dk[1] -
           Hk[3 * c + 2] * dk[2];
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
 * energy 1/2 sum_e beta |e| [[u]]^2 (and, for SIPG, - sum_e {P} : K_e).
 * With fpm.jump: quadratic the penalty measures the jump of the fits,
 * [[u]]_q = u_i + theta_i phi(d_i) - u_k - theta_k phi(d_k), and its force
 * leaves through zq_i = sum_e b and Zq_i = sum_e b (x) phi(d_i) (gathered
 * by the fit weights in pass 3) instead of r and Q; the boundary
 * interfaces' linear-jump penalty (beta_b |e| = rec[19], zero elsewhere)
 * leaves through r and Q as the linear jump's does.  The stiffening
 * (fpm.stiffening, c_e |e| = rec[20], from the onset (tau h_e)^2 =
 * rec[22]) adds the gradient of c_e |e| phi(|j|^2 - (tau h_e)^2) / 4 to the
 * force of the linear jump, or with fpm.stiffening_jump: quadratic of the
 * quadratic one (fpm_stiffen; |j|^4 at tau = 0); with
 * fpm.stiffening_spacing: current the onset is tau |dc|, dc the points'
 * deformed distance, whose derivative leaves through r (sd).  The volume
 * penalty (fpm.volume_penalty, rec[21]) adds 1/2 c |e| phi_e |j|^2 on the
 * linear jump and its derivative through each point's J (fpm_penalty_terms.h).
 * The energy counts the model's own points.  The general pass: this
 * thread's points (no barrier after them) and its share of the energy. */
static double flux_general(const fpm_model *m, const fields *fl) {
  const long n = m->n_flux, n_own = m->n_own;
  const long *restrict ptr = m->nbr_ptr;
  const int *restrict nbr = m->nbr;
  const double *restrict erec = m->erec;
  const double *restrict u = fl->u, *restrict H = fl->H, *restrict P = fl->P;
  double *restrict T = fl->T, *restrict r = fl->r;
  const double *bu = fl->bu, *bH = fl->bH;
  const bool base = bu != NULL;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const double *ms = m->mstate;
  const long mss = m->mstate_stride;
  const bool sym = m->flux == FPM_FLUX_SIPG;
  const double *restrict th = fl->theta;
  double *restrict zq = fl->zq, *restrict Zq = fl->Zq;
  const bool quad = th != NULL, squad = quad && m->stiffen_quadratic;
  const bool vol_on = m->volume_penalty > 0;
  const double *vphi = fl->vphi, *vdphi = fl->vdphi, *bth = fl->btheta;
  double epen = 0;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    const bool counted = i < n_own;
    const double *Pi = P + 9 * i, *Hi = H + 9 * i, *ui = u + 3 * i;
    double Q[9] = {0}, ri[3] = {0}, B[9] = {0}, z[3] = {0}, Z[27] = {0};
    double B0[9] = {0}; /* linearisation, SIPG: sum_e K_e at the base */
    double Tv[9] = {0}, va = 0, vda = 0; /* the volume penalty's flux */
    for (long e = ptr[i]; e < ptr[i + 1]; e++) {
      const long k = nbr[e];
      const double *rec = erec + FPM_EREC * e;
      const double *a = rec, *Mc = rec + 3, *di = rec + 12, *dk = rec + 15;
      const double be = rec[18], bl = rec[19], cs = rec[20], cv = rec[21];
      const double *Pk = P + 9 * k, *Hk = H + 9 * k, *uk = u + 3 * k;
      double w[3], phi_i[FPM_QFIT], phi_k[FPM_QFIT], jv[3], jq[3], j0[3];
      double sv[3] = {0}, sq[3] = {0}; /* linear, quadratic jump's extra */
      double sd[3] = {0}; /* the onset's, through u_k - u_i (current) */
      const double *bui = base ? bu + 3 * i : NULL,
                   *buk = base ? bu + 3 * k : NULL;
      double eadd = 0;
      if (quad) {
        fpm_gfd_phi(di, phi_i);
        fpm_gfd_phi(dk, phi_k);
        fpm_quad_jump(ui, uk, th + 27 * i, th + 27 * k, phi_i, phi_k, jq);
        if (cs != 0 && squad) {
          double jq0[3];
          if (base)
            fpm_quad_jump(bu + 3 * i, bu + 3 * k, bth + 27 * i, bth + 27 * k,
                          phi_i, phi_k, jq0);
          eadd += fpm_stiffen_entry(m, cs, rec[22], jq, base ? jq0 : NULL, ui,
                                    uk, bui, buk, di, dk, sq, sd);
        }
      }
      linear_jump(ui, uk, Hi, Hk, di, dk, jv);
      if (base && (cv != 0 || (cs != 0 && !squad)))
        linear_jump(bu + 3 * i, bu + 3 * k, bH + 9 * i, bH + 9 * k, di, dk, j0);
      if (cs != 0 && !squad)
        eadd += fpm_stiffen_entry(m, cs, rec[22], jv, base ? j0 : NULL, ui, uk,
                                  bui, buk, di, dk, sv, sd);
      if (cv != 0)
        eadd += fpm_volume_entry(cv, vphi[i], vphi[k], jv, base ? j0 : NULL,
                                 base ? vdphi[i] + vdphi[k] : 0, sv, &va, &vda);
      if (counted) epen += eadd;
      for (int c = 0; c < 3; c++) {
        const double jump = jv[c];
        const double pjump = quad ? jq[c] : jump;
        const double b = be * pjump + sq[c];
        w[c] = 0.5 * (Pk[3 * c] * a[0] + Pk[3 * c + 1] * a[1] +
                      Pk[3 * c + 2] * a[2]) -
               (quad ? bl * jump : b) - sv[c];
        ri[c] -= w[c] + sd[c];
        if (quad) {
          z[c] += b;
          for (int q = 0; q < FPM_QFIT; q++)
            Z[FPM_QFIT * c + q] += b * phi_i[q];
        }
        /* each interface is seen twice */
        if (counted) epen += 0.25 * (be * pjump * pjump + bl * jump * jump);
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
            if (counted) epen -= 0.25 * (Pi[3 * c + q] + Pk[3 * c + q]) * K;
          }
          if (base) {
            const double *bHi = bH + 9 * i, *bHk = bH + 9 * k;
            const double bj = bu[3 * i + c] - bu[3 * k + c] +
                              bHi[3 * c] * di[0] + bHi[3 * c + 1] * di[1] +
                              bHi[3 * c + 2] * di[2] - bHk[3 * c] * dk[0] -
                              bHk[3 * c + 1] * dk[1] - bHk[3 * c + 2] * dk[2];
            for (int q = 0; q < 3; q++)
              B0[3 * c + q] +=
                  bj * a[q] + (bHi[3 * c] - bHk[3 * c]) * Mc[3 * q] +
                  (bHi[3 * c + 1] - bHk[3 * c + 1]) * Mc[3 * q + 1] +
                  (bHi[3 * c + 2] - bHk[3 * c + 2]) * Mc[3 * q + 2];
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
       * -sum_e {P} : K_e through P_i (A_i = dP/dF at F_i).  Linearised:
       * 1/2 (A_i : dB + (dA_i[dF_i]) : B), the derivative of the tangent
       * along dF_i = dH_i by central differences. */
      const double *Hb = base ? bH + 9 * i : Hi;
      const double *msi = ms ? ms + mss * i : NULL;
      double F[9], dP[9];
      fpm_deformation(Hb, F);
      pm_material_tangent(&mats[mat[i]], F, msi, B, dP);
      for (int k = 0; k < 9; k++) Q[k] += 0.5 * dP[k];
      if (base) {
        double hn = 0, fn = 0;
        for (int k = 0; k < 9; k++) {
          hn += Hi[k] * Hi[k];
          fn += F[k] * F[k];
        }
        if (hn > 0) {
          const double eps = 1e-6 * sqrt(fn / hn);
          double Fp[9], Fm[9], dPp[9], dPm[9];
          for (int k = 0; k < 9; k++) {
            Fp[k] = F[k] + eps * Hi[k];
            Fm[k] = F[k] - eps * Hi[k];
          }
          pm_material_tangent(&mats[mat[i]], Fp, msi, B0, dPp);
          pm_material_tangent(&mats[mat[i]], Fm, msi, B0, dPm);
          for (int k = 0; k < 9; k++)
            Q[k] += 0.5 * (dPp[k] - dPm[k]) / (2 * eps);
        }
      }
    }
    if (vol_on)
      fpm_volume_flux(base ? bH + 9 * i : Hi, base ? Hi : NULL, va, vda, Tv);
    if (quad) {
      for (int c = 0; c < 3; c++) zq[3 * i + c] = z[c];
      for (int q = 0; q < 27; q++) Zq[27 * i + q] = Z[q];
    }
    fpm_flux_close(m, i, Pi, Q, ri, Tv, r, T);
  }
  return epen;
}

/* Pass 2 over the team (the plain formulation streams its entries,
 * fpm_stream.h), then a barrier; the interface energy of the model's own
 * points. */
static double flux_pass(const fpm_model *m, const fields *fl) {
  const double part =
      m->fs_rec ? fpm_stream_flux(m, fl->u, fl->H, fl->P, fl->T, fl->r)
                : flux_general(m, fl);
  return team_sum(fl->sums + 0, part);
}

/* Boundary terms: the consistency flux on facets with displacement
 * conditions, projected on the prescribed components
 * (r_i -= Pi P_i a_f, T_i -= Pi P_i (M_f - a_f (x) X_i)), and prescribed
 * tractions (r_i -= t |f|, T_i -= t (x) |f| (c_f - X_i)).  The flux's norm
 * counts the model's own points. */
static void boundary_pass(const fpm_model *m, const fields *fl, fpm_state *st) {
  const long nd = m->n_dpts, n_own = m->n_own;
  if (fl->fload) { /* body and point forces (before the flux's nowait) */
    const double *restrict fb = fl->fload;
    double *restrict rb = fl->r;
    PM_OMP(for schedule(static))
    for (long d = 0; d < 3 * n_own; d++) rb[d] -= fb[d];
  }
  const long *restrict dp = m->dpt_point;
  const double *restrict da = m->dpt_area, *restrict dm = m->dpt_mrel;
  const double *restrict P = fl->P;
  double *restrict T = fl->T, *restrict r = fl->r, *restrict bf = fl->bflux;
  double norm2 = 0;
  PM_OMP(for schedule(static) nowait)
  for (long p = 0; p < nd; p++) {
    const long i = dp[p];
    const double *Pi = P + 9 * i;
    for (int c = 0; c < 3; c++) {
      const double *A = da + 9 * p + 3 * c, *B = dm + 27 * p + 9 * c;
      const double flux =
          Pi[3 * c] * A[0] + Pi[3 * c + 1] * A[1] + Pi[3 * c + 2] * A[2];
      r[3 * i + c] -= flux;
      if (bf) bf[3 * p + c] = flux;
      if (i < n_own) norm2 += flux * flux;
      for (int q = 0; q < 3; q++)
        T[9 * i + 3 * c + q] -= Pi[3 * c] * B[q] + Pi[3 * c + 1] * B[3 + q] +
                                Pi[3 * c + 2] * B[6 + q];
    }
  }
  norm2 = team_sum(fl->sums + 1, norm2);
  if (!st) { /* the linearisation: only the pressures' tractions change */
    if (m->n_tfacets && fl->tf_p) {
      PM_OMP(single)
      for (long k = 0; k < m->n_tfacets; k++) {
        if (fl->tf_p[k] == 0) continue;
        const long i = m->tf_point[k];
        const double *rel = m->tf_rel + 3 * k;
        double t[3];
        fpm_pressure_dtraction(fl->bH + 9 * i, fl->H + 9 * i, fl->tf_p[k],
                               m->tf_normal + 3 * k, t);
        for (int c = 0; c < 3; c++) {
          r[3 * i + c] -= t[c] * m->tf_area[k];
          for (int q = 0; q < 3; q++) T[9 * i + 3 * c + q] -= t[c] * rel[q];
        }
      }
    }
    return;
  }
  if (m->n_tfacets == 0) {
    PM_OMP(masked) {
      st->bflux_sq = norm2;
      st->bflux_norm = sqrt(norm2);
    }
    return;
  }
  /* Several facets share a point: serial (boundary only). */
  PM_OMP(single) {
    st->bflux_sq = norm2;
    st->bflux_norm = sqrt(norm2);
    for (long k = 0; k < m->n_tfacets; k++) {
      const long i = m->tf_point[k];
      const double *rel = m->tf_rel + 3 * k;
      double *t = st->tf_load + 3 * k;
      /* the pressure's traction on the face as it is now */
      fpm_pressure_traction(fl->H + 9 * i, st->tf_p[k], m->tf_normal + 3 * k,
                            t);
      for (int c = 0; c < 3; c++) t[c] += st->tf_value[3 * k + c];
      for (int c = 0; c < 3; c++) {
        r[3 * i + c] -= t[c] * m->tf_area[k];
        for (int q = 0; q < 3; q++) T[9 * i + 3 * c + q] -= t[c] * rel[q];
      }
    }
  }
}

/* Pass 3: f_k = sum_{i in S(k)} T_i g_ik - T_k sum_j g_kj + r_k, over the
 * entries streamed (fpm_stream.h). */
static void gather_pass(const fpm_model *m, const fields *fl) {
  fpm_stream_gather(m, fl->T, fl->r, fl->f);
}

/* With fpm.jump: quadratic, the penalty force through the fits:
 * f_k += zq_k - Zq_k qsum_k + sum over the fits holding k of Zq_i q_ik. */
static void fit_gather_pass(const fpm_model *m, const fields *fl) {
  const long n = m->n_own;
  const long *restrict tp = m->qt_ptr;
  const int *restrict te = m->qt_entry, *restrict own = m->qs_own;
  const double *restrict q = m->q, *restrict qs = m->qsum,
                         *restrict zq = fl->zq, *restrict Zq = fl->Zq;
  double *restrict f = fl->f;
  /* f_k of the points the gather gave this thread: no barrier between */
  PM_OMP(for schedule(static) nowait)
  for (long k = 0; k < n; k++) {
    double fk[3];
    for (int c = 0; c < 3; c++)
      fk[c] = zq[3 * k + c] - fpm_fit_at(Zq + 27 * k, c, qs + FPM_QFIT * k);
    for (long t = tp[k]; t < tp[k + 1]; t++) {
      const long e = te[t];
      const double *Zi = Zq + 27 * own[e], *qe = q + FPM_QFIT * e;
      for (int c = 0; c < 3; c++) fk[c] += fpm_fit_at(Zi, c, qe);
    }
    for (int c = 0; c < 3; c++) f[3 * k + c] += fk[c];
  }
}

void fpm_force_skipped(const fpm_model *m, fpm_state *st) {
  if (m->vavg) fpm_volumetric_stress_skipped(m, st);
}

/* The passes after the stress over the team of the enclosing parallel
 * region: the fits (theta, with the quadratic jump) and the volume penalty's
 * phi (one barrier), the flux, the boundary, the gather.  The gather and the
 * fits' gather end without a barrier (the region's end is one). */
static void force_passes(const fpm_model *m, const fields *fl, double *theta,
                         fpm_state *st) {
  if (theta) fit_pass(m, fl->u, theta);
  if (st && st->vphi) fpm_volume_phi(m->n_stress, st->J, st->vphi);
  if (fl->theta || (st && st->vphi)) {
    PM_OMP(barrier)
  }
  const double epen = flux_pass(m, fl);
  if (st) {
    PM_OMP(masked)
    st->penalty_energy = epen;
  }
  boundary_pass(m, fl, st);
  gather_pass(m, fl);
  if (fl->theta) fit_gather_pass(m, fl);
}

/* One parallel region for the explicit force: a step's passes fork the
 * team once, and a barrier (not a fork and a join) separates them.  The
 * averaged volume's exchange between the stress and the flux needs the
 * ranks' order, so with it the stress is its own region. */
long fpm_force(const fpm_model *m, fpm_state *st) {
  return fpm_force_then(m, st, NULL, NULL);
}

long fpm_force_then(const fpm_model *m, fpm_state *st, void (*tail)(void *),
                    void *ctx) {
  double sums[2] = {0, 0};
  const fields fl = {.u = st->u,
                     .H = st->H,
                     .P = st->P,
                     .theta = st->theta,
                     .T = st->T,
                     .r = st->r,
                     .zq = st->zq,
                     .Zq = st->Zq,
                     .f = st->f,
                     .bflux = st->bflux,
                     .vphi = st->vphi,
                     .tf_p = st->tf_p,
                     .fload = m->bf_base || m->n_pforces ? st->fload : NULL,
                     .sums = sums};
  const bool whole = m->vavg == NULL;
  long bad = m->n_own;
  PM_OMP(parallel default(none) shared(m, st, fl, whole, bad, tail, ctx)) {
    stress_pass(m, st, &bad);
    if (whole && bad == m->n_own) {
      force_passes(m, &fl, st->theta, st);
      if (tail) tail(ctx);
    }
  }
  if (whole || bad < m->n_own) {
    if (m->vavg) fpm_volumetric_stress_skipped(m, st);
    return bad < m->n_own ? bad : -1;
  }
  fpm_volumetric_stress(m, st);
  PM_OMP(parallel default(none) shared(m, st, fl, tail, ctx)) {
    force_passes(m, &fl, st->theta, st);
    if (tail) tail(ctx);
  }
  return -1;
}

void fpm_linear_prepare(const fpm_model *m, const fpm_state *st,
                        fpm_linear *l) {
  const long n = m->n, ns = m->n_stress; /* (the stress's points) */
  const double *restrict H = st->H;
  double *restrict D = l->D;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const double *ms = m->mstate;
  const long mss = m->mstate_stride;
  memcpy(l->bu, st->u, 3 * n * sizeof(double));
  memcpy(l->bH, st->H, 9 * n * sizeof(double));
  if (l->btheta) memcpy(l->btheta, st->theta, 27 * n * sizeof(double));
  if (l->tf_p) memcpy(l->tf_p, st->tf_p, m->n_tfacets * sizeof(double));
  if (l->vphi) fpm_volume_dphi(ns, st->H, NULL, l->vphi, NULL);
  PM_OMP(parallel for schedule(static) default(none)
         shared(ns, H, D, mat, mats, ms, mss))
  for (long i = 0; i < ns; i++) {
    double F[9], E[9] = {0}, dP[9];
    fpm_deformation(H + 9 * i, F);
    for (int b = 0; b < 9; b++) {
      E[b] = 1;
      pm_material_tangent(&mats[mat[i]], F, ms ? ms + mss * i : NULL, E, dP);
      E[b] = 0;
      for (int a = 0; a < 9; a++) D[81 * i + 9 * a + b] = dP[a];
    }
  }
  if (m->vavg) fpm_volumetric_prepare(m, st, &l->vol, D);
}

void fpm_force_linear(const fpm_model *m, fpm_linear *l, const double *du,
                      double *df) {
  const long n = m->n_stress; /* the stress's points (all on one process) */
  const long *restrict ptr = m->nbr_ptr;
  const int *restrict nbr = m->nbr;
  const double *restrict g = m->g, *restrict D = l->D;
  double *restrict dH = l->dH, *restrict dP = l->dP;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, nbr, g, du, D, dH, dP))
  for (long i = 0; i < n; i++) {
    double h[9] = {0};
    for (long e = ptr[i]; e < ptr[i + 1]; e++) {
      const long k = nbr[e];
      for (int c = 0; c < 3; c++) {
        const double d = du[3 * k + c] - du[3 * i + c];
        for (int a = 0; a < 3; a++) h[3 * c + a] += d * g[3 * e + a];
      }
    }
    for (int a = 0; a < 9; a++) {
      double s = 0;
      for (int b = 0; b < 9; b++) s += D[81 * i + 9 * a + b] * h[b];
      dH[9 * i + a] = h[a];
      dP[9 * i + a] = s;
    }
  }
  if (m->vavg) fpm_volumetric_apply(m, &l->vol, dH, dP);
  double sums[2] = {0, 0};
  const fields fl = {.u = du,
                     .H = dH,
                     .P = dP,
                     .theta = l->theta,
                     .T = l->T,
                     .r = l->r,
                     .zq = l->zq,
                     .Zq = l->Zq,
                     .f = df,
                     .bu = l->bu,
                     .bH = l->bH,
                     .vphi = l->vphi,
                     .vdphi = l->vdphi,
                     .btheta = l->btheta,
                     .tf_p = l->tf_p,
                     .sums = sums};
  if (l->vdphi) fpm_volume_dphi(n, l->bH, dH, NULL, l->vdphi);
  PM_OMP(parallel default(none) shared(m, fl, l))
  force_passes(m, &fl, l->theta, NULL);
}
