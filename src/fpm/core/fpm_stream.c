/* fpm_stream: the support entries of the explicit force streamed
 * FPM_LANES at a time as structure-of-arrays blocks, so that a block is one
 * pass of vector instructions (the neighbours' data gathered): the gradient
 * and the gather for every formulation, the flux pass for the plain one. */
#include "fpm_stream.h"

#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"

/* Doubles of a flux block per lane: a (3), Mc (9), d_i (3), d_k (3),
 * beta |e|. */
#define FS_FIELDS 19

bool fpm_stream_plain(const fpm_model *m) {
  return m->jump != FPM_JUMP_QUADRATIC && m->flux != FPM_FLUX_SIPG &&
         m->stiffening == 0 && m->volume_penalty == 0;
}

size_t fpm_stream_bytes(long rows, long entries, bool plain) {
  return (size_t)entries *
             ((6 + (plain ? FS_FIELDS : 0)) * sizeof(double) + sizeof(int)) +
         (size_t)(rows + 1) * sizeof(long);
}

/* The block of entry s of row i (its lane is s % FPM_LANES). */
static inline long block_of(const fpm_model *m, long i, long s) {
  return m->fs_ptr[i] + s / FPM_LANES;
}

pm_err fpm_stream_build(fpm_model *m) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n_stress;
  const bool plain = fpm_stream_plain(m);
  PM_TRY(PM_ALLOC(m->fs_ptr, n + 1, "entry stream rows"));
  for (long i = 0; i < n; i++) {
    const long cnt = m->nbr_ptr[i + 1] - m->nbr_ptr[i];
    m->fs_ptr[i + 1] = m->fs_ptr[i] + (cnt + FPM_LANES - 1) / FPM_LANES;
  }
  const long nb = m->fs_ptr[n];
  PM_TRY(PM_ALLOC(m->fs_nbr, FPM_LANES * nb + 1, "entry stream neighbours"));
  PM_TRY(PM_ALLOC(m->fs_g, 3 * FPM_LANES * nb + 1, "entry stream weights"));
  PM_TRY(PM_ALLOC(m->fs_gm, 3 * FPM_LANES * nb + 1, "entry stream mirrors"));
  if (plain)
    PM_TRY(PM_ALLOC(m->fs_rec, FS_FIELDS * FPM_LANES * nb + 1,
                    "entry stream records"));
  for (long i = 0; i < n; i++) {
    const long e0 = m->nbr_ptr[i], cnt = m->nbr_ptr[i + 1] - e0;
    for (long s = 0; s < FPM_LANES * (m->fs_ptr[i + 1] - m->fs_ptr[i]); s++) {
      const long b = block_of(m, i, s), l = s % FPM_LANES;
      /* padding: the point itself with zero weights and a zero record */
      m->fs_nbr[FPM_LANES * b + l] = s < cnt ? m->nbr[e0 + s] : (int)i;
      if (s >= cnt) continue;
      for (int c = 0; c < 3; c++)
        m->fs_g[FPM_LANES * (3 * b + c) + l] = m->g[3 * (e0 + s) + c];
      /* g_ki of the mirror entry, where the gather reads it (own rows) */
      if (i < m->n_own)
        for (int c = 0; c < 3; c++)
          m->fs_gm[FPM_LANES * (3 * b + c) + l] =
              m->g[3 * m->mirror[e0 + s] + c];
      if (!plain) continue;
      const double *rec = m->erec + FPM_EREC * (e0 + s);
      for (int f = 0; f < FS_FIELDS; f++)
        m->fs_rec[FPM_LANES * (FS_FIELDS * b + f) + l] = rec[f];
    }
  }
done:
  return ret;
}

/* Per point i, over its entries as in fpm_force.c's flux pass with the
 * optional terms absent: [[u]] = u_i + H_i d_i - u_k - H_k d_k,
 * w = 1/2 P_k a - beta |e| [[u]], r_i -= w,
 * Q_i += 1/2 P_k Mc + w (x) d_i, FPM_LANES entries at a time; the lanes'
 * sums are added at the end.  This thread's points, no barrier after. */
double fpm_stream_flux(const fpm_model *m, const double *restrict u,
                       const double *restrict H, const double *restrict P,
                       double *restrict T, double *restrict r) {
  const long n = m->n_flux, n_own = m->n_own;
  const long *restrict bp = m->fs_ptr;
  const int *restrict nb = m->fs_nbr;
  const double *restrict R = m->fs_rec;
  double epen = 0;
  PM_OMP(for schedule(static) nowait)
  for (long i = 0; i < n; i++) {
    const double *Pi = P + 9 * i, *Hi = H + 9 * i, *ui = u + 3 * i;
    pm_v4 Qa[9] = {0}, ra[3] = {0}, ea = {0};
    for (long b = bp[i]; b < bp[i + 1]; b++) {
      const double *rb = R + FS_FIELDS * FPM_LANES * b;
      const int *kb = nb + FPM_LANES * b;
      const int k3[4] = {3 * kb[0], 3 * kb[1], 3 * kb[2], 3 * kb[3]};
      const int k9[4] = {9 * kb[0], 9 * kb[1], 9 * kb[2], 9 * kb[3]};
      pm_v4 Pk[9], Hk[9], Mc[9], di[3], dk[3], jv[3], w[3];
      fpm_gather9(P, k9, Pk);
      fpm_gather9(H, k9, Hk);
      for (int f = 0; f < 9; f++) Mc[f] = pm_v4_load(rb + FPM_LANES * (3 + f));
      for (int c = 0; c < 3; c++) {
        di[c] = pm_v4_load(rb + FPM_LANES * (12 + c));
        dk[c] = pm_v4_load(rb + FPM_LANES * (15 + c));
      }
      const pm_v4 a0 = pm_v4_load(rb), a1 = pm_v4_load(rb + FPM_LANES),
                  a2 = pm_v4_load(rb + 2 * FPM_LANES),
                  be = pm_v4_load(rb + 18 * FPM_LANES);
      for (int c = 0; c < 3; c++) {
        jv[c] = ui[c] - FPM_GATHER(u, k3, c) + Hi[3 * c] * di[0] +
                Hi[3 * c + 1] * di[1] + Hi[3 * c + 2] * di[2] -
                Hk[3 * c] * dk[0] - Hk[3 * c + 1] * dk[1] -
                Hk[3 * c + 2] * dk[2];
        w[c] =
            0.5 * (Pk[3 * c] * a0 + Pk[3 * c + 1] * a1 + Pk[3 * c + 2] * a2) -
            be * jv[c];
        ra[c] -= w[c];
        ea += 0.25 * (be * jv[c] * jv[c]);
      }
      for (int c = 0; c < 3; c++)
        for (int q = 0; q < 3; q++)
          Qa[3 * c + q] +=
              0.5 * (Pk[3 * c] * Mc[q] + Pk[3 * c + 1] * Mc[3 + q] +
                     Pk[3 * c + 2] * Mc[6 + q]) +
              w[c] * di[q];
    }
    double Q[9], ri[3], e = 0;
    for (int a = 0; a < 9; a++) {
      Q[a] = 0;
      for (int l = 0; l < FPM_LANES; l++) Q[a] += Qa[a][l];
    }
    for (int c = 0; c < 3; c++) {
      ri[c] = 0;
      for (int l = 0; l < FPM_LANES; l++) ri[c] += ra[c][l];
    }
    for (int l = 0; l < FPM_LANES; l++) e += ea[l];
    if (i < n_own) epen += e;
    const double Tv[9] = {0};
    fpm_flux_close(m, i, Pi, Q, ri, Tv, r, T);
  }
  return epen;
}

/* f_k = r_k - T_k sum_j g_kj + sum_{i in S(k)} T_i g_ik as fpm_force.c's
 * gather pass, FPM_LANES entries at a time.  This thread's points, no
 * barrier after. */
void fpm_stream_gather(const fpm_model *m, const double *restrict T,
                       const double *restrict r, double *restrict f) {
  const long n = m->n_own;
  const long *restrict bp = m->fs_ptr;
  const int *restrict nb = m->fs_nbr;
  const double *restrict G = m->fs_gm, *restrict gs = m->gsum;
  PM_OMP(for schedule(static) nowait)
  for (long k = 0; k < n; k++) {
    const double *Tk = T + 9 * k, *s = gs + 3 * k;
    pm_v4 fa[3] = {0};
    for (long b = bp[k]; b < bp[k + 1]; b++) {
      const int *kb = nb + FPM_LANES * b;
      const int k9[4] = {9 * kb[0], 9 * kb[1], 9 * kb[2], 9 * kb[3]};
      const pm_v4 g0 = pm_v4_load(G + FPM_LANES * 3 * b),
                  g1 = pm_v4_load(G + FPM_LANES * (3 * b + 1)),
                  g2 = pm_v4_load(G + FPM_LANES * (3 * b + 2));
      pm_v4 Tb[9];
      fpm_gather9(T, k9, Tb);
      for (int c = 0; c < 3; c++)
        fa[c] += Tb[3 * c] * g0 + Tb[3 * c + 1] * g1 + Tb[3 * c + 2] * g2;
    }
    for (int c = 0; c < 3; c++) {
      double fk = r[3 * k + c] - (Tk[3 * c] * s[0] + Tk[3 * c + 1] * s[1] +
                                  Tk[3 * c + 2] * s[2]);
      for (int l = 0; l < FPM_LANES; l++) fk += fa[c][l];
      f[3 * k + c] = fk;
    }
  }
}
