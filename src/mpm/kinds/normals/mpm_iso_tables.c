/* mpm_iso_tables: the paper's static cases of sections 4 and 6 (its Tables
 * I-III and figs. 4-11) computed by mpm_isonormal and printed as markdown
 * tables beside the paper's figures, with the wall time of a fit. */
#include <math.h>
#include <stdlib.h>

#include "mpm_iso_cases.h"
#include "mpm_isonormal.h"
#include "pm_progress.h"

static const double PI = 3.14159265358979323846;
static const double DEG = 180 / 3.14159265358979323846;

/* Below this largest angle (radians) a normal is exact to round-off. */
#define EXACT_TOL 1e-9
/* A fit is timed over at least this many seconds and repetitions. */
#define TIME_MIN 4e-3
#define TIME_REPS 20

/* What one fit of a case gave. */
typedef struct {
  double max, rms;      /* angle errors, radians */
  mpm_iso_report rep;   /* of the reported fit (exact condition) */
  double micros;        /* wall time per fit, the time loop's configuration */
  double phi_at_points; /* largest |phi - 1| at the points */
} outcome;

/* Wall time per fit (microseconds) of case c under configuration cfg with
 * the time loop's condition estimate (dtrcon), not the tables' exact one. */
static pm_err time_fit(const mpm_iso_case *c, mpm_iso_config cfg, uint64_t seed,
                       double *normal, double *micros) {
  cfg.exact_condition = false;
  mpm_iso_work *w = NULL;
  PM_CALL(mpm_iso_work_create(&cfg, &w));
  pm_err ret = PM_SUCCESS;
  long reps = 0;
  const double t0 = pm_wtime();
  double t = t0;
  while (reps < TIME_REPS || t - t0 < TIME_MIN) {
    PM_TRY(mpm_iso_fit(w, c->lo, c->H, c->n, c->x, NULL, seed, normal, NULL));
    reps++;
    t = pm_wtime();
  }
  *micros = 1e6 * (t - t0) / (double)reps;
done:
  mpm_iso_work_destroy(w);
  return ret;
}

/* Fit case c (cfg with the exact condition number) and time it. */
static pm_err run_case(const mpm_iso_case *c, mpm_iso_config cfg, uint64_t seed,
                       outcome *o) {
  double normal[3 * MPM_ISO_CASE_MAX];
  for (long k = 0; k < 3 * c->n; k++) normal[k] = c->exact[k];
  cfg.exact_condition = true;
  mpm_iso_work *w = NULL;
  PM_CALL(mpm_iso_work_create(&cfg, &w));
  pm_err ret = PM_SUCCESS;
  PM_TRY(mpm_iso_fit(w, c->lo, c->H, c->n, c->x, NULL, seed, normal, &o->rep));
  o->max = mpm_iso_case_error(c, normal, &o->rms);
  o->phi_at_points = 0;
  for (long k = 0; k < c->n; k++)
    o->phi_at_points =
        fmax(o->phi_at_points, fabs(mpm_iso_phi(w, c->x + 3 * k) - 1));
  PM_TRY(time_fit(c, cfg, seed, normal, &o->micros));
done:
  mpm_iso_work_destroy(w);
  return ret;
}

static int by_value(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* ---- Tables I and II: cond(T) over 100 random points ------------------- */

#define REALIZATIONS 100

/* One row: lines of slope s with n points, min / max / median cond(T) over
 * REALIZATIONS draws (seeds seed, seed + 1, ..., one draw each), beside the
 * paper's three figures, the largest angle error of all the fits and the
 * time per fit. */
static pm_err condition_row(FILE *out, double s, long n, const double paper[3],
                            uint64_t seed) {
  mpm_iso_case c;
  mpm_iso_case_line(s, n, &c);
  mpm_iso_config cfg = mpm_iso_config_default(2, 1);
  cfg.max_draws = 1;
  cfg.exact_condition = true;
  mpm_iso_work *w = NULL;
  PM_CALL(mpm_iso_work_create(&cfg, &w));
  pm_err ret = PM_SUCCESS;
  double cond[REALIZATIONS], normal[3 * MPM_ISO_CASE_MAX], worst = 0,
                                                           micros = 0;
  for (int k = 0; k < REALIZATIONS; k++) {
    mpm_iso_report rep;
    PM_TRY(mpm_iso_fit(w, c.lo, c.H, c.n, c.x, NULL, seed + k, normal, &rep));
    cond[k] = rep.condition;
    worst = fmax(worst, mpm_iso_case_error(&c, normal, NULL));
  }
  qsort(cond, REALIZATIONS, sizeof cond[0], by_value);
  PM_TRY(time_fit(&c, cfg, seed, normal, &micros));
  fprintf(out,
          "| %5.1f | %2ld | %8.1e | %8.1e | %8.1e | %8.1e | %8.1e | %8.1e | "
          "%8.1e | %-3s | %5.1f |\n",
          s, n, cond[0], cond[REALIZATIONS - 1],
          0.5 * (cond[REALIZATIONS / 2 - 1] + cond[REALIZATIONS / 2]), paper[0],
          paper[1], paper[2], worst, worst < EXACT_TOL ? "yes" : "NO", micros);
done:
  mpm_iso_work_destroy(w);
  return ret;
}

static void condition_head(FILE *out) {
  fprintf(out, "| slope | points | min | max | median | paper min | paper max "
               "| paper median | max error (rad) | exact | us/fit |\n"
               "|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|---:|\n");
}

static pm_err table_condition(FILE *out, uint64_t seed) {
  static const double slope1[10] = {0.1,   0.5,  1.0,  2.0,  10.0,
                                    -10.0, -2.0, -1.0, -0.5, -0.1};
  static const double paper1[10][3] = {
      {3.7e3, 1.3e8, 5.0e3},  {7.8e1, 4.6e7, 1.7e2}, {3.5e1, 4.8e5, 5.9e1},
      {2.3e2, 7.3e16, 3.6e2}, {3.7e3, 1.1e6, 5.4e3}, {3.6e3, 5.1e6, 5.3e3},
      {2.3e2, 1.4e7, 3.3e2},  {3.5e1, 3.6e7, 6.1e1}, {3.5e1, 3.6e7, 1.2e2},
      {3.7e3, 2.5e6, 6.0e3}};
  fprintf(out,
          "\n### Table I: cond(T) over %d random points, 3 points on lines, "
          "linear\n\n",
          REALIZATIONS);
  fprintf(out,
          "Lines through (0.5, 0.5) in the element [0, 1]^2; points "
          "equally spaced in arc length over the part inside the "
          "element, 10%% of it free at each end; random points of seeds "
          "%llu to %llu, one draw each; cond(T) = (smax / smin)^2 of "
          "S.  us/fit: the time loop's fit (QR, estimated condition, up "
          "to 4 draws).\n\n",
          (unsigned long long)seed,
          (unsigned long long)(seed + REALIZATIONS - 1));
  condition_head(out);
  for (int i = 0; i < 10; i++)
    PM_CALL(condition_row(out, slope1[i], 3, paper1[i], seed));

  static const double slope2[3] = {1, 2, 10};
  static const double paper2[3][2][3] = {
      {{3.2e1, 3.2e5, 7.9e1}, {3.6e1, 1.7e9, 6.5e1}},
      {{1.3e2, 2.9e6, 1.9e2}, {1.7e2, 9.9e5, 3.4e2}},
      {{4.1e3, 5.4e4, 5.8e3}, {5.7e3, 2.2e5, 7.7e3}}};
  fprintf(out,
          "\n### Table II: cond(T) over %d random points, 4 and 8 points "
          "on lines, linear\n\nPlacement and draws as in Table I.\n\n",
          REALIZATIONS);
  condition_head(out);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 2; j++)
      PM_CALL(
          condition_row(out, slope2[i], j == 0 ? 4 : 8, paper2[i][j], seed));
  return PM_SUCCESS;
}

/* ---- Table III: the circle of radius 0.8 ------------------------------- */

static pm_err table_circle(FILE *out, uint64_t seed) {
  fprintf(out, "\n### Table III: x^2 + y^2 = 0.8^2, errors in radians\n\n");
  fprintf(out,
          "Element [0, 1]^2; the quarter arc from 0 to 90 degrees, points "
          "equally spaced from 9 to 81 degrees (10%% free at each end); the "
          "random point fixed (seed %llu, one draw) as in the paper, which "
          "gives linear only.  The paper's rms column cannot be a root mean "
          "square over the points (that is at least max / sqrt(n): 0.0699, "
          "0.0546, 0.0416, 0.0315, 0.0231 for its rows); it matches |e|_2 / "
          "n, which is what `|e|/n` gives for ours and what `within paper` "
          "compares, with the max.  Quadratic with 8 points: the points lie "
          "symmetric about 45 degrees, where a second quadratic besides the "
          "circle vanishes at all of them (rank 8 of 9, see figs. 9c-d).  "
          "cond(T) exact; us/fit: the time loop's fit.\n\n",
          (unsigned long long)seed);
  fprintf(out, "| points | linear max | paper max | linear \\|e\\|/n | "
               "paper rms | within paper | linear rms | cond(T) linear | "
               "quadratic max | quadratic rms | cond(T) quadratic | us/fit "
               "linear | us/fit quadratic |\n|---:|---:|---:|---:|---:|:---:|"
               "---:|---:|---:|---:|---:|---:|---:|\n");
  for (int i = 0; i < MPM_ISO_TABLE_III_ROWS; i++) {
    const mpm_iso_paper_arc *paper = &mpm_iso_table_iii[i];
    mpm_iso_case c;
    mpm_iso_case_arc(0, 0, 0.8, 0, PI / 2, paper->points, &c);
    outcome o[2];
    for (int order = 1; order <= 2; order++) {
      mpm_iso_config cfg = mpm_iso_config_default(2, order);
      cfg.max_draws = 1;
      PM_CALL(run_case(&c, cfg, seed, &o[order - 1]));
    }
    const double per_n = o[0].rms / sqrt((double)c.n);
    const bool within = o[0].max <= paper->max && per_n <= paper->rms;
    fprintf(out,
            "| %2ld | %.4f | %.4f | %.4f | %.4f | %-3s | %.4f | %8.1e | "
            "%.2e | %.2e | %8.1e | %5.1f | %5.1f |\n",
            paper->points, o[0].max, paper->max, per_n, paper->rms,
            within ? "yes" : "NO", o[0].rms, o[0].rep.condition, o[1].max,
            o[1].rms, o[1].rep.condition, o[0].micros, o[1].micros);
  }
  return PM_SUCCESS;
}

/* ---- Figures 4-11 ------------------------------------------------------ */

typedef enum { ARC, BILINEAR, CUBIC, PLANE, SPHERE } shape;

typedef struct {
  const char *figure, *curve;
  shape kind;
  double p[5]; /* ARC: cx, cy, r, th0, th1 (degrees); CUBIC: k */
  long n;
  int order;
  bool normal_equations;
  bool exact; /* exact to round-off expected */
  const char *paper;
} figure_row;

static void build(const figure_row *f, mpm_iso_case *c) {
  switch (f->kind) {
  case ARC:
    mpm_iso_case_arc(f->p[0], f->p[1], f->p[2], f->p[3] / DEG, f->p[4] / DEG,
                     f->n, c);
    break;
  case BILINEAR: mpm_iso_case_bilinear(f->n, c); break;
  case CUBIC: mpm_iso_case_cubic(f->p[0], f->n, c); break;
  case PLANE: mpm_iso_case_plane(f->n, c); break;
  case SPHERE: mpm_iso_case_sphere(f->n, c); break;
  }
}

#define ARC_A                                                                  \
  ARC, { 0.5, 0.5, 0.3, 175, 275 }
#define ARC_B                                                                  \
  ARC, { 0.5, 0.5, 0.3, 40, 140 }

static const figure_row FIGURES[] = {
    {"4a", "xy + 0.1x + 0.3 = 0", BILINEAR, {0}, 3, 1, false, true, "exact"},
    {"4b",
     "x^2 + y^2 = 0.8^2",
     ARC,
     {0, 0, 0.8, 0, 90},
     3,
     1,
     false,
     false,
     "7 max"},
    {"7a", "arc (a): unique x, y", ARC_A, 6, 1, false, false, "6 max"},
    {"7b", "arc (b): pairs share y", ARC_B, 6, 1, false, false, "34 max"},
    {"9a", "arc (a)", ARC_A, 6, 2, true, false, "3 max"},
    {"9a", "arc (a)", ARC_A, 6, 2, false, false, "-"},
    {"9b", "arc (b)", ARC_B, 6, 2, true, false, "19 max"},
    {"9b", "arc (b)", ARC_B, 6, 2, false, false, "< 1 max"},
    {"9c", "arc (a)", ARC_A, 8, 2, false, true, "exact"},
    {"9d", "arc (b)", ARC_B, 8, 2, false, true, "exact"},
    {"9c'",
     "arc (a) turned 5 deg",
     ARC,
     {0.5, 0.5, 0.3, 180, 280},
     8,
     2,
     false,
     true,
     "exact"},
    {"10a",
     "y = 2x^2(x-1) + x + 0.5",
     CUBIC,
     {2},
     10,
     2,
     false,
     false,
     "1 max"},
    {"10b",
     "y = 4x^2(x-1) + x + 0.5",
     CUBIC,
     {4},
     10,
     2,
     false,
     false,
     "32 max, 5 rms"},
    {"5a",
     "plane 0.5x + 0.25y - z = 0",
     PLANE,
     {0},
     9,
     1,
     false,
     true,
     "exact"},
    {"11a",
     "plane 0.5x + 0.25y - z = 0",
     PLANE,
     {0},
     30,
     2,
     false,
     true,
     "exact"},
    {"5b", "sphere r = 0.8", SPHERE, {0}, 8, 1, false, false, "13 max, 3 rms"},
    {"11b", "sphere r = 0.8", SPHERE, {0}, 29, 2, false, true, "exact"},
};

static pm_err table_figures(FILE *out, uint64_t seed) {
  fprintf(out, "\n### Figures 4-11: errors in degrees\n\n");
  fprintf(out,
          "Element [0, 1]^d except fig. 4a ([-1, 0] x [0, 1], where the "
          "curve's branch runs from x = -1 to -3/11).  Curves: points "
          "equally spaced in arc length, 10%% of the length free at each "
          "end; arc (a): angles 175-275 degrees, so points at 185-265, "
          "every x and y distinct; arc (b): 40-140, points at 50-130, "
          "symmetric about x = 0.5 so pairs share y; cubics from x = 0 to "
          "where y = 1; plane: a grid of ceil(sqrt(n)) columns over x, y in "
          "[0.1, 0.9]; sphere: a golden-angle spiral over the octant, z "
          "equally spaced from 0.72 to 0.08, azimuth in 9-81 degrees.  "
          "Random point: seed %llu, redrawn while cond(T) > 1e12 (up to 4 "
          "draws).  Solver: QR (minimum norm when rank deficient) or the "
          "normal equations.  cond(T) exact (INFINITY: S rank deficient); "
          "us/fit: the time loop's fit.  Figs. 9c-d: eight points of a "
          "circle are the zeros of a trigonometric polynomial of degree 4, "
          "which is a biquadratic when its sin 4 theta term vanishes, i.e. "
          "when their angles about the centre sum to a multiple of 360 "
          "degrees, as they do placed symmetric about 225 (9c) or 90 (9d) "
          "degrees: S then has rank 8 of 9 and the minimum-norm phi is not "
          "the circle's.  Four pairs sharing y are always so placed, so the "
          "paper's exact fig. 9d cannot have had four such pairs.  9c': the "
          "points of 9c turned 5 degrees (sum 1840 degrees): rank 9, exact.  "
          "The paper's rms is taken as |e|_2 / n (Table III).\n\n",
          (unsigned long long)seed);
  fprintf(out,
          "| fig. | curve | order | points | solver | cond(T) | rank | "
          "draws | max error | rms error | \\|e\\|/n | paper | exact | us/fit "
          "|\n|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---|"
          ":---:|---:|\n");
  for (size_t i = 0; i < sizeof FIGURES / sizeof FIGURES[0]; i++) {
    const figure_row *f = &FIGURES[i];
    mpm_iso_case c;
    build(f, &c);
    mpm_iso_config cfg = mpm_iso_config_default(c.dim, f->order);
    cfg.normal_equations = f->normal_equations;
    outcome o;
    PM_CALL(run_case(&c, cfg, seed, &o));
    const char *exact = !f->exact ? "-"
                        : o.max < EXACT_TOL && o.phi_at_points < EXACT_TOL
                            ? "yes"
                            : "NO";
    fprintf(out,
            "| %s | %s | %d | %ld | %s | %8.1e | %d/%d | %d | %.3g | %.3g | "
            "%.3g | %s | %s | %5.1f |\n",
            f->figure, f->curve, f->order, f->n,
            f->normal_equations ? "normal eq." : "QR", o.rep.condition,
            o.rep.rank, mpm_iso_unknowns(c.dim, f->order), o.rep.draws,
            o.max * DEG, o.rms * DEG, o.rms * DEG / sqrt((double)c.n), f->paper,
            exact, o.micros);
  }
  return PM_SUCCESS;
}

/* ---- Cost -------------------------------------------------------------- */

/* The time loop's systems: a generic placement of each size, and the
 * rank-deficient extremes (a flat patch, symmetric circle points), which
 * fall to the minimum-norm solver. */
static const figure_row COSTS[] = {
    {"", "quarter circle", ARC, {0, 0, 0.8, 0, 90}, 8, 1, false, false, ""},
    {"", "quarter circle", ARC, {0, 0, 0.8, 0, 90}, 32, 1, false, false, ""},
    {"",
     "arc (a) turned 5 deg",
     ARC,
     {0.5, 0.5, 0.3, 180, 280},
     8,
     2,
     false,
     false,
     ""},
    {"", "quarter circle", ARC, {0, 0, 0.8, 0, 90}, 32, 2, false, false, ""},
    {"", "arc (a), symmetric: rank 8", ARC_A, 8, 2, false, false, ""},
    {"", "sphere", SPHERE, {0}, 8, 1, false, false, ""},
    {"", "sphere", SPHERE, {0}, 29, 2, false, false, ""},
    {"", "sphere", SPHERE, {0}, 64, 2, false, false, ""},
    {"", "plane: rank 20", PLANE, {0}, 30, 2, false, false, ""},
};

static pm_err cost_row(FILE *out, const figure_row *f, uint64_t seed) {
  mpm_iso_case c;
  build(f, &c);
  mpm_iso_config cfg = mpm_iso_config_default(c.dim, f->order);
  double normal[3 * MPM_ISO_CASE_MAX], micros = 0;
  PM_CALL(time_fit(&c, cfg, seed, normal, &micros));
  mpm_iso_work *w = NULL;
  PM_CALL(mpm_iso_work_create(&cfg, &w));
  pm_err ret = PM_SUCCESS;
  mpm_iso_report rep;
  PM_TRY(mpm_iso_fit(w, c.lo, c.H, c.n, c.x, NULL, seed, normal, &rep));
  fprintf(out, "| %d-D %s | %d | %ld | %d | %d | %.1f | %zu |\n", c.dim,
          f->curve, f->order, f->n, mpm_iso_unknowns(c.dim, f->order),
          rep.draws, micros, mpm_iso_work_bytes(w));
done:
  mpm_iso_work_destroy(w);
  return ret;
}

static pm_err table_cost(FILE *out, uint64_t seed) {
  fprintf(out,
          "\n### Cost of a fit (the time loop's: QR, estimated "
          "condition, up to 4 draws; seed %llu)\n\n| system | order | "
          "points | unknowns | draws | us/fit | workspace bytes "
          "|\n|---|---:|---:|---:|---:|---:|---:|\n",
          (unsigned long long)seed);
  for (size_t i = 0; i < sizeof COSTS / sizeof COSTS[0]; i++)
    PM_CALL(cost_row(out, &COSTS[i], seed));
  return PM_SUCCESS;
}

pm_err mpm_iso_tables(FILE *out, uint64_t seed) {
  PM_CHECK(out, PM_ERR_ARG, "mpm_iso_tables: NULL stream");
  fprintf(out, "## Normals without connectivity: the paper's static cases "
               "(papers/mpm-membrane-normals-without-connectivity.txt)\n");
  PM_CALL(table_condition(out, seed));
  PM_CALL(table_circle(out, seed));
  PM_CALL(table_figures(out, seed));
  PM_CALL(table_cost(out, seed));
  return PM_SUCCESS;
}
