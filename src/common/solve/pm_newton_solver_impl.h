/* pm_newton_solver_impl: the Newton solver's state and the functions its
 * files share (assembly, held values across ranks, SNES callbacks, linear
 * solver); not for callers of pm_newton.h. */
#ifndef PM_NEWTON_SOLVER_IMPL_H
#define PM_NEWTON_SOLVER_IMPL_H

#include <stdbool.h>

#include <petscsnes.h>

#include "pm_petsc_api.h"

#include "pm_coloring.h"
#include "pm_newton.h"
#include "pm_par.h"

typedef pm_err (*apply_fn)(void *ctx, const double *x, const double *dx,
                           double *dr);

struct pm_newton {
  pm_newton_problem p; /* the caller's, with pattern pointers cleared */
  pm_newton_options o;
  /* pm_newton_set_fallback_linear: the linear settings of the solver's
   * own (own) and of load stepping's fallbacks (alt), whether there are
   * such (has_alt) and which o holds now (on_alt). */
  pm_newton_options own, alt;
  bool has_alt, on_alt, alt_keep;
  char *petsc_options;     /* copy of o.petsc_options */
  pm_pattern jpat, ppat;   /* Jacobian's and cheap operator's */
  pm_coloring jcol, pcol;  /* their colourings (pcol: cheap only) */
  PetscInt *jcols, *pcols; /* pattern columns as PETSc indices */
  /* values in pattern order: across ranks (inserted into the matrix);
   * on one process jvals is made on first use (pm_newton_jvals) */
  double *jvals, *pvals;
  double *seed, *dr; /* colour seed and its image */
  double *srcvals;   /* jacobian_values: values in the caller's order */
  double *psrcvals;  /* precond_values: values in the caller's order */
  Vec X, R, Xstart, Xlin, Xacc, Work;
  /* pc_reuse_its: where the kept factorisation or preconditioner was
   * built (Xpc) and under which load (pc_load; load: the last set). */
  Vec Xpc;
  double load, pc_load;
  Mat J;     /* assembled Jacobian (not in the cheap mode) */
  Mat P;     /* assembled cheap operator (cheap mode only) */
  Mat Shell; /* matrix-free Jacobian (matrix-free modes only) */
  /* options.amg_threaded: the finest level's products on every thread
   * (pm_newton_fine.c), and whether its rows come in threes (-1: not yet
   * known) */
  Mat Fine;
  int fine_threes;
  /* Fine's single-precision copy of the values (fine_a, room for
   * fine_cap), wanted (fine_single), made from the values now held
   * (fine_single_ok), or to be made again (fine_stale: the Jacobian has
   * written new values); in 3 x 3 blocks where the matrix is made of them
   * (fine_blocks, -1: not yet known; fine_ib, fine_jb: each block row's
   * blocks and their block columns) */
  float *fine_a;
  long fine_cap;
  int fine_blocks;
  PetscInt *fine_ib, *fine_jb;
  int fine_single; /* -1: not yet read */
  bool fine_single_ok, fine_stale, fine_used;
  /* Pseudo-transient continuation (pm_load_ptc.c): while shifted, the
   * linear solves are of J + diag(Shift) (ShiftWork: the shell's term);
   * one process only. */
  Vec Shift, ShiftWork;
  bool shifted;
  SNES snes;
  KSP ksp;
  SNESLineSearch ls;
  /* PM_LINE_SEARCH_FULL_L2: the secant taken where the full step does not
   * lower the residual enough */
  SNESLineSearch ls2;
  PetscOptions opts;
  /* Across ranks (dist): the ranks' communicator (PETSC_COMM_SELF on one
   * process), the values a rank holds (owned and ghosts: nloc), the
   * numbering of its held values over all ranks, and ghosted vectors in
   * which the callbacks see the ghosts' values (Gx: a residual's state,
   * Glin: the linearisation point, Gdx: a product's direction) and leave
   * their contributions (Gr, Gdr). */
  bool dist;
  MPI_Comm comm;
  long nloc;
  ISLocalToGlobalMapping l2g;
  Vec Gx, Glin, Gdx, Gr, Gdr;

  /* The solve under way. */
  pm_newton_report *rep;
  pm_newton_reason reason;
  pm_err hard;      /* a callback's failure that aborts the solve */
  bool domain_last; /* the last residual call was inadmissible */
  char domain_msg[256];
  double r0, e0;       /* reference residual for rtol, |dx_0 . r(x_0)| */
  double r_ref;        /* a reference residual larger than |r(x_0)| (0: none) */
  double incr, energy; /* |dx_k|, |dx_k . r(x_k)| of the current step */
  long jacobians;      /* Jacobian callbacks in this solve (for pc_lag) */
  double linear_started, linear_started_cpu;
  bool in_linear; /* between the linear solver's pre- and postsolve */
  /* The last linear solve's residual norms: first and last (the linear
   * solver's convergence test records them). */
  double lin_r0, lin_r;
  /* pc_reuse_its: a preconditioner was built, and the last linear
   * solve's iterations and whether it failed. */
  bool pc_built, lin_failed;
  /* pc_reuse_cost: a set-up waits for the next linear solve (pending),
   * which is then the kept one's first (fresh); the last solve was
   * stopped because the kept one no longer pays (stale); the kept one's
   * set-up cost in iterations (budget, 0: unknown, no stop) and the
   * iterations of its first solve (-1: none yet). */
  bool pc_pending, pc_fresh, pc_stale;
  int pc_budget, pc_first_its;
  /* A solve made again from its last iterate after a stopped linear
   * solve: the Newton and linear iterations before (it_base indexes the
   * report's arrays). */
  int it_base, lin_base;
  /* linear_ew: |r| at the last linear solve of this Newton solve (0:
   * none yet) and the tolerance it was given. */
  double ew_rprev, ew_eta;
  int lin_its;
  /* pm_newton_cap_linear: at most this many iterations a linear solve (0:
   * the options' linear_max_iter), and whether the last solve's limit was
   * set by it. */
  int lin_cap;
  bool lin_capped;
  bool started; /* the initial state was admissible */
  /* pm_newton_problem.aux_n (one process): M's rows as the caller gives
   * them (aux_ptr, aux_idx over aux_N = n + aux_n, kept by the caller) and
   * their values (asrc, in that order); dirty: new values not
   * factorised.  Sparse: the pattern (apat), the matrix (its values in its
   * own storage), its LU (ka), its right-hand side and solution.  Dense
   * (aug_dense: n <= the dense bound, pm_newton_dense.c): the shift of the
   * first n diagonal entries (ashift) and D's values (adiag); the Schur
   * complement S = J0 - G D^-1 C is formed in Sd. */
  bool aug, aug_dirty, aug_dense;
  long aux_N;
  const long *aux_ptr, *aux_idx;
  double *asrc;
  pm_pattern apat;
  Mat Ma;
  KSP ka;
  Vec Ab, Ay;
  double *ashift, *adiag;
  /* The direct solver dense (pm_newton_dense.c): the augmented
   * preconditioner's (aug_dense), or the matrix's own (dense_direct: one
   * process, small and full enough); the matrix in Sd (n x n, row-major:
   * LAPACK's transpose), factorised there with its pivots (ipiv); failed:
   * the last factorisation met a zero pivot (or a zero in D). */
  bool dense_direct, dense_failed;
  double *Sd;
  int *ipiv;
};

/* A callback's failure that aborts the solve (not an inadmissible state);
 * a signal's (a callback that polls it) among them. */
static inline bool pm_newton_hard_failure(pm_err e) {
  return e == PM_ERR_MEMORY || e == PM_ERR_IO || e == PM_ERR_INTERNAL ||
         e == PM_ERR_INTERRUPTED;
}

/* A callback's answer, the same on every rank of a shared problem. */
static inline pm_err pm_newton_agreed(const pm_newton *s, pm_err e) {
  return s->dist ? pm_par_agree(e) : e;
}

/* ---- pm_newton_assembly.c ---- */

/* v's n values = x (copy_in), or x = v's (copy_out). */
pm_err pm_newton_copy_in(Vec v, const double *x, long n);
pm_err pm_newton_copy_out(Vec v, double *x, long n);

/* vals (pattern order) = J(x) by one application of f per colour of col;
 * a failing application is returned with its colour. */
pm_err pm_newton_color_values(pm_newton *s, apply_fn f, const pm_coloring *col,
                              const double *x, double *vals);

/* The Jacobian's values at x in pattern order: the caller's assembly when
 * it gives one, else colouring. */
pm_err pm_newton_values_at(pm_newton *s, const double *x, double *vals);
/* The cheaper operator's values at x into vals (pattern order): the
 * caller's assembly (precond_values) when it gives one, else colouring of
 * precond_apply. */
pm_err pm_newton_precond_values(pm_newton *s, const double *x, double *vals);
typedef pm_err (*pm_newton_values_fn)(pm_newton *s, const double *x,
                                      double *vals);
/* s->jvals (the Jacobian's values apart from its matrix: relaxation's
 * masses, the checks), made on first use. */
pm_err pm_newton_jvals(pm_newton *s, double **vals);

/* s->jpat.idx again, from the Jacobian's matrix, where it was let go (a
 * caller's assembly on one process keeps the columns in the matrix). */
pm_err pm_newton_pattern_columns(pm_newton *s);

/* M = vals on the pattern (the matrix's preallocated structure, its
 * columns cols). */
pm_err pm_newton_insert_values(const pm_newton *s, Mat M, const pm_pattern *pat,
                               const PetscInt *cols, const double *vals);
/* M = f's values at x: written by f into M's own storage where cols is
 * NULL, else into vals and inserted. */
pm_err pm_newton_fill(pm_newton *s, Mat M, const pm_pattern *pat,
                      const PetscInt *cols, double *vals, pm_newton_values_fn f,
                      const double *x);
/* M's own storage (one process: the pattern's order) = the caller's values
 * src (the pattern's source order) summed into their places. */
pm_err pm_newton_scatter_into(Mat M, const pm_pattern *pat, const double *src);

/* *M: an AIJ matrix with pat's structure, set to zeros.  On one process
 * its storage is the pattern's order and *cols is NULL (with release, the
 * pattern's columns are let go before the matrix is made: the matrix holds
 * them); across ranks *cols (allocated, the caller frees) holds the
 * pattern's columns as PETSc indices and zeros the pattern's count of
 * zeros (the caller's). */
pm_err pm_newton_create_matrix(const pm_newton *s, pm_pattern *pat,
                               bool release, PetscInt **cols, double *zeros,
                               Mat *M);

/* The problem's near-null vectors, orthonormalised, as M's near null space
 * (at most 16 of them, else PM_ERR_ARG). */
pm_err pm_newton_set_near_null(pm_newton *s, Mat M);

/* ---- pm_newton_shared.c ---- */

/* The values a callback reads of V (in_get .. in_done) and where it writes
 * them (out_get .. out_done): V's own array on one process, ghosted G's held
 * values across ranks; out_done with ok adds the ghosts' contributions on
 * their owners, into V. */
PetscErrorCode pm_newton_in_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
                                const double **a);
PetscErrorCode pm_newton_in_done(const pm_newton *s, Vec G, Vec *loc,
                                 const double **a);
PetscErrorCode pm_newton_out_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
                                 double **a);
PetscErrorCode pm_newton_out_done(const pm_newton *s, Vec V, Vec G, Vec *loc,
                                  double **a, bool ok);

/* Across ranks: the numbering of the held values over all ranks (s->l2g)
 * and the ghosted vectors of the callbacks. */
pm_err pm_newton_create_shared(pm_newton *s);

/* ---- pm_newton_callbacks.c: what SNES (and KSP) call, ctx = the solver. */

PetscErrorCode pm_newton_snes_residual(SNES snes, Vec X, Vec R, void *ctx);
PetscErrorCode pm_newton_snes_jacobian(SNES snes, Vec X, Mat A, Mat B,
                                       void *ctx);
PetscErrorCode pm_newton_shell_mult(Mat A, Vec in, Vec out);

/* ---- pm_newton_fine.c: multigrid's finest level on every thread. */
/* The shell Fine, when options.amg_threaded applies (else none). */
pm_err pm_newton_fine_create(pm_newton *s);
/* After the preconditioner's set-up: Fine in the finest smoother and
 * residual (again after a new hierarchy). */
PetscErrorCode pm_newton_fine_attach(pm_newton *s, KSP ksp);
/* ---- pm_newton_line_search.c: the full step, else the secant. */
/* s->ls runs it (a shell line search), s->ls2 the secant. */
pm_err pm_newton_full_l2_create(pm_newton *s);
PetscErrorCode pm_newton_precheck(SNESLineSearch ls, Vec X, Vec Y,
                                  PetscBool *changed, void *ctx);
PetscErrorCode pm_newton_linear_presolve(KSP ksp, Vec b, Vec x, void *ctx);
PetscErrorCode pm_newton_linear_postsolve(KSP ksp, Vec b, Vec x, void *ctx);
/* pc_reuse_cost: the kept preconditioner, at iteration it of a solve it
 * did not start fresh, has cost more than a set-up (the solve is to stop
 * and be made again on a new one). */
bool pm_newton_pc_spent(const pm_newton *s, int it);
/* pc_reuse_cost: the iterations a solve on a kept preconditioner may take
 * beyond its first solve's (0: no stop). */
int pm_newton_pc_budget(const pm_newton *s);

/* ---- pm_newton_augmented.c: pm_newton_problem.aux_n ---- */

/* The augmented matrix's pattern and values (at create), its PETSc
 * objects, its values at x (the Jacobian callback), its factorisation if
 * new values wait (the linear presolve), the shell preconditioner on pc,
 * and the release of it all. */
pm_err pm_newton_aug_init(pm_newton *s, const pm_newton_problem *p);
pm_err pm_newton_aug_objects(pm_newton *s);
pm_err pm_newton_aug_values(pm_newton *s, const double *x);
PetscErrorCode pm_newton_aug_factor(pm_newton *s);
PetscErrorCode pm_newton_aug_set_pc(pm_newton *s, PC pc);
/* Adds d (n values) to the diagonal of M's first n rows (the shift of
 * pseudo-transient continuation). */
PetscErrorCode pm_newton_aug_shift(pm_newton *s, const double *d);
void pm_newton_aug_free(pm_newton *s);

/* ---- pm_newton_dense.c ---- */

/* Whether a dense LU may serve: one process, and n within -pm_aug_dense_max
 * (else PM_NEWTON_AUG_DENSE_MAX) and LAPACK's int indices. */
bool pm_newton_dense_within(const pm_newton *s);
/* Sd and ipiv for the n unknowns, once. */
pm_err pm_newton_dense_storage(pm_newton *s);
/* The LU of Sd in place (dense_failed after a zero pivot). */
void pm_newton_dense_factor(pm_newton *s);
/* y = S^-1 x by Sd's factors; after a failed factorisation, infinities and
 * pc failed (the linear solve then fails as after a failed sparse LU). */
PetscErrorCode pm_newton_dense_solve(pm_newton *s, PC pc, Vec x, Vec y);
/* Whether the direct solver's own LU (no aux_n) is dense: one process, n
 * within the bound and the pattern a tenth full or more. */
bool pm_newton_dense_direct_fits(const pm_newton *s);
/* pc as the dense LU of the preconditioner's matrix (B of
 * pm_newton_operators), set up from its values at each new matrix. */
PetscErrorCode pm_newton_dense_set_pc(pm_newton *s, PC pc);
/* pc as a shell of s: setup (NULL: none) at each new matrix, apply. */
PetscErrorCode pm_newton_shell_pc(pm_newton *s, PC pc,
                                  PetscErrorCode (*setup)(PC),
                                  PetscErrorCode (*apply)(PC, Vec, Vec),
                                  const char *name);

/* ---- pm_newton_convergence.c ---- */

/* SNES's convergence test: sets s->reason and *reason after `it`
 * iterations. */
PetscErrorCode pm_newton_converged_test(SNES snes, PetscInt it, PetscReal xnorm,
                                        PetscReal snorm, PetscReal fnorm,
                                        SNESConvergedReason *reason, void *ctx);

/* ---- pm_newton_linear.c ---- */

/* Gives SNES a new linear solver (in place of one left inconsistent by a
 * failure inside it); s->ksp is it. */
pm_err pm_newton_replace_linear(pm_newton *s);
/* The augmented preconditioner in use: made (aux_n) and the linear solver
 * now the direct one (the solver's own, or its fallbacks'). */
static inline bool pm_newton_aug_on(const pm_newton *s) {
  return s->aug && s->o.linear == PM_NEWTON_DIRECT;
}

/* What the linear solver multiplies by (A) and builds its preconditioner
 * from (B). */
void pm_newton_operators(const pm_newton *s, Mat *A, Mat *B);

/* The signal (SIGINT, SIGTERM) that asks the solve to stop, 0 if none:
 * the process's, across ranks any rank's (collective then). */
int pm_newton_stop_signal(const pm_newton *s);

/* SNES's convergence test (pm_newton_converged_test) that also stops the
 * solve on a signal: s->hard = PM_ERR_INTERRUPTED, with the message. */
PetscErrorCode pm_newton_converged_or_stopped(SNES snes, PetscInt it,
                                              PetscReal xnorm, PetscReal snorm,
                                              PetscReal fnorm,
                                              SNESConvergedReason *reason,
                                              void *ctx);

/* A linear solver's reason in words ("the iteration limit was reached"). */
const char *pm_newton_linear_reason_words(KSPConvergedReason r);

#endif
