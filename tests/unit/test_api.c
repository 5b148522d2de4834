/* test_api: pointmech.h as a caller meets it: a scene from a string with
 * overrides, a run with an observer reading the state at its frames, the
 * fields, figures and reactions read back, and every misuse refused with
 * its reason (before a run, after a load, a second run, unknown names, a
 * bad scene at its line, the observer stopping the run). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pointmech.h"

/* A 2-D block squeezed by 1% of its height on rollers (its base and its
 * left side), relaxed to its quasi-static state. */
static const char scene[] =
    "name: squeeze\n"
    "method: fpm\n"
    "dimension: 2\n"
    "domain: {box: {min: [0, 0], max: [0.1, 0.1]}}\n"
    "discretization: {mesh_size: 0.025}\n"
    "materials: [{name: m, model: neo-hookean, density: 1000, "
    "youngs_modulus: 1e4, poisson_ratio: 0.3}]\n"
    "bodies: [{material: m, region: domain}]\n"
    "boundary:\n"
    "  - {on: ymin, displacement: {y: 0}}\n"
    "  - {on: xmin, displacement: {x: 0}}\n"
    "  - {on: ymax, displacement: {y: -0.001}, ramp: linear}\n"
    "time: {end: 0.5, ramp: 0.1, quasi_static: {method: "
    "dynamic-relaxation}}\n"
    "output: {every: 10}\n";

/* Only pointmech.h: the code, with text in the message. */
#define assert_code(expr, code, text)                                          \
  do {                                                                         \
    pointmech_code c_ = (expr);                                                \
    if (c_ != (code) || !strstr(pointmech_error_message(), (text)))            \
      fail_msg("%s: expected %s with '%s', got %s: %s", #expr,                 \
               pointmech_code_name(code), (text), pointmech_code_name(c_),     \
               pointmech_error_message());                                     \
  } while (0)
#define assert_api(expr) assert_code(expr, POINTMECH_OK, "")
#define assert_near(a, b, tol)                                                 \
  do {                                                                         \
    double a_ = (a), b_ = (b);                                                 \
    if (!(fabs(a_ - b_) <= (tol)))                                             \
      fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);                      \
  } while (0)

typedef struct {
  long calls, frames, last_step;
  double u_top; /* u_y of a top point, read at the last frame */
  long stop_at; /* return non-zero at this step (0: never) */
} watch;

static int observe(pointmech *p, const pointmech_step *st, void *ctx) {
  watch *w = ctx;
  w->calls++;
  w->last_step = st->step;
  if (st->frame) {
    w->frames++;
    const size_t n = (size_t)pointmech_point_count(p);
    double *x = malloc(3 * n * sizeof *x), *u = malloc(3 * n * sizeof *u);
    int bad = !x || !u || pointmech_points(p, x, 3 * n) ||
              pointmech_field_read(p, "displacement", u, 3 * n);
    for (size_t i = 0; !bad && i < n; i++)
      if (x[3 * i + 1] == 0.1) w->u_top = u[3 * i + 1];
    free(x);
    free(u);
    if (bad) return -1;
  }
  return w->stop_at && st->step == w->stop_at ? 5 : 0;
}

static pointmech *loaded(void) {
  pointmech *p = NULL;
  assert_api(pointmech_create(&p));
  assert_api(pointmech_set(p, "output.every=5"));
  assert_api(pointmech_load_string(p, scene, "squeeze.yaml"));
  return p;
}

static void test_run_and_read(void **state) {
  (void)state;
  assert_true(strlen(pointmech_version()) > 0);
  pointmech *p = loaded();
  assert_string_equal(pointmech_scene_name(p), "squeeze");
  assert_string_equal(pointmech_method(p), "fpm");
  assert_string_equal(pointmech_status(p), "not-run");
  double v = 0;
  assert_code(pointmech_figure(p, "time", &v), POINTMECH_ERR_ARG,
              "no state yet");
  assert_int_equal(pointmech_point_count(p), 0);
  watch w = {0};
  assert_api(pointmech_run(p, NULL, 0, observe, &w));
  assert_string_equal(pointmech_status(p), "converged");

  /* Every step once (step 0 included), frames every 5 and the last. */
  double steps = 0, t = 0;
  assert_api(pointmech_figure(p, "steps", &steps));
  assert_api(pointmech_figure(p, "time", &t));
  assert_int_equal(w.calls, (long)steps + 1);
  assert_int_equal(w.last_step, (long)steps);
  assert_true(w.frames >= 1 + (long)steps / 5);
  assert_true(t > 0.1 && t <= 0.5);

  /* The top held at -0.001 after the ramp: its points read it back. */
  const long n = pointmech_point_count(p);
  assert_true(n > 4);
  double *x = malloc(3 * (size_t)n * sizeof *x);
  double *u = malloc(3 * (size_t)n * sizeof *u);
  double *sigma = malloc(9 * (size_t)n * sizeof *sigma);
  assert_api(pointmech_points(p, x, 3 * (size_t)n));
  assert_api(pointmech_field_read(p, "displacement", u, 3 * (size_t)n));
  long top = 0;
  for (long i = 0; i < n; i++)
    if (x[3 * i + 1] == 0.1) {
      assert_near(u[3 * i + 1], -0.001, 1e-15);
      top++;
    }
  assert_true(top >= 2);
  assert_near(w.u_top, -0.001, 1e-15);
  int nc = 0;
  assert_api(pointmech_field_components(p, "stress", &nc));
  assert_int_equal(nc, 9);
  assert_api(pointmech_field_read(p, "stress", sigma, 9 * (size_t)n));
  bool found = false;
  for (int k = 0; k < pointmech_field_count(p); k++)
    found |= strcmp(pointmech_field_name(p, k), "jacobian") == 0;
  assert_true(found);
  assert_null(pointmech_field_name(p, pointmech_field_count(p)));

  /* The force the supports apply on the body: down on the top, up on the
   * base. */
  double f[3];
  assert_api(pointmech_reaction(p, "ymax", f));
  assert_true(f[1] < 0);
  double base[3];
  assert_api(pointmech_reaction(p, "ymin", base));
  assert_true(base[1] > 0);
  /* In balance, and near plane-strain uniaxial stress E/(1 - nu^2) 1% over
   * the 0.1 m width (small strain: finite strain moves it by about 1%). */
  assert_near(f[1] + base[1], 0, 1e-3 * base[1]);
  const double linear = 1e4 / (1 - 0.3 * 0.3) * 0.01 * 0.1;
  assert_near(base[1], linear, 0.02 * linear);

  /* Misuse, each with its reason. */
  assert_code(pointmech_field_read(p, "displacement", u, 3 * (size_t)n - 1),
              POINTMECH_ERR_ARG, "doubles needed");
  assert_code(pointmech_field_read(p, "temperature", u, 3 * (size_t)n),
              POINTMECH_ERR_ARG, "expected one of: displacement");
  assert_code(pointmech_figure(p, "speed", &v), POINTMECH_ERR_ARG,
              "no figure speed");
  assert_code(pointmech_reaction(p, "zmax", f), POINTMECH_ERR_ARG,
              "expected one of: ymin, xmin, ymax");
  assert_code(pointmech_run(p, NULL, 0, NULL, NULL), POINTMECH_ERR_ARG,
              "runs once");
  assert_code(pointmech_set(p, "time.end=1"), POINTMECH_ERR_ARG,
              "loaded already");
  assert_code(pointmech_load_string(p, scene, NULL), POINTMECH_ERR_ARG,
              "loaded already");
  free(x);
  free(u);
  free(sigma);
  pointmech_destroy(p);
}

static void test_refusals(void **state) {
  (void)state;
  assert_string_equal(pointmech_code_name(POINTMECH_OK), "POINTMECH_OK");
  assert_string_equal(pointmech_code_name(POINTMECH_ERR_NOT_CONVERGED),
                      "POINTMECH_ERR_NOT_CONVERGED");
  assert_string_equal(pointmech_code_name(99), "POINTMECH_UNKNOWN");
  pointmech *p = NULL;
  assert_api(pointmech_create(&p));
  assert_code(pointmech_set(p, "time.end"), POINTMECH_ERR_ARG,
              "expected KEY=VALUE");
  assert_code(pointmech_run(p, NULL, 0, NULL, NULL), POINTMECH_ERR_ARG,
              "no scene loaded");
  /* A bad override and a bad key, located. */
  assert_api(pointmech_set(p, "time.end=-1"));
  assert_code(pointmech_load_string(p, scene, "squeeze.yaml"),
              POINTMECH_ERR_SCENE, "time.end=-1: expected a number > 0");
  pointmech_destroy(p);
  assert_api(pointmech_create(&p));
  char bad[sizeof scene + 32];
  snprintf(bad, sizeof bad, "%stime_end: 3\n", scene);
  assert_code(pointmech_load_string(p, bad, "squeeze.yaml"),
              POINTMECH_ERR_SCENE, "squeeze.yaml:14:1: time_end");
  assert_code(pointmech_load_file(p, "/nonexistent/scene.yaml"),
              POINTMECH_ERR_IO, "/nonexistent/scene.yaml");
  pointmech_destroy(p);
  pointmech_destroy(NULL);
}

static void test_observer_stops(void **state) {
  (void)state;
  pointmech *p = loaded();
  watch w = {.stop_at = 3};
  assert_code(pointmech_run(p, NULL, 0, observe, &w), POINTMECH_ERR_INTERRUPTED,
              "stopped by the observer");
  assert_int_equal(w.last_step, 3);
  assert_string_equal(pointmech_status(p), "interrupted");
  double steps = 0;
  assert_api(pointmech_figure(p, "steps", &steps));
  assert_int_equal((long)steps, 3);
  pointmech_destroy(p);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_run_and_read),
      cmocka_unit_test(test_refusals),
      cmocka_unit_test(test_observer_stops),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
