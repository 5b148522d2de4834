/* test_mpm_traction: MPM tractions on a named edge of a gmsh body (the
 * user guide's tapered panel, coarse): the carriers' areas add up to the
 * edge's length, the nodal forces to the traction times it, and a static
 * implicit run closes its energy balance with the tractions' work. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_panel_testing.h"
#include "mpm_testing.h"
#include "mpm_traction.h"
#include "gmsh_testing.h"

/* The sum of the tractions' nodal forces at full load into sum. */
static void resultant(const model *m, double sum[3]) {
  const long n3 = 3 * m->model->grid.n_nodes;
  double *f = calloc((size_t)n3, sizeof *f);
  assert_non_null(f);
  mpm_tractions_nodal(m->model, &m->model->grid, m->model->x0, NULL, 1.0, f);
  for (int c = 0; c < 3; c++) sum[c] = 0;
  for (long i = 0; i < n3; i++) sum[i % 3] -= f[i];
  free(f);
}

/* Sum of the nodal forces = traction x edge length (2 m). */
static void test_resultant(void **state) {
  char path[512];
  write_panel(*state, path);
  model m = make_model(path, 0, NULL);
  const mpm_bc *bc = &m.model->bcs[1];
  double length = 0;
  for (long k = 0; k < bc->n_held; k++) length += bc->area[k];
  assert_near(length, 2.0, 1e-12);
  double sum[3];
  resultant(&m, sum);
  assert_near(sum[0], 4.0, 1e-12);
  assert_near(sum[1], 20.0, 1e-12);
  drop_model(&m);
}

/* In 3-D, on a Physical Surface: the forces add up to the traction times
 * the face's area (1 m^2). */
static void test_resultant_3d(void **state) {
  char path[512];
  pm_test_write_file(*state, "block.geo",
                     "SetFactory(\"OpenCASCADE\");\n"
                     "Box(1) = {0, 0, 0, 1, 1, 2};\n"
                     "Physical Volume(\"block\") = {1};\n"
                     "Physical Surface(\"top\") = {6};\n",
                     path);
  pm_test_write_file(
      *state, "block.yaml",
      "name: block\nmethod: mpm-implicit\ndimension: 3\n"
      "domain: {box: {min: [0, 0, 0], max: [1, 1, 2]}}\n"
      "discretization: {mesh_size: 0.5}\n"
      "materials:\n  - {name: gel, model: neo-hookean, density: 1000, "
      "youngs_modulus: 3000, poisson_ratio: 0.3}\n"
      "bodies: [{material: gel, mesh: block.geo}]\n"
      "boundary:\n  - {on: zmin, displacement: {x: 0, y: 0, z: 0}}\n"
      "  - {on: top, traction: {y: -30, z: 100}}\n"
      "time: {end: 1, quasi_static: {method: static, load_steps: 2}}\n",
      path);
  model m = make_model(path, 0, NULL);
  double sum[3];
  resultant(&m, sum);
  assert_near(sum[0], 0.0, 1e-12);
  assert_near(sum[1], -30.0, 1e-11);
  assert_near(sum[2], 100.0, 1e-11);
  drop_model(&m);
}

/* A name no gmsh body has is refused, naming the key. */
static void test_unknown_name(void **state) {
  char path[512];
  write_panel(*state, path);
  const char *set[] = {"boundary.1.on=nowhere"};
  pm_scene *s = NULL;
  mpm_model *mm = NULL;
  mpm_state *st = NULL;
  assert_ok(pm_scene_load(path, 1, set, &s));
  assert_int_equal(mpm_model_create(s, &mm, &st), PM_ERR_SCENE);
  assert_non_null(strstr(pm_error_message(), "boundary.1.on"));
  assert_non_null(strstr(pm_error_message(), "nowhere"));
  pm_scene_destroy(s);
}

/* A named edge takes a traction or a motion, not both: refused at its
 * key. */
static void test_refused(void **state) {
  char path[512];
  write_panel(*state, path);
  const char *set[] = {"boundary.1.traction={y: 10}",
                       "boundary.1.displacement={x: 0}"};
  pm_scene *s = NULL;
  assert_int_equal(pm_scene_load(path, 2, set, &s), PM_ERR_SCENE);
  assert_non_null(strstr(pm_error_message(), "boundary.1.traction"));
  assert_non_null(strstr(pm_error_message(), "one condition each"));
}

/* The energy balance of the static run: strain energy = the tractions'
 * work (trapezoid over 10 load steps), the supports fixed; without F-bar
 * and with it (the energy of Fbar, from which its residual derives). */
static void test_energy(void **state) {
  static const char *const fbar[] = {"mpm.fbar=none", "mpm.fbar=cell"};
  for (int k = 0; k < 2; k++) {
    char path[512], out[600];
    write_panel(*state, path);
    pm_scene *s = NULL;
    assert_ok(pm_scene_load(path, 1, &fbar[k], &s));
    snprintf(out, sizeof out, "%s/run%d", (const char *)*state, k);
    pm_outcome o;
    assert_ok(pm_run_scene(s, out, true, &o));
    print_message("  %s: energy error %.3g of external work %.6g\n", fbar[k],
                  o.fig.energy_error, o.fig.external_work);
    assert_true(o.fig.external_work > 1);
    assert_near(o.fig.energy_error, 0, 1e-3);
    assert_near(o.fig.reaction[0][1], -20, 1e-8);
    pm_scene_destroy(s);
  }
}

/* A load curve on the traction (here the constant 0.5) scales it: the
 * clamp holds half the force, and the balance still closes. */
static void test_curve(void **state) {
  char path[512], out[600];
  write_panel(*state, path);
  static const char *const set[] = {"boundary.1.curve=0.5"};
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 1, set, &s));
  snprintf(out, sizeof out, "%s/run", (const char *)*state);
  pm_outcome o;
  assert_ok(pm_run_scene(s, out, true, &o));
  print_message("  curve 0.5: clamp reaction %.12g N, energy error %.3g\n",
                o.fig.reaction[0][1], o.fig.energy_error);
  assert_near(o.fig.reaction[0][1], -10, 1e-8);
  assert_near(o.fig.energy_error, 0, 1e-3);
  pm_scene_destroy(s);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_resultant, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_resultant_3d, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_refused, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_unknown_name, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_curve, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_energy, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
