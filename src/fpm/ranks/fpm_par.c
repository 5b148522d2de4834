/* fpm_par: the shares of a run across ranks, the ghosts' displacements on
 * a star forest, the step's sums and failures, and the gather to rank 0. */
#include "fpm_par.h"

#include <mpi.h>
#include <petscsf.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_region.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_petsc.h"
#include "pm_progress.h"

struct fpm_par {
  fpm_exchange xc; /* what the core calls (ctx: this) */
  int rank, size;
  int *owner;               /* every point's rank (the partition) */
  fpm_share_counts *counts; /* every rank's share, on rank 0 */
  /* the ghosts' displacements: each ghost (a leaf) is a point its owner
   * holds among its own (a root) */
  PetscSF ghosts;
  /* the gather: each own point (a leaf) is a point of rank 0's whole
   * arrays (a root; none on the other ranks) */
  PetscSF to_root;
  MPI_Datatype three, nine;
  double none[9]; /* the roots of the gather on the other ranks */
  long n_ghost;   /* the share's ghost points */
  fpm_par_costs costs;
};

static void par_destroy(void *ctx) {
  struct fpm_par *P = ctx;
  if (!P) return;
  if (P->ghosts) PetscSFDestroy(&P->ghosts);
  if (P->to_root) PetscSFDestroy(&P->to_root);
  if (P->three) MPI_Type_free(&P->three);
  if (P->nine) MPI_Type_free(&P->nine);
  free(P->owner);
  free(P->counts);
  free(P);
}

/* A digest of the support graph and the positions (FNV-1a). */
static uint64_t graph_digest(const gm_dual *d) {
  uint64_t h = 1469598103934665603ull;
  const long n = d->n_points;
  const unsigned char *parts[3] = {(const unsigned char *)d->nbr_ptr,
                                   (const unsigned char *)d->nbr,
                                   (const unsigned char *)d->x};
  const size_t bytes[3] = {sizeof(long) * (size_t)(n + 1),
                           sizeof(long) * (size_t)d->nbr_ptr[n],
                           sizeof(double) * 3 * (size_t)n};
  for (int k = 0; k < 3; k++)
    for (size_t b = 0; b < bytes[k]; b++) {
      h ^= parts[k][b];
      h *= 1099511628211ull;
    }
  return h;
}

/* The partition, made on rank 0 and sent to every rank, which must hold the
 * same graph (each meshed the domain itself). */
static pm_err partition(struct fpm_par *P, const gm_dual *d) {
  uint64_t mine = graph_digest(d), first = mine;
  pm_par_bcast(&first, sizeof first);
  PM_CALL(pm_par_agree(
      first == mine
          ? PM_SUCCESS
          : PM_ERROR(PM_ERR_INTERNAL,
                     "rank %d meshed the domain into another graph of "
                     "points than rank 0 (%ld points): the ranks cannot "
                     "share it",
                     P->rank, d->n_points)));
  PM_CALL(PM_ALLOC(P->owner, d->n_points + 1, "partition"));
  PM_CALL(pm_par_agree(P->rank == 0 ? fpm_partition(d, P->size, P->owner)
                                    : PM_SUCCESS));
  pm_par_bcast(P->owner, sizeof(int) * (size_t)d->n_points);
  return PM_SUCCESS;
}

/* The star forests: ghosts to their owners' own points (each rank's own
 * points are in one-process order, so an owner's index of a point is the
 * count of its points before it), own points to rank 0's whole arrays. */
static pm_err make_forests(struct fpm_par *P, long n_whole,
                           const fpm_model *s) {
  pm_err ret = PM_SUCCESS;
  const long n_ghost = s->n - s->n_own;
  long *index = NULL, *seen = NULL;
  PetscInt *leaf = NULL;
  PetscSFNode *root = NULL;
  PM_TRY(PM_ALLOC(index, n_whole + 1, "owners' indices"));
  PM_TRY(PM_ALLOC(seen, P->size, "owners' indices"));
  for (long i = 0; i < n_whole; i++) index[i] = seen[P->owner[i]]++;
  PM_TRY(PM_ALLOC(leaf, n_ghost + 1, "ghost points"));
  PM_TRY(PM_ALLOC(root, (n_ghost > s->n_own ? n_ghost : s->n_own) + 1,
                  "ghost points' owners"));
  for (long k = 0; k < n_ghost; k++) {
    const long g = s->gid[s->n_own + k];
    leaf[k] = (PetscInt)(s->n_own + k);
    root[k].rank = P->owner[g];
    root[k].index = (PetscInt)index[g];
  }
  PM_PETSC(PetscSFCreate(PETSC_COMM_WORLD, &P->ghosts));
  PM_PETSC(PetscSFSetGraph(P->ghosts, (PetscInt)s->n_own, (PetscInt)n_ghost,
                           leaf, PETSC_COPY_VALUES, root, PETSC_COPY_VALUES));
  PM_PETSC(PetscSFSetUp(P->ghosts));
  for (long k = 0; k < s->n_own; k++) {
    root[k].rank = 0;
    root[k].index = (PetscInt)s->gid[k];
  }
  PM_PETSC(PetscSFCreate(PETSC_COMM_WORLD, &P->to_root));
  PM_PETSC(PetscSFSetGraph(P->to_root, P->rank == 0 ? (PetscInt)n_whole : 0,
                           (PetscInt)s->n_own, NULL, PETSC_COPY_VALUES, root,
                           PETSC_COPY_VALUES));
  PM_PETSC(PetscSFSetUp(P->to_root));
  MPI_Type_contiguous(3, MPI_DOUBLE, &P->three);
  MPI_Type_commit(&P->three);
  MPI_Type_contiguous(9, MPI_DOUBLE, &P->nine);
  MPI_Type_commit(&P->nine);
done:
  free(index);
  free(seen);
  free(leaf);
  free(root);
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
/* Broadcast the owners' values of width doubles a point (MPI type unit)
 * to the ghosts, counting the bytes and the time. */
static void bcast_ghosts(struct fpm_par *P, MPI_Datatype unit, int width,
                         double *v) {
  const double t0 = pm_wtime();
  /* Nothing to report: a star forest set up once fails only on MPI's own
   * failures, which stop every rank (MPI_ERRORS_ARE_FATAL). */
  PetscSFBcastBegin(P->ghosts, unit, v, v, MPI_REPLACE);
  PetscSFBcastEnd(P->ghosts, unit, v, v, MPI_REPLACE);
  const double bytes = width * sizeof(double) * (double)P->n_ghost;
  P->costs.ghost_bytes += bytes;
  pm_par_count_sent(bytes);
  P->costs.exchange_seconds += pm_wtime() - t0;
}

static void exchange_ghosts(void *ctx, double *u) {
  struct fpm_par *P = ctx;
  bcast_ghosts(P, P->three, 3, u);
  P->costs.exchanges++;
}

static void exchange_ghost_scalars(void *ctx, double *v) {
  bcast_ghosts(ctx, MPI_DOUBLE, 1, v);
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

pm_err fpm_par_create(const pm_scene *sc, const gm_mesh *mesh, gm_dual **cells,
                      const fpm_model *whole, fpm_model **local) {
  pm_err ret = PM_SUCCESS;
  struct fpm_par *P = NULL;
  fpm_model *s = NULL;
  const long n = (*cells)->n_points;
  *local = NULL;
  PM_TRY(pm_par_agree(PM_ALLOC(P, 1, "FPM ranks")));
  P->rank = pm_par_rank();
  P->size = pm_par_size();
  PM_TRY(pm_par_agree(pm_petsc_init()));
  PM_TRY(partition(P, *cells));
  PM_TRY(pm_par_agree(whole ? fpm_share_create(whole, P->owner, P->rank, &s)
                            : fpm_share_build(sc, fpm_scene_options(sc), mesh,
                                              cells, true, P->owner, P->rank,
                                              &s)));
  PM_TRY(pm_par_agree(make_forests(P, n, s)));
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
  const MPI_Datatype unit[7] = {P->three, P->three,   P->three,  P->nine,
                                P->nine,  MPI_DOUBLE, MPI_DOUBLE};
  for (int k = 0; k < 7; k++)
    PM_PETSC_CALL(
        PetscSFReduceBegin(P->to_root, unit[k], from[k], to[k], MPI_REPLACE));
  for (int k = 0; k < 7; k++)
    PM_PETSC_CALL(
        PetscSFReduceEnd(P->to_root, unit[k], from[k], to[k], MPI_REPLACE));
  pm_par_count_sent(29.0 * sizeof(double) * (double)m->n_own);
  P->costs.gather_seconds += pm_wtime() - t0;
  return PM_SUCCESS;
}

pm_err fpm_par_gather_points(const fpm_model *m, const double *local,
                             double *whole) {
  struct fpm_par *P = m->xc->ctx;
  const double t0 = pm_wtime();
  double *to = whole ? whole : P->none;
  PM_PETSC_CALL(
      PetscSFReduceBegin(P->to_root, P->three, local, to, MPI_REPLACE));
  PM_PETSC_CALL(PetscSFReduceEnd(P->to_root, P->three, local, to, MPI_REPLACE));
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
