/* mpm_motion: bodies that move as prescribed (a pipette): their particles
 * translate with the velocity the scene gives as expressions of t, and the
 * grid nodes they touch take that velocity, so that what touches the body
 * moves with it (no slip). */
#ifndef MPM_MOTION_H
#define MPM_MOTION_H

#include <stdbool.h>

#include "mpm_stage.h"
#include "pm_expr.h"

/* A moving body: its particles [begin, end) and its velocity (expressions
 * of t borrowed from the scene; NULL components are 0). */
typedef struct {
  int body; /* scene body */
  long begin, end;
  long first; /* its first particle's index on one process (across ranks,
                 the particles [begin, end) are the rank's share) */
  const pm_expr *v[3];
} mpm_motion;

/* The body's velocity at time t. */
void mpm_motion_velocity(const mpm_motion *mv, double t, double v[3]);

/* Move the velocity of the nodes the moving bodies' particles touch
 * towards the bodies' velocity over the step (at its midpoint), in vel (3
 * per node), by the body's share of each node's mass: all the way where
 * the body has all the node's mass, gradually as a body comes to touch a
 * node (a sudden switch would jolt what lies there each time the body
 * crosses a cell).  With book: the work the constraint does over the step
 * (J), from the velocity the nodes had (vel before the call) and vel0;
 * else 0. */
double mpm_motion_apply(const mpm_ctx *ctx, double *vel, bool book);

/* The stage after g2p: the moving particles' velocity (at the step's end)
 * and position increment (the midpoint velocity times dt). */
pm_err mpm_stage_motion(mpm_ctx *ctx, const mpm_stage *self);

#endif
