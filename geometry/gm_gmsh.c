/* gm_gmsh: one gmsh session setup for every geometry module. */
#include "gm_gmsh.h"

#include <gmshc.h>
#include <stddef.h>

#include "pm_omp.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GM_GMSH_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(GM_GMSH_ASAN)
/* gmsh 4.8 and OpenCASCADE leak a little on their own: meshing curved
 * surfaces (meshGFace), the .geo parser after a syntax error (its Malloc),
 * STEP reading and writing (OpenCASCADE's libTK*).  A sanitizer build
 * (detect_leaks=1) of any program that meshes through this module ignores
 * exactly those, so that a leak of ours, or an array from the gmsh API left
 * without gmshFree, still fails. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
  return "leak:meshGFace\nleak:^Malloc(\nleak:libTK\n";
}
#endif

pm_err gm_gmsh_fail(const char *what, const char *path) {
  char *msg = NULL;
  int ierr = 0;
  gmshLoggerGetLastError(&msg, &ierr);
  const char *text =
      (ierr == 0 && msg && msg[0]) ? msg : "(no message from gmsh)";
  pm_err e =
      path ? PM_ERROR(PM_ERR_MESH, "gmsh: %s '%s' failed: %s", what, path, text)
           : PM_ERROR(PM_ERR_MESH, "gmsh: %s failed: %s", what, text);
  if (msg) gmshFree(msg);
  return e;
}

typedef struct {
  const char *name;
  double value;
} gm_option;

static pm_err set_options(const gm_option *opts, size_t n, const char *path) {
  int ierr = 0;
  for (size_t i = 0; i < n; i++) {
    gmshOptionSetNumber(opts[i].name, opts[i].value, &ierr);
    if (ierr) return gm_gmsh_fail(opts[i].name, path);
  }
  return PM_SUCCESS;
}

pm_err gm_gmsh_begin(gm_gmsh_session *s, const char *path) {
  static const gm_option quiet[] = {
      {"General.Terminal", 0},
      {"General.NumThreads", 1},
      {"Mesh.RandomSeed", 1},
  };
  int ierr = 0;
  /* gmsh sets the process-wide OpenMP thread count from its own option:
   * gm_gmsh_end puts ours back. */
  s->threads = pm_omp_threads();
  s->open = false;
  gmshInitialize(0, NULL, 0, &ierr);
  if (ierr) return gm_gmsh_fail("initialize", path);
  s->open = true;
  /* gmsh resets every option at initialization: nothing leaks between
   * sessions. */
  return set_options(quiet, sizeof quiet / sizeof quiet[0], path);
}

void gm_gmsh_end(gm_gmsh_session *s) {
  int ierr = 0;
  if (s->open) gmshFinalize(&ierr);
  s->open = false;
  if (s->threads > 0) pm_omp_set_threads(s->threads);
}

pm_err gm_gmsh_size(double h, const char *path) {
  const gm_option size[] = {
      {"Mesh.MeshSizeFromPoints", 0},
      {"Mesh.MeshSizeFromCurvature", 0},
      {"Mesh.MeshSizeExtendFromBoundary", 1},
      {"Mesh.MeshSizeMin", h},
      {"Mesh.MeshSizeMax", h},
  };
  return set_options(size, sizeof size / sizeof size[0], path);
}
