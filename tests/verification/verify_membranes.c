/* Verification of the MPM membranes (section 2.1 and eqs. 38-41 of
 * papers/mpm-fluid-membrane-zona-piezo-icsi.txt), each against a figure
 * derived independently of the code: the frame under a rigid rotation, the
 * fundamental frequency of a pre-tensioned square membrane, the
 * elastodamage law at one point, a strip pulled to failure where the
 * reflected strain wave doubles, and a gas-filled sphere settling where its
 * pressure balances the membrane's tension. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_pipeline.h"
#include "mpm_verify.h"
#include "pm_scene.h"

#define CASES PM_SOURCE_DIR "/cases/mpm/"

static const double PI = 3.14159265358979323846;

static pm_scene *scene_text(const char *text, int n_sets,
                            const char *const *sets) {
  pm_scene *s = NULL;
  if (pm_app_init() != PM_SUCCESS) fail_msg("%s", pm_error_message());
  if (pm_scene_load_text(text, strlen(text), "verify-membranes.yaml", n_sets,
                         sets, &s) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return s;
}

/* The stage of the pipeline called name. */
static const mpm_stage *stage_named(const mpm_model *m, const char *name) {
  for (int k = 0; k < m->pipeline.n; k++)
    if (strcmp(m->pipeline.stage[k].name, name) == 0)
      return &m->pipeline.stage[k];
  fail_msg("no stage %s", name);
  return NULL;
}

/* ---- 1. the frame under a rigid rotation ------------------------------- */

static const char flat_scene[] =
    "name: flat\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [-1, -1, -1], max: [1, 1, 1]}}\n"
    "discretization: {mesh_size: 0.1}\n"
    "materials:\n"
    "  - {name: skin, model: linear-elastic, density: 1000, youngs_modulus: "
    "1.0e6, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - {name: sheet, material: skin, membrane: {thickness: 0.01, "
    "rectangle: {origin: [-0.3, -0.2, 0], edge_u: [0.6, 0, 0], edge_v: [0, "
    "0.4, 0], points: [25, 17]}}}\n"
    "time: {end: 1.0, dt: 1.0e-3}\n"
    "output: {every: 1000, fields: [stress]}\n";

/* A flat membrane pre-stretched (e11 = 2e-3, e22 = -1e-3, e12 = 5e-4 in its
 * frame), turned rigidly by the grid velocity v = w x x (w about an axis
 * tilted out of its plane) for a quarter turn: L is skew, D = 0, so the
 * stress in the frame must not change; the global stress turns with the
 * membrane, its traction on the current normal stays zero, and the frame's
 * normal is the connectivity normal. */
static void frame_rotation(const char *normals) {
  char set[80];
  snprintf(set, sizeof set, "bodies.0.membrane.normals=%s", normals);
  const char *sets[] = {set};
  pm_scene *s = scene_text(flat_scene, 1, sets);
  verify_run *r = verify_create(s);
  const mpm_model *m = r->sim->model;
  mpm_state *st = r->sim->state;
  mpm_work *w = r->sim->work;
  const mpm_stage *normal = stage_named(m, "normals: membrane");
  const mpm_stage *stage = stage_named(m, "stress: membrane");
  double *eps = (double *)group_array(st, 0, "membrane_strain");
  assert_non_null(eps);
  const double *frame = group_array(st, 0, "frame");
  assert_non_null(frame);
  const long n = m->n;
  for (long k = 0; k < n; k++) {
    eps[3 * k] = 2e-3;
    eps[3 * k + 1] = -1e-3;
    eps[3 * k + 2] = 5e-4;
  }
  double axis[3] = {1, 2, 0.5}, len = pm_v_norm(axis);
  const double rate = PI / 2; /* a quarter turn in 1 s */
  double om[3];
  for (int c = 0; c < 3; c++) om[c] = rate * axis[c] / len;
  const mpm_grid *g = &m->grid;
  double *vel = malloc(sizeof(double) * 3 * (size_t)g->n_nodes);
  assert_non_null(vel);
  for (long i = 0; i < g->n_nodes; i++) {
    long ix = i % g->nn[0], iy = (i / g->stride[1]) % g->nn[1],
         iz = i / g->stride[2];
    double x[3] = {g->origin[0] + ix * g->h, g->origin[1] + iy * g->h,
                   g->origin[2] + iz * g->h};
    pm_v_cross(om, x, vel + 3 * i);
  }
  /* The velocity the membrane's strain follows (MUSL: the updated one). */
  memcpy(w->nodes.vel_new, vel, sizeof(double) * 3 * (size_t)g->n_nodes);
  w->nodes.vel_stress = vel;
  const double dt = 1e-3;
  st->dt = dt;
  mpm_ctx ctx = {m, st, w};
  /* The first point's stress magnitude before. */
  assert_int_equal(normal->run(&ctx, normal), PM_SUCCESS);
  assert_int_equal(stage->run(&ctx, stage), PM_SUCCESS);
  double s0 = 0;
  for (int k = 0; k < 9; k++) s0 += st->sigma[k] * st->sigma[k];
  s0 = sqrt(s0);
  const int steps = 1000;
  for (int it = 0; it < steps; it++) {
    /* Move the points by the exact rotation of the step (Rodrigues). */
    double th = rate * dt, c = cos(th), sn = sin(th), u[3];
    for (int k = 0; k < 3; k++) u[k] = axis[k] / len;
    for (long p = 0; p < n; p++) {
      double *x = st->x + 3 * p, ux[3], d = pm_v_dot(u, x), y[3];
      pm_v_cross(u, x, ux);
      for (int k = 0; k < 3; k++)
        y[k] = x[k] * c + ux[k] * sn + u[k] * d * (1 - c);
      memcpy(x, y, sizeof y);
    }
    assert_int_equal(normal->run(&ctx, normal), PM_SUCCESS);
    assert_int_equal(stage->run(&ctx, stage), PM_SUCCESS);
  }
  double worst_mag = 0, worst_trac = 0, worst_normal = 0, worst_strain = 0;
  /* The connectivity normal of every point, from the current triangles. */
  double *nrm = calloc(3 * (size_t)n, sizeof(double));
  assert_non_null(nrm);
  for (long t = 0; t < m->n_tris; t++) {
    const long *v = m->tri + 3 * t;
    double a[3], b[3], q[3];
    for (int k = 0; k < 3; k++) {
      a[k] = st->x[3 * v[1] + k] - st->x[3 * v[0] + k];
      b[k] = st->x[3 * v[2] + k] - st->x[3 * v[0] + k];
    }
    pm_v_cross(a, b, q);
    double l = pm_v_norm(q);
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++) nrm[3 * v[j] + k] += q[k] / l;
  }
  for (long p = 0; p < n; p++) {
    const double *sg = st->sigma + 9 * p, *f = frame + 9 * p;
    double mag = 0, tr[3] = {0, 0, 0}, l = pm_v_norm(nrm + 3 * p);
    for (int k = 0; k < 9; k++) mag += sg[k] * sg[k];
    mag = sqrt(mag);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) tr[i] += sg[3 * i + j] * nrm[3 * p + j] / l;
    worst_mag = fmax(worst_mag, fabs(mag - s0) / s0);
    worst_trac = fmax(worst_trac, pm_v_norm(tr) / s0);
    double dn = 0;
    for (int k = 0; k < 3; k++) dn += pow(f[6 + k] - nrm[3 * p + k] / l, 2);
    worst_normal = fmax(worst_normal, sqrt(dn));
    worst_strain = fmax(worst_strain, fabs(eps[3 * p] - 2e-3) +
                                          fabs(eps[3 * p + 1] + 1e-3) +
                                          fabs(eps[3 * p + 2] - 5e-4));
  }
  char title[160];
  snprintf(title, sizeof title,
           "Frame: a pre-stretched flat membrane turned rigidly a quarter "
           "turn (1000 steps), normals by %s",
           normals);
  table_head(title);
  bool ok = true;
  ok &= row("|sigma| change, largest over points", worst_mag, 0, 1, 1e-10);
  ok &= row("|sigma n| / |sigma|, largest", worst_trac, 0, 1, 1e-10);
  ok &= row("|n_frame - n_connectivity|, largest", worst_normal, 0, 1, 1e-12);
  ok &= row("in-plane strain change, largest", worst_strain, 0, 1, 1e-14);
  free(nrm);
  free(vel);
  w->nodes.vel_stress = NULL;
  verify_destroy(r);
  pm_scene_destroy(s);
  assert_true(ok);
}

/* Connectivity, and the isosurface fits (a plane: linear and quadratic
 * B-splines reproduce it, so the normals are exact to round-off). */
static void test_frame_rotation(void **state) {
  (void)state;
  frame_rotation("connectivity");
  frame_rotation("hybrid");
}

/* ---- 2. the tension wave ------------------------------------------------ */

static const char drum_scene[] =
    "name: drum\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [0, 0, -0.2], max: [1, 1, 0.2]}}\n"
    "discretization: {mesh_size: 0.05}\n"
    "materials:\n"
    "  - {name: skin, model: linear-elastic, density: 1000, youngs_modulus: "
    "1.0e6, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - {name: drum, material: skin, membrane: {thickness: 0.01, "
    "rectangle: {origin: [0, 0, 0], edge_u: [1, 0, 0], edge_v: [0, 1, 0], "
    "points: [61, 61]}}}\n"
    "boundary:\n"
    "  - {on: xmin, velocity: {x: 0, y: 0, z: 0}, ramp: none}\n"
    "  - {on: xmax, velocity: {x: 0, y: 0, z: 0}, ramp: none}\n"
    "  - {on: ymin, velocity: {x: 0, y: 0, z: 0}, ramp: none}\n"
    "  - {on: ymax, velocity: {x: 0, y: 0, z: 0}, ramp: none}\n"
    "mpm: {shape: quadratic, update: musl, flip: 1.0}\n"
    "time: {end: 0.8}\n"
    "output: {every: 100000, fields: [displacement]}\n";

/* A 1 m square membrane (10 mm thick, 1000 kg/m^3) under equibiaxial
 * pre-strain e0 = 0.01 in its frame, so the tension is T = E e0 t / (1 -
 * nu), edges held, set moving in its fundamental mode v_z = V sin(pi x)
 * sin(pi y): its centre oscillates at f = (c / 2) sqrt(1/a^2 + 1/b^2) with
 * c = sqrt(T / (rho t)).  The period is measured from the centre's
 * upward zero crossings of z over two periods. */
static void test_tension_wave(void **state) {
  (void)state;
  pm_scene *s = scene_text(drum_scene, 0, NULL);
  verify_run *r = verify_create(s);
  const mpm_model *m = r->sim->model;
  mpm_state *st = r->sim->state;
  double *eps = (double *)group_array(st, 0, "membrane_strain");
  assert_non_null(eps);
  const double E = 1e6, nu = 0.3, rho = 1000, t = 0.01, e0 = 0.01, V = 0.01;
  long centre = -1;
  for (long p = 0; p < m->n; p++) {
    eps[3 * p] = eps[3 * p + 1] = e0;
    const double *x = st->x + 3 * p;
    st->v[3 * p + 2] = V * sin(PI * x[0]) * sin(PI * x[1]);
    if (fabs(x[0] - 0.5) < 1e-9 && fabs(x[1] - 0.5) < 1e-9) centre = p;
  }
  assert_true(centre >= 0);
  /* The pre-stress of the pre-strain (the stage sets it each step). */
  const double T = E * e0 / (1 - nu) * t, c = sqrt(T / (rho * t));
  const double f = 0.5 * c * sqrt(2.0);
  double prev = 0, last_cross = -1, first_cross = -1;
  int crossings = 0;
  while (st->t < s->time.end) {
    assert_int_equal(mpm_step(m, st, r->sim->work), PM_SUCCESS);
    double z = st->x[3 * centre + 2];
    if (prev < 0 && z >= 0) {
      double tc = st->t - st->dt * z / (z - prev);
      if (first_cross < 0) first_cross = tc;
      last_cross = tc;
      crossings++;
    }
    prev = z;
  }
  table_head("Tension wave: the fundamental mode of a pre-tensioned square "
             "membrane, edges held (h = 0.05 m, 61 x 61 points)");
  assert_true(crossings >= 2);
  double period = (last_cross - first_cross) / (crossings - 1);
  bool ok = row("fundamental frequency, Hz", 1.0 / period, f, 0, 0.02);
  printf("  (%d upward crossings; c = %.4g m/s, T = %.4g N/m)\n", crossings, c,
         T);
  verify_destroy(r);
  pm_scene_destroy(s);
  assert_true(ok);
}

/* ---- 3. elastodamage at one point -------------------------------------- */

/* Eqs. 38-41 with the zona's constants: elastic below S_L (omega 0, factor
 * 1); past it omega = e_max / S_L - 1 and the factor 1 + 2 c0 (exp(-c1
 * omega) - 1) (at least 0); unloading keeps omega (the surface grows only);
 * failure at the failure strain, for good. */
static void test_damage_point(void **state) {
  (void)state;
  const pm_scene_damage dm = {.given = true,
                              .c0 = 10,
                              .c1 = 10,
                              .elastic_limit = 0.05937,
                              .failure = 0.06};
  double om = 0, failed = 0;
  table_head("Elastodamage at one point (c0 = c1 = 10, S_L = 0.05937, fails "
             "at 0.06)");
  bool ok = true;
  ok &= row("factor at e_max = 0.05",
            mpm_membrane_damage(&dm, 0.05, &om, &failed), 1.0, 0, 0);
  ok &= row("omega at e_max = 0.05", om, 0, 1, 0);
  double e = 0.0594;
  double d = mpm_membrane_damage(&dm, e, &om, &failed);
  double om_x = e / 0.05937 - 1;
  ok &= row("omega at e_max = 0.0594", om, om_x, 0, 1e-15);
  ok &= row("factor at e_max = 0.0594", d, 1 + 20 * (exp(-10 * om_x) - 1), 0,
            1e-14);
  double d_un = mpm_membrane_damage(&dm, 0.03, &om, &failed);
  ok &= row("omega after unloading to 0.03 (kept)", om, om_x, 0, 1e-15);
  ok &= row("factor after unloading (kept)", d_un, d, 0, 1e-15);
  /* Softening to zero stiffness before the failure strain. */
  double e_zero = 0.05937 * (1 - log(1 - 1.0 / 20) / 10);
  double om2 = 0, f2 = 0;
  double dz = mpm_membrane_damage(&dm, e_zero + 1e-6, &om2, &f2);
  ok &= row("factor just past e_max = S_L (1 - ln(0.95)/c1)", dz, 0, 1, 0);
  ok &= row("failed below 0.06", f2, 0, 1, 0);
  mpm_membrane_damage(&dm, 0.06, &om2, &f2);
  ok &= row("failed at 0.06", f2, 1, 0, 0);
  ok &= row("factor after failure, unloaded",
            mpm_membrane_damage(&dm, 0.0, &om2, &f2), 0, 1, 0);
  printf("  (the secant stiffness reaches zero at e_max = %.6g, before the "
         "failure strain 0.06)\n",
         e_zero);
  assert_true(ok);
}

/* ---- 4. a strip pulled to failure -------------------------------------- */

static const char strip_scene[] =
    "name: strip\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [0, -0.1, -0.1], max: [1.2, 0.1, 0.1]}}\n"
    "discretization: {mesh_size: 0.025}\n"
    "materials:\n"
    "  - {name: skin, model: linear-elastic, density: 1000, youngs_modulus: "
    "1.0e6, poisson_ratio: 0.0, damage: {c0: 1, c1: 10, elastic_limit: "
    "0.05, failure_strain: 0.06}}\n"
    "  - {name: steel, model: linear-elastic, density: 8000, youngs_modulus: "
    "2.0e11, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - {name: strip, material: skin, membrane: {thickness: 0.01, "
    "rectangle: {origin: [0, -0.04, 0], edge_u: [1, 0, 0], edge_v: [0, 0.08, "
    "0], points: [161, 13]}}}\n"
    "  - {name: clamp, material: steel, box: {min: [0.99, -0.05, -0.01], "
    "max: [1.01, 0.05, 0.01]}, motion: {velocity: {x: "
    "\"1.138 * (1 - exp(-t / 0.002))\"}}}\n"
    "boundary:\n"
    "  - {on: xmin, velocity: {x: 0, y: 0, z: 0}, ramp: none}\n"
    "mpm: {shape: quadratic, update: musl, flip: 1.0}\n"
    "time: {end: 0.045}\n"
    "output: {every: 100000, fields: [displacement]}\n";

/* A strip (nu = 0: uniaxial, wave speed c = sqrt(E / rho) = 31.6 m/s)
 * held at x = 0 and pulled at x = 1 m by a clamp that moves as prescribed,
 * its velocity V (1 - exp(-t / tau)), V = 1.138 m/s, tau = 2 ms: a strain
 * front rising to V / c = 0.036 runs along the strip, below the elastic
 * limit 0.05, and doubles where it reflects from the held end, from t = L
 * / c on.  There the strain reaches the failure strain 0.06 when the
 * incident strain reaches 0.03, 1 - exp(-s / tau) = 0.03 c / V: at t = L /
 * c + tau ln(1 / (1 - 0.03 c / V)).  The strip must fail there first (not
 * where it is pulled), at about that time. */
static void test_strip_failure(void **state) {
  (void)state;
  pm_scene *s = scene_text(strip_scene, 0, NULL);
  verify_run *r = verify_create(s);
  const mpm_model *m = r->sim->model;
  mpm_state *st = r->sim->state;
  const double *failed = group_array(st, 0, "failed");
  assert_non_null(failed);
  const double c = sqrt(1e6 / 1000.0), V = 1.138, tau = 0.002;
  const double t_reflect = 1.0 / c - tau * log(1 - 0.03 * c / V);
  double t_first = -1, x_first = -1;
  while (st->t < s->time.end && t_first < 0) {
    if (mpm_step(m, st, r->sim->work) != PM_SUCCESS)
      fail_msg("%s", pm_error_message());
    for (long p = m->body_begin[0]; p < m->body_end[0]; p++)
      if (failed[p] > 0 && (x_first < 0 || m->x0[3 * p] < x_first)) {
        t_first = st->t;
        x_first = m->x0[3 * p];
      }
  }
  table_head("A strip pulled to failure: a strain front of 0.036 doubles "
             "at the held end");
  assert_true(t_first > 0);
  bool ok = true;
  ok &= row("x of the first failure (m from the held end)", x_first, 0, 1, 0.1);
  ok &= row("time of the first failure, s", t_first, t_reflect, 0, 0.15);
  verify_destroy(r);
  pm_scene_destroy(s);
  assert_true(ok);
}

/* ---- 5. the gas-filled sphere ------------------------------------------ */

/* The equilibrium radius of a sphere of radius R0 (membrane thickness t,
 * E, nu) full of ideal gas (gamma, pressure p0) in vacuum, once the motion
 * has died out: energy is conserved (viscous and shock heating stay in the
 * gas), so p V / (gamma - 1) + 4 pi R0^2 t E e^2 / (1 - nu) = p0 V0 /
 * (gamma - 1), and the pressure balances the tension, p = 2 t (1 + e_z)
 * sigma / R with sigma = E e / (1 - nu), e = ln(R / R0) (the strain the
 * membrane integrates), e_z = -2 nu e / (1 - nu).  Bisection on R. */
static double sphere_equilibrium(double R0, double t, double E, double nu,
                                 double gamma, double p0) {
  double V0 = 4.0 / 3.0 * PI * pow(R0, 3), lo = R0, hi = 1.2 * R0;
  for (int it = 0; it < 200; it++) {
    double R = 0.5 * (lo + hi), e = log(R / R0);
    double sig = E * e / (1 - nu), ez = -2 * nu * e / (1 - nu);
    double p = 2 * t * (1 + ez) * sig / R;
    double V = 4.0 / 3.0 * PI * pow(R, 3);
    double W = 4 * PI * R0 * R0 * t * E * e * e / (1 - nu);
    double residual = p * V / (gamma - 1) + W - p0 * V0 / (gamma - 1);
    if (residual > 0)
      hi = R;
    else
      lo = R;
  }
  return 0.5 * (lo + hi);
}

static void test_gas_sphere(void **state) {
  (void)state;
  const char *sets[] = {"time.end=0.3"};
  pm_scene *s = load_scene(CASES "membrane-sphere-gas.yaml", 1, sets);
  verify_run *r = verify_create(s);
  const mpm_model *m = r->sim->model;
  mpm_state *st = r->sim->state;
  const long mb = m->body_begin[0], me = m->body_end[0];
  const long gb = m->body_begin[1], ge = m->body_end[1];
  const double R0 = 0.5, t = 0.1, E = 1e6, nu = 0.3;
  const double Req = sphere_equilibrium(R0, t, E, nu, 1.4, 1000);
  const double *eps = group_array(st, 0, "membrane_strain");
  assert_non_null(eps);
  const double *pg = group_array(st, 1, "pressure");
  assert_non_null(pg);
  /* Over the last fifth of the run: the mean radius of the membrane's
   * points, its mean in-plane strain (e11 + e22) / 2, and the gas's mean
   * pressure. */
  double sum_r = 0, sum_e = 0, sum_p = 0, r_first = 0;
  long samples = 0;
  while (st->t < s->time.end) {
    assert_int_equal(mpm_step(m, st, r->sim->work), PM_SUCCESS);
    if (st->t < 0.8 * s->time.end) continue;
    double R = 0, e = 0, p = 0;
    for (long q = mb; q < me; q++) {
      R += pm_v_norm(st->x + 3 * q);
      e += 0.5 * (eps[3 * (q - mb)] + eps[3 * (q - mb) + 1]);
    }
    for (long q = gb; q < ge; q++) p += pg[q - gb];
    R /= me - mb;
    if (samples == 0) r_first = R;
    sum_r += R;
    sum_e += e / (me - mb);
    sum_p += p / (ge - gb);
    samples++;
  }
  const double R = sum_r / samples, e = sum_e / samples, p = sum_p / samples;
  const double sig = E * e / (1 - nu), ez = -2 * nu * e / (1 - nu);
  const double p_tension = 2 * t * (1 + ez) * sig / R;
  double rmin_mem = INFINITY, rmax_gas = 0;
  for (long q = mb; q < me; q++)
    rmin_mem = fmin(rmin_mem, pm_v_norm(st->x + 3 * q));
  long out = 0;
  for (long q = gb; q < ge; q++) {
    double rq = pm_v_norm(st->x + 3 * q);
    rmax_gas = fmax(rmax_gas, rq);
    if (rq > rmin_mem) out++;
  }
  table_head("Gas-filled sphere at rest against the balance of pressure and "
             "tension (h = 0.1 m, 2562 membrane points, 0.24-0.3 s)");
  bool ok = true;
  ok &= row("radial displacement of the points R - R0 (m)", R - R0, Req - R0, 0,
            0.05);
  ok &= row("membrane strain, as R0 exp(eps) - R0 (m)", R0 * exp(e) - R0,
            Req - R0, 0, 0.05);
  ok &= row("gas pressure against 2 t sigma / R (Pa)", p, p_tension, 0, 0.02);
  ok &= row("gas particles beyond the membrane", (double)out, 0, 1, 0);
  printf("  (equilibrium radius %.6g m; the points' mean radius %.6g m, "
         "moving %.3g m/s over the window)\n",
         Req, R, (R - r_first) / (0.2 * s->time.end));
  printf("  (largest gas radius %.6g m, smallest membrane radius %.6g m)\n",
         rmax_gas, rmin_mem);
  verify_destroy(r);
  pm_scene_destroy(s);
  assert_true(ok);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_damage_point),
      cmocka_unit_test(test_frame_rotation),
      cmocka_unit_test(test_tension_wave),
      cmocka_unit_test(test_strip_failure),
      cmocka_unit_test(test_gas_sphere),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
