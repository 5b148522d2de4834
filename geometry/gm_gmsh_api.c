/* gm_gmsh_api: libgmsh opened on first use and its functions resolved into
 * the table the geometry modules call through (gm_gmsh_api.h). */
#define GM_GMSH_API_IMPL
#include "gm_gmsh_api.h"

#include <dlfcn.h>
#include <stdbool.h>
#include <string.h>

#ifndef PM_GMSH_SONAME
#error "PM_GMSH_SONAME: the build names the gmsh library (CMakeLists.txt)"
#endif

gm_gmsh_api_table gm_gmsh_api;

/* Once filled, the table stays: the library is never closed, since gmsh and
 * OpenCASCADE keep state past gmshFinalize (static objects, handlers
 * registered at exit). */
static bool loaded;

pm_err gm_gmsh_api_load_from(const char *soname, const char *need) {
  if (loaded) return PM_SUCCESS;
  const char *why = need ? need : "meshing";
  void *lib = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    const char *msg = dlerror();
    return PM_ERROR(PM_ERR_UNSUPPORTED,
                    "gmsh library %s cannot be loaded, and %s needs it: %s "
                    "(install gmsh's library, or add its folder to "
                    "LD_LIBRARY_PATH)",
                    soname, why, msg ? msg : "no reason given");
  }
  gm_gmsh_api_table t;
  void *fn;
#define GM_GMSH_API_RESOLVE(name)                                              \
  fn = dlsym(lib, #name);                                                      \
  if (!fn) {                                                                   \
    dlclose(lib);                                                              \
    return PM_ERROR(PM_ERR_UNSUPPORTED,                                        \
                    "gmsh library %s lacks the function %s, and %s needs "     \
                    "it: another gmsh than the one pointmech was built with "  \
                    "(gmshc.h of gmsh %s)",                                    \
                    soname, #name, why, GMSH_API_VERSION);                     \
  }                                                                            \
  memcpy(&t.name, &fn, sizeof fn);
  GM_GMSH_API(GM_GMSH_API_RESOLVE)
#undef GM_GMSH_API_RESOLVE
  gm_gmsh_api = t;
  loaded = true;
  return PM_SUCCESS;
}

pm_err gm_gmsh_api_load(const char *need) {
  return gm_gmsh_api_load_from(PM_GMSH_SONAME, need);
}
