/* gm_inside: which side of a closed triangulated surface a point lies on,
 * by CGAL's AABB tree and side-of-triangle-mesh test (C++17 inside
 * geometry/cgal, behind this C interface). */
#ifndef GM_INSIDE_H
#define GM_INSIDE_H

#include <stdbool.h>

#include "gm_trisurf.h"
#include "pm_error.h"

typedef struct gm_inside gm_inside;

/* Build the test for the closed surface s (copied: s may be freed after):
 * a CGAL surface mesh (a point where the surface touches itself is split
 * in two), its AABB tree, built here, and the side-of-triangle-mesh test
 * on that tree.  Whether the normals point out or in does not matter; the
 * surface must not intersect itself (not checked).  On success *out is a new
 * test the caller frees with gm_inside_destroy; on failure *out is NULL and the
 * error is PM_ERR_ARG (NULL arguments; s not closed and consistently
 * oriented, with the reason of gm_trisurf_closed; CGAL refusing the
 * surface, with its message) or PM_ERR_MEMORY.  No C++ exception leaves
 * this interface. */
pm_err gm_inside_create(const gm_trisurf *s, gm_inside **out);

/* True when x lies inside the surface or on it (exact predicates: a point
 * on a face, an edge or a corner is inside); false for NULL arguments and
 * non-finite x.  Thread-safe: queries only read the tree built in
 * gm_inside_create.  Allocation-free but for CGAL's exact arithmetic in
 * the rare near-degenerate case its interval filter cannot decide. */
bool gm_inside_contains(const gm_inside *in, const double x[3]);

/* Bounding box of the surface's triangles (zeros for NULL). */
void gm_inside_bounds(const gm_inside *in, double lo[3], double hi[3]);

/* Frees the test; NULL is a no-op. */
void gm_inside_destroy(gm_inside *in);

#endif
