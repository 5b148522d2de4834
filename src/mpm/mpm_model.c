/* mpm_model: grid, particle seeding by body shape, groups by material with
 * their optional state, and the grid boundary conditions. */
#include "mpm_model.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_volume.h"
#include "pm_omp.h"
#include "pm_tensor.h"

/* ---- sizes -------------------------------------------------------------- */

size_t mpm_particle_bytes_common(void) {
  /* x0, x, v, dx (3 each), mass, vol0, vol, sigma (9) */
  return sizeof(double) * (3 * 4 + 3 + 9);
}

size_t mpm_group_bytes_per_particle(const mpm_group *g) {
  size_t b = 0;
  if (g->F) b += 9;
  if (g->rho) b += 1;
  if (g->energy) b += 1;
  if (g->pressure) b += 1;
  if (g->q) b += 1;
  return b * sizeof(double);
}

size_t mpm_grid_bytes(const mpm_grid *g) {
  size_t per_node = 1 + 3 * 4; /* mass, mom, force, vel0, vel_new */
  if (g->vel) per_node += 3;
  if (g->impedance) per_node += 2;
  if (g->force_prev) per_node += 3;
  per_node += (size_t)g->threads * g->acc_stride;
  size_t bytes = per_node * sizeof(double) * (size_t)g->n_nodes;
  if (g->owner) bytes += 3 * sizeof(short) * (size_t)g->n_nodes;
  if (g->fold) bytes += 6 * sizeof(double) * (size_t)g->n_nodes;
  return bytes;
}

/* ---- grid --------------------------------------------------------------- */

static pm_err grid_create(mpm_grid *g, const pm_scene *s) {
  g->dim = s->dimension;
  g->shape = s->mpm.shape;
  g->width = mpm_shape_width(g->shape);
  g->ghost = g->shape == PM_SHAPE_QUADRATIC ? 1 : 0;
  g->h = s->mesh_size;
  g->inv_h = 1.0 / g->h;
  g->node_volume = 1;
  g->n_nodes = 1;
  for (int c = 0; c < 3; c++) {
    if (c >= g->dim) {
      g->origin[c] = 0;
      g->nn[c] = 1;
      g->lo[c] = -INFINITY;
      g->hi[c] = INFINITY;
      continue;
    }
    double len = s->box_max[c] - s->box_min[c];
    long cells = (long)ceil(len / g->h - 1e-9);
    if (cells < 1) cells = 1;
    PM_CHECK(cells <= 100000, PM_ERR_SCENE,
             "%s: discretization.mesh_size: expected a cell size giving at "
             "most 100000 cells per axis, got %g (%ld cells along %c)",
             s->path, g->h, cells, "xyz"[c]);
    g->origin[c] = s->box_min[c] - g->ghost * g->h;
    g->nn[c] = cells + 1 + 2 * g->ghost;
    g->node_volume *= g->h;
    g->n_nodes *= g->nn[c];
    /* Where the stencil of x has its nodes in [0, nn - 1]: linear
     * 0 <= xi < nn - 1, quadratic 0.5 <= xi < nn - 1.5 (xi in cells from
     * the origin), less a margin of 1e-9 h. */
    double shift = g->ghost ? 0.5 : 0.0;
    g->lo[c] = g->origin[c] + (shift + 1e-9) * g->h;
    g->hi[c] = g->origin[c] + (g->nn[c] - 1 - shift - 1e-9) * g->h;
  }
  PM_CHECK(g->n_nodes <= 200000000L, PM_ERR_SCENE,
           "%s: discretization.mesh_size: expected at most 2e8 grid nodes, "
           "got %ld",
           s->path, g->n_nodes);
  g->stride[0] = 1;
  g->stride[1] = g->nn[0];
  g->stride[2] = g->nn[0] * g->nn[1];
  long n = g->n_nodes;
  PM_CALL(PM_ALLOC(g->mass, n, "grid masses"));
  PM_CALL(PM_ALLOC(g->mom, 3 * n, "grid momenta"));
  PM_CALL(PM_ALLOC(g->force, 3 * n, "grid forces"));
  PM_CALL(PM_ALLOC(g->vel0, 3 * n, "grid velocities"));
  if (s->mpm.update != PM_UPDATE_USL)
    PM_CALL(PM_ALLOC(g->vel, 3 * n, "grid velocities"));
  PM_CALL(PM_ALLOC(g->vel_new, 3 * n, "grid velocities"));
  g->vel_stress = g->vel ? g->vel : g->vel_new;
  return PM_SUCCESS;
}

void mpm_stencil_at(const mpm_grid *g, const double x[3], mpm_stencil *st) {
  st->base = 0;
  for (int c = 0; c < 3; c++) {
    if (c >= g->dim) {
      st->n[c] = 1;
      st->w[c][0] = 1;
      st->dw[c][0] = 0;
      continue;
    }
    long i0;
    mpm_shape_1d(g->shape, (x[c] - g->origin[c]) * g->inv_h, g->inv_h, &i0,
                 st->w[c], st->dw[c]);
    st->n[c] = g->width;
    st->base += i0 * g->stride[c];
  }
}

/* ---- seeding ------------------------------------------------------------ */

typedef struct {
  const pm_scene *s;
  gm_volume **vol; /* per body, for mesh shapes */
} seeder;

/* The last body containing x (later bodies take precedence), or -1. */
static int body_at(const seeder *sd, const double x[3]) {
  const pm_scene *s = sd->s;
  for (int b = s->n_bodies - 1; b >= 0; b--) {
    const pm_scene_body *body = &s->bodies[b];
    bool in = body->shape == PM_BODY_MESH
                  ? gm_volume_contains(sd->vol[b], x)
                  : pm_body_contains(body, s->dimension, x);
    if (in) return b;
  }
  return -1;
}

/* Bounding box of a body's shape; false when it has none (region, domain). */
static bool body_bounds(const seeder *sd, int b, double lo[3], double hi[3]) {
  const pm_scene_body *body = &sd->s->bodies[b];
  switch (body->shape) {
  case PM_BODY_BOX:
    for (int c = 0; c < 3; c++) lo[c] = body->a[c], hi[c] = body->b[c];
    return true;
  case PM_BODY_SPHERE:
    for (int c = 0; c < 3; c++)
      lo[c] = body->a[c] - body->radius, hi[c] = body->a[c] + body->radius;
    return true;
  case PM_BODY_CYLINDER: {
    /* End discs of radius r about the axis. */
    double len = pm_v_norm(body->b);
    for (int c = 0; c < 3; c++) {
      double e = body->radius * sqrt(fmax(0, 1 - pow(body->b[c] / len, 2)));
      double a = body->a[c], t = body->a[c] + body->b[c];
      lo[c] = fmin(a, t) - e;
      hi[c] = fmax(a, t) + e;
    }
    return true;
  }
  case PM_BODY_MESH: gm_volume_bounds(sd->vol[b], lo, hi); return true;
  default: return false;
  }
}

static pm_err check_inside(const seeder *sd) {
  const pm_scene *s = sd->s;
  static const char *const key[] = {"",       "region",   "box",
                                    "sphere", "cylinder", "mesh"};
  for (int b = 0; b < s->n_bodies; b++) {
    double lo[3], hi[3];
    if (!body_bounds(sd, b, lo, hi)) continue;
    for (int c = 0; c < s->dimension; c++) {
      double tol = 1e-9 * (s->box_max[c] - s->box_min[c]);
      if (lo[c] < s->box_min[c] - tol || hi[c] > s->box_max[c] + tol)
        return PM_ERROR(
            PM_ERR_SCENE,
            "%s:%d:%d: bodies.%d.%s: expected a shape inside the grid "
            "(domain.box, %c in [%g, %g]), got one reaching %c = %g: its "
            "particles would be outside the grid",
            s->path, s->bodies[b].mark.line, s->bodies[b].mark.col, b,
            key[s->bodies[b].shape], "xyz"[c], s -> box_min[c], s -> box_max[c],
            "xyz"[c], lo[c] < s -> box_min[c] - tol ? lo[c] : hi[c]);
    }
  }
  return PM_SUCCESS;
}

/* Visit every seed position: n^d per cell of the domain box, regularly
 * spaced, in cell order.  Calls fn(ctx, x, body) for positions in a body. */
typedef void (*seed_fn)(void *ctx, const double x[3], int body);

static void for_each_seed(const seeder *sd, const mpm_grid *g, seed_fn fn,
                          void *ctx) {
  const pm_scene *s = sd->s;
  long cells[3] = {1, 1, 1};
  int ppc[3] = {1, 1, 1};
  for (int c = 0; c < g->dim; c++) {
    cells[c] = g->nn[c] - 1 - 2 * g->ghost;
    ppc[c] = s->mpm.ppc[c];
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
  mpm_sim *sim;
  double vol;
} seed_ctx;

static void count_seed(void *ctx, const double x[3], int body) {
  seed_ctx *c = ctx;
  (void)x;
  c->count[c->s->bodies[body].material]++;
}

static void place_seed(void *ctx, const double x[3], int body) {
  seed_ctx *c = ctx;
  mpm_sim *sim = c->sim;
  const pm_scene_body *b = &c->s->bodies[body];
  mpm_group *g = &sim->group[c->group_of[b->material]];
  long p = c->next[b->material]++;
  long k = p - g->begin;
  for (int d = 0; d < 3; d++) {
    sim->x0[3 * p + d] = x[d];
    sim->x[3 * p + d] = x[d];
    sim->v[3 * p + d] = b->velocity[d];
  }
  /* The particle's share of its cell, clipped to the domain box where the
   * box is not a whole number of sub-cells. */
  double vol = c->vol;
  for (int d = 0; d < c->s->dimension; d++) {
    double hs = sim->grid.h / c->s->mpm.ppc[d];
    double top = x[d] + 0.5 * hs, end = c->s->box_max[d];
    if (top > end + 1e-12 * hs) vol *= (end - (x[d] - 0.5 * hs)) / hs;
  }
  sim->vol0[p] = vol;
  sim->vol[p] = vol;
  sim->mass[p] = b->density * vol;
  double *sig = sim->sigma + 9 * p;
  if (g->F) pm_t_identity(g->F + 9 * k);
  if (g->fluid) {
    g->rho[k] = b->density;
    g->pressure[k] = b->pressure;
    g->energy[k] = pm_eos_energy(&g->fluid_props, b->density, b->pressure);
    sig[0] = sig[4] = sig[8] = -b->pressure;
  }
}

static pm_err seed(mpm_sim *sim, const pm_scene *s) {
  pm_err ret = PM_SUCCESS;
  seeder sd = {.s = s, .vol = NULL};
  seed_ctx c;
  memset(&c, 0, sizeof c);
  c.s = s;
  c.sim = sim;
  PM_TRY(PM_ALLOC(sd.vol, s->n_bodies, "body volumes"));
  for (int b = 0; b < s->n_bodies; b++)
    if (s->bodies[b].shape == PM_BODY_MESH) {
      ret = gm_volume_load(s->bodies[b].mesh, s->dimension, 0.5 * s->mesh_size,
                           &sd.vol[b]);
      if (ret) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", pm_error_message());
        PM_FAIL(PM_ERR_SCENE, "%s:%d:%d: bodies.%d.mesh: %s", s->path,
                s->bodies[b].mark.line, s->bodies[b].mark.col, b, msg);
      }
    }
  PM_TRY(check_inside(&sd));
  PM_ENSURE(s->n_materials <= MPM_MAX_GROUPS, PM_ERR_SCENE,
            "%s: at most %d materials are supported by method mpm, got %d",
            s->path, MPM_MAX_GROUPS, s->n_materials);
  for_each_seed(&sd, &sim->grid, count_seed, &c);
  /* One group per material that has particles, in material order. */
  long total = 0;
  for (int m = 0; m < s->n_materials; m++) {
    c.group_of[m] = -1;
    if (c.count[m] == 0) continue;
    const pm_scene_material *sm = &s->materials[m];
    mpm_group *g = &sim->group[sim->n_groups];
    c.group_of[m] = sim->n_groups++;
    g->material = m;
    g->name = sm->name;
    g->fluid = sm->fluid;
    g->solid = sm->mat;
    g->fluid_props = sm->fluid_props;
    g->c0 = sm->av_c0;
    g->c1 = sm->av_c1;
    g->begin = total;
    g->end = total + c.count[m];
    c.next[m] = total;
    total += c.count[m];
    long k = c.count[m];
    if (g->fluid) {
      sim->has_fluid = true;
      PM_TRY(PM_ALLOC(g->rho, k, "fluid densities"));
      PM_TRY(PM_ALLOC(g->energy, k, "fluid internal energies"));
      PM_TRY(PM_ALLOC(g->pressure, k, "fluid pressures"));
    } else {
      PM_TRY(PM_ALLOC(g->F, 9 * k, "deformation gradients"));
    }
    if (g->c0 > 0 || g->c1 > 0)
      PM_TRY(PM_ALLOC(g->q, k, "artificial viscosity pressures"));
  }
  PM_ENSURE(total > 0, PM_ERR_SCENE,
            "%s: no particles: no seed position (%d x %d x %d per cell of "
            "size %g) lies in a body",
            s->path, s->mpm.ppc[0], s->mpm.ppc[1], s->mpm.ppc[2], s->mesh_size);
  sim->n = total;
  PM_TRY(PM_ALLOC(sim->x0, 3 * total, "particle positions"));
  PM_TRY(PM_ALLOC(sim->x, 3 * total, "particle positions"));
  PM_TRY(PM_ALLOC(sim->v, 3 * total, "particle velocities"));
  PM_TRY(PM_ALLOC(sim->dx, 3 * total, "particle increments"));
  PM_TRY(PM_ALLOC(sim->mass, total, "particle masses"));
  PM_TRY(PM_ALLOC(sim->vol0, total, "particle volumes"));
  PM_TRY(PM_ALLOC(sim->vol, total, "particle volumes"));
  PM_TRY(PM_ALLOC(sim->sigma, 9 * total, "particle stresses"));
  c.vol = sim->grid.node_volume / (s->mpm.ppc[0] * (double)s->mpm.ppc[1] *
                                   (s->dimension == 3 ? s->mpm.ppc[2] : 1));
  for_each_seed(&sd, &sim->grid, place_seed, &c);
done:
  if (sd.vol)
    for (int b = 0; b < s->n_bodies; b++) gm_volume_destroy(sd.vol[b]);
  free(sd.vol);
  return ret;
}

/* ---- boundary conditions ------------------------------------------------ */

static pm_err build_bcs(mpm_sim *sim, const pm_scene *s) {
  mpm_grid *g = &sim->grid;
  PM_CALL(PM_ALLOC(sim->bcs, s->n_bcs, "grid boundary conditions"));
  sim->n_bcs = s->n_bcs;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *sb = &s->bcs[b];
    mpm_bc *bc = &sim->bcs[b];
    bc->bc = b;
    bc->axis = pm_face_axis(sb->face);
    bc->plane = pm_face_plane(sb->face, s->box_min, s->box_max);
    bool is_max = sb->face == PM_FACE_XMAX || sb->face == PM_FACE_YMAX ||
                  sb->face == PM_FACE_ZMAX;
    bc->outward = is_max ? 1.0 : -1.0;
    bc->disp_mask = sb->disp_mask;
    bc->vel_mask = sb->velocity_mask;
    bc->absorbing = sb->absorbing;
    if (bc->absorbing) sim->has_absorbing = true;
    for (int c = 0; c < 3; c++) {
      const pm_expr *e = sb->disp[c] ? sb->disp[c] : sb->velocity[c];
      bc->constant[c] = !e || (!pm_expr_uses(e, 'x') && !pm_expr_uses(e, 'y') &&
                               !pm_expr_uses(e, 'z'));
    }
    /* Columns: every node of the face plane. */
    int a = bc->axis, t1 = (a + 1) % 3, t2 = (a + 2) % 3;
    long n1 = g->nn[t1], n2 = g->nn[t2];
    bc->n_cols = n1 * n2;
    PM_CALL(PM_ALLOC(bc->col, bc->n_cols, "boundary columns"));
    long ia = (long)llround((bc->plane - g->origin[a]) * g->inv_h);
    for (long j2 = 0; j2 < n2; j2++)
      for (long j1 = 0; j1 < n1; j1++)
        bc->col[j1 + n1 * j2] =
            ia * g->stride[a] + j1 * g->stride[t1] + j2 * g->stride[t2];
  }
  return PM_SUCCESS;
}

/* ---- create / destroy --------------------------------------------------- */

pm_err mpm_model_create(const pm_scene *s, mpm_sim **out) {
  pm_err ret = PM_SUCCESS;
  mpm_sim *sim = NULL;
  *out = NULL;
  PM_ENSURE(s->method == PM_METHOD_MPM, PM_ERR_ARG,
            "mpm_model_create: scene %s has method %s", s->path,
            pm_method_name(s->method));
  PM_TRY(PM_ALLOC(sim, 1, "MPM simulation"));
  sim->scene = s;
  sim->dim = s->dimension;
  PM_TRY(grid_create(&sim->grid, s));
  PM_TRY(seed(sim, s));
  PM_TRY(build_bcs(sim, s));
  mpm_grid *g = &sim->grid;
  g->threads = pm_omp_threads();
  g->acc_stride = sim->has_absorbing ? MPM_ACC_BASE + 2 : MPM_ACC_BASE;
  PM_TRY(PM_ALLOC(g->acc, (size_t)g->threads * g->n_nodes * g->acc_stride,
                  "per-thread grid accumulators"));
  if (sim->has_absorbing)
    PM_TRY(PM_ALLOC(g->impedance, 2 * g->n_nodes, "grid impedances"));
  if (sim->n_bcs > 0) {
    PM_TRY(PM_ALLOC(g->owner, 3 * g->n_nodes, "constrained dof owners"));
    PM_TRY(PM_ALLOC(g->fold, 3 * g->n_nodes, "folded condition forces"));
    PM_TRY(PM_ALLOC(g->fold_out, 3 * g->n_nodes, "folded condition forces"));
  }
  if (s->time.qs == PM_QS_DYNAMIC_RELAXATION)
    PM_TRY(PM_ALLOC(g->force_prev, 3 * g->n_nodes, "previous grid forces"));
  sim->dt_fixed = s->time.dt;
  sim->damping = s->time.qs == PM_QS_DAMPING ? s->time.qs_damping : 0;
  mpm_build_pipeline(sim);
  sim->dt_stable = mpm_stable_dt(sim);
  PM_ENSURE(sim->dt_fixed > 0 || isfinite(sim->dt_stable), PM_ERR_SCENE,
            "%s: no stable time step: no particle has a wave speed or a "
            "velocity (set time.dt)",
            s->path);
  sim->dt = sim->dt_fixed > 0 ? sim->dt_fixed : sim->dt_stable;
  *out = sim;
  sim = NULL;
done:
  mpm_model_destroy(sim);
  return ret;
}

void mpm_model_destroy(mpm_sim *sim) {
  if (!sim) return;
  mpm_grid *g = &sim->grid;
  free(g->mass);
  free(g->mom);
  free(g->force);
  free(g->vel0);
  free(g->vel);
  free(g->vel_new);
  free(g->acc);
  free(g->impedance);
  free(g->force_prev);
  free(g->owner);
  free(g->fold);
  free(g->fold_out);
  for (int k = 0; k < sim->n_groups; k++) {
    mpm_group *gr = &sim->group[k];
    free(gr->F);
    free(gr->rho);
    free(gr->energy);
    free(gr->pressure);
    free(gr->q);
  }
  for (int b = 0; b < sim->n_bcs; b++) free(sim->bcs[b].col);
  free(sim->bcs);
  free(sim->x0);
  free(sim->x);
  free(sim->v);
  free(sim->dx);
  free(sim->mass);
  free(sim->vol0);
  free(sim->vol);
  free(sim->sigma);
  free(sim);
}
