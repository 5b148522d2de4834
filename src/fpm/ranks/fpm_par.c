/* fpm_par: the shares of a run across ranks, the ghosts' displacements on
 * a neighbour exchange (pm_halo), the step's sums and failures, and the
 * gather to rank 0. */
#include "fpm_par.h"

#include <mpi.h>
#include <stdbool.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <stdlib.h>
#include <string.h>

#include "fpm_region.h"
#include "pm_halo.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

struct fpm_par {
  fpm_exchange xc; /* what the core calls (ctx: this) */
  int rank, size;
  int *owner;               /* every point's rank (the partition) */
  fpm_share_counts *counts; /* every rank's share, on rank 0 */
  /* the ghosts' displacements: each ghost (a leaf) is a point its owner
   * holds among its own (a root) */
  pm_halo *ghosts;
  /* the gather: each own point (a leaf) is a point of rank 0's whole
   * arrays (a root; none on the other ranks) */
  pm_halo *to_root;
  double none[9]; /* the roots of the gather on the other ranks */
  long n_ghost;   /* the share's ghost points */
  fpm_par_costs costs;
};

static void par_destroy(void *ctx) {
  struct fpm_par *P = ctx;
  if (!P) return;
  pm_halo_destroy(P->ghosts);
  pm_halo_destroy(P->to_root);
  free(P->owner);
  free(P->counts);
  free(P);
}

/* Where the ghosts' values come from: each point's rank and its index
 * among that rank's own points, over the points gid[0..n) (ascending; NULL:
 * the whole model's, gid[i] = i). */
typedef struct {
  const long *gid;
  const int *owner;
  const long *index;
  long n;
} roots;

/* The position of whole point g among r's points. */
static long root_of(const roots *r, long g) {
  if (!r->gid) return g;
  long lo = 0, hi = r->n - 1;
  while (lo < hi) {
    const long mid = lo + (hi - lo) / 2;
    if (r->gid[mid] < g)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* The exchanges: ghosts to their owners' own points (each rank's own
 * points are in one-process order, so an owner's index of a point is the
 * count of its points before it), own points to rank 0's whole arrays. */
static pm_err make_exchanges(struct fpm_par *P, const fpm_model *s,
                             const roots *from) {
  pm_err ret = PM_SUCCESS;
  const long n_ghost = s->n - s->n_own;
  const long most = (n_ghost > s->n_own ? n_ghost : s->n_own) + 1;
  long *leaf = NULL, *index = NULL;
  int *rank = NULL;
  PM_TRY(PM_ALLOC(leaf, most, "ghost points"));
  PM_TRY(PM_ALLOC(rank, most, "ghost points' owners"));
  PM_TRY(PM_ALLOC(index, most, "ghost points' owners"));
  for (long k = 0; k < n_ghost; k++) {
    const long at = root_of(from, s->gid[s->n_own + k]);
    PM_ENSURE(!from->gid || from->gid[at] == s->gid[s->n_own + k],
              PM_ERR_INTERNAL, "ghost point %ld is not in its rank's part",
              s->gid[s->n_own + k]);
    leaf[k] = s->n_own + k;
    rank[k] = from->owner[at];
    index[k] = from->index[at];
  }
  /* A point's displacement, or its averaged pressure. */
  PM_TRY(pm_halo_create(pm_par_comm(), n_ghost, leaf, rank, index,
                        3 * (int)sizeof(double), &P->ghosts));
  for (long k = 0; k < s->n_own; k++) {
    leaf[k] = k;
    rank[k] = 0;
    index[k] = s->gid[k];
  }
  /* The gather's widest array: a point's tensor. */
  PM_TRY(pm_halo_create(pm_par_comm(), s->n_own, leaf, rank, index,
                        9 * (int)sizeof(double), &P->to_root));
done:
  free(leaf);
  free(rank);
  free(index);
  return ret;
}

/* Every rank's share counted on rank 0, and every point owned once. */
static pm_err count_shares(struct fpm_par *P, long n_whole,
                           const fpm_model *s) {
  fpm_share_counts mine;
  fpm_share_count(s, &mine);
  PM_CALL(pm_par_agree(P->rank == 0 ? PM_ALLOC(P->counts, P->size, "shares")
                                    : PM_SUCCESS));
  MPI_Gather(&mine, (int)sizeof mine, MPI_BYTE, P->counts, (int)sizeof mine,
             MPI_BYTE, 0, pm_par_comm());
  long own = s->n_own;
  pm_par_sum_long(&own, 1);
  PM_CHECK(own == n_whole, PM_ERR_INTERNAL,
           "the ranks' shares own %ld points of %ld", own, n_whole);
  return PM_SUCCESS;
}

/* The exchange's operations (fpm_exchange.h) on a share's ranks.  The
 * bytes count every ghost value received; `exchanges` counts the
 * displacements' (one a step), so that their ratio is the bytes a step. */
/* Broadcast the owners' values of width doubles a point to the ghosts,
 * counting the bytes and the time. */
static void bcast_ghosts(struct fpm_par *P, int width, double *v) {
  const double t0 = pm_wtime();
  /* Nothing to report: an exchange set up once fails only on MPI's own
   * failures, which stop every rank (MPI_ERRORS_ARE_FATAL). */
  void *a = v;
  const int item = width * (int)sizeof(double);
  pm_halo_bcast(P->ghosts, 1, &a, &a, &item);
  const double bytes = item * (double)P->n_ghost;
  P->costs.ghost_bytes += bytes;
  pm_par_count_sent(bytes);
  P->costs.exchange_seconds += pm_wtime() - t0;
}

static void exchange_ghosts(void *ctx, double *u) {
  struct fpm_par *P = ctx;
  bcast_ghosts(P, 3, u);
  P->costs.exchanges++;
}

static void exchange_ghost_scalars(void *ctx, double *v) {
  bcast_ghosts(ctx, 1, v);
}

static pm_err agree(void *ctx, pm_err e, long key) {
  (void)ctx;
  return pm_par_agree_first(e, key);
}

static void sum(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_sum(v, n);
}

static void min(void *ctx, double *v, int n) {
  (void)ctx;
  pm_par_min(v, n);
}

static void sum_long(void *ctx, long *v, int n) {
  (void)ctx;
  pm_par_sum_long(v, n);
}

static long offset(void *ctx, long count) {
  (void)ctx;
  return pm_par_offset(count);
}

/* The parts travel in pieces of at most this many bytes (MPI counts in
 * int); a rank that cannot hold its part drains them into `drain`. */
#define PART_PIECE (1L << 22)
static char drain[PART_PIECE];

/* Rank 0 sends part bytes buf (len; -1: none, rank 0 failed) to rank r. */
static void send_part(const char *buf, long len, int r) {
  MPI_Send(&len, 1, MPI_LONG, r, 0, pm_par_comm());
  for (long at = 0; at < len; at += PART_PIECE) {
    const long n = len - at < PART_PIECE ? len - at : PART_PIECE;
    MPI_Send(buf + at, (int)n, MPI_BYTE, r, 0, pm_par_comm());
  }
  pm_par_count_sent(len > 0 ? (double)len : 0);
}

/* This rank's part from rank 0 (PM_SUCCESS with no part where rank 0
 * failed: the failure is agreed after). */
static pm_err recv_part(fpm_part *p) {
  pm_err ret = PM_SUCCESS;
  long len = 0;
  char *buf = NULL;
  MPI_Recv(&len, 1, MPI_LONG, 0, 0, pm_par_comm(), MPI_STATUS_IGNORE);
  if (len < 0) return PM_SUCCESS;
  ret = PM_ALLOC(buf, len + 1, "this rank's part of the cells");
  for (long at = 0; at < len; at += PART_PIECE) {
    const long n = len - at < PART_PIECE ? len - at : PART_PIECE;
    MPI_Recv(buf ? buf + at : drain, (int)n, MPI_BYTE, 0, 0, pm_par_comm(),
             MPI_STATUS_IGNORE);
  }
  if (!ret) ret = fpm_part_unpack(buf, (size_t)len, p);
  free(buf);
  return ret;
}

/* Rank 0 cuts every other rank's part and sends it, one at a time, so
 * that it holds the whole cells and one part at most (e: its failure so
 * far, sent as no part); the others receive theirs into *mine.  Every
 * rank's failure (collective). */
static pm_err scatter_parts(const fpm_cutter *c, pm_err e, fpm_part *mine) {
  const int size = pm_par_size();
  if (!pm_par_root()) return pm_par_agree(recv_part(mine));
  for (int r = 1; r < size; r++) {
    fpm_part p = {0};
    char *buf = NULL;
    size_t len = 0;
    if (!e) e = fpm_part_cut(c, r, &p);
    if (!e) e = fpm_part_pack(&p, &buf, &len);
    fpm_part_free(&p);
    send_part(buf, e ? -1 : (long)len, r);
    free(buf);
  }
  return pm_par_agree(e);
}

/* The whole mesh's surface names on every rank: the others' *mesh (NULL)
 * made of rank 0's (fpm_mesh_names; collective). */
static pm_err share_names(gm_mesh **mesh) {
  pm_err ret = PM_SUCCESS;
  gm_mesh head = {0};
  char *names = NULL, **name = NULL;
  long len = 0;
  if (pm_par_root()) {
    head = **mesh;
    for (int k = 0; k < head.n_surfaces; k++)
      len += (long)strlen(head.surface_name[k] ? head.surface_name[k] : "") + 1;
  }
  pm_par_bcast(&head, sizeof head);
  pm_par_bcast(&len, sizeof len);
  PM_TRY(pm_par_agree(PM_ALLOC(names, len + 1, "surface names")));
  if (pm_par_root())
    for (long k = 0, at = 0; k < head.n_surfaces; k++) {
      const char *nm = (*mesh)->surface_name[k];
      const size_t n = strlen(nm ? nm : "") + 1;
      memcpy(names + at, nm ? nm : "", n);
      at += (long)n;
    }
  pm_par_bcast(names, (size_t)len);
  if (!pm_par_root()) {
    PM_TRY(PM_ALLOC(name, head.n_surfaces + 1, "surface names"));
    for (long k = 0, at = 0; k < head.n_surfaces; k++) {
      name[k] = names + at;
      at += (long)strlen(name[k]) + 1;
    }
    head.surface_name = name;
    head.face_surface = NULL;
    ret = fpm_mesh_names(&head, mesh);
  }
done:
  ret = pm_par_agree(ret);
  free(names);
  free(name);
  return ret;
}

/* Rank 0 without the whole model: its own part cut, the whole cells and
 * mesh let go (the mesh for its surfaces' names), then its share. */
static pm_err root_part(const fpm_cutter *c, gm_mesh **mesh, gm_dual **cells,
                        fpm_part *p) {
  gm_mesh *names = NULL;
  PM_CALL(fpm_part_cut(c, 0, p));
  PM_CALL(fpm_mesh_names(*mesh, &names));
  gm_mesh_destroy(*mesh);
  *mesh = names;
  gm_dual_destroy(*cells);
  *cells = NULL;
#ifdef __GLIBC__
  /* The whole cells leave holes in the heap that the part's model, built
   * next, fills only in part: their pages go back now (F3 at 13762 points
   * on 2 ranks: rank 0's peak 1.7 MiB lower). */
  malloc_trim(0);
#endif
  return PM_SUCCESS;
}

pm_err fpm_par_create(const pm_scene *sc, gm_mesh **mesh, gm_dual **cells,
                      const fpm_model *whole, fpm_model **local) {
  pm_err ret = PM_SUCCESS;
  struct fpm_par *P = NULL;
  fpm_model *s = NULL;
  fpm_cutter cut = {0};
  fpm_part part = {0};
  const fpm_options *o = fpm_scene_options(sc);
  const bool root = pm_par_root();
  long n = root ? (*cells)->n_points : 0;
  *local = NULL;
  PM_TRY(pm_par_agree(PM_ALLOC(P, 1, "FPM ranks")));
  P->rank = pm_par_rank();
  P->size = pm_par_size();
  pm_par_bcast(&n, sizeof n);
  PM_TRY(share_names(mesh));
  /* Rank 0 partitions the points and cuts every part. */
  pm_err e = PM_SUCCESS;
  if (root) {
    e = PM_ALLOC(P->owner, n + 1, "partition");
    if (!e) e = fpm_partition(*cells, P->size, P->owner);
    if (!e) e = fpm_cutter_init(&cut, sc, o, *mesh, *cells, P->owner, P->size);
  }
  PM_TRY(scatter_parts(&cut, e, &part));
  PM_TRY(pm_par_agree(root && !whole ? root_part(&cut, mesh, cells, &part)
                                     : PM_SUCCESS));
  /* This rank's share: cut from the whole model where it is held, else
   * built on the part. */
  roots from = {.gid = NULL, .owner = P->owner, .index = cut.index, .n = n};
  if (part.cells)
    from = (roots){part.gid, part.owner, part.index, part.cells->n_points};
  PM_TRY(pm_par_agree(whole
                          ? fpm_share_create(whole, P->owner, P->rank, &s)
                          : fpm_part_share(sc, o, *mesh, &part, P->rank, &s)));
  PM_TRY(pm_par_agree(make_exchanges(P, s, &from)));
  PM_TRY(pm_par_agree(count_shares(P, n, s)));
  P->n_ghost = s->n - s->n_own;
  P->xc = (fpm_exchange){.ctx = P,
                         .ghosts = exchange_ghosts,
                         .ghost_scalars = exchange_ghost_scalars,
                         .agree = agree,
                         .sum = sum,
                         .min = min,
                         .sum_long = sum_long,
                         .offset = offset,
                         .release = par_destroy};
  s->xc = &P->xc;
  P = NULL;
  *local = s;
  s = NULL;
done:
  fpm_cutter_free(&cut);
  fpm_part_free(&part);
  par_destroy(P);
  fpm_model_destroy(s);
  return ret;
}

/* What the time loop carries from step to step. */
static void copy_carried(fpm_state *to, const fpm_state *from) {
  to->step = from->step;
  to->t = from->t;
  to->damping = from->damping;
  to->external_work = from->external_work;
  to->dissipated = from->dissipated;
}

void fpm_par_scatter(const fpm_model *m, const fpm_state *whole,
                     fpm_state *st) {
  for (long i = 0; i < m->n; i++) {
    const long g = m->gid[i];
    memcpy(st->u + 3 * i, whole->u + 3 * g, 3 * sizeof(double));
    memcpy(st->v + 3 * i, whole->v + 3 * g, 3 * sizeof(double));
  }
  copy_carried(st, whole);
}

pm_err fpm_par_gather(const fpm_model *m, const fpm_state *st,
                      fpm_state *whole) {
  struct fpm_par *P = m->xc->ctx;
  const double t0 = pm_wtime();
  const double *from[7] = {st->u, st->v, st->f, st->H, st->P, st->W, st->J};
  double *none = P->none;
  double *to[7] = {none, none, none, none, none, none, none};
  if (whole) {
    double *w[7] = {whole->u, whole->v, whole->f, whole->H,
                    whole->P, whole->W, whole->J};
    memcpy(to, w, sizeof to);
    copy_carried(whole, st);
    whole->penalty_energy = st->penalty_energy;
  }
  const int bytes[7] = {3, 3, 3, 9, 9, 1, 1};
  for (int k = 0; k < 7; k++) {
    void *leaf = (void *)from[k], *root = to[k];
    const int b = bytes[k] * (int)sizeof(double);
    pm_halo_reduce(P->to_root, 1, &root, &leaf, &b, PM_HALO_REPLACE);
  }
  pm_par_count_sent(29.0 * sizeof(double) * (double)m->n_own);
  P->costs.gather_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

pm_err fpm_par_gather_points(const fpm_model *m, const double *local,
                             double *whole) {
  struct fpm_par *P = m->xc->ctx;
  const double t0 = pm_wtime();
  double *to = whole ? whole : P->none;
  void *leaf = (void *)local, *root = to;
  const int bytes = 3 * sizeof(double);
  pm_halo_reduce(P->to_root, 1, &root, &leaf, &bytes, PM_HALO_REPLACE);
  pm_par_count_sent(3.0 * sizeof(double) * (double)m->n_own);
  P->costs.gather_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

/* The ranks of a share (its exchange's context). */
static const struct fpm_par *par_of(const fpm_model *m) {
  return m->xc ? m->xc->ctx : NULL;
}

const int *fpm_par_owner(const fpm_model *m) { return par_of(m)->owner; }

const fpm_share_counts *fpm_par_counts(const fpm_model *m) {
  return par_of(m)->counts;
}

void fpm_par_get_costs(const fpm_model *m, fpm_par_costs *c) {
  *c = m->xc ? par_of(m)->costs : (fpm_par_costs){0};
}
