/* Four doubles as one vector (GNU C vector extension): one 256-bit
 * register on x86-64-v3, two 128-bit halves on narrower instruction sets.
 * The explicit kernels of FPM and MPM load and store it unaligned. */
#ifndef PM_V4_H
#define PM_V4_H

#include <string.h>

typedef double pm_v4 __attribute__((vector_size(4 * sizeof(double))));

/* The four doubles at p (any alignment) as one vector. */
static inline pm_v4 pm_v4_load(const double *p) {
  pm_v4 v;
  memcpy(&v, p, sizeof v);
  return v;
}

/* Stores v's four doubles at p (any alignment). */
static inline void pm_v4_store(double *p, pm_v4 v) { memcpy(p, &v, sizeof v); }

/* The transpose of the 4 x 4 block whose rows are r[0..3]: c[j][l] =
 * r[l][j].  Eight shuffles, no arithmetic: the values are moved, not
 * changed. */
static inline void pm_v4_transpose(const pm_v4 r[4], pm_v4 c[4]) {
  const pm_v4 t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 2, 6),
              t1 = __builtin_shufflevector(r[0], r[1], 1, 5, 3, 7),
              t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 2, 6),
              t3 = __builtin_shufflevector(r[2], r[3], 1, 5, 3, 7);
  c[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
  c[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
  c[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
  c[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

#endif
