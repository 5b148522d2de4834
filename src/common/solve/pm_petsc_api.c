/* pm_petsc_api: libpetsc opened on first use and its symbols resolved into
 * the table the solvers use (pm_petsc_api.h). */
#define PM_PETSC_API_IMPL
#include "pm_petsc_api.h"

#include <stddef.h>

#define PM_STR_(x) #x
#define PM_STR(x) PM_STR_(x)

#ifndef PM_PETSC_SONAME
#error "PM_PETSC_SONAME: the build names the PETSc library (CMakeLists.txt)"
#endif

pm_petsc_api_table pm_petsc_api;

#define PM_DL_TYPE pm_petsc_api_table
static const pm_dl_entry entries[] = {PM_PETSC_API(PM_DL_ENTRY)};

pm_err pm_petsc_api_load(const char *need) {
  static pm_dl_library lib = {
      .what = "PETSc",
      .soname = PM_PETSC_SONAME,
      .built =
          "petscversion.h of PETSc " PM_STR(PETSC_VERSION_MAJOR) "." PM_STR(
              PETSC_VERSION_MINOR) "." PM_STR(PETSC_VERSION_SUBMINOR),
      .entries = entries,
      .n_entries = sizeof entries / sizeof entries[0],
      .table = &pm_petsc_api,
  };
  return pm_dl_load(&lib, need);
}
