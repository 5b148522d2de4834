/* mpm_pipeline: the step assembled from what the scene contains, and run.
 * A stage exists only if the scene needs it; a particle kind brings its
 * constitutive stage. */
#include "mpm_pipeline.h"

#include <stdio.h>

#include "mpm_contact.h"
#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_grip.h"
#include "mpm_traction.h"
#include "mpm_motion.h"
#include "mpm_exchange.h"
#include "mpm_state.h"
#include "mpm_transfer.h"

static mpm_stage *add(mpm_pipeline *pl, const char *name, mpm_stage_fn fn) {
  PM_ASSERT(pl->n < MPM_MAX_STAGES);
  mpm_stage *st = &pl->stage[pl->n];
  *st = (mpm_stage){.run = fn, .name = name, .index = pl->n, .group = -1};
  pl->n++;
  return st;
}

/* Each group's constitutive stage, from its kind. */
static void add_stress(mpm_model *m) {
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    if (!g->kind->stress) continue; /* moves as prescribed */
    mpm_stage *st;
    if (g->kind->pre_stress) {
      st = add(&m->pipeline, g->kind->pre_stage_name, g->kind->pre_stress);
      st->group = gi;
      int len = snprintf(st->detail, sizeof st->detail, "%s: ", g->name);
      if (len >= 0 && (size_t)len < sizeof st->detail)
        g->kind->describe_pre(m, g, st->detail + len, sizeof st->detail - len);
    }
    st = add(&m->pipeline, g->kind->stage_name, g->kind->stress);
    st->group = gi;
    int len = snprintf(st->detail, sizeof st->detail, "%s: ", g->name);
    if (len >= 0 && (size_t)len < sizeof st->detail)
      g->kind->describe(g, st->detail + len, sizeof st->detail - len);
  }
}

static void add_grid_forces(mpm_model *m) {
  const mpm_options *o = &m->opt;
  mpm_stage *st;
  if (o->has_gravity) {
    st = add(&m->pipeline, "gravity", mpm_stage_gravity);
    st->after_update = mpm_book_gravity;
    st->books = MPM_BOOKS_WORK;
    snprintf(st->detail, sizeof st->detail,
             "m g on the nodes, g = (%g, %g, %g); its work after the update",
             o->gravity[0], o->gravity[1], o->gravity[2]);
  }
  const int n_tractions = mpm_tractions_count(m->bcs, m->n_bcs);
  if (n_tractions > 0) {
    st = add(&m->pipeline, "tractions", mpm_stage_tractions);
    st->after_update = mpm_book_tractions;
    st->books = MPM_BOOKS_WORK;
    snprintf(st->detail, sizeof st->detail,
             "%d traction%s: t A on the particles at its face or surface, "
             "to the nodes through the shape functions; its work after "
             "the update",
             n_tractions, n_tractions == 1 ? "" : "s");
  }
  if (m->has_absorbing) {
    st = add(&m->pipeline, "absorbing boundaries", mpm_stage_absorbing);
    st->books = MPM_BOOKS_DISSIPATED;
    snprintf(st->detail, sizeof st->detail,
             "viscous tractions rho (c_p v_n, c_s v_t) on absorbing faces");
  }
  if (o->qs != PM_QS_NONE) {
    bool dr = o->qs == PM_QS_DYNAMIC_RELAXATION;
    st = add(&m->pipeline, "damping", mpm_stage_damping);
    st->books = MPM_BOOKS_DISSIPATED;
    if (dr && m->n_bcs > 0) st->after_update = mpm_remember_fixed;
    snprintf(st->detail, sizeof st->detail, "%s",
             dr ? "dynamic relaxation: adaptive mass-proportional damping"
                : "fixed mass-proportional damping");
  }
}

void mpm_pipeline_build(mpm_model *m) {
  const mpm_options *o = &m->opt;
  mpm_pipeline *pl = &m->pipeline;
  const char *impedances = m->has_absorbing ? ", impedances" : "";
  mpm_stage *st;
  pl->n = 0;
  if (o->dt_fixed <= 0) {
    st = add(pl, "time step", mpm_stage_time_step);
    snprintf(st->detail, sizeof st->detail,
             "dt = %g h / max(wave speed + |v|, with viscous terms)",
             o->dt_safety);
  }
  if (o->update == MPM_USF) {
    st = add(pl, "p2g", mpm_stage_p2g);
    st->mode = MPM_P2G_MASS | MPM_P2G_MOM;
    snprintf(st->detail, sizeof st->detail, "mass and momentum to the grid");
    st = add(pl, "grid velocity", mpm_stage_grid_velocity);
    snprintf(st->detail, sizeof st->detail,
             "USF: velocities with conditions for the stress");
    add_stress(m);
    st = add(pl, "p2g force", mpm_stage_p2g);
    st->mode = MPM_P2G_FORCE;
    snprintf(st->detail, sizeof st->detail, "internal forces to the grid%s",
             impedances);
  } else {
    st = add(pl, "p2g", mpm_stage_p2g);
    st->mode = MPM_P2G_MASS | MPM_P2G_MOM | MPM_P2G_FORCE;
    snprintf(st->detail, sizeof st->detail,
             "mass, momentum and internal force to the grid%s", impedances);
  }
  add_grid_forces(m);
  st = add(pl, "grid update", mpm_stage_grid_update);
  /* The conditions belong to the update: it books their work. */
  st->books = m->n_bcs > 0 || m->n_moving > 0 ? MPM_BOOKS_WORK : 0;
  pl->update = st->index;
  /* A transfer right before the update sums the nodes it starts from. */
  if (st->index > 0 && pl->stage[st->index - 1].run == mpm_stage_p2g) {
    pl->stage[st->index - 1].mode |= MPM_NODES_FUSED;
    st->mode |= MPM_NODES_FUSED;
  }
  const int n_rigid = mpm_contacts_count(m->bcs, m->n_bcs);
  snprintf(st->detail, sizeof st->detail,
           "v^L = v + dt f / m, %d boundary condition%s%s%s%s", m->n_bcs,
           m->n_bcs == 1 ? "" : "s",
           o->null_velocity ? ", null directions" : "",
           m->n_moving ? ", nodes of moving bodies at their velocity" : "",
           n_rigid ? ", rigid bodies in the grid's contact" : "");
  mpm_stage *g2p = st = add(pl, "g2p", mpm_stage_g2p);
  snprintf(st->detail, sizeof st->detail,
           "particle velocities (FLIP %g / PIC %g)", o->flip, 1 - o->flip);
  if (m->n_moving > 0) {
    st = add(pl, "motion", mpm_stage_motion);
    st->books = MPM_BOOKS_WORK;
    snprintf(st->detail, sizeof st->detail,
             "%d bod%s moving as prescribed: velocity and position of the "
             "expressions of t",
             m->n_moving, m->n_moving == 1 ? "y" : "ies");
  }
  const int n_grips = mpm_grips_count(m->bcs, m->n_bcs);
  if (n_grips > 0) {
    st = add(pl, "grips", mpm_stage_grips);
    st->books = MPM_BOOKS_WORK;
    snprintf(st->detail, sizeof st->detail,
             "%d grip%s: held particles at their prescribed motion, the "
             "nodes they touch with them",
             n_grips, n_grips == 1 ? "" : "s");
  }
  if (o->update == MPM_MUSL) {
    /* With no stage between them that moves particles' velocities, g2p
     * scatters the remap's momentum at the weights it has just used, and
     * its region goes on to the grid velocity. */
    const bool fused = m->n_moving == 0 && n_grips == 0;
    g2p->mode = fused ? MPM_P2G_MOM | MPM_NODES_FUSED : 0;
    st = add(pl, "remap", mpm_stage_remap);
    st->mode = fused ? MPM_NODES_FUSED : MPM_P2G_MOM;
    snprintf(st->detail, sizeof st->detail, "%s",
             fused ? "MUSL: momentum from the updated particles (scattered "
                     "by g2p), the grid velocity"
                   : "MUSL: momentum from the updated particles");
  }
  if (o->update != MPM_USF) add_stress(m);
  /* The only group's constitutive stage, last before the move, moves the
   * particles as it goes when its kind can. */
  mpm_stage *last = &pl->stage[pl->n - 1];
  const mpm_group *g0 = &m->group[0];
  const bool fused = o->update != MPM_USF && m->n_groups == 1 &&
                     g0->begin == 0 && g0->end == m->n && last->group == 0 &&
                     last->run == g0->kind->stress && g0->kind->moves &&
                     g0->kind->moves(g0);
  if (fused) last->mode |= MPM_MOVE_FUSED;
  st = add(pl, "move", mpm_stage_move);
  st->mode = fused ? MPM_MOVE_FUSED : 0;
  snprintf(st->detail, sizeof st->detail, "%s",
           fused ? "positions x += dt v^L (by the stress stage's loop)"
                 : "positions x += dt v^L");
}

pm_err mpm_step(const mpm_model *m, mpm_state *s, mpm_work *w) {
  mpm_ctx ctx = {m, s, w};
  const mpm_pipeline *pl = &m->pipeline;
  w->iter_max = 0;
  w->iter_capped = 0;
  w->max_div = 0;
  w->min_jacobian = INFINITY;
  w->fail.failed = false;
  for (int k = 0; k < pl->n; k++) {
    const mpm_stage *st = &pl->stage[k];
    pm_timers_start(&w->timers, w->timer[k]);
    pm_err e = st->run(&ctx, st);
    /* The hooks are timed with the update they follow. */
    for (int j = 0; !e && k == pl->update && j < pl->n; j++)
      if (pl->stage[j].after_update)
        e = pl->stage[j].after_update(&ctx, &pl->stage[j]);
    pm_timers_stop(&w->timers, w->timer[k]);
    /* Across ranks, every rank stops after the stage if one failed. */
    e = mpm_xc_agree(m, e);
    if (e) return e;
  }
  mpm_xc_step_end(m, w);
  s->t += s->dt;
  s->step++;
  s->max_div_prev = w->max_div;
  s->iter_capped_total += w->iter_capped;
  if (w->iter_max > s->iter_max_total) s->iter_max_total = w->iter_max;
  return PM_SUCCESS;
}
