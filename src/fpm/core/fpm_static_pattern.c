/* fpm_static_pattern: the pattern of the Jacobian of FPM's static solve:
 * each own point's force is reached by the supports of the supports of its
 * supports (and, with the quadratic jump, the fits of those). */
#include <stdlib.h>

#include "fpm_static_impl.h"
#include "pm_coloring.h"
#include "pm_omp.h"

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
pm_err fpm_static_pattern(const fpm_model *m, const long *free_of, long nf,
                          fpm_static_tangent *tg, long **ptr_out,
                          long **idx_out) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own;
  const int threads = pm_omp_threads();
  long *marks = NULL, *lists = NULL, *ptr = NULL, *idx = NULL;
  /* each thread's marks and lists (a and r), n each */
  PM_TRY(PM_ALLOC(marks, 2 * (size_t)threads * n, "pattern marks"));
  PM_TRY(PM_ALLOC(lists, 2 * (size_t)threads * n, "pattern lists"));
  PM_TRY(PM_ALLOC(ptr, nf + 1, "Jacobian pattern"));
  PM_TRY(PM_ALLOC(tg->R_ptr, n + 1, "Jacobian reach"));
  for (long i = 0; i < 2 * (long)threads * n; i++) marks[i] = -1;
  /* Count, then fill: rows on every thread, each its own. */
  for (int pass = 0; pass < 2; pass++) {
    PM_OMP(parallel default(none)
               shared(m, free_of, tg, marks, lists, ptr, idx, n, rows, pass)) {
      const size_t off = 2 * (size_t)pm_omp_thread() * n;
      long *mark_a = marks + off, *mark_r = mark_a + n, *a_list = lists + off,
           *r_list = a_list + n;
      PM_OMP(for schedule(dynamic, 16))
      for (long k = 0; k < rows; k++) {
        long nr = reach(m, k, r_list, a_list, mark_a, mark_r, pass * n + k);
        /* in increasing order: the rows' columns then are (the unknowns
         * number the free dofs in order), and the solver takes the
         * tangent's values in place */
        if (pass == 1) pm_pattern_sort_row(r_list, nr);
        if (pass == 0)
          tg->R_ptr[k + 1] = nr;
        else
          for (long t = 0; t < nr; t++)
            tg->R_list[tg->R_ptr[k] + t] = r_list[t];
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
  free(marks);
  free(lists);
  free(ptr);
  free(idx);
  return ret;
}
