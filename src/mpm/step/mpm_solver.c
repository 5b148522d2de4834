/* mpm_solver: the explicit time loop. */
#include "mpm_solver.h"

#include "mpm_exchange.h"
#include "mpm_pipeline.h"

/* Quasi-static convergence is tested only after this many steps: the
 * first steps' residual is that of a grid barely loaded. */
#define MPM_CONVERGE_AFTER 10

pm_err mpm_solve(mpm_model *m, mpm_state *s, mpm_work *w,
                 const mpm_run_options *opt, mpm_observer observer, void *ctx,
                 mpm_step_info *last) {
  const double t_load = m->opt.t_load;
  const double dt_fixed = m->opt.dt_fixed;
  mpm_step_info info = {.step = s->step, .t = s->t, .dt = s->dt};
  pm_err ret = PM_SUCCESS;
  for (;;) {
    if (s->t >= opt->t_end * (1 - 1e-12)) break;
    if (opt->max_steps > 0 && s->step >= opt->max_steps) break;
    if (dt_fixed > 0) {
      s->dt = dt_fixed;
      double left = opt->t_end - s->t;
      if (left < s->dt && left > 1e-12 * s->dt) s->dt = left;
    }
    ret = mpm_step(m, s, w);
    /* Across ranks, the particles that left this rank's cells. */
    if (!ret) ret = mpm_xc_migrate(m, s, w);
    if (ret) break;
    info = (mpm_step_info){
        .step = s->step,
        .t = s->t,
        .dt = s->dt,
        .residual = w->residual,
        .iter_max = w->iter_max,
        .iter_capped = w->iter_capped,
        .converged = m->opt.qs != PM_QS_NONE && s->t >= t_load &&
                     s->step > MPM_CONVERGE_AFTER &&
                     w->residual < m->opt.qs_tolerance,
    };
    bool last = info.converged || s->t >= opt->t_end * (1 - 1e-12) ||
                (opt->max_steps > 0 && s->step >= opt->max_steps);
    info.last = last;
    bool frame =
        (opt->frame_every > 0 && s->step % opt->frame_every == 0) || last;
    if (observer) {
      ret = observer(ctx, m, s, w, &info, frame);
      if (ret) {
        pm_error_trace(ret, __FILE__, __LINE__, __func__, "observer");
        break;
      }
    }
    if (info.converged) break;
  }
  if (last) *last = info;
  return ret;
}
