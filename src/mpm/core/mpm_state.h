/* mpm_state: what an MPM run changes, in two parts.  mpm_state is exactly
 * what a checkpoint writes to resume bit for bit; mpm_work is what a step
 * rebuilds or only reports, so a checkpoint leaves it out. */
#ifndef MPM_STATE_H
#define MPM_STATE_H

#include "mpm_fbar.h"
#include "mpm_model.h"
#include "pm_checkpoint.h"
#include "pm_progress.h"

/* The state of a run.  Everything a later step reads that an earlier one
 * wrote: time and step size, the particles, every kind's arrays, the
 * stages' energy accounts, the damping rate and what dynamic relaxation
 * remembers of the last step, and the counters the history reports over
 * the whole run. */
typedef struct mpm_state {
  double t;            /* time, s */
  long step;           /* steps taken */
  double dt;           /* the step size (of the last step, or the next) */
  double dt_stable;    /* the stable step as last estimated, s */
  double max_div_prev; /* largest |tr D| of the last stress update, 1/s (the
                          stable step's artificial viscosity term) */
  /* particles */
  double *x;                             /* 3: position */
  double *v;                             /* 3: velocity */
  double *vol;                           /* volume */
  double *sigma;                         /* 9: Cauchy stress */
  mpm_group_state group[MPM_MAX_GROUPS]; /* each kind's arrays */
  /* energy, J: each stage's accounts, and the totals of the same bookings */
  mpm_energy_account energy[MPM_MAX_STAGES];
  double external_work, dissipated;
  /* quasi-static */
  double damping;       /* current rate, 1/s */
  double *force_prev;   /* 3 per node: the last step's grid force before
                           damping (dynamic relaxation) */
  unsigned char *fixed; /* 3 per node: dofs the conditions set in the last
                           step, which dynamic relaxation leaves out */
  /* membranes' normals by isosurface least squares: totals over the run,
   * and the largest cond(T) of the last step's fits (history.csv reports
   * them as they are: a row between two others would otherwise change
   * what the next row counts, and a stop writes one) */
  struct {
    double cells[4];      /* cells fitted quadratic, linear, merged into a
                             larger element, left rank deficient */
    double points;        /* points whose normals were fitted */
    double degenerate;    /* points where grad phi vanished (normal kept) */
    double draws;         /* random points drawn */
    double max_condition; /* largest cond(T) of a fit kept, last step */
  } iso;
  /* iterations of the constitutive updates over the run */
  int iter_max_total;
  long iter_capped_total;
} mpm_state;

/* The workspace of a step: nodal arrays, the conditions' bookkeeping,
 * particle increments and wave speeds, and the figures of the last step.
 * A step overwrites all of it before reading it. */
typedef struct mpm_work {
  mpm_nodes nodes;
  mpm_cond_work cond;
  double *dx; /* 3 per particle: position increment of the step */
  double *cp; /* per particle: dilatational wave speed */
  double *cs; /* per particle: shear wave speed (absorbing faces only) */
  /* each group's own workspace (its kind's scratch; NULL: none) */
  double *scratch[MPM_MAX_GROUPS];
  long n_scratch[MPM_MAX_GROUPS];
  /* each group's workspace that is more than doubles (mpm_kind.work_create) */
  void *kind_work[MPM_MAX_GROUPS];
  void (*kind_work_free[MPM_MAX_GROUPS])(void *);
  size_t kind_work_bytes[MPM_MAX_GROUPS];
  double *rigid_mass; /* per node: a moving body's mass (bodies with
                         motion only) */
  mpm_fbar_work fbar; /* F-bar's averages (mpm.fbar and a solid only) */
  /* figures of the last step */
  double max_div;      /* largest |tr D| of the stress update, 1/s */
  double min_jacobian; /* smallest volume ratio J of the stress update */
  double residual;     /* quasi-static residual */
  int iter_max;        /* most iterations a particle took */
  long iter_capped;    /* particles whose iteration hit the cap */
  mpm_failure fail;
  pm_timers timers;
  int timer[MPM_MAX_STAGES]; /* each stage's timer */
  int timer_migrate;         /* across ranks: the particles' migration */
} mpm_work;

/* A state of model m's shape, zeroed (t = 0 and no particle data): what a
 * checkpoint is read into.  PM_ERR_MEMORY on failure (*out NULL). */
pm_err mpm_state_create(const mpm_model *m, mpm_state **out);
/* Release a state (NULL accepted). */
void mpm_state_destroy(mpm_state *s);

/* Copy every value of src into dst (both of model m's shape). */
void mpm_state_copy(const mpm_model *m, mpm_state *dst, const mpm_state *src);
/* Copy every member of src that is a value (time, step, energy accounts,
 * counters...) into dst, keeping dst's arrays (and their lengths). */
void mpm_state_copy_values(mpm_state *dst, const mpm_state *src);

/* The state's per-particle arrays, named: position, velocity, volume,
 * stress, then each group's own.  Writes at most max into out (the
 * arrays stay the state's); returns how many there are (at most
 * MPM_STATE_MAX_ARRAYS). */
#define MPM_STATE_MAX_ARRAYS (4 + MPM_MAX_GROUPS * MPM_MAX_ARRAYS)
int mpm_state_arrays(const mpm_model *m, const mpm_state *s, mpm_array *out,
                     int max);

/* Write every value of the state to a checkpoint, or read it back (the
 * same items both ways: pm_checkpoint.h). */
pm_err mpm_state_checkpoint(const mpm_model *m, mpm_state *s, pm_ckpt *ck);
/* The same items but the particles' and the nodes' arrays (a checkpoint
 * in pieces holds those in its pieces; s has no nodal arrays). */
pm_err mpm_state_checkpoint_values(mpm_state *s, pm_ckpt *ck);

/* Bytes of the state's arrays (particles and grid). */
size_t mpm_state_bytes(const mpm_model *m, const mpm_state *s);

/* The workspace of model m.  PM_ERR_MEMORY on failure (*out NULL). */
pm_err mpm_work_create(const mpm_model *m, mpm_work **out);
/* Release a workspace (NULL accepted). */
void mpm_work_destroy(mpm_work *w);
/* Bytes of the workspace's arrays (grid and particles). */
size_t mpm_work_bytes(const mpm_model *m, const mpm_work *w);

#endif
