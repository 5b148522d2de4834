/* pm_memory: the memory available (MemAvailable, the cgroup limit, the
 * user's cap) and the refusal of scenes estimated past it. */
#include "pm_memory.h"

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>
#include <sys/resource.h>

#include "pm_backend.h"
#include "pm_json.h"
#include "pm_par.h"
#include "pm_view.h"

static bool force_memory;

void pm_memory_set_force(bool force) { force_memory = force; }

const char *pm_memory_format(size_t bytes, char *buf, size_t size) {
  static const char *const unit[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB"};
  double v = (double)bytes;
  int k = 0;
  while (v >= 1024 && k < 5) {
    v /= 1024;
    k++;
  }
  snprintf(buf, size, k ? "%.1f %s" : "%.0f %s", v, unit[k]);
  return buf;
}

/* MemAvailable of a meminfo file, bytes; false if absent. */
static bool read_meminfo(const char *path, size_t *bytes) {
  FILE *f = path ? fopen(path, "r") : NULL;
  if (!f) return false;
  char line[256];
  bool found = false;
  while (!found && fgets(line, sizeof line, f)) {
    unsigned long long kib;
    if (sscanf(line, "MemAvailable: %llu kB", &kib) == 1) {
      *bytes = (size_t)kib * 1024;
      found = true;
    }
  }
  fclose(f);
  return found;
}

/* A byte count in a cgroup file; false if absent or "max". */
static bool read_bytes_file(const char *path, size_t *bytes) {
  FILE *f = path ? fopen(path, "r") : NULL;
  if (!f) return false;
  unsigned long long v;
  bool ok = fscanf(f, "%llu", &v) == 1;
  fclose(f);
  if (ok) *bytes = (size_t)v;
  return ok;
}

/* "8G", "512M", "1048576" into bytes. */
static pm_err parse_limit(const char *text, size_t *bytes) {
  char *end;
  errno = 0;
  double v = strtod(text, &end);
  double scale = 1;
  switch (toupper((unsigned char)*end)) {
  case 'K': scale = 1024.0; break;
  case 'M': scale = 1024.0 * 1024; break;
  case 'G': scale = 1024.0 * 1024 * 1024; break;
  case 'T': scale = 1024.0 * 1024 * 1024 * 1024; break;
  default: break;
  }
  if (scale > 1) end++;
  if (*end == 'B' || *end == 'b') end++;
  PM_CHECK(end != text && *end == '\0' && errno == 0 && v > 0 &&
               v * scale < (double)SIZE_MAX,
           PM_ERR_ARG,
           "POINTMECH_MEMORY_LIMIT: expected a byte count > 0 with an "
           "optional K, M, G or T suffix, got \"%s\"",
           text);
  *bytes = (size_t)(v * scale);
  return PM_SUCCESS;
}

pm_err pm_memory_available_from(const char *meminfo, const char *cgroup_max,
                                const char *cgroup_current, const char *limit,
                                pm_memory_available *out) {
  return pm_memory_available_shared(meminfo, cgroup_max, cgroup_current, limit,
                                    1, out);
}

pm_err pm_memory_available_shared(const char *meminfo, const char *cgroup_max,
                                  const char *cgroup_current, const char *limit,
                                  int sharing, pm_memory_available *out) {
  char a[32], b[32];
  size_t avail = 0, max = 0, current = 0, cap = 0;
  bool have = read_meminfo(meminfo, &avail);
  out->bytes = SIZE_MAX;
  out->source[0] = '\0';
  if (have) {
    out->bytes = avail;
    snprintf(out->source, sizeof out->source, "MemAvailable in %s", meminfo);
  }
  if (read_bytes_file(cgroup_max, &max)) {
    bool used = read_bytes_file(cgroup_current, &current);
    size_t left = max > current ? max - current : 0;
    if (left < out->bytes) {
      if (have)
        snprintf(out->source, sizeof out->source,
                 "the cgroup limit %s in %s%s, lower than MemAvailable %s",
                 pm_memory_format(max, a, sizeof a), cgroup_max,
                 used ? " less the usage in memory.current" : "",
                 pm_memory_format(avail, b, sizeof b));
      else
        snprintf(out->source, sizeof out->source, "the cgroup limit in %s%s",
                 cgroup_max, used ? " less the usage in memory.current" : "");
      out->bytes = left;
      have = true;
    }
  }
  /* The machine's memory is shared by its ranks; the cap is each one's. */
  if (have && sharing > 1) {
    out->bytes /= (size_t)sharing;
    size_t len = strlen(out->source);
    snprintf(out->source + len, sizeof out->source - len,
             ", shared by the %d ranks on this machine", sharing);
  }
  if (limit && *limit) {
    PM_CALL(parse_limit(limit, &cap));
    if (cap < out->bytes) {
      char was[sizeof out->source];
      snprintf(was, sizeof was, "%s", out->source);
      if (have)
        snprintf(out->source, sizeof out->source,
                 "POINTMECH_MEMORY_LIMIT=%s, lower than the %s of %.150s",
                 limit, pm_memory_format(out->bytes, a, sizeof a), was);
      else
        snprintf(out->source, sizeof out->source, "POINTMECH_MEMORY_LIMIT=%s",
                 limit);
      out->bytes = cap;
      have = true;
    }
  }
  PM_CHECK(have, PM_ERR_IO,
           "no memory figure: %s has no MemAvailable and %s no limit",
           meminfo ? meminfo : "(no meminfo)",
           cgroup_max ? cgroup_max : "(no cgroup)");
  return PM_SUCCESS;
}

pm_err pm_memory_query(pm_memory_available *out) {
  return pm_memory_available_shared(
      "/proc/meminfo", "/sys/fs/cgroup/memory.max",
      "/sys/fs/cgroup/memory.current", getenv("POINTMECH_MEMORY_LIMIT"),
      pm_par_host_ranks(), out);
}

double pm_memory_share_points(double n, int ranks, int dim, double layers) {
  const double own = n / (ranks > 1 ? ranks : 1);
  const double held = own + 2 * layers * pow(own, (dim - 1.0) / dim);
  return held < n ? held : n;
}

size_t pm_memory_rank_estimate(const pm_scene *s, int ranks, bool whole_here,
                               bool meshes, long *points) {
  const pm_backend *b = s->backend;
  const size_t whole = b->estimate_bytes(s, points);
  if (ranks <= 1 || !b->ghost_layers || *points <= 0) return whole;
  const double n = (double)*points;
  const double held =
      pm_memory_share_points(n, ranks, s->dimension, b->ghost_layers(s));
  *points = (long)held;
  /* The geometry the rank that meshes holds whole, the rest by the points
   * held; elsewhere the part received (its geometry and the model built on
   * it) with the share made of it.  A rank that meshes and keeps no whole
   * model cuts its own part too and builds its share on it, its geometry
   * let go only then: both counted. */
  const double geometry =
      b->geometry_bytes ? fmin((double)b->geometry_bytes(s), (double)whole) : 0;
  const double part =
      b->part_layers
          ? pm_memory_share_points(n, ranks, s->dimension, b->part_layers(s))
          : 0;
  const double rest = ((double)whole - geometry) * held / n;
  const double bytes =
      b->setup_whole || whole_here
          ? (double)whole + rest
          : (meshes ? geometry : 0) + (double)whole * part / n + rest;
  return bytes < (double)SIZE_MAX ? (size_t)bytes : SIZE_MAX;
}

pm_err pm_memory_check(const pm_scene *s) {
  if (!s->backend || !s->backend->estimate_bytes) return PM_SUCCESS;
  long points = 0;
  const int ranks = pm_par_size();
  const bool whole = s->backend->setup_whole || pm_view_keeps_whole_for(s);
  size_t need =
      pm_memory_rank_estimate(s, ranks, whole, pm_par_root(), &points);
  pm_memory_available avail;
  pm_err e = pm_memory_query(&avail);
  if (e == PM_ERR_IO) {
    pm_error_clear();
    return PM_SUCCESS;
  }
  PM_CALL(e);
  if (need <= avail.bytes || force_memory) return PM_SUCCESS;
  char a[32], b[32];
  if (ranks > 1)
    return PM_ERROR(
        PM_ERR_MEMORY,
        "%s: on %d ranks rank %d of the %s simulation needs an estimated "
        "%s (%zu bytes: %ld points held, %s) but %s (%zu bytes) is "
        "available to a rank (%s); nothing was allocated (--force-memory "
        "runs it anyway)",
        s->path, ranks, pm_par_rank(), s->method,
        pm_memory_format(need, a, sizeof a), need, points,
        whole ? "its share and the whole model, which it builds" : "its share",
        pm_memory_format(avail.bytes, b, sizeof b), avail.bytes, avail.source);
  return PM_ERROR(PM_ERR_MEMORY,
                  "%s: the %s simulation needs an estimated %s (%zu bytes, "
                  "%ld points) but %s (%zu bytes) is available (%s); nothing "
                  "was allocated (--force-memory runs it anyway)",
                  s->path, s->method, pm_memory_format(need, a, sizeof a), need,
                  points, pm_memory_format(avail.bytes, b, sizeof b),
                  avail.bytes, avail.source);
}

void pm_memory_plan(const pm_scene *s, FILE *out) {
  if (!s->backend || !s->backend->estimate_bytes) return;
  long points = 0;
  size_t need = s->backend->estimate_bytes(s, &points);
  const int ranks = pm_par_active() ? pm_par_size() : pm_par_plan_ranks();
  char a[32], b[32];
  pm_memory_available avail;
  if (pm_memory_query(&avail) != PM_SUCCESS) {
    pm_error_clear();
    snprintf(avail.source, sizeof avail.source, "no figure");
    avail.bytes = 0;
  }
  fprintf(out,
          "memory est.  %s before setup, from the scene alone (%ld points; "
          "with the mesh or grid); %s available (%s)\n",
          pm_memory_format(need, a, sizeof a), points,
          pm_memory_format(avail.bytes, b, sizeof b), avail.source);
  if (ranks > 1 && s->backend->ghost_layers) {
    long held = 0;
    long meshed = 0;
    const size_t share = pm_memory_rank_estimate(s, ranks, false, false, &held);
    const size_t root = pm_memory_rank_estimate(s, ranks, false, true, &meshed);
    need = pm_memory_rank_estimate(s, ranks, true, true, &held);
    if (s->backend->setup_whole)
      fprintf(out,
              "memory/rank  %s before setup on each of %d ranks at most "
              "(%ld points held: the whole model its setup builds, and its "
              "share with its ghosts)\n",
              pm_memory_format(need, a, sizeof a), ranks, held);
    else if (!pm_view_whole_needed(s) && !s->backend->geometry_bytes)
      fprintf(out,
              "memory/rank  %s before setup on each of %d ranks at most (its "
              "share with its ghosts, %ld points; no rank keeps the whole "
              "model: frames and checkpoints in pieces)\n",
              pm_memory_format(share, a, sizeof a), ranks, held);
    else if (!pm_view_whole_needed(s))
      fprintf(out,
              "memory/rank  %s before setup on each of %d ranks at most (its "
              "share with its ghosts, %ld points, and the part it is built "
              "from); %s on rank 0, which meshes (the whole mesh and its "
              "cells besides; no rank keeps the whole model: frames in "
              "pieces, no checkpoints)\n",
              pm_memory_format(share, a, sizeof a), ranks, held,
              pm_memory_format(root, b, sizeof b));
    else
      fprintf(out,
              "memory/rank  %s before setup on each of %d ranks at most (its "
              "share with its ghosts, %ld points%s); %s on a rank that keeps "
              "the whole model (rank 0 where the frames are gathered)\n",
              pm_memory_format(share, a, sizeof a), ranks, held,
              s->backend->part_layers ? ", and the part it is built from" : "",
              pm_memory_format(need, b, sizeof b));
  }
}

/* Each rank's peak resident memory, bytes, on rank 0 (pm_memory_gather_peaks).
 */
static double *peaks;
static int n_peaks;

double pm_memory_peak_rss(void) {
  struct rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return NAN;
  return 1024.0 * (double)u.ru_maxrss; /* kB on Linux */
}

pm_err pm_memory_gather_peaks(void) {
  const int ranks = pm_par_size();
  pm_err e = PM_SUCCESS;
  if (pm_par_root() && n_peaks != ranks) {
    free(peaks);
    peaks = NULL;
    n_peaks = 0;
    e = PM_ALLOC(peaks, ranks, "peak memory per rank");
    if (!e) n_peaks = ranks;
  }
  PM_CALL(pm_par_agree(e));
  pm_par_gather_double(pm_memory_peak_rss(), peaks); /* NULL off rank 0 */
  return PM_SUCCESS;
}

pm_err pm_memory_summary(struct pm_json *j) {
  if (n_peaks < 1) return PM_SUCCESS;
  double most = 0;
  PM_CALL(pm_json_begin_object(j, "memory"));
  PM_CALL(pm_json_begin_array(j, "peak_rss_per_rank"));
  for (int r = 0; r < n_peaks; r++) {
    PM_CALL(pm_json_number(j, NULL, peaks[r]));
    most = peaks[r] > most ? peaks[r] : most;
  }
  PM_CALL(pm_json_end_array(j));
  PM_CALL(pm_json_number(j, "peak_rss_max", most));
  return pm_json_end_object(j);
}
