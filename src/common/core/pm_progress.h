/* pm_progress: monotonic wall clock, per-stage timers with a summary table,
 * and a self-overwriting progress line shown only on a terminal. */
#ifndef PM_PROGRESS_H
#define PM_PROGRESS_H

#include <stdbool.h>
#include <stdio.h>

/* Seconds from an arbitrary origin on CLOCK_MONOTONIC (never jumps). */
double pm_wtime(void);
/* CPU seconds of the process (all its threads) from its start. */
double pm_cputime(void);

/* ---- Stage timers ------------------------------------------------------ */

#define PM_TIMERS_MAX 32

typedef struct {
  const char *name; /* borrowed: must outlive the timers (string literal) */
  double seconds;   /* accumulated time between start and stop */
  long calls;       /* completed start/stop pairs */
  double started;   /* pm_wtime() of the running start, < 0 when stopped */
} pm_stage;

/* Zero-initialise (pm_timers t = {0};) or call pm_timers_init. */
typedef struct {
  pm_stage stage[PM_TIMERS_MAX];
  int n;
} pm_timers;

/* Forget every stage. */
void pm_timers_init(pm_timers *t);

/* Register a stage named name (borrowed, not copied) and return its id;
 * a name registered before returns the same id.  Returns -1 when all
 * PM_TIMERS_MAX slots are used; start/stop ignore id -1, so a missing
 * timer costs nothing but its line in the table. */
int pm_timers_add(pm_timers *t, const char *name);

/* Start / stop stage id: one clock read each, no allocation.  stop adds the
 * time since the matching start and counts a call; a stop without a start
 * and out-of-range ids are ignored. */
void pm_timers_start(pm_timers *t, int id);
void pm_timers_stop(pm_timers *t, int id);

/* Seconds accumulated by stage id (0 for an invalid id). */
double pm_timers_seconds(const pm_timers *t, int id);

/* Print a table to out: stage, seconds, percent of total_wall (blank when
 * total_wall <= 0), calls, milliseconds per call; then the total line.
 * Stages may nest, so percentages need not add to 100. */
void pm_timers_print(const pm_timers *t, FILE *out, double total_wall);

/* ---- Progress line ----------------------------------------------------- */

typedef struct {
  FILE *stream;
  const char *label; /* borrowed */
  bool tty;          /* set by init from isatty(); a caller may override */
  double start;      /* pm_wtime() at init */
  double last;       /* pm_wtime() of the last print, < 0 before any */
  int width;         /* length of the last line, to blank leftovers */
} pm_progress;

/* Prepare a progress line on stream labelled label (both borrowed).  The
 * line is shown only when stream is a terminal; otherwise every call is a
 * no-op. */
void pm_progress_init(pm_progress *p, FILE *stream, const char *label);

/* Redraw "\r[label]  42.0%  ETA 0:13  status" at most 4 times a second (the
 * first call and fraction >= 1 always draw).  fraction_done in [0, 1] is
 * clamped; status may be NULL.  ETA = elapsed (1 - f) / f, "--:--" while
 * f is 0. */
void pm_progress_update(pm_progress *p, double fraction_done,
                        const char *status);

/* End the line (newline) on a terminal if anything was drawn. */
void pm_progress_finish(pm_progress *p);

#endif
