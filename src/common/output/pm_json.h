/* pm_json: a pretty-printed JSON writer to a file that appears whole, and
 * the opening members of a run's summary.json.  Included by
 * pm_files.h. */
#ifndef PM_JSON_H
#define PM_JSON_H

#include <stdbool.h>

#include "pm_error.h"

/* Pretty-printed JSON written straight to a pm_afile.  One top-level value;
 * containers nest at most PM_JSON_MAX_DEPTH deep.  Each call takes a key:
 * the member name inside an object (required, escaped like a string), NULL
 * inside an array and at the top level.  A misuse (wrong key, too deep,
 * mismatched end, second top-level value) fails with PM_ERR_ARG; every later
 * call then fails too and the writer refuses to commit.  Write errors fail with
 * PM_ERR_IO. */
#define PM_JSON_MAX_DEPTH 16
typedef struct pm_json pm_json;

/* Start writing path (through pm_afile).  *out owned by the caller, released
 * by pm_json_close.  Failures as pm_afile_open. */
pm_err pm_json_open(const char *path, pm_json **out);
/* Open an object ({) / close the innermost object (}). */
pm_err pm_json_begin_object(pm_json *j, const char *key);
pm_err pm_json_end_object(pm_json *j);
/* Open an array ([) / close the innermost array (]). */
pm_err pm_json_begin_array(pm_json *j, const char *key);
pm_err pm_json_end_array(pm_json *j);
/* A number printed with 15 significant digits, or 17 when 15 do not read
 * back exactly; NaN and infinities are
 * written as null (JSON has no such numbers). */
pm_err pm_json_number(pm_json *j, const char *key, double value);
pm_err pm_json_integer(pm_json *j, const char *key, long long value);
/* A string (UTF-8 passed through; quote, backslash and control characters
 * escaped).  NULL is written as null. */
pm_err pm_json_string(pm_json *j, const char *key, const char *value);
pm_err pm_json_bool(pm_json *j, const char *key, bool value);
pm_err pm_json_null(pm_json *j, const char *key);

/* commit: the document must be complete (one top-level value, every
 * container closed, no earlier misuse), then the file is committed;
 * otherwise (or when commit is false) the temporary file is removed.
 * Always frees j (NULL accepted).  Fails with PM_ERR_ARG for an incomplete
 * document (file discarded) or PM_ERR_IO from the commit. */
pm_err pm_json_close(pm_json *j, bool commit);

/* The opening members of a run's summary.json, the same for every method:
 * program, version, scene (path), name, method and the --set overrides
 * (n_overrides strings). */
pm_err pm_json_run_header(pm_json *j, const char *scene_path, const char *name,
                          const char *method, int n_overrides,
                          char *const *overrides);

#endif
