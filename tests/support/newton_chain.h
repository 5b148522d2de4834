/* newton_chain: the problem the tests of the Newton layer share
 * (test_newton, test_load_steps): a chain of nonlinear springs with its
 * exact solution, on a band pattern, as a pm_newton_problem.  Include
 * after cmocka.h and pm_testing.h. */
#ifndef NEWTON_CHAIN_H
#define NEWTON_CHAIN_H

#include <math.h>
#include <stdlib.h>

#include "pm_newton.h"

static const double PI = 3.14159265358979323846;

/* ---- A chain of nonlinear springs --------------------------------------
 * Nodes 0..n+1 at spacing h, the two ends fixed; node a is joined to a + d
 * for d = 1..reach by a spring of rest length L = d h, stiffness k / d and
 * tension T(s) = (k / d) (s + c s^3 / L^2) in its elongation s = u_b - u_a
 * (inadmissible at s <= -L: the spring passes through itself).  The load
 * is manufactured: at load factor lambda the external force is the
 * internal force of u*(lambda) = lambda A sin(pi x / X), so u* is the
 * solution. */
typedef struct {
  long n;
  int reach;
  double h, k, c, amp;
  double lambda;
  double *x;       /* a state */
  double *force;   /* external force on the free nodes at lambda */
  double *tangent; /* dT/ds per spring at the prepared point */
  long *ptr, *idx; /* pattern */
  long prepares;
  /* Load stepping tests: a load jump above jump_limit from the last
   * converged load is inadmissible (0: any). */
  double jump_limit, lambda_done;
  bool nan_residual; /* residual returns NaN */
  bool hard_failure; /* residual fails with PM_ERR_MEMORY */
} chain;

static inline long springs_of(const chain *ch) {
  long count = 0;
  for (long a = 0; a <= ch->n + 1; a++)
    for (int d = 1; d <= ch->reach && a + d <= ch->n + 1; d++) count++;
  return count;
}

static inline double node_u(const chain *ch, const double *x, long g) {
  return g == 0 || g == ch->n + 1 ? 0.0 : x[g - 1];
}

static inline double exact(const chain *ch, double lambda, long g) {
  return lambda * ch->amp * sin(PI * (double)g / (double)(ch->n + 1));
}

/* Internal force of x into f (free nodes); false if a spring inverts. */
static inline bool internal_force(const chain *ch, const double *x, double *f,
                                  long *bad) {
  for (long i = 0; i < ch->n; i++) f[i] = 0;
  for (long a = 0; a <= ch->n + 1; a++)
    for (int d = 1; d <= ch->reach && a + d <= ch->n + 1; d++) {
      long b = a + d;
      double L = d * ch->h, s = node_u(ch, x, b) - node_u(ch, x, a);
      if (!(s > -L)) {
        *bad = a;
        return false;
      }
      double t = ch->k / d * (s + ch->c * s * s * s / (L * L));
      if (a >= 1 && a <= ch->n) f[a - 1] -= t;
      if (b >= 1 && b <= ch->n) f[b - 1] += t;
    }
  return true;
}

static inline pm_err chain_set_load(void *ctx, double lambda) {
  chain *ch = ctx;
  double *u = calloc((size_t)ch->n, sizeof *u);
  PM_CHECK(u, PM_ERR_MEMORY, "out of memory");
  for (long i = 0; i < ch->n; i++) u[i] = exact(ch, lambda, i + 1);
  long bad;
  bool ok = internal_force(ch, u, ch->force, &bad);
  free(u);
  PM_CHECK(ok, PM_ERR_ARG, "manufactured state inverts spring %ld", bad);
  ch->lambda = lambda;
  return PM_SUCCESS;
}

static inline pm_err chain_residual(void *ctx, const double *x, double *r) {
  chain *ch = ctx;
  if (ch->hard_failure)
    return PM_ERROR(PM_ERR_MEMORY, "out of memory (test residual)");
  if (ch->jump_limit > 0 && ch->lambda - ch->lambda_done > ch->jump_limit)
    return PM_ERROR(PM_ERR_UNSTABLE, "load jump %g above %g",
                    ch->lambda - ch->lambda_done, ch->jump_limit);
  long bad;
  if (!internal_force(ch, x, r, &bad))
    return PM_ERROR(PM_ERR_UNSTABLE, "spring from node %ld inverted", bad);
  for (long i = 0; i < ch->n; i++)
    r[i] = ch->nan_residual ? NAN : r[i] - ch->force[i];
  return PM_SUCCESS;
}

static inline pm_err chain_prepare(void *ctx, const double *x) {
  chain *ch = ctx;
  long e = 0;
  for (long a = 0; a <= ch->n + 1; a++)
    for (int d = 1; d <= ch->reach && a + d <= ch->n + 1; d++) {
      double L = d * ch->h, s = node_u(ch, x, a + d) - node_u(ch, x, a);
      ch->tangent[e++] = ch->k / d * (1 + 3 * ch->c * s * s / (L * L));
    }
  ch->prepares++;
  return PM_SUCCESS;
}

/* dr = J dx with the tangents of the springs up to distance `upto`. */
static inline void apply_springs(const chain *ch, int upto, const double *dx,
                                 double *dr) {
  long e = 0;
  for (long i = 0; i < ch->n; i++) dr[i] = 0;
  for (long a = 0; a <= ch->n + 1; a++)
    for (int d = 1; d <= ch->reach && a + d <= ch->n + 1; d++, e++) {
      if (d > upto) continue;
      long b = a + d;
      double ds = node_u(ch, dx, b) - node_u(ch, dx, a);
      double t = ch->tangent[e] * ds;
      if (a >= 1 && a <= ch->n) dr[a - 1] -= t;
      if (b >= 1 && b <= ch->n) dr[b - 1] += t;
    }
}

static inline pm_err chain_apply(void *ctx, const double *x, const double *dx,
                                 double *dr) {
  (void)x;
  apply_springs(ctx, ((chain *)ctx)->reach, dx, dr);
  return PM_SUCCESS;
}

/* The nearest-neighbour springs only: a cheaper, tridiagonal operator. */
static inline pm_err chain_apply_nearest(void *ctx, const double *x,
                                         const double *dx, double *dr) {
  (void)x;
  apply_springs(ctx, 1, dx, dr);
  return PM_SUCCESS;
}

static inline pm_err chain_on_step(void *ctx, int step, double lambda,
                                   const double *x,
                                   const pm_newton_report *report) {
  chain *ch = ctx;
  (void)step;
  (void)x;
  (void)report;
  ch->lambda_done = lambda;
  return PM_SUCCESS;
}

/* The pattern of a band of half-width `band` over n unknowns (freed by the
 * caller). */
static inline void band_pattern(long n, int band, long **ptr, long **idx) {
  *ptr = calloc((size_t)n + 1, sizeof **ptr);
  *idx = calloc((size_t)n * (size_t)(2 * band + 1), sizeof **idx);
  assert_true(*ptr && *idx);
  for (long i = 0; i < n; i++) {
    (*ptr)[i + 1] = (*ptr)[i];
    for (long j = i - band; j <= i + band; j++)
      if (j >= 0 && j < n) (*idx)[(*ptr)[i + 1]++] = j;
  }
}

/* A chain of n free nodes; its pattern (band of half-width `band`). */
static inline void chain_init(chain *ch, long n, int reach, int band) {
  memset(ch, 0, sizeof *ch);
  ch->n = n;
  ch->reach = reach;
  ch->h = 1.0 / (double)(n + 1);
  ch->k = 1.0e3;
  ch->c = 4.0;
  ch->amp = 0.25 / PI;
  ch->x = calloc((size_t)n, sizeof *ch->x);
  ch->force = calloc((size_t)n, sizeof *ch->force);
  ch->tangent = calloc((size_t)springs_of(ch), sizeof *ch->tangent);
  assert_true(ch->x && ch->force && ch->tangent);
  band_pattern(n, band, &ch->ptr, &ch->idx);
  assert_ok(chain_set_load(ch, 1.0));
}

static inline void chain_free(chain *ch) {
  free(ch->x);
  free(ch->force);
  free(ch->tangent);
  free(ch->ptr);
  free(ch->idx);
}

static inline pm_newton_problem chain_problem(chain *ch) {
  return (pm_newton_problem){.n = ch->n,
                             .ctx = ch,
                             .residual = chain_residual,
                             .jacobian_apply = chain_apply,
                             .jacobian_prepare = chain_prepare,
                             .pat_ptr = ch->ptr,
                             .pat_idx = ch->idx,
                             .set_load = chain_set_load,
                             .on_step = chain_on_step};
}

/* Solves the problem from rest (the state in ch->x) with a solver of
 * these options, created and destroyed here; returns the solve's code. */
static inline pm_err chain_solve(chain *ch, const pm_newton_problem *prob,
                                 const pm_newton_options *opt,
                                 pm_newton_report *rep) {
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(prob, opt, &s));
  memset(ch->x, 0, (size_t)ch->n * sizeof *ch->x);
  pm_err e = pm_newton_solve(s, ch->x, rep);
  pm_newton_destroy(&s);
  return e;
}

/* Loads the chain from rest in steps (the state in ch->x) with a solver
 * of these options, created and destroyed here; returns the code. */
static inline pm_err chain_load_steps(chain *ch, const pm_newton_problem *prob,
                                      const pm_newton_options *opt,
                                      pm_load_report *rep) {
  pm_newton *s = NULL;
  assert_ok(pm_newton_create(prob, opt, &s));
  memset(ch->x, 0, (size_t)ch->n * sizeof *ch->x);
  ch->lambda_done = 0;
  assert_ok(chain_set_load(ch, 0));
  pm_err e = pm_load_steps(s, ch->x, rep);
  pm_newton_destroy(&s);
  return e;
}

/* Largest |x - u*(lambda)| over the largest |u*|. */
static inline double chain_error(const chain *ch, const double *x,
                                 double lambda) {
  double e = 0, m = 0;
  for (long i = 0; i < ch->n; i++) {
    e = fmax(e, fabs(x[i] - exact(ch, lambda, i + 1)));
    m = fmax(m, fabs(exact(ch, lambda, i + 1)));
  }
  return e / m;
}

#endif
