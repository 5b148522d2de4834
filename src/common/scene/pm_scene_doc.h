/* pm_scene_doc: a scene's YAML node tree (libyaml) with file marks, checked
 * against a libcyaml schema and edited by --set overrides.  Private to the
 * scene loader. */
#ifndef PM_SCENE_DOC_H
#define PM_SCENE_DOC_H

#include <cyaml/cyaml.h>
#include <stdbool.h>
#include <stddef.h>
#include <yaml.h>

#include "pm_error.h"
#include "pm_scene.h"

/* Longest key path and location prefix built for messages. */
#define PM_SDOC_PATH 256
#define PM_SDOC_WHERE 512

typedef struct {
  const char *path; /* scene file, for messages */
  yaml_document_t doc;
  bool loaded;                  /* doc holds a document to delete */
  int n_file_nodes;             /* node ids 1..n_file_nodes come from path */
  int n_overrides;              /* overrides applied so far */
  int *override_end;            /* last node id created by override k */
  const char *const *overrides; /* "KEY=VALUE" texts, for messages */
} pm_sdoc;

/* Parse text (len bytes, read from path) into d.  YAML syntax errors and
 * empty or multi-document files fail with PM_ERR_SCENE and a FILE:LINE:COL
 * message.  d must be zeroed; release it with pm_sdoc_free even on
 * failure. */
pm_err pm_sdoc_parse(pm_sdoc *d, const char *path, const char *text,
                     size_t len);
/* Apply overrides[0..n) (each "KEY=VALUE", KEY a dotted path with 0-based
 * list indices) in order.  A key must exist in schema; absent mapping keys
 * are added (with any absent parent mappings) and index n of an n-item list
 * appends.  VALUE is a plain scalar unless it starts with [, {, " or ', in
 * which case it is parsed as YAML.  overrides must outlive d. */
pm_err pm_sdoc_apply_overrides(pm_sdoc *d, const cyaml_schema_value_t *schema,
                               int n, const char *const *overrides);
/* Check the tree against schema: keys known and unique, required keys
 * present, scalar types, list lengths, enum and flag names.  The first
 * problem fails with PM_ERR_SCENE and a located message. */
pm_err pm_sdoc_validate(const pm_sdoc *d, const cyaml_schema_value_t *schema);
/* Write the (overridden) tree as YAML text for libcyaml; *text is
 * malloc'd, NUL-terminated, *len excludes the NUL. */
pm_err pm_sdoc_emit(pm_sdoc *d, char **text, size_t *len);
/* Release the tree; d may be zeroed or partly built. */
void pm_sdoc_free(pm_sdoc *d);

/* Node id at a dotted path ("time.quasi_static.tolerance", "boundary.2"),
 * or 0 when absent.  With key, the id of the mapping key node instead (0
 * for list items). */
int pm_sdoc_find(const pm_sdoc *d, const char *path, bool key);
/* The scalar text of node id, or NULL if it is not a scalar. */
const char *pm_sdoc_scalar(const pm_sdoc *d, int id);
/* File position of node id (0, 0 when it does not come from the file). */
pm_scene_mark pm_sdoc_mark(const pm_sdoc *d, int id);
/* Message prefix for node id reached by path: "FILE:LINE:COL: PATH", or
 * "--set KEY=VALUE" (": PATH" added when PATH is not KEY) for a node an
 * override made, or "FILE: PATH" for id 0. */
void pm_sdoc_where(const pm_sdoc *d, int id, const char *path, char *buf,
                   size_t size);
/* Short rendering of node id for "got ...": the scalar (shortened), "an
 * empty value", "a mapping" or "a list". */
void pm_sdoc_got(const pm_sdoc *d, int id, char *buf, size_t size);
/* Fail with PM_ERR_SCENE: "WHERE: expected WHAT, got GOT" for the node at
 * path. */
pm_err pm_sdoc_expected(const pm_sdoc *d, const char *path, const char *what);
/* Fail with PM_ERR_SCENE: "WHERE: " + printf-formatted text, for the node
 * at path (its key node when key is set). */
pm_err pm_sdoc_fail(const pm_sdoc *d, const char *path, bool key,
                    const char *fmt, ...) __attribute__((format(printf, 4, 5)));

#endif
