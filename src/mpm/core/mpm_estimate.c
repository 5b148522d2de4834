/* mpm_estimate: bytes per particle and per grid node, as mpm_model_bytes,
 * mpm_state_bytes and mpm_work_bytes count them, times the particles the
 * bodies' volumes hold and the nodes of the grid. */
#include "mpm_estimate.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>

#include "gm_image.h"
#include "mpm_grid.h"
#include "mpm_kind.h"
#include "mpm_particles.h"
#include "mpm_scene.h"
#include "pm_omp.h"

static const double PI = 3.14159265358979323846;

/* Volume (area in 2D) of body b; the domain box's for shapes whose volume
 * needs the shape itself (a region, a mesh). */
static double body_volume(const pm_scene *s, const pm_scene_body *b,
                          double box) {
  const int dim = s->dimension;
  double v = box;
  switch (b->shape) {
  case PM_BODY_BOX:
    v = 1;
    for (int c = 0; c < dim; c++) v *= fabs(b->b[c] - b->a[c]);
    break;
  case PM_BODY_SPHERE:
    v = dim == 2 ? PI * b->radius * b->radius
                 : 4.0 / 3.0 * PI * pow(b->radius, 3);
    break;
  case PM_BODY_CYLINDER: {
    double len = 0;
    for (int c = 0; c < 3; c++) len += b->b[c] * b->b[c];
    v = dim == 2 ? 2 * b->radius * sqrt(len)
                 : PI * b->radius * b->radius * sqrt(len);
    break;
  }
  case PM_BODY_INSIDE: {
    const pm_scene_body *m = &s->bodies[b->surface_body];
    if (m->membrane.surface == PM_SURFACE_SPHERE)
      v = 4.0 / 3.0 * PI * pow(m->radius, 3);
    break;
  }
  default: break;
  }
  return fmin(v, box);
}

/* Points of a membrane body's surface (a file's are not known before it is
 * read: counted as none). */
static double membrane_points(const pm_scene_body *b) {
  switch (b->membrane.surface) {
  case PM_SURFACE_SPHERE: return 10 * pow(4, b->membrane.refinement) + 2;
  case PM_SURFACE_RECTANGLE:
    return b->membrane.points[0] * b->membrane.points[1];
  default: return 0;
  }
}

/* Whether image bodies a and b take their voxels from one crop of one
 * image (one label range each, usually disjoint). */
static bool same_voxels(const pm_scene_body *a, const pm_scene_body *b) {
  if (a->shape != PM_BODY_IMAGE || !gm_image_same_source(a, b) ||
      a->image.n_crop_min != b->image.n_crop_min)
    return false;
  for (int c = 0; c < a->image.n_crop_min; c++)
    if (a->image.crop_min[c] != b->image.crop_min[c] ||
        a->image.crop_max[c] != b->image.crop_max[c])
      return false;
  return true;
}

/* Particles of image body b: at most n^d per voxel of its crop, or of the
 * whole image (its size from the file's headers, or the one given), and no
 * more voxels than the domain box holds (box: its volume).  Bodies on the
 * same voxels hold at most the largest n^d per voxel together: b adds
 * what its n^d exceeds the earlier ones' by. */
static double image_particles(const pm_scene *s, int b, double box) {
  const pm_scene_body *body = &s->bodies[b];
  const int dim = s->dimension;
  double voxel = 1, voxels = 1, prev = 0;
  long size[3] = {0, 0, 0};
  bool known = body->image.n_crop_min > 0;
  if (!known) {
    known = gm_image_body_size(body, size) == PM_SUCCESS;
    if (!known) pm_error_clear(); /* the seeder reports it, at the key */
  }
  for (int c = 0; c < dim; c++) {
    voxel *= body->image.voxel[c];
    voxels *= body->image.n_crop_min > 0
                  ? body->image.crop_max[c] - body->image.crop_min[c]
                  : (double)size[c];
  }
  for (int a = 0; a < b; a++)
    if (same_voxels(&s->bodies[a], body))
      prev = fmax(prev, pow((double)s->bodies[a].image.per_voxel, dim));
  double fit = box / voxel;
  double n = pow((double)body->image.per_voxel, dim);
  return (known ? fmin(voxels, fit) : fit) * fmax(0, n - prev);
}

/* Doubles per particle of the kind of body b's particles (the kind's
 * estimate_doubles). */
static double kind_doubles(const pm_scene_material *sm, const pm_scene_body *b,
                           bool fbar) {
  return mpm_kind_of(sm, mpm_body_role_of(b))->estimate_doubles(sm, fbar);
}

/* The grid of s: its nodes (returned; the quadratic basis's ghost layer
 * and the room kept beside the box included), cells and the box's volume,
 * and h its cell size. */
static double grid_of(const pm_scene *s, double *cells, double *box,
                      double *h) {
  const mpm_settings *o = mpm_scene_settings(s);
  mpm_layout lay;
  if (!mpm_grid_layout(s, &lay)) lay.h = s->mesh_size;
  const int ghost = o->shape == MPM_BASIS_QUADRATIC ? 1 : 0;
  double nodes = 1;
  *box = *cells = 1;
  *h = lay.h;
  for (int c = 0; c < s->dimension; c++) {
    double len = s->box_max[c] - s->box_min[c];
    double k = fmax(1, ceil(len / lay.h - 1e-9));
    *box *= len;
    *cells *= k;
    nodes *= k + 1 + 2 * ghost + (double)(lay.room[c][0] + lay.room[c][1]);
  }
  return nodes;
}

/* mpm_estimate_bytes, and the nodes the bodies touch (*active): those of
 * a cube of the cells the bodies seeded in cells fill (every cell where
 * any body is seeded apart), with the basis's reach, at most the grid's. */
static size_t estimate(const pm_scene *s, long *points, double *active) {
  const int dim = s->dimension;
  const mpm_settings *o = mpm_scene_settings(s);
  double box, cells, h, ppc = 1;
  const double nodes = grid_of(s, &cells, &box, &h), d = sizeof(double);
  for (int c = 0; c < dim; c++) ppc *= o->ppc[c];
  const bool fbar = o->fbar != MPM_FBAR_NONE;
  /* Particles: per body, at most the domain's.  Membranes' points and
   * image voxels' particles are not seeded in cells: apart. */
  double n = 0, own = 0, top = ppc, apart = 0, filled = 0;
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    double bppc = ppc;
    if (body->n_ppc > 0) {
      bppc = 1;
      for (int c = 0; c < dim; c++) bppc *= body->ppc[body->n_ppc == 1 ? 0 : c];
    }
    double nb;
    if (body->shape == PM_BODY_MEMBRANE || body->shape == PM_BODY_IMAGE) {
      nb = body->shape == PM_BODY_MEMBRANE ? membrane_points(body)
                                           : image_particles(s, b, box);
      apart += nb;
    } else {
      nb = body_volume(s, body, box) / pow(h, dim) * bppc;
      top = fmax(top, bppc);
      filled += nb / bppc;
    }
    n += nb;
    own += nb * kind_doubles(&s->materials[body->material], body, fbar);
  }
  /* At most the densest seeding over the whole domain, and the particles
   * seeded apart. */
  if (n > cells * top + apart) {
    own *= (cells * top + apart) / n;
    n = cells * top + apart;
  }
  /* Per particle: the common arrays, x0, mass and vol0 of the model, dx, cp
   * and cs of the workspace, and the 9 of the output buffer. */
  double bytes =
      n * (mpm_particle_bytes_common() + 5 * d + 5 * d + 9 * d) + own * d;
  /* Per node: mass, momentum, force, two velocities and the impedance, the
   * threads' accumulators, the conditions' folds and owners, the state's
   * previous force and fixed flags, and F-bar's partial sums and
   * averages. */
  double per_node = (1 + 3 * 4 + 3 + 2) * d +
                    pm_omp_threads() * (MPM_ACC_BASE + 2) * d + 6 * d +
                    3 * sizeof(short) + 3 * d + 3 +
                    (fbar ? (2 * pm_omp_threads() + 1) * d : 0);
  bytes += nodes * per_node;
  *points = n < (double)LONG_MAX ? (long)n : LONG_MAX;
  const double reach = o->shape == MPM_BASIS_QUADRATIC ? 3 : 1;
  filled = apart > 0 ? cells : fmin(filled, cells);
  *active = fmin(nodes, pow(pow(filled, 1.0 / dim) + reach, dim));
  return bytes < (double)SIZE_MAX ? (size_t)bytes : SIZE_MAX;
}

size_t mpm_estimate_bytes(const pm_scene *s, long *points) {
  double active;
  return estimate(s, points, &active);
}

double mpm_estimate_active_nodes(const pm_scene *s) {
  long points;
  double active;
  estimate(s, &points, &active);
  return active;
}
