/* pm_scene_doc: the scene's libyaml node tree, which keeps file marks for
 * messages and takes --set overrides; the key reader (pm_reader) checks it
 * against the key tables. */
#include "pm_scene_doc.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Deepest override value copied: the vocabulary nests far less. */
#define PM_SDOC_DEPTH 32
/* Scalars longer than this are shortened in "got ..." messages. */
#define PM_SDOC_GOT 60

static yaml_node_t *node_get(const pm_sdoc *d, int id) {
  /* libyaml takes a non-const document only to find the node. */
  return id > 0 ? yaml_document_get_node((yaml_document_t *)&d->doc, id) : NULL;
}

static int node_count(const pm_sdoc *d) {
  return (int)(d->doc.nodes.top - d->doc.nodes.start);
}

static int root_id(const pm_sdoc *d) {
  return d->loaded && node_count(d) > 0 ? 1 : 0;
}

/* Which override made node id: -1 for the file (or no node). */
static int node_origin(const pm_sdoc *d, int id) {
  if (id <= d->n_file_nodes) return -1;
  for (int k = 0; k < d->n_overrides; k++)
    if (id <= d->override_end[k]) return k;
  return d->n_overrides; /* the override being applied */
}

/* buf = path.seg, cut to size (paths are for messages only). */
static void path_join(char *buf, size_t size, const char *path,
                      const char *seg) {
  size_t n = 0;
  for (const char *p = path; *p && n + 1 < size; p++) buf[n++] = *p;
  if (path[0] && n + 1 < size) buf[n++] = '.';
  for (const char *p = seg; *p && n + 1 < size; p++) buf[n++] = *p;
  buf[n] = '\0';
}

/* Value (or key) node of the mapping pair with key name in mapping id. */
static int map_lookup(const pm_sdoc *d, int id, const char *name, bool key) {
  yaml_node_t *n = node_get(d, id);
  if (!n || n->type != YAML_MAPPING_NODE) return 0;
  for (yaml_node_pair_t *p = n->data.mapping.pairs.start;
       p < n->data.mapping.pairs.top; p++) {
    yaml_node_t *k = node_get(d, p->key);
    if (k && k->type == YAML_SCALAR_NODE &&
        strcmp((const char *)k->data.scalar.value, name) == 0)
      return key ? p->key : p->value;
  }
  return 0;
}

/* Parse a list index segment; -1 when seg is not a plain decimal. */
static long parse_index(const char *seg) {
  if (!seg[0] || strspn(seg, "0123456789") != strlen(seg) || strlen(seg) > 9)
    return -1;
  return strtol(seg, NULL, 10);
}

int pm_sdoc_find(const pm_sdoc *d, const char *path, bool key) {
  char buf[PM_SDOC_PATH];
  int id = root_id(d), key_id = 0;
  if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return 0;
  for (char *seg = buf, *next; id && seg && *seg; seg = next) {
    next = strchr(seg, '.');
    if (next) *next++ = '\0';
    yaml_node_t *n = node_get(d, id);
    if (n->type == YAML_MAPPING_NODE) {
      key_id = map_lookup(d, id, seg, true);
      id = map_lookup(d, id, seg, false);
    } else if (n->type == YAML_SEQUENCE_NODE) {
      long i = parse_index(seg);
      long count = n->data.sequence.items.top - n->data.sequence.items.start;
      key_id = 0;
      id = (i >= 0 && i < count) ? n->data.sequence.items.start[i] : 0;
    } else {
      id = 0;
    }
  }
  return key ? (id ? key_id : 0) : id;
}

int pm_sdoc_root(const pm_sdoc *d) { return root_id(d); }

pm_sdoc_kind pm_sdoc_kind_of(const pm_sdoc *d, int id) {
  yaml_node_t *n = node_get(d, id);
  if (!n) return PM_SDOC_NONE;
  switch (n->type) {
  case YAML_SCALAR_NODE: return PM_SDOC_SCALAR;
  case YAML_MAPPING_NODE: return PM_SDOC_MAPPING;
  case YAML_SEQUENCE_NODE: return PM_SDOC_LIST;
  default: return PM_SDOC_NONE;
  }
}

int pm_sdoc_count(const pm_sdoc *d, int id) {
  yaml_node_t *n = node_get(d, id);
  if (!n) return 0;
  if (n->type == YAML_MAPPING_NODE)
    return (int)(n->data.mapping.pairs.top - n->data.mapping.pairs.start);
  if (n->type == YAML_SEQUENCE_NODE)
    return (int)(n->data.sequence.items.top - n->data.sequence.items.start);
  return 0;
}

int pm_sdoc_item(const pm_sdoc *d, int id, int i) {
  yaml_node_t *n = node_get(d, id);
  if (!n || n->type != YAML_SEQUENCE_NODE || i < 0 || i >= pm_sdoc_count(d, id))
    return 0;
  return n->data.sequence.items.start[i];
}

int pm_sdoc_pair(const pm_sdoc *d, int id, int i, int *value) {
  yaml_node_t *n = node_get(d, id);
  if (!n || n->type != YAML_MAPPING_NODE || i < 0 || i >= pm_sdoc_count(d, id))
    return 0;
  yaml_node_pair_t p = n->data.mapping.pairs.start[i];
  if (value) *value = p.value;
  return p.key;
}

int pm_sdoc_child(const pm_sdoc *d, int id, const char *key) {
  return map_lookup(d, id, key, false);
}

const char *pm_sdoc_scalar(const pm_sdoc *d, int id) {
  yaml_node_t *n = node_get(d, id);
  return n && n->type == YAML_SCALAR_NODE ? (const char *)n->data.scalar.value
                                          : NULL;
}

pm_scene_mark pm_sdoc_mark(const pm_sdoc *d, int id) {
  pm_scene_mark m = {0, 0};
  yaml_node_t *n = node_get(d, id);
  if (n && node_origin(d, id) < 0) {
    m.line = (int)n->start_mark.line + 1;
    m.col = (int)n->start_mark.column + 1;
  }
  return m;
}

void pm_sdoc_where(const pm_sdoc *d, int id, const char *path, char *buf,
                   size_t size) {
  int k = id ? node_origin(d, id) : -1;
  if (k >= 0 && d->overrides) {
    const char *kv = d->overrides[k];
    size_t klen = strcspn(kv, "=");
    bool same = strlen(path) == klen && strncmp(path, kv, klen) == 0;
    snprintf(buf, size, "--set %s%s%s", kv, same || !path[0] ? "" : ": ",
             same ? "" : path);
    return;
  }
  pm_scene_mark m = pm_sdoc_mark(d, id);
  if (m.line > 0)
    snprintf(buf, size, "%s:%d:%d%s%s", d->path, m.line, m.col,
             path[0] ? ": " : "", path);
  else
    snprintf(buf, size, "%s%s%s", d->path, path[0] ? ": " : "", path);
}

void pm_sdoc_got(const pm_sdoc *d, int id, char *buf, size_t size) {
  yaml_node_t *n = node_get(d, id);
  if (!n) {
    snprintf(buf, size, "nothing");
  } else if (n->type == YAML_MAPPING_NODE) {
    snprintf(buf, size, "a mapping");
  } else if (n->type == YAML_SEQUENCE_NODE) {
    snprintf(buf, size, "a list");
  } else if (n->data.scalar.length == 0) {
    snprintf(buf, size, "an empty value");
  } else if (n->data.scalar.length > PM_SDOC_GOT) {
    snprintf(buf, size, "%.*s...", PM_SDOC_GOT, n->data.scalar.value);
  } else {
    snprintf(buf, size, "%s", n->data.scalar.value);
  }
}

/* Node for a message about path: the node itself, or for an absent key the
 * nearest ancestor that exists, so the location points at its parent. */
static int where_node(const pm_sdoc *d, const char *path, bool key) {
  char buf[PM_SDOC_PATH];
  int id = pm_sdoc_find(d, path, key);
  snprintf(buf, sizeof buf, "%s", path);
  while (!id) {
    char *dot = strrchr(buf, '.');
    if (!dot) return root_id(d);
    *dot = '\0';
    id = pm_sdoc_find(d, buf, false);
  }
  return id;
}

pm_err pm_sdoc_fail(const pm_sdoc *d, const char *path, bool key,
                    const char *fmt, ...) {
  char where[PM_SDOC_WHERE], what[PM_SDOC_WHERE];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  pm_sdoc_where(d, where_node(d, path, key), path, where, sizeof where);
  return PM_ERROR(PM_ERR_SCENE, "%s: %s", where, what);
}

pm_err pm_sdoc_expected(const pm_sdoc *d, const char *path, const char *what) {
  char where[PM_SDOC_WHERE], got[PM_SDOC_GOT + 8];
  int id = pm_sdoc_find(d, path, false);
  pm_sdoc_got(d, id, got, sizeof got);
  pm_sdoc_where(d, where_node(d, path, false), path, where, sizeof where);
  return PM_ERROR(PM_ERR_SCENE, "%s: expected %s, got %s", where, what, got);
}

/* ---- parsing ---------------------------------------------------------- */

static pm_err syntax_error(const char *path, const yaml_parser_t *p) {
  const char *problem = p->problem ? p->problem : "unreadable YAML";
  if (p->context)
    return PM_ERROR(PM_ERR_SCENE, "%s:%zu:%zu: YAML syntax error: %s %s", path,
                    p->problem_mark.line + 1, p->problem_mark.column + 1,
                    problem, p->context);
  return PM_ERROR(PM_ERR_SCENE, "%s:%zu:%zu: YAML syntax error: %s", path,
                  p->problem_mark.line + 1, p->problem_mark.column + 1,
                  problem);
}

pm_err pm_sdoc_parse(pm_sdoc *d, const char *path, const char *text,
                     size_t len) {
  pm_err ret = PM_SUCCESS;
  yaml_parser_t parser;
  yaml_document_t extra;
  bool parser_ok = false, extra_ok = false;
  d->path = path;
  PM_ENSURE(yaml_parser_initialize(&parser), PM_ERR_MEMORY,
            "cannot initialise the YAML parser for %s", path);
  parser_ok = true;
  yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
  if (!yaml_parser_load(&parser, &d->doc)) {
    ret = syntax_error(path, &parser);
    goto done;
  }
  d->loaded = true;
  d->n_file_nodes = node_count(d);
  PM_ENSURE(d->n_file_nodes > 0, PM_ERR_SCENE, "%s: empty scene", path);
  /* A second document would be silently ignored by the loader. */
  if (!yaml_parser_load(&parser, &extra)) {
    ret = syntax_error(path, &parser);
    goto done;
  }
  extra_ok = true;
  yaml_node_t *extra_root = yaml_document_get_root_node(&extra);
  PM_ENSURE(!extra_root, PM_ERR_SCENE,
            "%s:%zu:%zu: expected one YAML document, got a second one", path,
            extra_root ? extra_root->start_mark.line + 1 : 0,
            extra_root ? extra_root->start_mark.column + 1 : 0);
done:
  if (extra_ok) yaml_document_delete(&extra);
  if (parser_ok) yaml_parser_delete(&parser);
  return ret;
}

void pm_sdoc_free(pm_sdoc *d) {
  if (!d) return;
  if (d->loaded) yaml_document_delete(&d->doc);
  free(d->override_end);
  memset(d, 0, sizeof *d);
}

/* ---- overrides -------------------------------------------------------- */

/* Copy node id of document src into d's document; returns the new id, or
 * 0 when out of memory or (*deep set) nested deeper than PM_SDOC_DEPTH. */
static int copy_node(pm_sdoc *d, yaml_document_t *src, int id, int depth,
                     bool *deep) {
  yaml_node_t *n = yaml_document_get_node(src, id);
  int out = 0;
  if (!n) return 0;
  if (depth > PM_SDOC_DEPTH) {
    *deep = true;
    return 0;
  }
  switch (n->type) {
  case YAML_SCALAR_NODE:
    return yaml_document_add_scalar(&d->doc, NULL, n->data.scalar.value,
                                    (int)n->data.scalar.length,
                                    n->data.scalar.style);
  case YAML_SEQUENCE_NODE:
    out = yaml_document_add_sequence(&d->doc, NULL, YAML_FLOW_SEQUENCE_STYLE);
    for (yaml_node_item_t *it = n->data.sequence.items.start;
         out && it < n->data.sequence.items.top; it++) {
      int item = copy_node(d, src, *it, depth + 1, deep);
      if (!item || !yaml_document_append_sequence_item(&d->doc, out, item))
        return 0;
    }
    return out;
  case YAML_MAPPING_NODE:
    out = yaml_document_add_mapping(&d->doc, NULL, YAML_FLOW_MAPPING_STYLE);
    for (yaml_node_pair_t *p = n->data.mapping.pairs.start;
         out && p < n->data.mapping.pairs.top; p++) {
      int key = copy_node(d, src, p->key, depth + 1, deep);
      int value = key ? copy_node(d, src, p->value, depth + 1, deep) : 0;
      if (!value ||
          !yaml_document_append_mapping_pair(&d->doc, out, key, value))
        return 0;
    }
    return out;
  default: return 0;
  }
}

/* Make the node for an override's VALUE text; *id is its node id. */
static pm_err override_value(pm_sdoc *d, const char *kv, const char *value,
                             int *id) {
  pm_err ret = PM_SUCCESS;
  yaml_parser_t parser;
  yaml_document_t snip;
  bool parser_ok = false, snip_ok = false;
  *id = 0;
  if (!value[0] || !strchr("[{\"'", value[0])) {
    *id = yaml_document_add_scalar(&d->doc, NULL, (yaml_char_t *)value,
                                   (int)strlen(value), YAML_ANY_SCALAR_STYLE);
    PM_ENSURE(*id, PM_ERR_MEMORY, "--set %s: out of memory", kv);
    goto done;
  }
  PM_ENSURE(yaml_parser_initialize(&parser), PM_ERR_MEMORY,
            "--set %s: cannot initialise the YAML parser", kv);
  parser_ok = true;
  yaml_parser_set_input_string(&parser, (const unsigned char *)value,
                               strlen(value));
  PM_ENSURE(yaml_parser_load(&parser, &snip), PM_ERR_SCENE,
            "--set %s: invalid YAML value: %s", kv,
            parser.problem ? parser.problem : "unreadable");
  snip_ok = true;
  PM_ENSURE(yaml_document_get_root_node(&snip), PM_ERR_SCENE,
            "--set %s: empty value", kv);
  bool deep = false;
  *id = copy_node(d, &snip, 1, 0, &deep);
  PM_ENSURE(!deep, PM_ERR_SCENE,
            "--set %s: expected a value nested at most %d levels deep", kv,
            PM_SDOC_DEPTH);
  PM_ENSURE(*id, PM_ERR_MEMORY, "--set %s: out of memory", kv);
done:
  if (snip_ok) yaml_document_delete(&snip);
  if (parser_ok) yaml_parser_delete(&parser);
  return ret;
}

/* New empty mapping for an absent parent key, or the value node. */
static pm_err override_node(pm_sdoc *d, const char *kv, const char *value,
                            bool last, int *id) {
  if (last) return override_value(d, kv, value, id);
  *id = yaml_document_add_mapping(&d->doc, NULL, YAML_BLOCK_MAPPING_STYLE);
  return *id ? PM_SUCCESS : PM_ERROR(PM_ERR_MEMORY, "--set %s: no memory", kv);
}

/* Walk KEY of "KEY=VALUE" down the tree, creating absent mapping keys
 * (with their absent parent mappings) and appending at index n of an
 * n-item list, and put VALUE there.  A numeric segment indexes a list, any
 * other names a key (the vocabulary has no numeric keys); whether the key
 * exists is the reader's to check, against the tables. */
static pm_err apply_override(pm_sdoc *d, const char *kv) {
  char key[PM_SDOC_PATH], sofar[PM_SDOC_PATH] = "";
  const char *eq = strchr(kv, '=');
  size_t klen = eq ? (size_t)(eq - kv) : 0;
  PM_CHECK(eq && klen > 0 && klen < sizeof key, PM_ERR_SCENE,
           "--set %s: expected KEY=VALUE", kv);
  memcpy(key, kv, klen);
  key[klen] = '\0';
  const char *value = eq + 1;
  int id = root_id(d);
  for (char *seg = key, *next; seg; seg = next) {
    next = strchr(seg, '.');
    if (next) *next++ = '\0';
    bool last = next == NULL;
    char parent[PM_SDOC_PATH];
    snprintf(parent, sizeof parent, "%s", sofar);
    path_join(sofar, sizeof sofar, parent, seg);
    PM_CHECK(seg[0], PM_ERR_SCENE, "--set %s: empty key segment", kv);
    yaml_node_t *n = node_get(d, id);
    int child = 0;
    if (n->type == YAML_MAPPING_NODE) {
      long at = -1,
           n_pairs = n->data.mapping.pairs.top - n->data.mapping.pairs.start;
      for (long i = 0; i < n_pairs && at < 0; i++) {
        const char *k = pm_sdoc_scalar(d, n->data.mapping.pairs.start[i].key);
        if (k && strcmp(k, seg) == 0) at = i;
      }
      if (at >= 0 && !last) {
        child = n->data.mapping.pairs.start[at].value;
      } else if (at >= 0) {
        PM_CALL(override_value(d, kv, value, &child));
        /* Adding nodes may move the node array: look the pair up again. */
        node_get(d, id)->data.mapping.pairs.start[at].value = child;
      } else {
        char nseg[32] = "";
        if (!last)
          snprintf(nseg, sizeof nseg, "%.*s", (int)strcspn(next, "."), next);
        if (!last && parse_index(nseg) >= 0)
          return PM_ERROR(PM_ERR_SCENE,
                          "--set %s: %s is not in the scene, so it has no "
                          "entries to set",
                          kv, sofar);
        int k =
            yaml_document_add_scalar(&d->doc, NULL, (yaml_char_t *)seg,
                                     (int)strlen(seg), YAML_PLAIN_SCALAR_STYLE);
        PM_CHECK(k, PM_ERR_MEMORY, "--set %s: out of memory", kv);
        PM_CALL(override_node(d, kv, value, last, &child));
        PM_CHECK(yaml_document_append_mapping_pair(&d->doc, id, k, child),
                 PM_ERR_MEMORY, "--set %s: out of memory", kv);
      }
    } else if (n->type == YAML_SEQUENCE_NODE) {
      long i = parse_index(seg);
      if (i < 0)
        return PM_ERROR(PM_ERR_SCENE,
                        "--set %s: %s: expected a list index (0, 1, ...), "
                        "got %s",
                        kv, sofar, seg);
      long count = n->data.sequence.items.top - n->data.sequence.items.start;
      char nseg[32] = "";
      if (!last)
        snprintf(nseg, sizeof nseg, "%.*s", (int)strcspn(next, "."), next);
      if (i > count || (i == count && !last && parse_index(nseg) >= 0))
        return PM_ERROR(PM_ERR_SCENE,
                        "--set %s: index %ld out of range (%s has %ld "
                        "entries)",
                        kv, i, parent, count);
      if (i < count && !last) {
        child = n->data.sequence.items.start[i];
      } else if (i < count) {
        PM_CALL(override_value(d, kv, value, &child));
        node_get(d, id)->data.sequence.items.start[i] = child;
      } else {
        PM_CALL(override_node(d, kv, value, last, &child));
        PM_CHECK(yaml_document_append_sequence_item(&d->doc, id, child),
                 PM_ERR_MEMORY, "--set %s: out of memory", kv);
      }
    } else {
      return PM_ERROR(PM_ERR_SCENE,
                      "--set %s: unknown key %s (%s takes a single value)", kv,
                      sofar, parent);
    }
    id = child;
  }
  return PM_SUCCESS;
}

pm_err pm_sdoc_apply_overrides(pm_sdoc *d, int n,
                               const char *const *overrides) {
  if (n <= 0) return PM_SUCCESS;
  PM_CALL(PM_ALLOC(d->override_end, n, "override marks"));
  d->overrides = overrides;
  for (int k = 0; k < n; k++) {
    PM_CALL(apply_override(d, overrides[k]));
    d->override_end[k] = node_count(d);
    d->n_overrides = k + 1;
  }
  return PM_SUCCESS;
}
