/* pm_fe: the finite-element reference of a block case read from its text
 * files (ladder, lattice, claimed tolerances); pm_fe_errors.c compares a
 * run with it. */
#include "pm_fe.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_COLS 32
#define SHOW_MAX 60 /* bytes of a bad field quoted in errors */

/* ---- Tables with a header line ------------------------------------------ */

/* A CSV file read row by row: the header's column names, then each data
 * line split into as many fields. */
typedef struct {
  pm_lines in;
  const char *what;
  int ncol;
  char names[MAX_COLS][PM_FE_TEXT_MAX];
  char *f[MAX_COLS]; /* the current row's fields */
} table;

static pm_err table_open(table *t, const char *path, const char *what) {
  char *s;
  t->what = what;
  PM_CALL(pm_lines_open(&t->in, path, what));
  PM_CALL(pm_lines_next(&t->in, &s));
  PM_CHECK(s, PM_ERR_ARG, "%s '%s' is empty: expected a header line", what,
           path);
  t->ncol = pm_split_fields(s, t->f, MAX_COLS);
  PM_CHECK(t->ncol <= MAX_COLS, PM_ERR_ARG,
           "%s:%ld: expected at most %d columns in the header", path,
           t->in.line, MAX_COLS);
  for (int c = 0; c < t->ncol; c++) {
    PM_CHECK(t->f[c][0] && strlen(t->f[c]) < PM_FE_TEXT_MAX, PM_ERR_ARG,
             "%s:%ld: expected column names of 1 to %d characters in the "
             "header, got '%.*s'",
             path, t->in.line, PM_FE_TEXT_MAX - 1, SHOW_MAX, t->f[c]);
    strcpy(t->names[c], t->f[c]);
  }
  return PM_SUCCESS;
}

/* Index of column name, -1 when the header lacks it. */
static int table_column(const table *t, const char *name) {
  for (int c = 0; c < t->ncol; c++)
    if (strcmp(t->names[c], name) == 0) return c;
  return -1;
}

static pm_err table_require(const table *t, const char *name, int *col) {
  *col = table_column(t, name);
  PM_CHECK(*col >= 0, PM_ERR_ARG,
           "%s:%ld: expected a column '%s' in the header", t->in.path,
           t->in.line, name);
  return PM_SUCCESS;
}

/* The next row into t->f; *more false at the end of the file. */
static pm_err table_next(table *t, bool *more) {
  char *s;
  PM_CALL(pm_lines_next(&t->in, &s));
  *more = s != NULL;
  if (!s) return PM_SUCCESS;
  int n = pm_split_fields(s, t->f, MAX_COLS);
  PM_CHECK(n == t->ncol, PM_ERR_ARG,
           "%s:%ld: expected %d comma-separated fields as in the header, got "
           "%s%d",
           t->in.path, t->in.line, t->ncol, n > MAX_COLS ? "more than " : "",
           n > MAX_COLS ? MAX_COLS : n);
  return PM_SUCCESS;
}

/* Field col of the current row as a number (finite unless nan_ok). */
static pm_err table_number(const table *t, int col, bool nan_ok, double *v) {
  bool ok = pm_parse_number(t->f[col], v) && (isfinite(*v) || nan_ok);
  PM_CHECK(ok, PM_ERR_ARG, "%s:%ld: column %s: expected a %snumber, got '%.*s'",
           t->in.path, t->in.line, t->names[col], nan_ok ? "" : "finite ",
           SHOW_MAX, t->f[col]);
  return PM_SUCCESS;
}

static pm_err table_count(const table *t, int col, long lo, long *v) {
  double d;
  PM_CALL(table_number(t, col, false, &d));
  PM_CHECK(d == floor(d) && d >= (double)lo && d < 1e15, PM_ERR_ARG,
           "%s:%ld: column %s: expected a whole number >= %ld, got '%s'",
           t->in.path, t->in.line, t->names[col], lo, t->f[col]);
  *v = (long)d;
  return PM_SUCCESS;
}

static pm_err table_text(const table *t, int col, char *dst) {
  PM_CHECK(t->f[col][0] && strlen(t->f[col]) < PM_FE_TEXT_MAX, PM_ERR_ARG,
           "%s:%ld: column %s: expected text of 1 to %d characters, got "
           "'%.*s'",
           t->in.path, t->in.line, t->names[col], PM_FE_TEXT_MAX - 1, SHOW_MAX,
           t->f[col]);
  strcpy(dst, t->f[col]);
  return PM_SUCCESS;
}

/* ---- ladder.csv ---------------------------------------------------------- */

enum {
  C_N,
  C_NODES,
  C_DOFS,
  C_ELEMENT,
  C_H,
  C_RX,
  C_RY,
  C_RZ,
  C_SED,
  C_VM,
  C_INCREMENTS,
  C_WALL,
  C_VERSION,
  C_REQUIRED, /* the columns above are required, those below optional */
  C_FRACTION = C_REQUIRED,
  C_STATUS,
  C_TIP_FACE,
  C_TIP_AXIS,
  C_TIP_U,
  C_CPU,
  C_MEMORY,
  C_COUNT
};
static const char *const ladder_columns[C_COUNT] = {
    "N",           "nodes",
    "dofs",        "element",
    "h",           "reaction_x",
    "reaction_y",  "reaction_z",
    "mean_sed",    "von_mises_centre",
    "increments",  "wall_seconds",
    "ccx_version", "load_fraction",
    "status",      "tip_face",
    "tip_axis",    "tip_u",
    "cpu_seconds", "peak_memory_bytes"};

/* A traction case's tip columns: face name and component into indices
 * (-1 when the ladder has none). */
static pm_err tip_columns(const table *t, const int *col, int *face,
                          int *axis) {
  static const char *const faces[] = {"xmin", "xmax", "ymin",
                                      "ymax", "zmin", "zmax"};
  *face = *axis = -1;
  if (col[C_TIP_FACE] < 0 && col[C_TIP_AXIS] < 0 && col[C_TIP_U] < 0)
    return PM_SUCCESS;
  PM_CHECK(col[C_TIP_FACE] >= 0 && col[C_TIP_AXIS] >= 0 && col[C_TIP_U] >= 0,
           PM_ERR_ARG,
           "%s:%ld: expected the columns tip_face, tip_axis and tip_u "
           "together",
           t->in.path, t->in.line);
  const char *f = t->f[col[C_TIP_FACE]], *a = t->f[col[C_TIP_AXIS]];
  for (int k = 0; k < 6; k++)
    if (strcmp(f, faces[k]) == 0) *face = k;
  PM_CHECK(*face >= 0, PM_ERR_ARG,
           "%s:%ld: column tip_face: expected xmin, xmax, ymin, ymax, zmin "
           "or zmax, got '%.*s'",
           t->in.path, t->in.line, SHOW_MAX, f);
  PM_CHECK(strlen(a) == 1 && a[0] >= 'x' && a[0] <= 'z', PM_ERR_ARG,
           "%s:%ld: column tip_axis: expected x, y or z, got '%.*s'",
           t->in.path, t->in.line, SHOW_MAX, a);
  *axis = a[0] - 'x';
  return PM_SUCCESS;
}

static pm_err ladder_row(const table *t, const int *col, pm_fe_row *r) {
  long v;
  PM_CALL(table_count(t, col[C_N], 1, &v));
  r->n = (int)v;
  PM_CALL(table_count(t, col[C_NODES], 1, &r->nodes));
  PM_CALL(table_count(t, col[C_DOFS], 1, &r->dofs));
  PM_CALL(table_count(t, col[C_INCREMENTS], 0, &r->increments));
  PM_CALL(table_text(t, col[C_ELEMENT], r->element));
  PM_CALL(table_text(t, col[C_VERSION], r->ccx_version));
  r->load_fraction = 1.0;
  if (col[C_FRACTION] >= 0)
    PM_CALL(table_number(t, col[C_FRACTION], false, &r->load_fraction));
  r->converged = r->load_fraction == 1.0;
  if (col[C_STATUS] >= 0) {
    const char *s = t->f[col[C_STATUS]];
    PM_CHECK(strcmp(s, "converged") == 0 || strcmp(s, "stopped") == 0,
             PM_ERR_ARG,
             "%s:%ld: column status: expected converged or stopped, got "
             "'%.*s'",
             t->in.path, t->in.line, SHOW_MAX, s);
    r->converged = strcmp(s, "converged") == 0;
  }
  /* A run stopped short of the load may lack figures; a converged one
   * has them all. */
  bool nan_ok = !r->converged;
  PM_CALL(table_number(t, col[C_H], false, &r->h));
  PM_CALL(table_number(t, col[C_WALL], false, &r->wall_seconds));
  for (int k = 0; k < 3; k++)
    PM_CALL(table_number(t, col[C_RX + k], nan_ok, &r->reaction[k]));
  PM_CALL(table_number(t, col[C_SED], nan_ok, &r->mean_sed));
  PM_CALL(table_number(t, col[C_VM], nan_ok, &r->von_mises_centre));
  r->tip_u = r->cpu_seconds = r->memory_bytes = NAN;
  if (col[C_TIP_U] >= 0)
    PM_CALL(table_number(t, col[C_TIP_U], nan_ok, &r->tip_u));
  if (col[C_CPU] >= 0)
    PM_CALL(table_number(t, col[C_CPU], true, &r->cpu_seconds));
  if (col[C_MEMORY] >= 0)
    PM_CALL(table_number(t, col[C_MEMORY], true, &r->memory_bytes));
  PM_CHECK(r->h > 0, PM_ERR_ARG,
           "%s:%ld: column h: expected a size > 0, got %g", t->in.path,
           t->in.line, r->h);
  return PM_SUCCESS;
}

static pm_err read_ladder(const char *path, pm_fe_reference *r) {
  pm_err ret = PM_SUCCESS;
  table t = {.ncol = 0};
  int col[C_COUNT];
  bool more;
  PM_TRY(table_open(&t, path, "FE ladder"));
  for (int c = 0; c < C_COUNT; c++) {
    if (c < C_REQUIRED)
      PM_TRY(table_require(&t, ladder_columns[c], &col[c]));
    else
      col[c] = table_column(&t, ladder_columns[c]);
  }
  r->finest = r->previous = -1;
  for (;;) {
    PM_TRY(table_next(&t, &more));
    if (!more) break;
    pm_fe_row *rows = realloc(r->rows, (size_t)(r->n_rows + 1) * sizeof *rows);
    PM_ENSURE(rows, PM_ERR_MEMORY, "out of memory for the rows of '%s'", path);
    r->rows = rows;
    pm_fe_row *row = &r->rows[r->n_rows];
    memset(row, 0, sizeof *row);
    PM_TRY(ladder_row(&t, col, row));
    PM_TRY(tip_columns(&t, col, &r->tip_face, &r->tip_axis));
    PM_ENSURE(r->n_rows == 0 || row->h < r->rows[r->n_rows - 1].h, PM_ERR_ARG,
              "%s:%ld: expected the meshes from coarsest to finest (h %g after "
              "%g)",
              path, t.in.line, row->h, r->rows[r->n_rows - 1].h);
    if (row->converged) {
      r->previous = r->finest;
      r->finest = r->n_rows;
    }
    r->n_rows++;
  }
done:
  pm_lines_close(&t.in);
  return ret;
}

/* ---- lattice.csv -----------------------------------------------------------
 */

pm_err pm_fe_read_lattice(const char *path, long *n, double **x, double **u) {
  static const char *const names[6] = {"x", "y", "z", "u_x", "u_y", "u_z"};
  pm_err ret = PM_SUCCESS;
  table t = {.ncol = 0};
  long cap = 0, m = 0;
  double *px = NULL, *pu = NULL;
  bool more;
  PM_TRY(table_open(&t, path, "FE lattice"));
  bool header = t.ncol == 6;
  for (int c = 0; header && c < 6; c++) header = !strcmp(t.names[c], names[c]);
  PM_ENSURE(header, PM_ERR_ARG, "%s:%ld: expected the header x,y,z,u_x,u_y,u_z",
            path, t.in.line);
  for (;;) {
    PM_TRY(table_next(&t, &more));
    if (!more) break;
    if (m == cap) {
      cap = cap ? 2 * cap : 256;
      double *nx = realloc(px, (size_t)cap * 3 * sizeof *nx);
      if (nx) px = nx;
      double *nu = nx ? realloc(pu, (size_t)cap * 3 * sizeof *nu) : NULL;
      if (nu) pu = nu;
      PM_ENSURE(nx && nu, PM_ERR_MEMORY,
                "out of memory for the lattice of '%s'", path);
    }
    for (int c = 0; c < 3; c++) {
      PM_TRY(table_number(&t, c, false, &px[3 * m + c]));
      PM_TRY(table_number(&t, 3 + c, false, &pu[3 * m + c]));
    }
    m++;
  }
  PM_ENSURE(m > 0, PM_ERR_ARG, "FE lattice '%s' holds no points", path);
  *n = m;
  *x = px;
  *u = pu;
  px = pu = NULL;
done:
  free(px);
  free(pu);
  pm_lines_close(&t.in);
  return ret;
}

/* ---- tolerance.csv ---------------------------------------------------------
 */

/* The k-th quantity of a pm_fe_tolerance (reaction, mean_sed,
 * von_mises_centre, lattice_nrmse, tip). */
static double *quantity(pm_fe_tolerance *q, int k) {
  double *v[] = {&q->reaction, &q->mean_sed, &q->von_mises_centre,
                 &q->lattice_nrmse, &q->tip};
  return v[k];
}

/* An optional numeric field (col < 0 or empty: NaN). */
static pm_err table_optional(const table *t, int col, double *v) {
  *v = NAN;
  if (col < 0 || !t->f[col][0]) return PM_SUCCESS;
  return table_number(t, col, false, v);
}

static pm_err read_tolerance(const char *path, pm_fe_reference *r) {
  static const char *const names[] = {
      "reaction", "mean_sed", "von_mises_centre", "lattice_nrmse", "tip"};
  pm_err ret = PM_SUCCESS;
  table t = {.ncol = 0};
  int cq, ct;
  bool more;
  PM_TRY(table_open(&t, path, "FE tolerance"));
  PM_TRY(table_require(&t, "quantity", &cq));
  PM_TRY(table_require(&t, "tolerance", &ct));
  const int ce = table_column(&t, "extrapolated");
  const int cu = table_column(&t, "extrapolation_uncertainty");
  const int cs = table_column(&t, "estimated_error");
  for (;;) {
    PM_TRY(table_next(&t, &more));
    if (!more) break;
    int k = 0;
    while (k < 5 && strcmp(t.f[cq], names[k])) k++;
    PM_ENSURE(k < 5, PM_ERR_ARG,
              "%s:%ld: column quantity: expected reaction, mean_sed, "
              "von_mises_centre, lattice_nrmse or tip, got '%.*s'",
              path, t.in.line, SHOW_MAX, t.f[cq]);
    double *dst = quantity(&r->tolerance, k);
    PM_TRY(table_number(&t, ct, false, dst));
    PM_ENSURE(*dst > 0, PM_ERR_ARG,
              "%s:%ld: column tolerance: expected a number > 0, got %g", path,
              t.in.line, *dst);
    PM_TRY(table_optional(&t, ce, quantity(&r->extrapolated, k)));
    PM_TRY(table_optional(&t, cu, quantity(&r->extrapolation_uncertainty, k)));
    PM_TRY(table_optional(&t, cs, quantity(&r->estimated_error, k)));
  }
done:
  pm_lines_close(&t.in);
  return ret;
}

/* ---- the reference ----------------------------------------------------------
 */

static bool is_file(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

pm_err pm_fe_load(const char *dir, pm_fe_reference **out) {
  pm_err ret = PM_SUCCESS;
  pm_fe_reference *r = NULL;
  char path[PM_PATH_MAX + 1];
  *out = NULL;
  PM_TRY(PM_ALLOC(r, 1, "FE reference"));
  r->tolerance = (pm_fe_tolerance){NAN, NAN, NAN, NAN, NAN};
  r->extrapolated = r->extrapolation_uncertainty = r->tolerance;
  r->estimated_error = r->tolerance;
  size_t len = strlen(dir);
  while (len > 1 && dir[len - 1] == '/') len--;
  PM_ENSURE(len <= PM_PATH_MAX, PM_ERR_ARG,
            "FE folder name too long: '%.64s...'", dir);
  memcpy(r->dir, dir, len);
  const char *base = strrchr(r->dir, '/');
  base = base ? base + 1 : r->dir;
  PM_ENSURE(strlen(base) < sizeof r->name, PM_ERR_ARG,
            "FE folder name '%s' is longer than %zu characters", base,
            sizeof r->name - 1);
  memcpy(r->name, base, strlen(base) + 1);
  r->tip_face = r->tip_axis = -1;
  PM_TRY(pm_path_join(path, sizeof path, r->dir, "ladder.csv"));
  PM_TRY(read_ladder(path, r));
  PM_ENSURE(r->finest >= 0, PM_ERR_ARG,
            "FE ladder '%s' holds no mesh that reached the full load", path);
  PM_TRY(pm_path_join(path, sizeof path, r->dir, "lattice.csv"));
  PM_TRY(pm_fe_read_lattice(path, &r->n, &r->x, &r->u));
  PM_TRY(pm_path_join(path, sizeof path, r->dir, "tolerance.csv"));
  if (is_file(path)) PM_TRY(read_tolerance(path, r));
  const pm_fe_row *f = &r->rows[r->finest];
  memcpy(r->reaction, f->reaction, sizeof r->reaction);
  r->mean_sed = f->mean_sed;
  r->von_mises_centre = f->von_mises_centre;
  r->tip_u = f->tip_u;
  /* A Richardson limit stands for the solution where it is surer than the
   * finest mesh: its uncertainty below the finest mesh's estimated error
   * (with three meshes only it never is).  The reaction along the loaded
   * (largest) component. */
  int axis = 0;
  for (int c = 1; c < 3; c++)
    if (fabs(f->reaction[c]) > fabs(f->reaction[axis])) axis = c;
  double *fig[] = {&r->reaction[axis], &r->mean_sed, &r->von_mises_centre, NULL,
                   &r->tip_u};
  for (int k = 0; k < 5; k++) {
    const double lim = *quantity(&r->extrapolated, k);
    const double unc = *quantity(&r->extrapolation_uncertainty, k);
    if (fig[k] && isfinite(lim) && unc < *quantity(&r->estimated_error, k))
      *fig[k] = lim;
  }
  PM_ENSURE(r->tip_face < 0 || isfinite(r->tip_u), PM_ERR_ARG,
            "%s/ladder.csv: the finest converged mesh (N = %d) has no tip_u",
            r->dir, f->n);
  double lo[3], hi[3];
  for (int c = 0; c < 3; c++) lo[c] = hi[c] = r->x[c];
  for (long i = 1; i < r->n; i++)
    for (int c = 0; c < 3; c++) {
      lo[c] = fmin(lo[c], r->x[3 * i + c]);
      hi[c] = fmax(hi[c], r->x[3 * i + c]);
    }
  for (int c = 0; c < 3; c++) r->centre[c] = 0.5 * (lo[c] + hi[c]);
  r->dim = lo[2] == 0.0 && hi[2] == 0.0 ? 2 : 3;
  *out = r;
  r = NULL;
done:
  pm_fe_free(r);
  return ret;
}

pm_err pm_fe_read_ladder(const char *path, pm_fe_row **rows, int *n_rows) {
  pm_err ret = PM_SUCCESS;
  pm_fe_reference r = {.n_rows = 0};
  *rows = NULL;
  *n_rows = 0;
  PM_TRY(read_ladder(path, &r));
  *rows = r.rows;
  *n_rows = r.n_rows;
  r.rows = NULL;
done:
  free(r.rows);
  return ret;
}

void pm_fe_free(pm_fe_reference *r) {
  if (!r) return;
  free(r->rows);
  free(r->x);
  free(r->u);
  free(r);
}

bool pm_fe_names_reference(const char *spec, char *buf, size_t size) {
  char path[PM_PATH_MAX + 1];
  if (!spec) return false;
  if (strncmp(spec, "fe:", 3) == 0) {
    if (!spec[3]) return false;
    return (size_t)snprintf(buf, size, "%s", spec + 3) < size;
  }
  if (pm_path_join(path, sizeof path, spec, "ladder.csv") != PM_SUCCESS) {
    pm_error_clear();
    return false;
  }
  if (!is_file(path)) return false;
  return (size_t)snprintf(buf, size, "%s", spec) < size;
}
