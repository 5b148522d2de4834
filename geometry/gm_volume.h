/* gm_volume: a solid read from a gmsh-readable file (meshed by gmsh when it
 * has no mesh) and fast point-in-solid queries for seeding particles. */
#ifndef GM_VOLUME_H
#define GM_VOLUME_H

#include <stdbool.h>

#include "gm_gmsh.h"
#include "pm_error.h"

/* A volume: linear simplices (tetrahedra in 3D, triangles in the z = 0
 * plane in 2D) with a uniform bucket grid for point location.  Immutable
 * after gm_volume_load. */
typedef struct gm_volume gm_volume;

/* Load a gmsh-readable file (.msh, .geo, .step/.stp, .brep).  If it holds no
 * mesh of dimension dim (2 or 3), mesh it with gmsh at element size h by
 * rule (gm_gmsh_sizes; h <= 0: the file's and gmsh's own size settings);
 * a mesh already in the
 * file is used as it is, whatever h.  Higher-order elements count through
 * their corner nodes; flat (zero-measure) elements are dropped.  In 2D the
 * triangles must lie in the z = 0 plane.
 * On success *out is a new volume the caller frees with gm_volume_destroy;
 * on failure *out is NULL and the error is:
 *   PM_ERR_ARG          bad arguments (NULL, dim not 2 or 3, h not finite)
 *   PM_ERR_IO           the file is missing, unreadable or a directory
 *   PM_ERR_MESH         gmsh fails (message quotes gmsh), no element of
 *                       dimension dim, or 2D triangles off the z = 0 plane
 *   PM_ERR_UNSUPPORTED  elements of dimension dim that are not simplices
 *                       (hexahedra, prisms, pyramids, quadrangles)
 *   PM_ERR_MEMORY
 * Not thread-safe: gmsh keeps global state.  Like gm_mesh_box, this
 * initializes gmsh, and finalizes it before returning (success or not), so
 * it must not run while another thread uses gmsh, nor while the caller has
 * a gmsh session of its own open.  The OpenMP thread count is restored. */
pm_err gm_volume_load(const char *path, int dim, double h, gm_sizes rule,
                      gm_volume **out);

/* Frees the volume; NULL is a no-op. */
void gm_volume_destroy(gm_volume *v);

/* True when x (3 components; x[2] ignored in 2D) lies in some element or on
 * its boundary, within a tolerance of 1e-12 of the element's size (points
 * on shared faces and on the outer surface count as inside).  False for NULL
 * arguments and non-finite x.  Thread-safe (read-only) and allocation-free;
 * O(1) on average for meshes of roughly uniform element size. */
bool gm_volume_contains(const gm_volume *v, const double x[3]);

/* Bounding box of the elements' corner nodes (z = 0 for both in 2D). */
void gm_volume_bounds(const gm_volume *v, double min[3], double max[3]);

/* Total measure of the elements: volume in 3D, area in 2D. */
double gm_volume_measure(const gm_volume *v);

/* Number of elements kept (non-flat simplices of dimension dim). */
long gm_volume_elements(const gm_volume *v);

/* Dimension the volume was loaded with (2 or 3). */
int gm_volume_dim(const gm_volume *v);

#endif
