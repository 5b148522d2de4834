/* gm_gmsh_api: libgmsh opened on first use and its functions resolved into
 * the table the geometry modules call through (gm_gmsh_api.h). */
#define GM_GMSH_API_IMPL
#include "gm_gmsh_api.h"

#include <stddef.h>

#ifndef PM_GMSH_SONAME
#error "PM_GMSH_SONAME: the build names the gmsh library (CMakeLists.txt)"
#endif

gm_gmsh_api_table gm_gmsh_api;

#define PM_DL_TYPE gm_gmsh_api_table
static const pm_dl_entry entries[] = {GM_GMSH_API(PM_DL_ENTRY)};

pm_err gm_gmsh_api_load_from(const char *soname, const char *need) {
  static pm_dl_library lib = {
      .what = "gmsh",
      .built = "gmshc.h of gmsh " GMSH_API_VERSION,
      .entries = entries,
      .n_entries = sizeof entries / sizeof entries[0],
      .table = &gm_gmsh_api,
  };
  lib.soname = soname;
  return pm_dl_load(&lib, need);
}

pm_err gm_gmsh_api_load(const char *need) {
  return gm_gmsh_api_load_from(PM_GMSH_SONAME, need);
}
