/* mpm_par_nodes: nodal arrays across ranks: the node sums after a
 * transfer on the ghost nodes' exchange (pm_halo), typed reduces and
 * broadcasts, the
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
#include "pm_progress.h"

/* ---- node sums -------------------------------------------------------------
 */

pm_err mpm_par_sum_nodes(const mpm_model *m, mpm_nodes *nd, int mode,
                         bool imp) {
  struct mpm_par *P = par_of(m);
  const double t0 = pm_wtime();
  /* The arrays a transfer of `mode` filled, and their bytes per node. */
  void *data[4];
  int bytes[4];
  int n = 0, values = 0;
  if (mode & MPM_P2G_MASS) {
    data[n] = nd->mass;
    bytes[n++] = sizeof(double);
  }
  if (mode & MPM_P2G_MOM) {
    data[n] = nd->mom;
    bytes[n++] = 3 * sizeof(double);
  }
  if (mode & MPM_P2G_FORCE) {
    data[n] = nd->force;
    bytes[n++] = 3 * sizeof(double);
    if (imp) {
      data[n] = nd->impedance;
      bytes[n++] = 2 * sizeof(double);
    }
  }
  for (int k = 0; k < n; k++) values += bytes[k] / (int)sizeof(double);
  /* Ghosts' contributions added on their owners, then the sums back. */
  pm_halo_reduce(P->ghosts, n, data, data, bytes, PM_HALO_SUM_DOUBLE);
  pm_halo_bcast(P->ghosts, n, data, data, bytes);
  /* Each ghost node's values go to its owner and come back. */
  const double sent =
      2.0 * (double)(m->grid.n_nodes - P->n_owned) * values * sizeof(double);
  P->counts.halo_bytes += sent;
  pm_par_count_sent(sent);
  P->counts.halo_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

/* One pass of a nodal array's ghost values (`bytes` per node) between the
 * ranks, counted. */
static void count_ghosts(const mpm_model *m, int bytes) {
  const double sent = (double)(m->grid.n_nodes - par_of(m)->n_owned) * bytes;
  par_of(m)->counts.halo_bytes += sent;
  pm_par_count_sent(sent);
}

/* The bytes of a node's unit. */
static int unit_bytes(mpm_xc_unit u) {
  if (u == MPM_XC_DOUBLE) return sizeof(double);
  if (u == MPM_XC_BYTE) return 1;
  return 3 * (u == MPM_XC_LONG3 ? sizeof(long) : sizeof(double));
}

pm_err mpm_par_nodes_reduce(const mpm_model *m, void *a, mpm_xc_unit unit,
                            mpm_xc_op op) {
  const double t0 = pm_wtime();
  const int bytes = unit_bytes(unit);
  PM_CHECK(unit != MPM_XC_LONG3, PM_ERR_INTERNAL,
           "a node sum of dof numbers across ranks");
  const pm_halo_op how = op == MPM_XC_SUM      ? PM_HALO_SUM_DOUBLE
                         : unit == MPM_XC_BYTE ? PM_HALO_MAX_BYTE
                                               : PM_HALO_MAX_DOUBLE;
  PM_CHECK(unit != MPM_XC_BYTE || op == MPM_XC_MAX, PM_ERR_INTERNAL,
           "a node sum of flags across ranks");
  count_ghosts(m, bytes);
  pm_halo_reduce(par_of(m)->ghosts, 1, &a, &a, &bytes, how);
  count_ghosts(m, bytes);
  pm_halo_bcast(par_of(m)->ghosts, 1, &a, &a, &bytes);
  par_of(m)->counts.halo_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

pm_err mpm_par_nodes_bcast(const mpm_model *m, void *a, mpm_xc_unit unit) {
  const int bytes = unit_bytes(unit);
  count_ghosts(m, bytes);
  pm_halo_bcast(par_of(m)->ghosts, 1, &a, &a, &bytes);
  return PM_SUCCESS;
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
