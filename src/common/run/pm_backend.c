/* pm_backend: the registry of methods, status names and the energy
 * balance every method reports the same way. */
#include "pm_backend.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_par.h"

static const pm_backend *registry[PM_BACKENDS_MAX];
static int n_registered;

pm_err pm_backend_register(const pm_backend *b) {
  PM_CHECK(b && b->method, PM_ERR_ARG, "pm_backend_register: no backend");
  for (int k = 0; k < n_registered; k++)
    if (registry[k] == b) return PM_SUCCESS;
  PM_CHECK(!pm_backend_find(b->method), PM_ERR_ARG,
           "method %s is registered twice", b->method);
  PM_CHECK(n_registered < PM_BACKENDS_MAX, PM_ERR_ARG,
           "at most %d methods can be registered", PM_BACKENDS_MAX);
  registry[n_registered++] = b;
  return PM_SUCCESS;
}

int pm_backend_count(void) { return n_registered; }

const pm_backend *pm_backend_at(int k) {
  return k >= 0 && k < n_registered ? registry[k] : NULL;
}

const pm_backend *pm_backend_find(const char *method) {
  for (int k = 0; method && k < n_registered; k++)
    if (strcmp(registry[k]->method, method) == 0) return registry[k];
  return NULL;
}

const char *pm_status_name(pm_status s) {
  switch (s) {
  case PM_STATUS_COMPLETED: return "completed";
  case PM_STATUS_CONVERGED: return "converged";
  case PM_STATUS_NOT_CONVERGED: return "not-converged";
  case PM_STATUS_UNSTABLE: return "unstable";
  case PM_STATUS_FAILED: return "failed";
  case PM_STATUS_INTERRUPTED: return "interrupted";
  default: return "not-run";
  }
}

double pm_energy_error(double E0, double E, double D, double W) {
  double scale = fmax(fabs(E0), fabs(W));
  if (!(scale > 0)) scale = fabs(E + D);
  return scale > 0 ? (E - E0 + D - W) / scale : 0.0;
}

pm_status pm_static_status(pm_err e) {
  return e == PM_SUCCESS             ? PM_STATUS_CONVERGED
         : e == PM_ERR_UNSTABLE      ? PM_STATUS_UNSTABLE
         : e == PM_ERR_NOT_CONVERGED ? PM_STATUS_NOT_CONVERGED
                                     : PM_STATUS_FAILED;
}

void pm_backend_names(char *buf, size_t size) {
  size_t used = 0;
  if (size) buf[0] = '\0';
  for (int k = 0; k < n_registered && used < size; k++)
    used += (size_t)snprintf(buf + used, size - used, "%s%s", k ? ", " : "",
                             registry[k]->method);
}

pm_err pm_observer_share(const pm_observer *obs, const pm_step_report *r,
                         bool frame, pm_err (*gather)(void *ctx), void *ctx) {
  const bool view = pm_par_root() && obs;
  int want = frame;
  if (view && obs->wants) want = want || obs->wants(obs->ctx, r, frame);
  pm_par_bcast(&want, sizeof want);
  if (want) PM_CALL(gather(ctx));
  return pm_par_agree(view ? obs->step(obs->ctx, r, frame) : PM_SUCCESS);
}
