/* mpm_model: the MPM discretization of a scene: a Cartesian background
 * grid, particles as struct-of-arrays grouped by material (optional state
 * only where a material needs it), grid boundary conditions, and the step
 * as an array of stages built once from what the scene contains. */
#ifndef MPM_MODEL_H
#define MPM_MODEL_H

#include <stdbool.h>
#include <stddef.h>

#include "mpm_shape.h"
#include "pm_error.h"
#include "pm_fluid.h"
#include "pm_material.h"
#include "pm_progress.h"
#include "pm_scene.h"

/* Particles of one material, contiguous in [begin, end).  Optional state is
 * indexed p - begin and is NULL when the group does not need it. */
typedef struct {
  int material; /* scene material index */
  const char *name;
  bool fluid;
  pm_material solid; /* solids */
  pm_fluid fluid_props;
  double c0, c1; /* artificial viscosity (eq. 32); both 0: none */
  long begin, end;
  double *F;        /* 9: deformation gradient (solids) */
  double *rho;      /* density (fluids) */
  double *energy;   /* specific internal energy (fluids) */
  double *pressure; /* equation-of-state pressure, without q (fluids) */
  double *q;        /* artificial viscosity pressure (c0 or c1 > 0) */
} mpm_group;

/* Node accumulator record in the per-thread buffers. */
enum { MPM_ACC_M = 0, MPM_ACC_P = 1, MPM_ACC_F = 4, MPM_ACC_BASE = 7 };

typedef struct {
  int dim;
  pm_shape shape;
  int width; /* nodes per axis in a stencil */
  int ghost; /* node layers outside the domain box */
  double h, inv_h;
  double origin[3]; /* node (0, 0, 0) */
  long nn[3];       /* nodes per axis (1 on z in 2-D) */
  long stride[3];   /* index step per axis */
  long n_nodes;
  double lo[3], hi[3]; /* where a particle's stencil lies inside the grid */
  double node_volume;  /* h^dim */
  double *mass;        /* per node */
  double *mom;         /* 3 per node: momentum */
  double *force;       /* 3 per node: internal + external force */
  double *vel0;        /* 3 per node: velocity before the update */
  double *vel_new;     /* 3 per node: updated (Lagrangian) velocity */
  double *vel;         /* 3 per node: the velocity of USF (before the
                          update) or MUSL (remapped), with the boundary
                          conditions; NULL for USL */
  const double *vel_stress; /* the velocity the stress update reads */
  /* Per-thread accumulators [threads][n_nodes][acc_stride]. */
  double *acc;
  int acc_stride; /* 7, or 9 with the impedance sums */
  int threads;
  /* optional */
  double *impedance;  /* 2 per node: sum w m c_p, sum w m c_s (absorbing) */
  double *force_prev; /* 3 per node: internal force of the previous step
                         (dynamic relaxation) */
  short *owner;       /* 3 per node: the condition that set the dof this step,
                         -(b + 1) prescribed, b + 1 reflected, 0 free (with
                         boundary conditions) */
  double *fold;       /* 3 per node: forces of the conditions' dependent dofs
                         moved onto the dofs they follow (their anchors) */
  double *fold_out;   /* 3 per node: the force a dependent dof moved out */
} mpm_grid;

/* A boundary condition on a face, as grid columns normal to the face. */
typedef struct {
  int bc; /* scene index */
  int axis;
  double outward; /* -1 on a min face, +1 on a max face */
  double plane;   /* face coordinate */
  long n_cols;
  long *col; /* node index of each column on the face plane */
  unsigned disp_mask, vel_mask;
  bool absorbing;
  bool constant[3]; /* expression uses none of x, y, z */
  double reaction[3];
} mpm_bc;

typedef struct mpm_sim mpm_sim;
typedef void (*mpm_stage_fn)(mpm_sim *sim, int arg);
typedef struct {
  mpm_stage_fn fn;
  int arg;
  int timer;
  const char *name; /* short name: the timer's */
  char detail[160]; /* what it does, for the plan */
} mpm_stage;

#define MPM_MAX_GROUPS 16
/* Fixed stages (at most 11) and one stress stage per group. */
#define MPM_MAX_STAGES (12 + MPM_MAX_GROUPS)

/* A numerical failure found inside a stage. */
typedef struct {
  bool failed;
  long particle;
  char cause[192];
} mpm_failure;

struct mpm_sim {
  const pm_scene *scene; /* borrowed */
  int dim;
  mpm_grid grid;
  /* particles */
  long n;
  double *x0;    /* 3: reference position */
  double *x;     /* 3: position */
  double *v;     /* 3: velocity */
  double *dx;    /* 3: position increment of the step */
  double *mass;  /* per particle */
  double *vol0;  /* initial volume */
  double *vol;   /* current volume */
  double *sigma; /* 9: Cauchy stress */
  mpm_group group[MPM_MAX_GROUPS];
  int n_groups;
  bool has_fluid;
  /* boundary conditions */
  mpm_bc *bcs;
  int n_bcs;
  bool has_absorbing;
  /* the step */
  mpm_stage stage[MPM_MAX_STAGES];
  int n_stages;
  pm_timers timers;
  /* time */
  double t, dt, dt_stable;
  long step;
  double dt_fixed;     /* time.dt, or 0: the stable step each step */
  double max_div;      /* largest |tr D| of this step's stress update, 1/s */
  double max_div_prev; /* the same for the previous step (for dt) */
  /* quasi-static */
  double damping; /* current rate, 1/s */
  double residual;
  /* energy bookkeeping, J (per unit thickness in 2-D) */
  double external_work, dissipated;
  /* fluid energy iteration: per step, max iterations and particles that hit
   * the cap; over the run, totals */
  int iter_max_step;
  long iter_capped_step, iter_capped_total;
  int iter_max_total;
  mpm_failure fail;
};

/* Build the grid, seed the particles, allocate the state the scene needs,
 * and assemble the step.  Bad scenes fail with PM_ERR_SCENE naming the
 * scene file position. */
pm_err mpm_model_create(const pm_scene *s, mpm_sim **out);
void mpm_model_destroy(mpm_sim *sim);

/* Bytes of particle state, in total and per particle of each group (the
 * common arrays plus the group's own). */
size_t mpm_particle_bytes_common(void);
size_t mpm_group_bytes_per_particle(const mpm_group *g);
size_t mpm_grid_bytes(const mpm_grid *g);

/* Stable step: h over the largest of (wave speed + |v|) and the viscous and
 * artificial viscous terms (LS-DYNA form), over all particles. */
double mpm_stable_dt(const mpm_sim *sim);

/* One explicit step of size sim->dt: run every stage.  Returns
 * PM_ERR_UNSTABLE (message with step, time, particle, position, cause) on
 * a numerical failure. */
pm_err mpm_step(mpm_sim *sim);

/* Kinetic, strain and (fluid) internal energy of the particles. */
void mpm_energies(const mpm_sim *sim, double *kinetic, double *strain,
                  double *internal);

/* The grid basis of a particle at x. */
void mpm_stencil_at(const mpm_grid *g, const double x[3], mpm_stencil *st);

/* Assemble sim->stage from the scene (called by mpm_model_create). */
void mpm_build_pipeline(mpm_sim *sim);

/* Particle to grid of mass and momentum, and with with_force the internal
 * force (the first stage of USL/MUSL; used by the tests). */
void mpm_p2g(mpm_sim *sim, int with_force);

#endif
