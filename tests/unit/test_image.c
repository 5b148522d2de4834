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

/* Point file pts of text (len bytes; 0: up to the NUL) is refused with
 * "pts:want". */
static void bad_points(const char *pts, const char *text, size_t len,
                       const char *want) {
  const long n[3] = {7, 5, 3};
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  FILE *f = fopen(pts, "wb");
  assert_non_null(f);
  fwrite(text, 1, len ? len : strlen(text), f);
  fclose(f);
  gm_image a;
  assert_int_equal(gm_image_read_points(pts, 1e-6, n, d, o, &a), PM_ERR_SCENE);
  char where[192];
  snprintf(where, sizeof where, "%s:%s", pts, want);
  assert_non_null(strstr(pm_error_message(), where));
  assert_null(a.v);
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
  /* A point between voxel centres, a bad number, a line longer than any
   * buffer (one line: its bad value 2000 bytes in is in column 2001, and a
   * long good line is one point), a NUL byte. */
  bad_points(pts, "0.5 0.5 0.5\n1.5 2.0 0.5\n", 0,
             "2:1: expected a voxel centre");
  bad_points(pts, "0.5 0.5 0.5\n1.5 x 0.5\n", 0, "2:5: expected a number");
  char text[4096];
  snprintf(text, sizeof text, "%1996s0.5 0.5 0.5\n%2000sx\n", "", "");
  bad_points(pts, text, 0, "2:2001: expected a number");
  bad_points(pts, "0.5 0.5 0.5\n1.5\0 0.5 0.5\n", 25,
             "2:4: expected text, got a NUL byte");
  gm_image_free(&ref);
}

/* A page that announces 100000 x 100000 pixels in a file of 126 bytes is
 * refused from its header, before 20 GB are allocated for it. */
static void test_tiff_without_data(void **state) {
  (void)state;
  const char *tif =
      PM_SOURCE_DIR "/tests/fuzz/regressions/tiff/pixels-without-data.tif";
  const double d[3] = {1e-6, 1e-6, 1e-6}, o[3] = {0, 0, 0};
  gm_image im;
  assert_int_equal(gm_image_read_tiff_path(tif, d, o, &im), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), tif));
  assert_non_null(strstr(pm_error_message(),
                         "page 1: expected data for 100000 x 100000 pixels"));
  assert_null(im.v);
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
      cmocka_unit_test(test_tiff_without_data),
      cmocka_unit_test(test_vessel_slice),
      cmocka_unit_test(test_components),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
