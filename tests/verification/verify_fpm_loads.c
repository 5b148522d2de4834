/* Verification of FPM's loads beyond nominal tractions: gravity and body
 * forces against the exact field of a hanging column, a follower pressure
 * against the large-strain ring of tools/ring-pressure.py (static, and
 * dynamic relaxation to the same state) and the uniaxial state of a cube
 * in 3-D, concentrated forces and a load curve from a table against the
 * clamp's reaction; the work of each booked by the trapezoidal rule, so
 * the energy balance does not depend on the load steps beyond the rule's
 * second-order error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend.h"
#include "fpm_run_testing.h"
#include "fpm_solver.h"
#include "pm_app.h"
#include "pm_run.h"
#include "pm_scene.h"
#include "gmsh_testing.h"

/* The column hanging under gravity (129 points): NRMSE of u against the
 * exact field below 2e-3 (measured 9.4e-4; 1.7e-4 and 4.6e-5 at half and a
 * quarter of the size), the clamp's reaction rho g A = 2000 N to 1e-9, the
 * energy balance the same with 1 and 10 load steps (the problem is linear:
 * the rule is exact); body_force: {y: -10} gives the same field as
 * gravity, and body_curve 2 t the same again (a static solve takes
 * the curve at the end of the loading, t = 0.5 s). */
static void test_column_gravity(void **state) {
  (void)state;
  const char *one[] = {"time.quasi_static.load_steps=1"};
  const char *body[] = {"gravity=[0, 0]", "body_force.y=-10"};
  const char *curved[] = {"body_curve=2*t"};
  run_t a = {0}, b = {0}, c = {0}, d = {0};
  fpm_test_run(CASES "column-gravity.yaml", 0, NULL, &a);
  fpm_test_run(CASES "column-gravity.yaml", 1, one, &b);
  fpm_test_run(CASES "column-gravity.yaml", 2, body, &c);
  fpm_test_run(CASES "column-gravity.yaml", 1, curved, &d);
  double R[3];
  fpm_reaction(a.sim->model, a.sim->state, 0, R);
  print_message("column: %ld points, NRMSE u %.3e, reaction %.10g N, "
                "energy balance %.4e (10 steps), %.4e (1 step); body_force "
                "NRMSE %.3e, with body_curve 2 t %.3e\n",
                a.sim->model->n, a.out.nrmse_vector, R[1],
                a.out.fig.energy_error, b.out.fig.energy_error,
                c.out.nrmse_vector, d.out.nrmse_vector);
  assert_int_equal(a.sim->status, PM_STATUS_CONVERGED);
  assert_true(a.out.nrmse_vector < 2e-3);
  assert_true(fabs(R[1] - 2000) < 1e-9 * 2000);
  assert_true(fabs(a.out.fig.energy_error - b.out.fig.energy_error) < 1e-8);
  assert_true(fabs(c.out.nrmse_vector - a.out.nrmse_vector) < 1e-12);
  /* a static solve takes the curve's value at the end of the loading */
  assert_true(fabs(d.out.nrmse_vector - a.out.nrmse_vector) < 1e-9);
  done(&a);
  done(&b);
  done(&c);
  done(&d);
}

/* The column released under gravity (explicit, 0.05 s): the energy
 * balance closes to the leapfrog's first order in dt (kinetic energy at
 * half steps): halving dt twice takes it from 4.0e-3 to 2.1e-3 and 1.2e-3
 * with the symmetric flux (measured). */
static void test_column_explicit(void **state) {
  (void)state;
  double e[3];
  const char *safety[3] = {"time.dt_safety=0.8", "time.dt_safety=0.4",
                           "time.dt_safety=0.2"};
  for (int k = 0; k < 3; k++) {
    const char *sets[] = {"time.quasi_static.method=none", "time.end=0.05",
                          "fpm.flux=sipg", safety[k]};
    run_t r = {0};
    fpm_test_run(CASES "column-gravity.yaml", 4, sets, &r);
    e[k] = r.out.fig.energy_error;
    print_message("column, explicit, %s: %ld steps, energy balance %.4e\n",
                  safety[k], r.sim->last.step, e[k]);
    done(&r);
  }
  assert_true(fabs(e[0]) < 6e-3);
  assert_true(fabs(e[1]) < 0.7 * fabs(e[0]));
  assert_true(fabs(e[2]) < 0.7 * fabs(e[1]));
}

/* The ring under a follower pressure of 300 Pa (332 points): the inner
 * face's mean radial displacement against the boundary-value problem's
 * 0.272230 m (tools/ring-pressure.py --p 300) within 1.5% (measured
 * -1.05%; -0.49% and -0.23% at half and a quarter of the size); the
 * reaction on each cut edge p r(A) = 381.67 N within 1.5%; Newton
 * converges in at most 4 iterations a step (the tangent holds the load
 * stiffness); dynamic relaxation reaches the same state; the energy
 * balance within 3e-3 with 10 load steps. */
static double inner_radial(const fpm_sim *sim) {
  const fpm_model *m = sim->model;
  double sum = 0;
  int n = 0;
  for (long i = 0; i < m->n; i++) {
    const double *x = m->x + 3 * i, *u = sim->state->u + 3 * i;
    const double R = hypot(x[0], x[1]);
    if (fabs(R - 1) > 1e-6) continue;
    sum += (u[0] * x[0] + u[1] * x[1]) / R;
    n++;
  }
  assert_true(n > 0);
  return sum / n;
}

static void test_ring_pressure(void **state) {
  (void)state;
  const char *dr[] = {"time.quasi_static.method=dynamic-relaxation",
                      "time.end=200", "time.ramp=5"};
  run_t s = {0}, d = {0};
  fpm_test_run(CASES "ring/ring-pressure.yaml", 0, NULL, &s);
  fpm_test_run(CASES "ring/ring-pressure.yaml", 3, dr, &d);
  const double ref = 0.272230, us = inner_radial(s.sim),
               ud = inner_radial(d.sim);
  double R[3];
  fpm_reaction(s.sim->model, s.sim->state, 1, R);
  const int its = s.sim->static_report.load.newton_iterations;
  print_message("ring: inner u_r %.6g m static (%d Newton iterations), "
                "%.6g m by relaxation, reference %.6g m: error %.3e; "
                "reaction %.6g N (p r(A) %.6g N); energy balance %.4e\n",
                us, its, ud, ref, (us - ref) / ref, R[0], 300 * (1 + ref),
                s.out.fig.energy_error);
  assert_int_equal(s.sim->status, PM_STATUS_CONVERGED);
  assert_int_equal(d.sim->status, PM_STATUS_CONVERGED);
  assert_true(fabs(us - ref) < 1.5e-2 * ref);
  assert_true(fabs(ud - us) < 1e-5 * us);
  assert_true(fabs(-R[0] - 300 * (1 + ref)) < 1.5e-2 * 300 * (1 + ref));
  assert_true(its <= 4 * s.sim->static_report.load.steps);
  assert_true(fabs(s.out.fig.energy_error) < 3e-3);
  done(&s);
  done(&d);
}

/* Concentrated forces (a corner's, on a table curve, and one shared by the
 * bottom edge's points) with gravity: the clamp's reaction is their sum,
 * (300, -3000) N on the body, to 1e-8; the energy balance with 10 load
 * steps within 1.5e-3 of that with 40 (measured -5.1e-3, -4.1e-3). */
static void test_point_forces(void **state) {
  (void)state;
  double e[2];
  const char *steps[2] = {"time.quasi_static.load_steps=10",
                          "time.quasi_static.load_steps=40"};
  for (int k = 0; k < 2; k++) {
    run_t r = {0};
    fpm_test_run(CASES "point-forces.yaml", 1, &steps[k], &r);
    double R[3];
    fpm_reaction(r.sim->model, r.sim->state, 0, R);
    e[k] = r.out.fig.energy_error;
    print_message("point forces, %s: reaction (%.10g, %.10g) N, energy "
                  "balance %.4e\n",
                  steps[k], R[0], R[1], e[k]);
    assert_int_equal(r.sim->status, PM_STATUS_CONVERGED);
    assert_true(fabs(R[0] + 300) < 1e-8 * 300);
    assert_true(fabs(R[1] - 3000) < 1e-8 * 3000);
    done(&r);
  }
  assert_true(fabs(e[0] - e[1]) < 1.5e-3);
}

/* The cube under a follower pressure (145 points, a uniform state): the
 * field is the uniaxial solution's to 1e-12, the rollers carry p times the
 * deformed area, 3.183677390959122 N, to 1e-12; the energy balance is the
 * trapezoidal rule's alone, of second order in the load step: -3.58e-2,
 * -3.71e-4 and -2.32e-5 with 1, 10 and 40 steps (measured), within 1e-3
 * with 10. */
static void test_cube_pressure(void **state) {
  (void)state;
  double e[2];
  const char *steps[2] = {"time.quasi_static.load_steps=10",
                          "time.quasi_static.load_steps=40"};
  for (int k = 0; k < 2; k++) {
    run_t r = {0};
    fpm_test_run(CASES "cube-pressure.yaml", 1, &steps[k], &r);
    double R[3];
    fpm_reaction(r.sim->model, r.sim->state, 2, R);
    e[k] = r.out.fig.energy_error;
    print_message("cube, %s: NRMSE u %.3e, reaction %.15g N, energy "
                  "balance %.4e\n",
                  steps[k], r.out.nrmse_vector, R[2], e[k]);
    assert_int_equal(r.sim->status, PM_STATUS_CONVERGED);
    assert_true(r.out.nrmse_vector < 1e-12);
    assert_true(fabs(R[2] - 3.183677390959122) < 1e-12 * 3.2);
    done(&r);
  }
  assert_true(fabs(e[0]) < 1e-3);
  assert_true(fabs(e[1]) < fabs(e[0]) / 8);
}

int main(void) {
  gmsh_testing_preload();
  pm_app_init();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_column_gravity),
      cmocka_unit_test(test_column_explicit),
      cmocka_unit_test(test_ring_pressure),
      cmocka_unit_test(test_point_forces),
      cmocka_unit_test(test_cube_pressure),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
