/* fuzz_pipe: the parent's side of the protocol of pm_isolate.h under a
 * fuzzer: what a child reading a file passes back (a mark, the outcome's
 * code and message, the result's arrays, an end mark), as a child that
 * lies or dies part way may write it.  An input is a selector byte, then
 * the stream; the program's reader the selector names takes the stream as
 * its child's and goes on with what it accepts as the program does:
 *   0, 1  gm_mesh_file in 3-D, 2-D (the mesh built on: groups, order,
 *         orientation)
 *   2     gm_trisurf_load
 *   3, 4  gm_file_bounds in 3-D, 2-D
 *   5     pm_probe_map at 4 points (probe's reader, then the fit)
 *   6     pm_ckpt_vet (an outcome, no result)
 * A malformed stream must be refused by the file's name, never crash,
 * leak or read past what it holds. */
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

#include "fuzz_file.h"
#include "gm_mesh.h"
#include "gm_trisurf.h"
#include "gm_gmsh.h"
#include "pm_h5_vet.h"
#include "pm_isolate.h"
#include "pm_probe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  /* The stream replaces a child only where reads are isolated. */
  setenv("PM_ISOLATE", "1", 1);
  const char *stream = fuzz_file("stream", data + 1, size - 1);
  const int fd = open(stream, O_RDONLY | O_CLOEXEC);
  if (fd < 0) abort();
  const char *path = fuzz_file("mesh.msh", (const uint8_t *)"", 0);
  pm_isolate_stream(fd);
  switch (data[0] % 7) {
  case 0:
  case 1: {
    gm_mesh *m = NULL;
    (void)gm_mesh_file(path, data[0] % 7 == 0 ? 3 : 2, 0.1, GM_SIZES_REPLACE,
                       &m);
    gm_mesh_destroy(m);
    break;
  }
  case 2: {
    gm_trisurf s;
    (void)gm_trisurf_load(path, &s);
    gm_trisurf_free(&s);
    break;
  }
  case 3:
  case 4: {
    double lo[3], hi[3];
    (void)gm_file_bounds(path, data[0] % 7 == 3 ? 3 : 2, lo, hi);
    break;
  }
  case 5: {
    const double q[12] = {0, 0, 0, 0.5, 0.5, 0, 1, 0, 0.25, -1, 2, 0};
    double u[12];
    (void)pm_probe_map(fuzz_dir(), -1, NULL, 4, q, u);
    break;
  }
  default: (void)pm_ckpt_vet(fuzz_dir()); break;
  }
  pm_isolate_stream(-1);
  close(fd);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
