/* gm_shape: one table entry per kind of body (how to read it from the
 * scene, contains, bounds, release): a new kind is one more entry and its
 * functions, here.  The inside and the outside of a
 * closed triangulated surface are two more kinds, built from the surface. */
#include "gm_shape.h"

#include <math.h>
#include <stdlib.h>

#include "gm_curve.h"
#include "gm_image.h"
#include "gm_inside.h"
#include "gm_volume.h"
#include "pm_tensor.h"

/* Slack of the domain box and of gm_shape_check_inside, relative to the
 * box's size along each axis: round-off in node and seed positions. */
#define GM_SHAPE_BOX_TOL 1e-9

typedef struct shape_kind shape_kind;

struct gm_shape {
  const shape_kind *kind;
  int dim;
  double lo[3], hi[3];  /* domain box, or the box body */
  double c[3], axis[3]; /* sphere centre; cylinder base and axis */
  double radius, axis_len2;
  const pm_expr *region; /* borrowed from the scene */
  gm_volume *volume;     /* owned */
  gm_inside *inside;     /* owned */
  gm_polygon polygon;    /* owned: the region a 2-D membrane encloses */
  gm_image *image;       /* owned when read by gm_shape_create */
  gm_image_part part;    /* an image body's voxels (image borrowed) */
};

struct shape_kind {
  const char *key;  /* the scene's word for it */
  bool thread_safe; /* contains may run from several threads at once */
  /* Reads (and checks) the body's numbers into s; h: mesh element size. */
  pm_err (*init)(gm_shape *s, const pm_scene_body *b, double h);
  bool (*contains)(const gm_shape *s, const double x[3]);
  /* NULL: unbounded. */
  void (*bounds)(const gm_shape *s, double lo[3], double hi[3]);
  /* NULL: nothing owned. */
  void (*release)(gm_shape *s);
};

/* ---- domain and region: unbounded -------------------------------------- */

static pm_err domain_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)b;
  (void)h;
  /* The domain box, already in s, widened by the slack. */
  for (int k = 0; k < s->dim; k++) {
    double tol = GM_SHAPE_BOX_TOL * (s->hi[k] - s->lo[k]);
    s->lo[k] -= tol;
    s->hi[k] += tol;
  }
  return PM_SUCCESS;
}

/* The box test of both the domain and a box body. */
static bool box_contains(const gm_shape *s, const double x[3]) {
  for (int k = 0; k < s->dim; k++)
    if (x[k] < s->lo[k] || x[k] > s->hi[k]) return false;
  return true;
}

static pm_err region_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)h;
  PM_CHECK(b->region, PM_ERR_ARG, "region body without an expression");
  s->region = b->region;
  return PM_SUCCESS;
}

static bool region_contains(const gm_shape *s, const double x[3]) {
  return pm_expr_eval(s->region, x[0], x[1], s->dim == 3 ? x[2] : 0, 0) > 0;
}

/* ---- box, sphere, cylinder ---------------------------------------------- */

static pm_err box_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)h;
  for (int k = 0; k < s->dim; k++) {
    PM_CHECK(isfinite(b->a[k]) && isfinite(b->b[k]) && b->b[k] > b->a[k],
             PM_ERR_ARG, "box: expected min < max along %c, got [%g, %g]",
             "xyz"[k], b -> a[k], b -> b[k]);
    s->lo[k] = b->a[k];
    s->hi[k] = b->b[k];
  }
  return PM_SUCCESS;
}

static void box_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  for (int k = 0; k < s->dim; k++) {
    lo[k] = s->lo[k];
    hi[k] = s->hi[k];
  }
}

static pm_err round_init(gm_shape *s, const pm_scene_body *b) {
  PM_CHECK(isfinite(b->radius) && b->radius > 0, PM_ERR_ARG,
           "expected a radius > 0, got %g", b->radius);
  for (int k = 0; k < s->dim; k++) {
    PM_CHECK(isfinite(b->a[k]), PM_ERR_ARG, "expected a finite centre");
    s->c[k] = b->a[k];
  }
  s->radius = b->radius;
  return PM_SUCCESS;
}

static pm_err sphere_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)h;
  return round_init(s, b);
}

static bool sphere_contains(const gm_shape *s, const double x[3]) {
  double r2 = 0;
  for (int k = 0; k < s->dim; k++) r2 += (x[k] - s->c[k]) * (x[k] - s->c[k]);
  return r2 <= s->radius * s->radius;
}

static void sphere_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  for (int k = 0; k < s->dim; k++) {
    lo[k] = s->c[k] - s->radius;
    hi[k] = s->c[k] + s->radius;
  }
}

static pm_err cylinder_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)h;
  PM_CHECK(s->dim == 3, PM_ERR_ARG, "a cylinder needs dimension 3 (got %d)",
           s->dim);
  PM_CALL(round_init(s, b));
  for (int k = 0; k < 3; k++) s->axis[k] = b->b[k];
  s->axis_len2 = pm_v_dot(s->axis, s->axis);
  PM_CHECK(isfinite(s->axis_len2) && s->axis_len2 > 0, PM_ERR_ARG,
           "cylinder: expected a non-zero axis, got (%g, %g, %g)", b->b[0],
           b->b[1], b->b[2]);
  return PM_SUCCESS;
}

/* Between the end planes, and within radius of the axis. */
static bool cylinder_contains(const gm_shape *s, const double x[3]) {
  double d[3] = {x[0] - s->c[0], x[1] - s->c[1], x[2] - s->c[2]};
  double t = pm_v_dot(d, s->axis) / s->axis_len2;
  if (t < 0 || t > 1) return false;
  return pm_v_dot(d, d) - t * t * s->axis_len2 <= s->radius * s->radius;
}

/* The end discs' boxes: a disc of radius r normal to unit n reaches
 * r sqrt(1 - n_k^2) along axis k. */
static void cylinder_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; k++) {
    double n2 = s->axis[k] * s->axis[k] / s->axis_len2;
    double e = s->radius * sqrt(fmax(0, 1 - n2));
    double a = s->c[k], t = s->c[k] + s->axis[k];
    lo[k] = fmin(a, t) - e;
    hi[k] = fmax(a, t) + e;
  }
}

/* ---- gmsh volume -------------------------------------------------------- */

static pm_err mesh_init(gm_shape *s, const pm_scene_body *b, double h) {
  PM_CHECK(b->mesh && b->mesh[0], PM_ERR_ARG, "mesh body without a file");
  /* the inside of the body at the grid's size */
  return gm_volume_load(b->mesh, s->dim, h, GM_SIZES_REPLACE, &s->volume);
}

static bool mesh_contains(const gm_shape *s, const double x[3]) {
  return gm_volume_contains(s->volume, x);
}

static void mesh_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  gm_volume_bounds(s->volume, lo, hi);
}

static void mesh_release(gm_shape *s) { gm_volume_destroy(s->volume); }

/* ---- labelled image ----------------------------------------------------- */

/* The image read for this shape alone (gm_shape_create); a seeder that
 * shares one image among bodies uses gm_shape_from_image. */
static pm_err image_init(gm_shape *s, const pm_scene_body *b, double h) {
  (void)h;
  const char *key;
  PM_CALL(PM_ALLOC(s->image, 1, "image"));
  PM_CALL(gm_image_of_body(b, s->image));
  return gm_image_body_part(s->image, b, s->dim, &s->part, &key);
}

static bool image_contains(const gm_shape *s, const double x[3]) {
  return gm_image_part_contains(&s->part, s->dim, x);
}

static void image_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  gm_image_part_box(&s->part, s->dim, lo, hi);
}

static void image_release(gm_shape *s) {
  gm_image_free(s->image);
  free(s->image);
}

/* ---- closed triangulated surface ---------------------------------------- */

/* Not in the table: built from a surface, not from a scene body. */

static bool inside_contains(const gm_shape *s, const double x[3]) {
  return gm_inside_contains(s->inside, x);
}

/* The surface itself belongs to the inside. */
static bool outside_contains(const gm_shape *s, const double x[3]) {
  return !gm_inside_contains(s->inside, x);
}

static void inside_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  gm_inside_bounds(s->inside, lo, hi);
}

static void inside_release(gm_shape *s) { gm_inside_destroy(s->inside); }

static const shape_kind inside_kind = {.key = "inside",
                                       .thread_safe = true,
                                       .contains = inside_contains,
                                       .bounds = inside_bounds,
                                       .release = inside_release};
static const shape_kind outside_kind = {.key = "outside",
                                        .thread_safe = true,
                                        .contains = outside_contains,
                                        .release = inside_release};

pm_err gm_shape_from_surface(const gm_trisurf *s, bool outside,
                             gm_shape **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_shape_from_surface: out is NULL");
  *out = NULL;
  PM_CHECK(s, PM_ERR_ARG, "gm_shape_from_surface: no surface");
  pm_err ret = PM_SUCCESS;
  gm_shape *shape = NULL;
  PM_TRY(PM_ALLOC(shape, 1, "shape"));
  shape->kind = outside ? &outside_kind : &inside_kind;
  shape->dim = 3;
  PM_TRY(gm_inside_create(s, &shape->inside));
  *out = shape;
  shape = NULL;
done:
  gm_shape_destroy(shape);
  return ret;
}

/* ---- the region a 2-D membrane encloses ---------------------------------- */

/* The curve's points belong to the inside, as a surface's do (a point on
 * the polygon's edge is in or out by the crossing rule; seeds are not
 * placed on the membrane). */
static bool polygon_contains(const gm_shape *s, const double x[3]) {
  return gm_polygon_contains(&s->polygon, x);
}

static bool polygon_outside_contains(const gm_shape *s, const double x[3]) {
  return !gm_polygon_contains(&s->polygon, x);
}

static void polygon_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  for (int c = 0; c < 3; c++) lo[c] = hi[c] = 0;
  for (int c = 0; c < 2; c++) {
    lo[c] = INFINITY;
    hi[c] = -INFINITY;
  }
  for (long k = 0; k < s->polygon.n; k++)
    for (int c = 0; c < 2; c++) {
      lo[c] = fmin(lo[c], s->polygon.xy[2 * k + c]);
      hi[c] = fmax(hi[c], s->polygon.xy[2 * k + c]);
    }
}

static void polygon_release(gm_shape *s) { gm_polygon_free(&s->polygon); }

static const shape_kind polygon_inside_kind = {.key = "inside",
                                               .thread_safe = true,
                                               .contains = polygon_contains,
                                               .bounds = polygon_bounds,
                                               .release = polygon_release};
static const shape_kind polygon_outside_kind = {.key = "outside",
                                                .thread_safe = true,
                                                .contains =
                                                    polygon_outside_contains,
                                                .release = polygon_release};

pm_err gm_shape_from_curve(long n, const double *x, bool closed,
                           const double box_min[3], const double box_max[3],
                           bool outside, gm_shape **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_shape_from_curve: out is NULL");
  *out = NULL;
  pm_err ret = PM_SUCCESS;
  gm_shape *shape = NULL;
  PM_TRY(PM_ALLOC(shape, 1, "shape"));
  shape->kind = outside ? &polygon_outside_kind : &polygon_inside_kind;
  shape->dim = 2;
  double tol = 0;
  for (int c = 0; c < 2; c++)
    tol = fmax(tol, GM_SHAPE_BOX_TOL * 1e3 * (box_max[c] - box_min[c]));
  PM_TRY(
      gm_curve_polygon(n, x, closed, box_min, box_max, tol, &shape->polygon));
  *out = shape;
  shape = NULL;
done:
  gm_shape_destroy(shape);
  return ret;
}

/* ---- the table ---------------------------------------------------------- */

static const shape_kind kinds[] = {
    [PM_BODY_DOMAIN] = {"domain", true, domain_init, box_contains, NULL, NULL},
    [PM_BODY_REGION] = {"region", false, region_init, region_contains, NULL,
                        NULL},
    [PM_BODY_BOX] = {"box", true, box_init, box_contains, box_bounds, NULL},
    [PM_BODY_SPHERE] = {"sphere", true, sphere_init, sphere_contains,
                        sphere_bounds, NULL},
    [PM_BODY_CYLINDER] = {"cylinder", true, cylinder_init, cylinder_contains,
                          cylinder_bounds, NULL},
    [PM_BODY_MESH] = {"mesh", true, mesh_init, mesh_contains, mesh_bounds,
                      mesh_release},
    [PM_BODY_IMAGE] = {"image", true, image_init, image_contains, image_bounds,
                       image_release},
};

#define N_KINDS ((int)(sizeof kinds / sizeof kinds[0]))

pm_err gm_shape_create(const pm_scene_body *body, int dim,
                       const double box_min[3], const double box_max[3],
                       double h, gm_shape **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_shape_create: out is NULL");
  *out = NULL;
  PM_CHECK(body && box_min && box_max, PM_ERR_ARG,
           "gm_shape_create: NULL body or domain box");
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "shape dimension must be 2 or 3 (got %d)", dim);
  const int k = (int)body->shape;
  PM_CHECK(k >= 0 && k < N_KINDS && kinds[k].contains, PM_ERR_UNSUPPORTED,
           "body shape kind %d has no geometry", k);
  for (int c = 0; c < dim; c++)
    PM_CHECK(isfinite(box_min[c]) && isfinite(box_max[c]) &&
                 box_max[c] > box_min[c],
             PM_ERR_ARG, "empty domain box along %c: [%g, %g]", "xyz"[c],
             box_min[c], box_max[c]);
  pm_err ret = PM_SUCCESS;
  gm_shape *s = NULL;
  PM_TRY(PM_ALLOC(s, 1, "shape"));
  s->kind = &kinds[k];
  s->dim = dim;
  for (int c = 0; c < dim; c++) {
    s->lo[c] = box_min[c];
    s->hi[c] = box_max[c];
  }
  PM_TRY(s->kind->init(s, body, h));
  *out = s;
  s = NULL;
done:
  gm_shape_destroy(s);
  return ret;
}

pm_err gm_shape_from_image(const gm_image *im, const pm_scene_body *body,
                           int dim, gm_shape **out, const char **key) {
  PM_CHECK(out && key, PM_ERR_ARG, "gm_shape_from_image: out is NULL");
  *out = NULL;
  *key = "image";
  PM_CHECK(im && body, PM_ERR_ARG, "gm_shape_from_image: no image or body");
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "shape dimension must be 2 or 3 (got %d)", dim);
  pm_err ret = PM_SUCCESS;
  gm_shape *s = NULL;
  PM_TRY(PM_ALLOC(s, 1, "shape"));
  s->kind = &kinds[PM_BODY_IMAGE];
  s->dim = dim;
  PM_TRY(gm_image_body_part(im, body, dim, &s->part, key));
  *out = s;
  s = NULL;
done:
  gm_shape_destroy(s);
  return ret;
}

const gm_image_part *gm_shape_image(const gm_shape *s) {
  return s && s->kind == &kinds[PM_BODY_IMAGE] ? &s->part : NULL;
}

void gm_shape_destroy(gm_shape *s) {
  if (!s) return;
  if (s->kind && s->kind->release) s->kind->release(s);
  free(s);
}

bool gm_shape_contains(const gm_shape *s, const double x[3]) {
  return s && x && s->kind->contains(s, x);
}

bool gm_shape_bounds(const gm_shape *s, double lo[3], double hi[3]) {
  if (!s || !s->kind->bounds || !lo || !hi) return false;
  for (int k = 0; k < 3; k++) lo[k] = hi[k] = 0;
  s->kind->bounds(s, lo, hi);
  for (int k = s->dim; k < 3; k++) lo[k] = hi[k] = 0;
  return true;
}

const char *gm_shape_kind(const gm_shape *s) { return s ? s->kind->key : "?"; }

bool gm_shape_thread_safe(const gm_shape *s) {
  return s && s->kind->thread_safe;
}

int gm_shape_last_containing(const gm_shape *const *shapes, int n,
                             const double x[3]) {
  if (!shapes) return -1;
  for (int b = n - 1; b >= 0; b--)
    if (gm_shape_contains(shapes[b], x)) return b;
  return -1;
}

pm_err gm_shape_check_inside(const gm_shape *s, int body,
                             const double box_min[3], const double box_max[3]) {
  double lo[3], hi[3];
  if (!gm_shape_bounds(s, lo, hi)) return PM_SUCCESS;
  for (int c = 0; c < s->dim; c++) {
    double tol = GM_SHAPE_BOX_TOL * (box_max[c] - box_min[c]);
    if (lo[c] < box_min[c] - tol || hi[c] > box_max[c] + tol)
      return PM_ERROR(PM_ERR_SCENE,
                      "bodies.%d.%s: expected a shape inside domain.box (%c "
                      "in [%g, %g]), got one reaching %c = %g",
                      body, s->kind->key, "xyz"[c], box_min[c], box_max[c],
                      "xyz"[c], lo[c] < box_min[c] - tol ? lo[c] : hi[c]);
  }
  return PM_SUCCESS;
}
