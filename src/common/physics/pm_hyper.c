/* pm_hyper: the check of a model's keys shared by the hyperelastic entries
 * (the rest of pm_hyper is inline in its header). */
#include "pm_hyper.h"

pm_err pm_hyper_check_keys(const pm_material *m, const char **key) {
  *key = NULL;
  for (const pm_key *k = m->model->keys; k && k->type != PM_KEY_END; k++) {
    const char *at = (const char *)m + k->offset;
    bool required = k->flags & PM_KEY_REQUIRED;
    char what[128];
    pm_key_describe(k, what, sizeof what);
    if (k->type == PM_KEY_NUMBERS) {
      int n = *(const int *)((const char *)m + k->count_offset);
      if (required && n == 0) {
        *key = k->name;
        return PM_ERROR(PM_ERR_ARG, "expected %s (required), got none", what);
      }
    } else if (k->type == PM_KEY_NUMBER) {
      double v = *(const double *)at;
      if (isnan(v) && !required) continue;
      if (!pm_key_in_range(k, v)) {
        *key = k->name;
        if (isnan(v))
          return PM_ERROR(PM_ERR_ARG, "expected %s (required), got none", what);
        return PM_ERROR(PM_ERR_ARG, "expected %s, got %g", what, v);
      }
    }
  }
  return PM_SUCCESS;
}
