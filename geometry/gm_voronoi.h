/* gm_voronoi: the Voronoi cells of scattered points clipped to a box, as FPM
 * subdomains (a gm_dual), through CGAL's Delaunay triangulation (C++17
 * inside geometry/cgal, behind this C interface). */
#ifndef GM_VORONOI_H
#define GM_VORONOI_H

#include "gm_dual.h"
#include "pm_error.h"

/* A face whose area is below this fraction of the typical face area
 * ((box volume / n)^((dim - 1) / dim)) is dropped: two cells that touch
 * along an edge or at a corner of a degenerate (cospherical) point set,
 * such as a lattice, share such a face of round-off size. */
#define GM_VORONOI_TINY_FACE 1e-12

/* A cell whose quality (216 V^2 / S^3 in 3D, 16 A / P^2 in 2D: 1 for a
 * cube or a square, 1.91 and 1.27 for a ball and a disc) is below this is
 * a sliver: a flat cell about 1/11 (3D) or 1/20 (2D) as thick as it is
 * wide. */
#define GM_VORONOI_SLIVER 0.2

/* Voronoi cells of the n points x (3 coordinates each, z = 0 in 2D)
 * clipped to the box [lo, hi] (dim 2: the rectangle in the z = 0 plane,
 * lo[2] and hi[2] ignored), as a gm_dual:
 *   volume      the clipped cell's volume (its area in 2D);
 *   interfaces  one per pair of Voronoi neighbours whose shared face keeps
 *               a positive area after clipping: the planar polygon's area
 *               vector (from i to j), first moment a (x) c, centroid c and
 *               area; the adjacency lists these neighbours (the supports);
 *   facets      one per cell face on the box: area vector (outward),
 *               moment, centroid, area, and facet_surface = the entry of
 *               face_surface for its box face (indexed by pm_face: xmin,
 *               xmax, ymin, ymax, zmin, zmax), or the pm_face value itself
 *               when face_surface is NULL.
 * Faces below GM_VORONOI_TINY_FACE of the typical face are dropped (the
 * closure error that leaves is below that fraction); the volume of a cell
 * is the one its faces enclose (one third of the trace of sum over faces of
 * the moments about the point: two in 2D), so the volume, area vectors and
 * moments integrate constant and linear fields consistently.  The report
 * fields of the dual count the faces dropped and the slivers, and name the
 * cell of lowest quality.
 * Refused with PM_ERR_ARG: NULL arguments, n < 1, a box without volume,
 * a non-finite coordinate, a point outside the box by more than 1e-10 of
 * its size, two points closer than 1e-10 of the mean spacing (duplicates);
 * the message names the point indices and coordinates.  PM_ERR_GEOMETRY:
 * a cell without volume or whose faces do not close (not expected of
 * points inside the box).  PM_ERR_MEMORY.  CGAL's exceptions become
 * PM_ERR_GEOMETRY with CGAL's message: none leaves this interface.  On
 * success *out is a new dual the caller frees with gm_dual_destroy; on
 * failure *out is NULL.  Deterministic for given inputs. */
pm_err gm_voronoi_build(int dim, long n, const double *x, const double lo[3],
                        const double hi[3], const int *face_surface,
                        gm_dual **out);

#endif
