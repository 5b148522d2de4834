/* The ranks layers' neighbour exchange (pm_halo) alone, under mpirun on 3
 * ranks: each rank holds items of its own (roots) and leaves that mirror
 * items of every rank, its own included, several leaves of a rank on one
 * root, drawn at random (a fixed seed per rank).  Every rank learns the
 * whole pattern and every leaf's values (an all-gather), computes what
 * each of its roots must hold after each operation, and checks, bit for
 * bit, after three rounds on the same pattern:
 *  - a broadcast of three arrays at once (3 doubles, 1 byte, 3 longs an
 *    item: words and bytes in one buffer) puts each root's values on its
 *    leaves;
 *  - a reduce by sum adds a root's leaves in the fixed order (the root's
 *    own rank first, then the others by rank, each rank's in its leaves'
 *    order), with values of many magnitudes, so that another order would
 *    give other bits;
 *  - a reduce by maximum (doubles, and bytes) and by replacement (the
 *    last leaf in that order).
 * Prints a line per check; exit 0 when all hold. */
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_halo.h"

enum { OWN_BASE = 40, LEAF_BASE = 90 };

static int failures;

static void check(int rank, const char *what, int ok) {
  int all = ok, every = 0;
  MPI_Allreduce(&all, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (rank == 0) printf("%s %s\n", every ? "ok" : "FAIL", what);
  failures += !every;
}

/* A fixed stream per rank. */
static uint64_t draw(uint64_t *s) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return *s >> 33;
}

/* A value of a magnitude from 1e-8 to 1e8, either sign: sums of them
 * depend on their order. */
static double value(uint64_t *s) {
  const double m = (double)(draw(s) % 1000000) / 1e6 + 0.5;
  const double e = (double)((int)(draw(s) % 17) - 8);
  return (draw(s) & 1 ? -1 : 1) * m * pow(10.0, e);
}

typedef struct {
  int size;
  long *n_own, *n_leaf, *first; /* per rank; first: its leaves' offset */
  int *rank;                    /* every leaf's root: rank, index */
  long *index;
  double *leafval; /* every leaf's value of the sum */
} pattern;

/* Leaf k of rank q in the whole pattern's order. */
static long at(const pattern *p, int q, long k) { return p->first[q] + k; }

/* What root i of `me` holds after the sum: its value, then its leaves in
 * the fixed order. */
static double expected_sum(const pattern *p, int me, long i, double root) {
  for (int pass = 0; pass < 2; pass++)
    for (int q = 0; q < p->size; q++) {
      if ((pass == 0) != (q == me)) continue;
      for (long k = 0; k < p->n_leaf[q]; k++) {
        const long g = at(p, q, k);
        if (p->rank[g] == me && p->index[g] == i) root += p->leafval[g];
      }
    }
  return root;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int me = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  pattern p = {.size = size};
  p.n_own = calloc(size, sizeof *p.n_own);
  p.n_leaf = calloc(size, sizeof *p.n_leaf);
  p.first = calloc(size + 1, sizeof *p.first);
  long own = OWN_BASE + 7 * me, nl = LEAF_BASE + 11 * me;
  MPI_Allgather(&own, 1, MPI_LONG, p.n_own, 1, MPI_LONG, MPI_COMM_WORLD);
  MPI_Allgather(&nl, 1, MPI_LONG, p.n_leaf, 1, MPI_LONG, MPI_COMM_WORLD);
  for (int q = 0; q < size; q++) p.first[q + 1] = p.first[q] + p.n_leaf[q];
  const long total = p.first[size], n = own + nl;
  p.rank = calloc(total, sizeof *p.rank);
  p.index = calloc(total, sizeof *p.index);
  p.leafval = calloc(total, sizeof *p.leafval);
  /* This rank's leaves: items own..n of its arrays. */
  uint64_t s = 12345 + 977 * (uint64_t)me;
  long *leaf = calloc(nl, sizeof *leaf), *index = calloc(nl, sizeof *index);
  int *rank = calloc(nl, sizeof *rank);
  double *mine = calloc(nl, sizeof *mine);
  for (long k = 0; k < nl; k++) {
    leaf[k] = own + k;
    rank[k] = (int)(draw(&s) % (uint64_t)size);
    index[k] = (long)(draw(&s) % (uint64_t)p.n_own[rank[k]]);
    mine[k] = value(&s);
  }
  int *counts = calloc(size, sizeof *counts),
      *displs = calloc(size, sizeof *displs);
  for (int q = 0; q < size; q++) {
    counts[q] = (int)p.n_leaf[q];
    displs[q] = (int)p.first[q];
  }
  MPI_Allgatherv(rank, (int)nl, MPI_INT, p.rank, counts, displs, MPI_INT,
                 MPI_COMM_WORLD);
  MPI_Allgatherv(index, (int)nl, MPI_LONG, p.index, counts, displs, MPI_LONG,
                 MPI_COMM_WORLD);
  MPI_Allgatherv(mine, (int)nl, MPI_DOUBLE, p.leafval, counts, displs,
                 MPI_DOUBLE, MPI_COMM_WORLD);
  pm_halo *h = NULL;
  /* The widest exchange: 3 doubles, a byte and 3 longs. */
  const int most = 3 * (int)sizeof(double) + 1 + 3 * (int)sizeof(long);
  check(me, "pattern made",
        pm_halo_create(MPI_COMM_WORLD, nl, leaf, rank, index, most, &h) ==
            PM_SUCCESS);
  double *vec = calloc(3 * n, sizeof *vec), *sum = calloc(n, sizeof *sum);
  double *root0 = calloc(n, sizeof *root0);
  unsigned char *flag = calloc(n, 1);
  long *ids = calloc(3 * n, sizeof *ids);
  for (int round = 0; round < 3; round++) {
    /* Broadcast: each root's values are known from its rank and index. */
    for (long i = 0; i < n; i++)
      for (int c = 0; c < 3; c++) {
        const int mine_root = i < own;
        vec[3 * i + c] = mine_root ? me * 1e3 + i + 0.25 * c + round : NAN;
        ids[3 * i + c] = mine_root ? 1000000L * me + 10 * i + c + round : -1;
      }
    for (long i = 0; i < n; i++)
      flag[i] = i < own ? (unsigned char)(me * 50 + i + round) : 0;
    void *arr[3] = {vec, flag, ids};
    const int bytes[3] = {3 * sizeof(double), 1, 3 * sizeof(long)};
    pm_halo_bcast(h, 3, arr, arr, bytes);
    int ok = 1;
    for (long k = 0; k < nl; k++) {
      const int q = rank[k];
      const long i = index[k], l = leaf[k];
      for (int c = 0; c < 3; c++) {
        ok = ok && vec[3 * l + c] == q * 1e3 + i + 0.25 * c + round;
        ok = ok && ids[3 * l + c] == 1000000L * q + 10 * i + c + round;
      }
      ok = ok && flag[l] == (unsigned char)(q * 50 + i + round);
    }
    char what[96];
    snprintf(what, sizeof what, "round %d: broadcast of 3 arrays", round);
    check(me, what, ok);
    /* Sum, in the fixed order. */
    uint64_t t = 99 + (uint64_t)me + 7 * (uint64_t)round;
    for (long i = 0; i < own; i++) root0[i] = sum[i] = value(&t);
    for (long k = 0; k < nl; k++) sum[leaf[k]] = p.leafval[at(&p, me, k)];
    void *sarr[1] = {sum};
    const int sb[1] = {sizeof(double)};
    pm_halo_reduce(h, 1, sarr, sarr, sb, PM_HALO_SUM_DOUBLE);
    ok = 1;
    for (long i = 0; i < own; i++)
      ok = ok && sum[i] == expected_sum(&p, me, i, root0[i]);
    snprintf(what, sizeof what, "round %d: sums in rank order, bit for bit",
             round);
    check(me, what, ok);
    /* Maximum of doubles and of bytes, and replacement by the last leaf. */
    for (long i = 0; i < own; i++) {
      sum[i] = -1e300;
      flag[i] = 0;
    }
    for (long k = 0; k < nl; k++) {
      sum[leaf[k]] = p.leafval[at(&p, me, k)];
      flag[leaf[k]] = (unsigned char)(draw(&t) % 256);
    }
    unsigned char *sent = calloc(n, 1);
    memcpy(sent, flag, n);
    void *marr[1] = {sum}, *farr[1] = {flag};
    const int fb[1] = {1};
    pm_halo_reduce(h, 1, marr, marr, sb, PM_HALO_MAX_DOUBLE);
    pm_halo_reduce(h, 1, farr, farr, fb, PM_HALO_MAX_BYTE);
    /* Every rank's flags, to know what each root must hold. */
    unsigned char *allflag = calloc(total, 1);
    unsigned char *myflag = calloc(nl + 1, 1);
    for (long k = 0; k < nl; k++) myflag[k] = sent[leaf[k]];
    MPI_Allgatherv(myflag, (int)nl, MPI_UNSIGNED_CHAR, allflag, counts, displs,
                   MPI_UNSIGNED_CHAR, MPI_COMM_WORLD);
    int okmax = 1;
    for (long i = 0; i < own; i++) {
      double m = -1e300;
      unsigned char f = 0;
      for (long g = 0; g < total; g++)
        if (p.rank[g] == me && p.index[g] == i) {
          m = p.leafval[g] > m ? p.leafval[g] : m;
          f = allflag[g] > f ? allflag[g] : f;
        }
      okmax = okmax && sum[i] == m && flag[i] == f;
    }
    snprintf(what, sizeof what, "round %d: maxima of doubles and bytes", round);
    check(me, what, okmax);
    free(sent);
    free(allflag);
    free(myflag);
  }
  /* Replacement on items of one double: the last leaf in the fixed order
   * (own rank's, then by rank) wins. */
  for (long i = 0; i < own; i++) sum[i] = NAN;
  for (long k = 0; k < nl; k++) sum[leaf[k]] = p.leafval[at(&p, me, k)];
  void *rarr[1] = {sum};
  const int rb[1] = {sizeof(double)};
  pm_halo_reduce(h, 1, rarr, rarr, rb, PM_HALO_REPLACE);
  int ok = 1;
  for (long i = 0; i < own; i++) {
    double last = NAN;
    for (int pass = 0; pass < 2; pass++)
      for (int q = 0; q < size; q++) {
        if ((pass == 0) != (q == me)) continue;
        for (long k = 0; k < p.n_leaf[q]; k++) {
          const long g = at(&p, q, k);
          if (p.rank[g] == me && p.index[g] == i) last = p.leafval[g];
        }
      }
    ok = ok && (isnan(last) ? isnan(sum[i]) : sum[i] == last);
  }
  check(me, "replacement by the last leaf in the fixed order", ok);
  pm_halo_destroy(h);
  free(vec);
  free(sum);
  free(root0);
  free(flag);
  free(ids);
  free(leaf);
  free(index);
  free(rank);
  free(mine);
  free(counts);
  free(displs);
  free(p.n_own);
  free(p.n_leaf);
  free(p.first);
  free(p.rank);
  free(p.index);
  free(p.leafval);
  MPI_Finalize();
  return failures ? 1 : 0;
}
