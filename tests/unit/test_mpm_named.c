/* test_mpm_named: MPM motions on a named edge of a gmsh body (the user
 * guide's tapered panel, coarse).  Implicit: the panel clamped on its
 * named edge `clamped` (along the grid's plane x = 0) holds the same
 * nodes as when clamped on the face xmin, so the two runs agree to
 * round-off.  Explicit: a velocity on the named edge `tip` moves its
 * particles as prescribed, and the reaction is reported. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_testing.h"
#include "mpm_traction.h"

static const char *const GEO =
    "lc = 1;\n"
    "Point(1) = {0, 0, 0, lc}; Point(2) = {10, 1, 0, lc};\n"
    "Point(3) = {10, 3, 0, lc}; Point(4) = {0, 4, 0, lc};\n"
    "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
    "Curve Loop(1) = {1, 2, 3, 4};\nPlane Surface(1) = {1};\n"
    "Physical Curve(\"clamped\") = {4};\nPhysical Curve(\"tip\") = {2};\n"
    "Physical Surface(\"panel\") = {1};\n";

static const char *const SCENE =
    "name: panel\nmethod: mpm-implicit\ndimension: 2\n"
    "domain: {box: {min: [0, 0], max: [10, 4]}}\n"
    "discretization: {mesh_size: 1}\n"
    "materials:\n  - {name: gel, model: neo-hookean, density: 1000, "
    "youngs_modulus: 3000, poisson_ratio: 0.45}\n"
    "bodies: [{material: gel, mesh: panel.geo}]\n"
    "boundary:\n  - {on: xmin, displacement: {x: 0, y: 0}}\n"
    "  - {on: tip, traction: {x: 2, y: 10}, ramp: smooth}\n"
    "time: {end: 1, quasi_static: {method: static, load_steps: 4}}\n";

static void write_panel(const char *dir, char path[512]) {
  pm_test_write_file(dir, "panel.geo", GEO, path);
  pm_test_write_file(dir, "panel.yaml", SCENE, path);
}

/* The static implicit run of the panel with overrides set[0..n) into *o. */
static void run_panel(const char *dir, const char *name, int n,
                      const char *const *set, pm_outcome *o) {
  char path[512], out[600];
  write_panel(dir, path);
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, n, set, &s));
  snprintf(out, sizeof out, "%s/%s", dir, name);
  assert_ok(pm_run_scene(s, out, true, o));
  pm_scene_destroy(s);
}

/* Clamped on the named edge or on the face: the same energies and work,
 * and the clamp's reaction balances the traction's resultant, (2, 10) Pa
 * on the 2 m tip. */
static void test_clamp_as_face(void **state) {
  static const char *const named[] = {"boundary.0.on=clamped"};
  pm_outcome face, edge;
  run_panel(*state, "face", 0, NULL, &face);
  run_panel(*state, "edge", 1, named, &edge);
  print_message("  strain energy %.12g (face) %.12g (named edge)\n",
                face.fig.strain, edge.fig.strain);
  assert_int_equal(edge.fig.status, PM_STATUS_CONVERGED);
  assert_true(face.fig.strain > 1);
  assert_near(edge.fig.strain, face.fig.strain, 1e-10 * face.fig.strain);
  assert_near(edge.fig.external_work, face.fig.external_work,
              1e-10 * face.fig.external_work);
  assert_near(edge.fig.reaction[0][0], -4, 1e-8);
  assert_near(edge.fig.reaction[0][1], -20, 1e-8);
}

/* Explicit: a velocity along x on the named edge `tip` (x = 10) moves
 * the particles at it by v t, and its reaction pulls the body. */
static void test_explicit_velocity(void **state) {
  char path[512];
  write_panel(*state, path);
  const char *set[] = {
      "method=mpm", "boundary.0.on=clamped",
      "boundary.1={on: tip, velocity: {x: 0.01, y: 0}, ramp: none}",
      "time.end=0.5"};
  model m = make_model(path, 4, set);
  const mpm_bc *bc = &m.model->bcs[1];
  assert_true(bc->grip);
  assert_true(bc->n_held >= 4);
  while (m.state->t < 0.5 - 1e-12) step(&m);
  const double t = m.state->t;
  for (long k = 0; k < bc->n_held; k++) {
    const long p = bc->held[k];
    assert_true(m.model->x0[3 * p] > 9);
    assert_near(m.state->x[3 * p], m.model->x0[3 * p] + 0.01 * t, 1e-12);
    assert_near(m.state->x[3 * p + 1], m.model->x0[3 * p + 1], 1e-12);
  }
  const double *r = m.work->cond.reaction;
  print_message("  t = %g s: reactions (%g, %g) on the named edges\n", t, r[3],
                r[4]);
  assert_true(r[3] > 0);
  drop_model(&m);
}

/* Where a named edge cannot act: absorbing, or a traction with a motion,
 * refused at the key. */
static void test_refused(void **state) {
  char path[512];
  write_panel(*state, path);
  const char *absorbing[] = {"method=mpm",
                             "boundary.0={on: clamped, absorbing: true}"};
  pm_scene *s = NULL;
  assert_int_equal(pm_scene_load(path, 2, absorbing, &s), PM_ERR_SCENE);
  assert_non_null(strstr(pm_error_message(), "boundary.0.absorbing"));
  const char *both[] = {
      "boundary.1={on: tip, traction: {y: 1}, displacement: {x: 0}}"};
  assert_int_equal(pm_scene_load(path, 1, both, &s), PM_ERR_SCENE);
  assert_non_null(strstr(pm_error_message(), "boundary.1.traction"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_clamp_as_face, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_explicit_velocity, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_refused, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
