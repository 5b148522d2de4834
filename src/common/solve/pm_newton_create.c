/* pm_newton_create: a Newton solver's creation from a problem and options
 * (their checks, the patterns and colourings, PETSc's vectors, matrices and
 * SNES) and its destruction. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_coloring.h"
#include "pm_newton_solver_impl.h"
#include "pm_par.h"
#include "pm_petsc.h"

static pm_err check_options(const pm_newton_options *o) {
  PM_CHECK(o->rtol >= 0 && o->atol >= 0 && o->dtol >= 0 && o->etol >= 0 &&
               isfinite(o->rtol + o->atol + o->dtol + o->etol),
           PM_ERR_ARG,
           "Newton tolerances must be finite and >= 0 (rtol %g, atol %g, "
           "dtol %g, etol %g)",
           o->rtol, o->atol, o->dtol, o->etol);
  PM_CHECK(o->rtol > 0 || o->atol > 0 || o->dtol > 0 || o->etol > 0, PM_ERR_ARG,
           "Newton needs a convergence criterion: rtol, atol, dtol or etol "
           "> 0 (all are 0)");
  PM_CHECK(o->max_iter >= 1 && o->max_iter <= PM_NEWTON_MAX_ITER, PM_ERR_ARG,
           "Newton max_iter must be in [1, %d] (got %d)", PM_NEWTON_MAX_ITER,
           o->max_iter);
  PM_CHECK(o->linear >= PM_NEWTON_DIRECT && o->linear <= PM_NEWTON_CG_GAMG,
           PM_ERR_ARG, "unknown linear solver %d", (int)o->linear);
  PM_CHECK(o->op >= PM_NEWTON_ASSEMBLED &&
               o->op <= PM_NEWTON_MATRIX_FREE_CHEAP_PC,
           PM_ERR_ARG, "unknown Jacobian operator %d", (int)o->op);
  PM_CHECK(o->coloring == PM_COLORING_LARGEST_FIRST ||
               o->coloring == PM_COLORING_NATURAL,
           PM_ERR_ARG, "unknown colouring order %d", (int)o->coloring);
  PM_CHECK(o->line_search >= PM_LINE_SEARCH_BT &&
               o->line_search <= PM_LINE_SEARCH_FULL_L2,
           PM_ERR_ARG, "unknown line search %d", (int)o->line_search);
  PM_CHECK(o->linear_rtol > 0 && o->linear_rtol < 1, PM_ERR_ARG,
           "linear_rtol must be in (0, 1) (got %g)", o->linear_rtol);
  PM_CHECK(o->stall_after == 0 || o->stall_after >= 2, PM_ERR_ARG,
           "Newton stall_after must be 0 (off) or >= 2 (got %d)",
           o->stall_after);
  PM_CHECK(o->stall_linear >= 0, PM_ERR_ARG,
           "Newton stall_linear must be 0 (off) or > 0 (got %d)",
           o->stall_linear);
  PM_CHECK(o->linear_max_iter >= 1, PM_ERR_ARG,
           "linear_max_iter must be >= 1 (got %d)", o->linear_max_iter);
  PM_CHECK(o->gmres_restart >= 0, PM_ERR_ARG,
           "gmres_restart must be >= 0 (got %d)", o->gmres_restart);
  PM_CHECK(o->pc_reuse_its >= 0, PM_ERR_ARG,
           "pc_reuse_its must be >= 0 (got %d)", o->pc_reuse_its);
  PM_CHECK(o->pc_reuse_cost >= 0, PM_ERR_ARG,
           "pc_reuse_cost must be >= 0 (got %g)", o->pc_reuse_cost);
  PM_CHECK(o->pc_lag >= 1, PM_ERR_ARG, "pc_lag must be >= 1 (got %d)",
           o->pc_lag);
  PM_CHECK(o->load_steps >= 1, PM_ERR_ARG, "load_steps must be >= 1 (got %d)",
           o->load_steps);
  PM_CHECK(o->max_cuts >= 0 && o->max_cuts <= 60, PM_ERR_ARG,
           "max_cuts must be in [0, 60] (got %d)", o->max_cuts);
  PM_CHECK(o->min_dlambda >= 0 && o->min_dlambda <= 1, PM_ERR_ARG,
           "min_dlambda must be in [0, 1] (got %g)", o->min_dlambda);
  PM_CHECK(o->grow_after >= 0, PM_ERR_ARG, "grow_after must be >= 0 (got %d)",
           o->grow_after);
  return PM_SUCCESS;
}

static pm_err check_problem(const pm_newton_problem *p,
                            const pm_newton_options *o) {
  PM_CHECK(p->n >= 1 && p->n <= PETSC_MAX_INT, PM_ERR_ARG,
           "Newton problem: n must be in [1, %ld] (got %ld)",
           (long)PETSC_MAX_INT, p->n);
  PM_CHECK(p->residual && p->jacobian_apply && p->pat_ptr && p->pat_idx,
           PM_ERR_ARG,
           "Newton problem: residual, jacobian_apply, pat_ptr and pat_idx "
           "are required");
  const long rows = p->n + (p->shared && pm_par_active() ? p->n_ghost : 0);
  PM_CHECK(p->pat_ptr[rows] + rows <= PETSC_MAX_INT, PM_ERR_ARG,
           "Newton problem: %ld pattern entries exceed PETSc's indices",
           p->pat_ptr[rows]);
  PM_CHECK(o->op != PM_NEWTON_MATRIX_FREE_CHEAP_PC || p->precond_apply ||
               p->precond_values,
           PM_ERR_ARG,
           "Newton problem: the cheap preconditioner needs precond_apply or "
           "precond_values");
  PM_CHECK(!p->aux_prepare || p->aux_values, PM_ERR_ARG,
           "Newton problem: aux_prepare needs aux_values");
  PM_CHECK(!p->pc_pat_ptr == !p->pc_pat_idx, PM_ERR_ARG,
           "Newton problem: give both pc_pat_ptr and pc_pat_idx, or neither");
  if (!p->shared || !pm_par_active()) return PM_SUCCESS;
  PM_CHECK(p->n_ghost >= 0 && (p->n_ghost == 0 || p->ghost), PM_ERR_ARG,
           "Newton problem shared by the ranks: %ld ghost unknowns without "
           "their numbers",
           p->n_ghost);
  PM_CHECK(p->jacobian_values && o->op != PM_NEWTON_MATRIX_FREE_CHEAP_PC,
           PM_ERR_UNSUPPORTED,
           "Newton problem shared by %d ranks: the Jacobian must be assembled "
           "by the caller (jacobian_values), and the cheap preconditioner "
           "(coloured) runs on one process",
           pm_par_size());
  return PM_SUCCESS;
}

static pm_err configure_snes(pm_newton *s) {
  const pm_newton_options *o = &s->o;
  static const SNESLineSearchType types[] = {
      SNESLINESEARCHBT, SNESLINESEARCHBASIC, SNESLINESEARCHL2, SNESLINESEARCHCP,
      SNESLINESEARCHSHELL};
  PM_PETSC_CALL(PetscOptionsCreate(&s->opts));
  /* MUMPS: a singular matrix (a limit point) factors with its null pivots
   * set aside instead of failing with an error. */
  PM_PETSC_CALL(PetscOptionsInsertString(
      s->opts, "-pm_mat_mumps_icntl_24 1 -pm_aug_mat_mumps_icntl_24 1"));
  if (o->amg_reuse)
    PM_PETSC_CALL(PetscOptionsInsertString(
        s->opts, "-pm_pc_gamg_reuse_interpolation true"));
  if (o->amg_unsquared)
    PM_PETSC_CALL(
        PetscOptionsInsertString(s->opts, "-pm_pc_gamg_square_graph 0"));
  if (s->petsc_options) {
    PetscErrorCode code = PetscOptionsInsertString(s->opts, s->petsc_options);
    PM_CHECK(code == 0, PM_ERR_ARG, "PETSc options \"%s\" not understood",
             s->petsc_options);
  }
  PM_PETSC_CALL(SNESCreate(s->comm, &s->snes));
  PM_PETSC_CALL(PetscObjectSetOptions((PetscObject)s->snes, s->opts));
  PM_PETSC_CALL(SNESGetLineSearch(s->snes, &s->ls));
  PM_PETSC_CALL(PetscObjectSetOptions((PetscObject)s->ls, s->opts));
  PM_PETSC_CALL(SNESSetOptionsPrefix(s->snes, "pm_"));
  PM_CALL(pm_newton_replace_linear(s));

  PM_PETSC_CALL(SNESSetType(s->snes, SNESNEWTONLS));
  PM_PETSC_CALL(SNESSetFunction(s->snes, s->R, pm_newton_snes_residual, s));
  Mat A, B;
  pm_newton_operators(s, &A, &B);
  PM_PETSC_CALL(SNESSetJacobian(s->snes, A, B, pm_newton_snes_jacobian, s));
  PM_PETSC_CALL(
      SNESSetConvergenceTest(s->snes, pm_newton_converged_or_stopped, s, NULL));
  /* The step-size test (stol) is off: a short step is no convergence. */
  PM_PETSC_CALL(SNESSetTolerances(s->snes, 0, 0, 0, o->max_iter, 1000000000));
  PM_PETSC_CALL(SNESLineSearchSetType(s->ls, types[o->line_search]));
  PM_PETSC_CALL(SNESLineSearchSetTolerances(s->ls, PETSC_DEFAULT, 1e300,
                                            PETSC_DEFAULT, PETSC_DEFAULT,
                                            PETSC_DEFAULT, PETSC_DEFAULT));
  PM_PETSC_CALL(SNESLineSearchSetPreCheck(s->ls, pm_newton_precheck, s));
  if (o->line_search == PM_LINE_SEARCH_FULL_L2)
    PM_CALL(pm_newton_full_l2_create(s));
  PM_PETSC_CALL(PetscOptionsPush(s->opts));
  PetscErrorCode code = SNESSetFromOptions(s->snes);
  PetscOptionsPop();
  PM_PETSC_CALL(code);
  return PM_SUCCESS;
}

static pm_err create_petsc_objects(pm_newton *s) {
  PetscInt n = (PetscInt)s->p.n;
  if (s->dist) {
    PM_CALL(pm_newton_create_shared(s));
    PM_PETSC_CALL(VecCreateMPI(s->comm, n, PETSC_DETERMINE, &s->X));
  } else {
    PM_PETSC_CALL(VecCreateSeq(PETSC_COMM_SELF, n, &s->X));
  }
  PM_PETSC_CALL(VecDuplicate(s->X, &s->R));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xstart));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xlin));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xpc));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xacc));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Work));
  if (!s->dist) {
    PM_PETSC_CALL(VecDuplicate(s->X, &s->Shift));
    PM_PETSC_CALL(VecDuplicate(s->X, &s->ShiftWork));
  }
  if (s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
    PM_CALL(pm_newton_create_matrix(s, &s->ppat, false, &s->pcols, s->pvals,
                                    &s->P));
  } else if (!pm_newton_aug_on(s)) {
    /* The caller's assembly on one process: the columns are the matrix's
     * (pm_newton_pattern_columns gives them back where wanted). */
    const bool release = !s->dist && s->p.jacobian_values;
    PM_CALL(pm_newton_create_matrix(s, &s->jpat, release, &s->jcols, s->jvals,
                                    &s->J));
  }
  /* the caller's values, made once the matrix holds the pattern */
  if (s->p.jacobian_values && s->jpat.src)
    PM_CALL(PM_ALLOC(s->srcvals, s->jpat.nsrc > 0 ? s->jpat.nsrc : 1,
                     "Jacobian values"));
  PM_CALL(pm_newton_fine_create(s));
  if (s->p.near_null_count > 0 && !pm_newton_aug_on(s)) {
    Mat A, B;
    pm_newton_operators(s, &A, &B);
    PM_CALL(pm_newton_set_near_null(s, B));
  }
  if (s->o.op != PM_NEWTON_ASSEMBLED) {
    PM_PETSC_CALL(MatCreateShell(s->comm, n, n, PETSC_DETERMINE,
                                 PETSC_DETERMINE, s, &s->Shell));
    PM_PETSC_CALL(MatShellSetOperation(s->Shell, MATOP_MULT,
                                       (void (*)(void))pm_newton_shell_mult));
  }
  PM_CALL(configure_snes(s));
  return pm_newton_aug_objects(s);
}

pm_err pm_newton_create(const pm_newton_problem *problem,
                        const pm_newton_options *options, pm_newton **out) {
  pm_err ret = PM_SUCCESS;
  pm_newton *s = NULL;
  PM_CHECK(problem && options && out, PM_ERR_ARG,
           "pm_newton_create: problem, options and out are required");
  *out = NULL;
  PM_CALL(check_options(options));
  PM_CALL(check_problem(problem, options));
  PM_CALL(pm_petsc_init());
  PM_TRY(PM_ALLOC(s, 1, "Newton solver"));
  s->p = *problem;
  s->o = *options;
  s->pc_first_its = -1;
  s->p.pat_ptr = s->p.pat_idx = s->p.pc_pat_ptr = s->p.pc_pat_idx = NULL;
  s->dist = problem->shared && pm_par_active();
  s->comm = s->dist ? PETSC_COMM_WORLD : PETSC_COMM_SELF;
  s->nloc = problem->n + (s->dist ? problem->n_ghost : 0);
  s->p.ghost = NULL; /* the caller's: read once, below */
  if (options->petsc_options) {
    s->petsc_options = strdup(options->petsc_options);
    PM_ENSURE(s->petsc_options, PM_ERR_MEMORY, "out of memory (PETSc options)");
  }
  s->o.petsc_options = s->petsc_options;
  if (!(s->o.min_dlambda > 0))
    s->o.min_dlambda = ldexp(1.0 / s->o.load_steps, -s->o.max_cuts);

  long n = s->nloc;
  PM_TRY(
      pm_pattern_build(n, problem->pat_ptr, problem->pat_idx, true, &s->jpat));
  if (!problem->jacobian_values)
    PM_TRY(pm_coloring_build(&s->jpat, options->coloring, &s->jcol));
  /* across ranks the values go through jvals into the matrix; on one
   * process into its own storage */
  if (s->dist) PM_TRY(pm_newton_jvals(s, &s->jvals));
  if (options->op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
    const long *ptr =
        problem->pc_pat_ptr ? problem->pc_pat_ptr : problem->pat_ptr;
    const long *idx =
        problem->pc_pat_ptr ? problem->pc_pat_idx : problem->pat_idx;
    PM_TRY(pm_pattern_build(n, ptr, idx, true, &s->ppat));
    if (!problem->precond_values)
      PM_TRY(pm_coloring_build(&s->ppat, options->coloring, &s->pcol));
    else if (s->ppat.src)
      PM_TRY(PM_ALLOC(s->psrcvals, s->ppat.nsrc > 0 ? s->ppat.nsrc : 1,
                      "preconditioner values"));
    if (s->dist)
      PM_TRY(PM_ALLOC(s->pvals, s->ppat.ptr[n] + 1, "preconditioner values"));
  }
  PM_TRY(pm_newton_aug_init(s, problem));
  s->p.aux_ptr = s->p.aux_idx = NULL; /* the caller's: kept in aux_* */
  PM_TRY(PM_ALLOC(s->seed, n, "colour seed"));
  PM_TRY(PM_ALLOC(s->dr, n, "colour image"));
  s->p.ghost = problem->ghost;
  ret = create_petsc_objects(s);
  if (s->dist) ret = pm_par_agree(ret);
  s->p.ghost = NULL;
  PM_TRY(ret);
  s->p.near_null = NULL; /* the caller's: read once, above */
  *out = s;
  s = NULL;
done:
  pm_newton_destroy(&s);
  return ret;
}

void pm_newton_destroy(pm_newton **sp) {
  if (!sp || !*sp) return;
  pm_newton *s = *sp;
  /* Destruction never fails in practice; its codes have nowhere to go. */
  SNESDestroy(&s->snes);
  SNESLineSearchDestroy(&s->ls2);
  pm_newton_aug_free(s);
  MatDestroy(&s->Shell);
  MatDestroy(&s->Fine);
  free(s->fine_a);
  free(s->fine_ib);
  free(s->fine_jb);
  MatDestroy(&s->J);
  MatDestroy(&s->P);
  VecDestroy(&s->X);
  VecDestroy(&s->R);
  VecDestroy(&s->Xstart);
  VecDestroy(&s->Xlin);
  VecDestroy(&s->Xpc);
  VecDestroy(&s->Xacc);
  VecDestroy(&s->Work);
  VecDestroy(&s->Shift);
  VecDestroy(&s->ShiftWork);
  VecDestroy(&s->Gx);
  VecDestroy(&s->Glin);
  VecDestroy(&s->Gdx);
  VecDestroy(&s->Gr);
  VecDestroy(&s->Gdr);
  ISLocalToGlobalMappingDestroy(&s->l2g);
  PetscOptionsDestroy(&s->opts);
  pm_pattern_free(&s->jpat);
  pm_pattern_free(&s->ppat);
  pm_coloring_free(&s->jcol);
  pm_coloring_free(&s->pcol);
  free(s->jcols);
  free(s->pcols);
  free(s->jvals);
  free(s->srcvals);
  free(s->pvals);
  free(s->psrcvals);
  free(s->seed);
  free(s->dr);
  free(s->petsc_options);
  free(s);
  *sp = NULL;
}
