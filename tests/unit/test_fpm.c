/* Unit tests of the FPM operators: GFD weights reproduce linear fields,
 * homogeneous deformations are in discrete equilibrium (patch tests), and
 * the stable time step bounds the operator's spectrum. */
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
#include "fpm_static.h"
#include "gm_cells.h"
#include "gm_dual.h"
#include "gm_voronoi.h"
#include "pm_omp.h"
#include "pm_random.h"

typedef struct {
  gm_mesh *mesh;
  gm_dual *dual;
  pm_scene scene;
  fpm_options opt;
  pm_scene_material mat;
  pm_scene_body body;
  pm_scene_bc bcs[4];
} fixture;

static fixture *fixture_new(int dim, double h, double penalty, bool f2_bcs) {
  fixture *fx = calloc(1, sizeof *fx);
  double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
  assert_int_equal(gm_mesh_box(dim, lo, hi, h, &fx->mesh), PM_SUCCESS);
  assert_int_equal(gm_dual_build(fx->mesh, &fx->dual), PM_SUCCESS);
  assert_int_equal(
      pm_material_elastic(&fx->mat.mat, "neo-hookean", 1000, 3000, 0.495),
      PM_SUCCESS);
  fx->mat.name = "gel";
  pm_scene *s = &fx->scene;
  s->path = "test";
  s->dimension = dim;
  for (int c = 0; c < 3; c++) {
    s->box_min[c] = lo[c];
    s->box_max[c] = c < dim ? hi[c] : 0;
  }
  s->mesh_size = h;
  s->materials = &fx->mat;
  s->n_materials = 1;
  s->bodies = &fx->body; /* materials[0] over the whole domain */
  s->n_bodies = 1;
  fx->opt.penalty = penalty;
  s->time.ramp = 1;
  if (f2_bcs) {
    const char *val[4] = {"0", "0", "0", "-0.04"};
    pm_face face[4] = {PM_FACE_XMIN, PM_FACE_YMIN, PM_FACE_ZMIN, PM_FACE_ZMAX};
    int comp[4] = {0, 1, 2, 2};
    for (int b = 0; b < 4; b++) {
      fx->bcs[b].face = face[b];
      fx->bcs[b].surface = (char *)pm_face_name(face[b]);
      fx->bcs[b].disp_mask = 1u << comp[b];
      assert_int_equal(pm_expr_create(val[b], &fx->bcs[b].disp[comp[b]]),
                       PM_SUCCESS);
      fx->bcs[b].ramp = PM_RAMP_NONE;
    }
    s->bcs = fx->bcs;
    s->n_bcs = 4;
  }
  return fx;
}

static void fixture_free(fixture *fx) {
  for (int b = 0; b < 4; b++)
    for (int c = 0; c < 3; c++) pm_expr_destroy(fx->bcs[b].disp[c]);
  gm_dual_destroy(fx->dual);
  gm_mesh_destroy(fx->mesh);
  free(fx);
}

/* The model of the fixture's scene and a state for it. */
static void fixture_model(fixture *fx, fpm_model **m, fpm_state **st) {
  assert_int_equal(
      fpm_model_create(&fx->scene, &fx->opt, fx->mesh, fx->dual, m),
      PM_SUCCESS);
  assert_int_equal(fpm_state_create(*m, st), PM_SUCCESS);
}

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

/* The F2 gel in every solid model of the table, with the same small-strain
 * moduli (mu = 1003.3 Pa, K = 1e5 Pa); the fibred model gets one family
 * along x, so its lateral stretches differ. */
static void gel_model(const char *model, pm_scene_material *out,
                      pm_scene_body *body) {
  pm_material *m = &out->mat;
  body->point.n_fibres = 0;
  if (!strcmp(model, "neo-hookean") || !strcmp(model, "neo-hookean-log") ||
      !strcmp(model, "linear-elastic")) {
    assert_int_equal(pm_material_elastic(m, model, 1000, 3000, 0.495),
                     PM_SUCCESS);
    return;
  }
  assert_int_equal(pm_material_begin(m, model, 1000), PM_SUCCESS);
  assert_int_equal(pm_material_set(m, "bulk_modulus", 1e5), PM_SUCCESS);
  if (!strcmp(model, "mooney-rivlin")) {
    assert_int_equal(pm_material_set(m, "c10", 351.17), PM_SUCCESS);
    assert_int_equal(pm_material_set(m, "c01", 150.50), PM_SUCCESS);
  } else if (!strcmp(model, "ogden")) {
    const double mu[] = {1496, 2.85, -23.7}, alpha[] = {1.3, 5.0, -2.0};
    assert_int_equal(pm_material_set_list(m, "mu", 3, mu), PM_SUCCESS);
    assert_int_equal(pm_material_set_list(m, "alpha", 3, alpha), PM_SUCCESS);
  } else {
    assert_int_equal(pm_material_set(m, "shear_modulus", 1003.3), PM_SUCCESS);
    assert_int_equal(pm_material_set(m, "k1", 1000), PM_SUCCESS);
    assert_int_equal(pm_material_set(m, "k2", 2), PM_SUCCESS);
    assert_int_equal(pm_material_set(m, "dispersion", 0.1), PM_SUCCESS);
    body->point.n_fibres = 1;
    body->point.fibres[0][0] = 1;
  }
  assert_int_equal(pm_material_finish(m), PM_SUCCESS);
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
 * same with the quadratic jump) on the cells of variant `cells` (see
 * fixture_cells): the exact uniaxial-stress state (u_z = -0.4 z, lateral
 * stretches from P_xx = P_yy = 0) on every point, roller conditions on
 * three faces and the top displacement: zero force on every free dof,
 * boundary points included.  Round-off, whatever the model and the cells:
 * the discrete operator integrates any constant stress exactly. */
static void patch_f2(const char *model, int k, int cells) {
  double penalty = k == 0 ? 0 : k == 1 || k == 3 ? 20 : 100;
  fixture *fx = fixture_new(3, 0.02, penalty, true);
  fixture_cells(fx, cells, 400);
  gel_model(model, &fx->mat, &fx->body);
  if (k == 2 || k == 4) fx->opt.flux = FPM_FLUX_SIPG;
  if (k >= 3) fx->opt.jump = FPM_JUMP_QUADRATIC;
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
  print_message("F2 patch on %s, %s, %s %s jump, p = %g: %ld points, "
                "lateral stretches %.6f %.6f, max free |f| / (|P| h^2) = "
                "%.3g, top reaction %.6g N (exact %.6g N)\n",
                cell_names[cells], model,
                m->flux == FPM_FLUX_SIPG ? "SIPG" : "IIPG",
                m->jump == FPM_JUMP_QUADRATIC ? "quadratic" : "linear", penalty,
                m->n, lat[0], lat[1], worst / scale, R[2], Pzz * 0.01);
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
  fixture_free(fx);
}

static const char *const solid_models[] = {
    "neo-hookean", "neo-hookean-log",        "mooney-rivlin",
    "ogden",       "holzapfel-gasser-ogden", "linear-elastic"};

/* Every solid model of the table, every flux and jump, on median duals. */
static void test_patch_f2(void **state) {
  (void)state;
  for (int mi = 0; mi < 6; mi++)
    for (int k = 0; k < 5; k++) patch_f2(solid_models[mi], k, 0);
}

/* The same on Voronoi cells, of the mesh nodes and of random points. */
static void test_patch_f2_voronoi(void **state) {
  (void)state;
  for (int cells = 1; cells <= 2; cells++)
    for (int mi = 0; mi < 6; mi++)
      for (int k = 0; k < 5; k++) patch_f2(solid_models[mi], k, cells);
}

/* A smooth finite deformation u_a = smooth x_(a+1) x_a / 0.1 plus a rough
 * perturbation rough r (r uniform in [-1/2, 1/2], a fixed sequence from
 * seed), into u; d (may be NULL) receives r. */
static void smooth_plus_rough(const fpm_model *m, unsigned long long seed,
                              double smooth, double rough, double *u,
                              double *d) {
  for (long i = 0; i < 3 * m->n; i++) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    double r = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
    const double *x = m->x + 3 * (i / 3);
    u[i] = smooth * x[(i + 1) % 3] * x[i % 3] / 0.1 + rough * r;
    if (d) d[i] = r;
  }
}

static double stored_energy(const fpm_model *m, fpm_state *st) {
  assert_int_equal(fpm_force(m, st), -1);
  double e = st->penalty_energy;
  for (long i = 0; i < m->n; i++) e += m->dual->volume[i] * st->W[i];
  return e;
}

/* With the symmetric flux the force is the gradient of the stored energy
 * sum V W - sum_e {P} : K_e + 1/2 sum_e beta |e| [[u]]^2: its derivative
 * along a random direction, by central differences, equals f . d (relative
 * 1e-6).  The incomplete flux is not a gradient: its mismatch is printed. */
static void test_sipg_is_gradient(void **state) {
  (void)state;
  for (int k = 0; k < 3; k++) {
    fixture *fx = fixture_new(3, 0.03, 100, false);
    fx->opt.flux = k == 1 ? FPM_FLUX_IIPG : FPM_FLUX_SIPG;
    fx->opt.jump = k == 2 ? FPM_JUMP_QUADRATIC : FPM_JUMP_LINEAR;
    fpm_model *m;
    fpm_state *st;
    fixture_model(fx, &m, &st);
    long nd = 3 * m->n;
    double *u0 = calloc(nd, sizeof *u0), *d = calloc(nd, sizeof *d);
    smooth_plus_rough(m, 12345, 0.1, 2e-4, u0, d);
    memcpy(st->u, u0, nd * sizeof *u0);
    stored_energy(m, st);
    double fd = 0;
    for (long i = 0; i < nd; i++) fd += st->f[i] * d[i];
    double eps = 1e-7, ep, em;
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] + eps * d[i];
    ep = stored_energy(m, st);
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] - eps * d[i];
    em = stored_energy(m, st);
    double dE = (ep - em) / (2 * eps);
    double rel = fabs(dE - fd) / fabs(fd);
    print_message("%s: dE/de = %.10g, f . d = %.10g, relative mismatch %.3g\n",
                  k == 0   ? "SIPG"
                  : k == 1 ? "IIPG"
                           : "SIPG, quadratic jump",
                  dE, fd, rel);
    if (k != 1) assert_true(rel <= 1e-6);
    free(u0);
    free(d);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* The F2 cube at mesh size h, p = 20, with the flux and jump of variant k
 * (bit 0: SIPG, bit 1: quadratic jump): its model and state. */
static fixture *variant(double h, int k, fpm_model **m, fpm_state **st) {
  fixture *fx = fixture_new(3, h, 20, true);
  fx->opt.flux = k & 1 ? FPM_FLUX_SIPG : FPM_FLUX_IIPG;
  fx->opt.jump = k & 2 ? FPM_JUMP_QUADRATIC : FPM_JUMP_LINEAR;
  fixture_model(fx, m, st);
  return fx;
}

/* fpm_force_linear is the derivative of fpm_force: K d against central
 * differences of f along a random d at a finite deformation, for both
 * fluxes and both jumps (relative 1e-6 of |K d|). */
static void test_force_linearisation(void **state) {
  (void)state;
  for (int k = 0; k < 4; k++) {
    fpm_model *m;
    fpm_state *st;
    fpm_linear *lin;
    fixture *fx = variant(0.03, k, &m, &st);
    assert_int_equal(fpm_linear_create(m, &lin), PM_SUCCESS);
    long nd = 3 * m->n;
    double *u0 = calloc(nd, sizeof *u0), *d = calloc(nd, sizeof *d),
           *kd = calloc(nd, sizeof *kd), *fp = calloc(nd, sizeof *fp);
    smooth_plus_rough(m, 777, 0.2, 1e-3, u0, d);
    memcpy(st->u, u0, nd * sizeof *u0);
    assert_int_equal(fpm_force(m, st), -1);
    fpm_linear_prepare(m, st, lin);
    fpm_force_linear(m, lin, d, kd);
    double eps = 1e-6;
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] + eps * d[i];
    assert_int_equal(fpm_force(m, st), -1);
    memcpy(fp, st->f, nd * sizeof *fp);
    for (long i = 0; i < nd; i++) st->u[i] = u0[i] - eps * d[i];
    assert_int_equal(fpm_force(m, st), -1);
    double err = 0, norm = 0;
    for (long i = 0; i < nd; i++) {
      double fd = (fp[i] - st->f[i]) / (2 * eps);
      err += (fd - kd[i]) * (fd - kd[i]);
      norm += kd[i] * kd[i];
    }
    print_message("%s, %s jump: |K d - central difference| / |K d| = %.3g\n",
                  k & 1 ? "SIPG" : "IIPG", k & 2 ? "quadratic" : "linear",
                  sqrt(err / norm));
    assert_true(sqrt(err / norm) <= 1e-6);
    free(u0);
    free(d);
    free(kd);
    free(fp);
    fpm_linear_destroy(lin);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
}

/* The tangent the static solver assembles directly equals the one coloured
 * from fpm_force_linear and central differences of the force, for both
 * jumps (IIPG: exact; SIPG: the adjoint term's derivative is left out of
 * the assembled one, so only its distance is printed). */
static void test_static_tangent(void **state) {
  (void)state;
  for (int k = 0; k < 4; k++) {
    fpm_model *m;
    fpm_state *st;
    fixture *fx = variant(0.04, k, &m, &st);
    long nd = 3 * m->n;
    double *u = calloc(nd, sizeof *u);
    smooth_plus_rough(m, 99, 0.2, 1e-3, u, NULL);
    double ea, ed;
    assert_int_equal(fpm_static_check_tangent(m, st, u, &ea, &ed), PM_SUCCESS);
    print_message("%s, %s jump: assembled tangent against coloured %.3g, "
                  "against differences %.3g\n",
                  k & 1 ? "SIPG" : "IIPG", k & 2 ? "quadratic" : "linear", ea,
                  ed);
    if (!(k & 1)) {
      assert_true(ea <= 1e-10);
      assert_true(ed <= 1e-6);
    }
    free(u);
    fpm_state_destroy(st);
    fpm_model_destroy(m);
    fixture_free(fx);
  }
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
      assert_int_equal(fpm_partition(m, parts, owner), PM_SUCCESS);
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
        for (long i = 0; i < s->n_own; i++) {
          const long g = s->gid[i];
          assert_memory_equal(ss->f + 3 * i, st->f + 3 * g, 3 * sizeof(double));
          assert_memory_equal(ss->P + 9 * i, st->P + 9 * g, 9 * sizeof(double));
          assert_memory_equal(ss->J + i, st->J + g, sizeof(double));
        }
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
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_meshing_keeps_threads),
      cmocka_unit_test(test_gfd_linear),
      cmocka_unit_test(test_gfd_ill_conditioned),
      cmocka_unit_test(test_homogeneous_p0),
      cmocka_unit_test(test_homogeneous_p20),
      cmocka_unit_test(test_patch_f2),
      cmocka_unit_test(test_patch_f2_voronoi),
      cmocka_unit_test(test_sipg_is_gradient),
      cmocka_unit_test(test_force_linearisation),
      cmocka_unit_test(test_static_tangent),
      cmocka_unit_test(test_deformed_condition),
      cmocka_unit_test(test_shares),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
