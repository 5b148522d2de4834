/* test_fe_reference: the committed finite-element references (cases/fe)
 * load, agree between their two finest meshes to the tolerance each
 * claims, F2's is the exact homogeneous state, and malformed files fail
 * with the file and line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_fe.h"
#include "pm_metrics.h"

#define FE_DIR PM_SOURCE_DIR "/cases/fe"

static double rel_change(double fine, double coarse) {
  return fabs(fine - coarse) / fabs(fine);
}

/* ---- The committed references ------------------------------------------ */

/* The finest mesh against the one before it, to the claimed tolerances. */
static void check_case(const char *dir) {
  pm_fe_reference *r = NULL;
  char path[PM_PATH_MAX + 32];
  assert_ok(pm_fe_load(dir, &r));
  assert_true(r->n > 0 && r->finest >= 0);
  assert_true(r->previous >= 0 && r->previous < r->finest);
  const pm_fe_row *f = &r->rows[r->finest], *p = &r->rows[r->previous];
  /* The loaded component carries the largest reaction. */
  int axis = 0;
  for (int c = 1; c < 3; c++)
    if (fabs(f->reaction[c]) > fabs(f->reaction[axis])) axis = c;
  assert_true(isfinite(r->reaction[axis]) && r->reaction[axis] != 0);
  assert_true(r->mean_sed > 0 && r->von_mises_centre > 0);
  const pm_fe_tolerance *t = &r->tolerance;
  /* A traction case claims its tip displacement, its reaction being the
   * applied load. */
  const bool tip = r->tip_face >= 0;
  const double claim = tip ? t->tip : t->reaction;
  assert_true(claim > 0 && t->mean_sed > 0 && t->lattice_nrmse > 0 &&
              t->von_mises_centre > 0);
  double dr = tip ? rel_change(f->tip_u, p->tip_u)
                  : rel_change(f->reaction[axis], p->reaction[axis]);
  double ds = rel_change(f->mean_sed, p->mean_sed);
  double dv = rel_change(f->von_mises_centre, p->von_mises_centre);
  /* The previous mesh's lattice, at the same points. */
  long n;
  double *x = NULL, *u = NULL;
  snprintf(path, sizeof path, "%s/lattice-N%d.csv", dir, p->n);
  assert_ok(pm_fe_read_lattice(path, &n, &x, &u));
  assert_int_equal(n, r->n);
  for (long i = 0; i < 3 * n; i++) assert_true(fabs(x[i] - r->x[i]) < 1e-12);
  double dl = pm_nrmse_vector(n, r->dim == 2 ? 3u : 7u, u, r->u);
  print_message("%-30s N %d -> %d (%s): %s %.7g, change %.2e (tol "
                "%g); mean SED %.7g J/m^3, %.2e (%g); von Mises %.6g Pa, "
                "%.2e (%g); lattice NRMSE %.2e (%g)\n",
                r->name, p->n, f->n, f->element,
                tip ? "tip (m)" : "reaction (N)",
                tip ? r->tip_u : r->reaction[axis], dr, claim, r->mean_sed, ds,
                t->mean_sed, r->von_mises_centre, dv, t->von_mises_centre, dl,
                t->lattice_nrmse);
  /* A Richardson limit lies within the claim of the finest mesh. */
  if (!tip && isfinite(r->extrapolated.reaction))
    assert_true(rel_change(f->reaction[axis], r->extrapolated.reaction) <=
                claim);
  if (isfinite(r->extrapolated.mean_sed))
    assert_true(rel_change(f->mean_sed, r->extrapolated.mean_sed) <=
                t->mean_sed);
  assert_true(dr <= claim);
  assert_true(ds <= t->mean_sed);
  assert_true(dv <= t->von_mises_centre);
  assert_true(dl <= t->lattice_nrmse);
  free(x);
  free(u);
  pm_fe_free(r);
}

/* Every case folder with a claim (tolerance.csv) is a referee; a folder
 * without one records a ladder on which fewer than two meshes reached the
 * full load. */
static void test_committed_cases(void **state) {
  (void)state;
  DIR *d = opendir(FE_DIR);
  assert_non_null(d);
  struct dirent *e;
  int cases = 0;
  char dir[PM_PATH_MAX + 1], path[PM_PATH_MAX + 32];
  while ((e = readdir(d))) {
    if (e->d_name[0] == '.') continue;
    snprintf(dir, sizeof dir, "%s/%s", FE_DIR, e->d_name);
    if (!pm_fe_names_reference(dir, path, sizeof path)) continue; /* no case */
    snprintf(path, sizeof path, "%s/tolerance.csv", dir);
    FILE *f = fopen(path, "r");
    if (!f) {
      print_message("%-30s no referee (ladder only)\n", e->d_name);
      continue;
    }
    fclose(f);
    check_case(dir);
    cases++;
  }
  closedir(d);
  assert_true(cases >= 10);
}

/* ---- F2: the exact homogeneous state ------------------------------------ */

/* Uniaxial stress of W = mu/2 (J^(-2/3) I1 - 3) + K/2 (J - 1)^2 at axial
 * stretch a and lateral stretch s: the lateral and axial Cauchy stresses,
 * sigma = mu J^(-5/3) (b - I1/3 I) + K (J - 1) I. */
static void uniaxial(double mu, double K, double a, double s, double *lat,
                     double *ax) {
  double J = a * s * s, I1 = a * a + 2 * s * s;
  double c = mu * pow(J, -5.0 / 3.0);
  *lat = c * (s * s - I1 / 3) + K * (J - 1);
  *ax = c * (a * a - I1 / 3) + K * (J - 1);
}

static void test_f2_exact(void **state) {
  (void)state;
  const double E = 3000, nu = 0.495, a = 0.6, area = 0.01;
  const double mu = E / (2 * (1 + nu)), K = E / (3 * (1 - 2 * nu));
  /* The lateral stress rises with s: bisection for its zero. */
  double lo = 1.0, hi = 2.0, lat, ax;
  for (int k = 0; k < 200; k++) {
    double mid = 0.5 * (lo + hi);
    uniaxial(mu, K, a, mid, &lat, &ax);
    if (lat < 0)
      lo = mid;
    else
      hi = mid;
  }
  double s = 0.5 * (lo + hi);
  uniaxial(mu, K, a, s, &lat, &ax);
  /* Nominal stress P = J sigma F^-T: P_zz = s^2 sigma_zz. */
  double reaction = s * s * ax * area;
  double J = a * s * s;
  double W = 0.5 * mu * (pow(J, -2.0 / 3.0) * (a * a + 2 * s * s) - 3) +
             0.5 * K * (J - 1) * (J - 1);
  pm_fe_reference *r = NULL;
  assert_ok(pm_fe_load(FE_DIR "/f2-unconstrained-compression", &r));
  print_message("F2: lateral stretch %.9f; reaction FE %.7g N, exact %.7g N; "
                "mean SED FE %.7g, exact %.7g J/m^3; von Mises FE %.6g, exact "
                "%.6g Pa\n",
                s, r->reaction[2], reaction, r->mean_sed, W,
                r->von_mises_centre, fabs(ax));
  assert_true(fabs(r->reaction[2] - reaction) <= 1e-6 * fabs(reaction));
  assert_true(fabs(r->reaction[0]) <= 1e-9 && fabs(r->reaction[1]) <= 1e-9);
  assert_true(fabs(r->mean_sed - W) <= 1e-5 * W);
  /* The nodal stress of the .frd (extrapolated from the integration
   * points, 6 digits) is within 4e-5 of the exact value. */
  assert_true(fabs(r->von_mises_centre - fabs(ax)) <= 1e-4 * fabs(ax));
  double worst = 0;
  for (long i = 0; i < r->n; i++) {
    const double *x = &r->x[3 * i], *u = &r->u[3 * i];
    double ex[3] = {(s - 1) * x[0], (s - 1) * x[1], (a - 1) * x[2]};
    for (int c = 0; c < 3; c++) worst = fmax(worst, fabs(u[c] - ex[c]));
  }
  /* Against the largest displacement, 0.04 m. */
  print_message("F2: largest lattice error %.3g m (%.2g of 0.04 m)\n", worst,
                worst / 0.04);
  assert_true(worst <= 1e-6 * 0.04);
  pm_fe_free(r);
}

/* ---- Malformed files ----------------------------------------------------- */

#define LADDER_HEAD                                                            \
  "# comment\n"                                                                \
  "N,nodes,dofs,element,h,reaction_x,reaction_y,reaction_z,mean_sed,"          \
  "von_mises_centre,increments,wall_seconds,ccx_version,load_fraction,"        \
  "status\n"
#define LADDER_ROWS                                                            \
  "2,81,243,C3D20R,0.05,0,0,-21.79,346.9,1313.2,12,1.4,2.20,1,converged\n"     \
  "4,425,1275,C3D20R,0.025,0,0,-21.79,346.9,1313.2,12,4.2,2.20,1,converged\n"
#define LATTICE "x,y,z,u_x,u_y,u_z\n0,0,0,0,0,0\n0.1,0.1,0.1,0.03,0.03,-0.04\n"

/* Write the three files of a reference into dir (NULL: leave one out). */
static void write_reference(const char *dir, const char *ladder,
                            const char *lattice, const char *tolerance) {
  char path[512];
  if (ladder) pm_test_write_file(dir, "ladder.csv", ladder, path);
  if (lattice) pm_test_write_file(dir, "lattice.csv", lattice, path);
  if (tolerance) pm_test_write_file(dir, "tolerance.csv", tolerance, path);
}

static void test_good(void **state) {
  const char *dir = *state;
  pm_fe_reference *r = NULL;
  write_reference(dir, LADDER_HEAD LADDER_ROWS, LATTICE,
                  "quantity,finest_N,previous_N,relative_change,tolerance\n"
                  "reaction,4,2,1e-7,1e-6\nlattice_nrmse,4,2,1e-7,1e-6\n");
  assert_ok(pm_fe_load(dir, &r));
  assert_int_equal(r->n_rows, 2);
  assert_int_equal(r->finest, 1);
  assert_int_equal(r->previous, 0);
  assert_int_equal(r->n, 2);
  assert_int_equal(r->dim, 3);
  assert_true(r->reaction[2] == -21.79 && r->mean_sed == 346.9);
  assert_true(r->centre[0] == 0.05 && r->centre[2] == 0.05);
  assert_true(r->tolerance.reaction == 1e-6 && isnan(r->tolerance.mean_sed));
  assert_string_equal(r->rows[1].element, "C3D20R");
  pm_fe_free(r);
}

/* Richardson limits in tolerance.csv (column extrapolated) stand for the
 * referee's figures where their uncertainty is below the finest mesh's
 * estimated error; the finest row keeps the mesh's own, and an empty field or a
 * limit less sure than the finest mesh (von Mises here) leaves the finest
 * mesh's figure. */
static void test_extrapolated(void **state) {
  const char *dir = *state;
  pm_fe_reference *r = NULL;
  write_reference(dir, LADDER_HEAD LADDER_ROWS, LATTICE,
                  "quantity,tolerance,estimated_error,extrapolated,"
                  "extrapolation_uncertainty\n"
                  "reaction,1e-2,8e-3,-21.5,2e-3\nmean_sed,1e-2,8e-3,340,1e-3\n"
                  "von_mises_centre,1e-2,8e-3,1300,1e-2\n"
                  "lattice_nrmse,1e-2,,,\n");
  assert_ok(pm_fe_load(dir, &r));
  assert_true(r->reaction[2] == -21.5 && r->reaction[0] == 0);
  assert_true(r->rows[r->finest].reaction[2] == -21.79);
  assert_true(r->mean_sed == 340 && r->von_mises_centre == 1313.2);
  assert_true(r->extrapolation_uncertainty.reaction == 2e-3);
  assert_true(r->extrapolated.von_mises_centre == 1300);
  assert_true(isnan(r->extrapolated.lattice_nrmse));
  pm_fe_free(r);
}

/* A traction case: the tip columns name the loaded face and component,
 * and pm_fe_tip averages that component over the lattice points on the
 * face (here x = 0.1: two of the three points). */
static void test_tip(void **state) {
  const char *dir = *state;
  pm_fe_reference *r = NULL;
  const char *ladder =
      "N,nodes,dofs,element,h,reaction_x,reaction_y,reaction_z,mean_sed,"
      "von_mises_centre,increments,wall_seconds,ccx_version,load_fraction,"
      "status,tip_face,tip_axis,tip_u\n"
      "2,81,243,C3D20R,0.05,0,-8,0,1.3,52,12,1.4,2.20,1,converged,xmax,y,0.5\n"
      "4,425,1275,C3D20R,0.025,0,-8,0,1.4,52,12,4.2,2.20,1,converged,xmax,y,"
      "0.6\n";
  write_reference(dir, ladder,
                  "x,y,z,u_x,u_y,u_z\n0,0,0,0,0,0\n0.1,0,0,0,0.5,0\n"
                  "0.1,0.1,0,0,0.7,0\n",
                  "quantity,tolerance\ntip,1e-2\n");
  assert_ok(pm_fe_load(dir, &r));
  assert_int_equal(r->tip_face, 1);
  assert_int_equal(r->tip_axis, 1);
  assert_true(r->tip_u == 0.6 && r->tolerance.tip == 1e-2);
  assert_true(isnan(r->tolerance.reaction));
  double mapped[9] = {0, 0, 0, 0, 0.45, 0, 0, 0.69, 0};
  assert_close(pm_fe_tip(r, mapped), 0.57, 1e-15, 0);
  pm_fe_errors e;
  pm_outcome o = {.loaded_axis = -1, .fig = {.mean_sed = 1.4}};
  pm_fe_errors_of(r, mapped, &o, &e);
  assert_close(e.tip_error, -0.05, 1e-14, 0);
  assert_true(isnan(e.reaction_error));
  pm_fe_free(r);
  /* Without tip columns there is no tip. */
  write_reference(dir, LADDER_HEAD LADDER_ROWS, LATTICE, NULL);
  assert_ok(pm_fe_load(dir, &r));
  assert_true(r->tip_face == -1 && isnan(pm_fe_tip(r, mapped)));
  pm_fe_free(r);
}

/* The interior NRMSE sees only the lattice points off the bounding faces
 * and keeps the whole lattice's normaliser: on a 3 x 3 x 3 lattice an error
 * at a face point leaves it zero, and one at the centre (the one interior
 * point) gives |d| / max|u| there, sqrt(27) times the whole lattice's. */
/* A 3 x 3 x 3 lattice of spacing 0.05 (x, [27][3]) under u_z = -0.4 z (u:
 * |u| from 0 to 0.04). */
static void cube27(double *x, double *u) {
  for (int k = 0; k < 27; k++) {
    x[3 * k] = 0.05 * (k % 3);
    x[3 * k + 1] = 0.05 * (k / 3 % 3);
    x[3 * k + 2] = 0.05 * (k / 9);
    u[3 * k] = u[3 * k + 1] = 0;
    u[3 * k + 2] = -0.4 * x[3 * k + 2];
  }
}

static void test_interior_nrmse(void **state) {
  (void)state;
  double x[81], u[81], mapped[81];
  pm_fe_reference r = {.n = 27, .x = x, .u = u, .dim = 3};
  cube27(x, u);
  memcpy(mapped, u, sizeof u);
  mapped[3 * 1 + 0] += 1e-3; /* a point on the face y = 0 */
  assert_true(pm_fe_nrmse_interior(&r, mapped) == 0);
  assert_true(pm_nrmse_vector(27, 7u, mapped, u) > 0);
  memcpy(mapped, u, sizeof u);
  mapped[3 * 13 + 2] += 2e-3; /* the centre */
  assert_close(pm_fe_nrmse_interior(&r, mapped), 2e-3 / 0.04, 1e-14, 0);
  assert_close(pm_fe_nrmse_interior(&r, mapped),
               sqrt(27.0) * pm_nrmse_vector(27, 7u, mapped, u), 1e-14, 0);
  r.n = 9; /* one layer z = 0: no point is inside */
  assert_true(isnan(pm_fe_nrmse_interior(&r, mapped)));
}

/* The volume-weighted NRMSE (the paper's sampling): on a 3 x 3 x 3 lattice
 * of spacing 0.05 each point stands for its share of the cube (1 inside,
 * 1/2 on a face, 1/4 on an edge, 1/8 at a corner; 8 in all), and the
 * normaliser is max |u| - min |u|. */
static void test_volume_nrmse(void **state) {
  (void)state;
  double x[81], u[81], mapped[81];
  pm_fe_reference r = {.n = 27, .x = x, .u = u, .dim = 3};
  cube27(x, u);
  /* The same error everywhere: e / range, whatever the weights. */
  for (int k = 0; k < 81; k++) mapped[k] = u[k] + (k % 3 == 0 ? 3e-4 : 0);
  assert_close(pm_fe_nrmse_volume(&r, mapped), 3e-4 / 0.04, 1e-13, 0);
  /* The centre alone stands for 1/8 of the cube, a corner for 1/64. */
  memcpy(mapped, u, sizeof u);
  mapped[3 * 13 + 2] += 2e-3;
  assert_close(pm_fe_nrmse_volume(&r, mapped), 2e-3 / 0.04 / sqrt(8.0), 1e-13,
               0);
  memcpy(mapped, u, sizeof u);
  mapped[3 * 26 + 1] += 2e-3;
  assert_close(pm_fe_nrmse_volume(&r, mapped), 2e-3 / 0.04 / 8.0, 1e-13, 0);
  /* The range, not the largest |u|: shift the reference off zero. */
  for (int k = 0; k < 27; k++) u[3 * k] = 0.01;
  for (int k = 0; k < 81; k++) mapped[k] = u[k] + (k % 3 == 0 ? 3e-4 : 0);
  const double range = sqrt(0.01 * 0.01 + 0.04 * 0.04) - 0.01;
  assert_close(pm_fe_nrmse_volume(&r, mapped), 3e-4 / range, 1e-13, 0);
  /* A reference that does not move has no range. */
  memset(u, 0, sizeof u);
  assert_true(isnan(pm_fe_nrmse_volume(&r, mapped)));
}

/* A malformed file: its text (the others are good), the line at fault and
 * what the message says there. */
typedef struct {
  const char *ladder, *lattice, *tolerance;
  const char *file;
  int line;
  const char *text;
} bad_case;

static const bad_case BAD[] = {
    {LADDER_HEAD LADDER_ROWS
     "5,1,3,C3D20R,0.02,0,0,abc,1,1,1,1,2.20,1,converged\n",
     LATTICE, NULL, "ladder.csv", 5,
     "column reaction_z: expected a finite number, got 'abc'"},
    {LADDER_HEAD "2,81,243\n", LATTICE, NULL, "ladder.csv", 3,
     "expected 15 comma-separated fields"},
    {"N,nodes\n2,81\n", LATTICE, NULL, "ladder.csv", 1,
     "expected a column 'dofs'"},
    {LADDER_HEAD
     "2,81,243,C3D20R,0.05,0,0,-21.79,346.9,1313.2,12,1.4,2.20,1,done\n",
     LATTICE, NULL, "ladder.csv", 3,
     "column status: expected converged or stopped, got 'done'"},
    {LADDER_HEAD LADDER_ROWS
     "8,1,3,C3D20R,0.05,0,0,1,1,1,1,1,2.20,1,converged\n",
     LATTICE, NULL, "ladder.csv", 5,
     "expected the meshes from coarsest to finest"},
    {LADDER_HEAD LADDER_ROWS, "x,y,z,u,v,w\n0,0,0,0,0,0\n", NULL, "lattice.csv",
     1, "expected the header x,y,z,u_x,u_y,u_z"},
    {LADDER_HEAD LADDER_ROWS,
     "# c\nx,y,z,u_x,u_y,u_z\n0,0,0,0,0,0\n0,0,0,0,nan,0\n", NULL,
     "lattice.csv", 4, "column u_y: expected a finite number, got 'nan'"},
    {LADDER_HEAD LADDER_ROWS, LATTICE,
     "quantity,tolerance\nreaction,1e-3\nstress,1e-3\n", "tolerance.csv", 3,
     "column quantity: expected reaction, mean_sed"},
    {LADDER_HEAD LADDER_ROWS, LATTICE,
     "quantity,tolerance,extrapolated\nreaction,1e-3,abc\n", "tolerance.csv", 2,
     "column extrapolated: expected a finite number, got 'abc'"},
    {"N,nodes,dofs,element,h,reaction_x,reaction_y,reaction_z,mean_sed,"
     "von_mises_centre,increments,wall_seconds,ccx_version,tip_face,tip_axis,"
     "tip_u\n2,81,243,C3D20R,0.05,0,-8,0,1,1,12,1,2.20,top,y,0.5\n",
     LATTICE, NULL, "ladder.csv", 2,
     "column tip_face: expected xmin, xmax, ymin, ymax, zmin or zmax, got "
     "'top'"},
};

static void test_malformed(void **state) {
  const char *dir = *state;
  char where[600], path[512];
  pm_fe_reference *r = NULL;
  for (size_t k = 0; k < sizeof BAD / sizeof *BAD; k++) {
    const bad_case *b = &BAD[k];
    snprintf(path, sizeof path, "%s/tolerance.csv", dir);
    remove(path);
    write_reference(dir, b->ladder, b->lattice, b->tolerance);
    snprintf(where, sizeof where, "%s/%s:%d: %s", dir, b->file, b->line,
             b->text);
    r = (pm_fe_reference *)1;
    assert_fails(pm_fe_load(dir, &r), PM_ERR_ARG, where);
    assert_null(r);
  }
  /* No mesh reached the load (a stopped run may lack its figures). */
  write_reference(dir,
                  LADDER_HEAD "2,81,243,C3D20R,0.05,nan,nan,nan,nan,nan,3,1.4,"
                              "2.20,0.4,stopped\n",
                  LATTICE, NULL);
  snprintf(where, sizeof where, "%s/ladder.csv' holds no mesh", dir);
  assert_fails(pm_fe_load(dir, &r), PM_ERR_ARG, where);
  /* A missing file is named. */
  write_reference(dir, LADDER_HEAD LADDER_ROWS, NULL, NULL);
  snprintf(where, sizeof where, "%s/lattice.csv", dir);
  remove(where);
  assert_fails(pm_fe_load(dir, &r), PM_ERR_IO, where);
}

static void test_names(void **state) {
  const char *dir = *state;
  char buf[PM_PATH_MAX + 1];
  assert_true(pm_fe_names_reference("fe:cases/fe/x", buf, sizeof buf));
  assert_string_equal(buf, "cases/fe/x");
  assert_false(pm_fe_names_reference("fe:", buf, sizeof buf));
  assert_false(pm_fe_names_reference("last", buf, sizeof buf));
  assert_false(pm_fe_names_reference(dir, buf, sizeof buf));
  write_reference(dir, LADDER_HEAD, NULL, NULL);
  assert_true(pm_fe_names_reference(dir, buf, sizeof buf));
  assert_string_equal(buf, dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_committed_cases),
      cmocka_unit_test_setup_teardown(test_tip, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_f2_exact),
      cmocka_unit_test(test_interior_nrmse),
      cmocka_unit_test(test_volume_nrmse),
      cmocka_unit_test_setup_teardown(test_good, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_extrapolated, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_malformed, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_names, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
