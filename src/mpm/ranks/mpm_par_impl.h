/* mpm_par_impl: what the pieces of the ranks layer share: a rank's share
 * of the run (struct mpm_par), the migration's record, and the operations
 * each piece gives the exchange table (mpm_par.c).  Internal to ranks/. */
#ifndef MPM_PAR_IMPL_H
#define MPM_PAR_IMPL_H

#include <mpi.h>

#include "mpm_par.h"
#include "mpm_par_ghosts.h"
#include "pm_halo.h"

/* A particle's record in a migration: its index on one process, its group,
 * x0 (3), mass, vol0, x (3), v (3), vol, sigma (9), then its group's
 * arrays in their layout's order. */
enum {
  REC_GID = 0,
  REC_GROUP = 1,
  REC_X0 = 2,
  REC_MASS = 5,
  REC_VOL0 = 6,
  REC_X = 7,
  REC_V = 10,
  REC_VOL = 13,
  REC_SIGMA = 14,
  REC_BASE = 23
};

struct mpm_par {
  mpm_exchange xc; /* the core's view of this share (ctx: this) */
  mpm_decomp d;
  int rank;
  long own_lo[3], own_hi[3]; /* owned nodes (global) per axis */
  /* the node sums: each ghost node (a leaf) is a node of its owner (a
   * root); the sums go leaves to roots and back, on the ghost nodes and
   * the owned nodes next to other ranks only */
  pm_halo *ghosts;
  /* dynamic relaxation's nodal arrays to rank 0: a rank's owned nodes'
   * values, and on rank 0 every rank's */
  double *nodal, *whole;
  /* mpm_par_extreme's: five doubles a rank (a value, its index and place) */
  double *extreme;
  unsigned char *owned; /* per local node */
  long n_owned;         /* nodes this rank owns */
  /* the whole run's ranges, in indices on one process */
  long n_full;
  long gbegin[MPM_MAX_GROUPS], gend[MPM_MAX_GROUPS];
  long *bbegin, *bend; /* per body */
  /* migration: to the ranks whose boxes touch this rank's (a particle
   * moves less than a cell in a step), on a graph communicator */
  MPI_Comm near;
  int n_near;   /* such ranks */
  int *near_of; /* per rank: its place among them, or -1 */
  int rec;      /* doubles per record */
  int width;    /* doubles per particle of the widest array (>= 9) */
  int *dest;    /* per particle (room): where it goes among the near ranks
                   (-1: it stays) */
  int *scount, *rcount, *sdisp, *rdisp; /* per near rank, in doubles */
  double *sbuf, *rbuf;
  long sbuf_room, rbuf_room; /* records */
  long *order;               /* per new particle: old index, or -(k + 1) for
                                the k-th record received */
  double *tmp;               /* room x width: one array's new order */
  /* the ghosts of linked points (membranes' neighbours on other ranks),
   * and what the last migration did to them: linked points that left
   * this rank, and whether its particles changed */
  mpm_ghosts *gh;
  long linked_left;
  bool reordered;
  /* gather (rank 0 holds the whole run's buffers) */
  double *accounts; /* every rank's energy accounts, on rank 0 */
  long *ggid;
  double *gbuf;
  int *gcount, *gdisp;
  mpm_par_counts counts;
  /* cutting the boxes anew (mpm_par_balance): the scene, whether rank 0
   * gathers, and the imbalance that calls for it (0: never) */
  const pm_scene *scene;
  bool gather;
  double balance;
  /* a new cut's: the whole grid and its conditions (mpm_model_frame) and
   * the particles per cell of it, made at the first and kept */
  mpm_model *frame;
  long *per_cell;
};

/* Records (doubles, the first their one-process index) by that index, for
 * qsort. */
int mpm_par_by_gid(const void *a, const void *b);

/* Particle p of group gi (of m, s) into record q (REC_* then the group's
 * arrays), and back from q into particle j of group gi. */
void mpm_par_pack(const mpm_model *m, const mpm_state *s, long p, int gi,
                  double *q);
void mpm_par_unpack(const mpm_model *m, mpm_state *s, long j, int gi,
                    const double *q);
/* Room in each group's step workspace of w for what its kind needs now
 * (its particles, a membrane's triangles). */
pm_err mpm_par_grow_scratch(const mpm_model *m, mpm_work *w);

/* The share of local model m. */
static inline struct mpm_par *par_of(const mpm_model *m) { return m->xc->ctx; }

/* Room for n particles and some to arrive. */
static inline long mpm_par_room_for(long n) { return n + n / 4 + 64; }

/* The rank that owns cell q of decomposition d. */
int mpm_decomp_rank_of(const mpm_decomp *d, const long q[3]);

/* Body and group ranges of local model m (and its state s, if any) from
 * its particles' one-process indices, after they changed. */
void mpm_par_set_ranges(mpm_model *m, mpm_state *s);

/* The exchange's operations (mpm_exchange.h), by subject: node sums and
 * nodal arrays (mpm_par_nodes.c), migration and ghosts (mpm_par_migrate.c),
 * the implicit solver's nodes to rank 0 (mpm_par_gather.c). */
pm_err mpm_par_sum_nodes(const mpm_model *m, mpm_nodes *nd, int mode, bool imp);
pm_err mpm_par_nodes_reduce(const mpm_model *m, void *a, mpm_xc_unit unit,
                            mpm_xc_op op);
pm_err mpm_par_nodes_bcast(const mpm_model *m, void *a, mpm_xc_unit unit);
const unsigned char *mpm_par_owned(const mpm_model *m);
pm_err mpm_par_number_unknowns(const mpm_model *m, long nunk, long *dof,
                               long *gnum, long **ghost, long *nghost);
void mpm_par_step_end(const mpm_model *m, mpm_work *w);
pm_err mpm_par_migrate(mpm_model *m, mpm_state *s, mpm_work *w);
const double *mpm_par_ghost_x(const mpm_model *m, int gi);
const long *mpm_par_ghost_ids(const mpm_model *m, int gi, long *n);
const double *mpm_par_nearby(const mpm_model *m, int gi, long *n,
                             const long **ids);
void mpm_par_cells(const mpm_model *m, long nn[3], long lo[3], long hi[3]);
pm_err mpm_par_gather_nodes(const mpm_model *m, const mpm_model *full,
                            const double *local, double *whole);

#endif
