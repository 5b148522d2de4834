/* fpm_scotch: Scotch's serial library (libscotch), opened on first use
 * through a table of its functions (pm_dl.h), and the partition of a graph
 * by it: FPM's points among the ranks (fpm_share.h).  A run that does not
 * partition never maps it. */
#ifndef FPM_SCOTCH_H
#define FPM_SCOTCH_H

#include "pm_error.h"

/* The n vertices of a graph (adjacency ptr[n + 1], adj[ptr[n]], no
 * loops; each vertex weighted by weight[i] >= 1) into `parts` parts of
 * about equal weight (to 1%), the edges cut few: part[i] in [0, parts).
 * Deterministic: Scotch on one thread, its random numbers from a fixed
 * seed, so the same graph gives the same parts on any rank and in any
 * run.  PM_ERR_UNSUPPORTED where libscotch cannot be opened, or is built
 * with integers of another size than its header's; PM_ERR_INTERNAL naming
 * the call that failed. */
pm_err fpm_scotch_part(long n, const long *ptr, const long *adj,
                       const long *weight, int parts, int *part);

#endif
