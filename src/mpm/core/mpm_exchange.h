/* mpm_exchange: how MPM's core reaches other ranks: a table the ranks layer
 * fills into a rank's model (NULL on one process), and accessors that do
 * what one process does without it, so the core never asks about ranks. */
#ifndef MPM_EXCHANGE_H
#define MPM_EXCHANGE_H

#include <stdbool.h>
#include <stddef.h>

#include "mpm_state.h"

/* What a node of a nodal array holds, for the typed nodal reduce and
 * broadcast. */
typedef enum {
  MPM_XC_DOUBLE,  /* one double */
  MPM_XC_DOUBLE3, /* three doubles (a vector) */
  MPM_XC_LONG3,   /* three longs (a node's dof numbers) */
  MPM_XC_BYTE     /* one unsigned char (a flag) */
} mpm_xc_unit;

/* How the ranks' values at a node combine on its owner. */
typedef enum { MPM_XC_SUM, MPM_XC_MAX } mpm_xc_op;

/* The operations of a rank's share of a run across ranks, filled in by the
 * ranks layer (mpm_par_create); ctx is its share, which release frees with
 * the table itself.  Every operation but the lookups is collective.  The
 * accessors below give the meaning of each. */
typedef struct mpm_exchange {
  void *ctx;
  void (*sum)(void *ctx, double *v, int n);
  void (*max)(void *ctx, double *v, int n);
  void (*min)(void *ctx, double *v, int n);
  void (*sum_long)(void *ctx, long *v, int n);
  pm_err (*agree)(void *ctx, pm_err e);
  long (*offset)(void *ctx, long n);
  pm_err (*sum_nodes)(const mpm_model *m, mpm_nodes *nd, int mode,
                      bool impedances);
  pm_err (*nodes_reduce)(const mpm_model *m, void *a, mpm_xc_unit unit,
                         mpm_xc_op op);
  pm_err (*nodes_bcast)(const mpm_model *m, void *a, mpm_xc_unit unit);
  const unsigned char *(*owned)(const mpm_model *m);
  void (*work_attach)(const mpm_model *m, mpm_work *w);
  void (*step_end)(const mpm_model *m, mpm_work *w);
  pm_err (*migrate)(mpm_model *m, mpm_state *s, mpm_work *w);
  const double *(*ghost_x)(const mpm_model *m, int gi);
  const long *(*ghost_ids)(const mpm_model *m, int gi, long *n);
  const double *(*nearby)(const mpm_model *m, int gi, long *n,
                          const long **ids);
  void (*cells)(const mpm_model *m, long nn[3], long lo[3], long hi[3]);
  pm_err (*number_unknowns)(const mpm_model *m, long nunk, long *dof,
                            long *gnum, long **ghost, long *nghost);
  pm_err (*gather_nodes)(const mpm_model *m, const mpm_model *full,
                         const double *local, double *whole);
  void (*release)(struct mpm_exchange *xc);
} mpm_exchange;

/* Whether model m is a rank's share of a run across ranks. */
static inline bool mpm_xc_shared(const mpm_model *m) { return m->xc != NULL; }

/* Sums, maxima and minima of n values over the ranks, in place (one
 * process: unchanged). */
static inline void mpm_xc_sum(const mpm_model *m, double *v, int n) {
  if (m->xc) m->xc->sum(m->xc->ctx, v, n);
}
static inline void mpm_xc_max(const mpm_model *m, double *v, int n) {
  if (m->xc) m->xc->max(m->xc->ctx, v, n);
}
static inline void mpm_xc_min(const mpm_model *m, double *v, int n) {
  if (m->xc) m->xc->min(m->xc->ctx, v, n);
}
static inline void mpm_xc_sum_long(const mpm_model *m, long *v, int n) {
  if (m->xc) m->xc->sum_long(m->xc->ctx, v, n);
}
/* Every rank's e: PM_SUCCESS when all have it, else the lowest failing
 * rank's failure and message on every rank (pm_par_agree; one process: e). */
static inline pm_err mpm_xc_agree(const mpm_model *m, pm_err e) {
  return m->xc ? m->xc->agree(m->xc->ctx, e) : e;
}
/* The sum of n over the ranks before this one (one process: 0). */
static inline long mpm_xc_offset(const mpm_model *m, long n) {
  return m->xc ? m->xc->offset(m->xc->ctx, n) : 0;
}

/* After a particle-to-grid transfer (mode, with the impedances): the
 * ranks' contributions to each node summed, on every rank that holds it.
 * A PETSc failure is PM_ERR_LINALG. */
static inline pm_err mpm_xc_sum_nodes(const mpm_model *m, mpm_nodes *nd,
                                      int mode, bool impedances) {
  return m->xc ? m->xc->sum_nodes(m, nd, mode, impedances) : PM_SUCCESS;
}
/* A nodal array (one unit per node of m's block) combined by op on the
 * nodes' owners, then the owners' values on every rank that holds the
 * node; the bcast gives the owners' values alone.  PM_ERR_LINALG. */
static inline pm_err mpm_xc_nodes_reduce(const mpm_model *m, void *a,
                                         mpm_xc_unit unit, mpm_xc_op op) {
  return m->xc ? m->xc->nodes_reduce(m, a, unit, op) : PM_SUCCESS;
}
static inline pm_err mpm_xc_nodes_bcast(const mpm_model *m, void *a,
                                        mpm_xc_unit unit) {
  return m->xc ? m->xc->nodes_bcast(m, a, unit) : PM_SUCCESS;
}
/* Per node of m's block: 1 where this rank owns it (one process: NULL,
 * every node its own). */
static inline const unsigned char *mpm_xc_owned(const mpm_model *m) {
  return m->xc ? m->xc->owned(m) : NULL;
}
/* Point workspace w at what the rank shares (its owned nodes, the
 * migration's timer). */
static inline void mpm_xc_work_attach(const mpm_model *m, mpm_work *w) {
  if (m->xc) m->xc->work_attach(m, w);
}
/* The figures of a step every rank must share once it ends (the largest
 * |tr D|, the smallest J, the iterations). */
static inline void mpm_xc_step_end(const mpm_model *m, mpm_work *w) {
  if (m->xc) m->xc->step_end(m, w);
}
/* After the move: the particles that left this rank's cells to their
 * ranks, and the linked points' ghosts anew (mpm_par_migrate). */
static inline pm_err mpm_xc_migrate(mpm_model *m, mpm_state *s, mpm_work *w) {
  return m->xc ? m->xc->migrate(m, s, w) : PM_SUCCESS;
}

/* The positions of group gi's ghosts, the points of other ranks its points
 * are linked to (3 each; NULL on one process and for a group without). */
static inline const double *mpm_xc_ghost_x(const mpm_model *m, int gi) {
  return m->xc ? m->xc->ghost_x(m, gi) : NULL;
}
/* Their one-process indices (increasing), *n of them (NULL and 0 without). */
static inline const long *mpm_xc_ghost_ids(const mpm_model *m, int gi,
                                           long *n) {
  if (m->xc) return m->xc->ghost_ids(m, gi, n);
  *n = 0;
  return NULL;
}
/* Group gi's nearby points of other ranks (within its kind's ranks_reach
 * of this rank's cells): positions (3 each), one-process indices in *ids,
 * *n of them (NULL and 0 on one process and for a group without a reach). */
static inline const double *mpm_xc_nearby(const mpm_model *m, int gi, long *n,
                                          const long **ids) {
  if (m->xc) return m->xc->nearby(m, gi, n, ids);
  *n = 0;
  *ids = NULL;
  return NULL;
}
/* The whole grid's nodes per axis nn (1 along z in 2-D) and the cells whose
 * particles this rank holds, [lo, hi) per axis (one process: all). */
static inline void mpm_xc_cells(const mpm_model *m, long nn[3], long lo[3],
                                long hi[3]) {
  if (m->xc) {
    m->xc->cells(m, nn, lo, hi);
    return;
  }
  for (int a = 0; a < 3; a++) {
    nn[a] = m->grid.nn[a];
    lo[a] = 0;
    hi[a] = a < m->dim ? m->grid.nn[a] - 1 : 1;
  }
}

/* The implicit solver's unknowns over the ranks: dof (3 per node of m's
 * block: an owned node's unknown 0..nunk-1, else -1) gets the ghost nodes'
 * unknowns numbered after the owned ones; gnum (3 per node) each dof's
 * number over all ranks (each rank's owned unknowns after the ranks'
 * before it), -1 for none; *ghost (reallocated, the caller's) the ghost
 * unknowns' numbers over all ranks, *nghost of them.  One process: none.
 * PM_ERR_MEMORY; PM_ERR_INTERNAL when a rank and a node's owner disagree. */
static inline pm_err mpm_xc_number_unknowns(const mpm_model *m, long nunk,
                                            long *dof, long *gnum, long **ghost,
                                            long *nghost) {
  if (m->xc) return m->xc->number_unknowns(m, nunk, dof, gnum, ghost, nghost);
  *nghost = 0;
  return PM_SUCCESS;
}
/* Three values per node of the whole grid (whole, on rank 0; NULL on the
 * others) from each rank's owned nodes (local, three per node of m's
 * block); full is the whole model on rank 0.  One process: a copy. */
static inline pm_err mpm_xc_gather_nodes(const mpm_model *m,
                                         const mpm_model *full,
                                         const double *local, double *whole) {
  if (m->xc) return m->xc->gather_nodes(m, full, local, whole);
  for (long i = 0; i < 3 * m->grid.n_nodes; i++) whole[i] = local[i];
  return PM_SUCCESS;
}

/* Release the model's share of the run, if any (mpm_model_destroy). */
static inline void mpm_xc_release(mpm_model *m) {
  if (m->xc) m->xc->release(m->xc);
  m->xc = NULL;
}

#endif
