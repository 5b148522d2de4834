/* pm_probe: map a results frame's displacement to arbitrary reference
 * coordinates by moving least squares, as used to compare resolutions. */
#ifndef PM_PROBE_H
#define PM_PROBE_H

#include <stdio.h>

#include "pm_error.h"

/* Read OUT/results.h5 (frame index `frame`, or the last frame when < 0),
 * read reference coordinates from points_csv (one "x,y,z" per line; a
 * header line and '#' comments are skipped; 2 columns allowed in 2D) and
 * write "x,y,z,u_x,u_y,u_z" rows to out.  The displacement at each query
 * point is the linear moving-least-squares fit over the nearest result
 * points (cubic-spline weight over a radius adapted to the point spacing),
 * which reproduces linear fields exactly.  Errors name the file and line. */
pm_err pm_probe(const char *out_dir, const char *points_csv, long frame,
                FILE *out);

/* The values at the points themselves (no fit): every per-point field of
 * frame `frame` (last when < 0) of OUT/results.h5 (float datasets with a
 * row per point: vectors as _x _y _z columns, 3 x 3 tensors as _xx .. _zz),
 * as CSV rows "point,x,y,z,FIELDS..." (x the reference coordinates).  With
 * points_csv (as pm_probe reads it; NULL: every point), one row per query
 * for the nearest point, after "query_x,query_y,query_z,distance"; a query
 * farther than half the points' mean gap from every point is refused with
 * its file and line.  Nothing is written when anything fails. */
pm_err pm_probe_points(const char *out_dir, const char *points_csv, long frame,
                       FILE *out);

/* Read the reference coordinates and the displacement of frame `frame`
 * (last when < 0) of OUT/results.h5 into new [n][3] arrays. */
pm_err pm_results_read(const char *out_dir, long frame, long *n, double **x,
                       double **u);

struct pm_scene;
/* The displacement of OUT/results.h5 (frame as above) at the m reference
 * points q ([m][3]) by the same moving least squares, into u ([m][3]).
 * part: the scene of the run (NULL: none), where a point outside a part
 * mirrored about its symmetry planes takes its image's value
 * (pm_scene_mirror.h). */
pm_err pm_probe_map(const char *out_dir, long frame,
                    const struct pm_scene *part, long m, const double *q,
                    double *u);

#endif
