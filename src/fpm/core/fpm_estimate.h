/* fpm_estimate: the memory an FPM simulation of a scene will hold,
 * estimated from the scene alone (before meshing). */
#ifndef FPM_ESTIMATE_H
#define FPM_ESTIMATE_H

#include <stddef.h>

#include "pm_scene.h"

/* Bytes of the mesh, subdomains, operators and state (and, for a static
 * solve, the tangent) of the FPM simulation of s, from the domain box and
 * the mesh size: an upper bound within a factor of about 2 of what it
 * measures (pm_figures.memory_bytes) plus the mesh.  Sets *points to the
 * points it expects. */
size_t fpm_estimate_bytes(const pm_scene *s, long *points);
/* The part of it every rank holds across ranks: the mesh and its cells
 * (fpm_region.h). */
size_t fpm_estimate_geometry_bytes(const pm_scene *s);

#endif
