/* Verification of the implicit MPM (method mpm-implicit):
 *   - its tangent against central differences of its residual (assembled
 *     and matrix-free; 2D and 3D; linear and quadratic B-splines; grid
 *     kept and reset, the latter on a deformed base);
 *   - Newton's quadratic convergence on a sheared block;
 *   - case F2 against its exact homogeneous state, with the grid kept,
 *     linear and quadratic B-splines, with and without F-bar;
 *   - the same quasi-static block by the implicit and the explicit MPM. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mpm_implicit.h"
#include "mpm_verify.h"
#include "pm_scene.h"

#define F2 PM_SOURCE_DIR "/cases/mpm/f2-unconstrained-compression.yaml"

/* A block [0, 1]^d of a Simo-Hughes neo-Hookean solid (nu 0.3), clamped
 * at ymin and moved at ymax by (0.05, -0.1(, 0.02)): inhomogeneous. */
static pm_scene *block_scene(int dim, const char *shape, const char *grid,
                             int cells, int steps, const char *fbar) {
  char text[2048];
  snprintf(text, sizeof text,
           "name: block\nmethod: mpm-implicit\ndimension: %d\n"
           "domain: {box: {min: [0, 0%s], max: [1, 1%s]}}\n"
           "discretization: {mesh_size: %.17g}\n"
           "materials: [{name: m, model: neo-hookean-log, density: 1, "
           "youngs_modulus: 1000, poisson_ratio: 0.3}]\n"
           "bodies: [{material: m, region: domain}]\n"
           "boundary:\n"
           "  - {on: ymin, displacement: {x: 0, y: 0%s}}\n"
           "  - {on: ymax, displacement: {x: 0.05, y: -0.1%s}}\n"
           "mpm: {shape: %s, particles_per_cell: [2], fbar: %s, implicit: "
           "{grid: %s}}\n"
           "time: {end: 1, ramp: 1, quasi_static: {load_steps: %d, "
           "tolerance: 1e-12, max_iterations: 30, linear_solver: direct}}\n",
           dim, dim == 3 ? ", 0" : "", dim == 3 ? ", 1" : "", 1.0 / cells,
           dim == 3 ? ", z: 0" : "", dim == 3 ? ", z: 0.02" : "", shape, fbar,
           grid, steps);
  pm_scene *s = NULL;
  if (pm_app_init() != PM_SUCCESS) fail_msg("%s", pm_error_message());
  if (pm_scene_load_text(text, strlen(text), "block.yaml", 0, NULL, &s) !=
      PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return s;
}

static mpm_sim *implicit_sim(const pm_scene *s) {
  void *sim = NULL;
  if (mpm_implicit_backend.create(s, &sim) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return sim;
}

/* Central differences agree with the tangent to about the differences'
 * own error, h^2 |r'''| ~ 1e-9 relative: bound 1e-6. */
static void check_tangent(int dim, const char *shape, const char *grid,
                          const char *fbar) {
  /* reset: the stencils of the face layers take two node planes each */
  const bool reset = strcmp(grid, "reset") == 0;
  pm_scene *s = block_scene(dim, shape, grid,
                            reset      ? 6
                            : dim == 3 ? 3
                                       : 4,
                            2, fbar);
  mpm_sim *r = implicit_sim(s);
  if (reset) {
    /* a deformed base: run the first two load steps */
    if (mpm_implicit_run(r->imp, NULL, NULL) != PM_SUCCESS)
      fail_msg("%s", pm_error_message());
  }
  double ea, em;
  if (mpm_implicit_check_tangent(r->imp, 0.5, 0.02, &ea, &em) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  long unk, nz;
  mpm_implicit_size(r->imp, &unk, &nz);
  print_message("tangent %dD %-9s grid %-5s F-bar %-4s: %4ld unknowns, "
                "assembled %.2e, matrix-free %.2e (bound 1e-6)\n",
                dim, shape, grid, fbar, unk, ea, em);
  assert_true(ea < 1e-6);
  assert_true(em < 1e-6);
  mpm_implicit_backend.destroy(r);
  pm_scene_destroy(s);
}

static void test_tangent(void **state) {
  (void)state;
  check_tangent(2, "linear", "kept", "none");
  check_tangent(2, "quadratic", "kept", "none");
  check_tangent(3, "linear", "kept", "none");
  check_tangent(2, "linear", "reset", "none");
  check_tangent(3, "linear", "reset", "none");
  check_tangent(2, "linear", "kept", "cell");
  check_tangent(3, "linear", "kept", "cell");
  check_tangent(2, "linear", "reset", "cell");
  check_tangent(2, "quadratic", "kept", "cell");
  check_tangent(3, "quadratic", "kept", "cell");
}

/* The residual norms of the single load step's Newton solve. */
typedef struct {
  int n;
  double r[64];
} history;

static pm_err keep_history(void *ctx, const mpm_implicit_step *st) {
  history *h = ctx;
  h->n = st->report->iterations + 1;
  for (int k = 0; k < h->n && k < 64; k++)
    h->r[k] = st->report->residual_norm[k];
  return PM_SUCCESS;
}

/* Newton's order: log(r_k+1 / r_k) / log(r_k / r_k-1) over the iterations
 * above roundoff tends to 2. */
static void test_quadratic(void **state) {
  (void)state;
  pm_scene *s = block_scene(2, "linear", "kept", 8, 1, "none");
  mpm_sim *r = implicit_sim(s);
  history h = {0};
  if (mpm_implicit_run(r->imp, keep_history, &h) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  double order = 0;
  int used = 0;
  print_message("Newton on the sheared block (one load step):");
  for (int k = 0; k < h.n; k++) print_message(" %.3e", h.r[k]);
  print_message("\n");
  for (int k = 1; k + 1 < h.n; k++) {
    /* above roundoff: 1e-12 of the first residual */
    if (h.r[k + 1] < 1e-11 * h.r[0]) break;
    order = log(h.r[k + 1] / h.r[k]) / log(h.r[k] / h.r[k - 1]);
    used++;
  }
  print_message("observed order %.2f over the last pair above roundoff "
                "(bound 1.8)\n",
                order);
  assert_true(h.n >= 4); /* a problem Newton needs iterations for */
  assert_true(used >= 1);
  assert_true(order > 1.8);
  mpm_implicit_backend.destroy(r);
  pm_scene_destroy(s);
}

/* F2 with the grid kept, by set (shape, cell, F-bar): the exact state
 * u_z = -0.4 z and the exact reaction, to the Newton tolerance (bound
 * 1e-6).  With quadratic B-splines the conditions extend the field
 * beyond the faces (odd for a prescribed component, even for the ones a
 * roller leaves free), so the homogeneous state is the discrete solution;
 * setting the nodes beyond a face to its value left 3.1e-2 at 0.02 m. */
static void check_f2(const char *shape, const char *cell, const char *fbar) {
  char s_shape[64], s_cell[64], s_fbar[64];
  snprintf(s_shape, sizeof s_shape, "mpm.shape=%s", shape);
  snprintf(s_cell, sizeof s_cell, "discretization.mesh_size=%s", cell);
  snprintf(s_fbar, sizeof s_fbar, "mpm.fbar=%s", fbar);
  const char *sets[] = {"method=mpm-implicit", s_shape,
                        "time.quasi_static.tolerance=1e-10", s_cell, s_fbar};
  pm_scene *s = load_scene(F2, 5, sets);
  mpm_sim *r = implicit_sim(s);
  pm_outcome out;
  if (pm_run_sim(s, r, NULL, true, &out) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  assert_int_equal(out.fig.status, PM_STATUS_CONVERGED);
  const pm_material *mat = &s->materials[0].mat;
  double lateral[2], P[9];
  assert_int_equal(pm_material_uniaxial(mat, NULL, 0.6, lateral), PM_SUCCESS);
  double F[9] = {lateral[0], 0, 0, 0, lateral[0], 0, 0, 0, 0.6};
  assert_true(pm_material_stress(mat, F, NULL, P, NULL, NULL));
  const double exact = P[8] * 0.01, R = out.fig.reaction[3][2];
  const pm_load_report *lr = mpm_implicit_report(r->imp);
  print_message("F2 by implicit MPM (grid kept, %s, cell %s m, F-bar %s): "
                "%ld particles, %d load steps (%d cuts), %d Newton and %d "
                "linear iterations, %.2f s; NRMSE u_z %.3e (bound 1e-6); "
                "reaction %.6f N (exact %.6f N, %.2e, bound 1e-6)\n",
                shape, cell, fbar, r->model->n, lr->steps, lr->cuts,
                lr->newton_iterations, lr->linear_iterations,
                out.fig.wall_seconds, out.nrmse_vector, -R, -exact,
                fabs(R / exact - 1));
  assert_true(out.nrmse_vector < 1e-6);
  assert_true(fabs(R / exact - 1) < 1e-6);
  mpm_implicit_backend.destroy(r);
  pm_scene_destroy(s);
}

static void test_f2(void **state) {
  (void)state;
  check_f2("linear", "0.01", "none");
  check_f2("quadratic", "0.02", "cell"); /* F-bar: the default at nu 0.495 */
}

/* A plane-strain block [0, 1]^2 clamped at ymin and ymax, its top moved
 * down by 1e-5 (a barrel: the field is not homogeneous), by method. */
static pm_scene *barrel_scene(const char *method, double tol) {
  char text[2048];
  snprintf(text, sizeof text,
           "name: barrel\nmethod: %s\ndimension: 2\n"
           "domain: {box: {min: [0, 0], max: [1, 1]}}\n"
           "discretization: {mesh_size: 0.125}\n"
           "materials: [{name: m, model: neo-hookean-log, density: 1000, "
           "youngs_modulus: 1000, poisson_ratio: 0.3}]\n"
           "bodies: [{material: m, region: domain}]\n"
           "boundary:\n"
           "  - {on: ymin, displacement: {x: 0, y: 0}}\n"
           "  - {on: ymax, displacement: {x: 0, y: -1e-5}}\n"
           "mpm: {shape: linear, particles_per_cell: [2]}\n"
           "time: {end: 400, ramp: 2, quasi_static: {method: %s, "
           "tolerance: %g, load_steps: 2}}\n",
           method, strcmp(method, "mpm") == 0 ? "dynamic-relaxation" : "none",
           tol);
  pm_scene *s = NULL;
  if (pm_app_init() != PM_SUCCESS) fail_msg("%s", pm_error_message());
  if (pm_scene_load_text(text, strlen(text), "barrel.yaml", 0, NULL, &s) !=
      PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  return s;
}

/* The particles' displacement after a run of s (n x 3, malloc'd). */
static double *barrel_run(const pm_scene *s, long *n, double *seconds) {
  void *sim = NULL;
  if (s->backend->create(s, &sim) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  pm_outcome out;
  if (pm_run_sim(s, sim, NULL, true, &out) != PM_SUCCESS)
    fail_msg("%s: %s", s->method, pm_error_message());
  if (out.fig.status != PM_STATUS_CONVERGED)
    fail_msg("%s: status %s", s->method, pm_status_name(out.fig.status));
  const mpm_sim *r = sim;
  *n = r->model->n;
  double *u = malloc(3 * sizeof(double) * (size_t)*n);
  for (long i = 0; i < 3 * *n; i++) u[i] = r->state->x[i] - r->model->x0[i];
  *seconds = out.fig.wall_seconds;
  s->backend->destroy(sim);
  return u;
}

/* RMS of a - b over the range of b's y component. */
static double rms_difference(long n, const double *a, const double *b) {
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  for (long i = 0; i < n; i++) {
    for (int c = 0; c < 2; c++)
      sum += (a[3 * i + c] - b[3 * i + c]) * (a[3 * i + c] - b[3 * i + c]);
    lo = fmin(lo, b[3 * i + 1]);
    hi = fmax(hi, b[3 * i + 1]);
  }
  return sqrt(sum / n) / (hi - lo);
}

/* The same quasi-static barrel by the explicit MPM (dynamic relaxation
 * to a relative residual of 1e-4 and 1e-6) and the implicit MPM (grid
 * kept).  The two discretize alike but for one term: the explicit MPM
 * takes its gradients at the moved particles on a reset grid, which
 * differs by the displacement over the cell (measured: 8.8e-4 of the
 * range at 0.2% compression, 4.5e-6 at this 1e-5).  So the explicit run at
 * 1e-4 lies as far from the implicit as from its own tighter run (bound
 * 1.5 x its own change), and at 1e-6 under a third of that change away
 * (bound 0.35: measured 0.29). */
static void test_explicit(void **state) {
  (void)state;
  long n1, n2, n3;
  double t1, t2, t3;
  pm_scene *si = barrel_scene("mpm-implicit", 1e-10);
  pm_scene *s4 = barrel_scene("mpm", 1e-4);
  pm_scene *s6 = barrel_scene("mpm", 1e-6);
  double *ui = barrel_run(si, &n1, &t1);
  double *u4 = barrel_run(s4, &n2, &t2);
  double *u6 = barrel_run(s6, &n3, &t3);
  assert_int_equal(n1, n2);
  assert_int_equal(n1, n3);
  const double own = rms_difference(n1, u4, u6);
  const double d4 = rms_difference(n1, u4, ui), d6 = rms_difference(n1, u6, ui);
  print_message("barrel, %ld particles: implicit %.2f s; explicit 1e-4 %.2f "
                "s, 1e-6 %.2f s; explicit's own change 1e-4 -> 1e-6: %.2e; "
                "implicit against explicit 1e-4: %.2e, 1e-6: %.2e "
                "(bounds: 1.5 and 0.35 x the own change)\n",
                n1, t1, t2, t3, own, d4, d6);
  assert_true(d4 <= 1.5 * own);
  assert_true(d6 <= 0.35 * own);
  free(ui);
  free(u4);
  free(u6);
  pm_scene_destroy(si);
  pm_scene_destroy(s4);
  pm_scene_destroy(s6);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tangent), cmocka_unit_test(test_quadratic),
      cmocka_unit_test(test_f2), cmocka_unit_test(test_explicit)};
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
