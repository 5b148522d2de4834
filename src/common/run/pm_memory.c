/* pm_memory: the memory available (MemAvailable, the cgroup limit, the
 * user's cap) and the refusal of scenes estimated past it. */
#include "pm_memory.h"

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pm_backend.h"

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
  return pm_memory_available_from("/proc/meminfo", "/sys/fs/cgroup/memory.max",
                                  "/sys/fs/cgroup/memory.current",
                                  getenv("POINTMECH_MEMORY_LIMIT"), out);
}

pm_err pm_memory_check(const pm_scene *s) {
  if (!s->backend || !s->backend->estimate_bytes) return PM_SUCCESS;
  long points = 0;
  size_t need = s->backend->estimate_bytes(s, &points);
  pm_memory_available avail;
  pm_err e = pm_memory_query(&avail);
  if (e == PM_ERR_IO) {
    pm_error_clear();
    return PM_SUCCESS;
  }
  PM_CALL(e);
  if (need <= avail.bytes || force_memory) return PM_SUCCESS;
  char a[32], b[32];
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
}
