/* fuzz_gmsh: the readers of gmsh meshes under a fuzzer.  An input is one
 * .msh file, read as a volume mesh in 3-D and in 2-D and as a triangulated
 * surface (gmsh parses it; the project's code checks what gmsh returns).
 * The extension is fixed, so gmsh never reads an input as a .geo script.
 *
 * As the program reads it (the default): gmsh reads in a child
 * (pm_isolate.h), the process takes the mesh the child passes back and
 * builds on it, so a crash, leak or sanitizer report in this process is
 * one of the program's.  gmsh is initialized once here, before the first
 * child: each child only reads.  PM_ISOLATE=0: everything in this process
 * (the readers' own code under coverage and the sanitizers). */
#include <stdint.h>

#include "fuzz_file.h"
#include "gm_gmsh.h"
#include "gm_mesh.h"
#include "gm_trisurf.h"
#include "pm_isolate.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static bool warm = false;
  fuzz_isolate(data, size);
  if (!warm && pm_isolate_enabled()) {
    warm = gm_gmsh_warm() == PM_SUCCESS;
    pm_error_clear();
  }
  const char *path = fuzz_file("mesh.msh", data, size);
  for (int dim = 3; dim >= 2; dim--) {
    gm_mesh *m = NULL;
    (void)gm_mesh_file(path, dim, 0.1, GM_SIZES_REPLACE, &m);
    gm_mesh_destroy(m);
    pm_error_clear();
  }
  gm_trisurf s;
  (void)gm_trisurf_load(path, &s);
  gm_trisurf_free(&s);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
