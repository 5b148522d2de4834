/* pm_newton: Newton's method on PETSc (SNES) for a problem given by
 * callbacks, with the consistent tangent assembled by column colouring (or
 * applied matrix-free), and load stepping with step cutting.  It knows
 * nothing of the methods that use it.
 *
 * The contract with a caller:
 *
 * - Unknowns are x[0..n-1] (n < 2^31).  The residual r(x) is zero at the
 *   solution; the Jacobian is J = dr/dx.  r must be a deterministic
 *   function of x (and of the load): the line search compares values.
 * - residual(ctx, x, r) writes r(x).  Returning anything but PM_SUCCESS
 *   says that x is inadmissible (J <= 0, a point inverted, a model outside
 *   its range): the line search shortens the step, and load stepping cuts
 *   the load step; the callback's message (PM_ERROR) is kept for the
 *   report.  A residual with an entry not finite is inadmissible too.  Only
 * PM_ERR_MEMORY, PM_ERR_IO and PM_ERR_INTERNAL abort the solve at once and are
 * returned as they are.
 * - jacobian_prepare(ctx, x), if given, is called once at each new
 *   linearisation point x (an accepted Newton iterate, where residual
 *   succeeded) before any jacobian_apply there; it may compute and cache
 *   per-point tangents.  It is called with the same x as the residual call
 *   that accepted it, but residual may also be called at other points (line
 *   search trials, finite differences) between jacobian_prepare and the
 *   last jacobian_apply at x: a residual call must not change what
 *   jacobian_apply computes.
 * - jacobian_apply(ctx, x, dx, dr) writes dr = J(x) dx exactly (the
 *   consistent linearisation of residual, not an approximation: Newton's
 *   quadratic convergence depends on it).  x holds the values last passed
 *   to jacobian_prepare (the pointer may differ).  Without
 *   jacobian_prepare, jacobian_apply works from x alone.  Any failure
 *   aborts the solve.  One assembly takes pm_newton_colors() calls, each
 *   with dx = 1 on the columns of one colour and 0 elsewhere.
 * - The pattern (pat_ptr[n + 1], pat_idx[pat_ptr[n]], CSR over unknowns)
 *   lists for each row i every column j with dr_i/dx_j possibly non-zero; a
 *   superset is allowed (its zeros are stored), a missing entry is not:
 *   colouring would add J_ij into another entry of row i.  The pattern is
 *   copied by pm_newton_create; columns of a row need not be sorted and may
 *   repeat.
 * - The callbacks are called from the thread that called pm_newton_solve
 *   or pm_load_steps, one at a time; they may use OpenMP inside.
 * - x arrays given to callbacks are read-only and valid only during the
 *   call; r and dr are written in full (n entries).
 *
 * Load stepping: set_load(ctx, lambda) sets the load factor, lambda in
 * [0, 1]; residual and the Jacobian are those at the last lambda set.  The
 * state passed to pm_load_steps is taken as converged at lambda = 0.
 *
 * Across ranks (pm_newton_problem.shared, in a run of more than one
 * rank), every rank creates the solver with its share of the unknowns and
 * calls each of the solver's functions together with the others (they are
 * collective).  A rank owns its unknowns 0 .. n-1, numbered offset ..
 * offset + n - 1 over all ranks (offset = pm_par_offset(n): the ranks'
 * shares follow one another in rank order), and holds n_ghost unknowns
 * more that other ranks own: local numbers n .. n + n_ghost - 1, global
 * numbers ghost[0 .. n_ghost-1].  Then
 *  - x, dx given to callbacks have n + n_ghost values (a ghost's is its
 *    owner's);
 *  - residual and jacobian_apply write n + n_ghost values: a ghost's is
 *    this rank's part of its owner's entry, added there (an assembly: each
 *    rank adds what its own elements or particles give);
 *  - the pattern has n + n_ghost rows over local column numbers, and the
 *    values of jacobian_values are added likewise (a ghost row's to its
 *    owner's row);
 *  - an inadmissible state on one rank is inadmissible on all (the lowest
 *    failing rank's message is every rank's);
 *  - the arrays the solver's own functions take (x of pm_newton_solve and
 *    pm_load_steps, the load state, near_null) have the n owned values.
 * Colouring would need the whole pattern: a shared problem gives
 * jacobian_values, with the operator PM_NEWTON_ASSEMBLED or
 * PM_NEWTON_MATRIX_FREE.  Norms, reasons and iteration counts are over all
 * ranks (every rank sees the same); times are the rank's own.  ILU is
 * block Jacobi with ILU(0) in each rank's block.
 *
 * PETSc is initialised on first use (without command-line arguments; a
 * program started without mpirun runs as one MPI process) and finalised
 * by pm_solve_finalize or at exit.  Objects are sequential (one process),
 * or on every rank for a shared problem; PETSc's own options, prefixed
 * "pm_" ("-pm_snes_monitor", "-pm_ksp_view", "-pm_pc_type ilu"), may be
 * given per solver in pm_newton_options.petsc_options and override the
 * options struct. */
#ifndef PM_NEWTON_H
#define PM_NEWTON_H

#include <stdbool.h>

#include "pm_checkpoint.h"
#include "pm_coloring.h"
#include "pm_error.h"
#include "pm_scene.h"

/* The most Newton iterations one solve may take (the length of the
 * per-iteration arrays of a report, less one). */
#define PM_NEWTON_MAX_ITER 200

/* Up to this many unknowns the direct solver's LU is dense (on one
 * process): the augmented preconditioner's (aux_n: the Schur complement
 * J0 - G D^-1 C formed), and the matrix's own where its pattern is a
 * tenth full or more; LAPACK's LU on every OpenMP thread, in place of
 * MUMPS's (docs/validation.md, "The coupled LU dense when it is small").
 * The PETSc option -pm_aug_dense_max N (solver_options) sets the bound of
 * a run; 0: never dense. */
#define PM_NEWTON_AUG_DENSE_MAX 5000L

struct pm_newton_report;

typedef struct {
  long n;    /* number of unknowns */
  void *ctx; /* passed to every callback */

  /* r(x); non-success: x inadmissible (see above).  Required. */
  pm_err (*residual)(void *ctx, const double *x, double *r);
  /* dr = J(x) dx.  Required. */
  pm_err (*jacobian_apply)(void *ctx, const double *x, const double *dx,
                           double *dr);
  /* Called once at each new linearisation point.  Optional (NULL). */
  pm_err (*jacobian_prepare)(void *ctx, const double *x);
  /* The Jacobian at x (after jacobian_prepare there) as values in the
   * order of the problem's pattern (val[k] for pat_idx[k]; repeated
   * entries are summed): the caller assembles it, and no colouring is
   * made.  Optional (NULL: colouring of jacobian_apply). */
  pm_err (*jacobian_values)(void *ctx, const double *x, double *val);
  /* Sparsity of J: row i's columns are pat_idx[pat_ptr[i] .. pat_ptr[i+1]).
   * Required. */
  const long *pat_ptr;
  const long *pat_idx;

  /* A cheaper operator P(x) dx ~ J(x) dx to build the preconditioner from
   * (op PM_NEWTON_MATRIX_FREE_CHEAP_PC only), on its own pattern
   * (pc_pat_ptr/pc_pat_idx, NULL: the Jacobian's).  Called after
   * jacobian_prepare at the same x.  Optional. */
  pm_err (*precond_apply)(void *ctx, const double *x, const double *dx,
                          double *dr);
  const long *pc_pat_ptr;
  const long *pc_pat_idx;
  /* The cheaper operator's values at x (after jacobian_prepare there) in
   * the order of its pattern (val[k] for pc_pat_idx[k]; repeated entries
   * are summed): the caller assembles it, and no colouring is made (in
   * place of precond_apply; op PM_NEWTON_MATRIX_FREE_CHEAP_PC only).  A
   * failure aborts the solve.  Optional (NULL). */
  pm_err (*precond_values)(void *ctx, const double *x, double *val);

  /* A preconditioner factorised from a larger matrix (the direct solver,
   * the solver's own or its fallbacks' (pm_newton_set_fallback_linear),
   * with op PM_NEWTON_MATRIX_FREE, one process): M = [J0 G; C I] over the
   * n unknowns and aux_n more, on the pattern aux_ptr/aux_idx (CSR over
   * n + aux_n; kept by the caller until the solver is destroyed; the rows
   * past n hold no column past n but their own for the dense path,
   * PM_NEWTON_AUG_DENSE_MAX), its values from aux_values at each new
   * preconditioner (after jacobian_prepare, in the pattern's order,
   * repeated entries summed).  The LU of M applied to [r; 0], first n
   * values, is (J0 - G C)^-1 r: the exact inverse of J when J is J0
   * coupled through aux_n intermediate values (an averaged volume's).
   * Used in place of the assembled Jacobian while the direct solver is
   * (jacobian_values is then not called).  Optional (0, NULL). */
  long aux_n;
  const long *aux_ptr, *aux_idx;
  pm_err (*aux_values)(void *ctx, const double *x, double *val);
  /* The same made on first use, for the fallbacks' direct solver
   * (pm_newton_set_fallback_linear): with aux_n 0 and aux_values given,
   * aux_prepare is called when a fallback first takes the direct solver,
   * and gives aux_n and the pattern then (kept by the caller until the
   * solver is destroyed): a run whose steps never fall back never holds
   * it.  Optional (NULL). */
  pm_err (*aux_prepare)(void *ctx, long *aux_n, const long **aux_ptr,
                        const long **aux_idx);

  /* Vectors (near_null_count of n values each, one after the other) the
   * Jacobian nearly annihilates -- for a solid, its rigid motions -- given
   * to algebraic multigrid (gmres-gamg) to build its coarse spaces from.
   * Read by pm_newton_create, not kept (at most 16).  Optional (0, NULL). */
  int near_null_count;
  const double *near_null;
  /* Unknowns come in blocks of this many (a point's displacement
   * components, consecutive), on one process: the assembled matrix says
   * so, and algebraic multigrid aggregates whole blocks.  0 or 1: no
   * blocks.  Optional. */
  int block_size;

  /* Across ranks (see above): the problem is shared by the ranks when
   * this is set and more than one rank runs; ghost lists the global
   * numbers of the n_ghost unknowns held beyond the owned.  false, 0,
   * NULL: one process's problem. */
  bool shared;
  long n_ghost;
  const long *ghost;

  /* Load stepping only (pm_load_steps); NULL otherwise. */
  pm_err (*set_load)(void *ctx, double lambda);
  /* After each converged load step (step counts from 1, lambda the load
   * reached, x the converged state, report that step's last Newton solve).
   * A failure stops the stepping and is returned.  Optional. */
  pm_err (*on_step)(void *ctx, int step, double lambda, const double *x,
                    const struct pm_newton_report *report);
  /* Where a state that load stepping gives up at stands (x: the owned
   * values of the last state tried, at the load of the failing step): one
   * line into buf (cap bytes) naming, say, the point of largest
   * out-of-balance force and of smallest volume ratio, with their
   * positions; appended to the failure's message.  A failure of its own
   * is ignored.  Optional. */
  pm_err (*diagnose)(void *ctx, const double *x, char *buf, long cap);
  /* Where a vector of the unknowns v (a mode of the tangent) stands: one
   * line into buf (cap bytes), say the point where it is largest and its
   * mirror symmetry.  A failure of its own is ignored.  Optional. */
  pm_err (*describe_mode)(void *ctx, const double *v, char *buf, long cap);
  /* Load stepping: after a step's Newton solve has converged at x, a set
   * the residual depends on made consistent with x (contact: the points
   * the solution pulls off a body let go).  *changed: how many entries
   * changed (0: x stands, the step is done; else Newton solves the step
   * again from x, at most PM_SETTLE_PASSES times, and a set still changing
   * then fails the step, which is cut, with what into buf: cap bytes, one
   * line naming what changed).  Called on every process; *changed must be
   * the same on all (a count over the whole problem), since they solve the
   * step again together.  Optional. */
  pm_err (*settle)(void *ctx, const double *x, long *changed, char *buf,
                   long cap);
} pm_newton_problem;

/* The most times a load step is solved again for its settle callback. */
#define PM_SETTLE_PASSES 4

/* The linear solver of each Newton iteration.  With a matrix-free operator
 * the factorisation or preconditioner is built from the assembled matrix
 * and preconditions GMRES (CG for cg-jacobi). */
typedef enum {
  PM_NEWTON_DIRECT = 0, /* LU: MUMPS (null pivots of a singular J set aside,
                           ICNTL(24) = 1), else PETSc's own */
  PM_NEWTON_GMRES_GAMG, /* GMRES + algebraic multigrid */
  PM_NEWTON_CG_JACOBI,  /* CG + Jacobi: symmetric positive definite J only */
  PM_NEWTON_GMRES_ILU,  /* GMRES + ILU(0) */
  PM_NEWTON_CG_GAMG     /* CG + algebraic multigrid: symmetric positive
                           definite J only */
} pm_newton_linear;

/* What the linear solver multiplies by, and what it preconditions with. */
typedef enum {
  PM_NEWTON_ASSEMBLED = 0,       /* J assembled by colouring, used for both */
  PM_NEWTON_MATRIX_FREE,         /* J applied by jacobian_apply; J assembled
                                    by colouring for the preconditioner */
  PM_NEWTON_MATRIX_FREE_CHEAP_PC /* J applied by jacobian_apply; P assembled
                                    by colouring from precond_apply, or by
                                    the caller (precond_values) */
} pm_newton_operator;

typedef enum {
  PM_LINE_SEARCH_BT = 0, /* backtracking (cubic), the default */
  PM_LINE_SEARCH_BASIC,  /* full Newton step; a domain error then fails */
  PM_LINE_SEARCH_L2,     /* secant on the residual norm along the step */
  PM_LINE_SEARCH_CP,     /* critical point (for residuals that are gradients) */
  PM_LINE_SEARCH_FULL_L2 /* the full step where it lowers the residual
                            enough (as backtracking's first trial), else
                            the secant (PM_LINE_SEARCH_L2) */
} pm_line_search;

typedef struct {
  /* Convergence: a criterion with tolerance > 0 is on.  A solve has
   * converged after iteration k (x_{k+1} = x_k + alpha_k dx_k, J(x_k) dx_k
   * = -r(x_k)) when every criterion that is on holds (all_criteria) or any
   * one holds (!all_criteria); |r| <= atol always stops it.
   *   residual:      |r(x_{k+1})| <= rtol |r(x_0)|  (in pm_load_steps
   *                  with the predictor, rtol is relative to the larger of
   *                  |r(x_0)| and |r| of the last converged state under
   *                  the new load, so a good prediction does not tighten
   *                  it down to roundoff)
   *   displacement:  |dx_k| <= dtol |x_{k+1} - x_start|  (x_start: the
   *                  initial guess of pm_newton_solve; in pm_load_steps the
   *                  last converged state, also with the predictor;
   *                  alpha_k is not applied to dx_k)
   *   energy:        |dx_k . r(x_k)| <= etol |dx_0 . r(x_0)|
   * Norms are Euclidean over all unknowns.  A tolerance below the
   * residual's roundoff (about 1e-16 times the largest internal force
   * entry, times sqrt(n)) cannot be met: the solve then ends in a line
   * search failure at that level. */
  double rtol;       /* 1e-8 */
  double atol;       /* 0; scale-dependent: the caller's to set (a force) */
  double dtol;       /* 0 (off) */
  double etol;       /* 0 (off) */
  bool all_criteria; /* false */
  int max_iter;      /* 25, at most PM_NEWTON_MAX_ITER */
  /* A solve that has not halved the residual over the last two
   * iterations, at iteration stall_after or later, stops as stalled (a
   * failure load stepping answers by cutting the step, instead of creeping
   * on with short line-search steps up to max_iter); 0: never. */
  int stall_after; /* 0 */
  /* ...and, from the second iteration on, one whose linear solves have
   * taken more than stall_linear iterations in all: an iterative solver's
   * work far from Newton's basin, each solve dearer than the smaller step
   * a cut would take; 0: never. */
  int stall_linear; /* 0 */

  pm_newton_linear linear; /* PM_NEWTON_DIRECT */
  double linear_rtol;      /* iterative solvers: 1e-10 */
  /* Inexact Newton (Eisenstat-Walker, choice 2) for an iterative linear
   * solve (a Krylov method, the direct solver's too when it preconditions
   * a matrix-free operator or a kept factorisation): each linear solve
   * to eta_k = 0.9 (|r_k| / |r_(k-1)|)^2, safeguarded by 0.9 eta_(k-1)^2
   * when that exceeds 0.1, at most linear_ew_max (the first of a solve:
   * linear_ew_max), no tighter than half of Newton's residual target over
   * |r_k| nor than linear_rtol.  false: every solve to linear_rtol. */
  bool linear_ew;       /* false */
  double linear_ew_max; /* 1e-2 (when linear_ew) */
  int linear_max_iter;  /* iterative solvers: 1000 */
  /* GMRES's restart: the Krylov vectors kept (each of n values); 0:
   * PETSc's (30).  -pm_ksp_gmres_restart in petsc_options overrides it. */
  int gmres_restart;     /* 0 */
  pm_newton_operator op; /* PM_NEWTON_ASSEMBLED */
  /* Matrix-free operators: rebuild the preconditioner every pc_lag Newton
   * iterations (1: every one). */
  int pc_lag; /* 1 */
  /* Keep the factorisation or preconditioner while the linear solves it
   * serves converge in at most this many iterations: the next Jacobian
   * after a solve that took more (or failed) builds a new one, the others
   * are applied (the current one, assembled or matrix-free) with the kept
   * one preconditioning GMRES (the direct solver too).  0: a new one at
   * every Jacobian (every pc_lag with a matrix-free operator). */
  int pc_reuse_its; /* 0 */
  /* With pc_reuse_its: a linear solve on a kept one that fails, or takes
   * more iterations than the kept one's first solve by pc_reuse_cost times
   * pc_reuse_its (about what a new LU costs in iterations where FPM keeps
   * one: 17-60), is made again on a new one.  0: off. */
  double pc_reuse_cost; /* 4 */
  /* gamg: keep the hierarchy's interpolation over set-ups, only the coarse
   * operators recomputed (PETSc's -pc_gamg_reuse_interpolation). */
  bool amg_reuse; /* false */
  /* GAMG aggregates on the matrix's graph, not on its square (PETSc's
   * default; on a wide stencil: a coarse level of a few dozen unknowns). */
  bool amg_unsquared; /* false */
  /* Multigrid preconditioning a matrix-free operator: the finest level's
   * smoother and residual multiply by the assembled preconditioning
   * matrix, not the operator (PETSc's -pc_use_amat false; with PETSc's
   * default they call jacobian_apply about four times a V-cycle). */
  bool amg_assembled_smoother; /* false */
  /* and, on one process, through a shell on the OpenMP threads, from a
   * single-precision copy (pm_newton_fine.c) */
  bool amg_threaded; /* false */
  /* Krylov solvers preconditioned on the right: their residual and
   * tolerance are the true residual's (on the left, PETSc's default, the
   * preconditioned one's, which says little of the true residual when the
   * preconditioner comes from a cheaper operator: inexact Newton's steps
   * then miss their tolerance).  -pm_ksp_pc_side overrides it. */
  bool pc_right;              /* false */
  pm_coloring_order coloring; /* PM_COLORING_LARGEST_FIRST */
  pm_line_search line_search; /* PM_LINE_SEARCH_BT */

  /* Load stepping (pm_load_steps). */
  int load_steps;     /* nominal steps from lambda 0 to 1: 10 */
  int max_cuts;       /* halvings allowed in a row for one step: 10 */
  double min_dlambda; /* smallest step (0: 1/load_steps/2^max_cuts) */
  int grow_after;     /* after this many converged steps in a row at a cut
                         step, grow it by half (up to the nominal); 0
                         never: 2 */
  /* After an easy step (converged in at most easy_iterations Newton
   * iterations) the next grows by half, up to max_dlambda (0: the nominal
   * 1/load_steps); 0: growth only back to the nominal after cuts. */
  int easy_iterations; /* 0 */
  double max_dlambda;  /* 0 */
  /* The fallback of a step Newton cannot finish: dynamic relaxation within
   * the step (pm_load_relax.c) from the last converged state under the
   * step's load, with a mass per unknown from the tangent's row sums there
   * (raised where the response turns out stiffer) and damping from the
   * Rayleigh quotient of each increment, until the residual has fallen by
   * relax_rtol; then Newton again from there, and if that fails too,
   * relaxation on from Newton's last iterate to Newton's own tolerance.
   * Tried once a step has been cut relax_after times in a row, and again
   * before giving up at the smallest step; relax_max_iter iterations (one
   * residual each) per relaxation.  0: never.  One process's problems
   * only. */
  int relax_after;    /* 2 */
  int relax_max_iter; /* 20000 */
  double relax_rtol;  /* 1e-3 */
  /* After a step that relaxation carried (the continuation before it
   * failed or is off, or past a snap arc length found), the steps that
   * follow are relaxed first (then
   * Newton from there, as that relaxation), skipping the Newton attempts
   * and the continuation that failed on the step before; the first step
   * this fails on goes the ordinary way, and so do the steps after it
   * until relaxation carries one again.  Once relaxation has carried a
   * step, a step that falls back (Newton cut relax_after times) tries
   * relaxation before the lowest mode, arc length and the continuation,
   * which then go without a relaxation of their own.  false: every step
   * the ordinary way. */
  bool relax_first; /* false */
  /* Before that relaxation, where relax_after would try it: pseudo-
   * transient continuation within the step (pm_load_ptc.c), from the last
   * converged state under the step's load to Newton's tolerance: Newton
   * on J + M / dtau (M the relaxation's masses), dtau growing as the
   * residual falls, at most ptc_max_iter iterations (one linear solve
   * each); relaxation follows only if it fails.  It passes where the
   * tangent is singular or indefinite along the path (a fold, a
   * bifurcation), which stalls Newton at any step size.  0: never (the
   * relaxation alone).  One process's problems only. */
  int ptc_max_iter; /* 0 */
  /* Where arc length finds a limit point (the load turning back along the
   * path), the step's state past it: false, relaxation at the step's load
   * from the last converged state carries it to the stable branch the
   * structure jumps to (the dynamic answer of a snap under a prescribed
   * load or displacement); true, the arc follows the path round the fold
   * and on to the step's load (within its bounds), which may end on
   * another branch. */
  bool follow_fold; /* false */
  /* CPU seconds (the process's, all threads) each fallback of a step (the
   * lowest mode, arc length, a continuation, a relaxation) may take
   * before it stops and the next is tried; 0: no bound. */
  double fallback_seconds; /* 0 */
  bool predictor;          /* start each step from the linear extrapolation of
                              the last two converged states, or where there are
                              not two (the first step) from the tangent
                              predictor: xc + dx with J(xc) dx = -(r(xc) + the
                              change of r over the step linearised in the
                              load), one extra linear solve: false */

  /* PETSc options for this solver's SNES, KSP, PC, line search and the
   * objects PETSc makes inside them (factor matrices, multigrid levels),
   * with prefix "pm_" ("-pm_snes_monitor -pm_ksp_type bcgs
   * -pm_mat_mumps_icntl_14 50"); NULL: none.  Applied after the settings
   * above, so they override them; they are this solver's alone. */
  const char *petsc_options;
} pm_newton_options;

/* The solver of a scene's time.quasi_static.linear_solver. */
pm_newton_linear pm_newton_linear_of(pm_linear_solver l);
/* The line search a scene's time.quasi_static.line_search names (auto:
 * the method's own, own). */
pm_line_search pm_newton_line_search_of(pm_qs_line_search l,
                                        pm_line_search own);

/* The options above with their defaults. */
pm_newton_options pm_newton_options_default(void);

/* Why a solve stopped.  Every DIVERGED reason is a failure load stepping
 * answers by cutting the step. */
typedef enum {
  PM_NEWTON_NOT_RUN = 0,
  PM_NEWTON_CONVERGED_RESIDUAL,     /* rtol */
  PM_NEWTON_CONVERGED_ABSOLUTE,     /* atol (also: r(x_0) = 0, no step) */
  PM_NEWTON_CONVERGED_DISPLACEMENT, /* dtol */
  PM_NEWTON_CONVERGED_ENERGY,       /* etol */
  PM_NEWTON_CONVERGED_ALL,          /* every criterion on (all_criteria) */
  PM_NEWTON_DIVERGED_MAX_ITER,      /* max_iter without converging */
  PM_NEWTON_DIVERGED_STALLED,       /* the residual not halved over two
                                       iterations (stall_after,
                                       stall_linear) */
  PM_NEWTON_DIVERGED_LINE_SEARCH,   /* no step decreased the residual */
  PM_NEWTON_DIVERGED_NAN,           /* residual not finite */
  PM_NEWTON_DIVERGED_DOMAIN,        /* residual inadmissible at the start,
                                       or no admissible step found */
  PM_NEWTON_DIVERGED_LINEAR         /* the linear solver failed (no
                                       convergence, a singular matrix) */
} pm_newton_reason;

/* "converged (residual)", "diverged (max iterations)", ... */
const char *pm_newton_reason_name(pm_newton_reason r);

/* What one Newton solve did.  Arrays are indexed by iteration: entry 0 is
 * the initial state, entry k the state after iteration k (k <=
 * iterations). */
typedef struct pm_newton_report {
  pm_newton_reason reason;
  pm_err status;     /* PM_SUCCESS if converged, else the error returned */
  char message[512]; /* one line: the reason with its figures (empty on
                        success), e.g. "Newton did not converge in 25
                        iterations (residual 3.2e-04 from 1.1e+00)" */
  int iterations;
  int linear_iterations;      /* summed over the iterations */
  long residual_evaluations;  /* residual calls (line search included) */
  long jacobian_applications; /* jacobian_apply and precond_apply calls */
  double residual_norm[PM_NEWTON_MAX_ITER + 1];  /* |r(x_k)| */
  double increment_norm[PM_NEWTON_MAX_ITER + 1]; /* |dx_{k-1}| (0: 0) */
  double energy[PM_NEWTON_MAX_ITER + 1];         /* |dx_{k-1}.r(x_{k-1})| */
  double step_length[PM_NEWTON_MAX_ITER + 1];    /* alpha_{k-1} (0: 0) */
  /* The tangent's smallest curvature along a Newton direction over the
   * iterations, as the cosine dx.J dx / (|dx| |J dx|) = -dx.r / (|dx|
   * |r|) (0: none): negative, J is indefinite there (a fold, a
   * bifurcation), and the direction climbs the energy where r is its
   * gradient. */
  double min_curvature;
  /* Wall seconds: residual calls; Jacobian preparation and assembly
   * (colouring applications and insertion); linear solves (factorisation,
   * Krylov iterations, matrix-free applications); the whole solve (the
   * rest is vector work and the line search's own Jacobian product);
   * time_setup: the part of time_linear that set the preconditioner up
   * (the factorisation, the multigrid hierarchy). */
  double time_residual, time_assembly, time_linear, time_total;
  double time_setup;
  int pc_setups; /* factorisations or preconditioner set-ups */
  /* Of time_linear: the matrix-free products (jacobian_apply). */
  double time_apply;
  /* The process's CPU seconds (all threads) in the same parts. */
  double cpu_residual, cpu_assembly, cpu_linear, cpu_setup, cpu_apply;
  int jacobians; /* linearisations: jacobian_prepare and assembly calls */
} pm_newton_report;

/* A solver for one problem: the colouring, PETSc's matrix, vectors, SNES
 * and linear solver, created once and reused by every solve (nothing is
 * allocated per iteration but what PETSc allocates itself).  Several may
 * exist at once; one solve runs at a time in a process (PETSc is not
 * thread-safe). */
typedef struct pm_newton pm_newton;

/* Checks the problem (n, callbacks, pattern indices in [0, n)) and the
 * options (PM_ERR_ARG naming the bad value), colours the pattern, and
 * creates the PETSc objects.  problem is copied (its pattern too); ctx
 * must outlive the solver.  *out is NULL on failure. */
pm_err pm_newton_create(const pm_newton_problem *problem,
                        const pm_newton_options *options, pm_newton **out);
/* Releases everything of *s and sets it to NULL; NULL is allowed. */
void pm_newton_destroy(pm_newton **s);

/* The linear solver of load stepping's fallbacks (pm_load_steps: the
 * tangent's lowest mode, arc length, continuation, relaxation and the
 * Newton solves among them): alt's linear solver and its settings
 * (linear, linear_rtol, linear_ew, linear_ew_max, linear_max_iter,
 * gmres_restart, pc_reuse_its, pc_reuse_cost, pc_right, amg_*) in place of
 * the solver's own while a step's fallback runs, and with keep for every
 * step after the first that fell back (the load stepping's state says so,
 * and a resume takes it), else the solver's own again after it.
 * Multigrid where Newton passes, the LU where the tangent turns singular
 * (a fold, and the steps near it, where multigrid's solves crawl): each
 * where it is the cheaper.  alt's other fields are not read; NULL: the
 * solver's own throughout (the default).  Not with the cheap operator
 * (MATRIX_FREE_CHEAP_PC: its matrix is no tangent to factorise) nor the
 * augmented preconditioner as the solver's own: PM_ERR_ARG. */
pm_err pm_newton_set_fallback_linear(pm_newton *s, const pm_newton_options *alt,
                                     bool keep);

/* Colours of the Jacobian's pattern (the jacobian_apply calls one
 * assembly takes), and of the cheap preconditioner's (0 if none). */
int pm_newton_colors(const pm_newton *s);
int pm_newton_pc_colors(const pm_newton *s);

/* How multigrid's finest level has multiplied since the solver was made
 * (pm_newton_fine.c): "petsc" (PETSc's own product: across ranks, a
 * level that did not come to be, or no multigrid), "double" (the values
 * as they are, on every thread), "single" (their single-precision copy)
 * or "single, 3 x 3 blocks". */
const char *pm_newton_fine_storage(const pm_newton *s);

/* One Newton solve from x[0..n-1], the initial guess, which receives the
 * last iterate (the solution on success; on failure the last iterate
 * accepted by the line search, never an inadmissible trial).  report (may be
 * NULL) is filled in either case.  Returns PM_SUCCESS when converged;
 * PM_ERR_NOT_CONVERGED (max iterations, line search, linear solver) or
 * PM_ERR_UNSTABLE (NaN, domain) with report->message as the error message; a
 * callback's hard failure or a PETSc failure as it is. */
pm_err pm_newton_solve(pm_newton *s, double *x, pm_newton_report *report);

/* held (n + n_ghost values) = the owned values x (n) with their ghosts'
 * values from their owners: what the callbacks see of x (a copy on one
 * process; collective for a shared problem). */
pm_err pm_newton_held_values(pm_newton *s, const double *x, double *held);

/* Load stepping: pm_load_report, pm_load_steps, its state. */
#include "pm_load_steps.h"

/* The assembled Jacobian at x (jacobian_prepare, then colouring) as values
 * in the order of the problem's pattern: val[pat_ptr[i] + k] = J_ij for j
 * = pat_idx[pat_ptr[i] + k] (a repeated column gets the value at each
 * place).  For checks of a linearisation. */
pm_err pm_newton_jacobian_values(pm_newton *s, const double *x, double *val);

/* Compares the coloured Jacobian at x with central differences of
 * residual in every column (2n residual calls: small problems), step h
 * |x_j| + h in column j.  *max_error: the largest |J_fd - J| over all
 * entries (also those outside the pattern) divided by the largest |J_fd|;
 * *row, *col (may be NULL): where it is. */
pm_err pm_newton_check_jacobian(pm_newton *s, const double *x, double h,
                                double *max_error, long *row, long *col);

/* Finalises PETSc if this module initialised it (also registered to run
 * at exit).  No solver may be used afterwards, nor PETSc re-initialised. */
void pm_solve_finalize(void);

#endif
