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

/* Cauchy stress sigma = P F^T / J of the first n points of st into sig
 * (9 n). */
void fpm_backend_cauchy_stress(long n, const fpm_state *st, double *sig);
/* The end's tension over the first n points of m, their Cauchy stresses
 * sig: the largest hydrostatic tension tr(sigma)/3 and its point, and, in
 * 3-D (spherical: a void from a point; a plane's cylindrical void has no
 * such load), the largest ratio of it to the point's material's cavitation
 * load (pm_cavitation_load, computed for the materials some point inside
 * holds in tension; a material without a finite one, and the points on
 * the body's boundary, where no void opens, are passed over),
 * its point and that load (0, ratio_at -1: none).  The first point in
 * order among equal values. */
typedef struct {
  double tension, ratio, load;
  long tension_at, ratio_at;
} fpm_tension;
void fpm_backend_tension(const fpm_model *m, long n, const double *sig,
                         bool spherical, fpm_tension *t);
/* Across ranks with frames in pieces: this rank's own points of frame
 * `frame` written into the results folder dir (pm_view.piece), with a
 * field "position" (the frame's geometry) before the scene's fields; and
 * rank 0's record of the last frame's pieces (pm_backend.pieces). */
pm_err fpm_backend_piece(void *p, const char *dir, long frame,
                         const pm_step_report *r, long *n, int *n_fields,
                         pm_field *fields);
const pm_view_pieces *fpm_backend_pieces(void *p);

/* fpm_view_sums.c: across ranks without the whole model (sim->whole
 * false).  The setup (collective): the whole model's counts for the
 * summary, of the cells, interfaces and boundary facets given in
 * whole_counts (rank 0's, which meshed) and the others summed over the
 * shares; the positions of the points for results/mesh.h5 on rank 0
 * (sim->mesh_x). */
pm_err fpm_view_sums_setup(fpm_sim *sim, const long whole_counts[3]);
/* The figures of the shares' current state into sim->sums on every rank:
 * the reactions, the conditioning, the errors against the reference
 * field, and with fields the end's field figures (collective). */
pm_err fpm_view_sum(fpm_sim *sim, bool fields);
/* pm_backend.errors: the NRMSE of the last sums (false with the whole
 * model). */
bool fpm_backend_errors(void *p, double nrmse[3], double *vector);

/* fpm_backend_plan.c: pointmech plan (pm_backend.plan; collective across
 * ranks). */
pm_err fpm_backend_plan(void *p, FILE *out);

#endif
