/* fpm_exchange: how the FPM core reaches the other ranks of a run, and all
 * it may know of them.  The ranks layer (src/fpm/ranks) fills one in for a
 * share; a model on one process has none (fpm_model.xc NULL), and every
 * helper below is then the identity. */
#ifndef FPM_EXCHANGE_H
#define FPM_EXCHANGE_H

#include "pm_error.h"

/* The operations of a share across ranks, each collective (every rank
 * calls it, in the same order), on the context ctx. */
typedef struct fpm_exchange {
  void *ctx;
  /* The ghosts' values, 3 doubles per point held (the displacements, or
   * anything laid out as they are), from their owners. */
  void (*ghosts)(void *ctx, double *u);
  /* The same for one double per point held (the averaged volume's
   * pressure U'(Jbar) and its increments, fpm_volumetric.h). */
  void (*ghost_scalars)(void *ctx, double *v);
  /* Every rank's failure e, placed by key in one process's order: every
   * rank returns the one one process meets first. */
  pm_err (*agree)(void *ctx, pm_err e, long key);
  /* Sums and minima of n values over the ranks, in place. */
  void (*sum)(void *ctx, double *v, int n);
  void (*min)(void *ctx, double *v, int n);
  void (*sum_long)(void *ctx, long *v, int n);
  /* The count of the ranks before this one, of `count` items on each. */
  long (*offset)(void *ctx, long count);
  /* Release ctx (when the share's model is destroyed; not collective). */
  void (*release)(void *ctx);
} fpm_exchange;

static inline void fpm_exchange_ghosts(const fpm_exchange *xc, double *u) {
  if (xc) xc->ghosts(xc->ctx, u);
}

static inline void fpm_exchange_ghost_scalars(const fpm_exchange *xc,
                                              double *v) {
  if (xc) xc->ghost_scalars(xc->ctx, v);
}

static inline pm_err fpm_exchange_agree(const fpm_exchange *xc, pm_err e,
                                        long key) {
  return xc ? xc->agree(xc->ctx, e, key) : e;
}

static inline void fpm_exchange_sum(const fpm_exchange *xc, double *v, int n) {
  if (xc) xc->sum(xc->ctx, v, n);
}

static inline void fpm_exchange_min(const fpm_exchange *xc, double *v, int n) {
  if (xc) xc->min(xc->ctx, v, n);
}

static inline void fpm_exchange_sum_long(const fpm_exchange *xc, long *v,
                                         int n) {
  if (xc) xc->sum_long(xc->ctx, v, n);
}

static inline long fpm_exchange_offset(const fpm_exchange *xc, long count) {
  return xc ? xc->offset(xc->ctx, count) : 0;
}

#endif
