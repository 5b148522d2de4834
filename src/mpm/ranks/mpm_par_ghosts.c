/* mpm_par_ghosts: the ghosts of a rank's linked particles (membrane
 * points' neighbours on other ranks): which, from whom, and their
 * positions each step. */
#include "mpm_par_ghosts.h"

#include <stdlib.h>
#include <string.h>

#include <math.h>

#include "mpm_kind.h"
#include "pm_par.h"
#include "pm_par_mpi.h"

struct mpm_ghosts {
  MPI_Comm near; /* the ranks whose boxes touch this one's (borrowed) */
  int n_near, rank;
  /* each linked group's ghosts, from its kind: one-process indices,
   * increasing; in the whole list from start[gi] */
  bool linked[MPM_MAX_GROUPS];
  long *want_g[MPM_MAX_GROUPS], room_g[MPM_MAX_GROUPS], n_g[MPM_MAX_GROUPS];
  long start[MPM_MAX_GROUPS];
  /* every group's ghosts in one list (increasing: a group's particles
   * follow the previous group's), their positions, and for each position
   * received (in the order they arrive) its place in the list */
  long n, room;
  long *want, *slot;
  double *x, *rbuf;
  /* the neighbours' requests (their lists), and what this rank sends
   * them: the points it holds of each one's list, by one-process index
   * and by their place among its particles */
  int *nreq, *req_disp;
  long *req, req_room;
  long *send_gid, *send_idx, send_room, n_send;
  double *sbuf;
  int *scount, *sdisp, *rcount, *rdisp; /* per neighbour: points */
  int *sc3, *sd3, *rc3, *rd3;           /* per neighbour: doubles */
  double bytes;
  /* Nearby points: those of each group with a reach (mpm_kind.ranks_reach,
   * in cells) in the cells that far around this rank's box, sent every
   * step by the ranks whose boxes lie within the largest reach (their
   * graph communicator, and their boxes' cells [lo, hi), 6 each) as
   * records of 4 doubles (one-process index, position). */
  const mpm_grid *grid;
  long cells[3]; /* the whole grid's */
  int reach[MPM_MAX_GROUPS], most_reach;
  long gbegin[MPM_MAX_GROUPS], gend[MPM_MAX_GROUPS]; /* one-process */
  MPI_Comm far;
  int n_far;
  long *far_box;
  int *fcount, *fdisp, *gcount, *gdisp; /* per far rank: doubles */
  double *fsend, *frecv;
  long fsend_room, frecv_room; /* records */
  /* what came, by one-process index: every group's in one list, each
   * group's from nb_start */
  long nb_n[MPM_MAX_GROUPS], nb_start[MPM_MAX_GROUPS];
  long *nb_ids, nb_room;
  double *nb_x;
};

enum { NEAR_REC = 4 }; /* a nearby point's record: index, position */

static int long_cmp(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* The place of v in the increasing a[0, n), or -1. */
static long find(const long *a, long n, long v) {
  const long *f = n > 0 ? bsearch(&v, a, (size_t)n, sizeof *a, long_cmp) : NULL;
  return f ? f - a : -1;
}

/* Room r >= n (some to spare) for what is sized by n. */
static long room_for(long n) { return n + n / 4 + 16; }

/* Prefix sums: disp[k] of count[0, k) for n counts. */
static void prefix(const int *count, int *disp, int n) {
  disp[0] = 0;
  for (int k = 0; k < n; k++) disp[k + 1] = disp[k] + count[k];
}

void mpm_ghosts_destroy(mpm_ghosts *gh) {
  if (!gh) return;
  for (int gi = 0; gi < MPM_MAX_GROUPS; gi++) free(gh->want_g[gi]);
  free(gh->want);
  free(gh->slot);
  free(gh->x);
  free(gh->rbuf);
  free(gh->nreq);
  free(gh->req_disp);
  free(gh->req);
  free(gh->send_gid);
  free(gh->send_idx);
  free(gh->sbuf);
  free(gh->scount);
  free(gh->sdisp);
  free(gh->rcount);
  free(gh->rdisp);
  free(gh->sc3);
  free(gh->sd3);
  free(gh->rc3);
  free(gh->rd3);
  if (gh->far != MPI_COMM_NULL) MPI_Comm_free(&gh->far);
  free(gh->far_box);
  free(gh->fcount);
  free(gh->fdisp);
  free(gh->gcount);
  free(gh->gdisp);
  free(gh->fsend);
  free(gh->frecv);
  free(gh->nb_ids);
  free(gh->nb_x);
  free(gh);
}

/* ---- nearby points -------------------------------------------------------
 */

/* The cell of x along each axis, clamped to the grid (as the
 * decomposition's). */
static void cell_at(const mpm_ghosts *gh, const double x[3], long c[3]) {
  const mpm_grid *g = gh->grid;
  for (int a = 0; a < 3; a++) {
    if (a >= g->dim) {
      c[a] = 0;
      continue;
    }
    long k = (long)floor((x[a] - g->origin[a]) * g->inv_h);
    c[a] = k < 0 ? 0 : k >= gh->cells[a] ? gh->cells[a] - 1 : k;
  }
}

/* Whether cell c lies within r cells of box b (cells [lo, hi), 6). */
static bool within(const long c[3], const long *b, int r, int dim) {
  for (int a = 0; a < dim; a++)
    if (c[a] < b[a] - r || c[a] >= b[3 + a] + r) return false;
  return true;
}

/* The records of this rank's points for the far ranks whose boxes they
 * are near: counted into fcount (per far rank), and with pack written
 * into fsend from fdisp. */
static void nearby_records(mpm_ghosts *gh, const mpm_model *m,
                           const mpm_state *s, bool pack) {
  const int dim = gh->grid->dim;
  for (int k = 0; k < gh->n_far; k++) gh->fcount[k] = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    if (!gh->reach[gi]) continue;
    for (long p = m->group[gi].begin; p < m->group[gi].end; p++) {
      long c[3];
      cell_at(gh, s->x + 3 * p, c);
      for (int k = 0; k < gh->n_far; k++) {
        if (!within(c, gh->far_box + 6 * k, gh->reach[gi], dim)) continue;
        if (pack) {
          double *q = gh->fsend + gh->fdisp[k] + gh->fcount[k];
          q[0] = (double)m->gid[p];
          memcpy(q + 1, s->x + 3 * p, 3 * sizeof(double));
        }
        gh->fcount[k] += NEAR_REC;
      }
    }
  }
}

static int by_index(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Room for n records in *buf (room *room). */
static pm_err room_for_records(double **buf, long *room, long n) {
  if (n <= *room && *buf) return PM_SUCCESS;
  const long r = room_for(n);
  PM_CALL(PM_REALLOC(*buf, NEAR_REC * r, "nearby points"));
  *room = r;
  return PM_SUCCESS;
}

/* This step's nearby points from the far ranks (collective). */
static pm_err nearby(mpm_ghosts *gh, const mpm_model *m, const mpm_state *s) {
  const int nf = gh->n_far;
  nearby_records(gh, m, s, false);
  MPI_Neighbor_alltoall(gh->fcount, 1, MPI_INT, gh->gcount, 1, MPI_INT,
                        gh->far);
  prefix(gh->fcount, gh->fdisp, nf);
  prefix(gh->gcount, gh->gdisp, nf);
  const long sent = gh->fdisp[nf] / NEAR_REC, got = gh->gdisp[nf] / NEAR_REC;
  pm_err e = room_for_records(&gh->fsend, &gh->fsend_room, sent);
  if (!e) e = room_for_records(&gh->frecv, &gh->frecv_room, got);
  if (!e && (got > gh->nb_room || !gh->nb_ids)) {
    const long r = room_for(got);
    e = PM_REALLOC(gh->nb_ids, r, "nearby points");
    if (!e) e = PM_REALLOC(gh->nb_x, 3 * r, "nearby points");
    if (!e) gh->nb_room = r;
  }
  PM_CALL(pm_par_agree(e));
  nearby_records(gh, m, s, true);
  MPI_Neighbor_alltoallv(gh->fsend, gh->fcount, gh->fdisp, MPI_DOUBLE,
                         gh->frecv, gh->gcount, gh->gdisp, MPI_DOUBLE, gh->far);
  gh->bytes += (double)gh->fdisp[nf] * sizeof(double);
  /* In one-process order, each group's from its start. */
  qsort(gh->frecv, (size_t)got, NEAR_REC * sizeof(double), by_index);
  for (long j = 0; j < got; j++) {
    gh->nb_ids[j] = (long)gh->frecv[NEAR_REC * j];
    memcpy(gh->nb_x + 3 * j, gh->frecv + NEAR_REC * j + 1, 3 * sizeof(double));
  }
  long at = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    while (at < got && gh->nb_ids[at] < gh->gbegin[gi]) at++;
    gh->nb_start[gi] = at;
    while (at < got && gh->nb_ids[at] < gh->gend[gi]) at++;
    gh->nb_n[gi] = at - gh->nb_start[gi];
  }
  return PM_SUCCESS;
}

/* The ranks whose boxes lie within the largest reach of this rank's, and
 * their graph communicator. */
static pm_err make_far(mpm_ghosts *gh, const mpm_decomp *d, int rank, int dim) {
  const long *me = d->box + 6 * rank;
  int *list = NULL, *weight = NULL;
  pm_err ret = PM_ALLOC(gh->far_box, 6 * d->size, "nearby ranks");
  if (!ret) ret = PM_ALLOC(list, d->size + 1, "nearby ranks");
  if (!ret) ret = PM_ALLOC(weight, d->size + 1, "nearby ranks");
  int **counts[] = {&gh->fcount, &gh->fdisp, &gh->gcount, &gh->gdisp};
  for (size_t k = 0; !ret && k < sizeof counts / sizeof *counts; k++)
    ret = PM_ALLOC(*counts[k], d->size + 1, "nearby counts");
  ret = pm_par_agree(ret); /* before the collective */
  if (ret) goto done;
  for (int q = 0; q < d->size; q++) {
    const long *b = d->box + 6 * q;
    bool close = q != rank;
    for (int a = 0; a < dim; a++)
      close = close && b[a] - gh->most_reach < me[3 + a] &&
              me[a] < b[3 + a] + gh->most_reach;
    if (!close) continue;
    memcpy(gh->far_box + 6 * gh->n_far, b, 6 * sizeof(long));
    weight[gh->n_far] = 1;
    list[gh->n_far++] = q;
  }
  int e = MPI_Dist_graph_create_adjacent(pm_par_comm(), gh->n_far, list, weight,
                                         gh->n_far, list, weight, MPI_INFO_NULL,
                                         0, &gh->far);
  PM_ENSURE(e == MPI_SUCCESS, PM_ERR_INTERNAL,
            "MPI_Dist_graph_create_adjacent failed (%d)", e);
done:
  free(list);
  free(weight);
  return ret;
}

/* Every linked group's links and ghosts anew, into one list (local). */
static pm_err make_lists(mpm_ghosts *gh, mpm_model *m) {
  long total = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    if (!gh->linked[gi]) continue;
    mpm_group *g = &m->group[gi];
    PM_CALL(g->kind->ranks_link(m, g, &gh->want_g[gi], &gh->room_g[gi],
                                &gh->n_g[gi]));
    gh->start[gi] = total;
    total += gh->n_g[gi];
  }
  if (total > gh->room || !gh->want) {
    const long r = room_for(total);
    PM_CALL(PM_REALLOC(gh->want, r, "ghost points"));
    PM_CALL(PM_REALLOC(gh->slot, r, "ghost points"));
    PM_CALL(PM_REALLOC(gh->x, 3 * r, "ghost positions"));
    PM_CALL(PM_REALLOC(gh->rbuf, 3 * r, "ghost positions"));
    gh->room = r;
  }
  for (int gi = 0; gi < m->n_groups; gi++)
    if (gh->linked[gi])
      memcpy(gh->want + gh->start[gi], gh->want_g[gi],
             sizeof(long) * (size_t)gh->n_g[gi]);
  gh->n = total;
  return PM_SUCCESS;
}

/* Room for the neighbours' requests (total) and what this rank may send
 * of them. */
static pm_err room_to_answer(mpm_ghosts *gh, long total) {
  if (total <= gh->req_room && gh->req) return PM_SUCCESS;
  const long r = room_for(total);
  PM_CALL(PM_REALLOC(gh->req, r, "ghost requests"));
  PM_CALL(PM_REALLOC(gh->send_gid, r, "ghost requests"));
  PM_CALL(PM_REALLOC(gh->send_idx, r, "ghost requests"));
  PM_CALL(PM_REALLOC(gh->sbuf, 3 * r, "ghost positions"));
  gh->req_room = gh->send_room = r;
  return PM_SUCCESS;
}

/* Ask the neighbours for the ghosts and learn what to send them
 * (collective over the neighbourhood; every rank agrees on the result). */
static pm_err ask(mpm_ghosts *gh, const mpm_model *m, const mpm_state *s) {
  const int nb = gh->n_near;
  int cnt = (int)gh->n;
  MPI_Neighbor_allgather(&cnt, 1, MPI_INT, gh->nreq, 1, MPI_INT, gh->near);
  prefix(gh->nreq, gh->req_disp, nb);
  PM_CALL(pm_par_agree(room_to_answer(gh, gh->req_disp[nb])));
  MPI_Neighbor_allgatherv(gh->want, cnt, MPI_LONG, gh->req, gh->nreq,
                          gh->req_disp, MPI_LONG, gh->near);
  gh->bytes += (double)nb * cnt * sizeof(long);
  /* What this rank holds of each neighbour's list, in its order. */
  gh->n_send = 0;
  for (int k = 0; k < nb; k++) {
    gh->scount[k] = 0;
    for (int i = gh->req_disp[k]; i < gh->req_disp[k + 1]; i++) {
      const long p = find(m->gid, m->n, gh->req[i]);
      if (p < 0) continue;
      gh->send_gid[gh->n_send] = gh->req[i];
      gh->send_idx[gh->n_send++] = p;
      gh->scount[k]++;
    }
  }
  prefix(gh->scount, gh->sdisp, nb);
  MPI_Neighbor_alltoall(gh->scount, 1, MPI_INT, gh->rcount, 1, MPI_INT,
                        gh->near);
  prefix(gh->rcount, gh->rdisp, nb);
  /* Each point is on one rank and each list names it once: at most n. */
  const long got = gh->rdisp[nb];
  PM_ASSERT(got <= gh->n);
  MPI_Neighbor_alltoallv(gh->send_gid, gh->scount, gh->sdisp, MPI_LONG,
                         gh->slot, gh->rcount, gh->rdisp, MPI_LONG, gh->near);
  gh->bytes += (double)gh->n_send * sizeof(long);
  for (int k = 0; k <= nb; k++) {
    if (k < nb) {
      gh->sc3[k] = 3 * gh->scount[k];
      gh->rc3[k] = 3 * gh->rcount[k];
    }
    gh->sd3[k] = 3 * gh->sdisp[k];
    gh->rd3[k] = 3 * gh->rdisp[k];
  }
  /* Where each point that comes goes; one that none sends is on a rank
   * farther than the neighbours. */
  for (long j = 0; j < gh->n; j++) gh->x[3 * j] = 0;
  for (long r = 0; r < got; r++) {
    gh->slot[r] = find(gh->want, gh->n, gh->slot[r]);
    PM_ASSERT(gh->slot[r] >= 0);
    gh->x[3 * gh->slot[r]] = 1;
  }
  pm_err e = PM_SUCCESS;
  for (long j = 0; got < gh->n && j < gh->n; j++)
    if (gh->x[3 * j] == 0) {
      e = PM_ERROR(PM_ERR_UNSTABLE,
                   "step %ld, t = %.6g s: particle %ld, a membrane point "
                   "linked to points of rank %d, is on no rank whose box "
                   "touches that rank's: the membrane's links reach farther "
                   "than the next boxes; run on fewer ranks",
                   s->step, s->t, gh->want[j], gh->rank);
      break;
    }
  return pm_par_agree(e);
}

/* The ghosts' positions from the ranks that hold them (collective over the
 * neighbourhood). */
static void exchange(mpm_ghosts *gh, const mpm_state *s) {
  for (long i = 0; i < gh->n_send; i++)
    memcpy(gh->sbuf + 3 * i, s->x + 3 * gh->send_idx[i], 3 * sizeof(double));
  MPI_Neighbor_alltoallv(gh->sbuf, gh->sc3, gh->sd3, MPI_DOUBLE, gh->rbuf,
                         gh->rc3, gh->rd3, MPI_DOUBLE, gh->near);
  for (long r = 0; r < gh->n; r++)
    memcpy(gh->x + 3 * gh->slot[r], gh->rbuf + 3 * r, 3 * sizeof(double));
  gh->bytes += 3.0 * (double)gh->n_send * sizeof(double);
}

pm_err mpm_ghosts_update(mpm_ghosts *gh, mpm_model *m, const mpm_state *s,
                         bool relink, bool reordered) {
  if (relink) {
    PM_CALL(pm_par_agree(make_lists(gh, m)));
    PM_CALL(ask(gh, m, s));
  } else if (reordered) {
    /* The points sent are the same (none moved), their places not. */
    for (long i = 0; i < gh->n_send; i++)
      gh->send_idx[i] = find(m->gid, m->n, gh->send_gid[i]);
  }
  exchange(gh, s);
  return gh->most_reach > 0 ? nearby(gh, m, s) : PM_SUCCESS;
}

pm_err mpm_ghosts_create(mpm_model *m, const mpm_state *s, const mpm_decomp *d,
                         const long *gbegin, const long *gend, MPI_Comm near,
                         int n_near, mpm_ghosts **out) {
  pm_err ret = PM_SUCCESS;
  mpm_ghosts *gh = NULL;
  *out = NULL;
  bool any = false;
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_kind *k = m->group[gi].kind;
    any = any || k->ranks_link ||
          (k->ranks_reach && k->ranks_reach(&m->group[gi]));
  }
  if (!any) return PM_SUCCESS;
  PM_TRY(PM_ALLOC(gh, 1, "ghost points"));
  gh->near = near;
  gh->far = MPI_COMM_NULL;
  gh->n_near = n_near;
  gh->rank = pm_par_rank();
  gh->grid = &m->grid;
  for (int a = 0; a < 3; a++) gh->cells[a] = d->cells[a];
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_kind *k = m->group[gi].kind;
    gh->linked[gi] = k->ranks_link != NULL;
    gh->reach[gi] = k->ranks_reach ? k->ranks_reach(&m->group[gi]) : 0;
    if (gh->reach[gi] > gh->most_reach) gh->most_reach = gh->reach[gi];
    gh->gbegin[gi] = gbegin[gi];
    gh->gend[gi] = gend[gi];
  }
  int **counts[] = {&gh->nreq,   &gh->req_disp, &gh->scount, &gh->sdisp,
                    &gh->rcount, &gh->rdisp,    &gh->sc3,    &gh->sd3,
                    &gh->rc3,    &gh->rd3};
  for (size_t k = 0; k < sizeof counts / sizeof *counts; k++)
    PM_TRY(PM_ALLOC(*counts[k], n_near + 1, "ghost counts"));
done:
  ret = pm_par_agree(ret);
  if (!ret && gh->most_reach > 0) ret = make_far(gh, d, gh->rank, m->dim);
  if (!ret) ret = mpm_ghosts_update(gh, m, s, true, true);
  if (ret) {
    mpm_ghosts_destroy(gh);
    return ret;
  }
  *out = gh;
  return PM_SUCCESS;
}

const double *mpm_ghosts_x(const mpm_ghosts *gh, int gi) {
  return gh && gh->linked[gi] ? gh->x + 3 * gh->start[gi] : NULL;
}

long mpm_ghosts_count(const mpm_ghosts *gh, int gi) {
  return gh && gh->linked[gi] ? gh->n_g[gi] : 0;
}

const double *mpm_ghosts_nearby(const mpm_ghosts *gh, int gi, long *n,
                                const long **ids) {
  const bool has = gh && gh->reach[gi] > 0;
  *n = has ? gh->nb_n[gi] : 0;
  *ids = has ? gh->nb_ids + gh->nb_start[gi] : NULL;
  return has ? gh->nb_x + 3 * gh->nb_start[gi] : NULL;
}

const long *mpm_ghosts_ids(const mpm_ghosts *gh, int gi) {
  return gh && gh->linked[gi] ? gh->want + gh->start[gi] : NULL;
}

double mpm_ghosts_bytes(const mpm_ghosts *gh) { return gh ? gh->bytes : 0; }
