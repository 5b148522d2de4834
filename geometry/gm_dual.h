/* gm_dual: FPM subdomains, one cell per point, with the interfaces between
 * neighbouring cells and the boundary facets tagged with the mesh's named
 * surfaces; built here as the median duals of a simplex mesh (other
 * builders fill the same struct: gm_voronoi). */
#ifndef GM_DUAL_H
#define GM_DUAL_H

#include <stdbool.h>

#include "gm_mesh.h"
#include "pm_error.h"

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
 * pointing outward, and the mesh surface it lies on (gm_mesh face_surface of
 * its simplex face: for a box mesh the pm_face value).
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
  int *facet_surface;     /* n_facets: surface index of the mesh, -1 none */
  double *facet_area_vec; /* 3 * n_facets, outward */
  double *facet_moment;   /* 9 * n_facets */
  double *facet_centroid; /* 3 * n_facets */
  double *facet_area;     /* n_facets */
  /* What the builder reports of the cells' shapes (zeros from a builder
   * that does not assess them): */
  long n_dropped_faces;   /* faces of round-off size dropped */
  long n_slivers;         /* cells below the builder's quality bound */
  double min_quality;     /* the lowest cell quality (1 for a cube) */
  long min_quality_point; /* its point, -1 when not assessed */
} gm_dual;

/* Median-dual subdomains of mesh m (read during the call only: the dual
 * keeps copies of what it needs).  On success *out is a new dual the
 * caller frees with gm_dual_destroy; on failure *out is NULL and the error
 * is PM_ERR_ARG (NULL or inconsistent mesh), PM_ERR_GEOMETRY (a node in no
 * cell, a badly oriented cell, a zero-area interface or facet) or
 * PM_ERR_MEMORY. */
pm_err gm_dual_build(const gm_mesh *m, gm_dual **out);

/* For cell builders: sets d->n_facets = nf and allocates the facet arrays
 * (zeroed; none for nf = 0).  PM_ERR_MEMORY when they do not fit: the
 * arrays allocated stay for gm_dual_destroy. */
pm_err gm_dual_alloc_facets(gm_dual *d, long nf);

/* Frees the dual and all its arrays; NULL is a no-op. */
void gm_dual_destroy(gm_dual *d);

/* Let d's interfaces go (nbr_iface and the if_ arrays NULL, n_ifaces 0)
 * and, or, its boundary facets (the facet_ arrays NULL, n_facets 0); its
 * points and rows stay.  For a part of the cells whose model no longer
 * reads them. */
void gm_dual_drop(gm_dual *d, bool interfaces, bool facets);

#endif
