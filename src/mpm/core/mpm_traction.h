/* mpm_traction: surface loads on MPM bodies: nominal tractions and
 * follower pressures on a face of domain.box, or on a named surface (3-D)
 * or edge (2-D) of a gmsh body, carried by the particles next to it with
 * their share of its area and spread to the grid through the shape
 * functions. */
#ifndef MPM_TRACTION_H
#define MPM_TRACTION_H

#include "mpm_conditions.h"
#include "mpm_pressure.h"
#include "mpm_stage.h"
#include "pm_scene.h"

struct mpm_model;

/* Find the particles that carry each traction condition of model m (scene
 * s).  On a face: those of the volume bodies within one particle spacing
 * of it (a box body's own face, else the face of domain.box), each with
 * its area, its volume over its spacing normal to the face.  On a named
 * surface or edge: the Gauss points of its boundary facets in the gmsh
 * body's mesh (2 a segment, 3 a triangle), each with its share of its
 * facet's area, carried by the body's particle nearest it.  PM_ERR_SCENE
 * naming the condition's file:line:col when no particle lies at a face or
 * no gmsh body has the name; PM_ERR_MESH from gmsh; PM_ERR_MEMORY.  The lists
 * are the conditions' (mpm_conditions_destroy releases them). */
pm_err mpm_tractions_create(const pm_scene *s, struct mpm_model *m);

/* How many of the conditions bcs[0..n) are tractions. */
int mpm_tractions_count(const mpm_bc *bcs, int n);

/* The stage before the grid update: the tractions at time t (nominal, at
 * full load times the ramp) as nodal forces, f_I += N_I(x_p) t A_p, and
 * the pressures, f_I -= N_I(x_p) p cof(F) N A_p, F the carrier's. */
pm_err mpm_stage_tractions(mpm_ctx *ctx, const mpm_stage *self);

/* After the update: each traction's total force (its reaction column) and
 * its work over the step with the nodes' mean velocity. */
pm_err mpm_book_tractions(mpm_ctx *ctx, const mpm_stage *self);

/* The implicit MPM's external force: f -= lam t(X, t_load) A at the
 * surface points over the particles at base positions xb (3 per
 * particle), on grid g (3 per node), lam the load factor: dead (nominal)
 * tractions, and pressures on the surface deformed by the nodal
 * displacements u from xb (NULL: none), F = I + sum_I u_I grad N_I at
 * each point (their tangent: mpm_pressures_tangent). */
void mpm_tractions_nodal(const struct mpm_model *m, const mpm_grid *g,
                         const double *xb, const double *u, double lam,
                         double *f);

/* The tangent of the pressures' part of mpm_tractions_nodal (load
 * factor lam), entry by entry (mpm_pressure.h). */
void mpm_pressures_tangent(const struct mpm_model *m, const mpm_grid *g,
                           const double *xb, const double *u, double lam,
                           mpm_pressure_entry add, void *ctx);

/* The points of the loaded surfaces over the particles at x (3 per
 * particle) into at (6 per point: its place, and the pressure's force
 * there at the last step's end, 0 here; NULL: count only); their count. */
long mpm_tractions_points(const struct mpm_model *m, const double *x,
                          double *at);

/* The implicit MPM's work of the tractions over a load step from lam_old
 * to lam_new (trapezoid rule, the supports' rule): each point's force at
 * the mean load factor times its move from at (where the last step left
 * it; updated) to xs + N(xs) u, xs its place over the particles at base
 * positions xb, u the nodal displacements from them (3 per node of g);
 * a pressure's force the mean of its values at the step's ends. */
double mpm_tractions_work(const struct mpm_model *m, const mpm_grid *g,
                          const double *xb, const double *u, double *at,
                          double lam_old, double lam_new);

#endif
