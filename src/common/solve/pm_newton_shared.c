/* pm_newton_shared: a Newton problem shared by the ranks: the numbering of
 * the values each rank holds (owned and ghosts), the ghosted vectors the
 * callbacks read and write, and the residual and norm over all ranks. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <petscsnes.h>

#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_par.h"
#include "pm_petsc.h"

/* The values a callback reads of V: its own array (one process), or the
 * held values of ghosted G, V's owned values with their ghosts' (across
 * ranks).  *loc is what to give back to in_done. */
PetscErrorCode pm_newton_in_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
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

PetscErrorCode pm_newton_in_done(const pm_newton *s, Vec G, Vec *loc,
                                 const double **a) {
  PetscFunctionBeginUser;
  PetscCall(VecRestoreArrayRead(*loc, a));
  if (s->dist) PetscCall(VecGhostRestoreLocalForm(G, loc));
  PetscFunctionReturn(0);
}

/* Where a callback writes V's values: its array, or ghosted G's held
 * values (across ranks). */
PetscErrorCode pm_newton_out_get(const pm_newton *s, Vec V, Vec G, Vec *loc,
                                 double **a) {
  PetscFunctionBeginUser;
  *loc = V;
  if (s->dist) PetscCall(VecGhostGetLocalForm(G, loc));
  PetscCall(VecGetArray(*loc, a));
  PetscFunctionReturn(0);
}

/* Across ranks, with every rank's callback done (ok on all of them):
 * the ghosts' contributions added on their owners, into V. */
PetscErrorCode pm_newton_out_done(const pm_newton *s, Vec V, Vec G, Vec *loc,
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

/* Across ranks: the numbering of the held values over all ranks (owned
 * ones from this rank's offset, then the ghosts') and the ghosted vectors
 * of the callbacks. */
pm_err pm_newton_create_shared(pm_newton *s) {
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

pm_err pm_newton_residual(pm_newton *s, const double *x, double *r) {
  if (!s->dist) return s->p.residual(s->p.ctx, x, r);
  pm_err e = PM_SUCCESS;
  const double *xh;
  double *rh;
  Vec xl, rl;
  PM_CALL(pm_newton_copy_in(s->Work, x, s->p.n));
  PM_PETSC_CALL(pm_newton_in_get(s, s->Work, s->Gx, &xl, &xh));
  PM_PETSC_CALL(pm_newton_out_get(s, s->R, s->Gr, &rl, &rh));
  e = pm_newton_agreed(s, s->p.residual(s->p.ctx, xh, rh));
  PM_PETSC_CALL(pm_newton_out_done(s, s->R, s->Gr, &rl, &rh, e == PM_SUCCESS));
  PM_PETSC_CALL(pm_newton_in_done(s, s->Gx, &xl, &xh));
  if (e == PM_SUCCESS) PM_CALL(pm_newton_copy_out(s->R, r, s->p.n));
  return e;
}

pm_err pm_newton_held_values(pm_newton *s, const double *x, double *held) {
  if (!s->dist) {
    memcpy(held, x, (size_t)s->p.n * sizeof *held);
    return PM_SUCCESS;
  }
  const double *h;
  Vec hl;
  PM_CALL(pm_newton_copy_in(s->Work, x, s->p.n));
  PM_PETSC_CALL(pm_newton_in_get(s, s->Work, s->Gx, &hl, &h));
  memcpy(held, h, (size_t)s->nloc * sizeof *held);
  PM_PETSC_CALL(pm_newton_in_done(s, s->Gx, &hl, &h));
  return PM_SUCCESS;
}

double pm_newton_norm(const pm_newton *s, const double *v) {
  double sum = 0;
  for (long i = 0; i < s->p.n; i++) sum += v[i] * v[i];
  if (s->dist) pm_par_sum(&sum, 1);
  return sqrt(sum);
}
