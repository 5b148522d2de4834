/* pm_reader: reads a scene's YAML tree against key tables (pm_keys.h) into
 * the target structs in one pass: unknown and duplicate keys, missing
 * required keys, types, ranges, names, expressions and list lengths are
 * checked, defaults filled, and every problem fails with PM_ERR_SCENE and
 * "FILE:LINE:COL: KEY: expected ..., got ..." (or "--set KEY=VALUE: ..."
 * for a value an override gave). */
#ifndef PM_READER_H
#define PM_READER_H

#include <stdbool.h>

#include "pm_expr.h"
#include "pm_keys.h"
#include "pm_scene_doc.h"

struct pm_reader {
  const pm_sdoc *doc;
  int dimension; /* for POINT keys and z components; 3 until known */
};

/* Read mapping node id (found at path) against n tables at once: keys[t]
 * fill bases[t].  A key of the mapping that none of the tables has fails
 * with "unknown key (expected one of ...)", listing expected when given,
 * else every key of the tables.  A mapping absent from the scene (id 0)
 * gets the defaults. */
pm_err pm_reader_mapping(pm_reader *r, int id, const char *path, int n,
                         const pm_key *const *keys, void *const *bases,
                         const char *expected);

/* The same for one table. */
pm_err pm_reader_read(pm_reader *r, int id, const char *path,
                      const pm_key *keys, void *base);

/* Read one value of key k at node id into dst (the key's offset already
 * added). */
pm_err pm_reader_value(pm_reader *r, int id, const char *path, const pm_key *k,
                       void *dst);

/* Whether the scene gives the key at path (in the file or an override). */
bool pm_reader_has(const pm_reader *r, const char *path);

/* Compile an expression in the variables vars ("xyzt", "xyz") found at
 * path; a variable outside vars fails naming it. */
pm_err pm_reader_expr(pm_reader *r, const char *path, const char *text,
                      const char *vars, pm_expr **out);

/* Release what reading keys into base allocated (strings, expressions,
 * lists, recursively); base itself is the caller's. */
void pm_reader_release(const pm_key *keys, void *base);

/* Located failures (PM_ERR_SCENE), as pm_sdoc_fail / pm_sdoc_expected. */
#define pm_reader_fail(r, path, key, ...)                                      \
  pm_sdoc_fail((r)->doc, (path), (key), __VA_ARGS__)
#define pm_reader_expected(r, path, what)                                      \
  pm_sdoc_expected((r)->doc, (path), (what))

#endif
