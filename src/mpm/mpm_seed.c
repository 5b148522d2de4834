/* mpm_seed: particle seeding by body shape. */
#include "mpm_seed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_shape.h"
#include "mpm_kind.h"
#include "pm_tensor.h"

typedef struct {
  const pm_scene *s;
  gm_shape **shape; /* per body */
} seeder;

/* The last body containing x (later bodies take precedence), or -1. */
static int body_at(const seeder *sd, const double x[3]) {
  return gm_shape_last_containing((const gm_shape *const *)sd->shape,
                                  sd->s->n_bodies, x);
}

/* Every body's shape, each inside the grid (domain.box): a particle
 * outside it would have no nodes.  Failures name the body's position. */
static pm_err make_shapes(seeder *sd) {
  const pm_scene *s = sd->s;
  PM_CALL(PM_ALLOC(sd->shape, s->n_bodies, "body shapes"));
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    char msg[1024];
    if (gm_shape_create(body, s->dimension, s->box_min, s->box_max,
                        0.5 * s->mesh_size, &sd->shape[b]) != PM_SUCCESS) {
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return PM_ERROR(PM_ERR_SCENE, "%s:%d:%d: bodies.%d: %s", s->path,
                      body->mark.line, body->mark.col, b, msg);
    }
    if (gm_shape_check_inside(sd->shape[b], b, s->box_min, s->box_max) !=
        PM_SUCCESS) {
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return PM_ERROR(PM_ERR_SCENE,
                      "%s:%d:%d: %s: its particles would be outside the grid",
                      s->path, body->mark.line, body->mark.col, msg);
    }
  }
  return PM_SUCCESS;
}

/* Visit every seed position: ppc per direction in each cell of the domain
 * box, regularly spaced, in cell order.  Calls fn(ctx, x, body) for
 * positions in a body. */
typedef void (*seed_fn)(void *ctx, const double x[3], int body);

static void for_each_seed(const seeder *sd, const mpm_grid *g,
                          const int ppc_opt[3], seed_fn fn, void *ctx) {
  const pm_scene *s = sd->s;
  long cells[3] = {1, 1, 1};
  int ppc[3] = {1, 1, 1};
  for (int c = 0; c < g->dim; c++) {
    cells[c] = g->nn[c] - 1 - 2 * g->ghost;
    ppc[c] = ppc_opt[c];
  }
  for (long k = 0; k < cells[2]; k++)
    for (long j = 0; j < cells[1]; j++)
      for (long i = 0; i < cells[0]; i++) {
        long cell[3] = {i, j, k};
        for (int c2 = 0; c2 < ppc[2]; c2++)
          for (int c1 = 0; c1 < ppc[1]; c1++)
            for (int c0 = 0; c0 < ppc[0]; c0++) {
              int sub[3] = {c0, c1, c2};
              double x[3] = {0, 0, 0};
              bool inside = true;
              for (int c = 0; c < g->dim; c++) {
                x[c] =
                    s->box_min[c] + (cell[c] + (sub[c] + 0.5) / ppc[c]) * g->h;
                if (x[c] > s->box_max[c]) inside = false;
              }
              if (!inside) continue;
              int b = body_at(sd, x);
              if (b >= 0) fn(ctx, x, b);
            }
      }
}

typedef struct {
  const pm_scene *s;
  long count[MPM_MAX_GROUPS]; /* per scene material */
  long next[MPM_MAX_GROUPS];  /* fill position per material */
  int group_of[MPM_MAX_GROUPS];
  mpm_model *m;
  mpm_state *st;
  double vol;
} seed_ctx;

static void count_seed(void *ctx, const double x[3], int body) {
  seed_ctx *c = ctx;
  (void)x;
  c->count[c->s->bodies[body].material]++;
}

static void place_seed(void *ctx, const double x[3], int body) {
  seed_ctx *c = ctx;
  mpm_model *m = c->m;
  mpm_state *st = c->st;
  const pm_scene_body *b = &c->s->bodies[body];
  int gi = c->group_of[b->material];
  const mpm_group *g = &m->group[gi];
  long p = c->next[b->material]++;
  for (int d = 0; d < 3; d++) {
    m->x0[3 * p + d] = x[d];
    st->x[3 * p + d] = x[d];
    st->v[3 * p + d] = b->velocity[d];
  }
  /* The particle's share of its cell, clipped to the domain box where the
   * box is not a whole number of sub-cells. */
  double vol = c->vol;
  for (int d = 0; d < c->s->dimension; d++) {
    double hs = m->grid.h / m->opt.ppc[d];
    double top = x[d] + 0.5 * hs, end = c->s->box_max[d];
    if (top > end + 1e-12 * hs) vol *= (end - (x[d] - 0.5 * hs)) / hs;
  }
  m->vol0[p] = vol;
  st->vol[p] = vol;
  m->mass[p] = b->density * vol;
  g->kind->seed(g, &st->group[gi], p - g->begin, b, st->sigma + 9 * p);
}

/* One group per material that has particles, in material order, each set
 * up by its kind.  Returns the particle count in *total. */
static pm_err make_groups(seed_ctx *c, long *total) {
  const pm_scene *s = c->s;
  mpm_model *m = c->m;
  *total = 0;
  for (int mi = 0; mi < s->n_materials; mi++) {
    c->group_of[mi] = -1;
    if (c->count[mi] == 0) continue;
    const pm_scene_material *sm = &s->materials[mi];
    mpm_group *g = &m->group[m->n_groups];
    c->group_of[mi] = m->n_groups;
    g->index = m->n_groups++;
    g->material = mi;
    g->name = sm->name;
    g->kind = mpm_kind_of(sm);
    g->c0 = sm->av_c0;
    g->c1 = sm->av_c1;
    g->begin = *total;
    g->end = *total + c->count[mi];
    c->next[mi] = *total;
    *total += c->count[mi];
    PM_CALL(g->kind->setup(g, sm, &m->opt));
    m->kinds |= g->kind->flags;
  }
  return PM_SUCCESS;
}

pm_err mpm_seed(const pm_scene *s, mpm_model *m, mpm_state **state) {
  pm_err ret = PM_SUCCESS;
  seeder sd = {.s = s, .shape = NULL};
  seed_ctx c;
  memset(&c, 0, sizeof c);
  c.s = s;
  c.m = m;
  *state = NULL;
  PM_TRY(make_shapes(&sd));
  PM_ENSURE(s->n_materials <= MPM_MAX_GROUPS, PM_ERR_SCENE,
            "%s: at most %d materials are supported by method mpm, got %d",
            s->path, MPM_MAX_GROUPS, s->n_materials);
  for_each_seed(&sd, &m->grid, m->opt.ppc, count_seed, &c);
  long total;
  PM_TRY(make_groups(&c, &total));
  PM_ENSURE(total > 0, PM_ERR_SCENE,
            "%s: no particles: no seed position (%d x %d x %d per cell of "
            "size %g) lies in a body",
            s->path, m->opt.ppc[0], m->opt.ppc[1], m->opt.ppc[2], s->mesh_size);
  m->n = total;
  PM_TRY(PM_ALLOC(m->x0, 3 * total, "particle positions"));
  PM_TRY(PM_ALLOC(m->mass, total, "particle masses"));
  PM_TRY(PM_ALLOC(m->vol0, total, "particle volumes"));
  PM_TRY(mpm_state_create(m, &c.st));
  c.vol = m->grid.node_volume / (m->opt.ppc[0] * (double)m->opt.ppc[1] *
                                 (s->dimension == 3 ? m->opt.ppc[2] : 1));
  for_each_seed(&sd, &m->grid, m->opt.ppc, place_seed, &c);
  *state = c.st;
  c.st = NULL;
done:
  mpm_state_destroy(c.st);
  if (sd.shape)
    for (int b = 0; b < s->n_bodies; b++) gm_shape_destroy(sd.shape[b]);
  free(sd.shape);
  return ret;
}
