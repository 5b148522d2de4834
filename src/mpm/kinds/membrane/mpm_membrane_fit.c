/* mpm_membrane_fit: membrane normals without connectivity, by isosurface
 * least squares fitted per grid cell (mpm_isonormal.h), on one process or
 * with the nearby points of other ranks. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_isonormal.h"
#include "mpm_membrane_impl.h"
#include "mpm_exchange.h"
#include "pm_omp.h"
#include "pm_sorted.h"

/* ---- normals by isosurface least squares ---------------------------------
 * Per body, each step: the points sorted by grid cell; each cell fitted on
 * its own (quadratic or linear by the method, or by the hybrid rule), or,
 * with too few points for the hybrid rule, with the points of the block of
 * 2, then 4 cells a side around it taken as one larger element (the block
 * placed so that the cell's points are nearest its middle).  The fits of
 * different cells are independent: one thread each. */

enum { ISO_MERGE_LEVELS = 3 }; /* blocks of 2, 4 and 8 cells a side */

typedef struct {
  long key, k; /* cell key, point (within the body) */
} cell_point;

/* One thread's fits. */
typedef struct {
  mpm_iso_work *fit[2]; /* linear, quadratic */
  long *gather;         /* points of a merged block */
  double *normal;       /* 3 per point of a body: a merged block's normals */
} iso_thread;

struct iso_work {
  int threads;
  iso_thread *t;
  cell_point *cp; /* per point of a body */
  long *order;    /* the points in cell order */
  long *run;      /* start of each cell's points in order, and the end */
  /* across ranks: a body's points with the nearby points of other ranks,
   * in one-process order (3 each), their normals, and where each of the
   * rank's points is among them */
  double *xe, *ne;
  long *at;
};

void mpm_membrane_fits_free(void *p) {
  iso_work *w = p;
  if (!w) return;
  for (int t = 0; w->t && t < w->threads; t++) {
    mpm_iso_work_destroy(w->t[t].fit[0]);
    mpm_iso_work_destroy(w->t[t].fit[1]);
    free(w->t[t].gather);
    free(w->t[t].normal);
  }
  free(w->t);
  free(w->cp);
  free(w->order);
  free(w->run);
  free(w->xe);
  free(w->ne);
  free(w->at);
  free(w);
}

pm_err mpm_membrane_fits_create(const mpm_model *m, const mpm_group *g,
                                void **out, size_t *bytes) {
  const membrane_params *mp = g->params;
  *out = NULL;
  *bytes = 0;
  if (!mp->iso) return PM_SUCCESS;
  pm_err ret = PM_SUCCESS;
  iso_work *w = NULL;
  const long n = mp->max_body;
  PM_TRY(PM_ALLOC(w, 1, "membrane normal fits"));
  w->threads = pm_omp_threads();
  PM_TRY(PM_ALLOC(w->t, w->threads, "membrane normal fits"));
  PM_TRY(PM_ALLOC(w->cp, n, "membrane points by cell"));
  PM_TRY(PM_ALLOC(w->order, n, "membrane points by cell"));
  PM_TRY(PM_ALLOC(w->run, n + 1, "membrane cells"));
  *bytes = sizeof *w + (size_t)n * (sizeof(cell_point) + 2 * sizeof(long));
  if (m->xc) {
    PM_TRY(PM_ALLOC(w->xe, 3 * n, "membrane points with nearby ones"));
    PM_TRY(PM_ALLOC(w->ne, 3 * n, "membrane points with nearby ones"));
    PM_TRY(PM_ALLOC(w->at, n, "membrane points with nearby ones"));
    *bytes += (size_t)n * (6 * sizeof(double) + sizeof(long));
  }
  for (int t = 0; t < w->threads; t++) {
    for (int o = 0; o < 2; o++) {
      mpm_iso_config c = mpm_iso_config_default(m->dim, o + 1);
      PM_TRY(mpm_iso_work_create(&c, &w->t[t].fit[o]));
      *bytes += mpm_iso_work_bytes(w->t[t].fit[o]);
    }
    PM_TRY(PM_ALLOC(w->t[t].gather, n, "membrane merged cells"));
    PM_TRY(PM_ALLOC(w->t[t].normal, 3 * n, "membrane merged cells"));
    *bytes += (size_t)n * (sizeof(long) + 3 * sizeof(double));
  }
  *out = w;
  w = NULL;
done:
  mpm_membrane_fits_free(w);
  return ret;
}

static int cell_point_cmp(const void *a, const void *b) {
  const cell_point *p = a, *q = b;
  if (p->key != q->key) return p->key < q->key ? -1 : 1;
  return (p->k > q->k) - (p->k < q->k);
}

/* The cell of x (indices of its lower node), its key on the whole grid
 * of nn nodes per axis. */
static inline long cell_of(const mpm_grid *g, const long nn[3],
                           const double x[3], long c[3]) {
  c[2] = 0;
  for (int d = 0; d < g->dim; d++)
    c[d] = (long)floor((x[d] - g->origin[d]) * g->inv_h);
  return c[0] + nn[0] * (c[1] + nn[1] * c[2]);
}

/* The points of the cell at key in cell order [*lo, *hi), found by
 * bisection of the sorted cells; false when it has none. */
static bool cell_range(const iso_work *w, long n_cells, long key, long *lo,
                       long *hi) {
  long a = 0, b = n_cells;
  while (a < b) {
    long mid = (a + b) / 2;
    long km = w->cp[w->run[mid]].key;
    if (km < key)
      a = mid + 1;
    else
      b = mid;
  }
  if (a >= n_cells || w->cp[w->run[a]].key != key) return false;
  *lo = w->run[a];
  *hi = w->run[a + 1];
  return true;
}

/* Whether the n points x + 3 idx[k] spread over a surface in 3D, not
 * along a line: the second principal variance of their covariance at least
 * ISO_SPREAD of the largest (m2 / tr^2, m2 the sum of its principal 2 x 2
 * minors, is that ratio when the third vanishes).  Points along a line do
 * not fix the plane through them: a fit takes some plane, and a flat sheet
 * turned rigidly got normals 9 degrees off.  Always true in 2D (a curve). */
#define ISO_SPREAD 0.01
static bool spread(int dim, const double *x, const long *idx, long n) {
  if (dim == 2) return true;
  double c[3] = {0, 0, 0}, C[3][3] = {{0}};
  for (long k = 0; k < n; k++)
    for (int d = 0; d < 3; d++) c[d] += x[3 * idx[k] + d] / (double)n;
  for (long k = 0; k < n; k++) {
    double u[3];
    for (int d = 0; d < 3; d++) u[d] = x[3 * idx[k] + d] - c[d];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) C[a][b] += u[a] * u[b];
  }
  const double tr = C[0][0] + C[1][1] + C[2][2];
  const double m2 = C[0][0] * C[1][1] - C[0][1] * C[0][1] + C[0][0] * C[2][2] -
                    C[0][2] * C[0][2] + C[1][1] * C[2][2] - C[1][2] * C[1][2];
  return m2 > ISO_SPREAD * tr * tr;
}

/* A fit's seed: the step, the body, the cell and the block level mixed
 * (splitmix64's finaliser), so that a run repeats bit for bit whatever
 * thread fits which cell. */
static inline uint64_t fit_seed(long step, int body, long key, int level) {
  return mpm_iso_mix((uint64_t)step * 0x9E3779B97F4A7C15ull ^
                     ((uint64_t)body << 56) ^ ((uint64_t)level << 48) ^
                     (uint64_t)key * 0xBF58476D1CE4E5B9ull);
}

static void stats_merge(iso_stats *a, const iso_stats *b) {
  for (int i = 0; i < 4; i++) a->cells[i] += b->cells[i];
  a->points += b->points;
  a->degenerate += b->degenerate;
  a->draws += b->draws;
  if (b->max_condition > a->max_condition) a->max_condition = b->max_condition;
}

static void stats_add(iso_stats *a, const mpm_iso_report *r, long points) {
  a->points += points;
  a->degenerate += r->degenerate;
  a->draws += r->draws;
  if (r->condition > a->max_condition) a->max_condition = r->condition;
}

/* Normals nn (3 per point of the body, holding its previous normals on
 * entry) of the body's n points at x (3 each), by method, at step `step`,
 * for the points in the cells [cells->lo, cells->hi). */
pm_err mpm_membrane_fit(const mpm_grid *g, const iso_cells *cells, iso_work *w,
                        int body, int method, long n, const double *x,
                        long step, double *nn, iso_stats *st) {
  const int dim = g->dim;
  const long *gn = cells->nn;
  for (long k = 0; k < n; k++) {
    long c[3];
    w->cp[k].key = cell_of(g, gn, x + 3 * k, c);
    w->cp[k].k = k;
  }
  qsort(w->cp, (size_t)n, sizeof *w->cp, cell_point_cmp);
  long n_cells = 0;
  for (long k = 0; k < n; k++) {
    w->order[k] = w->cp[k].k;
    if (k == 0 || w->cp[k].key != w->cp[k - 1].key) w->run[n_cells++] = k;
  }
  w->run[n_cells] = n;
  pm_err err = PM_SUCCESS;
  iso_stats sum = {0};
  PM_OMP(parallel default(none) shared(g, cells, gn, w, body, method, n, x,
                                       step, nn, n_cells, dim, err, sum)) {
    iso_stats my = {0};
    iso_thread *th = &w->t[pm_omp_thread()];
    PM_OMP(for schedule(dynamic, 8))
    for (long ci = 0; ci < n_cells; ci++) {
      const long r0 = w->run[ci], r1 = w->run[ci + 1], cnt = r1 - r0;
      const long key = w->cp[r0].key;
      long cell[3];
      cell_of(g, gn, x + 3 * w->order[r0], cell);
      bool wanted = true;
      for (int d = 0; d < dim; d++)
        wanted = wanted && cell[d] >= cells->lo[d] && cell[d] < cells->hi[d];
      if (!wanted) continue; /* another rank's */
      int order = method == PM_NORMALS_ISO_LINEAR ? 1
                  : method == PM_NORMALS_ISO_QUADRATIC
                      ? 2
                      : mpm_iso_hybrid_order(dim, cnt);
      /* hybrid-quadratic: quadratic or merged; linear only on the largest
       * block. */
      const bool hybrid =
          method == PM_NORMALS_HYBRID || method == PM_NORMALS_HYBRID_QUADRATIC;
      const int block_order = method == PM_NORMALS_HYBRID_QUADRATIC ? 2 : 1;
      if (hybrid && order > 0 &&
          (order < block_order || !spread(dim, x, w->order + r0, cnt)))
        order = 0;
      mpm_iso_report rep;
      double lo[3] = {0, 0, 0};
      if (order > 0) {
        for (int d = 0; d < dim; d++) lo[d] = g->origin[d] + cell[d] * g->h;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            th->normal[3 * w->order[r] + d] = nn[3 * w->order[r] + d];
        pm_err e =
            mpm_iso_fit(th->fit[order - 1], lo, g->h, cnt, x, w->order + r0,
                        fit_seed(step, body, key, 0), nn, &rep);
        if (e) {
          PM_OMP(critical(membrane_iso)) err = e;
          continue;
        }
        /* Hybrid: points in a special position (on a line or a conic of
         * the surface) leave S rank deficient, and the minimum-norm phi is
         * not constant along the surface (7 points of a flat sheet gave a
         * normal 2.7 degrees off): the cell is merged as a sparse one. */
        if (!hybrid || rep.rank == mpm_iso_unknowns(dim, order)) {
          my.cells[order == 2 ? 0 : 1]++;
          stats_add(&my, &rep, cnt);
          continue;
        }
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            nn[3 * w->order[r] + d] = th->normal[3 * w->order[r] + d];
      }
      /* Too few points (or, by the hybrid rule, points that do not fix the
       * surface): the block of B cells a side around the cell, B = 2, 4, 8,
       * until it has enough for a full-rank linear fit. */
      double mid[3] = {0, 0, 0};
      for (long r = r0; r < r1; r++)
        for (int d = 0; d < dim; d++)
          mid[d] += (x[3 * w->order[r] + d] - g->origin[d]) * g->inv_h / cnt;
      bool done_cell = false;
      for (int level = 1; level <= ISO_MERGE_LEVELS && !done_cell; level++) {
        const long B = 1L << level;
        long first[3] = {0, 0, 0}, span[3] = {1, 1, 1};
        for (int d = 0; d < dim; d++) {
          long f = lround(mid[d] - 0.5 * (double)B);
          if (f > cell[d]) f = cell[d];
          if (f < cell[d] - B + 1) f = cell[d] - B + 1;
          first[d] = f;
          span[d] = B;
        }
        long m = 0;
        for (long c2 = 0; c2 < span[2]; c2++)
          for (long c1 = 0; c1 < span[1]; c1++)
            for (long c0 = 0; c0 < span[0]; c0++) {
              long q[3] = {first[0] + c0, first[1] + c1, first[2] + c2}, a, z;
              bool in = true;
              for (int d = 0; d < dim; d++)
                if (q[d] < 0 || q[d] >= gn[d] - 1) in = false;
              if (!in ||
                  !cell_range(w, n_cells, q[0] + gn[0] * (q[1] + gn[1] * q[2]),
                              &a, &z))
                continue;
              for (long r = a; r < z; r++) th->gather[m++] = w->order[r];
            }
        /* The larger element's fit: linear as the paper does (hybrid), or
         * quadratic when the block has enough points (hybrid-quadratic);
         * else the next block, and the largest block's fit whatever it
         * has (linear). */
        order = mpm_iso_hybrid_order(dim, m) >= block_order ? block_order : 0;
        if ((order == 0 || !spread(dim, x, th->gather, m)) &&
            level < ISO_MERGE_LEVELS)
          continue;
        if (order == 0) order = 1;
        for (int d = 0; d < dim; d++) lo[d] = g->origin[d] + first[d] * g->h;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            th->normal[3 * w->order[r] + d] = nn[3 * w->order[r] + d];
        pm_err e = mpm_iso_fit(th->fit[order - 1], lo, (double)B * g->h, m, x,
                               th->gather, fit_seed(step, body, key, level),
                               th->normal, &rep);
        if (e) {
          PM_OMP(critical(membrane_iso)) err = e;
          break;
        }
        if (rep.rank < mpm_iso_unknowns(dim, order) && level < ISO_MERGE_LEVELS)
          continue;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            nn[3 * w->order[r] + d] = th->normal[3 * w->order[r] + d];
        my.cells[rep.rank == mpm_iso_unknowns(dim, order) ? 2 : 3]++;
        stats_add(&my, &rep, cnt);
        done_cell = true;
      }
    }
    PM_OMP(critical(membrane_iso_stats)) stats_merge(&sum, &my);
  }
  stats_merge(st, &sum);
  return err;
}

/* Across ranks, the fitted normals nn of body b's points of the rank
 * (group points [b0, b1), positions x from the group's start): fitted with
 * the nearby points of other ranks (those within the merged blocks' reach
 * of the rank's cells), all in one-process order, so that each cell of
 * the rank is fitted to the points, in the order, one process fits it
 * to. */
pm_err mpm_membrane_fit_ranks(const mpm_model *m, const mpm_group *gr,
                              const struct membrane_body *b,
                              const iso_cells *cells, iso_work *w, long b0,
                              long b1, const double *x, long step, double *nn,
                              iso_stats *st) {
  const membrane_params *mp = gr->params;
  const long *own = m->gid + gr->begin, *ids;
  long n_near;
  const double *xn = mpm_xc_nearby(m, gr->index, &n_near, &ids);
  const long j0 = pm_lower_bound(ids, n_near, mp->whole.first + b->begin),
             j1 = pm_lower_bound(ids, n_near, mp->whole.first + b->end);
  long e = 0;
  for (long k = b0, j = j0; k < b1 || j < j1; e++) {
    const bool mine = j >= j1 || (k < b1 && own[k] < ids[j]);
    if (mine) {
      memcpy(w->xe + 3 * e, x + 3 * k, 3 * sizeof(double));
      memcpy(w->ne + 3 * e, nn + 3 * k, 3 * sizeof(double));
      w->at[k++ - b0] = e;
    } else {
      memcpy(w->xe + 3 * e, xn + 3 * j++, 3 * sizeof(double));
      memset(w->ne + 3 * e, 0, 3 * sizeof(double)); /* not read */
    }
  }
  PM_CALL(mpm_membrane_fit(&m->grid, cells, w, b->body, b->method, e, w->xe,
                           step, w->ne, st));
  for (long k = b0; k < b1; k++)
    memcpy(nn + 3 * k, w->ne + 3 * w->at[k - b0], 3 * sizeof(double));
  return PM_SUCCESS;
}

/* Across ranks, the cells around a rank's whose points its fits read: a
 * merged block of up to 2^ISO_MERGE_LEVELS cells a side reaches that many
 * less one beyond the cell it fits. */
int mpm_membrane_ranks_reach(const mpm_group *g) {
  const membrane_params *mp = g->params;
  return mp->iso ? (1 << ISO_MERGE_LEVELS) - 1 : 0;
}
