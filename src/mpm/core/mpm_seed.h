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

/* A share of the particles (a rank's): those at positions x where
 * keep(ctx, x) holds, each numbered as on one process. */
typedef struct mpm_seed_share {
  bool (*keep)(void *ctx, const double x[3]);
  void *ctx;
  long (*room)(long n); /* room for n particles (a model's, a group's) */
  /* set by mpm_seed_for_share: the particles on one process and their groups'
   * and bodies' ranges there (bbegin, bend: per body, the caller frees) */
  long n_full;
  long gbegin[MPM_MAX_GROUPS], gend[MPM_MAX_GROUPS];
  long *bbegin, *bend;
} mpm_seed_share;

/* mpm_seed keeping share sh's particles only (sh NULL: all), with their
 * one-process indices in m->gid, in one process's order; a group whose
 * kind finishes on the whole group or shares its links across ranks (a
 * membrane: mpm_kind.finish, ranks_share) is kept whole, for the caller
 * to narrow (mpm_model_share).  m's arrays have room for sh->room(n), each
 * group's for sh->room(its count).  Nothing but the seeding's memory grows
 * with the particles sh leaves out. */
pm_err mpm_seed_for_share(const pm_scene *s, mpm_model *m, mpm_seed_share *sh,
                          mpm_state **state);

/* Every seed position of scene s on m's grid (m->opt and m->grid set), as
 * one process seeds them, to sh->keep (whose answer is not used): a count
 * without storing a particle (the cells' counts of a decomposition).
 * mpm_seed's failures. */
pm_err mpm_seed_visit(const pm_scene *s, const mpm_model *m,
                      mpm_seed_share *sh);

#endif
