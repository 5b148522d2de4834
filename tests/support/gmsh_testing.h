/* gmsh_testing: a test that meshes or reads gmsh files many times maps
 * libgmsh once, in its own process, before its tests (gm_gmsh_preload):
 * each mesh is made in a child that then starts from it, instead of
 * mapping and relocating libgmsh and its libraries again (test_fpm_tangent
 * meshes 33 times, verify_fpm_static 15).  The children, and what they pass
 * back, are the program's as before. */
#ifndef GMSH_TESTING_H
#define GMSH_TESTING_H

#include <stdio.h>
#include <stdlib.h>

#include "gm_gmsh.h"

static inline void gmsh_testing_preload(void) {
  if (gm_gmsh_preload("the test's meshes") != PM_SUCCESS) {
    fprintf(stderr, "%s\n", pm_error_message());
    exit(1);
  }
}

#endif
