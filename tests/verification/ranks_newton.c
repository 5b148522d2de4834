/* The Newton layer across ranks (pm_newton with a shared problem): run
 * under mpirun (tests/verification/ranks-implicit.sh), it solves a chain of
 * nonlinear springs whose nodes are shared among the ranks in order, each
 * rank assembling the springs that end at its own nodes (so a spring
 * across two ranks adds to a ghost node's row), and checks
 *  - the solution against the exact one (every spring carries the end
 *    load F: k (d + a d^3) = F), for each linear solver, with the
 *    assembled and the matrix-free operator, and with load stepping and
 *    its tangent predictor;
 *  - the same solve on one process (rank 0 alone) to round-off;
 *  - a state inadmissible on one rank only stops the solve on every rank
 *    with that rank's message, without a hang.
 * Usage: ranks_newton; prints a line per check and exits 0 when all
 * hold. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_petsc.h"
#include "ranks_testing.h"

#define N 400     /* unknowns: nodes 1..N; node 0 is fixed */
#define K 2.0e3   /* spring stiffness, N/m */
#define A 40.0    /* cubic hardening, 1/m^2 */
#define LOAD 60.0 /* the end load, N */

/* One rank's share: its nodes [lo, hi) of 1..N, the springs ending at them
 * (spring e joins nodes e and e + 1), and node lo - 1 as a ghost when it
 * is not the fixed node. */
typedef struct {
  long lo, hi, n, n_ghost;
  long ghost[1];
  long ptr[N + 2], idx[4 * (N + 1)]; /* two springs, two nodes each */
  double lambda;
  bool shared;
  long refuse_at; /* node whose stretch the residual refuses (0: none) */
} chain;

/* Local number of node i (-1: the fixed node). */
static long local(const chain *c, long i) {
  if (i == 0) return -1;
  return i >= c->lo ? i - c->lo : c->n;
}

static void share(chain *c, int rank, int size, bool shared) {
  memset(c, 0, sizeof *c);
  c->shared = shared;
  if (!shared) rank = 0, size = 1;
  c->lo = 1 + (long)N * rank / size;
  c->hi = 1 + (long)N * (rank + 1) / size;
  c->n = c->hi - c->lo;
  c->n_ghost = c->lo - 1 >= 1 ? 1 : 0;
  c->ghost[0] = c->lo - 2; /* node lo - 1's global number */
  /* Rows: owned nodes, then the ghost; each lists the nodes of the springs
   * this rank assembles that touch it. */
  long at = 0;
  for (long l = 0; l < c->n + c->n_ghost; l++) {
    long i = l < c->n ? c->lo + l : c->lo - 1;
    c->ptr[l] = at;
    for (long e = i - 1; e <= i; e++) {
      if (e < c->lo - 1 || e > c->hi - 2) continue; /* not this rank's */
      for (long j = e; j <= e + 1; j++)
        if (local(c, j) >= 0) c->idx[at++] = local(c, j);
    }
  }
  c->ptr[c->n + c->n_ghost] = at;
}

/* Spring e's stretch and tension at held values x. */
static double stretch(const chain *c, const double *x, long e) {
  long a = local(c, e), b = local(c, e + 1);
  return x[b] - (a >= 0 ? x[a] : 0);
}

static pm_err residual(void *ctx, const double *x, double *r) {
  const chain *c = ctx;
  memset(r, 0, sizeof(double) * (size_t)(c->n + c->n_ghost));
  for (long e = c->lo - 1; e <= c->hi - 2; e++) {
    double d = stretch(c, x, e), t = K * (d + A * d * d * d);
    if (e + 1 == c->refuse_at && d > 0)
      return PM_ERROR(PM_ERR_UNSTABLE, "spring %ld refuses stretch %g", e, d);
    long a = local(c, e), b = local(c, e + 1);
    if (a >= 0) r[a] -= t;
    r[b] += t;
  }
  if (c->hi == N + 1) r[c->n - 1] -= c->lambda * LOAD;
  return PM_SUCCESS;
}

static pm_err apply(void *ctx, const double *x, const double *dx, double *dr) {
  const chain *c = ctx;
  memset(dr, 0, sizeof(double) * (size_t)(c->n + c->n_ghost));
  for (long e = c->lo - 1; e <= c->hi - 2; e++) {
    double d = stretch(c, x, e), dd = stretch(c, dx, e);
    double dt = K * (1 + 3 * A * d * d) * dd;
    long a = local(c, e), b = local(c, e + 1);
    if (a >= 0) dr[a] -= dt;
    dr[b] += dt;
  }
  return PM_SUCCESS;
}

static pm_err values(void *ctx, const double *x, double *val) {
  const chain *c = ctx;
  for (long l = 0; l < c->n + c->n_ghost; l++) {
    long i = l < c->n ? c->lo + l : c->lo - 1;
    for (long q = c->ptr[l]; q < c->ptr[l + 1]; q++) val[q] = 0;
    long q = c->ptr[l];
    for (long e = i - 1; e <= i; e++) {
      if (e < c->lo - 1 || e > c->hi - 2) continue;
      double d = stretch(c, x, e), kt = K * (1 + 3 * A * d * d);
      for (long j = e; j <= e + 1; j++)
        if (local(c, j) >= 0) val[q++] = j == i ? kt : -kt;
    }
  }
  return PM_SUCCESS;
}

static pm_err set_load(void *ctx, double lambda) {
  ((chain *)ctx)->lambda = lambda;
  return PM_SUCCESS;
}

/* The exact stretch: k (d + a d^3) = F by Newton on the scalar. */
static double exact_stretch(void) {
  double d = LOAD / K;
  for (int k = 0; k < 100; k++)
    d -= (K * (d + A * d * d * d) - LOAD) / (K * (1 + 3 * A * d * d));
  return d;
}

/* Solve the chain (shared among the ranks or rank 0's alone) with linear
 * solver lin and operator op, by load steps or one Newton solve; x gets
 * the owned values.  Returns the largest error against the exact
 * solution over all ranks. */
static pm_err solve(chain *c, pm_newton_linear lin, pm_newton_operator op,
                    bool steps, double *x, double *err) {
  pm_newton_problem p = {.n = c->n,
                         .ctx = c,
                         .residual = residual,
                         .jacobian_apply = apply,
                         .jacobian_values = values,
                         .pat_ptr = c->ptr,
                         .pat_idx = c->idx,
                         .set_load = set_load,
                         .shared = c->shared,
                         .n_ghost = c->n_ghost,
                         .ghost = c->ghost};
  pm_newton_options o = pm_newton_options_default();
  o.rtol = 1e-10;
  o.atol = 1e-9; /* N: the residual's round-off is some 1e-12 */
  o.linear = lin;
  o.op = op;
  o.linear_rtol = 1e-13;
  o.linear_max_iter = 5000;
  o.load_steps = 4;
  o.predictor = true;
  pm_newton *s = NULL;
  pm_err e = pm_newton_create(&p, &o, &s);
  memset(x, 0, sizeof(double) * (size_t)c->n);
  if (!e && steps) {
    pm_load_report rep;
    e = pm_load_steps(s, x, &rep);
  } else if (!e) {
    c->lambda = 1;
    e = pm_newton_solve(s, x, NULL);
  }
  pm_newton_destroy(&s);
  double d = exact_stretch(), worst = 0;
  for (long l = 0; l < c->n; l++)
    worst = fmax(worst, fabs(x[l] - (double)(c->lo + l) * d) / ((double)N * d));
  if (c->shared) pm_par_max(&worst, 1);
  *err = worst;
  return e;
}

int main(int argc, char **argv) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  /* PETSc starts on every rank together (its start is collective). */
  if (pm_par_init(&argc, &argv) || pm_par_attach(MPI_COMM_WORLD) ||
      pm_petsc_init())
    return 2;
  const int rank = pm_par_rank(), size = pm_par_size();
  static chain c, one;
  static double x[N], x1[N];
  share(&c, rank, size, true);
  long offset = pm_par_offset(c.n);
  expect(offset == c.lo - 1, "each rank's unknowns follow the ranks' before");

  /* The same problem on rank 0 alone, the reference for round-off. */
  share(&one, 0, 1, false);
  double err1 = 0;
  if (rank == 0) {
    pm_err e =
        solve(&one, PM_NEWTON_DIRECT, PM_NEWTON_ASSEMBLED, true, x1, &err1);
    if (e) printf("one process: %s\n", pm_error_message());
  }
  pm_par_bcast(x1, sizeof x1);
  pm_par_bcast(&err1, sizeof err1);
  char what[256];
  snprintf(what, sizeof what,
           "one process: exact to 1e-10 (largest error %.2e of the end "
           "displacement)",
           err1);
  expect(err1 < 1e-10, what);

  static const struct {
    pm_newton_linear lin;
    pm_newton_operator op;
    bool steps;
    const char *name;
  } runs[] = {
      {PM_NEWTON_DIRECT, PM_NEWTON_ASSEMBLED, true, "direct, load steps"},
      {PM_NEWTON_DIRECT, PM_NEWTON_ASSEMBLED, false, "direct, one solve"},
      {PM_NEWTON_GMRES_GAMG, PM_NEWTON_ASSEMBLED, true, "gmres-gamg"},
      {PM_NEWTON_CG_JACOBI, PM_NEWTON_ASSEMBLED, true, "cg-jacobi"},
      {PM_NEWTON_GMRES_ILU, PM_NEWTON_ASSEMBLED, true, "gmres-ilu"},
      {PM_NEWTON_CG_GAMG, PM_NEWTON_ASSEMBLED, true, "cg-gamg"},
      {PM_NEWTON_DIRECT, PM_NEWTON_MATRIX_FREE, true, "matrix-free, direct"},
  };
  for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
    double err = 0;
    pm_err e = pm_par_agree(
        solve(&c, runs[k].lin, runs[k].op, runs[k].steps, x, &err));
    snprintf(what, sizeof what, "%d ranks, %s: converged%s%s", size,
             runs[k].name, e ? ": " : "", e ? pm_error_message() : "");
    expect(e == PM_SUCCESS, what);
    double diff = 0, scale = 0;
    for (long l = 0; l < c.n; l++) {
      diff = fmax(diff, fabs(x[l] - x1[c.lo - 1 + l]));
      scale = fmax(scale, fabs(x1[c.lo - 1 + l]));
    }
    pm_par_max(&diff, 1);
    pm_par_max(&scale, 1);
    snprintf(what, sizeof what,
             "%d ranks, %s: exact to 1e-10 (%.2e), one process's to 1e-10 "
             "(%.2e)",
             size, runs[k].name, err, diff / scale);
    expect(err < 1e-10 && diff / scale < 1e-10, what);
  }

  /* The last rank's first spring refuses to stretch: every rank stops. */
  if (size > 1) {
    c.refuse_at = rank == size - 1 ? c.lo : 0;
    double err;
    pm_err e = solve(&c, PM_NEWTON_DIRECT, PM_NEWTON_ASSEMBLED, false, x, &err);
    snprintf(what, sizeof what,
             "inadmissible on rank %d only: unstable on every rank (%s)",
             size - 1, pm_error_message());
    char spring[64];
    long lo_last = 1 + (long)N * (size - 1) / size;
    snprintf(spring, sizeof spring, "spring %ld refuses", lo_last - 1);
    expect(e == PM_ERR_UNSTABLE && strstr(pm_error_message(), spring), what);
  }
  if (rank == 0) printf("%d failed\n", failures);
  return failures ? 1 : 0;
}
