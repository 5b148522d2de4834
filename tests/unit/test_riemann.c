/* Unit tests of the exact Riemann solver: published star states, the jump
 * conditions across its waves, and the sampled profile. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pm_riemann.h"
#include "pm_testing.h"

static const double G = 1.4;

static pm_riemann solve(pm_riemann_state l, pm_riemann_state r) {
  pm_riemann s;
  assert_ok(pm_riemann_solve(G, l, r, &s));
  return s;
}

static double sound(double rho, double p) { return sqrt(G * p / rho); }

/* Toro, "Riemann Solvers and Numerical Methods for Fluid Dynamics", ch. 4,
 * test 1 (Sod): star values to the five decimals published. */
static void test_sod_published(void **state) {
  (void)state;
  pm_riemann s =
      solve((pm_riemann_state){1, 0, 1}, (pm_riemann_state){0.125, 0, 0.1});
  assert_close(s.p_star, 0.30313, 0, 5e-6);
  assert_close(s.u_star, 0.92745, 0, 5e-6);
  assert_close(s.rho_star_left, 0.42632, 0, 5e-6);
  assert_close(s.rho_star_right, 0.26557, 0, 5e-6);
  assert_int_equal(s.left_shock, 0);
  assert_int_equal(s.right_shock, 1);
  /* 40-digit reference (mpmath root of the same pressure function):
   * p* = 0.303130178050646824, u* = 0.927452620048949949 */
  assert_close(s.p_star, 0.303130178050646824, 1e-14, 0);
  assert_close(s.u_star, 0.927452620048949949, 1e-14, 0);
}

/* The same chapter's tests 2 (two strong rarefactions, "123 problem") and
 * 3 (left half of Woodward-Colella: pressure ratio 1e5). */
static void test_toro_2_3_published(void **state) {
  (void)state;
  pm_riemann s =
      solve((pm_riemann_state){1, -2, 0.4}, (pm_riemann_state){1, 2, 0.4});
  assert_close(s.p_star, 0.00189, 0, 5e-6);
  assert_close(s.u_star, 0, 0, 1e-15);
  assert_close(s.rho_star_left, 0.02185, 0, 5e-6);
  assert_close(s.rho_star_right, 0.02185, 0, 5e-6);
  assert_true(!s.left_shock && !s.right_shock);

  s = solve((pm_riemann_state){1, 0, 1000}, (pm_riemann_state){1, 0, 0.01});
  assert_close(s.p_star, 460.894, 0, 5e-4);
  assert_close(s.u_star, 19.5975, 0, 5e-5);
  assert_close(s.rho_star_left, 0.57506, 0, 5e-6);
  assert_close(s.rho_star_right, 5.99924, 0, 5e-6);
}

/* Pressure ratio 1000: left (1, 0, 1), right (0.125, 0, 0.001). */
static pm_riemann strong(void) {
  return solve((pm_riemann_state){1, 0, 1},
               (pm_riemann_state){0.125, 0, 0.001});
}

/* Values of the strong case, against a 40-digit mpmath solution of the
 * same equations:
 *   p*    = 0.210857745568255205     u* (contact) = 1.17954095285382248
 *   rho*L = 0.328954172319024888     rho*R (shock) = 0.729825484266030128
 *   shock speed = 1.42331808021090281, fan tail = 0.232233186804663770
 * The residual of the pressure equation, evaluated with formulas written
 * out here, shows p* converged to ~1e-14. */
static void test_strong_values(void **state) {
  (void)state;
  pm_riemann s = strong();
  assert_int_equal(s.left_shock, 0);
  assert_int_equal(s.right_shock, 1);
  assert_close(s.p_star, 0.210857745568255205, 1e-14, 0);
  assert_close(s.u_star, 1.17954095285382248, 1e-14, 0);
  assert_close(s.rho_star_left, 0.328954172319024888, 1e-14, 0);
  assert_close(s.rho_star_right, 0.729825484266030128, 1e-14, 0);
  assert_close(s.s_right_head, 1.42331808021090281, 1e-14, 0);
  assert_close(s.s_right_tail, s.s_right_head, 0, 0);
  assert_close(s.s_contact, 1.17954095285382248, 1e-14, 0);
  assert_close(s.s_left_tail, 0.232233186804663770, 1e-14, 0);
  assert_close(s.s_left_head, -sound(1, 1), 1e-15, 0);

  /* u* reached from the left through the fan and from the right through
   * the shock agree. */
  double p = s.p_star, g1 = (G - 1) / (G + 1);
  double from_left =
      -2 * sound(1, 1) / (G - 1) * (pow(p, (G - 1) / (2 * G)) - 1);
  double from_right =
      (p - 0.001) * sqrt(2 / ((G + 1) * 0.125) / (p + g1 * 0.001));
  assert_close(from_left, from_right, 1e-14, 0);
}

/* Shock frame: mass, momentum and energy fluxes are equal on both sides;
 * the shock compresses, at most to (gamma+1)/(gamma-1) rho_R = 0.75. */
static void test_strong_rankine_hugoniot(void **state) {
  (void)state;
  pm_riemann s = strong();
  double S = s.s_right_head;
  double r0 = 0.125, w0 = 0 - S, p0 = 0.001;
  double r1 = s.rho_star_right, w1 = s.u_star - S, p1 = s.p_star;
  double m0 = r0 * w0, m1 = r1 * w1;
  assert_close(m1, m0, 1e-10, 0);
  assert_close(m1 * w1 + p1, m0 * w0 + p0, 1e-10, 0);
  double h0 = pm_riemann_energy(G, r0, p0) + p0 / r0;
  double h1 = pm_riemann_energy(G, r1, p1) + p1 / r1;
  assert_close(m1 * (h1 + 0.5 * w1 * w1), m0 * (h0 + 0.5 * w0 * w0), 1e-10, 0);
  assert_true(s.rho_star_right > r0);
  assert_true(s.rho_star_right <= (G + 1) / (G - 1) * r0);
  assert_close(s.rho_star_right, 0.7298, 0, 5e-5);
}

/* Left fan tail: same entropy p / rho^gamma and same invariant
 * u + 2 c / (gamma - 1) as the undisturbed left gas; the tail moves at
 * u* - c*. */
static void test_strong_rarefaction(void **state) {
  (void)state;
  pm_riemann s = strong();
  double rho = s.rho_star_left, p = s.p_star, c = sound(rho, p);
  assert_close(p / pow(rho, G), 1.0, 1e-13, 0);
  assert_close(s.u_star + 2 * c / (G - 1), 0 + 2 * sound(1, 1) / (G - 1), 1e-14,
               0);
  assert_close(s.s_left_tail, s.u_star - c, 1e-14, 0);
  /* The sampled fan meets the star state at its tail. */
  double r_, u_, p_;
  pm_riemann_sample(&s, s.s_left_tail * (1 - 1e-12), &r_, &u_, &p_);
  assert_close(r_, rho, 1e-10, 0);
  assert_close(u_, s.u_star, 1e-10, 0);
  assert_close(p_, p, 1e-10, 0);
}

/* Pressure and velocity are continuous across the contact, density
 * jumps. */
static void test_strong_contact(void **state) {
  (void)state;
  pm_riemann s = strong();
  double d = 1e-9, rl, ul, pl, rr, ur, pr;
  pm_riemann_sample(&s, s.s_contact - d, &rl, &ul, &pl);
  pm_riemann_sample(&s, s.s_contact + d, &rr, &ur, &pr);
  assert_close(pl, pr, 0, 0);
  assert_close(ul, ur, 0, 0);
  assert_close(ul, s.s_contact, 0, 0);
  assert_close(rl, s.rho_star_left, 0, 0);
  assert_close(rr, s.rho_star_right, 0, 0);
  assert_true(rr > 2 * rl);
}

/* Mirror-symmetric states meet at rest: two shocks, or two fans. */
static void test_symmetric(void **state) {
  (void)state;
  pm_riemann s =
      solve((pm_riemann_state){1, 1, 1}, (pm_riemann_state){1, -1, 1});
  assert_true(s.u_star == 0);
  assert_true(s.left_shock && s.right_shock);
  assert_close(s.rho_star_left, s.rho_star_right, 0, 0);
  assert_close(s.s_left_head, -s.s_right_head, 0, 0);
  assert_true(s.p_star > 1);

  s = solve((pm_riemann_state){1, -1, 1}, (pm_riemann_state){1, 1, 1});
  assert_true(s.u_star == 0);
  assert_true(!s.left_shock && !s.right_shock);
  assert_true(s.p_star < 1);

  /* Colliding streams 1e4 times the sound speed: p* = 1.2e8 (strong-shock
   * limit (gamma + 1) / 2 rho u^2) and rho* -> 6. */
  s = solve((pm_riemann_state){1, 1e4, 1}, (pm_riemann_state){1, -1e4, 1});
  assert_true(s.u_star == 0);
  assert_close(s.p_star, 1.2e8, 1e-6, 0);
  assert_close(s.rho_star_left, 6, 1e-6, 0);
}

/* Mirrored Sod exercises the left shock and the right fan: the profile is
 * the reflection of Sod's. */
static void test_mirror(void **state) {
  (void)state;
  pm_riemann a =
      solve((pm_riemann_state){1, 0, 1}, (pm_riemann_state){0.125, 0, 0.1});
  pm_riemann b =
      solve((pm_riemann_state){0.125, 0, 0.1}, (pm_riemann_state){1, 0, 1});
  assert_true(b.left_shock && !b.right_shock);
  assert_close(b.u_star, -a.u_star, 1e-15, 0);
  for (int k = 0; k <= 40; k++) {
    double xi = -2.05 + 0.1 * k, ra, ua, pa, rb, ub, pb;
    pm_riemann_sample(&a, xi, &ra, &ua, &pa);
    pm_riemann_sample(&b, -xi, &rb, &ub, &pb);
    assert_close(rb, ra, 1e-13, 0);
    assert_close(ub, -ua, 1e-13, 1e-15);
    assert_close(pb, pa, 1e-13, 0);
  }
}

/* Sod sampled in each region: undisturbed far away, the fan on its
 * characteristics, the two star states, and the right state past the
 * shock. */
static void test_sample_regions(void **state) {
  (void)state;
  pm_riemann s =
      solve((pm_riemann_state){1, 0, 1}, (pm_riemann_state){0.125, 0, 0.1});
  double rho, u, p;
  pm_riemann_sample(&s, -100, &rho, &u, &p);
  assert_true(rho == 1 && u == 0 && p == 1);
  pm_riemann_sample(&s, 100, &rho, &u, &p);
  assert_true(rho == 0.125 && u == 0 && p == 0.1);
  pm_riemann_sample(&s, s.s_left_head - 1e-3, &rho, &u, &p);
  assert_true(rho == 1 && u == 0 && p == 1);

  /* Inside the fan: u - c = xi, isentrope, invariant. */
  double xi = 0.5 * (s.s_left_head + s.s_left_tail);
  pm_riemann_sample(&s, xi, &rho, &u, &p);
  assert_true(p < 1 && p > s.p_star && u > 0 && u < s.u_star);
  assert_close(u - sound(rho, p), xi, 1e-14, 1e-15);
  assert_close(p / pow(rho, G), 1, 1e-14, 0);
  assert_close(u + 2 * sound(rho, p) / (G - 1), 2 * sound(1, 1) / (G - 1),
               1e-14, 0);
  /* The fan starts continuously at its head. */
  pm_riemann_sample(&s, s.s_left_head + 1e-12, &rho, &u, &p);
  assert_close(rho, 1, 1e-10, 0);
  assert_close(p, 1, 1e-10, 0);

  pm_riemann_sample(&s, 0.5 * (s.s_left_tail + s.s_contact), &rho, &u, &p);
  assert_true(rho == s.rho_star_left && u == s.u_star && p == s.p_star);
  pm_riemann_sample(&s, 0.5 * (s.s_contact + s.s_right_head), &rho, &u, &p);
  assert_true(rho == s.rho_star_right && u == s.u_star && p == s.p_star);
  pm_riemann_sample(&s, s.s_right_head * (1 + 1e-12), &rho, &u, &p);
  assert_true(rho == 0.125 && u == 0 && p == 0.1);

  /* Waves are ordered. */
  assert_true(s.s_left_head < s.s_left_tail);
  assert_true(s.s_left_tail < s.s_contact);
  assert_true(s.s_contact < s.s_right_tail);
  assert_true(s.s_right_tail == s.s_right_head);
}

static void test_energy(void **state) {
  (void)state;
  assert_close(pm_riemann_energy(1.4, 1, 1), 2.5, 1e-15, 0);
  assert_close(pm_riemann_energy(5.0 / 3, 2, 3), 2.25, 1e-15, 0);
}

/* Extreme but valid data still converge: pressure ratio 1e20, and a star
 * pressure 55 orders below the initial ones near the vacuum limit. */
static void test_extreme(void **state) {
  (void)state;
  pm_riemann s =
      solve((pm_riemann_state){1, 0, 1e10}, (pm_riemann_state){1, 0, 1e-10});
  assert_true(s.p_star > 1e-10 && s.p_star < 1e10 && s.right_shock);
  assert_close(s.rho_star_right, 6, 1e-12, 0);
  s = solve((pm_riemann_state){1, -5.9160797, 1},
            (pm_riemann_state){1, 5.9160797, 1});
  assert_true(s.p_star > 0 && s.p_star < 1e-50);
}

static void expect_error(pm_err want, double gamma, pm_riemann_state l,
                         pm_riemann_state r) {
  pm_riemann s;
  pm_error_clear();
  assert_int_equal(pm_riemann_solve(gamma, l, r, &s), want);
  assert_true(isnan(s.p_star) && isnan(s.u_star));
  assert_true(pm_error_message()[0] != '\0');
}

static void test_bad_inputs(void **state) {
  (void)state;
  pm_riemann_state ok = {1, 0, 1};
  expect_error(PM_ERR_ARG, G, (pm_riemann_state){0, 0, 1}, ok);
  expect_error(PM_ERR_ARG, G, ok, (pm_riemann_state){-1, 0, 1});
  expect_error(PM_ERR_ARG, G, ok, (pm_riemann_state){1, 0, 0});
  expect_error(PM_ERR_ARG, G, (pm_riemann_state){1, 0, -2}, ok);
  expect_error(PM_ERR_ARG, G, (pm_riemann_state){1, NAN, 1}, ok);
  expect_error(PM_ERR_ARG, G, ok, (pm_riemann_state){INFINITY, 0, 1});
  expect_error(PM_ERR_ARG, 1.0, ok, ok);
  expect_error(PM_ERR_ARG, 0.5, ok, ok);
  expect_error(PM_ERR_ARG, NAN, ok, ok);
  /* The message names the bad value. */
  pm_riemann s;
  assert_int_equal(pm_riemann_solve(G, ok, (pm_riemann_state){1, 0, -0.25}, &s),
                   PM_ERR_ARG);
  assert_non_null(strstr(pm_error_message(), "right pressure"));
  assert_non_null(strstr(pm_error_message(), "-0.25"));
  assert_int_equal(pm_riemann_solve(G, ok, ok, NULL), PM_ERR_ARG);
  /* Separating at 10 m/s each way: 2 (c_L + c_R) / (gamma - 1) = 11.8. */
  expect_error(PM_ERR_UNSTABLE, G, (pm_riemann_state){1, -10, 1},
               (pm_riemann_state){1, 10, 1});
  /* Just short of it for gamma near 1 the star pressure underflows. */
  expect_error(PM_ERR_UNSTABLE, 1.01, (pm_riemann_state){1, -199, 1},
               (pm_riemann_state){1, 199, 1});
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sod_published),
      cmocka_unit_test(test_toro_2_3_published),
      cmocka_unit_test(test_strong_values),
      cmocka_unit_test(test_strong_rankine_hugoniot),
      cmocka_unit_test(test_strong_rarefaction),
      cmocka_unit_test(test_strong_contact),
      cmocka_unit_test(test_symmetric),
      cmocka_unit_test(test_mirror),
      cmocka_unit_test(test_sample_regions),
      cmocka_unit_test(test_energy),
      cmocka_unit_test(test_extreme),
      cmocka_unit_test(test_bad_inputs),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
