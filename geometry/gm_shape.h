/* gm_shape: the shape of a scene body, whatever its kind (the domain, a
 * region expression, a box, a sphere, a cylinder, a gmsh volume, the inside
 * or outside of a closed surface, the labelled voxels of an image): whether
 * it contains a point, its bounding box, and checks on where it lies. */
#ifndef GM_SHAPE_H
#define GM_SHAPE_H

#include <stdbool.h>

#include "gm_image.h"
#include "gm_trisurf.h"
#include "pm_error.h"
#include "pm_scene.h"

/* The shape of one body.  Immutable after gm_shape_create.
 *
 * Thread safety: gm_shape_contains may run on one shape from several
 * threads at once when gm_shape_thread_safe says so, which is every kind
 * but the region: a region evaluates its libmatheval expression
 * (pm_expr_eval), which stores the point in the expression itself.  The
 * other queries only read the shape.  Creating and destroying are not
 * thread-safe for a mesh body (gmsh keeps global state). */
typedef struct gm_shape gm_shape;

/* The shape of body in a problem of dimension dim (2 or 3) whose domain
 * is the box [box_min, box_max] (z ignored in 2D).  Kinds and what is read
 * from body:
 *   PM_BODY_DOMAIN    the domain box (boundary included, within 1e-9 of
 *                     its size): every point a method asks about
 *   PM_BODY_REGION    region > 0 (region is borrowed: it must outlive the
 *                     shape; z = 0 in 2D)
 *   PM_BODY_BOX       a <= x <= b componentwise (a = min, b = max)
 *   PM_BODY_SPHERE    |x - a| <= radius (a disk in 2D)
 *   PM_BODY_CYLINDER  3D only: base a, axis b (base to top face), radius
 *   PM_BODY_MESH      the gmsh volume of file mesh (surface in 2D), read
 *                     with gm_volume_load at element size h (h <= 0: the
 *                     file's own sizes; a mesh in the file is used as is)
 *   PM_BODY_IMAGE     the voxels of the crop of the image (read with
 *                     gm_image_of_body) whose intensity is in the label
 *                     range (gm_image_body_part); bounds: the crop's box
 * Boundaries count as inside, but for a region: its zero set is outside,
 * and for an image: a voxel's upper faces are its neighbour's.
 * On success *out is a new shape the caller
 * frees with gm_shape_destroy; on failure *out is NULL and the error is
 * PM_ERR_ARG (NULL arguments, dim not 2 or 3, an empty domain box, a body
 * whose numbers make no shape: min >= max, radius <= 0, a zero axis, a
 * cylinder in 2D, no region or file, an image crop outside the image),
 * PM_ERR_UNSUPPORTED (a kind without geometry), PM_ERR_MEMORY, or
 * gm_volume_load's errors for a mesh body and the image readers' for an
 * image body (they name the file).  Not thread-safe for a mesh body. */
pm_err gm_shape_create(const pm_scene_body *body, int dim,
                       const double box_min[3], const double box_max[3],
                       double h, gm_shape **out);

/* The inside (outside false) or the outside (outside true) of the closed,
 * consistently oriented surface s, in 3D, for seeding particles: contains
 * is gm_inside_contains, or its negation for the outside, so a point on
 * the surface belongs to the inside and not to the outside.  Kinds
 * "inside" and "outside"; bounds are the surface's for the inside, none
 * (unbounded) for the outside; thread-safe.  s is copied (it may be freed
 * after).  On success *out is a new shape the caller frees with
 * gm_shape_destroy; on failure *out is NULL and the error is PM_ERR_ARG
 * (NULL arguments, or s not closed: the message gives gm_trisurf_closed's
 * reason) or PM_ERR_MEMORY. */
pm_err gm_shape_from_surface(const gm_trisurf *s, bool outside, gm_shape **out);

/* The inside (outside false) or the outside (outside true) of the region
 * a 2-D membrane encloses: the polygon of its n points x (3 each, in
 * order), closed directly when closed, else along the boundary of the box
 * [box_min, box_max] on which its ends lie (gm_curve_polygon, ends within
 * 1e-6 of the box's size).  Thread-safe; x is copied.  PM_ERR_GEOMETRY
 * (an open curve whose ends are not on the box's boundary: the message
 * says which end) or PM_ERR_MEMORY; *out NULL on failure. */
pm_err gm_shape_from_curve(long n, const double *x, bool closed,
                           const double box_min[3], const double box_max[3],
                           bool outside, gm_shape **out);

/* The shape of image body `body` on the image im, read once (by
 * gm_image_of_body) for every body that shares it: im is borrowed and must
 * outlive the shape.  Kind "image", thread-safe.  On failure *out is NULL
 * and the error is PM_ERR_ARG, PM_ERR_MEMORY or gm_image_body_part's
 * (with *key the key of the body's image at fault). */
pm_err gm_shape_from_image(const gm_image *im, const pm_scene_body *body,
                           int dim, gm_shape **out, const char **key);

/* The voxels of an image shape (for seeding them, gm_image_seeds), or
 * NULL for a shape of another kind. */
const gm_image_part *gm_shape_image(const gm_shape *s);

/* Frees the shape (and the volume of a mesh body, the inside test of a
 * surface); NULL is a no-op. */
void gm_shape_destroy(gm_shape *s);

/* True when x (3 components; z ignored in 2D) lies in the shape or on its
 * boundary (but for a region and the outside of a surface, whose boundary
 * is out); false for a NULL shape or point.  See gm_shape for threads. */
bool gm_shape_contains(const gm_shape *s, const double x[3]);

/* Axis-aligned box [lo, hi] holding the shape (components beyond dim are
 * 0); true when the shape has one.  False, with lo and hi untouched, for
 * the unbounded kinds: the domain (the whole problem), a region and the
 * outside of a surface. */
bool gm_shape_bounds(const gm_shape *s, double lo[3], double hi[3]);

/* The scene's word for the shape's kind: "domain", "region", "box",
 * "sphere", "cylinder", "mesh" or "image", or "inside" / "outside" for a shape
 * of gm_shape_from_surface ("?" for NULL). */
const char *gm_shape_kind(const gm_shape *s);

/* Whether gm_shape_contains may run on s from several threads at once
 * (false for a region, and for NULL). */
bool gm_shape_thread_safe(const gm_shape *s);

/* The last of shapes[0 .. n) containing x (later shapes take precedence,
 * as later bodies do in a scene), or -1 when none does.  NULL entries
 * contain nothing.  Thread-safe when every shape is. */
int gm_shape_last_containing(const gm_shape *const *shapes, int n,
                             const double x[3]);

/* Checks that a bounded shape lies in the box [box_min, box_max] within
 * 1e-9 of the box's size along each axis (unbounded shapes pass).  On
 * failure returns PM_ERR_SCENE with "bodies.BODY.KIND: expected a shape
 * inside domain.box (x in [LO, HI]), got one reaching x = V"; the caller
 * puts the file, line and column in front. */
pm_err gm_shape_check_inside(const gm_shape *s, int body,
                             const double box_min[3], const double box_max[3]);

#endif
