/* pm_newton: the problem's callbacks behind PETSc's SNES (residual with
 * domain errors, Jacobian by colouring or as a shell, a convergence test
 * with the residual, displacement and energy criteria) and the report. */
#include "pm_newton.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_coloring.h"
#include "pm_newton_impl.h"
#include "pm_par.h"
#include "pm_petsc.h"
#include "pm_progress.h"

typedef pm_err (*apply_fn)(void *ctx, const double *x, const double *dx,
                           double *dr);

struct pm_newton {
  pm_newton_problem p; /* the caller's, with pattern pointers cleared */
  pm_newton_options o;
  char *petsc_options;     /* copy of o.petsc_options */
  pm_pattern jpat, ppat;   /* Jacobian's and cheap operator's */
  pm_coloring jcol, pcol;  /* their colourings (pcol: cheap only) */
  PetscInt *jcols, *pcols; /* pattern columns as PETSc indices */
  double *jvals, *pvals;   /* values in pattern order */
  double *seed, *dr;       /* colour seed and its image */
  double *srcvals;         /* jacobian_values: values in the caller's order */
  Vec X, R, Xstart, Xlin, Xacc, Work;
  Mat J;     /* assembled Jacobian (not in the cheap mode) */
  Mat P;     /* assembled cheap operator (cheap mode only) */
  Mat Shell; /* matrix-free Jacobian (matrix-free modes only) */
  SNES snes;
  KSP ksp;
  SNESLineSearch ls;
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
  double linear_started;
  bool in_linear; /* between the linear solver's pre- and postsolve */
  bool started;   /* the initial state was admissible */
};

static bool hard_failure(pm_err e) {
  return e == PM_ERR_MEMORY || e == PM_ERR_IO || e == PM_ERR_INTERNAL;
}

pm_newton_options pm_newton_options_default(void) {
  return (pm_newton_options){.rtol = 1e-8,
                             .max_iter = 25,
                             .linear = PM_NEWTON_DIRECT,
                             .linear_rtol = 1e-10,
                             .linear_max_iter = 1000,
                             .op = PM_NEWTON_ASSEMBLED,
                             .pc_lag = 1,
                             .coloring = PM_COLORING_LARGEST_FIRST,
                             .line_search = PM_LINE_SEARCH_BT,
                             .load_steps = 10,
                             .max_cuts = 10,
                             .grow_after = 2};
}

const char *pm_newton_reason_name(pm_newton_reason r) {
  switch (r) {
  case PM_NEWTON_NOT_RUN: return "not run";
  case PM_NEWTON_CONVERGED_RESIDUAL: return "converged (residual)";
  case PM_NEWTON_CONVERGED_ABSOLUTE: return "converged (absolute residual)";
  case PM_NEWTON_CONVERGED_DISPLACEMENT: return "converged (displacement)";
  case PM_NEWTON_CONVERGED_ENERGY: return "converged (energy)";
  case PM_NEWTON_CONVERGED_ALL: return "converged (all criteria)";
  case PM_NEWTON_DIVERGED_MAX_ITER: return "diverged (max iterations)";
  case PM_NEWTON_DIVERGED_STALLED: return "diverged (stalled)";
  case PM_NEWTON_DIVERGED_LINE_SEARCH: return "diverged (line search)";
  case PM_NEWTON_DIVERGED_NAN: return "diverged (not a number)";
  case PM_NEWTON_DIVERGED_DOMAIN: return "diverged (inadmissible state)";
  case PM_NEWTON_DIVERGED_LINEAR: return "diverged (linear solver)";
  }
  return "unknown";
}

const pm_newton_problem *pm_newton_problem_of(const pm_newton *s) {
  return &s->p;
}
const pm_newton_options *pm_newton_options_of(const pm_newton *s) {
  return &s->o;
}
int pm_newton_colors(const pm_newton *s) { return s ? s->jcol.ncolors : 0; }
int pm_newton_pc_colors(const pm_newton *s) { return s ? s->pcol.ncolors : 0; }

static pm_err copy_in(Vec v, const double *x, long n) {
  double *a;
  PM_PETSC_CALL(VecGetArray(v, &a));
  memcpy(a, x, (size_t)n * sizeof *a);
  PM_PETSC_CALL(VecRestoreArray(v, &a));
  return PM_SUCCESS;
}

static pm_err copy_out(Vec v, double *x, long n) {
  const double *a;
  PM_PETSC_CALL(VecGetArrayRead(v, &a));
  memcpy(x, a, (size_t)n * sizeof *a);
  PM_PETSC_CALL(VecRestoreArrayRead(v, &a));
  return PM_SUCCESS;
}

/* ---- Colouring assembly ------------------------------------------------ */

/* vals (pattern order) = J(x) by one application of f per colour. */
static pm_err color_values(pm_newton *s, apply_fn f, const pm_coloring *col,
                           const double *x, double *vals) {
  for (int c = 0; c < col->ncolors; c++) {
    long lo = col->color_ptr[c], hi = col->color_ptr[c + 1];
    for (long k = lo; k < hi; k++) s->seed[col->color_col[k]] = 1.0;
    pm_err e = f(s->p.ctx, x, s->seed, s->dr);
    if (s->rep) s->rep->jacobian_applications++;
    for (long k = lo; k < hi; k++) s->seed[col->color_col[k]] = 0.0;
    PM_CHECK(e == PM_SUCCESS, e, "%s (applying the Jacobian to colour %d)",
             pm_error_message(), c);
    for (long k = lo; k < hi; k++) {
      long j = col->color_col[k];
      for (long q = col->col_ptr[j]; q < col->col_ptr[j + 1]; q++)
        vals[col->col_pos[q]] = s->dr[col->col_row[q]];
    }
  }
  return PM_SUCCESS;
}

/* The Jacobian's values at x in pattern order: the caller's assembly when
 * it gives one, else colouring. */
static pm_err jacobian_values(pm_newton *s, const double *x, double *vals) {
  if (!s->p.jacobian_values)
    return color_values(s, s->p.jacobian_apply, &s->jcol, x, vals);
  PM_CALL(s->p.jacobian_values(s->p.ctx, x, s->srcvals));
  memset(vals, 0, (size_t)s->jpat.ptr[s->jpat.n] * sizeof *vals);
  for (long k = 0; k < s->jpat.nsrc; k++) vals[s->jpat.src[k]] += s->srcvals[k];
  return PM_SUCCESS;
}

/* Rows of the pattern into M: their values (one process), or added to
 * the rows they are a part of, by local numbers (across ranks). */
static pm_err set_rows(Mat M, bool dist, const pm_pattern *pat,
                       const PetscInt *cols, const double *vals) {
  for (long i = 0; i < pat->n; i++) {
    PetscInt row = (PetscInt)i, len = (PetscInt)(pat->ptr[i + 1] - pat->ptr[i]);
    if (dist)
      PM_PETSC_CALL(MatSetValuesLocal(M, 1, &row, len, cols + pat->ptr[i],
                                      vals + pat->ptr[i], ADD_VALUES));
    else
      PM_PETSC_CALL(MatSetValues(M, 1, &row, len, cols + pat->ptr[i],
                                 vals + pat->ptr[i], INSERT_VALUES));
  }
  PM_PETSC_CALL(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY));
  PM_PETSC_CALL(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY));
  return PM_SUCCESS;
}

/* M = vals on the pattern (the matrix's preallocated structure). */
static pm_err insert_values(const pm_newton *s, Mat M, const pm_pattern *pat,
                            const PetscInt *cols, const double *vals) {
  if (s->dist) PM_PETSC_CALL(MatZeroEntries(M));
  return set_rows(M, s->dist, pat, cols, vals);
}

/* Across ranks: M's structure from every rank's rows, whichever rank owns
 * them (PETSc's preallocator matrix collects them). */
static pm_err preallocate_shared(const pm_newton *s, const pm_pattern *pat,
                                 const PetscInt *cols, const double *zeros,
                                 Mat M) {
  pm_err ret = PM_SUCCESS;
  Mat pre = NULL;
  PetscInt n = (PetscInt)s->p.n;
  PM_PETSC(MatCreate(s->comm, &pre));
  PM_PETSC(MatSetType(pre, MATPREALLOCATOR));
  PM_PETSC(MatSetSizes(pre, n, n, PETSC_DETERMINE, PETSC_DETERMINE));
  PM_PETSC(MatSetLocalToGlobalMapping(pre, s->l2g, s->l2g));
  PM_PETSC(MatSetUp(pre));
  PM_TRY(set_rows(pre, true, pat, cols, zeros));
  PM_PETSC(MatPreallocatorPreallocate(pre, PETSC_TRUE, M));
done:
  MatDestroy(&pre);
  return ret;
}

/* An AIJ matrix with the pattern's structure (zeros): sequential, or over
 * the ranks with every rank's rows. */
static pm_err create_matrix(const pm_newton *s, const pm_pattern *pat,
                            PetscInt **cols, double *zeros, Mat *M) {
  pm_err ret = PM_SUCCESS;
  PetscInt *nnz = NULL;
  long n = pat->n, total = pat->ptr[n];
  PM_TRY(PM_ALLOC(*cols, total > 0 ? total : 1, "matrix columns"));
  for (long k = 0; k < total; k++) (*cols)[k] = (PetscInt)pat->idx[k];
  if (s->dist) {
    PetscInt own = (PetscInt)s->p.n;
    PM_PETSC(MatCreate(s->comm, M));
    PM_PETSC(MatSetType(*M, MATAIJ));
    PM_PETSC(MatSetSizes(*M, own, own, PETSC_DETERMINE, PETSC_DETERMINE));
    PM_PETSC(MatSetLocalToGlobalMapping(*M, s->l2g, s->l2g));
    PM_TRY(preallocate_shared(s, pat, *cols, zeros, *M));
  } else {
    PM_TRY(PM_ALLOC(nnz, n, "matrix row lengths"));
    for (long i = 0; i < n; i++)
      nnz[i] = (PetscInt)(pat->ptr[i + 1] - pat->ptr[i]);
    PM_PETSC(
        MatCreateSeqAIJ(PETSC_COMM_SELF, (PetscInt)n, (PetscInt)n, 0, nnz, M));
  }
  PM_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PM_TRY(insert_values(s, *M, pat, *cols, zeros));
done:
  free(nnz);
  return ret;
}

/* ---- Across ranks: the held values ------------------------------------- */

/* The values a callback reads of V: its own array (one process), or the
 * held values of ghosted G, V's owned values with their ghosts' (across
 * ranks).  *loc is what to give back to in_done. */
static PetscErrorCode in_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
                             const double **a) {
  PetscFunctionBeginUser;
  *loc = V;
  if (s->dist) {
    PetscCall(VecCopy(V, G));
    PetscCall(VecGhostUpdateBegin(G, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGhostUpdateEnd(G, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGhostGetLocalForm(G, loc));
  }
  PetscCall(VecGetArrayRead(*loc, a));
  PetscFunctionReturn(0);
}

static PetscErrorCode in_done(const pm_newton *s, Vec G, Vec *loc,
                              const double **a) {
  PetscFunctionBeginUser;
  PetscCall(VecRestoreArrayRead(*loc, a));
  if (s->dist) PetscCall(VecGhostRestoreLocalForm(G, loc));
  PetscFunctionReturn(0);
}

/* Where a callback writes V's values: its array, or ghosted G's held
 * values (across ranks). */
static PetscErrorCode out_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
                              double **a) {
  PetscFunctionBeginUser;
  *loc = V;
  if (s->dist) PetscCall(VecGhostGetLocalForm(G, loc));
  PetscCall(VecGetArray(*loc, a));
  PetscFunctionReturn(0);
}

/* Across ranks, with every rank's callback done (ok on all of them):
 * the ghosts' contributions added on their owners, into V. */
static PetscErrorCode out_done(const pm_newton *s, Vec V, Vec G, Vec *loc,
                               double **a, bool ok) {
  PetscFunctionBeginUser;
  PetscCall(VecRestoreArray(*loc, a));
  if (s->dist) {
    PetscCall(VecGhostRestoreLocalForm(G, loc));
    if (ok) {
      PetscCall(VecGhostUpdateBegin(G, ADD_VALUES, SCATTER_REVERSE));
      PetscCall(VecGhostUpdateEnd(G, ADD_VALUES, SCATTER_REVERSE));
      PetscCall(VecCopy(G, V));
    }
  }
  PetscFunctionReturn(0);
}

/* A callback's answer, the same on every rank of a shared problem. */
static pm_err agreed(const pm_newton *s, pm_err e) {
  return s->dist ? pm_par_agree(e) : e;
}

/* ---- SNES callbacks ---------------------------------------------------- */

static PetscErrorCode snes_residual(SNES snes, Vec X, Vec R, void *ctx) {
  pm_newton *s = ctx;
  const double *x;
  double *r;
  Vec xl, rl;
  PetscFunctionBeginUser;
  double t = pm_wtime();
  PetscCall(in_get(s, X, s->Gx, &xl, &x));
  PetscCall(out_get(s, R, s->Gr, &rl, &r));
  pm_err e = agreed(s, s->p.residual(s->p.ctx, x, r));
  PetscCall(out_done(s, R, s->Gr, &rl, &r, e == PM_SUCCESS));
  PetscCall(in_done(s, s->Gx, &xl, &x));
  if (s->rep) {
    s->rep->time_residual += pm_wtime() - t;
    s->rep->residual_evaluations++;
  }
  s->domain_last = e != PM_SUCCESS;
  if (e == PM_SUCCESS) PetscFunctionReturn(0);
  if (hard_failure(e)) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "residual callback failed: %s",
            pm_error_message());
  }
  snprintf(s->domain_msg, sizeof s->domain_msg, "%s",
           pm_error_code() == e ? pm_error_message() : pm_err_string(e));
  pm_error_clear();
  PetscCall(SNESSetFunctionDomainError(snes));
  PetscFunctionReturn(0);
}

static PetscErrorCode snes_jacobian(SNES snes, Vec X, Mat A, Mat B, void *ctx) {
  pm_newton *s = ctx;
  const double *x;
  Vec xl;
  (void)snes;
  (void)A;
  PetscFunctionBeginUser;
  double t = pm_wtime();
  PetscCall(VecCopy(X, s->Xlin));
  PetscCall(in_get(s, X, s->Glin, &xl, &x));
  pm_err e = PM_SUCCESS;
  if (s->p.jacobian_prepare) e = agreed(s, s->p.jacobian_prepare(s->p.ctx, x));
  /* A preconditioner matrix left unchanged keeps its factorisation: PETSc
   * sets a PC up again only when the matrix's state has changed. */
  bool rebuild =
      s->o.op == PM_NEWTON_ASSEMBLED || s->jacobians % s->o.pc_lag == 0;
  s->jacobians++;
  if (e == PM_SUCCESS && rebuild) {
    if (s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
      e = color_values(s, s->p.precond_apply, &s->pcol, x, s->pvals);
      if (e == PM_SUCCESS)
        e = insert_values(s, B, &s->ppat, s->pcols, s->pvals);
    } else {
      e = agreed(s, jacobian_values(s, x, s->jvals));
      if (e == PM_SUCCESS)
        e = insert_values(s, B, &s->jpat, s->jcols, s->jvals);
    }
  }
  e = agreed(s, e);
  PetscCall(in_done(s, s->Glin, &xl, &x));
  if (s->rep) s->rep->time_assembly += pm_wtime() - t;
  if (e != PM_SUCCESS) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "Jacobian callback failed: %s",
            pm_error_message());
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode shell_mult(Mat A, Vec in, Vec out) {
  pm_newton *s;
  const double *x, *dx;
  double *dr;
  Vec xl, dxl, drl;
  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &s));
  /* The linearisation point's held values are Glin's since the Jacobian
   * was made there. */
  xl = s->Xlin;
  if (s->dist) PetscCall(VecGhostGetLocalForm(s->Glin, &xl));
  PetscCall(VecGetArrayRead(xl, &x));
  PetscCall(in_get(s, in, s->Gdx, &dxl, &dx));
  PetscCall(out_get(s, out, s->Gdr, &drl, &dr));
  pm_err e = agreed(s, s->p.jacobian_apply(s->p.ctx, x, dx, dr));
  if (s->rep) s->rep->jacobian_applications++;
  PetscCall(out_done(s, out, s->Gdr, &drl, &dr, e == PM_SUCCESS));
  PetscCall(in_done(s, s->Gdx, &dxl, &dx));
  PetscCall(VecRestoreArrayRead(xl, &x));
  if (s->dist) PetscCall(VecGhostRestoreLocalForm(s->Glin, &xl));
  if (e != PM_SUCCESS) {
    s->hard = e;
    SETERRQ(s->comm, PETSC_ERR_USER, "jacobian_apply failed: %s",
            pm_error_message());
  }
  PetscFunctionReturn(0);
}

/* The Newton direction before the line search scales it: SNES's Y solves
 * J Y = r, so dx = -Y. */
static PetscErrorCode line_search_precheck(SNESLineSearch ls, Vec X, Vec Y,
                                           PetscBool *changed, void *ctx) {
  pm_newton *s = ctx;
  Vec F;
  PetscReal dot;
  (void)ls;
  (void)X;
  PetscFunctionBeginUser;
  *changed = PETSC_FALSE;
  PetscCall(SNESGetFunction(s->snes, &F, NULL, NULL));
  PetscCall(VecNorm(Y, NORM_2, &s->incr));
  PetscCall(VecDot(Y, F, &dot));
  s->energy = fabs(dot);
  PetscFunctionReturn(0);
}

static PetscErrorCode linear_presolve(KSP ksp, Vec b, Vec x, void *ctx) {
  pm_newton *s = ctx;
  (void)ksp;
  (void)b;
  (void)x;
  s->linear_started = pm_wtime();
  s->in_linear = true;
  return 0;
}

static PetscErrorCode linear_postsolve(KSP ksp, Vec b, Vec x, void *ctx) {
  pm_newton *s = ctx;
  (void)ksp;
  (void)b;
  (void)x;
  if (s->rep) s->rep->time_linear += pm_wtime() - s->linear_started;
  s->in_linear = false;
  return 0;
}

/* Called with the state after `it` iterations (accepted by the line
 * search). */
static PetscErrorCode converged_test(SNES snes, PetscInt it, PetscReal xnorm,
                                     PetscReal snorm, PetscReal fnorm,
                                     SNESConvergedReason *reason, void *ctx) {
  pm_newton *s = ctx;
  pm_newton_report *rep = s->rep;
  const pm_newton_options *o = &s->o;
  Vec X;
  (void)xnorm;
  (void)snorm;
  PetscFunctionBeginUser;
  *reason = SNES_CONVERGED_ITERATING;
  if (it <= PM_NEWTON_MAX_ITER) rep->residual_norm[it] = fnorm;
  if (!isfinite(fnorm)) {
    s->reason = PM_NEWTON_DIVERGED_NAN;
    *reason = SNES_DIVERGED_FNORM_NAN;
    PetscFunctionReturn(0);
  }
  PetscCall(SNESGetSolution(snes, &X));
  PetscCall(VecCopy(X, s->Xacc));
  if (it == 0) {
    s->started = true;
    s->r0 = fmax(fnorm, s->r_ref);
    if (fnorm <= o->atol || fnorm == 0) {
      s->reason = PM_NEWTON_CONVERGED_ABSOLUTE;
      *reason = SNES_CONVERGED_FNORM_ABS;
    }
    PetscFunctionReturn(0);
  }
  PetscReal alpha = 0;
  PetscCall(SNESLineSearchGetLambda(s->ls, &alpha));
  if (it <= PM_NEWTON_MAX_ITER) {
    rep->increment_norm[it] = s->incr;
    rep->energy[it] = s->energy;
    rep->step_length[it] = alpha;
  }
  if (it == 1) s->e0 = s->energy;

  bool on[3] = {o->rtol > 0, o->dtol > 0, o->etol > 0};
  bool met[3] = {false, false, false};
  met[0] = on[0] && fnorm <= o->rtol * s->r0;
  if (on[1]) {
    PetscReal travel;
    PetscCall(VecWAXPY(s->Work, -1.0, s->Xstart, X));
    PetscCall(VecNorm(s->Work, NORM_2, &travel));
    met[1] = s->incr <= o->dtol * travel;
  }
  met[2] = on[2] && s->energy <= o->etol * s->e0;
  static const pm_newton_reason which[3] = {PM_NEWTON_CONVERGED_RESIDUAL,
                                            PM_NEWTON_CONVERGED_DISPLACEMENT,
                                            PM_NEWTON_CONVERGED_ENERGY};
  int count_on = 0, count_met = 0, first = -1;
  for (int c = 0; c < 3; c++) {
    count_on += on[c];
    count_met += met[c];
    if (met[c] && first < 0) first = c;
  }
  if (fnorm <= o->atol) {
    s->reason = PM_NEWTON_CONVERGED_ABSOLUTE;
  } else if (o->all_criteria ? count_on > 0 && count_met == count_on
                             : count_met > 0) {
    s->reason = o->all_criteria && count_on > 1 ? PM_NEWTON_CONVERGED_ALL
                                                : which[first];
  } else if (it >= o->max_iter) {
    s->reason = PM_NEWTON_DIVERGED_MAX_ITER;
    *reason = SNES_DIVERGED_MAX_IT;
    PetscFunctionReturn(0);
  } else if (o->stall_after > 0 && it >= o->stall_after &&
             it <= PM_NEWTON_MAX_ITER &&
             fnorm > 0.5 * rep->residual_norm[it - 2]) {
    s->reason = PM_NEWTON_DIVERGED_STALLED;
    *reason = SNES_DIVERGED_MAX_IT;
    PetscFunctionReturn(0);
  } else {
    PetscFunctionReturn(0);
  }
  *reason = s->reason == PM_NEWTON_CONVERGED_ABSOLUTE
                ? SNES_CONVERGED_FNORM_ABS
                : SNES_CONVERGED_FNORM_RELATIVE;
  PetscFunctionReturn(0);
}

/* ---- Creation ---------------------------------------------------------- */

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
               o->line_search <= PM_LINE_SEARCH_CP,
           PM_ERR_ARG, "unknown line search %d", (int)o->line_search);
  PM_CHECK(o->linear_rtol > 0 && o->linear_rtol < 1, PM_ERR_ARG,
           "linear_rtol must be in (0, 1) (got %g)", o->linear_rtol);
  PM_CHECK(o->stall_after == 0 || o->stall_after >= 2, PM_ERR_ARG,
           "Newton stall_after must be 0 (off) or >= 2 (got %d)",
           o->stall_after);
  PM_CHECK(o->linear_max_iter >= 1, PM_ERR_ARG,
           "linear_max_iter must be >= 1 (got %d)", o->linear_max_iter);
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
  PM_CHECK(o->op != PM_NEWTON_MATRIX_FREE_CHEAP_PC || p->precond_apply,
           PM_ERR_ARG,
           "Newton problem: the cheap preconditioner needs precond_apply");
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
    PM_PETSC(KSPSetType(ksp, matrix_free ? KSPGMRES : KSPPREONLY));
    PM_PETSC(PCSetType(pc, PCLU));
#ifdef PETSC_HAVE_MUMPS
    PM_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
    break;
  case PM_NEWTON_GMRES_GAMG:
    PM_PETSC(KSPSetType(ksp, KSPGMRES));
    PM_PETSC(PCSetType(pc, PCGAMG));
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
    break;
  }
  PM_PETSC(KSPSetTolerances(ksp, o->linear_rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                            o->linear_max_iter));
  PM_PETSC(KSPSetPreSolve(ksp, linear_presolve, s));
  PM_PETSC(KSPSetPostSolve(ksp, linear_postsolve, s));
  PM_PETSC(PetscOptionsPush(s->opts));
  PetscErrorCode code = KSPSetFromOptions(ksp);
  PetscOptionsPop();
  PM_PETSC(code);
  *out = ksp;
  ksp = NULL;
done:
  KSPDestroy(&ksp);
  return ret;
}

/* Gives SNES a new linear solver (in place of one left inconsistent by a
 * failure inside it). */
static pm_err replace_linear(pm_newton *s) {
  KSP ksp, held;
  PM_CALL(create_linear(s, &ksp));
  held = ksp;
  PetscErrorCode code = SNESSetKSP(s->snes, ksp);
  KSPDestroy(&ksp); /* SNES holds it */
  PM_PETSC_CALL(code);
  s->ksp = held;
  return PM_SUCCESS;
}

/* What the linear solver multiplies by (A) and builds its preconditioner
 * from (B). */
static void operators(const pm_newton *s, Mat *A, Mat *B) {
  *A = s->o.op == PM_NEWTON_ASSEMBLED ? s->J : s->Shell;
  *B = s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC ? s->P : s->J;
}

static pm_err configure_snes(pm_newton *s) {
  const pm_newton_options *o = &s->o;
  static const SNESLineSearchType types[] = {
      SNESLINESEARCHBT, SNESLINESEARCHBASIC, SNESLINESEARCHL2,
      SNESLINESEARCHCP};
  PM_PETSC_CALL(PetscOptionsCreate(&s->opts));
  /* MUMPS: a singular matrix (a limit point) factors with its null pivots
   * set aside instead of failing with an error. */
  PM_PETSC_CALL(PetscOptionsInsertString(s->opts, "-pm_mat_mumps_icntl_24 1"));
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
  PM_CALL(replace_linear(s));

  PM_PETSC_CALL(SNESSetType(s->snes, SNESNEWTONLS));
  PM_PETSC_CALL(SNESSetFunction(s->snes, s->R, snes_residual, s));
  Mat A, B;
  operators(s, &A, &B);
  PM_PETSC_CALL(SNESSetJacobian(s->snes, A, B, snes_jacobian, s));
  PM_PETSC_CALL(SNESSetConvergenceTest(s->snes, converged_test, s, NULL));
  /* The step-size test (stol) is off: a short step is no convergence. */
  PM_PETSC_CALL(SNESSetTolerances(s->snes, 0, 0, 0, o->max_iter, 1000000000));
  PM_PETSC_CALL(SNESLineSearchSetType(s->ls, types[o->line_search]));
  PM_PETSC_CALL(SNESLineSearchSetTolerances(s->ls, PETSC_DEFAULT, 1e300,
                                            PETSC_DEFAULT, PETSC_DEFAULT,
                                            PETSC_DEFAULT, PETSC_DEFAULT));
  PM_PETSC_CALL(SNESLineSearchSetPreCheck(s->ls, line_search_precheck, s));
  PM_PETSC_CALL(PetscOptionsPush(s->opts));
  PetscErrorCode code = SNESSetFromOptions(s->snes);
  PetscOptionsPop();
  PM_PETSC_CALL(code);
  return PM_SUCCESS;
}

/* The problem's near-null vectors, orthonormalised (modified Gram-Schmidt;
 * a vector dependent on the earlier ones is dropped), as M's near null
 * space. */
static pm_err set_near_null(pm_newton *s, Mat M) {
  pm_err ret = PM_SUCCESS;
  const long n = s->p.n;
  const int k = s->p.near_null_count;
  Vec v[16];
  int m = 0;
  MatNullSpace ns = NULL;
  PM_CHECK(k <= 16, PM_ERR_ARG,
           "Newton problem: %d near-null vectors (at "
           "most 16)",
           k);
  for (int a = 0; a < k; a++) {
    double *w;
    PetscReal norm0, norm;
    PM_PETSC(VecDuplicate(s->X, &v[m]));
    PM_TRY(copy_in(v[m], s->p.near_null + (size_t)a * n, n));
    PM_PETSC(VecNorm(v[m], NORM_2, &norm0));
    for (int b = 0; b < m; b++) {
      PetscScalar dot;
      PM_PETSC(VecDot(v[m], v[b], &dot));
      PM_PETSC(VecAXPY(v[m], -dot, v[b]));
    }
    PM_PETSC(VecNorm(v[m], NORM_2, &norm));
    if (!(norm > 1e-10 * norm0)) {
      VecDestroy(&v[m]);
      continue;
    }
    PM_PETSC(VecGetArray(v[m], &w));
    for (long i = 0; i < n; i++) w[i] /= norm;
    PM_PETSC(VecRestoreArray(v[m], &w));
    m++;
  }
  PM_PETSC(MatNullSpaceCreate(s->comm, PETSC_FALSE, m, v, &ns));
  PM_PETSC(MatSetNearNullSpace(M, ns));
done:
  MatNullSpaceDestroy(&ns);
  for (int b = 0; b < m; b++) VecDestroy(&v[b]);
  return ret;
}

/* Across ranks: the numbering of the held values over all ranks (owned
 * ones from this rank's offset, then the ghosts') and the ghosted vectors
 * of the callbacks. */
static pm_err create_shared(pm_newton *s) {
  pm_err ret = PM_SUCCESS;
  const long n = s->p.n, ng = s->p.n_ghost;
  PetscInt *global = NULL, *ghost = NULL;
  PM_TRY(PM_ALLOC(global, s->nloc, "global numbers"));
  PM_TRY(PM_ALLOC(ghost, ng + 1, "ghost numbers"));
  const long offset = pm_par_offset(n);
  for (long i = 0; i < n; i++) global[i] = (PetscInt)(offset + i);
  for (long k = 0; k < ng; k++)
    global[n + k] = ghost[k] = (PetscInt)s->p.ghost[k];
  PM_PETSC(ISLocalToGlobalMappingCreate(s->comm, 1, (PetscInt)s->nloc, global,
                                        PETSC_COPY_VALUES, &s->l2g));
  PM_PETSC(VecCreateGhost(s->comm, (PetscInt)n, PETSC_DETERMINE, (PetscInt)ng,
                          ghost, &s->Gx));
  PM_PETSC(VecDuplicate(s->Gx, &s->Glin));
  PM_PETSC(VecDuplicate(s->Gx, &s->Gdx));
  PM_PETSC(VecDuplicate(s->Gx, &s->Gr));
  PM_PETSC(VecDuplicate(s->Gx, &s->Gdr));
done:
  free(global);
  free(ghost);
  return ret;
}

static pm_err create_petsc_objects(pm_newton *s) {
  PetscInt n = (PetscInt)s->p.n;
  if (s->dist) {
    PM_CALL(create_shared(s));
    PM_PETSC_CALL(VecCreateMPI(s->comm, n, PETSC_DETERMINE, &s->X));
  } else {
    PM_PETSC_CALL(VecCreateSeq(PETSC_COMM_SELF, n, &s->X));
  }
  PM_PETSC_CALL(VecDuplicate(s->X, &s->R));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xstart));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xlin));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Xacc));
  PM_PETSC_CALL(VecDuplicate(s->X, &s->Work));
  if (s->o.op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
    PM_CALL(create_matrix(s, &s->ppat, &s->pcols, s->pvals, &s->P));
  } else {
    PM_CALL(create_matrix(s, &s->jpat, &s->jcols, s->jvals, &s->J));
  }
  if (s->p.near_null_count > 0) {
    Mat A, B;
    operators(s, &A, &B);
    PM_CALL(set_near_null(s, B));
  }
  if (s->o.op != PM_NEWTON_ASSEMBLED) {
    PM_PETSC_CALL(MatCreateShell(s->comm, n, n, PETSC_DETERMINE,
                                 PETSC_DETERMINE, s, &s->Shell));
    PM_PETSC_CALL(
        MatShellSetOperation(s->Shell, MATOP_MULT, (void (*)(void))shell_mult));
  }
  return configure_snes(s);
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
  if (problem->jacobian_values)
    PM_TRY(PM_ALLOC(s->srcvals, s->jpat.nsrc > 0 ? s->jpat.nsrc : 1,
                    "Jacobian values"));
  else
    PM_TRY(pm_coloring_build(&s->jpat, options->coloring, &s->jcol));
  PM_TRY(PM_ALLOC(s->jvals, s->jpat.ptr[n], "Jacobian values"));
  if (options->op == PM_NEWTON_MATRIX_FREE_CHEAP_PC) {
    const long *ptr =
        problem->pc_pat_ptr ? problem->pc_pat_ptr : problem->pat_ptr;
    const long *idx =
        problem->pc_pat_ptr ? problem->pc_pat_idx : problem->pat_idx;
    PM_TRY(pm_pattern_build(n, ptr, idx, true, &s->ppat));
    PM_TRY(pm_coloring_build(&s->ppat, options->coloring, &s->pcol));
    PM_TRY(PM_ALLOC(s->pvals, s->ppat.ptr[n], "preconditioner values"));
  }
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
  MatDestroy(&s->Shell);
  MatDestroy(&s->J);
  MatDestroy(&s->P);
  VecDestroy(&s->X);
  VecDestroy(&s->R);
  VecDestroy(&s->Xstart);
  VecDestroy(&s->Xlin);
  VecDestroy(&s->Xacc);
  VecDestroy(&s->Work);
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
  free(s->seed);
  free(s->dr);
  free(s->petsc_options);
  free(s);
  *sp = NULL;
}

/* ---- Solving ----------------------------------------------------------- */

/* The reason, status and message of a finished SNESSolve. */
static pm_err classify(pm_newton *s, pm_newton_report *rep) {
  SNESConvergedReason sr;
  PM_PETSC_CALL(SNESGetConvergedReason(s->snes, &sr));
  int it = rep->iterations;
  double r = it <= PM_NEWTON_MAX_ITER ? rep->residual_norm[it] : NAN;
  char figures[96];
  snprintf(figures, sizeof figures, "residual %.2e from %.2e", r, s->r0);
  size_t cap = sizeof rep->message;
  if (sr > 0) {
    rep->reason = s->reason;
    rep->status = PM_SUCCESS;
    return PM_SUCCESS;
  }
  rep->status = PM_ERR_NOT_CONVERGED;
  switch (sr) {
  case SNES_DIVERGED_MAX_IT:
    if (s->reason == PM_NEWTON_DIVERGED_STALLED) {
      rep->reason = PM_NEWTON_DIVERGED_STALLED;
      snprintf(rep->message, cap,
               "Newton stalled: the residual was not halved over iterations "
               "%d and %d (%s)",
               it - 1, it, figures);
      break;
    }
    rep->reason = PM_NEWTON_DIVERGED_MAX_ITER;
    snprintf(rep->message, cap, "Newton did not converge in %d iterations (%s)",
             it, figures);
    break;
  case SNES_DIVERGED_FNORM_NAN:
    rep->reason = PM_NEWTON_DIVERGED_NAN;
    rep->status = PM_ERR_UNSTABLE;
    snprintf(rep->message, cap,
             "Newton: residual not finite after %d "
             "iterations",
             it);
    break;
  case SNES_DIVERGED_FUNCTION_DOMAIN:
    rep->reason = PM_NEWTON_DIVERGED_DOMAIN;
    rep->status = PM_ERR_UNSTABLE;
    if (!s->started)
      snprintf(rep->message, cap,
               "Newton: the initial state is inadmissible: %s", s->domain_msg);
    else
      snprintf(rep->message, cap,
               "Newton: no admissible step in iteration %d (%s): %s", it + 1,
               figures, s->domain_msg);
    break;
  case SNES_DIVERGED_LINEAR_SOLVE: {
    KSPConvergedReason kr;
    PetscInt kits;
    PM_PETSC_CALL(KSPGetConvergedReason(s->ksp, &kr));
    PM_PETSC_CALL(KSPGetIterationNumber(s->ksp, &kits));
    rep->reason = PM_NEWTON_DIVERGED_LINEAR;
    snprintf(rep->message, cap,
             "Newton: the linear solver failed in iteration %d (%s after %d "
             "linear iterations; %s)",
             it + 1, KSPConvergedReasons[kr], (int)kits, figures);
    /* A failed factorisation is not redone by PETSc 3.18 (MUMPS keeps its
     * error): the next solve gets a new linear solver. */
    if (kr == KSP_DIVERGED_PC_FAILED) PM_CALL(replace_linear(s));
    break;
  }
  default:
    if (s->domain_last) {
      rep->reason = PM_NEWTON_DIVERGED_DOMAIN;
      rep->status = PM_ERR_UNSTABLE;
      snprintf(rep->message, cap,
               "Newton: no admissible step in iteration %d (%s): %s", it + 1,
               figures, s->domain_msg);
    } else {
      rep->reason = PM_NEWTON_DIVERGED_LINE_SEARCH;
      snprintf(rep->message, cap,
               "Newton: the line search found no step that decreases the "
               "residual in iteration %d (%s; SNES %s)",
               it + 1, figures, SNESConvergedReasons[sr]);
    }
  }
  return PM_SUCCESS;
}

pm_err pm_newton_solve_from(pm_newton *s, double *x, const double *x_start,
                            double r_ref, pm_newton_report *rep) {
  pm_err ret = PM_SUCCESS;
  long n = s->p.n;
  double t0 = pm_wtime();
  memset(rep, 0, sizeof *rep);
  s->rep = rep;
  s->reason = PM_NEWTON_NOT_RUN;
  s->hard = PM_SUCCESS;
  s->domain_last = false;
  s->domain_msg[0] = '\0';
  s->r0 = s->e0 = s->incr = s->energy = 0;
  s->r_ref = r_ref;
  s->jacobians = 0;
  s->in_linear = false;
  s->started = false;
  PM_TRY(copy_in(s->X, x, n));
  PM_TRY(copy_in(s->Xstart, x_start, n));
  PM_PETSC(VecCopy(s->X, s->Xacc));
  /* Objects PETSc creates inside the solve (the factor matrix, multigrid
   * levels) read the default options database: this solver's, for now. */
  PM_PETSC(PetscOptionsPush(s->opts));
  PetscErrorCode code = SNESSolve(s->snes, NULL, s->X);
  PetscOptionsPop();
  PetscInt its = 0, lits = 0;
  SNESGetIterationNumber(s->snes, &its);
  SNESGetLinearSolveIterations(s->snes, &lits);
  rep->iterations = (int)its;
  rep->linear_iterations = (int)lits;
  if (s->hard != PM_SUCCESS) {
    ret = pm_error_trace(s->hard, __FILE__, __LINE__, __func__,
                         "a callback of the Newton solve");
    rep->status = ret;
    snprintf(rep->message, sizeof rep->message, "%s", pm_error_message());
    goto done;
  }
  if (code && s->in_linear) {
    /* A numerical failure inside the linear solver that PETSc raises as an
     * error (an external solver's, a zero pivot) is a linear solver failure
     * like any other: the caller may cut the step, and the solver it left
     * half-way is replaced.  Other errors (bad options) are PETSc's. */
    PetscErrorCode cause;
    const char *what = pm_petsc_last_message(&cause);
    s->in_linear = false;
    rep->time_linear += pm_wtime() - s->linear_started;
    if (cause != PETSC_ERR_LIB && cause != PETSC_ERR_MAT_LU_ZRPVT &&
        cause != PETSC_ERR_MAT_CH_ZRPVT && cause != PETSC_ERR_FP &&
        cause != PETSC_ERR_NOT_CONVERGED) {
      ret = PM_ERROR(PM_ERR_LINALG, "SNESSolve failed: %s", what);
      (void)replace_linear(s);
      goto done;
    }
    rep->reason = PM_NEWTON_DIVERGED_LINEAR;
    rep->status = PM_ERR_NOT_CONVERGED;
    snprintf(rep->message, sizeof rep->message,
             "Newton: the linear solver failed in iteration %d (%s)",
             rep->iterations + 1, what);
    PM_TRY(replace_linear(s));
    ret = PM_ERROR(rep->status, "%s", rep->message);
    goto done;
  }
  PM_PETSC(code);
  PM_TRY(classify(s, rep));
  if (rep->status != PM_SUCCESS)
    ret = PM_ERROR(rep->status, "%s", rep->message);
done:
  if (copy_out(s->Xacc, x, n) != PM_SUCCESS && ret == PM_SUCCESS)
    ret = pm_error_code();
  rep->time_total = pm_wtime() - t0;
  s->rep = NULL;
  return ret;
}

pm_err pm_newton_tangent_solve(pm_newton *s, const double *x, const double *b,
                               double *dx, pm_newton_report *rep) {
  pm_err ret = PM_SUCCESS;
  long n = s->p.n;
  Mat A, B;
  operators(s, &A, &B);
  KSPConvergedReason kr;
  s->rep = rep;
  s->hard = PM_SUCCESS;
  s->jacobians = 0;
  PM_TRY(copy_in(s->X, x, n));
  PM_TRY(copy_in(s->Work, b, n));
  PM_PETSC(PetscOptionsPush(s->opts));
  PetscErrorCode code = snes_jacobian(s->snes, s->X, A, B, s);
  if (!code) code = KSPSetOperators(s->ksp, A, B);
  if (!code) {
    linear_presolve(s->ksp, s->Work, s->R, s);
    code = KSPSolve(s->ksp, s->Work, s->R);
    if (s->in_linear) linear_postsolve(s->ksp, s->Work, s->R, s);
  }
  PetscOptionsPop();
  if (s->hard != PM_SUCCESS) {
    ret = pm_error_trace(s->hard, __FILE__, __LINE__, __func__,
                         "the tangent of a load step's predictor");
    goto done;
  }
  if (code) {
    /* A failed factorisation leaves the solver unusable: replace it. */
    PetscErrorCode cause;
    const char *what = pm_petsc_last_message(&cause);
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "the predictor's linear solve: %s",
                   what);
    (void)replace_linear(s);
    goto done;
  }
  PM_PETSC(KSPGetConvergedReason(s->ksp, &kr));
  if (kr < 0) {
    ret = PM_ERROR(PM_ERR_NOT_CONVERGED, "the predictor's linear solve: %s",
                   KSPConvergedReasons[kr]);
    if (kr == KSP_DIVERGED_PC_FAILED) (void)replace_linear(s);
    goto done;
  }
  PM_TRY(copy_out(s->R, dx, n));
done:
  s->rep = NULL;
  return ret;
}

pm_err pm_newton_residual(pm_newton *s, const double *x, double *r) {
  if (!s->dist) return s->p.residual(s->p.ctx, x, r);
  pm_err e = PM_SUCCESS;
  const double *xh;
  double *rh;
  Vec xl, rl;
  PM_CALL(copy_in(s->Work, x, s->p.n));
  PM_PETSC_CALL(in_get(s, s->Work, s->Gx, &xl, &xh));
  PM_PETSC_CALL(out_get(s, s->R, s->Gr, &rl, &rh));
  e = agreed(s, s->p.residual(s->p.ctx, xh, rh));
  PM_PETSC_CALL(out_done(s, s->R, s->Gr, &rl, &rh, e == PM_SUCCESS));
  PM_PETSC_CALL(in_done(s, s->Gx, &xl, &xh));
  if (e == PM_SUCCESS) PM_CALL(copy_out(s->R, r, s->p.n));
  return e;
}

pm_err pm_newton_held_values(pm_newton *s, const double *x, double *held) {
  if (!s->dist) {
    memcpy(held, x, (size_t)s->p.n * sizeof *held);
    return PM_SUCCESS;
  }
  const double *h;
  Vec hl;
  PM_CALL(copy_in(s->Work, x, s->p.n));
  PM_PETSC_CALL(in_get(s, s->Work, s->Gx, &hl, &h));
  memcpy(held, h, (size_t)s->nloc * sizeof *held);
  PM_PETSC_CALL(in_done(s, s->Gx, &hl, &h));
  return PM_SUCCESS;
}

double pm_newton_norm(const pm_newton *s, const double *v) {
  double sum = 0;
  for (long i = 0; i < s->p.n; i++) sum += v[i] * v[i];
  if (s->dist) pm_par_sum(&sum, 1);
  return sqrt(sum);
}

pm_err pm_newton_solve(pm_newton *s, double *x, pm_newton_report *report) {
  pm_newton_report local;
  PM_CHECK(s && x, PM_ERR_ARG, "pm_newton_solve: solver and x are required");
  return pm_newton_solve_from(s, x, x, 0, report ? report : &local);
}

/* ---- Checks of a linearisation ----------------------------------------- */

pm_err pm_newton_jacobian_values(pm_newton *s, const double *x, double *val) {
  PM_CHECK(s && x && val, PM_ERR_ARG,
           "pm_newton_jacobian_values: solver, x and val are required");
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED,
           "pm_newton_jacobian_values: one process's problems only");
  if (s->p.jacobian_prepare) PM_CALL(s->p.jacobian_prepare(s->p.ctx, x));
  PM_CALL(jacobian_values(s, x, s->jvals));
  for (long k = 0; k < s->jpat.nsrc; k++) val[k] = s->jvals[s->jpat.src[k]];
  return PM_SUCCESS;
}

pm_err pm_newton_check_jacobian(pm_newton *s, const double *x, double h,
                                double *max_error, long *row, long *col) {
  pm_err ret = PM_SUCCESS;
  double *xp = NULL, *rp = NULL, *rm = NULL, *column = NULL;
  PM_CHECK(s && x && max_error && h > 0, PM_ERR_ARG,
           "pm_newton_check_jacobian: solver, x, max_error and h > 0 are "
           "required (h %g)",
           h);
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED,
           "pm_newton_check_jacobian: one process's problems only");
  long n = s->p.n;
  /* The pattern by columns (a caller-assembled Jacobian has no colouring
   * yet). */
  if (!s->jcol.col_ptr)
    PM_CALL(pm_coloring_build(&s->jpat, s->o.coloring, &s->jcol));
  const pm_coloring *c = &s->jcol;
  if (s->p.jacobian_prepare) PM_CALL(s->p.jacobian_prepare(s->p.ctx, x));
  PM_CALL(jacobian_values(s, x, s->jvals));
  PM_TRY(PM_ALLOC(xp, n, "perturbed state"));
  PM_TRY(PM_ALLOC(rp, n, "perturbed residual"));
  PM_TRY(PM_ALLOC(rm, n, "perturbed residual"));
  PM_TRY(PM_ALLOC(column, n, "Jacobian column"));
  memcpy(xp, x, (size_t)n * sizeof *xp);
  double worst = 0, largest = 0;
  long worst_row = 0, worst_col = 0;
  for (long j = 0; j < n; j++) {
    double step = h * fabs(x[j]) + h;
    xp[j] = x[j] + step;
    PM_TRY(s->p.residual(s->p.ctx, xp, rp));
    xp[j] = x[j] - step;
    PM_TRY(s->p.residual(s->p.ctx, xp, rm));
    xp[j] = x[j];
    for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++)
      column[c->col_row[q]] = s->jvals[c->col_pos[q]];
    for (long i = 0; i < n; i++) {
      double fd = (rp[i] - rm[i]) / (2 * step);
      double err = fabs(fd - column[i]);
      if (fabs(fd) > largest) largest = fabs(fd);
      if (!(err <= worst)) {
        worst = err;
        worst_row = i;
        worst_col = j;
      }
    }
    for (long q = c->col_ptr[j]; q < c->col_ptr[j + 1]; q++)
      column[c->col_row[q]] = 0;
  }
  *max_error = largest > 0 ? worst / largest : worst;
  if (row) *row = worst_row;
  if (col) *col = worst_col;
done:
  free(xp);
  free(rp);
  free(rm);
  free(column);
  return ret;
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
