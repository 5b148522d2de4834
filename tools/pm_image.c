/* pm-image: make the image stacks of the image-based cases.
 *
 *   pm-image points IN.pts OUT.tif NX NY NZ DX DY DZ OX OY OZ UNIT
 *     a point file of voxel centres (the form the vessel slice comes in)
 *     to a multi-page TIFF of 0 and 255.  N: voxels per axis; D: voxel
 *     size and O: corner of voxel (0, 0, 0), in m; UNIT: metres per unit
 *     of the point file (1e-6 for micrometres).
 *
 *   pm-image construct OUT.tif --size NX NY NZ [--voxel DX DY DZ]
 *       [--fraction F] [--seed S] [--radius R_MIN R_MAX] [--branch P]
 *       [--align A] [--roots N]
 *     a synthetic vascularized construct (geometry/gm_construct.h): a
 *     seeded random network of branching tubes, 255, in gel, 0, written as
 *     an 8-bit multi-page TIFF. */
#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_construct.h"
#include "gm_image.h"

static const char *usage =
    "usage: pm-image points IN.pts OUT.tif NX NY NZ DX DY DZ OX OY OZ UNIT\n"
    "       pm-image construct OUT.tif --size NX NY NZ [--voxel DX DY DZ (m)]\n"
    "           [--fraction F] [--seed S] [--radius R_MIN R_MAX (voxels)]\n"
    "           [--branch P] [--align A] [--roots N]\n"
    "  construct defaults: --voxel 1.05e-6 1.05e-6 1.0e-6 --fraction 0.104\n"
    "  --seed 1 --radius 3 6 --branch 0.1 --align 0 --roots 2\n";

static int points(int argc, char **argv) {
  if (argc != 14) {
    fputs(usage, stderr);
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

/* The `count` values after option argv[*a] as numbers (integers when
 * integer is set) into x; false, with a message, when they are missing or
 * not numbers. */
static bool values(int argc, char **argv, int *a, int count, bool integer,
                   double *x) {
  const char *opt = argv[*a];
  for (int m = 0; m < count; m++) {
    if (*a + 1 >= argc) {
      fprintf(stderr, "pm-image construct: %s: expected %d value(s), got %d\n",
              opt, count, m);
      return false;
    }
    const char *s = argv[++*a];
    char *end;
    errno = 0;
    x[m] = integer ? (double)strtoll(s, &end, 10) : strtod(s, &end);
    if (end == s || *end || errno) {
      fprintf(stderr, "pm-image construct: %s: expected %s, got '%s'\n", opt,
              integer ? "an integer" : "a number", s);
      return false;
    }
  }
  return true;
}

static int construct(int argc, char **argv) {
  if (argc < 3 || argv[2][0] == '-') {
    fputs(usage, stderr);
    return 1;
  }
  const char *file = argv[2];
  gm_construct_opts o;
  gm_construct_defaults(&o);
  bool sized = false;
  for (int a = 3; a < argc; a++) {
    const char *opt = argv[a];
    double x[3];
    bool ok;
    if (!strcmp(opt, "--size")) {
      if ((ok = values(argc, argv, &a, 3, true, x)))
        for (int c = 0; c < 3; c++) o.n[c] = (long)x[c];
      sized = true;
    } else if (!strcmp(opt, "--voxel")) {
      if ((ok = values(argc, argv, &a, 3, false, x)))
        for (int c = 0; c < 3; c++) o.d[c] = x[c];
    } else if (!strcmp(opt, "--fraction")) {
      if ((ok = values(argc, argv, &a, 1, false, x))) o.fraction = x[0];
    } else if (!strcmp(opt, "--seed")) {
      /* Any 64-bit word: read as unsigned, so not through a double. */
      const char *w = a + 1 < argc ? argv[++a] : "";
      char *end;
      errno = 0;
      o.seed = (uint64_t)strtoull(w, &end, 10);
      ok = *w >= '0' && *w <= '9' && !*end && !errno;
      if (!ok)
        fprintf(stderr,
                "pm-image construct: --seed: expected an integer in [0, "
                "2^64), got '%s'\n",
                w);
    } else if (!strcmp(opt, "--radius")) {
      if ((ok = values(argc, argv, &a, 2, false, x)))
        o.r_min = x[0], o.r_max = x[1];
    } else if (!strcmp(opt, "--branch")) {
      if ((ok = values(argc, argv, &a, 1, false, x))) o.branch = x[0];
    } else if (!strcmp(opt, "--align")) {
      if ((ok = values(argc, argv, &a, 1, false, x))) o.align = x[0];
    } else if (!strcmp(opt, "--roots")) {
      if ((ok = values(argc, argv, &a, 1, true, x)))
        o.roots = x[0] < INT_MIN   ? INT_MIN
                  : x[0] > INT_MAX ? INT_MAX
                                   : (int)x[0];
    } else {
      fprintf(stderr, "pm-image construct: unknown option '%s'\n%s", opt,
              usage);
      return 1;
    }
    if (!ok) return 1;
  }
  if (!sized) {
    fprintf(stderr, "pm-image construct: --size NX NY NZ is required\n%s",
            usage);
    return 1;
  }
  gm_image im;
  gm_construct_report r;
  pm_err e = gm_construct_vessels(&o, &im, &r);
  if (!e) e = gm_image_write_tiff(&im, file);
  if (e) {
    fprintf(stderr, "pm-image: %s\n", pm_error_message());
    gm_image_free(&im);
    return 1;
  }
  printf("pm-image: %s: %ld x %ld x %ld voxels of %g x %g x %g m, seed %" PRIu64
         "\n"
         "  vessel fraction %.4f (target %g), %ld vessel voxels\n"
         "  %ld segments, %ld branches, %ld sprouts, %ld joins, %ld roots\n"
         "  %ld connected components (6-connectivity); the largest holds "
         "%.1f%% of the vessel volume\n",
         file, o.n[0], o.n[1], o.n[2], o.d[0], o.d[1], o.d[2], o.seed,
         r.fraction, o.fraction, r.vessel_voxels, r.segments, r.branches,
         r.sprouts, r.joins, r.roots, r.components, 100 * r.largest_share);
  gm_image_free(&im);
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "points")) return points(argc, argv);
  if (argc >= 2 && !strcmp(argv[1], "construct")) return construct(argc, argv);
  fputs(usage, stderr);
  return 1;
}
