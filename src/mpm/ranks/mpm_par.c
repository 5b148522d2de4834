/* mpm_par: each rank's share of the model and state of an MPM run, and
 * the exchange table (mpm_exchange.h) that its core calls. */
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "mpm_seed.h"
#include "pm_par.h"
#include "pm_par_mpi.h"

static void fill_exchange(struct mpm_par *P);
static pm_err share_links(pm_qs_method qs, const mpm_grid *whole, bool gather,
                          mpm_model *lm, mpm_state *ls);
static void par_free(struct mpm_par *P);

/* ---- each rank's share -----------------------------------------------------
 */

/* This rank's block of the grid: its box's nodes and the ghost layers. */
static pm_err local_grid(struct mpm_par *P, const mpm_grid *full, mpm_grid *g) {
  long lo[3], hi[3];
  mpm_decomp_held(&P->d, P->rank, full, lo, hi);
  mpm_decomp_nodes(&P->d, P->rank, P->own_lo, P->own_hi);
  *g = *full;
  g->n_nodes = 1;
  for (int a = 0; a < 3; a++) {
    g->offset[a] = a < full->dim ? lo[a] : 0;
    g->nn[a] = a < full->dim ? hi[a] - lo[a] : 1;
    g->n_nodes *= g->nn[a];
  }
  g->stride[0] = 1;
  g->stride[1] = g->nn[0];
  g->stride[2] = g->nn[0] * g->nn[1];
  PM_CALL(PM_ALLOC(P->owned, g->n_nodes, "owned nodes"));
  P->n_owned = 0;
  for (long k = 0; k < g->nn[2]; k++)
    for (long j = 0; j < g->nn[1]; j++)
      for (long i = 0; i < g->nn[0]; i++) {
        const long q[3] = {i + g->offset[0], j + g->offset[1],
                           k + g->offset[2]};
        bool own = true;
        for (int a = 0; a < full->dim; a++)
          own = own && q[a] >= P->own_lo[a] && q[a] < P->own_hi[a];
        P->owned[i + j * g->stride[1] + k * g->stride[2]] = own;
        P->n_owned += own;
      }
  return PM_SUCCESS;
}

/* The first local particle whose one-process index is at least q. */
static long first_at_least(const long *gid, long n, long q) {
  long lo = 0, hi = n;
  while (lo < hi) {
    long mid = lo + (hi - lo) / 2;
    if (gid[mid] < q)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* Body and group ranges from the particles' indices (after a change). */
void mpm_par_set_ranges(mpm_model *m, mpm_state *s) {
  const struct mpm_par *P = par_of(m);
  for (int b = 0; b < m->n_bodies; b++) {
    m->body_begin[b] = first_at_least(m->gid, m->n, P->bbegin[b]);
    m->body_end[b] = first_at_least(m->gid, m->n, P->bend[b]);
  }
  for (int k = 0; k < m->n_moving; k++) {
    m->moving[k].begin = m->body_begin[m->moving[k].body];
    m->moving[k].end = m->body_end[m->moving[k].body];
  }
  for (int gi = 0; gi < m->n_groups; gi++) {
    mpm_group *g = &m->group[gi];
    g->begin = first_at_least(m->gid, m->n, P->gbegin[gi]);
    g->end = first_at_least(m->gid, m->n, P->gend[gi]);
    for (int k = 0; k < g->n_arrays; k++) {
      g->layout[k].count = g->end - g->begin;
      if (s) s->group[gi].array[k].count = g->end - g->begin;
    }
  }
}

/* The node sums' graph: every node this rank holds but does not own, and
 * where its owner holds it (the owner's block is computed as this rank's
 * is: its nodes and the ghost layers, clipped to the grid). */
static pm_err make_ghosts(struct mpm_par *P, const mpm_grid *full,
                          const mpm_grid *g) {
  pm_err ret = PM_SUCCESS;
  const mpm_decomp *d = &P->d;
  const long n_ghost = g->n_nodes - P->n_owned;
  long *leaf = NULL, *at = NULL;
  int *owner = NULL;
  PM_TRY(PM_ALLOC(leaf, n_ghost + 1, "ghost nodes"));
  PM_TRY(PM_ALLOC(owner, n_ghost + 1, "ghost nodes' owners"));
  PM_TRY(PM_ALLOC(at, n_ghost + 1, "ghost nodes' owners"));
  long k = 0;
  for (long i = 0; i < g->n_nodes; i++) {
    if (P->owned[i]) continue;
    const long q[3] = {i % g->nn[0] + g->offset[0],
                       (i / g->nn[0]) % g->nn[1] + g->offset[1],
                       i / (g->nn[0] * g->nn[1]) + g->offset[2]};
    const int r = mpm_decomp_rank_of(d, q);
    long lo[3], hi[3], step = 1;
    mpm_decomp_held(d, r, full, lo, hi);
    at[k] = 0;
    for (int a = 0; a < 3; a++) {
      at[k] += (q[a] - lo[a]) * step;
      step *= hi[a] - lo[a];
    }
    leaf[k] = i;
    owner[k] = r;
    k++;
  }
  /* A node's mass, momentum, force and impedances at most at once. */
  PM_TRY(pm_halo_create(pm_par_comm(), k, leaf, owner, at,
                        9 * (int)sizeof(double), &P->ghosts));
done:
  free(leaf);
  free(owner);
  free(at);
  return ret;
}

/* The ranks whose boxes touch this rank's, within a cell (those a
 * particle can move to in a step), and their graph communicator. */
static pm_err make_near(struct mpm_par *P, const mpm_model *m) {
  const mpm_decomp *d = &P->d;
  const long *me = d->box + 6 * P->rank;
  PM_CALL(PM_ALLOC(P->near_of, d->size, "near ranks"));
  int *list = NULL, *weight = NULL; /* (all 1: one step's particles) */
  PM_CALL(PM_ALLOC(list, d->size + 1, "near ranks"));
  if (PM_ALLOC(weight, d->size + 1, "near ranks")) {
    free(list);
    return PM_ERR_MEMORY;
  }
  P->n_near = 0;
  for (int q = 0; q < d->size; q++) {
    P->near_of[q] = -1;
    if (q == P->rank) continue;
    const long *b = d->box + 6 * q;
    bool touch = true;
    for (int a = 0; a < m->dim; a++)
      touch = touch && b[a] <= me[3 + a] && me[a] <= b[3 + a];
    if (!touch) continue;
    P->near_of[q] = P->n_near;
    weight[P->n_near] = 1;
    list[P->n_near++] = q;
  }
  int e = MPI_Dist_graph_create_adjacent(pm_par_comm(), P->n_near, list, weight,
                                         P->n_near, list, weight, MPI_INFO_NULL,
                                         0, &P->near);
  free(list);
  free(weight);
  PM_CHECK(e == MPI_SUCCESS, PM_ERR_INTERNAL,
           "MPI_Dist_graph_create_adjacent failed (%d)", e);
  return PM_SUCCESS;
}

/* The local model's particles: those of full model m in this rank's cells,
 * their constants and groups (set up anew from the scene), bodies,
 * conditions and pipeline. */
static pm_err local_model(const pm_scene *s, const mpm_model *m,
                          const mpm_state *st, struct mpm_par *P,
                          mpm_model **out) {
  pm_err ret = PM_SUCCESS;
  mpm_model *lm = NULL;
  long *sel = NULL;
  *out = NULL;
  mpm_grid grid;
  PM_TRY(local_grid(P, &m->grid, &grid));
  PM_TRY(make_ghosts(P, &m->grid, &grid));
  /* The particles in this rank's cells now (at the start, or where a
   * resumed run's checkpoint has them). */
  long n = 0;
  for (long p = 0; p < m->n; p++)
    n += mpm_decomp_rank_at(&P->d, &m->grid, st->x + 3 * p) == P->rank;
  PM_TRY(PM_ALLOC(sel, n + 1, "this rank's particles"));
  for (long p = 0, k = 0; p < m->n; p++)
    if (mpm_decomp_rank_at(&P->d, &m->grid, st->x + 3 * p) == P->rank)
      sel[k++] = p;
  PM_TRY(mpm_model_subset(s, m, &grid, sel, n, mpm_par_room_for, &lm));
  /* The whole model's group and body ranges, which migration keeps. */
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *fg = &m->group[gi];
    P->gbegin[gi] = fg->begin;
    P->gend[gi] = fg->end;
    if (fg->kind->ranks_share)
      PM_TRY(fg->kind->ranks_share(fg, &lm->group[gi]));
  }
  P->n_full = m->n;
  PM_TRY(PM_ALLOC(P->bbegin, m->n_bodies + 1, "body ranges"));
  PM_TRY(PM_ALLOC(P->bend, m->n_bodies + 1, "body ranges"));
  for (int b = 0; b < m->n_bodies; b++) {
    P->bbegin[b] = m->body_begin[b];
    P->bend[b] = m->body_end[b];
  }
  lm->xc = &P->xc;
  mpm_par_set_ranges(lm, NULL);
  *out = lm;
  lm = NULL;
done:
  free(sel);
  if (lm) lm->xc = NULL; /* P is the caller's until it is attached */
  mpm_model_destroy(lm);
  return ret;
}

/* The local state: the full state's values of this rank's particles and
 * nodes; the energy accounts this rank's row of `accounts` (each rank sums
 * its own from there), or without them all on rank 0. */
static pm_err local_state(const mpm_model *m, const mpm_state *st,
                          const mpm_model *lm, const double *accounts,
                          mpm_state **out) {
  mpm_state *ls = NULL;
  PM_CALL(mpm_state_create(lm, &ls));
  const struct mpm_par *P = par_of(lm);
  mpm_par_take_state(m, st, lm, ls);
  if (accounts) {
    const double *row = accounts + MPM_PAR_ACCOUNTS * P->rank;
    memcpy(ls->energy, row, sizeof ls->energy);
    ls->external_work = row[MPM_PAR_ACCOUNTS - 2];
    ls->dissipated = row[MPM_PAR_ACCOUNTS - 1];
  } else if (P->rank != 0) {
    memset(ls->energy, 0, sizeof ls->energy);
    ls->external_work = ls->dissipated = 0;
  }
  *out = ls;
  return PM_SUCCESS;
}

void mpm_par_take_state(const mpm_model *m, const mpm_state *st,
                        const mpm_model *lm, mpm_state *ls) {
  for (long k = 0; k < lm->n; k++) {
    const long p = lm->gid[k];
    memcpy(ls->x + 3 * k, st->x + 3 * p, 3 * sizeof(double));
    memcpy(ls->v + 3 * k, st->v + 3 * p, 3 * sizeof(double));
    ls->vol[k] = st->vol[p];
    memcpy(ls->sigma + 9 * k, st->sigma + 9 * p, 9 * sizeof(double));
  }
  for (int gi = 0; gi < lm->n_groups; gi++) {
    const mpm_group *g = &lm->group[gi];
    for (int a = 0; a < ls->group[gi].n; a++) {
      const mpm_array *src = &st->group[gi].array[a];
      mpm_array *dst = &ls->group[gi].array[a];
      const int nc = dst->ncomp;
      for (long k = g->begin; k < g->end; k++)
        memcpy(dst->data + (k - g->begin) * nc,
               src->data + (lm->gid[k] - m->group[gi].begin) * nc,
               nc * sizeof(double));
    }
  }
  /* Scalars: every rank's the same (the energy accounts are set by the
   * caller). */
  mpm_state_copy_values(ls, st);
  /* Nodal arrays of dynamic relaxation, from the whole grid's. */
  const mpm_grid *g = &lm->grid, *fg = &m->grid;
  for (long i = 0; i < g->n_nodes && ls->force_prev; i++) {
    long q = 0, r = i;
    for (int a = 2; a >= 0; a--) {
      long ia = r / g->stride[a];
      r -= ia * g->stride[a];
      q += (ia + g->offset[a]) * fg->stride[a];
    }
    memcpy(ls->force_prev + 3 * i, st->force_prev + 3 * q, 3 * sizeof(double));
    if (ls->fixed) memcpy(ls->fixed + 3 * i, st->fixed + 3 * q, 3);
  }
}

/* Doubles of a migration record for model m's groups, and of its widest
 * per-particle array (the stress's 9 at least). */
static int record_doubles(const mpm_model *m, int *width) {
  int most = 0;
  *width = 9;
  for (int gi = 0; gi < m->n_groups; gi++) {
    int sum = 0;
    for (int k = 0; k < m->group[gi].n_arrays; k++) {
      const int nc = m->group[gi].layout[k].ncomp;
      sum += nc;
      *width = nc > *width ? nc : *width;
    }
    most = sum > most ? sum : most;
  }
  return REC_BASE + most;
}

double mpm_par_balance_of(const pm_scene *s) {
  if (strcmp(s->method, "mpm") != 0 || s->time.qs != PM_QS_NONE) return 0;
  return mpm_scene_settings(s)->rebalance;
}

static void set_balance(struct mpm_par *P, const pm_scene *s, bool gather) {
  P->scene = s;
  P->gather = gather;
  P->balance = mpm_par_balance_of(s);
}

pm_err mpm_par_create(const pm_scene *s, const mpm_model *m,
                      const mpm_state *st, const double *accounts,
                      const long *cut, mpm_model **local,
                      mpm_state **local_state_out) {
  pm_err ret = PM_SUCCESS;
  struct mpm_par *P = NULL;
  mpm_model *lm = NULL;
  mpm_state *ls = NULL;
  const int size = pm_par_size();
  *local = NULL;
  *local_state_out = NULL;
  /* Every rank decomposes alike; a failure of one (memory) stops all
   * before the collectives that follow. */
  ret = PM_ALLOC(P, 1, "run across ranks");
  if (!ret)
    ret = cut ? mpm_decomp_unpack(cut, size, &m->grid, "the cut of the boxes",
                                  &P->d)
              : mpm_decomp_create(s, m, size, &P->d);
  PM_TRY(pm_par_agree(ret));
  P->rank = pm_par_rank();
  fill_exchange(P);
  set_balance(P, s, true);
  ret = local_model(s, m, st, P, &lm);
  if (!ret) P = NULL; /* lm holds it */
  if (!ret) ret = local_state(m, st, lm, accounts, &ls);
  PM_TRY(pm_par_agree(ret));
  PM_TRY(share_links(m->opt.qs, &m->grid, true, lm, ls));
  *local = lm;
  *local_state_out = ls;
  lm = NULL;
  ls = NULL;
done:
  par_free(P);
  mpm_state_destroy(ls);
  mpm_model_destroy(lm);
  return ret;
}

/* What links share lm (state ls) with the other ranks: the ranks near
 * it, its membranes' ghosts, the migration's buffers and, with dynamic
 * relaxation, the nodal gather's (on rank 0 of the whole grid `whole`);
 * on rank 0 with `gather`, the buffers that gather the whole run. */
static pm_err share_links(pm_qs_method qs, const mpm_grid *whole, bool gather,
                          mpm_model *lm, mpm_state *ls) {
  const int size = pm_par_size();
  struct mpm_par *Q = par_of(lm);
  Q->counts.most = lm->n;
  PM_CALL(make_near(Q, lm));
  PM_CALL(mpm_ghosts_create(lm, ls, &Q->d, Q->gbegin, Q->gend, Q->near,
                            Q->n_near, &Q->gh));
  Q->rec = record_doubles(lm, &Q->width);
  const long room = mpm_model_room(lm);
  PM_CALL(PM_ALLOC(Q->dest, room, "migration ranks"));
  PM_CALL(PM_ALLOC(Q->order, room, "migration order"));
  PM_CALL(PM_ALLOC(Q->tmp, Q->width * room, "migration buffer"));
  PM_CALL(PM_ALLOC(Q->scount, size, "migration counts"));
  PM_CALL(PM_ALLOC(Q->rcount, size, "migration counts"));
  PM_CALL(PM_ALLOC(Q->sdisp, size + 1, "migration offsets"));
  PM_CALL(PM_ALLOC(Q->rdisp, size + 1, "migration offsets"));
  PM_CALL(PM_ALLOC(Q->gcount, size, "gather counts"));
  PM_CALL(PM_ALLOC(Q->gdisp, size + 1, "gather offsets"));
  PM_CALL(PM_ALLOC(Q->extreme, 5 * size, "extremes over the ranks"));
  Q->sbuf_room = Q->rbuf_room = 64 + room / 8;
  PM_CALL(PM_ALLOC(Q->sbuf, Q->sbuf_room * Q->rec, "migration buffer"));
  PM_CALL(PM_ALLOC(Q->rbuf, Q->rbuf_room * Q->rec, "migration buffer"));
  if (qs == PM_QS_DYNAMIC_RELAXATION) {
    PM_CALL(PM_ALLOC(Q->nodal, 3 * Q->n_owned + 1, "nodal gather"));
    if (Q->rank == 0 && gather)
      PM_CALL(PM_ALLOC(Q->whole, 3 * whole->n_nodes, "nodal gather"));
  }
  if (Q->rank == 0) {
    PM_CALL(PM_ALLOC(Q->accounts, MPM_PAR_ACCOUNTS * size, "energy accounts"));
    if (gather) {
      PM_CALL(PM_ALLOC(Q->ggid, Q->n_full, "gather indices"));
      PM_CALL(PM_ALLOC(Q->gbuf, Q->width * Q->n_full, "gather buffer"));
    }
  }
  return PM_SUCCESS;
}

/* Each rank's particles at x: whether rank `rank` of d keeps them. */
typedef struct {
  const mpm_decomp *d;
  const mpm_grid *g;
  int rank;
  long cells[3], *per_cell;
} box_test;

static bool in_box(void *ctx, const double x[3]) {
  const box_test *bt = ctx;
  return mpm_decomp_rank_at(bt->d, bt->g, x) == bt->rank;
}

static bool count_in_cell(void *ctx, const double x[3]) {
  box_test *bt = ctx;
  mpm_decomp_count(bt->g, bt->cells, x, bt->per_cell);
  return false;
}

/* The decomposition of the whole run from the particles per cell, which
 * every rank counts as one process seeds them (none stored). */
static pm_err decompose(const pm_scene *s, const mpm_model *frame,
                        mpm_decomp *d) {
  box_test bt = {.g = &frame->grid};
  PM_CALL(PM_ALLOC(bt.per_cell, mpm_decomp_cells(bt.g, bt.cells),
                   "particles per cell"));
  mpm_seed_share count = {.keep = count_in_cell, .ctx = &bt};
  pm_err e = mpm_seed_visit(s, frame, &count);
  long total = 0;
  for (long c = 0; !e && c < bt.cells[0] * bt.cells[1] * bt.cells[2]; c++)
    total += bt.per_cell[c];
  if (!e)
    e = mpm_decomp_from_counts(s, frame, pm_par_size(), bt.per_cell, total, d);
  free(bt.per_cell);
  return e;
}

pm_err mpm_par_create_seeded(const pm_scene *s, bool gather, mpm_model **local,
                             mpm_state **local_state_out) {
  return mpm_par_create_picked(s, gather, NULL, local, local_state_out);
}

pm_err mpm_par_create_picked(const pm_scene *s, bool gather,
                             const mpm_par_pick *pick, mpm_model **local,
                             mpm_state **local_state_out) {
  return mpm_par_create_cut(s, gather, NULL, pick, local, local_state_out);
}

pm_err mpm_par_create_cut(const pm_scene *s, bool gather, const long *cut,
                          const mpm_par_pick *pick, mpm_model **local,
                          mpm_state **local_state_out) {
  pm_err ret = PM_SUCCESS;
  struct mpm_par *P = NULL;
  mpm_model *frame = NULL, *lm = NULL;
  mpm_state *ls = NULL;
  mpm_seed_share sh = {.room = mpm_par_room_for};
  *local = NULL;
  *local_state_out = NULL;
  ret = mpm_model_frame(s, &frame);
  if (!ret) ret = PM_ALLOC(P, 1, "run across ranks");
  if (!ret)
    ret = cut ? mpm_decomp_unpack(cut, pm_par_size(), &frame->grid,
                                  "the cut of the boxes", &P->d)
              : decompose(s, frame, &P->d);
  PM_TRY(pm_par_agree(ret));
  P->rank = pm_par_rank();
  fill_exchange(P);
  set_balance(P, s, gather);
  mpm_grid grid;
  ret = local_grid(P, &frame->grid, &grid);
  if (!ret) ret = make_ghosts(P, &frame->grid, &grid);
  box_test bt = {.d = &P->d, .g = &frame->grid, .rank = P->rank};
  sh.keep = in_box;
  sh.ctx = &bt;
  if (pick) { /* (its particles are where a checkpoint has them) */
    if (!ret && pick->prepare)
      ret = pick->prepare(pick->ctx, &P->d, &frame->grid, P->rank);
    sh.keep = pick->keep;
    sh.ctx = pick->ctx;
  }
  if (!ret) ret = mpm_model_share(s, &grid, &sh, &lm, &ls);
  PM_TRY(pm_par_agree(ret));
  /* The whole run's ranges, which migration keeps. */
  for (int gi = 0; gi < lm->n_groups; gi++) {
    P->gbegin[gi] = sh.gbegin[gi];
    P->gend[gi] = sh.gend[gi];
  }
  P->n_full = sh.n_full;
  P->bbegin = sh.bbegin;
  P->bend = sh.bend;
  sh.bbegin = sh.bend = NULL;
  lm->xc = &P->xc;
  P = NULL; /* lm holds it */
  mpm_par_set_ranges(lm, ls);
  /* The first step: the least of the shares' stable steps, as one
   * process finds it over all its particles. */
  pm_par_min(&ls->dt_stable, 1);
  PM_TRY(pm_par_agree(mpm_model_first_dt(s, lm, ls)));
  PM_TRY(share_links(lm->opt.qs, &frame->grid, gather, lm, ls));
  *local = lm;
  *local_state_out = ls;
  lm = NULL;
  ls = NULL;
done:
  free(sh.bbegin);
  free(sh.bend);
  par_free(P);
  mpm_state_destroy(ls);
  mpm_model_destroy(lm);
  mpm_model_destroy(frame);
  return ret;
}

static void par_free(struct mpm_par *P) {
  if (!P) return;
  pm_halo_destroy(P->ghosts);
  free(P->nodal);
  free(P->extreme);
  free(P->whole);
  mpm_ghosts_destroy(P->gh);
  if (P->near_of) MPI_Comm_free(&P->near);
  free(P->near_of);
  mpm_decomp_destroy(&P->d);
  free(P->owned);
  free(P->bbegin);
  free(P->bend);
  free(P->dest);
  free(P->scount);
  free(P->rcount);
  free(P->sdisp);
  free(P->rdisp);
  free(P->sbuf);
  free(P->rbuf);
  free(P->order);
  free(P->tmp);
  free(P->accounts);
  free(P->ggid);
  free(P->gbuf);
  free(P->gcount);
  free(P->gdisp);
  mpm_model_destroy(P->frame);
  free(P->per_cell);
  free(P);
}

static void par_work_attach(const mpm_model *m, mpm_work *w) {
  w->nodes.owned = par_of(m)->owned;
  w->timer_migrate = pm_timers_add(&w->timers, "migrate");
}

const mpm_decomp *mpm_par_decomp(const mpm_model *m) { return &par_of(m)->d; }

const double *mpm_par_accounts(const mpm_model *m) {
  return par_of(m)->accounts;
}

void mpm_par_get_counts(const mpm_model *m, mpm_par_counts *c) {
  *c = m->xc ? par_of(m)->counts : (mpm_par_counts){0};
}

/* The core's reductions over the ranks (mpm_exchange.h). */
static void xc_sum(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_sum(v, n);
}
static void xc_max(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_max(v, n);
}
static void xc_min(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_min(v, n);
}
static void xc_sum_long(void *ctx, long *v, int n) {
  (void)ctx;
  pm_par_sum_long(v, n);
}
static pm_err xc_agree(void *ctx, pm_err e) {
  (void)ctx;
  return pm_par_agree(e);
}
static long xc_offset(void *ctx, long n) {
  (void)ctx;
  return pm_par_offset(n);
}
static void xc_release(mpm_exchange *xc) { par_free(xc->ctx); }

/* The exchange that a local model holds: this share's operations. */
static void fill_exchange(struct mpm_par *P) {
  P->xc = (mpm_exchange){.ctx = P,
                         .sum = xc_sum,
                         .max = xc_max,
                         .min = xc_min,
                         .sum_long = xc_sum_long,
                         .agree = xc_agree,
                         .offset = xc_offset,
                         .sum_nodes = mpm_par_sum_nodes,
                         .nodes_reduce = mpm_par_nodes_reduce,
                         .nodes_bcast = mpm_par_nodes_bcast,
                         .owned = mpm_par_owned,
                         .work_attach = par_work_attach,
                         .step_end = mpm_par_step_end,
                         .migrate = mpm_par_migrate,
                         .ghost_x = mpm_par_ghost_x,
                         .ghost_ids = mpm_par_ghost_ids,
                         .nearby = mpm_par_nearby,
                         .cells = mpm_par_cells,
                         .number_unknowns = mpm_par_number_unknowns,
                         .gather_nodes = mpm_par_gather_nodes,
                         .release = xc_release};
}
