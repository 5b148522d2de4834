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

#endif
