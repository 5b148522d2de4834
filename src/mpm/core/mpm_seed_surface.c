/* mpm_seed_surface: a membrane body's surface for the seeding: a sphere,
 * a rectangle, a triangulated file, a parametric curve or a point cloud,
 * with each point's share of its area. */
#include <stdio.h>
#include <stdlib.h>

#include "gm_curve.h"
#include "gm_trisurf.h"
#include "mpm_seed_impl.h"

/* A located failure at bodies.B(.KEY): the message of the call that
 * failed, after the scene position. */
pm_err mpm_seed_body_fail(const pm_scene *s, int b, const char *key,
                          const char *what) {
  char p[PM_SDOC_PATH], msg[1024];
  snprintf(msg, sizeof msg, "%s", pm_error_message());
  if (key)
    snprintf(p, sizeof p, "bodies.%d.%s", b, key);
  else
    snprintf(p, sizeof p, "bodies.%d", b);
  return pm_scene_fail(s, p, key != NULL, "%s: %s", what, msg);
}

/* A curve's or point cloud's points as a surface without triangles. */
static void points_only(long n, double *x, gm_trisurf *out) {
  *out = (gm_trisurf){.n_points = n, .x = x};
}

/* Each point's share of the point cloud of body b: the file's column, or
 * membrane.area shared equally. */
static pm_err cloud_shares(const pm_scene *s, int b, long n, double **share) {
  const pm_scene_body *body = &s->bodies[b];
  if (*share) return PM_SUCCESS;
  char p[PM_SDOC_PATH];
  if (!(body->membrane.area > 0))
    return pm_scene_fail(s, PM_PATH(p, "bodies.%d.membrane.points", b), true,
                         "expected a file with an area per point (a last "
                         "column), or membrane.area: the file %s gives none",
                         body->membrane.file);
  PM_CALL(PM_ALLOC(*share, n, "membrane point areas"));
  for (long k = 0; k < n; k++) (*share)[k] = body->membrane.area / (double)n;
  return PM_SUCCESS;
}

/* The points of membrane body b (and its triangles), each point's share
 * of its area (length in 2D), all inside the grid. */
pm_err mpm_seed_surface(const pm_scene *s, int b, gm_trisurf *out,
                        double **share) {
  const pm_scene_body *body = &s->bodies[b];
  pm_err e = PM_SUCCESS;
  const char *key = "membrane";
  gm_curve cv = {0};
  long n = 0;
  double *x = NULL;
  switch (body->membrane.surface) {
  case PM_SURFACE_SPHERE:
    e = gm_trisurf_sphere(body->a, body->radius, (int)body->membrane.refinement,
                          out);
    key = "membrane.sphere";
    break;
  case PM_SURFACE_RECTANGLE:
    e = gm_trisurf_rectangle(body->a, body->b, body->membrane.edge_v,
                             (long)body->membrane.points[0],
                             (long)body->membrane.points[1], out);
    key = "membrane.rectangle";
    break;
  case PM_SURFACE_FILE:
    e = gm_trisurf_load(body->membrane.file, out);
    key = "membrane.file";
    break;
  case PM_SURFACE_CURVE:
    key = "membrane.curve";
    e = gm_curve_parametric(
        body->membrane.curve[0], body->membrane.curve[1],
        body->membrane.curve_range[0], body->membrane.curve_range[1],
        body->membrane.curve_points, body->membrane.closed, &cv);
    if (e) break;
    points_only(cv.n, cv.x, out);
    e = PM_ALLOC(*share, cv.n, "membrane point lengths");
    if (!e) gm_curve_point_lengths(&cv, *share);
    break;
  case PM_SURFACE_POINTS:
    key = "membrane.points";
    e = gm_points_load(body->membrane.file, s->dimension, &n, &x, share);
    if (e) {
      /* The reader's message names the file, line and column. */
      char p[PM_SDOC_PATH], msg[1024];
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return pm_scene_fail(s, PM_PATH(p, "bodies.%d.%s", b, key), true, "%s",
                           msg);
    }
    points_only(n, x, out);
    PM_CALL(cloud_shares(s, b, n, share));
    break;
  }
  if (e) return mpm_seed_body_fail(s, b, key, "expected a surface");
  if (!*share) {
    PM_CALL(PM_ALLOC(*share, out->n_points, "membrane point areas"));
    gm_trisurf_point_areas(out, *share);
  }
  double lo[3], hi[3];
  gm_trisurf_bounds(out, lo, hi);
  for (int c = 0; c < s->dimension; c++) {
    double tol = 1e-9 * (s->box_max[c] - s->box_min[c]);
    if (lo[c] < s->box_min[c] - tol || hi[c] > s->box_max[c] + tol) {
      char p[PM_SDOC_PATH];
      return pm_scene_fail(s, PM_PATH(p, "bodies.%d.%s", b, key), true,
                           "expected a surface inside domain.box (%c in [%g, "
                           "%g]), got one reaching %c = %g: its particles "
                           "would be outside the grid",
                           "xyz"[c], s -> box_min[c], s -> box_max[c], "xyz"[c],
                           lo[c] < s -> box_min[c] ? lo[c] : hi[c]);
    }
  }
  return PM_SUCCESS;
}
