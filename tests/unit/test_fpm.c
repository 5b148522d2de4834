/* Unit tests of the FPM operators: GFD weights reproduce linear fields,
 * homogeneous deformations are in discrete equilibrium (patch tests),
 * supports stay conditioned, and a rank's share computes its force as the
 * whole model does. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_gfd.h"
#include "fpm_model.h"
#include "fpm_share.h"
#include "fpm_solver.h"
#include "fpm_testing.h"
#include "gm_cells.h"
#include "gm_dual.h"
#include "gm_voronoi.h"
#include "pm_omp.h"
#include "pm_random.h"
#include "gmsh_testing.h"

/* u = H X + c for a fixed H: the GFD gradient equals H at every point. */
static void test_gfd_linear(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; dim++) {
    fixture *fx = fixture_new(dim, dim == 3 ? 0.025 : 0.01, 0, false);
    fpm_model *m;
    fpm_state *st;
    fixture_model(fx, &m, &st);
    double H[9] = {0.3, -0.2, 0.1, 0.05, -0.4, 0.2, -0.1, 0.15, 0.25};
    if (dim == 2) H[2] = H[5] = H[6] = H[7] = H[8] = 0;
    for (long i = 0; i < m->n; i++)
      for (int a = 0; a < 3; a++)
        st->u[3 * i + a] = 0.01 * (a + 1) + H[3 * a] * m->x[3 * i] +
                           H[3 * a + 1] * m->x[3 * i + 1] +
                           H[3 * a + 2] * m->x[3 * i + 2];
    assert_int_equal(fpm_force(m, st), -1);
    double err = 0;
    for (long i = 0; i < m->n; i++)
      for (int a = 0; a < 9; a++)
        err = fmax(err, fabs(st->H[9 * i + a] - H[a]));
    print_message("dim %d: %ld points, max |grad u - H| = %.3g\n", dim, m->n,
                  err);
    assert_true(err < 1e-12);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* A homogeneous deformation leaves zero force at every interior point.
 * Points on the boundary and their neighbours carry the traction P n of
 * the free faces (the test functions of the neighbours reach the boundary
 * facets), so "interior" means neither. */
static void check_homogeneous(double penalty) {
  const double h = 0.0125;
  fixture *fx = fixture_new(3, h, penalty, false);
  fpm_model *m;
  fpm_state *st;
  fixture_model(fx, &m, &st);
  double H[9] = {0.3, -0.2, 0.1, 0.05, -0.4, 0.2, -0.1, 0.15, 0.25};
  for (long i = 0; i < m->n; i++)
    for (int a = 0; a < 3; a++)
      st->u[3 * i + a] = H[3 * a] * m->x[3 * i] +
                         H[3 * a + 1] * m->x[3 * i + 1] +
                         H[3 * a + 2] * m->x[3 * i + 2];
  assert_int_equal(fpm_force(m, st), -1);
  /* boundary points: those with a facet */
  unsigned char *on_boundary = calloc(m->n, 1);
  for (long f = 0; f < fx->dual->n_facets; f++)
    on_boundary[fx->dual->facet_point[f]] = 1;
  for (long i = 0; i < m->n; i++)
    if (on_boundary[i] == 1)
      for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
        if (!on_boundary[m->nbr[e]]) on_boundary[m->nbr[e]] = 2;
  double scale = pm_t_norm(st->P) * h * h, worst = 0;
  long interior = 0;
  for (long i = 0; i < m->n; i++) {
    if (on_boundary[i]) continue;
    interior++;
    for (int a = 0; a < 3; a++) worst = fmax(worst, fabs(st->f[3 * i + a]));
  }
  print_message("p = %g: %ld interior points, max |f| / (|P| h^2) = %.3g\n",
                penalty, interior, worst / scale);
  assert_true(interior > 0);
  assert_true(worst <= 1e-11 * scale);
  free(on_boundary);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
  fixture_free(fx);
}

static void test_homogeneous_p0(void **state) {
  (void)state;
  check_homogeneous(0);
}
static void test_homogeneous_p20(void **state) {
  (void)state;
  check_homogeneous(20);
}

/* The cells of variant `cells` in place of the fixture's median duals:
 * 1 the Voronoi cells of its mesh nodes (the "voronoi" builder), 2 those
 * of n seeded random points in the box (no point on the boundary: the
 * facets belong to points inside).  The mesh still names the box faces. */
static void fixture_cells(fixture *fx, int cells, long n) {
  if (cells == 0) return;
  gm_dual_destroy(fx->dual);
  fx->dual = NULL;
  if (cells == 1) {
    assert_int_equal(gm_cells_find("voronoi")->build(fx->mesh, &fx->dual),
                     PM_SUCCESS);
    return;
  }
  double *x = calloc(3 * (size_t)n, sizeof *x);
  pm_random r = pm_random_seed(2024);
  for (long i = 0; i < 3 * n; i++)
    x[i] = i % 3 < fx->mesh->dim ? 0.1 * pm_random_uniform(&r) : 0;
  assert_int_equal(gm_voronoi_build(fx->mesh->dim, n, x, fx->mesh->box_min,
                                    fx->mesh->box_max, NULL, &fx->dual),
                   PM_SUCCESS);
  free(x);
}

/* The finite-strain patch test of case F2 for one solid model, flux and
 * jump variant k (0: p = 0; 1: IIPG p = 20; 2: SIPG p = 100; 3, 4: the
 * same with the quadratic jump; 5: the default formulation, with its
 * boundary penalty) on the cells of variant `cells` (see
 * fixture_cells): the exact uniaxial-stress state (u_z = -0.4 z, lateral
 * stretches from P_xx = P_yy = 0) on every point, roller conditions on
 * three faces and the top displacement: zero force on every free dof,
 * boundary points included.  Round-off, whatever the model and the cells:
 * the discrete operator integrates any constant stress exactly. */
static void patch_f2(fixture *fx, const char *model, int k, int cells) {
  double penalty = k == 0 ? 0 : k == 1 || k == 3 ? 20 : 100;
  memset(&fx->opt, 0, sizeof fx->opt);
  fx->opt.penalty = penalty;
  gel_model(model, &fx->mat, &fx->body);
  if (k == 2 || k == 4) fx->opt.flux = FPM_FLUX_SIPG;
  if (k >= 3) fx->opt.jump = FPM_JUMP_QUADRATIC;
  if (k == 5) fixture_defaults(fx);
  penalty = fmax(fx->opt.penalty, fx->opt.boundary_penalty);
  fpm_model *m;
  fpm_state *st;
  fixture_model(fx, &m, &st);
  double lat[2];
  assert_int_equal(pm_material_uniaxial(&m->mats[0], m->mstate, 0.6, lat),
                   PM_SUCCESS);
  for (long i = 0; i < m->n; i++) {
    st->u[3 * i] = (lat[0] - 1) * m->x[3 * i];
    st->u[3 * i + 1] = (lat[1] - 1) * m->x[3 * i + 1];
    st->u[3 * i + 2] = -0.4 * m->x[3 * i + 2];
  }
  assert_int_equal(fpm_force(m, st), -1);
  double scale = fabs(st->P[8]) * 0.02 * 0.02, worst = 0;
  for (long i = 0; i < 3 * m->n; i++)
    if (!m->fixed[i]) worst = fmax(worst, fabs(st->f[i]));
  /* The support's force on the top face is the uniaxial force P_zz L^2;
   * the lateral roller faces carry none. */
  double R[3], Pzz = st->P[8];
  fpm_reaction(m, st, 3, R);
  static const char *const cell_names[] = {"median duals", "Voronoi cells",
                                           "Voronoi cells of random points"};
  print_message("F2 patch on %s, %s, %s %s jump, p = %g (p_b %g): %ld points, "
                "lateral stretches %.6f %.6f, max free |f| / (|P| h^2) = "
                "%.3g, top reaction %.6g N (exact %.6g N)\n",
                cell_names[cells], model,
                m->flux == FPM_FLUX_SIPG ? "SIPG" : "IIPG",
                m->jump == FPM_JUMP_QUADRATIC ? "quadratic" : "linear",
                m->penalty, m->boundary_penalty, m->n, lat[0], lat[1],
                worst / scale, R[2], Pzz * 0.01);
  /* Round-off: the penalty's terms are p times the stress's and cancel
   * to zero, so the residual is some 1000 machine epsilons of (1 + p)
   * |P| h^2 (the worst measured: 1.02e-11 at p = 100 on an AMD EPYC,
   * against 2.2e-11; 5e-14 at p = 0 against 2.2e-13). */
  assert_true(worst <= 1000 * DBL_EPSILON * (1 + penalty) * scale);
  assert_true(fabs(R[2] - Pzz * 0.01) <= 1e-10 * fabs(Pzz * 0.01));
  fpm_reaction(m, st, 0, R);
  assert_true(fabs(R[0]) <= 1e-10 * fabs(Pzz * 0.01));
  fpm_state_destroy(st);
  fpm_model_destroy(m);
}

static const char *const solid_models[] = {
    "neo-hookean", "neo-hookean-log",        "mooney-rivlin",
    "ogden",       "holzapfel-gasser-ogden", "linear-elastic"};

/* Every solid model, flux and jump on one cloud and its cells of variant
 * `cells`: the mesh and the cells are built once (they depend on neither;
 * each combination gets its options afresh). */
static void patch_f2_all(int cells) {
  fixture *fx = fixture_new(3, 0.02, 0, true);
  fixture_cells(fx, cells, 400);
  for (int mi = 0; mi < 6; mi++)
    for (int k = 0; k < 6; k++) patch_f2(fx, solid_models[mi], k, cells);
  fixture_free(fx);
}

/* Every solid model of the table, every flux and jump, on median duals. */
static void test_patch_f2(void **state) {
  (void)state;
  patch_f2_all(0);
}

/* The same on Voronoi cells, of the mesh nodes and of random points. */
static void test_patch_f2_voronoi(void **state) {
  (void)state;
  for (int cells = 1; cells <= 2; cells++) patch_f2_all(cells);
}

/* Supports in the deformed configuration: none is ill-conditioned at rest;
 * a flattening to 1e-6 of the height makes every support so. */
static void test_deformed_condition(void **state) {
  (void)state;
  fixture *fx = fixture_new(3, 0.04, 20, false);
  fpm_model *m;
  assert_int_equal(
      fpm_model_create(&fx->scene, &fx->opt, fx->mesh, fx->dual, &m),
      PM_SUCCESS);
  double *u = calloc(3 * m->n, sizeof *u), worst;
  long wp;
  assert_int_equal(fpm_gfd_deformed_condition(m->dim, m->n, m->x, u, m->nbr_ptr,
                                              fx->dual->nbr, FPM_COND_MAX,
                                              &worst, &wp),
                   0);
  assert_true(worst < 1e3 && wp >= 0);
  for (long i = 0; i < m->n; i++) u[3 * i + 2] = (1e-6 - 1) * m->x[3 * i + 2];
  assert_int_equal(fpm_gfd_deformed_condition(m->dim, m->n, m->x, u, m->nbr_ptr,
                                              fx->dual->nbr, FPM_COND_MAX,
                                              &worst, &wp),
                   m->n);
  free(u);
  fpm_model_destroy(m);
  fixture_free(fx);
}

/* A part mirrored about a symmetry plane (x = 0 here, the part at x >=
 * 0): a state with a point past the plane (its surface folded through it,
 * into the mirrored part) is found and named with the plane; points on
 * the plane, sliding along it, and a scene without planes are not. */
static void test_symmetry_crossed(void **state) {
  (void)state;
  fixture *fx = fixture_new(3, 0.04, 20, true);
  fpm_model *m;
  fpm_state *st;
  fixture_model(fx, &m, &st);
  int axis = 7;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), -1);
  assert_int_equal(axis, -1);
  fx->scene.mirror_mask = 1u;
  fx->scene.mirror_at[0] = 0;
  /* at rest, and every point on the plane moved along it */
  for (long i = 0; i < m->n; i++)
    if (m->x[3 * i] == 0) st->u[3 * i + 1] = 0.03;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), -1);
  /* the two innermost points off the plane pushed past it */
  long inner[2] = {-1, -1};
  for (long i = 0; i < m->n; i++)
    if (m->x[3 * i] > 0 && m->x[3 * i + 1] > 0 && m->x[3 * i + 2] > 0) {
      if (inner[0] < 0 || m->x[3 * i] < m->x[3 * inner[0]]) {
        inner[1] = inner[0];
        inner[0] = i;
      } else if (inner[1] < 0 || m->x[3 * i] < m->x[3 * inner[1]]) {
        inner[1] = i;
      }
    }
  const long first = inner[0] < inner[1] ? inner[0] : inner[1];
  for (int k = 0; k < 2; k++) st->u[3 * inner[k]] = -m->x[3 * inner[k]] - 1e-3;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), first);
  assert_int_equal(axis, 0);
  assert_int_equal(fpm_symmetry_failure(m, st, first, axis, "step 3: "),
                   PM_ERR_UNSTABLE);
  const char *msg = pm_error_message();
  print_message("%s\n", msg);
  char want[64];
  snprintf(want, sizeof want, "step 3: point %ld at (", first);
  assert_non_null(strstr(msg, want));
  assert_non_null(strstr(msg, "passed the symmetry plane x = 0 (now at x = "
                              "-0.001)"));
  pm_error_clear();
  /* a plane at x = 0.1, the part on its other side (x <= 0.1): those
   * points are on the part's side, and a point of the face x = 0.1 moved
   * out past it is the one named */
  fx->scene.mirror_at[0] = 0.1;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), -1);
  long out = -1;
  for (long i = 0; i < m->n && out < 0; i++)
    if (m->x[3 * i] == 0.1) out = i;
  st->u[3 * out] = 1e-3;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), out);
  fx->scene.mirror_mask = 0;
  assert_int_equal(fpm_symmetry_crossed(m, st, &axis), -1);
  fpm_state_destroy(st);
  fpm_model_destroy(m);
  fixture_free(fx);
}

/* A support that does not span 3D (all neighbours in one plane) is
 * reported with the point's id and position. */
static void test_gfd_ill_conditioned(void **state) {
  (void)state;
  const double x[] = {0.5, 0.5, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const long ptr[] = {0, 4, 5, 6, 7, 8};
  const long nbr[] = {1, 2, 3, 4, 0, 0, 0, 0};
  double g[3 * 8], cond[5];
  pm_error_clear();
  assert_int_equal(fpm_gfd_weights(3, 5, x, ptr, nbr, 1e8, g, cond),
                   PM_ERR_GEOMETRY);
  print_message("%s\n", pm_error_message());
  assert_non_null(strstr(pm_error_message(), "point 0 at (0.5, 0.5, 0)"));
  assert_non_null(strstr(pm_error_message(), "condition number"));
}

/* gmsh sets the OpenMP thread count process-wide; meshing must leave the
 * caller's setting as it was (it once silently serialized every run). */
/* A rank's share computes the force on its own points as the whole model
 * does, bit for bit, from the displacements of the points it holds (those
 * the exchange brings); every point is owned by exactly one rank, a share's
 * own points come first in one-process order, and an inadmissible point
 * is reported by its owner alone.  Linear and quadratic jumps, IIPG and
 * SIPG, on 2 and 3 ranks. */
static void test_shares(void **state) {
  (void)state;
  const int flux[3] = {FPM_FLUX_IIPG, FPM_FLUX_SIPG, FPM_FLUX_IIPG};
  const int jump[3] = {FPM_JUMP_LINEAR, FPM_JUMP_LINEAR, FPM_JUMP_QUADRATIC};
  for (int k = 0; k < 3; k++) {
    fixture *fx = fixture_new(3, 0.02, 20, true);
    fx->opt.flux = flux[k];
    fx->opt.jump = jump[k];
    fpm_model *m;
    fpm_state *st;
    fixture_model(fx, &m, &st);
    smooth_plus_rough(m, 7 + k, 0.05, 1e-4, st->u, NULL);
    double *moved = malloc(sizeof(double) * 3 * m->n);
    memcpy(moved, st->u, sizeof(double) * 3 * m->n);
    for (int a = 0; a < 3; a++) st->u[3 * (m->n / 2) + a] += 0.05;
    const long inverted = fpm_force(m, st);
    assert_true(inverted >= 0);
    memcpy(st->u, moved, sizeof(double) * 3 * m->n);
    free(moved);
    assert_int_equal(fpm_force(m, st), -1);
    int *owner = malloc(sizeof(int) * m->n), *owned = calloc(m->n, sizeof(int));
    for (int parts = 2; parts <= 3; parts++) {
      assert_int_equal(fpm_partition(m->dual, parts, owner), PM_SUCCESS);
      memset(owned, 0, sizeof(int) * m->n);
      long ghosts = 0, first = m->n;
      for (int r = 0; r < parts; r++) {
        fpm_model *s;
        fpm_state *ss;
        assert_int_equal(fpm_share_create(m, owner, r, &s), PM_SUCCESS);
        assert_int_equal(fpm_state_create(s, &ss), PM_SUCCESS);
        assert_true(s->n_own > 0 && s->n_own <= s->n_flux &&
                    s->n_flux <= s->n_stress && s->n_stress <= s->n);
        for (long i = 0; i < s->n; i++) {
          const long g = s->gid[i];
          assert_int_equal(owner[g] == r, i < s->n_own);
          if (i < s->n_own) owned[g]++;
          if (i > 0 && i != s->n_own && i != s->n_flux && i != s->n_stress)
            assert_true(s->gid[i - 1] < g);
          memcpy(ss->u + 3 * i, st->u + 3 * g, 3 * sizeof(double));
        }
        ghosts += s->n - s->n_own;
        assert_int_equal(fpm_force(s, ss), -1);
        assert_share_is_whole(s, ss, st);
        /* A point moved far: the points it turns inside out are named by
         * their owners alone, by their indices on one process, and the
         * smallest is the one the whole model names. */
        for (long i = 0; i < s->n; i++)
          if (s->gid[i] == m->n / 2)
            for (int a = 0; a < 3; a++) ss->u[3 * i + a] += 0.05;
        const long found = fpm_force(s, ss);
        if (found >= 0) {
          assert_true(found < s->n_own && ss->J[found] <= 0);
          first = s->gid[found] < first ? s->gid[found] : first;
        }
        fpm_state_destroy(ss);
        fpm_model_destroy(s);
      }
      for (long i = 0; i < m->n; i++) assert_int_equal(owned[i], 1);
      assert_int_equal(first, inverted);
      print_message("%s %s, %d ranks: %ld points, %ld ghosts, %ld pairs "
                    "cut: forces on own points as one process's\n",
                    flux[k] == FPM_FLUX_SIPG ? "SIPG" : "IIPG",
                    jump[k] == FPM_JUMP_QUADRATIC ? "quadratic" : "linear",
                    parts, m->n, ghosts, fpm_partition_edge_cut(m, owner));
    }
    free(owner);
    free(owned);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

static void test_meshing_keeps_threads(void **state) {
  (void)state;
  pm_omp_set_threads(2);
  fixture *fx = fixture_new(3, 0.05, 0, false);
  assert_int_equal(pm_omp_threads(), PM_OMP_AVAILABLE ? 2 : 1);
  fixture_free(fx);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_meshing_keeps_threads),
      cmocka_unit_test(test_gfd_linear),
      cmocka_unit_test(test_gfd_ill_conditioned),
      cmocka_unit_test(test_homogeneous_p0),
      cmocka_unit_test(test_homogeneous_p20),
      cmocka_unit_test(test_patch_f2),
      cmocka_unit_test(test_patch_f2_voronoi),
      cmocka_unit_test(test_deformed_condition),
      cmocka_unit_test(test_symmetry_crossed),
      cmocka_unit_test(test_shares),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
