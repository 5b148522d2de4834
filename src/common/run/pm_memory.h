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

/* The same from /proc/meminfo, /sys/fs/cgroup/memory.{max,current} and
 * the environment variable POINTMECH_MEMORY_LIMIT. */
pm_err pm_memory_query(pm_memory_available *out);

/* Run scenes whose estimate exceeds the available memory anyway (the
 * command line's --force-memory).  Process-wide; off by default. */
void pm_memory_set_force(bool force);

/* Refuse s with PM_ERR_MEMORY when its backend's estimate exceeds the
 * memory available, naming both figures and their sources, unless forced.
 * Succeeds when the backend gives no estimate or no figure is available. */
pm_err pm_memory_check(const pm_scene *s);

/* Print the estimate of s and the memory available in one line of a plan
 * ("estimate     ..."); nothing when the backend gives none. */
void pm_memory_plan(const pm_scene *s, FILE *out);

/* bytes as "12.3 MiB" / "4.5 GiB" into buf. */
const char *pm_memory_format(size_t bytes, char *buf, size_t size);

#endif
