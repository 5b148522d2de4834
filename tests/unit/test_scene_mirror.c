/* Symmetry planes (boundary: {on: FACE, symmetry: true}): the scene holds
 * the normal component at 0 on the face and records the plane; the whole
 * body's reaction and lattice values come from the part's by mirroring;
 * the key is refused where it cannot be a plane of symmetry. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_app.h"
#include "pm_expr.h"
#include "pm_scene.h"
#include "pm_scene_mirror.h"
#include "pm_testing.h"

#define NAME "mirror.yaml"

/* The quarter x, y >= 0.05 of the 0.1 m block, pulled along z, with the
 * boundary lines bcs after the two clamps. */
static pm_err load(const char *box_min, const char *bcs, pm_scene **s) {
  char text[2048];
  snprintf(text, sizeof text,
           "name: t\nmethod: fpm\ndimension: 3\n"
           "domain: {box: {min: %s, max: [0.1, 0.1, 0.1]}}\n"
           "discretization: {mesh_size: 0.02}\n"
           "materials:\n  - {name: gel, model: neo-hookean, density: 1000, "
           "youngs_modulus: 3000, poisson_ratio: 0.45}\n"
           "bodies: [{material: gel, region: domain}]\n"
           "boundary:\n"
           "  - {on: zmin, displacement: {x: 0, y: 0, z: 0}}\n"
           "  - {on: zmax, displacement: {x: 0, y: 0, z: 0.06}}\n%s"
           "time: {end: 1}\n",
           box_min, bcs);
  pm_error_clear();
  return pm_scene_load_text(text, strlen(text), NAME, 0, NULL, s);
}

static void test_quarter(void **state) {
  (void)state;
  pm_scene *s = NULL;
  assert_ok(load("[0.05, 0.05, 0]",
                 "  - {on: xmin, symmetry: true}\n"
                 "  - {on: ymin, symmetry: true}\n",
                 &s));
  assert_int_equal(s->mirror_mask, 3u);
  assert_near(s->mirror_at[0], 0.05, 0);
  assert_near(s->mirror_at[1], 0.05, 0);
  /* Each plane holds its normal component at 0, at once. */
  for (int b = 2; b < 4; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    assert_true(bc->symmetry);
    assert_int_equal(bc->disp_mask, 1u << (b - 2));
    assert_near(pm_expr_eval(bc->disp[b - 2], 0.05, 0.07, 0.03, 0.5), 0, 0);
    assert_int_equal(bc->ramp, PM_RAMP_NONE);
  }
  /* The top face crosses both planes: its z force four times, its x and y
   * forces cancel; a face on the x plane's side (xmin itself) doubles by
   * the y plane alone. */
  assert_near(pm_scene_mirror_factor(s, 2, 2), 4, 0);
  assert_near(pm_scene_mirror_factor(s, 2, 0), 0, 0);
  assert_near(pm_scene_mirror_factor(s, 0, 0), 2, 0);
  /* A boundary of no known orientation (a region): along the planes
   * doubled by each, across one not known. */
  assert_near(pm_scene_mirror_factor(s, -1, 2), 4, 0);
  assert_true(isnan(pm_scene_mirror_factor(s, -1, 0)));
  /* The conditions' own axes: a face's, a plate's normal along an axis. */
  assert_int_equal(pm_scene_bc_axis(&s->bcs[1]), 2);
  pm_scene_bc plate = {.on = PM_ON_PLATE, .rigid_normal = {-1, 0, 0}};
  assert_int_equal(pm_scene_bc_axis(&plate), 0);
  plate.rigid_normal[0] = -0.6;
  plate.rigid_normal[1] = 0.8;
  assert_int_equal(pm_scene_bc_axis(&plate), -1);
  /* A point of another quarter takes its image's value in this one. */
  double y[3], v[3] = {1, 2, 3};
  unsigned flips = pm_scene_mirror_fold(s, (double[3]){0.02, 0.07, 0.03}, y);
  assert_int_equal(flips, 1u);
  assert_near(y[0], 0.08, 1e-15);
  assert_near(y[1], 0.07, 0);
  pm_scene_mirror_unfold(flips, v);
  assert_near(v[0], -1, 0);
  assert_near(v[1], 2, 0);
  flips = pm_scene_mirror_fold(s, (double[3]){0.01, 0.01, 0.05}, y);
  assert_int_equal(flips, 3u);
  assert_near(y[0], 0.09, 1e-15);
  assert_near(y[1], 0.09, 1e-15);
  flips = pm_scene_mirror_fold(s, (double[3]){0.06, 0.07, 0.05}, y);
  assert_int_equal(flips, 0u);
  pm_scene_destroy(s);

  /* The part below its plane: the half x <= 0.1 mirrored about xmax. */
  assert_ok(load("[0, 0, 0]", "  - {on: xmax, symmetry: true}\n", &s));
  assert_near(s->mirror_at[0], 0.1, 0);
  flips = pm_scene_mirror_fold(s, (double[3]){0.13, 0.07, 0.03}, y);
  assert_int_equal(flips, 1u);
  assert_near(y[0], 0.07, 1e-15);
  assert_int_equal(pm_scene_mirror_fold(s, (double[3]){0.02, 0, 0}, y), 0u);
  pm_scene_destroy(s);
}

/* Refused with the key and what it takes. */
static void test_refused(void **state) {
  (void)state;
  static const struct {
    const char *bcs, *frag;
  } bad[] = {
      {"  - {region: x - 0.09, symmetry: true}\n",
       "boundary.2.symmetry: expected symmetry on a face xmin ... zmax"},
      {"  - {on: xmin, symmetry: true, displacement: {y: 0}}\n",
       "boundary.2.displacement: expected symmetry alone"},
      {"  - {on: xmin, symmetry: true, traction: {x: 1}}\n",
       "boundary.2.traction: expected symmetry alone"},
      {"  - {on: xmin, symmetry: true}\n  - {on: xmax, symmetry: true}\n",
       "boundary.3.on: expected one symmetry plane normal to x"},
      {"  - {on: xmin, symmetry: true, ramp: linear}\n",
       "boundary.2.ramp: expected symmetry alone"},
      {"  - {on: xmin, symmetry: true}\n"
       "  - {on: xmin, traction: {y: 5}}\n",
       "boundary.3.on: expected no other condition on xmin, a symmetry plane "
       "(boundary.2)"},
      {"  - {plate: {point: [0.2, 0, 0], normal: [-1, 0, 0]}, "
       "symmetry: true}\n",
       "boundary.2.plate: expected symmetry on a face"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    pm_scene *s = (pm_scene *)&s;
    assert_int_equal(load("[0.05, 0.05, 0]", bad[i].bcs, &s), PM_ERR_SCENE);
    assert_null(s);
    if (!strstr(pm_error_message(), bad[i].frag))
      fail_msg("message \"%s\" lacks \"%s\"", pm_error_message(), bad[i].frag);
    if (!strstr(pm_error_message(), NAME ":"))
      fail_msg("message \"%s\" names no file", pm_error_message());
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_quarter),
      cmocka_unit_test(test_refused),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
