/* mpm_seed: particles from the scene's bodies: n per direction regularly in
 * each cell, inside the body's shape (n^d per voxel for an image body),
 * grouped by material. */
#ifndef MPM_SEED_H
#define MPM_SEED_H

#include "mpm_model.h"
#include "mpm_state.h"

/* Seed the particles of scene s on m's grid (m->opt and m->grid set): the
 * groups (one per material with particles, in material order, each set up
 * by its kind), the particle constants of m, and a new state *state with
 * the particles' initial positions, velocities, volumes, stresses and
 * kind arrays.  Fails with PM_ERR_SCENE naming the scene position (a shape
 * outside the grid, an unreadable mesh or image, an image crop outside the
 * image, an image label range matching no voxel, no particle, too many
 * materials);
 * on failure *state is NULL and m keeps what it got for
 * mpm_model_destroy. */
pm_err mpm_seed(const pm_scene *s, mpm_model *m, mpm_state **state);

#endif
