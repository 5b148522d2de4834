/* mpm_contact: rigid plates and spheres (boundary: plate / sphere) in the
 * grid's contact of the explicit MPM: a node the body's particles bring to
 * the rigid body loses its velocity towards it, booked as its force. */
#ifndef MPM_CONTACT_H
#define MPM_CONTACT_H

#include <stdbool.h>

#include "mpm_conditions.h"
#include "mpm_stage.h"
#include "pm_scene.h"

struct mpm_model;

/* The most rigid bodies a scene of method mpm may have. */
#define MPM_CONTACT_MAX 7

/* How many of the conditions bcs[0..n) are rigid bodies. */
int mpm_contacts_count(const mpm_bc *bcs, int n);

/* Check the rigid bodies of model m (scene s, particles seeded): one that
 * starts inside a body (a particle's centre past its surface at t = 0), a
 * glued one that no particle reaches at t = 0 (a grip that grips nothing), or
 * more than MPM_CONTACT_MAX of them, fail with PM_ERR_SCENE at the key
 * (file:line:col), naming the particle.
 * Nothing to do without rigid bodies. */
pm_err mpm_contacts_check(const pm_scene *s, const struct mpm_model *m);

/* The rigid bodies' contact on the nodal velocities vel (3 per node) over
 * the step from the state's t to t + dt, after the other conditions.  The
 * nodes in contact with a body are those some particle reaches it at (its
 * centre within half its size vol^(1/dim) of the surface at t + dt) that
 * lie at or past the surface, and, for a plate normal to an axis, the
 * nodes within h/2 inside it: their velocity is the line through the
 * body's velocity at the surface and the first node of the column at
 * least h/2 inside (the extension a face condition makes), so that a
 * linear field stays linear through the plate.  Frictionless: the normal
 * component; sticking: all of them; either only where that pushes the
 * body away (no pull).  Glued (a grip on a face): every node with mass
 * at or past the surface or within h/2 inside it, all components,
 * pulling too, the line taken only to an anchor with a quarter of the
 * node's mass or more (else V at and past the surface, free inside).  With
 * reactions (the grid update) the nodes in contact are found; without, MUSL's
 * remap keeps the update's.  With reactions: add the force this applies to the
 * conditions' reactions, mark the dofs it sets (owner) and return its
 * work over the step (J); else 0.  Parallel over nodes; allocates
 * nothing. */
double mpm_contacts_apply(const mpm_ctx *ctx, double *vel, bool reactions);

#endif
