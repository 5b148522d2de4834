/* mpm_par: explicit MPM across MPI ranks.  The grid is cut into boxes, one
 * per rank; each rank holds the particles of its cells
 * and its block of the grid with the ghost node layers their stencils
 * reach.
 *
 * A step on a rank is the step of one process on its own particles and
 * nodes, with three additions:
 *  - after every particle-to-grid transfer the ranks' contributions to a
 *    node are summed on its owner and the sums sent back to every rank
 *    that holds the node as a ghost (pm_halo, whose leaves are the ghost
 *    nodes and whose roots are their owners' nodes: reduce by sum, then
 *    broadcast), so that each rank holds whole nodal sums on all
 * its nodes and updates its ghost nodes as their owner does: the grid's
 *    velocities need no second exchange;
 *  - sums over nodes (reactions, residual, damping, energies) count owned
 *    nodes only and are summed over the ranks; the stable step is their
 *    minimum; a failure on one rank stops all of them after the same
 *    stage, with that rank's message (particles named by their index on
 *    one process);
 *  - after the move, particles that left the rank's cells go to the rank
 *    that owns their cell, with every array they carry; a rank's
 *    particles stay in increasing order of their index on one process, so
 *    groups and bodies stay contiguous;
 *  - particles that read others of their group (a membrane point's normal
 *    reads its neighbours', or the points of the cells around its own
 *    when it is fitted per cell) get the positions of those on other
 *    ranks, the ghosts, once a step after the migration
 *    (mpm_par_ghosts.h); the links among them are made anew when a linked
 *    point changed rank;
 *  - a body moving as prescribed sums its mass at the nodes over the
 *    ranks before it sets their velocities.
 * Each rank seeds its own share from the scene (mpm_par_create_seeded),
 * with the particles of its cells in one process's order: no rank builds
 * the whole model for it.  Rank 0 may keep a whole model of its own and
 * gather the state into it when the run writes (frames, history,
 * checkpoints): the output of a run across ranks is that of one process,
 * in the same order.
 *
 * The decomposition balances particles, not cells: along each axis it
 * splits, the cuts divide the particles of the initial state into equal
 * shares (recursive bisection: boxes of any shape, so that particles in a
 * sphere are shared as well as particles filling the box).  It leaves
 * uncut an axis along which a boundary wall moves (a face condition's
 * column is walked from the grid's edge to the wall) and keeps cuts clear
 * of face planes.  Particles that travel unbalance the boxes: every 20
 * steps the busiest rank's count is compared with the mean, and past
 * mpm.rebalance the boxes are cut anew by the same bisection on the
 * particles where they are (mpm_par_balance).  The node sums run on the
 * ghost nodes' exchange (pm_halo: MPI alone). */
#ifndef MPM_PAR_H
#define MPM_PAR_H

#include <stdint.h>
#include <stdio.h>

#include "mpm_exchange.h"
#include "mpm_model.h"
#include "mpm_state.h"

/* A cut of the bisection: cells below `at` along `axis` go to child[0],
 * the others to child[1]; a child is another cut, or -(rank + 1). */
typedef struct {
  int axis;
  long at;
  int child[2];
} mpm_decomp_cut;

/* A decomposition of the grid's cells into boxes, one per rank, by
 * recursive bisection. */
typedef struct {
  int size;             /* ranks */
  long cells[3];        /* cells per axis of the whole grid (1 on z in 2-D) */
  long *box;            /* 6 per rank: its cells [lo, hi) along x, y, z */
  mpm_decomp_cut *tree; /* size - 1 cuts; the first is the root */
  int cuts[3];          /* cuts along each axis */
  long *count;          /* particles per rank where the cut was made */
  long *count0;         /* particles per rank at the run's start */
  long recuts;          /* cuts made since the start (mpm_par_balance) */
  int ghost;            /* node layers a rank holds beyond its own nodes */
  char held[256];       /* the axes that are not cut, and why */
} mpm_decomp;

/* Decompose model m's grid (scene s) for `size` ranks, balancing its
 * particles at their reference positions (so that a resumed run has the
 * boxes of its start): the box of the whole grid is cut along its
 * longest axis that may be cut, where its particles divide in the
 * proportion of the ranks on each side, and each side likewise.  PM_ERR_SCENE
 * (naming what prevents it) when the grid cannot be shared by that many ranks.
 * Release with mpm_decomp_destroy. */
pm_err mpm_decomp_create(const pm_scene *s, const mpm_model *m, int size,
                         mpm_decomp *d);
/* mpm_decomp_create from the particles per cell of the whole grid
 * (per_cell: mpm_decomp_cells of them, x fastest; total particles): m
 * needs its grid and conditions alone (mpm_model_frame). */
pm_err mpm_decomp_from_counts(const pm_scene *s, const mpm_model *m, int size,
                              const long *per_cell, long total, mpm_decomp *d);
/* The cells of grid g per axis (1 on z in 2-D) and their count. */
long mpm_decomp_cells(const mpm_grid *g, long cells[3]);
/* Count a particle at x in its cell (clamped to the grid) of per_cell. */
void mpm_decomp_count(const mpm_grid *g, const long cells[3], const double x[3],
                      long *per_cell);
void mpm_decomp_destroy(mpm_decomp *d);
/* The cut as mpm_decomp_items(size) integers (a checkpoint's), and back
 * for the grid `whole` (mpm_decomp_unpack checks what it reads: PM_ERR_IO
 * naming `what` when the integers are no cut of that grid for `size`
 * ranks; release with mpm_decomp_destroy). */
long mpm_decomp_items(int size);
void mpm_decomp_pack(const mpm_decomp *d, long *buf);
pm_err mpm_decomp_unpack(const long *buf, int size, const mpm_grid *whole,
                         const char *what, mpm_decomp *d);
/* The rank that owns the cell of position x. */
int mpm_decomp_rank_at(const mpm_decomp *d, const mpm_grid *g,
                       const double x[3]);
/* The nodes rank r owns, [lo, hi) per axis (a box's cells' lower nodes,
 * and the grid's last nodes for a box at its upper end), and those it
 * holds (with the ghost layers, within grid g). */
void mpm_decomp_nodes(const mpm_decomp *d, int r, long lo[3], long hi[3]);
void mpm_decomp_held(const mpm_decomp *d, int r, const mpm_grid *g, long lo[3],
                     long hi[3]);

/* What a run across ranks needs that one process does not: refuse what
 * it cannot do yet, naming the scene key (PM_ERR_SCENE).  The backends'
 * scene checks call it when more than one rank runs, after the method's
 * own checks (mpm_check_scene); mpm_par_check_implicit then adds what the
 * implicit MPM cannot do across ranks yet, before its own checks. */
pm_err mpm_par_check(const pm_scene *s);
pm_err mpm_par_check_implicit(const pm_scene *s);

/* This rank's model and state of the run of full model m (scene s) at
 * state st, which every rank holds, on cut `cut` (mpm_decomp_pack's, or
 * NULL: m's particles at their reference positions): its cells'
 * particles, its block of the
 * grid, the conditions on it and the exchanges with the other ranks
 * (collective).  Its energy accounts are its row of `accounts`
 * (MPM_PAR_ACCOUNTS per rank, as a checkpoint of as many ranks keeps
 * them), or without them st's on rank 0 and none on the others.  *local
 * owns its arrays and holds the exchange its core calls (mpm_exchange.h:
 * this share, released with it); m and st are left as they are. */
pm_err mpm_par_create(const pm_scene *s, const mpm_model *m,
                      const mpm_state *st, const double *accounts,
                      const long *cut, mpm_model **local,
                      mpm_state **local_state);

/* This rank's model and state at the start of a run of scene s, made from
 * the scene alone (collective): the decomposition from the particles per
 * cell, counted as one process seeds them without storing one, then the
 * particles of this rank's cells seeded in one process's order
 * (mpm_model_share), the same share mpm_par_create makes from the whole
 * model, bit for bit.  No rank builds the whole model; with `gather`,
 * rank 0 has the buffers to gather the run into a whole model it keeps
 * (mpm_par_gather). */
pm_err mpm_par_create_seeded(const pm_scene *s, bool gather, mpm_model **local,
                             mpm_state **local_state);

/* A share other than the particles whose reference positions lie in the
 * rank's cells (a run resumed from a checkpoint in pieces: those where
 * the checkpoint has them): prepare (if any) learns the decomposition d of the
 * whole grid g and this rank, then keep says which reference positions
 * the share keeps (called as mpm_seed_share.keep). */
typedef struct {
  pm_err (*prepare)(void *ctx, const mpm_decomp *d, const mpm_grid *g,
                    int rank);
  bool (*keep)(void *ctx, const double x0[3]);
  void *ctx;
} mpm_par_pick;
/* mpm_par_create_seeded keeping pick's particles (pick NULL: the
 * rank's cells'). */
pm_err mpm_par_create_picked(const pm_scene *s, bool gather,
                             const mpm_par_pick *pick, mpm_model **local,
                             mpm_state **local_state);
/* mpm_par_create_picked on a cut (NULL: the particles per cell at the
 * start's): mpm_decomp_pack's integers, as a checkpoint keeps them and
 * mpm_par_create takes them. */
pm_err mpm_par_create_cut(const pm_scene *s, bool gather, const long *cut,
                          const mpm_par_pick *pick, mpm_model **local,
                          mpm_state **local_state);

/* A set of particles known by their reference positions, which a share's
 * seeding asks (mpm_par_pick.keep): n positions of 3 doubles, `stride`
 * doubles apart from x0 (borrowed); mpm_x0_set_index makes its table
 * (PM_ERR_MEMORY), mpm_x0_set_free lets the table go. */
typedef struct {
  const double *x0;
  long stride, n;
  long *slot; /* [mask + 1]: a position's index, or -1 */
  uint64_t mask;
} mpm_x0_set;
pm_err mpm_x0_set_index(mpm_x0_set *set);
bool mpm_x0_set_has(const mpm_x0_set *set, const double x[3]);
void mpm_x0_set_free(mpm_x0_set *set);

/* After a step's migration: every 20 steps, whether the busiest rank holds
 * more than mpm.rebalance times the mean of the particles, and if so the
 * boxes cut anew from the particles where they are, each particle sent to
 * its new rank with every array it carries, and this rank's share made
 * anew in place (m, s and w keep their addresses; collective).  Explicit
 * steps without dynamic relaxation only; a membrane's points are linked
 * anew where they are. */
pm_err mpm_par_balance(mpm_model *m, mpm_state *s, mpm_work *w);
/* The imbalance past which a run of scene s cuts its boxes anew, or 0:
 * mpm.rebalance for explicit steps without dynamic relaxation (its nodal
 * arrays span the steps). */
double mpm_par_balance_of(const pm_scene *s);

/* The values of full state st (of full model m) of local model lm's
 * particles and nodes into local state ls, whose arrays have room for
 * them: particles, their groups' arrays, the scalars (but the energy
 * accounts) and dynamic relaxation's nodal arrays. */
void mpm_par_take_state(const mpm_model *m, const mpm_state *st,
                        const mpm_model *lm, mpm_state *ls);

/* A rank's energy accounts: each stage's (work, dissipated), the external
 * work and the energy dissipated. */
#define MPM_PAR_ACCOUNTS                                                       \
  ((int)(sizeof(((mpm_state *)0)->energy) / (sizeof(double))) + 2)
/* Every rank's accounts as the last gather found them, on rank 0 (NULL on
 * the others). */
const double *mpm_par_accounts(const mpm_model *m);
/* Gather the state of every rank into the whole model's state full_state
 * on rank 0 (NULL on the others), in the order of one process: particles,
 * the energy accounts, and with dynamic relaxation the nodal arrays it
 * keeps (collective). */
pm_err mpm_par_gather(const mpm_model *m, const mpm_state *s,
                      const mpm_model *full, mpm_state *full_state);

/* The whole run as one process numbers it, from local model m: its
 * particles, and each group's and each scene body's range of indices. */
typedef struct {
  long n;
  const long *gbegin, *gend; /* per group */
  const long *bbegin, *bend; /* per body */
} mpm_par_ranges;
void mpm_par_whole_ranges(const mpm_model *m, mpm_par_ranges *out);
/* The reference positions of every rank's particles in one process's order
 * into *x0 on rank 0 (3 doubles a particle, allocated; NULL on the
 * others), a rank's at a time so that rank 0 holds one share besides
 * (collective; every rank returns the same error). */
pm_err mpm_par_gather_x0(const mpm_model *m, double **x0);
/* The extreme over the ranks of a value each rank found among its
 * particles (*v: the largest where max, else the smallest), with the
 * particle's one-process index gid (LONG_MAX: none) and its 3 doubles at:
 * the first in one process's order among equal values, as one process
 * finds it; into *v and at on every rank (collective), in the share m's
 * buffer: no allocation at a history row. */
void mpm_par_extreme(const mpm_model *m, double *v, long gid, double at[3],
                     bool max);

/* Print the decomposition and every rank's share (particles, nodes, ghost
 * nodes, memory of the model and of the workspace w, which may be NULL) to
 * out on rank 0 (collective; out may be NULL on other ranks). */
void mpm_par_plan(const mpm_model *m, const mpm_work *w, FILE *out);

/* Print decomposition d of model m: its boxes, cuts and balance. */
void mpm_decomp_print(const mpm_decomp *d, const pm_scene *s, FILE *out);
/* Print what each rank of decomposition d would hold and send, from the
 * decomposition alone (pointmech plan --ranks N on one process): its
 * particles, owned and ghost nodes, and the bytes of node sums it sends
 * per step (each ghost node's values go to its owner and come back, for
 * every transfer of the step). */
void mpm_decomp_predict(const mpm_decomp *d, const mpm_model *m, FILE *out);

/* Bytes a rank sent per step by exchanges of nodes and particles, and the
 * seconds they took, over the run so far (summary.json). */
typedef struct {
  double halo_bytes, halo_seconds;       /* node sums */
  double migrate_bytes, migrate_seconds; /* particles (and ghosts' seconds) */
  double ghost_bytes;                    /* linked points' ghosts */
  long migrated;                         /* particles sent */
  long grown;                            /* times the arrays grew */
  long most;                             /* particles held, the most */
  /* the busiest rank's particles and the mean, summed over the looks
   * at the balance (every 20 steps): their ratio is what the load costs
   * a step's pace over the run */
  double look_most, look_mean;
  double recut_seconds; /* cutting the boxes anew */
} mpm_par_counts;
void mpm_par_get_counts(const mpm_model *m, mpm_par_counts *c);
/* The decomposition of local model m. */
const mpm_decomp *mpm_par_decomp(const mpm_model *m);

#endif
