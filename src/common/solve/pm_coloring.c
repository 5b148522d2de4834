/* pm_coloring: canonical patterns and greedy distance-2 colouring. */
#include "pm_coloring.h"

#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"
#include "pm_sorted.h"

/* Sorts a[0 .. len) in increasing order: quicksort on the median of
 * three, insertion below 24 entries, the smaller part first (the stack
 * stays within 64 levels).  Rows of a pattern are a few hundred columns,
 * often runs already in order. */
static void sort_longs(long *a, long len) {
  long lo_stack[64], hi_stack[64];
  int top = 0;
  long lo = 0, hi = len - 1;
  for (;;) {
    while (hi - lo >= 24) {
      const long mid = lo + (hi - lo) / 2;
      long x = a[lo], y = a[mid], z = a[hi], pivot;
      pivot =
          x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
      long i = lo, j = hi;
      while (i <= j) {
        while (a[i] < pivot) i++;
        while (a[j] > pivot) j--;
        if (i <= j) {
          const long t = a[i];
          a[i++] = a[j];
          a[j--] = t;
        }
      }
      /* the larger part waits on the stack */
      if (j - lo < hi - i) {
        lo_stack[top] = i;
        hi_stack[top++] = hi;
        hi = j;
      } else {
        lo_stack[top] = lo;
        hi_stack[top++] = j;
        lo = i;
      }
    }
    for (long i = lo + 1; i <= hi; i++) {
      const long v = a[i];
      long k = i - 1;
      for (; k >= lo && a[k] > v; k--) a[k + 1] = a[k];
      a[k + 1] = v;
    }
    if (top == 0) return;
    top--;
    lo = lo_stack[top];
    hi = hi_stack[top];
  }
}

pm_err pm_pattern_check(long n, const long *ptr, const long *idx) {
  PM_CHECK(n > 0 && ptr && idx, PM_ERR_ARG,
           "pattern: n must be > 0 (got %ld) with ptr and idx given", n);
  PM_CHECK(ptr[0] == 0, PM_ERR_ARG, "pattern: ptr[0] must be 0 (got %ld)",
           ptr[0]);
  for (long i = 0; i < n; i++)
    PM_CHECK(ptr[i + 1] >= ptr[i], PM_ERR_ARG,
             "pattern: ptr must not decrease (row %ld: %ld -> %ld)", i, ptr[i],
             ptr[i + 1]);
  for (long k = 0; k < ptr[n]; k++) {
    if (idx[k] >= 0 && idx[k] < n) continue;
    long i = 0;
    while (ptr[i + 1] <= k) i++;
    PM_CHECK(false, PM_ERR_ARG,
             "pattern: row %ld has column %ld, outside [0, %ld)", i, idx[k], n);
  }
  return PM_SUCCESS;
}

pm_err pm_pattern_build(long n, const long *ptr, const long *idx, bool diagonal,
                        pm_pattern *p) {
  pm_err ret = PM_SUCCESS;
  memset(p, 0, sizeof *p);
  PM_CALL(pm_pattern_check(n, ptr, idx));
  p->n = n;
  p->nsrc = ptr[n];
  const long extra = diagonal ? 1 : 0;
  PM_TRY(PM_ALLOC(p->ptr, n + 1, "pattern rows"));
  PM_TRY(PM_ALLOC(p->idx, ptr[n] + extra * n, "pattern columns"));
  PM_TRY(PM_ALLOC(p->src, ptr[n] > 0 ? ptr[n] : 1, "pattern map"));
  PM_TRY(PM_ALLOC(p->sptr, n + 1, "pattern map"));
  memcpy(p->sptr, ptr, (size_t)(n + 1) * sizeof *ptr);
  long *out = p->idx, *cnt = p->ptr;
  /* Each row sorted and made unique in its own slot (its source's place
   * and one more for the diagonal), every thread its rows; then the rows
   * moved down in order, which only ever moves a row to where rows before
   * it have been; then each source entry's place by bisection. */
  PM_OMP(parallel for schedule(dynamic, 64) default(none)
         shared(n, ptr, idx, extra, out, cnt))
  for (long i = 0; i < n; i++) {
    long *row = out + ptr[i] + extra * i, len = 0;
    for (long k = ptr[i]; k < ptr[i + 1]; k++) row[len++] = idx[k];
    if (extra) row[len++] = i;
    sort_longs(row, len);
    long m = 0;
    for (long k = 0; k < len; k++)
      if (m == 0 || row[k] != row[m - 1]) row[m++] = row[k];
    cnt[i + 1] = m;
  }
  cnt[0] = 0;
  for (long i = 0; i < n; i++) {
    const long m = cnt[i + 1], from = ptr[i] + extra * i;
    cnt[i + 1] = cnt[i] + m;
    if (from != cnt[i])
      memmove(out + cnt[i], out + from, (size_t)m * sizeof *out);
  }
  long *src = p->src;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, idx, out, cnt, src))
  for (long i = 0; i < n; i++)
    for (long k = ptr[i]; k < ptr[i + 1]; k++)
      src[k] =
          cnt[i] + pm_lower_bound(out + cnt[i], cnt[i + 1] - cnt[i], idx[k]);
  /* A source that is the pattern itself needs no map. */
  bool same = p->nsrc == p->ptr[n];
  for (long k = 0; same && k < p->nsrc; k++) same = p->src[k] == k;
  if (same) {
    free(p->src);
    free(p->sptr);
    p->src = p->sptr = NULL;
  }
done:
  if (ret != PM_SUCCESS) pm_pattern_free(p);
  return ret;
}

void pm_pattern_sort_row(long *row, long len) { sort_longs(row, len); }

void pm_pattern_free(pm_pattern *p) {
  free(p->ptr);
  free(p->idx);
  free(p->src);
  free(p->sptr);
  memset(p, 0, sizeof *p);
}

long pm_pattern_max_row(const pm_pattern *p) {
  long m = 0;
  for (long i = 0; i < p->n; i++)
    if (p->ptr[i + 1] - p->ptr[i] > m) m = p->ptr[i + 1] - p->ptr[i];
  return m;
}

/* Lists with identical contents grouped: list k is
 * idx[ptr[k] .. ptr[k + 1]) (sorted). */
typedef struct {
  long count;  /* groups */
  long *group; /* per list */
  long *first; /* per group: its first list (the representative) */
  long *size;  /* per group: its lists */
} grouping;

typedef struct {
  unsigned long long hash;
  long length, list;
} keyed;

static int compare_keyed(const void *a, const void *b) {
  const keyed *x = a, *y = b;
  if (x->hash != y->hash) return x->hash < y->hash ? -1 : 1;
  if (x->length != y->length) return x->length < y->length ? -1 : 1;
  return (x->list > y->list) - (x->list < y->list);
}

static bool same_list(const long *ptr, const long *idx, long a, long b) {
  long la = ptr[a + 1] - ptr[a];
  return la == ptr[b + 1] - ptr[b] &&
         !memcmp(idx + ptr[a], idx + ptr[b], (size_t)la * sizeof *idx);
}

static void grouping_free(grouping *g) {
  free(g->group);
  free(g->first);
  free(g->size);
  memset(g, 0, sizeof *g);
}

/* Groups the m lists by content (hash, then exact comparison); groups are
 * numbered in the order of their first list. */
static pm_err group_lists(long m, const long *ptr, const long *idx,
                          grouping *g) {
  pm_err ret = PM_SUCCESS;
  keyed *keys = NULL;
  memset(g, 0, sizeof *g);
  PM_TRY(PM_ALLOC(keys, m, "pattern grouping"));
  PM_TRY(PM_ALLOC(g->group, m, "pattern grouping"));
  PM_TRY(PM_ALLOC(g->first, m, "pattern grouping"));
  PM_TRY(PM_ALLOC(g->size, m, "pattern grouping"));
  for (long k = 0; k < m; k++) {
    unsigned long long h = 1469598103934665603ull; /* FNV-1a */
    for (long q = ptr[k]; q < ptr[k + 1]; q++)
      h = (h ^ (unsigned long long)idx[q]) * 1099511628211ull;
    keys[k] = (keyed){h, ptr[k + 1] - ptr[k], k};
    g->group[k] = -1;
  }
  qsort(keys, (size_t)m, sizeof *keys, compare_keyed);
  /* Within a run of equal keys, each list joins the first equal one. */
  for (long a = 0; a < m;) {
    long b = a;
    while (b < m && keys[b].hash == keys[a].hash &&
           keys[b].length == keys[a].length)
      b++;
    for (long u = a; u < b; u++) {
      long lu = keys[u].list;
      if (g->group[lu] >= 0) continue;
      g->group[lu] = lu; /* provisional: its own representative */
      for (long v = u + 1; v < b; v++)
        if (g->group[keys[v].list] < 0 && same_list(ptr, idx, lu, keys[v].list))
          g->group[keys[v].list] = lu;
    }
    a = b;
  }
  /* Number groups by their first list (keys were sorted by list within a
   * run, so the representative is the first). */
  long *number = g->size; /* scratch: group number of a representative */
  for (long k = 0; k < m; k++) number[k] = -1;
  for (long k = 0; k < m; k++) {
    long r = g->group[k];
    if (number[r] < 0) {
      number[r] = g->count;
      g->first[g->count++] = k;
    }
    g->group[k] = number[r];
  }
  memset(g->size, 0, (size_t)m * sizeof *g->size);
  for (long k = 0; k < m; k++) g->size[g->group[k]]++;
done:
  free(keys);
  if (ret != PM_SUCCESS) grouping_free(g);
  return ret;
}

/* For each group of lists (by its representative), the distinct groups of
 * what it lists: out_ptr[count + 1], out_idx. */
static pm_err group_links(const grouping *from, const long *ptr,
                          const long *idx, const grouping *to, long to_lists,
                          long **out_ptr, long **out_idx) {
  pm_err ret = PM_SUCCESS;
  long *stamp = NULL, total = 0;
  *out_ptr = *out_idx = NULL;
  for (long G = 0; G < from->count; G++)
    total += ptr[from->first[G] + 1] - ptr[from->first[G]];
  PM_TRY(PM_ALLOC(*out_ptr, from->count + 1, "grouped pattern"));
  PM_TRY(PM_ALLOC(*out_idx, total > 0 ? total : 1, "grouped pattern"));
  PM_TRY(PM_ALLOC(stamp, to_lists > 0 ? to_lists : 1, "grouped pattern"));
  for (long k = 0; k < to_lists; k++) stamp[k] = -1;
  for (long G = 0; G < from->count; G++) {
    long r = from->first[G], at = (*out_ptr)[G];
    for (long q = ptr[r]; q < ptr[r + 1]; q++) {
      long H = to->group[idx[q]];
      if (stamp[H] == G) continue;
      stamp[H] = G;
      (*out_idx)[at++] = H;
    }
    (*out_ptr)[G + 1] = at;
  }
done:
  free(stamp);
  return ret;
}

/* The pattern between groups: column group G's row groups
 * row_of[col_ptr[G] ..], row group R's column groups col_of[row_ptr[R] ..]. */
typedef struct {
  long *col_ptr, *row_of, *row_ptr, *col_of;
} linked;

/* The column groups sharing a row with G (G among them) into out; seen[H]
 * = G marks them.  Returns their number. */
static long neighbour_groups(const linked *l, long G, long *seen, long *out) {
  long count = 0;
  for (long q = l->col_ptr[G]; q < l->col_ptr[G + 1]; q++) {
    long R = l->row_of[q];
    for (long u = l->row_ptr[R]; u < l->row_ptr[R + 1]; u++) {
      long H = l->col_of[u];
      if (seen[H] == G) continue;
      seen[H] = G;
      out[count++] = H;
    }
  }
  return count;
}

typedef struct {
  long degree, group;
} ranked;

/* Decreasing degree, then increasing group. */
static int compare_ranked(const void *a, const void *b) {
  const ranked *x = a, *y = b;
  if (x->degree != y->degree) return x->degree < y->degree ? 1 : -1;
  return (x->group > y->group) - (x->group < y->group);
}

/* Columns with the same rows (the components of one point) form a group,
 * and so do rows with the same columns; the greedy colouring runs over
 * column groups, each taking as many consecutive colours as it has
 * columns, which gives what colouring column by column gives at a
 * fraction of the cost (sum over rows of the squared row length, divided
 * by the group sizes cubed). */
pm_err pm_coloring_build(const pm_pattern *p, pm_coloring_order order,
                         pm_coloring *c) {
  pm_err ret = PM_SUCCESS;
  long n = p->n, nnz = p->ptr[n];
  grouping cols = {0}, rows = {0};
  linked l = {0};
  long *start = NULL, *seen = NULL, *near = NULL, *taken = NULL;
  long *fill = NULL;
  ranked *rank = NULL;
  memset(c, 0, sizeof *c);
  PM_TRY(PM_ALLOC(c->color, n, "colours"));
  PM_TRY(PM_ALLOC(c->col_ptr, n + 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(c->col_row, nnz > 0 ? nnz : 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(c->col_pos, nnz > 0 ? nnz : 1, "pattern by columns"));
  PM_TRY(PM_ALLOC(fill, n, "colouring fill"));

  /* The transpose: rows of each column (ascending), with the entry's
   * place. */
  for (long k = 0; k < nnz; k++) c->col_ptr[p->idx[k] + 1]++;
  for (long j = 0; j < n; j++) c->col_ptr[j + 1] += c->col_ptr[j];
  for (long i = 0; i < n; i++)
    for (long k = p->ptr[i]; k < p->ptr[i + 1]; k++) {
      long j = p->idx[k], q = c->col_ptr[j] + fill[j]++;
      c->col_row[q] = i;
      c->col_pos[q] = k;
    }

  PM_TRY(group_lists(n, c->col_ptr, c->col_row, &cols));
  PM_TRY(group_lists(n, p->ptr, p->idx, &rows));
  PM_TRY(group_links(&cols, c->col_ptr, c->col_row, &rows, n, &l.col_ptr,
                     &l.row_of));
  PM_TRY(group_links(&rows, p->ptr, p->idx, &cols, n, &l.row_ptr, &l.col_of));

  long ng = cols.count;
  PM_TRY(PM_ALLOC(rank, ng, "colouring order"));
  PM_TRY(PM_ALLOC(seen, ng, "colouring"));
  PM_TRY(PM_ALLOC(near, ng, "colouring"));
  for (long G = 0; G < ng; G++) seen[G] = -1;
  for (long G = 0; G < ng; G++) {
    rank[G].group = G;
    if (order != PM_COLORING_LARGEST_FIRST) continue;
    /* Largest first: the columns that share a row with G's. */
    long count = neighbour_groups(&l, G, seen, near);
    for (long k = 0; k < count; k++) rank[G].degree += cols.size[near[k]];
  }
  if (order == PM_COLORING_LARGEST_FIRST)
    qsort(rank, (size_t)ng, sizeof *rank, compare_ranked);

  /* Greedy: taken[colour] = G marks the colours G's neighbours hold. */
  PM_TRY(PM_ALLOC(start, ng, "colouring"));
  PM_TRY(PM_ALLOC(taken, 2 * n + 1, "colouring"));
  for (long G = 0; G < ng; G++) start[G] = seen[G] = -1;
  for (long k = 0; k <= 2 * n; k++) taken[k] = -1;
  long ncolors = 0;
  for (long v = 0; v < ng; v++) {
    long G = rank[v].group, m = cols.size[G];
    long count = neighbour_groups(&l, G, seen, near);
    for (long k = 0; k < count; k++) {
      long H = near[k];
      if (start[H] < 0) continue;
      for (long t = 0; t < cols.size[H]; t++) taken[start[H] + t] = G;
    }
    long first = 0;
    for (long run = 0; run < m; first++) run = taken[first] == G ? 0 : run + 1;
    start[G] = first - m;
    if (first > ncolors) ncolors = first;
  }
  PM_ENSURE(ncolors <= n, PM_ERR_INTERNAL,
            "colouring took %ld colours for %ld columns", ncolors, n);
  c->ncolors = (int)ncolors;
  memset(fill, 0, (size_t)n * sizeof *fill);
  for (long j = 0; j < n; j++) {
    long G = cols.group[j];
    c->color[j] = (int)(start[G] + fill[G]++);
  }

  PM_TRY(PM_ALLOC(c->color_ptr, ncolors + 1, "colour lists"));
  PM_TRY(PM_ALLOC(c->color_col, n, "colour lists"));
  for (long j = 0; j < n; j++) c->color_ptr[c->color[j] + 1]++;
  for (long k = 0; k < ncolors; k++) c->color_ptr[k + 1] += c->color_ptr[k];
  memset(fill, 0, (size_t)n * sizeof *fill);
  for (long j = 0; j < n; j++) {
    int k = c->color[j];
    c->color_col[c->color_ptr[k] + fill[k]++] = j;
  }
done:
  grouping_free(&cols);
  grouping_free(&rows);
  free(l.col_ptr);
  free(l.row_of);
  free(l.row_ptr);
  free(l.col_of);
  free(near);
  free(start);
  free(seen);
  free(taken);
  free(fill);
  free(rank);
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
