/* mpm_fbar: the cell and patch averages of F-bar, and their workspace. */
#include "mpm_fbar.h"

#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"

pm_err mpm_fbar_work_create(mpm_fbar_work *fw, mpm_fbar_mode mode, long n,
                            long n_slots, int threads) {
  *fw = (mpm_fbar_work){.threads = threads, .n_slots = n_slots, .n = n};
  PM_CALL(PM_ALLOC(fw->partial, 2 * (size_t)threads * n_slots,
                   "F-bar partial sums"));
  PM_CALL(PM_ALLOC(fw->mean, n_slots, "F-bar averages"));
  PM_CALL(PM_ALLOC(fw->jm1, n, "F-bar volume ratios"));
  if (mode == MPM_FBAR_CELL) PM_CALL(PM_ALLOC(fw->cell, n, "F-bar cells"));
  if (mode == MPM_FBAR_PATCH)
    PM_CALL(PM_ALLOC(fw->qbar, n, "F-bar patch averages"));
  return PM_SUCCESS;
}

void mpm_fbar_work_destroy(mpm_fbar_work *fw) {
  free(fw->partial);
  free(fw->mean);
  free(fw->jm1);
  free(fw->cell);
  free(fw->qbar);
  *fw = (mpm_fbar_work){0};
}

size_t mpm_fbar_work_bytes(const mpm_fbar_work *fw) {
  size_t per_slot = 2 * (size_t)fw->threads + 1;
  size_t per_particle =
      1 + (fw->cell ? sizeof(long) / sizeof(double) : 0) + (fw->qbar ? 1 : 0);
  return sizeof(double) *
         (per_slot * (size_t)fw->n_slots + per_particle * (size_t)fw->n);
}

/* The threads' partial sums added in thread order: the ratio of the two
 * sums of each slot (0 where nothing was summed).  Inside the parallel
 * region, after a barrier. */
static void reduce_slots(const mpm_fbar_work *fw, double *mean) {
  const long ns = fw->n_slots;
  const int T = pm_omp_team();
  PM_OMP(for schedule(static))
  for (long i = 0; i < ns; i++) {
    double num = 0, den = 0;
    for (int t = 0; t < T; t++) {
      const double *r = fw->partial + 2 * ((size_t)t * ns + i);
      num += r[0];
      den += r[1];
    }
    mean[i] = den > 0 ? num / den : 0.0;
  }
}

void mpm_fbar_cell_average(mpm_fbar_work *fw, long n, const long *cell,
                           const double *q, const double *vol0, double *mean) {
  const long ns = fw->n_slots;
  PM_OMP(parallel num_threads(fw->threads) default(none)
             shared(fw, n, cell, q, vol0, mean, ns)) {
    double *restrict acc = fw->partial + 2 * (size_t)pm_omp_thread() * ns;
    memset(acc, 0, 2 * sizeof(double) * ns);
    PM_OMP(for schedule(static))
    for (long p = 0; p < n; p++) {
      double *r = acc + 2 * cell[p];
      r[0] += vol0[p] * q[p];
      r[1] += vol0[p];
    }
    reduce_slots(fw, mean); /* after the loop's barrier */
  }
}

void mpm_fbar_patch_average(mpm_fbar_work *fw, const mpm_grid *g, long n,
                            const double *x, const double *q,
                            const double *vol0, double *qbar) {
  const long ns = fw->n_slots;
  double *mean = fw->mean;
  PM_OMP(parallel num_threads(fw->threads) default(none)
             shared(fw, g, n, x, q, vol0, qbar, mean, ns)) {
    double *restrict acc = fw->partial + 2 * (size_t)pm_omp_thread() * ns;
    memset(acc, 0, 2 * sizeof(double) * ns);
    PM_OMP(for schedule(static))
    for (long p = 0; p < n; p++) {
      mpm_stencil st;
      mpm_stencil_at(g, x + 3 * p, MPM_STENCIL_W, &st);
      for (int k = 0; k < st.n; k++) {
        double *r = acc + 2 * st.node[k];
        const double wv = st.w[k] * vol0[p];
        r[0] += wv * q[p];
        r[1] += wv;
      }
    }
    reduce_slots(fw, mean); /* each loop ends in a barrier */
    PM_OMP(for schedule(static))
    for (long p = 0; p < n; p++) {
      mpm_stencil st;
      mpm_stencil_at(g, x + 3 * p, MPM_STENCIL_W, &st);
      double s = 0;
      for (int k = 0; k < st.n; k++) s += st.w[k] * mean[st.node[k]];
      qbar[p] = s;
    }
  }
}
