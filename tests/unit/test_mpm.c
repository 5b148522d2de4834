/* test_mpm: the explicit MPM backend: B-spline weights and their tensor
 * products, mass and momentum conservation of the transfers and the step,
 * state and stages built only for what a scene holds, located scene errors,
 * and particle seeding. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_testing.h"

#include "mpm_driver.h"
#include "mpm_model.h"
#include "mpm_shape.h"
#include "pm_scene.h"

#define PI 3.14159265358979323846
#define EPS DBL_EPSILON
#define MINIMAL PM_TEST_DATA "/scenes/minimal-2d.yaml"

/* |a - b| <= tol with both values in the message (NaN fails). */
#define assert_near(a, b, tol) check_near((a), (b), (tol), #a, __LINE__)
static void check_near(double a, double b, double tol, const char *what,
                       int line) {
  if (!(fabs(a - b) <= tol))
    fail_msg("line %d: %s = %.17g, expected %.17g (tol %g, off by %g)", line,
             what, a, b, tol, fabs(a - b));
}

/* Deterministic uniform numbers in [0, 1) (xorshift64*). */
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void) {
  rng ^= rng >> 12;
  rng ^= rng << 25;
  rng ^= rng >> 27;
  return (double)((rng * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
}

/* Writes text to dir/name; path receives the full name. */
static void write_file(const char *dir, const char *name, const char *text,
                       char path[512]) {
  int len = snprintf(path, 512, "%s/%s", dir, name);
  assert_true(len > 0 && len < 512);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  assert_true(fputs(text, f) >= 0);
  assert_int_equal(fclose(f), 0);
}

typedef struct {
  pm_scene *scene;
  mpm_sim *sim;
} model;

static model make_model(const char *path, int n, const char *const *set) {
  model m = {NULL, NULL};
  assert_ok(pm_scene_load(path, n, set, &m.scene));
  assert_ok(mpm_model_create(m.scene, &m.sim));
  return m;
}

static void drop_model(model *m) {
  mpm_model_destroy(m->sim);
  pm_scene_destroy(m->scene);
}

/* Coordinates of grid node `node`. */
static void node_position(const mpm_grid *g, long node, double x[3]) {
  long ijk[3] = {node % g->nn[0], (node / g->nn[0]) % g->nn[1],
                 node / (g->nn[0] * g->nn[1])};
  for (int c = 0; c < 3; c++) x[c] = g->origin[c] + ijk[c] * g->h;
}

/* ---- 1. shape functions ------------------------------------------------- */

static void test_shape_1d(void **state) {
  (void)state;
  const double h = 0.37, inv_h = 1 / h;
  for (int s = 0; s < 2; s++) {
    const pm_shape shape = s ? PM_SHAPE_QUADRATIC : PM_SHAPE_LINEAR;
    const int width = mpm_shape_width(shape);
    assert_int_equal(width, s ? 3 : 2);
    for (int trial = 0; trial < 20000; trial++) {
      double xi = 0.5 + 40 * uniform();
      long i0;
      double w[3], dw[3];
      mpm_shape_1d(shape, xi, inv_h, &i0, w, dw);
      double sw = 0, sdw = 0, sx = 0, sg = 0;
      for (int k = 0; k < width; k++) {
        if (!(w[k] >= 0)) fail_msg("w[%d] = %g < 0 at xi = %.17g", k, w[k], xi);
        /* Every stencil node is within the support of its function. */
        assert_true(fabs(xi - (double)(i0 + k)) <= 0.5 * width);
        sw += w[k];
        sdw += dw[k];
        sx += w[k] * (double)(i0 + k);
        sg += dw[k] * (double)(i0 + k) * h;
      }
      /* A sum of at most three terms in [0, 1], each a square or product
       * rounded once: a few ulp of 1. */
      assert_near(sw, 1.0, 1e-15);
      /* Derivatives are O(1/h) each, rounded once: a few ulp of 1/h. */
      assert_near(sdw, 0.0, 1e-15 * inv_h);
      /* Terms up to |xi| + 2 in size: a few ulp of that. */
      assert_near(sx, xi, 8 * EPS * (xi + 2));
      assert_near(sg, 1.0, 8 * EPS * (xi + 2));
    }
  }
}

/* Weight and derivative (per cell) of node i at xi, 0 outside its
 * support: the global basis function, whichever stencil holds it. */
static void node_weight(pm_shape s, long i, double xi, double *N, double *dN) {
  long i0;
  double w[3], dw[3];
  mpm_shape_1d(s, xi, 1.0, &i0, w, dw);
  *N = *dN = 0;
  for (int k = 0; k < mpm_shape_width(s); k++)
    if (i0 + k == i) *N = w[k], *dN = dw[k];
}

/* Largest jumps of the basis functions and their derivatives across the
 * knots (half-integers for the quadratic, integers for the linear). */
static void knot_jumps(pm_shape s, double delta, double *jump_w,
                       double *jump_dw) {
  double knot_shift = s == PM_SHAPE_QUADRATIC ? 0.5 : 0.0;
  *jump_w = *jump_dw = 0;
  for (long n = 2; n < 12; n++) {
    double knot = n + knot_shift;
    for (long i = n - 3; i <= n + 3; i++) {
      double Nl, dNl, Nr, dNr;
      node_weight(s, i, knot - delta, &Nl, &dNl);
      node_weight(s, i, knot + delta, &Nr, &dNr);
      *jump_w = fmax(*jump_w, fabs(Nr - Nl));
      *jump_dw = fmax(*jump_dw, fabs(dNr - dNl));
      /* At the knot itself: the right-hand branch, equal to the left
       * limit for a continuous function. */
      double N0, dN0;
      node_weight(s, i, knot, &N0, &dN0);
      *jump_w = fmax(*jump_w, fabs(N0 - Nl) - delta);
    }
  }
}

static void test_shape_continuity(void **state) {
  (void)state;
  const double delta = 1e-7;
  double jw, jdw;
  /* Quadratic: C1.  Across 2 delta the weight changes by at most
   * 2 delta max|N'| = 2 delta and the derivative by 2 delta max|N''| =
   * 4 delta; the bounds leave room for rounding. */
  knot_jumps(PM_SHAPE_QUADRATIC, delta, &jw, &jdw);
  assert_true(jw <= 3 * delta);
  assert_true(jdw <= 5 * delta);
  /* Linear: C0 only: the same check sees the kink (slopes -1 | +1, or
   * +1 | -1 at the node: a jump of 2 per cell). */
  knot_jumps(PM_SHAPE_LINEAR, delta, &jw, &jdw);
  assert_true(jw <= 3 * delta);
  assert_near(jdw, 2.0, 1e-6);
}

/* The tensor-product stencil of the grid reproduces f = a + b.x and its
 * gradient at random positions where a particle may be. */
static void check_linear_field(const mpm_grid *g, int trials) {
  const double a = 0.7, b[3] = {1.3, -2.1, 0.6};
  for (int t = 0; t < trials; t++) {
    double x[3] = {0, 0, 0};
    for (int c = 0; c < g->dim; c++)
      x[c] = g->lo[c] + (g->hi[c] - g->lo[c]) * uniform();
    mpm_stencil st;
    mpm_stencil_at(g, x, &st);
    double f = 0, grad[3] = {0, 0, 0}, f_abs = 0, g_abs[3] = {0, 0, 0};
    for (int k = 0; k < st.n[2]; k++)
      for (int j = 0; j < st.n[1]; j++)
        for (int i = 0; i < st.n[0]; i++) {
          long node =
              st.base + i * g->stride[0] + j * g->stride[1] + k * g->stride[2];
          assert_true(node >= 0 && node < g->n_nodes);
          double xn[3];
          node_position(g, node, xn);
          double fn = a + b[0] * xn[0] + b[1] * xn[1] + b[2] * xn[2];
          double w = st.w[0][i] * st.w[1][j] * st.w[2][k];
          double gw[3] = {st.dw[0][i] * st.w[1][j] * st.w[2][k],
                          st.w[0][i] * st.dw[1][j] * st.w[2][k],
                          st.w[0][i] * st.w[1][j] * st.dw[2][k]};
          f += w * fn;
          f_abs += fabs(w * fn);
          for (int c = 0; c < 3; c++) {
            grad[c] += gw[c] * fn;
            g_abs[c] += fabs(gw[c] * fn);
          }
        }
    /* Round-off of a sum of at most 27 products of three rounded weights
     * and a rounded value: bounded by ~ 64 eps times the sum of |terms|. */
    assert_near(f, a + b[0] * x[0] + b[1] * x[1] + b[2] * x[2],
                64 * EPS * f_abs);
    for (int c = 0; c < 3; c++)
      assert_near(grad[c], c < g->dim ? b[c] : 0.0, 64 * EPS * g_abs[c]);
  }
}

static const char *const BOX_3D =
    "name: stencil-3d\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [-0.2, 0.1, 0.3], max: [0.6, 0.5, 0.9]}}\n"
    "discretization: {mesh_size: 0.1}\n"
    "materials:\n"
    "  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: "
    "1.0e4, poisson_ratio: 0.3}\n"
    "time: {end: 1}\n";

static void test_stencil_reproduces_linear(void **state) {
  char path[512];
  write_file(*state, "box-3d.yaml", BOX_3D, path);
  static const char *const shapes[] = {"mpm.shape=linear",
                                       "mpm.shape=quadratic"};
  for (int s = 0; s < 2; s++) {
    model m2 = make_model(MINIMAL, 1, &shapes[s]);
    assert_int_equal(m2.sim->grid.dim, 2);
    check_linear_field(&m2.sim->grid, 2000);
    drop_model(&m2);
    model m3 = make_model(path, 1, &shapes[s]);
    assert_int_equal(m3.sim->grid.dim, 3);
    assert_int_equal(m3.sim->grid.width, s ? 3 : 2);
    check_linear_field(&m3.sim->grid, 2000);
    drop_model(&m3);
  }
}

/* ---- 2. conservation by the transfers and the step ---------------------- */

/* Two solids of different materials with different velocities: a box
 * inside a sphere, so that the velocity jump makes stresses. */
static const char *const TWO_BODIES =
    "name: two-bodies\n"
    "method: mpm\n"
    "dimension: 3\n"
    "domain: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
    "discretization: {mesh_size: 0.125}\n"
    "materials:\n"
    "  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: "
    "1.0e4, poisson_ratio: 0.3}\n"
    "  - {name: stiff, model: linear-elastic, density: 2000, "
    "youngs_modulus: 4.0e4, poisson_ratio: 0.25}\n"
    "bodies:\n"
    "  - {material: gel, sphere: {center: [0.5, 0.5, 0.5], radius: 0.3}, "
    "velocity: [0.2, -0.1, 0.05]}\n"
    "  - {material: stiff, box: {min: [0.3, 0.35, 0.4], max: [0.6, 0.65, "
    "0.7]}, velocity: [-0.3, 0.25, 0.1]}\n"
    "time: {end: 1}\n";

typedef struct {
  double mass, mom[3], mom_scale; /* sum m, sum m v, sum m |v| */
} particle_sums;

static particle_sums sum_particles(const mpm_sim *sim) {
  particle_sums s = {0, {0, 0, 0}, 0};
  for (long p = 0; p < sim->n; p++) {
    const double *v = sim->v + 3 * p;
    s.mass += sim->mass[p];
    for (int c = 0; c < 3; c++) s.mom[c] += sim->mass[p] * v[c];
    s.mom_scale += sim->mass[p] * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  return s;
}

static void test_p2g_conserves(void **state) {
  char path[512];
  write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
  static const char *const shapes[] = {"mpm.shape=quadratic",
                                       "mpm.shape=linear"};
  for (int s = 0; s < 2; s++) {
    model m = make_model(path, 1, &shapes[s]);
    mpm_sim *sim = m.sim;
    const mpm_grid *g = &sim->grid;
    assert_int_equal(sim->n_groups, 2);
    assert_true(sim->n > 300);
    /* Random symmetric stresses, up to 1 kPa. */
    for (long p = 0; p < sim->n; p++) {
      double *sig = sim->sigma + 9 * p;
      for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++)
          sig[3 * i + j] = sig[3 * j + i] = 1e3 * (2 * uniform() - 1);
    }
    mpm_p2g(sim, 1);
    particle_sums ps = sum_particles(sim);
    double mass = 0, mom[3] = {0, 0, 0}, F[3] = {0, 0, 0}, F_abs = 0;
    double T[3] = {0, 0, 0}, T_abs = 0;
    for (long i = 0; i < g->n_nodes; i++) {
      mass += g->mass[i];
      const double *f = g->force + 3 * i;
      double x[3];
      node_position(g, i, x);
      for (int c = 0; c < 3; c++) {
        mom[c] += g->mom[3 * i + c];
        F[c] += f[c];
        x[c] -= 0.5; /* about the domain's centre */
      }
      double fn = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      F_abs += fn;
      T[0] += x[1] * f[2] - x[2] * f[1];
      T[1] += x[2] * f[0] - x[0] * f[2];
      T[2] += x[0] * f[1] - x[1] * f[0];
      T_abs += sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) * fn;
    }
    /* The weights sum to 1 to a few ulp; the sums over ~ 500 particles
     * and ~ 1000 nodes add ~ 1e-16 relative each, in random directions. */
    assert_near(mass, ps.mass, 1e-14 * ps.mass);
    for (int c = 0; c < 3; c++)
      assert_near(mom[c], ps.mom[c], 1e-14 * ps.mom_scale);
    /* Internal forces cancel (the gradients sum to 0) and, the stress
     * being symmetric, exert no torque (the gradients reproduce x): both
     * to round-off of the sums, relative to the size of the terms. */
    assert_true(F_abs > 0);
    double em = fabs(mass - ps.mass) / ps.mass, ep = 0, ef = 0, et = 0;
    for (int c = 0; c < 3; c++) {
      ep = fmax(ep, fabs(mom[c] - ps.mom[c]) / ps.mom_scale);
      ef = fmax(ef, fabs(F[c]) / F_abs);
      et = fmax(et, fabs(T[c]) / T_abs);
    }
    print_message("%s, %ld particles: mass %.1e, momentum %.1e, force %.1e, "
                  "torque %.1e (relative)\n",
                  shapes[s], sim->n, em, ep, ef, et);
    for (int c = 0; c < 3; c++) {
      assert_near(F[c], 0.0, 1e-13 * F_abs);
      assert_near(T[c], 0.0, 1e-13 * T_abs);
    }
    drop_model(&m);
  }
}

static void test_step_conserves(void **state) {
  char path[512];
  write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
  static const char *const sets[][3] = {
      {"mpm.shape=quadratic", "mpm.flip=1", "mpm.update=musl"},
      {"mpm.shape=quadratic", "mpm.flip=0", "mpm.update=musl"},
      {"mpm.shape=linear", "mpm.flip=1", "mpm.update=musl"},
      {"mpm.shape=linear", "mpm.flip=0", "mpm.update=musl"},
      {"mpm.shape=quadratic", "mpm.flip=1", "mpm.update=usl"},
      {"mpm.shape=quadratic", "mpm.flip=0.5", "mpm.update=usf"},
  };
  const int steps = 25;
  for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
    model m = make_model(path, 3, sets[k]);
    mpm_sim *sim = m.sim;
    particle_sums p0 = sum_particles(sim);
    assert_true(sim->dt > 0 && isfinite(sim->dt));
    double worst = 0;
    for (int n = 0; n < steps; n++) {
      assert_ok(mpm_step(sim));
      particle_sums p = sum_particles(sim);
      /* Particle masses never change; the grid mass of the step's
       * transfer is theirs to round-off. */
      assert_true(p.mass == p0.mass);
      double gm = 0;
      for (long i = 0; i < sim->grid.n_nodes; i++) gm += sim->grid.mass[i];
      assert_near(gm, p0.mass, 1e-14 * p0.mass);
      for (int c = 0; c < 3; c++)
        worst = fmax(worst, fabs(p.mom[c] - p0.mom[c]) / p0.mom_scale);
    }
    /* No boundary conditions, no gravity: the internal forces cancel on
     * the grid and both FLIP and PIC hand the grid's momentum change back
     * whole; what is left is round-off, ~ 1e-16 per step. */
    if (!(worst <= 1e-13))
      fail_msg("%s %s %s: momentum drift %g of sum m|v| after %d steps",
               sets[k][0], sets[k][1], sets[k][2], worst, steps);
    print_message("%s %s %s: momentum drift %.1e of sum m|v| over %d steps\n",
                  sets[k][0], sets[k][1], sets[k][2], worst, steps);
    /* The bodies did interact: the velocities changed by far more than
     * the tolerance above. */
    double change = 0;
    for (int gi = 0; gi < sim->n_groups; gi++) {
      const pm_scene_body *b = &m.scene->bodies[gi];
      for (long p = sim->group[gi].begin; p < sim->group[gi].end; p++)
        for (int c = 0; c < 3; c++)
          change += sim->mass[p] * fabs(sim->v[3 * p + c] - b->velocity[c]);
    }
    assert_true(change > 1e-3 * p0.mom_scale);
    drop_model(&m);
  }
}

/* ---- 3. state and stages from what the scene holds ---------------------- */

static bool has_stage(const mpm_sim *sim, const char *name) {
  for (int k = 0; k < sim->n_stages; k++)
    if (strcmp(sim->stage[k].name, name) == 0) return true;
  return false;
}

/* The plan's text, for searching. */
static char *plan_text(const pm_scene *s) {
  mpm_run *r = NULL;
  assert_ok(mpm_run_create(s, &r));
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  assert_non_null(f);
  assert_ok(mpm_run_plan(r, f));
  assert_int_equal(fclose(f), 0);
  mpm_run_destroy(r);
  return text;
}

static void assert_contains(const char *text, const char *frag) {
  if (!strstr(text, frag)) fail_msg("\"%s\" not in:\n%s", frag, text);
}

static const char *const GAS_2D =
    "name: gas-2d\n"
    "method: mpm\n"
    "dimension: 2\n"
    "domain: {box: {min: [0, 0], max: [1, 0.5]}}\n"
    "discretization: {mesh_size: 0.1}\n"
    "materials:\n"
    "  - name: gas\n"
    "    model: fluid\n"
    "    density: 1.0\n"
    "    eos: {type: ideal-gas, gamma: 1.4}\n"
    "    artificial_viscosity: {c0: 2.0, c1: 1.0}\n"
    "bodies:\n"
    "  - {material: gas, box: {min: [0.2, 0.1], max: [0.8, 0.4]}, pressure: "
    "1.0}\n"
    "time: {end: 1}\n";

static void test_solid_state_and_stages(void **state) {
  (void)state;
  model m = make_model(MINIMAL, 0, NULL);
  const mpm_sim *sim = m.sim;
  assert_false(sim->has_fluid);
  assert_int_equal(sim->n_groups, 1);
  const mpm_group *g = &sim->group[0];
  assert_false(g->fluid);
  assert_non_null(g->F);
  assert_null(g->rho);
  assert_null(g->energy);
  assert_null(g->pressure);
  assert_null(g->q);
  assert_null(sim->grid.impedance);
  assert_null(sim->grid.force_prev);
  assert_int_equal(mpm_group_bytes_per_particle(g), 72); /* F only */
  static const char *const absent[] = {"stress: fluid", "absorbing boundaries",
                                       "gravity", "damping"};
  for (int k = 0; k < 4; k++) assert_false(has_stage(sim, absent[k]));
  static const char *const present[] = {"time step",   "p2g",           "g2p",
                                        "grid update", "stress: solid", "move"};
  for (int k = 0; k < 6; k++) assert_true(has_stage(sim, present[k]));
  drop_model(&m);

  /* Artificial viscosity on a solid: q, still no fluid state. */
  const char *av = "materials.0.artificial_viscosity.c1=0.5";
  m = make_model(MINIMAL, 1, &av);
  g = &m.sim->group[0];
  assert_non_null(g->F);
  assert_non_null(g->q);
  assert_null(g->rho);
  assert_int_equal(mpm_group_bytes_per_particle(g), 80);
  drop_model(&m);

  /* The update variant: USL keeps no separate stress velocity (the stress
   * reads the updated one, which must be allocated before it is taken),
   * MUSL remaps, USF takes the velocity before the update. */
  const char *usl = "mpm.update=usl", *usf = "mpm.update=usf";
  m = make_model(MINIMAL, 1, &usl);
  assert_null(m.sim->grid.vel);
  assert_non_null(m.sim->grid.vel_new);
  assert_ptr_equal(m.sim->grid.vel_stress, m.sim->grid.vel_new);
  assert_false(has_stage(m.sim, "remap"));
  assert_false(has_stage(m.sim, "grid velocity"));
  drop_model(&m);
  m = make_model(MINIMAL, 0, NULL);
  assert_non_null(m.sim->grid.vel);
  assert_ptr_equal(m.sim->grid.vel_stress, m.sim->grid.vel);
  assert_true(has_stage(m.sim, "remap"));
  drop_model(&m);
  m = make_model(MINIMAL, 1, &usf);
  assert_ptr_equal(m.sim->grid.vel_stress, m.sim->grid.vel);
  assert_true(has_stage(m.sim, "grid velocity"));
  assert_true(has_stage(m.sim, "p2g force"));
  assert_false(has_stage(m.sim, "remap"));
  drop_model(&m);

  /* Gravity adds its stage, an absorbing face its stage and the grid
   * impedances. */
  const char *grav = "gravity=[0, -9.81]";
  m = make_model(MINIMAL, 1, &grav);
  assert_true(has_stage(m.sim, "gravity"));
  assert_false(has_stage(m.sim, "absorbing boundaries"));
  assert_null(m.sim->grid.impedance);
  drop_model(&m);
  const char *absorb = "boundary=[{on: xmin, absorbing: true}]";
  m = make_model(MINIMAL, 1, &absorb);
  assert_true(m.sim->has_absorbing);
  assert_true(has_stage(m.sim, "absorbing boundaries"));
  assert_false(has_stage(m.sim, "gravity"));
  assert_non_null(m.sim->grid.impedance);
  drop_model(&m);

  /* The plan names the stages and the memory per particle. */
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(MINIMAL, 0, NULL, &s));
  char *text = plan_text(s);
  assert_contains(text, "pipeline");
  for (int k = 0; k < 6; k++) assert_contains(text, present[k]);
  assert_contains(text, "bytes per particle");
  char own[64];
  snprintf(own, sizeof own, "%zu bytes per particle (%zu common + 72: F)",
           mpm_particle_bytes_common() + 72, mpm_particle_bytes_common());
  assert_contains(text, own);
  free(text);
  pm_scene_destroy(s);
}

static void test_fluid_state_and_stages(void **state) {
  char path[512];
  write_file(*state, "gas-2d.yaml", GAS_2D, path);
  model m = make_model(path, 0, NULL);
  const mpm_sim *sim = m.sim;
  assert_true(sim->has_fluid);
  assert_int_equal(sim->n_groups, 1);
  const mpm_group *g = &sim->group[0];
  assert_true(g->fluid);
  assert_null(g->F);
  assert_non_null(g->rho);
  assert_non_null(g->energy);
  assert_non_null(g->pressure);
  assert_non_null(g->q);
  assert_int_equal(mpm_group_bytes_per_particle(g), 32);
  assert_true(has_stage(sim, "stress: fluid"));
  assert_false(has_stage(sim, "stress: solid"));
  assert_false(has_stage(sim, "gravity"));
  assert_null(sim->grid.impedance);
  /* Seeded state: the body's density and pressure, sigma = -p I. */
  for (long k = 0; k < g->end - g->begin; k++) {
    assert_near(g->rho[k], 1.0, 0);
    assert_near(g->pressure[k], 1.0, 0);
    assert_near(sim->sigma[9 * (g->begin + k)], -1.0, 0);
  }
  drop_model(&m);

  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  char *text = plan_text(s);
  assert_contains(text, "stress: fluid");
  assert_contains(text, "bytes per particle");
  assert_contains(text, " density energy pressure q)");
  free(text);
  pm_scene_destroy(s);
}

/* ---- 4. bad scenes --------------------------------------------------------
 */

/* "path:line:col" of the first occurrence of needle in text. */
static void locate(const char *path, const char *text, const char *needle,
                   char *buf, size_t size) {
  const char *at = strstr(text, needle);
  assert_non_null(at);
  int line = 1;
  const char *bol = text;
  for (const char *c = text; c < at; c++)
    if (*c == '\n') line++, bol = c + 1;
  snprintf(buf, size, "%s:%d:%d", path, line, (int)(at - bol) + 1);
}

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
     "{name: gas", ": materials.0: ", "missing required key eos", false},
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
    write_file(*state, BAD[k].name, BAD[k].text, path);
    locate(path, BAD[k].text, BAD[k].at, at, sizeof at);
    pm_scene *s = (pm_scene *)&s; /* must be reset to NULL */
    pm_error_clear();
    if (!BAD[k].at_create) {
      assert_int_equal(pm_scene_load(path, 0, NULL, &s), PM_ERR_SCENE);
      assert_null(s);
    } else {
      assert_ok(pm_scene_load(path, 0, NULL, &s));
      mpm_sim *sim = (mpm_sim *)&sim;
      assert_int_equal(mpm_model_create(s, &sim), PM_ERR_SCENE);
      assert_null(sim);
      pm_scene_destroy(s);
    }
    /* Where and which key, then what was expected. */
    char where[700];
    snprintf(where, sizeof where, "%s%s", at, BAD[k].key);
    assert_message(where, BAD[k].what, NULL);
    print_message("%s\n", pm_error_message());
  }
  /* The same sphere reaching below y = 0 names that side. */
  write_file(*state, "sphere-low.yaml", BAD[2].text, path);
  locate(path, BAD[2].text, BAD[2].at, at, sizeof at);
  const char *low = "bodies.1.sphere.center=[0.5, 0.1, 0.5]";
  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 1, &low, &s));
  mpm_sim *sim = NULL;
  assert_int_equal(mpm_model_create(s, &sim), PM_ERR_SCENE);
  char where[700];
  snprintf(where, sizeof where, "%s: bodies.1.sphere: ", at);
  assert_message(where, "y in [0, 1]), got one reaching y = -0.1",
                 "outside the grid");
  pm_scene_destroy(s);
  /* A scene of another method is refused as an argument error. */
  assert_ok(pm_scene_load(PM_TEST_DATA "/scenes/f2-unconstrained-"
                                       "compression.yaml",
                          0, NULL, &s));
  assert_int_equal(mpm_model_create(s, &sim), PM_ERR_ARG);
  assert_null(sim);
  pm_scene_destroy(s);
}

/* ---- 5. seeding ------------------------------------------------------------
 */

static void test_seed_box(void **state) {
  (void)state;
  const char *set[] = {
      "mpm.particles_per_cell=[2, 2]",
      "bodies=[{material: rubber, box: {min: [0, 0], max: [1, 0.5]}, "
      "density: 800}]",
  };
  model m = make_model(MINIMAL, 2, set);
  const mpm_sim *sim = m.sim;
  const double h = 0.1, area = 1.0 * 0.5;
  enum { NX = 10, NY = 5 };
  assert_int_equal(sim->n, 4 * NX * NY);
  int count[NX][NY];
  memset(count, 0, sizeof count);
  double vol = 0;
  for (long p = 0; p < sim->n; p++) {
    const double *x = sim->x + 3 * p;
    int i = (int)floor(x[0] / h), j = (int)floor(x[1] / h);
    assert_true(i >= 0 && i < NX && j >= 0 && j < NY);
    count[i][j]++;
    /* Seeds at a quarter and three quarters of the cell. */
    double fx = x[0] / h - i, fy = x[1] / h - j;
    assert_true(fabs(fx - 0.25) < 1e-9 || fabs(fx - 0.75) < 1e-9);
    assert_true(fabs(fy - 0.25) < 1e-9 || fabs(fy - 0.75) < 1e-9);
    assert_near(x[2], 0.0, 0);
    /* h^2 / 4 and density times it, rounded once each. */
    assert_near(sim->vol0[p], h * h / 4, 2 * EPS * h * h / 4);
    assert_near(sim->vol[p], sim->vol0[p], 0);
    assert_near(sim->mass[p], 800 * sim->vol0[p], 2 * EPS * sim->mass[p]);
    vol += sim->vol0[p];
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
  write_file(dir, name, text, path);
  model m = make_model(path, 0, NULL);
  double vol = 0;
  for (long p = 0; p < m.sim->n; p++) {
    vol += m.sim->vol0[p];
    assert_near(m.sim->mass[p], 1000 * m.sim->vol0[p], 1e-12);
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
      cmocka_unit_test(test_shape_1d),
      cmocka_unit_test(test_shape_continuity),
      cmocka_unit_test_setup_teardown(test_stencil_reproduces_linear,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_p2g_conserves, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_step_conserves, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_solid_state_and_stages),
      cmocka_unit_test_setup_teardown(test_fluid_state_and_stages,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_scenes, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_seed_box),
      cmocka_unit_test_setup_teardown(test_seed_sphere, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
