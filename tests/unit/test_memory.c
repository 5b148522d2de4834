/* test_memory: the memory available (MemAvailable, a cgroup limit, the
 * user's cap), the backends' estimates against what their simulations
 * measure, and the refusal of a scene estimated past the memory. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <math.h>
#include <stdint.h>

#include "pm_app.h"
#include "pm_backend.h"
#include "pm_memory.h"
#include "pm_scene.h"

#define MEMINFO                                                                \
  "MemTotal:       24684024 kB\n"                                              \
  "MemFree:        23000000 kB\n"                                              \
  "MemAvailable:    1048576 kB\n"

/* ---- the figure and its source ---------------------------------------- */

static void test_available(void **state) {
  const char *dir = *state;
  char meminfo[512], max[512], current[512], unlimited[512], nothing[512];
  pm_test_write_file(dir, "meminfo", MEMINFO, meminfo);
  pm_test_write_file(dir, "memory.max", "536870912\n", max);
  pm_test_write_file(dir, "memory.current", "134217728\n", current);
  pm_test_write_file(dir, "unlimited", "max\n", unlimited);
  snprintf(nothing, sizeof nothing, "%s/absent", dir);
  pm_memory_available a;

  /* MemAvailable alone: 1 GiB. */
  assert_ok(pm_memory_available_from(meminfo, nothing, nothing, NULL, &a));
  assert_int_equal(a.bytes, (size_t)1 << 30);
  assert_non_null(strstr(a.source, "MemAvailable in "));

  /* A cgroup limit of 512 MiB with 128 MiB used: 384 MiB, named with the
   * MemAvailable it beat. */
  assert_ok(pm_memory_available_from(meminfo, max, current, NULL, &a));
  assert_int_equal(a.bytes, (size_t)384 << 20);
  assert_non_null(strstr(a.source, "cgroup limit 512.0 MiB"));
  assert_non_null(strstr(a.source, "lower than MemAvailable 1.0 GiB"));

  /* "max" is no limit; a limit above MemAvailable is not the figure. */
  assert_ok(pm_memory_available_from(meminfo, unlimited, current, NULL, &a));
  assert_int_equal(a.bytes, (size_t)1 << 30);
  assert_ok(pm_memory_available_from(meminfo, nothing, nothing, "2G", &a));
  assert_int_equal(a.bytes, (size_t)1 << 30);

  /* The user's cap, with a suffix, when lower. */
  assert_ok(pm_memory_available_from(meminfo, max, current, "100M", &a));
  assert_int_equal(a.bytes, (size_t)100 << 20);
  assert_non_null(strstr(a.source, "POINTMECH_MEMORY_LIMIT=100M"));
  assert_ok(pm_memory_available_from(nothing, nothing, nothing, "4096", &a));
  assert_int_equal(a.bytes, 4096);

  assert_fails(pm_memory_available_from(meminfo, nothing, nothing, "2X", &a),
               PM_ERR_ARG, "got \"2X\"");
  assert_fails(pm_memory_available_from(meminfo, nothing, nothing, "-1", &a),
               PM_ERR_ARG, "POINTMECH_MEMORY_LIMIT");
  assert_fails(pm_memory_available_from(nothing, nothing, nothing, NULL, &a),
               PM_ERR_IO, "no memory figure");

  /* Across ranks: the machine's figure shared by its 4 ranks, the cap
   * each one's. */
  assert_ok(pm_memory_available_shared(meminfo, max, current, NULL, 4, &a));
  assert_int_equal(a.bytes, (size_t)96 << 20);
  assert_non_null(strstr(a.source, "shared by the 4 ranks on this machine"));
  assert_ok(
      pm_memory_available_shared(meminfo, nothing, nothing, "200M", 4, &a));
  assert_int_equal(a.bytes, (size_t)200 << 20);
  assert_ok(
      pm_memory_available_shared(meminfo, nothing, nothing, "300M", 4, &a));
  assert_int_equal(a.bytes, (size_t)256 << 20);
}

/* ---- a rank's share ------------------------------------------------------ */

/* The points a rank holds: its part and the ghost layers over two faces
 * of a cube of its points, at most all of them; and a rank's estimate: its
 * share of the whole, with the whole where the setup builds it. */
static void test_rank_estimate(void **state) {
  (void)state;
  assert_true(fabs(pm_memory_share_points(8e6, 8, 3, 2) - (1e6 + 2 * 2 * 1e4)) <
              1e-6);
  assert_true(pm_memory_share_points(1e6, 1, 3, 5) == 1e6);
  assert_true(pm_memory_share_points(4000, 2, 3, 5) <= 4000);
  char path[1024];
  snprintf(path, sizeof path, "%s/cases/fpm/f2-unconstrained-compression.yaml",
           PM_SOURCE_DIR);
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  long whole_points = 0, held = 0;
  const size_t whole =
      pm_memory_rank_estimate(s, 1, false, false, &whole_points);
  assert_int_equal(whole, s->backend->estimate_bytes(s, &held));
  const size_t rank = pm_memory_rank_estimate(s, 1000, false, false, &held);
  assert_true(held > 0 && held < whole_points);
  const double geometry = (double)s->backend->geometry_bytes(s);
  const double share = ((double)whole - geometry) * held / whole_points;
  /* a rank that does not mesh: the part it receives, with its model, and
   * its share */
  const double part = pm_memory_share_points(
      (double)whole_points, 1000, s->dimension, s->backend->part_layers(s));
  assert_true(part > held && part < whole_points);
  const double expect = s->backend->setup_whole
                            ? whole + share
                            : (double)whole * part / whole_points + share;
  /* rank 0, which meshes and keeps no whole model: the whole geometry,
   * and the part it cuts for itself, with its model, and its share */
  long held0 = 0;
  const size_t rank0 = pm_memory_rank_estimate(s, 1000, false, true, &held0);
  const double part0 = (double)whole * part / whole_points;
  assert_true(fabs((double)rank0 - (geometry + part0 + share)) <=
              1 + (double)whole / whole_points);
  /* held is the figure's whole points (a point's bytes apart) */
  assert_true(fabs((double)rank - expect) <= 1 + (double)whole / whole_points);
  print_message("f2 at %ld points: %zu bytes on one process, %zu on the "
                "largest of 1000 ranks (%ld points held)\n",
                whole_points, whole, rank, held);
  pm_scene_destroy(s);
}

/* ---- estimates against measured memory --------------------------------- */

/* The estimate of a case, before setup, is at least what the simulation
 * then holds (pm_figures.memory_bytes) and at most `ratio` times it. */
static void check_estimate(const char *scene, double ratio) {
  char path[1024];
  snprintf(path, sizeof path, "%s/cases/%s", PM_SOURCE_DIR, scene);
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  long points = 0;
  size_t estimate = s->backend->estimate_bytes(s, &points);
  void *sim = NULL;
  assert_ok(s->backend->create(s, &sim));
  pm_figures f;
  memset(&f, 0, sizeof f);
  s->backend->figures(sim, &f, false);
  double r = (double)estimate / (double)f.memory_bytes;
  if (!(r >= 1 && r <= ratio))
    fail_msg("%s: estimate %zu bytes (%ld points) over measured %zu bytes "
             "(%ld points) = %.3f, expected in [1, %g]",
             scene, estimate, points, f.memory_bytes, f.points, r, ratio);
  /* The point count itself within 30%. */
  assert_close((double)points, (double)f.points, 0.3, 0);
  s->backend->destroy(sim);
  pm_scene_destroy(s);
}

static void test_estimates(void **state) {
  (void)state;
  /* FPM's estimate adds the mesh and subdomains (about as much again as
   * the operators and state, measured as resident memory). */
  check_estimate("fpm/f2-unconstrained-compression.yaml", 2.5);
  check_estimate("fpm/f1-compression.yaml", 2.5);
  check_estimate("mpm/f2-unconstrained-compression.yaml", 2);
  check_estimate("mpm/m2-shock-tube.yaml", 2);
  check_estimate("mpm/disks-collision.yaml", 2);
}

/* ---- the refusal ------------------------------------------------------- */

static void test_refusal(void **state) {
  (void)state;
  char path[1024];
  snprintf(path, sizeof path, "%s/cases/mpm/f2-unconstrained-compression.yaml",
           PM_SOURCE_DIR);
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  const char *was = getenv("POINTMECH_MEMORY_LIMIT");
  char *saved = was ? strdup(was) : NULL;
  setenv("POINTMECH_MEMORY_LIMIT", "1M", 1);
  assert_fails(pm_memory_check(s), PM_ERR_MEMORY, "is available");
  /* Both figures, in bytes, and where the available one comes from. */
  long points;
  char need[64];
  snprintf(need, sizeof need, "(%zu bytes, ",
           s->backend->estimate_bytes(s, &points));
  assert_non_null(strstr(pm_error_message(), need));
  assert_non_null(strstr(pm_error_message(), "1.0 MiB (1048576 bytes)"));
  assert_non_null(strstr(pm_error_message(), "POINTMECH_MEMORY_LIMIT=1M"));
  pm_memory_set_force(true);
  assert_ok(pm_memory_check(s));
  pm_memory_set_force(false);
  setenv("POINTMECH_MEMORY_LIMIT", "1T", 1);
  assert_ok(pm_memory_check(s));
  if (saved)
    setenv("POINTMECH_MEMORY_LIMIT", saved, 1);
  else
    unsetenv("POINTMECH_MEMORY_LIMIT");
  free(saved);
  pm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_available, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_estimates),
      cmocka_unit_test(test_rank_estimate),
      cmocka_unit_test(test_refusal),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
