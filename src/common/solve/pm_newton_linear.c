/* pm_newton_linear: the linear solver of each Newton step, configured from
 * the options and then PETSc's, what it multiplies by, and the tests that
 * stop it (and Newton) on a signal. */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_interrupt.h"
#include "pm_newton_solver_impl.h"
#include "pm_petsc.h"

int pm_newton_stop_signal(const pm_newton *s) {
  int sig = pm_interrupt_signal();
  if (s->dist) {
    int any = sig;
    MPI_Allreduce(&sig, &any, 1, MPI_INT, MPI_MAX, s->comm);
    sig = any;
  }
  return sig;
}

const char *pm_newton_linear_reason_words(KSPConvergedReason r) {
  switch (r) {
  case KSP_DIVERGED_ITS: return "the iteration limit was reached";
  case KSP_DIVERGED_DTOL: return "the residual grew past the divergence limit";
  case KSP_DIVERGED_BREAKDOWN:
  case KSP_DIVERGED_BREAKDOWN_BICG: return "the Krylov method broke down";
  case KSP_DIVERGED_INDEFINITE_PC: return "the preconditioner is indefinite";
  case KSP_DIVERGED_INDEFINITE_MAT: return "the matrix is indefinite";
  case KSP_DIVERGED_NANORINF: return "a residual was not finite";
  case KSP_DIVERGED_PC_FAILED:
    return "the preconditioner failed (a zero pivot or a singular matrix)";
  case KSP_DIVERGED_NULL: return "a null vector appeared";
  case KSP_DIVERGED_NONSYMMETRIC: return "the matrix is not symmetric";
  default: break;
  }
  return r > 0 ? "converged" : "diverged";
}

/* A signal asks the solve to stop: s->hard = PM_ERR_INTERRUPTED with
 * where it was (`where` iteration it, residual r from r0); true then. */
static bool stopped(pm_newton *s, const char *where, int it, double r,
                    double r0) {
  const int sig = pm_newton_stop_signal(s);
  if (!sig) return false;
  s->hard = PM_ERROR(PM_ERR_INTERRUPTED,
                     "interrupted by %s in %s %d (residual %.3e from %.3e)",
                     pm_interrupt_name(sig), where, it, r, r0);
  return true;
}

/* The linear solver's convergence test: PETSc's default, the residual
 * norms recorded, and a stop on a signal (checked at every iteration). */
typedef struct {
  pm_newton *s;
  void *dflt; /* the default test's context */
} linear_test_ctx;

static PetscErrorCode linear_test(KSP ksp, PetscInt it, PetscReal rnorm,
                                  KSPConvergedReason *reason, void *ctx) {
  linear_test_ctx *t = ctx;
  pm_newton *s = t->s;
  PetscCall(KSPConvergedDefault(ksp, it, rnorm, reason, t->dflt));
  if (it == 0) s->lin_r0 = rnorm;
  s->lin_r = rnorm;
  if (*reason == KSP_CONVERGED_ITERATING &&
      stopped(s, "a linear solve, linear iteration", (int)it, rnorm, s->lin_r0))
    *reason = KSP_DIVERGED_ITS;
  /* a kept preconditioner that now costs more than a new one: the solve
   * stops, to be made again on a new one */
  if (*reason == KSP_CONVERGED_ITERATING && pm_newton_pc_spent(s, (int)it)) {
    s->pc_stale = true;
    *reason = KSP_DIVERGED_ITS;
  }
  return 0;
}

static PetscErrorCode linear_test_destroy(void *ctx) {
  linear_test_ctx *t = ctx;
  PetscCall(KSPConvergedDefaultDestroy(t->dflt));
  free(t);
  return 0;
}

/* Before each linear solve: its residual norms unknown (a direct solve
 * records none), then the Newton solver's presolve. */
static PetscErrorCode linear_presolve(KSP ksp, Vec b, Vec x, void *ctx) {
  pm_newton *s = ctx;
  s->lin_r0 = s->lin_r = NAN;
  return pm_newton_linear_presolve(ksp, b, x, ctx);
}

/* ksp's convergence test: linear_test (after KSPSetFromOptions, which would
 * set PETSc's default in its place). */
static pm_err set_linear_test(pm_newton *s, KSP ksp) {
  pm_err ret = PM_SUCCESS;
  linear_test_ctx *t = calloc(1, sizeof *t);
  PM_CHECK(t, PM_ERR_MEMORY, "out of memory (linear solver test)");
  t->s = s;
  PM_PETSC(KSPConvergedDefaultCreate(&t->dflt));
  PM_PETSC(KSPSetConvergenceTest(ksp, linear_test, t, linear_test_destroy));
  return PM_SUCCESS;
done:
  if (t->dflt) KSPConvergedDefaultDestroy(t->dflt);
  free(t);
  return ret;
}

PetscErrorCode pm_newton_converged_or_stopped(SNES snes, PetscInt it,
                                              PetscReal xnorm, PetscReal snorm,
                                              PetscReal fnorm,
                                              SNESConvergedReason *reason,
                                              void *ctx) {
  pm_newton *s = ctx;
  PetscCall(
      pm_newton_converged_test(snes, it, xnorm, snorm, fnorm, reason, ctx));
  if (*reason == SNES_CONVERGED_ITERATING &&
      stopped(s, "Newton iteration", (int)it + 1, fnorm, s->r0))
    *reason = SNES_DIVERGED_FUNCTION_DOMAIN;
  return 0;
}

/* The linear solver, configured from the options and then PETSc's. */
static pm_err create_linear(pm_newton *s, KSP *out) {
  pm_err ret = PM_SUCCESS;
  const pm_newton_options *o = &s->o;
  bool matrix_free = o->op != PM_NEWTON_ASSEMBLED;
  KSP ksp = NULL;
  PC pc;
  PM_PETSC(KSPCreate(s->comm, &ksp));
  PM_PETSC(PetscObjectSetOptions((PetscObject)ksp, s->opts));
  PM_PETSC(KSPSetOptionsPrefix(ksp, "pm_"));
  PM_PETSC(KSPGetPC(ksp, &pc));
  PM_PETSC(PetscObjectSetOptions((PetscObject)pc, s->opts));
  switch (o->linear) {
  case PM_NEWTON_DIRECT:
    /* With a matrix-free operator the factorisation preconditions GMRES
     * (exactly, for a current J: one iteration). */
    PM_PETSC(KSPSetType(ksp, matrix_free || o->pc_reuse_its > 0 ? KSPGMRES
                                                                : KSPPREONLY));
    if (s->aug) { /* the augmented matrix's LU (pm_newton_augmented.c) */
      PM_PETSC(pm_newton_aug_set_pc(s, pc));
      break;
    }
    s->dense_direct = pm_newton_dense_direct_fits(s);
    if (s->dense_direct) { /* the LU dense (pm_newton_dense.c) */
      PM_TRY(pm_newton_dense_storage(s));
      PM_PETSC(pm_newton_dense_set_pc(s, pc));
      break;
    }
    PM_PETSC(PCSetType(pc, PCLU));
#ifdef PETSC_HAVE_MUMPS
    PM_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
    break;
  case PM_NEWTON_GMRES_GAMG:
    PM_PETSC(KSPSetType(ksp, KSPGMRES));
    PM_PETSC(PCSetType(pc, PCGAMG));
    if (o->amg_assembled_smoother) PM_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
    break;
  case PM_NEWTON_CG_JACOBI:
    PM_PETSC(KSPSetType(ksp, KSPCG));
    PM_PETSC(PCSetType(pc, PCJACOBI));
    break;
  case PM_NEWTON_GMRES_ILU:
    /* Across ranks ILU(0) in each rank's block (block Jacobi's default). */
    PM_PETSC(KSPSetType(ksp, KSPGMRES));
    PM_PETSC(PCSetType(pc, s->dist ? PCBJACOBI : PCILU));
    break;
  case PM_NEWTON_CG_GAMG:
    PM_PETSC(KSPSetType(ksp, KSPCG));
    PM_PETSC(PCSetType(pc, PCGAMG));
    if (o->amg_assembled_smoother) PM_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
    break;
  }
  PM_PETSC(KSPSetTolerances(ksp, o->linear_rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                            o->linear_max_iter));
  if (o->gmres_restart > 0) {
    KSPType type;
    PM_PETSC(KSPGetType(ksp, &type));
    if (!strcmp(type, KSPGMRES))
      PM_PETSC(KSPGMRESSetRestart(ksp, (PetscInt)o->gmres_restart));
  }
  if (o->pc_right && o->linear != PM_NEWTON_DIRECT)
    PM_PETSC(KSPSetPCSide(ksp, PC_RIGHT));
  PM_PETSC(KSPSetPreSolve(ksp, linear_presolve, s));
  PM_PETSC(KSPSetPostSolve(ksp, pm_newton_linear_postsolve, s));
  PM_PETSC(PetscOptionsPush(s->opts));
  PetscErrorCode code = KSPSetFromOptions(ksp);
  PetscOptionsPop();
  PM_PETSC(code);
  PM_TRY(set_linear_test(s, ksp));
  *out = ksp;
  ksp = NULL;
done:
  KSPDestroy(&ksp);
  return ret;
}

/* Gives SNES a new linear solver (in place of one left inconsistent by a
 * failure inside it). */
pm_err pm_newton_replace_linear(pm_newton *s) {
  KSP ksp, held;
  PM_CALL(create_linear(s, &ksp));
  held = ksp;
  PetscErrorCode code = SNESSetKSP(s->snes, ksp);
  KSPDestroy(&ksp); /* SNES holds it */
  PM_PETSC_CALL(code);
  s->ksp = held;
  s->pc_built = false;
  return PM_SUCCESS;
}

/* The linear settings of `from` into o. */
static void take_linear(pm_newton_options *o, const pm_newton_options *from) {
  o->linear = from->linear;
  o->linear_rtol = from->linear_rtol;
  o->linear_ew = from->linear_ew;
  o->linear_ew_max = from->linear_ew_max;
  o->linear_max_iter = from->linear_max_iter;
  o->gmres_restart = from->gmres_restart;
  o->pc_reuse_its = from->pc_reuse_its;
  o->pc_reuse_cost = from->pc_reuse_cost;
  o->pc_right = from->pc_right;
  o->amg_reuse = from->amg_reuse;
  o->amg_unsquared = from->amg_unsquared;
  o->amg_assembled_smoother = from->amg_assembled_smoother;
  o->amg_threaded = from->amg_threaded;
}

pm_err pm_newton_set_fallback_linear(pm_newton *s, const pm_newton_options *alt,
                                     bool keep) {
  PM_CHECK(!s->on_alt, PM_ERR_ARG,
           "pm_newton_set_fallback_linear: inside a fallback");
  s->has_alt = false;
  if (!alt) return PM_SUCCESS;
  PM_CHECK(s->o.op != PM_NEWTON_MATRIX_FREE_CHEAP_PC && !pm_newton_aug_on(s),
           PM_ERR_ARG,
           "pm_newton_set_fallback_linear: the cheap operator and the "
           "augmented preconditioner in use keep their own linear solver");
  PM_CHECK(alt->linear >= PM_NEWTON_DIRECT &&
               alt->linear <= PM_NEWTON_CG_GAMG && alt->linear_rtol > 0 &&
               alt->linear_rtol < 1 && alt->linear_max_iter >= 1 &&
               alt->gmres_restart >= 0 && alt->pc_reuse_its >= 0 &&
               alt->pc_reuse_cost >= 0,
           PM_ERR_ARG,
           "pm_newton_set_fallback_linear: linear solver %d, linear_rtol %g, "
           "linear_max_iter %d, gmres_restart %d, pc_reuse_its %d, "
           "pc_reuse_cost %g out of range",
           (int)alt->linear, alt->linear_rtol, alt->linear_max_iter,
           alt->gmres_restart, alt->pc_reuse_its, alt->pc_reuse_cost);
  s->own = s->o;
  s->alt = s->o;
  take_linear(&s->alt, alt);
  s->has_alt = true;
  s->alt_keep = keep;
  return PM_SUCCESS;
}

bool pm_newton_fallback_kept(const pm_newton *s) {
  return s->has_alt && s->alt_keep;
}

void pm_newton_cap_linear(pm_newton *s, int max_its) {
  s->lin_cap = max_its > 0 ? max_its : 0;
}

pm_err pm_newton_use_fallback_linear(pm_newton *s, bool on) {
  if (!s->has_alt || s->on_alt == on) return PM_SUCCESS;
  if (on && s->alt.linear == PM_NEWTON_DIRECT && s->p.aux_prepare && !s->aug) {
    /* the augmented preconditioner, made now (pm_newton_problem) */
    pm_newton_problem p = s->p;
    PM_CALL(s->p.aux_prepare(s->p.ctx, &p.aux_n, &p.aux_ptr, &p.aux_idx));
    PM_CALL(pm_newton_aug_init(s, &p));
    s->p.aux_n = p.aux_n;
    PM_CALL(pm_newton_aug_objects(s));
  }
  take_linear(&s->o, on ? &s->alt : &s->own);
  s->on_alt = on;
  /* the kept preconditioner's record starts again with the new solver */
  s->lin_its = 0;
  s->lin_failed = false;
  s->pc_pending = s->pc_fresh = s->pc_stale = false;
  s->pc_budget = 0;
  s->pc_first_its = -1;
  PM_CALL(pm_newton_replace_linear(s));
  /* (the augmented preconditioner's shell, or the tangent, as B) */
  Mat A, B;
  pm_newton_operators(s, &A, &B);
  PM_PETSC_CALL(SNESSetJacobian(s->snes, A, B, pm_newton_snes_jacobian, s));
  return PM_SUCCESS;
}

/* What the linear solver multiplies by (A) and builds its preconditioner
 * from (B). */
void pm_newton_operators(const pm_newton *s, Mat *A, Mat *B) {
  *A = s->o.op == PM_NEWTON_ASSEMBLED ? s->J : s->Shell;
  *B = s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC ? s->P
       : pm_newton_aug_on(s)                     ? s->Shell
                                                 : s->J;
}

pm_line_search pm_newton_line_search_of(pm_qs_line_search l,
                                        pm_line_search own) {
  switch (l) {
  case PM_QS_LS_SECANT: return PM_LINE_SEARCH_L2;
  case PM_QS_LS_FULL_SECANT: return PM_LINE_SEARCH_FULL_L2;
  case PM_QS_LS_BACKTRACKING: return PM_LINE_SEARCH_BT;
  case PM_QS_LS_AUTO: break;
  }
  return own;
}

pm_newton_linear pm_newton_linear_of(pm_linear_solver l) {
  switch (l) {
  case PM_LINEAR_GMRES_GAMG: return PM_NEWTON_GMRES_GAMG;
  case PM_LINEAR_CG_JACOBI: return PM_NEWTON_CG_JACOBI;
  case PM_LINEAR_GMRES_ILU: return PM_NEWTON_GMRES_ILU;
  case PM_LINEAR_CG_GAMG: return PM_NEWTON_CG_GAMG;
  case PM_LINEAR_DIRECT: break;
  }
  return PM_NEWTON_DIRECT;
}

void pm_newton_note_load(pm_newton *s, double lambda) { s->load = lambda; }

pm_err pm_newton_pc_save(const pm_newton *s, pm_load_state *st) {
  st->pc_built = s->pc_built;
  st->pc_its = s->lin_its;
  st->pc_failed = s->lin_failed;
  st->pc_lambda = s->pc_load;
  st->pc_first_its = s->pc_first_its;
  if (!s->pc_built) return PM_SUCCESS;
  return pm_newton_copy_out(s->Xpc, st->pc_x, s->p.n);
}
