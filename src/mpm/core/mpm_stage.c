/* mpm_stage: failure records and energy bookings of the stages. */
#include "mpm_stage.h"

#include <stdio.h>

#include "mpm_state.h"
#include "pm_omp.h"

void mpm_fail(mpm_work *w, long p, const char *fmt, double a, double b) {
  PM_OMP(critical(mpm_fail)) {
    if (!w->fail.failed) {
      w->fail.failed = true;
      w->fail.particle = p;
      snprintf(w->fail.cause, sizeof w->fail.cause, fmt, a, b);
    }
  }
}

pm_err mpm_stage_status(const mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_work *w = ctx->work;
  if (!w->fail.failed) return PM_SUCCESS;
  const mpm_model *m = ctx->model;
  const mpm_state *s = ctx->state;
  long p = w->fail.particle;
  const double *x = s->x + 3 * p, *x0 = m->x0 + 3 * p;
  const long named = m->gid ? m->gid[p] : p; /* its index on one process */
  return PM_ERROR(PM_ERR_UNSTABLE,
                  "step %ld, t = %.6g s, stage %s: particle %ld at (%g, %g, "
                  "%g), started at (%g, %g, %g): %s",
                  s->step + 1, s->t + s->dt, self->name, named, x[0], x[1],
                  x[2], x0[0], x0[1], x0[2], w->fail.cause);
}

void mpm_book_work(mpm_ctx *ctx, const mpm_stage *self, double work) {
  ctx->state->energy[self->index].work += work;
  ctx->state->external_work += work;
}

void mpm_book_dissipated(mpm_ctx *ctx, const mpm_stage *self, double energy) {
  ctx->state->energy[self->index].dissipated += energy;
  ctx->state->dissipated += energy;
}
