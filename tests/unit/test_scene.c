/* test_scene: scene loading against the schema, located error messages for
 * malformed scenes, --set overrides, ramps and method names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fpm_scene.h"
#include "pm_app.h"
#include "pm_scene.h"
#include "pm_testing.h"

#define SCENES PM_TEST_DATA "/scenes/"
#define F2 SCENES "f2-unconstrained-compression.yaml"
#define MINIMAL SCENES "minimal-2d.yaml"

static pm_scene *load_ok(const char *path, int n, const char *const *set) {
  pm_scene *s = NULL;
  pm_err err = pm_scene_load(path, n, set, &s);
  if (err != PM_SUCCESS)
    fail_msg("loading %s failed: %s", path, pm_error_message());
  assert_non_null(s);
  return s;
}

/* Loading fails with code and a message containing every fragment. */
static void load_fails(const char *path, int n, const char *const *set,
                       pm_err code, const char *frag1, const char *frag2) {
  pm_scene *s = (pm_scene *)&s; /* must be reset to NULL */
  pm_error_clear();
  assert_int_equal(pm_scene_load(path, n, set, &s), code);
  assert_null(s);
  const char *msg = pm_error_message();
  if (frag1 && !strstr(msg, frag1))
    fail_msg("message \"%s\" lacks \"%s\"", msg, frag1);
  if (frag2 && !strstr(msg, frag2))
    fail_msg("message \"%s\" lacks \"%s\"", msg, frag2);
}

static double eval(const pm_expr *e, double x, double y, double z, double t) {
  assert_non_null(e);
  return pm_expr_eval(e, x, y, z, t);
}

static void test_f2_values(void **state) {
  (void)state;
  pm_scene *s = load_ok(F2, 0, NULL);
  assert_string_equal(s->path, F2);
  assert_non_null(strstr(s->text, "name: f2-unconstrained-compression\n"));
  assert_non_null(strstr(s->text, "# F2: unconstrained"));
  assert_string_equal(s->name, "f2-unconstrained-compression");
  assert_string_equal(s->method, "fpm");
  assert_string_equal(s->backend->method, "fpm");
  assert_int_equal(s->dimension, 3);
  for (int c = 0; c < 3; c++) {
    assert_near(s->box_min[c], 0.0, 0.0);
    assert_near(s->box_max[c], 0.1, 1e-15);
  }
  assert_near(s->mesh_size, 1.09e-2, 1e-15);

  assert_int_equal(s->n_materials, 1);
  assert_string_equal(s->materials[0].name, "gel");
  assert_string_equal(s->materials[0].mat.model->name, "neo-hookean");
  assert_near(s->materials[0].mat.density, 1000, 0);
  assert_near(s->materials[0].mat.youngs_modulus, 3000, 0);
  assert_near(s->materials[0].mat.poisson_ratio, 0.495, 1e-15);
  assert_int_equal(s->materials[0].mark.line, 8);
  assert_int_equal(s->materials[0].mark.col, 5);

  assert_int_equal(s->n_bodies, 1);
  assert_int_equal(s->bodies[0].material, 0);
  assert_null(s->bodies[0].region);

  assert_int_equal(s->n_bcs, 5);
  const pm_face faces[] = {PM_FACE_XMIN, PM_FACE_YMIN, PM_FACE_ZMIN,
                           PM_FACE_ZMAX, PM_FACE_XMAX};
  for (int i = 0; i < 5; i++) {
    assert_int_equal(s->bcs[i].face, faces[i]);
    assert_int_equal(s->bcs[i].mark.line, 11 + i);
    assert_int_equal(s->bcs[i].mark.col, 5);
  }
  for (int i = 0; i < 3; i++) {
    assert_int_equal(s->bcs[i].disp_mask, 1u << i);
    assert_int_equal(s->bcs[i].traction_mask, 0);
    assert_near(eval(s->bcs[i].disp[i], 1, 2, 3, 4), 0.0, 0.0);
    assert_int_equal(s->bcs[i].ramp, PM_RAMP_SMOOTH);
    assert_near(s->bcs[i].ramp_time, 1.0, 0); /* time.ramp = end/2 */
  }
  assert_int_equal(s->bcs[3].disp_mask, 4u);
  assert_null(s->bcs[3].disp[0]);
  assert_near(eval(s->bcs[3].disp[2], 0, 0, 0.1, 0), -0.04, 1e-15);
  assert_int_equal(s->bcs[3].ramp, PM_RAMP_SMOOTH);
  assert_near(s->bcs[3].ramp_time, 0.5, 0);
  assert_int_equal(s->bcs[4].disp_mask, 0);
  assert_int_equal(s->bcs[4].traction_mask, 1u);
  assert_near(eval(s->bcs[4].traction[0], 0, 0, 0, 0.5), 50, 1e-12);
  assert_int_equal(s->bcs[4].ramp, PM_RAMP_NONE);

  assert_near(fpm_scene_options(s)->penalty, 20, 0);
  assert_near(s->time.end, 2.0, 0);
  assert_near(s->time.dt, 0, 0);
  assert_near(s->time.dt_safety, 0.9, 0);
  assert_near(s->time.ramp, 1.0, 0);
  assert_int_equal(s->time.max_steps, 0);
  assert_int_equal(s->time.qs, PM_QS_DYNAMIC_RELAXATION);
  assert_near(s->time.qs_tolerance, 1e-8, 0);
  assert_near(s->time.qs_damping, 0, 0);
  assert_int_equal(s->output.every, 50);
  assert_int_equal(s->output.fields, PM_FIELD_DISPLACEMENT | PM_FIELD_VELOCITY |
                                         PM_FIELD_STRESS |
                                         PM_FIELD_STRAIN_ENERGY_DENSITY |
                                         PM_FIELD_JACOBIAN | PM_FIELD_FORCE);
  assert_int_equal(s->reference_mask, 4u);
  assert_null(s->reference[0]);
  assert_near(eval(s->reference[2], 0, 0, 0.1, 0), -0.04, 1e-15);
  assert_true(pm_expr_uses(s->reference[2], 'z'));
  pm_scene_destroy(s);
}

static void test_defaults(void **state) {
  (void)state;
  pm_scene *s = load_ok(MINIMAL, 0, NULL);
  assert_string_equal(s->method, "mpm");
  assert_int_equal(s->dimension, 2);
  assert_near(s->box_max[0], 1.0, 0);
  assert_near(s->box_max[1], 0.5, 0);
  assert_string_equal(s->materials[0].mat.model->name, "linear-elastic");
  assert_int_equal(s->n_bodies, 1);
  assert_int_equal(s->bodies[0].material, 0);
  assert_null(s->bodies[0].region);
  assert_int_equal(s->n_bcs, 0);
  /* the default formulation: quadratic jump, small penalty (the averaged
   * volume is test_volumetric_default's) */
  assert_int_equal(fpm_scene_options(s)->formulation, FPM_FORMULATION_DEFAULT);
  assert_int_equal(fpm_scene_options(s)->jump, FPM_JUMP_QUADRATIC);
  assert_near(fpm_scene_options(s)->penalty, 0.05, 0);
  assert_near(s->time.dt, 0, 0);
  assert_near(s->time.dt_safety, 0.5, 0); /* the default of method mpm */
  assert_near(s->time.ramp, 0.5, 0);
  assert_int_equal(s->time.max_steps, 0);
  assert_int_equal(s->time.qs, PM_QS_NONE);
  assert_near(s->time.qs_tolerance, 1e-8, 0);
  assert_int_equal(s->output.every, 100);
  assert_int_equal(s->output.fields, PM_FIELD_DISPLACEMENT | PM_FIELD_STRESS |
                                         PM_FIELD_STRAIN_ENERGY_DENSITY);
  assert_int_equal(s->reference_mask, 0);
  pm_scene_destroy(s);
}

static void test_malformed(void **state) {
  (void)state;
  static const struct {
    const char *file, *where, *what;
  } cases[] = {
      {"bad-unknown-key.yaml", "bad-unknown-key.yaml:9:3: time.end_time: ",
       "unknown key (expected one of end, dt, dt_safety, dt_rule, ramp, "
       "max_steps, "
       "quasi_static)"},
      {"bad-wrong-type.yaml", "bad-wrong-type.yaml:9:14: materials.0.density: ",
       "expected a number > 0, got heavy"},
      {"bad-mesh-size.yaml",
       "bad-mesh-size.yaml:6:14: discretization.mesh_size: ",
       "expected a number > 0, got -0.01"},
      {"bad-poisson.yaml", "bad-poisson.yaml:7:89: materials.0.poisson_ratio",
       "expected a number in (-1, 0.5), got 0.5"},
      {"bad-material-name.yaml",
       "bad-material-name.yaml:9:16: bodies.0.material: ",
       "expected a material name (gel), got rubber"},
      {"bad-face-2d.yaml",
       "bad-face-2d.yaml:10:10: boundary.1.on: ", "got zmax"},
      {"bad-missing-key.yaml",
       "bad-missing-key.yaml:9:3: time.end: ", "missing required key"},
      {"bad-expression.yaml",
       "bad-expression.yaml:11:8: reference.displacement.z: ",
       "invalid expression \"-0.4*q\": unknown variable q (allowed: x, y, z, "
       "t)"},
      {"bad-syntax.yaml", "bad-syntax.yaml:3:", "YAML syntax error"},
  };
  char path[512];
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    snprintf(path, sizeof path, SCENES "%s", cases[i].file);
    load_fails(path, 0, NULL, PM_ERR_SCENE, cases[i].where, cases[i].what);
  }
}

static void test_missing_file(void **state) {
  (void)state;
  load_fails(
      SCENES "no-such-scene.yaml", 0, NULL, PM_ERR_IO,
      "cannot open scene " SCENES "no-such-scene.yaml: ", "No such file");
}

static void test_overrides(void **state) {
  (void)state;
  const char *set[] = {
      "discretization.mesh_size=8.02e-3", /* replace */
      "time.dt=1e-3",                     /* add an absent key */
      "boundary.3.displacement.z=-0.06",  /* index a list */
      "time.quasi_static.tolerance=1e-9", /* nested */
      "boundary.4.traction.x=2e3",        /* number for an expression */
      "output.fields=[force, jacobian]",  /* YAML flow value */
      "materials.0.poisson_ratio=0.3",    /* inside a flow mapping */
  };
  pm_scene *s = load_ok(F2, 7, set);
  /* The overrides are kept, and written into the text stored with the
   * results, so the run can be reproduced from its output. */
  assert_int_equal(s->n_overrides, 7);
  assert_string_equal(s->overrides[2], "boundary.3.displacement.z=-0.06");
  assert_non_null(strstr(s->text, "#   --set time.dt=1e-3\n"));
  assert_near(s->mesh_size, 8.02e-3, 1e-18);
  assert_near(s->time.dt, 1e-3, 0);
  assert_near(eval(s->bcs[3].disp[2], 0, 0, 0.1, 0), -0.06, 1e-15);
  assert_near(s->time.qs_tolerance, 1e-9, 0);
  assert_near(eval(s->bcs[4].traction[0], 0, 0, 0, 1), 2e3, 0);
  assert_int_equal(s->output.fields, PM_FIELD_FORCE | PM_FIELD_JACOBIAN);
  assert_near(s->materials[0].mat.poisson_ratio, 0.3, 0);
  /* The stored text is the file's. */
  assert_non_null(strstr(s->text, "mesh_size: 1.09e-2"));
  pm_scene_destroy(s);

  /* Absent parents are created; a list grows by one at index n. */
  const char *grow[] = {
      "time.quasi_static.method=damping",
      "time.quasi_static.damping=3",
      "fpm.penalty=50",
      "bodies=[{material: rubber, region: \"x - 0.5\"}]",
      "boundary=[]",
      "boundary.0.on=xmax",
      "boundary.0.velocity.x=100*t",
      "reference.displacement.x=0.1*x",
  };
  s = load_ok(MINIMAL, 8, grow);
  assert_int_equal(s->time.qs, PM_QS_DAMPING);
  assert_near(s->time.qs_damping, 3, 0);
  assert_near(fpm_scene_options(s)->penalty, 50, 0);
  assert_near(eval(s->bodies[0].region, 0.75, 0, 0, 0), 0.25, 1e-15);
  assert_int_equal(s->n_bcs, 1);
  assert_int_equal(s->bcs[0].face, PM_FACE_XMAX);
  assert_int_equal(s->bcs[0].mark.line, 0); /* not from the file */
  assert_near(eval(s->bcs[0].velocity[0], 0, 0, 0, 2), 200, 1e-12);
  assert_int_equal(s->reference_mask, 1u);
  pm_scene_destroy(s);
}

static void bad_override(const char *path, const char *set, const char *frag1,
                         const char *frag2) {
  load_fails(path, 1, &set, PM_ERR_SCENE, frag1, frag2);
}

static void test_bad_overrides(void **state) {
  (void)state;
  bad_override(F2, "time.end_tim=3",
               "--set time.end_tim=3: unknown key (expected one of end,", NULL);
  bad_override(
      F2, "discretization.mesh_size=-1",
      "--set discretization.mesh_size=-1: ", "expected a number > 0, got -1");
  bad_override(F2, "time.dt=soon",
               "--set time.dt=soon: ", "expected a number >= 0, got soon");
  bad_override(F2, "boundary.9.on=xmin", "--set boundary.9.on=xmin: ",
               "index 9 out of range (boundary has 5 entries)");
  bad_override(F2, "materials.first.name=a",
               "--set materials.first.name=a: ", "expected a list index");
  bad_override(F2, "name.first=a", "--set name.first=a: unknown key", NULL);
  bad_override(F2, "mesh_size", "--set mesh_size: expected KEY=VALUE", NULL);
  bad_override(F2, "boundary.4.traction.x=2*w", "--set boundary.4.traction.x",
               "unknown variable w");
  bad_override(F2, "method=sph", "--set method=sph: ",
               "expected one of fpm, mpm, mpm-implicit, got sph");
  bad_override(MINIMAL, "boundary.0.on=xmin",
               "--set boundary.0.on=xmin: ", "boundary is not in the scene");
  /* A value nested past any key's needs is refused as such, not as a
   * failed allocation. */
  char deep[128];
  snprintf(deep, sizeof deep, "materials.0.name=%.40s%.40s",
           "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[",
           "]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]");
  bad_override(F2, deep, "--set materials.0.name=[[[",
               "]]]: expected a value nested at most 32 levels deep");
  /* A file value that an override makes invalid is reported at the file. */
  bad_override(F2, "dimension=2",
               "f2-unconstrained-compression.yaml:5:21: domain.box.min: ",
               "expected 2 numbers (dimension 2), got 3");
}

/* A parameter the model does not take, or one it needs and lacks, fails at
 * file:line:col naming the keys it expects; so do sections' keys and what
 * a method cannot honour. */
static void test_model_keys_and_methods(void **state) {
  (void)state;
  static const struct {
    const char *set, *frag1, *frag2;
  } cases[] = {
      {"materials.0={name: gel, model: mooney-rivlin, density: 1000, c10: 300, "
       "c01: 100, youngs_modulus: 3}",
       "materials.0.youngs_modulus: unknown key (expected one of name, model, "
       "density, artificial_viscosity, damage, and model mooney-rivlin's c10, "
       "c01, "
       "bulk_modulus)",
       NULL},
      {"materials.0={name: gel, model: mooney-rivlin, density: 1000, c10: "
       "300, c01: 100}",
       "materials.0.bulk_modulus: missing required key", NULL},
      {"materials.0={name: gel, model: neo-hookean, density: 1000, "
       "youngs_modulus: 3000}",
       "--set materials.0={name: gel, model: neo-hookean, density: 1000, "
       "youngs_modulus: 3000}: missing required key poisson_ratio",
       "takes youngs_modulus and poisson_ratio, or shear_modulus and "
       "bulk_modulus"},
      {"materials.0={name: gel, model: ogden, density: 1000, mu: [1, 2], "
       "alpha: [2], bulk_modulus: 10}",
       "materials.0.alpha: ", "expected as many alpha as mu"},
      {"materials.0={name: gel, model: rubbery, density: 1000}",
       "materials.0.model: expected one of neo-hookean, neo-hookean-log, "
       "mooney-rivlin, ogden, holzapfel-gasser-ogden, linear-elastic, fluid, "
       "got rubbery",
       NULL},
      {"materials.0={name: gel, model: holzapfel-gasser-ogden, density: "
       "1000, shear_modulus: 1000, k1: 1000, k2: 2, bulk_modulus: 1e5}",
       "bodies.0: missing required key fibres", "needs 1 to 2 fibre"},
      {"bodies.0.fibres=[[1, 0, 0]]", "--set bodies.0.fibres=[[1, 0, 0]]: ",
       "expected no fibres (model neo-hookean of material gel takes none)"},
      {"fpm.cells=delaunay", "--set fpm.cells=delaunay: ",
       "expected one of median-dual, voronoi, got delaunay"},
      {"fpm.flux=symmetric", "--set fpm.flux=symmetric: ",
       "expected one of iipg, sipg, got symmetric"},
      {"boundary.0.at=[0, 0, 0]",
       "--set boundary.0.at=[0, 0, 0]: ", "expected at or on, got both"},
      {"boundary.0.curve=x*t", "--set boundary.0.curve=x*t: ",
       "expected a function of t only, got x*t, which uses x"},
      {"body_curve=absent.csv",
       "--set body_curve=absent.csv: ", "cannot open load curve"},
      {"boundary.0.pressure=p",
       "--set boundary.0.pressure=p: ", "unknown variable p"},
      {"boundary.0.velocity.y=1",
       "--set boundary.0.velocity.y=1: boundary.0.velocity",
       "expected displacement or traction (method fpm), got velocity"},
      {"boundary.0.on=top", "--set boundary.0.on=top: ",
       "expected a face of domain.box (xmin, xmax, ymin, ymax, zmin, zmax), a "
       "region, or the name of a physical surface of a gmsh body, got top"},
      {"boundary.0.region=x",
       "--set boundary.0.region=x: ", "expected on or region, got both"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    load_fails(F2, 1, &cases[i].set, PM_ERR_SCENE, cases[i].frag1,
               cases[i].frag2);
}

/* The new vocabulary reads: a model's keys (both forms of the elastic
 * pair, lists), fibres normalized, a region condition, a body region of
 * the word domain, the sections' defaults and presence queries. */
static void test_vocabulary(void **state) {
  (void)state;
  const char *set[] = {
      "materials.0={name: t, model: holzapfel-gasser-ogden, density: 1000, "
      "shear_modulus: 1000, k1: 500, k2: 2, bulk_modulus: 1e5}",
      "materials.1={name: gel, model: neo-hookean-log, density: 900, "
      "shear_modulus: 1000, bulk_modulus: 2000}",
      "materials.2={name: rubber, model: ogden, density: 1100, mu: [1500, "
      "-20], alpha: [1.3, -2], bulk_modulus: 1e5}",
      "bodies=[{material: t, region: domain, fibres: [[3, 4, 0], [0, 0, 2]]}, "
      "{material: rubber, sphere: {center: [0.05, 0.05, 0.05], radius: "
      "0.01}}]",
      "boundary.1={region: \"0.001 - y\", displacement: {y: 0}}",
  };
  pm_scene *s = load_ok(F2, 5, set);
  const pm_material *t = &s->materials[0].mat, *g = &s->materials[1].mat;
  assert_string_equal(t->model->name, "holzapfel-gasser-ogden");
  assert_near(t->shear_modulus, 1000, 0);
  /* mu and K given: E = 9 K mu / (3 K + mu), nu = (3K - 2mu)/(2(3K + mu)) */
  assert_near(g->youngs_modulus, 9 * 2000 * 1000 / 7000.0, 1e-10);
  assert_near(g->poisson_ratio, 4000 / 14000.0, 1e-15);
  assert_near(s->materials[2].mat.shear_modulus, (1500 * 1.3 + 20 * 2) / 2,
              1e-10);
  assert_int_equal(s->bodies[0].shape, PM_BODY_DOMAIN);
  assert_int_equal(s->bodies[0].point.n_fibres, 2);
  assert_near(s->bodies[0].point.fibres[0][0], 0.6, 1e-15);
  assert_near(s->bodies[0].point.fibres[0][1], 0.8, 1e-15);
  assert_near(s->bodies[0].point.fibres[1][2], 1, 0);
  assert_int_equal(s->bodies[1].shape, PM_BODY_SPHERE);
  assert_int_equal(s->bcs[1].on, PM_ON_REGION);
  assert_near(eval(s->bcs[1].region, 0, 0, 0, 0), 0.001, 1e-18);
  assert_int_equal(s->bcs[0].on, PM_ON_FACE);
  assert_int_equal(s->bcs[0].face, PM_FACE_XMIN);
  assert_true(pm_scene_has(s, "fpm.formulation"));
  assert_false(pm_scene_has(s, "fpm.penalty"));
  assert_false(pm_scene_has(s, "fpm.flux"));
  const fpm_options *o = fpm_scene_options(s);
  /* formulation: paper sets the keys the scene does not give */
  assert_int_equal(o->formulation, FPM_FORMULATION_PAPER);
  assert_int_equal(o->jump, FPM_JUMP_LINEAR);
  assert_near(o->penalty, 20, 0);
  assert_int_equal(o->flux, FPM_FLUX_IIPG);
  assert_string_equal(o->cells, "median-dual");
  pm_scene_destroy(s);
}

/* fpm.volumetric: averaged is the default where it applies; the paper's
 * formulation, the SIPG flux and a model without the volumetric split get
 * the standard term unless the scene asks, and an asked averaged volume
 * that cannot be honoured is refused at the key. */
static void test_volumetric_default(void **state) {
  (void)state;
  const char *def[] = {"fpm.formulation=default"};
  pm_scene *s = load_ok(F2, 1, def);
  assert_int_equal(fpm_scene_options(s)->volumetric, FPM_VOLUMETRIC_AVERAGED);
  pm_scene_destroy(s);
  s = load_ok(F2, 0, NULL); /* the scene's formulation: paper */
  assert_int_equal(fpm_scene_options(s)->volumetric, FPM_VOLUMETRIC_STANDARD);
  pm_scene_destroy(s);
  const char *sipg[] = {"fpm.formulation=default", "fpm.flux=sipg"};
  s = load_ok(F2, 2, sipg);
  assert_int_equal(fpm_scene_options(s)->volumetric, FPM_VOLUMETRIC_STANDARD);
  pm_scene_destroy(s);
  const char *linear[] = {"fpm.formulation=default",
                          "materials.0={name: gel, model: linear-elastic, "
                          "density: 1000, youngs_modulus: 3000, "
                          "poisson_ratio: 0.3}"};
  s = load_ok(F2, 2, linear);
  assert_int_equal(fpm_scene_options(s)->volumetric, FPM_VOLUMETRIC_STANDARD);
  pm_scene_destroy(s);
  const char *asked[] = {"fpm.formulation=default", "fpm.flux=sipg",
                         "fpm.volumetric=averaged"};
  load_fails(F2, 3, asked, PM_ERR_SCENE, "fpm.volumetric",
             "expected standard with fpm.flux sipg");
}

static void test_ramp_and_names(void **state) {
  (void)state;
  assert_near(pm_ramp_factor(PM_RAMP_NONE, 1, 0), 1, 0);
  assert_near(pm_ramp_factor(PM_RAMP_LINEAR, 2, 0.5), 0.25, 1e-15);
  assert_near(pm_ramp_factor(PM_RAMP_LINEAR, 2, 3), 1, 0);
  assert_near(pm_ramp_factor(PM_RAMP_SMOOTH, 2, 0), 0, 0);
  assert_near(pm_ramp_factor(PM_RAMP_SMOOTH, 2, 1), 0.5, 1e-15);
  assert_near(pm_ramp_factor(PM_RAMP_SMOOTH, 2, 2), 1, 0);
  assert_near(pm_ramp_factor(PM_RAMP_SMOOTH, 2, -1), 0, 0);
  /* C2: the slope is zero at both ends. */
  double h = 1e-6;
  assert_true(pm_ramp_factor(PM_RAMP_SMOOTH, 1, h) < 1e-15);
  assert_true(1 - pm_ramp_factor(PM_RAMP_SMOOTH, 1, 1 - h) < 1e-15);
}

/* A 2-D MPM scene as text, with line 9 "  end: END" and line 11 the
 * condition on xmin ("  - {on: xmin, displacement: {x: DISP}}"). */
static void scene_text(char *buf, size_t size, const char *end,
                       const char *disp) {
  snprintf(buf, size,
           "name: t\n"
           "method: mpm\n"
           "dimension: 2\n"
           "domain: {box: {min: [0, 0], max: [1, 0.5]}}\n"
           "discretization: {mesh_size: 0.1}\n"
           "materials:\n"
           "  - {name: r, model: linear-elastic, density: 1100, "
           "youngs_modulus: 1e6, poisson_ratio: 0.3}\n"
           "time:\n"
           "  end: %s\n"
           "boundary:\n"
           "  - {on: xmin, displacement: {x: %s}}\n",
           end, disp);
}

/* Loading text fails with PM_ERR_SCENE and a message containing frag. */
static void text_fails(const char *text, int n, const char *const *set,
                       const char *frag) {
  pm_scene *s = (pm_scene *)&s;
  pm_error_clear();
  assert_int_equal(
      pm_scene_load_text(text, strlen(text), "mem/t.yaml", n, set, &s),
      PM_ERR_SCENE);
  assert_null(s);
  if (!strstr(pm_error_message(), frag))
    fail_msg("message \"%s\" lacks \"%s\"", pm_error_message(), frag);
}

/* NaN and Inf, however written, are refused at FILE:LINE:COL (or at the
 * --set override) naming the key and what it takes, as are constant
 * expressions whose value is not finite. */
static void test_not_finite(void **state) {
  (void)state;
  char text[1024];
  scene_text(text, sizeof text, "0.5", "0");
  pm_scene *s = NULL;
  assert_int_equal(
      pm_scene_load_text(text, strlen(text), "mem/t.yaml", 0, NULL, &s),
      PM_SUCCESS);
  assert_string_equal(s->path, "mem/t.yaml");
  assert_near(s->time.end, 0.5, 0);
  assert_string_equal(pm_expr_origin(s->bcs[0].disp[0]),
                      "mem/t.yaml:11:34: boundary.0.displacement.x");
  pm_scene_destroy(s);

  static const struct {
    const char *end, *disp, *what;
  } yaml[] = {
      {".nan", "0",
       "mem/t.yaml:9:8: time.end: expected a number > 0, got .nan (not a "
       "number; numbers must be finite)"},
      {"nan", "0",
       "mem/t.yaml:9:8: time.end: expected a number > 0, got nan "
       "(not a number; "},
      {".inf", "0",
       "mem/t.yaml:9:8: time.end: expected a number > 0, got "
       ".inf (infinite; "},
      {"-inf", "0",
       "mem/t.yaml:9:8: time.end: expected a number > 0, got "
       "-inf (infinite; "},
      {"1e999", "0",
       "mem/t.yaml:9:8: time.end: expected a number > 0, got "
       "1e999 (too large for a double; numbers must be finite)"},
      {"1", "1/0",
       "mem/t.yaml:11:34: boundary.0.displacement.x: invalid expression "
       "\"1/0\": its value is inf (expected a finite value)"},
      {"1", "sqrt(-1)",
       "mem/t.yaml:11:34: boundary.0.displacement.x: invalid expression "
       "\"sqrt(-1)\": its value is nan"},
      {"1", ".nan",
       "mem/t.yaml:11:34: boundary.0.displacement.x: invalid "
       "expression \".nan\": not a number"},
      {"1", "-0.1*t*1e999",
       "mem/t.yaml:11:34: boundary.0.displacement.x: "
       "invalid expression \"-0.1*t*1e999\": syntax "
       "error at character 8: number too large"},
  };
  for (size_t i = 0; i < sizeof yaml / sizeof yaml[0]; i++) {
    scene_text(text, sizeof text, yaml[i].end, yaml[i].disp);
    text_fails(text, 0, NULL, yaml[i].what);
  }

  /* Lists of numbers and integers, and expressions, by override. */
  static const struct {
    const char *set, *what;
  } sets[] = {
      {"domain.box.max=[1, .Inf]",
       "--set domain.box.max=[1, .Inf]: domain.box.max.1: expected a number, "
       "got .Inf (infinite; numbers must be finite)"},
      {"output.every=.inf", "--set output.every=.inf: expected an integer > "
                            "0, got .inf (infinite; "},
      {"materials.0.density=-1e400",
       "--set materials.0.density=-1e400: expected a number > 0, got -1e400 "
       "(too large for a double; "},
      {"gravity=[0, NaN]", "--set gravity=[0, NaN]: gravity.1: expected a "
                           "number, got NaN (not a number; "},
      {"boundary.0.displacement.x=log(0)",
       "--set boundary.0.displacement.x=log(0): invalid expression "
       "\"log(0)\": its value is -inf"},
  };
  scene_text(text, sizeof text, "1", "0");
  for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++)
    text_fails(text, 1, &sets[i].set, sets[i].what);
  /* A variable expression is the run's to check. */
  const char *var = "boundary.0.displacement.x=sqrt(0.5 - t)";
  s = NULL;
  assert_int_equal(
      pm_scene_load_text(text, strlen(text), "mem/t.yaml", 1, &var, &s),
      PM_SUCCESS);
  assert_string_equal(pm_expr_origin(s->bcs[0].disp[0]),
                      "--set boundary.0.displacement.x=sqrt(0.5 - t)");
  pm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_f2_values),
      cmocka_unit_test(test_defaults),
      cmocka_unit_test(test_volumetric_default),
      cmocka_unit_test(test_malformed),
      cmocka_unit_test(test_missing_file),
      cmocka_unit_test(test_overrides),
      cmocka_unit_test(test_bad_overrides),
      cmocka_unit_test(test_model_keys_and_methods),
      cmocka_unit_test(test_vocabulary),
      cmocka_unit_test(test_ramp_and_names),
      cmocka_unit_test(test_not_finite),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
