/* pm_view: rank 0's view of a run across ranks (pm_view.h). */
#include "pm_view.h"

#include <stdio.h>

#include "pm_par.h"

bool pm_view_keeps_whole(void) { return pm_par_active() && pm_par_root(); }

void pm_view_release(pm_view *v) {
  if (v->ranks && !pm_par_root() && v->release) v->release(v->ctx);
}

void pm_view_start(pm_view *v, const pm_observer *obs) {
  pm_view_release(v);
  v->obs = obs;
}

pm_err pm_view_step(pm_view *v, const pm_step_report *r, bool frame) {
  if (v->ranks)
    return pm_observer_share(pm_par_root() ? v->obs : NULL, r, frame, v->gather,
                             v->ctx);
  return v->obs ? v->obs->step(v->obs->ctx, r, frame) : PM_SUCCESS;
}

pm_err pm_view_stopped_inside(pm_view *v, const pm_step_report *r, pm_err e) {
  if (e != PM_ERR_INTERRUPTED) return e;
  char where[512];
  snprintf(where, sizeof where, "%s", pm_error_message());
  pm_err o = pm_view_step(v, r, false);
  if (o != PM_ERR_INTERRUPTED) return o ? o : e;
  char after[1024];
  snprintf(after, sizeof after, "%s", pm_error_message());
  return PM_ERROR(PM_ERR_INTERRUPTED, "%s; %s", where, after);
}

pm_err pm_view_end(pm_view *v, pm_err e) {
  if (v->ranks) {
    pm_err g = v->gather(v->ctx);
    if (!e) e = g;
  }
  v->obs = NULL;
  return e;
}
