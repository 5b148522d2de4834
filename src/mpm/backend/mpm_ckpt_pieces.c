/* mpm_ckpt_pieces: an MPM run across ranks without the whole model
 * checkpointed in pieces (pm_checkpoint.h): each rank its share's
 * particles with their one-process indices (the implicit MPM's also its
 * own unknowns of load stepping), rank 0 the index with the run's values;
 * and resumed from them on any count of ranks, each rank reading the
 * pieces that hold particles in its cells, or on one process all of
 * them. */
#include <stdint.h>
#include <stdio.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <stdlib.h>
#include <string.h>

#include "mpm_backend_impl.h"
#include "mpm_par.h"
#include "pm_par.h"

/* The index's item that marks a checkpoint in pieces. */
#define PIECES_ITEM "pieces.n"
/* A piece's record in the index: the box of its particles' positions
 * (lower corner, upper corner; the implicit MPM's: reference positions,
 * by which its particles keep their ranks), then its rank's energy
 * accounts, then (implicit) the box of its unknowns' nodes. */
#define REC_BOX 0
#define REC_ACCOUNTS 6
#define REC_NODES (REC_ACCOUNTS + MPM_PAR_ACCOUNTS)
_Static_assert(REC_NODES + 6 <= PM_VIEW_CKPT_VALUES,
               "a piece's record fits the view's");

bool mpm_sim_ckpt_pieces(const pm_scene *s) {
  /* Dynamic relaxation's nodal arrays span the whole grid: gathered. */
  return s->time.qs != PM_QS_DYNAMIC_RELAXATION;
}

bool mpm_sim_pieces_apply(const pm_scene *s) {
  /* A membrane's triangles number its particles in one process's order;
   * with dynamic relaxation a signal's checkpoint needs the whole grid's
   * nodal arrays, which rank 0 keeps where frames are gathered. */
  for (int b = 0; b < s->n_bodies; b++)
    if (s->bodies[b].shape == PM_BODY_MEMBRANE) return false;
  return mpm_sim_ckpt_pieces(s);
}

/* The common arrays of a state, as a piece names them. */
static int common_arrays(mpm_state *s, const char **names, int *ncomp,
                         double **data) {
  static const char *const n[4] = {"position", "velocity", "volume", "stress"};
  static const int nc[4] = {3, 3, 1, 9};
  double *d[4] = {s->x, s->v, s->vol, s->sigma};
  for (int k = 0; k < 4; k++) {
    names[k] = n[k];
    ncomp[k] = nc[k];
    data[k] = d[k];
  }
  return 4;
}

/* ---- writing ------------------------------------------------------------ */

/* Share m (state s) as a piece: indices, reference positions, the common
 * arrays, then each group's count and arrays. */
static pm_err write_items(const mpm_model *m, mpm_state *s, pm_ckpt *ck) {
  const char *names[4];
  int nc[4];
  double *data[4];
  char name[96];
  PM_CALL(pm_ckpt_longs(ck, "piece.gid", m->n, m->gid));
  PM_CALL(pm_ckpt_doubles(ck, "piece.x0", 3 * m->n, m->x0));
  for (int k = 0; k < common_arrays(s, names, nc, data); k++) {
    snprintf(name, sizeof name, "piece.%s", names[k]);
    PM_CALL(pm_ckpt_doubles(ck, name, nc[k] * m->n, data[k]));
  }
  for (int gi = 0; gi < m->n_groups; gi++) {
    long count = m->group[gi].end - m->group[gi].begin;
    snprintf(name, sizeof name, "piece.g%02d.count", gi);
    PM_CALL(pm_ckpt_long(ck, name, &count));
    for (int a = 0; a < s->group[gi].n; a++) {
      mpm_array *arr = &s->group[gi].array[a];
      snprintf(name, sizeof name, "piece.g%02d.%s", gi, arr->name);
      PM_CALL(pm_ckpt_doubles(ck, name, arr->ncomp * count, arr->data));
    }
  }
  return PM_SUCCESS;
}

pm_err mpm_sim_ckpt_piece(void *ctx, const char *dir, long id, long *count,
                          unsigned long long *sum, double *values) {
  mpm_sim *r = ctx;
  const mpm_model *m = r->local_model;
  mpm_state *s = r->local_state;
  pm_ckpt *ck = NULL;
  PM_CALL(pm_ckpt_create_piece(dir, id, pm_par_rank(), sum, &ck));
  pm_err e = write_items(m, s, ck);
  if (!e && r->imp)
    e = mpm_implicit_checkpoint_piece(r->imp, ck, values + REC_NODES);
  if (!e) {
    pm_ckpt *done = ck;
    ck = NULL;
    e = pm_ckpt_finish(done);
  }
  pm_ckpt_abort(ck);
  PM_CALL(e);
  *count = m->n;
  double *box = values + REC_BOX, *acc = values + REC_ACCOUNTS;
  const double *pos = r->imp ? m->x0 : s->x;
  for (int a = 0; a < 3; a++) {
    box[a] = m->n ? pos[a] : 0;
    box[3 + a] = m->n ? pos[a] : 0;
  }
  for (long p = 0; p < m->n; p++)
    for (int a = 0; a < 3; a++) {
      const double x = pos[3 * p + a];
      box[a] = x < box[a] ? x : box[a];
      box[3 + a] = x > box[3 + a] ? x : box[3 + a];
    }
  memcpy(acc, s->energy, sizeof s->energy);
  acc[MPM_PAR_ACCOUNTS - 2] = s->external_work;
  acc[MPM_PAR_ACCOUNTS - 1] = s->dissipated;
  return PM_SUCCESS;
}

/* The run's values as one process has them: rank 0's share's, with the
 * energy accounts summed over the pieces' records. */
static void whole_values(const mpm_state *ls, int n, const double *rec,
                         mpm_state *out) {
  *out = *ls; /* (its arrays are not the checkpoint's: values only) */
  memset(out->energy, 0, sizeof out->energy);
  out->external_work = out->dissipated = 0;
  double *e = (double *)out->energy;
  const int ne = MPM_PAR_ACCOUNTS - 2;
  for (int k = 0; k < n; k++) {
    const double *acc = rec + PM_VIEW_CKPT_VALUES * k + REC_ACCOUNTS;
    for (int j = 0; j < ne; j++) e[j] += acc[j];
    out->external_work += acc[ne];
    out->dissipated += acc[ne + 1];
  }
}

/* ---- the index ---------------------------------------------------------- */

pm_err mpm_sim_ckpt_index(mpm_sim *r, pm_ckpt *ck) {
  mpm_ckpt_pieces *cp = &r->ckpt_pieces;
  const bool reading = pm_ckpt_reading(ck);
  long n = 0, id = 0;
  if (!reading) { /* rank 0: every rank's piece first */
    PM_CHECK(mpm_sim_ckpt_pieces(r->scene), PM_ERR_ARG,
             "dynamic relaxation across ranks with frames in pieces keeps "
             "no whole model to checkpoint (set output.checkpoint, which "
             "keeps it on rank 0, or output.ranks: gather)");
    id = r->local_state->step;
    n = pm_par_size();
    PM_CALL(pm_view_checkpoint_pieces(&r->view, id));
    pm_ckpt_set_pieces(ck, id);
    free(cp->counts);
    free(cp->values);
    cp->counts = r->view.ckpt_counts; /* (borrowed while it writes) */
    cp->values = r->view.ckpt_values;
    whole_values(r->local_state, (int)n, cp->values, &cp->vals);
  }
  PM_CALL(pm_ckpt_long(ck, PIECES_ITEM, &n));
  PM_CHECK(n >= 1 && n <= 1000000, PM_ERR_IO,
           "%s: %s: expected a count of pieces, got %ld", pm_ckpt_path(ck),
           PIECES_ITEM, n);
  PM_CALL(pm_ckpt_long(ck, "pieces.id", &id));
  if (reading) {
    free(cp->counts);
    free(cp->values);
    cp->counts = NULL;
    cp->values = NULL;
    memset(&cp->vals, 0, sizeof cp->vals);
    PM_CALL(PM_ALLOC(cp->counts, 2 * n, "checkpoint pieces"));
    PM_CALL(PM_ALLOC(cp->values, PM_VIEW_CKPT_VALUES * n, "checkpoint pieces"));
  }
  cp->n = (int)n;
  cp->id = id;
  pm_err e = pm_ckpt_longs(ck, "pieces.counts", 2 * n, cp->counts);
  if (!e)
    e = pm_ckpt_doubles(ck, "pieces.values", PM_VIEW_CKPT_VALUES * n,
                        cp->values);
  if (!e) e = mpm_state_checkpoint_values(&cp->vals, ck);
  if (!e) e = mpm_sim_run_items(r, ck);
  if (!e) e = mpm_sim_cut_items(r, ck, n);
  if (!reading) { /* (the view's) */
    cp->counts = NULL;
    cp->values = NULL;
  }
  PM_CALL(e);
  if (!reading) return PM_SUCCESS;
  for (int k = 0; k < n; k++)
    PM_CHECK(cp->counts[2 * k] >= 0, PM_ERR_IO, "%s: piece %d of %ld particles",
             pm_ckpt_path(ck), k, cp->counts[2 * k]);
  /* Each rank's accounts, for a run resumed on as many ranks. */
  free(r->ckpt_accounts);
  r->ckpt_accounts = NULL;
  PM_CALL(PM_ALLOC(r->ckpt_accounts, MPM_PAR_ACCOUNTS * n, "energy accounts"));
  for (int k = 0; k < n; k++)
    memcpy(r->ckpt_accounts + MPM_PAR_ACCOUNTS * k,
           cp->values + PM_VIEW_CKPT_VALUES * k + REC_ACCOUNTS,
           MPM_PAR_ACCOUNTS * sizeof(double));
  r->ckpt_ranks = (int)n;
  snprintf(cp->dir, sizeof cp->dir, "%s", pm_ckpt_path(ck));
  char *slash = strrchr(cp->dir, '/');
  if (slash)
    *slash = '\0';
  else
    snprintf(cp->dir, sizeof cp->dir, ".");
  cp->on = true;
  r->resumed = true;
  r->last.step = cp->vals.step;
  r->last.t = cp->vals.t;
  r->last.dt = cp->vals.dt;
  /* One process, or a run that keeps the whole model: every piece now. */
  if (r->model || !r->view.ranks || r->whole) return mpm_sim_ckpt_load_whole(r);
  return PM_SUCCESS;
}

bool mpm_sim_ckpt_is_pieces(const pm_ckpt *ck) {
  return pm_ckpt_has(ck, PIECES_ITEM);
}

/* ---- reading a piece ---------------------------------------------------- */

/* Where a piece's particles go: model m's particles by their one-process
 * indices (m->gid, increasing; NULL: the whole model's own). */
typedef struct {
  const mpm_model *m;
  mpm_state *s;
  long n;    /* the piece's particles */
  long *gid; /* [n] */
  long *at;  /* [n]: the particle's place in m, or -1 */
  double *buf;
  long placed;       /* particles placed, over the pieces */
  bool *seen;        /* [m->n]: placed already (a particle in two pieces is
                        refused: the count alone would let one stand for a
                        missing one) */
  bool vetted;       /* the pieces were vetted when picked */
  mpm_implicit *imp; /* the implicit solver, whose unknowns the pieces
                        hold too (NULL: explicit) */
  long unk_placed;   /* its unknowns placed, over the pieces */
  bool *unk_seen;    /* [its unknowns]: placed already */
} piece_reader;

static int long_order(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

static long place_of(const mpm_model *m, long gid) {
  if (!m->gid) return gid >= 0 && gid < m->n ? gid : -1;
  const long *at = bsearch(&gid, m->gid, (size_t)m->n, sizeof gid, long_order);
  return at ? (long)(at - m->gid) : -1;
}

/* Item name of nc values a particle into buf, then those of the particles
 * in m into dst (rows from base: a group's first). */
static pm_err read_scatter(piece_reader *pr, pm_ckpt *ck, const char *name,
                           long first, long count, int nc, long base,
                           double *dst) {
  PM_CALL(pm_ckpt_doubles(ck, name, nc * count, pr->buf));
  for (long j = 0; j < count; j++) {
    const long p = pr->at[first + j];
    if (p >= 0)
      memcpy(dst + (p - base) * nc, pr->buf + j * nc, nc * sizeof(double));
  }
  return PM_SUCCESS;
}

/* Piece k's particles that m holds, into state s. */
static pm_err read_piece(piece_reader *pr, const mpm_ckpt_pieces *cp, int k) {
  pm_err ret = PM_SUCCESS;
  pm_ckpt *ck = NULL;
  const mpm_model *m = pr->m;
  const long n = cp->counts[2 * k];
  const char *names[4];
  int nc[4];
  double *data[4];
  char name[96];
  PM_TRY(pm_ckpt_open_piece(cp->dir, cp->id, k,
                            (unsigned long long)cp->counts[2 * k + 1],
                            !pr->vetted, &ck));
  free(pr->gid);
  free(pr->at);
  free(pr->buf);
  pr->gid = pr->at = NULL;
  pr->buf = NULL;
  pr->n = n;
  PM_TRY(PM_ALLOC(pr->gid, n + 1, "checkpoint piece"));
  PM_TRY(PM_ALLOC(pr->at, n + 1, "checkpoint piece"));
  PM_TRY(PM_ALLOC(pr->buf, 9 * n + 1, "checkpoint piece"));
  PM_TRY(pm_ckpt_longs(ck, "piece.gid", n, pr->gid));
  for (long j = 0; j < n; j++) {
    const long p = pr->at[j] = place_of(m, pr->gid[j]);
    if (p < 0) continue;
    PM_ENSURE(!pr->seen[p], PM_ERR_IO,
              "checkpoint '%s/checkpoint.h5': particle %ld is in two of its "
              "pieces (the second: piece %d)",
              cp->dir, pr->gid[j], k);
    pr->seen[p] = true;
    pr->placed++;
  }
  PM_TRY(pm_ckpt_doubles(ck, "piece.x0", 3 * n, pr->buf));
  for (int a = 0; a < common_arrays(pr->s, names, nc, data); a++) {
    snprintf(name, sizeof name, "piece.%s", names[a]);
    PM_TRY(read_scatter(pr, ck, name, 0, n, nc[a], 0, data[a]));
  }
  long first = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    long count = 0;
    snprintf(name, sizeof name, "piece.g%02d.count", gi);
    PM_TRY(pm_ckpt_long(ck, name, &count));
    PM_ENSURE(count >= 0 && first + count <= n, PM_ERR_IO,
              "checkpoint '%s': %s is %ld, of a piece of %ld particles",
              pm_ckpt_path(ck), name, count, n);
    for (int a = 0; a < pr->s->group[gi].n; a++) {
      mpm_array *arr = &pr->s->group[gi].array[a];
      snprintf(name, sizeof name, "piece.g%02d.%s", gi, arr->name);
      PM_TRY(read_scatter(pr, ck, name, first, count, arr->ncomp,
                          m->group[gi].begin, arr->data));
    }
    first += count;
  }
  PM_ENSURE(first == n, PM_ERR_IO,
            "checkpoint '%s': its groups hold %ld of its %ld particles",
            pm_ckpt_path(ck), first, n);
  if (pr->imp)
    PM_TRY(mpm_implicit_read_piece(pr->imp, ck, pr->unk_seen, &pr->unk_placed));
  pm_ckpt *done_ck = ck;
  ck = NULL;
  PM_TRY(pm_ckpt_finish(done_ck));
done:
  pm_ckpt_abort(ck);
  return ret;
}

/* The pieces need[k] (all where need is NULL; vetted: vetted already)
 * into model m's state s, and the implicit solver imp's unknowns (NULL:
 * none); every particle of m and every unknown must be found in them
 * once. */
static pm_err read_pieces(const mpm_ckpt_pieces *cp, const bool *need,
                          bool vetted, const mpm_model *m, mpm_state *s,
                          mpm_implicit *imp) {
  piece_reader pr = {.m = m, .s = s, .vetted = vetted, .imp = imp};
  const long unknowns = imp ? mpm_implicit_unknowns(imp) : 0;
  pm_err ret = PM_ALLOC(pr.seen, m->n + 1, "checkpoint pieces");
  if (!ret) ret = PM_ALLOC(pr.unk_seen, unknowns + 1, "checkpoint pieces");
  for (int k = 0; k < cp->n && !ret; k++)
    if (!need || need[k]) ret = read_piece(&pr, cp, k);
  if (!ret && pr.placed != m->n)
    ret = PM_ERROR(PM_ERR_IO,
                   "checkpoint '%s/checkpoint.h5': its pieces hold %ld of "
                   "the %ld particles this run reads from them",
                   cp->dir, pr.placed, m->n);
  if (!ret && pr.unk_placed != unknowns)
    ret = PM_ERROR(PM_ERR_IO,
                   "checkpoint '%s/checkpoint.h5': its pieces hold %ld of "
                   "the %ld unknowns of load stepping this rank reads from "
                   "them",
                   cp->dir, pr.unk_placed, unknowns);
  free(pr.gid);
  free(pr.at);
  free(pr.buf);
  free(pr.seen);
  free(pr.unk_seen);
  return ret;
}

pm_err mpm_sim_ckpt_load_whole(mpm_sim *r) {
  mpm_ckpt_pieces *cp = &r->ckpt_pieces;
  if (!r->model) PM_CALL(mpm_model_create(r->scene, &r->model, &r->state));
  mpm_state_copy_values(r->state, &cp->vals);
  PM_CALL(read_pieces(cp, NULL, false, r->model, r->state, r->imp));
  cp->on = false; /* (read: a run across ranks shares it anew) */
  return PM_SUCCESS;
}

/* ---- a share made anew from the pieces ---------------------------------- */

/* The particles a rank keeps: those the pieces have in its cells, known
 * by their reference positions (an open-addressed set of them). */
typedef struct {
  const mpm_ckpt_pieces *cp;
  bool *need;  /* per piece: it holds some */
  double *x0;  /* 3 per kept particle */
  long n, cap; /* kept, and room */
  mpm_x0_set set;
} pick_set;

static bool pick_keep(void *ctx, const double x[3]) {
  return mpm_x0_set_has(&((const pick_set *)ctx)->set, x);
}

/* Whether a piece's box of positions meets rank's box of cells. */
static bool meets(const double *box, const mpm_decomp *d, const mpm_grid *g,
                  int rank) {
  for (int a = 0; a < g->dim; a++) {
    long c[2];
    for (int e = 0; e < 2; e++) {
      const double k = (box[3 * e + a] - g->origin[a]) * g->inv_h;
      c[e] = k < 0 ? 0 : k >= d->cells[a] ? d->cells[a] - 1 : (long)k;
    }
    if (c[1] < d->box[6 * rank + a] || c[0] >= d->box[6 * rank + 3 + a])
      return false;
  }
  return true;
}

/* Piece k's particles in rank's cells (their positions now) into the set
 * (their reference positions). */
static pm_err pick_piece(pick_set *ps, int k, const mpm_decomp *d,
                         const mpm_grid *g, int rank) {
  pm_err ret = PM_SUCCESS;
  const mpm_ckpt_pieces *cp = ps->cp;
  const long n = cp->counts[2 * k];
  pm_ckpt *ck = NULL;
  long *gid = NULL;
  double *x0 = NULL, *x = NULL;
  PM_TRY(pm_ckpt_open_piece(cp->dir, cp->id, k,
                            (unsigned long long)cp->counts[2 * k + 1], true,
                            &ck));
  PM_TRY(PM_ALLOC(gid, n + 1, "checkpoint piece"));
  PM_TRY(PM_ALLOC(x0, 3 * n + 1, "checkpoint piece"));
  PM_TRY(PM_ALLOC(x, 3 * n + 1, "checkpoint piece"));
  PM_TRY(pm_ckpt_longs(ck, "piece.gid", n, gid));
  PM_TRY(pm_ckpt_doubles(ck, "piece.x0", 3 * n, x0));
  PM_TRY(pm_ckpt_doubles(ck, "piece.position", 3 * n, x));
  for (long j = 0; j < n; j++) {
    if (mpm_decomp_rank_at(d, g, x + 3 * j) != rank) continue;
    if (ps->n == ps->cap) {
      ps->cap = 2 * ps->cap + 1024;
      PM_TRY(PM_REALLOC(ps->x0, 3 * ps->cap, "checkpoint particles"));
    }
    memcpy(ps->x0 + 3 * ps->n++, x0 + 3 * j, 3 * sizeof(double));
  }
done:
  free(gid);
  free(x0);
  free(x);
  pm_ckpt_abort(ck); /* (read again whole, and checked, by read_pieces) */
  return ret;
}

static pm_err pick_prepare(void *ctx, const mpm_decomp *d, const mpm_grid *g,
                           int rank) {
  pick_set *ps = ctx;
  const mpm_ckpt_pieces *cp = ps->cp;
  PM_CALL(PM_ALLOC(ps->need, cp->n, "checkpoint pieces"));
  for (int k = 0; k < cp->n; k++) {
    ps->need[k] =
        cp->counts[2 * k] > 0 &&
        meets(cp->values + PM_VIEW_CKPT_VALUES * k + REC_BOX, d, g, rank);
    if (ps->need[k]) PM_CALL(pick_piece(ps, k, d, g, rank));
  }
  ps->set = (mpm_x0_set){.x0 = ps->x0, .stride = 3, .n = ps->n};
  return mpm_x0_set_index(&ps->set);
}

/* The checkpoint's values into share state ls (and rank 0's scalars):
 * each rank's accounts as the checkpoint's ranks had them; on another
 * count of ranks, their sums on rank 0. */
static void share_values(mpm_sim *r, mpm_state *ls) {
  const mpm_ckpt_pieces *cp = &r->ckpt_pieces;
  mpm_state_copy_values(ls, &cp->vals);
  const int me = pm_par_rank();
  const bool same = cp->n == pm_par_size();
  if (!same && me != 0) {
    memset(ls->energy, 0, sizeof ls->energy);
    ls->external_work = ls->dissipated = 0;
  } else if (same) {
    const double *row = r->ckpt_accounts + MPM_PAR_ACCOUNTS * me;
    memcpy(ls->energy, row, sizeof ls->energy);
    ls->external_work = row[MPM_PAR_ACCOUNTS - 2];
    ls->dissipated = row[MPM_PAR_ACCOUNTS - 1];
  }
  if (r->state) mpm_state_copy_values(r->state, &cp->vals);
}

/* The share anew from the pieces into r (the old one let go first). */
static pm_err reload(mpm_sim *r, pick_set *ps) {
  mpm_ckpt_pieces *cp = &r->ckpt_pieces;
  mpm_par_pick pick = {.prepare = pick_prepare, .keep = pick_keep, .ctx = ps};
  mpm_model *lm = NULL;
  mpm_state *ls = NULL;
  /* The share setup seeded goes first, a rank holding one share at a
   * time, and back to the system: glibc's calloc clears memory it reuses,
   * which makes every page of the new share's room resident (measured:
   * a rank of the fine block resumed held 120 MiB more than the run). */
  mpm_view_drop_share(r);
#ifdef __GLIBC__
  malloc_trim(0);
#endif
  pm_err ret =
      mpm_par_create_cut(r->scene, false, r->ckpt_cut, &pick, &lm, &ls);
  mpm_x0_set_free(&ps->set); /* (the seeding's alone) */
  free(ps->x0);
  ps->x0 = NULL;
  if (!ret && lm->n != ps->n)
    ret = PM_ERROR(PM_ERR_IO,
                   "checkpoint '%s/checkpoint.h5': rank %d's cells hold %ld "
                   "of its particles, the scene seeds %ld of them there",
                   cp->dir, pm_par_rank(), ps->n, lm->n);
  if (!ret) ret = read_pieces(cp, ps->need, true, lm, ls, NULL);
  PM_TRY(pm_par_agree(ret));
  share_values(r, ls);
  r->local_model = lm;
  r->local_state = ls;
  lm = NULL;
  ls = NULL;
  cp->on = false;
  ret = pm_par_agree(mpm_work_create(r->local_model, &r->local_work));
done:
  mpm_state_destroy(ls);
  mpm_model_destroy(lm);
  return ret;
}

pm_err mpm_view_reload(mpm_sim *r) {
  pick_set ps = {.cp = &r->ckpt_pieces};
  pm_err ret = reload(r, &ps);
  free(ps.need);
  free(ps.x0);
  mpm_x0_set_free(&ps.set);
#ifdef __GLIBC__
  malloc_trim(0); /* (the pieces' buffers) */
#endif
  if (!ret) return PM_SUCCESS;
  /* A damaged piece: the share of the start again, so that the failed
   * run's figures and summary have one to read (every rank has ret). */
  char why[1024];
  snprintf(why, sizeof why, "%s", pm_error_message());
  mpm_view_drop_share(r);
  if (mpm_par_create_seeded(r->scene, false, &r->local_model,
                            &r->local_state) == PM_SUCCESS)
    (void)pm_par_agree(mpm_work_create(r->local_model, &r->local_work));
  return PM_ERROR(ret, "%s", why);
}

/* ---- the implicit MPM's share, read in place ----------------------------- */

/* Whether boxes of node indices a and b (lower corner, upper corner,
 * inclusive) meet. */
static bool nodes_meet(const double *a, const double *b) {
  for (int ax = 0; ax < 3; ax++)
    if (a[3 + ax] < b[ax] || a[ax] > b[3 + ax]) return false;
  return true;
}

pm_err mpm_view_implicit_reload(mpm_sim *r) {
  mpm_ckpt_pieces *cp = &r->ckpt_pieces;
  const mpm_model *lm = r->local_model;
  const mpm_decomp *d = mpm_par_decomp(lm);
  const int me = pm_par_rank();
  /* The pieces with particles in this rank's cells by their reference
   * positions (which its particles keep), or unknowns at its nodes. */
  bool *need = NULL;
  double own[6];
  const bool unknowns = mpm_implicit_unknowns(r->imp) > 0;
  mpm_implicit_nodes_box(r->imp, own);
  pm_err ret = PM_ALLOC(need, cp->n, "checkpoint pieces");
  for (int k = 0; k < cp->n && !ret; k++) {
    const double *rec = cp->values + PM_VIEW_CKPT_VALUES * k;
    need[k] =
        (cp->counts[2 * k] > 0 && meets(rec + REC_BOX, d, &lm->grid, me)) ||
        (unknowns && nodes_meet(rec + REC_NODES, own));
  }
  if (!ret) ret = read_pieces(cp, need, false, lm, r->local_state, r->imp);
  free(need);
  PM_CALL(pm_par_agree(ret));
  share_values(r, r->local_state);
  cp->on = false;
  return PM_SUCCESS;
}
