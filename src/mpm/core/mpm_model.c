/* mpm_model: creation of the model and its initial state from a scene. */
#include "mpm_model.h"

#include "mpm_grip.h"
#include "mpm_traction.h"
#include "mpm_contact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_exchange.h"
#include "mpm_grip.h"
#include "mpm_seed.h"
#include "mpm_state.h"

void mpm_options_from_scene(const pm_scene *s, mpm_options *o) {
  const mpm_settings *set = mpm_scene_settings(s);
  *o = (mpm_options){
      .shape = (mpm_basis)set->shape,
      .update = (mpm_update)set->update,
      .flip = set->flip,
      .null_velocity = set->null_velocity,
      .fbar = (mpm_fbar_mode)set->fbar,
      .energy_update = (mpm_energy_update)set->fluid.energy_update,
      .energy_tolerance = set->fluid.tolerance,
      .max_iterations = (int)set->fluid.max_iterations,
      .has_gravity = s->has_gravity,
      .t_end = s->time.end,
      .t_load = pm_scene_load_end(s),
      .dt_fixed = s->time.dt,
      .dt_safety = s->time.dt_safety,
      .max_steps = s->time.max_steps,
      .qs = s->time.qs,
      .qs_tolerance = s->time.qs_tolerance,
      .qs_damping = s->time.qs_damping,
      .min_jacobian = s->stability.min_jacobian,
  };
  for (int c = 0; c < 3; c++) {
    o->ppc[c] = set->ppc[c];
    o->gravity[c] = s->gravity[c];
  }
}

pm_err mpm_model_start(mpm_model *m, mpm_state *st) {
  double *cp = NULL;
  mpm_pipeline_build(m);
  st->damping = m->opt.qs == PM_QS_DAMPING ? m->opt.qs_damping : 0;
  PM_CALL(PM_ALLOC(cp, m->n + 1, "particle wave speeds"));
  st->dt_stable = mpm_stable_dt(m, st, cp);
  free(cp);
  return PM_SUCCESS;
}

pm_err mpm_model_first_dt(const pm_scene *s, const mpm_model *m,
                          mpm_state *st) {
  PM_CHECK(m->opt.dt_fixed > 0 || isfinite(st->dt_stable), PM_ERR_SCENE,
           "%s: no stable time step: no particle has a wave speed or a "
           "velocity (set time.dt)",
           s->path);
  st->dt = m->opt.dt_fixed > 0 ? m->opt.dt_fixed : st->dt_stable;
  return PM_SUCCESS;
}

pm_err mpm_model_frame(const pm_scene *s, mpm_model **out) {
  pm_err ret = PM_SUCCESS;
  mpm_model *m = NULL;
  *out = NULL;
  PM_ENSURE(s->method && (strcmp(s->method, "mpm") == 0 ||
                          strcmp(s->method, "mpm-implicit") == 0),
            PM_ERR_ARG, "mpm_model_create: scene %s has method %s", s->path,
            s->method ? s->method : "(none)");
  PM_TRY(PM_ALLOC(m, 1, "MPM model"));
  mpm_options_from_scene(s, &m->opt);
  m->dim = s->dimension;
  for (int c = 0; c < 3; c++) {
    m->box_min[c] = s->box_min[c];
    m->box_max[c] = s->box_max[c];
  }
  PM_ENSURE(mpm_grid_layout(s, &m->layout), PM_ERR_SCENE,
            "%s: discretization.mesh_size: no cell divides domain.box",
            s->path);
  PM_TRY(mpm_grid_init(&m->grid, s->dimension, m->opt.shape, m->layout.h,
                       m->layout.lo, m->layout.hi, s->path));
  PM_TRY(mpm_conditions_create(s, &m->grid, &m->bcs, &m->n_bcs));
  for (int b = 0; b < m->n_bcs; b++)
    if (m->bcs[b].absorbing) m->has_absorbing = true;
  *out = m;
  m = NULL;
done:
  mpm_model_destroy(m);
  return ret;
}

/* The whole model (sh NULL), or share sh of it on grid block `block`. */
static pm_err build(const pm_scene *s, const mpm_grid *block,
                    mpm_seed_share *sh, mpm_model **model, mpm_state **state) {
  pm_err ret = PM_SUCCESS;
  mpm_model *m = NULL;
  mpm_state *st = NULL;
  *model = NULL;
  *state = NULL;
  PM_TRY(mpm_model_frame(s, &m));
  /* The state's arrays follow the groups and the conditions.  A share is
   * seeded and finished on the whole grid (a membrane's fits read its
   * cells), then moved onto its block; grips, tractions and rigid bodies
   * run on one process (mpm_par_check). */
  PM_TRY(mpm_seed_for_share(s, m, sh, &st));
  if (sh) {
    PM_TRY(mpm_model_narrow(s, block, sh, m, st));
  } else {
    PM_TRY(mpm_grips_create(s, m));
    PM_TRY(mpm_tractions_create(s, m));
    PM_TRY(mpm_contacts_check(s, m));
  }
  PM_TRY(mpm_model_start(m, st));
  if (!sh) PM_TRY(mpm_model_first_dt(s, m, st));
  *model = m;
  *state = st;
  m = NULL;
  st = NULL;
done:
  mpm_state_destroy(st);
  mpm_model_destroy(m);
  return ret;
}

pm_err mpm_model_create(const pm_scene *s, mpm_model **model,
                        mpm_state **state) {
  return build(s, NULL, NULL, model, state);
}

pm_err mpm_model_share(const pm_scene *s, const mpm_grid *block,
                       mpm_seed_share *sh, mpm_model **model,
                       mpm_state **state) {
  return build(s, block, sh, model, state);
}

void mpm_model_destroy(mpm_model *m) {
  if (!m) return;
  for (int gi = 0; gi < m->n_groups; gi++) {
    if (m->group[gi].kind && m->group[gi].kind->release)
      m->group[gi].kind->release(&m->group[gi]);
    free(m->group[gi].params);
  }
  free(m->body_begin);
  free(m->body_end);
  free(m->body_tri_begin);
  free(m->body_tri_end);
  free(m->body_links);
  free(m->body_normals);
  free(m->tri);
  free(m->moving);
  mpm_conditions_destroy(m->bcs, m->n_bcs);
  free(m->x0);
  free(m->mass);
  free(m->vol0);
  free(m->gid);
  mpm_xc_release(m);
  free(m);
}

pm_err mpm_triangles_local(const mpm_model *m, long t0, long t1, long first,
                           long **out) {
  PM_CALL(PM_ALLOC(*out, 3 * (t1 - t0) + 1, "membrane triangles"));
  for (long j = 0; j < 3 * (t1 - t0); j++)
    (*out)[j] = m->tri[3 * t0 + j] - first;
  return PM_SUCCESS;
}

size_t mpm_model_bytes(const mpm_model *m) {
  /* x0, mass, vol0, and across ranks the indices */
  size_t bytes = (5 * sizeof(double) + (m->gid ? sizeof(long) : 0)) *
                 (size_t)mpm_model_room(m);
  /* membrane triangles and incidence */
  bytes += 6 * sizeof(long) * (size_t)m->n_tris;
  for (int b = 0; b < m->n_bcs; b++)
    bytes += sizeof(long) * (size_t)m->bcs[b].n_cols;
  return bytes;
}
