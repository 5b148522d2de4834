/* mpm_grid: grid geometry and the nodal arrays. */
#include "mpm_grid.h"

#include <math.h>
#include <stdlib.h>

pm_err mpm_grid_init(mpm_grid *g, int dim, mpm_basis shape, double h,
                     const double box_min[3], const double box_max[3],
                     const char *path) {
  g->dim = dim;
  g->shape = shape;
  g->width = mpm_shape_width(shape);
  g->ghost = shape == MPM_BASIS_QUADRATIC ? 1 : 0;
  g->h = h;
  g->inv_h = 1.0 / h;
  g->node_volume = 1;
  g->n_nodes = 1;
  for (int c = 0; c < 3; c++) {
    g->offset[c] = 0;
    if (c >= dim) {
      g->origin[c] = 0;
      g->nn[c] = 1;
      g->lo[c] = -INFINITY;
      g->hi[c] = INFINITY;
      continue;
    }
    double len = box_max[c] - box_min[c];
    long cells = (long)ceil(len / h - 1e-9);
    if (cells < 1) cells = 1;
    PM_CHECK(cells <= 100000, PM_ERR_SCENE,
             "%s: discretization.mesh_size: expected a cell size giving at "
             "most 100000 cells per axis, got %g (%ld cells along %c)",
             path, h, cells, "xyz"[c]);
    g->origin[c] = box_min[c] - g->ghost * h;
    g->nn[c] = cells + 1 + 2 * g->ghost;
    g->node_volume *= h;
    g->n_nodes *= g->nn[c];
    /* Where the stencil of x has its nodes in [0, nn - 1]: linear
     * 0 <= xi < nn - 1, quadratic 0.5 <= xi < nn - 1.5 (xi in cells from
     * the origin), less a margin of 1e-9 h. */
    double shift = g->ghost ? 0.5 : 0.0;
    g->lo[c] = g->origin[c] + (shift + 1e-9) * h;
    g->hi[c] = g->origin[c] + (g->nn[c] - 1 - shift - 1e-9) * h;
  }
  PM_CHECK(g->n_nodes <= 200000000L, PM_ERR_SCENE,
           "%s: discretization.mesh_size: expected at most 2e8 grid nodes, "
           "got %ld",
           path, g->n_nodes);
  g->stride[0] = 1;
  g->stride[1] = g->nn[0];
  g->stride[2] = g->nn[0] * g->nn[1];
  return PM_SUCCESS;
}

pm_err mpm_nodes_create(mpm_nodes *n, const mpm_grid *g, bool with_vel,
                        bool with_impedance, int threads) {
  const long nn = g->n_nodes;
  PM_CALL(PM_ALLOC(n->mass, nn, "grid masses"));
  PM_CALL(PM_ALLOC(n->mom, 3 * nn, "grid momenta"));
  PM_CALL(PM_ALLOC(n->force, 3 * nn, "grid forces"));
  /* One double past the last node: g2p reads a node's three components
   * as four (the fourth unused). */
  PM_CALL(PM_ALLOC(n->vel0, 3 * nn + 1, "grid velocities"));
  if (with_vel) PM_CALL(PM_ALLOC(n->vel, 3 * nn, "grid velocities"));
  PM_CALL(PM_ALLOC(n->vel_new, 3 * nn + 1, "grid velocities"));
  n->vel_stress = n->vel ? n->vel : n->vel_new;
  n->threads = threads;
  n->acc_stride = with_impedance ? MPM_ACC_BASE + 2 : MPM_ACC_BASE;
  PM_CALL(PM_ALLOC(n->acc, (size_t)threads * nn * n->acc_stride,
                   "per-thread grid accumulators"));
  if (with_impedance)
    PM_CALL(PM_ALLOC(n->impedance, 2 * nn, "grid impedances"));
  return PM_SUCCESS;
}

void mpm_nodes_destroy(mpm_nodes *n) {
  free(n->mass);
  free(n->mom);
  free(n->force);
  free(n->vel0);
  free(n->vel);
  free(n->vel_new);
  free(n->acc);
  free(n->impedance);
  memset(n, 0, sizeof *n);
}

size_t mpm_nodes_bytes(const mpm_nodes *n, const mpm_grid *g) {
  if (!n->mass) return 0;      /* a workspace without nodal arrays */
  size_t per_node = 1 + 3 * 4; /* mass, mom, force, vel0, vel_new */
  if (n->vel) per_node += 3;
  if (n->impedance) per_node += 2;
  per_node += (size_t)n->threads * n->acc_stride;
  return per_node * sizeof(double) * (size_t)g->n_nodes;
}
