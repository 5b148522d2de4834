/* pm_app: the backend table of this build. */
#include "pm_app.h"

#include "fpm_backend.h"
#include "gm_gmsh.h"
#include "mpm_backend.h"
#include "pm_backend.h"
#include "pm_omp.h"
#include "pm_scene.h"

pm_err pm_app_init(void) {
  pm_blas_single_thread();
  pm_scene_set_file_bounds(gm_file_bounds);
  PM_CALL(pm_backend_register(&fpm_backend));
  PM_CALL(pm_backend_register(&mpm_backend));
  PM_CALL(pm_backend_register(&mpm_implicit_backend));
  return PM_SUCCESS;
}
