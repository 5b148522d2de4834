/* pm_app: the methods this program offers.  The only place that knows
 * every backend: it registers each with the backend table, after which the
 * scene loader and the run driver reach them by name. */
#ifndef PM_APP_H
#define PM_APP_H

#include "pm_error.h"

/* Register every backend of this build (idempotent).  Call before loading
 * a scene. */
pm_err pm_app_init(void);

#endif
