/* Images to voxels (gm_image): a 3-page TIFF, a raw volume and a point file
 * of the same voxels give the same image; TIFF output reads back; a
 * truncated TIFF, a raw file of the wrong size and a point off the grid
 * fail with the file named (and where); the vessel slice of case I2 reads
 * with its published pixel count; 6-connected components are counted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gm_image.h"

static char dir[64];

static void path(char *buf, size_t size, const char *name) {
  snprintf(buf, size, "%s/%s", dir, name);
}

/* A 7 x 5 x 3 pattern of 0 and 255. */
static void pattern(gm_image *im) {
  const long n[3] = {7, 5, 3};
  memset(im, 0, sizeof *im);
  for (int c = 0; c < 3; c++) im->n[c] = n[c], im->d[c] = 1e-6;
  im->v = calloc(7 * 5 * 3, sizeof *im->v);
  assert_non_null(im->v);
  for (long k = 0; k < 3; k++)
    for (long j = 0; j < 5; j++)
      for (long i = 0; i < 7; i++)
        im->v[i + 7 * (j + 5 * k)] =
            ((i * 3 + j * 5 + k * 7) % 4 == 0) ? 255 : 0;
}

static void test_three_sources(void **state) {
  (void)state;
  gm_image ref, a, b, c;
  pattern(&ref);
  char tif[128], raw[128], pts[128];
  path(tif, sizeof tif, "v.tif");
  path(raw, sizeof raw, "v.raw");
  path(pts, sizeof pts, "v.pts");
  assert_int_equal(gm_image_write_tiff(&ref, tif), PM_SUCCESS);
  FILE *f = fopen(raw, "wb");
  FILE *g = fopen(pts, "w");
  assert_non_null(f);
  assert_non_null(g);
  fprintf(g, "# voxel centres, um\n");
  for (long q = 0; q < 7 * 5 * 3; q++) {
    unsigned char v = (unsigned char)ref.v[q];
    fwrite(&v, 1, 1, f);
    if (v)
      fprintf(g, "%g %g %g\n", 0.5 + q % 7, 0.5 + (q / 7) % 5, 0.5 + q / 35);
  }
  fclose(f);
  fclose(g);
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  const long n[3] = {7, 5, 3};
  const char *files[] = {tif};
  assert_int_equal(gm_image_read_tiff(1, files, d, o, &a), PM_SUCCESS);
  assert_int_equal(gm_image_read_raw(raw, n, 8, d, o, &b), PM_SUCCESS);
  assert_int_equal(gm_image_read_points(pts, 1e-6, n, d, o, &c), PM_SUCCESS);
  for (int k = 0; k < 3; k++) {
    assert_int_equal(a.n[k], n[k]);
    assert_int_equal(b.n[k], n[k]);
    assert_int_equal(c.n[k], n[k]);
  }
  assert_memory_equal(a.v, ref.v, sizeof(uint16_t) * 105);
  assert_memory_equal(b.v, ref.v, sizeof(uint16_t) * 105);
  assert_memory_equal(c.v, ref.v, sizeof(uint16_t) * 105);
  assert_int_equal(a.bits, 8);
  gm_image_free(&a);
  gm_image_free(&b);
  gm_image_free(&c);
  /* 16 bits when a value needs them. */
  ref.v[3] = 4000;
  assert_int_equal(gm_image_write_tiff(&ref, tif), PM_SUCCESS);
  assert_int_equal(gm_image_read_tiff(1, files, d, o, &a), PM_SUCCESS);
  assert_int_equal(a.bits, 16);
  assert_memory_equal(a.v, ref.v, sizeof(uint16_t) * 105);
  gm_image_free(&a);
  gm_image_free(&ref);
}

static void test_bad_files(void **state) {
  (void)state;
  gm_image ref, a;
  pattern(&ref);
  char tif[128], raw[128], pts[128];
  path(tif, sizeof tif, "t.tif");
  path(raw, sizeof raw, "t.raw");
  path(pts, sizeof pts, "t.pts");
  assert_int_equal(gm_image_write_tiff(&ref, tif), PM_SUCCESS);
  /* Truncated: its last bytes cut. */
  FILE *f = fopen(tif, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fclose(f);
  assert_int_equal(truncate(tif, size / 2), 0);
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  const char *files[] = {tif};
  assert_int_not_equal(gm_image_read_tiff(1, files, d, o, &a), PM_SUCCESS);
  assert_non_null(strstr(pm_error_message(), tif));
  assert_null(a.v);
  /* Raw of the wrong size. */
  f = fopen(raw, "wb");
  assert_non_null(f);
  fwrite(ref.v, 1, 100, f);
  fclose(f);
  const long n[3] = {7, 5, 3};
  assert_int_equal(gm_image_read_raw(raw, n, 8, d, o, &a), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "expected 105 bytes"));
  assert_non_null(strstr(pm_error_message(), "got 100"));
  /* A point between voxel centres. */
  f = fopen(pts, "w");
  assert_non_null(f);
  fprintf(f, "0.5 0.5 0.5\n1.5 2.0 0.5\n");
  fclose(f);
  assert_int_equal(gm_image_read_points(pts, 1e-6, n, d, o, &a), PM_ERR_SCENE);
  char where[192];
  snprintf(where, sizeof where, "%s:2:1: expected a voxel centre", pts);
  assert_non_null(strstr(pm_error_message(), where));
  /* A bad number. */
  f = fopen(pts, "w");
  assert_non_null(f);
  fprintf(f, "0.5 0.5 0.5\n1.5 x 0.5\n");
  fclose(f);
  assert_int_equal(gm_image_read_points(pts, 1e-6, n, d, o, &a), PM_ERR_SCENE);
  snprintf(where, sizeof where, "%s:2:5: expected a number", pts);
  assert_non_null(strstr(pm_error_message(), where));
  gm_image_free(&ref);
}

/* The vessel slice carried under cases/mpm/data: its size and its 50760
 * vessel pixels (the count its point file gives). */
static void test_vessel_slice(void **state) {
  (void)state;
  const char *files[] = {PM_SOURCE_DIR "/cases/mpm/data/vesselslice25_512.tif"};
  const double d[3] = {1.05e-6, 1.05e-6, 1.0e-6}, o[3] = {0, 0, 24.0e-6};
  gm_image im;
  assert_int_equal(gm_image_read_tiff(1, files, d, o, &im), PM_SUCCESS);
  assert_int_equal(im.n[0], 512);
  assert_int_equal(im.n[1], 512);
  assert_int_equal(im.n[2], 1);
  long on = 0;
  for (long q = 0; q < 512 * 512; q++) on += im.v[q] == 255;
  assert_int_equal(on, 50760);
  gm_image_free(&im);
}

/* Two components on a 4 x 3 x 2 grid: {(0,0,0), (1,0,0), (1,1,0),
 * (1,1,1)} (4 voxels, the last joined through z) and {(2,2,0), (2,2,1),
 * (3,2,1)} (3), which touch the first only along edges; none in an empty
 * image. */
static void test_components(void **state) {
  (void)state;
  gm_image im;
  const long n[3] = {4, 3, 2};
  const double d[3] = {1, 1, 1};
  assert_int_equal(gm_image_alloc(&im, n, d, NULL), PM_SUCCESS);
  long comps = -1, largest = -1;
  assert_int_equal(gm_image_components(&im, &comps, &largest), PM_SUCCESS);
  assert_int_equal(comps, 0);
  assert_int_equal(largest, 0);
  const long set[7][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1},
                          {2, 2, 0}, {2, 2, 1}, {3, 2, 1}};
  for (int m = 0; m < 7; m++)
    im.v[set[m][0] + 4 * (set[m][1] + 3 * set[m][2])] = 255;
  assert_int_equal(gm_image_components(&im, &comps, &largest), PM_SUCCESS);
  assert_int_equal(comps, 2);
  assert_int_equal(largest, 4);
  gm_image_free(&im);
}

static int setup(void **state) {
  (void)state;
  snprintf(dir, sizeof dir, "/tmp/pm-image-XXXXXX");
  return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state) {
  (void)state;
  const char *names[] = {"v.tif", "v.raw", "v.pts", "t.tif", "t.raw", "t.pts"};
  char p[128];
  for (int k = 0; k < 6; k++) {
    path(p, sizeof p, names[k]);
    unlink(p);
  }
  rmdir(dir);
  return 0;
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_three_sources),
      cmocka_unit_test(test_bad_files),
      cmocka_unit_test(test_vessel_slice),
      cmocka_unit_test(test_components),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
