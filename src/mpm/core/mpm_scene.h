/* mpm_scene: the "mpm:" section of a scene (its keys, each with its
 * default) and what method mpm refuses in a scene. */
#ifndef MPM_SCENE_H
#define MPM_SCENE_H

#include <stdbool.h>

#include "pm_backend.h"
#include "pm_scene.h"

/* Grid basis functions, update variants and the fluid energy update. */
typedef enum { MPM_BASIS_LINEAR = 0, MPM_BASIS_QUADRATIC } mpm_basis;
typedef enum { MPM_USF = 0, MPM_USL, MPM_MUSL } mpm_update;
/* Implicit MPM (method mpm-implicit): the grid kept with the particles
 * (the implicit paper's modified algorithm) or reset after each load step
 * (the standard one); the Jacobian assembled or applied matrix-free; the
 * convergence test on the residual or on the paper's eq. 9. */
typedef enum { MPM_GRID_KEPT = 0, MPM_GRID_RESET } mpm_grid_mode;
typedef enum { MPM_OP_ASSEMBLED = 0, MPM_OP_MATRIX_FREE } mpm_operator;
typedef enum { MPM_CONV_RESIDUAL = 0, MPM_CONV_PAPER } mpm_convergence;
typedef enum {
  MPM_ENERGY_ITERATIVE = 0, /* steps (1)-(6) of the fluid paper, eqs. 27-31 */
  MPM_ENERGY_NON_ITERATIVE  /* energy from the previous stress (eq. 27) */
} mpm_energy_update;
/* F-bar for solids (mpm_fbar.h): the volume ratio J the stress sees,
 * averaged over each grid cell's particles, over a node's patch, or not. */
typedef enum {
  MPM_FBAR_NONE = 0,
  MPM_FBAR_CELL, /* the particles of the cell (of the same material) */
  MPM_FBAR_PATCH /* J carried to the nodes and back with the shape weights */
} mpm_fbar_mode;

/* Settings of the mpm section (what the scene says; the model copies what it
 * uses into mpm_options). */
typedef struct {
  int shape;   /* mpm_basis: mpm.shape */
  int update;  /* mpm_update: mpm.update */
  double flip; /* mpm.flip: FLIP fraction in [0, 1] (1 FLIP, 0 PIC) */
  double ppc_given[3];
  int n_ppc_given;
  int ppc[3];             /* particles per cell per direction (1 on z in
                             2D), from mpm.particles_per_cell */
  unsigned null_velocity; /* mpm.null_velocity: grid velocity components
                             held at zero (mask) */
  int fbar;               /* mpm_fbar_mode: mpm.fbar */
  double rebalance;       /* mpm.rebalance: the imbalance past which a run
                             across ranks cuts its boxes anew (0: never) */
  struct {
    int energy_update;   /* mpm_energy_update */
    double tolerance;    /* relative change that ends the iteration */
    long max_iterations; /* cap on the iterations per particle-step */
  } fluid;
  struct {
    int grid;          /* mpm_grid_mode */
    int op;            /* mpm_operator */
    int convergence;   /* mpm_convergence */
    double dtol, etol; /* eq. 9: displacement and energy tolerances */
  } implicit;
} mpm_settings;

extern const pm_section mpm_section;

/* The mpm options of a scene (its defaults when the scene has none). */
const mpm_settings *mpm_scene_settings(const pm_scene *s);

/* What MPM cannot honour (tractions, a bound on the energy balance, a cell
 * size that does not divide the box, named surfaces, ...), failing at the
 * key with pm_scene_fail. */
pm_err mpm_check_scene(const pm_scene *s);

/* The grid MPM lays over a scene.  A box that the cell size
 * (discretization.mesh_size) divides is the grid, as the scene gives it,
 * unless a body fills the box (region: domain) and a condition displaces
 * it.  Otherwise (a scene made for FPM, whose mesh_size is an element
 * size) the cell is the largest no larger than mesh_size that divides
 * every edge of domain.box (from 1 to 4 times as many cells along x; the
 * scene's own when it divides), and the grid reaches past the box by the
 * room the body may deform into: beyond a face
 * whose condition holds its normal component, the outward part of that
 * displacement; beyond a free face, the largest displacement of any
 * condition; each a cell more (none beyond a face held in place).  The
 * box's faces stay grid planes, where the conditions act. */
typedef struct {
  double h;            /* cell size, m */
  double lo[3], hi[3]; /* the box the grid covers (ghost layers besides) */
  long room[3][2];     /* cells added below and above the box, per axis */
  bool mapped;         /* chosen here (true) or the scene's own (false) */
} mpm_layout;

/* The largest prescribed displacement of condition b's component comp at
 * full load, over its face's corners and centre: its magnitude (sign 0),
 * or its largest part along sign (the face's outward direction, for its
 * normal component; 0 when it only moves inward). */
double mpm_bc_largest_displacement(const pm_scene *s, int b, int comp,
                                   double sign);

/* The layout of scene s; false when no cell divides the box. */
bool mpm_grid_layout(const pm_scene *s, mpm_layout *lay);

/* What method mpm-implicit cannot honour beyond mpm_check_scene's (which
 * its backend runs first): fluids, membranes, moving bodies, velocity and
 * absorbing conditions, models without a tangent. */
pm_err mpm_implicit_check_scene(const pm_scene *s);

#endif
