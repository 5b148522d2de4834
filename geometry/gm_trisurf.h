/* gm_trisurf: triangulated surfaces for membranes and for seeding bodies
 * inside or outside a closed surface: built-in shapes (a flat rectangle, a
 * subdivided icosahedron), gmsh-readable files (.msh, .stl, ...), and what
 * a membrane needs of them (areas per point, point-to-triangle incidence,
 * closedness and orientation). */
#ifndef GM_TRISURF_H
#define GM_TRISURF_H

#include <stdbool.h>
#include <stddef.h>

#include "pm_error.h"

/* A triangulated surface.  Triangles list their corners counter-clockwise
 * seen from the side their normal points to: outward for a closed surface
 * once oriented (gm_trisurf_orient_outward). */
typedef struct {
  long n_points;
  double *x; /* 3 per point */
  long n_tris;
  long *tri; /* 3 point indices per triangle, in [0, n_points) */
} gm_trisurf;

/* A flat rectangle: nu x nv points origin + i/(nu-1) edge_u + j/(nv-1)
 * edge_v (i fastest), 2 (nu - 1)(nv - 1) triangles with normal along
 * edge_u x edge_v.  PM_ERR_ARG for nu or nv < 2 or parallel edges. */
pm_err gm_trisurf_rectangle(const double origin[3], const double edge_u[3],
                            const double edge_v[3], long nu, long nv,
                            gm_trisurf *out);

/* A sphere: the icosahedron subdivided `refinement` times (each triangle
 * into four, new points pushed out to the sphere): 10 4^r + 2 points and
 * 20 4^r triangles (r = 6: 40962 points, 81920 triangles), normals
 * outward.  PM_ERR_ARG for radius <= 0 or refinement outside [0, 9]. */
pm_err gm_trisurf_sphere(const double center[3], double radius, int refinement,
                         gm_trisurf *out);

/* The 2-D elements of a file gmsh 4.8 reads as a mesh (.msh, .stl, .ply,
 * .ply2, .vtk, .wrl/.vrml, .mesh, .unv, .bdf/.nas, .med, .cgns; gmsh reads
 * neither .obj nor .off):
 * triangles (higher-order ones by their corners; quadrangles split in two
 * along their first diagonal), points that coincide within 1e-10 of the
 * bounding box's diagonal merged (an STL repeats them), unused points
 * dropped, degenerate triangles (a repeated corner after merging, or an
 * area below 1e-12 of the longest edge squared) dropped.  The file's
 * orientation is kept.  gmsh is initialised and finalised by the call.
 * Errors name the file: PM_ERR_IO (missing, unreadable, a directory),
 * PM_ERR_MESH (gmsh fails, no surface element, every element degenerate,
 * 2-D elements other than triangles and quadrangles), PM_ERR_MEMORY.  On
 * failure out holds nothing.  Not thread-safe (gmsh keeps global state);
 * must not run inside another gmsh session. */
pm_err gm_trisurf_load(const char *path, gm_trisurf *out);
/* The same in the process itself (gm_trisurf_load runs it in a child
 * process: gm_gmsh.h). */
pm_err gm_trisurf_load_here(const char *path, gm_trisurf *out);

/* Release the arrays (and zero s); NULL accepted. */
void gm_trisurf_free(gm_trisurf *s);

/* Each point's share of the area: a third of each incident triangle's
 * area, into area[n_points].  The sum is the surface's area. */
void gm_trisurf_point_areas(const gm_trisurf *s, double *area);

/* Point-to-triangle incidence as compressed rows: the triangles of point
 * p are tris[start[p] .. start[p + 1]) (start has n_points + 1 entries),
 * in increasing order.  Arrays malloc'd, owned by the caller.
 * PM_ERR_MEMORY on failure. */
pm_err gm_trisurf_incidence(const gm_trisurf *s, long **start, long **tris);

/* Whether s is closed and consistently oriented: every edge is shared by
 * exactly two triangles that run it in opposite directions.  When not,
 * writes the reason into why (e.g. "edge (12, 40) belongs to 1 triangle
 * (7): the surface has a hole", "... to 3 triangles (7, 8, 30): the
 * surface is not a manifold", "triangles 5 and 9 run edge (3, 4) the same
 * way: inconsistent orientation"; also a triangle repeating a point or
 * naming one out of range, or no triangle).  why may be NULL. */
bool gm_trisurf_closed(const gm_trisurf *s, char *why, size_t size);

/* Signed enclosed volume (positive when the normals point outward) of a
 * closed surface. */
double gm_trisurf_volume(const gm_trisurf *s);

/* Reverse every triangle when the enclosed volume is negative, so that the
 * normals point outward.  For a closed, consistently oriented surface. */
void gm_trisurf_orient_outward(gm_trisurf *s);

/* Bounding box of the points. */
void gm_trisurf_bounds(const gm_trisurf *s, double lo[3], double hi[3]);

#endif
