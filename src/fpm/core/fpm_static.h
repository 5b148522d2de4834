/* fpm_static: quasi-static equilibrium of an FPM model by Newton's method
 * in load steps (time.quasi_static.method: static), with the consistent
 * tangent of fpm_force_linear assembled by colouring, through the shared
 * PETSc layer (pm_newton).  The load path is proportional: at load factor
 * lambda the prescribed displacements and tractions are lambda times their
 * values once every ramp has ended (t_load, pm_scene_load_end); a frame's
 * time is lambda t_load. */
#ifndef FPM_STATIC_H
#define FPM_STATIC_H

#include "fpm_solver.h"
#include "pm_newton.h"

/* What the static solve did, beside the step figures. */
typedef struct {
  pm_load_report load;  /* steps, cuts, iterations, times */
  long unknowns;        /* free dofs */
  long pattern_entries; /* stored Jacobian entries */
  long coupled_entries; /* those of the coupled factorisation (0: none) */
  double setup_seconds; /* pattern, tangent geometry, PETSc objects */
  /* The whole solve of this run (set-up and load steps): wall and CPU
   * seconds (the process's, every thread's). */
  double seconds, cpu_seconds;
  /* Sticking contact: points held at a converged step though pulled off
   * their body (grazing: let go once in the step, they came back), summed
   * over steps, and the largest gap one was held at (m). */
  long contact_frozen;
  double contact_frozen_gap;
} fpm_static_report;

/* Free dofs (over all ranks) up to which a static solve's default linear
 * solver is direct (MUMPS LU of the assembled tangent, kept over Newton
 * iterations: time.quasi_static.reuse_iterations); above, GMRES with
 * algebraic multigrid (GAMG on the rigid-body near null space, blocks of
 * a point's components; FPM_STATIC_AMG_*), whose memory grows with the
 * tangent where the factorisation's grows faster.  Measured on F3 60% on a
 * quiet machine (docs/validation.md, "Static solves: multigrid from 1500
 * free dofs, the LU in the fallbacks"): at 474 points (1100 free dofs)
 * the two cost the same wall time, multigrid 60% of the memory; at 700
 * points multigrid 0.7 of the time, at 1851 points (4359) half the time
 * and a third of the memory (the LU's factors are about as many as a
 * dense matrix's); at 13762 (36 549) the coupled LU took 13 GB.  Those
 * were MUMPS's figures: up to PM_NEWTON_AUG_DENSE_MAX free dofs the
 * coupled LU is now dense (LAPACK), and it took 0.73, 0.71 and 0.89 of
 * multigrid's wall time at 700, 1201 and 1851 points, at 1.7 to 2.1 times
 * its memory (docs/validation.md, "The coupled LU dense"): the bound was
 * left where it was. */
#define FPM_STATIC_DIRECT_MAX 1500L
/* Free dofs up to which a default multigrid solve (above
 * FPM_STATIC_DIRECT_MAX) hands load stepping's fallbacks (a fold's
 * lowest mode, arc length, continuation, relaxation: a singular tangent,
 * where multigrid's solves crawl) to the LU of the tangent, kept for the
 * rest of the run (pm_newton_set_fallback_linear), the memory of the LU
 * then needed: FPM_STATIC_COUPLED_MAX, the coupled LU's bound, so that
 * the blocks' 4036-point budgets (8877-10071 free dofs) get it (F3 200%
 * there: 1034 CPU s and 1.7 GiB, where multigrid's arcs crawled past 18
 * minutes; docs/validation.md, "The completion matrix"). */
#define FPM_STATIC_FALLBACK_DIRECT_MAX FPM_STATIC_COUPLED_MAX
/* Free dofs (over all ranks) up to which the averaged volume's coupling
 * is factorised by default (time.quasi_static.averaged_coupling): its LU
 * takes about 1.8 times the memory of the tangent's (805 against 457 MiB
 * at 4359 free dofs, 13 GB at 41 000), about 4 GB here; above, the
 * tangent's LU without the coupling preconditions GMRES.  It matters
 * where a scene names the direct solver above FPM_STATIC_DIRECT_MAX. */
#define FPM_STATIC_COUPLED_MAX 15000L
/* The multigrid solve's relative tolerance. */
#define FPM_STATIC_AMG_RTOL 1e-6
/* GMRES's restart with multigrid (the tangent of the quadratic jump takes
 * tens of iterations a solve; PETSc's 30 restarts and stalls). */
#define FPM_STATIC_AMG_RESTART 200
/* With multigrid and no time.quasi_static.reuse_iterations: the hierarchy
 * is kept while the solves it preconditions take at most this many
 * iterations. */
#define FPM_STATIC_AMG_REUSE 40
/* With multigrid: a load step's Newton solve that has not halved the
 * residual over two iterations while its solves took more than this many
 * GMRES iterations in all (five times a usual solve's 20-45) is cut then,
 * not at stall_after (pm_newton_options.stall_linear; docs/validation.md,
 * "The finest level in single precision, and the first step cut sooner"). */
#define FPM_STATIC_STALL_LINEAR 200

/* Whether a static solve of scene s (model m) with this many free dofs
 * (over all ranks) hands its fallbacks to the LU
 * (FPM_STATIC_FALLBACK_DIRECT_MAX): no time.quasi_static.linear_solver,
 * multigrid by default, built on the tangent (not on the supports:
 * fpm_static_amg_on_support).  m NULL (an estimate before the model):
 * the supports' case counted as falling back. */
bool fpm_static_fallback_direct(const pm_scene *s, const fpm_model *m,
                                long unknowns);

/* Whether a static solve of scene s (model m, with this many free dofs
 * over all ranks, linear solver `linear`) factorises the averaged
 * volume's coupling: the averaged volume, one process, the direct
 * solver (or multigrid whose fallbacks take the LU:
 * fpm_static_fallback_direct), time.quasi_static.averaged_coupling, and
 * when the key is not
 * given at most FPM_STATIC_COUPLED_MAX free dofs. */
bool fpm_static_couples(const pm_scene *s, const fpm_model *m, long unknowns,
                        pm_newton_linear linear);

/* Whether multigrid (linear solver `linear`) is built on the tangent of
 * each point's support in a static solve of scene s, model m (one
 * process, time.quasi_static.multigrid_operator support or support2; not
 * the default): see fpm_static_support.c. */
bool fpm_static_amg_on_support(const pm_scene *s, const fpm_model *m,
                               pm_newton_linear linear);

/* Bytes of a static solve's tangent with its LU factors (coupled: of
 * the averaged volume's coupled matrix) or its multigrid hierarchy, for
 * this many free dofs; *entries (if given): the tangent's entries.  The
 * figures are whole runs' peak memory over the tangent's entries
 * (docs/validation.md, "Bad disks, memory for solves, and signals"), so
 * they hold the operators and state too: an upper bound. */
double fpm_static_solver_bytes(long free_dofs, bool quadratic,
                               pm_newton_linear linear, bool coupled,
                               double *entries);

/* The default linear solver for a static solve of this many unknowns. */
pm_newton_linear fpm_static_default_linear(long unknowns);

/* o's linear solver for scene s and this many unknowns (over all ranks):
 * the scene's time.quasi_static.linear_solver when it gives one, else
 * fpm_static_default_linear; with the scene's reuse_iterations and
 * inexact; a multigrid one with its tolerance, restart and set-up reuse,
 * and inexact Newton unless the scene sets it. */
void fpm_static_choose_linear(const pm_scene *s, long unknowns,
                              pm_newton_options *o);

/* Solve from rest with the settings of the model's scene
 * (time.quasi_static: tolerance, load_steps, max_iterations, linear_solver,
 * solver_options; stability.min_jacobian).  observer sees the initial state
 * (step 0) and every converged load step as a frame (step = load step, t =
 * lambda t_load). On failure returns the error of pm_load_steps
 * (PM_ERR_NOT_CONVERGED, PM_ERR_UNSTABLE) with a message naming the load step,
 * the load factor and the cause; info then holds the last converged step's
 * figures. */
pm_err fpm_static_run(const fpm_model *m, fpm_state *st, fpm_observer observer,
                      void *ctx, fpm_step_info *info, fpm_static_report *rep);

/* What a static run carries from one load step to the next, kept by the
 * caller so that a checkpoint can write it: the load stepping's state over
 * the free dofs, and the work of the supports and tractions so far. */
typedef struct {
  pm_load_state load;
  long free_dofs; /* the length of load.xc and load.xprev */
  double external_work;
} fpm_static_state;

/* The unknowns of model m (its own points' free dofs: all its points' on
 * one process) as displacements u (3 per own point, 0 at the prescribed
 * dofs), and back: how load stepping's states cross between a share and
 * the whole model. */
void fpm_static_nodal(const fpm_model *m, const double *x, double *u);
/* The same over n points whose prescribed dofs are fixed (3 n). */
void fpm_static_nodal_fixed(long n, const unsigned char *fixed, const double *x,
                            double *u);
void fpm_static_unknowns(const fpm_model *m, const double *u, double *x);

/* A state for model m (from rest).  PM_ERR_MEMORY. */
pm_err fpm_static_state_init(fpm_static_state *s, const fpm_model *m);
void fpm_static_state_free(fpm_static_state *s);

/* fpm_static_run keeping its state in *ss.  With ss->load.lambda > 0 (a
 * checkpoint's) it continues from there without reporting the initial
 * state, rep->load's counters going on from their values; the steps that
 * follow are those the first run would have taken. */
pm_err fpm_static_run_from(const fpm_model *m, fpm_state *st,
                           fpm_static_state *ss, fpm_observer observer,
                           void *ctx, fpm_step_info *info,
                           fpm_static_report *rep);

/* Checks of the directly assembled tangent at the state u (3 n, prescribed
 * dofs included): its largest difference from the tangent coloured from
 * fpm_force_linear (*assembled_error) and from central differences of the
 * force (*difference_error, 2 x free-dof force evaluations: small models),
 * each over the largest entry. */
pm_err fpm_static_check_tangent(const fpm_model *m, fpm_state *st,
                                const double *u, double *assembled_error,
                                double *difference_error);

#endif
