/* test_mpm: the explicit MPM backend's pieces: B-spline weights and their
 * tensor products, mass and momentum conservation of the transfers and the
 * step, state and stages built only for what a scene holds, and F-bar's
 * averages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_fbar.h"
#include "mpm_testing.h"

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
  pm_test_write_file(*state, "box-3d.yaml", BOX_3D, path);
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
  pm_test_write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
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
  pm_test_write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
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
  assert_non_null(group_array(m.state, 0, "F"));
  assert_null(group_array(m.state, 0, "density"));
  assert_null(group_array(m.state, 0, "energy"));
  assert_null(group_array(m.state, 0, "pressure"));
  assert_null(group_array(m.state, 0, "q"));
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
  assert_non_null(group_array(m.state, 0, "F"));
  assert_non_null(group_array(m.state, 0, "q"));
  assert_null(group_array(m.state, 0, "density"));
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
  pm_test_write_file(*state, "gas-2d.yaml", GAS_2D, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  assert_int_equal(md->kinds, MPM_KIND_INTERNAL_ENERGY | MPM_KIND_ITERATES);
  assert_int_equal(md->n_groups, 1);
  const mpm_group *g = &md->group[0];
  assert_ptr_equal(g->kind, &mpm_kind_fluid);
  /* No F: density, energy, pressure and q. */
  assert_null(group_array(m.state, 0, "F"));
  const double *rho = group_array(m.state, 0, "density");
  const double *pressure = group_array(m.state, 0, "pressure");
  assert_non_null(rho);
  assert_non_null(group_array(m.state, 0, "energy"));
  assert_non_null(pressure);
  assert_non_null(group_array(m.state, 0, "q"));
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

/* ---- F-bar ----------------------------------------------------------------
 */

/* F-bar's state, workspace and stage line exist only when asked for; the
 * cell average is the volume-weighted mean of each cell's particles, the
 * patch average reproduces a constant, and Fbar has the averaged volume
 * ratio with the out-of-plane stretch of plane strain left alone. */
static void test_fbar(void **state) {
  (void)state;
  model m = make_model(MINIMAL, 0, NULL);
  assert_null(group_array(m.state, 0, "Jbar_minus_1"));
  assert_null(m.work->fbar.partial);
  assert_null(m.work->fbar.jm1);
  assert_int_equal(mpm_fbar_work_bytes(&m.work->fbar), 0);
  assert_null(strstr(find_stage(m.model, "stress: solid")->detail, "F-bar"));
  drop_model(&m);

  const char *cell = "mpm.fbar=cell", *patch = "mpm.fbar=patch";
  m = make_model(MINIMAL, 1, &cell);
  assert_non_null(group_array(m.state, 0, "Jbar_minus_1"));
  assert_non_null(m.work->fbar.cell);
  assert_null(m.work->fbar.qbar);
  assert_contains(find_stage(m.model, "stress: solid")->detail,
                  "F-bar: J averaged over each cell's particles");
  /* The particles' cells: each its own, the one its x lies in. */
  const mpm_grid *g = &m.model->grid;
  for (long p = 0; p < m.model->n; p++) {
    const double *x = m.state->x + 3 * p;
    long c = mpm_fbar_cell(g, x);
    double lo[2] = {g->origin[0] + (double)(c % g->stride[1]) * g->h,
                    g->origin[1] + (double)(c / g->stride[1]) * g->h};
    for (int k = 0; k < 2; k++)
      assert_true(x[k] >= lo[k] && x[k] < lo[k] + g->h);
  }
  /* Random J - 1 and volumes on random cells, one cell left empty. */
  mpm_fbar_work *fw = &m.work->fbar;
  const long n = m.model->n, ns = fw->n_slots;
  double *q = malloc(sizeof(double) * n), *v0 = malloc(sizeof(double) * n);
  long *cl = malloc(sizeof(long) * n);
  double *num = calloc(ns, sizeof(double)), *den = calloc(ns, sizeof(double));
  assert_true(q && v0 && cl && num && den);
  for (long p = 0; p < n; p++) {
    cl[p] = 1 + (long)(uniform() * (ns - 1)); /* never slot 0 */
    q[p] = 0.1 * (uniform() - 0.5);
    v0[p] = 0.5 + uniform();
    num[cl[p]] += v0[p] * q[p];
    den[cl[p]] += v0[p];
  }
  mpm_fbar_cell_average(fw, n, cl, q, v0, fw->mean);
  assert_true(fw->mean[0] == 0);
  for (long c = 1; c < ns; c++)
    assert_near(fw->mean[c], den[c] > 0 ? num[c] / den[c] : 0, 1e-15);
  drop_model(&m);

  m = make_model(MINIMAL, 1, &patch);
  fw = &m.work->fbar;
  assert_non_null(m.work->fbar.qbar);
  assert_null(m.work->fbar.cell);
  assert_contains(find_stage(m.model, "stress: solid")->detail,
                  "F-bar: J averaged over the nodes' patches");
  for (long p = 0; p < n; p++) q[p] = 0.0123;
  mpm_fbar_patch_average(fw, &m.model->grid, n, m.state->x, q, m.model->vol0,
                         fw->qbar);
  for (long p = 0; p < n; p++) assert_near(fw->qbar[p], 0.0123, 1e-16);
  drop_model(&m);
  free(q);
  free(v0);
  free(cl);
  free(num);
  free(den);

  /* Fbar: det = Jbar in 2-D (the 2 x 2 block scaled, F_33 = 1 kept) and in
   * 3-D. */
  const double F2[9] = {1.01, 0.02, 0, -0.015, 0.995, 0, 0, 0, 1};
  const double F3[9] = {1.01, 0.02,  0.003, -0.015, 0.995,
                        0.01, 0.004, -0.02, 1.007};
  const double jbm1 = -2.5e-3;
  double Fb[9];
  mpm_fbar_apply(2, pm_t_det(F2) - 1, jbm1, F2, Fb);
  assert_near(pm_t_det(Fb), 1 + jbm1, 1e-15);
  assert_true(Fb[8] == 1 && Fb[2] == 0 && Fb[5] == 0 && Fb[6] == 0);
  assert_near(Fb[1] / Fb[0], F2[1] / F2[0], 1e-15);
  mpm_fbar_apply(3, pm_t_det(F3) - 1, jbm1, F3, Fb);
  assert_near(pm_t_det(Fb), 1 + jbm1, 1e-15);
  assert_near(Fb[7] / Fb[8], F3[7] / F3[8], 1e-15);
  /* Jbar = J leaves F as it is. */
  mpm_fbar_apply(3, pm_t_det(F3) - 1, pm_t_det(F3) - 1, F3, Fb);
  for (int k = 0; k < 9; k++) assert_true(Fb[k] == F3[k]);
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
      cmocka_unit_test(test_fbar),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
