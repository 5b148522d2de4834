/* test_gmsh_api: gmsh opened on first use.  A process maps libgmsh only
 * once a session begins; a library that cannot be opened, or that lacks a
 * function of the table, fails with a message naming the library, the
 * function and what needed it; the library the build found then loads,
 * and a box meshes through the table. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "pm_testing.h"

#include "gm_gmsh_api.h"
#include "gm_mesh.h"
#include "pm_isolate.h"

/* Whether a mapping of this process comes from a file named like name. */
static bool mapped(const char *name) {
  FILE *f = fopen("/proc/self/maps", "r");
  assert_non_null(f);
  char line[4096];
  bool found = false;
  while (!found && fgets(line, sizeof line, f)) found = strstr(line, name);
  fclose(f);
  return found;
}

static void test_not_mapped_before_use(void **state) {
  (void)state;
  assert_false(mapped("libgmsh"));
  assert_false(mapped("libTKernel"));
}

static void test_missing_library(void **state) {
  (void)state;
  assert_fails(
      gm_gmsh_api_load_from("libpm-no-such-gmsh.so.0", "reading 'cube.msh'"),
      PM_ERR_UNSUPPORTED,
      "gmsh library libpm-no-such-gmsh.so.0 cannot be loaded, and "
      "reading 'cube.msh' needs it");
  assert_false(mapped("libgmsh"));
}

/* The C library itself, opened in gmsh's stead, has none of its functions:
 * the first in the table is named. */
static void test_library_without_gmsh(void **state) {
  (void)state;
  assert_fails(gm_gmsh_api_load_from("libc.so.6", "meshing a box"),
               PM_ERR_UNSUPPORTED,
               "gmsh library libc.so.6 lacks gmshFinalize, and "
               "meshing a box needs it");
}

/* A box is meshed in a child process: the process itself never maps gmsh.
 * Meshed here instead, the table is filled on first use. */
static void test_box_through_table(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  gm_mesh *m = NULL;
  assert_ok(gm_mesh_box(3, lo, hi, 0.5, &m));
  assert_true(m->n_nodes >= 8);
  assert_true(m->n_cells >= 6);
  assert_int_equal(mapped("libgmsh"), !pm_isolate_enabled());
  gm_gmsh_mesh raw = {.dim = 0};
  assert_ok(gm_mesh_box_raw_here(3, lo, hi, 0.5, NULL, &raw));
  assert_int_equal(raw.n_nodes, m->n_nodes);
  assert_int_equal(raw.n_elems, m->n_cells);
  gm_gmsh_mesh_free(&raw);
  gm_mesh_destroy(m);
  assert_true(mapped("libgmsh"));
  /* Opened once: a second request finds the table filled. */
  assert_ok(gm_gmsh_api_load_from("libpm-no-such-gmsh.so.0", "again"));
}

int main(void) {
  /* In this order: the library is mapped by the last. */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_not_mapped_before_use),
      cmocka_unit_test(test_missing_library),
      cmocka_unit_test(test_library_without_gmsh),
      cmocka_unit_test(test_box_through_table),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
