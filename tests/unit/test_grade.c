/* test_grade: box meshes graded toward faces (gm_mesh_box_graded and the
 * scene key discretization.refine): denser near the faces, refused bad input
 * at file:line:col. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gm_mesh.h"
#include "pm_app.h"
#include "pm_scene.h"
#include "pm_testing.h"

/* Nodes with coordinate c below lo and above hi. */
static void count_slabs(const gm_mesh *m, int c, double lo, double hi,
                        long *below, long *above) {
  *below = *above = 0;
  for (long i = 0; i < m->n_nodes; i++) {
    if (m->x[3 * i + c] < lo) (*below)++;
    if (m->x[3 * i + c] > hi) (*above)++;
  }
}

/* Graded toward zmin (3D) or ymin (2D) at a third of the size: the slab
 * next to the face holds several times the nodes of the opposite slab of
 * the same volume, which the uniform mesh splits evenly. */
static void check_graded(int dim) {
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const int c = dim - 1;
  const gm_grade g = {.faces = 1u << (2 * c), .size = 0.1, .distance = 0.6};
  gm_mesh *u = NULL, *m = NULL;
  assert_int_equal(gm_mesh_box(dim, lo, hi, 0.3, &u), PM_SUCCESS);
  assert_int_equal(gm_mesh_box_graded(dim, lo, hi, 0.3, &g, &m), PM_SUCCESS);
  long ub, ua, b, a;
  count_slabs(u, c, 0.25, 0.75, &ub, &ua);
  count_slabs(m, c, 0.25, 0.75, &b, &a);
  /* Uniform: the slabs within 30% of each other. */
  assert_true(ub < 1.3 * ua && ua < 1.3 * ub);
  /* Graded: the mean size over the near slab is about 0.16 against 0.3
   * (3D: (0.3/0.16)^3 = 6.6 times the nodes; 2D: 3.5); asked: 3 times. */
  if (b < 3 * a)
    fail_msg("dim %d: %ld nodes near the face, %ld far (uniform %ld, %ld)", dim,
             b, a, ub, ua);
  assert_true(m->n_nodes > u->n_nodes);
  /* gm_grade_size: the size on the face, halfway and beyond distance. */
  const double x0[3] = {0.5, 0.5, 0.5};
  double x[3] = {0.5, 0.5, 0.5};
  x[c] = 0.0;
  assert_near(gm_grade_size(&g, dim, lo, hi, 0.3, x), 0.1, 1e-12);
  x[c] = 0.3;
  assert_near(gm_grade_size(&g, dim, lo, hi, 0.3, x), 0.2, 1e-12);
  assert_near(gm_grade_size(&g, dim, lo, hi, 0.3, x0), 0.3 - 0.2 / 6, 1e-12);
  x[c] = 0.9;
  assert_near(gm_grade_size(&g, dim, lo, hi, 0.3, x), 0.3, 1e-12);
  gm_mesh_destroy(u);
  gm_mesh_destroy(m);
}

static void test_graded_3d(void **state) {
  (void)state;
  check_graded(3);
}

static void test_graded_2d(void **state) {
  (void)state;
  check_graded(2);
}

static void test_graded_bad_args(void **state) {
  (void)state;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  gm_mesh *m = (gm_mesh *)&m;
  const gm_grade big = {.faces = 1u, .size = 0.5, .distance = 0.5};
  assert_int_equal(gm_mesh_box_graded(3, lo, hi, 0.3, &big, &m), PM_ERR_ARG);
  assert_null(m);
  const gm_grade zmin2d = {.faces = 1u << 4, .size = 0.1, .distance = 0.5};
  assert_int_equal(gm_mesh_box_graded(2, lo, hi, 0.3, &zmin2d, &m), PM_ERR_ARG);
  const gm_grade nodist = {.faces = 1u, .size = 0.1, .distance = 0};
  assert_int_equal(gm_mesh_box_graded(3, lo, hi, 0.3, &nodist, &m), PM_ERR_ARG);
}

#define SCENE_HEAD                                                             \
  "name: grade\n"                                                              \
  "method: %s\n"                                                               \
  "dimension: %d\n"                                                            \
  "domain: {box: {min: [%s], max: [%s]}}\n"                                    \
  "discretization:\n"                                                          \
  "  mesh_size: 0.02\n"                                                        \
  "  refine: {near: [%s], size: %s, distance: 0.03}\n"
#define SCENE_TAIL                                                             \
  "materials:\n"                                                               \
  "  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: 3000, "  \
  "poisson_ratio: 0.45}\n"                                                     \
  "bodies: [{material: gel, region: domain}]\n"                                \
  "boundary:\n"                                                                \
  "  - {on: xmin, displacement: {x: 0, y: 0}}\n"                               \
  "time: {end: 0.01}\n"

/* A scene with refine near faces and size, loaded: ok, or failing with a
 * message at the located needle holding frag. */
static void scene_case(void **state, const char *method, int dim,
                       const char *faces, const char *size, const char *needle,
                       const char *frag) {
  char text[2048], path[512], at[600];
  snprintf(text, sizeof text, SCENE_HEAD SCENE_TAIL, method, dim,
           dim == 3 ? "0, 0, 0" : "0, 0",
           dim == 3 ? "0.1, 0.1, 0.1" : "0.1, 0.1", faces, size);
  pm_test_write_file(*state, "grade.yaml", text, path);
  pm_scene *s = NULL;
  pm_error_clear();
  pm_err err = pm_scene_load(path, 0, NULL, &s);
  if (!needle) {
    if (err != PM_SUCCESS) fail_msg("%s", pm_error_message());
    assert_int_equal(s->refine.near, (1u << PM_FACE_ZMIN) | 1u);
    assert_near(s->refine.size, 0.005, 0);
    assert_near(s->refine.distance, 0.03, 0);
    pm_scene_destroy(s);
    return;
  }
  assert_int_equal(err, PM_ERR_SCENE);
  assert_null(s);
  pm_test_locate(path, text, needle, at, sizeof at);
  const char *msg = pm_error_message();
  if (!strstr(msg, at) || !strstr(msg, frag))
    fail_msg("message \"%s\" lacks \"%s\" or \"%s\"", msg, at, frag);
}

static void test_scene_key(void **state) {
  scene_case(state, "fpm", 3, "zmin, xmin", "0.005", NULL, NULL);
  /* A size above mesh_size, at the size. */
  scene_case(state, "fpm", 3, "zmin", "0.03", "0.03,",
             "discretization.refine.size");
  /* A face name that is none. */
  scene_case(state, "fpm", 3, "top", "0.005", "top", "xmin, xmax");
  /* zmax in 2D. */
  scene_case(state, "fpm", 2, "zmax", "0.005", "[zmax]", "dimension 2");
  /* MPM has a grid, not a gmsh mesh. */
  scene_case(state, "mpm", 3, "zmin", "0.005", "refine", "method fpm");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_graded_3d),
      cmocka_unit_test(test_graded_2d),
      cmocka_unit_test(test_graded_bad_args),
      cmocka_unit_test_setup_teardown(test_scene_key, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
