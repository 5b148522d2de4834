/* pm_json: a pretty-printed JSON writer straight to a file that appears
 * whole (pm_afile), and the opening members of a run's summary.json. */
#include "pm_json.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_files.h"

struct pm_json {
  pm_afile *file;
  FILE *fp;
  int depth;
  bool complete; /* the top-level value has been written */
  bool misused;  /* a call failed: refuse to commit */
  struct {
    char close; /* '}' or ']' */
    long count; /* values written so far in the container */
  } stack[PM_JSON_MAX_DEPTH];
};

static void json_escaped(FILE *fp, const char *s) {
  putc('"', fp);
  for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
    switch (*p) {
    case '"': fputs("\\\"", fp); break;
    case '\\': fputs("\\\\", fp); break;
    case '\b': fputs("\\b", fp); break;
    case '\f': fputs("\\f", fp); break;
    case '\n': fputs("\\n", fp); break;
    case '\r': fputs("\\r", fp); break;
    case '\t': fputs("\\t", fp); break;
    default:
      if (*p < 0x20)
        fprintf(fp, "\\u%04x", (unsigned)*p);
      else
        putc(*p, fp);
    }
  }
  putc('"', fp);
}

static void json_newline(pm_json *j, int depth) {
  putc('\n', j->fp);
  for (int i = 0; i < depth; i++) fputs("  ", j->fp);
}

/* Check key against the context, then write separator, indent and key. */
static pm_err json_begin_value(pm_json *j, const char *key) {
  PM_CHECK(j, PM_ERR_ARG, "JSON writer is NULL");
  PM_CHECK(!j->misused, PM_ERR_ARG, "JSON writer for '%s' already failed",
           pm_afile_path(j->file));
  if (j->depth == 0) {
    if (j->complete || key) j->misused = true;
    PM_CHECK(!j->complete, PM_ERR_ARG, "JSON '%s': a second top-level value",
             pm_afile_path(j->file));
    PM_CHECK(!key, PM_ERR_ARG, "JSON '%s': key \"%s\" at the top level",
             pm_afile_path(j->file), key);
    return PM_SUCCESS;
  }
  bool in_object = j->stack[j->depth - 1].close == '}';
  if (in_object != (key != NULL)) {
    j->misused = true;
    return PM_ERROR(PM_ERR_ARG,
                    in_object ? "JSON '%s': object member without a key"
                              : "JSON '%s': key \"%s\" inside an array",
                    pm_afile_path(j->file), key ? key : "");
  }
  if (j->stack[j->depth - 1].count++ > 0) putc(',', j->fp);
  json_newline(j, j->depth);
  if (key) {
    json_escaped(j->fp, key);
    fputs(": ", j->fp);
  }
  return PM_SUCCESS;
}

/* After a value: mark a top-level value complete, check the stream. */
static pm_err json_end_value(pm_json *j) {
  if (j->depth == 0) j->complete = true;
  PM_CHECK(!ferror(j->fp), PM_ERR_IO, "write error on '%s'",
           pm_afile_path(j->file));
  return PM_SUCCESS;
}

static pm_err json_begin(pm_json *j, const char *key, char open, char close) {
  PM_CALL(json_begin_value(j, key));
  if (j->depth >= PM_JSON_MAX_DEPTH) {
    j->misused = true;
    return PM_ERROR(PM_ERR_ARG, "JSON '%s': nesting deeper than %d",
                    pm_afile_path(j->file), PM_JSON_MAX_DEPTH);
  }
  putc(open, j->fp);
  j->stack[j->depth].close = close;
  j->stack[j->depth].count = 0;
  j->depth++;
  PM_CHECK(!ferror(j->fp), PM_ERR_IO, "write error on '%s'",
           pm_afile_path(j->file));
  return PM_SUCCESS;
}

static pm_err json_end(pm_json *j, char close) {
  PM_CHECK(j, PM_ERR_ARG, "JSON writer is NULL");
  PM_CHECK(!j->misused, PM_ERR_ARG, "JSON writer for '%s' already failed",
           pm_afile_path(j->file));
  if (j->depth == 0 || j->stack[j->depth - 1].close != close) {
    j->misused = true;
    return PM_ERROR(PM_ERR_ARG, "JSON '%s': '%c' does not match an open %s",
                    pm_afile_path(j->file), close,
                    close == '}' ? "object" : "array");
  }
  j->depth--;
  if (j->stack[j->depth].count > 0) json_newline(j, j->depth);
  putc(close, j->fp);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_open(const char *path, pm_json **out) {
  pm_err ret = PM_SUCCESS;
  pm_json *j = NULL;
  PM_CHECK(out, PM_ERR_ARG, "pm_json_open: NULL out");
  *out = NULL;
  PM_TRY(PM_ALLOC(j, 1, "JSON writer"));
  PM_TRY(pm_afile_open(path, &j->file));
  j->fp = pm_afile_stream(j->file);
  *out = j;
  j = NULL;
done:
  free(j);
  return ret;
}

pm_err pm_json_begin_object(pm_json *j, const char *key) {
  PM_CALL(json_begin(j, key, '{', '}'));
  return PM_SUCCESS;
}

pm_err pm_json_end_object(pm_json *j) {
  PM_CALL(json_end(j, '}'));
  return PM_SUCCESS;
}

pm_err pm_json_begin_array(pm_json *j, const char *key) {
  PM_CALL(json_begin(j, key, '[', ']'));
  return PM_SUCCESS;
}

pm_err pm_json_end_array(pm_json *j) {
  PM_CALL(json_end(j, ']'));
  return PM_SUCCESS;
}

pm_err pm_json_number(pm_json *j, const char *key, double value) {
  PM_CALL(json_begin_value(j, key));
  if (isfinite(value)) {
    char buf[40]; /* shortest of 15 / 17 digits that reads back exactly */
    snprintf(buf, sizeof buf, "%.15g", value);
    if (strtod(buf, NULL) != value) snprintf(buf, sizeof buf, "%.17g", value);
    fputs(buf, j->fp);
  } else
    fputs("null", j->fp);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_integer(pm_json *j, const char *key, long long value) {
  PM_CALL(json_begin_value(j, key));
  fprintf(j->fp, "%lld", value);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_string(pm_json *j, const char *key, const char *value) {
  PM_CALL(json_begin_value(j, key));
  if (value)
    json_escaped(j->fp, value);
  else
    fputs("null", j->fp);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_bool(pm_json *j, const char *key, bool value) {
  PM_CALL(json_begin_value(j, key));
  fputs(value ? "true" : "false", j->fp);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_null(pm_json *j, const char *key) {
  PM_CALL(json_begin_value(j, key));
  fputs("null", j->fp);
  PM_CALL(json_end_value(j));
  return PM_SUCCESS;
}

pm_err pm_json_close(pm_json *j, bool commit) {
  pm_err ret = PM_SUCCESS;
  if (!j) return PM_SUCCESS;
  if (!commit) {
    pm_afile_abort(j->file);
    goto done;
  }
  if (j->misused || j->depth != 0 || !j->complete) {
    ret = PM_ERROR(PM_ERR_ARG, "JSON '%s' is incomplete (%s): not written",
                   pm_afile_path(j->file),
                   j->misused ? "an earlier call failed"
                   : j->depth ? "unclosed object or array"
                              : "no value");
    pm_afile_abort(j->file);
    goto done;
  }
  putc('\n', j->fp);
  PM_TRY(pm_afile_commit(j->file));
done:
  free(j);
  return ret;
}

pm_err pm_json_run_header(pm_json *j, const char *scene_path, const char *name,
                          const char *method, int n_overrides,
                          char *const *overrides) {
  PM_CALL(pm_json_string(j, "program", "pointmech"));
  PM_CALL(pm_json_string(j, "version", PM_VERSION));
  PM_CALL(pm_json_string(j, "scene", scene_path));
  PM_CALL(pm_json_string(j, "name", name));
  PM_CALL(pm_json_string(j, "method", method));
  PM_CALL(pm_json_begin_array(j, "overrides"));
  for (int k = 0; k < n_overrides; k++)
    PM_CALL(pm_json_string(j, NULL, overrides[k]));
  return pm_json_end_array(j);
}
