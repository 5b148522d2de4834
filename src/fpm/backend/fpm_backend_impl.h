/* fpm_backend_impl: the entries of FPM's backend table (fpm_backend.c)
 * that live in the files of their subject: the run, what the run driver
 * reads, and the plan.  Each takes the fpm_sim as its void *. */
#ifndef FPM_BACKEND_IMPL_H
#define FPM_BACKEND_IMPL_H

#include <stdbool.h>
#include <stdio.h>

#include "fpm_backend.h"
#include "pm_backend.h"
#include "pm_files.h"

/* fpm_backend_run.c: the time loop or static solve (pm_backend.run), and
 * the run's view (pm_view; across ranks when sim has a share). */
pm_err fpm_backend_run(void *p, const pm_observer *obs);
void fpm_backend_view_init(fpm_sim *sim);
/* A static solve resumed across ranks: the share's load stepping and
 * displacements (of every point it holds) from the whole run's ws, which
 * every rank read from the checkpoint, with the whole run's prescribed
 * dofs fixed (3 n) and nodal, room for 3 n. */
void fpm_backend_scatter_static(fpm_sim *sim, const unsigned char *fixed,
                                long n, const fpm_static_state *ws,
                                double *nodal);

/* fpm_backend_figures.c: the points, fields, figures, history columns and
 * summary of the run (pm_backend's entries of those names). */
void fpm_backend_points(void *p, pm_points *pts);
const double *fpm_backend_displacement(void *p);
int fpm_backend_fields(void *p, unsigned want, pm_field *out, int max);
void fpm_backend_figures(void *p, pm_figures *f, bool with_fields);
int fpm_backend_history_names(void *p, const char **names, int max);
void fpm_backend_history_values(void *p, double *v);
pm_err fpm_backend_summary(void *p, pm_json *j);

/* fpm_backend_plan.c: pointmech plan (pm_backend.plan; collective across
 * ranks). */
pm_err fpm_backend_plan(void *p, FILE *out);

#endif
