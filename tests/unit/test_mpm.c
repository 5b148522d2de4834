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

#include "mpm_backend.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_shape.h"
#include "mpm_solver.h"
#include "mpm_state.h"
#include "mpm_transfer.h"
#include "pm_app.h"
#include "pm_run.h"
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

/* A scene's model, state and workspace. */
typedef struct {
  pm_scene *scene;
  mpm_model *model;
  mpm_state *state;
  mpm_work *work;
} model;

static model make_model(const char *path, int n, const char *const *set) {
  model m = {NULL, NULL, NULL, NULL};
  assert_ok(pm_scene_load(path, n, set, &m.scene));
  assert_ok(mpm_model_create(m.scene, &m.model, &m.state));
  assert_ok(mpm_work_create(m.model, &m.work));
  return m;
}

static void drop_model(model *m) {
  mpm_work_destroy(m->work);
  mpm_state_destroy(m->state);
  mpm_model_destroy(m->model);
  pm_scene_destroy(m->scene);
}

static void step(model *m) { assert_ok(mpm_step(m->model, m->state, m->work)); }

/* Group gi's state array called name, or NULL. */
static const double *group_array(const model *m, int gi, const char *name) {
  const mpm_array *a = mpm_group_state_find(&m->state->group[gi], name);
  return a ? a->data : NULL;
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
    const mpm_basis shape = s ? MPM_BASIS_QUADRATIC : MPM_BASIS_LINEAR;
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
static void node_weight(mpm_basis s, long i, double xi, double *N, double *dN) {
  long i0;
  double w[3], dw[3];
  mpm_shape_1d(s, xi, 1.0, &i0, w, dw);
  *N = *dN = 0;
  for (int k = 0; k < mpm_shape_width(s); k++)
    if (i0 + k == i) *N = w[k], *dN = dw[k];
}

/* Largest jumps of the basis functions and their derivatives across the
 * knots (half-integers for the quadratic, integers for the linear). */
static void knot_jumps(mpm_basis s, double delta, double *jump_w,
                       double *jump_dw) {
  double knot_shift = s == MPM_BASIS_QUADRATIC ? 0.5 : 0.0;
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
  knot_jumps(MPM_BASIS_QUADRATIC, delta, &jw, &jdw);
  assert_true(jw <= 3 * delta);
  assert_true(jdw <= 5 * delta);
  /* Linear: C0 only: the same check sees the kink (slopes -1 | +1, or
   * +1 | -1 at the node: a jump of 2 per cell). */
  knot_jumps(MPM_BASIS_LINEAR, delta, &jw, &jdw);
  assert_true(jw <= 3 * delta);
  assert_near(jdw, 2.0, 1e-6);
}

/* The stencil iterator at random positions where a particle may be: all
 * width^dim nodes on the grid and distinct, weights >= 0 that are a
 * partition of unity with gradients summing to zero, and together they
 * reproduce f = a + b.x and its gradient; asking for weights or gradients
 * alone gives the same values to the bit. */
static void check_stencil(const mpm_grid *g, int trials) {
  const double a = 0.7, b[3] = {1.3, -2.1, 0.6};
  const int n =
      g->dim == 3 ? g->width * g->width * g->width : g->width * g->width;
  for (int t = 0; t < trials; t++) {
    double x[3] = {0, 0, 0};
    for (int c = 0; c < g->dim; c++)
      x[c] = g->lo[c] + (g->hi[c] - g->lo[c]) * uniform();
    mpm_stencil st, sw, sg;
    mpm_stencil_at(g, x, MPM_STENCIL_W | MPM_STENCIL_GRAD, &st);
    mpm_stencil_at(g, x, MPM_STENCIL_W, &sw);
    mpm_stencil_at(g, x, MPM_STENCIL_GRAD, &sg);
    assert_int_equal(st.n, n);
    assert_int_equal(sw.n, n);
    assert_int_equal(sg.n, n);
    double f = 0, grad[3] = {0, 0, 0}, f_abs = 0, g_abs[3] = {0, 0, 0};
    double sum_w = 0, sum_g[3] = {0, 0, 0}, x_w[3] = {0, 0, 0};
    for (int k = 0; k < st.n; k++) {
      long node = st.node[k];
      assert_true(node >= 0 && node < g->n_nodes);
      for (int l = 0; l < k; l++) assert_true(st.node[l] != node);
      assert_true(sw.node[k] == node && sg.node[k] == node);
      assert_true(sw.w[k] == st.w[k]);
      for (int c = 0; c < 3; c++) assert_true(sg.grad[k][c] == st.grad[k][c]);
      assert_true(st.w[k] >= 0);
      double xn[3];
      node_position(g, node, xn);
      double fn = a + b[0] * xn[0] + b[1] * xn[1] + b[2] * xn[2];
      sum_w += st.w[k];
      f += st.w[k] * fn;
      f_abs += fabs(st.w[k] * fn);
      for (int c = 0; c < 3; c++) {
        sum_g[c] += st.grad[k][c];
        x_w[c] += st.w[k] * xn[c];
        grad[c] += st.grad[k][c] * fn;
        g_abs[c] += fabs(st.grad[k][c] * fn);
      }
    }
    /* Round-off of a sum of at most 27 products of three rounded weights
     * (each in [0, 1]) and a rounded value: bounded by ~ 64 eps times the
     * sum of |terms|. */
    assert_near(sum_w, 1.0, 64 * EPS);
    for (int c = 0; c < 3; c++) {
      double scale = 0;
      for (int k = 0; k < st.n; k++) scale += fabs(st.grad[k][c]);
      assert_near(sum_g[c], 0.0, 64 * EPS * scale);
      assert_near(x_w[c], x[c], 64 * EPS * (fabs(x[c]) + 2 * g->h));
    }
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

static void test_stencil_iterator(void **state) {
  char path[512];
  write_file(*state, "box-3d.yaml", BOX_3D, path);
  static const char *const shapes[] = {"mpm.shape=linear",
                                       "mpm.shape=quadratic"};
  for (int s = 0; s < 2; s++) {
    model m2 = make_model(MINIMAL, 1, &shapes[s]);
    assert_int_equal(m2.model->grid.dim, 2);
    assert_int_equal(m2.model->grid.width, s ? 3 : 2);
    check_stencil(&m2.model->grid, 2000);
    drop_model(&m2);
    model m3 = make_model(path, 1, &shapes[s]);
    assert_int_equal(m3.model->grid.dim, 3);
    assert_int_equal(m3.model->grid.width, s ? 3 : 2);
    check_stencil(&m3.model->grid, 2000);
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

static particle_sums sum_particles(const model *m) {
  particle_sums s = {0, {0, 0, 0}, 0};
  const double *mass = m->model->mass;
  for (long p = 0; p < m->model->n; p++) {
    const double *v = m->state->v + 3 * p;
    s.mass += mass[p];
    for (int c = 0; c < 3; c++) s.mom[c] += mass[p] * v[c];
    s.mom_scale += mass[p] * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
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
    const mpm_grid *g = &m.model->grid;
    const mpm_nodes *nd = &m.work->nodes;
    assert_int_equal(m.model->n_groups, 2);
    assert_true(m.model->n > 300);
    /* Random symmetric stresses, up to 1 kPa. */
    for (long p = 0; p < m.model->n; p++) {
      double *sig = m.state->sigma + 9 * p;
      for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++)
          sig[3 * i + j] = sig[3 * j + i] = 1e3 * (2 * uniform() - 1);
    }
    mpm_ctx ctx = {m.model, m.state, m.work};
    mpm_p2g(&ctx, MPM_P2G_MASS | MPM_P2G_MOM | MPM_P2G_FORCE);
    particle_sums ps = sum_particles(&m);
    double mass = 0, mom[3] = {0, 0, 0}, F[3] = {0, 0, 0}, F_abs = 0;
    double T[3] = {0, 0, 0}, T_abs = 0;
    for (long i = 0; i < g->n_nodes; i++) {
      mass += nd->mass[i];
      const double *f = nd->force + 3 * i;
      double x[3];
      node_position(g, i, x);
      for (int c = 0; c < 3; c++) {
        mom[c] += nd->mom[3 * i + c];
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
                  shapes[s], m.model->n, em, ep, ef, et);
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
    particle_sums p0 = sum_particles(&m);
    assert_true(m.state->dt > 0 && isfinite(m.state->dt));
    double worst = 0;
    for (int n = 0; n < steps; n++) {
      step(&m);
      particle_sums p = sum_particles(&m);
      /* Particle masses never change; the grid mass of the step's
       * transfer is theirs to round-off. */
      assert_true(p.mass == p0.mass);
      double gm = 0;
      for (long i = 0; i < m.model->grid.n_nodes; i++)
        gm += m.work->nodes.mass[i];
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
    for (int gi = 0; gi < m.model->n_groups; gi++) {
      const pm_scene_body *b = &m.scene->bodies[gi];
      const mpm_group *g = &m.model->group[gi];
      for (long p = g->begin; p < g->end; p++)
        for (int c = 0; c < 3; c++)
          change +=
              m.model->mass[p] * fabs(m.state->v[3 * p + c] - b->velocity[c]);
    }
    assert_true(change > 1e-3 * p0.mom_scale);
    drop_model(&m);
  }
}

/* ---- 3. state and stages from what the scene holds ---------------------- */

static const mpm_stage *find_stage(const mpm_model *m, const char *name) {
  for (int k = 0; k < m->pipeline.n; k++)
    if (strcmp(m->pipeline.stage[k].name, name) == 0)
      return &m->pipeline.stage[k];
  return NULL;
}

static bool has_stage(const model *m, const char *name) {
  return find_stage(m->model, name) != NULL;
}

/* The plan's text, for searching. */
static char *plan_text(const pm_scene *s) {
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  assert_non_null(f);
  assert_ok(pm_plan_scene(s, f));
  assert_int_equal(fclose(f), 0);
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

/* No stage of m runs fn, as its step or as its hook. */
static bool never_runs(const mpm_model *m, mpm_stage_fn fn) {
  for (int k = 0; k < m->pipeline.n; k++)
    if (m->pipeline.stage[k].run == fn ||
        m->pipeline.stage[k].after_update == fn)
      return false;
  return true;
}

static void test_solid_state_and_stages(void **state) {
  (void)state;
  model m = make_model(MINIMAL, 0, NULL);
  const mpm_model *md = m.model;
  assert_int_equal(md->kinds, MPM_KIND_STRAIN_ENERGY);
  assert_int_equal(md->n_groups, 1);
  const mpm_group *g = &md->group[0];
  assert_ptr_equal(g->kind, &mpm_kind_solid);
  /* F and nothing else, in the layout and in the state. */
  assert_int_equal(g->n_arrays, 1);
  assert_string_equal(g->layout[0].name, "F");
  assert_int_equal(m.state->group[0].n, 1);
  assert_non_null(group_array(&m, 0, "F"));
  assert_null(group_array(&m, 0, "density"));
  assert_null(group_array(&m, 0, "energy"));
  assert_null(group_array(&m, 0, "pressure"));
  assert_null(group_array(&m, 0, "q"));
  assert_null(m.work->nodes.impedance);
  assert_null(m.work->cs);
  assert_null(m.state->force_prev);
  assert_null(m.state->fixed);
  assert_int_equal(mpm_group_bytes_per_particle(g), 72); /* F only */
  /* No fluid code runs. */
  assert_true(never_runs(md, mpm_kind_fluid.stress));
  static const char *const absent[] = {"stress: fluid", "absorbing boundaries",
                                       "gravity", "damping"};
  for (int k = 0; k < 4; k++) assert_false(has_stage(&m, absent[k]));
  static const char *const present[] = {"time step",   "p2g",           "g2p",
                                        "grid update", "stress: solid", "move"};
  for (int k = 0; k < 6; k++) assert_true(has_stage(&m, present[k]));
  const mpm_stage *st = find_stage(md, "stress: solid");
  assert_ptr_equal(st->run, mpm_kind_solid.stress);
  assert_int_equal(st->group, 0);
  drop_model(&m);

  /* Artificial viscosity on a solid: q, still no fluid state. */
  const char *av = "materials.0.artificial_viscosity.c1=0.5";
  m = make_model(MINIMAL, 1, &av);
  g = &m.model->group[0];
  assert_non_null(group_array(&m, 0, "F"));
  assert_non_null(group_array(&m, 0, "q"));
  assert_null(group_array(&m, 0, "density"));
  assert_int_equal(mpm_group_bytes_per_particle(g), 80);
  drop_model(&m);

  /* The update variant: USL keeps no separate stress velocity (the stress
   * reads the updated one, which must be allocated before it is taken),
   * MUSL remaps, USF takes the velocity before the update. */
  const char *usl = "mpm.update=usl", *usf = "mpm.update=usf";
  m = make_model(MINIMAL, 1, &usl);
  assert_null(m.work->nodes.vel);
  assert_non_null(m.work->nodes.vel_new);
  assert_ptr_equal(m.work->nodes.vel_stress, m.work->nodes.vel_new);
  assert_false(has_stage(&m, "remap"));
  assert_false(has_stage(&m, "grid velocity"));
  drop_model(&m);
  m = make_model(MINIMAL, 0, NULL);
  assert_non_null(m.work->nodes.vel);
  assert_ptr_equal(m.work->nodes.vel_stress, m.work->nodes.vel);
  assert_true(has_stage(&m, "remap"));
  drop_model(&m);
  m = make_model(MINIMAL, 1, &usf);
  assert_ptr_equal(m.work->nodes.vel_stress, m.work->nodes.vel);
  assert_true(has_stage(&m, "grid velocity"));
  assert_true(has_stage(&m, "p2g force"));
  assert_false(has_stage(&m, "remap"));
  drop_model(&m);

  /* Gravity adds its stage, an absorbing face its stage and the grid
   * impedances. */
  const char *grav = "gravity=[0, -9.81]";
  m = make_model(MINIMAL, 1, &grav);
  assert_true(has_stage(&m, "gravity"));
  assert_false(has_stage(&m, "absorbing boundaries"));
  assert_null(m.work->nodes.impedance);
  drop_model(&m);
  const char *absorb = "boundary=[{on: xmin, absorbing: true}]";
  m = make_model(MINIMAL, 1, &absorb);
  assert_true(m.model->has_absorbing);
  assert_true(has_stage(&m, "absorbing boundaries"));
  assert_false(has_stage(&m, "gravity"));
  assert_non_null(m.work->nodes.impedance);
  assert_non_null(m.work->cs);
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
  assert_contains(text, ", solid, ");
  if (strstr(text, "fluid")) fail_msg("\"fluid\" in a solid's plan:\n%s", text);
  free(text);
  pm_scene_destroy(s);
}

static void test_fluid_state_and_stages(void **state) {
  char path[512];
  write_file(*state, "gas-2d.yaml", GAS_2D, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  assert_int_equal(md->kinds, MPM_KIND_INTERNAL_ENERGY | MPM_KIND_ITERATES);
  assert_int_equal(md->n_groups, 1);
  const mpm_group *g = &md->group[0];
  assert_ptr_equal(g->kind, &mpm_kind_fluid);
  /* No F: density, energy, pressure and q. */
  assert_null(group_array(&m, 0, "F"));
  const double *rho = group_array(&m, 0, "density");
  const double *pressure = group_array(&m, 0, "pressure");
  assert_non_null(rho);
  assert_non_null(group_array(&m, 0, "energy"));
  assert_non_null(pressure);
  assert_non_null(group_array(&m, 0, "q"));
  assert_int_equal(m.state->group[0].n, 4);
  assert_int_equal(mpm_group_bytes_per_particle(g), 32);
  assert_true(has_stage(&m, "stress: fluid"));
  assert_false(has_stage(&m, "stress: solid"));
  assert_false(has_stage(&m, "gravity"));
  assert_true(never_runs(md, mpm_kind_solid.stress));
  assert_null(m.work->nodes.impedance);
  /* Seeded state: the body's density and pressure, sigma = -p I. */
  for (long k = 0; k < g->end - g->begin; k++) {
    assert_near(rho[k], 1.0, 0);
    assert_near(pressure[k], 1.0, 0);
    assert_near(m.state->sigma[9 * (g->begin + k)], -1.0, 0);
  }
  drop_model(&m);

  pm_scene *s = NULL;
  assert_ok(pm_scene_load(path, 0, NULL, &s));
  char *text = plan_text(s);
  assert_contains(text, "stress: fluid");
  assert_contains(text, "bytes per particle");
  assert_contains(text, " density energy pressure q)");
  assert_contains(text, ", fluid, ");
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
    write_file(*state, BAD[k].name, BAD[k].text, path);
    locate(path, BAD[k].text, BAD[k].at, at, sizeof at);
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
  write_file(*state, "sphere-low.yaml", BAD[2].text, path);
  locate(path, BAD[2].text, BAD[2].at, at, sizeof at);
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

/* ---- 5. model, state and workspace apart ---------------------------------
 */

/* A column on a floor under gravity, pressed from the top by a moving wall
 * and held on the sides, relaxed dynamically: every kind of condition, the
 * dynamic relaxation's memory and gravity's booking. */
static const char *const COLUMN[] = {
    "gravity=[0, -9.81]",
    "boundary=[{on: ymin, displacement: {y: 0}, ramp: none}, {on: xmin, "
    "displacement: {x: 0}, ramp: none}, {on: ymax, displacement: {y: "
    "-0.01}, ramp: linear, ramp_time: 0.05}]",
    "time.quasi_static.method=dynamic-relaxation",
    "materials.0.artificial_viscosity.c1=0.5",
};

/* Every value of two states of model m, compared to the bit. */
static void assert_same_state(const mpm_model *m, const mpm_state *a,
                              const mpm_state *b) {
  mpm_array aa[MPM_STATE_MAX_ARRAYS], ba[MPM_STATE_MAX_ARRAYS];
  int n = mpm_state_arrays(m, a, aa, MPM_STATE_MAX_ARRAYS);
  assert_int_equal(mpm_state_arrays(m, b, ba, MPM_STATE_MAX_ARRAYS), n);
  for (int k = 0; k < n; k++) {
    assert_string_equal(aa[k].name, ba[k].name);
    assert_true(aa[k].data != ba[k].data);
    if (memcmp(aa[k].data, ba[k].data,
               sizeof(double) * aa[k].ncomp * aa[k].count) != 0)
      fail_msg("array %s differs", aa[k].name);
  }
  const size_t n3 = 3 * (size_t)m->grid.n_nodes;
  assert_true((a->force_prev == NULL) == (b->force_prev == NULL));
  assert_true((a->fixed == NULL) == (b->fixed == NULL));
  if (a->force_prev)
    assert_memory_equal(a->force_prev, b->force_prev, n3 * sizeof(double));
  if (a->fixed) assert_memory_equal(a->fixed, b->fixed, n3);
#define SAME(f) assert_memory_equal(&a->f, &b->f, sizeof a->f)
  SAME(t);
  SAME(step);
  SAME(dt);
  SAME(dt_stable);
  SAME(max_div_prev);
  SAME(energy);
  SAME(external_work);
  SAME(dissipated);
  SAME(damping);
  SAME(iter_max_total);
  SAME(iter_capped_total);
#undef SAME
}

/* Run N steps, copy the state, run M more; restore the copy into a fresh
 * model and workspace and run the same M steps: the same state to the bit,
 * and the same figures of the last step.  So nothing a step reads from one
 * step to the next is kept outside the state. */
static void check_restart(const char *path, int n_sets, const char *const *sets,
                          int N, int M) {
  model a = make_model(path, n_sets, sets);
  for (int k = 0; k < N; k++) step(&a);
  mpm_state *saved = NULL;
  assert_ok(mpm_state_create(a.model, &saved));
  mpm_state_copy(a.model, saved, a.state);
  for (int k = 0; k < M; k++) step(&a);

  model b = make_model(path, n_sets, sets);
  mpm_state *restored = NULL;
  assert_ok(mpm_state_create(b.model, &restored));
  mpm_state_copy(b.model, restored, saved);
  assert_same_state(b.model, saved, restored);
  for (int k = 0; k < M; k++) assert_ok(mpm_step(b.model, restored, b.work));
  assert_same_state(a.model, a.state, restored);
  assert_int_equal(restored->step, N + M);
  assert_memory_equal(&a.work->residual, &b.work->residual, sizeof(double));
  if (a.model->n_bcs > 0)
    assert_memory_equal(a.work->cond.reaction, b.work->cond.reaction,
                        3 * sizeof(double) * a.model->n_bcs);
  mpm_state_destroy(restored);
  mpm_state_destroy(saved);
  drop_model(&b);
  drop_model(&a);
}

static void test_state_alone_resumes(void **state) {
  /* Dynamic relaxation with conditions keeps what it needs of the last
   * step in the state: the run must have used it. */
  model m = make_model(MINIMAL, 4, COLUMN);
  assert_non_null(m.state->force_prev);
  assert_non_null(m.state->fixed);
  double rate = 0;
  for (int k = 0; k < 20; k++) {
    step(&m);
    rate = fmax(rate, m.state->damping);
  }
  assert_true(rate > 0);
  drop_model(&m);
  check_restart(MINIMAL, 4, COLUMN, 20, 15);
  const char *usl[] = {COLUMN[0], COLUMN[1], "mpm.update=usl",
                       "mpm.shape=linear"};
  check_restart(MINIMAL, 4, usl, 7, 9);
  /* A fluid with artificial viscosity and an absorbing face. */
  char path[512];
  write_file(*state, "gas-2d.yaml", GAS_2D, path);
  const char *gas[] = {"boundary=[{on: xmin, absorbing: true}, {on: xmax, "
                       "velocity: {x: 0}}]"};
  check_restart(path, 1, gas, 12, 10);
  /* Two solids, USF, fixed damping and a fixed step. */
  write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
  const char *usf[] = {"mpm.update=usf", "time.quasi_static.method=damping",
                       "time.quasi_static.damping=5", "time.dt=1e-3"};
  check_restart(path, 4, usf, 5, 6);
}

/* ---- 6. energy booked by the stages ------------------------------------- */

static void test_stage_energy(void **state) {
  model m = make_model(MINIMAL, 4, COLUMN);
  const mpm_model *md = m.model;
  const mpm_pipeline *pl = &md->pipeline;
  const mpm_stage *gravity = find_stage(md, "gravity");
  const mpm_stage *update = find_stage(md, "grid update");
  const mpm_stage *damping = find_stage(md, "damping");
  assert_non_null(gravity);
  assert_non_null(update);
  assert_non_null(damping);
  assert_int_equal(gravity->books, MPM_BOOKS_WORK);
  assert_int_equal(update->books, MPM_BOOKS_WORK);
  assert_int_equal(damping->books, MPM_BOOKS_DISSIPATED);
  assert_non_null(gravity->after_update);
  /* Gravity's work, m g . (v0 + v1) / 2 dt over the nodes of each step,
   * summed here from the workspace the step leaves. */
  const double g = -m.scene->gravity[1];
  double grav_work = 0;
  for (int k = 0; k < 40; k++) {
    step(&m);
    const mpm_nodes *nd = &m.work->nodes;
    double w = 0;
    for (long i = 0; i < md->grid.n_nodes; i++)
      if (nd->mass[i] > 0)
        w -= nd->mass[i] * g * 0.5 *
             (nd->vel0[3 * i + 1] + nd->vel_new[3 * i + 1]);
    grav_work += w * m.state->dt;
  }
  const mpm_state *st = m.state;
  assert_true(grav_work > 0);
  /* The same terms summed in another order: round-off. */
  assert_near(st->energy[gravity->index].work, grav_work, 1e-12 * grav_work);
  assert_true(st->energy[damping->index].dissipated > 0);
  double work = 0, dissipated = 0, scale = 0;
  for (int k = 0; k < pl->n; k++) {
    const mpm_energy_account *e = &st->energy[k];
    if (!(pl->stage[k].books & MPM_BOOKS_WORK)) assert_true(e->work == 0);
    if (!(pl->stage[k].books & MPM_BOOKS_DISSIPATED))
      assert_true(e->dissipated == 0);
    work += e->work;
    dissipated += e->dissipated;
    scale += fabs(e->work) + fabs(e->dissipated);
  }
  /* The totals are the stages' bookings, summed in the order they came. */
  assert_near(work, st->external_work, 1e-14 * scale);
  assert_near(dissipated, st->dissipated, 1e-14 * scale);
  drop_model(&m);

  /* An absorbing face books all that is dissipated. */
  const char *absorb[] = {"boundary=[{on: xmin, absorbing: true}]",
                          "bodies=[{material: rubber, box: {min: [0, 0], max: "
                          "[1, 0.5]}, velocity: [-1, 0]}]"};
  m = make_model(MINIMAL, 2, absorb);
  for (int k = 0; k < 10; k++) step(&m);
  const mpm_stage *ab = find_stage(m.model, "absorbing boundaries");
  assert_non_null(ab);
  assert_int_equal(ab->books, MPM_BOOKS_DISSIPATED);
  assert_true(m.state->dissipated > 0);
  assert_true(m.state->energy[ab->index].dissipated == m.state->dissipated);
  drop_model(&m);

  /* summary.json has them by stage. */
  pm_scene *s = NULL;
  const char *sets[] = {COLUMN[0], COLUMN[1], COLUMN[2], COLUMN[3],
                        "time.max_steps=5"};
  assert_ok(pm_scene_load(MINIMAL, 5, sets, &s));
  pm_outcome o;
  char out[600], path[700];
  snprintf(out, sizeof out, "%s/run", (const char *)*state);
  pm_err e = pm_run_scene(s, out, true, &o);
  assert_true(e == PM_SUCCESS || e == PM_ERR_NOT_CONVERGED);
  snprintf(path, sizeof path, "%s/summary.json", out);
  FILE *f = fopen(path, "r");
  assert_non_null(f);
  char text[16384];
  size_t len = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[len] = '\0';
  assert_contains(text, "\"energy_by_stage\": {");
  assert_contains(text, "\"gravity\": {");
  assert_contains(text, "\"grid update\": {");
  assert_contains(text, "\"damping\": {");
  assert_contains(text, "\"dissipated\":");
  pm_scene_destroy(s);
}

/* ---- 7. the time loop ----------------------------------------------------
 */

typedef struct {
  int calls, frames;
  long frame_step[8];
  long fail_at; /* step at which the observer fails, or 0 */
} watch;

static pm_err observe(void *ctx, const mpm_model *m, const mpm_state *s,
                      const mpm_work *w, const mpm_step_info *info,
                      bool frame) {
  (void)m, (void)w;
  watch *o = ctx;
  o->calls++;
  assert_int_equal(info->step, s->step);
  assert_true(info->t == s->t);
  if (frame && o->frames < 8) o->frame_step[o->frames++] = info->step;
  if (info->step == o->fail_at)
    return PM_ERROR(PM_ERR_IO, "observer failed at step %ld", info->step);
  return PM_SUCCESS;
}

static void test_solver_observer(void **state) {
  (void)state;
  const char *moving[] = {"bodies=[{material: rubber, box: {min: [0.2, 0.1], "
                          "max: [0.8, 0.4]}, velocity: [0.05, 0]}]"};
  model m = make_model(MINIMAL, 1, moving);
  mpm_run_options opt = {.t_end = 1, .max_steps = 7, .frame_every = 3};
  watch o = {0};
  mpm_step_info last;
  assert_ok(mpm_solve(m.model, m.state, m.work, &opt, observe, &o, &last));
  /* Frames every 3 steps and at the last step. */
  assert_int_equal(o.calls, 7);
  assert_int_equal(o.frames, 3);
  assert_int_equal(o.frame_step[0], 3);
  assert_int_equal(o.frame_step[1], 6);
  assert_int_equal(o.frame_step[2], 7);
  assert_int_equal(last.step, 7);
  assert_int_equal(m.state->step, 7);
  assert_false(last.converged);
  /* An observer's failure stops the run with it. */
  opt.max_steps = 20;
  o = (watch){.fail_at = 9};
  assert_int_equal(
      mpm_solve(m.model, m.state, m.work, &opt, observe, &o, &last), PM_ERR_IO);
  assert_int_equal(o.calls, 2);
  assert_int_equal(m.state->step, 9);
  drop_model(&m);

  /* A fixed step: the last one is cut to end at t_end. */
  const char *fixed[] = {moving[0], "time.dt=0.3"};
  m = make_model(MINIMAL, 2, fixed);
  opt = (mpm_run_options){.t_end = 1, .frame_every = 100};
  o = (watch){0};
  assert_ok(mpm_solve(m.model, m.state, m.work, &opt, observe, &o, &last));
  assert_int_equal(o.calls, 4);
  assert_int_equal(o.frames, 1); /* the last step, at t_end */
  assert_int_equal(o.frame_step[0], 4);
  assert_near(m.state->t, 1.0, 4 * EPS);
  assert_near(m.state->dt, 0.1, 1e-12);
  drop_model(&m);
}

/* A step far above the stable one inverts particles: the run stops with
 * the step, time, stage, particle, positions and cause. */
static void test_unstable_message(void **state) {
  char path[512];
  write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
  const char *big[] = {"time.dt=0.5"};
  model m = make_model(path, 1, big);
  pm_err e = PM_SUCCESS;
  for (int k = 0; k < 20 && !e; k++) e = mpm_step(m.model, m.state, m.work);
  assert_int_equal(e, PM_ERR_UNSTABLE);
  const char *msg = pm_error_message();
  char head[64];
  snprintf(head, sizeof head, "step %ld, t = ", m.state->step + 1);
  assert_contains(msg, head);
  assert_contains(msg, " s, stage stress: ");
  assert_contains(msg, ": particle ");
  assert_contains(msg, "), started at (");
  assert_contains(msg, "volume ratio J = ");
  print_message("%s\n", msg);
  drop_model(&m);
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
  write_file(dir, name, text, path);
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
      cmocka_unit_test(test_shape_1d),
      cmocka_unit_test(test_shape_continuity),
      cmocka_unit_test_setup_teardown(test_stencil_iterator, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_p2g_conserves, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_step_conserves, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_solid_state_and_stages),
      cmocka_unit_test_setup_teardown(test_fluid_state_and_stages,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_scenes, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_state_alone_resumes,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_stage_energy, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_solver_observer),
      cmocka_unit_test_setup_teardown(test_unstable_message, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_seed_box),
      cmocka_unit_test_setup_teardown(test_seed_sphere, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
