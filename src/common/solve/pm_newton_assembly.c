/* pm_newton_assembly: the Jacobian's values by colouring (or the caller's
 * assembly) into PETSc matrices with the pattern's structure, on one process
 * or across ranks, and the near null space of the preconditioner's matrix. */
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"

pm_err pm_newton_copy_in(Vec v, const double *x, long n) {
  double *a;
  PM_PETSC_CALL(VecGetArray(v, &a));
  memcpy(a, x, (size_t)n * sizeof *a);
  PM_PETSC_CALL(VecRestoreArray(v, &a));
  return PM_SUCCESS;
}

pm_err pm_newton_copy_out(Vec v, double *x, long n) {
  const double *a;
  PM_PETSC_CALL(VecGetArrayRead(v, &a));
  memcpy(x, a, (size_t)n * sizeof *a);
  PM_PETSC_CALL(VecRestoreArrayRead(v, &a));
  return PM_SUCCESS;
}

/* ---- Colouring assembly ------------------------------------------------ */

/* vals (pattern order) = J(x) by one application of f per colour. */
pm_err pm_newton_color_values(pm_newton *s, apply_fn f, const pm_coloring *col,
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

/* vals (pat's order) = the caller's values src (the source's order)
 * summed into their places, row by row on every thread (each row's sums
 * in the source's order, as one thread makes them). */
static void scatter(const pm_pattern *pat, const double *src, double *vals) {
  const long n = pat->n;
  if (!pat->src) { /* the source is the pattern */
    if (vals != src) memcpy(vals, src, (size_t)pat->ptr[n] * sizeof *vals);
    return;
  }
  const long *ptr = pat->ptr, *sptr = pat->sptr, *to = pat->src;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, ptr, sptr, to, src, vals))
  for (long i = 0; i < n; i++) {
    for (long k = ptr[i]; k < ptr[i + 1]; k++) vals[k] = 0;
    for (long k = sptr[i]; k < sptr[i + 1]; k++) vals[to[k]] += src[k];
  }
}

/* The Jacobian's values at x in pattern order: the caller's assembly when
 * it gives one, else colouring. */
pm_err pm_newton_values_at(pm_newton *s, const double *x, double *vals) {
  if (!s->p.jacobian_values)
    return pm_newton_color_values(s, s->p.jacobian_apply, &s->jcol, x, vals);
  /* (the caller's order the pattern's: its values in place) */
  double *src = s->jpat.src ? s->srcvals : vals;
  PM_CALL(s->p.jacobian_values(s->p.ctx, x, src));
  scatter(&s->jpat, src, vals);
  return PM_SUCCESS;
}

pm_err pm_newton_precond_values(pm_newton *s, const double *x, double *vals) {
  if (!s->p.precond_values)
    return pm_newton_color_values(s, s->p.precond_apply, &s->pcol, x, vals);
  double *src = s->ppat.src ? s->psrcvals : vals;
  PM_CALL(s->p.precond_values(s->p.ctx, x, src));
  scatter(&s->ppat, src, vals);
  return PM_SUCCESS;
}

pm_err pm_newton_jvals(pm_newton *s, double **vals) {
  if (!s->jvals)
    PM_CALL(PM_ALLOC(s->jvals, s->jpat.ptr[s->jpat.n] + 1, "Jacobian values"));
  *vals = s->jvals;
  return PM_SUCCESS;
}

pm_err pm_newton_pattern_columns(pm_newton *s) {
  if (s->jpat.idx) return PM_SUCCESS;
  pm_err ret = PM_SUCCESS;
  PetscInt n;
  const PetscInt *ia, *ja;
  PetscBool done;
  long *idx = NULL;
  const long total = s->jpat.ptr[s->jpat.n];
  PM_CALL(PM_ALLOC(idx, total + 1, "pattern columns"));
  PM_PETSC(MatGetRowIJ(s->J, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  const bool same = done && n == s->jpat.n && ia[n] == total;
  if (same)
    for (long k = 0; k < total; k++) idx[k] = ja[k];
  PM_PETSC(
      MatRestoreRowIJ(s->J, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PM_ENSURE(same, PM_ERR_INTERNAL,
            "the Jacobian's matrix does not hold its pattern");
  s->jpat.idx = idx;
  idx = NULL;
done:
  free(idx);
  return ret;
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
pm_err pm_newton_insert_values(const pm_newton *s, Mat M, const pm_pattern *pat,
                               const PetscInt *cols, const double *vals) {
  if (s->dist) PM_PETSC_CALL(MatZeroEntries(M));
  return set_rows(M, s->dist, pat, cols, vals);
}

pm_err pm_newton_fill(pm_newton *s, Mat M, const pm_pattern *pat,
                      const PetscInt *cols, double *vals, pm_newton_values_fn f,
                      const double *x) {
  if (cols) {
    PM_CALL(f(s, x, vals));
    return pm_newton_insert_values(s, M, pat, cols, vals);
  }
  double *a;
  PM_PETSC_CALL(MatSeqAIJGetArrayWrite(M, &a));
  pm_err e = f(s, x, a);
  PM_PETSC_CALL(MatSeqAIJRestoreArrayWrite(M, &a));
  return e;
}

pm_err pm_newton_scatter_into(Mat M, const pm_pattern *pat, const double *src) {
  double *a;
  PM_PETSC_CALL(MatSeqAIJGetArrayWrite(M, &a));
  scatter(pat, src, a);
  PM_PETSC_CALL(MatSeqAIJRestoreArrayWrite(M, &a));
  return PM_SUCCESS;
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

/* An AIJ matrix with the pattern's structure (zeros): sequential, its
 * storage the pattern's order (*cols then NULL: values are written in
 * place), or over the ranks with every rank's rows (zeros: the values
 * inserted, as many as the pattern's entries). */
pm_err pm_newton_create_matrix(const pm_newton *s, pm_pattern *pat,
                               bool release, PetscInt **cols, double *zeros,
                               Mat *M) {
  pm_err ret = PM_SUCCESS;
  PetscInt *ia = NULL;
  long n = pat->n, total = pat->ptr[n];
  PM_TRY(PM_ALLOC(*cols, total > 0 ? total : 1, "matrix columns"));
  for (long k = 0; k < total; k++) (*cols)[k] = (PetscInt)pat->idx[k];
  if (release && !s->dist) {
    free(pat->idx);
    pat->idx = NULL;
  }
  if (s->dist) {
    PetscInt own = (PetscInt)s->p.n;
    PM_PETSC(MatCreate(s->comm, M));
    PM_PETSC(MatSetType(*M, MATAIJ));
    PM_PETSC(MatSetSizes(*M, own, own, PETSC_DETERMINE, PETSC_DETERMINE));
    PM_PETSC(MatSetLocalToGlobalMapping(*M, s->l2g, s->l2g));
    PM_TRY(preallocate_shared(s, pat, *cols, zeros, *M));
    PM_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    PM_TRY(pm_newton_insert_values(s, *M, pat, *cols, zeros));
    goto done;
  }
  PM_TRY(PM_ALLOC(ia, n + 1, "matrix rows"));
  for (long i = 0; i <= n; i++) ia[i] = (PetscInt)pat->ptr[i];
  PM_PETSC(MatCreate(PETSC_COMM_SELF, M));
  PM_PETSC(MatSetSizes(*M, (PetscInt)n, (PetscInt)n, (PetscInt)n, (PetscInt)n));
  PM_PETSC(MatSetType(*M, MATSEQAIJ));
  /* unknowns in blocks (a point's components): multigrid aggregates
   * the blocks and fits the near null space on them */
  if (s->p.block_size > 1 && n % s->p.block_size == 0)
    PM_PETSC(MatSetBlockSize(*M, (PetscInt)s->p.block_size));
  /* the rows' sorted columns: PETSc keeps them in this order, so the
   * pattern's places are its storage's */
  PM_PETSC(MatSeqAIJSetPreallocationCSR(*M, ia, *cols, NULL));
  PM_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
done:
  /* (one process: the matrix holds the columns; none kept) */
  if (!s->dist) {
    free(*cols);
    *cols = NULL;
  }
  free(ia);
  return ret;
}

/* The problem's near-null vectors, orthonormalised (modified Gram-Schmidt;
 * a vector dependent on the earlier ones is dropped), as M's near null
 * space. */
pm_err pm_newton_set_near_null(pm_newton *s, Mat M) {
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
    PM_TRY(pm_newton_copy_in(v[m], s->p.near_null + (size_t)a * n, n));
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
