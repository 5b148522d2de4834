/* gm_curve: membranes in 2-D and membranes given as bare points.
 *
 * A 2-D membrane is a line of points in order (a polyline, open or
 * closed); each point carries half the length of each segment it belongs
 * to (per unit depth).  A point cloud is a list of points with no
 * connectivity, each with its share of the area (3-D) or length (2-D),
 * read from a file. */
#ifndef GM_CURVE_H
#define GM_CURVE_H

#include <stdbool.h>

#include "pm_error.h"
#include "pm_expr.h"

/* Points (3 doubles each, z = 0 in 2-D) in order along a curve. */
typedef struct {
  long n;
  double *x;
  bool closed; /* the last point joins the first */
} gm_curve;

/* The curve (x(t), y(t)) for the parameter t in [t0, t1] (pm_expr
 * expressions in the variable t only), n points placed at equal arc length
 * (the arc length measured by the chords of 64 n equal steps of t and
 * inverted within a step: the point where the chord from the step's start
 * has the length left, every point on the curve itself).  closed: the
 * curve returns to its start (the point at t1 is then not repeated: n
 * points, n segments).  PM_ERR_ARG (n < 2, t0 or t1 not finite),
 * PM_ERR_EXPR (an expression not finite at some t), PM_ERR_GEOMETRY (zero
 * length, or closed but ending more than 1e-6 of its length away from its
 * start), PM_ERR_MEMORY. */
pm_err gm_curve_parametric(const pm_expr *xs, const pm_expr *ys, double t0,
                           double t1, long n, bool closed, gm_curve *out);

/* The curve through n given points (3 each, copied).  PM_ERR_ARG (fewer
 * than 2 points, 3 when closed), PM_ERR_GEOMETRY (a point not finite),
 * PM_ERR_MEMORY. */
pm_err gm_curve_from_points(long n, const double *x, bool closed,
                            gm_curve *out);

void gm_curve_free(gm_curve *c);

/* Each point's share of the curve's length: half of each segment it
 * belongs to (len: n; a closed curve's last segment joins its last point
 * to its first). */
void gm_curve_point_lengths(const gm_curve *c, double *len);

/* The curve's unit normals from its neighbours in the list (the tangent
 * x[k+1] - x[k-1], one-sided at the ends of an open curve, turned by -90
 * degrees: n = (t_y, -t_x, 0), which points outward for a curve running
 * counter-clockwise).  Points given by x (3 each, n of them, possibly
 * moved since the curve was made).  A point whose tangent vanishes gets
 * (0, 0, 0) and the function returns how many did.  Allocates nothing
 * (it runs every step). */
long gm_curve_normals(long n, const double *x, bool closed, double *normal);
/* The neighbours in the list of point k of n (prev and next, as
 * gm_curve_normals takes them: around a closed curve, the point itself at
 * an open curve's ends). */
void gm_curve_neighbours(long k, long n, bool closed, long *prev, long *next);
/* The unit normal of a point whose neighbours are at prev and next (as
 * gm_curve_normals gives it); false, with n = 0, when their chord
 * vanishes (or is not finite). */
bool gm_curve_normal(const double prev[3], const double next[3], double n[3]);

/* The region a 2-D membrane encloses, for `inside` and `outside` bodies:
 * the polygon of the points x (n, in order), closed
 *   - directly, when the curve is closed (lo and hi may then be NULL);
 *   - along the domain's boundary when its ends lie on the boundary of the
 *     box [lo, hi] (within tol): straight along one face when both ends are
 *     on the same face, through the corner two faces share when they are on
 *     adjacent faces (quarter symmetry; the corner is the polygon's last
 *     vertex);
 *   - otherwise, PM_ERR_GEOMETRY (an open curve encloses nothing; ends on
 *     opposite faces or corners leave the side ambiguous).
 * x and y only: z is ignored.  The polygon is copied into *poly (2 doubles
 * per vertex; the closing edge from the last vertex to the first is
 * implicit).  PM_ERR_ARG (n < 2, or < 3 closed), PM_ERR_MEMORY. */
typedef struct {
  long n;
  double *xy;
} gm_polygon;

pm_err gm_curve_polygon(long n, const double *x, bool closed,
                        const double lo[3], const double hi[3], double tol,
                        gm_polygon *poly);
void gm_polygon_free(gm_polygon *p);
/* Point-in-polygon (even-odd crossing rule; x[2] ignored).  Half-open:
 * each edge counts for a horizontal ray from x when its lower end is at
 * or below x and its upper end above, and where it crosses is computed
 * from the edge's lower end whichever way the polygon runs.  So a point on
 * an edge or vertex gets one answer, and polygons that tile the plane
 * hold every point exactly once (a rectangle keeps its lower and left
 * sides).  Allocates nothing; safe from several threads. */
bool gm_polygon_contains(const gm_polygon *p, const double x[3]);
/* The polygon's signed area (positive counter-clockwise). */
double gm_polygon_area(const gm_polygon *p);

/* A point cloud from a text file (.csv: comma-separated, .xyz or any other
 * extension: white-space separated; '#' starts a comment; a first line that
 * does not parse as numbers is a header and skipped: one with no number in
 * it at all, for a first line mixing numbers and words is a point with a
 * mistake).  Each line holds dim coordinates (x y, or x y z) and,
 * optionally, one more column: the point's area (3-D) or length (2-D),
 * positive.  Either every line has it or none does.  On a bad line,
 * PM_ERR_SCENE with "FILE:LINE:COL: expected ..., got ..." (pm_error_set;
 * LINE and COL from 1, COL in bytes); PM_ERR_SCENE also for a file without
 * points, PM_ERR_IO for one that cannot be read, PM_ERR_ARG for dim not 2
 * or 3.  *x gets 3 doubles per point (z 0 in 2-D), *share the last column
 * or NULL when absent (both malloc'd, the caller frees them); on failure
 * *n is 0 and both are NULL. */
pm_err gm_points_load(const char *path, int dim, long *n, double **x,
                      double **share);

#endif
