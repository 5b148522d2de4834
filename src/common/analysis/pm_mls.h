/* pm_mls: moving least squares over a cloud of points: the value at any
 * point of a field known at the cloud's points, by a linear fit weighted by
 * a cubic B-spline over a radius set by the points' mean spacing. */
#ifndef PM_MLS_H
#define PM_MLS_H

#include "pm_error.h"

/* Components a fit can carry at once (a tensor's nine). */
#define PM_MLS_MAX_COMP 9

/* The cloud: its points, their bucket grid and a fit's scratch. */
typedef struct pm_mls pm_mls;

/* Index the n >= 1 points x ([n][3], borrowed: kept alive and unchanged
 * until pm_mls_free).  The axes along which the points extend are found
 * (a 2-D cloud at z = 0 is fitted in x and y alone); the mean spacing is
 * (V / n)^(1/d) over the bounding box of those axes.  Fails with
 * PM_ERR_GEOMETRY when the points all coincide or a coordinate is not
 * finite (what: the cloud's name in the message), PM_ERR_MEMORY.  *out is
 * released by pm_mls_free. */
pm_err pm_mls_create(long n, const double *x, const char *what, pm_mls **out);
void pm_mls_free(pm_mls *m);

/* The axes the points extend along (1 to 3) and their mean spacing. */
int pm_mls_dim(const pm_mls *m);
double pm_mls_spacing(const pm_mls *m);

/* The distance from q to the nearest point of the cloud, along its axes. */
double pm_mls_nearest(pm_mls *m, const double *q);

/* The nearest point of the cloud to q (its index), and its distance along
 * the cloud's axes into *dist (may be NULL). */
long pm_mls_nearest_point(pm_mls *m, const double *q, double *dist);

/* The mean distance from a point of the cloud to its nearest other point
 * (computed at the first call; 0 for a single point): the spacing a query
 * point farther than about that from every point lies off the cloud by. */
double pm_mls_gap(pm_mls *m);

/* The field f ([n][ncomp], ncomp in [1, PM_MLS_MAX_COMP]) at the point q
 * into v[ncomp]: the value at q of the fit f ~ a + B (x - q) over the
 * points within a radius R, weighted by the cubic B-spline of |x - q| / R.
 * R starts at 2.2 mean spacings and grows by half until at least 3 (d + 1)
 * points give a regular fit.  reach > 0 caps R at reach mean spacings;
 * reach = 0 lets it grow until it holds every point.  The fit reproduces a
 * linear field to round-off.  Returns the number of points of the fit, 0
 * when no regular fit was found within the cap (too few neighbours: v is
 * then NaN).  Not thread-safe: the scratch is the cloud's. */
long pm_mls_fit(pm_mls *m, const double *q, int ncomp, const double *f,
                double reach, double *v);

#endif
