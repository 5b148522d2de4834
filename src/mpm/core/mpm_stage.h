/* mpm_stage: what a stage of the MPM step is: a function of the step's
 * context (model, state, workspace) that returns pm_err, its own energy
 * accounts, and the failure record through which a numerical failure in a
 * parallel loop becomes PM_ERR_UNSTABLE with the particle named. */
#ifndef MPM_STAGE_H
#define MPM_STAGE_H

#include <stdbool.h>

#include "pm_error.h"

struct mpm_model;
struct mpm_state;
struct mpm_work;

/* What a stage works on.  The model is read-only during a step. */
typedef struct {
  const struct mpm_model *model;
  struct mpm_state *state;
  struct mpm_work *work;
} mpm_ctx;

typedef struct mpm_stage mpm_stage;

/* A stage: returns PM_SUCCESS, or PM_ERR_UNSTABLE (see mpm_stage_status)
 * after a numerical failure. */
typedef pm_err (*mpm_stage_fn)(mpm_ctx *ctx, const mpm_stage *self);

/* The energy accounts a stage keeps (which the summary reports). */
enum { MPM_BOOKS_WORK = 1u, MPM_BOOKS_DISSIPATED = 2u };

struct mpm_stage {
  mpm_stage_fn run;
  /* Optional: run after the grid update of the same step, when the step's
   * velocities are known (gravity books its work there). */
  mpm_stage_fn after_update;
  const char *name; /* short name (a string literal): the timer's */
  int index;        /* place in the pipeline: its energy account */
  int group;        /* a particle kind's stage: its group; else -1 */
  int mode;         /* a transfer's mode (what it moves) */
  unsigned books;   /* MPM_BOOKS_* */
  char detail[160]; /* what it does, for the plan */
};

/* One stage's energy, J (per unit thickness in 2-D), over the run. */
typedef struct {
  double work;       /* work done on the particles from outside */
  double dissipated; /* energy taken out (damping, absorbing faces) */
} mpm_energy_account;

/* A numerical failure found inside a stage: the first one of the step. */
typedef struct {
  bool failed;
  long particle;
  char cause[192];
} mpm_failure;

/* Record a failure at particle p with its cause, fmt formatted with a and
 * b, unless one is recorded already.  Safe inside parallel loops. */
void mpm_fail(struct mpm_work *w, long p, const char *fmt, double a, double b);

/* PM_SUCCESS, or, when a failure is recorded, PM_ERR_UNSTABLE with
 * "step N, t = T s, stage NAME: particle P at (x), started at (X):
 * CAUSE" (the step and time it was heading for). */
pm_err mpm_stage_status(const mpm_ctx *ctx, const mpm_stage *self);

/* Book external work / dissipated energy to the stage's account and to
 * the run's totals, in the order the bookings come (so the totals are the
 * sums over the stages). */
void mpm_book_work(mpm_ctx *ctx, const mpm_stage *self, double work);
void mpm_book_dissipated(mpm_ctx *ctx, const mpm_stage *self, double energy);

#endif
