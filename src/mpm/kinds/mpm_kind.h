/* mpm_kind: particle kinds (solid, fluid, membrane, rigid: each a file or
 * a folder under kinds/, and a row of the table in mpm_kind.c).  A kind brings
 * its constants, its per-particle state arrays, its constitutive stage and
 * what the rest of the step needs to know of it (wave speeds, energies,
 * output fields), so that nothing outside a kind's file branches on what a
 * particle is.  Per-particle work is a loop inside the kind. */
#ifndef MPM_KIND_H
#define MPM_KIND_H

#include <stdbool.h>
#include <stddef.h>

#include "mpm_particles.h"
#include "mpm_stage.h"
#include "pm_material.h"
#include "pm_scene.h"

struct mpm_options;

/* What a kind has (mpm_kind.flags). */
enum {
  MPM_KIND_STRAIN_ENERGY = 1u,   /* stores elastic strain energy */
  MPM_KIND_INTERNAL_ENERGY = 2u, /* carries a specific internal energy;
                                    outputs density, pressure and energy */
  MPM_KIND_ITERATES = 4u,        /* its update iterates: it reports the
                                    iterations of a step */
  MPM_KIND_MEMBRANE = 8u,        /* points of a triangulated surface: normal,
                                    damage and failed are output fields */
  MPM_KIND_RIGID = 16u           /* moves as prescribed: no stress */
};

/* What a body makes of its material's particles. */
typedef enum {
  MPM_BODY_VOLUME = 0, /* seeded in cells: the material's kind */
  MPM_BODY_MEMBRANE,   /* the vertices of a surface */
  MPM_BODY_RIGID       /* moves as prescribed */
} mpm_body_role;

typedef struct mpm_kind {
  const char *name;       /* "solid", "fluid" */
  const char *stage_name; /* its constitutive stage's ("stress: solid") */
  unsigned flags;         /* MPM_KIND_* */

  /* Whether the kind takes the particles of scene material sm whose bodies
   * have the role given (mpm_kind_of asks the kinds in the table's
   * order). */
  bool (*takes)(const pm_scene_material *sm, mpm_body_role role);
  /* Doubles per particle of the kind's own arrays and workspace, as setup
   * lays them out, for mpm_estimate_bytes: of material sm, with F-bar
   * (fbar) or without. */
  double (*estimate_doubles)(const pm_scene_material *sm, bool fbar);

  /* Fill group g (material, c0, c1 and the particle range already set) from
   * its scene material: the kind's constants into g->params (owned by g,
   * released with free), g->viscosity, and the layout of its state arrays.
   * PM_ERR_MEMORY on failure. */
  pm_err (*setup)(mpm_group *g, const pm_scene_material *sm,
                  const struct mpm_options *opt);
  /* Optional: release what setup put in g->params besides the struct. */
  void (*release)(mpm_group *g);

  /* Initial state of particle k (from the group's start) of body b (its
   * density, kg/m^3, pressure, Pa, and what its material's points take
   * from it): its entries of the group's arrays and its Cauchy stress
   * sigma (9, zero on entry). */
  void (*seed)(const mpm_group *g, mpm_group_state *gs, long k,
               const pm_scene_body *b, double sigma[9]);

  /* Optional: once every particle is placed, what needs the whole group
   * (a membrane's incidence and frames).  PM_ERR_SCENE / PM_ERR_MEMORY. */
  pm_err (*finish)(const struct mpm_model *m, mpm_group *g,
                   struct mpm_state *s);
  /* Optional: doubles of step workspace the group needs
   * (mpm_work.scratch[g->index]). */
  long (*scratch)(const struct mpm_model *m, const mpm_group *g);

  /* Optional: a step workspace that is more than doubles (a membrane's
   * per-thread least-squares fits): created with the run's workspace into
   * *out, released by work_free; *bytes its size.  PM_ERR_MEMORY. */
  pm_err (*work_create)(const struct mpm_model *m, const mpm_group *g,
                        void **out, size_t *bytes);
  void (*work_free)(void *w);

  /* Optional, across ranks (mpm_exchange.h), for a group whose points read
   * other points of the group each step (a membrane point's normal reads
   * its neighbours' positions).  ranks_share: at setup, a rank's group g
   * takes from the whole model's group what its links are made from (a
   * surface's triangles in one-process order).  ranks_link: whenever
   * points moved between ranks, the one-process indices of the points of
   * other ranks that the rank's points of g read (the ghosts: sorted,
   * without repeats) into *want (room *room, grown as needed), *n of them,
   * and g's links among its points and those anew (ghost j is point
   * (g->end - g->begin) + j; mpm_xc_ghost_x gives their positions).
   * PM_ERR_MEMORY. */
  pm_err (*ranks_share)(const mpm_group *whole, mpm_group *g);
  pm_err (*ranks_link)(const struct mpm_model *m, mpm_group *g, long **want,
                       long *room, long *n);
  /* Optional, across ranks: how many cells around a rank's cells hold
   * points of group g that its points read each step (a membrane's normals
   * fitted per cell read the points of the blocks of cells around it), 0
   * when none; mpm_xc_nearby gives those of other ranks. */
  int (*ranks_reach)(const mpm_group *g);

  /* Optional: a stage run just before the constitutive stage (membranes:
   * their normals), named pre_stage_name, described by describe_pre. */
  mpm_stage_fn pre_stress;
  const char *pre_stage_name;
  void (*describe_pre)(const struct mpm_model *m, const mpm_group *g, char *buf,
                       size_t size);

  /* The constitutive stage: velocity gradient to stress, volume and the
   * kind's state, for the particles of group self->group (NULL: none, for
   * particles that move as prescribed). */
  mpm_stage_fn stress;
  /* Optional: whether the constitutive stage of group g moves its
   * particles when its stage's mode has MPM_MOVE_FUSED (mpm_transfer.h). */
  bool (*moves)(const mpm_group *g);

  /* The constitutive stage in a line for the plan (without the group's
   * name), into buf. */
  void (*describe)(const mpm_group *g, char *buf, size_t size);

  /* Dilatational wave speed cp[p] and, when cs is not NULL, shear wave
   * speed cs[p] (m/s) of the group's particles p in [begin, end). */
  void (*wave_speeds)(const struct mpm_model *m, const struct mpm_state *s,
                      const mpm_group *g, double *cp, double *cs);

  /* Add the group's strain energy (sum V0 W) to *strain and internal energy
   * (sum m e) to *internal, J. */
  void (*energies)(const struct mpm_model *m, const struct mpm_state *s,
                   const mpm_group *g, double *strain, double *internal);

  /* Output fields of the group's particles p in [begin, end): strain energy
   * density W (J/m^3 of reference volume), pressure (Pa) and specific
   * internal energy (J/kg), each an array indexed by p. */
  void (*fields)(const struct mpm_model *m, const struct mpm_state *s,
                 const mpm_group *g, double *sed, double *pressure,
                 double *energy);

  /* Optional (MPM_KIND_MEMBRANE): unit normal (3 per particle), damage
   * (1 - the secant factor) and failed (0 or 1) of the group's particles,
   * indexed by p. */
  void (*surface_fields)(const struct mpm_model *m, const struct mpm_state *s,
                         const mpm_group *g, double *normal, double *damage,
                         double *failed);
} mpm_kind;

extern const mpm_kind mpm_kind_solid;
extern const mpm_kind mpm_kind_fluid;
extern const mpm_kind mpm_kind_membrane;
extern const mpm_kind mpm_kind_rigid;

/* The role of body b in scene s. */
mpm_body_role mpm_body_role_of(const pm_scene_body *b);

/* The kind of the particles of a scene material whose bodies have the role
 * given (mpm_check_scene sees that they share it): the first kind of the
 * table (mpm_kind.c) that takes them; NULL when none does (every role has
 * a kind today). */
const mpm_kind *mpm_kind_of(const pm_scene_material *sm, mpm_body_role role);

/* Membrane law, for tests: the largest principal strain of the in-plane
 * strain e = (e11, e22, e12), and one damage step of eqs. 38-41 at e_max
 * (omega and failed updated), returning the secant factor. */
double mpm_membrane_max_strain(const double e[3]);
double mpm_membrane_damage(const pm_scene_damage *dm, double e_max,
                           double *omega, double *failed);
/* Carry a membrane frame f = (e1, e2, n) over a step: turn about n by phi,
 * then by S of eqs. 9-22 from n to the unit normal n1. */
void mpm_membrane_carry_frame(double f[9], double phi, const double n1[3]);

/* A solid group's model and arrays, for solvers other than the explicit
 * step (implicit MPM): the material, F (9 per particle from the group's
 * start) and the model's per-particle state (mstride per particle, NULL
 * when none). */
typedef struct {
  const pm_material *mat;
  double *F;
  const double *mstate;
  long mstride;
} mpm_solid_view;

/* Fill v for group g of state s; false when g is not of the solid kind. */
bool mpm_solid_access(const mpm_group *g, struct mpm_state *s,
                      mpm_solid_view *v);

/* D and W, the symmetric and skew parts of L (all row-major 3x3). */
static inline void mpm_sym_skew(const double L[9], double D[9], double W[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      D[3 * i + j] = 0.5 * (L[3 * i + j] + L[3 * j + i]);
      W[3 * i + j] = 0.5 * (L[3 * i + j] - L[3 * j + i]);
    }
}

#endif
