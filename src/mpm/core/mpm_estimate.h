/* mpm_estimate: the memory an MPM simulation of a scene will hold,
 * estimated from the scene alone (before seeding). */
#ifndef MPM_ESTIMATE_H
#define MPM_ESTIMATE_H

#include <stddef.h>

#include "pm_scene.h"

/* Bytes of the model, state, workspace and output buffer of the MPM
 * simulation of s: particles from the bodies' volumes, the cell size and
 * the particles per cell, grid nodes from the domain box.  An upper bound
 * within a factor of about 2 of what it measures (pm_figures.memory_bytes)
 * when the bodies do not overlap.  Sets *points to the particles. */
size_t mpm_estimate_bytes(const pm_scene *s, long *points);

/* The grid nodes the bodies of s touch: those of a cube of the cells they
 * fill, with the basis's reach (every cell where a body is seeded apart:
 * images, membranes), at most the grid's. */
double mpm_estimate_active_nodes(const pm_scene *s);

#endif
