/* gm_curve: the 2-D membrane's line of points (from a parametric curve or
 * given points), its lengths and normals, and the polygon it encloses
 * with the point-in-polygon test of `inside` and `outside` bodies. */
#include "gm_curve.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Sub-intervals per point on which a parametric curve's arc length is
 * measured (the header's 64 n). */
#define GM_CURVE_SAMPLES 64
/* A closed parametric curve must come back to its start within this
 * fraction of its length: a gap would be bridged by one long segment. */
#define GM_CURVE_GAP_TOL 1e-6
/* Enough for regula falsi to reach round-off from the linear guess (it
 * takes 3 to 5); a bound, not a count. */
#define GM_CURVE_PLACE_ITERATIONS 30

/* ---- the curve ---------------------------------------------------------- */

/* (x(t), y(t)) into p (3 doubles), or PM_ERR_EXPR naming the expression
 * that is not finite at t. */
static pm_err evaluate(const pm_expr *xs, const pm_expr *ys, double t,
                       double *p) {
  const pm_expr *e[2] = {xs, ys};
  for (int k = 0; k < 2; k++) {
    p[k] = pm_expr_eval(e[k], 0, 0, 0, t);
    const char *origin = pm_expr_origin(e[k]);
    PM_CHECK(isfinite(p[k]), PM_ERR_EXPR,
             "%s%scurve %c(t) = \"%s\" is %g at t = %.17g: expected a finite "
             "value",
             origin ? origin : "", origin ? ": " : "", "xy"[k],
             pm_expr_text(e[k]), p[k], t);
  }
  p[2] = 0.0;
  return PM_SUCCESS;
}

static double distance(const double *a, const double *b) {
  return hypot(hypot(b[0] - a[0], b[1] - a[1]), b[2] - a[2]);
}

/* The point q of the curve in the sample step [ta, tb] (from pa, its
 * chord ds) whose chord from pa is d (0 < d < ds) long.  Interpolating t
 * linearly would misplace it by s''(t) dt^2 / 8 where the speed ds/dt
 * varies (4e-7 on a step of (t^3, 0) of 21 points, 8e-6 of their
 * spacing); regula falsi (Illinois) from that guess makes the chords agree
 * to round-off in a few evaluations. */
static pm_err place(const pm_expr *xs, const pm_expr *ys, double ta, double tb,
                    const double *pa, double ds, double d, double *q) {
  const double tol = 1e-13 * ds + 8 * DBL_EPSILON * (fabs(pa[0]) + fabs(pa[1]));
  double lo = ta, hi = tb, glo = -d, ghi = ds - d;
  int side = 0;
  for (int it = 0; it < GM_CURVE_PLACE_ITERATIONS; it++) {
    const double t = lo + (hi - lo) * (glo / (glo - ghi));
    PM_CALL(evaluate(xs, ys, t, q));
    const double g = distance(pa, q) - d;
    if (fabs(g) <= tol) break;
    /* Illinois: the end kept twice in a row has its value halved, so that
     * the bracket shrinks from both sides. */
    if (g < 0.0) {
      lo = t;
      glo = g;
      if (side < 0) ghi *= 0.5;
      side = -1;
    } else {
      hi = t;
      ghi = g;
      if (side > 0) glo *= 0.5;
      side = 1;
    }
  }
  return PM_SUCCESS;
}

/* Sample i of m (from 0) of [t0, t1], exactly t1 at the end. */
static double sample_t(double t0, double t1, long i, long m) {
  return i == m ? t1 : t0 + (t1 - t0) * ((double)i / (double)m);
}

pm_err gm_curve_parametric(const pm_expr *xs, const pm_expr *ys, double t0,
                           double t1, long n, bool closed, gm_curve *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_curve_parametric: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(xs && ys, PM_ERR_ARG, "gm_curve_parametric: no expression");
  PM_CHECK(n >= 2, PM_ERR_ARG, "a curve needs at least 2 points (got %ld)", n);
  PM_CHECK(n <= (1L << 40) / GM_CURVE_SAMPLES, PM_ERR_ARG,
           "a curve of %ld points is too many", n);
  PM_CHECK(isfinite(t0) && isfinite(t1), PM_ERR_ARG,
           "the curve's parameter range [%g, %g] must be finite", t0, t1);
  pm_err ret = PM_SUCCESS;
  const long m = GM_CURVE_SAMPLES * n;
  /* Only the arc lengths are kept (8 bytes a sample, not 32): the few
   * samples needed again are evaluated again, to the same bits. */
  double *s = NULL, start[3], prev[3], here[3];
  PM_TRY(PM_ALLOC(s, (size_t)m + 1, "curve arc lengths"));
  PM_TRY(PM_ALLOC(out->x, 3 * (size_t)n, "curve points"));
  PM_TRY(evaluate(xs, ys, t0, start));
  memcpy(prev, start, sizeof prev);
  for (long i = 1; i <= m; i++) {
    PM_TRY(evaluate(xs, ys, sample_t(t0, t1, i, m), here));
    s[i] = s[i - 1] + distance(prev, here);
    memcpy(prev, here, sizeof prev);
  }
  const double length = s[m];
  PM_ENSURE(length > 0.0 && isfinite(length), PM_ERR_GEOMETRY,
            "the curve (\"%s\", \"%s\") for t in [%g, %g] has length %g: "
            "expected a positive length",
            pm_expr_text(xs), pm_expr_text(ys), t0, t1, length);
  if (closed) {
    const double gap = distance(start, prev);
    PM_ENSURE(gap <= GM_CURVE_GAP_TOL * length, PM_ERR_GEOMETRY,
              "the closed curve (\"%s\", \"%s\") starts at (%g, %g) at t = "
              "%g but ends at (%g, %g) at t = %g, %g away (its length is %g): "
              "expected it to return to its start",
              pm_expr_text(xs), pm_expr_text(ys), start[0], start[1], t0,
              prev[0], prev[1], t1, gap, length);
  }
  /* Point k at arc length k L / segments, found by walking the samples
   * once (s increases), then within its sample step. */
  const long segments = closed ? n : n - 1;
  long i = 0;
  for (long k = 0; k < n; k++) {
    double *q = out->x + 3 * k;
    if (!closed && k == n - 1) {
      memcpy(q, prev, 3 * sizeof *q);
      break;
    }
    const double target = length * ((double)k / (double)segments);
    while (i < m - 1 && s[i + 1] <= target) i++;
    const double ds = s[i + 1] - s[i], d = target - s[i];
    const double ta = sample_t(t0, t1, i, m), tb = sample_t(t0, t1, i + 1, m);
    if (!(d > 0.0 && d < ds)) {
      PM_TRY(evaluate(xs, ys, d > 0.0 ? tb : ta, q));
      continue;
    }
    double pa[3];
    PM_TRY(evaluate(xs, ys, ta, pa));
    PM_TRY(place(xs, ys, ta, tb, pa, ds, d, q));
  }
  out->n = n;
  out->closed = closed;
done:
  if (ret) gm_curve_free(out);
  free(s);
  return ret;
}

/* The n points x (3 each) are finite and enough for a (closed) curve. */
static pm_err check_points(const char *what, long n, const double *x,
                           bool closed) {
  const long least = closed ? 3 : 2;
  PM_CHECK(n >= least, PM_ERR_ARG, "%s %s needs at least %ld points (got %ld)",
           closed ? "a closed" : "an open", what, least, n);
  PM_CHECK(x, PM_ERR_ARG, "%s: no points", what);
  for (long i = 0; i < n; i++)
    PM_CHECK(isfinite(x[3 * i]) && isfinite(x[3 * i + 1]) &&
                 isfinite(x[3 * i + 2]),
             PM_ERR_GEOMETRY,
             "%s point %ld is at (%g, %g, %g): expected finite coordinates",
             what, i, x[3 * i], x[3 * i + 1], x[3 * i + 2]);
  return PM_SUCCESS;
}

pm_err gm_curve_from_points(long n, const double *x, bool closed,
                            gm_curve *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_curve_from_points: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CALL(check_points("curve", n, x, closed));
  PM_CALL(PM_ALLOC(out->x, 3 * (size_t)n, "curve points"));
  memcpy(out->x, x, 3 * (size_t)n * sizeof *x);
  out->n = n;
  out->closed = closed;
  return PM_SUCCESS;
}

void gm_curve_free(gm_curve *c) {
  if (!c) return;
  free(c->x);
  memset(c, 0, sizeof *c);
}

void gm_curve_point_lengths(const gm_curve *c, double *len) {
  const long n = c->n;
  for (long k = 0; k < n; k++) len[k] = 0.0;
  const long segments = c->closed ? n : n - 1;
  for (long e = 0; e < segments; e++) {
    const long a = e, b = (e + 1) % n;
    const double half = 0.5 * distance(c->x + 3 * a, c->x + 3 * b);
    len[a] += half;
    len[b] += half;
  }
}

void gm_curve_neighbours(long k, long n, bool closed, long *prev, long *next) {
  if (closed) {
    *prev = (k + n - 1) % n;
    *next = (k + 1) % n;
  } else {
    *prev = k - 1 < 0 ? 0 : k - 1;
    *next = k + 1 > n - 1 ? n - 1 : k + 1;
  }
}

bool gm_curve_normal(const double prev[3], const double next[3], double n[3]) {
  const double tx = next[0] - prev[0];
  const double ty = next[1] - prev[1];
  const double len = hypot(tx, ty);
  /* Not (len > 0) also catches a NaN from a point that went bad. */
  if (!(len > 0.0)) {
    n[0] = n[1] = n[2] = 0.0;
    return false;
  }
  n[0] = ty / len;
  n[1] = -tx / len;
  n[2] = 0.0;
  return true;
}

long gm_curve_normals(long n, const double *x, bool closed, double *normal) {
  long vanished = 0;
  for (long k = 0; k < n; k++) {
    long prev, next;
    gm_curve_neighbours(k, n, closed, &prev, &next);
    vanished += !gm_curve_normal(x + 3 * prev, x + 3 * next, normal + 3 * k);
  }
  return vanished;
}

/* ---- the enclosed polygon ----------------------------------------------- */

/* The faces of the box in the plane, as bits: x = lo, x = hi, y = lo,
 * y = hi. */
enum { FACE_XLO = 1, FACE_XHI = 2, FACE_YLO = 4, FACE_YHI = 8 };

/* The faces of [lo, hi] (in x, y) that p lies on within tol. */
static unsigned faces_of(const double *p, const double lo[3],
                         const double hi[3], double tol) {
  const bool in_x = p[0] >= lo[0] - tol && p[0] <= hi[0] + tol;
  const bool in_y = p[1] >= lo[1] - tol && p[1] <= hi[1] + tol;
  unsigned f = 0;
  if (in_y && fabs(p[0] - lo[0]) <= tol) f |= FACE_XLO;
  if (in_y && fabs(p[0] - hi[0]) <= tol) f |= FACE_XHI;
  if (in_x && fabs(p[1] - lo[1]) <= tol) f |= FACE_YLO;
  if (in_x && fabs(p[1] - hi[1]) <= tol) f |= FACE_YHI;
  return f;
}

/* The corners where an x face of one end's faces fa meets a y face of the
 * other's fb: how many (0 to 2), the first into corner. */
static int shared_corners(unsigned fa, unsigned fb, const double lo[3],
                          const double hi[3], double corner[2]) {
  int found = 0;
  for (int ax = 0; ax < 2; ax++)
    for (int ay = 0; ay < 2; ay++) {
      const unsigned fx = ax ? FACE_XHI : FACE_XLO;
      const unsigned fy = ay ? FACE_YHI : FACE_YLO;
      if (!(((fa & fx) && (fb & fy)) || ((fa & fy) && (fb & fx)))) continue;
      if (found++ == 0) {
        corner[0] = ax ? hi[0] : lo[0];
        corner[1] = ay ? hi[1] : lo[1];
      }
    }
  return found;
}

/* How the open curve from a to b closes along the box's boundary: *corner
 * set (and *add true) when through a corner; nothing when straight along
 * a face they share; PM_ERR_GEOMETRY when not at all. */
static pm_err close_along_box(const double *a, const double *b,
                              const double lo[3], const double hi[3],
                              double tol, bool *add, double corner[2]) {
  const unsigned fa = faces_of(a, lo, hi, tol), fb = faces_of(b, lo, hi, tol);
  *add = false;
  if (fa & fb) return PM_SUCCESS;
  PM_CHECK(fa && fb, PM_ERR_GEOMETRY,
           "the membrane curve is open and its ends (%g, %g) and (%g, %g) are "
           "not both on the boundary of the domain [%g, %g] x [%g, %g] "
           "(within %g): an open curve encloses nothing (expected a closed "
           "curve, or ends on the domain's boundary)",
           a[0], a[1], b[0], b[1], lo[0], hi[0], lo[1], hi[1], tol);
  /* Ends on opposite faces, or on opposite corners, split the box in two
   * with nothing to say which part the membrane holds. */
  const int corners = shared_corners(fa, fb, lo, hi, corner);
  PM_CHECK(corners == 1, PM_ERR_GEOMETRY,
           "the membrane curve is open and its ends (%g, %g) and (%g, %g) lie "
           "on opposite %s of the domain [%g, %g] x [%g, %g]: which side it "
           "encloses is ambiguous (expected a closed curve, or ends on one "
           "face or on two adjacent faces)",
           a[0], a[1], b[0], b[1], corners ? "corners" : "faces", lo[0], hi[0],
           lo[1], hi[1]);
  *add = true;
  return PM_SUCCESS;
}

pm_err gm_curve_polygon(long n, const double *x, bool closed,
                        const double lo[3], const double hi[3], double tol,
                        gm_polygon *poly) {
  PM_CHECK(poly, PM_ERR_ARG, "gm_curve_polygon: poly is NULL");
  memset(poly, 0, sizeof *poly);
  PM_CALL(check_points("membrane curve", n, x, closed));
  double corner[2];
  bool add_corner = false;
  /* A closed curve closes itself: the last edge back to the first point
   * is implicit, as is the straight one along a face. */
  if (!closed) {
    PM_CHECK(lo && hi && tol >= 0.0, PM_ERR_ARG,
             "gm_curve_polygon: no box or a negative tolerance (%g)", tol);
    PM_CALL(
        close_along_box(x, x + 3 * (n - 1), lo, hi, tol, &add_corner, corner));
  }
  const long nv = n + (add_corner ? 1 : 0);
  PM_CALL(PM_ALLOC(poly->xy, 2 * (size_t)nv, "membrane polygon"));
  for (long k = 0; k < n; k++) {
    poly->xy[2 * k] = x[3 * k];
    poly->xy[2 * k + 1] = x[3 * k + 1];
  }
  if (add_corner) memcpy(poly->xy + 2 * n, corner, sizeof corner);
  poly->n = nv;
  return PM_SUCCESS;
}

void gm_polygon_free(gm_polygon *p) {
  if (!p) return;
  free(p->xy);
  memset(p, 0, sizeof *p);
}

bool gm_polygon_contains(const gm_polygon *p, const double x[3]) {
  bool inside = false;
  const double px = x[0], py = x[1];
  for (long i = 0, j = p->n - 1; i < p->n; j = i++) {
    /* The edge from its lower end a to its upper end b, whichever way the
     * polygon runs: an edge two polygons share then gives both the same
     * crossing, and a point on it lies in exactly one of them. */
    const double *a = p->xy + 2 * i, *b = p->xy + 2 * j;
    if (a[1] > b[1]) {
      const double *t = a;
      a = b;
      b = t;
    }
    /* Half-open in y (a[1] <= py < b[1]): a horizontal edge never counts,
     * and a vertex counts for one of its two edges only. */
    if (!(a[1] <= py && py < b[1])) continue;
    const double xc = a[0] + (py - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
    if (px < xc) inside = !inside;
  }
  return inside;
}

double gm_polygon_area(const gm_polygon *p) {
  double twice = 0.0;
  if (p->n < 3) return 0.0;
  /* About the first vertex: less cancellation far from the origin. */
  const double ox = p->xy[0], oy = p->xy[1];
  for (long i = 1; i + 1 < p->n; i++) {
    const double *a = p->xy + 2 * i, *b = a + 2;
    twice += (a[0] - ox) * (b[1] - oy) - (b[0] - ox) * (a[1] - oy);
  }
  return 0.5 * twice;
}
