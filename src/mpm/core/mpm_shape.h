/* mpm_shape: grid basis functions of the MPM (linear and quadratic
 * B-splines on a uniform grid), as tensor products of 1-D weights.
 * Node i of an axis sits at origin + i h. */
#ifndef MPM_SHAPE_H
#define MPM_SHAPE_H

#include <math.h>

#include "mpm_scene.h"

/* Nodes per axis in a particle's stencil. */
static inline int mpm_shape_width(mpm_basis s) {
  return s == MPM_BASIS_QUADRATIC ? 3 : 2;
}

/* One axis: xi = (x - origin) / h in cell units.  Writes the first node
 * index *i0 and the weights w[k] and derivatives dw[k] (per unit length,
 * inv_h = 1 / h) of nodes i0 + k, k < width. */
static inline void mpm_shape_1d(mpm_basis s, double xi, double inv_h, long *i0,
                                double w[3], double dw[3]) {
  if (s == MPM_BASIS_QUADRATIC) {
    /* Quadratic B-spline, support 3 h, centred on the node. */
    double b = floor(xi - 0.5);
    double d = xi - b; /* in [0.5, 1.5) */
    double a0 = 1.5 - d, a1 = d - 1.0, a2 = d - 0.5;
    *i0 = (long)b;
    w[0] = 0.5 * a0 * a0;
    w[1] = 0.75 - a1 * a1;
    w[2] = 0.5 * a2 * a2;
    dw[0] = -a0 * inv_h;
    dw[1] = -2.0 * a1 * inv_h;
    dw[2] = a2 * inv_h;
  } else {
    /* Linear hat, support 2 h. */
    double b = floor(xi);
    double d = xi - b; /* in [0, 1) */
    *i0 = (long)b;
    w[0] = 1.0 - d;
    w[1] = d;
    w[2] = 0.0;
    dw[0] = -inv_h;
    dw[1] = inv_h;
    dw[2] = 0.0;
  }
}

#endif
