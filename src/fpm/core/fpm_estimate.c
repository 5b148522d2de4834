/* fpm_estimate: bytes per point of each FPM array, times the points gmsh
 * makes of the domain box at the scene's mesh size (and grading). */
#include "fpm_estimate.h"

#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "fpm_stream.h"
#include "fpm_gfd.h"
#include "fpm_grade.h"
#include "gm_gmsh.h"
#include "gm_mesh.h"
#include "fpm_model.h"
#include "fpm_scene.h"
#include "fpm_static.h"

/* Support entries per point (mesh edges, both ways): 11.8-12.4 on the 3D
 * blocks of cases/fpm, 5.4 in 2D; quadratic-fit entries per point over two
 * rings of neighbours: 26 (3D, half the points on two rings) to 15 (2D). */
#define NNZ_3D 12.5
#define NNZ_2D 6.0
#define QFIT_3D 40.0
#define QFIT_2D 16.0
/* The gmsh mesh and the median-dual subdomains (cells, interfaces, facets)
 * per point: measured as peak resident memory above the operators. */
#define MESH_BYTES 2500.0

/* The points of a graded mesh over those of the uniform one at mesh_size
 * (1 ungraded, about 1 for the ratio form, which keeps the budget). */
static double grade_factor(const pm_scene *s) {
  gm_grade g;
  double far;
  fpm_grade_of(s, &g, &far);
  return fpm_grade_density(s, &g, far) * pow(s->mesh_size / far, s->dimension);
}

size_t fpm_estimate_bytes(const pm_scene *s, long *points) {
  const int dim = s->dimension;
  const fpm_options *o = fpm_scene_options(s);
  const bool quadratic = o->jump == FPM_JUMP_QUADRATIC;
  /* Nodes of a structured grid of the box at the mesh size; gmsh's
   * unstructured 2D meshes are denser (mean edge below the size). */
  double n = dim == 2 ? 1.4 : 1.0;
  for (int c = 0; c < dim; c++)
    n *= (s->box_max[c] - s->box_min[c]) / s->mesh_size + 1;
  n *= grade_factor(s);
  /* A meshed body (.msh) is used as it is: its points are its nodes. */
  const int body = fpm_domain_body(s);
  const long nodes = body >= 0 ? gm_msh_node_count(s->bodies[body].mesh) : -1;
  if (nodes > 0) n = (double)nodes;
  const double d = sizeof(double);
  const double nnz = dim == 2 ? NNZ_2D : NNZ_3D;
  /* As fpm_model_bytes and fpm_state_bytes count them, per point; every
   * point may sit on a prescribed face. */
  double per_point = nnz * ((3 + FPM_EREC) * d + 2 * sizeof(int)) +
                     (3 + 1 + 3 + 9 + 1) * d + sizeof(int) + 3 +
                     0.5 * (36 * d + sizeof(long)) + (3 * 4 + 9 * 3 + 2) * d +
                     3 * (d + sizeof(long)) + MESH_BYTES;
  if (quadratic)
    per_point +=
        (dim == 2 ? QFIT_2D : QFIT_3D) * (FPM_QFIT * d + 3 * sizeof(int)) +
        FPM_QFIT * d + 2 * sizeof(long) + 57 * d;
  /* The entry stream (fpm_stream_bytes), with the flux records for the
   * plain formulation; a row's padding is (FPM_LANES - 1) / 2 entries on
   * average. */
  const bool plain = !quadratic && o->flux != FPM_FLUX_SIPG &&
                     o->stiffening == 0 && o->volume_penalty == 0;
  per_point += (double)fpm_stream_bytes(
      1, (long)ceil(nnz + (FPM_LANES - 1) / 2.0), plain);
  /* Newton's method adds fpm_linear_bytes, and the tangent with its
   * factors or multigrid hierarchy: those of every point's 3 dofs free
   * (the prescribed are a few percent), by the solver the solve would
   * choose (fpm_static_choose_linear, fpm_static_couples). */
  double solver = 0;
  if (s->time.qs == PM_QS_STATIC) {
    per_point += (81 + 9 + 9 + 9 + 3 + 12 + (quadratic ? 57 : 0)) * d;
    const double dofs = fmin(3 * n, (double)LONG_MAX / 2);
    const pm_newton_linear linear =
        pm_scene_has(s, "time.quasi_static.linear_solver")
            ? pm_newton_linear_of(s->time.qs_linear)
            : fpm_static_default_linear((long)dofs);
    /* (whether an LU, the solve's or its fallbacks', takes the coupling) */
    const bool couples =
        o->volumetric == FPM_VOLUMETRIC_AVERAGED && s->time.qs_coupled &&
        (pm_scene_has(s, "time.quasi_static.averaged_coupling") ||
         dofs <= FPM_STATIC_COUPLED_MAX);
    solver =
        fpm_static_solver_bytes((long)dofs, quadratic, linear,
                                couples && linear == PM_NEWTON_DIRECT, NULL);
    /* the fallbacks' LU, beside the multigrid it stands in for */
    if (fpm_static_fallback_direct(s, NULL, (long)dofs))
      solver = fmax(solver,
                    fpm_static_solver_bytes((long)dofs, quadratic,
                                            PM_NEWTON_DIRECT, couples, NULL));
  }
  *points = n < (double)LONG_MAX ? (long)n : LONG_MAX;
  double bytes = n * per_point + solver;
  return bytes < (double)SIZE_MAX ? (size_t)bytes : SIZE_MAX;
}

size_t fpm_estimate_geometry_bytes(const pm_scene *s) {
  long points = 0;
  fpm_estimate_bytes(s, &points);
  return (size_t)(MESH_BYTES * (double)points);
}
