/* mpm_par_nodes: nodal arrays across ranks: the node sums after a
 * transfer on a PETSc star forest, typed reduces and broadcasts, the
 * implicit solver's unknowns numbered over the ranks, a step's figures. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "mpm_transfer.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_petsc.h"
#include "pm_progress.h"

/* ---- node sums -------------------------------------------------------------
 */

pm_err mpm_par_sum_nodes(const mpm_model *m, mpm_nodes *nd, int mode,
                         bool imp) {
  struct mpm_par *P = par_of(m);
  const double t0 = pm_wtime();
  PetscSF sf = P->ghosts;
  /* The arrays a transfer of `mode` filled, and their values per node. */
  double *data[4];
  MPI_Datatype unit[4];
  int n = 0, values = 0;
  if (mode & MPM_P2G_MASS) {
    data[n] = nd->mass;
    unit[n++] = MPI_DOUBLE;
    values += 1;
  }
  if (mode & MPM_P2G_MOM) {
    data[n] = nd->mom;
    unit[n++] = P->three;
    values += 3;
  }
  if (mode & MPM_P2G_FORCE) {
    data[n] = nd->force;
    unit[n++] = P->three;
    values += 3;
    if (imp) {
      data[n] = nd->impedance;
      unit[n++] = P->two;
      values += 2;
    }
  }
  /* Ghosts' contributions added on their owners, then the sums back. */
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFReduceBegin(sf, unit[k], data[k], data[k], MPI_SUM));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFReduceEnd(sf, unit[k], data[k], data[k], MPI_SUM));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(
        PetscSFBcastBegin(sf, unit[k], data[k], data[k], MPI_REPLACE));
  for (int k = 0; k < n; k++)
    PM_PETSC_CALL(PetscSFBcastEnd(sf, unit[k], data[k], data[k], MPI_REPLACE));
  /* Each ghost node's values go to its owner and come back. */
  const double bytes =
      2.0 * (double)(m->grid.n_nodes - P->n_owned) * values * sizeof(double);
  P->counts.halo_bytes += bytes;
  pm_par_count_sent(bytes);
  P->counts.halo_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

/* One pass of a nodal array's ghost values (`unit` per node) between the
 * ranks, counted. */
static void count_ghosts(const mpm_model *m, MPI_Datatype unit) {
  int size = 0;
  MPI_Type_size(unit, &size);
  const double bytes = (double)(m->grid.n_nodes - par_of(m)->n_owned) * size;
  par_of(m)->counts.halo_bytes += bytes;
  pm_par_count_sent(bytes);
}

static pm_err bcast_nodes(const mpm_model *m, void *a, MPI_Datatype unit) {
  PetscSF sf = par_of(m)->ghosts;
  count_ghosts(m, unit);
  PM_PETSC_CALL(PetscSFBcastBegin(sf, unit, a, a, MPI_REPLACE));
  PM_PETSC_CALL(PetscSFBcastEnd(sf, unit, a, a, MPI_REPLACE));
  return PM_SUCCESS;
}

static pm_err reduce_nodes(const mpm_model *m, void *a, MPI_Datatype unit,
                           MPI_Op op) {
  PetscSF sf = par_of(m)->ghosts;
  const double t0 = pm_wtime();
  count_ghosts(m, unit);
  PM_PETSC_CALL(PetscSFReduceBegin(sf, unit, a, a, op));
  PM_PETSC_CALL(PetscSFReduceEnd(sf, unit, a, a, op));
  pm_err e = bcast_nodes(m, a, unit);
  par_of(m)->counts.halo_seconds += pm_wtime() - t0;
  return e;
}

/* The MPI type of a node's unit; *made when it was made here (to free). */
static MPI_Datatype unit_type(mpm_xc_unit u, bool *made) {
  *made = false;
  if (u == MPM_XC_DOUBLE) return MPI_DOUBLE;
  if (u == MPM_XC_BYTE) return MPI_UNSIGNED_CHAR;
  MPI_Datatype t;
  MPI_Type_contiguous(3, u == MPM_XC_LONG3 ? MPI_LONG : MPI_DOUBLE, &t);
  MPI_Type_commit(&t);
  *made = true;
  return t;
}

pm_err mpm_par_nodes_reduce(const mpm_model *m, void *a, mpm_xc_unit unit,
                            mpm_xc_op op) {
  bool made;
  MPI_Datatype t = unit_type(unit, &made);
  pm_err e = reduce_nodes(m, a, t, op == MPM_XC_MAX ? MPI_MAX : MPI_SUM);
  if (made) MPI_Type_free(&t);
  return e;
}

pm_err mpm_par_nodes_bcast(const mpm_model *m, void *a, mpm_xc_unit unit) {
  bool made;
  MPI_Datatype t = unit_type(unit, &made);
  pm_err e = bcast_nodes(m, a, t);
  if (made) MPI_Type_free(&t);
  return e;
}

const unsigned char *mpm_par_owned(const mpm_model *m) {
  return par_of(m)->owned;
}

pm_err mpm_par_number_unknowns(const mpm_model *m, long nunk, long *dof,
                               long *gnum, long **ghost, long *nghost) {
  const long nn = m->grid.n_nodes;
  const unsigned char *own = par_of(m)->owned;
  const long first = pm_par_offset(nunk);
  for (long d = 0; d < 3 * nn; d++) gnum[d] = dof[d] >= 0 ? first + dof[d] : -1;
  PM_CALL(mpm_par_nodes_bcast(m, gnum, MPM_XC_LONG3));
  long count = 0;
  for (long k = 0; k < nn; k++)
    for (int c = 0; !own[k] && c < 3; c++) count += gnum[3 * k + c] >= 0;
  PM_CALL(PM_REALLOC(*ghost, count + 1, "ghost unknowns"));
  *nghost = 0;
  for (long k = 0; k < nn; k++)
    for (int c = 0; !own[k] && c < 3; c++) {
      const long d = 3 * k + c;
      if (gnum[d] < 0) continue;
      /* Active nodes and prescribed dofs are the same on every rank that
       * holds the node. */
      PM_CHECK(dof[d] == -1, PM_ERR_INTERNAL,
               "implicit MPM across ranks: dof %ld of a ghost node is %ld "
               "here and an unknown on its owner",
               d, dof[d]);
      (*ghost)[*nghost] = gnum[d];
      dof[d] = nunk + (*nghost)++;
    }
  return PM_SUCCESS;
}

void mpm_par_step_end(const mpm_model *m, mpm_work *w) {
  (void)m;
  double most[3] = {w->max_div, -w->min_jacobian, (double)w->iter_max};
  pm_par_max(most, 3);
  w->max_div = most[0];
  w->min_jacobian = -most[1];
  w->iter_max = (int)most[2];
  pm_par_sum_long(&w->iter_capped, 1);
}
