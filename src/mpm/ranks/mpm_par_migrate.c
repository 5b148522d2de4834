/* mpm_par_migrate: particles that left a rank's cells sent to their new
 * ranks with every array they carry, then the linked points' ghosts. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

/* ---- migration --------------------------------------------------------------
 */

/* Grow every per-particle array of m, s and w to room for n particles. */
static pm_err grow(mpm_model *m, mpm_state *s, mpm_work *w, long n) {
  struct mpm_par *P = par_of(m);
  if (n <= m->cap) return PM_SUCCESS;
  const long room = mpm_par_room_for(n);
  PM_CALL(PM_REALLOC(m->x0, 3 * room, "particle positions"));
  PM_CALL(PM_REALLOC(m->mass, room, "particle masses"));
  PM_CALL(PM_REALLOC(m->vol0, room, "particle volumes"));
  PM_CALL(PM_REALLOC(m->gid, room, "particle indices"));
  PM_CALL(PM_REALLOC(s->x, 3 * room, "particle positions"));
  PM_CALL(PM_REALLOC(s->v, 3 * room, "particle velocities"));
  PM_CALL(PM_REALLOC(s->vol, room, "particle volumes"));
  PM_CALL(PM_REALLOC(s->sigma, 9 * room, "particle stresses"));
  PM_CALL(PM_REALLOC(w->dx, 3 * room, "particle increments"));
  PM_CALL(PM_REALLOC(w->cp, room, "particle wave speeds"));
  if (w->cs) PM_CALL(PM_REALLOC(w->cs, room, "particle wave speeds"));
  if (w->fbar.jm1) {
    PM_CALL(PM_REALLOC(w->fbar.jm1, room, "F-bar volume ratios"));
    w->fbar.n = room;
  }
  if (w->fbar.cell) PM_CALL(PM_REALLOC(w->fbar.cell, room, "F-bar cells"));
  PM_CALL(PM_REALLOC(P->dest, room, "migration ranks"));
  PM_CALL(PM_REALLOC(P->order, room, "migration order"));
  PM_CALL(PM_REALLOC(P->tmp, P->width * room, "migration buffer"));
  m->cap = room;
  P->counts.grown++;
  return PM_SUCCESS;
}

static pm_err grow_group(mpm_group *g, mpm_group_state *gs, long n) {
  if (n <= g->cap) return PM_SUCCESS;
  const long room = mpm_par_room_for(n);
  for (int k = 0; k < gs->n; k++)
    PM_CALL(PM_REALLOC(gs->array[k].data, gs->array[k].ncomp * room,
                       gs->array[k].name));
  g->cap = room;
  return PM_SUCCESS;
}

static pm_err grow_buffer(double **buf, long *room, long records, int rec) {
  if (records <= *room) return PM_SUCCESS;
  const long r = mpm_par_room_for(records);
  PM_CALL(PM_REALLOC(*buf, r * rec, "migration buffer"));
  *room = r;
  return PM_SUCCESS;
}

int mpm_par_by_gid(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* One array's values in the new order: n_new of nc doubles, from the old
 * array (index order[j] >= 0) or a record (at offset off). */
static void permute(const struct mpm_par *P, double *data, long n_new, int nc,
                    long old_base, const double *recs, int off) {
  double *tmp = P->tmp;
  const long *order = P->order;
  const int rec = P->rec;
  PM_OMP(parallel for schedule(static) default(none)
         shared(tmp, order, data, n_new, nc, old_base, recs, off, rec))
  for (long j = 0; j < n_new; j++) {
    const long o = order[j];
    const double *src =
        o >= 0 ? data + (o - old_base) * nc : recs + (-o - 1) * rec + off;
    for (int c = 0; c < nc; c++) tmp[j * nc + c] = src[c];
  }
  memcpy(data, tmp, sizeof(double) * (size_t)(n_new * nc));
}

void mpm_par_pack(const mpm_model *m, const mpm_state *s, long p, int gi,
                  double *q) {
  const mpm_group *g = &m->group[gi];
  q[REC_GID] = (double)m->gid[p];
  q[REC_GROUP] = gi;
  memcpy(q + REC_X0, m->x0 + 3 * p, 3 * sizeof(double));
  q[REC_MASS] = m->mass[p];
  q[REC_VOL0] = m->vol0[p];
  memcpy(q + REC_X, s->x + 3 * p, 3 * sizeof(double));
  memcpy(q + REC_V, s->v + 3 * p, 3 * sizeof(double));
  q[REC_VOL] = s->vol[p];
  memcpy(q + REC_SIGMA, s->sigma + 9 * p, 9 * sizeof(double));
  int off = REC_BASE;
  for (int k = 0; k < s->group[gi].n; k++) {
    const mpm_array *a = &s->group[gi].array[k];
    memcpy(q + off, a->data + (p - g->begin) * a->ncomp,
           a->ncomp * sizeof(double));
    off += a->ncomp;
  }
}

void mpm_par_unpack(const mpm_model *m, mpm_state *s, long j, int gi,
                    const double *q) {
  const mpm_group *g = &m->group[gi];
  memcpy(s->x + 3 * j, q + REC_X, 3 * sizeof(double));
  memcpy(s->v + 3 * j, q + REC_V, 3 * sizeof(double));
  s->vol[j] = q[REC_VOL];
  memcpy(s->sigma + 9 * j, q + REC_SIGMA, 9 * sizeof(double));
  int off = REC_BASE;
  for (int k = 0; k < s->group[gi].n; k++) {
    const mpm_array *a = &s->group[gi].array[k];
    memcpy(a->data + (j - g->begin) * a->ncomp, q + off,
           a->ncomp * sizeof(double));
    off += a->ncomp;
  }
}

/* The particles' move between ranks (collective; every rank returns the
 * same). */
static pm_err move_particles(mpm_model *m, mpm_state *s, mpm_work *w) {
  struct mpm_par *P = par_of(m);
  const int n_near = P->n_near, rec = P->rec;
  const double t0 = pm_wtime();
  pm_err ret = PM_SUCCESS;
  P->linked_left = 0;
  P->reordered = false;
  pm_timers_start(&w->timers, w->timer_migrate);
  /* Where each particle goes. */
  memset(P->scount, 0, sizeof(int) * (size_t)(n_near + 1));
  long leaving = 0, far = -1;
  for (long p = 0; p < m->n; p++) {
    const int r = mpm_decomp_rank_at(&P->d, &m->grid, s->x + 3 * p);
    const int k = r == P->rank ? -1 : P->near_of[r];
    P->dest[p] = k;
    if (r != P->rank && k < 0 && far < 0) far = p;
    if (k >= 0) {
      P->scount[k]++;
      leaving++;
    }
  }
  if (far >= 0)
    ret = PM_ERROR(PM_ERR_UNSTABLE,
                   "step %ld, t = %.6g s, migration: particle %ld at (%g, %g, "
                   "%g) moved past the boxes next to its rank's in one step "
                   "(more than a cell): the step is too large",
                   s->step, s->t, m->gid[far], s->x[3 * far], s->x[3 * far + 1],
                   s->x[3 * far + 2]);
  MPI_Neighbor_alltoall(P->scount, 1, MPI_INT, P->rcount, 1, MPI_INT, P->near);
  long arriving = 0;
  for (int k = 0; k < n_near; k++) arriving += P->rcount[k];
  if (!ret) ret = grow_buffer(&P->sbuf, &P->sbuf_room, leaving, rec);
  if (!ret) ret = grow_buffer(&P->rbuf, &P->rbuf_room, arriving, rec);
  ret = pm_par_agree(ret);
  if (ret) goto done;
  /* Pack the leaving particles, by rank, in their order. */
  P->sdisp[0] = P->rdisp[0] = 0;
  for (int k = 0; k < n_near; k++) {
    P->sdisp[k + 1] = P->sdisp[k] + P->scount[k];
    P->rdisp[k + 1] = P->rdisp[k] + P->rcount[k];
  }
  for (int k = 0; k < n_near; k++) P->scount[k] = 0;
  for (int gi = 0; leaving > 0 && gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const bool linked = g->kind->ranks_link != NULL;
    for (long p = g->begin; p < g->end; p++) {
      const int r = P->dest[p];
      if (r < 0) continue;
      P->linked_left += linked;
      mpm_par_pack(m, s, p, gi,
                   P->sbuf + (long)(P->sdisp[r] + P->scount[r]++) * rec);
    }
  }
  for (int k = 0; k <= n_near; k++) {
    P->sdisp[k] *= rec;
    P->rdisp[k] *= rec;
  }
  for (int k = 0; k < n_near; k++) {
    P->scount[k] = P->sdisp[k + 1] - P->sdisp[k];
    P->rcount[k] = P->rdisp[k + 1] - P->rdisp[k];
  }
  MPI_Neighbor_alltoallv(P->sbuf, P->scount, P->sdisp, MPI_DOUBLE, P->rbuf,
                         P->rcount, P->rdisp, MPI_DOUBLE, P->near);
  P->counts.migrated += leaving;
  P->counts.migrate_bytes += (double)leaving * rec * sizeof(double);
  pm_par_count_sent((double)leaving * rec * sizeof(double));
  if (leaving == 0 && arriving == 0) goto done;
  P->reordered = true;
  /* The new order: those that stay and those that came, by index. */
  qsort(P->rbuf, (size_t)arriving, (size_t)rec * sizeof(double),
        mpm_par_by_gid);
  const long n_new = m->n - leaving + arriving;
  ret = grow(m, s, w, n_new);
  long gcount[MPM_MAX_GROUPS] = {0};
  for (int gi = 0; gi < m->n_groups; gi++)
    gcount[gi] = m->group[gi].end - m->group[gi].begin;
  for (long p = 0; p < m->n; p++)
    if (P->dest[p] >= 0)
      for (int gi = 0; gi < m->n_groups; gi++)
        if (p >= m->group[gi].begin && p < m->group[gi].end) gcount[gi]--;
  for (long k = 0; k < arriving; k++)
    gcount[(int)P->rbuf[k * rec + REC_GROUP]]++;
  for (int gi = 0; !ret && gi < m->n_groups; gi++)
    ret = grow_group(&m->group[gi], &s->group[gi], gcount[gi]);
  if (ret) goto done;
  {
    long j = 0, p = 0, k = 0;
    while (p < m->n || k < arriving) {
      if (p < m->n && P->dest[p] >= 0) {
        p++;
        continue;
      }
      bool take_old =
          k >= arriving ||
          (p < m->n && (double)m->gid[p] < P->rbuf[k * rec + REC_GID]);
      P->order[j++] = take_old ? p++ : -(k++ + 1);
    }
  }
  /* The common arrays (old indices from 0), then each group's (old
   * indices from the group's old start; a particle never changes group). */
  const double *recs = P->rbuf;
  long old_begin[MPM_MAX_GROUPS];
  for (int gi = 0; gi < m->n_groups; gi++) old_begin[gi] = m->group[gi].begin;
  {
    /* gid as doubles through the buffer, then back */
    double *tmp = P->tmp;
    for (long j = 0; j < n_new; j++) {
      const long o = P->order[j];
      tmp[j] = o >= 0 ? (double)m->gid[o] : recs[(-o - 1) * rec + REC_GID];
    }
    for (long j = 0; j < n_new; j++) m->gid[j] = (long)tmp[j];
  }
  permute(P, m->x0, n_new, 3, 0, recs, REC_X0);
  permute(P, m->mass, n_new, 1, 0, recs, REC_MASS);
  permute(P, m->vol0, n_new, 1, 0, recs, REC_VOL0);
  permute(P, s->x, n_new, 3, 0, recs, REC_X);
  permute(P, s->v, n_new, 3, 0, recs, REC_V);
  permute(P, s->vol, n_new, 1, 0, recs, REC_VOL);
  permute(P, s->sigma, n_new, 9, 0, recs, REC_SIGMA);
  /* The groups' new ranges are known from the indices now. */
  const long old_n = m->n;
  m->n = n_new;
  mpm_par_set_ranges(m, s);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    /* This group's slice of the order, with old indices relative to its
     * old start. */
    long *order = P->order + g->begin;
    const long ng = g->end - g->begin;
    int off = REC_BASE;
    for (int k = 0; k < s->group[gi].n; k++) {
      mpm_array *a = &s->group[gi].array[k];
      const int nc = a->ncomp;
      for (long j = 0; j < ng; j++) {
        const long o = order[j];
        const double *src = o >= 0 ? a->data + (o - old_begin[gi]) * nc
                                   : recs + (-o - 1) * rec + off;
        for (int c = 0; c < nc; c++) P->tmp[j * nc + c] = src[c];
      }
      memcpy(a->data, P->tmp, sizeof(double) * (size_t)(ng * nc));
      off += nc;
    }
  }
  (void)old_n;
done:
  if (m->n > P->counts.most) P->counts.most = m->n;
  pm_timers_stop(&w->timers, w->timer_migrate);
  P->counts.migrate_seconds += pm_wtime() - t0;
  return pm_par_agree(ret);
}

/* Room in each group's step workspace for what its kind needs now (its
 * particles, a membrane's triangles). */
pm_err mpm_par_grow_scratch(const mpm_model *m, mpm_work *w) {
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const long need = g->kind->scratch ? g->kind->scratch(m, g) : 0;
    if (need <= w->n_scratch[gi]) continue;
    PM_CALL(PM_REALLOC(w->scratch[gi], need, "kind workspace"));
    w->n_scratch[gi] = need;
  }
  return PM_SUCCESS;
}

pm_err mpm_par_migrate(mpm_model *m, mpm_state *s, mpm_work *w) {
  struct mpm_par *P = par_of(m);
  PM_CALL(move_particles(m, s, w));
  if (!P->gh) return mpm_par_balance(m, s, w);
  /* The ghosts: their links anew when a linked point moved between any
   * two ranks, and their positions after this step's move. */
  const double t0 = pm_wtime();
  pm_timers_start(&w->timers, w->timer_migrate);
  long moved = P->linked_left;
  pm_par_sum_long(&moved, 1);
  const double sent = mpm_ghosts_bytes(P->gh);
  pm_err e = mpm_ghosts_update(P->gh, m, s, moved > 0, P->reordered);
  if (!e) e = pm_par_agree(mpm_par_grow_scratch(m, w));
  P->counts.ghost_bytes += mpm_ghosts_bytes(P->gh) - sent;
  pm_par_count_sent(mpm_ghosts_bytes(P->gh) - sent);
  pm_timers_stop(&w->timers, w->timer_migrate);
  P->counts.migrate_seconds += pm_wtime() - t0;
  return e ? e : mpm_par_balance(m, s, w);
}

const double *mpm_par_ghost_x(const mpm_model *m, int gi) {
  return mpm_ghosts_x(par_of(m)->gh, gi);
}

const double *mpm_par_nearby(const mpm_model *m, int gi, long *n,
                             const long **ids) {
  return mpm_ghosts_nearby(par_of(m)->gh, gi, n, ids);
}

void mpm_par_cells(const mpm_model *m, long nn[3], long lo[3], long hi[3]) {
  const struct mpm_par *P = par_of(m);
  for (int a = 0; a < 3; a++) {
    nn[a] = a < m->dim ? P->d.cells[a] + 1 : 1;
    lo[a] = P->d.box[6 * P->rank + a];
    hi[a] = P->d.box[6 * P->rank + 3 + a];
  }
}

const long *mpm_par_ghost_ids(const mpm_model *m, int gi, long *n) {
  *n = mpm_ghosts_count(par_of(m)->gh, gi);
  return mpm_ghosts_ids(par_of(m)->gh, gi);
}
