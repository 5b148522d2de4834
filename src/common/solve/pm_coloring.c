/* pm_coloring: canonical patterns and greedy distance-2 colouring. */
#include "pm_coloring.h"

#include <stdlib.h>
#include <string.h>

static int compare_long(const void *a, const void *b) {
  long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

pm_err pm_pattern_build(long n, const long *ptr, const long *idx, bool diagonal,
                        pm_pattern *p) {
  pm_err ret = PM_SUCCESS;
  long *row = NULL;
  memset(p, 0, sizeof *p);
  PM_CHECK(n > 0 && ptr && idx, PM_ERR_ARG,
           "pattern: n must be > 0 (got %ld) with ptr and idx given", n);
  PM_CHECK(ptr[0] == 0, PM_ERR_ARG, "pattern: ptr[0] must be 0 (got %ld)",
           ptr[0]);
  long longest = 0;
  for (long i = 0; i < n; i++) {
    PM_CHECK(ptr[i + 1] >= ptr[i], PM_ERR_ARG,
             "pattern: ptr must not decrease (row %ld: %ld -> %ld)", i, ptr[i],
             ptr[i + 1]);
    if (ptr[i + 1] - ptr[i] > longest) longest = ptr[i + 1] - ptr[i];
  }
  for (long k = 0; k < ptr[n]; k++) {
    if (idx[k] >= 0 && idx[k] < n) continue;
    long i = 0;
    while (ptr[i + 1] <= k) i++;
    PM_CHECK(false, PM_ERR_ARG,
             "pattern: row %ld has column %ld, outside [0, %ld)", i, idx[k], n);
  }
  p->n = n;
  p->nsrc = ptr[n];
  PM_TRY(PM_ALLOC(p->ptr, n + 1, "pattern rows"));
  PM_TRY(PM_ALLOC(p->idx, ptr[n] + (diagonal ? n : 0), "pattern columns"));
  PM_TRY(PM_ALLOC(p->src, ptr[n] > 0 ? ptr[n] : 1, "pattern map"));
  PM_TRY(PM_ALLOC(row, longest + 1, "pattern row"));
  for (long i = 0; i < n; i++) {
    long len = 0;
    for (long k = ptr[i]; k < ptr[i + 1]; k++) row[len++] = idx[k];
    if (diagonal) row[len++] = i;
    qsort(row, (size_t)len, sizeof *row, compare_long);
    long start = p->ptr[i], m = 0;
    for (long k = 0; k < len; k++)
      if (m == 0 || row[k] != p->idx[start + m - 1])
        p->idx[start + m++] = row[k];
    p->ptr[i + 1] = start + m;
    /* Each source entry's place, by bisection in the sorted row. */
    for (long k = ptr[i]; k < ptr[i + 1]; k++) {
      long *at = bsearch(&idx[k], p->idx + start, (size_t)m, sizeof(long),
                         compare_long);
      PM_ASSERT(at);
      p->src[k] = at - p->idx;
    }
  }
done:
  free(row);
  if (ret != PM_SUCCESS) pm_pattern_free(p);
  return ret;
}

void pm_pattern_free(pm_pattern *p) {
  free(p->ptr);
  free(p->idx);
  free(p->src);
  memset(p, 0, sizeof *p);
}

long pm_pattern_max_row(const pm_pattern *p) {
  long m = 0;
  for (long i = 0; i < p->n; i++)
    if (p->ptr[i + 1] - p->ptr[i] > m) m = p->ptr[i + 1] - p->ptr[i];
  return m;
}

typedef struct {
  long degree, column;
} ranked;

/* Decreasing degree, then increasing index. */
static int compare_ranked(const void *a, const void *b) {
  const ranked *x = a, *y = b;
  if (x->degree != y->degree) return x->degree < y->degree ? 1 : -1;
  return (x->column > y->column) - (x->column < y->column);
}

pm_err pm_coloring_build(const pm_pattern *p, pm_coloring_order order,
                         pm_coloring *c) {
  pm_err ret = PM_SUCCESS;
  long n = p->n, nnz = p->ptr[n];
  long *visit = NULL, *stamp = NULL, *fill = NULL;
  ranked *rank = NULL;
  memset(c, 0, sizeof *c);
  PM_TRY(PM_ALLOC(c->color, n, "colours"));
  PM_TRY(PM_ALLOC(c->col_ptr, n + 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(c->col_row, nnz > 0 ? nnz : 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(c->col_pos, nnz > 0 ? nnz : 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(visit, n, "colouring order"));
  PM_TRY(PM_ALLOC(stamp, n + 1, "colouring marks"));
  PM_TRY(PM_ALLOC(fill, n, "colouring fill"));

  /* The transpose: rows of each column, with the entry's place. */
  for (long k = 0; k < nnz; k++) c->col_ptr[p->idx[k] + 1]++;
  for (long j = 0; j < n; j++) c->col_ptr[j + 1] += c->col_ptr[j];
  for (long i = 0; i < n; i++)
    for (long k = p->ptr[i]; k < p->ptr[i + 1]; k++) {
      long j = p->idx[k], q = c->col_ptr[j] + fill[j]++;
      c->col_row[q] = i;
      c->col_pos[q] = k;
    }

  for (long j = 0; j < n; j++) visit[j] = j;
  for (long j = 0; j <= n; j++) stamp[j] = -1;
  if (order == PM_COLORING_LARGEST_FIRST) {
    /* Distance-2 degree: the other columns that share a row with j. */
    PM_TRY(PM_ALLOC(rank, n, "colouring degrees"));
    for (long j = 0; j < n; j++) {
      rank[j].column = j;
      stamp[j] = j;
      for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++) {
        long i = c->col_row[q];
        for (long k = p->ptr[i]; k < p->ptr[i + 1]; k++)
          if (stamp[p->idx[k]] != j) {
            stamp[p->idx[k]] = j;
            rank[j].degree++;
          }
      }
    }
    qsort(rank, (size_t)n, sizeof *rank, compare_ranked);
    for (long j = 0; j < n; j++) visit[j] = rank[j].column;
    for (long j = 0; j <= n; j++) stamp[j] = -1;
  }

  /* Greedy: stamp[colour] = j marks the colours j's neighbours hold. */
  for (long j = 0; j < n; j++) c->color[j] = -1;
  int ncolors = 0;
  for (long v = 0; v < n; v++) {
    long j = visit[v];
    for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++) {
      long i = c->col_row[q];
      for (long k = p->ptr[i]; k < p->ptr[i + 1]; k++) {
        int col = c->color[p->idx[k]];
        if (col >= 0) stamp[col] = j;
      }
    }
    int col = 0;
    while (stamp[col] == j) col++;
    c->color[j] = col;
    if (col + 1 > ncolors) ncolors = col + 1;
  }
  c->ncolors = ncolors;

  PM_TRY(PM_ALLOC(c->color_ptr, ncolors + 1, "colour lists"));
  PM_TRY(PM_ALLOC(c->color_col, n, "colour lists"));
  for (long j = 0; j < n; j++) c->color_ptr[c->color[j] + 1]++;
  for (int k = 0; k < ncolors; k++) c->color_ptr[k + 1] += c->color_ptr[k];
  memset(fill, 0, (size_t)n * sizeof *fill);
  for (long j = 0; j < n; j++) {
    int k = c->color[j];
    c->color_col[c->color_ptr[k] + fill[k]++] = j;
  }
done:
  free(visit);
  free(stamp);
  free(rank);
  free(fill);
  if (ret != PM_SUCCESS) pm_coloring_free(c);
  return ret;
}

void pm_coloring_free(pm_coloring *c) {
  free(c->color);
  free(c->color_ptr);
  free(c->color_col);
  free(c->col_ptr);
  free(c->col_row);
  free(c->col_pos);
  memset(c, 0, sizeof *c);
}
