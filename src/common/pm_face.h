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

#endif
