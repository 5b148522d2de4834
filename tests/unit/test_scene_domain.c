/* The domain of a scene that gives none: for FPM the bounds of its one
 * gmsh volume (read by gmsh, .geo and .msh alike) or of its one box body;
 * MPM and unbounded bodies refused with the key and what it takes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gm_gmsh.h"
#include "gm_mesh.h"
#include "pm_app.h"
#include "pm_scene.h"
#include "pm_testing.h"
#include "gmsh_testing.h"

/* Scenes named as if in tests/data/scenes, so that ../geometry resolves. */
#define NAME PM_TEST_DATA "/scenes/no-domain.yaml"
#define GEOMETRY PM_TEST_DATA "/geometry/"

/* A scene of method method, dimension dim, whose bodies line is body. */
static pm_err load(const char *method, int dim, const char *body,
                   pm_scene **s) {
  char text[1024];
  snprintf(text, sizeof text,
           "name: t\nmethod: %s\ndimension: %d\n"
           "discretization: {mesh_size: 0.5}\n"
           "materials:\n  - {name: gel, model: neo-hookean, density: 1000, "
           "youngs_modulus: 3000, poisson_ratio: 0.45}\n"
           "bodies: [%s]\n"
           "time: {end: 1}\n",
           method, dim, body);
  *s = NULL;
  pm_error_clear();
  return pm_scene_load_text(text, strlen(text), NAME, 0, NULL, s);
}

static void expect_box(const pm_scene *s, const double lo[3],
                       const double hi[3], double tol) {
  assert_true(s->domain_from_body);
  for (int c = 0; c < 3; c++) {
    assert_true(fabs(s->box_min[c] - lo[c]) <= tol);
    assert_true(fabs(s->box_max[c] - hi[c]) <= tol);
  }
}

/* A .geo's bounds (the tapered panel: [0, 10] x [0, 4]), a .msh's equal
 * to its nodes' bounds, and a box body's own box. */
static void test_bounds_from_body(void **state) {
  (void)state;
  pm_scene *s = NULL;
  assert_ok(load("fpm", 2,
                 "{material: gel, mesh: ../geometry/panel-corner.geo}", &s));
  expect_box(s, (double[3]){0, 0, 0}, (double[3]){10, 4, 0}, 1e-9);
  pm_scene_destroy(s);

  gm_mesh *m = NULL;
  assert_ok(
      gm_mesh_file(GEOMETRY "tet-groups.msh", 3, 0.0, GM_SIZES_REPLACE, &m));
  assert_ok(
      load("fpm", 3, "{material: gel, mesh: ../geometry/tet-groups.msh}", &s));
  expect_box(s, m->box_min, m->box_max, 1e-12);
  pm_scene_destroy(s);
  gm_mesh_destroy(m);

  assert_ok(load("fpm", 3,
                 "{material: gel, box: {min: [0, 0, 0], max: [1, 2, 3]}}", &s));
  expect_box(s, (double[3]){0, 0, 0}, (double[3]){1, 2, 3}, 0);
  pm_scene_destroy(s);
}

/* Refused with the key and what it takes: MPM (the grid needs room), a
 * body that does not bound the scene, a missing file. */
static void test_refused(void **state) {
  (void)state;
  static const struct {
    const char *method, *body, *frag;
  } bad[] = {
      {"mpm", "{material: gel, mesh: ../geometry/panel-corner.geo}",
       "domain: expected domain: {box: {min, max}} for method mpm"},
      {"fpm", "{material: gel, sphere: {center: [0, 0], radius: 1}}",
       "one gmsh volume (bodies.N.mesh) or one box body"},
      {"fpm", "{material: gel, mesh: ../geometry/none.geo}",
       "bodies.0.mesh: the bounds of"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    pm_scene *s = (pm_scene *)&s;
    assert_int_equal(load(bad[i].method, 2, bad[i].body, &s), PM_ERR_SCENE);
    assert_null(s);
    if (!strstr(pm_error_message(), bad[i].frag))
      fail_msg("message \"%s\" lacks \"%s\"", pm_error_message(), bad[i].frag);
    if (!strstr(pm_error_message(), "no-domain.yaml:"))
      fail_msg("message \"%s\" names no file", pm_error_message());
  }
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bounds_from_body),
      cmocka_unit_test(test_refused),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
