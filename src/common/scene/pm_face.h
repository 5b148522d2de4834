/* pm_face: names of the faces of a box (3D) or rectangle (2D) domain, used to
 * put boundary conditions on named faces. */
#ifndef PM_FACE_H
#define PM_FACE_H

typedef enum {
  PM_FACE_XMIN = 0,
  PM_FACE_XMAX,
  PM_FACE_YMIN,
  PM_FACE_YMAX,
  PM_FACE_ZMIN,
  PM_FACE_ZMAX,
  PM_FACE_COUNT,
  PM_FACE_NONE = -1
} pm_face;

/* "xmin" ... "zmax"; "none" for PM_FACE_NONE. */
static inline const char *pm_face_name(int face) {
  static const char *const names[] = {"xmin", "xmax", "ymin",
                                      "ymax", "zmin", "zmax"};
  return (face >= 0 && face < PM_FACE_COUNT) ? names[face] : "none";
}

/* The axis a face is normal to (0, 1, 2) and the coordinate of its plane
 * for the box [lo, hi]. */
static inline int pm_face_axis(int face) { return face / 2; }
static inline double pm_face_plane(int face, const double lo[3],
                                   const double hi[3]) {
  return (face % 2) ? hi[face / 2] : lo[face / 2];
}

#endif
