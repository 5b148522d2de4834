/* gm_gmsh: the gmsh session of the geometry modules (gm_mesh, gm_volume):
 * quiet, single-threaded and repeatable, leaving the process's OpenMP
 * thread count as it found it, and gmsh's errors as PM_ERR_MESH. */
#ifndef GM_GMSH_H
#define GM_GMSH_H

#include <stdbool.h>

#include "pm_error.h"

typedef struct {
  int threads; /* OpenMP threads before gmsh set its own */
  bool open;
} gm_gmsh_session;

/* Initialize gmsh and make it quiet, single-threaded and repeatable.  path
 * (may be NULL) names the file in a failure message.  Call gm_gmsh_end
 * whatever this returns. */
pm_err gm_gmsh_begin(gm_gmsh_session *s, const char *path);
/* Finalize gmsh (if it was initialized) and restore the thread count. */
void gm_gmsh_end(gm_gmsh_session *s);
/* Element size h everywhere (overrides sizes a file sets). */
pm_err gm_gmsh_size(double h, const char *path);
/* The last gmsh error as PM_ERR_MESH: "gmsh: WHAT['PATH'] failed: MSG". */
pm_err gm_gmsh_fail(const char *what, const char *path);

#endif
