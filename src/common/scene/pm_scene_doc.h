/* pm_scene_doc: a scene's YAML node tree (libyaml) with file marks, edited
 * by --set overrides, and located messages about its nodes.  Private to the
 * scene loader and the key reader. */
#ifndef PM_SCENE_DOC_H
#define PM_SCENE_DOC_H

#include <stdbool.h>
#include <stddef.h>
#include <yaml.h>

#include "pm_error.h"

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
 * list indices) in order: absent mapping keys are added (with any absent
 * parent mappings) and index n of an n-item list appends.  VALUE is a plain
 * scalar unless it starts with [, {, " or ', in which case it is parsed as
 * YAML.  Whether the keys exist is checked by the reader afterwards, which
 * names the override.  overrides must outlive d. */
pm_err pm_sdoc_apply_overrides(pm_sdoc *d, int n, const char *const *overrides);
/* Release the tree; d may be zeroed or partly built. */
void pm_sdoc_free(pm_sdoc *d);

/* A position in the scene file (1-based; 0 when not from the file). */
typedef struct {
  int line, col;
} pm_scene_mark;

typedef enum {
  PM_SDOC_NONE = 0,
  PM_SDOC_SCALAR,
  PM_SDOC_MAPPING,
  PM_SDOC_LIST
} pm_sdoc_kind;

/* The root node (0 for an empty tree), what a node is, and its size:
 * pairs of a mapping, items of a list (0 otherwise). */
int pm_sdoc_root(const pm_sdoc *d);
pm_sdoc_kind pm_sdoc_kind_of(const pm_sdoc *d, int id);
int pm_sdoc_count(const pm_sdoc *d, int id);
/* Item i of list id (0 when out of range). */
int pm_sdoc_item(const pm_sdoc *d, int id, int i);
/* Pair i of mapping id: returns its key node, *value its value node. */
int pm_sdoc_pair(const pm_sdoc *d, int id, int i, int *value);
/* Value node of key in mapping id, or 0. */
int pm_sdoc_child(const pm_sdoc *d, int id, const char *key);

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
