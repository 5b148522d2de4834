/* roofline-peak: the machine's roofs for benchmarks/bench-roofline.sh: the
 * double-precision multiply-add rate of independent chains (the compiler's
 * widest vectors for the -march given) and the triad bandwidth
 * a = b + s c at sizes held in L2, in L3 and in memory, on 1 and 2 threads.
 * Timed by each thread's CPU time (the slowest thread's), so that time
 * the machine's other processes hold the core is not counted. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define CHAINS 64 /* independent accumulators: enough to cover the latency */

/* Seconds of this thread's CPU time. */
static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Flops per second of `reps` rounds of CHAINS multiply-adds per thread. */
static double fma_rate(int threads, long reps) {
  double best = 0;
  for (int trial = 0; trial < 3; trial++) {
    double sink = 0, t = 0;
#pragma omp parallel num_threads(threads) reduction(+ : sink) reduction(max : t)
    {
      const double t0 = now();
      double acc[CHAINS];
      const double a = 0.999999, b = 1e-7 * (1 + omp_get_thread_num());
      for (int k = 0; k < CHAINS; k++) acc[k] = k;
      for (long r = 0; r < reps; r++)
#pragma omp simd
        for (int k = 0; k < CHAINS; k++) acc[k] = acc[k] * a + b;
      for (int k = 0; k < CHAINS; k++) sink += acc[k];
      t = now() - t0;
    }
    const double rate = 2.0 * CHAINS * reps * threads / t;
    if (rate > best) best = rate;
    if (sink == 42) printf(" ");
  }
  return best;
}

/* Bytes per second of the triad over arrays of n doubles (24 bytes an
 * element: two read, one written; write-allocate not counted). */
static double triad_rate(int threads, long n, double *a, double *b, double *c) {
  const long reps = 1e8 / n + 1;
  double best = 0;
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long i = 0; i < n; i++) a[i] = 0, b[i] = 1, c[i] = 2;
  for (int trial = 0; trial < 3; trial++) {
    double t = 0;
#pragma omp parallel num_threads(threads) reduction(max : t)
    {
      const double t0 = now();
      for (long r = 0; r < reps; r++) {
#pragma omp for schedule(static) nowait
        for (long i = 0; i < n; i++) a[i] = b[i] + 0.5 * c[i];
      }
      t = now() - t0;
    }
    const double rate = 24.0 * n * reps / t;
    if (rate > best) best = rate;
  }
  return best + 0 * a[n / 2];
}

int main(void) {
  const long big = 1L << 24; /* 3 x 128 MiB: memory */
  double *a = malloc(big * sizeof *a), *b = malloc(big * sizeof *b),
         *c = malloc(big * sizeof *c);
  if (!a || !b || !c) return 1;
  printf("%-8s %12s %14s %14s %14s\n", "threads", "GFLOP/s", "L2 GB/s",
         "L3 GB/s", "memory GB/s");
  for (int t = 1; t <= 2; t++) {
    const double f = fma_rate(t, 20000000);
    /* 3 x 256 KiB per thread in L2 (2 MiB), 3 x 4 MiB in L3 (32 MiB) */
    const double l2 = triad_rate(t, 32768L * t, a, b, c);
    const double l3 = triad_rate(t, 524288L, a, b, c);
    const double mem = triad_rate(t, big, a, b, c);
    printf("%-8d %12.2f %14.2f %14.2f %14.2f\n", t, f / 1e9, l2 / 1e9, l3 / 1e9,
           mem / 1e9);
  }
  free(a);
  free(b);
  free(c);
  return 0;
}
