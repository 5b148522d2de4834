/* mpm_iso_cases: the paper's static configurations for the isosurface
 * normals, points and exact normals (placements in mpm_iso_cases.h). */
#include "mpm_iso_cases.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

const mpm_iso_paper_arc mpm_iso_table_iii[MPM_ISO_TABLE_III_ROWS] = {
    {3, 0.1211, 0.0571},  {4, 0.1091, 0.0434},  {8, 0.1177, 0.0231},
    {16, 0.1261, 0.0141}, {32, 0.1308, 0.0092},
};

/* A curve p(t), t in [0, 1], and the gradient g of an implicit function of
 * it (the normal's direction) at p(t). */
typedef void (*curve_fn)(const double *par, double t, double p[2], double g[2]);

/* Samples of the arc length: enough that linear interpolation between them
 * puts the points equally spaced to ~1e-7 of the length. */
#define ARC_SAMPLES 4096

static void start(int dim, long n, mpm_iso_case *c) {
  memset(c, 0, sizeof *c);
  c->dim = dim;
  c->H = 1;
  c->n = n < 0 ? 0 : (n > MPM_ISO_CASE_MAX ? MPM_ISO_CASE_MAX : n);
}

static void set_normal(mpm_iso_case *c, long k, const double g[3]) {
  const double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  for (int a = 0; a < 3; a++) c->exact[3 * k + a] = g[a] / len;
}

/* Fraction of the arc length where point k of n stands. */
static double station(long k, long n) {
  return n > 1 ? 0.1 + 0.8 * (double)k / (double)(n - 1) : 0.5;
}

/* The points of curve f equally spaced in arc length (chords of
 * ARC_SAMPLES samples), each evaluated on the curve itself. */
static void place_curve(curve_fn f, const double *par, mpm_iso_case *c) {
  double len[ARC_SAMPLES + 1], p0[2], p[2], g[2];
  len[0] = 0;
  f(par, 0, p0, g);
  for (int s = 1; s <= ARC_SAMPLES; s++) {
    f(par, (double)s / ARC_SAMPLES, p, g);
    len[s] = len[s - 1] + hypot(p[0] - p0[0], p[1] - p0[1]);
    p0[0] = p[0];
    p0[1] = p[1];
  }
  int s = 0;
  for (long k = 0; k < c->n; k++) {
    const double want = station(k, c->n) * len[ARC_SAMPLES];
    while (s < ARC_SAMPLES - 1 && len[s + 1] < want) s++;
    const double seg = len[s + 1] - len[s];
    const double frac = seg > 0 ? (want - len[s]) / seg : 0;
    f(par, (s + frac) / ARC_SAMPLES, p, g);
    c->x[3 * k] = p[0];
    c->x[3 * k + 1] = p[1];
    set_normal(c, k, (double[3]){g[0], g[1], 0});
  }
}

/* par: slope, x0, x1 */
static void line_at(const double *par, double t, double p[2], double g[2]) {
  p[0] = par[1] + t * (par[2] - par[1]);
  p[1] = 0.5 + par[0] * (p[0] - 0.5);
  g[0] = -par[0];
  g[1] = 1;
}

void mpm_iso_case_line(double s, long n, mpm_iso_case *c) {
  start(2, n, c);
  const double half = s != 0 ? 0.5 / fabs(s) : 1;
  const double par[3] = {s, fmax(0, 0.5 - half), fmin(1, 0.5 + half)};
  place_curve(line_at, par, c);
}

/* par: cx, cy, r, th0, th1 */
static void arc_at(const double *par, double t, double p[2], double g[2]) {
  const double th = par[3] + t * (par[4] - par[3]);
  g[0] = cos(th);
  g[1] = sin(th);
  p[0] = par[0] + par[2] * g[0];
  p[1] = par[1] + par[2] * g[1];
}

void mpm_iso_case_arc(double cx, double cy, double r, double th0, double th1,
                      long n, mpm_iso_case *c) {
  start(2, n, c);
  const double par[5] = {cx, cy, r, th0, th1};
  place_curve(arc_at, par, c);
}

/* par: x0, x1 */
static void bilinear_at(const double *par, double t, double p[2], double g[2]) {
  p[0] = par[0] + t * (par[1] - par[0]);
  p[1] = -0.1 - 0.3 / p[0];
  g[0] = p[1] + 0.1;
  g[1] = p[0];
}

void mpm_iso_case_bilinear(long n, mpm_iso_case *c) {
  start(2, n, c);
  c->lo[0] = -1;
  const double par[2] = {-1, -3.0 / 11.0};
  place_curve(bilinear_at, par, c);
}

static double cubic_y(double k, double x) {
  return k * x * x * (x - 1) + x + 0.5;
}

/* par: k, x1 */
static void cubic_at(const double *par, double t, double p[2], double g[2]) {
  const double k = par[0], x = t * par[1];
  p[0] = x;
  p[1] = cubic_y(k, x);
  g[0] = -(3 * k * x * x - 2 * k * x + 1);
  g[1] = 1;
}

void mpm_iso_case_cubic(double k, long n, mpm_iso_case *c) {
  start(2, n, c);
  /* Where y = 1 (y(0) = 0.5, y(1) = 1.5): bisection. */
  double a = 0, b = 1;
  for (int it = 0; it < 60; it++) {
    const double m = 0.5 * (a + b);
    if (cubic_y(k, m) < 1)
      a = m;
    else
      b = m;
  }
  const double par[2] = {k, a};
  place_curve(cubic_at, par, c);
}

void mpm_iso_case_plane(long n, mpm_iso_case *c) {
  start(3, n, c);
  long nx = (long)ceil(sqrt((double)c->n));
  if (nx < 1) nx = 1;
  const long ny = (c->n + nx - 1) / nx;
  for (long k = 0; k < c->n; k++) {
    const long i = k % nx, j = k / nx;
    double *x = c->x + 3 * k;
    x[0] = nx > 1 ? 0.1 + 0.8 * (double)i / (double)(nx - 1) : 0.5;
    x[1] = ny > 1 ? 0.1 + 0.8 * (double)j / (double)(ny - 1) : 0.5;
    x[2] = 0.5 * x[0] + 0.25 * x[1];
    set_normal(c, k, (double[3]){0.5, 0.25, -1});
  }
}

void mpm_iso_case_sphere(long n, mpm_iso_case *c) {
  start(3, n, c);
  const double r = 0.8, golden = 0.5 * (sqrt(5.0) - 1);
  for (long k = 0; k < c->n; k++) {
    const double z = 1 - station(k, c->n);
    const double turn = (double)k * golden - floor((double)k * golden);
    const double ph = 0.5 * PI * (0.1 + 0.8 * turn), s = sqrt(1 - z * z);
    const double d[3] = {s * cos(ph), s * sin(ph), z};
    for (int a = 0; a < 3; a++) c->x[3 * k + a] = r * d[a];
    set_normal(c, k, d);
  }
}

double mpm_iso_case_error(const mpm_iso_case *c, const double *normal,
                          double *rms) {
  double worst = 0, sum = 0;
  for (long k = 0; k < c->n; k++) {
    const double *u = normal + 3 * k, *e = c->exact + 3 * k;
    const double x[3] = {u[1] * e[2] - u[2] * e[1], u[2] * e[0] - u[0] * e[2],
                         u[0] * e[1] - u[1] * e[0]};
    const double dot = fabs(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]);
    const double ang =
        atan2(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), dot);
    if (!(ang <= worst) && !isnan(worst)) worst = ang; /* a NaN stays */
    sum += ang * ang;
  }
  if (rms) *rms = c->n > 0 ? sqrt(sum / (double)c->n) : 0;
  return worst;
}
