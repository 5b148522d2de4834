/* pm_dl: a library opened on first use and its symbols resolved into a
 * table of typed pointers (gmsh: gm_gmsh_api; PETSc: pm_petsc_api), so
 * that a process maps a large library, and the libraries it brings, only
 * when its run needs it. */
#ifndef PM_DL_H
#define PM_DL_H

#include <stddef.h>

#include "pm_error.h"

/* The struct of a table: a typed pointer to each symbol list names (an
 * X-macro list of names, declared by the library's headers). */
#define PM_DL_POINTER_(name) __typeof__(name) *name;
#define PM_DL_TABLE(list, type)                                                \
  typedef struct {                                                             \
    list(PM_DL_POINTER_)                                                       \
  } type

/* The entries of a table of type PM_DL_TYPE (defined where they are). */
#define PM_DL_ENTRY(name) {#name, offsetof(PM_DL_TYPE, name)},

/* One entry of a table: the symbol's name and where its address goes. */
typedef struct {
  const char *name;
  size_t offset; /* offsetof the table's pointer */
} pm_dl_entry;

/* A table and how to fill it. */
typedef struct {
  const char *what;   /* "gmsh", "PETSc": names the library in messages */
  const char *soname; /* dlopen's argument */
  const char *built;  /* the version the build's headers declare */
  const pm_dl_entry *entries;
  size_t n_entries;
  void *table; /* the struct the entries' offsets point into */
  int loaded;  /* set once the table is filled */
} pm_dl_library;

/* Opens lib->soname (RTLD_NOW, local) unless lib is loaded, and writes the
 * address of every entry's symbol into lib->table.  need says what needs
 * the library, for the message of PM_ERR_UNSUPPORTED when it cannot be
 * opened or lacks a symbol (then nothing is written).  The library stays
 * open: gmsh, OpenCASCADE and PETSc keep state (static objects, handlers
 * at exit) past their own finalisation.  Not thread-safe: called from the
 * process's one thread before the library is used. */
pm_err pm_dl_load(pm_dl_library *lib, const char *need);

#endif
