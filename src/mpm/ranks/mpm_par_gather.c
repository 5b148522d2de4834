/* mpm_par_gather: every rank's particles and nodal arrays gathered into
 * the whole model's state on rank 0, in the order of one process. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "pm_omp.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

/* ---- gather to rank 0 -------------------------------------------------------
 */

/* Gather n local values of nc doubles each (data) into the whole run's
 * array on rank 0 (out, indexed by the one-process index less base). */
static void gather_array(struct mpm_par *P, const double *data, long n, int nc,
                         const long *gid, long base, double *out) {
  const int size = P->d.size;
  int cnt = (int)(n * nc);
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(data, cnt, MPI_DOUBLE, P->gbuf, P->gcount, P->gdisp, MPI_DOUBLE,
              0, pm_par_comm());
  if (P->rank != 0) {
    pm_par_count_sent((double)cnt * sizeof(double));
    return;
  }
  const long total = P->gdisp[size] / (nc ? nc : 1);
  for (long j = 0; j < total; j++)
    memcpy(out + (gid[j] - base) * nc, P->gbuf + j * nc, nc * sizeof(double));
}

/* Three values per node of this rank's owned nodes (of src, or the flags
 * srcf) into the whole grid's array on rank 0 (dst, or the flags dstf;
 * fg the whole grid there, NULL on the other ranks): each rank's owned
 * nodes in its box's order, placed by rank 0 (collective). */
static pm_err gather_owned(const mpm_model *m, const mpm_grid *fg,
                           const double *src, const unsigned char *srcf,
                           double *dst, unsigned char *dstf) {
  struct mpm_par *P = par_of(m);
  const mpm_grid *g = &m->grid;
  const int size = P->d.size;
  pm_err e = PM_SUCCESS;
  if (!P->nodal) e = PM_ALLOC(P->nodal, 3 * P->n_owned + 1, "nodal gather");
  if (!e && fg && !P->whole)
    e = PM_ALLOC(P->whole, 3 * fg->n_nodes, "nodal gather");
  PM_CALL(pm_par_agree(e));
  long k = 0;
  for (long i = 0; i < g->n_nodes; i++)
    if (P->owned[i])
      for (int c = 0; c < 3; c++, k++)
        P->nodal[k] = src ? src[3 * i + c] : (double)srcf[3 * i + c];
  int cnt = (int)k;
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(P->nodal, cnt, MPI_DOUBLE, P->whole, P->gcount, P->gdisp,
              MPI_DOUBLE, 0, pm_par_comm());
  if (!fg) return PM_SUCCESS;
  const double *b = P->whole;
  for (int r = 0; r < size; r++) {
    long lo[3], hi[3];
    mpm_decomp_nodes(&P->d, r, lo, hi);
    for (int a = fg->dim; a < 3; a++) lo[a] = 0, hi[a] = 1;
    for (long z = lo[2]; z < hi[2]; z++)
      for (long y = lo[1]; y < hi[1]; y++)
        for (long x = lo[0]; x < hi[0]; x++, b += 3) {
          const long q = x + y * fg->stride[1] + z * fg->stride[2];
          for (int c = 0; c < 3; c++) {
            if (dst)
              dst[3 * q + c] = b[c];
            else
              dstf[3 * q + c] = b[c] != 0;
          }
        }
  }
  return PM_SUCCESS;
}

pm_err mpm_par_gather(const mpm_model *m, const mpm_state *s,
                      const mpm_model *full, mpm_state *fs) {
  struct mpm_par *P = par_of(m);
  const int size = P->d.size;
  /* The one-process indices, all at once, then per group. */
  int cnt = (int)m->n;
  MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
  if (P->rank == 0) {
    P->gdisp[0] = 0;
    for (int r = 0; r < size; r++) P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
  }
  MPI_Gatherv(m->gid, cnt, MPI_LONG, P->ggid, P->gcount, P->gdisp, MPI_LONG, 0,
              pm_par_comm());
  double *fx = fs ? fs->x : NULL, *fv = fs ? fs->v : NULL,
         *fvol = fs ? fs->vol : NULL, *fsig = fs ? fs->sigma : NULL;
  gather_array(P, s->x, m->n, 3, P->ggid, 0, fx);
  gather_array(P, s->v, m->n, 3, P->ggid, 0, fv);
  gather_array(P, s->vol, m->n, 1, P->ggid, 0, fvol);
  gather_array(P, s->sigma, m->n, 9, P->ggid, 0, fsig);
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    const long ng = g->end - g->begin;
    cnt = (int)ng;
    MPI_Gather(&cnt, 1, MPI_INT, P->gcount, 1, MPI_INT, 0, pm_par_comm());
    if (P->rank == 0) {
      P->gdisp[0] = 0;
      for (int r = 0; r < size; r++)
        P->gdisp[r + 1] = P->gdisp[r] + P->gcount[r];
    }
    MPI_Gatherv(m->gid + g->begin, cnt, MPI_LONG, P->ggid, P->gcount, P->gdisp,
                MPI_LONG, 0, pm_par_comm());
    for (int k = 0; k < s->group[gi].n; k++) {
      const mpm_array *a = &s->group[gi].array[k];
      gather_array(P, a->data, ng, a->ncomp, P->ggid, P->gbegin[gi],
                   fs ? fs->group[gi].array[k].data : NULL);
    }
  }
  /* The energy accounts: every rank's (for a checkpoint), and summed. */
  enum { n_acc = MPM_PAR_ACCOUNTS - 2 };
  double acc[MPM_PAR_ACCOUNTS];
  memcpy(acc, s->energy, sizeof s->energy);
  acc[n_acc] = s->external_work;
  acc[n_acc + 1] = s->dissipated;
  MPI_Gather(acc, MPM_PAR_ACCOUNTS, MPI_DOUBLE, P->accounts, MPM_PAR_ACCOUNTS,
             MPI_DOUBLE, 0, pm_par_comm());
  pm_par_sum(acc, MPM_PAR_ACCOUNTS);
  if (fs) {
    mpm_state_copy_values(fs, s);
    memcpy(fs->energy, acc, sizeof fs->energy);
    fs->external_work = acc[n_acc];
    fs->dissipated = acc[n_acc + 1];
  }
  if (!s->force_prev) return PM_SUCCESS;
  /* Dynamic relaxation's nodal arrays. */
  const mpm_grid *fg = fs ? &full->grid : NULL;
  PM_CALL(gather_owned(m, fg, s->force_prev, NULL, fs ? fs->force_prev : NULL,
                       NULL));
  if (s->fixed)
    PM_CALL(gather_owned(m, fg, NULL, s->fixed, NULL, fs ? fs->fixed : NULL));
  return PM_SUCCESS;
}

pm_err mpm_par_gather_nodes(const mpm_model *m, const mpm_model *full,
                            const double *local, double *whole) {
  return gather_owned(m, full ? &full->grid : NULL, local, NULL, whole, NULL);
}

void mpm_par_whole_ranges(const mpm_model *m, mpm_par_ranges *out) {
  const struct mpm_par *P = par_of(m);
  *out = (mpm_par_ranges){.n = P->n_full,
                          .gbegin = P->gbegin,
                          .gend = P->gend,
                          .bbegin = P->bbegin,
                          .bend = P->bend};
}

enum { x0_block = 1 << 15 }; /* particles a message */

/* A rank's particles' one-process indices and reference positions to rank
 * 0, in blocks, the last one short (empty where n is a multiple). */
static void send_x0(const mpm_model *m) {
  for (long at = 0;; at += x0_block) {
    const int k = (int)(m->n - at < x0_block ? m->n - at : x0_block);
    MPI_Send(m->gid + at, k, MPI_LONG, 0, 1, pm_par_comm());
    MPI_Send(m->x0 + 3 * at, 3 * k, MPI_DOUBLE, 0, 2, pm_par_comm());
    if (k < x0_block) break;
  }
  pm_par_count_sent((double)m->n * (sizeof(long) + 3 * sizeof(double)));
}

/* On rank 0: rank r's blocks (send_x0) placed into all, through the
 * buffers gid and x of a block. */
static void receive_x0(int r, long *gid, double *x, double *all) {
  for (;;) {
    MPI_Status st;
    int k = 0;
    MPI_Recv(gid, x0_block, MPI_LONG, r, 1, pm_par_comm(), &st);
    MPI_Get_count(&st, MPI_LONG, &k);
    MPI_Recv(x, 3 * x0_block, MPI_DOUBLE, r, 2, pm_par_comm(),
             MPI_STATUS_IGNORE);
    for (int j = 0; j < k; j++)
      memcpy(all + 3 * gid[j], x + 3 * j, 3 * sizeof(double));
    if (k < x0_block) return;
  }
}

pm_err mpm_par_gather_x0(const mpm_model *m, double **x0) {
  struct mpm_par *P = par_of(m);
  long *gid = NULL;
  double *all = NULL, *x = NULL;
  pm_err e = PM_SUCCESS;
  if (P->rank == 0) {
    e = PM_ALLOC(all, 3 * P->n_full + 1, "reference positions");
    if (!e) e = PM_ALLOC(gid, x0_block, "reference positions");
    if (!e) e = PM_ALLOC(x, 3 * x0_block, "reference positions");
  }
  e = pm_par_agree(e);
  if (!e && P->rank != 0) send_x0(m);
  if (!e && P->rank == 0) {
    for (long j = 0; j < m->n; j++)
      memcpy(all + 3 * m->gid[j], m->x0 + 3 * j, 3 * sizeof(double));
    for (int r = 1; r < P->d.size; r++) receive_x0(r, gid, x, all);
  }
  free(gid);
  free(x);
  if (e) free(all);
  *x0 = e ? NULL : all;
  return e;
}

void mpm_par_extreme(const mpm_model *m, double *v, long gid, double at[3],
                     bool max) {
  const int size = pm_par_size();
  double mine[5] = {*v, (double)gid, at[0], at[1], at[2]};
  double *all = par_of(m)->extreme; /* [5 size], made with the share */
  MPI_Allgather(mine, 5, MPI_DOUBLE, all, 5, MPI_DOUBLE, pm_par_comm());
  int best = 0;
  for (int r = 1; r < size; r++) {
    const double *a = all + 5 * r, *b = all + 5 * best;
    const bool beats = max ? a[0] > b[0] : a[0] < b[0];
    if (beats || (a[0] == b[0] && a[1] < b[1])) best = r;
  }
  *v = all[5 * best];
  memcpy(at, all + 5 * best + 2, 3 * sizeof(double));
}
