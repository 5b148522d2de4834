/* gm_construct: a synthetic vascularized construct, a seeded random network
 * of branching tubes (microvessels) in a box of voxels (collagen gel), for
 * the image-based cases whose confocal stack is not public.
 *
 * The network is a union of capsules (cylinders with round ends), each a
 * straight segment of a vessel's axis with the vessel's radius:
 *   - roots: `roots` parent vessels, each from a random point of the box
 *     growing both ways;
 *   - growth: every live tip in turn adds a segment of 2 to 4 radii along
 *     a persistent random walk (each new direction is the last one plus a
 *     random turn of up to 37 degrees in the x-y plane and a smaller one in
 *     z; |u_z| <= 0.3, since a confocal stack is thin); the axis reflects
 *     off the top and bottom of the stack, and a tip that leaves the box
 *     sideways ends there (the vessel clipped by the box's sides);
 *   - branching: at the end of each segment, with probability `branch`, a
 *     second tip starts at 40-70 degrees to the first, of a radius drawn in
 *     [r_min, the parent's];
 *   - joining: a tip two segments or more from its start whose segment ends
 *     in a vessel voxel joins that vessel and ends (anastomosis);
 *   - sprouting: when no tip is left, a new vessel sprouts from the side of
 *     a segment drawn at random, so the network stays connected;
 *   - `align` > 0 turns every step towards the y axis (the loading axis of
 *     the cases): 0 gives no preferred direction in the plane.
 * Capsules are rasterized as they are added (a voxel is vessel when its
 * centre lies within the radius of the segment) and the vessel voxels are
 * counted; the last segment is shortened by bisection so that the fraction
 * ends within GM_CONSTRUCT_TOLERANCE of the target.  Positions are in units
 * of the x voxel size, so tubes are round in space for anisotropic voxels.
 * Every random draw comes from pm_random, and only correctly rounded
 * operations act on them (+, -, *, /, sqrt, floor; no sin, cos or log): the
 * same options give the same image on every machine. */
#ifndef GM_CONSTRUCT_H
#define GM_CONSTRUCT_H

#include <stdint.h>

#include "gm_image.h"
#include "pm_error.h"

/* The largest distance between the fraction reached and the target. */
#define GM_CONSTRUCT_TOLERANCE 0.002

typedef struct {
  long n[3];       /* voxels per axis, >= 1 */
  double d[3];     /* voxel size, m */
  double fraction; /* target vessel volume fraction, in (0, 0.6] */
  uint64_t seed;
  double r_min, r_max; /* vessel radius range, x voxels: half a voxel's
                        * diagonal <= r_min <= r_max */
  double branch;       /* probability that a segment branches, [0, 1] */
  double align;        /* pull of each step towards the y axis, [0, 1] */
  int roots;           /* parent vessels, >= 1 */
} gm_construct_opts;

/* What the network came out as. */
typedef struct {
  double fraction;      /* vessel voxels / voxels */
  long vessel_voxels;   /* voxels of 255 */
  long segments;        /* capsules rasterized */
  long branches;        /* tips started at a segment's end */
  long sprouts;         /* vessels started from a segment's side */
  long joins;           /* tips that ran into another vessel and ended */
  long roots;           /* parent vessels */
  long components;      /* 6-connected components of the vessel voxels */
  long largest;         /* voxels of the largest component */
  double largest_share; /* largest / vessel_voxels */
} gm_construct_report;

/* The defaults: the paper's stack (512 x 512 x 52 voxels of 1.05 x 1.05 x
 * 1.0 um, fraction 0.104), seed 1, radii 3-6 voxels (vessels 6.3-12.6 um
 * across), branch 0.1, align 0, 2 roots. */
void gm_construct_defaults(gm_construct_opts *o);

/* Check the options: PM_ERR_ARG naming the option, the expected range and
 * the value, or PM_SUCCESS. */
pm_err gm_construct_check(const gm_construct_opts *o);

/* Grow the network of o into *out (a new 8-bit image of o->n voxels of size
 * o->d, corner at 0: 255 for vessel, 0 for gel; the caller frees it with
 * gm_image_free) and describe it in *rep (may be NULL).  PM_ERR_ARG (bad
 * options, or a box too small to hold the fraction within the tolerance),
 * PM_ERR_NOT_CONVERGED (the fraction not reached: the network saturated, or
 * a voxel step of the last segment larger than the tolerance), PM_ERR_MEMORY.
 * On failure *out is empty. */
pm_err gm_construct_vessels(const gm_construct_opts *o, gm_image *out,
                            gm_construct_report *rep);

#endif
