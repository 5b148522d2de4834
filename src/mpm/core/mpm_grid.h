/* mpm_grid: the MPM background grid: its geometry (fixed after setup), the
 * nodal arrays a step fills, and a particle's stencil, expanded into flat
 * lists of nodes, weights and weight gradients or walked in place by the
 * explicit step's transfers. */
#ifndef MPM_GRID_H
#define MPM_GRID_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "mpm_shape.h"
#include "pm_v4.h"
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

/* Node accumulator record in the per-thread buffers: mass and momentum,
 * then the force and a pad (never read), each four doubles that a transfer
 * adds as one vector, then the impedance sums. */
enum {
  MPM_ACC_M = 0,
  MPM_ACC_P = 1,
  MPM_ACC_F = 4,
  MPM_ACC_PAD = 7,
  MPM_ACC_BASE = 8
};

/* The nodal arrays of a step.  Workspace: every step rebuilds them from
 * the particles, so a checkpoint never writes them. */
typedef struct {
  double *mass;    /* per node */
  double *mom;     /* 3 per node: momentum */
  double *force;   /* 3 per node: internal + external force */
  double *vel0;    /* 3 per node (and 1 double of padding at the end):
                      velocity before the update */
  double *vel_new; /* 3 per node (and the padding): updated (Lagrangian)
                      velocity */
  double *vel;     /* 3 per node: the velocity of USF (before the update)
                      or MUSL (remapped), with the boundary conditions;
                      NULL for USL */
  const double *vel_stress; /* the velocity the stress update reads */
  /* Per-thread accumulators [threads][n_nodes][acc_stride]. */
  double *acc;
  int acc_stride; /* 8, or 10 with the impedance sums */
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
 * weights S_I(x_p) and gradients grad S_I(x_p): expanded into arrays (the
 * implicit solver, the conditions) or walked in place (MPM_STENCIL_FOR: the
 * explicit step's transfers).  Both form the products in one fixed order
 * (w_x (w_y w_z), ...), which every transfer shares. */

#define MPM_STENCIL_MAX 27
enum { MPM_STENCIL_W = 1, MPM_STENCIL_GRAD = 2 };

typedef struct {
  int n; /* nodes: width^dim */
  long node[MPM_STENCIL_MAX];
  double w[MPM_STENCIL_MAX];       /* with MPM_STENCIL_W */
  double grad[MPM_STENCIL_MAX][3]; /* with MPM_STENCIL_GRAD, 1/m */
} mpm_stencil;

/* ---- the stencil walked in place ----------------------------------------
 * A particle's nodes in tensor-product order (x fastest), each weight and
 * gradient formed by the products w_x (w_y w_z), ... (those
 * mpm_stencil_expand stores, so every sum is the same to the bit), where
 * they are used: nothing is stored and read back, and the compiler drops what
 * the body does not read.  DIM and WIDTH must be constants.  The body sees
 * `node` (the node's index), `wk` (its weight), `gk0`, `gk1`, `gk2` (its
 * gradient, 1/m) and, as vectors of the same products lane by lane, `wkv`
 * (the weight in every lane) and `gkv` (gk0, gk1, gk2, wk): one vector
 * multiplication each from factors broadcast once a particle or a row, where
 * the scalars would each be a multiplication and a broadcast.  No lane is
 * built as a zero, whose instruction (vmovq between registers) Valgrind
 * cannot run. */

/* A particle's 1-D weights and derivatives along each axis and its first
 * node (the smallest index): what a walk of its stencil starts from. */
typedef struct {
  long base;
  double w[3][3], dw[3][3];
} mpm_axes;

/* The axes of a particle at x, for a constant dimension and width. */
static inline __attribute__((always_inline)) void
mpm_axes_at(const mpm_grid *g, const double x[3], mpm_axes *ax, const int dim,
            const int width) {
  const mpm_basis sh = width == 3 ? MPM_BASIS_QUADRATIC : MPM_BASIS_LINEAR;
  ax->base = 0;
  ax->w[2][0] = 1;
  ax->dw[2][0] = 0;
  for (int c = 0; c < dim; c++) {
    long i0;
    mpm_shape_1d(sh, (x[c] - g->origin[c]) * g->inv_h, g->inv_h, &i0, ax->w[c],
                 ax->dw[c]);
    ax->base += (i0 - g->offset[c]) * g->stride[c];
  }
}

/* The stencil of axes ax (mpm_axes_at) walked in place: the body as in
 * MPM_STENCIL_FOR.  Two walks of one particle's stencil share its axes. */
#define MPM_STENCIL_WALK(g, ax, DIM, WIDTH, ...)                               \
  do {                                                                         \
    const double(*w_)[3] = (ax).w, (*dw_)[3] = (ax).dw;                        \
    pm_v4 wx_[3], gx_[3];                                                      \
    for (int a_ = 0; a_ < (WIDTH); a_++) {                                     \
      wx_[a_] = (pm_v4){w_[0][a_], w_[0][a_], w_[0][a_], w_[0][a_]};           \
      gx_[a_] = (pm_v4){dw_[0][a_], w_[0][a_], w_[0][a_], w_[0][a_]};          \
    }                                                                          \
    for (int c_ = 0; c_ < ((DIM) == 3 ? (WIDTH) : 1); c_++)                    \
      for (int b_ = 0; b_ < (WIDTH); b_++) {                                   \
        const double wbc_ = w_[1][b_] * w_[2][c_];                             \
        const double gy_ = dw_[1][b_] * w_[2][c_];                             \
        const double gz_ = w_[1][b_] * dw_[2][c_];                             \
        const pm_v4 wbcv_ = {wbc_, wbc_, wbc_, wbc_};                          \
        const pm_v4 gyz_ = {wbc_, gy_, gz_, wbc_};                             \
        const long row_ =                                                      \
            (ax).base + b_ * (g)->stride[1] + c_ * (g)->stride[2];             \
        for (int a_ = 0; a_ < (WIDTH); a_++) {                                 \
          const long node = row_ + a_;                                         \
          const double wk = w_[0][a_] * wbc_;                                  \
          const double gk0 = dw_[0][a_] * wbc_;                                \
          const double gk1 = w_[0][a_] * gy_;                                  \
          const double gk2 = w_[0][a_] * gz_;                                  \
          const pm_v4 wkv = wx_[a_] * wbcv_;                                   \
          const pm_v4 gkv = gx_[a_] * gyz_;                                    \
          (void)node, (void)wk, (void)gk0, (void)gk1, (void)gk2, (void)wkv;    \
          (void)gkv;                                                           \
          __VA_ARGS__                                                          \
        }                                                                      \
      }                                                                        \
  } while (0)

/* The stencil of a particle at x walked in place: its axes, then the walk. */
#define MPM_STENCIL_FOR(g, x, DIM, WIDTH, ...)                                 \
  do {                                                                         \
    mpm_axes ax_;                                                              \
    mpm_axes_at((g), (x), &ax_, (DIM), (WIDTH));                               \
    MPM_STENCIL_WALK(g, ax_, DIM, WIDTH, __VA_ARGS__);                         \
  } while (0)

/* Lane L of v in every lane. */
#define MPM_LANE(v, L) __builtin_shufflevector((v), (v), L, L, L, L)

/* Call FN(..., dim, width) with the grid's dimension and width as
 * constants (FN inline: one copy of its loops a combination). */
#define MPM_STENCIL_DISPATCH(g, FN, ...)                                       \
  do {                                                                         \
    if ((g)->dim == 3 && (g)->width == 3)                                      \
      FN(__VA_ARGS__, 3, 3);                                                   \
    else if ((g)->dim == 3)                                                    \
      FN(__VA_ARGS__, 3, 2);                                                   \
    else if ((g)->width == 3)                                                  \
      FN(__VA_ARGS__, 2, 3);                                                   \
    else                                                                       \
      FN(__VA_ARGS__, 2, 2);                                                   \
  } while (0)

/* The expansion for a constant dimension and width (the shape follows the
 * width), so that its loops unroll: the walk above, stored. */
static inline __attribute__((always_inline)) void
mpm_stencil_expand(const mpm_grid *g, const double x[3], int what,
                   mpm_stencil *st, const int dim, const int width) {
  int k = 0;
  MPM_STENCIL_FOR(g, x, dim, width, {
    st->node[k] = node;
    if (what & MPM_STENCIL_W) st->w[k] = wk;
    if (what & MPM_STENCIL_GRAD) {
      st->grad[k][0] = gk0;
      st->grad[k][1] = gk1;
      st->grad[k][2] = gk2;
    }
    k++;
  });
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
 * velocities vel (3 per node), for a constant dimension and width. */
static inline __attribute__((always_inline)) void
mpm_velocity_gradient_dw(const mpm_grid *g, const double *vel,
                         const double x[3], double L[9], const int dim,
                         const int width) {
  /* Three rows of L as vectors, l_i += v_i grad S, lane by lane the
   * products and sums of the scalar loop. */
  pm_v4 r0 = {0, 0, 0, 0}, r1 = r0, r2 = r0;
  MPM_STENCIL_FOR(g, x, dim, width, {
    const double *v = vel + 3 * node;
    r0 += v[0] * gkv;
    r1 += v[1] * gkv;
    r2 += v[2] * gkv;
  });
  L[0] = r0[0], L[1] = r0[1], L[2] = r0[2], L[3] = r1[0], L[4] = r1[1];
  L[5] = r1[2], L[6] = r2[0], L[7] = r2[1], L[8] = r2[2];
}

/* Velocity gradient L_ij = sum_I v_Ii dS_I/dx_j at x from the nodal
 * velocities vel (3 per node). */
static inline __attribute__((always_inline)) void
mpm_velocity_gradient(const mpm_grid *g, const double *vel, const double x[3],
                      double L[9]) {
  MPM_STENCIL_DISPATCH(g, mpm_velocity_gradient_dw, g, vel, x, L);
}

#endif
