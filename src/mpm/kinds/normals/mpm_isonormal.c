/* mpm_isonormal: normals of a surface known only by unconnected points, from
 * a B-spline function phi fitted to 1 at the points and 0 at a random point
 * of their element (the paper's sections 3 and 5). */
#include "mpm_isonormal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* S is taken as rank deficient below this reciprocal condition number (of
 * R, LAPACK's 1-norm estimate, or of S's singular values), i.e. above
 * cond(T) ~ 1e26.  The entries of S are B-spline values, of order one,
 * so round-off puts a truly dependent column at rcond ~ 1e-16 or below,
 * while the worst full-rank draws of the paper's Table I (cond(T) 7e16,
 * rcond(S) ~ 4e-9) stay far above: three orders of magnitude of margin on
 * either side.  Below it the system is solved in the minimum-norm sense. */
#define RCOND_MIN 1e-13
/* |grad phi| H below this is no gradient: phi ~ 1 at the points, so its
 * logical gradient is of order one where the surface is resolved. */
/* Rows a workspace may hold (the matrix is 2^20 x 27 doubles at most). */
#define MAX_POINTS_LIMIT (1 << 20)
#define MAX_UNKNOWNS 27

/* All arrays are column-major: LAPACKE's _work routines transpose a
 * row-major matrix into a buffer they allocate, column-major ones pass
 * straight to LAPACK. */
struct mpm_iso_work {
  mpm_iso_config c;
  int nu;       /* unknowns */
  int lds;      /* rows S holds: max_points + the random and extra point */
  int ldr;      /* length of r: max(lds, nu) (dgelsy returns nu values) */
  double *S;    /* lds x nu: B-spline values at the points, then the draws */
  double *b;    /* lds: phi wanted at each row */
  double *A;    /* lds x nu: S as LAPACK factorises it */
  double *r;    /* ldr: the right side, then the solution */
  double *tau;  /* nu: QR's reflectors */
  double *sv;   /* nu: singular values */
  double *T;    /* nu x nu: S^T S, for the normal equations */
  double *work; /* lwork: every routine's workspace */
  lapack_int lwork;
  lapack_int *jpvt;          /* nu: dgelsy's column pivots */
  lapack_int *ipiv;          /* nu: dsysv's pivots */
  lapack_int *iwork;         /* nu: dtrcon */
  double coef[MAX_UNKNOWNS]; /* phi of the last fit */
  double kept[MAX_UNKNOWNS]; /* phi of the best draw so far */
  double lo[3], H;           /* the element of the last fit */
};

mpm_iso_config mpm_iso_config_default(int dim, int order) {
  return (mpm_iso_config){.dim = dim,
                          .order = order,
                          .max_points = 256,
                          .max_condition = 1e12,
                          .max_draws = 4,
                          .min_gradient = 0.1};
}

int mpm_iso_unknowns(int dim, int order) {
  if ((dim != 2 && dim != 3) || (order != 1 && order != 2)) return 0;
  int k = order + 1, n = 1;
  for (int c = 0; c < dim; c++) n *= k;
  return n;
}

int mpm_iso_hybrid_order(int dim, long n) {
  if (n + 1 >= mpm_iso_unknowns(dim, 2)) return 2;
  if (n + 1 >= mpm_iso_unknowns(dim, 1)) return 1;
  return 0;
}

void mpm_iso_work_destroy(mpm_iso_work *w) {
  if (!w) return;
  free(w->S);
  free(w->b);
  free(w->A);
  free(w->r);
  free(w->tau);
  free(w->sv);
  free(w->T);
  free(w->work);
  free(w->jpvt);
  free(w->ipiv);
  free(w->iwork);
  free(w);
}

size_t mpm_iso_work_bytes(const mpm_iso_work *w) {
  if (!w) return 0;
  const size_t d = sizeof(double), nu = (size_t)w->nu, lds = (size_t)w->lds;
  return sizeof *w +
         d * (2 * lds * nu + lds + (size_t)w->ldr + 2 * nu + nu * nu +
              (size_t)w->lwork) +
         3 * nu * sizeof(lapack_int);
}

/* A LAPACK info as an error: negative names a bad argument (a bug here),
 * positive a numerical failure of the routine. */
static pm_err lapack_check(const char *routine, lapack_int info) {
  if (info < 0)
    return PM_ERROR(PM_ERR_LINALG, "LAPACKE_%s_work: argument %d is invalid",
                    routine, (int)-info);
  if (info > 0)
    return PM_ERROR(PM_ERR_LINALG, "LAPACKE_%s_work failed (info %d)", routine,
                    (int)info);
  return PM_SUCCESS;
}

/* Raise *lwork to the optimum a workspace query (lwork = -1) reports. */
static pm_err raise_lwork(const char *routine, lapack_int info, double q,
                          lapack_int *lwork) {
  PM_CALL(lapack_check(routine, info));
  if (q > *lwork) *lwork = (lapack_int)q;
  return PM_SUCCESS;
}

/* Raise *lwork to what every routine a fit may call wants for m rows. */
static pm_err query_rows(mpm_iso_work *w, int m, lapack_int *lwork) {
  const int nu = w->nu;
  double q = 0;
  lapack_int rank = 0;
  if (m >= nu) {
    PM_CALL(raise_lwork("dgeqrf",
                        LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, m, nu, w->A,
                                            w->lds, w->tau, &q, -1),
                        q, lwork));
    PM_CALL(raise_lwork("dormqr",
                        LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', m, 1,
                                            nu, w->A, w->lds, w->tau, w->r,
                                            w->ldr, &q, -1),
                        q, lwork));
  }
  PM_CALL(raise_lwork("dgelsy",
                      LAPACKE_dgelsy_work(LAPACK_COL_MAJOR, m, nu, 1, w->A,
                                          w->lds, w->r, w->ldr, w->jpvt,
                                          RCOND_MIN, &rank, &q, -1),
                      q, lwork));
  PM_CALL(
      raise_lwork("dgesvd",
                  LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, 'N', 'N', m, nu, w->A,
                                      w->lds, w->sv, NULL, 1, NULL, 1, &q, -1),
                  q, lwork));
  return PM_SUCCESS;
}

/* The largest optimal workspace over every row count a fit may have.  The
 * requirements stop growing with m a few times nu on (dgesvd's is largest
 * just below its QR-first threshold, ~1.6 nu), so the counts up to 4 nu and
 * lds itself cover them. */
static pm_err query_lwork(mpm_iso_work *w) {
  const int nu = w->nu, mtop = w->lds < 4 * nu ? w->lds : 4 * nu;
  lapack_int lwork = 3 * nu; /* dtrcon's */
  for (int m = 1; m <= mtop; m++) PM_CALL(query_rows(w, m, &lwork));
  if (w->lds > mtop) PM_CALL(query_rows(w, w->lds, &lwork));
  double q = 0;
  PM_CALL(raise_lwork("dsysv",
                      LAPACKE_dsysv_work(LAPACK_COL_MAJOR, 'U', nu, 1, w->T, nu,
                                         w->ipiv, w->r, nu, &q, -1),
                      q, &lwork));
  w->lwork = lwork;
  return PM_SUCCESS;
}

pm_err mpm_iso_work_create(const mpm_iso_config *c, mpm_iso_work **out) {
  PM_CHECK(c && out, PM_ERR_ARG, "mpm_iso_work_create: NULL argument");
  *out = NULL;
  PM_CHECK(c->dim == 2 || c->dim == 3, PM_ERR_ARG,
           "isonormal: dim must be 2 or 3 (got %d)", c->dim);
  PM_CHECK(c->order == 1 || c->order == 2, PM_ERR_ARG,
           "isonormal: order must be 1 (linear) or 2 (quadratic) (got %d)",
           c->order);
  PM_CHECK(c->max_points >= 1 && c->max_points <= MAX_POINTS_LIMIT, PM_ERR_ARG,
           "isonormal: max_points must be in [1, %d] (got %d)",
           MAX_POINTS_LIMIT, c->max_points);
  PM_CHECK(c->max_draws >= 1, PM_ERR_ARG,
           "isonormal: max_draws must be >= 1 (got %d)", c->max_draws);
  PM_CHECK(c->max_condition > 0, PM_ERR_ARG,
           "isonormal: max_condition must be > 0 (got %g)", c->max_condition);
  pm_err ret = PM_SUCCESS;
  mpm_iso_work *w = NULL;
  PM_TRY(PM_ALLOC(w, 1, "isonormal workspace"));
  w->c = *c;
  w->nu = mpm_iso_unknowns(c->dim, c->order);
  w->lds = c->max_points + 2;
  w->ldr = w->lds > w->nu ? w->lds : w->nu;
  w->H = 1;
  const size_t nu = (size_t)w->nu, lds = (size_t)w->lds;
  PM_TRY(PM_ALLOC(w->S, lds * nu, "isonormal matrix"));
  PM_TRY(PM_ALLOC(w->b, lds, "isonormal right side"));
  PM_TRY(PM_ALLOC(w->A, lds * nu, "isonormal factors"));
  PM_TRY(PM_ALLOC(w->r, w->ldr, "isonormal solution"));
  PM_TRY(PM_ALLOC(w->tau, nu, "isonormal reflectors"));
  PM_TRY(PM_ALLOC(w->sv, nu, "isonormal singular values"));
  PM_TRY(PM_ALLOC(w->T, nu * nu, "isonormal normal equations"));
  PM_TRY(PM_ALLOC(w->jpvt, nu, "isonormal pivots"));
  PM_TRY(PM_ALLOC(w->ipiv, nu, "isonormal pivots"));
  PM_TRY(PM_ALLOC(w->iwork, nu, "isonormal integer workspace"));
  PM_TRY(query_lwork(w));
  PM_TRY(PM_ALLOC(w->work, w->lwork, "LAPACK workspace"));
  *out = w;
  w = NULL;
done:
  mpm_iso_work_destroy(w);
  return ret;
}

/* ---- B-splines --------------------------------------------------------- */

/* The 1-D functions of the element at logical u, values v and derivatives
 * dv.  On [0, 1] these are the paper's N1(u - i), i = 0, 1, and N2(u - c),
 * c = -1/2, 1/2, 3/2; outside it they are the same polynomial pieces
 * continued, which is what the element's unknowns alone represent: a point
 * slightly outside the element sees the function phi the fit makes, and
 * what the element reproduces exactly (a line, a circle) it reproduces
 * there too. */
static void pieces(int order, double u, double *v, double *dv) {
  if (order == 1) {
    v[0] = 1 - u;
    v[1] = u;
    dv[0] = -1;
    dv[1] = 1;
  } else {
    v[0] = 0.5 * (1 - u) * (1 - u);
    v[1] = 0.75 - (u - 0.5) * (u - 0.5);
    v[2] = 0.5 * u * u;
    dv[0] = u - 1;
    dv[1] = 1 - 2 * u;
    dv[2] = u;
  }
}

/* The 1-D functions of each axis at logical xi; in 2-D the z axis has one
 * function, 1. */
static void axes(int dim, int order, const double xi[3], double v[3][3],
                 double dv[3][3]) {
  memset(v, 0, sizeof(double[3][3]));
  memset(dv, 0, sizeof(double[3][3]));
  v[2][0] = 1;
  for (int c = 0; c < dim; c++) pieces(order, xi[c], v[c], dv[c]);
}

/* The tensor-product functions at logical xi: val[a], a = i + k (j + k l)
 * with k = order + 1 (l = 0 in 2-D). */
static void tensor(int dim, int order, const double xi[3], double *val) {
  double v[3][3], dv[3][3];
  axes(dim, order, xi, v, dv);
  const int k = order + 1, kz = dim == 3 ? k : 1;
  for (int l = 0; l < kz; l++)
    for (int j = 0; j < k; j++)
      for (int i = 0; i < k; i++)
        val[i + k * (j + k * l)] = v[0][i] * v[1][j] * v[2][l];
}

/* phi of coefficients coef at logical xi, and its logical gradient g,
 * summed over x first and then over y and z. */
static double evaluate(const mpm_iso_work *w, const double *coef,
                       const double xi[3], double g[3]) {
  double v[3][3], dv[3][3], phi = 0;
  axes(w->c.dim, w->c.order, xi, v, dv);
  const int k = w->c.order + 1, kz = w->c.dim == 3 ? k : 1;
  g[0] = g[1] = g[2] = 0;
  for (int l = 0; l < kz; l++)
    for (int j = 0; j < k; j++) {
      const double *cx = coef + k * (j + k * l);
      double s = 0, t = 0;
      for (int i = 0; i < k; i++) {
        s += cx[i] * v[0][i];
        t += cx[i] * dv[0][i];
      }
      phi += s * v[1][j] * v[2][l];
      g[0] += t * v[1][j] * v[2][l];
      g[1] += s * dv[1][j] * v[2][l];
      g[2] += s * v[1][j] * dv[2][l];
    }
  return phi;
}

static void logical(const mpm_iso_work *w, const double *x, double xi[3]) {
  xi[2] = 0;
  for (int c = 0; c < w->c.dim; c++) xi[c] = (x[c] - w->lo[c]) / w->H;
}

/* Row r of the system: phi(xi) = value. */
static void put_row(mpm_iso_work *w, int r, const double xi[3], double value) {
  double val[MAX_UNKNOWNS];
  tensor(w->c.dim, w->c.order, xi, val);
  for (int a = 0; a < w->nu; a++) w->S[r + (size_t)w->lds * a] = val[a];
  w->b[r] = value;
}

/* ---- The random point -------------------------------------------------- */

static const uint64_t GOLDEN = 0x9E3779B97F4A7C15u;

uint64_t mpm_iso_mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
  return z ^ (z >> 31);
}

/* Coordinate c of draw d (c 0-2 the random point, 3-5 the extra point),
 * uniform in [0, 1): a function of (seed, d, c) alone, so a fit does not
 * depend on which thread runs it or what ran before. */
static double uniform(uint64_t seed, int d, int c) {
  const uint64_t key = mpm_iso_mix(seed + GOLDEN);
  const uint64_t z =
      mpm_iso_mix(key + ((uint64_t)d * 8 + (uint64_t)c + 1) * GOLDEN);
  return (double)(z >> 11) * 0x1.0p-53;
}

/* ---- Solving ----------------------------------------------------------- */

/* A = S and r = b over the first m rows (LAPACK destroys both). */
static void copy_system(mpm_iso_work *w, int m) {
  const size_t lds = (size_t)w->lds;
  for (int a = 0; a < w->nu; a++)
    memcpy(w->A + lds * a, w->S + lds * a, sizeof(double) * (size_t)m);
  memset(w->r, 0, sizeof(double) * (size_t)w->ldr);
  memcpy(w->r, w->b, sizeof(double) * (size_t)m);
}

/* cond(T) = (smax / smin)^2 from S's singular values and the rank they
 * show; INFINITY when S is rank deficient. */
static pm_err singular_values(mpm_iso_work *w, int m, double *cond, int *rank) {
  copy_system(w, m);
  double dummy = 0;
  PM_CALL(lapack_check("dgesvd",
                       LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, 'N', 'N', m, w->nu,
                                           w->A, w->lds, w->sv, &dummy, 1,
                                           &dummy, 1, w->work, w->lwork)));
  const int k = m < w->nu ? m : w->nu;
  *rank = 0;
  for (int i = 0; i < k; i++)
    if (w->sv[i] > RCOND_MIN * w->sv[0]) (*rank)++;
  *cond = INFINITY;
  if (*rank == w->nu) {
    const double ratio = w->sv[0] / w->sv[w->nu - 1];
    *cond = ratio * ratio;
  }
  return PM_SUCCESS;
}

/* The minimum-norm least-squares solution (complete orthogonal
 * factorisation with column pivoting) into r, and its rank. */
static pm_err min_norm(mpm_iso_work *w, int m, int *rank) {
  copy_system(w, m);
  memset(w->jpvt, 0, sizeof(lapack_int) * (size_t)w->nu);
  lapack_int rk = 0;
  PM_CALL(lapack_check("dgelsy",
                       LAPACKE_dgelsy_work(LAPACK_COL_MAJOR, m, w->nu, 1, w->A,
                                           w->lds, w->r, w->ldr, w->jpvt,
                                           RCOND_MIN, &rk, w->work, w->lwork)));
  *rank = (int)rk;
  return PM_SUCCESS;
}

/* T = S^T S and r = S^T b over the first m rows. */
static void normal_system(mpm_iso_work *w, int m) {
  const int nu = w->nu;
  const size_t lds = (size_t)w->lds;
  for (int a = 0; a < nu; a++) {
    const double *sa = w->S + lds * a;
    for (int e = 0; e <= a; e++) {
      const double *se = w->S + lds * e;
      double t = 0;
      for (int p = 0; p < m; p++) t += sa[p] * se[p];
      w->T[e + (size_t)nu * a] = w->T[a + (size_t)nu * e] = t;
    }
    double t = 0;
    for (int p = 0; p < m; p++) t += sa[p] * w->b[p];
    w->r[a] = t;
  }
}

static bool all_finite(const double *v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

/* The normal equations T phi = S^T b (only to compare with QR, the paper's
 * fig. 9b): Cholesky; where round-off leaves the singular T of an
 * underdetermined system not positive definite, the symmetric indefinite
 * factorisation, which solves it with whatever its tiny pivots give, as
 * a normal-equations solver without a rank check does.  Only an exactly
 * zero pivot or a non-finite result keeps the QR coefficients in coef. */
static pm_err solve_normal(mpm_iso_work *w, int m) {
  const int nu = w->nu;
  normal_system(w, m);
  const char *routine = "dposv";
  lapack_int info =
      LAPACKE_dposv_work(LAPACK_COL_MAJOR, 'U', nu, 1, w->T, nu, w->r, nu);
  if (info > 0) {
    normal_system(w, m);
    routine = "dsysv";
    info = LAPACKE_dsysv_work(LAPACK_COL_MAJOR, 'U', nu, 1, w->T, nu, w->ipiv,
                              w->r, nu, w->work, w->lwork);
    if (info > 0) return PM_SUCCESS;
  }
  PM_CALL(lapack_check(routine, info));
  if (all_finite(w->r, nu)) memcpy(w->coef, w->r, sizeof(double) * (size_t)nu);
  return PM_SUCCESS;
}

/* Solve the first m rows for coef and say how well S determines it:
 * cond(T) and the numerical rank.  Full rank and m >= nu: QR (dgeqrf, Q^T b
 * by dormqr, R x = Q^T b by dtrtrs), cond(T) ~ (1 / rcond(R))^2 from
 * dtrcon's 1-norm estimate; otherwise the minimum-norm solution (dgelsy)
 * with cond(T) INFINITY.  exact_condition takes cond(T) and the rank from
 * the singular values instead.  (Factoring the point rows once and
 * appending each draw's row by dtpqrt costs as much as a new dgeqrf at
 * these sizes: LAPACK's dtpqrt takes 7 us for one row of 27 unknowns.) */
static pm_err solve(mpm_iso_work *w, int m, double *cond, int *rank) {
  const int nu = w->nu;
  bool full = false;
  *cond = INFINITY;
  *rank = 0;
  if (w->c.exact_condition) {
    PM_CALL(singular_values(w, m, cond, rank));
    full = *rank == nu;
  }
  double rc = 0;
  if (m >= nu && (full || !w->c.exact_condition)) {
    copy_system(w, m);
    PM_CALL(lapack_check("dgeqrf", LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, m, nu,
                                                       w->A, w->lds, w->tau,
                                                       w->work, w->lwork)));
    if (!w->c.exact_condition) {
      PM_CALL(lapack_check(
          "dtrcon", LAPACKE_dtrcon_work(LAPACK_COL_MAJOR, '1', 'U', 'N', nu,
                                        w->A, w->lds, &rc, w->work, w->iwork)));
      full = rc >= RCOND_MIN;
      if (full) {
        *rank = nu;
        *cond = 1 / (rc * rc);
      }
    }
    if (full) {
      PM_CALL(lapack_check("dormqr",
                           LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', m, 1,
                                               nu, w->A, w->lds, w->tau, w->r,
                                               w->ldr, w->work, w->lwork)));
      /* info > 0 is an exactly zero diagonal of R: the estimate missed a
       * singular R, which the minimum-norm solve below handles. */
      lapack_int info = LAPACKE_dtrtrs_work(LAPACK_COL_MAJOR, 'U', 'N', 'N', nu,
                                            1, w->A, w->lds, w->r, w->ldr);
      if (info < 0) PM_CALL(lapack_check("dtrtrs", info));
      full = info == 0;
    }
  }
  if (!full) {
    int rk = 0;
    PM_CALL(min_norm(w, m, &rk));
    if (!w->c.exact_condition) {
      *rank = rk;
      *cond = rk < nu || !(rc > 0) ? INFINITY : 1 / (rc * rc);
    }
  }
  memcpy(w->coef, w->r, sizeof(double) * (size_t)nu);
  if (w->c.normal_equations) PM_CALL(solve_normal(w, m));
  return PM_SUCCESS;
}

/* ---- The fit ----------------------------------------------------------- */

/* The point of row i when np of n points are used: evenly strided. */
static long strided(int i, long n, int np) {
  const long q = n / np, rem = n % np;
  return (long)i * q + ((long)i * rem) / np;
}

/* Draw d's random point (and extra point) into the rows after the np
 * points' rows; their physical positions into q (6 values). */
static void put_draws(mpm_iso_work *w, int np, uint64_t seed, int d,
                      double q[6]) {
  double xi[3] = {0, 0, 0}, xe[3] = {0, 0, 0};
  for (int c = 0; c < w->c.dim; c++) {
    xi[c] = uniform(seed, d, c);
    xe[c] = uniform(seed, d, 3 + c);
  }
  put_row(w, np, xi, 0);
  if (w->c.extra_point) put_row(w, np + 1, xe, 2);
  for (int c = 0; c < 3; c++) {
    q[c] = c < w->c.dim ? w->lo[c] + w->H * xi[c] : 0;
    q[3 + c] = c < w->c.dim ? w->lo[c] + w->H * xe[c] : 0;
  }
}

pm_err mpm_iso_fit(mpm_iso_work *w, const double lo[3], double H, long n,
                   const double *x, const long *idx, uint64_t seed,
                   double *normal, mpm_iso_report *report) {
  PM_CHECK(w && lo, PM_ERR_ARG, "mpm_iso_fit: NULL workspace or element");
  PM_CHECK(isfinite(H) && H > 0, PM_ERR_ARG,
           "mpm_iso_fit: element size H must be finite and > 0 (got %g)", H);
  PM_CHECK(n >= 0, PM_ERR_ARG, "mpm_iso_fit: n must be >= 0 (got %ld)", n);
  PM_CHECK(n == 0 || (x && normal), PM_ERR_ARG,
           "mpm_iso_fit: NULL points or normals for %ld points", n);
  const int dim = w->c.dim, nu = w->nu;
  for (int c = 0; c < dim; c++) {
    PM_CHECK(isfinite(lo[c]), PM_ERR_ARG,
             "mpm_iso_fit: element corner lo[%d] is not finite (%g)", c, lo[c]);
    w->lo[c] = lo[c];
  }
  w->H = H;
  const int np = n > w->c.max_points ? w->c.max_points : (int)n;
  for (int i = 0; i < np; i++) {
    const long k = strided(i, n, np), p = idx ? idx[k] : k;
    double xi[3];
    logical(w, x + 3 * p, xi);
    PM_CHECK(isfinite(xi[0]) && isfinite(xi[1]) && isfinite(xi[2]), PM_ERR_ARG,
             "mpm_iso_fit: point %ld is not finite (%g, %g, %g)", p, x[3 * p],
             x[3 * p + 1], x[3 * p + 2]);
    put_row(w, i, xi, 1);
  }
  const int m = np + 1 + (w->c.extra_point ? 1 : 0);

  /* Draw until cond(T) is acceptable.  The best draw is the highest rank,
   * then the lowest cond(T); its coefficients are kept, as a refit would
   * give them bit for bit.  The drawing stops early when no draw can help:
   * a random point adds one to the rank at most, so a system two or more
   * short of full rank stays deficient (points on one grid line, a plane
   * seen by quadratics), as do fewer rows than unknowns all independent;
   * and a redraw that neither raises the rank nor lowers cond(T) tenfold
   * shows the ill-conditioning is the points' (a patch of sphere seen by
   * quadratics), not the random point's. */
  mpm_iso_report rep = {.condition = INFINITY};
  double q[6];
  for (int d = 0; d < w->c.max_draws; d++) {
    double cond;
    int rank;
    put_draws(w, np, seed, d, q);
    PM_CALL(solve(w, m, &cond, &rank));
    const bool better =
        d == 0 || rank > rep.rank || (rank == rep.rank && cond < rep.condition);
    const bool gain = d == 0 || rank > rep.rank ||
                      (rank == rep.rank && cond < 0.1 * rep.condition);
    rep.draws = d + 1;
    if (better) {
      rep.condition = cond;
      rep.rank = rank;
      memcpy(rep.random_point, q, sizeof rep.random_point);
      memcpy(w->kept, w->coef, sizeof(double) * (size_t)nu);
    }
    if (cond <= w->c.max_condition || !gain || rank <= nu - 2 || rank == m)
      break;
  }
  memcpy(w->coef, w->kept, sizeof(double) * (size_t)nu);

  for (long k = 0; k < n; k++) {
    const long p = idx ? idx[k] : k;
    double xi[3], g[3];
    logical(w, x + 3 * p, xi);
    evaluate(w, w->coef, xi, g);
    /* The logical gradient is H grad phi, and points the same way. */
    const double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(isfinite(len) && len >= w->c.min_gradient)) {
      rep.degenerate++;
      continue;
    }
    for (int c = 0; c < 3; c++) normal[3 * p + c] = c < dim ? g[c] / len : 0;
  }
  if (report) *report = rep;
  return PM_SUCCESS;
}

double mpm_iso_phi(const mpm_iso_work *w, const double x[3]) {
  double xi[3], g[3];
  logical(w, x, xi);
  return evaluate(w, w->coef, xi, g);
}
