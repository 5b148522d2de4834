/* gm_mesh: simplex meshes (tetrahedra in 3D, triangles in 2D) of a box made
 * with gmsh, of a gmsh-readable file, or of caller arrays, with the named
 * boundary surfaces that boundary conditions are put on. */
#ifndef GM_MESH_H
#define GM_MESH_H

#include <stdbool.h>
#include <stddef.h>

#include "gm_gmsh.h"
#include "pm_error.h"
#include "pm_face.h"

/* A simplex mesh.  Coordinates are 3 per node (z = 0 in 2D).
 *
 * Boundary surfaces: surface s is named surface_name[s]; face o of cell c
 * (the face opposite its local node o, nodes_per_cell faces per cell) lies
 * on surface face_surface[nodes_per_cell * c + o], -1 for none.  Only the
 * entries of boundary faces (faces of one cell) mean anything: they are all
 * gm_dual reads.  A mesh of a box names its faces "xmin", "xmax", "ymin",
 * "ymax" (, "zmin", "zmax") with surface index equal to the pm_face value;
 * a mesh of a file names the physical groups of dimension dim - 1. */
typedef struct {
  int dim; /* 2 or 3 */
  long n_nodes;
  double *x; /* 3 * n_nodes */
  long n_cells;
  int nodes_per_cell; /* 3 (triangles) or 4 (tetrahedra) */
  long *cells;        /* nodes_per_cell * n_cells, 0-based, positive volume */
  double box_min[3], box_max[3]; /* the box meshed (gm_mesh_box), given
                                    (gm_mesh_from_arrays) or bounding the
                                    nodes (gm_mesh_file); z = 0 in 2D */
  int n_surfaces;
  char **surface_name; /* n_surfaces, owned */
  int *face_surface;   /* nodes_per_cell * n_cells, or NULL: no surfaces */
  bool meshed;         /* gm_mesh_file: gmsh meshed the file (it held no
                          mesh: else used as it is) */
  double size_factor;  /* then: what multiplied the file's own sizes (0:
                          replaced by h; gm_sizes) */
} gm_mesh;

/* Mesh the box [min, max] (dim 3: tetrahedra; dim 2: triangles in the z = 0
 * plane, min[2] and max[2] ignored) with gmsh at target element size h, and
 * name its faces (see gm_mesh).  Nodes are in Morton order of the box, cells
 * positively oriented.  Deterministic for given inputs.  On success *out is
 * a new mesh the caller frees with gm_mesh_destroy; on failure *out is NULL
 * and the error is PM_ERR_ARG for h <= 0 or an empty box, PM_ERR_MESH when
 * gmsh fails (message quotes gmsh), PM_ERR_MEMORY.  Not thread-safe: gmsh
 * keeps global state, initialized and finalized here. */
pm_err gm_mesh_box(int dim, const double min[3], const double max[3], double h,
                   gm_mesh **out);

/* A grading of a box mesh toward some of its faces, or toward the edges
 * bounding them: element size `size` on them, growing linearly with the
 * distance d from the nearest of them to the box's own size h at
 * d >= distance. */
typedef struct {
  unsigned faces;  /* bit f: face f (xmin = 0 ... zmax = 5, as pm_face); 0:
                      no grading */
  double size;     /* element size on the faces (edges), 0 < size <= h */
  double distance; /* where the size reaches h, > 0 */
  bool edges;      /* false: d is the distance to the faces; true: to the
                      edges bounding them (the corners in 2D) */
} gm_grade;

/* gm_mesh_box with the element size graded by g (gmsh's Distance and
 * Threshold fields as the background mesh); g NULL or g->faces 0: as
 * gm_mesh_box.  Errors as gm_mesh_box, and PM_ERR_ARG for a size outside
 * (0, h], a distance <= 0 or a face the dimension has not. */
pm_err gm_mesh_box_graded(int dim, const double min[3], const double max[3],
                          double h, const gm_grade *g, gm_mesh **out);

/* The nodes and elements gmsh makes of the box graded by g (g may be
 * NULL), as gm_gmsh_read leaves them: gm_mesh_box_raw meshes in a child
 * process (pm_isolate.h; gm_gmsh_isolate.c), gm_mesh_box_raw_here in the
 * process.  The arguments are gm_mesh_box_graded's, checked by it. */
pm_err gm_mesh_box_raw(int dim, const double min[3], const double max[3],
                       double h, const gm_grade *g, gm_gmsh_mesh *raw);
pm_err gm_mesh_box_raw_here(int dim, const double min[3], const double max[3],
                            double h, const gm_grade *g, gm_gmsh_mesh *raw);

/* The element size g asks at x in the box [min, max] of a mesh of size h
 * (h where g is NULL or grades no face). */
double gm_grade_size(const gm_grade *g, int dim, const double min[3],
                     const double max[3], double h, const double x[3]);

/* Mesh the volume (the surface in the z = 0 plane in 2D) of a gmsh-readable
 * file (.geo, .msh, .step/.stp, .brep), read and meshed as gm_volume_load
 * does (same h rule: a mesh in the file is used as it is; otherwise gmsh
 * meshes it at size h by rule, or at the file's own sizes for h <= 0;
 * higher-order elements count through their corners).  Its surfaces are the
 * physical groups of dimension dim - 1 (Physical Surface in 3D, Physical Curve
 * in 2D), in gmsh's order (by tag), named by their physical names
 * ("surface-TAG" for a group without one).  A boundary face takes
 * the surface of the group element with the same nodes (of the last such
 * group in gmsh's order), -1 when none has them; group elements that are
 * not boundary faces of the mesh are ignored.  Nodes are in Morton order of
 * the bounding box, cells positively oriented.  On success *out is a new
 * mesh (gm_mesh_destroy); on failure *out is NULL and the error names the
 * file: PM_ERR_ARG (bad arguments), PM_ERR_IO (missing, unreadable, a
 * directory), PM_ERR_MESH (gmsh fails, no element of dimension dim, 2D
 * triangles off z = 0), PM_ERR_UNSUPPORTED (non-simplex elements in the
 * volume or in a group), PM_ERR_GEOMETRY (a flat cell), PM_ERR_MEMORY.  Not
 * thread-safe, like gm_mesh_box. */
pm_err gm_mesh_file(const char *path, int dim, double h, gm_sizes rule,
                    gm_mesh **out);

/* Build a mesh from given arrays (copied): x holds 3 coordinates per node,
 * cells dim + 1 nodes per cell (0-based).  Cells with negative volume are
 * reoriented and the box [box_min, box_max] names its faces as gm_mesh_box
 * does (faces on the box planes, within 1e-9 of the box size).  On success
 * *out is a new mesh (gm_mesh_destroy); fails with PM_ERR_ARG for bad
 * arguments (node index out of range, non-finite coordinate, empty box),
 * PM_ERR_GEOMETRY for a zero-volume cell, PM_ERR_MEMORY. */
pm_err gm_mesh_from_arrays(int dim, long n_nodes, const double *x, long n_cells,
                           const long *cells, const double box_min[3],
                           const double box_max[3], gm_mesh **out);

/* Frees the mesh and everything it owns; NULL is a no-op. */
void gm_mesh_destroy(gm_mesh *m);

/* Mean mesh edge length, each edge counted once (a resolution figure to
 * report); NAN for an empty mesh or when memory runs out. */
double gm_mesh_mean_edge(const gm_mesh *m);

/* Volume (3D) or area (2D) of the mesh: the sum of its cells' measures;
 * 0 for NULL or an empty mesh. */
double gm_mesh_volume(const gm_mesh *m);

/* Index of the surface called name, or -1 (no such surface, NULL
 * arguments).  Names compare exactly. */
int gm_mesh_surface_find(const gm_mesh *m, const char *name);

/* Name of surface s, or NULL when s is out of range. */
const char *gm_mesh_surface_name(const gm_mesh *m, int s);

/* The surface names for a message, ", "-separated ("xmin, xmax, ...";
 * "(none)" for a mesh without surfaces), written into buf of size bytes
 * (truncated with "..." when it does not fit; nothing for size 0).  Returns
 * buf. */
char *gm_mesh_surface_list(const gm_mesh *m, char *buf, size_t size);

#endif
