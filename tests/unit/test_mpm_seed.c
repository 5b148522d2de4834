/* test_mpm_seed: scenes into particles: bad MPM scenes refused at the key
 * at fault, and seeding (positions, volumes, masses, shapes). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_testing.h"

/* ---- 4. bad scenes --------------------------------------------------------
 */

static void assert_message(const char *f1, const char *f2, const char *f3) {
  const char *msg = pm_error_message();
  const char *frag[] = {f1, f2, f3};
  for (int k = 0; k < 3; k++)
    if (frag[k] && !strstr(msg, frag[k]))
      fail_msg("message \"%s\" lacks \"%s\"", msg, frag[k]);
}

#define BAD_HEAD                                                               \
  "name: bad\n"                                                                \
  "method: mpm\n"                                                              \
  "dimension: 3\n"                                                             \
  "domain: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
#define BAD_GEL                                                                \
  "materials:\n"                                                               \
  "  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: 1.0e4, " \
  "poisson_ratio: 0.3}\n"

static const struct {
  const char *name, *text;
  const char *at;   /* where the message points */
  const char *key;  /* the key path it names */
  const char *what; /* what it expected */
  bool at_create;   /* the scene loads; the model refuses it */
} BAD[] = {
    {"no-eos.yaml",
     BAD_HEAD "discretization: {mesh_size: 0.25}\n"
              "materials:\n"
              "  - {name: gas, model: fluid, density: 1.0}\n"
              "bodies:\n"
              "  - {material: gas, pressure: 1.0}\n"
              "time: {end: 1}\n",
     "{name: gas", ": materials.0.eos: ", "missing required key", false},
    {"negative-mesh.yaml",
     BAD_HEAD "discretization: {mesh_size: -0.1}\n" BAD_GEL "time: {end: 1}\n",
     "-0.1", ": discretization.mesh_size: ", "expected a number > 0, got -0.1",
     false},
    {"sphere-outside.yaml",
     BAD_HEAD "discretization: {mesh_size: 0.25}\n" BAD_GEL "bodies:\n"
              "  - {material: gel, sphere: {center: [0.5, 0.5, 0.5], radius: "
              "0.3}}\n"
              "  - {material: gel, sphere: {center: [0.9, 0.5, 0.5], radius: "
              "0.2}}\n"
              "time: {end: 1}\n",
     "{material: gel, sphere: {center: [0.9", ": bodies.1.sphere: ",
     "x in [0, 1]), got one reaching x = 1.1: its particles would be outside "
     "the grid",
     true},
    {"solid-pressure.yaml",
     BAD_HEAD "discretization: {mesh_size: 0.25}\n" BAD_GEL "bodies:\n"
              "  - {material: gel, box: {min: [0, 0, 0], max: [1, 1, 1]}, "
              "pressure: 2.0e3}\n"
              "time: {end: 1}\n",
     "pressure:", ": bodies.0.pressure: ",
     "got pressure (material gel is not a fluid)", false},
    {"flip.yaml",
     BAD_HEAD "discretization: {mesh_size: 0.25}\n" BAD_GEL
              "mpm: {shape: linear, flip: 1.5}\n"
              "time: {end: 1}\n",
     "1.5", ": mpm.flip: ", "expected a number in [0, 1], got 1.5", false},
};

static void test_bad_scenes(void **state) {
  char path[512], at[600];
  for (size_t k = 0; k < sizeof BAD / sizeof BAD[0]; k++) {
    pm_test_write_file(*state, BAD[k].name, BAD[k].text, path);
    pm_test_locate(path, BAD[k].text, BAD[k].at, at, sizeof at);
    pm_scene *s = (pm_scene *)&s; /* must be reset to NULL */
    pm_error_clear();
    if (!BAD[k].at_create) {
      assert_int_equal(pm_scene_load(path, 0, NULL, &s), PM_ERR_SCENE);
      assert_null(s);
    } else {
      assert_ok(pm_scene_load(path, 0, NULL, &s));
      mpm_model *md = (mpm_model *)&md; /* must be reset to NULL */
      mpm_state *st = (mpm_state *)&st;
      assert_int_equal(mpm_model_create(s, &md, &st), PM_ERR_SCENE);
      assert_null(md);
      assert_null(st);
      pm_scene_destroy(s);
    }
    /* Where and which key, then what was expected. */
    char where[700];
    snprintf(where, sizeof where, "%s%s", at, BAD[k].key);
    assert_message(where, BAD[k].what, NULL);
    print_message("%s\n", pm_error_message());
  }
  /* The same sphere reaching below y = 0 names that side. */
  pm_test_write_file(*state, "sphere-low.yaml", BAD[2].text, path);
  pm_test_locate(path, BAD[2].text, BAD[2].at, at, sizeof at);
  const char *low = "bodies.1.sphere.center=[0.5, 0.1, 0.5]";
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 1, &low, &s));
  mpm_model *md = NULL;
  mpm_state *st = NULL;
  assert_int_equal(mpm_model_create(s, &md, &st), PM_ERR_SCENE);
  char where[700];
  snprintf(where, sizeof where, "%s: bodies.1.sphere: ", at);
  assert_message(where, "y in [0, 1]), got one reaching y = -0.1",
                 "outside the grid");
  pm_scene_destroy(s);
  /* A scene of another method is refused as an argument error. */
  assert_ok(pm_scene_load(PM_TEST_DATA "/scenes/f2-unconstrained-"
                                       "compression.yaml",
                          0, NULL, &s));
  assert_int_equal(mpm_model_create(s, &md, &st), PM_ERR_ARG);
  assert_null(md);
  assert_null(st);
  pm_scene_destroy(s);
}

/* ---- 8. seeding ------------------------------------------------------------
 */

static void test_seed_box(void **state) {
  (void)state;
  const char *set[] = {
      "mpm.particles_per_cell=[2, 2]",
      "bodies=[{material: rubber, box: {min: [0, 0], max: [1, 0.5]}, "
      "density: 800}]",
  };
  model m = make_model(MINIMAL, 2, set);
  const mpm_model *md = m.model;
  const mpm_state *st = m.state;
  const double h = 0.1, area = 1.0 * 0.5;
  enum { NX = 10, NY = 5 };
  assert_int_equal(md->n, 4 * NX * NY);
  int count[NX][NY];
  memset(count, 0, sizeof count);
  double vol = 0;
  for (long p = 0; p < md->n; p++) {
    const double *x = st->x + 3 * p;
    int i = (int)floor(x[0] / h), j = (int)floor(x[1] / h);
    assert_true(i >= 0 && i < NX && j >= 0 && j < NY);
    count[i][j]++;
    /* Seeds at a quarter and three quarters of the cell. */
    double fx = x[0] / h - i, fy = x[1] / h - j;
    assert_true(fabs(fx - 0.25) < 1e-9 || fabs(fx - 0.75) < 1e-9);
    assert_true(fabs(fy - 0.25) < 1e-9 || fabs(fy - 0.75) < 1e-9);
    assert_near(x[2], 0.0, 0);
    /* h^2 / 4 and density times it, rounded once each. */
    assert_near(md->vol0[p], h * h / 4, 2 * EPS * h * h / 4);
    assert_near(st->vol[p], md->vol0[p], 0);
    assert_near(md->mass[p], 800 * md->vol0[p], 2 * EPS * md->mass[p]);
    vol += md->vol0[p];
  }
  for (int i = 0; i < NX; i++)
    for (int j = 0; j < NY; j++) assert_int_equal(count[i][j], 4);
  assert_near(vol, area, 1e-13 * area); /* a sum of 200 equal terms */
  drop_model(&m);
}

/* Seeded volume of a sphere (3-D) or disk (2-D) of radius R at h = R/n. */
static double seeded_volume(const char *dir, int dim, double R, int n) {
  char text[1024], path[512], name[64];
  double h = R / n;
  snprintf(text, sizeof text,
           "name: ball\n"
           "method: mpm\n"
           "dimension: %d\n"
           "domain: {box: {min: [0, 0%s], max: [1, 1%s]}}\n"
           "discretization: {mesh_size: %.17g}\n"
           "materials:\n"
           "  - {name: gel, model: neo-hookean, density: 1000, "
           "youngs_modulus: 1.0e4, poisson_ratio: 0.3}\n"
           "bodies:\n"
           "  - {material: gel, sphere: {center: [0.5, 0.5%s], radius: "
           "%.17g}}\n"
           "time: {end: 1}\n",
           dim, dim == 3 ? ", 0" : "", dim == 3 ? ", 1" : "", h,
           dim == 3 ? ", 0.5" : "", R);
  snprintf(name, sizeof name, "ball-%dd-%d.yaml", dim, n);
  pm_test_write_file(dir, name, text, path);
  model m = make_model(path, 0, NULL);
  double vol = 0;
  for (long p = 0; p < m.model->n; p++) {
    vol += m.model->vol0[p];
    assert_near(m.model->mass[p], 1000 * m.model->vol0[p], 1e-12);
  }
  drop_model(&m);
  return vol;
}

static void test_seed_sphere(void **state) {
  const double R = 0.4, exact3 = 4.0 / 3.0 * PI * R * R * R,
               exact2 = PI * R * R;
  /* Counting lattice points (spacing h/2) in a ball: the error is a
   * surface effect of relative size ~ h / R, less by cancellation.
   * Bounds: 8% at h = R/2, 5% at R/4, 2% at R/8 (observed: 4.5%, 1.5%,
   * 0.6% for the sphere, 3.5%, 3.5%, 1.0% for the disk). */
  static const int n[] = {2, 4, 8};
  static const double tol[] = {0.08, 0.05, 0.02};
  for (int k = 0; k < 3; k++) {
    double e3 = seeded_volume(*state, 3, R, n[k]) / exact3 - 1;
    double e2 = seeded_volume(*state, 2, R, n[k]) / exact2 - 1;
    print_message("h = R/%d: sphere volume error %+.4f, disk area %+.4f\n",
                  n[k], e3, e2);
    assert_true(fabs(e3) <= tol[k]);
    assert_true(fabs(e2) <= tol[k]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_bad_scenes, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_seed_box),
      cmocka_unit_test_setup_teardown(test_seed_sphere, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
