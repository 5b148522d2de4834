/* mpm_seed: particles from the scene's bodies.  A volume body is seeded n
 * per direction regularly in each cell (its own particles_per_cell, or the
 * scene's) where it is the last body containing the point; a membrane's
 * particles are the vertices of its surface; an image body's, n^d per
 * labelled voxel, apart from the cells and from the other bodies.
 * Particles are grouped by material, and within a group by body, so that
 * each body's particles are one range.  A share (a rank's) keeps the
 * particles its test keeps, numbered as on one process (gid), and every
 * particle of a group that is finished whole (a membrane). */
#include "mpm_seed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_curve.h"
#include "gm_image.h"
#include "gm_shape.h"
#include "gm_trisurf.h"
#include "mpm_kind.h"
#include "mpm_seed_impl.h"
#include "pm_tensor.h"

typedef struct {
  const pm_scene *s;
  gm_shape **shape;  /* per body: volume bodies seeded in cells (NULL for
                        membranes and images, which take no part in the
                        bodies' precedence) */
  gm_trisurf *surf;  /* per body: membranes' points (and triangles) */
  double **share;    /* per body: each membrane point's area (2D: length) */
  int (*ppc)[3];     /* per body: particles per cell and direction */
  gm_image *image;   /* per body: the image an image body reads first (each
                        image is read once) */
  gm_shape **voxels; /* per body: an image body's voxels, on image[b] of
                        the first body that reads the same image */
} seeder;

/* The last volume body containing x (later bodies take precedence), or
 * -1. */
static int body_at(const seeder *sd, const double x[3]) {
  return gm_shape_last_containing((const gm_shape *const *)sd->shape,
                                  sd->s->n_bodies, x);
}

/* The inside or outside of membrane body mb for body b: of its closed
 * surface (3D) or of the region its curve encloses (2D). */
static pm_err membrane_region(const seeder *sd, int b, int mb, gm_shape **out) {
  const pm_scene *s = sd->s;
  const pm_scene_body *body = &s->bodies[b];
  const bool outside = body->shape == PM_BODY_OUTSIDE;
  const gm_trisurf *sf = &sd->surf[mb];
  pm_err e;
  if (s->dimension == 3)
    e = gm_shape_from_surface(sf, outside, out);
  else if (s->bodies[mb].membrane.surface == PM_SURFACE_CURVE)
    e = gm_shape_from_curve(sf->n_points, sf->x, s->bodies[mb].membrane.closed,
                            s->box_min, s->box_max, outside, out);
  else
    e = PM_ERROR(PM_ERR_GEOMETRY,
                 "bodies.%d is a point cloud: its points are in no order, "
                 "so they enclose nothing",
                 mb);
  if (e == PM_SUCCESS) return PM_SUCCESS;
  char what[256];
  snprintf(what, sizeof what,
           "expected the name of a closed membrane (bodies.%d, whose "
           "surface splits the domain into an inside and an outside)",
           mb);
  return mpm_seed_body_fail(s, b, outside ? "outside" : "inside", what);
}

/* A failure located at the value of bodies.b.image.KEY: what (if any),
 * then the message of the call that failed. */
static pm_err image_fail(const pm_scene *s, int b, const char *key,
                         const char *what) {
  char p[PM_SDOC_PATH], msg[1024];
  snprintf(msg, sizeof msg, "%s", pm_error_message());
  return pm_scene_fail(s, PM_PATH(p, "bodies.%d.image.%s", b, key), false,
                       "%s%s%s", what, what[0] ? ": " : "", msg);
}

/* The voxels of image body b in *out, on its image, read only for the
 * first body that reads it; a label range that matches no voxel fails.
 * Failures name the key of bodies.b.image at fault. */
static pm_err make_voxels(seeder *sd, int b, gm_shape **out) {
  const pm_scene *s = sd->s;
  const pm_scene_body *body = &s->bodies[b];
  int src = b;
  for (int a = 0; a < b && src == b; a++)
    if (sd->image[a].v && gm_image_same_source(&s->bodies[a], body)) src = a;
  if (src == b && gm_image_of_body(body, &sd->image[b]) != PM_SUCCESS)
    return image_fail(
        s, b, gm_image_source_key(body),
        body->image.source == PM_IMAGE_TIFF
            ? "expected a TIFF of 8- or 16-bit grey pages, or a folder of them"
        : body->image.source == PM_IMAGE_RAW
            ? "expected a raw volume of the given size"
            : "expected a point file of voxel centres on the given grid");
  const char *key = NULL;
  if (gm_shape_from_image(&sd->image[src], body, s->dimension, out, &key) !=
      PM_SUCCESS)
    return image_fail(s, b, key, "");
  const gm_image_part *part = gm_shape_image(*out);
  if (gm_image_part_voxels(part) > 0) return PM_SUCCESS;
  char p[PM_SDOC_PATH];
  return pm_scene_fail(
      s, PM_PATH(p, "bodies.%d.image.label", b), false,
      "expected a range matching some voxel of %s (crop [%ld, %ld) x [%ld, "
      "%ld) x [%ld, %ld)), got [%u, %u]: no voxel",
      body->image.file, part->lo[0], part->hi[0], part->lo[1], part->hi[1],
      part->lo[2], part->hi[2], (unsigned)part->label[0],
      (unsigned)part->label[1]);
}

/* Every body's shape or surface, each inside the grid (domain.box): a
 * particle outside it would have no nodes.  Failures name the body's
 * position. */
static pm_err make_shapes(seeder *sd, const mpm_options *o) {
  const pm_scene *s = sd->s;
  const int nb = s->n_bodies;
  PM_CALL(PM_ALLOC(sd->shape, nb, "body shapes"));
  PM_CALL(PM_ALLOC(sd->surf, nb, "membrane surfaces"));
  PM_CALL(PM_ALLOC(sd->share, nb, "membrane point shares"));
  PM_CALL(PM_ALLOC(sd->ppc, nb, "particles per cell"));
  PM_CALL(PM_ALLOC(sd->image, nb, "body images"));
  PM_CALL(PM_ALLOC(sd->voxels, nb, "body voxels"));
  for (int b = 0; b < nb; b++) {
    const pm_scene_body *body = &s->bodies[b];
    for (int c = 0; c < 3; c++)
      sd->ppc[b][c] = c >= s->dimension  ? 1
                      : body->n_ppc == 0 ? o->ppc[c]
                      : body->n_ppc == 1 ? (int)body->ppc[0]
                                         : (int)body->ppc[c];
    if (body->shape == PM_BODY_MEMBRANE)
      PM_CALL(mpm_seed_surface(s, b, &sd->surf[b], &sd->share[b]));
  }
  for (int b = 0; b < nb; b++) {
    const pm_scene_body *body = &s->bodies[b];
    char msg[1024];
    if (body->shape == PM_BODY_MEMBRANE) continue;
    if (body->shape == PM_BODY_INSIDE || body->shape == PM_BODY_OUTSIDE) {
      PM_CALL(membrane_region(sd, b, body->surface_body, &sd->shape[b]));
      continue;
    }
    gm_shape **shape = &sd->shape[b];
    if (body->shape == PM_BODY_IMAGE) {
      shape = &sd->voxels[b];
      PM_CALL(make_voxels(sd, b, shape));
    } else if (gm_shape_create(body, s->dimension, s->box_min, s->box_max,
                               0.5 * s->mesh_size, shape) != PM_SUCCESS) {
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return PM_ERROR(PM_ERR_SCENE, "%s:%d:%d: bodies.%d: %s", s->path,
                      body->mark.line, body->mark.col, b, msg);
    }
    if (gm_shape_check_inside(*shape, b, s->box_min, s->box_max) !=
        PM_SUCCESS) {
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return PM_ERROR(PM_ERR_SCENE,
                      "%s:%d:%d: %s: its particles would be outside the grid",
                      s->path, body->mark.line, body->mark.col, msg);
    }
  }
  return PM_SUCCESS;
}

/* Visit the seed positions of volume body b: its particles per cell and
 * direction regularly in each cell of the domain box (those cells that
 * meet its bounds), in cell order, where b is the last body containing the
 * point.  Calls fn(ctx, x, b). */
typedef void (*seed_fn)(void *ctx, const double x[3], int body);

static void for_each_seed(const seeder *sd, const mpm_grid *g, int b,
                          seed_fn fn, void *ctx) {
  const pm_scene *s = sd->s;
  long lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const int *ppc = sd->ppc[b];
  double blo[3], bhi[3];
  bool bounded = gm_shape_bounds(sd->shape[b], blo, bhi);
  for (int c = 0; c < g->dim; c++) {
    /* the cells of the domain box (the grid may reach past it: room) */
    hi[c] = lround((s->box_max[c] - s->box_min[c]) * g->inv_h);
    if (!bounded) continue;
    long a = (long)floor((blo[c] - s->box_min[c]) * g->inv_h) - 1;
    long z = (long)ceil((bhi[c] - s->box_min[c]) * g->inv_h) + 1;
    lo[c] = a > 0 ? a : 0;
    if (z < hi[c]) hi[c] = z;
  }
  for (long k = lo[2]; k < hi[2]; k++)
    for (long j = lo[1]; j < hi[1]; j++)
      for (long i = lo[0]; i < hi[0]; i++) {
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
              if (inside && body_at(sd, x) == b) fn(ctx, x, b);
            }
      }
}

typedef struct {
  const pm_scene *s;
  const seeder *sd;
  long *count; /* per body */
  long *next;  /* per body: fill position */
  int group_of[MPM_MAX_GROUPS];
  int body; /* the image body being seeded */
  mpm_model *m;
  mpm_state *st;
  /* a share: its test, each body's particles it keeps, each body's next
   * one-process index, and the groups kept whole */
  mpm_seed_share *sh;
  long *kept;
  long *gnext;
  bool whole[MPM_MAX_GROUPS];
} seed_ctx;

/* Whether the share keeps a particle at x (every one without a share). */
static bool keeps(const seed_ctx *c, const double x[3]) {
  return !c->sh || c->sh->keep(c->sh->ctx, x);
}

static void count_seed(void *ctx, const double x[3], int body) {
  seed_ctx *c = ctx;
  c->count[body]++;
  c->kept[body] += keeps(c, x);
}

static void count_voxel(void *ctx, const double x[3], double vol) {
  (void)vol;
  count_seed(ctx, x, ((seed_ctx *)ctx)->body);
}

/* The index of body b's next particle, at x, in the model, or -1 where
 * the share leaves it out (its one-process index then passes). */
static long next_index(seed_ctx *c, int b, const double x[3]) {
  if (!c->sh) return c->next[b]++;
  const long gp = c->gnext[b]++;
  if (!c->whole[c->group_of[c->s->bodies[b].material]] && !keeps(c, x))
    return -1;
  c->m->gid[c->next[b]] = gp;
  return c->next[b]++;
}

/* Particle p of body b at x with volume vol: constants, state, and its
 * kind's initial state. */
static void place(seed_ctx *c, int b, long p, const double x[3], double vol) {
  mpm_model *m = c->m;
  mpm_state *st = c->st;
  const pm_scene_body *body = &c->s->bodies[b];
  int gi = c->group_of[body->material];
  const mpm_group *g = &m->group[gi];
  for (int d = 0; d < 3; d++) {
    m->x0[3 * p + d] = x[d];
    st->x[3 * p + d] = x[d];
    st->v[3 * p + d] = body->velocity[d];
  }
  m->vol0[p] = vol;
  st->vol[p] = vol;
  m->mass[p] = body->density * vol;
  g->kind->seed(g, &st->group[gi], p - g->begin, body, st->sigma + 9 * p);
}

static void place_seed(void *ctx, const double x[3], int b) {
  seed_ctx *c = ctx;
  const mpm_model *m = c->m;
  const int *ppc = c->sd->ppc[b];
  /* The particle's share of its cell, clipped to the domain box where the
   * box is not a whole number of sub-cells. */
  double vol = m->grid.node_volume;
  for (int d = 0; d < c->s->dimension; d++) {
    double hs = m->grid.h / ppc[d];
    double top = x[d] + 0.5 * hs, end = c->s->box_max[d];
    vol /= ppc[d];
    if (top > end + 1e-12 * hs) vol *= (end - (x[d] - 0.5 * hs)) / hs;
  }
  const long p = next_index(c, b, x);
  if (p >= 0) place(c, b, p, x, vol);
}

static void place_voxel(void *ctx, const double x[3], double vol) {
  seed_ctx *c = ctx;
  const long p = next_index(c, c->body, x);
  if (p >= 0) place(c, c->body, p, x, vol);
}

/* Image body b's particles (place NULL: their count). */
static long seed_voxels(seed_ctx *c, int b, gm_image_seed_fn place) {
  c->body = b;
  return gm_image_seeds(gm_shape_image(c->sd->voxels[b]), c->s->dimension,
                        (int)c->s->bodies[b].image.per_voxel, place, c);
}

/* Membrane body b: its surface's vertices, each with its share of the
 * area times the thickness, and its triangles from *t on. */
static pm_err place_membrane(seed_ctx *c, int b, long *t) {
  const gm_trisurf *sf = &c->sd->surf[b];
  const pm_scene_body *body = &c->s->bodies[b];
  mpm_model *m = c->m;
  const double *area = c->sd->share[b];
  const long first = c->next[b];
  for (long k = 0; k < sf->n_points; k++) /* (kept whole) */
    place(c, b, next_index(c, b, sf->x + 3 * k), sf->x + 3 * k,
          area[k] * body->membrane.thickness);
  m->body_links[b] = sf->n_tris > 0 ? MPM_LINKS_TRIANGLES
                     : body->membrane.surface != PM_SURFACE_CURVE
                         ? MPM_LINKS_NONE
                     : body->membrane.closed ? MPM_LINKS_LOOP
                                             : MPM_LINKS_CHAIN;
  m->body_normals[b] = (unsigned char)body->membrane.normals;
  for (long j = 0; j < 3 * sf->n_tris; j++)
    m->tri[3 * *t + j] = first + sf->tri[j];
  m->body_tri_begin[b] = *t;
  *t += sf->n_tris;
  m->body_tri_end[b] = *t;
  return PM_SUCCESS;
}

/* One group per material that has particles, in material order, each set
 * up by its kind; each body's range within its group, in body order.
 * Returns the particle count in *total. */
static pm_err make_groups(seed_ctx *c, long *total) {
  const pm_scene *s = c->s;
  mpm_model *m = c->m;
  *total = 0;
  for (int mi = 0; mi < s->n_materials; mi++) {
    c->group_of[mi] = -1;
    long n = 0;
    int first = -1;
    for (int b = 0; b < s->n_bodies; b++)
      if (s->bodies[b].material == mi) {
        n += c->count[b];
        if (first < 0 && c->count[b] > 0) first = b;
      }
    if (n == 0) continue;
    const pm_scene_material *sm = &s->materials[mi];
    mpm_group *g = &m->group[m->n_groups];
    c->group_of[mi] = m->n_groups;
    g->index = m->n_groups++;
    g->material = mi;
    g->name = sm->name;
    g->kind = mpm_kind_of(sm, mpm_body_role_of(&s->bodies[first]));
    g->c0 = sm->av_c0;
    g->c1 = sm->av_c1;
    g->begin = *total;
    g->end = *total + n;
    for (int b = 0; b < s->n_bodies; b++)
      if (s->bodies[b].material == mi) {
        c->next[b] = m->body_begin[b] = *total;
        *total += c->count[b];
        m->body_end[b] = *total;
      }
    PM_CALL(g->kind->setup(g, sm, &m->opt));
    m->kinds |= g->kind->flags;
  }
  return PM_SUCCESS;
}

/* A share's ranges: the one-process ones (make_groups') into the share,
 * then each group's and body's among the particles it keeps (all of a
 * group kept whole), each group with the room the share asks.  *total:
 * the particles on one process, then those kept. */
static pm_err share_ranges(seed_ctx *c, long *total) {
  const pm_scene *s = c->s;
  mpm_model *m = c->m;
  mpm_seed_share *sh = c->sh;
  sh->n_full = *total;
  PM_CALL(PM_ALLOC(sh->bbegin, s->n_bodies + 1, "body ranges"));
  PM_CALL(PM_ALLOC(sh->bend, s->n_bodies + 1, "body ranges"));
  for (int b = 0; b < s->n_bodies; b++) {
    sh->bbegin[b] = c->gnext[b] = m->body_begin[b];
    sh->bend[b] = m->body_end[b];
  }
  *total = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    mpm_group *g = &m->group[gi];
    sh->gbegin[gi] = g->begin;
    sh->gend[gi] = g->end;
    c->whole[gi] = g->kind->finish || g->kind->ranks_share;
    g->begin = *total;
    for (int b = 0; b < s->n_bodies; b++)
      if (c->group_of[s->bodies[b].material] == gi) {
        c->next[b] = m->body_begin[b] = *total;
        *total += c->whole[gi] ? c->count[b] : c->kept[b];
        m->body_end[b] = *total;
      }
    g->end = *total;
    g->cap = sh->room(g->end - g->begin);
    for (int k = 0; k < g->n_arrays; k++)
      g->layout[k].count = g->end - g->begin;
  }
  return PM_SUCCESS;
}

/* The triangles' ranges per group, and the moving bodies. */
static pm_err make_lists(seed_ctx *c) {
  const pm_scene *s = c->s;
  mpm_model *m = c->m;
  for (int b = 0; b < s->n_bodies; b++) {
    m->n_tris += c->sd->surf[b].n_tris;
    if (s->bodies[b].moving && c->count[b] > 0) m->n_moving++;
  }
  if (m->n_tris) PM_CALL(PM_ALLOC(m->tri, 3 * m->n_tris, "membrane triangles"));
  if (m->n_moving) PM_CALL(PM_ALLOC(m->moving, m->n_moving, "moving bodies"));
  int k = 0;
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *body = &s->bodies[b];
    if (!body->moving || c->count[b] == 0) continue;
    mpm_motion *mv = &m->moving[k++];
    mv->body = b;
    mv->begin = mv->first = m->body_begin[b];
    if (c->sh) mv->first = c->sh->bbegin[b];
    mv->end = m->body_end[b];
    for (int d = 0; d < 3; d++) mv->v[d] = body->motion[d];
  }
  return PM_SUCCESS;
}

static void seeder_free(seeder *sd, int nb) {
  for (int b = 0; sd->shape && b < nb; b++) gm_shape_destroy(sd->shape[b]);
  for (int b = 0; sd->voxels && b < nb; b++) gm_shape_destroy(sd->voxels[b]);
  for (int b = 0; sd->image && b < nb; b++) gm_image_free(&sd->image[b]);
  for (int b = 0; sd->surf && b < nb; b++) gm_trisurf_free(&sd->surf[b]);
  for (int b = 0; sd->share && b < nb; b++) free(sd->share[b]);
  free(sd->share);
  free(sd->shape);
  free(sd->surf);
  free(sd->ppc);
  free(sd->voxels);
  free(sd->image);
}

pm_err mpm_seed_visit(const pm_scene *s, const mpm_model *m,
                      mpm_seed_share *sh) {
  pm_err ret = PM_SUCCESS;
  const int nb = s->n_bodies;
  seeder sd = {.s = s};
  seed_ctx c = {.s = s, .sd = &sd, .sh = sh};
  PM_TRY(make_shapes(&sd, &m->opt));
  PM_TRY(PM_ALLOC(c.count, nb, "body counts"));
  PM_TRY(PM_ALLOC(c.kept, nb, "body counts"));
  for (int b = 0; b < nb; b++) {
    const gm_trisurf *sf = &sd.surf[b];
    if (s->bodies[b].shape == PM_BODY_MEMBRANE)
      for (long k = 0; k < sf->n_points; k++) sh->keep(sh->ctx, sf->x + 3 * k);
    else if (s->bodies[b].shape == PM_BODY_IMAGE)
      seed_voxels(&c, b, count_voxel);
    else
      for_each_seed(&sd, &m->grid, b, count_seed, &c);
  }
done:
  seeder_free(&sd, nb);
  free(c.count);
  free(c.kept);
  return ret;
}

pm_err mpm_seed(const pm_scene *s, mpm_model *m, mpm_state **state) {
  return mpm_seed_for_share(s, m, NULL, state);
}

pm_err mpm_seed_for_share(const pm_scene *s, mpm_model *m, mpm_seed_share *sh,
                          mpm_state **state) {
  pm_err ret = PM_SUCCESS;
  seeder sd = {.s = s};
  seed_ctx c;
  memset(&c, 0, sizeof c);
  c.s = s;
  c.sd = &sd;
  c.m = m;
  c.sh = sh;
  *state = NULL;
  const int nb = s->n_bodies;
  PM_ENSURE(s->n_materials <= MPM_MAX_GROUPS, PM_ERR_SCENE,
            "%s: at most %d materials are supported by method mpm, got %d",
            s->path, MPM_MAX_GROUPS, s->n_materials);
  PM_TRY(make_shapes(&sd, &m->opt));
  PM_TRY(PM_ALLOC(c.count, nb, "body counts"));
  PM_TRY(PM_ALLOC(c.next, nb, "body counts"));
  PM_TRY(PM_ALLOC(c.kept, nb, "body counts"));
  PM_TRY(PM_ALLOC(c.gnext, nb, "body counts"));
  PM_TRY(PM_ALLOC(m->body_begin, nb, "body ranges"));
  PM_TRY(PM_ALLOC(m->body_end, nb, "body ranges"));
  PM_TRY(PM_ALLOC(m->body_tri_begin, nb, "body ranges"));
  PM_TRY(PM_ALLOC(m->body_tri_end, nb, "body ranges"));
  PM_TRY(PM_ALLOC(m->body_links, nb, "body links"));
  PM_TRY(PM_ALLOC(m->body_normals, nb, "body normal methods"));
  m->n_bodies = nb;
  for (int b = 0; b < nb; b++) {
    if (s->bodies[b].shape == PM_BODY_MEMBRANE)
      c.count[b] = sd.surf[b].n_points;
    else if (s->bodies[b].shape == PM_BODY_IMAGE && sh)
      seed_voxels(&c, b, count_voxel);
    else if (s->bodies[b].shape == PM_BODY_IMAGE)
      c.count[b] = seed_voxels(&c, b, NULL);
    else
      for_each_seed(&sd, &m->grid, b, count_seed, &c);
  }
  long total;
  PM_TRY(make_groups(&c, &total));
  PM_ENSURE(total > 0, PM_ERR_SCENE,
            "%s: no particles: no seed position (%d x %d x %d per cell of "
            "size %g) lies in a body",
            s->path, m->opt.ppc[0], m->opt.ppc[1], m->opt.ppc[2], s->mesh_size);
  if (sh) PM_TRY(share_ranges(&c, &total));
  m->n = m->cap = total;
  if (sh) m->cap = sh->room(total);
  PM_TRY(PM_ALLOC(m->x0, 3 * m->cap, "particle positions"));
  PM_TRY(PM_ALLOC(m->mass, m->cap, "particle masses"));
  PM_TRY(PM_ALLOC(m->vol0, m->cap, "particle volumes"));
  if (sh) PM_TRY(PM_ALLOC(m->gid, m->cap, "particle indices"));
  PM_TRY(make_lists(&c));
  PM_TRY(mpm_state_create(m, &c.st));
  /* Triangles group by group, in body order within a group. */
  long t = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    m->tri_begin[gi] = t;
    for (int b = 0; b < nb; b++) {
      if (c.group_of[s->bodies[b].material] != gi) continue;
      if (s->bodies[b].shape == PM_BODY_MEMBRANE)
        PM_TRY(place_membrane(&c, b, &t));
      else if (s->bodies[b].shape == PM_BODY_IMAGE)
        seed_voxels(&c, b, place_voxel);
      else
        for_each_seed(&sd, &m->grid, b, place_seed, &c);
    }
    m->tri_end[gi] = t;
  }
  for (int gi = 0; gi < m->n_groups; gi++)
    if (m->group[gi].kind->finish)
      PM_TRY(m->group[gi].kind->finish(m, &m->group[gi], c.st));
  *state = c.st;
  c.st = NULL;
done:
  mpm_state_destroy(c.st);
  seeder_free(&sd, nb);
  free(c.count);
  free(c.next);
  free(c.kept);
  free(c.gnext);
  return ret;
}
