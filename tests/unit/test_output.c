/* test_output: results.h5 + results.xdmf written, read back with the HDF5
 * API, aborted results and bad arguments or directories. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <dirent.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_output.h"

/* ---- Helpers ----------------------------------------------------------- */

#include "output_testing.h"

static void fill_frame(int frame, double *u, double *damage, double *stress) {
  for (int i = 0; i < NP; i++) {
    for (int k = 0; k < 3; k++) u[3 * i + k] = 100 * frame + 10 * i + k;
    damage[i] = 0.1 * i + frame;
    for (int k = 0; k < 9; k++) stress[9 * i + k] = 1000 * frame + 9 * i + k;
  }
}

/* Read /path of the file as doubles into out (count values). */
static void read_doubles(hid_t file, const char *path, double *out,
                         size_t count, int rank, const hsize_t *dims) {
  hid_t d = H5Dopen2(file, path, H5P_DEFAULT);
  hsize_t got[3] = {0, 0, 0};
  assert_true(d >= 0);
  hid_t s = H5Dget_space(d);
  assert_int_equal(H5Sget_simple_extent_ndims(s), rank);
  H5Sget_simple_extent_dims(s, got, NULL);
  for (int k = 0; k < rank; k++) assert_int_equal(got[k], dims[k]);
  assert_int_equal(H5Sget_simple_extent_npoints(s), (hssize_t)count);
  assert_true(
      H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0);
  H5Sclose(s);
  H5Dclose(d);
}

/* ---- Tests ------------------------------------------------------------- */

static void test_write_read(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double u[3 * NP], damage[NP], stress[9 * NP], buf[9 * NP];
  char path[512];
  int tmp;
  pm_field fields[3] = {
      {"displacement", 3, u}, {"damage", 1, damage}, {"stress", 9, stress}};

  assert_ok(
      pm_results_create(dir, 3, NP, coords, NC, 4, tets, scene, "0.1.0", &r));
  for (int f = 0; f < 2; f++) {
    fill_frame(f, u, damage, stress);
    assert_ok(pm_results_write_frame(r, 100 * f, 0.5 * f, 3, fields));
  }
  assert_int_equal(pm_results_frames(r), 2);
  /* While the run goes on, every frame is on disk under its final name:
   * the index, the XDMF and the results folder, no temporary file. */
  assert_int_equal(pm_test_count_entries(dir, &tmp), 3);
  assert_int_equal(tmp, 0);
  /* mesh, two frames and the spares of the index and the XDMF */
  snprintf(path, sizeof path, "%s/results", dir);
  assert_int_equal(pm_test_count_entries(path, &tmp), 5);
  assert_int_equal(tmp, 0);
  pm_results_close(r, true);
  assert_int_equal(pm_test_count_entries(dir, &tmp), 3);

  /* Read back with the HDF5 API. */
  snprintf(path, sizeof path, "%s/results.h5", dir);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  assert_true(file >= 0);
  hsize_t cdims[2] = {NP, 3};
  read_doubles(file, "/mesh/coordinates", buf, 3 * NP, 2, cdims);
  assert_int_equal(H5Lexists(file, "/mesh/surface", H5P_DEFAULT), 0);
  assert_memory_equal(buf, coords, sizeof coords);

  long cells[4 * NC];
  hid_t d = H5Dopen2(file, "/mesh/cells", H5P_DEFAULT);
  assert_true(d >= 0);
  assert_true(
      H5Dread(d, H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, cells) >= 0);
  H5Dclose(d);
  assert_memory_equal(cells, tets, sizeof tets);

  fill_frame(1, u, damage, stress);
  read_doubles(file, "/frames/000001/displacement", buf, 3 * NP, 2, cdims);
  assert_memory_equal(buf, u, sizeof u);
  hsize_t tdims[3] = {NP, 3, 3};
  read_doubles(file, "/frames/000001/stress", buf, 9 * NP, 3, tdims);
  assert_memory_equal(buf, stress, sizeof stress);
  hsize_t sdims[1] = {NP};
  read_doubles(file, "/frames/000001/damage", buf, NP, 1, sdims);
  assert_memory_equal(buf, damage, sizeof damage);

  /* Frame attributes. */
  double time = -1;
  long step = -1;
  hid_t g = H5Gopen2(file, "/frames/000001", H5P_DEFAULT);
  assert_true(g >= 0);
  hid_t a = H5Aopen(g, "time", H5P_DEFAULT);
  assert_true(H5Aread(a, H5T_NATIVE_DOUBLE, &time) >= 0);
  H5Aclose(a);
  a = H5Aopen(g, "step", H5P_DEFAULT);
  assert_true(H5Aread(a, H5T_NATIVE_LONG, &step) >= 0);
  H5Aclose(a);
  H5Gclose(g);
  assert_true(time == 0.5);
  assert_int_equal(step, 100);

  /* Root attribute: the scene text, as a variable-length string. */
  char *text = NULL;
  a = H5Aopen(file, "scene", H5P_DEFAULT);
  assert_true(a >= 0);
  hid_t t = H5Aget_type(a);
  assert_true(H5Aread(a, t, &text) >= 0);
  assert_string_equal(text, scene);
  H5free_memory(text);
  H5Tclose(t);
  H5Aclose(a);
  assert_true(H5Aexists(file, "version") > 0);
  assert_true(H5Fclose(file) >= 0);

  /* XDMF: both frames, their times and datasets. */
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  char *x = pm_test_slurp(path);
  assert_non_null(strstr(x, "<Xdmf Version=\"3.0\">"));
  assert_null(strstr(x, "position"));
  assert_non_null(strstr(x, "CollectionType=\"Temporal\""));
  assert_non_null(strstr(x, "<Time Value=\"0\"/>"));
  assert_non_null(strstr(x, "<Time Value=\"0.5\"/>"));
  assert_non_null(strstr(x, "TopologyType=\"Tetrahedron\" "
                            "NumberOfElements=\"2\""));
  assert_non_null(strstr(x, "results/mesh.h5:/cells"));
  assert_non_null(strstr(x, "results/mesh.h5:/coordinates"));
  assert_non_null(strstr(x, "results/frame_000000.h5:/displacement"));
  assert_non_null(strstr(x, "results/frame_000001.h5:/damage"));
  assert_non_null(strstr(x, "AttributeType=\"Tensor\""));
  assert_non_null(strstr(x, "Dimensions=\"5 3 3\""));
  assert_non_null(strstr(x, "</Xdmf>"));
  assert_null(strstr(x, "Spatial")); /* no surface: one grid per frame */
  free(x);

  /* Well-formed XML, a grid per frame. */
  python_check_xdmf(dir, "len(x.findall(\".//Grid/Grid\")) == 2");
}

static void test_abort_and_point_cloud(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double damage[NP] = {0};
  pm_field f = {"damage", 1, damage};
  char path[512];

  /* keep = false before any frame leaves nothing ... */
  assert_ok(
      pm_results_create(dir, 3, NP, coords, NC, 4, tets, scene, "0.1.0", &r));
  pm_results_close(r, false);
  assert_int_equal(pm_test_count_entries(dir, NULL), 0);
  /* ... but a frame written is never taken back. */
  assert_ok(
      pm_results_create(dir, 3, NP, coords, NC, 4, tets, scene, "0.1.0", &r));
  assert_ok(pm_results_write_frame(r, 0, 0.0, 1, &f));
  pm_results_close(r, false);
  assert_int_equal(pm_test_count_entries(dir, NULL), 3);

  /* Point cloud without cells and without frames: bare mesh XDMF. */
  assert_ok(pm_results_create(dir, 2, NP, coords, 0, 1, NULL, NULL, NULL, &r));
  pm_results_close(r, true);
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  char *x = pm_test_slurp(path);
  assert_non_null(strstr(x, "TopologyType=\"Polyvertex\" "
                            "NumberOfElements=\"5\" NodesPerElement=\"1\""));
  assert_null(strstr(x, "Temporal"));
  free(x);
  pm_results_close(NULL, true);
}

/* Moving points: a "position" field is the frame's geometry.  A resumed
 * run keeps the first frames and continues their numbering. */
static void test_moving_and_reopen(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double pos[3 * NP], u[3 * NP] = {0};
  char path[512];
  int tmp;
  pm_field f[2] = {{"position", 3, pos}, {"displacement", 3, u}};
  memcpy(pos, coords, sizeof pos);
  assert_ok(pm_results_create(dir, 3, NP, coords, 0, 1, NULL, scene, "v", &r));
  for (int k = 0; k < 3; k++) {
    pos[0] = k;
    assert_ok(pm_results_write_frame(r, 10 * k, k, 2, f));
  }
  pm_results_close(r, true);
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  char *x = pm_test_slurp(path);
  assert_non_null(strstr(x, "results/frame_000002.h5:/position</DataItem>\n"
                            "        </Geometry>"));
  assert_null(strstr(x, "Attribute Name=\"position\""));
  free(x);

  /* Keep two frames: the third goes, the next one is frame 2 again. */
  assert_int_equal(pm_results_reopen(dir, NP + 1, 2, &r), PM_ERR_ARG);
  assert_ok(pm_results_reopen(dir, NP, 2, &r));
  assert_int_equal(pm_results_frames(r), 2);
  snprintf(path, sizeof path, "%s/results/frame_000002.h5", dir);
  assert_int_equal(access(path, F_OK), -1);
  pos[0] = 7;
  assert_ok(pm_results_write_frame(r, 25, 2.5, 2, f));
  pm_results_close(r, true);
  /* mesh.h5, three frames and the spares of the index and the XDMF. */
  snprintf(path, sizeof path, "%s/results", dir);
  assert_int_equal(pm_test_count_entries(path, &tmp), 6);
  assert_int_equal(tmp, 0);
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  x = pm_test_slurp(path);
  assert_non_null(strstr(x, "<Time Value=\"1\"/>"));
  assert_non_null(strstr(x, "<Time Value=\"2.5\"/>"));
  assert_null(strstr(x, "<Time Value=\"2\"/>"));
  free(x);
  /* The index reads as one file through its links. */
  snprintf(path, sizeof path, "%s/results.h5", dir);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  assert_true(file >= 0);
  double back[3 * NP];
  hsize_t dims[2] = {NP, 3};
  read_doubles(file, "/frames/000002/position", back, 3 * NP, 2, dims);
  assert_true(back[0] == 7);
  H5Fclose(file);
}

/* The index lists frames 000000 .. n-1 in creation order, and says n. */
static void check_index(const char *dir, long n) {
  char path[512], name[32];
  long held = -1;
  snprintf(path, sizeof path, "%s/results.h5", dir);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  assert_true(file >= 0);
  hid_t a = H5Aopen(file, "frames", H5P_DEFAULT);
  assert_true(H5Aread(a, H5T_NATIVE_LONG, &held) >= 0);
  H5Aclose(a);
  assert_int_equal(held, n);
  hid_t g = H5Gopen2(file, "frames", H5P_DEFAULT);
  H5G_info_t info;
  assert_true(H5Gget_info(g, &info) >= 0);
  assert_int_equal(info.nlinks, n);
  for (long k = 0; k < n; k++) {
    assert_true(H5Lget_name_by_idx(g, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC,
                                   (hsize_t)k, name, sizeof name,
                                   H5P_DEFAULT) == 6);
    assert_int_equal(strtol(name, NULL, 10), k);
  }
  H5Gclose(g);
  H5Fclose(file);
}

/* Damage a file: cut its last bytes (a torn tail). */
static void cut_tail(const char *path) {
  struct stat st;
  assert_int_equal(stat(path, &st), 0);
  assert_int_equal(truncate(path, st.st_size - 5), 0);
}

/* Frames appended to the spares of the index and the XDMF: after every
 * frame both list exactly the frames written; the appended XDMF is byte for
 * byte the one rewritten whole (by a reopen); spares torn or missing are
 * rebuilt. */
static void test_many_frames(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double u[3 * NP], damage[NP], stress[9 * NP];
  char path[512], spare[512];
  pm_field f[3] = {
      {"displacement", 3, u}, {"damage", 1, damage}, {"stress", 9, stress}};
  const long n = 40;
  assert_ok(pm_results_create(dir, 3, NP, coords, NC, 4, tets, scene, "v", &r));
  for (long k = 0; k < n; k++) {
    fill_frame((int)k, u, damage, stress);
    if (k == 20) { /* torn spares: detected, rebuilt from the published */
      snprintf(spare, sizeof spare, "%s/results/.spare-results.xdmf", dir);
      cut_tail(spare);
      snprintf(spare, sizeof spare, "%s/results/.spare-results.h5", dir);
      cut_tail(spare);
    }
    if (k == 30) { /* missing spares */
      snprintf(spare, sizeof spare, "%s/results/.spare-results.xdmf", dir);
      assert_int_equal(unlink(spare), 0);
      snprintf(spare, sizeof spare, "%s/results/.spare-results.h5", dir);
      assert_int_equal(unlink(spare), 0);
    }
    assert_ok(pm_results_write_frame(r, 10 * k, 0.5 * (double)k, 3, f));
    check_index(dir, k + 1);
    snprintf(path, sizeof path, "%s/results.xdmf", dir);
    char *x = pm_test_slurp(path);
    assert_int_equal(count_in(x, x + strlen(x), "<Time Value="), k + 1);
    free(x);
  }
  pm_results_close(r, true);
  snprintf(path, sizeof path, "%s/results.xdmf", dir);
  char *appended = pm_test_slurp(path);
  python_check_xdmf(dir, "len(x.findall(\"Domain/Grid/Grid\")) == 40");
  /* A reopen keeping every frame rewrites both files whole. */
  assert_ok(pm_results_reopen(dir, NP, n, &r));
  pm_results_close(r, true);
  char *whole = pm_test_slurp(path);
  assert_string_equal(appended, whole);
  free(appended);
  free(whole);
  check_index(dir, n);
  /* The reopen removed the spares (a killed run's may be torn). */
  snprintf(spare, sizeof spare, "%s/results/.spare-results.h5", dir);
  assert_int_equal(access(spare, F_OK), -1);
  /* Frame 17's fields through the index's link. */
  snprintf(path, sizeof path, "%s/results.h5", dir);
  hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  assert_true(file >= 0);
  double back[NP];
  hsize_t dims[1] = {NP};
  read_doubles(file, "/frames/000017/damage", back, NP, 1, dims);
  assert_true(back[2] == 0.2 + 17);
  H5Fclose(file);
}

static void test_bad_arguments(void **state) {
  const char *dir = *state;
  pm_results *r = NULL;
  double v[3 * NP] = {0};
  long bad_tets[4 * NC] = {0, 1, 2, 3, 1, 2, 3, 5};

  assert_int_equal(
      pm_results_create(dir, 3, NP, coords, NC, 4, bad_tets, scene, "v", &r),
      PM_ERR_ARG);
  assert_null(r);
  assert_int_equal(
      pm_results_create(dir, 3, NP, coords, NC, 5, tets, scene, "v", &r),
      PM_ERR_ARG);
  assert_int_equal(
      pm_results_create(dir, 1, NP, coords, NC, 4, tets, scene, "v", &r),
      PM_ERR_ARG);
  assert_int_equal(pm_test_count_entries(dir, NULL), 0);

  assert_ok(pm_results_create(dir, 3, NP, coords, NC, 4, tets, scene, "v", &r));
  pm_field two = {"u", 2, v};
  assert_int_equal(pm_results_write_frame(r, 0, 0.0, 1, &two), PM_ERR_ARG);
  pm_field slash = {"a/b", 3, v};
  assert_int_equal(pm_results_write_frame(r, 0, 0.0, 1, &slash), PM_ERR_ARG);
  pm_field dup[2] = {{"u", 3, v}, {"u", 1, v}};
  assert_int_equal(pm_results_write_frame(r, 0, 0.0, 2, dup), PM_ERR_ARG);
  pm_field nodata = {"u", 3, NULL};
  assert_int_equal(pm_results_write_frame(r, 0, 0.0, 1, &nodata), PM_ERR_ARG);
  assert_int_equal(pm_results_frames(r), 0);
  pm_results_close(r, false);
  assert_int_equal(pm_test_count_entries(dir, NULL), 0);
  pm_error_clear();
}

static void test_bad_directory(void **state) {
  const char *dir = *state;
  pm_results *r = (pm_results *)1;
  char missing[512];
  snprintf(missing, sizeof missing, "%s/missing", dir);
  assert_int_equal(
      pm_results_create(missing, 3, NP, coords, NC, 4, tets, scene, "v", &r),
      PM_ERR_IO);
  assert_null(r);
  assert_non_null(strstr(pm_error_message(), missing));

  if (geteuid() != 0) { /* root ignores permissions */
    char ro[512];
    snprintf(ro, sizeof ro, "%s/readonly", dir);
    assert_int_equal(mkdir(ro, 0500), 0);
    assert_int_equal(
        pm_results_create(ro, 3, NP, coords, NC, 4, tets, scene, "v", &r),
        PM_ERR_IO);
    assert_non_null(strstr(pm_error_message(), ro));
    chmod(ro, 0700);
  }
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_write_read, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_abort_and_point_cloud,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_moving_and_reopen, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_many_frames, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_arguments, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_directory, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
