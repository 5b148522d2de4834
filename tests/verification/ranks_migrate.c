/* Particle migration across ranks moves particles and nothing else: run
 * under mpirun (tests/verification/ranks.sh), it steps a scene and checks
 * after every migration that
 *  - every particle of the run is on exactly one rank (the one-process
 *    indices 0..N-1, each once) and sits in a cell of its rank;
 *  - each particle's constants (mass, reference position and volume) are
 *    those it had on one process, bit for bit;
 *  - the state gathered in one-process order (positions, velocities,
 *    volumes, stresses, each group's arrays) and the total mass and
 *    momentum summed in that order are the same before and after the
 *    migration, bit for bit;
 *  - with membranes, every rank's ghosts are exactly the points of other
 *    ranks that its membrane points are linked to (the other corners of
 *    every triangle it has a corner of, the neighbours along a curve),
 *    each held by one other rank, at that rank's position bit for bit:
 *    every triangle's three points found; and where a membrane's normals
 *    are fitted per cell, its nearby points are exactly the points of
 *    other ranks in the cells within the fits' reach of the rank's box.  It
 * prints how many triangles (or a curve's segments) span two ranks or more and
 * how many membrane points moved.  First, each rank's share seeded from the
 * scene with no whole model on any rank (mpm_par_create_seeded) is the
 * share cut from the whole model (mpm_par_create), bit for bit: its
 * decomposition, particles, constants, state, groups, bodies and first
 * step. Usage: ranks_migrate SCENE STEPS
 * [KEY=VALUE...]; prints a line per check and exits 0 when all hold. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_curve.h"
#include "mpm_backend.h"
#include "mpm_kind.h"
#include "mpm_par.h"
#include "pm_app.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_scene.h"

static int failures;

static void expect(bool ok, const char *what, long step) {
  long bad = !ok;
  pm_par_sum_long(&bad, 1);
  if (bad && pm_par_root())
    printf("FAIL: step %ld: %s (on %ld ranks)\n", step, what, bad);
  failures += bad != 0;
}

/* The gathered state's arrays, copied. */
static double *snapshot(const mpm_model *m, const mpm_state *s, long *len) {
  mpm_array a[MPM_STATE_MAX_ARRAYS];
  int na = mpm_state_arrays(m, s, a, MPM_STATE_MAX_ARRAYS);
  long n = 0;
  for (int k = 0; k < na; k++) n += a[k].ncomp * a[k].count;
  double *copy = malloc(sizeof(double) * (size_t)(n + 1));
  long at = 0;
  for (int k = 0; k < na; k++) {
    memcpy(copy + at, a[k].data, sizeof(double) * a[k].ncomp * a[k].count);
    at += a[k].ncomp * a[k].count;
  }
  *len = n;
  return copy;
}

static int long_cmp(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* Whether this rank's ghosts of every linked group are the points of other
 * ranks its points are linked to in the one-process model ref (mine: 1
 * where this rank holds the particle), at positions x (the whole run's,
 * in one-process order). */
static bool ghosts_right(const mpm_model *m, const mpm_model *ref,
                         const char *mine, const double *x) {
  bool ok = true;
  long *need =
      malloc(sizeof(long) * (size_t)(6 * ref->n_tris + 2 * ref->n + 1));
  for (int gi = 0; gi < m->n_groups; gi++) {
    if (!m->group[gi].kind->ranks_link) continue;
    long n_need = 0, n;
    for (long t = ref->tri_begin[gi]; t < ref->tri_end[gi]; t++) {
      const long *c = ref->tri + 3 * t;
      if (!mine[c[0]] && !mine[c[1]] && !mine[c[2]]) continue;
      for (int k = 0; k < 3; k++)
        if (!mine[c[k]]) need[n_need++] = c[k];
    }
    for (int b = 0; b < ref->n_bodies; b++) {
      const long b0 = ref->body_begin[b], nb = ref->body_end[b] - b0;
      const int links = ref->body_links[b];
      if (b0 < ref->group[gi].begin || b0 >= ref->group[gi].end ||
          (links != MPM_LINKS_CHAIN && links != MPM_LINKS_LOOP))
        continue;
      for (long k = 0; k < nb; k++) {
        long prev, next;
        gm_curve_neighbours(k, nb, links == MPM_LINKS_LOOP, &prev, &next);
        if (!mine[b0 + k]) continue;
        if (!mine[b0 + prev]) need[n_need++] = b0 + prev;
        if (!mine[b0 + next]) need[n_need++] = b0 + next;
      }
    }
    qsort(need, (size_t)n_need, sizeof *need, long_cmp);
    long u = 0;
    for (long k = 0; k < n_need; k++)
      if (u == 0 || need[k] != need[u - 1]) need[u++] = need[k];
    const long *ids = mpm_xc_ghost_ids(m, gi, &n);
    const double *gx = mpm_xc_ghost_x(m, gi);
    ok = ok && n == u &&
         (n == 0 || !memcmp(ids, need, sizeof(long) * (size_t)n));
    for (long j = 0; ok && j < n; j++)
      ok = !memcmp(gx + 3 * j, x + 3 * ids[j], 3 * sizeof(double));
  }
  free(need);
  return ok;
}

/* Whether this rank's nearby points of every group whose kind reads the
 * cells around its own are the points of other ranks in those cells
 * (within the kind's reach of the rank's box), at positions x. */
static bool nearby_right(const mpm_model *m, const mpm_model *ref,
                         const char *mine, const double *x) {
  const mpm_decomp *d = mpm_par_decomp(m);
  const long *box = d->box + 6 * pm_par_rank();
  const mpm_grid *g = &ref->grid;
  bool ok = true;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_kind *k = m->group[gi].kind;
    const int reach = k->ranks_reach ? k->ranks_reach(&m->group[gi]) : 0;
    if (!reach) continue;
    long n, at = 0;
    const long *ids;
    const double *nx = mpm_xc_nearby(m, gi, &n, &ids);
    for (long p = ref->group[gi].begin; ok && p < ref->group[gi].end; p++) {
      bool in = !mine[p];
      for (int a = 0; a < g->dim; a++) {
        long c = (long)floor((x[3 * p + a] - g->origin[a]) * g->inv_h);
        c = c < 0 ? 0 : c >= d->cells[a] ? d->cells[a] - 1 : c;
        in = in && c >= box[a] - reach && c < box[3 + a] + reach;
      }
      if (!in) continue;
      ok = at < n && ids[at] == p &&
           !memcmp(nx + 3 * at, x + 3 * p, 3 * sizeof(double));
      at++;
    }
    ok = ok && at == n;
  }
  return ok;
}

static bool same_doubles(const double *a, const double *b, long n) {
  return n == 0 || !memcmp(a, b, sizeof(double) * (size_t)n);
}

/* Whether shares a (seeded) and b (cut from the whole) are alike. */
static bool shares_alike(const mpm_model *a, const mpm_state *as,
                         const mpm_model *b, const mpm_state *bs) {
  const mpm_decomp *da = mpm_par_decomp(a), *db = mpm_par_decomp(b);
  bool ok = a->n == b->n && a->cap == b->cap && a->n_groups == b->n_groups &&
            a->n_bodies == b->n_bodies && a->n_moving == b->n_moving &&
            a->n_bcs == b->n_bcs && a->kinds == b->kinds &&
            a->grid.n_nodes == b->grid.n_nodes &&
            !memcmp(a->grid.offset, b->grid.offset, sizeof a->grid.offset) &&
            !memcmp(da->box, db->box, sizeof(long) * 6 * (size_t)da->size) &&
            !memcmp(da->count, db->count, sizeof(long) * (size_t)da->size) &&
            as->dt == bs->dt && as->dt_stable == bs->dt_stable &&
            as->damping == bs->damping;
  if (!ok) return false;
  const long n = a->n;
  ok = (n == 0 || !memcmp(a->gid, b->gid, sizeof(long) * (size_t)n)) &&
       same_doubles(a->x0, b->x0, 3 * n) && same_doubles(a->mass, b->mass, n) &&
       same_doubles(a->vol0, b->vol0, n) && same_doubles(as->x, bs->x, 3 * n) &&
       same_doubles(as->v, bs->v, 3 * n) && same_doubles(as->vol, bs->vol, n) &&
       same_doubles(as->sigma, bs->sigma, 9 * n);
  for (int gi = 0; ok && gi < a->n_groups; gi++) {
    const mpm_group *ga = &a->group[gi], *gb = &b->group[gi];
    const mpm_group_state *sa = &as->group[gi], *sb = &bs->group[gi];
    ok = ga->begin == gb->begin && ga->end == gb->end && ga->cap == gb->cap &&
         ga->kind == gb->kind && sa->n == sb->n;
    for (int k = 0; ok && k < sa->n; k++)
      ok = sa->array[k].ncomp == sb->array[k].ncomp &&
           sa->array[k].count == sb->array[k].count &&
           same_doubles(sa->array[k].data, sb->array[k].data,
                        sa->array[k].ncomp * sa->array[k].count);
  }
  for (int k = 0; ok && k < a->n_bodies; k++)
    ok = a->body_begin[k] == b->body_begin[k] &&
         a->body_end[k] == b->body_end[k] &&
         a->body_links[k] == b->body_links[k] &&
         a->body_normals[k] == b->body_normals[k];
  for (int k = 0; ok && k < a->n_moving; k++)
    ok = a->moving[k].begin == b->moving[k].begin &&
         a->moving[k].end == b->moving[k].end &&
         a->moving[k].first == b->moving[k].first;
  return ok;
}

/* Total mass and momentum in one-process order. */
static void totals(const mpm_model *m, const mpm_state *s, double t[4]) {
  t[0] = t[1] = t[2] = t[3] = 0;
  for (long p = 0; p < m->n; p++) {
    t[0] += m->mass[p];
    for (int c = 0; c < 3; c++) t[1 + c] += m->mass[p] * s->v[3 * p + c];
  }
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: ranks_migrate SCENE STEPS [KEY=VALUE...]\n");
    return 2;
  }
  if (pm_app_init() || pm_par_init(&argc, &argv) ||
      pm_par_attach(MPI_COMM_WORLD)) {
    fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  const long steps = atol(argv[2]);
  pm_scene *sc = NULL;
  mpm_sim *r = NULL;
  if (pm_scene_load(argv[1], argc - 3, (const char *const *)argv + 3, &sc) ||
      mpm_sim_create(sc, &r)) {
    if (pm_par_root()) fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  if (!r->local_model) {
    fprintf(stderr,
            "ranks_migrate: run it under mpirun with 2 or more ranks\n");
    return 2;
  }
  /* Every rank's reference: the model as one process has it. */
  mpm_model *ref = NULL;
  mpm_state *ref_state = NULL;
  mpm_model *seeded = NULL, *cut = NULL;
  mpm_state *seeded_state = NULL, *cut_state = NULL;
  if (mpm_par_create_seeded(sc, false, &seeded, &seeded_state)) return 2;
  if (mpm_model_create(sc, &ref, &ref_state)) return 2;
  if (mpm_par_create(sc, ref, ref_state, NULL, NULL, &cut, &cut_state))
    return 2;
  expect(shares_alike(seeded, seeded_state, cut, cut_state),
         "the share seeded from the scene is the share cut from the whole "
         "model, bit for bit",
         0);
  mpm_state_destroy(seeded_state);
  mpm_model_destroy(seeded);
  mpm_state_destroy(cut_state);
  mpm_model_destroy(cut);
  mpm_model *m = r->local_model;
  mpm_state *s = r->local_state;
  mpm_work *w = r->local_work;
  const long N = ref->n;
  long moved = 0, linked_moved = 0, spanning = 0;
  int *owner = NULL, *owner_prev = NULL; /* rank 0's */
  char *mine = calloc((size_t)N + 1, 1);
  double *whole_x = malloc(sizeof(double) * 3 * (size_t)(N + 1));
  bool linked = false;
  for (int gi = 0; gi < m->n_groups; gi++)
    linked = linked || m->group[gi].kind->ranks_link ||
             m->group[gi].kind->ranks_reach;
  for (long step = 1; step <= steps; step++) {
    if (mpm_step(m, s, w)) {
      if (pm_par_root()) fprintf(stderr, "%s\n", pm_error_message());
      return 2;
    }
    long before_len = 0, after_len = 0;
    double *before = NULL, *after = NULL, tb[4], ta[4];
    mpm_par_gather(m, s, r->model, r->state);
    if (r->model) {
      before = snapshot(r->model, r->state, &before_len);
      totals(r->model, r->state, tb);
    }
    mpm_par_counts c0, c1;
    mpm_par_get_counts(m, &c0);
    if (mpm_xc_migrate(m, s, w)) return 2;
    mpm_par_get_counts(m, &c1);
    moved += c1.migrated - c0.migrated;
    /* Where every particle is, and what it carries. */
    long count = m->n;
    pm_par_sum_long(&count, 1);
    expect(count == N, "the ranks hold every particle", step);
    bool own = true, same = true, sorted = true;
    const mpm_decomp *d = mpm_par_decomp(m);
    for (long k = 0; k < m->n; k++) {
      const long p = m->gid[k];
      own =
          own && mpm_decomp_rank_at(d, &m->grid, s->x + 3 * k) == pm_par_rank();
      same = same && p >= 0 && p < N && m->mass[k] == ref->mass[p] &&
             m->vol0[k] == ref->vol0[p] &&
             !memcmp(m->x0 + 3 * k, ref->x0 + 3 * p, 3 * sizeof(double));
      sorted = sorted && (k == 0 || m->gid[k - 1] < p);
    }
    expect(own, "each particle on the rank of its cell", step);
    /* every one-process index once over the ranks */
    int cnt = (int)m->n, size = pm_par_size(), *counts = NULL, *offs = NULL;
    long *all = NULL;
    if (pm_par_root()) {
      counts = calloc((size_t)size, sizeof *counts);
      offs = calloc((size_t)size + 1, sizeof *offs);
      all = calloc((size_t)N + 1, sizeof *all);
    }
    MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, MPI_COMM_WORLD);
    bool once = true;
    if (pm_par_root()) {
      for (int q = 0; q < size; q++) offs[q + 1] = offs[q] + counts[q];
      once = offs[size] == N;
    }
    pm_par_bcast(&once, sizeof once);
    if (once) {
      MPI_Gatherv(m->gid, cnt, MPI_LONG, all, counts, offs, MPI_LONG, 0,
                  MPI_COMM_WORLD);
      if (pm_par_root()) {
        free(owner_prev);
        owner_prev = owner;
        owner = calloc((size_t)N + 1, sizeof *owner);
        for (int q = 0; q < size; q++)
          for (int k = offs[q]; k < offs[q + 1]; k++)
            if (all[k] >= 0 && all[k] < N) owner[all[k]] = q;
        char *seen = calloc((size_t)N, 1);
        for (long k = 0; k < N && once; k++) {
          once = all[k] >= 0 && all[k] < N && !seen[all[k]];
          if (once) seen[all[k]] = 1;
        }
        free(seen);
      }
    }
    free(counts);
    free(offs);
    free(all);
    expect(once, "every particle on exactly one rank", step);
    expect(same, "each particle's mass, x0 and V0 as on one process", step);
    expect(sorted, "a rank's particles in one-process order", step);
    mpm_par_gather(m, s, r->model, r->state);
    if (r->model) {
      after = snapshot(r->model, r->state, &after_len);
      totals(r->model, r->state, ta);
      same = before_len == after_len &&
             !memcmp(before, after, sizeof(double) * (size_t)before_len);
      same = same && !memcmp(tb, ta, sizeof tb);
    }
    pm_par_bcast(&same, sizeof same);
    expect(same, "state, mass and momentum gathered unchanged, bit for bit",
           step);
    if (linked && once) {
      /* The ghosts against the whole run's positions. */
      if (r->model)
        memcpy(whole_x, r->state->x, sizeof(double) * 3 * (size_t)N);
      MPI_Bcast(whole_x, (int)(3 * N), MPI_DOUBLE, 0, MPI_COMM_WORLD);
      memset(mine, 0, (size_t)N);
      for (long k = 0; k < m->n; k++) mine[m->gid[k]] = 1;
      expect(ghosts_right(m, ref, mine, whole_x),
             "ghosts: the points linked to this rank's, at their positions",
             step);
      expect(nearby_right(m, ref, mine, whole_x),
             "nearby points: those of other ranks within reach, at their "
             "positions",
             step);
      if (pm_par_root()) {
        long span = 0;
        for (long t = 0; t < ref->n_tris; t++) {
          const long *c = ref->tri + 3 * t;
          span += owner[c[0]] != owner[c[1]] || owner[c[0]] != owner[c[2]];
        }
        for (int b = 0; b < ref->n_bodies; b++) {
          const long b0 = ref->body_begin[b], nb = ref->body_end[b] - b0;
          const int links = ref->body_links[b];
          for (long k = 0; k + 1 < nb && (links == MPM_LINKS_CHAIN ||
                                          links == MPM_LINKS_LOOP);
               k++)
            span += owner[b0 + k] != owner[b0 + k + 1];
        }
        spanning = span > spanning ? span : spanning;
        for (int gi = 0; owner_prev && gi < ref->n_groups; gi++)
          if (ref->group[gi].kind->ranks_link)
            for (long p = ref->group[gi].begin; p < ref->group[gi].end; p++)
              linked_moved += owner[p] != owner_prev[p];
      }
    }
    free(before);
    free(after);
  }
  pm_par_sum_long(&moved, 1); /* each rank counted those it sent */
  if (pm_par_root() && linked)
    printf("%s: membrane points moved between ranks %ld, links spanning two "
           "ranks or more (triangles, a curve's segments) %ld (most at one "
           "step)\n",
           sc->name, linked_moved, spanning);
  if (pm_par_root())
    printf("%s: %ld steps on %d ranks, %ld particles migrated, %d failed "
           "check%s\n",
           sc->name, steps, pm_par_size(), moved, failures,
           failures == 1 ? "" : "s");
  free(owner);
  free(owner_prev);
  free(mine);
  free(whole_x);
  mpm_state_destroy(ref_state);
  mpm_model_destroy(ref);
  mpm_sim_destroy(r);
  pm_scene_destroy(sc);
  return failures ? 1 : 0;
}
