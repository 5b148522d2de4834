/* test_contact: rigid plates and spheres in contact with FPM points: the
 * penalty force and its tangent on a few points, the scene keys, and bad
 * input refused at its key (file:line:col). */
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
#include "fpm_contact.h"
#include "fpm_static.h"
#include "pm_app.h"
#include "pm_scene.h"
#include "pm_testing.h"
#include "gmsh_testing.h"

/* A rigid body as the scene loader leaves it. */
static pm_scene_bc rigid(pm_on on, pm_contact contact, const double p[3],
                         const double n[3], double radius) {
  pm_scene_bc bc = {0};
  bc.on = on;
  bc.contact = contact;
  memcpy(bc.rigid_point, p, sizeof bc.rigid_point);
  if (n) memcpy(bc.rigid_normal, n, sizeof bc.rigid_normal);
  bc.rigid_radius = radius;
  return bc;
}

/* The tangent against central differences of the force (a fresh anchor
 * copy for each evaluation, as set by the first call). */
static void check_tangent(const pm_scene_bc *bc, double k, const double d[3],
                          const double x[3], const double anchor[3]) {
  double K[9], h = 1e-7;
  fpm_contact_tangent(bc, k, d, x, anchor, K);
  for (int b = 0; b < 3; b++) {
    double xp[3], xm[3], Fp[3], Fm[3], e, ap[3], am[3];
    memcpy(xp, x, sizeof xp);
    memcpy(xm, x, sizeof xm);
    memcpy(ap, anchor, sizeof ap);
    memcpy(am, anchor, sizeof am);
    xp[b] += h;
    xm[b] -= h;
    fpm_contact_point(bc, k, d, xp, ap, Fp, &e);
    fpm_contact_point(bc, k, d, xm, am, Fm, &e);
    for (int a = 0; a < 3; a++)
      assert_near(-(Fp[a] - Fm[a]) / (2 * h), K[3 * a + b], 1e-6 * k);
  }
}

/* A plate z = 0.1 facing down, moved down by 0.01: a point at z = 0.095
 * penetrates 0.005 and is pushed down by k 0.005; one below is free. */
static void test_plate_frictionless(void **state) {
  (void)state;
  const double p[3] = {0, 0, 0.1}, n[3] = {0, 0, -1}, d[3] = {0, 0, -0.01};
  pm_scene_bc bc = rigid(PM_ON_PLATE, PM_CONTACT_FRICTIONLESS, p, n, 0);
  const double k = 2e4;
  double x[3] = {0.03, 0.07, 0.095}, a[3] = {NAN, NAN, NAN}, F[3], e;
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_near(F[0], 0, 0);
  assert_near(F[1], 0, 0);
  assert_near(F[2], -k * 0.005, 1e-12);
  assert_near(e, 0.5 * k * 0.005 * 0.005, 1e-15);
  check_tangent(&bc, k, d, x, a);
  double y[3] = {0.03, 0.07, 0.0899};
  assert_false(fpm_contact_point(&bc, k, d, y, a, F, &e));
  assert_near(F[2], 0, 0);
  assert_near(e, 0, 0);
}

/* Sticking: the point is held where it touched; moving it sideways while
 * in contact pulls it back by k times the slip, and leaving frees it. */
static void test_plate_sticking(void **state) {
  (void)state;
  const double p[3] = {0, 0, 0}, n[3] = {0, 0, 1}, d[3] = {0, 0, 0};
  pm_scene_bc bc = rigid(PM_ON_PLATE, PM_CONTACT_STICKING, p, n, 0);
  const double k = 10;
  double x[3] = {0.2, 0.1, -0.01}, a[3] = {NAN, NAN, NAN}, F[3], e;
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_near(a[0], 0.2, 1e-15);
  assert_near(a[1], 0.1, 1e-15);
  assert_near(a[2], 0, 1e-15);
  assert_near(F[2], 0.1, 1e-14);
  x[0] += 0.03; /* slides 0.03 along x */
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_near(F[0], -0.3, 1e-14);
  assert_near(F[2], 0.1, 1e-14);
  assert_near(e, 0.5 * k * (0.03 * 0.03 + 0.01 * 0.01), 1e-15);
  check_tangent(&bc, k, d, x, a);
  x[2] = 0.001; /* leaves */
  assert_false(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_true(isnan(a[0]));
}

/* Glued: held where it touched, and pulled back when it leaves: the
 * anchor stays and the force is k times the distance from it, normal part
 * included; the tangent is k I on either side of the surface. */
static void test_plate_glued(void **state) {
  (void)state;
  const double p[3] = {0, 0, 0}, n[3] = {0, 0, 1}, d[3] = {0, 0, 0};
  pm_scene_bc bc = rigid(PM_ON_PLATE, PM_CONTACT_GLUED, p, n, 0);
  const double k = 10;
  double x[3] = {0.2, 0.1, 0.001}, a[3] = {NAN, NAN, NAN}, F[3], e;
  /* apart and not anchored: free */
  assert_false(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_true(isnan(a[0]));
  x[2] = -0.01;
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_near(a[2], 0, 1e-15);
  assert_near(F[2], 0.1, 1e-14);
  x[0] += 0.03; /* slides 0.03 along x and leaves by 0.002 */
  x[2] = 0.002;
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  assert_near(a[0], 0.2, 1e-15);
  assert_near(F[0], -0.3, 1e-14);
  assert_near(F[2], -0.02, 1e-14);
  assert_near(e, 0.5 * k * (0.03 * 0.03 + 0.002 * 0.002), 1e-15);
  check_tangent(&bc, k, d, x, a);
}

/* A sphere of radius 0.02 moved by (0, 0, -0.01): the force is along the
 * radius through the point, k times the depth, and the tangent holds the
 * turning of the normal. */
static void test_sphere(void **state) {
  (void)state;
  const double c[3] = {0.05, 0.05, 0.12}, d[3] = {0, 0, -0.01};
  pm_scene_bc bc = rigid(PM_ON_SPHERE, PM_CONTACT_FRICTIONLESS, c, NULL, 0.02);
  const double k = 3e3;
  double x[3] = {0.06, 0.05, 0.095}, a[3] = {NAN, NAN, NAN}, F[3], e;
  const double r[3] = {0.01, 0, -0.015},
               len = sqrt(0.01 * 0.01 + 0.015 * 0.015);
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  for (int i = 0; i < 3; i++)
    assert_near(F[i], k * (0.02 - len) * r[i] / len, 1e-12);
  check_tangent(&bc, k, d, x, a);
  bc.contact = PM_CONTACT_STICKING;
  a[0] = a[1] = a[2] = NAN;
  assert_true(fpm_contact_point(&bc, k, d, x, a, F, &e));
  for (int i = 0; i < 3; i++)
    assert_near(F[i], k * (0.02 - len) * r[i] / len, 1e-12);
  check_tangent(&bc, k, d, x, a);
}

/* A scene text with the plate entry given, loaded as NAME; extra: more
 * top-level lines ("" for none). */
static pm_err load_with(const char *plate, const char *method, const char *qs,
                        const char *extra, pm_scene **s) {
  char text[2048];
  snprintf(text, sizeof text,
           "name: contact\n"
           "method: %s\n"
           "dimension: 3\n"
           "domain: {box: {min: [0, 0, 0], max: [0.1, 0.1, 0.1]}}\n"
           "discretization: {mesh_size: 0.04}\n"
           "materials:\n"
           "  - {name: gel, model: neo-hookean, density: 1000, "
           "youngs_modulus: 3000, poisson_ratio: 0.3}\n"
           "bodies: [{material: gel, region: domain}]\n"
           "boundary:\n"
           "  - {on: zmin, displacement: {x: 0, y: 0, z: 0}}\n"
           "  - %s\n"
           "time: {end: 1, quasi_static: {method: %s}}\n"
           "%s",
           method, plate, qs, extra);
  return pm_scene_load_text(text, strlen(text), "contact.yaml", 0, NULL, s);
}

static pm_err load(const char *plate, const char *method, const char *qs,
                   pm_scene **s) {
  return load_with(plate, method, qs, "", s);
}

/* Loading fails with a message holding frag1 and frag2. */
static void load_fails(const char *plate, const char *method, const char *qs,
                       const char *frag1, const char *frag2) {
  pm_scene *s = NULL;
  pm_error_clear();
  assert_int_equal(load(plate, method, qs, &s), PM_ERR_SCENE);
  assert_null(s);
  const char *msg = pm_error_message();
  if (!strstr(msg, frag1) || (frag2 && !strstr(msg, frag2)))
    fail_msg("message \"%s\" lacks \"%s\" or \"%s\"", msg, frag1,
             frag2 ? frag2 : "");
}

static void test_keys(void **state) {
  (void)state;
  pm_scene *s = NULL;
  assert_ok(load("{plate: {point: [0, 0, 0.1], normal: [0, 0, -2]}, "
                 "displacement: {z: -0.01*t}, contact: sticking}",
                 "fpm", "dynamic-relaxation", &s));
  const pm_scene_bc *bc = &s->bcs[1];
  assert_int_equal(bc->on, PM_ON_PLATE);
  assert_int_equal(bc->contact, PM_CONTACT_STICKING);
  assert_near(bc->rigid_normal[2], -1, 0);
  assert_int_equal(bc->disp_mask, 7);
  assert_string_equal(bc->surface, "plate.1");
  assert_near(pm_expr_eval(bc->disp[0], 0, 0, 0, 1), 0, 0);
  assert_near(pm_expr_eval(bc->disp[2], 0, 0, 0, 2), -0.02, 1e-15);
  assert_near(bc->contact_penalty, 100, 0);
  pm_scene_destroy(s);
  assert_ok(load("{sphere: {center: [0.05, 0.05, 0.13], radius: 0.02}, "
                 "displacement: {z: -0.01}, name: ball}",
                 "fpm", "dynamic-relaxation", &s));
  assert_int_equal(s->bcs[1].on, PM_ON_SPHERE);
  assert_int_equal(s->bcs[1].contact, PM_CONTACT_FRICTIONLESS);
  assert_string_equal(s->bcs[1].surface, "ball");
  pm_scene_destroy(s);
}

static void test_bad_keys(void **state) {
  (void)state;
  const char *dr = "dynamic-relaxation";
  load_fails("{plate: {point: [0, 0, 0.1], normal: [0, 0, 0]}, "
             "displacement: {z: -0.01}}",
             "fpm", dr, "contact.yaml:11:", "non-zero length");
  load_fails("{on: zmax, plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
             "displacement: {z: -0.01}}",
             "fpm", dr, "contact.yaml:11:", "expected no on with plate");
  load_fails("{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
             "displacement: {z: -0.01*x}}",
             "fpm", dr, "contact.yaml:11:", "a function of t only");
  load_fails("{on: zmax, displacement: {z: -0.01}, contact: sticking}", "fpm",
             dr, "contact.yaml:11:", "only with a plate or a sphere");
  load_fails("{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
             "displacement: {z: -0.01}}",
             "mpm-implicit", "static",
             "contact.yaml:11:", "contact needs method mpm or fpm");
}

/* The scene with the plate entry given, method fpm, and its simulation
 * made: what fpm_sim_create returned. */
static pm_err make_fpm(const char *plate, const char *qs, pm_scene **s,
                       fpm_sim **sim) {
  assert_ok(load(plate, "fpm", qs, s));
  pm_error_clear();
  return fpm_sim_create(*s, sim);
}

/* A plate that starts 5 mm inside the block is refused when the points
 * are made, at its key, naming a point. */
static void test_plate_inside(void **state) {
  (void)state;
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  assert_int_equal(make_fpm("{plate: {point: [0, 0, 0.095], normal: [0, 0, "
                            "-1]}, displacement: {z: -0.01}}",
                            "dynamic-relaxation", &s, &sim),
                   PM_ERR_SCENE);
  const char *msg = pm_error_message();
  if (!strstr(msg, "contact.yaml:11:") || !strstr(msg, "inside"))
    fail_msg("message \"%s\"", msg);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

/* The static solve's tangent with a rigid body pressed into the top of
 * the block (u_z stretches it 2 mm past the plate or into the sphere, with
 * a lateral shear, 1 mm more since the anchors were set): the assembled
 * tangent equals the one coloured from
 * the linearised force and central differences of the residual (relative
 * 1e-6), for a frictionless plate, a sticking plate (every other touching
 * point anchored by fpm_contact_commit at a state 1 mm shallower, the rest
 * touching anew) and a frictionless sphere. */
static void check_static_tangent(const char *body, const char *what) {
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  /* The standard volumetric term: the assembled tangent is then the whole
   * tangent (the averaged volume's coupling is applied matrix-free, and
   * unit.test_fpm_volumetric checks its linearisation). */
  assert_ok(
      load_with(body, "fpm", "static", "fpm: {volumetric: standard}\n", &s));
  assert_ok(fpm_sim_create(s, &sim));
  const fpm_model *m = sim->model;
  fpm_state *st = sim->state;
  const long nd = 3 * m->n;
  double ztop = 0;
  for (long i = 0; i < m->n; i++) ztop = fmax(ztop, m->x[3 * i + 2]);
  double *u = calloc(nd, sizeof *u);
  for (int pass = 0; pass < 2; pass++) {
    /* pass 0: 1 mm less deep, where the anchors are set */
    const double a = (0.101 + 0.001 * pass - ztop) / ztop;
    for (long i = 0; i < m->n; i++) {
      const double *x = m->x + 3 * i;
      u[3 * i] = (0.02 + 0.01 * pass) * x[2] + 1e-4 * sin(97 * x[1]);
      u[3 * i + 1] = -0.01 * x[2] + 1e-4 * cos(53 * x[0]);
      u[3 * i + 2] = a * x[2] + 1e-5 * sin(71 * x[0] + 31 * x[1]);
    }
    if (pass == 1) break;
    memcpy(st->u, u, nd * sizeof *u);
    fpm_contact_commit(m, st, 1, 0);
  }
  long anchored = 0;
  for (long q = 0; q < m->contact->pair_ptr[1]; q++) {
    double *A = st->contact + 3 * q;
    if (isnan(A[0])) continue;
    if (q % 2)
      anchored++;
    else
      A[0] = A[1] = A[2] = NAN; /* touching anew */
  }
  double ea, ed;
  assert_ok(fpm_static_check_tangent(m, st, u, &ea, &ed));
  double R[3] = {0, 0, 0};
  fpm_contact_reaction(m, st, 1, R);
  print_message("%s: reaction (%.4g, %.4g) N in x, z, %ld points anchored; "
                "assembled "
                "tangent against coloured %.3g, against differences %.3g\n",
                what, R[0], R[2], anchored, ea, ed);
  assert_true(R[2] < 0);
  assert_true(ea <= 1e-10);
  assert_true(ed <= 1e-6);
  free(u);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

static void test_static_tangent(void **state) {
  (void)state;
  check_static_tangent("{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
                       "displacement: {z: -0.01}}",
                       "frictionless plate");
  check_static_tangent("{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
                       "displacement: {z: -0.01}, contact: sticking}",
                       "sticking plate");
  check_static_tangent("{sphere: {center: [0.05, 0.05, 0.3], radius: "
                       "0.2}, displacement: {z: -0.01}}",
                       "frictionless sphere");
}

/* The sticking set of a static solve updated between Newton iterations:
 * the points a uniform compression pushes 1 mm into a sticking plate are
 * anchored where they penetrate, which leaves every force as it was (the
 * normal push -k g n becomes the anchor's pull of the same value); a
 * second call anchors none; drawn 2 mm back, every one is let go, the
 * farthest 1 mm off, and none is left anchored; pushed in and drawn back
 * once more, they are anchored again and then held as grazing, not let go
 * a second time within the step. */
static void test_static_touch_release(void **state) {
  (void)state;
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  assert_ok(load(
      "{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, displacement: {z: "
      "-0.01}, contact: sticking}",
      "fpm", "static", &s));
  assert_ok(fpm_sim_create(s, &sim));
  const fpm_model *m = sim->model;
  fpm_state *st = sim->state;
  const long nd = 3 * m->n, np = m->contact->pair_ptr[1];
  double *f0 = calloc(nd, sizeof *f0), ztop = 0;
  for (long i = 0; i < m->n; i++) ztop = fmax(ztop, m->x[3 * i + 2]);
  for (long i = 0; i < m->n; i++) /* the top 1 mm past the plate at 0.09 */
    st->u[3 * i + 2] = (0.091 - ztop) / ztop * m->x[3 * i + 2];
  for (long q = 0; q < np; q++) assert_true(isnan(st->contact[3 * q]));
  memset(st->f, 0, nd * sizeof *st->f);
  fpm_contact_force_fixed(m, st, 1, 1);
  memcpy(f0, st->f, nd * sizeof *f0);
  const long added = fpm_contact_touch_fixed(m, st, 1, 1);
  assert_int_equal(fpm_contact_touch_fixed(m, st, 1, 1), 0);
  memset(st->f, 0, nd * sizeof *st->f);
  fpm_contact_force_fixed(m, st, 1, 1);
  double df = 0, fmax_ = 0;
  for (long d = 0; d < nd; d++) {
    df = fmax(df, fabs(st->f[d] - f0[d]));
    fmax_ = fmax(fmax_, fabs(f0[d]));
  }
  long top = 0;
  for (long i = 0; i < m->n; i++) top += m->x[3 * i + 2] > ztop - 1e-12;
  for (long i = 0; i < m->n; i++)
    st->u[3 * i + 2] -= 0.002 * m->x[3 * i + 2] / ztop;
  unsigned char *let_go = calloc(np, 1);
  fpm_contact_release r;
  const long released = fpm_contact_release_fixed(m, st, 1, 1, let_go, &r);
  long left = 0;
  for (long q = 0; q < np; q++) left += !isnan(st->contact[3 * q]);
  /* pushed in again, anchored again, drawn back again: they graze and
   * are held (frozen) this time */
  for (long i = 0; i < m->n; i++)
    st->u[3 * i + 2] += 0.002 * m->x[3 * i + 2] / ztop;
  const long again = fpm_contact_touch_fixed(m, st, 1, 1);
  for (long i = 0; i < m->n; i++)
    st->u[3 * i + 2] -= 0.002 * m->x[3 * i + 2] / ztop;
  fpm_contact_release r2;
  const long released2 = fpm_contact_release_fixed(m, st, 1, 1, let_go, &r2);
  print_message("sticking set: %ld top points, %ld anchored on touching "
                "(force changed by %.2g of %.3g N), %ld let go drawn back (the "
                "farthest %.3g m off), %ld left; anchored again %ld, then %ld "
                "let go and %ld held grazing (%.3g m off)\n",
                top, added, df, fmax_, released, r.first_gap, left, again,
                released2, r2.frozen, r2.frozen_gap);
  assert_int_equal(added, top);
  assert_true(df <= 1e-12 * fmax_);
  assert_int_equal(released, top);
  assert_true(r.first >= 0 && fabs(m->x[3 * r.first + 2] - ztop) < 1e-12);
  assert_near(r.first_gap, 0.001, 1e-12);
  assert_int_equal(left, 0);
  assert_int_equal(again, top);
  assert_int_equal(released2, 0);
  assert_int_equal(r2.frozen, top);
  assert_near(r2.frozen_gap, 0.001, 1e-12);
  free(let_go);
  free(f0);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

/* A glued plate on the cube's top face: its points are anchored at rest,
 * and a static solve's set updates never let them go; drawn 1 mm off
 * the plate, each is pulled back by k times 1 mm, the plate's reaction
 * the sum of them. */
static void test_static_glued(void **state) {
  (void)state;
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  assert_ok(make_fpm("{plate: {point: [0, 0, 0.1], normal: [0, 0, -1]}, "
                     "displacement: {z: -0.01}, contact: glued}",
                     "static", &s, &sim));
  const fpm_model *m = sim->model;
  fpm_state *st = sim->state;
  const fpm_contact *c = m->contact;
  const long nd = 3 * m->n, np = c->pair_ptr[1];
  double ztop = 0;
  for (long i = 0; i < m->n; i++) ztop = fmax(ztop, m->x[3 * i + 2]);
  long top = 0, anchored = 0;
  for (long i = 0; i < m->n; i++) top += m->x[3 * i + 2] > ztop - 1e-12;
  for (long q = 0; q < np; q++) anchored += !isnan(st->contact[3 * q]);
  assert_int_equal(anchored, top);
  for (long i = 0; i < m->n; i++) /* the top 1 mm below the plate */
    st->u[3 * i + 2] = -0.001 * m->x[3 * i + 2] / ztop;
  unsigned char *let_go = calloc(np, 1);
  fpm_contact_release r;
  assert_int_equal(fpm_contact_release_fixed(m, st, 0, 0, let_go, &r), 0);
  fpm_contact_commit(m, st, 0, 0);
  memset(st->f, 0, nd * sizeof *st->f);
  fpm_contact_force_fixed(m, st, 0, 0);
  double R[3] = {0, 0, 0}, ksum = 0;
  fpm_contact_reaction(m, st, 1, R);
  for (long q = 0; q < np; q++) {
    if (isnan(st->contact[3 * q])) continue;
    ksum += c->pair_k[q];
    const long i = c->pair_point[q];
    assert_near(st->f[3 * i + 2], -c->pair_k[q] * 0.001, 1e-12 * c->pair_k[q]);
  }
  print_message("glued top: %ld points anchored at rest, none let go 1 mm "
                "off; reaction %.6g N (k sum x 1 mm %.6g N)\n",
                anchored, R[2], ksum * 0.001);
  assert_int_equal(r.first, -1);
  assert_near(R[2], ksum * 0.001, 1e-12 * ksum);
  free(let_go);
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
}

int main(void) {
  gmsh_testing_preload();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plate_frictionless),
      cmocka_unit_test(test_plate_sticking),
      cmocka_unit_test(test_plate_glued),
      cmocka_unit_test(test_sphere),
      cmocka_unit_test(test_keys),
      cmocka_unit_test(test_bad_keys),
      cmocka_unit_test(test_plate_inside),
      cmocka_unit_test(test_static_tangent),
      cmocka_unit_test(test_static_touch_release),
      cmocka_unit_test(test_static_glued),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
