/* pm_memory: the memory a run may take, and the check that refuses a scene
 * whose estimate (the backend's, from the scene alone) exceeds it before
 * anything large is allocated. */
#ifndef PM_MEMORY_H
#define PM_MEMORY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "pm_error.h"
#include "pm_scene.h"

/* Memory available to this process, and where the figure comes from. */
typedef struct {
  size_t bytes;
  char source[256]; /* "MemAvailable in /proc/meminfo", or the cgroup limit
                       or POINTMECH_MEMORY_LIMIT with the figure it beat */
} pm_memory_available;

/* The smallest of: MemAvailable in `meminfo`, the cgroup v2 limit in
 * `cgroup_max` less the usage in `cgroup_current` (files that are absent,
 * or a limit of "max", count as no limit), and `limit` (a byte count with
 * an optional K, M, G or T suffix, binary; NULL or "" for none).  Fails
 * with PM_ERR_IO when no figure could be read, and PM_ERR_ARG naming a
 * malformed limit. */
pm_err pm_memory_available_from(const char *meminfo, const char *cgroup_max,
                                const char *cgroup_current, const char *limit,
                                pm_memory_available *out);

/* The same, the machine's figure (MemAvailable, the cgroup's) shared by
 * `sharing` processes (the ranks on one machine): each one's part of it,
 * then `limit`, which is each process's. */
pm_err pm_memory_available_shared(const char *meminfo, const char *cgroup_max,
                                  const char *cgroup_current, const char *limit,
                                  int sharing, pm_memory_available *out);

/* The same from /proc/meminfo, /sys/fs/cgroup/memory.{max,current} and
 * the environment variable POINTMECH_MEMORY_LIMIT, for one rank: the
 * machine's figure shared by the ranks on it. */
pm_err pm_memory_query(pm_memory_available *out);

/* Run scenes whose estimate exceeds the available memory anyway (the
 * command line's --force-memory).  Process-wide; off by default. */
void pm_memory_set_force(bool force);

/* The points a rank holds of n points shared by `ranks` ranks in
 * dimension dim: its n / ranks and `layers` layers of ghosts over two
 * faces of a compact part (n / ranks)^((dim - 1) / dim) points each (the
 * plan's shares of F3 at 4036 points: 1.4 faces at 2 ranks), at most n. */
double pm_memory_share_points(double n, int ranks, int dim, double layers);

/* The backend's estimate for s on `ranks` ranks, from the scene alone:
 * the bytes of the rank that holds the most: its share of the whole run's
 * estimate, less the geometry (the backend's geometry_bytes), by the
 * points it holds (pm_memory_share_points with the backend's ghost
 * layers), and
 *  - the whole where the backend's setup builds it on every rank or
 *    whole_here (this rank keeps it);
 *  - else where the rank meshes (meshes: rank 0), the geometry whole;
 *  - else the whole run's estimate by the points of the part it receives
 *    and builds its share from (the backend's part_layers; none without).
 * On one rank, or for a backend without ghost layers, the whole run's.
 * *points: the points that rank holds. */
size_t pm_memory_rank_estimate(const pm_scene *s, int ranks, bool whole_here,
                               bool meshes, long *points);

/* Refuse s with PM_ERR_MEMORY when its backend's estimate exceeds the
 * memory available, naming both figures and their sources, unless forced:
 * across ranks, each rank's estimate (with the whole model where it
 * builds it: pm_view_keeps_whole) against the memory available to a rank
 * (pm_memory_query), agreed by the caller.
 * Succeeds when the backend gives no estimate or no figure is available. */
pm_err pm_memory_check(const pm_scene *s);

/* Print the estimate of s and the memory available in one line of a plan
 * ("estimate     ..."); nothing when the backend gives none. */
void pm_memory_plan(const pm_scene *s, FILE *out);

/* This process's peak resident memory so far (getrusage), bytes. */
double pm_memory_peak_rss(void);
/* Every rank's peak resident memory so far onto rank 0, for
 * pm_memory_summary (collective; PM_ERR_MEMORY agreed by every rank). */
pm_err pm_memory_gather_peaks(void);
/* On rank 0: "memory": {"peak_rss_per_rank": [bytes of each rank, in rank
 * order], "peak_rss_max"} of the last pm_memory_gather_peaks; nothing
 * before one. */
struct pm_json;
pm_err pm_memory_summary(struct pm_json *j);

/* bytes as "12.3 MiB" / "4.5 GiB" into buf. */
const char *pm_memory_format(size_t bytes, char *buf, size_t size);

#endif
