/* mpm_par_balance: the boxes cut anew while a run goes on, when the
 * particles' travel has unbalanced them (mpm.rebalance).  The boxes of
 * the start share the particles where they were seeded; particles that
 * travel (a shock's gas, colliding bodies) crowd some boxes and empty
 * others, and the busiest rank sets every step's pace.  Every 20 steps
 * the ranks compare their counts; past the threshold the cut is made
 * again by the same bisection from the particles per cell now, each
 * particle goes to the rank whose new box holds it with every array it
 * carries, and each rank makes its share anew from the scene (as a run
 * resumed from a checkpoint in pieces does: the particles it received
 * seeded in one process's order, then their state) and takes it in place
 * of the old one.  The step is then one process's on the new boxes: the
 * results stay those of one process to round-off (the nodes' sums are
 * added in another order). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_par_impl.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

/* Steps between two looks at the balance. */
#define BALANCE_EVERY 20
/* A new cut is taken when it lowers the busiest rank's count by this. */
#define BALANCE_GAIN 0.05

/* Whether the seeding keeps x: a particle received (mpm_x0_set). */
static bool received_keep(void *ctx, const double x[3]) {
  return mpm_x0_set_has(ctx, x);
}

/* The buffers of one cut: per rank counts and offsets (in doubles), the
 * records sent and received. */
typedef struct {
  int *scount, *rcount, *sdisp, *rdisp, *fill;
  double *sbuf, *rbuf;
  long arriving;
} transfer;

static void transfer_free(transfer *t) {
  free(t->scount);
  free(t->rcount);
  free(t->sdisp);
  free(t->rdisp);
  free(t->fill);
  free(t->sbuf);
  free(t->rbuf);
}

/* Every particle of m (state s) to its rank in decomposition d of the
 * whole grid g (collective). */
static pm_err send_all(const mpm_model *m, const mpm_state *s,
                       const mpm_decomp *d, const mpm_grid *g, transfer *t) {
  struct mpm_par *P = par_of(m);
  const int size = pm_par_size(), rec = P->rec;
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(t->scount, size, "cut counts"));
  PM_TRY(PM_ALLOC(t->rcount, size, "cut counts"));
  PM_TRY(PM_ALLOC(t->sdisp, size + 1, "cut offsets"));
  PM_TRY(PM_ALLOC(t->rdisp, size + 1, "cut offsets"));
  PM_TRY(PM_ALLOC(t->fill, size, "cut counts"));
  for (long p = 0; p < m->n; p++) {
    P->dest[p] = mpm_decomp_rank_at(d, g, s->x + 3 * p);
    t->scount[P->dest[p]]++;
  }
done:
  PM_CALL(pm_par_agree(ret));
  MPI_Alltoall(t->scount, 1, MPI_INT, t->rcount, 1, MPI_INT, pm_par_comm());
  t->sdisp[0] = t->rdisp[0] = 0;
  for (int k = 0; k < size; k++) {
    t->sdisp[k + 1] = t->sdisp[k] + t->scount[k];
    t->rdisp[k + 1] = t->rdisp[k] + t->rcount[k];
  }
  t->arriving = t->rdisp[size];
  ret = PM_ALLOC(t->sbuf, (long)rec * (m->n + 1), "cut records");
  if (!ret)
    ret = PM_ALLOC(t->rbuf, (long)rec * (t->arriving + 1), "cut records");
  PM_CALL(pm_par_agree(ret));
  for (int gi = 0; gi < m->n_groups; gi++)
    for (long p = m->group[gi].begin; p < m->group[gi].end; p++) {
      const int r = P->dest[p];
      mpm_par_pack(m, s, p, gi,
                   t->sbuf + (long)(t->sdisp[r] + t->fill[r]++) * rec);
    }
  for (int k = 0; k < size; k++) {
    t->scount[k] *= rec;
    t->rcount[k] *= rec;
    t->sdisp[k] *= rec;
    t->rdisp[k] *= rec;
  }
  MPI_Alltoallv(t->sbuf, t->scount, t->sdisp, MPI_DOUBLE, t->rbuf, t->rcount,
                t->rdisp, MPI_DOUBLE, pm_par_comm());
  P->counts.migrate_bytes += (double)m->n * rec * sizeof(double);
  pm_par_count_sent((double)m->n * rec * sizeof(double));
  /* (a rank holds its old share, the records received and the new share
   * at once while it cuts: the records sent go first) */
  free(t->sbuf);
  t->sbuf = NULL;
  qsort(t->rbuf, (size_t)t->arriving, (size_t)rec * sizeof(double),
        mpm_par_by_gid);
  return PM_SUCCESS;
}

/* The share seeded on cut d with the particles received, their state from
 * the records, the run's values from s (collective). */
static pm_err share_anew(const mpm_model *m, const mpm_state *s,
                         const long *cut, const transfer *t, mpm_model **lm,
                         mpm_state **ls) {
  const struct mpm_par *P = par_of(m);
  mpm_x0_set rv = {.x0 = t->rbuf + REC_X0, .stride = P->rec, .n = t->arriving};
  mpm_par_pick pick = {.keep = received_keep, .ctx = &rv};
  pm_err ret = pm_par_agree(mpm_x0_set_index(&rv));
  if (!ret) ret = mpm_par_create_cut(P->scene, P->gather, cut, &pick, lm, ls);
  mpm_x0_set_free(&rv);
  PM_CALL(ret);
  /* Each particle seeded is one received, in the same order. */
  const mpm_model *n = *lm;
  long bad = n->n != t->arriving ? 0 : -1;
  for (int gi = 0; bad < 0 && gi < n->n_groups; gi++)
    for (long j = n->group[gi].begin; bad < 0 && j < n->group[gi].end; j++)
      if ((double)n->gid[j] != t->rbuf[j * P->rec + REC_GID] ||
          gi != (int)t->rbuf[j * P->rec + REC_GROUP])
        bad = j;
  if (bad >= 0)
    ret = PM_ERROR(PM_ERR_INTERNAL,
                   "step %ld: cutting the boxes anew, rank %d received %ld "
                   "particles and seeded %ld (the first apart: %ld)",
                   s->step, pm_par_rank(), t->arriving, (*lm)->n, bad);
  PM_CALL(pm_par_agree(ret));
  for (int gi = 0; gi < n->n_groups; gi++)
    for (long j = n->group[gi].begin; j < n->group[gi].end; j++)
      mpm_par_unpack(n, *ls, j, gi, t->rbuf + j * P->rec);
  /* The run's values, this rank's energy accounts among them. */
  mpm_state_copy_values(*ls, s);
  return PM_SUCCESS;
}

/* The new share in place of the old: m, s and w keep their addresses
 * (the time loop holds them), their contents swapped and the old freed;
 * what the run counted so far goes on. */
static void take(mpm_model *m, mpm_state *s, mpm_work *w, mpm_model *lm,
                 mpm_state *ls, mpm_work *lw) {
  struct mpm_par *P = par_of(m), *Q = par_of(lm);
  Q->counts = P->counts;
  Q->frame = P->frame; /* (the cuts' grid and counts go on) */
  Q->per_cell = P->per_cell;
  P->frame = NULL;
  P->per_cell = NULL;
  if (lm->n > Q->counts.most) Q->counts.most = lm->n;
  lw->timers = w->timers;
  memcpy(lw->timer, w->timer, sizeof w->timer);
  lw->timer_migrate = w->timer_migrate;
  lw->max_div = w->max_div;
  lw->min_jacobian = w->min_jacobian;
  lw->residual = w->residual;
  lw->iter_max = w->iter_max;
  lw->iter_capped = w->iter_capped;
  lw->fail = w->fail;
  if (m->n_bcs > 0)
    memcpy(lw->cond.reaction, w->cond.reaction,
           3 * sizeof(double) * (size_t)m->n_bcs);
  const mpm_model tm = *m;
  *m = *lm;
  *lm = tm;
  const mpm_state ts = *s;
  *s = *ls;
  *ls = ts;
  const mpm_work tw = *w;
  *w = *lw;
  *lw = tw;
}

pm_err mpm_par_balance(mpm_model *m, mpm_state *s, mpm_work *w) {
  struct mpm_par *P = par_of(m);
  /* (on steps of their own, so that a resumed run looks when the
   * straight one did) */
  if (s->step % BALANCE_EVERY != 0) return PM_SUCCESS;
  const int size = pm_par_size();
  double most = (double)m->n, total = (double)m->n;
  pm_par_max(&most, 1);
  pm_par_sum(&total, 1);
  P->counts.look_most += most;
  P->counts.look_mean += total / size;
  if (P->balance <= 0 || total <= 0 || most * size <= P->balance * total)
    return PM_SUCCESS;
  /* The cut from the particles per cell where they are now. */
  const double t0 = pm_wtime();
  pm_err ret = PM_SUCCESS;
  mpm_model *lm = NULL;
  mpm_state *ls = NULL;
  mpm_work *lw = NULL;
  mpm_decomp d = {0};
  transfer t = {0};
  long cells[3], *cut = NULL;
  /* (the whole grid and its counts made at the first look past the
   * threshold and kept: one that finds no better cut allocates nothing) */
  if (!P->frame) ret = mpm_model_frame(P->scene, &P->frame);
  const long n_cells = P->frame ? mpm_decomp_cells(&P->frame->grid, cells) : 0;
  if (!ret && !P->per_cell)
    ret = PM_ALLOC(P->per_cell, n_cells, "particles per cell");
  PM_TRY(pm_par_agree(ret));
  const mpm_grid *g = &P->frame->grid;
  memset(P->per_cell, 0, sizeof(long) * (size_t)n_cells);
  for (long p = 0; p < m->n; p++)
    mpm_decomp_count(g, cells, s->x + 3 * p, P->per_cell);
  pm_par_sum_long(P->per_cell, (int)n_cells);
  PM_TRY(pm_par_agree(mpm_decomp_from_counts(P->scene, P->frame, size,
                                             P->per_cell, (long)total, &d)));
  long new_most = 0;
  for (int k = 0; k < size; k++)
    new_most = d.count[k] > new_most ? d.count[k] : new_most;
  /* (every rank decides alike: the counts are the same everywhere) */
  if ((double)new_most > (1 - BALANCE_GAIN) * most) goto done;
  /* The new cut keeps the start's counts and counts itself. */
  d.recuts = P->d.recuts + 1;
  ret = PM_ALLOC(d.count0, size, "particles per rank");
  if (!ret) ret = PM_ALLOC(cut, mpm_decomp_items(size), "the cut");
  PM_TRY(pm_par_agree(ret));
  memcpy(d.count0, P->d.count0 ? P->d.count0 : P->d.count,
         sizeof(long) * (size_t)size);
  mpm_decomp_pack(&d, cut);
  PM_TRY(send_all(m, s, &d, g, &t));
  PM_TRY(share_anew(m, s, cut, &t, &lm, &ls));
  PM_TRY(pm_par_agree(mpm_work_create(lm, &lw)));
  take(m, s, w, lm, ls, lw);
  P = par_of(m); /* (the new share's) */
  /* A membrane's ghosts were made at the seeded positions: linked anew
   * where its points are now. */
  if (P->gh) {
    ret = mpm_ghosts_update(P->gh, m, s, true, true);
    if (!ret) ret = pm_par_agree(mpm_par_grow_scratch(m, w));
  }
done:
  P->counts.recut_seconds += pm_wtime() - t0;
  transfer_free(&t);
  free(cut);
  mpm_decomp_destroy(&d);
  mpm_work_destroy(lw);
  mpm_state_destroy(ls);
  mpm_model_destroy(lm);
  return ret;
}
