/* fpm_static_support: a cheaper operator to build multigrid on in FPM's
 * static solve: the tangent's blocks of each point's own support (the
 * 1-ring) or of its supports' supports (the 2-ring), the rest left out. */
#include <stdlib.h>

#include "fpm_static_impl.h"

void fpm_static_support_free(fpm_static_support *sp) {
  free(sp->ptr);
  free(sp->idx);
  free(sp->L_ptr);
  free(sp->L);
  sp->ptr = sp->idx = sp->L_ptr = sp->L = NULL;
}

/* The points of own point k's rings (k first) into list from w (NULL:
 * counted only; mark[p] == k: p listed for k); returns their number. */
static long ring_points(const fpm_model *m, long k, int rings, long *mark,
                        long *list, long w) {
  long cnt = 0;
  for (long r = 0; r < closed_size(m, k); r++) {
    const double *g;
    const long j = closed_member(m, k, r, &g);
    const long reach = rings > 1 ? closed_size(m, j) : 1;
    for (long r2 = 0; r2 < reach; r2++) {
      const long p = rings > 1 ? closed_member(m, j, r2, &g) : j;
      if (mark[p] == k) continue;
      mark[p] = k;
      if (list) list[w + cnt] = p;
      cnt++;
    }
  }
  return cnt;
}

pm_err fpm_static_support_build(const fpm_model *m, const long *free_of,
                                long nf, int rings, fpm_static_support *sp) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own;
  long *mark = NULL;
  sp->rings = rings;
  PM_TRY(PM_ALLOC(mark, n, "support marks"));
  PM_TRY(PM_ALLOC(sp->L_ptr, rows + 1, "support lists"));
  /* the lists: counted, then filled */
  for (long i = 0; i < n; i++) mark[i] = -1;
  sp->L_ptr[0] = 0;
  for (long k = 0; k < rows; k++)
    sp->L_ptr[k + 1] = sp->L_ptr[k] + ring_points(m, k, rings, mark, NULL, 0);
  PM_TRY(PM_ALLOC(sp->L, sp->L_ptr[rows] + 1, "support lists"));
  for (long i = 0; i < n; i++) mark[i] = -1;
  for (long k = 0; k < rows; k++)
    ring_points(m, k, rings, mark, sp->L, sp->L_ptr[k]);
  /* the pattern: each free row of k over the free dofs of k's list */
  PM_TRY(PM_ALLOC(sp->ptr, nf + 1, "support pattern"));
  sp->ptr[0] = 0;
  for (long k = 0; k < rows; k++) {
    long cols = 0;
    for (long t = sp->L_ptr[k]; t < sp->L_ptr[k + 1]; t++)
      for (int b = 0; b < 3; b++) cols += free_of[3 * sp->L[t] + b] >= 0;
    for (int c = 0; c < 3; c++)
      if (free_of[3 * k + c] >= 0) sp->ptr[free_of[3 * k + c] + 1] = cols;
  }
  for (long r = 0; r < nf; r++) sp->ptr[r + 1] += sp->ptr[r];
  PM_TRY(
      PM_ALLOC(sp->idx, sp->ptr[nf] > 0 ? sp->ptr[nf] : 1, "support pattern"));
  for (long k = 0; k < rows; k++)
    for (int c = 0; c < 3; c++) {
      const long row = free_of[3 * k + c];
      if (row < 0) continue;
      long w = sp->ptr[row];
      for (long t = sp->L_ptr[k]; t < sp->L_ptr[k + 1]; t++)
        for (int b = 0; b < 3; b++)
          if (free_of[3 * sp->L[t] + b] >= 0)
            sp->idx[w++] = free_of[3 * sp->L[t] + b];
    }
done:
  free(mark);
  return ret;
}

void fpm_static_support_row(long k, const long *free_of, const long *mark,
                            const double *blk, const fpm_static_support *sp,
                            double *val) {
  for (int cc = 0; cc < 3; cc++) {
    const long row = free_of[3 * k + cc];
    if (row < 0) continue;
    long w = sp->ptr[row];
    for (long t = sp->L_ptr[k]; t < sp->L_ptr[k + 1]; t++) {
      const long p = sp->L[t];
      const double *b = blk + 9 * mark[p];
      for (int bb = 0; bb < 3; bb++)
        if (free_of[3 * p + bb] >= 0) val[w++] = b[3 * cc + bb];
    }
  }
}
