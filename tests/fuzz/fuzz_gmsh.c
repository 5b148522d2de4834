/* fuzz_gmsh: the readers of gmsh meshes under a fuzzer.  An input is one
 * .msh file, read as a volume mesh in 3-D and in 2-D and as a triangulated
 * surface (gmsh parses it; the project's code checks what gmsh returns).
 * The extension is fixed, so gmsh never reads an input as a .geo script. */
#include <stdint.h>

#include "fuzz_file.h"
#include "gm_mesh.h"
#include "gm_trisurf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
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
