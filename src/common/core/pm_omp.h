/* pm_omp: OpenMP pragmas behind a macro, so a build without OpenMP compiles
 * warning-free, and the thread-count query both builds need. */
#ifndef PM_OMP_H
#define PM_OMP_H

#ifdef _OPENMP
#include <omp.h>
#define PM_OMP_AVAILABLE 1
#define PM_PRAGMA_(x) _Pragma(#x)
#define PM_OMP(...) PM_PRAGMA_(omp __VA_ARGS__)
static inline int pm_omp_threads(void) { return omp_get_max_threads(); }
static inline void pm_omp_set_threads(int n) { omp_set_num_threads(n); }
static inline int pm_omp_thread(void) { return omp_get_thread_num(); }
/* Threads of the team running this (inside a parallel region). */
static inline int pm_omp_team(void) { return omp_get_num_threads(); }
#else
#define PM_OMP_AVAILABLE 0
#define PM_OMP(...)
static inline int pm_omp_threads(void) { return 1; }
static inline void pm_omp_set_threads(int n) { (void)n; }
static inline int pm_omp_thread(void) { return 0; }
static inline int pm_omp_team(void) { return 1; }
#endif

/* LAPACK runs on small matrices inside OpenMP loops (the membranes' normal
 * fits, FPM's gradients), where OpenBLAS's own threads can only compete
 * with OpenMP's for the cores.  One thread for OpenBLAS when it is the BLAS
 * loaded; nothing with another BLAS. */
void openblas_set_num_threads(int n) __attribute__((weak));
int openblas_get_num_threads(void) __attribute__((weak));
static inline void pm_blas_single_thread(void) {
  if (openblas_set_num_threads) openblas_set_num_threads(1);
}

/* Where no OpenMP loop runs beside it (a sparse factorisation's dense
 * fronts), OpenBLAS on the OpenMP threads: pm_blas_widen() returns the
 * threads it had, which pm_blas_restore(that) gives back.  Nothing with
 * another BLAS (0 returned). */
static inline int pm_blas_widen(void) {
  if (!openblas_set_num_threads || !openblas_get_num_threads) return 0;
  const int had = openblas_get_num_threads();
  if (pm_omp_threads() > had) openblas_set_num_threads(pm_omp_threads());
  return had;
}
static inline void pm_blas_restore(int had) {
  if (had > 0 && openblas_set_num_threads) openblas_set_num_threads(had);
}

#endif
