/* mpm_grip: conditions on regions of particles (grips).  The particles of
 * the volume bodies in a condition's region at t = 0 are held (or, for a
 * motion on a named surface of a gmsh body, the particles that carry its
 * Gauss points: mpm_traction.h): they move as prescribed and impose that
 * motion on the grid nodes they touch, and the condition's reaction is the
 * force the grip exerts on the body. */
#ifndef MPM_GRIP_H
#define MPM_GRIP_H

#include <stdbool.h>

#include "mpm_conditions.h"
#include "mpm_stage.h"
#include "pm_scene.h"

struct mpm_model;

/* The share of a node's mass (of the particles that reach it) from which a
 * grip's particles hold it wholly (why 0.25: mpm_grip.c). */
#define MPM_GRIP_SHARE 0.25

/* Find the held particles of each region condition of model m (scene s):
 * those of its volume bodies whose reference position lies in the region.
 * PM_ERR_SCENE naming the condition's file:line:col when a region holds
 * none (a grip that grips nothing); PM_ERR_MEMORY.  The lists are the
 * conditions' (released by mpm_conditions_destroy). */
pm_err mpm_grips_create(const pm_scene *s, struct mpm_model *m);

/* How many of the conditions bcs[0..n) are grips. */
int mpm_grips_count(const mpm_bc *bcs, int n);

/* Move the velocity of the nodes the held particles touch towards the
 * grip's velocity over the step, prescribed component by component, by
 * the grip's share of each node's mass (all the way from a quarter of it
 * on).  With
 * reactions: add the force this applies to the grid to the conditions'
 * reactions, mark the nodes it holds wholly as set (so the quasi-static
 * residual leaves them out) and return its work over the step (J); else 0. Call
 * after mpm_conditions_apply. */
double mpm_grips_apply(const mpm_ctx *ctx, double *vel, bool reactions);

/* The stage after g2p: the held particles' prescribed components of
 * velocity (the step's mean) and position (the prescribed one at the
 * step's end). */
pm_err mpm_stage_grips(mpm_ctx *ctx, const mpm_stage *self);

#endif
