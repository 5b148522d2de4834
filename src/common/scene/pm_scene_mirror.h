/* pm_scene_mirror: a scene that models the part of a body on one side of
 * its symmetry planes (boundary conditions with symmetry: true), and the
 * whole body's figures from the part's.  A plane normal to axis a lies at
 * s->mirror_at[a] on a face of the domain's box; the part is the box's
 * side of it. */
#ifndef PM_SCENE_MIRROR_H
#define PM_SCENE_MIRROR_H

#include <math.h>
#include <stdbool.h>

#include "pm_scene.h"

/* The whole body's force component comp on a face from the part's: for
 * every plane, the face's image is the face itself (x2: the image carries
 * the same component, 0 for the component normal to the plane, which
 * cancels) unless the face is parallel to the plane (face_axis == its
 * axis: the image is the opposite face, x1).  face_axis -1: a boundary of
 * no known orientation (a region, a named surface, a sphere), taken to
 * cross every plane; its component across a plane is then not known
 * (NaN: it cancels if the boundary crosses the plane, it is the part's
 * own if it lies beside it). */
static inline double pm_scene_mirror_factor(const pm_scene *s, int face_axis,
                                            int comp) {
  double f = 1;
  for (int a = 0; a < 3; a++)
    if ((s->mirror_mask >> a & 1u) && a != face_axis) {
      if (a == comp && face_axis < 0) return (double)NAN;
      f *= a == comp ? 0 : 2;
    }
  return f;
}

/* The axis a boundary condition's face is normal to: a face of the box's,
 * a plate's normal along an axis; -1 otherwise. */
static inline int pm_scene_bc_axis(const pm_scene_bc *bc) {
  if (bc->on == PM_ON_FACE) return pm_face_axis(bc->face);
  if (bc->on == PM_ON_PLATE)
    for (int a = 0; a < 3; a++)
      if (fabs(bc->rigid_normal[a]) > 1 - 1e-12) return a;
  return -1;
}

/* Whether the part lies above the plane normal to axis a (on the side of
 * larger coordinates), which lies on a face of the box: the part is the
 * box's side of it. */
static inline bool pm_scene_mirror_above(const pm_scene *s, int a) {
  return s->mirror_at[a] <= 0.5 * (s->box_min[a] + s->box_max[a]);
}

/* The point of the part whose image is x (x itself in the part): y, and
 * the axes along which it was reflected (a bit each). */
static inline unsigned pm_scene_mirror_fold(const pm_scene *s,
                                            const double x[3], double y[3]) {
  unsigned flips = 0;
  for (int a = 0; a < 3; a++) {
    y[a] = x[a];
    if (!(s->mirror_mask >> a & 1u)) continue;
    const double at = s->mirror_at[a];
    if (pm_scene_mirror_above(s, a) ? x[a] < at : x[a] > at) {
      y[a] = 2 * at - x[a];
      flips |= 1u << a;
    }
  }
  return flips;
}

/* A vector field's value at the image from the part's, in place. */
static inline void pm_scene_mirror_unfold(unsigned flips, double v[3]) {
  for (int a = 0; a < 3; a++)
    if (flips >> a & 1u) v[a] = -v[a];
}

#endif
