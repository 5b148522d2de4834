/* mpm_isonormal: the normal of a surface known only by unconnected points
 * on it (papers/mpm-membrane-normals-without-connectivity.txt, sections 3
 * and 5).  On one element (a grid cell, or a block of cells taken as one
 * larger element) a function phi of B-splines is fitted, in the least-
 * squares sense and by QR (LAPACK), to phi = 1 at the points and phi = 0 at
 * one random point of the element; the normal at a point is
 * grad phi / |grad phi| there.
 *
 *   linear (order 1):    phi = sum_I phi_I N1(xi - I), 2^d nodal unknowns
 *                        (eqs. 10-11);
 *   quadratic (order 2): phi = sum_C phi_C N2(xi - C), 3^d unknowns at the
 *                        centres of the element and its neighbours (eq. 16).
 *
 * xi = (x - lo) / H are the element's logical coordinates (the element is
 * [lo, lo + H]^d; points may lie slightly outside it, where the element's
 * polynomial pieces are continued: what the element reproduces exactly, a
 * line or a plane (linear), a circle or a sphere (quadratic), it
 * reproduces there too).  Nothing here
 * allocates after mpm_iso_work_create: a fit runs inside the time loop,
 * one workspace per thread. */
#ifndef MPM_ISONORMAL_H
#define MPM_ISONORMAL_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "pm_error.h"

typedef struct {
  int dim;   /* 2 or 3 (in 2-D the z coordinates are ignored) */
  int order; /* 1: linear B-splines, 2: quadratic */
  /* Rows the workspace holds: a fit of more points than this uses an evenly
   * strided subset of max_points of them (every point still gets its
   * normal). */
  int max_points;
  /* cond(T) (T = S^T S, the normal-equations matrix, the paper's measure)
   * above which the random point is drawn again, up to max_draws draws in
   * all; the best-conditioned draw is kept.  The drawing stops earlier
   * when no draw can help: S two or more short of full rank (a random
   * point adds one at most), fewer rows than unknowns all independent, or
   * a redraw that neither raised the rank nor lowered cond(T) tenfold (the
   * ill-conditioning is the points'). */
  double max_condition;
  int max_draws;
  /* The paper's remedy for a phi whose maximum is 1 on the surface: a
   * second random point with phi = 2. */
  bool extra_point;
  /* H |grad phi| (the change of phi across the element) below which a
   * point's gradient counts as vanished: phi then has an extremum on the
   * surface, a ridge whose gradient points anywhere, and the point keeps
   * its normal.  Measured on M5 (hybrid, the angle to the connectivity
   * normals over every frame): 1e-8 gives an rms of 1.04 degrees (circle)
   * and 1.37 (dogbone); 0.1 gives 0.87 and 0.85. */
  double min_gradient;
  /* Solve the normal equations T phi = S^T phi0 (Cholesky; where round-off
   * leaves a singular T not positive definite, the symmetric indefinite
   * factorisation) instead of QR: only to show what QR gains (the paper's
   * fig. 9b).  The report still describes S (condition and rank). */
  bool normal_equations;
  /* cond(T) exactly, from the singular values of S (tables), instead of
   * LAPACK's 1-norm estimate from R (dtrcon, the time loop's). */
  bool exact_condition;
} mpm_iso_config;

/* Defaults: max_points 256, max_condition 1e12, max_draws 4, no extra
 * point, min_gradient 0.1, QR, estimated condition. */
mpm_iso_config mpm_iso_config_default(int dim, int order);

/* Unknowns of a fit: 2^d (linear) or 3^d (quadratic). */
int mpm_iso_unknowns(int dim, int order);

/* The hybrid rule (section 8): with n membrane points in an element, order
 * 2 when n + 1 >= 3^d (a determined quadratic system with the random point),
 * order 1 when n + 1 >= 2^d, and 0 when the element has too few points
 * (the caller merges it with its neighbours into a larger element). */
int mpm_iso_hybrid_order(int dim, long n);

typedef struct mpm_iso_work mpm_iso_work;

/* A workspace for fits of configuration c (copied).  PM_ERR_MEMORY /
 * PM_ERR_ARG (dim, order or max_points out of range). */
pm_err mpm_iso_work_create(const mpm_iso_config *c, mpm_iso_work **w);
void mpm_iso_work_destroy(mpm_iso_work *w);
/* Bytes a workspace holds. */
size_t mpm_iso_work_bytes(const mpm_iso_work *w);

/* What a fit found. */
typedef struct {
  double condition; /* cond(T) of the draw kept; INFINITY when S is rank
                       deficient (fewer equations than unknowns, or
                       dependent columns: rcond(S) below 1e-13, i.e.
                       cond(T) above ~1e26) */
  int rank;         /* numerical rank of S */
  int draws;        /* random points drawn */
  long degenerate;  /* points where grad phi vanished: their normal is what
                       it was on entry */
  double random_point[3]; /* where phi = 0 was imposed (the kept draw) */
} mpm_iso_report;

/* Fit phi on the element [lo, lo + H]^d to the n points
 * x + 3 idx[k] (idx NULL: x + 3 k), and set the unit normal of each point
 * in normal + 3 idx[k] (3 each; the z component 0 in 2-D).  The random
 * point's draw d comes from the counter-based generator at (seed, d), so a
 * fit repeats bit for bit whatever thread runs it.  Where |grad phi| H is
 * below min_gradient (phi has an extremum on the surface), the point's normal
 * is left as it came in (the caller's previous normal, a unit vector) and
 * counted in report->degenerate.  The normals' sign is arbitrary.
 * Rank-deficient and underdetermined systems are solved in the minimum-
 * norm sense (complete orthogonal factorisation, dgelsy).  Returns
 * PM_SUCCESS, or PM_ERR_LINALG when LAPACK fails (not for a merely
 * ill-conditioned system).  Does not allocate; not thread-safe on one w. */
pm_err mpm_iso_fit(mpm_iso_work *w, const double lo[3], double H, long n,
                   const double *x, const long *idx, uint64_t seed,
                   double *normal, mpm_iso_report *report);

/* splitmix64's output function: a bijection of 64-bit words whose outputs
 * for consecutive inputs pass the usual statistical tests.  Callers make a
 * fit's seed with it from what identifies the fit (step, cell, ...). */
uint64_t mpm_iso_mix(uint64_t z);

/* phi at x of the last fit of w (for contour plots and tests); 0 before
 * any fit. */
double mpm_iso_phi(const mpm_iso_work *w, const double x[3]);

/* The paper's static cases (M6 of CASES.md), printed to out as markdown
 * tables with the paper's figures beside ours and the wall time of a fit
 * (placements: mpm_iso_cases.h): Table I (condition numbers over 100 random
 * points, lines of 10 slopes, 3 points), Table II (4 and 8 points), Table
 * III (circle arc, 3 to 32 points, linear and quadratic), the bilinear
 * curve xy + 0.1 x + 0.3 = 0, the arcs of figs. 7 and 9 (QR against the
 * normal equations), the cubic curves c = 2 and 4, and in 3-D the plane
 * 0.5 x + 0.25 y - z = 0 and the sphere of radius 0.8.  PM_ERR_* from a
 * fit. */
pm_err mpm_iso_tables(FILE *out, uint64_t seed);

#endif
