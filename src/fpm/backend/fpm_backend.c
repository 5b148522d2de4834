/* fpm_backend: FPM's entry of the backend table: the simulation of a scene
 * set up (on one process, or every rank's share), its checkpoint, and the
 * table naming the run (fpm_backend_run.c), what the run driver reads
 * (fpm_backend_figures.c) and the plan (fpm_backend_plan.c). */
#include "fpm_backend.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend_impl.h"
#include "fpm_contact.h"
#include "fpm_estimate.h"
#include "fpm_gfd.h"
#include "fpm_grade.h"
#include "fpm_par.h"
#include "fpm_scene.h"
#include "gm_cells.h"
#include "pm_interrupt.h"
#include "pm_isolate.h"
#include "pm_par.h"
#include "pm_petsc.h"

void fpm_sim_destroy(fpm_sim *sim) {
  if (!sim) return;
  fpm_state_destroy(sim->local_state);
  fpm_model_destroy(sim->local_model);
  fpm_static_state_free(&sim->static_state);
  fpm_static_state_free(&sim->local_static);
  free(sim->whole_fixed);
  free(sim->static_local);
  free(sim->static_whole);
  fpm_state_destroy(sim->state);
  fpm_model_destroy(sim->model);
  gm_dual_destroy(sim->dual);
  gm_mesh_destroy(sim->mesh);
  free(sim->scratch);
  free(sim->mesh_x);
  free(sim->share_scratch);
  free(sim->own_nbr);
  free(sim);
}

/* A simulation of scene s with its timers, before any geometry. */
static pm_err sim_new(const pm_scene *s, fpm_sim **out) {
  fpm_sim *sim = NULL;
  *out = NULL;
  PM_CHECK(s->method && strcmp(s->method, "fpm") == 0, PM_ERR_ARG,
           "fpm_sim_create: scene %s has method %s", s->path,
           s->method ? s->method : "(none)");
  PM_CALL(PM_ALLOC(sim, 1, "FPM simulation"));
  sim->scene = s;
  pm_timers_init(&sim->timers);
  sim->tm_mesh = pm_timers_add(&sim->timers, "mesh (gmsh)");
  sim->tm_dual = pm_timers_add(&sim->timers, "subdomains");
  sim->tm_operators = pm_timers_add(&sim->timers, "GFD operators and BCs");
  sim->tm_force = pm_timers_add(&sim->timers, "internal force");
  sim->tm_assembly = sim->tm_linear = sim->tm_pcsetup = -1;
  if (s->time.qs == PM_QS_STATIC) {
    sim->tm_update = pm_timers_add(&sim->timers, "load steps and output");
    sim->tm_assembly = pm_timers_add(&sim->timers, "tangent (colouring)");
    sim->tm_pcsetup =
        pm_timers_add(&sim->timers, "factorisation or preconditioner set-up");
    sim->tm_linear = pm_timers_add(&sim->timers, "linear solves");
  } else {
    sim->tm_update = pm_timers_add(&sim->timers, "time integration");
  }
  sim->cells = gm_cells_find(fpm_scene_options(s)->cells);
  *out = sim;
  return PM_SUCCESS;
}

/* The cheap geometry: the mesh of the domain and its cells (points,
 * supports, interfaces' and facets' shapes); across ranks, rank 0's
 * alone. */
static pm_err sim_mesh(fpm_sim *sim) {
  const pm_scene *s = sim->scene;
  double t0 = pm_wtime();
  pm_timers_start(&sim->timers, sim->tm_mesh);
  /* The domain: the box, or the scene's one gmsh volume. */
  int domain = fpm_domain_body(s);
  sim->far_size = s->mesh_size;
  pm_err meshed;
  /* A static solve's PETSc opened while gmsh meshes in its child. */
  if (s->time.qs == PM_QS_STATIC) pm_isolate_meanwhile(pm_petsc_preload);
  if (domain >= 0)
    meshed = gm_mesh_file(s->bodies[domain].mesh, s->dimension, s->mesh_size,
                          (gm_sizes)s->mesh_sizes, &sim->mesh);
  else {
    gm_grade grade;
    fpm_grade_of(s, &grade, &sim->far_size);
    meshed = gm_mesh_box_graded(s->dimension, s->box_min, s->box_max,
                                sim->far_size, &grade, &sim->mesh);
    sim->near_size = grade.faces ? grade.size : 0.0;
  }
  pm_isolate_meanwhile(NULL);
  /* gmsh meshes in a child process, which a signal stops at once. */
  if (meshed == PM_ERR_INTERRUPTED)
    PM_CALL(pm_interrupt_check("during meshing (nothing written)"));
  PM_CALL(meshed);
  pm_timers_stop(&sim->timers, sim->tm_mesh);
  /* A signal stops the setup between its other stages, which run to their
   * end (seconds at 1e5 points). */
  PM_CALL(pm_interrupt_check("after meshing (nothing written)"));
  sim->mean_edge = gm_mesh_mean_edge(sim->mesh);
  pm_timers_start(&sim->timers, sim->tm_dual);
  PM_CALL(sim->cells->build(sim->mesh, &sim->dual));
  pm_timers_stop(&sim->timers, sim->tm_dual);
  PM_CALL(pm_interrupt_check("after the subdomains (nothing written)"));
  sim->setup_wall = pm_wtime() - t0;
  return PM_SUCCESS;
}

/* The step: time.dt, else dt_safety times the stable step of the scene's
 * rule. */
static void pick_dt(fpm_sim *sim) {
  const pm_scene *s = sim->scene;
  sim->dt_stable =
      s->time.dt_rule == PM_DT_SPECTRAL ? sim->dt_spectral : sim->dt_paper;
  sim->dt = s->time.dt > 0 ? s->time.dt : s->time.dt_safety * sim->dt_stable;
}

/* The supports' speed is a figure of quasi-static runs by relaxation or
 * damping, where the body must keep up with them. */
static bool relaxes(const pm_scene *s) {
  return s->time.qs == PM_QS_DYNAMIC_RELAXATION || s->time.qs == PM_QS_DAMPING;
}

/* The whole model on the geometry, its state and step. */
static pm_err sim_model(fpm_sim *sim) {
  const pm_scene *s = sim->scene;
  const double t0 = pm_wtime();
  pm_timers_start(&sim->timers, sim->tm_operators);
  PM_CALL(fpm_model_create(s, fpm_scene_options(s), sim->mesh, sim->dual,
                           &sim->model));
  PM_CALL(pm_interrupt_check("after the operators (nothing written)"));
  PM_CALL(fpm_state_create(sim->model, &sim->state));
  if (s->time.qs == PM_QS_STATIC)
    PM_CALL(fpm_static_state_init(&sim->static_state, sim->model));
  PM_CALL(PM_ALLOC(sim->scratch, 11 * sim->model->n, "output buffer"));
  sim->dt_paper = fpm_stable_dt(sim->model, &sim->dt_point);
  if (relaxes(s)) sim->support_speed = fpm_support_speed(sim->model);
  if (s->time.dt_rule == PM_DT_SPECTRAL) fpm_sim_measure_spectrum(sim);
  pick_dt(sim);
  pm_timers_stop(&sim->timers, sim->tm_operators);
  sim->setup_wall += pm_wtime() - t0;
  return PM_SUCCESS;
}

pm_err fpm_sim_create(const pm_scene *s, fpm_sim **out) {
  fpm_sim *sim = NULL;
  *out = NULL;
  PM_CALL(sim_new(s, &sim));
  pm_err e = sim_mesh(sim);
  if (!e) e = sim_model(sim);
  if (e) {
    fpm_sim_destroy(sim);
    return e;
  }
  sim->whole = true;
  sim->n_whole = sim->model->n;
  *out = sim;
  return PM_SUCCESS;
}

/* Power iterations for the spectral radius: the Rayleigh quotient
 * approaches it from below, to within a percent on the meshes tried. */
#define FPM_SPECTRAL_ITERATIONS 100

void fpm_sim_measure_spectrum(fpm_sim *sim) {
  if (sim->dt_spectral > 0) return;
  double lambda;
  sim->dt_spectral = fpm_contact_stable_dt(
      sim->model->contact,
      fpm_spectral_dt(sim->model, sim->state, FPM_SPECTRAL_ITERATIONS,
                      sim->scratch, &lambda));
}

long fpm_sim_conditioning(const fpm_sim *sim, double *worst,
                          long *worst_point) {
  const fpm_model *m = sim->model;
  return fpm_gfd_deformed_condition(m->dim, m->n, m->x, sim->state->u,
                                    m->nbr_ptr, sim->dual->nbr, FPM_COND_MAX,
                                    worst, worst_point);
}

static const pm_timers *timers(void *p) { return &((fpm_sim *)p)->timers; }

/* The time loop's state (fpm_state: u, v and what the loop carries) and
 * what the run reports over all its steps. */
/* A static solve's load stepping: where it is, its last two converged
 * states over the free dofs, and its counters. */
static pm_err checkpoint_static(fpm_sim *sim, fpm_static_state *ss,
                                pm_ckpt *ck) {
  PM_CALL(pm_load_checkpoint(ck, "static", ss->free_dofs, &ss->load,
                             &sim->static_report.load));
  return pm_ckpt_double(ck, "static.external_work", &ss->external_work);
}

/* The time loop's state st of the whole run (fpm_state: u, v and what the
 * loop carries, of n points; or a static solve's load stepping ss) and
 * what the run reports over all its steps. */
static pm_err checkpoint_whole(fpm_sim *sim, pm_ckpt *ck, fpm_state *st, long n,
                               fpm_static_state *ss) {
  const long n3 = 3 * n;
  const bool is_static = sim->scene->time.qs == PM_QS_STATIC;
  if (is_static) {
    PM_CALL(checkpoint_static(sim, ss, ck));
  } else {
    PM_CALL(pm_ckpt_doubles(ck, "fpm.u", n3, st->u));
    PM_CALL(pm_ckpt_doubles(ck, "fpm.v", n3, st->v));
    PM_CALL(pm_ckpt_long(ck, "fpm.step", &st->step));
    PM_CALL(pm_ckpt_double(ck, "fpm.t", &st->t));
    PM_CALL(pm_ckpt_double(ck, "fpm.damping", &st->damping));
    PM_CALL(pm_ckpt_double(ck, "fpm.external_work", &st->external_work));
    PM_CALL(pm_ckpt_double(ck, "fpm.dissipated", &st->dissipated));
    if (st->contact)
      PM_CALL(pm_ckpt_doubles(ck, "fpm.contact",
                              fpm_contact_state_size(sim->model->contact),
                              st->contact));
  }
  PM_CALL(pm_ckpt_double(ck, "run.min_jacobian", &sim->run_min_jacobian));
  PM_CALL(
      pm_ckpt_long(ck, "run.min_jacobian_step", &sim->run_min_jacobian_step));
  PM_CALL(
      pm_ckpt_double(ck, "run.max_energy_error", &sim->run_max_energy_error));
  PM_CALL(pm_ckpt_double(ck, "run.residual0", &sim->res0));
  if (pm_ckpt_reading(ck)) {
    sim->resumed = true;
    if (is_static) {
      sim->last.step = sim->static_report.load.steps;
      sim->last.t = ss->load.lambda * pm_scene_load_end(sim->scene);
      sim->last.external_work = ss->external_work;
    } else {
      sim->last.step = st->step;
      sim->last.t = st->t;
      sim->last.damping = st->damping;
      sim->last.external_work = st->external_work;
      sim->last.dissipated = st->dissipated;
    }
  }
  return PM_SUCCESS;
}

/* A rank that does not hold the whole model resumes: every rank reads the
 * checkpoint (rank 0 writes it), this one into the whole run's state for
 * the time it takes to keep its share of it. */
static pm_err checkpoint_share(fpm_sim *sim, pm_ckpt *ck) {
  pm_err ret = PM_SUCCESS;
  const long n = sim->n_whole;
  const bool is_static = sim->scene->time.qs == PM_QS_STATIC;
  fpm_state whole = {0};
  fpm_static_state ws = {0};
  double *nodal = NULL;
  PM_ENSURE(pm_ckpt_reading(ck), PM_ERR_INTERNAL,
            "a rank without the whole model writes no checkpoint");
  PM_TRY(PM_ALLOC(whole.u, 3 * n + 1, "checkpoint's displacements"));
  PM_TRY(PM_ALLOC(whole.v, 3 * n + 1, "checkpoint's velocities"));
  if (is_static) {
    ws.free_dofs = sim->free_whole;
    PM_TRY(pm_load_state_init(&ws.load, ws.free_dofs > 0 ? ws.free_dofs : 1));
    PM_TRY(PM_ALLOC(nodal, 3 * n + 1, "checkpoint's displacements"));
  }
  PM_TRY(checkpoint_whole(sim, ck, &whole, n, &ws));
  if (is_static)
    fpm_backend_scatter_static(sim, sim->whole_fixed, n, &ws, nodal);
  else
    fpm_par_scatter(sim->local_model, &whole, sim->local_state);
  sim->scattered = true;
done:
  free(whole.u);
  free(whole.v);
  free(nodal);
  if (is_static) fpm_static_state_free(&ws);
  return ret;
}

static pm_err checkpoint(void *p, pm_ckpt *ck) {
  fpm_sim *sim = p;
  PM_CHECK(sim->whole || pm_ckpt_reading(ck), PM_ERR_ARG,
           "a run across ranks with frames in pieces and no "
           "output.checkpoint keeps no whole model to checkpoint (set "
           "output.checkpoint.every, or output.ranks: gather)");
  if (!sim->model) return checkpoint_share(sim, ck);
  return checkpoint_whole(sim, ck, sim->state, sim->model->n,
                          &sim->static_state);
}

/* The stable step of the paper's bound across ranks: the largest lambda
 * over the shares, and the point one process names (the smallest index
 * among those that have it) (collective). */
static void shares_dt(fpm_sim *sim) {
  const fpm_model *lm = sim->local_model;
  long crit = 0;
  double lam = fpm_stable_lambda(lm, &crit), most = lam;
  pm_par_max(&most, 1);
  long first = lam == most ? -crit : -LONG_MAX;
  pm_par_max_long(&first, 1);
  sim->dt_point = -first;
  sim->dt_paper = fpm_stable_dt_of(lm, most);
  if (relaxes(sim->scene)) {
    sim->support_speed = fpm_support_speed(lm);
    pm_par_max(&sim->support_speed, 1);
  }
}

/* A static solve across ranks: the whole run's prescribed dofs (3 per
 * point) and free dofs, with which every rank reads a checkpoint of the
 * whole run into its share (collective). */
static pm_err whole_fixed(fpm_sim *sim) {
  const fpm_model *lm = sim->local_model;
  const long n = sim->n_whole;
  double *mask = NULL;
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(mask, 3 * n + 1, "prescribed dofs"));
  PM_TRY(PM_ALLOC(sim->whole_fixed, 3 * n + 1, "prescribed dofs"));
  for (long i = 0; i < lm->n_own; i++)
    for (int c = 0; c < 3; c++) mask[3 * lm->gid[i] + c] = lm->fixed[3 * i + c];
done:
  ret = pm_par_agree(ret);
  if (!ret) {
    pm_par_max(mask, (int)(3 * n));
    for (long d = 0; d < 3 * n; d++) sim->whole_fixed[d] = mask[d] > 0;
    sim->free_whole = sim->local_static.free_dofs;
    pm_par_sum_long(&sim->free_whole, 1);
  }
  free(mask);
  return ret;
}

/* Across ranks with frames in pieces, this rank's own points of a frame
 * and, without the whole model, of the figures: the share's output buffer
 * (collective). */
static pm_err share_pieces(fpm_sim *sim, const long whole_counts[3]) {
  const fpm_model *lm = sim->local_model;
  if (sim->pieces)
    PM_CALL(pm_par_agree(PM_ALLOC(sim->share_scratch, 14 * lm->n_own + 1,
                                  "the share's output")));
  return sim->whole ? PM_SUCCESS : fpm_view_sums_setup(sim, whole_counts);
}

/* Across ranks rank 0 alone meshes the domain and builds its cells; the
 * whole model is built only where this rank keeps it
 * (pm_view_keeps_whole_for: not where the frames go in pieces and nothing
 * else reads the whole run), and each rank makes its share, from the
 * whole model there, from the part of the cells rank 0 sends it elsewhere
 * (collective). */
static pm_err create_share(const pm_scene *s, fpm_sim **out) {
  fpm_sim *sim = NULL;
  const bool whole = pm_view_keeps_whole_for(s), root = pm_par_root();
  long counts[3] = {0, 0, 0}; /* the whole cells', for the summary */
  pm_err e = pm_par_agree(sim_new(s, &sim));
  if (!e) e = pm_par_agree(root ? sim_mesh(sim) : PM_SUCCESS);
  if (!e) { /* what every rank reports of the geometry */
    double g[3] = {sim->mean_edge, sim->far_size, sim->near_size};
    sim->whole = pm_view_whole_needed(s);
    sim->pieces =
        s->output.ranks == PM_OUTPUT_PIECES && s->time.qs != PM_QS_STATIC;
    if (root) {
      counts[0] = sim->mesh->n_cells;
      counts[1] = sim->dual->n_ifaces;
      counts[2] = sim->dual->n_facets;
    }
    sim->n_whole = root ? sim->dual->n_points : 0;
    pm_par_bcast(g, sizeof g);
    pm_par_bcast(&sim->n_whole, sizeof sim->n_whole);
    sim->mean_edge = g[0];
    sim->far_size = g[1];
    sim->near_size = g[2];
  }
  if (!e) e = pm_par_agree(whole ? sim_model(sim) : PM_SUCCESS);
  if (!e)
    e = pm_par_agree(whole && sim->model->contact ? fpm_contact_refuse_ranks(s)
                                                  : PM_SUCCESS);
  const double t0 = pm_wtime();
  if (!e) {
    pm_timers_start(&sim->timers, sim->tm_operators);
    e = fpm_par_create(s, &sim->mesh, &sim->dual, sim->model,
                       &sim->local_model);
    pm_timers_stop(&sim->timers, sim->tm_operators);
  }
  if (!e)
    e = pm_par_agree(fpm_state_create(sim->local_model, &sim->local_state));
  if (!e) e = share_pieces(sim, counts);
  if (!e && s->time.qs == PM_QS_STATIC) { /* its load stepping's share */
    const fpm_model *lm = sim->local_model;
    e = fpm_static_state_init(&sim->local_static, lm);
    if (!e) e = PM_ALLOC(sim->static_local, 3 * lm->n + 1, "nodal gather");
    if (!e && whole)
      e = PM_ALLOC(sim->static_whole, 3 * sim->model->n, "nodal gather");
    e = pm_par_agree(e);
    if (!e) e = whole_fixed(sim);
  }
  if (!e) {
    shares_dt(sim);
    /* The spectral radius of the whole model, where it is held. */
    double spectral = sim->dt_spectral;
    pm_par_bcast(&spectral, sizeof spectral);
    if (s->time.dt_rule == PM_DT_SPECTRAL && !(spectral > 0))
      e = PM_ERROR(PM_ERR_UNSUPPORTED,
                   "%s: time.dt_rule: spectral measures the whole model, "
                   "which no rank holds here; across ranks use time.dt_rule: "
                   "paper or set time.dt",
                   s->path);
    sim->dt_spectral = spectral;
    pick_dt(sim);
  }
  if (sim) sim->setup_wall += pm_wtime() - t0;
  if (e) {
    fpm_sim_destroy(sim);
    return e;
  }
  *out = sim;
  return PM_SUCCESS;
}

static pm_err create(const pm_scene *s, void **out) {
  fpm_sim *sim = NULL;
  pm_err e = pm_par_active() ? create_share(s, &sim) : fpm_sim_create(s, &sim);
  if (e) return e;
  fpm_backend_view_init(sim);
  *out = sim;
  return PM_SUCCESS;
}

/* The ghosts reach 3 rings of support, 5 where the quadratic fits take
 * two rings (fpm_share.h). */
static double ghost_layers(const pm_scene *s) {
  return fpm_scene_options(s)->jump == FPM_JUMP_QUADRATIC ? 5 : 3;
}

/* A rank's part of the cells: the share's rings and two more
 * (fpm_region.h). */
static double part_layers(const pm_scene *s) { return ghost_layers(s) + 2; }

static void destroy(void *sim) { fpm_sim_destroy(sim); }

/* The method's scene checks, and across ranks: a static solve writes its
 * frames gathered (its load stepping's states are gathered into rank 0's
 * whole model for its checkpoints). */
static pm_err check(const pm_scene *s) {
  PM_CALL(fpm_check_scene(s));
  if (pm_par_active() && s->output.ranks == PM_OUTPUT_PIECES &&
      s->time.qs == PM_QS_STATIC)
    return pm_scene_fail(s, "output.ranks", false,
                         "a static solve (time.quasi_static.method: static) "
                         "across ranks writes each frame gathered into rank "
                         "0 (this run has %d ranks): take gather",
                         pm_par_size());
  return PM_SUCCESS;
}

/* output.ranks: auto gathers FPM's frames: in pieces they are a point
 * cloud without the mesh's cells, its static solve refuses them and its
 * checkpoints are gathered into rank 0's whole model. */
static bool pieces_apply(const pm_scene *s) {
  (void)s;
  return false;
}

const pm_backend fpm_backend = {
    .method = "fpm",
    .description = "explicit total-Lagrangian Fragile Points Method",
    .section = &fpm_section,
    .dt_safety = 0.9,
    .ranks = true,
    .check = check,
    .create = create,
    .estimate_bytes = fpm_estimate_bytes,
    .ghost_layers = ghost_layers,
    .geometry_bytes = fpm_estimate_geometry_bytes,
    .part_layers = part_layers,
    .destroy = destroy,
    .plan = fpm_backend_plan,
    .run = fpm_backend_run,
    .points = fpm_backend_points,
    .fields = fpm_backend_fields,
    .displacement = fpm_backend_displacement,
    .figures = fpm_backend_figures,
    .history_names = fpm_backend_history_names,
    .history_values = fpm_backend_history_values,
    .summary = fpm_backend_summary,
    .timers = timers,
    .checkpoint = checkpoint,
    .pieces = fpm_backend_pieces,
    .pieces_apply = pieces_apply,
    .errors = fpm_backend_errors,
};
