/* mpm_implicit_dofs: the implicit MPM's structure: particles in coloured
 * buckets, prescribed and unknown dofs, the Jacobian's pattern, the
 * near-null space and the Newton solver over them. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_grip.h"
#include "mpm_implicit_impl.h"
#include "mpm_kind.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* ---- structure: buckets, dofs, pattern ---------------------------------- */

/* The first node of particle p's stencil (its cell's for linear shapes). */
static long stencil_base(const mpm_grid *g, const double x[3], long ijk[3]) {
  long base = 0;
  for (int c = 0; c < 3; c++) {
    ijk[c] = 0;
    if (c >= g->dim) continue;
    double w[3], dw[3];
    mpm_shape_1d(g->shape, (x[c] - g->origin[c]) * g->inv_h, g->inv_h, &ijk[c],
                 w, dw);
    ijk[c] -= g->offset[c]; /* in the rank's block (0 on one process) */
    base += ijk[c] * g->stride[c];
  }
  return base;
}

/* Particles sorted into buckets by their stencil's first node, and the
 * non-empty buckets listed by colour (sum_c (ijk_c mod w) w^c). */
void mpm_implicit_make_buckets(mpm_implicit *im) {
  const mpm_grid *g = &im->g;
  const long nn = g->n_nodes;
  long *cnt = im->bucket; /* nn + 1 */
  memset(cnt, 0, sizeof(long) * (size_t)(nn + 1));
  for (long p = 0; p < im->n; p++) {
    long ijk[3];
    cnt[stencil_base(g, im->xb + 3 * p, ijk) + 1]++;
  }
  for (long k = 0; k < nn; k++) cnt[k + 1] += cnt[k];
  /* fill: order by bucket (cnt[k] moves to the bucket's end, then back) */
  for (long p = 0; p < im->n; p++) {
    long ijk[3];
    long b = stencil_base(g, im->xb + 3 * p, ijk);
    im->order[cnt[b]++] = p;
  }
  for (long k = nn; k > 0; k--) cnt[k] = cnt[k - 1];
  cnt[0] = 0;
  /* colours */
  long ccount[MPM_STENCIL_MAX + 1] = {0};
  for (long k = 0; k < nn; k++) {
    if (cnt[k + 1] == cnt[k]) continue;
    long i = k % g->nn[0], j = (k / g->nn[0]) % g->nn[1], l = k / g->stride[2];
    int col = (int)(i % im->w) +
              im->w * ((int)(j % im->w) + im->w * (int)(l % im->w));
    ccount[col + 1]++;
  }
  im->ncol = im->sn;
  for (int c = 0; c < im->ncol; c++) ccount[c + 1] += ccount[c];
  memcpy(im->cptr, ccount, sizeof(long) * (size_t)(im->ncol + 1));
  for (long k = 0; k < nn; k++) {
    if (cnt[k + 1] == cnt[k]) continue;
    long i = k % g->nn[0], j = (k / g->nn[0]) % g->nn[1], l = k / g->stride[2];
    int col = (int)(i % im->w) +
              im->w * ((int)(j % im->w) + im->w * (int)(l % im->w));
    im->cbuck[ccount[col]++] = k;
  }
}

/* The full-load value of condition b's component c at x (on a face: on
 * its plane). */
static double bc_value(const mpm_implicit *im, int b, int c,
                       const double x[3]) {
  const mpm_bc *bc = &im->m->bcs[b];
  double y[3] = {x[0], x[1], x[2]};
  if (!bc->grip) y[bc->axis] = bc->plane;
  double T = im->m->opt.t_load;
  return mpm_bc_factor(bc, T) * pm_expr_eval(bc->disp[c], y[0], y[1], y[2], T);
}

/* Prescribe component c of node k by condition b: u = v at local load 1
 * plus t times the grid dof anchor (-1: none); a later condition
 * overrides an earlier one. */
static pm_err prescribe(mpm_implicit *im, long node, int c, int b, double v,
                        long anchor, double t) {
  long d = 3 * node + c, k;
  if (im->dof[d] <= -2) {
    k = -2 - im->dof[d];
  } else {
    if (im->npre == im->pre_cap) {
      long cap = im->pre_cap ? 2 * im->pre_cap : 1024;
      PM_CALL(PM_REALLOC(im->pre_dof, cap, "prescribed dofs"));
      PM_CALL(PM_REALLOC(im->pre_val, cap, "prescribed values"));
      PM_CALL(PM_REALLOC(im->pre_bc, cap, "prescribed dofs"));
      PM_CALL(PM_REALLOC(im->pre_anchor, cap, "prescribed dofs"));
      PM_CALL(PM_REALLOC(im->pre_t, cap, "prescribed dofs"));
      im->pre_cap = cap;
    }
    k = im->npre++;
    im->dof[d] = -2 - k;
  }
  im->pre_dof[k] = d;
  im->pre_val[k] = v;
  im->pre_bc[k] = b;
  im->pre_anchor[k] = anchor;
  im->pre_t[k] = anchor >= 0 ? t : 0.0;
  return PM_SUCCESS;
}

/* Condition b on the kept grid (the reference, where its face is a fixed
 * plane).  Quadratic B-splines reach a node beyond the face: setting it
 * to the face's value (as a linear grid may) bends every field that
 * crosses the face (F2 at 0.01 m stalls, 3e-2 off at 0.02 m).  Instead,
 * as the explicit MPM's conditions do (mpm_conditions.c), a node at or
 * beyond the face follows one inside:
 *  - a prescribed component (mirror false): u = g + (d / d_an)(u_an - g),
 *    the line through the anchor's value and the face's g, d the node's
 *    outward distance from the face, the anchor the first node at least
 *    h/2 inside (d_an <= -h/2); at a face on a node plane the odd
 *    reflection u = 2 g - u_an, and u = g at the face's nodes;
 *  - with mirror, a component the condition leaves free while it holds
 *    the normal one (a roller, a plane of symmetry): the first inside
 *    node's value beyond the face (the even reflection).
 * A linear field is then reproduced through the face, and the face's
 * value is g.  An anchor no particle reaches leaves the value g. */
static pm_err extend_kept(mpm_implicit *im, int b, double scale, bool mirror) {
  const mpm_bc *bc = &im->m->bcs[b];
  const mpm_grid *g = &im->g;
  const int a = bc->axis;
  const double h = g->h, eps = 1e-9 * h, out = bc->outward;
  /* the face as a local node index, the anchors' indices */
  const double sf = (bc->plane - g->origin[a]) / h - (double)g->offset[a];
  const long i_an =
      out > 0 ? (long)floor(sf - 0.5 + 1e-9) : (long)ceil(sf + 0.5 - 1e-9);
  const long i_in =
      out > 0 ? (long)ceil(sf - 1e-9) - 1 : (long)floor(sf + 1e-9) + 1;
  const long i_from = mirror ? i_in : i_an;
  for (long k = 0; k < g->n_nodes; k++) {
    if (!im->active[k]) continue;
    const long i = (k / g->stride[a]) % g->nn[a];
    if ((double)(i - i_from) * out <= 0) continue;
    const double d = ((double)i - sf) * h * out;
    if (mirror && d <= eps) continue;
    double x[3];
    mpm_grid_node_position(g, k, x);
    const long kan = k + (i_from - i) * g->stride[a];
    const bool has_an = i_from >= 0 && i_from < g->nn[a] && im->active[kan];
    PM_CHECK(has_an || !im->ranks || (i_from >= 0 && i_from < g->nn[a]),
             PM_ERR_INTERNAL,
             "condition %d: the anchor of node %ld lies outside this rank's "
             "grid",
             b, k);
    for (int c = 0; c < im->dim; c++) {
      const bool fixed = bc->disp_mask >> c & 1u;
      if (fixed == mirror) continue;
      if (mirror) {
        if (im->dof[3 * k + c] == -1 && has_an)
          PM_CALL(prescribe(im, k, c, b, 0.0, 3 * kan + c, 1.0));
        continue;
      }
      const double v = scale * bc_value(im, b, c, x);
      if (!has_an || fabs(d) <= eps) {
        PM_CALL(prescribe(im, k, c, b, v, -1, 0.0));
        continue;
      }
      const double d_an = ((double)i_an - sf) * h * out, t = d / d_an;
      PM_CALL(prescribe(im, k, c, b, (1 - t) * v, 3 * kan + c, t));
    }
  }
  return PM_SUCCESS;
}

/* A motion on a named surface (condition b) on the kept grid: the nodes
 * its particles hold wholly in the explicit MPM's rule (mpm_grip.c), those
 * where they weigh at least MPM_GRIP_SHARE of the mass of the particles
 * that reach the node, take its value there.  On a surface along a node
 * plane, with linear shapes, these are the plane's nodes: a face's. */
static pm_err hold_surface(mpm_implicit *im, int b, double scale) {
  const mpm_model *m = im->m;
  const mpm_bc *bc = &m->bcs[b];
  const mpm_grid *g = &im->g;
  double *mass = im->grip_mass, *held = im->grip_mass + g->n_nodes;
  memset(mass, 0, 2 * sizeof(double) * (size_t)g->n_nodes);
  for (int pass = 0; pass < 2; pass++) {
    const long n = pass ? bc->n_held : im->n;
    for (long q = 0; q < n; q++) {
      const long p = pass ? bc->held[q] : q;
      mpm_stencil st;
      mpm_stencil_at(g, im->xb + 3 * p, MPM_STENCIL_W, &st);
      for (int k = 0; k < st.n; k++)
        (pass ? held : mass)[st.node[k]] += st.w[k] * m->mass[p];
    }
  }
  for (long k = 0; k < g->n_nodes; k++) {
    if (!(held[k] > 0) || held[k] < MPM_GRIP_SHARE * mass[k]) continue;
    double x[3];
    mpm_grid_node_position(g, k, x);
    for (int c = 0; c < im->dim; c++)
      if (bc->disp_mask >> c & 1u)
        PM_CALL(prescribe(im, k, c, b, scale * bc_value(im, b, c, x), -1, 0));
  }
  return PM_SUCCESS;
}

/* Every prescribed dof that follows another prescribed dof follows, in
 * the end, an unknown: substitute the anchors' own rules (a corner's
 * node follows across two faces). */
static pm_err resolve_anchors(mpm_implicit *im) {
  for (long k = 0; k < im->npre; k++) {
    int hops = 0;
    while (im->pre_anchor[k] >= 0 && im->dof[im->pre_anchor[k]] <= -2) {
      const long j = -2 - im->dof[im->pre_anchor[k]];
      PM_CHECK(j != k && ++hops <= 8, PM_ERR_INTERNAL,
               "the conditions' extension at grid dof %ld is circular",
               im->pre_dof[k]);
      im->pre_val[k] += im->pre_t[k] * im->pre_val[j];
      im->pre_t[k] *= im->pre_t[j];
      im->pre_anchor[k] = im->pre_anchor[j];
    }
  }
  return PM_SUCCESS;
}

/* Prescribed dofs of the conditions for the step from lam0 to lam1. */
static pm_err make_prescribed(mpm_implicit *im) {
  const mpm_model *m = im->m;
  const mpm_grid *g = &im->g;
  const double scale = im->lam1 - im->lam0;
  im->npre = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->disp_mask) continue;
    if (im->mode == MPM_GRID_KEPT && bc->grip) {
      PM_CALL(hold_surface(im, b, scale));
    } else if (im->mode == MPM_GRID_KEPT) {
      PM_CALL(extend_kept(im, b, scale, false));
    } else {
      for (long q = im->face_ptr[b]; q < im->face_ptr[b + 1]; q++) {
        long p = im->face[q];
        mpm_stencil st;
        mpm_stencil_at(g, im->xb + 3 * p, MPM_STENCIL_W, &st);
        for (int k = 0; k < st.n; k++)
          for (int c = 0; c < im->dim; c++)
            if (bc->disp_mask & (1u << c))
              PM_CALL(prescribe(im, st.node[k], c, b,
                                scale * bc_value(im, b, c, m->x0 + 3 * p), -1,
                                0.0));
      }
    }
  }
  /* the components a wall leaves free, mirrored beyond it */
  if (im->mode == MPM_GRID_KEPT)
    for (int b = 0; b < m->n_bcs; b++)
      if (!m->bcs[b].grip && m->bcs[b].disp_mask >> m->bcs[b].axis & 1u)
        PM_CALL(extend_kept(im, b, scale, true));
  return resolve_anchors(im);
}

/* Active nodes, prescribed and unknown dofs, and the Jacobian's pattern:
 * every row of a node lists the unknowns of the nodes within a stencil's
 * reach in neighbour order, each neighbour's components in order.  Across
 * ranks a node is active where any rank's particles reach it, a rank
 * numbers its own nodes' unknowns, and the rows of ghost nodes hold what
 * its particles add to them. */
pm_err mpm_implicit_make_dofs(mpm_implicit *im) {
  const mpm_grid *g = &im->g;
  const long nn = g->n_nodes;
  memset(im->active, 0, (size_t)nn);
  for (long p = 0; p < im->n; p++) {
    mpm_stencil st;
    mpm_stencil_at(g, im->xb + 3 * p, MPM_STENCIL_W, &st);
    for (int k = 0; k < st.n; k++) im->active[st.node[k]] = 1;
  }
  const unsigned char *own = im->ranks ? mpm_xc_owned(im->m) : NULL;
  if (im->ranks)
    PM_CALL(mpm_xc_nodes_reduce(im->m, im->active, MPM_XC_BYTE, MPM_XC_MAX));
  for (long d = 0; d < 3 * nn; d++) im->dof[d] = -1;
  PM_CALL(make_prescribed(im));
  im->nunk = 0;
  im->active_all = 0;
  for (long k = 0; k < nn; k++) {
    if (!im->active[k] || (own && !own[k])) continue;
    im->active_all++;
    for (int c = 0; c < im->dim; c++)
      if (im->dof[3 * k + c] == -1) im->dof[3 * k + c] = im->nunk++;
  }
  im->nheld = im->nunk;
  /* Across ranks: the global numbers of the unknowns, the owners' numbers
   * at the ghost nodes, and the ghost nodes' unknowns after the owned. */
  if (im->ranks) {
    PM_CALL(mpm_xc_number_unknowns(im->m, im->nunk, im->dof, im->gnum,
                                   &im->ghost, &im->nghost));
    im->nheld = im->nunk + im->nghost;
  }
  /* an anchor no unknown was numbered for holds u = 0 */
  for (long k = 0; k < im->npre; k++)
    if (im->pre_anchor[k] >= 0 && im->dof[im->pre_anchor[k]] < 0)
      im->pre_anchor[k] = -1;
  long counts[2] = {im->nunk, im->active_all};
  mpm_xc_sum_long(im->m, counts, 2);
  im->nunk_all = counts[0];
  im->active_all = counts[1];
  PM_CHECK(im->nunk_all > 0, PM_ERR_SCENE,
           "%s: every grid displacement is prescribed: nothing to solve",
           im->s->path);
  const long nh = im->nheld;
  PM_CALL(PM_REALLOC(im->unk_dof, nh + 1, "unknowns"));
  PM_CALL(PM_REALLOC(im->x_unk, im->nunk + 1, "unknowns"));
  if (im->ranks) PM_CALL(PM_REALLOC(im->x_held, nh + 1, "held unknowns"));
  PM_CALL(PM_REALLOC(im->diag, nh + 1, "tangent diagonal"));
  PM_CALL(PM_REALLOC(im->pat_ptr, nh + 1, "Jacobian pattern"));
  PM_CALL(PM_REALLOC(im->pc_ptr, nh + 1, "diagonal pattern"));
  PM_CALL(PM_REALLOC(im->pc_idx, nh + 1, "diagonal pattern"));
  memset(im->x_unk, 0, sizeof(double) * (size_t)im->nunk);
  for (long d = 0; d < 3 * nn; d++)
    if (im->dof[d] >= 0) im->unk_dof[im->dof[d]] = d;
  for (long k = 0; k <= nh; k++) im->pc_ptr[k] = k;
  for (long k = 0; k < nh; k++) im->pc_idx[k] = k;
  /* neighbour offsets and the row lengths */
  const int span = im->w - 1;
  long total = 0;
  im->pat_ptr[0] = 0;
  for (long k = 0; k < nn; k++) {
    int *off = im->nb_off + k * im->nnb;
    int cnt = 0, own = 0;
    for (int c = 0; c < 3; c++) own += im->dof[3 * k + c] >= 0;
    long ijk[3] = {k % g->nn[0], (k / g->nn[0]) % g->nn[1], k / g->stride[2]};
    for (int s = 0; s < im->nnb; s++) {
      off[s] = -1;
      if (!own) continue;
      int d[3] = {0, 0, 0};
      for (int c = 0, q = s; c < im->dim; c++, q /= im->nb)
        d[c] = q % im->nb - span;
      long nb = 0;
      bool in = true;
      for (int c = 0; c < 3; c++) {
        if (c >= im->dim) {
          if (d[c] != 0) in = false;
          continue;
        }
        long i = ijk[c] + d[c];
        if (i < 0 || i >= g->nn[c]) in = false;
        nb += i * g->stride[c];
      }
      if (!in) continue;
      int r = 0;
      for (int c = 0; c < 3; c++) r += im->dof[3 * nb + c] >= 0;
      if (!r) continue;
      off[s] = cnt;
      cnt += r;
    }
    for (int c = 0; c < 3; c++) {
      long row = im->dof[3 * k + c];
      if (row < 0) continue;
      total += cnt;
      im->pat_ptr[row + 1] = cnt; /* lengths first */
    }
  }
  for (long r = 0; r < nh; r++) im->pat_ptr[r + 1] += im->pat_ptr[r];
  im->entries_all = total;
  mpm_xc_sum_long(im->m, &im->entries_all, 1);
  if (total > im->pat_cap) {
    PM_CALL(PM_REALLOC(im->pat_idx, total, "Jacobian pattern"));
    im->pat_cap = total;
  }
  for (long k = 0; k < nn; k++) {
    const int *off = im->nb_off + k * im->nnb;
    long ijk[3] = {k % g->nn[0], (k / g->nn[0]) % g->nn[1], k / g->stride[2]};
    for (int c = 0; c < 3; c++) {
      long row = im->dof[3 * k + c];
      if (row < 0) continue;
      long pos = im->pat_ptr[row];
      for (int s = 0; s < im->nnb; s++) {
        if (off[s] < 0) continue;
        long nb = 0;
        for (int e = 0; e < im->dim; e++) {
          int d = (e == 0   ? s % im->nb
                   : e == 1 ? (s / im->nb) % im->nb
                            : s / (im->nb * im->nb)) -
                  span;
          nb += (ijk[e] + d) * g->stride[e];
        }
        for (int e = 0; e < 3; e++)
          if (im->dof[3 * nb + e] >= 0)
            im->pat_idx[pos++] = im->dof[3 * nb + e];
      }
    }
  }
  return PM_SUCCESS;
}

/* Rigid motions over the unknowns, at the nodes' base positions (the
 * grid's for reset; the reference for kept), for algebraic multigrid. */
static pm_err make_near_null(mpm_implicit *im, int *count) {
  const int nr = im->dim == 3 ? 6 : 3;
  PM_CALL(PM_REALLOC(im->near_null, (long)nr * im->nunk, "rigid motions"));
  double *z = im->near_null;
  for (long k = 0; k < im->nunk; k++) {
    long d = im->unk_dof[k], node = d / 3;
    int c = (int)(d % 3);
    double x[3];
    mpm_grid_node_position(&im->g, node, x);
    for (int r = 0; r < nr; r++) z[(long)r * im->nunk + k] = 0;
    z[(long)c * im->nunk + k] = 1; /* translations */
    if (im->dim == 2) {
      /* rotation about z: (-y, x) */
      z[2L * im->nunk + k] = c == 0 ? -x[1] : x[0];
    } else {
      /* rotations about x, y, z: e_r x x */
      const double rx[3][3] = {
          {0, -x[2], x[1]}, {x[2], 0, -x[0]}, {-x[1], x[0], 0}};
      for (int r = 0; r < 3; r++) z[(long)(3 + r) * im->nunk + k] = rx[r][c];
    }
  }
  *count = nr;
  return PM_SUCCESS;
}

/* The solver for the current structure. */
pm_err mpm_implicit_make_solver(mpm_implicit *im) {
  pm_newton_destroy(&im->solver);
  int nnull = 0;
  const bool amg = im->opt.linear == PM_NEWTON_GMRES_GAMG ||
                   im->opt.linear == PM_NEWTON_CG_GAMG;
  if (amg) PM_CALL(make_near_null(im, &nnull));
  pm_newton_problem pb = {
      .n = im->nunk,
      .ctx = im,
      .residual = mpm_implicit_cb_residual,
      .jacobian_apply = mpm_implicit_cb_apply,
      .jacobian_prepare = mpm_implicit_cb_prepare,
      .jacobian_values = im->matrix_free ? NULL : mpm_implicit_cb_values,
      .pat_ptr = im->pat_ptr,
      .pat_idx = im->pat_idx,
      .precond_apply = im->matrix_free ? mpm_implicit_cb_precond : NULL,
      .pc_pat_ptr = im->matrix_free ? im->pc_ptr : NULL,
      .pc_pat_idx = im->matrix_free ? im->pc_idx : NULL,
      .near_null_count = nnull,
      .near_null = amg ? im->near_null : NULL,
      .shared = im->ranks,
      .n_ghost = im->nghost,
      .ghost = im->ghost,
      .set_load = mpm_implicit_cb_set_load,
  };
  pb.on_step = mpm_implicit_on_step;
  return pm_newton_create(&pb, &im->opt, &im->solver);
}

/* Build buckets, dofs and the solver for the base as it is. */
pm_err mpm_implicit_rebuild(mpm_implicit *im) {
  mpm_implicit_make_buckets(im);
  PM_CALL(mpm_implicit_make_dofs(im));
  return mpm_implicit_make_solver(im);
}
