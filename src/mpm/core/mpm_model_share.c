/* mpm_model_share: a share of the model (a rank's) made from the scene
 * alone (mpm_model_share, mpm_model.c): once seeded with the share's
 * particles (mpm_seed_for_share), a membrane's narrowed to them after it
 * was finished whole, and the share moved onto its block of the grid. */
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_model.h"
#include "mpm_seed.h"
#include "mpm_state.h"

/* Move particle p's values to q (q <= p): constants, state, and its
 * group's arrays (the group's index k of p, kq of q). */
static void move_particle(mpm_model *m, mpm_state *st, int gi, long p, long q,
                          long k, long kq) {
  memmove(m->x0 + 3 * q, m->x0 + 3 * p, 3 * sizeof(double));
  m->mass[q] = m->mass[p];
  m->vol0[q] = m->vol0[p];
  m->gid[q] = m->gid[p];
  memmove(st->x + 3 * q, st->x + 3 * p, 3 * sizeof(double));
  memmove(st->v + 3 * q, st->v + 3 * p, 3 * sizeof(double));
  st->vol[q] = st->vol[p];
  memmove(st->sigma + 9 * q, st->sigma + 9 * p, 9 * sizeof(double));
  mpm_group_state *gs = &st->group[gi];
  for (int a = 0; a < gs->n; a++) {
    const int nc = gs->array[a].ncomp;
    memmove(gs->array[a].data + kq * nc, gs->array[a].data + k * nc,
            nc * sizeof(double));
  }
}

/* A group kept whole anew, set up by its kind for its particles [begin,
 * end), with its links from the whole group's (whole: its one-process
 * range, its parameters), whose parameters are then let go. */
static pm_err renew_group(const pm_scene *s, const mpm_options *opt,
                          mpm_group *g, mpm_group whole) {
  mpm_group fresh = {.index = g->index,
                     .material = g->material,
                     .name = g->name,
                     .kind = g->kind,
                     .c0 = g->c0,
                     .c1 = g->c1,
                     .begin = g->begin,
                     .end = g->end,
                     .cap = g->cap};
  pm_err e = fresh.kind->setup(&fresh, &s->materials[g->material], opt);
  if (!e && fresh.kind->ranks_share)
    e = fresh.kind->ranks_share(&whole, &fresh);
  if (whole.kind->release) whole.kind->release(&whole);
  free(whole.params);
  *g = fresh;
  return e;
}

/* Narrow the groups kept whole to the particles sh keeps, in place
 * (their one-process order stays), and give each array the room
 * sh->room asks. */
static pm_err narrow(const pm_scene *s, mpm_model *m, mpm_state *st,
                     mpm_seed_share *sh) {
  long q = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    mpm_group *g = &m->group[gi];
    const bool whole = g->kind->finish || g->kind->ranks_share;
    const long begin = q;
    for (long p = g->begin; p < g->end; p++)
      if (!whole || sh->keep(sh->ctx, m->x0 + 3 * p)) {
        move_particle(m, st, gi, p, q, p - g->begin, q - begin);
        q++;
      }
    mpm_group old = *g;
    old.begin = sh->gbegin[gi];
    old.end = sh->gend[gi];
    g->begin = begin;
    g->end = q;
    if (whole) {
      g->cap = sh->room(g->end - g->begin);
      PM_CALL(renew_group(s, &m->opt, g, old));
      mpm_group_state *gs = &st->group[gi];
      for (int a = 0; a < gs->n; a++) {
        gs->array[a].count = g->end - g->begin;
        PM_CALL(PM_REALLOC(gs->array[a].data, gs->array[a].ncomp * g->cap,
                           gs->array[a].name));
      }
    }
  }
  m->n = q;
  m->cap = sh->room(q);
  PM_CALL(PM_REALLOC(m->x0, 3 * m->cap, "particle positions"));
  PM_CALL(PM_REALLOC(m->mass, m->cap, "particle masses"));
  PM_CALL(PM_REALLOC(m->vol0, m->cap, "particle volumes"));
  PM_CALL(PM_REALLOC(m->gid, m->cap, "particle indices"));
  PM_CALL(PM_REALLOC(st->x, 3 * m->cap, "particle positions"));
  PM_CALL(PM_REALLOC(st->v, 3 * m->cap, "particle velocities"));
  PM_CALL(PM_REALLOC(st->vol, m->cap, "particle volumes"));
  PM_CALL(PM_REALLOC(st->sigma, 9 * m->cap, "particle stresses"));
  /* The links are the kinds' (ranks_share): the model keeps no triangle. */
  free(m->tri);
  m->tri = NULL;
  m->n_tris = 0;
  for (int gi = 0; gi < MPM_MAX_GROUPS; gi++) m->tri_begin[gi] = 0;
  for (int gi = 0; gi < MPM_MAX_GROUPS; gi++) m->tri_end[gi] = 0;
  for (int b = 0; b < m->n_bodies; b++)
    m->body_tri_begin[b] = m->body_tri_end[b] = 0;
  return PM_SUCCESS;
}

/* The share onto grid block `block`: its conditions, and dynamic
 * relaxation's nodal arrays (zero at the start) of the block's nodes. */
static pm_err onto_block(const pm_scene *s, const mpm_grid *block, mpm_model *m,
                         mpm_state *st) {
  m->grid = *block;
  mpm_conditions_destroy(m->bcs, m->n_bcs);
  m->bcs = NULL;
  m->n_bcs = 0;
  PM_CALL(mpm_conditions_create(s, &m->grid, &m->bcs, &m->n_bcs));
  if (!st->force_prev) return PM_SUCCESS;
  const long n3 = 3 * m->grid.n_nodes;
  free(st->force_prev);
  free(st->fixed);
  st->force_prev = NULL;
  st->fixed = NULL;
  PM_CALL(PM_ALLOC(st->force_prev, n3, "previous grid forces"));
  if (m->n_bcs > 0) PM_CALL(PM_ALLOC(st->fixed, n3, "previous fixed dofs"));
  return PM_SUCCESS;
}

pm_err mpm_model_narrow(const pm_scene *s, const mpm_grid *block,
                        mpm_seed_share *sh, mpm_model *m, mpm_state *st) {
  PM_CALL(narrow(s, m, st, sh));
  return onto_block(s, block, m, st);
}
