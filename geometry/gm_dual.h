/* gm_dual: simplex meshes of a box (3D, tetrahedra) or rectangle (2D,
 * triangles) made with gmsh, and their median-dual subdomains: one cell per
 * mesh node, interfaces between edge neighbours, boundary facets. */
#ifndef GM_DUAL_H
#define GM_DUAL_H

#include "pm_error.h"
#include "pm_face.h"

/* A simplex mesh.  Coordinates are 3 per node (z = 0 in 2D). */
typedef struct {
  int dim; /* 2 or 3 */
  long n_nodes;
  double *x; /* 3 * n_nodes */
  long n_cells;
  int nodes_per_cell; /* 3 (triangles) or 4 (tetrahedra) */
  long *cells;        /* nodes_per_cell * n_cells, 0-based, positive volume */
  double box_min[3], box_max[3];
} gm_mesh;

/* Median-dual subdomains of a gm_mesh.  Each node gets exactly V/4 (3D) or
 * A/3 (2D) of each incident simplex.  In 2D "area" means length per unit
 * thickness and "volume" area per unit thickness.
 *
 * Interface e between nodes i < j (a mesh edge): union of the triangles
 * (edge midpoint, face centroid, element centroid) of every element sharing
 * the edge (in 2D: the segments (edge midpoint, element centroid)).
 *   area_vec  a_e = sum_t a_t, oriented from i to j (3 per interface)
 *   moment    M_e = sum_t a_t (x) c_t, row-major M[3a+b] = sum a_t[a] c_t[b],
 *             c_t the triangle (segment) centroid (9 per interface)
 *   centroid  x_e = sum |a_t| c_t / sum |a_t| (3 per interface)
 *   area      sum |a_t| (1 per interface)
 * Boundary facet f of node i: the part of the dual cell boundary on the
 * domain boundary, one per (boundary simplex face, node) pair: in 3D the
 * quadrilateral (node, two edge midpoints, face centroid) split into two
 * triangles, in 2D the half boundary edge.  Same quantities, area vector
 * pointing outward, and the box face it lies on.
 * For every node, sum of its interface area vectors (signed outward from
 * the node) plus its facet area vectors is zero to round-off. */
typedef struct {
  int dim;
  long n_points;
  double *x;      /* 3 * n_points: reference positions (mesh nodes) */
  double *volume; /* n_points */
  /* adjacency (CSR): neighbours of point i are nbr[nbr_ptr[i] .. nbr_ptr[i+1]),
   * sorted ascending; nbr_iface[k] is the interface shared with nbr[k]. */
  long *nbr_ptr; /* n_points + 1 */
  long *nbr;
  long *nbr_iface;
  long n_ifaces;
  long *if_pair;       /* 2 * n_ifaces: (i, j), i < j */
  double *if_area_vec; /* 3 * n_ifaces */
  double *if_moment;   /* 9 * n_ifaces */
  double *if_centroid; /* 3 * n_ifaces */
  double *if_area;     /* n_ifaces */
  long n_facets;
  long *facet_point;      /* n_facets */
  int *facet_face;        /* n_facets: pm_face, or PM_FACE_NONE */
  double *facet_area_vec; /* 3 * n_facets, outward */
  double *facet_moment;   /* 9 * n_facets */
  double *facet_centroid; /* 3 * n_facets */
  double *facet_area;     /* n_facets */
} gm_dual;

/* Mesh the box [min, max] (dim 3: tetrahedra; dim 2: triangles in the z = 0
 * plane, min[2] and max[2] ignored) with gmsh at target element size h.
 * Deterministic for given inputs.  Fails with PM_ERR_ARG for h <= 0 or an
 * empty box and PM_ERR_MESH when gmsh fails (message quotes gmsh). */
pm_err gm_mesh_box(int dim, const double min[3], const double max[3], double h,
                   gm_mesh **out);
/* Build a mesh from given arrays (copied); cells with negative volume are
 * reoriented; fails with PM_ERR_GEOMETRY for a zero-volume cell. */
pm_err gm_mesh_from_arrays(int dim, long n_nodes, const double *x, long n_cells,
                           const long *cells, const double box_min[3],
                           const double box_max[3], gm_mesh **out);
void gm_mesh_destroy(gm_mesh *m);

/* Median-dual subdomains of mesh m.  Boundary facets are tagged with the
 * box face they lie on (relative tolerance 1e-9 of the box size). */
pm_err gm_dual_build(const gm_mesh *m, gm_dual **out);
void gm_dual_destroy(gm_dual *d);

/* Mean mesh edge length (a resolution figure to report). */
double gm_mesh_mean_edge(const gm_mesh *m);

#endif
