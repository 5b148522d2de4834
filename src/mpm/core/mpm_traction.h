/* mpm_traction: surface tractions on MPM bodies: nominal tractions on a
 * face, carried by the particles next to it with their share of its area
 * and spread to the grid through the shape functions. */
#ifndef MPM_TRACTION_H
#define MPM_TRACTION_H

#include "mpm_conditions.h"
#include "mpm_stage.h"
#include "pm_scene.h"

struct mpm_model;

/* Find the particles that carry each traction condition of model m (scene
 * s): those of the volume bodies within one particle spacing of the face
 * (a box body's own face, else the face of domain.box), each with its
 * area, its volume over its spacing normal to the face.  PM_ERR_SCENE
 * naming the condition's file:line:col when no particle lies there;
 * PM_ERR_MEMORY.  The lists are the conditions' (mpm_conditions_destroy
 * releases them). */
pm_err mpm_tractions_create(const pm_scene *s, struct mpm_model *m);

/* How many of the conditions bcs[0..n) are tractions. */
int mpm_tractions_count(const mpm_bc *bcs, int n);

/* The stage before the grid update: the tractions at time t (nominal, at
 * full load times the ramp) as nodal forces, f_I += N_I(x_p) t A_p. */
pm_err mpm_stage_tractions(mpm_ctx *ctx, const mpm_stage *self);

/* After the update: each traction's total force (its reaction column) and
 * its work over the step with the nodes' mean velocity. */
pm_err mpm_book_tractions(mpm_ctx *ctx, const mpm_stage *self);

/* The implicit MPM's external force: f -= lam t(X, t_load) A at the face
 * points over the particles at base positions xb (3 per particle), on grid
 * g (3 per node), lam the load factor: dead loads, no tangent. */
void mpm_tractions_nodal(const struct mpm_model *m, const mpm_grid *g,
                         const double *xb, double lam, double *f);

#endif
