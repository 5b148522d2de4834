/* fpm_testing: what the FPM unit tests share (test_fpm, test_fpm_tangent):
 * the F2 cube fixture, the gel in every solid model, a smooth-plus-rough
 * deformation.  Include after cmocka.h. */
#ifndef FPM_TESTING_H
#define FPM_TESTING_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_model.h"
#include "fpm_scene.h"
#include "pm_keys.h"
#include "gm_dual.h"

typedef struct {
  gm_mesh *mesh;
  gm_dual *dual;
  pm_scene scene;
  fpm_options opt;
  pm_scene_material mat;
  pm_scene_body body;
  pm_scene_bc bcs[4];
} fixture;

static inline fixture *fixture_new(int dim, double h, double penalty,
                                   bool f2_bcs) {
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

static inline void fixture_free(fixture *fx) {
  for (int b = 0; b < 4; b++)
    for (int c = 0; c < 3; c++) pm_expr_destroy(fx->bcs[b].disp[c]);
  gm_dual_destroy(fx->dual);
  gm_mesh_destroy(fx->mesh);
  free(fx);
}

/* The model of the fixture's scene and a state for it. */
static inline void fixture_model(fixture *fx, fpm_model **m, fpm_state **st) {
  assert_int_equal(
      fpm_model_create(&fx->scene, &fx->opt, fx->mesh, fx->dual, m),
      PM_SUCCESS);
  assert_int_equal(fpm_state_create(*m, st), PM_SUCCESS);
}

/* The F2 gel in every solid model of the table, with the same small-strain
 * moduli (mu = 1003.3 Pa, K = 1e5 Pa); the fibred model gets one family
 * along x, so its lateral stretches differ. */
static inline void gel_model(const char *model, pm_scene_material *out,
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

/* A smooth finite deformation u_a = smooth x_(a+1) x_a / 0.1 plus a rough
 * perturbation rough r (r uniform in [-1/2, 1/2], a fixed sequence from
 * seed), into u; d (may be NULL) receives r. */
static inline void smooth_plus_rough(const fpm_model *m,
                                     unsigned long long seed, double smooth,
                                     double rough, double *u, double *d) {
  for (long i = 0; i < 3 * m->n; i++) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    double r = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
    const double *x = m->x + 3 * (i / 3);
    u[i] = smooth * x[(i + 1) % 3] * x[i % 3] / 0.1 + rough * r;
    if (d) d[i] = r;
  }
}

/* The fixture's options set to the fpm section's defaults (the default
 * formulation, as the key table gives it: a scene without fpm: keys). */
static inline void fixture_defaults(fixture *fx) {
  for (const pm_key *k = fpm_section.keys; k->name; k++) {
    if (!strcmp(k->name, "penalty")) fx->opt.penalty = atof(k->def);
    if (!strcmp(k->name, "boundary_penalty"))
      fx->opt.boundary_penalty = atof(k->def);
    if (!strcmp(k->name, "stiffening")) fx->opt.stiffening = atof(k->def);
    if (!strcmp(k->name, "volume_penalty"))
      fx->opt.volume_penalty = atof(k->def);
    if (!strcmp(k->name, "stiffening_jump"))
      fx->opt.stiffening_jump =
          strcmp(k->def, "quadratic") ? FPM_JUMP_LINEAR : FPM_JUMP_QUADRATIC;
    if (!strcmp(k->name, "jump"))
      fx->opt.jump =
          strcmp(k->def, "quadratic") ? FPM_JUMP_LINEAR : FPM_JUMP_QUADRATIC;
    if (!strcmp(k->name, "flux"))
      fx->opt.flux = strcmp(k->def, "sipg") ? FPM_FLUX_IIPG : FPM_FLUX_SIPG;
  }
}

/* A share's force on its own points is the whole model's bit for bit: f,
 * P and J of each own point of share s (its state ss) against the whole
 * model's state st. */
static inline void assert_share_is_whole(const fpm_model *s,
                                         const fpm_state *ss,
                                         const fpm_state *st) {
  for (long i = 0; i < s->n_own; i++) {
    const long g = s->gid[i];
    assert_memory_equal(ss->f + 3 * i, st->f + 3 * g, 3 * sizeof(double));
    assert_memory_equal(ss->P + 9 * i, st->P + 9 * g, 9 * sizeof(double));
    assert_memory_equal(ss->J + i, st->J + g, sizeof(double));
  }
}

/* |K d - (f(u0 + eps d) - f(u0 - eps d)) / 2 eps| / |K d| at the state
 * u0 = smooth_plus_rough(seed, smooth 0.2, rough 1e-3), d its rough part,
 * eps = 1e-6: how far fpm_force_linear is from the force's derivative. */
static inline double linearisation_error(const fpm_model *m, fpm_state *st,
                                         unsigned long long seed) {
  fpm_linear *lin;
  assert_int_equal(fpm_linear_create(m, &lin), PM_SUCCESS);
  const long nd = 3 * m->n;
  double *u0 = calloc(nd, sizeof *u0), *d = calloc(nd, sizeof *d),
         *kd = calloc(nd, sizeof *kd), *fp = calloc(nd, sizeof *fp);
  smooth_plus_rough(m, seed, 0.2, 1e-3, u0, d);
  memcpy(st->u, u0, nd * sizeof *u0);
  assert_int_equal(fpm_force(m, st), -1);
  fpm_linear_prepare(m, st, lin);
  fpm_force_linear(m, lin, d, kd);
  const double eps = 1e-6;
  for (long i = 0; i < nd; i++) st->u[i] = u0[i] + eps * d[i];
  assert_int_equal(fpm_force(m, st), -1);
  memcpy(fp, st->f, nd * sizeof *fp);
  for (long i = 0; i < nd; i++) st->u[i] = u0[i] - eps * d[i];
  assert_int_equal(fpm_force(m, st), -1);
  double err = 0, norm = 0;
  for (long i = 0; i < nd; i++) {
    const double c = (fp[i] - st->f[i]) / (2 * eps);
    err += (c - kd[i]) * (c - kd[i]);
    norm += kd[i] * kd[i];
  }
  free(u0);
  free(d);
  free(kd);
  free(fp);
  fpm_linear_destroy(lin);
  return sqrt(err / norm);
}

#endif
