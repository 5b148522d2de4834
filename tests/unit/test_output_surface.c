/* test_output_surface: results whose points carry a surface triangulation
 * (an MPM membrane): mesh.h5's triangles, both grids of every XDMF frame,
 * a resumed run's XDMF, and bad triangulations refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "pm_testing.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output_testing.h"
#include "pm_output.h"

/* ---- Surface: a second grid of triangles over the same points ----------- */

/* Two triangles over the first four points of the five. */
#define NT 2
static const long tris[3 * NT] = {0, 1, 2, 1, 4, 2};

/* The text of frame k's grid in the XDMF x: from its opening tag to the
 * next frame's (or the end); *end set. */
static const char *frame_text(const char *x, long k, const char **end) {
  char tag[96];
  snprintf(tag, sizeof tag,
           "<Grid Name=\"frame_%06ld\" GridType=\"Collection\" "
           "CollectionType=\"Spatial\">",
           k);
  const char *at = strstr(x, tag);
  assert_non_null(at);
  const char *next = strstr(at + 1, "<Grid Name=\"frame_");
  *end = next ? next : at + strlen(at);
  return at;
}

/* Frame k of the surface results: both grids, each with the frame's
 * position as geometry and its damage as an attribute. */
static void check_surface_frame(const char *x, long k) {
  const char *end, *at = frame_text(x, k, &end);
  char pos[64], dmg[64];
  snprintf(pos, sizeof pos, "results/frame_%06ld.h5:/position<", k);
  snprintf(dmg, sizeof dmg, "results/frame_%06ld.h5:/damage<", k);
  const struct {
    const char *text;
    int count;
  } expect[] = {
      {"<Time ", 1},
      {"<Grid Name=\"points\" GridType=\"Uniform\">", 1},
      {"<Grid Name=\"membrane\" GridType=\"Uniform\">", 1},
      {"TopologyType=\"Polyvertex\" NumberOfElements=\"5\"", 1},
      {"TopologyType=\"Triangle\" NumberOfElements=\"2\">", 1},
      {"Dimensions=\"2 3\" NumberType=\"Int\" Precision=\"8\" "
       "Format=\"HDF\">results/mesh.h5:/surface<",
       1},
      {pos, 2},
      {dmg, 2},
      {"Attribute Name=\"damage\"", 2},
      {"mesh.h5:/coordinates", 0},
  };
  for (size_t i = 0; i < sizeof expect / sizeof expect[0]; i++)
    assert_int_equal(count_in(at, end, expect[i].text), expect[i].count);
}

static const pm_points surface_points = {.n = NP,
                                         .x = coords,
                                         .nodes_per_cell = 1,
                                         .n_surface = NT,
                                         .surface = tris};

static void test_surface(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double pos[3 * NP], damage[NP] = {0};
  char path[512];
  pm_field f[2] = {{"position", 3, pos}, {"damage", 1, damage}};
  memcpy(pos, coords, sizeof pos);
  snprintf(path, sizeof path, "%s/results.xdmf", dir);

  /* Before the first frame: the bare mesh, both grids on the reference
   * coordinates. */
  assert_ok(pm_results_create_ex(dir, 3, &surface_points, scene, "v", &r));
  char *x = pm_test_slurp(path);
  assert_non_null(strstr(x, "<Grid Name=\"mesh\" GridType=\"Collection\" "
                            "CollectionType=\"Spatial\">"));
  assert_int_equal(count_in(x, x + strlen(x), "<Grid Name=\"points\""), 1);
  assert_int_equal(count_in(x, x + strlen(x), "<Grid Name=\"membrane\""), 1);
  assert_int_equal(count_in(x, x + strlen(x), "mesh.h5:/coordinates"), 2);
  assert_int_equal(count_in(x, x + strlen(x), "mesh.h5:/surface"), 1);
  free(x);

  char *two = NULL; /* the XDMF of two frames, for the resume below */
  for (int k = 0; k < 3; k++) {
    pos[3 * 4 + 2] = 1 + k; /* the apex rises */
    damage[4] = 0.5 * k;
    assert_ok(pm_results_write_frame(r, 10 * k, 1e-6 * k, 2, f));
    if (k == 1) two = pm_test_slurp(path);
  }
  pm_results_close(r, true);
  x = pm_test_slurp(path);
  for (long k = 0; k < 3; k++) check_surface_frame(x, k);
  assert_int_equal(count_in(x, x + strlen(x), "<Time "), 3);
  free(x);

  /* mesh.h5 holds the triangles, named, read through the index. */
  snprintf(path, sizeof path, "%s/results.h5", dir);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  assert_true(file >= 0);
  hid_t d = H5Dopen2(file, "/mesh/surface", H5P_DEFAULT);
  assert_true(d >= 0);
  hid_t sp = H5Dget_space(d), ty = H5Dget_type(d);
  hsize_t dims[2] = {0, 0};
  assert_int_equal(H5Sget_simple_extent_ndims(sp), 2);
  H5Sget_simple_extent_dims(sp, dims, NULL);
  assert_int_equal(dims[0], NT);
  assert_int_equal(dims[1], 3);
  assert_true(H5Tequal(ty, H5T_STD_I64LE) > 0);
  long back[3 * NT];
  assert_true(
      H5Dread(d, H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, back) >= 0);
  assert_memory_equal(back, tris, sizeof tris);
  hid_t a = H5Aopen(d, "name", H5P_DEFAULT);
  assert_true(a >= 0);
  hid_t at = H5Aget_type(a);
  char *name = NULL;
  assert_true(H5Aread(a, at, &name) >= 0);
  assert_string_equal(name, "membrane");
  H5free_memory(name);
  H5Tclose(at);
  H5Aclose(a);
  H5Tclose(ty);
  H5Sclose(sp);
  H5Dclose(d);
  H5Fclose(file);

  /* A resumed run keeping two frames rebuilds the XDMF of those two byte
   * for byte from mesh.h5 and the frames, then goes on with both grids. */
  assert_ok(pm_results_reopen(dir, NP, 2, &r));
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  x = pm_test_slurp(path);
  assert_string_equal(x, two);
  free(x);
  free(two);
  pos[3 * 4 + 2] = 7;
  assert_ok(pm_results_write_frame(r, 25, 2.5e-6, 2, f));
  pm_results_close(r, true);
  x = pm_test_slurp(path);
  for (long k = 0; k < 3; k++) check_surface_frame(x, k);
  assert_non_null(strstr(x, "<Time Value=\"2.5e-06\"/>"));
  free(x);

  /* Well-formed XML: three frames, each a collection of two grids. */
  python_check_xdmf(dir, "len(x.findall(\"Domain/Grid/Grid\")) == 3 and "
                         "all([g.get(\"Name\") for g in f.findall(\"Grid\")]"
                         " == [\"points\", \"membrane\"] "
                         "for f in x.findall(\"Domain/Grid/Grid\"))");
}

/* Triangles that name a point outside the cloud, or a surface without
 * triangles, are refused before anything is written. */
static void test_surface_bad(void **state) {
  const char *dir = *state;
  pm_results *r = (pm_results *)1;
  long out_of_range[3 * NT] = {0, 1, 2, 1, NP, 2};
  long negative[3 * NT] = {0, 1, 2, 1, -1, 2};
  pm_points bad[4] = {surface_points, surface_points, surface_points,
                      surface_points};
  bad[0].surface = out_of_range;
  bad[1].surface = negative;
  bad[2].surface = NULL;
  bad[3].n_surface = -1;
  for (int k = 0; k < 4; k++) {
    assert_int_equal(pm_results_create_ex(dir, 3, &bad[k], scene, "v", &r),
                     PM_ERR_ARG);
    assert_null(r);
    if (k == 0)
      assert_non_null(strstr(pm_error_message(), "surface triangle 1"));
  }
  assert_int_equal(pm_results_create_ex(dir, 3, NULL, scene, "v", &r),
                   PM_ERR_ARG);
  assert_int_equal(pm_test_count_entries(dir, NULL), 0);

  /* n_surface 0: no surface, whatever the pointer (points-only results). */
  pm_points p = surface_points;
  p.n_surface = 0;
  assert_ok(pm_results_create_ex(dir, 3, &p, scene, "v", &r));
  pm_results_close(r, true);
  char path[512];
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  char *x = pm_test_slurp(path);
  assert_null(strstr(x, "membrane"));
  assert_non_null(strstr(x, "<Grid Name=\"mesh\" GridType=\"Uniform\">"));
  free(x);
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_surface, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_surface_bad, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
