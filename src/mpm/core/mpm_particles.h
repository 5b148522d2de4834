/* mpm_particles: particles as struct-of-arrays, grouped by material.  A
 * group's kind decides which state arrays it has; each is named, so that
 * output and checkpoints can walk them without knowing the kind. */
#ifndef MPM_PARTICLES_H
#define MPM_PARTICLES_H

#include <stddef.h>

#include "pm_error.h"

#define MPM_MAX_GROUPS 16
#define MPM_MAX_ARRAYS 6

struct mpm_kind;
struct mpm_model;
struct mpm_state;

/* A named per-particle array: ncomp doubles for each of count particles
 * (a group's arrays: indexed (p - begin) ncomp + c). */
typedef struct {
  const char *name; /* a string literal */
  int ncomp;
  long count;
  double *data;
} mpm_array;

/* Particles of one material, contiguous in [begin, end): fixed after
 * setup (part of the model). */
typedef struct {
  int index;        /* place among the model's groups (and the state's) */
  int material;     /* scene material index */
  const char *name; /* the material's name (borrowed from the scene) */
  const struct mpm_kind *kind;
  long begin, end;
  long cap;         /* particles its state arrays have room for (>= end -
                       begin; more across ranks, where groups grow and
                       shrink as particles move between ranks) */
  double c0, c1;    /* artificial viscosity (eq. 32); both 0: none */
  double viscosity; /* dynamic viscosity of the kind's viscous stress, Pa s,
                       for the stable step (0: none) */
  void *params;     /* the kind's constants (owned) */
  /* Layout of the group's state arrays: names and components (data NULL;
   * the state holds the arrays). */
  int n_arrays;
  mpm_array layout[MPM_MAX_ARRAYS];
} mpm_group;

/* A group's state arrays, as laid out by its kind. */
typedef struct {
  int n;
  mpm_array array[MPM_MAX_ARRAYS];
} mpm_group_state;

/* Add a state array of ncomp components named name (a literal) to g's
 * layout; returns its slot. */
int mpm_group_add_array(mpm_group *g, const char *name, int ncomp);

/* The array of gs named name, or NULL when the group has none. */
const mpm_array *mpm_group_state_find(const mpm_group_state *gs,
                                      const char *name);

/* Bytes per particle of the arrays every particle has (x0, x, v, dx, mass,
 * vol0, vol, sigma), and of a group's own. */
size_t mpm_particle_bytes_common(void);
size_t mpm_group_bytes_per_particle(const mpm_group *g);

/* Allocate the state arrays of group g into gs (zeroed).  PM_ERR_MEMORY on
 * failure (what was allocated stays for mpm_group_state_free). */
pm_err mpm_group_state_alloc(const mpm_group *g, mpm_group_state *gs);
/* Release a group's state arrays (and zero gs). */
void mpm_group_state_free(mpm_group_state *gs);

/* Kinetic, strain and internal energy of the particles, J. */
void mpm_energies(const struct mpm_model *m, const struct mpm_state *s,
                  double *kinetic, double *strain, double *internal);

#endif
