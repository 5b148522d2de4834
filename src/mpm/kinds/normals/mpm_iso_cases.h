/* mpm_iso_cases: the paper's static configurations for mpm_isonormal (its
 * sections 4 and 6), with their exact normals, shared by the tables
 * (mpm_iso_tables) and the verification (verify_normals).  The paper gives
 * the curves but not where the points stand; the placements here are ours:
 *
 *   curves (2-D):  equally spaced in arc length over the part of the curve
 *                  inside the element, a tenth of that length left free at
 *                  each end (one point: the middle);
 *   plane (3-D):   a grid of ceil(sqrt(n)) columns over x, y in
 *                  [0.1, 0.9], row by row, z on the plane;
 *   sphere (3-D):  a golden-angle spiral over the octant patch, equally
 *                  spaced in z from 0.9 r to 0.1 r (equal areas), the
 *                  azimuth in [0.1, 0.9] pi / 2. */
#ifndef MPM_ISO_CASES_H
#define MPM_ISO_CASES_H

#define MPM_ISO_CASE_MAX 64

typedef struct {
  int dim;
  double lo[3], H; /* the element */
  long n;
  double x[3 * MPM_ISO_CASE_MAX];     /* the points */
  double exact[3 * MPM_ISO_CASE_MAX]; /* their exact unit normals */
} mpm_iso_case;

/* n points (at most MPM_ISO_CASE_MAX, as for all cases) on the line of
 * slope s through (0.5, 0.5), element [0, 1]^2. */
void mpm_iso_case_line(double s, long n, mpm_iso_case *c);
/* The arc of the circle of centre (cx, cy) and radius r from angle th0 to
 * th1 (radians, counter-clockwise), element [0, 1]^2. */
void mpm_iso_case_arc(double cx, double cy, double r, double th0, double th1,
                      long n, mpm_iso_case *c);
/* The curve x y + 0.1 x + 0.3 = 0 on the element [-1, 0] x [0, 1] (the
 * branch through it: x from -1 to -3/11). */
void mpm_iso_case_bilinear(long n, mpm_iso_case *c);
/* The cubic y = k x^2 (x - 1) + x + 0.5 from x = 0 to where it leaves
 * [0, 1]^2 at y = 1. */
void mpm_iso_case_cubic(double k, long n, mpm_iso_case *c);
/* The plane 0.5 x + 0.25 y - z = 0 in [0, 1]^3. */
void mpm_iso_case_plane(long n, mpm_iso_case *c);
/* The sphere x^2 + y^2 + z^2 = 0.8^2 in [0, 1]^3 (its octant patch). */
void mpm_iso_case_sphere(long n, mpm_iso_case *c);

/* The paper's Table III (x^2 + y^2 = 0.8^2, linear, the random point
 * fixed): points, the largest angle error and its "rms" (radians), which
 * is |e|_2 / n: a root mean square over the points would be at least
 * max / sqrt(n), above every figure of the column. */
typedef struct {
  long points;
  double max, rms;
} mpm_iso_paper_arc;
#define MPM_ISO_TABLE_III_ROWS 5
extern const mpm_iso_paper_arc mpm_iso_table_iii[MPM_ISO_TABLE_III_ROWS];

/* The largest angle (radians) between the normals (3 per point) and the
 * exact ones, the sign ignored: acos |n . n_exact|, computed as
 * atan2(|n x n_exact|, |n . n_exact|) to keep its digits near zero; the rms
 * angle into *rms (if not NULL). */
double mpm_iso_case_error(const mpm_iso_case *c, const double *normal,
                          double *rms);

#endif
