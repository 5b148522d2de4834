/* pm_coloring: a square sparsity pattern in canonical form, and the greedy
 * distance-2 column colouring that assembles a Jacobian from one
 * directional derivative per colour. */
#ifndef PM_COLORING_H
#define PM_COLORING_H

#include <stdbool.h>

#include "pm_error.h"

/* Rows of an n x n pattern with sorted, unique columns. */
typedef struct {
  long n;
  long *ptr; /* n + 1 */
  long *idx; /* ptr[n] */
  /* Where each entry of the pattern it was built from went: entry k of
   * the source is idx[src[k]] (duplicates share a place), and the
   * source's rows: row i's entries are sptr[i] .. sptr[i + 1] (n + 1).
   * Both NULL where the source is the pattern itself (its rows sorted,
   * unique and holding the diagonal where it is added): src[k] = k. */
  long *src, *sptr;
  long nsrc; /* entries of the source */
} pm_pattern;

/* Canonical form of the CSR pattern ptr/idx over n unknowns (columns
 * unsorted, repeated, or missing the diagonal are allowed), with the
 * diagonal added when diagonal is true.  PM_ERR_ARG naming the row when
 * ptr is not non-decreasing from 0 or a column is outside [0, n). */
pm_err pm_pattern_build(long n, const long *ptr, const long *idx, bool diagonal,
                        pm_pattern *p);
/* The same checks alone: PM_ERR_ARG naming the row as above, else
 * PM_SUCCESS. */
pm_err pm_pattern_check(long n, const long *ptr, const long *idx);
void pm_pattern_free(pm_pattern *p);
/* row[0 .. len) in increasing order. */
void pm_pattern_sort_row(long *row, long len);

/* Largest number of entries in a row. */
long pm_pattern_max_row(const pm_pattern *p);

/* Order in which the greedy colouring visits columns. */
typedef enum {
  PM_COLORING_LARGEST_FIRST = 0, /* most distance-2 neighbours first */
  PM_COLORING_NATURAL            /* index order */
} pm_coloring_order;

/* Columns in colours such that no two columns of one colour share a row:
 * J e_c (e_c: ones on colour c's columns) then holds J_ij at row i for the
 * one column j of colour c in row i. */
typedef struct {
  int ncolors;
  int *color;      /* per column */
  long *color_ptr; /* ncolors + 1: colour c's columns are */
  long *color_col; /* color_col[color_ptr[c] .. color_ptr[c + 1]) */
  /* The pattern by columns: column j's rows col_row[col_ptr[j] ..] and
   * the places of those entries in the row pattern's idx. */
  long *col_ptr, *col_row, *col_pos;
} pm_coloring;

/* Greedy colouring of p (each column takes the smallest colour free of
 * the columns it shares a row with), visiting columns in the order
 * given. */
pm_err pm_coloring_build(const pm_pattern *p, pm_coloring_order order,
                         pm_coloring *c);
void pm_coloring_free(pm_coloring *c);

#endif
