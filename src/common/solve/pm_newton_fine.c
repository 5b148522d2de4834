/* pm_newton_fine: multigrid's finest level multiplied on every thread.
 * PETSc's sparse product runs on one thread; with the finest level
 * smoothed by the assembled matrix (amg_assembled_smoother), its
 * smoother's and residual's products are most of a V-cycle's work (four
 * or five products a cycle against a coarse level of tens of unknowns).
 * They go through a shell (Fine) that multiplies the same assembled
 * matrix, in PETSc's own storage, in an OpenMP loop over the rows. */
#include <stdbool.h>

#include <petscksp.h>

#include "pm_newton_solver_impl.h"
#include "pm_petsc.h"
#include "pm_omp.h"

/* The assembled matrix the finest level is built from (one process). */
static Mat fine_source(const pm_newton *s) {
  Mat A, B;
  pm_newton_operators(s, &A, &B);
  return B;
}

/* Whether each run of three rows from a multiple of 3 shares its columns
 * (a point's three components: the tangent's rows come in such blocks),
 * which lets one pass over the columns serve three rows. */
static bool rows_in_threes(PetscInt n, const PetscInt *ia, const PetscInt *ja) {
  if (n % 3) return false;
  for (PetscInt i = 0; i < n; i += 3) {
    const PetscInt len = ia[i + 1] - ia[i];
    if (ia[i + 2] - ia[i + 1] != len || ia[i + 3] - ia[i + 2] != len)
      return false;
    for (PetscInt k = 0; k < len; k++)
      if (ja[ia[i] + k] != ja[ia[i + 1] + k] ||
          ja[ia[i] + k] != ja[ia[i + 2] + k])
        return false;
  }
  return true;
}

static PetscErrorCode fine_mult(Mat F, Vec in, Vec out) {
  pm_newton *s;
  PetscInt n;
  const PetscInt *ia, *ja;
  const PetscScalar *a, *x;
  PetscScalar *y;
  PetscBool done;
  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(F, &s));
  const Mat B = fine_source(s);
  PetscCall(MatGetRowIJ(B, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP,
             "the finest level's matrix gives no rows");
  if (s->fine_threes < 0) s->fine_threes = rows_in_threes(n, ia, ja);
  PetscCall(MatSeqAIJGetArrayRead(B, &a));
  PetscCall(VecGetArrayRead(in, &x));
  PetscCall(VecGetArrayWrite(out, &y));
  if (s->fine_threes) {
    const PetscInt nb = n / 3;
    PM_OMP(parallel for schedule(static) default(none)
           shared(nb, ia, ja, a, x, y))
    for (PetscInt b = 0; b < nb; b++) {
      const PetscInt i = 3 * b, k0 = ia[i], len = ia[i + 1] - k0;
      const PetscScalar *a0 = a + k0, *a1 = a + ia[i + 1], *a2 = a + ia[i + 2];
      const PetscInt *j = ja + k0;
      PetscScalar y0 = 0, y1 = 0, y2 = 0;
      for (PetscInt k = 0; k < len; k++) {
        const PetscScalar xj = x[j[k]];
        y0 += a0[k] * xj;
        y1 += a1[k] * xj;
        y2 += a2[k] * xj;
      }
      y[i] = y0;
      y[i + 1] = y1;
      y[i + 2] = y2;
    }
  } else {
    PM_OMP(parallel for schedule(static) default(none)
           shared(n, ia, ja, a, x, y))
    for (PetscInt i = 0; i < n; i++) {
      PetscScalar sum = 0;
      for (PetscInt k = ia[i]; k < ia[i + 1]; k++) sum += a[k] * x[ja[k]];
      y[i] = sum;
    }
  }
  PetscCall(VecRestoreArrayWrite(out, &y));
  PetscCall(VecRestoreArrayRead(in, &x));
  PetscCall(MatSeqAIJRestoreArrayRead(B, &a));
  PetscCall(
      MatRestoreRowIJ(B, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PetscFunctionReturn(0);
}

pm_err pm_newton_fine_create(pm_newton *s) {
  const pm_newton_options *o = &s->o;
  const bool amg =
      o->linear == PM_NEWTON_GMRES_GAMG || o->linear == PM_NEWTON_CG_GAMG;
  s->fine_threes = -1;
  if (!o->amg_threaded || !amg || !o->amg_assembled_smoother || s->dist ||
      pm_newton_aug_on(s) || pm_omp_threads() < 2)
    return PM_SUCCESS;
  PetscBool seqaij;
  PM_PETSC_CALL(
      PetscObjectTypeCompare((PetscObject)fine_source(s), MATSEQAIJ, &seqaij));
  if (!seqaij) return PM_SUCCESS;
  const PetscInt n = (PetscInt)s->p.n;
  PM_PETSC_CALL(MatCreateShell(PETSC_COMM_SELF, n, n, n, n, s, &s->Fine));
  PM_PETSC_CALL(
      MatShellSetOperation(s->Fine, MATOP_MULT, (void (*)(void))fine_mult));
  return PM_SUCCESS;
}

PetscErrorCode pm_newton_fine_attach(pm_newton *s, KSP ksp) {
  PC pc;
  PetscInt levels;
  KSP smoother;
  Mat A, P;
  PetscFunctionBeginUser;
  /* (a multigrid solver's: not the fallbacks' LU in its place) */
  if (!s->Fine ||
      (s->o.linear != PM_NEWTON_GMRES_GAMG && s->o.linear != PM_NEWTON_CG_GAMG))
    PetscFunctionReturn(0);
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCMGGetLevels(pc, &levels));
  if (levels < 2) PetscFunctionReturn(0);
  PetscCall(PCMGGetSmoother(pc, levels - 1, &smoother));
  PetscCall(KSPGetOperators(smoother, &A, &P));
  /* A new hierarchy gives its finest smoother the assembled matrix again;
   * the same matrix's values, multiplied on every thread, in its place
   * (the smoother's Jacobi diagonal still comes from P). */
  if (A == s->Fine || A != fine_source(s)) PetscFunctionReturn(0);
  PetscCall(KSPSetOperators(smoother, s->Fine, P));
  PetscCall(PCMGSetResidual(pc, levels - 1, PCMGResidualDefault, s->Fine));
  PetscFunctionReturn(0);
}
