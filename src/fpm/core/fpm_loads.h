/* fpm_loads: the loads of an FPM model beyond the nominal tractions: body
 * forces (gravity and body_force, per unit mass, times body_curve),
 * concentrated forces on points (boundary.N.force), and the follower
 * pressure's traction -p cof(F) N on its facets with its linearisation
 * (the load stiffness, not symmetric). */
#ifndef FPM_LOADS_H
#define FPM_LOADS_H

#include "fpm_model.h"

/* The body forces m_i (g + b(X_i, 0)) per point and the rows of the
 * concentrated forces (the point nearest at, or the points of the facets
 * a condition selects, sharing its force equally).  Called by
 * fpm_build_boundary. */
pm_err fpm_build_loads(fpm_model *m, const pm_scene *s);

/* st->fload at time t: the body forces on the model's own points and the
 * concentrated forces, times their curves (serial: expressions); adds
 * their |f|^2 to st->fext_sq (and fext_norm).  Returns -1, or the first
 * entry whose value is not finite: 3 i + a of a body force, 3 (n + k) + a
 * of concentrated force row k. */
long fpm_update_loads(const fpm_model *m, fpm_state *st, double t);

/* PM_ERR_UNSTABLE for entry k of fpm_update_loads that is not finite,
 * naming the point, the key and its expression (step < 0: none). */
pm_err fpm_load_failure(const fpm_model *m, long k, long step, double t);

/* The loads of st (tractions, pressures, body and point forces) times
 * lambda: a static solve's proportional loading. */
void fpm_loads_scale(const fpm_model *m, fpm_state *st, double lambda);

/* The nominal traction of pressure p on a face of unit normal N at a
 * point of displacement gradient H: t = -p cof(I + H) N. */
void fpm_pressure_traction(const double *H, double p, const double *N,
                           double t[3]);

/* Its change along dH about H: dt = -p dcof(I + H)[dH] N. */
void fpm_pressure_dtraction(const double *H, const double *dH, double p,
                            const double *N, double dt[3]);

/* The work of the body and point forces over an increment du times scale
 * (trapezoidal rule with the forces at the last call; the model's own
 * points), and those forces kept for the next. */
double fpm_loads_work(const fpm_model *m, fpm_state *st, const double *du,
                      double scale);

/* Keep the current body and point forces as the last step's. */
void fpm_loads_start(const fpm_model *m, fpm_state *st);

#endif
