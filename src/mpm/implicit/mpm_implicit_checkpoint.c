/* mpm_implicit_checkpoint: load stepping's states as nodal displacements
 * of the whole grid: gathered across ranks, written and read back. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_implicit_impl.h"
#include "mpm_kind.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* Node i of the solver's grid g as a node of the whole grid fg. */
static long whole_node(const mpm_grid *g, const mpm_grid *fg, long i) {
  const long ijk[3] = {i % g->nn[0], (i / g->nn[0]) % g->nn[1],
                       i / g->stride[2]};
  long q = 0;
  for (int a = 0; a < 3; a++) q += (ijk[a] + g->offset[a]) * fg->stride[a];
  return q;
}

/* The owned unknowns x (nunk) as nodal displacements u of the solver's
 * grid (0 at the other dofs), and back. */
static void unknowns_to_nodes(const mpm_implicit *im, const double *x,
                              double *u) {
  memset(u, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nunk; k++) u[im->unk_dof[k]] = x[k];
}

pm_err mpm_implicit_gather(mpm_implicit *im, const mpm_model *full) {
  if (im->mode != MPM_GRID_KEPT) return PM_SUCCESS;
  pm_err e = PM_SUCCESS;
  if (full && !im->whole)
    e = PM_ALLOC(im->whole, 6 * full->grid.n_nodes, "nodal gather");
  PM_CALL(mpm_xc_agree(im->m, e));
  const long nf = full ? 3 * full->grid.n_nodes : 0;
  for (int s = 0; s < 2; s++) {
    unknowns_to_nodes(im, s ? im->ls.xprev : im->ls.xc, im->du);
    PM_CALL(mpm_xc_gather_nodes(im->m, full, im->du,
                                full ? im->whole + s * nf : NULL));
  }
  return PM_SUCCESS;
}

/* With the grid kept: load stepping's two states as nodal displacements of
 * the whole grid (full's), written from the solver's unknowns (or, across
 * ranks, from what mpm_implicit_gather gathered) or read into them. */
static pm_err checkpoint_states(mpm_implicit *im, const mpm_model *full,
                                pm_ckpt *ck) {
  const mpm_grid *fg = &full->grid;
  const long nf = 3 * fg->n_nodes;
  const bool reading = pm_ckpt_reading(ck);
  if (!im->whole) PM_CALL(PM_ALLOC(im->whole, 2 * nf, "nodal states"));
  for (int s = 0; s < 2; s++) {
    double *x = s ? im->ls.xprev : im->ls.xc, *u = im->whole + s * nf;
    if (!reading && !im->ranks) unknowns_to_nodes(im, x, u);
    PM_CALL(pm_ckpt_doubles(ck, s ? "implicit.load.u_prev" : "implicit.load.u",
                            nf, u));
    if (!reading) continue;
    for (long k = 0; k < im->nunk; k++) {
      const long d = im->unk_dof[k];
      x[k] = u[3 * whole_node(&im->g, fg, d / 3) + d % 3];
    }
  }
  return PM_SUCCESS;
}

pm_err mpm_implicit_checkpoint(mpm_implicit *im, const mpm_model *full,
                               pm_ckpt *ck) {
  long step = im->step;
  PM_CALL(pm_ckpt_double(ck, "implicit.lambda", &im->lambda));
  PM_CALL(pm_ckpt_long(ck, "implicit.step", &step));
  im->step = (int)step;
  PM_CALL(
      pm_ckpt_doubles(ck, "implicit.reaction", 3 * im->m->n_bcs, im->reaction));
  PM_CALL(pm_ckpt_double(ck, "implicit.residual", &im->residual));
  if (im->mode == MPM_GRID_KEPT) {
    PM_CALL(pm_load_checkpoint(ck, "implicit.load", 0, &im->ls, &im->rep));
    PM_CALL(checkpoint_states(im, full, ck));
  } else {
    PM_CALL(pm_load_checkpoint(ck, "implicit.load", 0, NULL, &im->rep));
  }
  if (pm_ckpt_reading(ck) && im->mode == MPM_GRID_RESET) im->built_for = -1;
  return PM_SUCCESS;
}
