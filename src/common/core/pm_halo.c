/* pm_halo: the neighbour exchange of the ranks layers on MPI alone (each
 * leaf's item to or from its root's, buffers made once). */
#include "pm_halo.h"

#include <limits.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* One side of the pattern: the ranks this rank exchanges with (ascending)
 * and, per rank, the items of this rank's arrays that go or come, packed
 * in that order into one buffer. */
typedef struct {
  int n;      /* ranks */
  int *rank;  /* [n] */
  long *ptr;  /* [n + 1] into item */
  long *item; /* [ptr[n]] */
  char *buf;  /* ptr[n] items of max_bytes */
} side;

struct pm_halo {
  MPI_Comm comm; /* a copy of the run's: no other message meets these */
  int max_bytes;
  side leaves; /* the leaves whose roots are on other ranks, by root rank */
  side roots;  /* the roots that other ranks' leaves mirror, by leaf rank */
  long n_self; /* leaves whose roots are on this rank */
  long *self_leaf, *self_root;
  MPI_Request *req; /* leaves.n + roots.n */
};

static void side_free(side *s) {
  free(s->rank);
  free(s->ptr);
  free(s->item);
  free(s->buf);
}

void pm_halo_destroy(pm_halo *h) {
  if (!h) return;
  side_free(&h->leaves);
  side_free(&h->roots);
  free(h->self_leaf);
  free(h->self_root);
  free(h->req);
  if (h->comm != MPI_COMM_NULL) MPI_Comm_free(&h->comm);
  free(h);
}

/* The ranks of s from per-rank counts (those > 0 but `skip`), with room for
 * their items and buffer. */
static pm_err side_make(side *s, const long *count, int size, int skip,
                        int max_bytes) {
  s->n = 0;
  for (int r = 0; r < size; r++) s->n += r != skip && count[r] > 0;
  PM_CALL(PM_ALLOC(s->rank, s->n + 1, "exchange ranks"));
  PM_CALL(PM_ALLOC(s->ptr, s->n + 1, "exchange offsets"));
  s->ptr[0] = 0;
  for (int r = 0, k = 0; r < size; r++) {
    if (r == skip || count[r] <= 0) continue;
    s->rank[k] = r;
    s->ptr[k + 1] = s->ptr[k] + count[r];
    k++;
  }
  PM_CALL(PM_ALLOC(s->item, s->ptr[s->n] + 1, "exchange items"));
  PM_CALL(PM_ALLOC(s->buf, (s->ptr[s->n] + 1) * (long)max_bytes,
                   "exchange buffer"));
  for (int k = 0; k < s->n; k++)
    PM_CHECK((s->ptr[k + 1] - s->ptr[k]) * max_bytes <= INT_MAX,
             PM_ERR_INTERNAL,
             "an exchange of %ld items of %d bytes with rank %d is past MPI's "
             "count",
             s->ptr[k + 1] - s->ptr[k], max_bytes, s->rank[k]);
  return PM_SUCCESS;
}

/* Whether every rank got here without a failure (collective): a rank
 * that failed before the pattern's messages is known before they start. */
static pm_err agree(MPI_Comm comm, pm_err e) {
  int bad = e != PM_SUCCESS, any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, comm);
  if (e || !any) return e;
  return PM_ERROR(PM_ERR_INTERNAL, "another rank failed to make its exchange");
}

/* This rank's leaves grouped by their roots' rank (in their order). */
static pm_err group_leaves(pm_halo *h, long n, const long *leaf,
                           const int *rank, const long *index, int me, int size,
                           long *count, long *at, long **remote) {
  for (long k = 0; k < n; k++) {
    PM_CHECK(rank[k] >= 0 && rank[k] < size, PM_ERR_INTERNAL,
             "leaf %ld's root is on rank %d of %d", leaf[k], rank[k], size);
    count[rank[k]]++;
  }
  h->n_self = count[me];
  PM_CALL(PM_ALLOC(h->self_leaf, h->n_self + 1, "exchange items"));
  PM_CALL(PM_ALLOC(h->self_root, h->n_self + 1, "exchange items"));
  PM_CALL(side_make(&h->leaves, count, size, me, h->max_bytes));
  PM_CALL(PM_ALLOC(*remote, h->leaves.ptr[h->leaves.n] + 1, "root indices"));
  for (int k = 0; k < h->leaves.n; k++)
    at[h->leaves.rank[k]] = h->leaves.ptr[k];
  long self = 0;
  for (long k = 0; k < n; k++) {
    if (rank[k] == me) {
      h->self_leaf[self] = leaf[k];
      h->self_root[self++] = index[k];
      continue;
    }
    const long i = at[rank[k]]++;
    h->leaves.item[i] = leaf[k];
    (*remote)[i] = index[k];
  }
  return PM_SUCCESS;
}

/* Each root rank told which of its items this rank's leaves mirror (the
 * counts by an all-to-all, the indices by messages). */
static pm_err tell_roots(pm_halo *h, int me, int size, const long *count,
                         long *in_count, const long *remote) {
  MPI_Alltoall(count, 1, MPI_LONG, in_count, 1, MPI_LONG, h->comm);
  pm_err e = side_make(&h->roots, in_count, size, me, h->max_bytes);
  if (!e)
    e = PM_ALLOC(h->req, h->leaves.n + h->roots.n + 1, "exchange requests");
  PM_CALL(agree(h->comm, e));
  int q = 0;
  for (int k = 0; k < h->roots.n; k++)
    MPI_Irecv(h->roots.item + h->roots.ptr[k],
              (int)(h->roots.ptr[k + 1] - h->roots.ptr[k]), MPI_LONG,
              h->roots.rank[k], 0, h->comm, &h->req[q++]);
  for (int k = 0; k < h->leaves.n; k++)
    MPI_Isend(remote + h->leaves.ptr[k],
              (int)(h->leaves.ptr[k + 1] - h->leaves.ptr[k]), MPI_LONG,
              h->leaves.rank[k], 0, h->comm, &h->req[q++]);
  MPI_Waitall(q, h->req, MPI_STATUSES_IGNORE);
  return PM_SUCCESS;
}

pm_err pm_halo_create(MPI_Comm comm, long n_leaves, const long *leaf,
                      const int *rank, const long *index, int max_bytes,
                      pm_halo **out) {
  pm_err ret = PM_SUCCESS;
  pm_halo *h = NULL;
  long *count = NULL, *in_count = NULL, *at = NULL, *remote = NULL;
  int me = 0, size = 1;
  MPI_Comm dup = MPI_COMM_NULL;
  *out = NULL;
  MPI_Comm_rank(comm, &me);
  MPI_Comm_size(comm, &size);
  MPI_Comm_dup(comm, &dup);
  ret = PM_ALLOC(h, 1, "exchange");
  if (!ret) {
    h->comm = dup;
    dup = MPI_COMM_NULL;
    h->max_bytes = max_bytes;
    ret = PM_ALLOC(count, size, "exchange counts");
  }
  if (!ret) ret = PM_ALLOC(in_count, size, "exchange counts");
  if (!ret) ret = PM_ALLOC(at, size, "exchange counts");
  if (!ret)
    ret = group_leaves(h, n_leaves, leaf, rank, index, me, size, count, at,
                       &remote);
  PM_TRY(agree(h ? h->comm : dup, ret));
  PM_TRY(tell_roots(h, me, size, count, in_count, remote));
  *out = h;
  h = NULL;
done:
  if (dup != MPI_COMM_NULL) MPI_Comm_free(&dup);
  pm_halo_destroy(h);
  free(count);
  free(in_count);
  free(at);
  free(remote);
  return ret;
}

/* ---- the exchanges ---------------------------------------------------------
 */

/* Items of an array are copied and summed in words of 8 bytes where
 * their size allows (doubles and longs), with the common widths (1, 2, 3
 * words) as constants so that each copy is a move; else byte by byte. */
#define WORD 8

static inline void pack_words(char *buf, int stride, const long *item, long n,
                              const char *arr, int w) {
  const long b = (long)w * WORD;
  for (long i = 0; i < n; i++, buf += stride)
    for (int c = 0; c < w; c++)
      memcpy(buf + c * WORD, arr + item[i] * b + c * WORD, WORD);
}

static inline void unpack_words(const char *buf, int stride, const long *item,
                                long n, char *arr, int w) {
  const long b = (long)w * WORD;
  for (long i = 0; i < n; i++, buf += stride)
    for (int c = 0; c < w; c++)
      memcpy(arr + item[i] * b + c * WORD, buf + c * WORD, WORD);
}

/* In the buffer's order: a root's sum does not depend on the messages'. */
static inline void sum_words(const char *buf, int stride, const long *item,
                             long n, char *arr, int w) {
  for (long i = 0; i < n; i++, buf += stride) {
    double *t = (double *)(void *)(arr + item[i] * w * WORD);
    for (int c = 0; c < w; c++) {
      double f;
      memcpy(&f, buf + c * WORD, WORD);
      t[c] += f;
    }
  }
}

/* Items item[0..n) of array arr (b bytes an item) into a buffer of items
 * `stride` bytes apart, at byte `off` of each. */
static void pack_one(char *buf, int stride, int off, const long *item, long n,
                     const char *arr, int b) {
  buf += off;
  if (b % WORD || stride % WORD || off % WORD) {
    for (long i = 0; i < n; i++, buf += stride)
      memcpy(buf, arr + item[i] * b, (size_t)b);
  } else if (b == WORD) {
    pack_words(buf, stride, item, n, arr, 1);
  } else if (b == 2 * WORD) {
    pack_words(buf, stride, item, n, arr, 2);
  } else if (b == 3 * WORD) {
    pack_words(buf, stride, item, n, arr, 3);
  } else {
    pack_words(buf, stride, item, n, arr, b / WORD);
  }
}

/* The buffer's items back into array arr by op (the inverse of pack_one). */
static void unpack_one(const char *buf, int stride, int off, const long *item,
                       long n, char *arr, int b, pm_halo_op op) {
  buf += off;
  const bool words = !(b % WORD || stride % WORD || off % WORD);
  if (op == PM_HALO_REPLACE && !words) {
    for (long i = 0; i < n; i++, buf += stride)
      memcpy(arr + item[i] * b, buf, (size_t)b);
  } else if (op == PM_HALO_REPLACE) {
    if (b == WORD)
      unpack_words(buf, stride, item, n, arr, 1);
    else if (b == 3 * WORD)
      unpack_words(buf, stride, item, n, arr, 3);
    else
      unpack_words(buf, stride, item, n, arr, b / WORD);
  } else if (op == PM_HALO_SUM_DOUBLE) {
    if (b == WORD)
      sum_words(buf, stride, item, n, arr, 1);
    else if (b == 2 * WORD)
      sum_words(buf, stride, item, n, arr, 2);
    else if (b == 3 * WORD)
      sum_words(buf, stride, item, n, arr, 3);
    else
      sum_words(buf, stride, item, n, arr, b / WORD);
  } else if (op == PM_HALO_MAX_BYTE) {
    for (long i = 0; i < n; i++, buf += stride)
      for (int c = 0; c < b; c++) {
        unsigned char *t = (unsigned char *)arr + item[i] * b + c;
        const unsigned char f = (unsigned char)buf[c];
        *t = f > *t ? f : *t;
      }
  } else {
    for (long i = 0; i < n; i++, buf += stride)
      for (int c = 0; c < b / WORD; c++) {
        double f, *t = (double *)(void *)(arr + item[i] * b) + c;
        memcpy(&f, buf + c * WORD, WORD);
        *t = f > *t ? f : *t;
      }
  }
}

/* Items item[0..n) of the arrays to a buffer, side by side (pack) or
 * back (unpack, by op). */
static void pack(char *buf, const long *item, long n, int na, void *const *arr,
                 const int *bytes) {
  int stride = 0;
  for (int a = 0; a < na; a++) stride += bytes[a];
  for (int a = 0, off = 0; a < na; off += bytes[a++])
    pack_one(buf, stride, off, item, n, arr[a], bytes[a]);
}

static void unpack(const char *buf, const long *item, long n, int na,
                   void *const *arr, const int *bytes, pm_halo_op op) {
  int stride = 0;
  for (int a = 0; a < na; a++) stride += bytes[a];
  for (int a = 0, off = 0; a < na; off += bytes[a++])
    unpack_one(buf, stride, off, item, n, arr[a], bytes[a], op);
}

/* Post the receives of `to` and the sends of `from` (packed already). */
static void post(pm_halo *h, const side *to, const side *from, int stride) {
  int q = 0;
  for (int k = 0; k < to->n; k++)
    MPI_Irecv(to->buf + to->ptr[k] * stride,
              (int)((to->ptr[k + 1] - to->ptr[k]) * stride), MPI_BYTE,
              to->rank[k], 0, h->comm, &h->req[q++]);
  for (int k = 0; k < from->n; k++)
    MPI_Isend(from->buf + from->ptr[k] * stride,
              (int)((from->ptr[k + 1] - from->ptr[k]) * stride), MPI_BYTE,
              from->rank[k], 0, h->comm, &h->req[q++]);
}

void pm_halo_bcast(pm_halo *h, int n, void *const *root, void *const *leaf,
                   const int *bytes) {
  int stride = 0;
  for (int a = 0; a < n; a++) stride += bytes[a];
  pack(h->roots.buf, h->roots.item, h->roots.ptr[h->roots.n], n, root, bytes);
  post(h, &h->leaves, &h->roots, stride);
  for (int a = 0; a < n; a++)
    for (long i = 0; i < h->n_self; i++)
      memcpy((char *)leaf[a] + h->self_leaf[i] * bytes[a],
             (const char *)root[a] + h->self_root[i] * bytes[a],
             (size_t)bytes[a]);
  MPI_Waitall(h->leaves.n + h->roots.n, h->req, MPI_STATUSES_IGNORE);
  unpack(h->leaves.buf, h->leaves.item, h->leaves.ptr[h->leaves.n], n, leaf,
         bytes, PM_HALO_REPLACE);
}

void pm_halo_reduce(pm_halo *h, int n, void *const *root, void *const *leaf,
                    const int *bytes, pm_halo_op op) {
  int stride = 0;
  for (int a = 0; a < n; a++) stride += bytes[a];
  pack(h->leaves.buf, h->leaves.item, h->leaves.ptr[h->leaves.n], n, leaf,
       bytes);
  post(h, &h->roots, &h->leaves, stride);
  /* This rank's own leaves first, then the others' by rank (the buffer's
   * order): a root's sum is the same whichever message came first. */
  for (int a = 0; a < n; a++)
    for (long i = 0; i < h->n_self; i++)
      unpack_one((const char *)leaf[a] + h->self_leaf[i] * bytes[a], 0, 0,
                 &h->self_root[i], 1, root[a], bytes[a], op);
  MPI_Waitall(h->leaves.n + h->roots.n, h->req, MPI_STATUSES_IGNORE);
  unpack(h->roots.buf, h->roots.item, h->roots.ptr[h->roots.n], n, root, bytes,
         op);
}
