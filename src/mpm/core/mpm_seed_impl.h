/* mpm_seed_impl: what the seeding's files share (mpm_seed.c, the bodies'
 * particles; mpm_seed_surface.c, the membranes' surfaces).  Internal to
 * the seeding. */
#ifndef MPM_SEED_IMPL_H
#define MPM_SEED_IMPL_H

#include "gm_trisurf.h"
#include "pm_scene.h"

/* A located failure at bodies.B(.KEY) (key may be NULL): the message of
 * the call that failed, after the scene position and what was expected. */
pm_err mpm_seed_body_fail(const pm_scene *s, int b, const char *key,
                          const char *what);

/* The points of membrane body b (and its triangles) into *out, each
 * point's share of its area (length in 2D) into a new *share, all inside
 * the grid; failures name the body's key. */
pm_err mpm_seed_surface(const pm_scene *s, int b, gm_trisurf *out,
                        double **share);

#endif
