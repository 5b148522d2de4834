/* test_membrane: membranes, bodies inside and outside them, and moving
 * bodies, from scene to a few steps: masses from areas, frames and normals
 * from the connectivity, which side each fluid lies on, the moving body's
 * exact path, the stages and arrays a scene brings (and a scene without
 * membranes does not), and the run's fields. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_testing.h"

/* A membrane sphere of radius 0.3 (642 points) with gas inside and
 * outside, and a small box moving as prescribed. */
static const char SCENE[] =
    "name: membrane\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5]}}\n"
    "discretization: {mesh_size: 0.125}\n"
    "materials:\n"
    "  - {name: skin, model: linear-elastic, density: 500, youngs_modulus: "
    "1.0e5, poisson_ratio: 0.3, damage: {c0: 1, c1: 1, elastic_limit: 0.1, "
    "failure_strain: 0.2}}\n"
    "  - {name: gas, model: fluid, density: 1.0, eos: {type: ideal-gas, "
    "gamma: 1.4}}\n"
    "  - {name: air, model: fluid, density: 1.0, eos: {type: ideal-gas, "
    "gamma: 1.4}}\n"
    "  - {name: steel, model: linear-elastic, density: 8000, youngs_modulus: "
    "2.0e11, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - {name: skin, material: skin, membrane: {thickness: 0.02, sphere: "
    "{center: [0, 0, 0], radius: 0.3, refinement: 3}}}\n"
    "  - {name: air, material: air, outside: skin, pressure: 100}\n"
    "  - {name: gas, material: gas, inside: skin, pressure: 200, "
    "particles_per_cell: [3]}\n"
    "  - {name: rod, material: steel, box: {min: [0.35, -0.05, -0.05], max: "
    "[0.45, 0.05, 0.05]}, particles_per_cell: [4], motion: {velocity: {y: "
    "\"0.1 * cos(10 * t)\"}}}\n"
    "mpm: {shape: quadratic, update: musl, particles_per_cell: [1]}\n"
    "time: {end: 0.01}\n";

static void test_seeding(void **state) {
  char path[512];
  pm_test_write_file(*state, "membrane.yaml", SCENE, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  const mpm_state *st = m.state;
  /* Groups: the membrane, the two fluids, the rigid rod. */
  assert_int_equal(md->n_groups, 4);
  assert_ptr_equal(md->group[0].kind, &mpm_kind_membrane);
  assert_ptr_equal(md->group[3].kind, &mpm_kind_rigid);
  assert_true(md->kinds & MPM_KIND_MEMBRANE);
  /* The membrane: 10 4^3 + 2 points, 20 4^3 triangles; mass = density x
   * thickness x area, the area the icosphere's (within its approximation
   * of the sphere: 1e-2 at r = 3). */
  const long mb = md->body_begin[0], me = md->body_end[0];
  assert_int_equal(me - mb, 642);
  assert_int_equal(md->n_tris, 1280);
  double mass = 0, vol = 0;
  for (long p = mb; p < me; p++) {
    mass += md->mass[p];
    vol += md->vol0[p];
  }
  const double area = 4 * PI * 0.3 * 0.3;
  assert_near(mass, 500 * 0.02 * area, 1e-2 * 500 * 0.02 * area);
  assert_near(mass, 500 * vol, 1e-12 * mass);
  /* Frames: orthonormal, the normal outward (n . x > 0 on a sphere about
   * the origin) and along x within the icosphere's facets. */
  const double *frame = group_array(m.state, 0, "frame");
  assert_non_null(frame);
  double worst = 0, worst_dir = 0;
  for (long k = 0; k < me - mb; k++) {
    const double *f = frame + 9 * k, *x = st->x + 3 * (mb + k);
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) {
        double d = pm_v_dot(f + 3 * a, f + 3 * b) - (a == b);
        worst = fmax(worst, fabs(d));
      }
    double r = pm_v_norm(x);
    worst_dir = fmax(worst_dir, 1 - pm_v_dot(f + 6, x) / r);
  }
  assert_true(worst < 1e-14);
  assert_true(worst_dir < 2e-3);
  /* The gas inside the sphere and the air outside it. */
  for (long p = md->body_begin[2]; p < md->body_end[2]; p++)
    assert_true(pm_v_norm(st->x + 3 * p) <= 0.3);
  for (long p = md->body_begin[1]; p < md->body_end[1]; p++)
    assert_true(pm_v_norm(st->x + 3 * p) > 0.29);
  /* Per-body particles per cell: the gas's volume is a 27th of a cell. */
  assert_near(md->vol0[md->body_begin[2]], pow(0.125, 3) / 27, 1e-18);
  /* The stages the scene brings. */
  assert_true(has_stage(&m, "stress: membrane"));
  assert_true(has_stage(&m, "motion"));
  drop_model(&m);
}

/* A few steps: the moving rod's particles follow y(t) = 0.01 sin(10 t)
 * (the midpoint rule on a velocity of a sine: second order), every state
 * finite, the membrane's arrays kept; and its output fields. */
static void test_steps(void **state) {
  char path[512];
  pm_test_write_file(*state, "membrane.yaml", SCENE, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  const long rb = md->body_begin[3];
  const double y0 = m.state->x[3 * rb + 1];
  double dt_max = 0;
  while (m.state->t < 0.01 - 1e-15) {
    step(&m);
    dt_max = fmax(dt_max, m.state->dt);
  }
  const double t = m.state->t;
  double y = m.state->x[3 * rb + 1] - y0, exact = 0.01 * sin(10 * t);
  /* The midpoint rule's error over the run is at most t dt^2 max|v''| / 24
   * with |v''| <= 10 (dt: the largest step taken). */
  const double bound = t * dt_max * dt_max * 10 / 24 + 1e-16;
  if (!(fabs(y - exact) <= bound))
    fail_msg("rod: y = %.17g, expected %.17g (bound %g)", y, exact, bound);
  assert_near(m.state->v[3 * rb + 1], 0.1 * cos(10 * t), 1e-15);
  for (long i = 0; i < 3 * md->n; i++) assert_true(isfinite(m.state->x[i]));
  for (long i = 0; i < 9 * md->n; i++) assert_true(isfinite(m.state->sigma[i]));
  assert_non_null(group_array(m.state, 0, "membrane_strain"));
  assert_non_null(group_array(m.state, 0, "failed"));
  drop_model(&m);
}

/* The fields and history of a run with membranes, through the backend. */
static void test_fields(void **state) {
  char path[512];
  pm_test_write_file(*state, "membrane.yaml", SCENE, path);
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  mpm_sim *r = NULL;
  assert_ok(mpm_sim_create(s, &r));
  pm_field f[16];
  int nf = mpm_backend.fields(r, PM_FIELD_STRESS, f, 16);
  const char *want[] = {"material", "normal", "damage", "failed"};
  for (int k = 0; k < 4; k++) {
    bool found = false;
    for (int j = 0; j < nf; j++) found |= strcmp(f[j].name, want[k]) == 0;
    if (!found) fail_msg("no field %s", want[k]);
  }
  pm_points pts;
  mpm_backend.points(r, &pts);
  assert_int_equal(pts.n_surface, 1280);
  const char *names[PM_HISTORY_MAX];
  int nh = mpm_backend.history_names(r, names, PM_HISTORY_MAX);
  bool inside = false, failed = false;
  for (int k = 0; k < nh; k++) {
    inside |= strcmp(names[k], "mass_inside_skin_gas") == 0;
    failed |= strcmp(names[k], "failed_points") == 0;
  }
  assert_true(inside && failed);
  double v[PM_HISTORY_MAX];
  mpm_backend.history_values(r, v);
  /* The gas inside its membrane: all of its mass. */
  double gas = 0;
  for (long p = r->model->body_begin[2]; p < r->model->body_end[2]; p++)
    gas += r->model->mass[p];
  for (int k = 0; k < nh; k++)
    if (strcmp(names[k], "mass_inside_skin_gas") == 0)
      assert_near(v[k], gas, 1e-12 * gas);
  mpm_sim_destroy(r);
  pm_scene_destroy(s);
}

/* A scene without membranes or moving bodies has none of their stages,
 * arrays or fields. */
static void test_absent(void **state) {
  char path[512];
  pm_test_write_file(*state, "two.yaml", TWO_BODIES, path);
  model m = make_model(path, 0, NULL);
  assert_false(has_stage(&m, "stress: membrane"));
  assert_false(has_stage(&m, "motion"));
  assert_false(m.model->kinds & MPM_KIND_MEMBRANE);
  assert_int_equal(m.model->n_tris, 0);
  assert_null(m.work->rigid_mass);
  for (int g = 0; g < m.model->n_groups; g++) assert_null(m.work->scratch[g]);
  drop_model(&m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_seeding, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_steps, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_fields, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_absent, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
