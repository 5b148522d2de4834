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

pm_err mpm_implicit_checkpoint_scalars(mpm_implicit *im, pm_ckpt *ck) {
  long step = im->step;
  PM_CALL(pm_ckpt_double(ck, "implicit.lambda", &im->lambda));
  PM_CALL(pm_ckpt_long(ck, "implicit.step", &step));
  im->step = (int)step;
  PM_CALL(
      pm_ckpt_doubles(ck, "implicit.reaction", 3 * im->m->n_bcs, im->reaction));
  PM_CALL(pm_ckpt_double(ck, "implicit.residual", &im->residual));
  PM_CALL(pm_load_checkpoint(ck, "implicit.load", 0,
                             im->mode == MPM_GRID_KEPT ? &im->ls : NULL,
                             &im->rep));
  if (pm_ckpt_reading(ck) && im->mode == MPM_GRID_RESET) im->built_for = -1;
  return PM_SUCCESS;
}

pm_err mpm_implicit_checkpoint(mpm_implicit *im, const mpm_model *full,
                               pm_ckpt *ck) {
  PM_CALL(mpm_implicit_checkpoint_scalars(im, ck));
  return im->mode == MPM_GRID_KEPT ? checkpoint_states(im, full, ck)
                                   : PM_SUCCESS;
}

/* ---- in pieces ----------------------------------------------------------- */

long mpm_implicit_unknowns(const mpm_implicit *im) {
  return im->mode == MPM_GRID_KEPT ? im->nunk : 0;
}

/* Node i of the solver's grid as a node of the whole grid (nodes per axis
 * nn), and the whole node's indices along the axes. */
static long grid_node(const mpm_grid *g, const long nn[3], long i,
                      long ijk[3]) {
  const long loc[3] = {i % g->nn[0], (i / g->nn[0]) % g->nn[1],
                       i / g->stride[2]};
  for (int a = 0; a < 3; a++) ijk[a] = loc[a] + g->offset[a];
  return ijk[0] + nn[0] * (ijk[1] + nn[1] * ijk[2]);
}

/* The whole grid's dof of own unknown k, and its node's indices. */
static long whole_dof(const mpm_implicit *im, const long nn[3], long k,
                      long ijk[3]) {
  const long d = im->unk_dof[k];
  return 3 * grid_node(&im->g, nn, d / 3, ijk) + d % 3;
}

void mpm_implicit_nodes_box(const mpm_implicit *im, double box[6]) {
  long nn[3], lo[3], hi[3];
  mpm_xc_cells(im->m, nn, lo, hi);
  for (int a = 0; a < 3; a++) box[a] = box[3 + a] = 0;
  for (long k = 0; k < mpm_implicit_unknowns(im); k++) {
    long ijk[3];
    whole_dof(im, nn, k, ijk);
    for (int a = 0; a < 3; a++) {
      if (k == 0 || ijk[a] < box[a]) box[a] = (double)ijk[a];
      if (k == 0 || ijk[a] > box[3 + a]) box[3 + a] = (double)ijk[a];
    }
  }
}

pm_err mpm_implicit_checkpoint_piece(mpm_implicit *im, pm_ckpt *ck,
                                     double box[6]) {
  long count = mpm_implicit_unknowns(im), nn[3], lo[3], hi[3];
  mpm_xc_cells(im->m, nn, lo, hi);
  mpm_implicit_nodes_box(im, box);
  PM_CALL(pm_ckpt_long(ck, "implicit.piece.count", &count));
  if (!count) return PM_SUCCESS;
  long *dofs = NULL;
  pm_err e = PM_ALLOC(dofs, count, "checkpoint piece");
  for (long k = 0; k < count && !e; k++) {
    long ijk[3];
    dofs[k] = whole_dof(im, nn, k, ijk);
  }
  if (!e) e = pm_ckpt_longs(ck, "implicit.piece.dofs", count, dofs);
  if (!e) e = pm_ckpt_doubles(ck, "implicit.piece.u", count, im->ls.xc);
  if (!e) e = pm_ckpt_doubles(ck, "implicit.piece.u_prev", count, im->ls.xprev);
  free(dofs);
  return e;
}

static int pair_order(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

pm_err mpm_implicit_read_piece(mpm_implicit *im, pm_ckpt *ck, bool *seen,
                               long *placed) {
  pm_err ret = PM_SUCCESS;
  long count = 0, *dofs = NULL, *own = NULL;
  double *u = NULL;
  PM_CALL(pm_ckpt_long(ck, "implicit.piece.count", &count));
  PM_CHECK(count >= 0, PM_ERR_IO,
           "%s: implicit.piece.count: expected a count of unknowns, got %ld",
           pm_ckpt_path(ck), count);
  if (!count) return PM_SUCCESS;
  PM_TRY(PM_ALLOC(dofs, count, "checkpoint piece"));
  PM_TRY(PM_ALLOC(u, 2 * count, "checkpoint piece"));
  PM_TRY(PM_ALLOC(own, 2 * im->nunk + 2, "checkpoint piece"));
  PM_TRY(pm_ckpt_longs(ck, "implicit.piece.dofs", count, dofs));
  PM_TRY(pm_ckpt_doubles(ck, "implicit.piece.u", count, u));
  PM_TRY(pm_ckpt_doubles(ck, "implicit.piece.u_prev", count, u + count));
  if (im->mode != MPM_GRID_KEPT) goto done;
  /* This rank's unknowns by their whole dofs (dof, unknown pairs). */
  long nn[3], lo[3], hi[3];
  mpm_xc_cells(im->m, nn, lo, hi);
  for (long k = 0; k < im->nunk; k++) {
    long ijk[3];
    own[2 * k] = whole_dof(im, nn, k, ijk);
    own[2 * k + 1] = k;
  }
  qsort(own, (size_t)im->nunk, 2 * sizeof *own, pair_order);
  for (long j = 0; j < count; j++) {
    const long *at =
        bsearch(&dofs[j], own, (size_t)im->nunk, 2 * sizeof *own, pair_order);
    if (!at) continue;
    PM_ENSURE(!seen[at[1]], PM_ERR_IO,
              "%s: the unknown of dof %ld on the whole grid is in another "
              "piece too",
              pm_ckpt_path(ck), dofs[j]);
    seen[at[1]] = true;
    im->ls.xc[at[1]] = u[j];
    im->ls.xprev[at[1]] = u[count + j];
    (*placed)++;
  }
done:
  free(dofs);
  free(u);
  free(own);
  return ret;
}
