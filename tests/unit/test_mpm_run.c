/* test_mpm_run: the explicit MPM backend's run: model, state and
 * workspace apart (the state alone resumes a run bit for bit), energy
 * booked by the stages, the time loop's observer and failure, and MUSL's
 * remap scattered by g2p equal to the bit to the remap on its own. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_testing.h"

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
  pm_test_write_file(*state, "gas-2d.yaml", GAS_2D, path);
  const char *gas[] = {"boundary=[{on: xmin, absorbing: true}, {on: xmax, "
                       "velocity: {x: 0}}]"};
  check_restart(path, 1, gas, 12, 10);
  /* Two solids, USF, fixed damping and a fixed step. */
  pm_test_write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
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

/* MUSL's remap scattered by g2p at the weights it has just used (the
 * pipeline's choice when no stage between them changes velocities), with
 * the grid velocity's and the grid update's node loops in the regions of
 * g2p and p2g (MPM_NODES_FUSED), and every stage on its own: the same
 * state to the bit after 15 steps, for two material groups, both shapes,
 * FLIP and PIC. */
static void test_fused_remap_same_bits(void **state) {
  char path[512];
  pm_test_write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
  static const char *const sets[][3] = {
      {"mpm.shape=quadratic", "mpm.flip=1", "mpm.update=musl"},
      {"mpm.shape=linear", "mpm.flip=0", "mpm.update=musl"},
  };
  for (int k = 0; k < 2; k++) {
    model a = make_model(path, 3, sets[k]);
    model b = make_model(path, 3, sets[k]);
    /* b: the remap as its own transfer, every node loop in its stage. */
    int fused = 0, nodes = 0;
    mpm_pipeline *pl = &b.model->pipeline;
    for (int j = 0; j < pl->n; j++) {
      nodes += (pl->stage[j].mode & MPM_NODES_FUSED) != 0;
      pl->stage[j].mode &= ~MPM_NODES_FUSED;
      if (strcmp(pl->stage[j].name, "g2p") == 0) {
        fused += pl->stage[j].mode == MPM_P2G_MOM;
        pl->stage[j].mode = 0;
      }
      if (strcmp(pl->stage[j].name, "remap") == 0) {
        fused += pl->stage[j].mode == 0;
        pl->stage[j].mode = MPM_P2G_MOM;
      }
    }
    assert_int_equal(fused, 2);
    assert_int_equal(nodes, 4); /* p2g, grid update, g2p, remap */
    for (int n = 0; n < 15; n++) {
      step(&a);
      step(&b);
    }
    assert_same_state(a.model, a.state, b.state);
    assert_memory_equal(a.work->nodes.mom, b.work->nodes.mom,
                        3 * sizeof(double) * a.model->grid.n_nodes);
    drop_model(&b);
    drop_model(&a);
  }
}

/* A step far above the stable one inverts particles: the run stops with
 * the step, time, stage, particle, positions and cause. */
static void test_unstable_message(void **state) {
  char path[512];
  pm_test_write_file(*state, "two-bodies.yaml", TWO_BODIES, path);
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

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_state_alone_resumes,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_stage_energy, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_solver_observer),
      cmocka_unit_test_setup_teardown(test_fused_remap_same_bits,
                                      pm_test_make_dir, pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_unstable_message, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
