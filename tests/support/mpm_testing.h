/* mpm_testing: what the MPM unit tests share: scenes, a model with its
 * state and workspace, and checks (include after cmocka.h). */
#ifndef MPM_TESTING_H
#define MPM_TESTING_H

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_shape.h"
#include "mpm_solver.h"
#include "mpm_state.h"
#include "mpm_test_arrays.h"
#include "mpm_transfer.h"
#include "pm_app.h"
#include "pm_run.h"
#include "pm_scene.h"
#include "pm_testing.h"

#define PI 3.14159265358979323846
#define EPS DBL_EPSILON
#define MINIMAL PM_TEST_DATA "/scenes/minimal-2d.yaml"

/* The MPM tests' one stream of uniform numbers in [0, 1). */
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static inline double uniform(void) { return pm_test_uniform(&rng); }

/* A scene's model, state and workspace. */
typedef struct {
  pm_scene *scene;
  mpm_model *model;
  mpm_state *state;
  mpm_work *work;
} model;

static inline model make_model(const char *path, int n,
                               const char *const *set) {
  model m = {NULL, NULL, NULL, NULL};
  assert_ok(pm_scene_load(path, n, set, &m.scene));
  assert_ok(mpm_model_create(m.scene, &m.model, &m.state));
  assert_ok(mpm_work_create(m.model, &m.work));
  return m;
}

static inline void drop_model(model *m) {
  mpm_work_destroy(m->work);
  mpm_state_destroy(m->state);
  mpm_model_destroy(m->model);
  pm_scene_destroy(m->scene);
}

static inline void step(model *m) {
  assert_ok(mpm_step(m->model, m->state, m->work));
}

/* Coordinates of grid node `node`. */
static inline void node_position(const mpm_grid *g, long node, double x[3]) {
  long ijk[3] = {node % g->nn[0], (node / g->nn[0]) % g->nn[1],
                 node / (g->nn[0] * g->nn[1])};
  for (int c = 0; c < 3; c++) x[c] = g->origin[c] + ijk[c] * g->h;
}

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

static inline const mpm_stage *find_stage(const mpm_model *m,
                                          const char *name) {
  for (int k = 0; k < m->pipeline.n; k++)
    if (strcmp(m->pipeline.stage[k].name, name) == 0)
      return &m->pipeline.stage[k];
  return NULL;
}

static inline bool has_stage(const model *m, const char *name) {
  return find_stage(m->model, name) != NULL;
}

/* The plan's text, for searching. */
static inline char *plan_text(const pm_scene *s) {
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  assert_non_null(f);
  assert_ok(pm_plan_scene(s, f));
  assert_int_equal(fclose(f), 0);
  return text;
}

static inline void assert_contains(const char *text, const char *frag) {
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
static inline bool never_runs(const mpm_model *m, mpm_stage_fn fn) {
  for (int k = 0; k < m->pipeline.n; k++)
    if (m->pipeline.stage[k].run == fn ||
        m->pipeline.stage[k].after_update == fn)
      return false;
  return true;
}

#endif
