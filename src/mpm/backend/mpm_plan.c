/* mpm_plan: pointmech plan of an MPM scene, explicit and implicit: groups,
 * bodies, layout, memory, a few steps timed, and across ranks (or for
 * --ranks N) the decomposition. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_estimate.h"
#include "mpm_par.h"
#include "pm_omp.h"
#include "pm_par.h"

/* m: the whole model, or a share with its whole run's ranges (w). */
static void plan_groups(const mpm_model *m, const mpm_par_ranges *w,
                        FILE *out) {
  size_t common = mpm_particle_bytes_common();
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    size_t own = mpm_group_bytes_per_particle(g);
    fprintf(out,
            "  group %-8s %ld particles, %s, %zu bytes per particle (%zu "
            "common + %zu:",
            g->name, w ? w->gend[gi] - w->gbegin[gi] : g->end - g->begin,
            g->kind->name, common + own, common, own);
    for (int k = 0; k < g->n_arrays; k++)
      fprintf(out, " %s", g->layout[k].name);
    fprintf(out, "%s)\n", own ? "" : " none");
  }
}

/* Each body's particles: membranes with their triangles, thickness and
 * area; bodies seeded at their own density; moving bodies (m: the whole
 * model, or a share with its whole run's ranges w, where no membrane
 * is). */
static void plan_bodies(const mpm_sim *r, const mpm_model *m,
                        const mpm_par_ranges *w, FILE *out) {
  const pm_scene *s = r->scene;
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    long n = w ? w->bend[b] - w->bbegin[b] : m->body_end[b] - m->body_begin[b];
    fprintf(out, "  body %d%s%s: %ld particles", b, body->name ? " " : "",
            body->name ? body->name : "", n);
    if (body->shape == PM_BODY_MEMBRANE && !w) {
      long nt = m->body_tri_end[b] - m->body_tri_begin[b];
      double area = 0;
      for (long q = m->body_begin[b]; q < m->body_end[b]; q++)
        area += m->vol0[q] / body->membrane.thickness;
      const int links = m->body_links[b];
      if (links == MPM_LINKS_TRIANGLES)
        fprintf(out, ", membrane of %ld triangles", nt);
      else if (links == MPM_LINKS_NONE)
        fprintf(out, ", membrane of unconnected points");
      else
        fprintf(out, ", membrane along a%s curve",
                links == MPM_LINKS_LOOP ? " closed" : "n open");
      fprintf(out, ", thickness %g m, %s %.6g m%s, normals: %s",
              body->membrane.thickness, m->dim == 3 ? "area" : "length", area,
              m->dim == 3 ? "^2" : " (per unit depth)",
              pm_key_name_of(pm_normals_names, m->body_normals[b]));
    } else if (body->shape == PM_BODY_IMAGE) {
      fprintf(out,
              ", voxels of %s with intensity in [%g, %g], %ld^%d per voxel",
              body->image.file, body->image.label[0], body->image.label[1],
              body->image.per_voxel, m->dim);
    } else if (body->n_ppc) {
      fprintf(out, ", %d x %d x %d per cell", (int)body->ppc[0],
              (int)body->ppc[body->n_ppc == 1 ? 0 : 1],
              m->dim == 3 ? (int)body->ppc[body->n_ppc == 1 ? 0 : 2] : 1);
    }
    if (body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE)
      fprintf(out, ", %s membrane %s",
              body->shape == PM_BODY_INSIDE ? "inside" : "outside",
              s->bodies[body->surface_body].name);
    if (body->moving) fprintf(out, ", moves as prescribed");
    fprintf(out, "\n");
  }
}

/* How the grid was laid when the loader chose it (a scene made for FPM). */
static void plan_layout(const mpm_model *m, const pm_scene *s, FILE *out) {
  const mpm_layout *l = &m->layout;
  if (!l->mapped) return;
  fprintf(out,
          "             chosen for this scene: %s; room beyond "
          "its faces for the body to deform into (cells below/above):",
          l->h == s->mesh_size
              ? "the cell discretization.mesh_size"
              : "the largest cell up to discretization.mesh_size that "
                "divides domain.box");
  for (int c = 0; c < m->dim; c++)
    fprintf(out, " %c %ld/%ld", "xyz"[c], l -> room[c][0], l -> room[c][1]);
  fprintf(out, "\n");
}

/* The plan's lines from the scene to the number of steps; the steps. */
static double plan_head(const mpm_sim *r, FILE *out) {
  const mpm_model *m = r->model;
  const mpm_state *st = r->state;
  const pm_scene *s = r->scene;
  const mpm_grid *g = &m->grid;
  const mpm_options *o = &m->opt;
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm, %dD%s, %s B-splines, %s, FLIP %g\n", m->dim,
          m->dim == 2 ? " plane strain" : "", mpm_sim_basis_name(o->shape),
          mpm_sim_update_name(o->update, true), o->flip);
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", g->nn[0],
          g->nn[1], g->nn[2], g->h);
  plan_layout(m, r->scene, out);
  fprintf(out, "particles    %ld (%d x %d x %d per cell)\n", m->n, o->ppc[0],
          o->ppc[1], m->dim == 3 ? o->ppc[2] : 1);
  plan_groups(m, NULL, out);
  plan_bodies(r, m, NULL, out);
  fprintf(out, "pipeline\n");
  for (int k = 0; k < m->pipeline.n; k++)
    fprintf(out, "  %2d. %-20s %s\n", k + 1, m->pipeline.stage[k].name,
            m->pipeline.stage[k].detail);
  fprintf(out, "dt           %.4g s (%s); stable estimate %.4g s\n", st->dt,
          o->dt_fixed > 0 ? "time.dt" : "dt_safety x stable, each step",
          st->dt_stable);
  if (o->dt_fixed > st->dt_stable)
    fprintf(out,
            "             warning: time.dt is %.2f x the stable estimate\n",
            o->dt_fixed / st->dt_stable);
  double steps = ceil(o->t_end / st->dt);
  if (o->max_steps > 0 && steps > o->max_steps) steps = (double)o->max_steps;
  fprintf(out, "steps        %.0f to t = %g s%s%s\n", steps, o->t_end,
          o->qs != PM_QS_NONE ? " (at most: stops when converged)" : "",
          o->dt_fixed > 0 ? "" : " (at the first step's dt; the step adapts)");
  return steps;
}

static void plan_estimate(double per, double steps, long n, double setup,
                          FILE *out) {
  fprintf(out,
          "estimate     %.3g s per step, %.3g s for %.0f steps on %d "
          "thread%s%s (%.3g particle-steps/s; setup took %.3g s)\n",
          per, per * steps, steps, pm_omp_threads(),
          pm_omp_threads() == 1 ? "" : "s", pm_par_active() ? " per rank" : "",
          n / per, setup);
}

/* The plan across ranks (collective): rank 0's view prints the scene's
 * lines, every rank its share, and a few steps of the shares are timed. */
static pm_err plan_ranks(mpm_sim *r, FILE *out) {
  pm_view_release(&r->view);
  double steps = r->model ? plan_head(r, out) : 0;
  mpm_par_plan(r->local_model, r->local_work, r->model ? out : NULL);
  double t0 = pm_wtime();
  int reps = 0, more = 1;
  for (;;) {
    more = pm_wtime() - t0 < 0.3 && reps < 200;
    pm_par_bcast(&more, sizeof more);
    if (!more) break;
    pm_err e = mpm_step(r->local_model, r->local_state, r->local_work);
    if (!e) e = mpm_xc_migrate(r->local_model, r->local_state, r->local_work);
    if (e) break; /* agreed by every rank */
    reps++;
  }
  if (r->model && reps > 0)
    plan_estimate((pm_wtime() - t0) / reps, steps, r->model->n, r->setup_wall,
                  out);
  return PM_SUCCESS;
}

/* plan --ranks N on one process: how N ranks would share the run. */
static pm_err plan_decomposition(const mpm_sim *r, FILE *out) {
  if (pm_par_plan_ranks() <= 1) return PM_SUCCESS;
  mpm_decomp d;
  PM_CALL(mpm_decomp_create(r->scene, r->model, pm_par_plan_ranks(), &d));
  mpm_decomp_print(&d, r->scene, out);
  mpm_decomp_predict(&d, r->model, out);
  mpm_decomp_destroy(&d);
  return PM_SUCCESS;
}

pm_err mpm_sim_plan(void *p, FILE *out) {
  mpm_sim *r = p;
  if (r->local_model) return plan_ranks(r, out);
  const mpm_model *m = r->model;
  mpm_state *st = r->state;
  const double steps = plan_head(r, out);
  fprintf(out,
          "memory       %.1f MiB (model %.1f, state %.1f, workspace %.1f "
          "with %d thread accumulators, output buffers %.1f)\n",
          mpm_sim_bytes(r) / 1048576.0, mpm_model_bytes(m) / 1048576.0,
          mpm_state_bytes(m, st) / 1048576.0,
          mpm_work_bytes(m, r->work) / 1048576.0, r->work->nodes.threads,
          9 * sizeof(double) * (size_t)m->n / 1048576.0);
  PM_CALL(plan_decomposition(r, out));
  /* Time a few steps (the state is advanced: a plan is not run after). */
  double t0 = pm_wtime();
  int reps = 0;
  while (pm_wtime() - t0 < 0.3 && reps < 200) {
    if (mpm_step(m, st, r->work) != PM_SUCCESS) break;
    reps++;
  }
  if (reps > 0)
    plan_estimate((pm_wtime() - t0) / reps, steps, m->n, r->setup_wall, out);
  return PM_SUCCESS;
}

/* The whole run's lines of an implicit plan: the scene, grid, particles,
 * groups and bodies (rank 0's: of the whole model, or without it of its
 * share with the whole run's counts). */
static void implicit_head(const mpm_sim *r, FILE *out) {
  const mpm_model *m = r->model ? r->model : r->local_model;
  const pm_scene *s = r->scene;
  mpm_par_ranges whole, *w = NULL;
  long nn[3], lo[3], hi[3];
  mpm_xc_cells(m, nn, lo, hi); /* (the whole grid's nodes) */
  if (!r->model) mpm_par_whole_ranges(m, w = &whole);
  fprintf(out, "scene        %s (%s)\n", s->name, s->path);
  fprintf(out, "method       mpm-implicit, %dD%s, %s B-splines, quasi-static\n",
          m->dim, m->dim == 2 ? " plane strain" : "",
          mpm_sim_basis_name(m->opt.shape));
  fprintf(out, "grid         %ld x %ld x %ld nodes, cell %g m\n", nn[0], nn[1],
          nn[2], m->grid.h);
  plan_layout(m, r->scene, out);
  fprintf(out, "particles    %ld\n", w ? w->n : m->n);
  plan_groups(m, w, out);
  plan_bodies(r, m, w, out);
}

pm_err mpm_sim_implicit_plan(void *p, FILE *out) {
  mpm_sim *r = p;
  const mpm_model *m = r->model;
  /* Across ranks a rank without the whole model has its share's lines
   * alone (the decomposition's are collective). */
  if (pm_par_root()) implicit_head(r, out);
  mpm_implicit_plan(r->imp, out);
  if (r->local_model) /* across ranks: the decomposition, each rank's share */
    mpm_par_plan(r->local_model, NULL, pm_par_root() ? out : NULL);
  else
    PM_CALL(plan_decomposition(r, out));
  if (!m) return PM_SUCCESS;
  fprintf(out,
          "memory       %.1f MiB (model %.1f, state %.1f, output %.1f; "
          "PETSc's matrix and solver besides)\n",
          mpm_sim_bytes(r) / 1048576.0, mpm_model_bytes(m) / 1048576.0,
          mpm_state_bytes(m, r->state) / 1048576.0,
          mpm_sim_scratch_per_particle(m) * sizeof(double) * (size_t)m->n /
              1048576.0);
  return PM_SUCCESS;
}

double mpm_sim_ghost_layers(const pm_scene *s) {
  (void)s;
  return 2;
}
