/* pm_newton_fine: multigrid's finest level multiplied on every thread.
 * PETSc's sparse product runs on one thread; with the finest level
 * smoothed by the assembled matrix (amg_assembled_smoother), its
 * smoother's and residual's products are most of a V-cycle's work (four
 * or five products a cycle against a coarse level of tens of unknowns).
 * They go through a shell (Fine) that multiplies the same assembled
 * matrix, by PETSc's own structure, in an OpenMP loop over the rows.
 *
 * By default they read a single-precision copy of the values, made when
 * the Jacobian writes new ones, in 3 x 3 blocks with one column index a
 * block where the matrix is made of whole points (else row by row): 4.4
 * bytes an entry against 9.3, and independent multiply-adds where a row's
 * sum was a chain of dependent additions; 2.6 times faster on two threads
 * and 2.8 on one (benchmarks/fine-product.c), so the shell serves one
 * thread too.  A preconditioner approximates the tangent already:
 * rounding its values to 6e-8 leaves the hierarchy's work what it was.
 * The vectors and sums stay in double; Newton's and GMRES's operator is
 * the exact tangent, untouched.  solver_options "-pm_fine_single false":
 * the values as they are (docs/validation.md, "The finest level in single
 * precision, and the first step cut sooner"). */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

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

/* Whether, besides, each block's columns come as whole points: runs of
 * three from a multiple of 3 (no component of a point prescribed alone).
 * The matrix is then made of 3 x 3 blocks, one column index each. */
static bool columns_in_threes(PetscInt n, const PetscInt *ia,
                              const PetscInt *ja) {
  for (PetscInt i = 0; i < n; i += 3) {
    const PetscInt len = ia[i + 1] - ia[i];
    const PetscInt *j = ja + ia[i];
    if (len % 3) return false;
    for (PetscInt k = 0; k < len; k += 3)
      if (j[k] % 3 || j[k + 1] != j[k] + 1 || j[k + 2] != j[k] + 2)
        return false;
  }
  return true;
}

/* y = A x over rows in threes (one pass over a block's columns) or one
 * row at a time; T is the type of the values (the matrix's own, or the
 * single-precision copy).  Each row's sum in one thread, in an order
 * fixed by the code (vector lanes over the columns): the same result on
 * any number of threads. */
#define FINE_KERNEL(NAME, T)                                                   \
  static void NAME(PetscInt n, bool threes, const PetscInt *ia,                \
                   const PetscInt *ja, const T *a, const PetscScalar *x,       \
                   PetscScalar *y) {                                           \
    if (threes) {                                                              \
      const PetscInt nb = n / 3;                                               \
      PM_OMP(parallel for schedule(static) default(none)                       \
             shared(nb, ia, ja, a, x, y))                                      \
      for (PetscInt b = 0; b < nb; b++) {                                      \
        const PetscInt i = 3 * b, k0 = ia[i], len = ia[i + 1] - k0;            \
        const T *a0 = a + k0, *a1 = a + ia[i + 1], *a2 = a + ia[i + 2];        \
        const PetscInt *j = ja + k0;                                           \
        PetscScalar y0 = 0, y1 = 0, y2 = 0;                                    \
        PM_OMP(simd reduction(+ : y0, y1, y2))                                 \
        for (PetscInt k = 0; k < len; k++) {                                   \
          const PetscScalar xj = x[j[k]];                                      \
          y0 += (PetscScalar)a0[k] * xj;                                       \
          y1 += (PetscScalar)a1[k] * xj;                                       \
          y2 += (PetscScalar)a2[k] * xj;                                       \
        }                                                                      \
        y[i] = y0;                                                             \
        y[i + 1] = y1;                                                         \
        y[i + 2] = y2;                                                         \
      }                                                                        \
    } else {                                                                   \
      PM_OMP(parallel for schedule(static) default(none)                       \
             shared(n, ia, ja, a, x, y))                                       \
      for (PetscInt i = 0; i < n; i++) {                                       \
        PetscScalar sum = 0;                                                   \
        PM_OMP(simd reduction(+ : sum))                                        \
        for (PetscInt k = ia[i]; k < ia[i + 1]; k++)                           \
          sum += (PetscScalar)a[k] * x[ja[k]];                                 \
        y[i] = sum;                                                            \
      }                                                                        \
    }                                                                          \
  }
FINE_KERNEL(mult_double, PetscScalar)
FINE_KERNEL(mult_single, float)

/* y = A x over 3 x 3 blocks of single precision (fine_a: a block's nine
 * values row by row; fine_ib, fine_jb: each block row's blocks and their
 * block columns). */
static void mult_blocks(const pm_newton *s, PetscInt nb, const PetscScalar *x,
                        PetscScalar *y) {
  const PetscInt *ib = s->fine_ib, *jb = s->fine_jb;
  const float *a = s->fine_a;
  PM_OMP(parallel for schedule(static) default(none)
         shared(nb, ib, jb, a, x, y))
  for (PetscInt b = 0; b < nb; b++) {
    PetscScalar y0 = 0, y1 = 0, y2 = 0;
    PM_OMP(simd reduction(+ : y0, y1, y2))
    for (PetscInt k = ib[b]; k < ib[b + 1]; k++) {
      const float *v = a + 9 * (long)k;
      const PetscScalar *xc = x + 3 * (long)jb[k];
      y0 += (PetscScalar)v[0] * xc[0] + (PetscScalar)v[1] * xc[1] +
            (PetscScalar)v[2] * xc[2];
      y1 += (PetscScalar)v[3] * xc[0] + (PetscScalar)v[4] * xc[1] +
            (PetscScalar)v[5] * xc[2];
      y2 += (PetscScalar)v[6] * xc[0] + (PetscScalar)v[7] * xc[1] +
            (PetscScalar)v[8] * xc[2];
    }
    y[3 * b] = y0;
    y[3 * b + 1] = y1;
    y[3 * b + 2] = y2;
  }
}

/* The copy's storage and the blocks' structure, once a solver (the pattern
 * is fixed over its load steps); false where it cannot be had (the values
 * then as they are). */
static bool fine_storage(pm_newton *s, PetscInt n, const PetscInt *ia,
                         const PetscInt *ja) {
  const long nnz = (long)ia[n];
  if (nnz > s->fine_cap) {
    free(s->fine_a);
    free(s->fine_ib);
    free(s->fine_jb);
    s->fine_ib = s->fine_jb = NULL;
    s->fine_cap = 0;
    s->fine_a = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *s->fine_a);
    if (!s->fine_a) return false;
    s->fine_cap = nnz;
  }
  if (s->fine_blocks && !s->fine_ib) {
    const PetscInt nb = n / 3;
    s->fine_ib = malloc((size_t)(nb + 1) * sizeof *s->fine_ib);
    s->fine_jb = malloc((size_t)(nnz / 9 + 1) * sizeof *s->fine_jb);
    if (!s->fine_ib || !s->fine_jb) {
      free(s->fine_ib);
      free(s->fine_jb);
      s->fine_ib = s->fine_jb = NULL;
      s->fine_blocks = 0;
    } else {
      s->fine_ib[0] = 0;
      for (PetscInt b = 0; b < nb; b++) {
        const PetscInt k0 = ia[3 * b], len = ia[3 * b + 1] - k0;
        s->fine_ib[b + 1] = s->fine_ib[b] + len / 3;
        for (PetscInt t = 0; t < len / 3; t++)
          s->fine_jb[s->fine_ib[b] + t] = ja[k0 + 3 * t] / 3;
      }
    }
  }
  return true;
}

/* The single-precision copy of B's values, made again after the Jacobian
 * has written them (fine_stale); none where a value is beyond 1e30 or not
 * finite (then the matrix's own values serve). */
static PetscErrorCode fine_refresh(pm_newton *s, Mat B, PetscInt n,
                                   const PetscInt *ia, const PetscInt *ja) {
  const PetscScalar *a;
  PetscFunctionBeginUser;
  s->fine_stale = false;
  s->fine_single_ok = false;
  if (s->fine_single < 0) {
    PetscBool single = PETSC_TRUE, set = PETSC_FALSE;
    PetscCall(
        PetscOptionsGetBool(s->opts, NULL, "-pm_fine_single", &single, &set));
    s->fine_single = single == PETSC_TRUE;
  }
  if (!s->fine_single) PetscFunctionReturn(0);
  const bool room = fine_storage(s, n, ia, ja);
  PetscCall(MatSeqAIJGetArrayRead(B, &a));
  int bad = !room;
  float *f = s->fine_a;
  if (room && s->fine_blocks) {
    const PetscInt nb = n / 3, *ib = s->fine_ib;
    PM_OMP(parallel for schedule(static) default(none)
           shared(nb, ib, ia, a, f) reduction(|| : bad))
    for (PetscInt b = 0; b < nb; b++)
      for (PetscInt t = 0; t < ib[b + 1] - ib[b]; t++)
        for (int r = 0; r < 3; r++)
          for (int c = 0; c < 3; c++) {
            const double v = a[ia[3 * b + r] + 3 * t + c];
            bad = bad || !(fabs(v) <= 1e30);
            f[9 * (long)(ib[b] + t) + 3 * r + c] = (float)v;
          }
  } else if (room) {
    const long nnz = (long)ia[n];
    PM_OMP(parallel for schedule(static) default(none)
           shared(nnz, a, f) reduction(|| : bad))
    for (long k = 0; k < nnz; k++) {
      const double v = a[k];
      bad = bad || !(fabs(v) <= 1e30);
      f[k] = (float)v;
    }
  }
  PetscCall(MatSeqAIJRestoreArrayRead(B, &a));
  s->fine_single_ok = !bad;
  PetscFunctionReturn(0);
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
  if (s->fine_threes < 0) {
    s->fine_threes = rows_in_threes(n, ia, ja);
    s->fine_blocks = s->fine_threes && columns_in_threes(n, ia, ja);
  }
  if (s->fine_stale) PetscCall(fine_refresh(s, B, n, ia, ja));
  s->fine_used = true;
  PetscCall(VecGetArrayRead(in, &x));
  PetscCall(VecGetArrayWrite(out, &y));
  if (s->fine_single_ok && s->fine_blocks) {
    mult_blocks(s, n / 3, x, y);
  } else if (s->fine_single_ok) {
    mult_single(n, s->fine_threes, ia, ja, s->fine_a, x, y);
  } else {
    PetscCall(MatSeqAIJGetArrayRead(B, &a));
    mult_double(n, s->fine_threes, ia, ja, a, x, y);
    PetscCall(MatSeqAIJRestoreArrayRead(B, &a));
  }
  PetscCall(VecRestoreArrayWrite(out, &y));
  PetscCall(VecRestoreArrayRead(in, &x));
  PetscCall(
      MatRestoreRowIJ(B, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  PetscFunctionReturn(0);
}

pm_err pm_newton_fine_create(pm_newton *s) {
  const pm_newton_options *o = &s->o;
  const bool amg =
      o->linear == PM_NEWTON_GMRES_GAMG || o->linear == PM_NEWTON_CG_GAMG;
  s->fine_threes = s->fine_blocks = -1;
  s->fine_stale = true;
  s->fine_single = -1; /* (the options are read at the first product) */
  if (!o->amg_threaded || !amg || !o->amg_assembled_smoother || s->dist ||
      pm_newton_aug_on(s))
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

const char *pm_newton_fine_storage(const pm_newton *s) {
  if (!s->Fine || !s->fine_used) return "petsc";
  if (!s->fine_single_ok) return "double";
  return s->fine_blocks > 0 ? "single, 3 x 3 blocks" : "single";
}
