/* pm_halo: a neighbour exchange between the ranks on MPI alone: items of
 * one rank's arrays (leaves) that mirror items another rank holds (roots).
 * The pattern is built once from each leaf's root (its rank and index
 * there), with buffers for items of up to a given size; each exchange then
 * only packs, sends to the ranks it names and unpacks (nothing allocated).
 * A broadcast copies roots onto their leaves; a reduce combines leaves
 * into their roots, the leaves of each root taken in one fixed order (this
 * rank's own first, then the other ranks' by rank, each rank's in the
 * order of its leaves), so that sums do not depend on which message came
 * first.  For the ranks layers (src/fpm/ranks, src/mpm/ranks). */
#ifndef PM_HALO_H
#define PM_HALO_H

#include <mpi.h>

#include "pm_error.h"

typedef struct pm_halo pm_halo;

/* How a reduce combines a leaf's item into its root's. */
typedef enum {
  PM_HALO_REPLACE,    /* the leaf's bytes replace the root's */
  PM_HALO_SUM_DOUBLE, /* doubles: root += leaf */
  PM_HALO_MAX_DOUBLE, /* doubles: root = max(root, leaf) */
  PM_HALO_MAX_BYTE    /* unsigned chars: root = max(root, leaf) */
} pm_halo_op;

/* The pattern on the ranks of comm (collective): leaf k of this rank is
 * item leaf[k] of its arrays, and mirrors item index[k] of rank rank[k]'s
 * arrays.  Items are at most max_bytes each (an exchange of several arrays
 * at once packs them side by side: the sum of their sizes). */
pm_err pm_halo_create(MPI_Comm comm, long n_leaves, const long *leaf,
                      const int *rank, const long *index, int max_bytes,
                      pm_halo **out);
void pm_halo_destroy(pm_halo *h);

/* Roots onto leaves, for n arrays at once: array a's items are bytes[a]
 * bytes, the roots' in root[a] and the leaves' in leaf[a] (the same array
 * where a rank's roots and leaves are items of one array); the bytes
 * together at most the pattern's max_bytes.  Collective over the ranks
 * the pattern names. */
void pm_halo_bcast(pm_halo *h, int n, void *const *root, void *const *leaf,
                   const int *bytes);
/* Leaves into roots by op, for n arrays at once (as pm_halo_bcast). */
void pm_halo_reduce(pm_halo *h, int n, void *const *root, void *const *leaf,
                    const int *bytes, pm_halo_op op);

#endif
