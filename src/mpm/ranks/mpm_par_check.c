/* mpm_par_check: what a run of MPM across ranks cannot do yet, refused at
 * the scene check. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"
#include "pm_rigid.h"

/* ---- what a run across ranks cannot do yet ---------------------------------
 */

pm_err mpm_par_check(const pm_scene *s) {
  if (mpm_scene_settings(s)->fbar == MPM_FBAR_PATCH)
    return pm_scene_fail(s, "mpm.fbar", false,
                         "F-bar over node patches runs on one process (this "
                         "run has %d ranks): take mpm.fbar: cell, or run with "
                         "-np 1",
                         pm_par_size());
  for (int b = 0; s->output.ranks == PM_OUTPUT_PIECES && b < s->n_bodies; b++)
    if (s->bodies[b].shape == PM_BODY_MEMBRANE)
      return pm_scene_fail(s, "output.ranks", false,
                           "frames in pieces hold particles without "
                           "triangles, and body %d is a membrane (its "
                           "triangles number the particles in one process's "
                           "order): take gather",
                           b);
  for (int i = 0; i < s->n_bcs; i++)
    if (PM_BC_RIGID(&s->bcs[i])) {
      char got[64];
      snprintf(got, sizeof got, "a run across %d ranks", pm_par_size());
      return pm_rigid_refuse(s, i,
                             "one process (a node's contact reads the "
                             "particles of other ranks' blocks): run with "
                             "-np 1",
                             got);
    }
  for (int i = 0; i < s->n_bcs; i++)
    if (s->bcs[i].on == PM_ON_REGION || s->bcs[i].on == PM_ON_SURFACE ||
        s->bcs[i].traction_mask || s->bcs[i].pressure) {
      const bool grip = s->bcs[i].on == PM_ON_REGION;
      char p[64];
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.%s", i, grip ? "region" : "on"), true,
          "%s run on one process (this run has %d ranks): run with -np 1",
          grip ? "grips on regions of particles"
               : "conditions on particles (tractions, pressures, named "
                 "surfaces)",
          pm_par_size());
    }
  return PM_SUCCESS;
}

pm_err mpm_par_check_implicit(const pm_scene *s) {
  const mpm_settings *ms = mpm_scene_settings(s);
  if (ms->implicit.grid == MPM_GRID_RESET)
    return pm_scene_fail(s, "mpm.implicit.grid", false,
                         "the grid reset after each load step runs on one "
                         "process (this run has %d ranks): take kept, or run "
                         "with -np 1",
                         pm_par_size());
  if (ms->implicit.op == MPM_OP_MATRIX_FREE)
    return pm_scene_fail(s, "mpm.implicit.operator", false,
                         "the matrix-free operator runs on one process (this "
                         "run has %d ranks): take assembled, or run with -np "
                         "1",
                         pm_par_size());
  if (ms->fbar == MPM_FBAR_CELL)
    return pm_scene_fail(s, "mpm.fbar", false,
                         "the implicit F-bar runs on one process (this run "
                         "has %d ranks): run with -np 1",
                         pm_par_size());
  return PM_SUCCESS;
}
