/* fpm_backend_plan: pointmech plan for FPM: the scene's discretization,
 * pipeline, step and memory, the shares across ranks and a timed estimate
 * of the run. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend_impl.h"
#include "fpm_par.h"
#include "fpm_static.h"
#include "pm_omp.h"
#include "pm_par.h"

/* Seconds of one force evaluation at a small deformation of model m (u:
 * its state's; across ranks every rank times its share together,
 * collective). */
static double time_force(const fpm_model *m, fpm_state *st) {
  for (long i = 0; i < 3 * m->n; i++) st->u[i] = 1e-9 * m->x[i];
  double t0 = pm_wtime();
  int reps = 0, more = 1;
  for (;;) {
    more = pm_wtime() - t0 < 0.2 && reps < 1000;
    if (m->xc) pm_par_bcast(&more, sizeof more);
    if (!more) break;
    fpm_exchange_ghosts(m->xc, st->u);
    fpm_force(m, st);
    reps++;
  }
  memset(st->u, 0, 3 * m->n * sizeof(double));
  return 1.1 * (pm_wtime() - t0) / (reps > 0 ? reps : 1);
}

static void plan_estimate(const fpm_sim *sim, double per_step, double steps,
                          FILE *out) {
  fprintf(out,
          "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
          "threads%s (setup took %.3g s)\n",
          per_step, per_step * steps, steps, pm_omp_threads(),
          pm_par_active() ? " per rank" : "", sim->setup_wall);
}

/* How fast the supports move in a quasi-static run by relaxation or
 * damping (sim->support_speed, 0 in other runs), against the slowest shear
 * wave speed. */
static void plan_supports(const fpm_sim *sim, FILE *out) {
  const pm_scene *s = sim->scene;
  const double c = pm_scene_shear_wave_speed(s), v = sim->support_speed;
  if (!(c > 0) || !(v > 0)) return;
  const double ratio = v / c, end = pm_scene_load_end(s);
  fprintf(out,
          "ramp         supports move at up to %.3g m/s until t = %g s, %.2f "
          "of the shear wave speed sqrt(mu/rho) = %.3g m/s\n",
          v, end, ratio, c);
  if (ratio > PM_QS_SUPPORT_SPEED_FAST)
    fprintf(out,
            "             above %.2f: the body may lag behind them (inertia, "
            "and the damping's drag on what moves), stretched near them; a "
            "time.ramp of about %.3g s moves them at "
            "%.2f\n",
            PM_QS_SUPPORT_SPEED_FAST, end * ratio / PM_QS_SUPPORT_SPEED_HELD,
            PM_QS_SUPPORT_SPEED_HELD);
}

/* The plan's lines from the scene to the memory; the steps (0 for a static
 * solve, whose lines end there). */
static double plan_head(fpm_sim *sim, FILE *out) {
  const pm_scene *s = sim->scene;
  fpm_model *m = sim->model;
  double steps = ceil(s->time.end / sim->dt);
  if (s->time.max_steps > 0 && steps > s->time.max_steps)
    steps = (double)s->time.max_steps;
  size_t bytes = fpm_model_bytes(m) + fpm_state_bytes(m);
  const double *xc = m->x + 3 * sim->dt_point;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       fpm, %dD, %s\n", m->dim,
          m->dim == 2 ? "plane strain" : "solid");
  fprintf(out, "points       %ld (mesh size %g m, mean edge %.4g m)\n", m->n,
          s->mesh_size, sim->mean_edge);
  const int body = fpm_domain_body(s);
  if (body >= 0 && sim->mesh && !sim->mesh->meshed)
    fprintf(out,
            "             %s holds a mesh: used as it is (mesh_size does "
            "not remesh it)\n",
            s->bodies[body].mesh);
  else if (body >= 0 && sim->mesh && sim->mesh->size_factor > 0)
    fprintf(out,
            "             %s meshed by gmsh at its own sizes times %.4g "
            "(discretization.mesh_sizes: %s)\n",
            s->bodies[body].mesh, sim->mesh->size_factor,
            s->mesh_sizes == PM_MESH_SIZES_FILE
                ? "file"
                : "scale: its "
                  "curves' longest edge becomes mesh_size");
  else if (body >= 0 && sim->mesh)
    fprintf(out,
            "             %s meshed by gmsh at mesh_size everywhere, its own "
            "sizes replaced (discretization.mesh_sizes: replace)\n",
            s->bodies[body].mesh);
  if (s->domain_from_body) {
    fprintf(out,
            "domain       not given: the bounds of bodies.%d, [%g, %g] x "
            "[%g, %g]",
            body >= 0 ? body : 0, s->box_min[0], s->box_max[0], s->box_min[1],
            s->box_max[1]);
    if (m->dim == 3) fprintf(out, " x [%g, %g]", s->box_min[2], s->box_max[2]);
    fprintf(out, " (its faces xmin ... %s)\n", m->dim == 3 ? "zmax" : "ymax");
  }
  if (sim->near_size > 0)
    fprintf(out,
            "             graded (discretization.refine): %.4g m on the %s, "
            "%.4g m from %g m away%s\n",
            sim->near_size,
            s->refine.to == PM_REFINE_EDGES ? "faces' edges" : "faces",
            sim->far_size, s->refine.distance,
            s->refine.size_ratio > 0 ? "; mesh_size is the uniform cloud's "
                                       "point budget"
                                     : "");
  const gm_dual *d = sim->dual;
  fprintf(out,
          "cells        %s, one per node of %ld simplices: %ld interfaces, %ld "
          "facets\n",
          sim->cells->name, sim->mesh->n_cells, d->n_ifaces, d->n_facets);
  if (d->min_quality_point >= 0)
    fprintf(out,
            "             %ld faces of round-off size dropped, %ld slivers; "
            "lowest quality %.3g (1 for a cube) at point %ld\n",
            d->n_dropped_faces, d->n_slivers, d->min_quality,
            d->min_quality_point);
  fprintf(out, "pipeline     1. stress per point (");
  for (int k = 0; k < m->n_mats; k++)
    fprintf(out, "%s%s", k ? ", " : "", m->mats[k].model->name);
  fprintf(out, ")\n");
  if (m->vavg)
    fprintf(out, "             averaged volume: Jbar = A J and the pressure A "
                 "U'(Jbar) over each closed support (fpm.volumetric)\n");
  if (m->q)
    fprintf(out,
            "             2. quadratic fit per point, %ld entries (%ld "
            "points over two rings, %ld linear)\n",
            m->qs_ptr[m->n], m->n_qwide, m->n_qlinear);
  char extra[200] = "";
  if (m->boundary_penalty > 0 || m->stiffening > 0 || m->volume_penalty > 0)
    snprintf(extra, sizeof extra,
             "; boundary penalty %g, stiffening %g on the %s jump from %g h "
             "(%s spacing), volume penalty %g",
             m->boundary_penalty, m->stiffening,
             m->stiffen_quadratic ? "quadratic" : "linear", m->stiffening_onset,
             m->stiffen_current ? "current" : "reference", m->volume_penalty);
  fprintf(out,
          "             %d. interface flux (%s, penalty %g on the %s "
          "jump%s), %ld support entries\n",
          m->q ? 3 : 2,
          m->flux == FPM_FLUX_SIPG ? "SIPG: with the adjoint term, tangent "
                                     "per point"
                                   : "IIPG",
          m->penalty, m->q ? "quadratic" : "linear", extra, m->nnz);
  int stage = m->q ? 4 : 3;
  if (m->n_dpts > 0)
    fprintf(out,
            "             %d. consistency flux on prescribed faces, %ld "
            "points\n",
            stage++, m->n_dpts);
  if (m->n_tfacets > 0)
    fprintf(out, "             %d. tractions, %ld facets%s\n", stage++,
            m->n_tfacets, m->tf_time_dependent ? " (time-dependent)" : "");
  fprintf(out, "             %d. gather forces\n", stage++);
  if (s->time.qs == PM_QS_STATIC) {
    static const char *const linear[] = {"direct (LU)", "GMRES + GAMG",
                                         "CG + Jacobi", "GMRES + ILU(0)",
                                         "CG + GAMG"};
    long nfree = 0; /* this process's model's free dofs */
    for (long d = 0; d < 3 * m->n_own; d++) nfree += !m->fixed[d];
    pm_newton_options no = pm_newton_options_default();
    fpm_static_choose_linear(s, nfree, &no);
    char why[96] = "time.quasi_static.linear_solver";
    if (!pm_scene_has(s, "time.quasi_static.linear_solver"))
      snprintf(why, sizeof why, "default: %ld free dofs %s %ld", nfree,
               nfree <= FPM_STATIC_DIRECT_MAX ? "<=" : ">",
               FPM_STATIC_DIRECT_MAX);
    /* fpm_static_run_from's choice: the averages' coupling factorised */
    const bool coupled = fpm_static_couples(s, m, nfree, no.linear);
    fprintf(
        out,
        "             %d. Newton's method in %ld proportional load steps "
        "(at most %ld iterations each), %ld prescribed dofs\n"
        "             tangent assembled directly (%s), linear solver "
        "%s (%s)%s%s%s\n",
        stage++, s->time.qs_load_steps, s->time.qs_max_iterations, m->n_cdofs,
        coupled && no.linear == PM_NEWTON_DIRECT
            ? "with the averages' coupling through one unknown a point: "
              "the exact tangent's LU"
        : m->flux == FPM_FLUX_SIPG || m->vavg
            ? "preconditioning the exact tangent applied matrix-free"
            : "exact",
        linear[no.linear], why,
        fpm_static_amg_on_support(s, m, no.linear)
            ? ", built on each point's support (multigrid_operator)"
            : "",
        no.pc_reuse_its > 0 ? ", kept while GMRES takes few iterations" : "",
        no.linear_ew ? ", inexact Newton" : "");
    /* fpm_static_run_from's: the fallbacks on the LU */
    const bool fallback_lu = fpm_static_fallback_direct(s, m, nfree);
    if (fallback_lu)
      fprintf(out,
              "             from a load step's first fallback (a fold: "
              "lowest mode, arc length, continuation, relaxation) on, "
              "the LU%s (%ld free dofs <= %ld)\n",
              coupled ? " with the averages' coupling" : "", nfree,
              FPM_STATIC_FALLBACK_DIRECT_MAX);
    const bool lu = no.linear == PM_NEWTON_DIRECT || fallback_lu;
    double entries = 0;
    const double solver = fpm_static_solver_bytes(
        nfree, m->q != NULL, fallback_lu ? PM_NEWTON_DIRECT : no.linear,
        coupled, &entries);
    fprintf(out,
            "memory       %.1f MiB (operators and state) + about %.0f MiB "
            "for the tangent (~%.3g entries) and its %s\n",
            (bytes + fpm_linear_bytes(m)) / 1048576.0, solver / 1048576.0,
            entries,
            fallback_lu ? "LU factors (at most; multigrid's hierarchy "
                          "until a fallback)"
            : lu        ? "LU factors"
                        : "multigrid hierarchy");
    return 0;
  }
  fprintf(out, "             %d. central difference%s, %ld prescribed dofs\n",
          stage++,
          s->time.qs == PM_QS_DYNAMIC_RELAXATION ? " with dynamic relaxation"
          : s->time.qs == PM_QS_DAMPING          ? " with damping"
                                                 : "",
          m->n_cdofs);
  fpm_sim_measure_spectrum(sim);
  fprintf(out, "dt           %.4g s (%s)\n", sim->dt,
          s->time.dt > 0                      ? "time.dt"
          : s->time.dt_rule == PM_DT_SPECTRAL ? "dt_safety x spectral"
                                              : "dt_safety x paper bound");
  fprintf(out,
          "             bound of eqs. 24-26: %.4g s, set by point %ld at "
          "(%g, %g, %g)\n",
          sim->dt_paper, sim->dt_point, xc[0], xc[1], xc[2]);
  fprintf(out,
          "             spectral (power iteration): %.4g s = %.2f x the "
          "bound\n",
          sim->dt_spectral, sim->dt_spectral / sim->dt_paper);
  fprintf(out, "steps        %.0f to t = %g s%s\n", steps, s->time.end,
          s->time.qs != PM_QS_NONE ? " (at most: stops when converged)" : "");
  plan_supports(sim, out);
  fprintf(out, "memory       %.1f MiB (operators and state)\n",
          bytes / 1048576.0);
  return steps;
}

/* The plan across ranks (collective): rank 0's view prints the scene's
 * lines and every rank's share, and the shares' forces are timed. */
static pm_err plan_ranks(fpm_sim *sim, FILE *out) {
  const fpm_model *lm = sim->local_model;
  double steps = 0;
  /* Rank 0 prints from the whole model where it keeps it. */
  const bool view = pm_par_root() && sim->model;
  if (view) {
    steps = plan_head(sim, out);
    fpm_share_print(sim->model, fpm_par_owner(lm), pm_par_size(),
                    fpm_par_counts(lm), out);
  }
  double per_step = time_force(lm, sim->local_state);
  if (view) plan_estimate(sim, per_step, steps, out);
  return PM_SUCCESS;
}

pm_err fpm_backend_plan(void *p, FILE *out) {
  fpm_sim *sim = p;
  if (sim->local_model) return plan_ranks(sim, out);
  const int ranks = pm_par_plan_ranks();
  double per_step = time_force(sim->model, sim->state);
  double steps = plan_head(sim, out);
  if (ranks > 1) PM_CALL(fpm_share_predict(sim->model, ranks, out));
  if (sim->scene->time.qs == PM_QS_STATIC) return PM_SUCCESS;
  plan_estimate(sim, per_step, steps, out);
  return PM_SUCCESS;
}
