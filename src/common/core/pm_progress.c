/* pm_progress: wall clock, stage timers and the terminal progress line.
 * Nothing here allocates; every function is cheap enough for hot loops. */
#include "pm_progress.h"

#include <math.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

double pm_wtime(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double pm_cputime(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- Stage timers ------------------------------------------------------ */

void pm_timers_init(pm_timers *t) { memset(t, 0, sizeof *t); }

int pm_timers_add(pm_timers *t, const char *name) {
  if (!t || !name) return -1;
  for (int i = 0; i < t->n; i++)
    if (strcmp(t->stage[i].name, name) == 0) return i;
  if (t->n >= PM_TIMERS_MAX) return -1;
  pm_stage *s = &t->stage[t->n];
  s->name = name;
  s->seconds = 0.0;
  s->calls = 0;
  s->started = -1.0;
  return t->n++;
}

void pm_timers_start(pm_timers *t, int id) {
  if (id < 0 || id >= t->n) return;
  t->stage[id].started = pm_wtime();
}

void pm_timers_stop(pm_timers *t, int id) {
  if (id < 0 || id >= t->n || t->stage[id].started < 0.0) return;
  pm_stage *s = &t->stage[id];
  s->seconds += pm_wtime() - s->started;
  s->calls++;
  s->started = -1.0;
}

double pm_timers_seconds(const pm_timers *t, int id) {
  if (!t || id < 0 || id >= t->n) return 0.0;
  return t->stage[id].seconds;
}

void pm_timers_print(const pm_timers *t, FILE *out, double total_wall) {
  int w = 5; /* width of the stage column: at least "stage" / "total" */
  for (int i = 0; i < t->n; i++) {
    int len = (int)strlen(t->stage[i].name);
    if (len > w) w = len;
  }
  fprintf(out, "%-*s  %11s  %6s  %10s  %12s\n", w, "stage", "seconds", "%",
          "calls", "ms/call");
  for (int i = 0; i < t->n; i++) {
    const pm_stage *s = &t->stage[i];
    fprintf(out, "%-*s  %11.3f  ", w, s->name, s->seconds);
    if (total_wall > 0.0)
      fprintf(out, "%6.1f  ", 100.0 * s->seconds / total_wall);
    else
      fprintf(out, "%6s  ", "");
    fprintf(out, "%10ld  ", s->calls);
    if (s->calls > 0)
      fprintf(out, "%12.4g\n", 1e3 * s->seconds / (double)s->calls);
    else
      fprintf(out, "%12s\n", "-");
  }
  if (total_wall > 0.0)
    fprintf(out, "%-*s  %11.3f  %6.1f\n", w, "total", total_wall, 100.0);
}

/* ---- Progress line ----------------------------------------------------- */

void pm_progress_init(pm_progress *p, FILE *stream, const char *label) {
  p->stream = stream;
  p->label = label ? label : "";
  p->tty = stream && isatty(fileno(stream));
  p->start = pm_wtime();
  p->last = -1.0;
  p->width = 0;
}

/* "m:ss" or "h:mm:ss" of s seconds into buf. */
static void format_duration(char *buf, size_t size, double s) {
  if (!isfinite(s) || s < 0.0 || s > 359999.0) {
    snprintf(buf, size, "--:--");
    return;
  }
  long t = (long)(s + 0.5);
  if (t >= 3600)
    snprintf(buf, size, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
  else
    snprintf(buf, size, "%ld:%02ld", t / 60, t % 60);
}

void pm_progress_update(pm_progress *p, double fraction_done,
                        const char *status) {
  char eta[32];
  double now, f = fraction_done;
  int len;
  if (!p->tty || !p->stream) return;
  if (!(f >= 0.0)) f = 0.0; /* also NaN */
  if (f > 1.0) f = 1.0;
  now = pm_wtime();
  if (p->last >= 0.0 && now - p->last < 0.25 && f < 1.0) return;
  p->last = now;
  if (f > 0.0)
    format_duration(eta, sizeof eta, (now - p->start) * (1.0 - f) / f);
  else
    snprintf(eta, sizeof eta, "--:--");
  len = fprintf(p->stream, "\r[%s]  %5.1f%%  ETA %s  %s", p->label, 100.0 * f,
                eta, status ? status : "");
  if (len < 0) return;
  len -= 1; /* the carriage return takes no column */
  if (len < p->width) fprintf(p->stream, "%*s", p->width - len, "");
  p->width = len;
  fflush(p->stream);
}

void pm_progress_finish(pm_progress *p) {
  if (!p->tty || !p->stream || p->last < 0.0) return;
  putc('\n', p->stream);
  fflush(p->stream);
  p->last = -1.0;
  p->width = 0;
}
