/* gm_surface: how a gm_mesh gets its named boundary surfaces (internal to
 * geometry/: gm_mesh.c calls these while it builds a mesh). */
#ifndef GM_SURFACE_H
#define GM_SURFACE_H

#include "gm_gmsh.h"
#include "gm_mesh.h"

/* Names the 2 * dim faces of m's box "xmin" ... "zmax" (index = pm_face)
 * and tags every cell face whose nodes all lie on one of the box planes,
 * within 1e-9 of the largest box side.  Replaces any surfaces m had.
 * PM_ERR_MEMORY on failure. */
pm_err gm_surface_name_box(gm_mesh *m);

/* Names m's surfaces after raw's physical groups (surface g is group g)
 * and tags each boundary face of m with
 * the surface of the group face having the same nodes (the last group
 * wins).  raw's node numbers must be m's.  PM_ERR_MEMORY on failure. */
pm_err gm_surface_from_groups(gm_mesh *m, const gm_gmsh_mesh *raw);

/* Frees m's surface names and tags and leaves it without surfaces. */
void gm_surface_drop(gm_mesh *m);

#endif
