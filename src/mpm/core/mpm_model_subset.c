/* mpm_model_subset: the model of some of a whole model's particles (a
 * rank's share), made in the core beside the whole model's constructor:
 * the ranks layer chooses the particles and the grid block, and knows none
 * of the model's fields. */
#include <stdlib.h>
#include <string.h>

#include "mpm_conditions.h"
#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_pipeline.h"

pm_err mpm_model_subset(const pm_scene *s, const mpm_model *m,
                        const mpm_grid *grid, const long *sel, long n,
                        long (*room)(long), mpm_model **out) {
  pm_err ret = PM_SUCCESS;
  mpm_model *lm = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(lm, 1, "MPM model (this rank's)"));
  lm->opt = m->opt;
  lm->dim = m->dim;
  memcpy(lm->box_min, m->box_min, sizeof lm->box_min);
  memcpy(lm->box_max, m->box_max, sizeof lm->box_max);
  lm->layout = m->layout;
  lm->grid = *grid;
  lm->n = n;
  lm->cap = room(n);
  PM_TRY(PM_ALLOC(lm->x0, 3 * lm->cap, "particle positions"));
  PM_TRY(PM_ALLOC(lm->mass, lm->cap, "particle masses"));
  PM_TRY(PM_ALLOC(lm->vol0, lm->cap, "particle volumes"));
  PM_TRY(PM_ALLOC(lm->gid, lm->cap, "particle indices"));
  for (long k = 0; k < n; k++) {
    const long p = sel[k];
    lm->gid[k] = p;
    for (int c = 0; c < 3; c++) lm->x0[3 * k + c] = m->x0[3 * p + c];
    lm->mass[k] = m->mass[p];
    lm->vol0[k] = m->vol0[p];
  }
  /* Groups: ranges of the one-process indices, each set up by its kind. */
  lm->n_groups = m->n_groups;
  lm->kinds = m->kinds;
  long at = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *fg = &m->group[gi];
    mpm_group *g = &lm->group[gi];
    *g = (mpm_group){.index = fg->index,
                     .material = fg->material,
                     .name = fg->name,
                     .kind = fg->kind,
                     .c0 = fg->c0,
                     .c1 = fg->c1};
    g->begin = at;
    while (at < n && lm->gid[at] < fg->end) at++;
    g->end = at;
    g->cap = room(g->end - g->begin);
    PM_TRY(g->kind->setup(g, &s->materials[g->material], &lm->opt));
  }
  /* Bodies: their ranges follow the particles (the caller sets them). */
  lm->n_bodies = m->n_bodies;
  PM_TRY(PM_ALLOC(lm->body_begin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_end, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_tri_begin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_tri_end, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(lm->body_links, m->n_bodies + 1, "body links"));
  PM_TRY(PM_ALLOC(lm->body_normals, m->n_bodies + 1, "body normals"));
  for (int b = 0; b < m->n_bodies; b++) {
    lm->body_links[b] = m->body_links[b];
    lm->body_normals[b] = m->body_normals[b];
  }
  PM_TRY(mpm_conditions_create(s, &lm->grid, &lm->bcs, &lm->n_bcs));
  lm->has_absorbing = m->has_absorbing;
  /* Bodies moving as prescribed: their ranges are set with the bodies'. */
  if (m->n_moving > 0) {
    PM_TRY(PM_ALLOC(lm->moving, m->n_moving, "moving bodies"));
    memcpy(lm->moving, m->moving, sizeof *m->moving * (size_t)m->n_moving);
    lm->n_moving = m->n_moving;
  }
  mpm_pipeline_build(lm);
  *out = lm;
  lm = NULL;
done:
  mpm_model_destroy(lm);
  return ret;
}
