/* fpm_static_coupled: the averaged volume's coupling in the static solve's
 * factorisation: the matrix [K0 G; C I] with one value per point more,
 * whose Schur complement on the free dofs is the exact tangent. */
#include <stdlib.h>
#include <string.h>

#include "fpm_static_impl.h"
#include "fpm_volumetric.h"
#include "pm_omp.h"

void fpm_static_coupled_free(fpm_static_coupled *cp) {
  free(cp->Z_ptr);
  free(cp->Z_i);
  free(cp->U_ptr);
  free(cp->U_m);
  free(cp->ptr);
  free(cp->idx);
  free(cp->D);
  free(cp->jv);
  free(cp->mark);
  free(cp->acc);
  memset(cp, 0, sizeof *cp);
}

/* A[k][r]: the averaging weight of the r-th member of k's closed support. */
static inline double weight(const fpm_model *m, long k, long r) {
  return r == 0 ? m->vself[k] : m->vavg[m->nbr_ptr[k] + r - 1];
}

/* The points two closed supports away from each point k of [0, rows):
 * with via_E, the closed supports of the points j of t's E_k (the z whose
 * stresses reach f_k); else those of the members l of k's closed support
 * (the u that reach z_k).  Into *ptr_out, *list_out (CSR). */
static pm_err two_step_lists(const fpm_model *m, const fpm_static_tangent *t,
                             bool via_E, long rows, long **ptr_out,
                             long **list_out) {
  pm_err ret = PM_SUCCESS;
  long *mark = NULL, *ptr = NULL, *list = NULL;
  PM_TRY(PM_ALLOC(mark, m->n, "coupling marks"));
  PM_TRY(PM_ALLOC(ptr, rows + 1, "coupling lists"));
  for (long i = 0; i < m->n; i++) mark[i] = -1;
  for (int pass = 0; pass < 2; pass++) {
    for (long k = 0; k < rows; k++) {
      long cnt = 0, *out = pass ? list + ptr[k] : NULL;
      const long q0 = via_E ? t->E_ptr[k] : 0,
                 q1 = via_E ? t->E_ptr[k + 1] : closed_size(m, k);
      for (long q = q0; q < q1; q++) {
        const double *w;
        const long j = via_E ? t->E_j[q] : closed_member(m, k, q, &w);
        for (long r = 0; r < closed_size(m, j); r++) {
          const long i = closed_member(m, j, r, &w);
          if (mark[i] == k) continue;
          mark[i] = k;
          if (out) out[cnt] = i;
          cnt++;
        }
      }
      if (!pass) ptr[k + 1] = cnt;
    }
    if (!pass) {
      for (long k = 0; k < rows; k++) ptr[k + 1] += ptr[k];
      PM_TRY(PM_ALLOC(list, ptr[rows] + 1, "coupling lists"));
      for (long i = 0; i < m->n; i++) mark[i] = -1;
    }
  }
  *ptr_out = ptr;
  *list_out = list;
  ptr = list = NULL;
done:
  free(mark);
  free(ptr);
  free(list);
  return ret;
}

pm_err fpm_static_coupled_build(fpm_static_solve *v) {
  fpm_static_ctx *c = &v->c;
  const fpm_model *m = c->m;
  fpm_static_coupled *cp = &c->cp;
  const long n = m->n, nf = c->nf, *free_of = v->free_of;
  PM_CALL(two_step_lists(m, &c->tg, true, m->n_own, &cp->Z_ptr, &cp->Z_i));
  PM_CALL(two_step_lists(m, &c->tg, false, n, &cp->U_ptr, &cp->U_m));
  /* rows: the free dofs (the tangent's columns, then the z of Z_k), then
   * the points (z_i itself, then the free dofs of U_i) */
  PM_CALL(PM_ALLOC(cp->ptr, nf + n + 1, "coupled pattern"));
  for (long row = 0; row < nf; row++) {
    const long k = c->dof[row] / 3;
    cp->ptr[row + 1] = cp->ptr[row] + (v->ptr[row + 1] - v->ptr[row]) +
                       (cp->Z_ptr[k + 1] - cp->Z_ptr[k]);
  }
  for (long i = 0; i < n; i++) {
    long cnt = 1;
    for (long q = cp->U_ptr[i]; q < cp->U_ptr[i + 1]; q++)
      for (int r = 0; r < 3; r++) cnt += free_of[3 * cp->U_m[q] + r] >= 0;
    cp->ptr[nf + i + 1] = cp->ptr[nf + i] + cnt;
  }
  PM_CALL(PM_ALLOC(cp->idx, cp->ptr[nf + n], "coupled pattern"));
  for (long row = 0; row < nf; row++) {
    /* the tangent's row (its pattern's columns, in fpm_static_pattern's
     * order, from the points that reach k) */
    const long k = c->dof[row] / 3, nj = v->ptr[row + 1] - v->ptr[row];
    long *out = cp->idx + cp->ptr[row], w = 0;
    for (long t = c->tg.R_ptr[k]; t < c->tg.R_ptr[k + 1]; t++)
      for (int a = 0; a < 3; a++) {
        const long col = free_of[3 * c->tg.R_list[t] + a];
        if (col >= 0) out[w++] = col;
      }
    PM_CHECK(w == nj, PM_ERR_INTERNAL,
             "coupled pattern: row %ld holds %ld columns, the tangent's %ld",
             row, w, nj);
    for (long q = cp->Z_ptr[k]; q < cp->Z_ptr[k + 1]; q++)
      out[nj + q - cp->Z_ptr[k]] = nf + cp->Z_i[q];
  }
  for (long i = 0; i < n; i++) {
    long *out = cp->idx + cp->ptr[nf + i];
    *out++ = nf + i;
    for (long q = cp->U_ptr[i]; q < cp->U_ptr[i + 1]; q++)
      for (int r = 0; r < 3; r++)
        if (free_of[3 * cp->U_m[q] + r] >= 0)
          *out++ = free_of[3 * cp->U_m[q] + r];
  }
  cp->maxlen = 1;
  for (long k = 0; k < m->n_own; k++)
    if (cp->Z_ptr[k + 1] - cp->Z_ptr[k] > cp->maxlen)
      cp->maxlen = cp->Z_ptr[k + 1] - cp->Z_ptr[k];
  for (long i = 0; i < n; i++)
    if (cp->U_ptr[i + 1] - cp->U_ptr[i] > cp->maxlen)
      cp->maxlen = cp->U_ptr[i + 1] - cp->U_ptr[i];
  cp->threads = pm_omp_threads();
  PM_CALL(PM_ALLOC(cp->D, 81 * n, "coupled moduli"));
  PM_CALL(PM_ALLOC(cp->jv, v->ptr[nf] + 1, "coupled tangent values"));
  PM_CALL(PM_ALLOC(cp->mark, (size_t)cp->threads * n, "coupled marks"));
  for (long a = 0; a < (long)cp->threads * n; a++) cp->mark[a] = -1;
  PM_CALL(
      PM_ALLOC(cp->acc, (size_t)cp->threads * 3 * cp->maxlen, "coupled rows"));
  v->prob.aux_n = n;
  v->prob.aux_ptr = cp->ptr;
  v->prob.aux_idx = cp->idx;
  v->prob.aux_values = fpm_static_coupled_values;
  return PM_SUCCESS;
}

/* Row block of own point k: G's columns, sum_(j in E_k) E^c_kj : cof F_j
 * A_ji for each z_i, into acc (3 per member of Z_k, component fastest). */
static void force_row(const fpm_model *m, const fpm_static_tangent *t,
                      const fpm_static_coupled *cp, const double *cof, long k,
                      long *mark, double *acc) {
  const long z0 = cp->Z_ptr[k], nz = cp->Z_ptr[k + 1] - z0;
  for (long a = 0; a < nz; a++) mark[cp->Z_i[z0 + a]] = a;
  memset(acc, 0, (size_t)(3 * nz) * sizeof *acc);
  for (long q = t->E_ptr[k]; q < t->E_ptr[k + 1]; q++) {
    const long j = t->E_j[q];
    const double *E = t->E + 9 * q, *cj = cof + 9 * j;
    double ec[3];
    for (int cc = 0; cc < 3; cc++)
      ec[cc] = E[3 * cc] * cj[3 * cc] + E[3 * cc + 1] * cj[3 * cc + 1] +
               E[3 * cc + 2] * cj[3 * cc + 2];
    for (long r = 0; r < closed_size(m, j); r++) {
      const double *w;
      const long i = closed_member(m, j, r, &w), s = mark[i];
      const double a = weight(m, j, r);
      for (int cc = 0; cc < 3; cc++) acc[3 * s + cc] += a * ec[cc];
    }
  }
  for (long a = 0; a < nz; a++) mark[cp->Z_i[z0 + a]] = -1;
}

/* Row of z_i: the weight of u_m[r] in (A dJ)_i = sum_l A_il cof F_l :
 * dH_l, into acc (3 per member of U_i). */
static void average_row(const fpm_model *m, const fpm_static_coupled *cp,
                        const double *cof, long i, long *mark, double *acc) {
  const long u0 = cp->U_ptr[i], nu = cp->U_ptr[i + 1] - u0;
  for (long a = 0; a < nu; a++) mark[cp->U_m[u0 + a]] = a;
  memset(acc, 0, (size_t)(3 * nu) * sizeof *acc);
  for (long rl = 0; rl < closed_size(m, i); rl++) {
    const double *w;
    const long l = closed_member(m, i, rl, &w);
    const double a = weight(m, i, rl), *cl = cof + 9 * l;
    for (long r = 0; r < closed_size(m, l); r++) {
      const long mm = closed_member(m, l, r, &w), s = mark[mm];
      const double sg = r == 0 ? -a : a; /* (r = 0: the weight is -gsum) */
      for (int c3 = 0; c3 < 3; c3++)
        acc[3 * s + c3] += sg * (cl[3 * c3] * w[0] + cl[3 * c3 + 1] * w[1] +
                                 cl[3 * c3 + 2] * w[2]);
    }
  }
  for (long a = 0; a < nu; a++) mark[cp->U_m[u0 + a]] = -1;
}

pm_err fpm_static_coupled_values(void *ctx, const double *x, double *val) {
  fpm_static_ctx *c = ctx;
  const fpm_model *m = c->m;
  fpm_static_coupled *cp = &c->cp;
  const fpm_volumetric_lin *vl = fpm_linear_volumetric(c->lin);
  const double *D = fpm_linear_tangent(c->lin);
  const double *cof = vl->cof, *d2 = vl->d2, *d2b = vl->d2bar;
  const long n = m->n, nf = c->nf, *free_of = c->free_of, *pat = c->pat_ptr;
  double *Dp = cp->D;
  /* K0: the moduli less U''(J) cof F (x) cof F */
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, D, Dp, cof, d2))
  for (long k = 0; k < n; k++)
    for (int a = 0; a < 9; a++)
      for (int b = 0; b < 9; b++)
        Dp[81 * k + 9 * a + b] =
            D[81 * k + 9 * a + b] - d2[k] * cof[9 * k + a] * cof[9 * k + b];
  c->tg.Dpc = Dp;
  pm_err e = fpm_static_tangent_values(ctx, x, cp->jv);
  c->tg.Dpc = NULL;
  PM_CALL(e);
  const double *jv = cp->jv;
  PM_OMP(parallel default(none)
             shared(m, cp, cof, d2b, n, nf, free_of, pat, jv, val, c)) {
    const int th = pm_omp_thread();
    long *mark = cp->mark + (size_t)th * n;
    double *acc = cp->acc + (size_t)th * 3 * cp->maxlen;
    PM_OMP(for schedule(dynamic, 16))
    for (long k = 0; k < m->n_own; k++) {
      force_row(m, &c->tg, cp, cof, k, mark, acc);
      const long nz = cp->Z_ptr[k + 1] - cp->Z_ptr[k];
      for (int cc = 0; cc < 3; cc++) {
        const long row = free_of[3 * k + cc];
        if (row < 0) continue;
        const long nj = pat[row + 1] - pat[row];
        double *out = val + cp->ptr[row];
        memcpy(out, jv + pat[row], (size_t)nj * sizeof *out);
        for (long a = 0; a < nz; a++) out[nj + a] = acc[3 * a + cc];
      }
    }
    PM_OMP(for schedule(dynamic, 16))
    for (long i = 0; i < n; i++) {
      average_row(m, cp, cof, i, mark, acc);
      double *out = val + cp->ptr[nf + i];
      *out++ = 1;
      for (long q = cp->U_ptr[i]; q < cp->U_ptr[i + 1]; q++)
        for (int r = 0; r < 3; r++)
          if (free_of[3 * cp->U_m[q] + r] >= 0)
            *out++ = -d2b[i] * acc[3 * (q - cp->U_ptr[i]) + r];
    }
  }
  return PM_SUCCESS;
}
