/* mpm_decomp: the decomposition of MPM's grid into boxes, one per rank, by
 * recursive bisection balancing the particles. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

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
int mpm_decomp_rank_of(const mpm_decomp *d, const long q[3]) {
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
  return mpm_decomp_rank_of(d, c);
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
  free(d->count0);
  memset(d, 0, sizeof *d);
}

long mpm_decomp_items(int size) { return 4 + 12 * (long)size; }

void mpm_decomp_pack(const mpm_decomp *d, long *buf) {
  const long n = d->size;
  memset(buf, 0, sizeof(long) * (size_t)mpm_decomp_items(d->size));
  buf[0] = d->recuts;
  for (int a = 0; a < 3; a++) buf[1 + a] = d->cuts[a];
  long *box = buf + 4, *tree = box + 6 * n, *count = tree + 4 * n,
       *count0 = count + n;
  memcpy(box, d->box, 6 * sizeof(long) * (size_t)n);
  for (long k = 0; k + 1 < n; k++) {
    tree[4 * k] = d->tree[k].axis;
    tree[4 * k + 1] = d->tree[k].at;
    tree[4 * k + 2] = d->tree[k].child[0];
    tree[4 * k + 3] = d->tree[k].child[1];
  }
  memcpy(count, d->count, sizeof(long) * (size_t)n);
  memcpy(count0, d->count0 ? d->count0 : d->count, sizeof(long) * (size_t)n);
}

/* Whether buf's integers are a cut of d's grid (d's cells set): each cut
 * of the tree inside its grid, its children later cuts or ranks (so that
 * every descent ends), each box inside the grid and its corner the rank's
 * own. */
static bool cut_holds(const long *buf, const mpm_decomp *d) {
  const long n = d->size;
  const long *box = buf + 4, *tree = box + 6 * n, *count = tree + 4 * n;
  if (buf[0] < 0) return false;
  for (long k = 0; k + 1 < n; k++) {
    const long a = tree[4 * k], at = tree[4 * k + 1];
    if (a < 0 || a > 2 || at <= 0 || at >= d->cells[a]) return false;
    for (int c = 0; c < 2; c++) {
      const long q = tree[4 * k + 2 + c];
      if (q < 0 ? -q - 1 >= n : q <= k || q + 1 >= n) return false;
    }
  }
  for (long r = 0; r < n; r++) {
    if (count[r] < 0 || count[r + n] < 0) return false;
    for (int a = 0; a < 3; a++)
      if (box[6 * r + a] < 0 || box[6 * r + a] >= box[6 * r + 3 + a] ||
          box[6 * r + 3 + a] > d->cells[a])
        return false;
  }
  return true;
}

pm_err mpm_decomp_unpack(const long *buf, int size, const mpm_grid *whole,
                         const char *what, mpm_decomp *d) {
  pm_err ret = PM_SUCCESS;
  memset(d, 0, sizeof *d);
  d->size = size;
  d->ghost = whole->width - 1;
  mpm_decomp_cells(whole, d->cells);
  PM_CHECK(size >= 1 && cut_holds(buf, d), PM_ERR_IO,
           "%s: expected the cut of a grid of %ld x %ld x %ld cells for %d "
           "ranks, got integers that are none",
           what, d->cells[0], d->cells[1], d->cells[2], size);
  const long n = size;
  const long *box = buf + 4, *tree = box + 6 * n, *count = tree + 4 * n;
  PM_TRY(PM_ALLOC(d->box, 6 * n, "decomposition boxes"));
  PM_TRY(PM_ALLOC(d->tree, n, "decomposition cuts"));
  PM_TRY(PM_ALLOC(d->count, n, "particles per rank"));
  PM_TRY(PM_ALLOC(d->count0, n, "particles per rank"));
  d->recuts = buf[0];
  for (int a = 0; a < 3; a++) d->cuts[a] = (int)buf[1 + a];
  memcpy(d->box, box, 6 * sizeof(long) * (size_t)n);
  for (long k = 0; k + 1 < n; k++)
    d->tree[k] =
        (mpm_decomp_cut){.axis = (int)tree[4 * k],
                         .at = tree[4 * k + 1],
                         .child = {(int)tree[4 * k + 2], (int)tree[4 * k + 3]}};
  memcpy(d->count, count, sizeof(long) * (size_t)n);
  memcpy(d->count0, count + n, sizeof(long) * (size_t)n);
  for (int r = 0; r < size; r++) {
    const long q[3] = {d->box[6 * r], d->box[6 * r + 1], d->box[6 * r + 2]};
    PM_ENSURE(mpm_decomp_rank_of(d, q) == r, PM_ERR_IO,
              "%s: the cut's box of rank %d is not where its tree puts it",
              what, r);
  }
done:
  if (ret) mpm_decomp_destroy(d);
  return ret;
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
 * particles per cell, a histogram, and the tree it grows. */
typedef struct {
  const pm_scene *s;
  const mpm_model *m;
  mpm_decomp *d;
  bool splits[3];
  const long *per_cell; /* cells[0] x cells[1] x cells[2], x fastest */
  long *hist;
  int n_nodes;
} bisection;

/* The particles of box [lo, hi) in each slab across axis a into hist
 * (hi[a] - lo[a] of them). */
static void slabs(const bisection *B, const long lo[3], const long hi[3], int a,
                  long *hist) {
  const long *n = B->d->cells;
  memset(hist, 0, sizeof(long) * (size_t)(hi[a] - lo[a]));
  for (long k = lo[2]; k < hi[2]; k++)
    for (long j = lo[1]; j < hi[1]; j++)
      for (long i = lo[0]; i < hi[0]; i++) {
        const long q[3] = {i, j, k};
        hist[q[a] - lo[a]] += B->per_cell[i + n[0] * (j + n[1] * k)];
      }
}

/* Cells of box [lo, hi). */
static double box_cells(const long lo[3], const long hi[3]) {
  return (double)(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

/* Share n ranks from r0 among the count particles of box [lo, hi): cut
 * the box's longest axis that may be cut where the particles divide in
 * the ranks' proportion, and each side likewise.  Returns the tree node
 * it made, or -(r0 + 1) for a box of one rank. */
static pm_err bisect(bisection *B, int r0, int n, const long lo[3],
                     const long hi[3], long count, int *node) {
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
  slabs(B, lo, hi, axis, B->hist);
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
  long split = 0; /* the particles below the cut */
  for (long c = 0; c < best; c++) split += B->hist[c];
  const int me = B->n_nodes++;
  d->tree[me].axis = axis;
  d->tree[me].at = at;
  d->cuts[axis]++;
  long mid_hi[3], mid_lo[3];
  memcpy(mid_hi, hi, sizeof mid_hi);
  memcpy(mid_lo, lo, sizeof mid_lo);
  mid_hi[axis] = mid_lo[axis] = at;
  int child;
  PM_CALL(bisect(B, r0, nl, lo, mid_hi, split, &child));
  d->tree[me].child[0] = child;
  PM_CALL(bisect(B, r0 + nl, nr, mid_lo, hi, count - split, &child));
  d->tree[me].child[1] = child;
  *node = me;
  return PM_SUCCESS;
}

long mpm_decomp_cells(const mpm_grid *g, long cells[3]) {
  long n = 1;
  for (int a = 0; a < 3; a++) {
    cells[a] = a < g->dim ? g->nn[a] - 1 : 1;
    n *= cells[a];
  }
  return n;
}

void mpm_decomp_count(const mpm_grid *g, const long cells[3], const double x[3],
                      long *per_cell) {
  long c[3];
  cell_of(g, cells, x, c);
  per_cell[c[0] + cells[0] * (c[1] + cells[1] * c[2])]++;
}

pm_err mpm_decomp_create(const pm_scene *s, const mpm_model *m, int size,
                         mpm_decomp *d) {
  long cells[3], *per_cell = NULL;
  PM_CALL(PM_ALLOC(per_cell, mpm_decomp_cells(&m->grid, cells),
                   "particles per cell"));
  for (long p = 0; p < m->n; p++)
    mpm_decomp_count(&m->grid, cells, m->x0 + 3 * p, per_cell);
  pm_err e = mpm_decomp_from_counts(s, m, size, per_cell, m->n, d);
  free(per_cell);
  return e;
}

pm_err mpm_decomp_from_counts(const pm_scene *s, const mpm_model *m, int size,
                              const long *per_cell, long total, mpm_decomp *d) {
  pm_err ret = PM_SUCCESS;
  const mpm_grid *g = &m->grid;
  bisection B = {.s = s, .m = m, .d = d, .per_cell = per_cell};
  const bool implicit = strcmp(s->method, "mpm-implicit") == 0;
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
  PM_TRY(PM_ALLOC(B.hist, most, "decomposition histogram"));
  const long lo[3] = {0, 0, 0};
  int root;
  PM_TRY(bisect(&B, 0, size, lo, d->cells, total, &root));
done:
  free(B.hist);
  if (ret) mpm_decomp_destroy(d);
  return ret;
}
