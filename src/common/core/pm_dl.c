/* pm_dl: libraries opened on first use, their symbols into a table. */
#include "pm_dl.h"

#include <dlfcn.h>
#include <string.h>

pm_err pm_dl_load(pm_dl_library *lib, const char *need) {
  if (lib->loaded) return PM_SUCCESS;
  const char *why = need ? need : "the run";
  void *h = dlopen(lib->soname, RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    const char *msg = dlerror();
    return PM_ERROR(PM_ERR_UNSUPPORTED,
                    "%s library %s cannot be loaded, and %s needs it: %s "
                    "(install %s's library, or add its folder to "
                    "LD_LIBRARY_PATH)",
                    lib->what, lib->soname, why, msg ? msg : "no reason given",
                    lib->what);
  }
  /* Every symbol first, then the table: a library missing one leaves the
   * table as it was. */
  void *addr[512];
  PM_CHECK(lib->n_entries <= sizeof addr / sizeof addr[0], PM_ERR_INTERNAL,
           "pm_dl_load: %zu symbols of %s, more than %zu", lib->n_entries,
           lib->what, sizeof addr / sizeof addr[0]);
  for (size_t i = 0; i < lib->n_entries; i++) {
    addr[i] = dlsym(h, lib->entries[i].name);
    if (!addr[i]) {
      dlclose(h);
      return PM_ERROR(PM_ERR_UNSUPPORTED,
                      "%s library %s lacks %s, and %s needs it: another %s "
                      "than the one pointmech was built with (%s)",
                      lib->what, lib->soname, lib->entries[i].name, why,
                      lib->what, lib->built);
    }
  }
  for (size_t i = 0; i < lib->n_entries; i++)
    memcpy((char *)lib->table + lib->entries[i].offset, &addr[i],
           sizeof addr[i]);
  lib->loaded = 1;
  return PM_SUCCESS;
}
