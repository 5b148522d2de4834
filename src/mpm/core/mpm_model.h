/* mpm_model: the explicit MPM discretization of a scene, everything that is
 * fixed once it is set up: options, grid geometry, particle constants,
 * groups and their kinds, boundary-condition descriptors and the step's
 * pipeline.  What changes is in mpm_state (see mpm_state.h). */
#ifndef MPM_MODEL_H
#define MPM_MODEL_H

#include <stdbool.h>

#include "mpm_conditions.h"
#include "mpm_grid.h"
#include "mpm_motion.h"
#include "mpm_particles.h"
#include "mpm_pipeline.h"
#include "mpm_scene.h"
#include "pm_scene.h"

struct mpm_state;
struct mpm_exchange;

/* What the model takes from the scene, copied at creation so that nothing
 * after it reads the scene's mpm, time or stability sections. */
typedef struct mpm_options {
  mpm_basis shape;
  mpm_update update;
  double flip;            /* FLIP fraction of the particle velocity update */
  int ppc[3];             /* particles per cell and direction */
  unsigned null_velocity; /* grid velocity components held at zero (mask) */
  mpm_fbar_mode fbar;     /* F-bar of the solids' stress */
  mpm_energy_update energy_update; /* kinds with an energy equation */
  double energy_tolerance;
  int max_iterations;
  bool has_gravity;
  double gravity[3]; /* m/s^2 */
  double t_end;      /* s */
  double t_load;     /* when every ramped condition is at full value, s */
  double dt_fixed;   /* time.dt, or 0: the stable step each step */
  double dt_safety;
  long max_steps; /* 0: no limit */
  pm_qs_method qs;
  double qs_tolerance;
  double qs_damping;   /* 1/s, fixed damping */
  double min_jacobian; /* stop when some J falls to or below it */
} mpm_options;

typedef struct mpm_model {
  mpm_options opt;
  int dim;
  double box_min[3], box_max[3];
  mpm_grid grid;
  mpm_layout layout; /* the box the grid covers and its cell (mpm_scene.h) */
  /* particles: count and constants, 3 or 1 per particle */
  long n;
  double *x0;   /* reference position */
  double *mass; /* mass, kg */
  double *vol0; /* initial volume */
  /* Across ranks: the exchange with the other ranks (mpm_exchange.h, filled
   * in by the ranks layer; owned), the particles this rank holds (their
   * arrays have room for cap) and each one's index on one process (gid,
   * increasing).  On one process xc and gid are NULL and cap is n. */
  struct mpm_exchange *xc;
  long *gid;
  long cap;
  mpm_group group[MPM_MAX_GROUPS];
  int n_groups;
  unsigned kinds; /* the groups' kinds' flags, or-ed (MPM_KIND_*) */
  /* bodies: the particles of scene body b are [body_begin[b], body_end[b])
   * (within its material's group) */
  int n_bodies;
  long *body_begin, *body_end;
  /* membranes: triangles of 3 particle indices, those of group g in
   * [tri_begin[g], tri_end[g]) (empty for other kinds) */
  long n_tris;
  long *tri;
  long tri_begin[MPM_MAX_GROUPS], tri_end[MPM_MAX_GROUPS];
  long *body_tri_begin, *body_tri_end; /* per scene body (membranes) */
  /* per scene body (membranes): what links its points (MPM_LINKS_*) and
   * how its normals are found (pm_normals_method) */
  unsigned char *body_links, *body_normals;
  /* bodies that move as prescribed */
  int n_moving;
  mpm_motion *moving;
  /* boundary conditions */
  mpm_bc *bcs;
  int n_bcs;
  bool has_absorbing;
  mpm_pipeline pipeline;
} mpm_model;

/* Particles the model's and its states' arrays have room for. */
static inline long mpm_model_room(const mpm_model *m) {
  return m->cap > m->n ? m->cap : m->n;
}

/* What links a membrane body's points (mpm_model.body_links). */
enum {
  MPM_LINKS_NONE = 0,  /* a point cloud (or not a membrane) */
  MPM_LINKS_TRIANGLES, /* a triangulated surface (3D) */
  MPM_LINKS_CHAIN,     /* a curve, open: neighbours in the list (2D) */
  MPM_LINKS_LOOP       /* a closed curve */
};

/* Copy what the model needs from the scene into o (the one place that reads
 * the scene's mpm section). */
void mpm_options_from_scene(const pm_scene *s, mpm_options *o);

/* Build the grid, seed the particles, set up the groups' kinds and the
 * conditions, assemble the pipeline, and return the model with its initial
 * state (t = 0, dt the first step's).  The scene must outlive the model (it
 * borrows names and expressions).  Bad scenes fail with PM_ERR_SCENE naming
 * the scene file position; a scene of another method with PM_ERR_ARG.  On
 * failure *model and *state are NULL. */
pm_err mpm_model_create(const pm_scene *s, mpm_model **model,
                        struct mpm_state **state);
/* The model's frame: its options, grid and conditions, without particles
 * (what a share's seeding and a decomposition start from).  The failures of
 * mpm_model_create before the seeding. */
pm_err mpm_model_frame(const pm_scene *s, mpm_model **out);

/* The initial state's start: the model's pipeline, the damping, and the
 * stable step of the initial state (dt_stable). */
pm_err mpm_model_start(mpm_model *m, struct mpm_state *st);
/* The first step's size: time.dt, or the stable step dt_stable (of the
 * whole run: across ranks the least of the shares'); PM_ERR_SCENE when
 * there is neither. */
pm_err mpm_model_first_dt(const pm_scene *s, const mpm_model *m,
                          struct mpm_state *st);

struct mpm_seed_share;
/* A share of the model (a rank's) made from the scene alone, never the
 * whole: the particles sh keeps (mpm_seed_share), numbered and ordered as
 * on one process, a membrane's narrowed to them once it is finished whole
 * (its links kept whole by its kind's ranks_share), on grid block `block`
 * (as mpm_model_subset's) with the conditions on the block and the
 * pipeline, and its initial state, whose dt_stable is the share's own
 * (the caller takes the least over the shares, then mpm_model_first_dt).
 * The body ranges and the exchange are the caller's, as for
 * mpm_model_subset. */
pm_err mpm_model_share(const pm_scene *s, const mpm_grid *block,
                       struct mpm_seed_share *sh, mpm_model **model,
                       struct mpm_state **state);
/* The share's groups kept whole by the seeding narrowed to sh's particles
 * in place, and the share moved onto grid block `block` with its
 * conditions (mpm_model_share's step after the seeding). */
pm_err mpm_model_narrow(const pm_scene *s, const mpm_grid *block,
                        struct mpm_seed_share *sh, mpm_model *m,
                        struct mpm_state *st);

/* Release a model (NULL accepted); its states and workspaces first. */
void mpm_model_destroy(mpm_model *m);

/* The model of whole model m's particles sel[0..n) (one-process indices,
 * increasing), on grid block `grid` (a copy of m's grid's geometry shifted
 * to a block of it), for scene s: their constants, with room for room(n)
 * particles and each group room(its count); every group set up by its
 * kind; the bodies, the conditions on the block, the moving bodies and the
 * pipeline.  The body ranges (which follow the particles) and the exchange
 * are the caller's to set (a rank's share, src/mpm/ranks).  PM_ERR_MEMORY,
 * or a kind's or the conditions' failure; *out NULL then. */
pm_err mpm_model_subset(const pm_scene *s, const mpm_model *m,
                        const mpm_grid *grid, const long *sel, long n,
                        long (*room)(long), mpm_model **out);

/* Triangles [t0, t1) of m with their corners counted from particle
 * `first` (a group's or a body's surface as gm_trisurf wants it): a new
 * array of 3 (t1 - t0) indices the caller frees.  PM_ERR_MEMORY. */
pm_err mpm_triangles_local(const mpm_model *m, long t0, long t1, long first,
                           long **out);

/* Bytes of the model's arrays (particle constants, condition columns). */
size_t mpm_model_bytes(const mpm_model *m);

#endif
