/* fpm_static: Newton's method in load steps on the free dofs of an FPM
 * model.  Unknowns are the free displacement components; the prescribed
 * ones follow the load factor.  This file runs the load stepping (and the
 * tangent's check); the problem, the tangent, its pattern and the unknowns
 * are in fpm_static_problem.c, _tangent.c, _pattern.c and _unknowns.c. */
#include "fpm_static.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_contact.h"
#include "fpm_static_impl.h"
#include "pm_progress.h"

/* A force floor far below any load but above the force's round-off: the
 * stiffest modulus times the squared size of the body, times 1e-12. */
static double force_floor(const fpm_model *m) {
  double emax = 0, lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < m->n_mats; k++)
    emax = fmax(emax, m->mats[k].youngs_modulus);
  for (long i = 0; i < m->n_own; i++)
    for (int a = 0; a < 3; a++) {
      lo[a] = fmin(lo[a], m->x[3 * i + a]);
      hi[a] = fmax(hi[a], m->x[3 * i + a]);
    }
  if (m->xc) { /* the body's box: every rank's points (the same floor) */
    fpm_exchange_min(m->xc, lo, 3);
    for (int a = 0; a < 3; a++) hi[a] = -hi[a];
    fpm_exchange_min(m->xc, hi, 3);
    for (int a = 0; a < 3; a++) hi[a] = -hi[a];
  }
  double diag2 = 0;
  for (int a = 0; a < 3; a++) diag2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  return 1e-12 * emax * diag2;
}

/* Per tangent entry, measured as the peak memory of whole F2 and F3 60%
 * runs over the tangent's entries: the LU 180 (F3, quadratic jump) to
 * 207 (F2, linear jump) bytes at 4359 and 4759 free dofs, taken as 210;
 * the coupled LU of the averaged volume 318, taken as 330; both growing
 * with the fill about as the free dofs to the power 0.25 (nested
 * dissection's factors grow as n^(4/3) against the tangent's n; the
 * coupled LU took 13.0 GB at 36 549 free dofs); multigrid (GAMG, its
 * operator complexity included) 68 at 4359, 48 at 36 549 and 46 at
 * 89 535 since the tangent is written in the matrix's own storage
 * (docs/validation.md, "Static solves: the matrix in the pattern's
 * order"; 116 at 4359 before; the finest level's single-precision copy,
 * 4.4 bytes an entry, within it: the peak comes before), taken as 75,
 * flat.  Entries
 * per free dof: 650 with the quadratic jump (3 rings), 403 with the linear
 * jump.  The LU up to PM_NEWTON_AUG_DENSE_MAX free dofs is dense (the
 * tangent's alone where it is a tenth full or more): 8 n^2 bytes, and the
 * coupled values. */
double fpm_static_solver_bytes(long free_dofs, bool quadratic,
                               pm_newton_linear linear, bool coupled,
                               double *entries) {
  const double n = (double)free_dofs, nnz = (quadratic ? 650.0 : 403.0) * n,
               fill = pow(n / 4359.0, 0.25);
  if (entries) *entries = nnz;
  if (linear != PM_NEWTON_DIRECT) return 75.0 * nnz;
  /* the LU dense (pm_newton_dense.c): the matrix, and with the coupling
   * the coupled matrix's values (about 1.4 times the tangent's entries:
   * 493 k against 359 k at 813 free dofs); without it where the tangent is
   * a tenth full or more */
  if (free_dofs <= PM_NEWTON_AUG_DENSE_MAX && (coupled || nnz >= 0.1 * n * n))
    return 8.0 * n * n + 8.0 * (coupled ? 1.4 : 0.0) * nnz;
  return (coupled ? 330.0 : 210.0) * fill * nnz;
}

pm_newton_linear fpm_static_default_linear(long unknowns) {
  return unknowns <= FPM_STATIC_DIRECT_MAX ? PM_NEWTON_DIRECT
                                           : PM_NEWTON_GMRES_GAMG;
}

bool fpm_static_couples(const pm_scene *s, const fpm_model *m, long unknowns,
                        pm_newton_linear linear) {
  if (!m->vavg || m->xc || !s->time.qs_coupled ||
      (linear != PM_NEWTON_DIRECT &&
       !fpm_static_fallback_direct(s, m, unknowns)))
    return false;
  return pm_scene_has(s, "time.quasi_static.averaged_coupling") ||
         unknowns <= FPM_STATIC_COUPLED_MAX;
}

bool fpm_static_amg_on_support(const pm_scene *s, const fpm_model *m,
                               pm_newton_linear linear) {
  return (linear == PM_NEWTON_GMRES_GAMG || linear == PM_NEWTON_CG_GAMG) &&
         !m->xc && s->time.qs_amg != PM_AMG_TANGENT;
}

/* pm_newton_problem.aux_prepare: the averages' coupling, for the
 * fallbacks' LU (ctx: the solve's context, the first member of its
 * fpm_static_solve). */
static pm_err coupled_prepare(void *ctx, long *aux_n, const long **aux_ptr,
                              const long **aux_idx) {
  fpm_static_solve *v = (fpm_static_solve *)ctx;
  PM_CALL(fpm_static_coupled_build(v));
  *aux_n = v->prob.aux_n;
  *aux_ptr = v->prob.aux_ptr;
  *aux_idx = v->prob.aux_idx;
  return PM_SUCCESS;
}

bool fpm_static_fallback_direct(const pm_scene *s, const fpm_model *m,
                                long unknowns) {
  return !pm_scene_has(s, "time.quasi_static.linear_solver") &&
         unknowns > FPM_STATIC_DIRECT_MAX &&
         unknowns <= FPM_STATIC_FALLBACK_DIRECT_MAX &&
         !(m && fpm_static_amg_on_support(s, m, PM_NEWTON_GMRES_GAMG));
}

/* The settings of the linear solver o->linear (chosen). */
static void linear_settings(const pm_scene *s, pm_newton_options *o) {
  o->pc_reuse_its = (int)s->time.qs_reuse;
  o->linear_ew = s->time.qs_inexact;
  /* The stop of a solve on a stale factorisation is decided by iteration
   * counts, which round-off across ranks can move by one: exact solves
   * (inexact: false) promise round-off agreement, so they go without it. */
  if (!o->linear_ew) o->pc_reuse_cost = 0;
  if (o->linear != PM_NEWTON_GMRES_GAMG && o->linear != PM_NEWTON_CG_GAMG)
    return;
  /* Multigrid: a bounded Krylov solve (a failure cuts the load step with
   * its reason), its hierarchy's interpolation kept over a load step's
   * Newton iterations (only the coarse operators are recomputed), the
   * finest level smoothed with the assembled tangent (not the matrix-free
   * one: a third less CPU at 1851 points), GMRES not
   * restarted short of FPM_STATIC_AMG_RESTART, and, unless the scene
   * says otherwise, inexact Newton and the hierarchy kept while a solve
   * takes at most FPM_STATIC_AMG_REUSE iterations (docs/validation.md,
   * "Static solves at 13762 and 32715 points"). */
  o->linear_rtol = FPM_STATIC_AMG_RTOL;
  o->linear_max_iter = 1000;
  o->amg_reuse = true;
  o->amg_assembled_smoother = true;
  o->amg_threaded = true;
  /* The aggregation graph not squared: the tangent's 3 rings already
   * make aggregates of about 60 points (a squared graph: about 480, a coarse
   * level of 42 unknowns at 4036 points), and the finer hierarchy takes a
   * third fewer GMRES iterations (docs/validation.md, "Static solves at
   * 13762 points: the Krylov operator and the hierarchy"). */
  o->amg_unsquared = true;
  o->gmres_restart = FPM_STATIC_AMG_RESTART;
  o->stall_linear = FPM_STATIC_STALL_LINEAR;
  if (!pm_scene_has(s, "time.quasi_static.inexact")) o->linear_ew = true;
  if (!pm_scene_has(s, "time.quasi_static.reuse_iterations"))
    o->pc_reuse_its = FPM_STATIC_AMG_REUSE;
  /* A new hierarchy's solves take tens of iterations, varying with inexact
   * Newton's tolerance, and a set-up costs a few: stopping a solve for a
   * new one cost 1.8 times the CPU at 4036 points (docs/validation.md,
   * "Static solves: big steps, cheap cuts"). */
  o->pc_reuse_cost = 0;
}

void fpm_static_choose_linear(const pm_scene *s, long unknowns,
                              pm_newton_options *o) {
  o->linear = pm_scene_has(s, "time.quasi_static.linear_solver")
                  ? pm_newton_linear_of(s->time.qs_linear)
                  : fpm_static_default_linear(unknowns);
  linear_settings(s, o);
}

pm_err fpm_static_run(const fpm_model *m, fpm_state *st, fpm_observer observer,
                      void *ctx, fpm_step_info *info, fpm_static_report *rep) {
  fpm_static_state ss;
  PM_CALL(fpm_static_state_init(&ss, m));
  pm_err e = fpm_static_run_from(m, st, &ss, observer, ctx, info, rep);
  fpm_static_state_free(&ss);
  return e;
}

pm_err fpm_static_run_from(const fpm_model *m, fpm_state *st,
                           fpm_static_state *ss, fpm_observer observer,
                           void *ctx, fpm_step_info *info,
                           fpm_static_report *rep) {
  pm_err ret = PM_SUCCESS;
  fpm_static_solve v = {.c = {.observer = observer, .octx = ctx}};
  const pm_scene *s = m->scene;
  fpm_static_ctx *c = &v.c;
  pm_newton *solver = NULL;
  const bool resumed = ss->load.lambda > 0;
  const pm_load_report done_before = rep->load;
  memset(rep, 0, sizeof *rep);
  if (resumed) rep->load = done_before;
  c->ext_work = &ss->external_work;
  const double w0 = pm_wtime(), c0 = pm_cputime();
  PM_TRY(fpm_static_setup(m, st, &v));
  long sizes[2] = {c->nf, v.ptr[c->nheld]};
  fpm_exchange_sum_long(m->xc, sizes, 2);
  rep->unknowns = sizes[0];
  rep->pattern_entries = sizes[1];
  PM_ENSURE(c->nf == ss->free_dofs, PM_ERR_ARG,
            "static state of %ld free dofs for a model of %ld", ss->free_dofs,
            c->nf);

  if (!resumed) {
    /* The initial state, as a frame. */
    memset(st->u, 0, 3 * m->n * sizeof(double));
    ss->external_work = 0;
    PM_TRY(fpm_static_set_load(c, 0));
  } else {
    /* The last converged state: its force gives the supports' forces the
     * work of the next step starts from, as in the first run. */
    PM_TRY(fpm_static_set_load(c, ss->load.lambda));
    c->t = ss->load.lambda * c->load_end;
    memcpy(v.x, ss->load.xc, (size_t)c->nf * sizeof *v.x);
  }
  /* (across ranks the state holds a resumed run's displacements on every
   * point, its ghosts' too) */
  PM_TRY(fpm_static_admissible(
      c, fpm_static_evaluate(c, resumed && !m->xc ? v.x : NULL)));
  fpm_support_start(m, st);
  if (!resumed) fpm_contact_commit(m, st, c->load_end, 0);
  fpm_static_keep_anchors(c);
  fpm_contact_start_scaled(m, st, c->load_end, ss->load.lambda);
  memcpy(c->u_old, st->u, 3 * m->n * sizeof(double));
  /* The figures of the state (a resumed one's too, for a run that fails
   * before its next step); only the initial state is a frame. */
  fpm_static_figures(c, rep->load.steps);
  if (!resumed && observer) PM_TRY(observer(ctx, m, st, &c->si, true));

  pm_newton_options no = pm_newton_options_default();
  no.rtol = s->time.qs_tolerance;
  no.atol = force_floor(m);
  no.max_iter = (int)s->time.qs_max_iterations;
  /* A step Newton creeps through (short line-search steps from a state
   * outside its basin) is cut sooner than at max_iter. */
  no.stall_after = 6;
  fpm_static_choose_linear(s, rep->unknowns, &no);
  no.load_steps = (int)s->time.qs_load_steps;
  no.predictor = true;
  /* Steps Newton cannot finish get pseudo-transient continuation, then
   * dynamic relaxation, within the step;
   * steps grow back after cuts at once when Newton found them easy. */
  no.relax_after = (int)s->time.qs_relax_after;
  no.ptc_max_iter = (int)s->time.qs_ptc;
  no.follow_fold = s->time.qs_follow_fold;
  no.relax_first = s->time.qs_relax_first;
  /* Newton's whole step where it lowers the residual enough, else the
   * secant: near a stretched block's necking the whole step overshoots,
   * and backtracking creeps (docs/validation.md, "The secant line search"
   * and "The whole step, else the secant"). */
  no.line_search =
      pm_newton_line_search_of(s->time.qs_line_search, PM_LINE_SEARCH_FULL_L2);
  no.fallback_seconds = s->time.qs_fallback_cpu;
  no.easy_iterations = 3;
  /* ...and, with max_load_step, grow past 1/load_steps up to it (not by
   * default: larger steps cost fewer Newton iterations but more CPU, the
   * kept factorisation going stale sooner; docs/validation.md, "Static
   * solves: big steps, cheap cuts"). */
  no.max_dlambda = s->time.qs_max_step;
  no.petsc_options = s->time.qs_solver_options;
  /* SIPG, the stiffening and the volume penalty: the assembled tangent
   * lacks the adjoint term's and the state-dependent penalties'
   * derivatives; it preconditions the exact tangent applied matrix-free. */
  if (m->flux == FPM_FLUX_SIPG || m->stiffening > 0 || m->volume_penalty > 0)
    no.op = PM_NEWTON_MATRIX_FREE;
  /* fpm.volumetric averaged: the assembled tangent lacks the averages'
   * coupling (it keeps each point's own volumetric stiffness); it
   * preconditions the exact tangent applied matrix-free. */
  if (m->vavg) no.op = PM_NEWTON_MATRIX_FREE;
  /* A follower pressure: the assembled tangent lacks its load stiffness
   * (fpm_loads.h); it preconditions the exact tangent likewise. */
  for (int b = 0; b < s->n_bcs; b++)
    if (s->bcs[b].pressure) no.op = PM_NEWTON_MATRIX_FREE;
  /* ...unless the factorisation takes the coupling in (one value per
   * point more): then GMRES converges in an iteration or two. */
  if (fpm_static_couples(s, m, rep->unknowns, no.linear)) {
    if (no.linear == PM_NEWTON_DIRECT) {
      PM_TRY(fpm_static_coupled_build(&v));
    } else {
      /* the fallbacks' LU only: made if a step falls back */
      v.prob.aux_prepare = coupled_prepare;
      v.prob.aux_values = fpm_static_coupled_values;
    }
  }
  /* Multigrid on one process built on the tangent on each point's own
   * support (multigrid_operator support or support2,
   * fpm_static_support.c), the exact tangent applied matrix-free: less
   * memory, more CPU (docs/validation.md, "Static solves at 13762 points:
   * a cheaper preconditioner"). */
  if (fpm_static_amg_on_support(s, m, no.linear)) {
    const int rings = s->time.qs_amg == PM_AMG_SUPPORT ? 1 : 2;
    PM_TRY(fpm_static_support_build(m, v.free_of, c->nf, rings, &c->sp));
    v.prob.precond_values = fpm_static_support_values;
    v.prob.pc_pat_ptr = c->sp.ptr;
    v.prob.pc_pat_idx = c->sp.idx;
    no.op = PM_NEWTON_MATRIX_FREE_CHEAP_PC;
    no.pc_right = true;
    /* a narrow stencil (the 1-ring): the squared graph's aggregates, as
     * PETSc means them (unsquared at 474 points: 100 GMRES iterations a
     * solve against 52) */
    no.amg_unsquared = false;
  }
  PM_TRY(pm_newton_create(&v.prob, &no, &solver));
  c->solver = solver;
  /* The solver holds the pattern now (a coupled pattern made later takes
   * the tangent's rows from the points that reach each point). */
  free(v.idx);
  v.idx = NULL;
  v.prob.pat_idx = NULL;
  /* Multigrid where Newton passes, the LU in the fallbacks (a fold's
   * singular tangent, where multigrid's solves crawl) while it fits. */
  if (fpm_static_fallback_direct(s, m, rep->unknowns)) {
    pm_newton_options alt = pm_newton_options_default();
    alt.linear = PM_NEWTON_DIRECT;
    linear_settings(s, &alt);
    PM_TRY(pm_newton_set_fallback_linear(solver, &alt, true));
  }
  rep->setup_seconds = pm_wtime() - w0;
  ret = pm_load_steps_from(solver, v.x, &ss->load, &rep->load);
  if (ret != PM_SUCCESS) {
    /* A solve that stops (not converged, unstable, interrupted) ends in
     * its last converged state, which load stepping left in v.x with its
     * load set: the fields (the summary's figures, the message's) are that
     * state's, as its last frame and checkpoint are, not the last iterate
     * tried's.  (Every rank stops: collective.) */
    long bad = -1;
    (void)fpm_static_evaluate_owned(c, v.x, &bad);
  }
done:
  rep->seconds = pm_wtime() - w0;
  rep->cpu_seconds = pm_cputime() - c0;
  if (v.c.cp.ptr) rep->coupled_entries = v.c.cp.ptr[c->nf + m->n];
  if (info) *info = c->si;
  rep->contact_frozen = c->contact_frozen;
  rep->contact_frozen_gap = c->contact_frozen_gap;
  pm_newton_destroy(&solver);
  fpm_static_solve_free(&v);
  return ret;
}

pm_err fpm_static_check_tangent(const fpm_model *m, fpm_state *st,
                                const double *u, double *assembled_error,
                                double *difference_error) {
  pm_err ret = PM_SUCCESS;
  fpm_static_solve v = {0};
  double *v1 = NULL, *v2 = NULL;
  pm_newton *direct = NULL, *colored = NULL;
  PM_TRY(fpm_static_setup(m, st, &v));
  memcpy(st->u, u, 3 * m->n * sizeof(double));
  for (long j = 0; j < v.c.nf; j++) v.x[j] = u[v.c.dof[j]];
  pm_newton_options no = pm_newton_options_default();
  PM_TRY(pm_newton_create(&v.prob, &no, &direct));
  v.prob.jacobian_values = NULL;
  PM_TRY(pm_newton_create(&v.prob, &no, &colored));
  const long nv = v.ptr[v.c.nf];
  PM_TRY(PM_ALLOC(v1, nv, "tangent values"));
  PM_TRY(PM_ALLOC(v2, nv, "tangent values"));
  PM_TRY(pm_newton_jacobian_values(direct, v.x, v1));
  PM_TRY(pm_newton_jacobian_values(colored, v.x, v2));
  double dmax = 0, big = 0;
  for (long k = 0; k < nv; k++) {
    dmax = fmax(dmax, fabs(v1[k] - v2[k]));
    big = fmax(big, fabs(v2[k]));
  }
  *assembled_error = big > 0 ? dmax / big : dmax;
  if (difference_error) {
    long row, col;
    PM_TRY(pm_newton_check_jacobian(direct, v.x, 1e-7, difference_error, &row,
                                    &col));
  }
done:
  pm_newton_destroy(&direct);
  pm_newton_destroy(&colored);
  fpm_static_solve_free(&v);
  free(v1);
  free(v2);
  return ret;
}
