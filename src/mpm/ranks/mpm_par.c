/* mpm_par: the decomposition, each rank's share of the model, the node sums
 * on a PETSc star forest, particle migration (and the ghosts of linked
 * points after it) and the gather to rank 0. */
#include "mpm_par.h"

#include <math.h>
#include <mpi.h>
#include <petscsf.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_par_ghosts.h"
#include "mpm_transfer.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_petsc.h"
#include "pm_progress.h"

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
  PetscSF ghosts;
  MPI_Datatype two, three; /* a node's impedances, a node's vector */
  /* dynamic relaxation's nodal arrays to rank 0: a rank's owned nodes'
   * values, and on rank 0 every rank's */
  double *nodal, *whole;
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
};

static void fill_exchange(struct mpm_par *P);
static void par_free(struct mpm_par *P);

/* The share of local model m. */
static inline struct mpm_par *par_of(const mpm_model *m) { return m->xc->ctx; }

/* ---- decomposition --------------------------------------------------------
 */

/* A prescribed value that is 0 wherever and whenever: the wall stays. */
static bool zero_value(const pm_expr *e) {
  if (!e) return true;
  if (pm_expr_uses(e, 'x') || pm_expr_uses(e, 'y') || pm_expr_uses(e, 'z') ||
      pm_expr_uses(e, 't'))
    return false;
  return pm_expr_eval(e, 0, 0, 0, 0) == 0;
}

/* The condition on axis a whose wall moves (its normal component
 * prescribed and not 0), or -1. */
static int moving_wall(const mpm_model *m, int a) {
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (bc->axis != a) continue;
    if ((bc->disp_mask >> a & 1u) && !zero_value(bc->disp[a])) return b;
    if ((bc->vel_mask >> a & 1u) && !zero_value(bc->velocity[a])) return b;
  }
  return -1;
}

/* The particle's cell along each axis (clamped to the grid). */
static void cell_of(const mpm_grid *g, const long cells[3], const double x[3],
                    long c[3]) {
  for (int a = 0; a < 3; a++) {
    if (a >= g->dim) {
      c[a] = 0;
      continue;
    }
    long k = (long)floor((x[a] - g->origin[a]) * g->inv_h);
    c[a] = k < 0 ? 0 : k >= cells[a] ? cells[a] - 1 : k;
  }
}

/* The rank whose box holds cell (or node) q: down the bisections, the side
 * of each cut (a node on a cut belongs to the upper box, like its cell). */
static int rank_of(const mpm_decomp *d, const long q[3]) {
  if (d->size == 1) return 0;
  int k = 0;
  for (;;) {
    const mpm_decomp_cut *t = &d->tree[k];
    const int next = t->child[q[t->axis] >= t->at];
    if (next < 0) return -next - 1;
    k = next;
  }
}

int mpm_decomp_rank_at(const mpm_decomp *d, const mpm_grid *g,
                       const double x[3]) {
  long c[3];
  cell_of(g, d->cells, x, c);
  return rank_of(d, c);
}

void mpm_decomp_nodes(const mpm_decomp *d, int r, long lo[3], long hi[3]) {
  for (int a = 0; a < 3; a++) {
    lo[a] = d->box[6 * r + a];
    hi[a] = d->box[6 * r + 3 + a] + (d->box[6 * r + 3 + a] == d->cells[a]);
  }
}

void mpm_decomp_held(const mpm_decomp *d, int r, const mpm_grid *g, long lo[3],
                     long hi[3]) {
  mpm_decomp_nodes(d, r, lo, hi);
  for (int a = 0; a < 3; a++) {
    if (a >= g->dim) continue;
    lo[a] = lo[a] - d->ghost > 0 ? lo[a] - d->ghost : 0;
    hi[a] = hi[a] + d->ghost < g->nn[a] ? hi[a] + d->ghost : g->nn[a];
  }
}

void mpm_decomp_destroy(mpm_decomp *d) {
  free(d->box);
  free(d->tree);
  free(d->count);
  memset(d, 0, sizeof *d);
}

/* Cells a box keeps at least along an axis it is cut along, and how far a
 * cut stays from a condition's face plane (its columns' anchors and the
 * ghost layers then lie in the face's box). */
static int min_cells(const mpm_grid *g) { return g->width; }
static int face_clearance(const mpm_grid *g) { return g->width + 2; }

static bool cut_allowed(const mpm_model *m, int a, long c) {
  const mpm_grid *g = &m->grid;
  for (int b = 0; b < m->n_bcs; b++) {
    if (m->bcs[b].axis != a) continue;
    long ia = llround((m->bcs[b].plane - g->origin[a]) * g->inv_h);
    if (labs(c - ia) < face_clearance(g)) return false;
  }
  return true;
}

/* What the bisection works on: the model, the axes it may cut, the
 * particles' cells, a histogram, and the tree it grows. */
typedef struct {
  const pm_scene *s;
  const mpm_model *m;
  mpm_decomp *d;
  bool splits[3];
  long *cell; /* 3 per particle */
  long *hist;
  int n_nodes;
} bisection;

/* Cells of box [lo, hi). */
static double box_cells(const long lo[3], const long hi[3]) {
  return (double)(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

/* Share n ranks from r0 among the particles idx[0..count) of box [lo, hi):
 * cut the box's longest axis that may be cut where the particles divide
 * in the ranks' proportion, and each side likewise.  Returns the tree
 * node it made, or -(r0 + 1) for a box of one rank. */
static pm_err bisect(bisection *B, int r0, int n, const long lo[3],
                     const long hi[3], long *idx, long count, int *node) {
  mpm_decomp *d = B->d;
  const long w = min_cells(&B->m->grid);
  if (n == 1) {
    for (int a = 0; a < 3; a++) {
      d->box[6 * r0 + a] = lo[a];
      d->box[6 * r0 + 3 + a] = hi[a];
    }
    d->count[r0] = count;
    *node = -(r0 + 1);
    return PM_SUCCESS;
  }
  const int nl = n / 2, nr = n - nl;
  /* The longest axis the box may be cut along, with room for both sides. */
  int axis = -1;
  for (int a = 0; a < B->m->dim; a++)
    if (B->splits[a] && hi[a] - lo[a] >= 2 * w &&
        (axis < 0 || hi[a] - lo[a] > hi[axis] - lo[axis]))
      axis = a;
  PM_CHECK(axis >= 0, PM_ERR_SCENE,
           "%s: %d ranks cannot share the grid (%ld x %ld x %ld cells): a box "
           "of %ld x %ld x %ld cells for %d ranks cannot be cut along an axis "
           "that may be cut, keeping %ld cells on each side%s%s; run on fewer "
           "ranks or refine discretization.mesh_size",
           B->s->path, d->size, d->cells[0], d->cells[1], d->cells[2],
           hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], n, w,
           d->held[0] ? " (not cut: " : "", d->held[0] ? d->held : "");
  const long len = hi[axis] - lo[axis];
  memset(B->hist, 0, sizeof(long) * (size_t)len);
  for (long k = 0; k < count; k++)
    B->hist[B->cell[3 * idx[k] + axis] - lo[axis]]++;
  /* The cut nearest to the particles' share, in a whole cell; of the cuts
   * that share them alike (empty slabs), the middle one. */
  const double target = (double)count * nl / n;
  long best = -1, last = -1, below = 0;
  double best_miss = INFINITY;
  for (long c = 1; c < len; c++) {
    below += B->hist[c - 1];
    const long at = lo[axis] + c;
    long left[3], right[3];
    memcpy(left, hi, sizeof left);
    memcpy(right, lo, sizeof right);
    left[axis] = right[axis] = at;
    if (c < w || len - c < w || !cut_allowed(B->m, axis, at) ||
        box_cells(lo, left) < (double)nl * w ||
        box_cells(right, hi) < (double)nr * w)
      continue;
    const double miss = fabs(below - target);
    if (miss < best_miss) {
      best_miss = miss;
      best = last = c;
    } else if (miss == best_miss && last == c - 1) {
      last = c; /* the same empty stretch */
    }
  }
  if (best >= 0) {
    const long mid = best + (last - best) / 2;
    if (cut_allowed(B->m, axis, lo[axis] + mid)) best = mid;
  }
  PM_CHECK(best >= 0, PM_ERR_SCENE,
           "%s: %d ranks cannot share the grid: a box of %ld cells along %c "
           "for %d ranks has no cut %ld cells from its ends and %d cells "
           "from a boundary face; run on fewer ranks or refine "
           "discretization.mesh_size",
           B->s->path, d->size, len, "xyz"[axis], n, w,
           face_clearance(&B->m->grid));
  const long at = lo[axis] + best;
  /* The particles below the cut first. */
  long split = 0;
  for (long k = 0; k < count; k++)
    if (B->cell[3 * idx[k] + axis] < at) {
      long t = idx[k];
      idx[k] = idx[split];
      idx[split++] = t;
    }
  const int me = B->n_nodes++;
  d->tree[me].axis = axis;
  d->tree[me].at = at;
  d->cuts[axis]++;
  long mid_hi[3], mid_lo[3];
  memcpy(mid_hi, hi, sizeof mid_hi);
  memcpy(mid_lo, lo, sizeof mid_lo);
  mid_hi[axis] = mid_lo[axis] = at;
  int child;
  PM_CALL(bisect(B, r0, nl, lo, mid_hi, idx, split, &child));
  d->tree[me].child[0] = child;
  PM_CALL(
      bisect(B, r0 + nl, nr, mid_lo, hi, idx + split, count - split, &child));
  d->tree[me].child[1] = child;
  *node = me;
  return PM_SUCCESS;
}

pm_err mpm_decomp_create(const pm_scene *s, const mpm_model *m, int size,
                         mpm_decomp *d) {
  pm_err ret = PM_SUCCESS;
  const mpm_grid *g = &m->grid;
  bisection B = {.s = s, .m = m, .d = d};
  const bool implicit = strcmp(s->method, "mpm-implicit") == 0;
  long *idx = NULL;
  memset(d, 0, sizeof *d);
  d->size = size;
  d->ghost = g->width - 1;
  size_t used = 0;
  long most = 1;
  for (int a = 0; a < 3; a++) {
    d->cells[a] = a < g->dim ? g->nn[a] - 1 : 1;
    most = d->cells[a] > most ? d->cells[a] : most;
    B.splits[a] = a < g->dim;
    /* (The implicit solver prescribes the nodes at and beyond a face by
     * their place alone: no column to walk.) */
    int b = a < g->dim && !implicit ? moving_wall(m, a) : -1;
    if (b >= 0) {
      B.splits[a] = false;
      used += (size_t)snprintf(d->held + used, sizeof d->held - used,
                               "%s%c: the wall of boundary.%d (%s) moves",
                               used ? "; " : "", "xyz"[a], b,
                               pm_face_name(m->bcs[b].face));
      if (used >= sizeof d->held) used = sizeof d->held - 1;
    }
  }
  PM_TRY(PM_ALLOC(d->box, 6 * size, "decomposition boxes"));
  PM_TRY(PM_ALLOC(d->tree, size, "decomposition cuts"));
  PM_TRY(PM_ALLOC(d->count, size, "particles per rank"));
  PM_TRY(PM_ALLOC(B.cell, 3 * m->n + 1, "particles' cells"));
  PM_TRY(PM_ALLOC(B.hist, most, "decomposition histogram"));
  PM_TRY(PM_ALLOC(idx, m->n + 1, "particles' order"));
  for (long p = 0; p < m->n; p++) {
    cell_of(g, d->cells, m->x0 + 3 * p, B.cell + 3 * p);
    idx[p] = p;
  }
  const long lo[3] = {0, 0, 0};
  int root;
  PM_TRY(bisect(&B, 0, size, lo, d->cells, idx, m->n, &root));
done:
  free(idx);
  free(B.cell);
  free(B.hist);
  if (ret) mpm_decomp_destroy(d);
  return ret;
}

/* ---- what a run across ranks cannot do yet ---------------------------------
 */

pm_err mpm_par_check(const pm_scene *s) {
  if (mpm_scene_settings(s)->fbar == MPM_FBAR_PATCH)
    return pm_scene_fail(s, "mpm.fbar", false,
                         "F-bar over node patches runs on one process (this "
                         "run has %d ranks): take mpm.fbar: cell, or run with "
                         "-np 1",
                         pm_par_size());
  return PM_SUCCESS;
}

pm_err mpm_par_check_implicit(const pm_scene *s) {
  const mpm_settings *ms = mpm_scene_settings(s);
  if (ms->implicit.grid == MPM_GRID_RESET)
    return pm_scene_fail(s, "mpm.implicit.grid", false,
                         "the grid reset after each load step runs on one "
                         "process (this run has %d ranks): take kept, or run "
                         "with -np 1",
                         pm_par_size());
  if (ms->implicit.op == MPM_OP_MATRIX_FREE)
    return pm_scene_fail(s, "mpm.implicit.operator", false,
                         "the matrix-free operator runs on one process (this "
                         "run has %d ranks): take assembled, or run with -np "
                         "1",
                         pm_par_size());
  if (ms->fbar == MPM_FBAR_CELL)
    return pm_scene_fail(s, "mpm.fbar", false,
                         "the implicit F-bar runs on one process (this run "
                         "has %d ranks): run with -np 1",
                         pm_par_size());
  return PM_SUCCESS;
}

/* ---- each rank's share -----------------------------------------------------
 */

/* Values a transfer of `mode` moves per node. */
static int dof_of(int mode, bool imp) {
  return (mode & MPM_P2G_MASS ? 1 : 0) + (mode & MPM_P2G_MOM ? 3 : 0) +
         (mode & MPM_P2G_FORCE ? 3 + (imp ? 2 : 0) : 0);
}

/* This rank's block of the grid: its box's nodes and the ghost layers. */
static pm_err local_grid(struct mpm_par *P, const mpm_grid *full, mpm_grid *g) {
  long lo[3], hi[3];
  mpm_decomp_held(&P->d, P->rank, full, lo, hi);
  mpm_decomp_nodes(&P->d, P->rank, P->own_lo, P->own_hi);
  *g = *full;
  g->n_nodes = 1;
  for (int a = 0; a < 3; a++) {
    g->offset[a] = a < full->dim ? lo[a] : 0;
    g->nn[a] = a < full->dim ? hi[a] - lo[a] : 1;
    g->n_nodes *= g->nn[a];
  }
  g->stride[0] = 1;
  g->stride[1] = g->nn[0];
  g->stride[2] = g->nn[0] * g->nn[1];
  PM_CALL(PM_ALLOC(P->owned, g->n_nodes, "owned nodes"));
  P->n_owned = 0;
  for (long k = 0; k < g->nn[2]; k++)
    for (long j = 0; j < g->nn[1]; j++)
      for (long i = 0; i < g->nn[0]; i++) {
        const long q[3] = {i + g->offset[0], j + g->offset[1],
                           k + g->offset[2]};
        bool own = true;
        for (int a = 0; a < full->dim; a++)
          own = own && q[a] >= P->own_lo[a] && q[a] < P->own_hi[a];
        P->owned[i + j * g->stride[1] + k * g->stride[2]] = own;
        P->n_owned += own;
      }
  return PM_SUCCESS;
}

/* The first local particle whose one-process index is at least q. */
static long first_at_least(const long *gid, long n, long q) {
  long lo = 0, hi = n;
  while (lo < hi) {
    long mid = lo + (hi - lo) / 2;
    if (gid[mid] < q)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* Body and group ranges from the particles' indices (after a change). */
static void set_ranges(mpm_model *m, mpm_state *s) {
  const struct mpm_par *P = par_of(m);
  for (int b = 0; b < m->n_bodies; b++) {
    m->body_begin[b] = first_at_least(m->gid, m->n, P->bbegin[b]);
    m->body_end[b] = first_at_least(m->gid, m->n, P->bend[b]);
  }
  for (int k = 0; k < m->n_moving; k++) {
    m->moving[k].begin = m->body_begin[m->moving[k].body];
    m->moving[k].end = m->body_end[m->moving[k].body];
  }
  for (int gi = 0; gi < m->n_groups; gi++) {
    mpm_group *g = &m->group[gi];
    g->begin = first_at_least(m->gid, m->n, P->gbegin[gi]);
    g->end = first_at_least(m->gid, m->n, P->gend[gi]);
    for (int k = 0; k < g->n_arrays; k++) {
      g->layout[k].count = g->end - g->begin;
      if (s) s->group[gi].array[k].count = g->end - g->begin;
    }
  }
}

/* The node sums' graph: every node this rank holds but does not own, and
 * where its owner holds it (the owner's block is computed as this rank's
 * is: its nodes and the ghost layers, clipped to the grid). */
static pm_err make_ghosts(struct mpm_par *P, const mpm_grid *full,
                          const mpm_grid *g) {
  pm_err ret = PM_SUCCESS;
  const mpm_decomp *d = &P->d;
  const long n_ghost = g->n_nodes - P->n_owned;
  PetscInt *leaf = NULL;
  PetscSFNode *root = NULL;
  PM_TRY(PM_ALLOC(leaf, n_ghost + 1, "ghost nodes"));
  PM_TRY(PM_ALLOC(root, n_ghost + 1, "ghost nodes' owners"));
  long k = 0;
  for (long i = 0; i < g->n_nodes; i++) {
    if (P->owned[i]) continue;
    const long q[3] = {i % g->nn[0] + g->offset[0],
                       (i / g->nn[0]) % g->nn[1] + g->offset[1],
                       i / (g->nn[0] * g->nn[1]) + g->offset[2]};
    const int r = rank_of(d, q);
    long lo[3], hi[3], at = 0, step = 1;
    mpm_decomp_held(d, r, full, lo, hi);
    for (int a = 0; a < 3; a++) {
      at += (q[a] - lo[a]) * step;
      step *= hi[a] - lo[a];
    }
    leaf[k] = (PetscInt)i;
    root[k].rank = r;
    root[k].index = (PetscInt)at;
    k++;
  }
  PM_PETSC(PetscSFCreate(PETSC_COMM_WORLD, &P->ghosts));
  PM_PETSC(PetscSFSetGraph(P->ghosts, (PetscInt)g->n_nodes, (PetscInt)k, leaf,
                           PETSC_OWN_POINTER, root, PETSC_OWN_POINTER));
  leaf = NULL;
  root = NULL;
  PM_PETSC(PetscSFSetUp(P->ghosts));
  MPI_Type_contiguous(2, MPI_DOUBLE, &P->two);
  MPI_Type_commit(&P->two);
  MPI_Type_contiguous(3, MPI_DOUBLE, &P->three);
  MPI_Type_commit(&P->three);
done:
  free(leaf);
  free(root);
  return ret;
}

/* The ranks whose boxes touch this rank's, within a cell (those a
 * particle can move to in a step), and their graph communicator. */
static pm_err make_near(struct mpm_par *P, const mpm_model *m) {
  const mpm_decomp *d = &P->d;
  const long *me = d->box + 6 * P->rank;
  PM_CALL(PM_ALLOC(P->near_of, d->size, "near ranks"));
  int *list = NULL, *weight = NULL; /* (all 1: one step's particles) */
  PM_CALL(PM_ALLOC(list, d->size + 1, "near ranks"));
  if (PM_ALLOC(weight, d->size + 1, "near ranks")) {
    free(list);
    return PM_ERR_MEMORY;
  }
  P->n_near = 0;
  for (int q = 0; q < d->size; q++) {
    P->near_of[q] = -1;
    if (q == P->rank) continue;
    const long *b = d->box + 6 * q;
    bool touch = true;
    for (int a = 0; a < m->dim; a++)
      touch = touch && b[a] <= me[3 + a] && me[a] <= b[3 + a];
    if (!touch) continue;
    P->near_of[q] = P->n_near;
    weight[P->n_near] = 1;
    list[P->n_near++] = q;
  }
  int e = MPI_Dist_graph_create_adjacent(pm_par_comm(), P->n_near, list, weight,
                                         P->n_near, list, weight, MPI_INFO_NULL,
                                         0, &P->near);
  free(list);
  free(weight);
  PM_CHECK(e == MPI_SUCCESS, PM_ERR_INTERNAL,
           "MPI_Dist_graph_create_adjacent failed (%d)", e);
  return PM_SUCCESS;
}

/* Room for n particles and some to arrive. */
static long room_for(long n) { return n + n / 4 + 64; }

/* The local model's particles: those of full model m in this rank's cells,
 * their constants and groups (set up anew from the scene), bodies,
 * conditions and pipeline. */
static pm_err local_model(const pm_scene *s, const mpm_model *m,
                          const mpm_state *st, struct mpm_par *P,
                          mpm_model **out) {
  pm_err ret = PM_SUCCESS;
  mpm_model *lm = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(lm, 1, "MPM model (this rank's)"));
  lm->opt = m->opt;
  lm->dim = m->dim;
  memcpy(lm->box_min, m->box_min, sizeof lm->box_min);
  memcpy(lm->box_max, m->box_max, sizeof lm->box_max);
  lm->layout = m->layout;
  PM_TRY(local_grid(P, &m->grid, &lm->grid));
  PM_TRY(make_ghosts(P, &m->grid, &lm->grid));
  /* The particles in this rank's cells now (at the start, or where a
   * resumed run's checkpoint has them). */
  long n = 0;
  for (long p = 0; p < m->n; p++)
    n += mpm_decomp_rank_at(&P->d, &m->grid, st->x + 3 * p) == P->rank;
  lm->n = n;
  lm->cap = room_for(n);
  PM_TRY(PM_ALLOC(lm->x0, 3 * lm->cap, "particle positions"));
  PM_TRY(PM_ALLOC(lm->mass, lm->cap, "particle masses"));
  PM_TRY(PM_ALLOC(lm->vol0, lm->cap, "particle volumes"));
  PM_TRY(PM_ALLOC(lm->gid, lm->cap, "particle indices"));
  long k = 0;
  for (long p = 0; p < m->n; p++) {
    if (mpm_decomp_rank_at(&P->d, &m->grid, st->x + 3 * p) != P->rank) continue;
    lm->gid[k] = p;
    for (int c = 0; c < 3; c++) lm->x0[3 * k + c] = m->x0[3 * p + c];
    lm->mass[k] = m->mass[p];
    lm->vol0[k] = m->vol0[p];
    k++;
  }
  /* Groups and bodies: ranges of the one-process indices. */
  lm->n_groups = m->n_groups;
  lm->kinds = m->kinds;
  long at = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *fg = &m->group[gi];
    mpm_group *g = &lm->group[gi];
    P->gbegin[gi] = fg->begin;
    P->gend[gi] = fg->end;
    *g = (mpm_group){.index = fg->index,
                     .material = fg->material,
                     .name = fg->name,
                     .kind = fg->kind,
                     .c0 = fg->c0,
                     .c1 = fg->c1};
    g->begin = at;
    while (at < n && lm->gid[at] < fg->end) at++;
    g->end = at;
    g->cap = room_for(g->end - g->begin);
    PM_TRY(g->kind->setup(g, &s->materials[g->material], &lm->opt));
    if (g->kind->ranks_share) PM_TRY(g->kind->ranks_share(fg, g));
  }
  lm->n_bodies = m->n_bodies;
  P->n_full = m->n;
  PM_TRY(PM_ALLOC(P->bbegin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(P->bend, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_begin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_end, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_tri_begin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_tri_end, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_links, m->n_bodies + 1, "body links"));
  PM_TRY(PM_ALLOC(lm->body_normals, m->n_bodies + 1, "body normals"));
  for (int b = 0; b < m->n_bodies; b++) {
    P->bbegin[b] = m->body_begin[b];
    P->bend[b] = m->body_end[b];
    lm->body_links[b] = m->body_links[b];
    lm->body_normals[b] = m->body_normals[b];
  }
  PM_TRY(mpm_conditions_create(s, &lm->grid, &lm->bcs, &lm->n_bcs));
  lm->has_absorbing = m->has_absorbing;
  /* Bodies moving as prescribed: their ranges are set with the bodies'. */
  if (m->n_moving > 0) {
    PM_TRY(PM_ALLOC(lm->moving, m->n_moving, "moving bodies"));
    memcpy(lm->moving, m->moving, sizeof *m->moving * (size_t)m->n_moving);
    lm->n_moving = m->n_moving;
  }
  mpm_pipeline_build(lm);
  lm->xc = &P->xc;
  set_ranges(lm, NULL);
  *out = lm;
  lm = NULL;
done:
  if (lm) lm->xc = NULL; /* P is the caller's until it is attached */
  mpm_model_destroy(lm);
  return ret;
}

/* The local state: the full state's values of this rank's particles and
 * nodes; the energy accounts this rank's row of `accounts` (each rank sums
 * its own from there), or without them all on rank 0. */
static pm_err local_state(const mpm_model *m, const mpm_state *st,
                          const mpm_model *lm, const double *accounts,
                          mpm_state **out) {
  mpm_state *ls = NULL;
  PM_CALL(mpm_state_create(lm, &ls));
  const struct mpm_par *P = par_of(lm);
  mpm_par_take_state(m, st, lm, ls);
  if (accounts) {
    const double *row = accounts + MPM_PAR_ACCOUNTS * P->rank;
    memcpy(ls->energy, row, sizeof ls->energy);
    ls->external_work = row[MPM_PAR_ACCOUNTS - 2];
    ls->dissipated = row[MPM_PAR_ACCOUNTS - 1];
  } else if (P->rank != 0) {
    memset(ls->energy, 0, sizeof ls->energy);
    ls->external_work = ls->dissipated = 0;
  }
  *out = ls;
  return PM_SUCCESS;
}

void mpm_par_take_state(const mpm_model *m, const mpm_state *st,
                        const mpm_model *lm, mpm_state *ls) {
  for (long k = 0; k < lm->n; k++) {
    const long p = lm->gid[k];
    memcpy(ls->x + 3 * k, st->x + 3 * p, 3 * sizeof(double));
    memcpy(ls->v + 3 * k, st->v + 3 * p, 3 * sizeof(double));
    ls->vol[k] = st->vol[p];
    memcpy(ls->sigma + 9 * k, st->sigma + 9 * p, 9 * sizeof(double));
  }
  for (int gi = 0; gi < lm->n_groups; gi++) {
    const mpm_group *g = &lm->group[gi];
    for (int a = 0; a < ls->group[gi].n; a++) {
      const mpm_array *src = &st->group[gi].array[a];
      mpm_array *dst = &ls->group[gi].array[a];
      const int nc = dst->ncomp;
      for (long k = g->begin; k < g->end; k++)
        memcpy(dst->data + (k - g->begin) * nc,
               src->data + (lm->gid[k] - m->group[gi].begin) * nc,
               nc * sizeof(double));
    }
  }
  /* Scalars: every rank's the same (the energy accounts are set by the
   * caller). */
  mpm_state_copy_values(ls, st);
  /* Nodal arrays of dynamic relaxation, from the whole grid's. */
  const mpm_grid *g = &lm->grid, *fg = &m->grid;
  for (long i = 0; i < g->n_nodes && ls->force_prev; i++) {
    long q = 0, r = i;
    for (int a = 2; a >= 0; a--) {
      long ia = r / g->stride[a];
      r -= ia * g->stride[a];
      q += (ia + g->offset[a]) * fg->stride[a];
    }
    memcpy(ls->force_prev + 3 * i, st->force_prev + 3 * q, 3 * sizeof(double));
    if (ls->fixed) memcpy(ls->fixed + 3 * i, st->fixed + 3 * q, 3);
  }
}

/* Doubles of a migration record for model m's groups, and of its widest
 * per-particle array (the stress's 9 at least). */
static int record_doubles(const mpm_model *m, int *width) {
  int most = 0;
  *width = 9;
  for (int gi = 0; gi < m->n_groups; gi++) {
    int sum = 0;
    for (int k = 0; k < m->group[gi].n_arrays; k++) {
      const int nc = m->group[gi].layout[k].ncomp;
      sum += nc;
      *width = nc > *width ? nc : *width;
    }
    most = sum > most ? sum : most;
  }
  return REC_BASE + most;
}

pm_err mpm_par_create(const pm_scene *s, const mpm_model *m,
                      const mpm_state *st, const double *accounts,
                      mpm_model **local, mpm_state **local_state_out) {
  pm_err ret = PM_SUCCESS;
  struct mpm_par *P = NULL;
  mpm_model *lm = NULL;
  mpm_state *ls = NULL;
  const int size = pm_par_size();
  *local = NULL;
  *local_state_out = NULL;
  /* Every rank decomposes alike; a failure of one (memory) stops all
   * before the collectives that follow. */
  ret = pm_petsc_init();
  if (!ret) ret = PM_ALLOC(P, 1, "run across ranks");
  if (!ret) ret = mpm_decomp_create(s, m, size, &P->d);
  PM_TRY(pm_par_agree(ret));
  P->rank = pm_par_rank();
  fill_exchange(P);
  ret = local_model(s, m, st, P, &lm);
  if (!ret) P = NULL; /* lm holds it */
  if (!ret) ret = local_state(m, st, lm, accounts, &ls);
  PM_TRY(pm_par_agree(ret));
  struct mpm_par *Q = par_of(lm);
  PM_TRY(make_near(Q, m));
  PM_TRY(mpm_ghosts_create(lm, ls, &Q->d, Q->gbegin, Q->gend, Q->near,
                           Q->n_near, &Q->gh));
  Q->rec = record_doubles(lm, &Q->width);
  const long room = mpm_model_room(lm);
  PM_TRY(PM_ALLOC(Q->dest, room, "migration ranks"));
  PM_TRY(PM_ALLOC(Q->order, room, "migration order"));
  PM_TRY(PM_ALLOC(Q->tmp, Q->width * room, "migration buffer"));
  PM_TRY(PM_ALLOC(Q->scount, size, "migration counts"));
  PM_TRY(PM_ALLOC(Q->rcount, size, "migration counts"));
  PM_TRY(PM_ALLOC(Q->sdisp, size + 1, "migration offsets"));
  PM_TRY(PM_ALLOC(Q->rdisp, size + 1, "migration offsets"));
  PM_TRY(PM_ALLOC(Q->gcount, size, "gather counts"));
  PM_TRY(PM_ALLOC(Q->gdisp, size + 1, "gather offsets"));
  Q->sbuf_room = Q->rbuf_room = 64 + room / 8;
  PM_TRY(PM_ALLOC(Q->sbuf, Q->sbuf_room * Q->rec, "migration buffer"));
  PM_TRY(PM_ALLOC(Q->rbuf, Q->rbuf_room * Q->rec, "migration buffer"));
  if (m->opt.qs == PM_QS_DYNAMIC_RELAXATION) {
    PM_TRY(PM_ALLOC(Q->nodal, 3 * Q->n_owned + 1, "nodal gather"));
    if (Q->rank == 0)
      PM_TRY(PM_ALLOC(Q->whole, 3 * m->grid.n_nodes, "nodal gather"));
  }
  if (Q->rank == 0) {
    PM_TRY(PM_ALLOC(Q->accounts, MPM_PAR_ACCOUNTS * size, "energy accounts"));
    PM_TRY(PM_ALLOC(Q->ggid, m->n, "gather indices"));
    PM_TRY(PM_ALLOC(Q->gbuf, Q->width * m->n, "gather buffer"));
  }
  *local = lm;
  *local_state_out = ls;
  lm = NULL;
  ls = NULL;
done:
  par_free(P);
  mpm_state_destroy(ls);
  mpm_model_destroy(lm);
  return ret;
}

static void par_free(struct mpm_par *P) {
  if (!P) return;
  if (P->ghosts) {
    PetscSFDestroy(&P->ghosts);
    MPI_Type_free(&P->two);
    MPI_Type_free(&P->three);
  }
  free(P->nodal);
  free(P->whole);
  mpm_ghosts_destroy(P->gh);
  if (P->near_of) MPI_Comm_free(&P->near);
  free(P->near_of);
  mpm_decomp_destroy(&P->d);
  free(P->owned);
  free(P->bbegin);
  free(P->bend);
  free(P->dest);
  free(P->scount);
  free(P->rcount);
  free(P->sdisp);
  free(P->rdisp);
  free(P->sbuf);
  free(P->rbuf);
  free(P->order);
  free(P->tmp);
  free(P->accounts);
  free(P->ggid);
  free(P->gbuf);
  free(P->gcount);
  free(P->gdisp);
  free(P);
}

static void par_work_attach(const mpm_model *m, mpm_work *w) {
  w->nodes.owned = par_of(m)->owned;
  w->timer_migrate = pm_timers_add(&w->timers, "migrate");
}

/* ---- node sums -------------------------------------------------------------
 */

static pm_err par_sum_nodes(const mpm_model *m, mpm_nodes *nd, int mode,
                            bool imp) {
  struct mpm_par *P = par_of(m);
  const double t0 = pm_wtime();
  PetscSF sf = P->ghosts;
  /* The arrays a transfer of `mode` filled, and their values per node. */
  double *data[4];
  MPI_Datatype unit[4];
  int n = 0, values = 0;
  if (mode & MPM_P2G_MASS) {
    data[n] = nd->mass;
    unit[n++] = MPI_DOUBLE;
    values += 1;
  }
  if (mode & MPM_P2G_MOM) {
    data[n] = nd->mom;
    unit[n++] = P->three;
    values += 3;
  }
  if (mode & MPM_P2G_FORCE) {
    data[n] = nd->force;
    unit[n++] = P->three;
    values += 3;
    if (imp) {
      data[n] = nd->impedance;
      unit[n++] = P->two;
      values += 2;
    }
  }
  /* Ghosts' contributions added on their owners, then the sums back. */
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFReduceBegin(sf, unit[k], data[k], data[k], MPI_SUM));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFReduceEnd(sf, unit[k], data[k], data[k], MPI_SUM));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(
        PetscSFBcastBegin(sf, unit[k], data[k], data[k], MPI_REPLACE));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFBcastEnd(sf, unit[k], data[k], data[k], MPI_REPLACE));
  /* Each ghost node's values go to its owner and come back. */
  const double bytes =
      2.0 * (double)(m->grid.n_nodes - P->n_owned) * values * sizeof(double);
  P->counts.halo_bytes += bytes;
  pm_par_count_sent(bytes);
  P->counts.halo_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

/* One pass of a nodal array's ghost values (`unit` per node) between the
 * ranks, counted. */
static void count_ghosts(const mpm_model *m, MPI_Datatype unit) {
  int size = 0;
  MPI_Type_size(unit, &size);
  const double bytes = (double)(m->grid.n_nodes - par_of(m)->n_owned) * size;
  par_of(m)->counts.halo_bytes += bytes;
  pm_par_count_sent(bytes);
}

static pm_err bcast_nodes(const mpm_model *m, void *a, MPI_Datatype unit) {
  PetscSF sf = par_of(m)->ghosts;
  count_ghosts(m, unit);
  PM_PETSC_CALL(PetscSFBcastBegin(sf, unit, a, a, MPI_REPLACE));
  PM_PETSC_CALL(PetscSFBcastEnd(sf, unit, a, a, MPI_REPLACE));
  return PM_SUCCESS;
}

static pm_err reduce_nodes(const mpm_model *m, void *a, MPI_Datatype unit,
                           MPI_Op op) {
  PetscSF sf = par_of(m)->ghosts;
  const double t0 = pm_wtime();
  count_ghosts(m, unit);
  PM_PETSC_CALL(PetscSFReduceBegin(sf, unit, a, a, op));
  PM_PETSC_CALL(PetscSFReduceEnd(sf, unit, a, a, op));
  pm_err e = bcast_nodes(m, a, unit);
  par_of(m)->counts.halo_seconds += pm_wtime() - t0;
  return e;
}

/* The MPI type of a node's unit; *made when it was made here (to free). */
static MPI_Datatype unit_type(mpm_xc_unit u, bool *made) {
  *made = false;
  if (u == MPM_XC_DOUBLE) return MPI_DOUBLE;
  if (u == MPM_XC_BYTE) return MPI_UNSIGNED_CHAR;
  MPI_Datatype t;
  MPI_Type_contiguous(3, u == MPM_XC_LONG3 ? MPI_LONG : MPI_DOUBLE, &t);
  MPI_Type_commit(&t);
  *made = true;
  return t;
}

static pm_err par_nodes_reduce(const mpm_model *m, void *a, mpm_xc_unit unit,
                               mpm_xc_op op) {
  bool made;
  MPI_Datatype t = unit_type(unit, &made);
  pm_err e = reduce_nodes(m, a, t, op == MPM_XC_MAX ? MPI_MAX : MPI_SUM);
  if (made) MPI_Type_free(&t);
  return e;
}

static pm_err par_nodes_bcast(const mpm_model *m, void *a, mpm_xc_unit unit) {
  bool made;
  MPI_Datatype t = unit_type(unit, &made);
  pm_err e = bcast_nodes(m, a, t);
  if (made) MPI_Type_free(&t);
  return e;
}

static const unsigned char *par_owned(const mpm_model *m) {
  return par_of(m)->owned;
}

static pm_err par_number_unknowns(const mpm_model *m, long nunk, long *dof,
                                  long *gnum, long **ghost, long *nghost) {
  const long nn = m->grid.n_nodes;
  const unsigned char *own = par_of(m)->owned;
  const long first = pm_par_offset(nunk);
  for (long d = 0; d < 3 * nn; d++) gnum[d] = dof[d] >= 0 ? first + dof[d] : -1;
  PM_CALL(par_nodes_bcast(m, gnum, MPM_XC_LONG3));
  long count = 0;
  for (long k = 0; k < nn; k++)
    for (int c = 0; !own[k] && c < 3; c++) count += gnum[3 * k + c] >= 0;
  PM_CALL(PM_REALLOC(*ghost, count + 1, "ghost unknowns"));
  *nghost = 0;
  for (long k = 0; k < nn; k++)
    for (int c = 0; !own[k] && c < 3; c++) {
      const long d = 3 * k + c;
      if (gnum[d] < 0) continue;
      /* Active nodes and prescribed dofs are the same on every rank that
       * holds the node. */
      PM_CHECK(dof[d] == -1, PM_ERR_INTERNAL,
               "implicit MPM across ranks: dof %ld of a ghost node is %ld "
               "here and an unknown on its owner",
               d, dof[d]);
      (*ghost)[*nghost] = gnum[d];
      dof[d] = nunk + (*nghost)++;
    }
  return PM_SUCCESS;
}

static void par_step_end(const mpm_model *m, mpm_work *w) {
  (void)m;
  double most[3] = {w->max_div, -w->min_jacobian, (double)w->iter_max};
  pm_par_max(most, 3);
  w->max_div = most[0];
  w->min_jacobian = -most[1];
  w->iter_max = (int)most[2];
  pm_par_sum_long(&w->iter_capped, 1);
}

/* ---- migration --------------------------------------------------------------
 */

/* Grow every per-particle array of m, s and w to room for n particles. */
static pm_err grow(mpm_model *m, mpm_state *s, mpm_work *w, long n) {
  struct mpm_par *P = par_of(m);
  if (n <= m->cap) return PM_SUCCESS;
  const long room = room_for(n);
  PM_CALL(PM_REALLOC(m->x0, 3 * room, "particle positions"));
  PM_CALL(PM_REALLOC(m->mass, room, "particle masses"));
  PM_CALL(PM_REALLOC(m->vol0, room, "particle volumes"));
  PM_CALL(PM_REALLOC(m->gid, room, "particle indices"));
  PM_CALL(PM_REALLOC(s->x, 3 * room, "particle positions"));
  PM_CALL(PM_REALLOC(s->v, 3 * room, "particle velocities"));
  PM_CALL(PM_REALLOC(s->vol, room, "particle volumes"));
  PM_CALL(PM_REALLOC(s->sigma, 9 * room, "particle stresses"));
  PM_CALL(PM_REALLOC(w->dx, 3 * room, "particle increments"));
  PM_CALL(PM_REALLOC(w->cp, room, "particle wave speeds"));
  if (w->cs) PM_CALL(PM_REALLOC(w->cs, room, "particle wave speeds"));
  if (w->fbar.jm1) {
    PM_CALL(PM_REALLOC(w->fbar.jm1, room, "F-bar volume ratios"));
    w->fbar.n = room;
  }
  if (w->fbar.cell) PM_CALL(PM_REALLOC(w->fbar.cell, room, "F-bar cells"));
  PM_CALL(PM_REALLOC(P->dest, room, "migration ranks"));
  PM_CALL(PM_REALLOC(P->order, room, "migration order"));
  PM_CALL(PM_REALLOC(P->tmp, P->width * room, "migration buffer"));
  m->cap = room;
  P->counts.grown++;
  return PM_SUCCESS;
}

static pm_err grow_group(mpm_group *g, mpm_group_state *gs, long n) {
  if (n <= g->cap) return PM_SUCCESS;
  const long room = room_for(n);
  for (int k = 0; k < gs->n; k++)
    PM_CALL(PM_REALLOC(gs->array[k].data, gs->array[k].ncomp * room,
                       gs->array[k].name));
  g->cap = room;
  return PM_SUCCESS;
}

static pm_err grow_buffer(double **buf, long *room, long records, int rec) {
  if (records <= *room) return PM_SUCCESS;
  const long r = room_for(records);
  PM_CALL(PM_REALLOC(*buf, r * rec, "migration buffer"));
  *room = r;
  return PM_SUCCESS;
}

static int by_gid(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* One array's values in the new order: n_new of nc doubles, from the old
 * array (index order[j] >= 0) or a record (at offset off). */
static void permute(const struct mpm_par *P, double *data, long n_new, int nc,
                    long old_base, const double *recs, int off) {
  double *tmp = P->tmp;
  const long *order = P->order;
  const int rec = P->rec;
  PM_OMP(parallel for schedule(static) default(none)
         shared(tmp, order, data, n_new, nc, old_base, recs, off, rec))
  for (long j = 0; j < n_new; j++) {
    const long o = order[j];
    const double *src =
        o >= 0 ? data + (o - old_base) * nc : recs + (-o - 1) * rec + off;
    for (int c = 0; c < nc; c++) tmp[j * nc + c] = src[c];
  }
  memcpy(data, tmp, sizeof(double) * (size_t)(n_new * nc));
}

/* The particles' move between ranks (collective; every rank returns the
 * same). */
static pm_err move_particles(mpm_model *m, mpm_state *s, mpm_work *w) {
  struct mpm_par *P = par_of(m);
  const int n_near = P->n_near, rec = P->rec;
  const double t0 = pm_wtime();
  pm_err ret = PM_SUCCESS;
  P->linked_left = 0;
  P->reordered = false;
  pm_timers_start(&w->timers, w->timer_migrate);
  /* Where each particle goes. */
  memset(P->scount, 0, sizeof(int) * (size_t)(n_near + 1));
  long leaving = 0, far = -1;
  for (long p = 0; p < m->n; p++) {
    const int r = mpm_decomp_rank_at(&P->d, &m->grid, s->x + 3 * p);
    const int k = r == P->rank ? -1 : P->near_of[r];
    P->dest[p] = k;
    if (r != P->rank && k < 0 && far < 0) far = p;
    if (k >= 0) {
      P->scount[k]++;
      leaving++;
    }
  }
  if (far >= 0)
    ret = PM_ERROR(PM_ERR_UNSTABLE,
                   "step %ld, t = %.6g s, migration: particle %ld at (%g, %g, "
                   "%g) moved past the boxes next to its rank's in one step "
                   "(more than a cell): the step is too large",
                   s->step, s->t, m->gid[far], s->x[3 * far], s->x[3 * far + 1],
                   s->x[3 * far + 2]);
  MPI_Neighbor_alltoall(P->scount, 1, MPI_INT, P->rcount, 1, MPI_INT, P->near);
  long arriving = 0;
  for (int k = 0; k < n_near; k++) arriving += P->rcount[k];
  if (!ret) ret = grow_buffer(&P->sbuf, &P->sbuf_room, leaving, rec);
  if (!ret) ret = grow_buffer(&P->rbuf, &P->rbuf_room, arriving, rec);
  ret = pm_par_agree(ret);
  if (ret) goto done;
  /* Pack the leaving particles, by rank, in their order. */
  P->sdisp[0] = P->rdisp[0] = 0;
  for (int k = 0; k < n_near; k++) {
    P->sdisp[k + 1] = P->sdisp[k] + P->scount[k];
    P->rdisp[k + 1] = P->rdisp[k] + P->rcount[k];
  }
  for (int k = 0; k < n_near; k++) P->scount[k] = 0;
  for (int gi = 0; leaving > 0 && gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const bool linked = g->kind->ranks_link != NULL;
    for (long p = g->begin; p < g->end; p++) {
      const int r = P->dest[p];
      if (r < 0) continue;
      P->linked_left += linked;
      double *q = P->sbuf + (long)(P->sdisp[r] + P->scount[r]++) * rec;
      q[REC_GID] = (double)m->gid[p];
      q[REC_GROUP] = gi;
      memcpy(q + REC_X0, m->x0 + 3 * p, 3 * sizeof(double));
      q[REC_MASS] = m->mass[p];
      q[REC_VOL0] = m->vol0[p];
      memcpy(q + REC_X, s->x + 3 * p, 3 * sizeof(double));
      memcpy(q + REC_V, s->v + 3 * p, 3 * sizeof(double));
      q[REC_VOL] = s->vol[p];
      memcpy(q + REC_SIGMA, s->sigma + 9 * p, 9 * sizeof(double));
      int off = REC_BASE;
      for (int k = 0; k < s->group[gi].n; k++) {
        const mpm_array *a = &s->group[gi].array[k];
        memcpy(q + off, a->data + (p - g->begin) * a->ncomp,
               a->ncomp * sizeof(double));
        off += a->ncomp;
      }
    }
  }
  for (int k = 0; k <= n_near; k++) {
    P->sdisp[k] *= rec;
    P->rdisp[k] *= rec;
  }
  for (int k = 0; k < n_near; k++) {
    P->scount[k] = P->sdisp[k + 1] - P->sdisp[k];
    P->rcount[k] = P->rdisp[k + 1] - P->rdisp[k];
  }
  MPI_Neighbor_alltoallv(P->sbuf, P->scount, P->sdisp, MPI_DOUBLE, P->rbuf,
                         P->rcount, P->rdisp, MPI_DOUBLE, P->near);
  P->counts.migrated += leaving;
  P->counts.migrate_bytes += (double)leaving * rec * sizeof(double);
  pm_par_count_sent((double)leaving * rec * sizeof(double));
  if (leaving == 0 && arriving == 0) goto done;
  P->reordered = true;
  /* The new order: those that stay and those that came, by index. */
  qsort(P->rbuf, (size_t)arriving, (size_t)rec * sizeof(double), by_gid);
  const long n_new = m->n - leaving + arriving;
  ret = grow(m, s, w, n_new);
  long gcount[MPM_MAX_GROUPS] = {0};
  for (int gi = 0; gi < m->n_groups; gi++)
    gcount[gi] = m->group[gi].end - m->group[gi].begin;
  for (long p = 0; p < m->n; p++)
    if (P->dest[p] >= 0)
      for (int gi = 0; gi < m->n_groups; gi++)
        if (p >= m->group[gi].begin && p < m->group[gi].end) gcount[gi]--;
  for (long k = 0; k < arriving; k++)
    gcount[(int)P->rbuf[k * rec + REC_GROUP]]++;
  for (int gi = 0; !ret && gi < m->n_groups; gi++)
    ret = grow_group(&m->group[gi], &s->group[gi], gcount[gi]);
  if (ret) goto done;
  {
    long j = 0, p = 0, k = 0;
    while (p < m->n || k < arriving) {
      if (p < m->n && P->dest[p] >= 0) {
        p++;
        continue;
      }
      bool take_old =
          k >= arriving ||
          (p < m->n && (double)m->gid[p] < P->rbuf[k * rec + REC_GID]);
      P->order[j++] = take_old ? p++ : -(k++ + 1);
    }
  }
  /* The common arrays (old indices from 0), then each group's (old
   * indices from the group's old start; a particle never changes group). */
  const double *recs = P->rbuf;
  long old_begin[MPM_MAX_GROUPS];
  for (int gi = 0; gi < m->n_groups; gi++) old_begin[gi] = m->group[gi].begin;
  {
    /* gid as doubles through the buffer, then back */
    double *tmp = P->tmp;
    for (long j = 0; j < n_new; j++) {
      const long o = P->order[j];
      tmp[j] = o >= 0 ? (double)m->gid[o] : recs[(-o - 1) * rec + REC_GID];
    }
    for (long j = 0; j < n_new; j++) m->gid[j] = (long)tmp[j];
  }
  permute(P, m->x0, n_new, 3, 0, recs, REC_X0);
  permute(P, m->mass, n_new, 1, 0, recs, REC_MASS);
  permute(P, m->vol0, n_new, 1, 0, recs, REC_VOL0);
  permute(P, s->x, n_new, 3, 0, recs, REC_X);
  permute(P, s->v, n_new, 3, 0, recs, REC_V);
  permute(P, s->vol, n_new, 1, 0, recs, REC_VOL);
  permute(P, s->sigma, n_new, 9, 0, recs, REC_SIGMA);
  /* The groups' new ranges are known from the indices now. */
  const long old_n = m->n;
  m->n = n_new;
  set_ranges(m, s);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    /* This group's slice of the order, with old indices relative to its
     * old start. */
    long *order = P->order + g->begin;
    const long ng = g->end - g->begin;
    int off = REC_BASE;
    for (int k = 0; k < s->group[gi].n; k++) {
      mpm_array *a = &s->group[gi].array[k];
      const int nc = a->ncomp;
      for (long j = 0; j < ng; j++) {
        const long o = order[j];
        const double *src = o >= 0 ? a->data + (o - old_begin[gi]) * nc
                                   : recs + (-o - 1) * rec + off;
        for (int c = 0; c < nc; c++) P->tmp[j * nc + c] = src[c];
      }
      memcpy(a->data, P->tmp, sizeof(double) * (size_t)(ng * nc));
      off += nc;
    }
  }
  (void)old_n;
done:
  pm_timers_stop(&w->timers, w->timer_migrate);
  P->counts.migrate_seconds += pm_wtime() - t0;
  return pm_par_agree(ret);
}

/* Room in each group's step workspace for what its kind needs now (its
 * particles, a membrane's triangles). */
static pm_err grow_scratch(const mpm_model *m, mpm_work *w) {
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const long need = g->kind->scratch ? g->kind->scratch(m, g) : 0;
    if (need <= w->n_scratch[gi]) continue;
    PM_CALL(PM_REALLOC(w->scratch[gi], need, "kind workspace"));
    w->n_scratch[gi] = need;
  }
  return PM_SUCCESS;
}

static pm_err par_migrate(mpm_model *m, mpm_state *s, mpm_work *w) {
  struct mpm_par *P = par_of(m);
  PM_CALL(move_particles(m, s, w));
  if (!P->gh) return PM_SUCCESS;
  /* The ghosts: their links anew when a linked point moved between any
   * two ranks, and their positions after this step's move. */
  const double t0 = pm_wtime();
  pm_timers_start(&w->timers, w->timer_migrate);
  long moved = P->linked_left;
  pm_par_sum_long(&moved, 1);
  const double sent = mpm_ghosts_bytes(P->gh);
  pm_err e = mpm_ghosts_update(P->gh, m, s, moved > 0, P->reordered);
  if (!e) e = pm_par_agree(grow_scratch(m, w));
  P->counts.ghost_bytes += mpm_ghosts_bytes(P->gh) - sent;
  pm_par_count_sent(mpm_ghosts_bytes(P->gh) - sent);
  pm_timers_stop(&w->timers, w->timer_migrate);
  P->counts.migrate_seconds += pm_wtime() - t0;
  return e;
}

static const double *par_ghost_x(const mpm_model *m, int gi) {
  return mpm_ghosts_x(par_of(m)->gh, gi);
}

static const double *par_nearby(const mpm_model *m, int gi, long *n,
                                const long **ids) {
  return mpm_ghosts_nearby(par_of(m)->gh, gi, n, ids);
}

static void par_cells(const mpm_model *m, long nn[3], long lo[3], long hi[3]) {
  const struct mpm_par *P = par_of(m);
  for (int a = 0; a < 3; a++) {
    nn[a] = a < m->dim ? P->d.cells[a] + 1 : 1;
    lo[a] = P->d.box[6 * P->rank + a];
    hi[a] = P->d.box[6 * P->rank + 3 + a];
  }
}

static const long *par_ghost_ids(const mpm_model *m, int gi, long *n) {
  *n = mpm_ghosts_count(par_of(m)->gh, gi);
  return mpm_ghosts_ids(par_of(m)->gh, gi);
}

/* ---- gather to rank 0 -------------------------------------------------------
 */

/* Gather n local values of nc doubles each (data) into the whole run's
 * array on rank 0 (out, indexed by the one-process index less base). */
static void gather_array(struct mpm_par *P, const double *data, long n, int nc,
                         const long *gid, long base, double *out) {
  const int size = P->d.size;
  int cnt = (int)(n * nc);
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(data, cnt, MPI_DOUBLE, P->gbuf, P->gcount, P->gdisp, MPI_DOUBLE,
              0, pm_par_comm());
  if (P->rank != 0) {
    pm_par_count_sent((double)cnt * sizeof(double));
    return;
  }
  const long total = P->gdisp[size] / (nc ? nc : 1);
  for (long j = 0; j < total; j++)
    memcpy(out + (gid[j] - base) * nc, P->gbuf + j * nc, nc * sizeof(double));
}

/* Three values per node of this rank's owned nodes (of src, or the flags
 * srcf) into the whole grid's array on rank 0 (dst, or the flags dstf;
 * fg the whole grid there, NULL on the other ranks): each rank's owned
 * nodes in its box's order, placed by rank 0 (collective). */
static pm_err gather_owned(const mpm_model *m, const mpm_grid *fg,
                           const double *src, const unsigned char *srcf,
                           double *dst, unsigned char *dstf) {
  struct mpm_par *P = par_of(m);
  const mpm_grid *g = &m->grid;
  const int size = P->d.size;
  pm_err e = PM_SUCCESS;
  if (!P->nodal) e = PM_ALLOC(P->nodal, 3 * P->n_owned + 1, "nodal gather");
  if (!e && fg && !P->whole)
    e = PM_ALLOC(P->whole, 3 * fg->n_nodes, "nodal gather");
  PM_CALL(pm_par_agree(e));
  long k = 0;
  for (long i = 0; i < g->n_nodes; i++)
    if (P->owned[i])
      for (int c = 0; c < 3; c++, k++)
        P->nodal[k] = src ? src[3 * i + c] : (double)srcf[3 * i + c];
  int cnt = (int)k;
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(P->nodal, cnt, MPI_DOUBLE, P->whole, P->gcount, P->gdisp,
              MPI_DOUBLE, 0, pm_par_comm());
  if (!fg) return PM_SUCCESS;
  const double *b = P->whole;
  for (int r = 0; r < size; r++) {
    long lo[3], hi[3];
    mpm_decomp_nodes(&P->d, r, lo, hi);
    for (int a = fg->dim; a < 3; a++) lo[a] = 0, hi[a] = 1;
    for (long z = lo[2]; z < hi[2]; z++)
      for (long y = lo[1]; y < hi[1]; y++)
        for (long x = lo[0]; x < hi[0]; x++, b += 3) {
          const long q = x + y * fg->stride[1] + z * fg->stride[2];
          for (int c = 0; c < 3; c++) {
            if (dst)
              dst[3 * q + c] = b[c];
            else
              dstf[3 * q + c] = b[c] != 0;
          }
        }
  }
  return PM_SUCCESS;
}

pm_err mpm_par_gather(const mpm_model *m, const mpm_state *s,
                      const mpm_model *full, mpm_state *fs) {
  struct mpm_par *P = par_of(m);
  const int size = P->d.size;
  /* The one-process indices, all at once, then per group. */
  int cnt = (int)m->n;
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(m->gid, cnt, MPI_LONG, P->ggid, P->gcount, P->gdisp, MPI_LONG, 0,
              pm_par_comm());
  double *fx = fs ? fs->x : NULL, *fv = fs ? fs->v : NULL,
         *fvol = fs ? fs->vol : NULL, *fsig = fs ? fs->sigma : NULL;
  gather_array(P, s->x, m->n, 3, P->ggid, 0, fx);
  gather_array(P, s->v, m->n, 3, P->ggid, 0, fv);
  gather_array(P, s->vol, m->n, 1, P->ggid, 0, fvol);
  gather_array(P, s->sigma, m->n, 9, P->ggid, 0, fsig);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const long ng = g->end - g->begin;
    cnt = (int)ng;
    MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
    if (P->rank == 0) {
      P->gdisp[0] = 0;
      for (int r = 0; r < size; r++)
        P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
    }
    MPI_Gatherv(m->gid + g->begin, cnt, MPI_LONG, P->ggid, P->gcount, P->gdisp,
                MPI_LONG, 0, pm_par_comm());
    for (int k = 0; k < s->group[gi].n; k++) {
      const mpm_array *a = &s->group[gi].array[k];
      gather_array(P, a->data, ng, a->ncomp, P->ggid, P->gbegin[gi],
                   fs ? fs->group[gi].array[k].data : NULL);
    }
  }
  /* The energy accounts: every rank's (for a checkpoint), and summed. */
  enum { n_acc = MPM_PAR_ACCOUNTS - 2 };
  double acc[MPM_PAR_ACCOUNTS];
  memcpy(acc, s->energy, sizeof s->energy);
  acc[n_acc] = s->external_work;
  acc[n_acc + 1] = s->dissipated;
  MPI_Gather(acc, MPM_PAR_ACCOUNTS, MPI_DOUBLE, P->accounts, MPM_PAR_ACCOUNTS,
             MPI_DOUBLE, 0, pm_par_comm());
  pm_par_sum(acc, MPM_PAR_ACCOUNTS);
  if (fs) {
    mpm_state_copy_values(fs, s);
    memcpy(fs->energy, acc, sizeof fs->energy);
    fs->external_work = acc[n_acc];
    fs->dissipated = acc[n_acc + 1];
  }
  if (!s->force_prev) return PM_SUCCESS;
  /* Dynamic relaxation's nodal arrays. */
  const mpm_grid *fg = fs ? &full->grid : NULL;
  PM_CALL(gather_owned(m, fg, s->force_prev, NULL, fs ? fs->force_prev : NULL,
                       NULL));
  if (s->fixed)
    PM_CALL(gather_owned(m, fg, NULL, s->fixed, NULL, fs ? fs->fixed : NULL));
  return PM_SUCCESS;
}

static pm_err par_gather_nodes(const mpm_model *m, const mpm_model *full,
                               const double *local, double *whole) {
  return gather_owned(m, full ? &full->grid : NULL, local, NULL, whole, NULL);
}

/* ---- plan and counts -------------------------------------------------------
 */

void mpm_decomp_print(const mpm_decomp *d, const mpm_model *m, FILE *out) {
  fprintf(out,
          "ranks        %d: boxes of the grid's cells by recursive bisection "
          "(cuts along x %d, y %d, z %d), %d ghost node layer%s\n",
          d->size, d->cuts[0], d->cuts[1], d->cuts[2], d->ghost,
          d->ghost == 1 ? "" : "s");
  if (d->held[0]) fprintf(out, "             not cut: %s\n", d->held);
  long most = 0, least = -1, total = 0;
  for (int r = 0; r < d->size; r++) {
    total += d->count[r];
    most = d->count[r] > most ? d->count[r] : most;
    least = least < 0 || d->count[r] < least ? d->count[r] : least;
  }
  fprintf(out,
          "             particles per rank %ld to %ld (imbalance %.3f: the "
          "most over the mean)\n",
          least, most, total > 0 ? most * (double)d->size / total : 0.0);
  (void)m;
}

/* Values per node the step's transfers exchange (mass, momentum, forces,
 * impedances; the MUSL remap's momentum). */
static int node_values_per_step(const mpm_model *m) {
  int v = 0;
  for (int k = 0; k < m->pipeline.n; k++) {
    const mpm_stage *stg = &m->pipeline.stage[k];
    if (stg->run == mpm_stage_p2g)
      v += dof_of(stg->mode, m->has_absorbing && (stg->mode & MPM_P2G_FORCE));
    if (stg->run == mpm_stage_remap) v += dof_of(MPM_P2G_MOM, false);
    /* each moving body's mass at the nodes, in the update (and before
     * the stress with USF) */
    if (stg->run == mpm_stage_grid_update ||
        stg->run == mpm_stage_grid_velocity)
      v += m->n_moving;
  }
  return v;
}

/* Whether rank r holds a node rank q owns (q is one of r's neighbours). */
static bool neighbours(const mpm_decomp *d, const mpm_grid *g, int r, int q) {
  long hl[3], hh[3], ol[3], oh[3];
  mpm_decomp_held(d, r, g, hl, hh);
  mpm_decomp_nodes(d, q, ol, oh);
  for (int a = 0; a < g->dim; a++)
    if (hh[a] <= ol[a] || oh[a] <= hl[a]) return false;
  return true;
}

void mpm_decomp_predict(const mpm_decomp *d, const mpm_model *m, FILE *out) {
  const mpm_grid *g = &m->grid;
  const int values = node_values_per_step(m);
  double ghost_sum = 0, ghost_max = 0, ratio_max = 0;
  int most_nb = 0;
  if (d->size <= 8)
    fprintf(out, "             rank  particles  nodes (owned + ghost)  "
                 "node bytes sent per step\n");
  for (int r = 0; r < d->size; r++) {
    long lo[3], hi[3], hl[3], hh[3];
    mpm_decomp_nodes(d, r, lo, hi);
    mpm_decomp_held(d, r, g, hl, hh);
    double own = 1, held = 1;
    for (int a = 0; a < g->dim; a++) {
      own *= (double)(hi[a] - lo[a]);
      held *= (double)(hh[a] - hl[a]);
    }
    int nb = 0;
    for (int q = 0; q < d->size; q++) nb += q != r && neighbours(d, g, r, q);
    most_nb = nb > most_nb ? nb : most_nb;
    const double ghost = held - own;
    ghost_sum += ghost;
    ghost_max = ghost > ghost_max ? ghost : ghost_max;
    ratio_max = ghost / own > ratio_max ? ghost / own : ratio_max;
    if (d->size <= 8)
      fprintf(out, "             %4d  %9ld  %9.0f (%.0f + %.0f)  %.0f\n", r,
              d->count[r], held, own, ghost,
              2 * ghost * values * sizeof(double));
  }
  fprintf(out,
          "             ghost nodes per rank %.0f on average, %.0f at most "
          "(%.3f of its own at most), %d neighbour ranks at most; %d values "
          "per node and step, so a rank sends %.0f bytes of node sums per "
          "step on average, %.0f at most\n",
          ghost_sum / d->size, ghost_max, ratio_max, most_nb, values,
          2 * ghost_sum / d->size * values * sizeof(double),
          2 * ghost_max * values * sizeof(double));
}

void mpm_par_plan(const mpm_model *m, const mpm_work *w, FILE *out) {
  const struct mpm_par *P = par_of(m);
  const int size = P->d.size;
  /* Per rank: particles, nodes held, nodes owned, bytes, ghost points. */
  double ghosts = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    long nearby;
    const long *ids;
    mpm_ghosts_nearby(P->gh, gi, &nearby, &ids);
    ghosts += (double)(mpm_ghosts_count(P->gh, gi) + nearby);
  }
  double mine[5] = {
      (double)m->n, (double)m->grid.n_nodes, (double)P->n_owned,
      (double)(mpm_model_bytes(m) + (w ? mpm_work_bytes(m, w) : 0)), ghosts};
  double *all = NULL;
  if (P->rank == 0) all = calloc((size_t)size * 5, sizeof(double));
  MPI_Gather(mine, 5, MPI_DOUBLE, all, 5, MPI_DOUBLE, 0, pm_par_comm());
  if (P->rank != 0 || !out || !all) {
    free(all);
    return;
  }
  mpm_decomp_print(&P->d, m, out);
  const bool linked = P->gh != NULL;
  fprintf(out,
          "             rank  particles  nodes (owned + ghost)  memory%s\n",
          linked ? "  ghost points (of membranes)" : "");
  for (int r = 0; r < size; r++) {
    const double *v = all + 5 * r;
    fprintf(out, "             %4d  %9.0f  %9.0f (%.0f + %.0f)  %.1f MiB", r,
            v[0], v[1], v[2], v[1] - v[2], v[3] / 1048576.0);
    if (linked) fprintf(out, "  %.0f", v[4]);
    fprintf(out, "\n");
  }
  free(all);
}

const mpm_decomp *mpm_par_decomp(const mpm_model *m) { return &par_of(m)->d; }

const double *mpm_par_accounts(const mpm_model *m) {
  return par_of(m)->accounts;
}

void mpm_par_get_counts(const mpm_model *m, mpm_par_counts *c) {
  *c = m->xc ? par_of(m)->counts : (mpm_par_counts){0};
}

/* The core's reductions over the ranks (mpm_exchange.h). */
static void xc_sum(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_sum(v, n);
}
static void xc_max(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_max(v, n);
}
static void xc_min(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_min(v, n);
}
static void xc_sum_long(void *ctx, long *v, int n) {
  (void)ctx;
  pm_par_sum_long(v, n);
}
static pm_err xc_agree(void *ctx, pm_err e) {
  (void)ctx;
  return pm_par_agree(e);
}
static long xc_offset(void *ctx, long n) {
  (void)ctx;
  return pm_par_offset(n);
}
static void xc_release(mpm_exchange *xc) { par_free(xc->ctx); }

/* The exchange that a local model holds: this share's operations. */
static void fill_exchange(struct mpm_par *P) {
  P->xc = (mpm_exchange){.ctx = P,
                         .sum = xc_sum,
                         .max = xc_max,
                         .min = xc_min,
                         .sum_long = xc_sum_long,
                         .agree = xc_agree,
                         .offset = xc_offset,
                         .sum_nodes = par_sum_nodes,
                         .nodes_reduce = par_nodes_reduce,
                         .nodes_bcast = par_nodes_bcast,
                         .owned = par_owned,
                         .work_attach = par_work_attach,
                         .step_end = par_step_end,
                         .migrate = par_migrate,
                         .ghost_x = par_ghost_x,
                         .ghost_ids = par_ghost_ids,
                         .nearby = par_nearby,
                         .cells = par_cells,
                         .number_unknowns = par_number_unknowns,
                         .gather_nodes = par_gather_nodes,
                         .release = xc_release};
}
