/* pm-image: convert a point file of voxel centres (the form the vessel
 * slice comes in) to a multi-page TIFF of 0 and 255.
 *
 *   pm-image points IN.pts OUT.tif NX NY NZ DX DY DZ OX OY OZ UNIT
 *
 * N: voxels per axis; D: voxel size and O: corner of voxel (0, 0, 0), in m;
 * UNIT: metres per unit of the point file (1e-6 for micrometres). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_image.h"

int main(int argc, char **argv) {
  if (argc != 14 || strcmp(argv[1], "points") != 0) {
    fprintf(stderr,
            "usage: pm-image points IN.pts OUT.tif NX NY NZ DX DY DZ OX OY OZ "
            "UNIT\n");
    return 1;
  }
  long n[3];
  double d[3], o[3];
  for (int c = 0; c < 3; c++) {
    n[c] = strtol(argv[4 + c], NULL, 10);
    d[c] = strtod(argv[7 + c], NULL);
    o[c] = strtod(argv[10 + c], NULL);
  }
  gm_image im;
  pm_err e =
      gm_image_read_points(argv[2], strtod(argv[13], NULL), n, d, o, &im);
  if (!e) e = gm_image_write_tiff(&im, argv[3]);
  if (e) {
    fprintf(stderr, "pm-image: %s\n", pm_error_message());
    return 1;
  }
  long on = 0;
  for (long q = 0; q < n[0] * n[1] * n[2]; q++) on += im.v[q] > 0;
  printf("pm-image: %s: %ld x %ld x %ld voxels, %ld set (%.2f%%)\n", argv[3],
         n[0], n[1], n[2], on, 100.0 * on / (double)(n[0] * n[1] * n[2]));
  gm_image_free(&im);
  return 0;
}
