/* mpm_grid: the MPM background grid: its geometry (fixed after setup), the
 * nodal arrays a step fills, and a particle's stencil expanded into flat
 * lists of nodes, weights and weight gradients, which every transfer
 * walks. */
#ifndef MPM_GRID_H
#define MPM_GRID_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "mpm_shape.h"
#include "pm_error.h"

/* Geometry of a uniform Cartesian grid over the domain box, with `ghost`
 * node layers outside it.  Part of the model: nothing here changes.  On a
 * rank of a run across ranks (src/mpm/ranks) it is the rank's block of the
 * whole grid: nn nodes per axis from global node `offset`, with the whole
 * grid's origin and reach, so that a node's position and a particle's
 * weights are computed exactly as on one process. */
typedef struct {
  int dim;
  mpm_basis shape;
  int width; /* nodes per axis in a stencil */
  int ghost; /* node layers outside the domain box */
  double h, inv_h;
  double origin[3]; /* node (0, 0, 0) */
  long nn[3];       /* nodes per axis (1 on z in 2-D) */
  long offset[3];   /* global index of node (0, 0, 0): 0 on one process */
  long stride[3];   /* index step per axis */
  long n_nodes;
  double lo[3], hi[3]; /* where a particle's stencil lies inside the grid */
  double node_volume;  /* h^dim */
} mpm_grid;

/* Node accumulator record in the per-thread buffers. */
enum { MPM_ACC_M = 0, MPM_ACC_P = 1, MPM_ACC_F = 4, MPM_ACC_BASE = 7 };

/* The nodal arrays of a step.  Workspace: every step rebuilds them from
 * the particles, so a checkpoint never writes them. */
typedef struct {
  double *mass;    /* per node */
  double *mom;     /* 3 per node: momentum */
  double *force;   /* 3 per node: internal + external force */
  double *vel0;    /* 3 per node: velocity before the update */
  double *vel_new; /* 3 per node: updated (Lagrangian) velocity */
  double *vel;     /* 3 per node: the velocity of USF (before the update)
                      or MUSL (remapped), with the boundary conditions;
                      NULL for USL */
  const double *vel_stress; /* the velocity the stress update reads */
  /* Per-thread accumulators [threads][n_nodes][acc_stride]. */
  double *acc;
  int acc_stride; /* 7, or 9 with the impedance sums */
  int threads;
  double *impedance; /* 2 per node: sum w m c_p, sum w m c_s (absorbing
                        faces only) */
  /* Across ranks: 1 where this rank owns the node, 0 at a ghost node whose
   * values it computes too but whose sums belong to another rank (NULL on
   * one process).  Borrowed from the model's share (mpm_xc_work_attach). */
  const unsigned char *owned;
} mpm_nodes;

/* Whether sums over nodes count node i on this rank. */
static inline bool mpm_node_owned(const mpm_nodes *n, long i) {
  return !n->owned || n->owned[i];
}

/* Node i's position (x, y[, z]; 0 beyond the grid's dimension). */
static inline void mpm_grid_node_position(const mpm_grid *g, long i,
                                          double x[3]) {
  for (int c = 2; c >= 0; c--) {
    const long k = i / g->stride[c];
    i -= k * g->stride[c];
    x[c] = c < g->dim ? g->origin[c] + (double)(k + g->offset[c]) * g->h : 0;
  }
}

/* Lay the grid over the box [box_min, box_max] in cells of h (dim 2 or 3).
 * Fails with PM_ERR_SCENE, naming the scene file `path` and
 * discretization.mesh_size, when the grid would be too large. */
pm_err mpm_grid_init(mpm_grid *g, int dim, mpm_basis shape, double h,
                     const double box_min[3], const double box_max[3],
                     const char *path);

/* Allocate the nodal arrays of grid g (zeroed): `vel` unless the update
 * is USL (with_vel false), the impedances with absorbing faces, and the
 * accumulators of `threads` threads.  On failure (PM_ERR_MEMORY) what was
 * allocated stays for mpm_nodes_destroy. */
pm_err mpm_nodes_create(mpm_nodes *n, const mpm_grid *g, bool with_vel,
                        bool with_impedance, int threads);
/* Release the nodal arrays (and zero n). */
void mpm_nodes_destroy(mpm_nodes *n);
/* Bytes the nodal arrays take. */
size_t mpm_nodes_bytes(const mpm_nodes *n, const mpm_grid *g);

/* ---- the stencil ---------------------------------------------------------
 * A particle's nodes in tensor-product order (x fastest), with their
 * weights S_I(x_p) and gradients grad S_I(x_p).  Expanded once per particle
 * and transfer, then walked by a flat loop.  The products are formed in
 * one fixed order (w_x (w_y w_z), ...), which every transfer shares. */

#define MPM_STENCIL_MAX 27
enum { MPM_STENCIL_W = 1, MPM_STENCIL_GRAD = 2 };

typedef struct {
  int n; /* nodes: width^dim */
  long node[MPM_STENCIL_MAX];
  double w[MPM_STENCIL_MAX];       /* with MPM_STENCIL_W */
  double grad[MPM_STENCIL_MAX][3]; /* with MPM_STENCIL_GRAD, 1/m */
} mpm_stencil;

/* The expansion for a constant dimension and width (the shape follows the
 * width), so that its loops unroll. */
static inline __attribute__((always_inline)) void
mpm_stencil_expand(const mpm_grid *g, const double x[3], int what,
                   mpm_stencil *st, const int dim, const int width) {
  const mpm_basis shape = width == 3 ? MPM_BASIS_QUADRATIC : MPM_BASIS_LINEAR;
  const int nz = dim == 3 ? width : 1;
  long base = 0;
  double w[3][3], dw[3][3];
  w[2][0] = 1;
  dw[2][0] = 0;
  for (int c = 0; c < dim; c++) {
    long i0;
    mpm_shape_1d(shape, (x[c] - g->origin[c]) * g->inv_h, g->inv_h, &i0, w[c],
                 dw[c]);
    base += (i0 - g->offset[c]) * g->stride[c];
  }
  int k = 0;
  for (int c = 0; c < nz; c++)
    for (int b = 0; b < width; b++) {
      const double wbc = w[1][b] * w[2][c];
      const double gy = dw[1][b] * w[2][c];
      const double gz = w[1][b] * dw[2][c];
      const long row = base + b * g->stride[1] + c * g->stride[2];
      for (int a = 0; a < width; a++, k++) {
        st->node[k] = row + a;
        if (what & MPM_STENCIL_W) st->w[k] = w[0][a] * wbc;
        if (what & MPM_STENCIL_GRAD) {
          st->grad[k][0] = dw[0][a] * wbc;
          st->grad[k][1] = w[0][a] * gy;
          st->grad[k][2] = w[0][a] * gz;
        }
      }
    }
  st->n = k;
}

/* Expand the stencil of a particle at x (inside the grid's reach, lo <= x
 * < hi) into st: what = MPM_STENCIL_W, MPM_STENCIL_GRAD or both.  Inline so
 * that a constant `what` leaves no test in the loop. */
static inline void mpm_stencil_at(const mpm_grid *g, const double x[3],
                                  int what, mpm_stencil *st) {
  if (g->dim == 3) {
    if (g->width == 3)
      mpm_stencil_expand(g, x, what, st, 3, 3);
    else
      mpm_stencil_expand(g, x, what, st, 3, 2);
  } else {
    if (g->width == 3)
      mpm_stencil_expand(g, x, what, st, 2, 3);
    else
      mpm_stencil_expand(g, x, what, st, 2, 2);
  }
}

/* Velocity gradient L_ij = sum_I v_Ii dS_I/dx_j at x from the nodal
 * velocities vel (3 per node). */
static inline void mpm_velocity_gradient(const mpm_grid *g, const double *vel,
                                         const double x[3], double L[9]) {
  mpm_stencil st;
  mpm_stencil_at(g, x, MPM_STENCIL_GRAD, &st);
  /* Nine named sums: held in registers.  As an array, the compiler
   * vectorises the sums across nodes (in order, to keep them exact) at
   * twice the instructions. */
  double l0 = 0, l1 = 0, l2 = 0, l3 = 0, l4 = 0, l5 = 0, l6 = 0, l7 = 0, l8 = 0;
  for (int k = 0; k < st.n; k++) {
    const double *v = vel + 3 * st.node[k];
    const double g0 = st.grad[k][0], g1 = st.grad[k][1], g2 = st.grad[k][2];
    l0 += v[0] * g0;
    l1 += v[0] * g1;
    l2 += v[0] * g2;
    l3 += v[1] * g0;
    l4 += v[1] * g1;
    l5 += v[1] * g2;
    l6 += v[2] * g0;
    l7 += v[2] * g1;
    l8 += v[2] * g2;
  }
  L[0] = l0, L[1] = l1, L[2] = l2, L[3] = l3, L[4] = l4;
  L[5] = l5, L[6] = l6, L[7] = l7, L[8] = l8;
}

#endif
