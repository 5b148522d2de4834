/* pm_files: atomic output files (temporary name + rename), mkdir -p, the
 * history CSV, a small streaming JSON writer, and a reader of text tables'
 * data lines. */
#include "pm_files.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

/* ---- Paths ------------------------------------------------------------- */

pm_err pm_path_join(char *buf, size_t size, const char *dir, const char *name) {
  int n;
  PM_CHECK(buf && size > 0 && name, PM_ERR_ARG, "pm_path_join: NULL argument");
  if (!dir || !dir[0])
    n = snprintf(buf, size, "%s", name);
  else if (dir[strlen(dir) - 1] == '/')
    n = snprintf(buf, size, "%s%s", dir, name);
  else
    n = snprintf(buf, size, "%s/%s", dir, name);
  PM_CHECK(n >= 0 && (size_t)n < size, PM_ERR_ARG,
           "path '%s/%s' is too long (%zu bytes at most)", dir ? dir : "", name,
           size - 1);
  return PM_SUCCESS;
}

/* ---- Reading text tables ------------------------------------------------ */

pm_err pm_lines_open(pm_lines *r, const char *path, const char *what) {
  memset(r, 0, sizeof *r);
  r->path = path;
  r->fp = fopen(path, "r");
  PM_CHECK(r->fp, PM_ERR_IO, "cannot open %s '%s': %s", what, path,
           strerror(errno));
  return PM_SUCCESS;
}

pm_err pm_lines_next(pm_lines *r, char **text) {
  ssize_t len;
  *text = NULL;
  while ((len = getline(&r->buf, &r->size, r->fp)) >= 0) {
    r->line++;
    while (len > 0 && strchr(" \t\r\n", r->buf[len - 1])) r->buf[--len] = '\0';
    char *s = r->buf + strspn(r->buf, " \t");
    if (*s == '\0' || *s == '#') continue;
    *text = s;
    return PM_SUCCESS;
  }
  PM_CHECK(!ferror(r->fp), PM_ERR_IO, "read error on '%s' after line %ld",
           r->path, r->line);
  return PM_SUCCESS;
}

void pm_lines_close(pm_lines *r) {
  if (r->fp) fclose(r->fp);
  free(r->buf);
  r->fp = NULL;
  r->buf = NULL;
}

static char *trim(char *s) {
  s += strspn(s, " \t");
  size_t len = strlen(s);
  while (len > 0 && (s[len - 1] == ' ' || s[len - 1] == '\t')) s[--len] = '\0';
  return s;
}

int pm_split_fields(char *s, char **fields, int max) {
  int n = 0;
  for (;;) {
    char *comma = strchr(s, ',');
    if (comma) *comma = '\0';
    if (n == max) return max + 1;
    fields[n++] = trim(s);
    if (!comma) return n;
    s = comma + 1;
  }
}

bool pm_parse_number(const char *s, double *v) {
  char *end;
  s += strspn(s, " \t");
  *v = strtod(s, &end);
  if (end == s) return false;
  end += strspn(end, " \t");
  return *end == '\0';
}

/* ---- Directories -------------------------------------------------------- */

/* mkdir one component; an existing directory is fine. */
static pm_err mkdir_one(const char *path) {
  struct stat st;
  int e;
  if (mkdir(path, 0777) == 0) return PM_SUCCESS;
  e = errno;
  if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return PM_SUCCESS;
  PM_CHECK(e != EEXIST, PM_ERR_IO,
           "cannot create directory '%s': exists and is not a directory", path);
  return PM_ERROR(PM_ERR_IO, "cannot create directory '%s': %s", path,
                  strerror(e));
}

pm_err pm_mkdir_p(const char *dir) {
  char buf[PM_PATH_MAX + 1];
  size_t len;
  PM_CHECK(dir && dir[0], PM_ERR_ARG, "pm_mkdir_p: empty directory name");
  len = strlen(dir);
  PM_CHECK(len <= PM_PATH_MAX, PM_ERR_ARG,
           "directory name too long: '%.64s...'", dir);
  memcpy(buf, dir, len + 1);
  /* Create every prefix ending before a '/', then the whole path. */
  for (size_t i = 1; i < len; i++) {
    if (buf[i] != '/' || buf[i - 1] == '/') continue;
    buf[i] = '\0';
    PM_CALL(mkdir_one(buf));
    buf[i] = '/';
  }
  PM_CALL(mkdir_one(buf));
  return PM_SUCCESS;
}

/* fsync the directory holding path (best effort: errors are ignored, some
 * file systems refuse to sync directories). */
static void sync_parent_dir(const char *path) {
  char dir[PM_PATH_MAX + 1];
  const char *slash = strrchr(path, '/');
  size_t len;
  int fd;
  if (!slash) {
    strcpy(dir, ".");
  } else {
    len = (size_t)(slash - path);
    if (len == 0) len = 1; /* "/file" */
    if (len > PM_PATH_MAX) return;
    memcpy(dir, path, len);
    dir[len] = '\0';
  }
  fd = open(dir, O_RDONLY);
  if (fd < 0) return;
  (void)fsync(fd);
  (void)close(fd);
}

pm_err pm_rename(const char *from, const char *to) {
  PM_CHECK(from && to, PM_ERR_ARG, "pm_rename: NULL path");
  PM_CHECK(rename(from, to) == 0, PM_ERR_IO, "cannot rename '%s' to '%s': %s",
           from, to, strerror(errno));
  sync_parent_dir(to);
  return PM_SUCCESS;
}

pm_err pm_sync_rename(const char *tmp, const char *path) {
  int fd = open(tmp, O_RDONLY | O_CLOEXEC);
  PM_CHECK(fd >= 0, PM_ERR_IO, "cannot reopen '%s' to sync it: %s", tmp,
           strerror(errno));
  int rc = fsync(fd), e = errno;
  close(fd);
  PM_CHECK(rc == 0, PM_ERR_IO, "cannot sync '%s': %s", tmp, strerror(e));
  return pm_rename(tmp, path);
}

/* ---- Atomic files ------------------------------------------------------ */

struct pm_afile {
  FILE *fp;
  char *final_path; /* both point into one allocation: paths[] */
  char *tmp_path;
  char paths[];
};

pm_err pm_afile_open(const char *final_path, pm_afile **out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  size_t len, tmp_size;
  int n;
  PM_CHECK(out, PM_ERR_ARG, "pm_afile_open: NULL out");
  *out = NULL;
  PM_CHECK(final_path && final_path[0], PM_ERR_ARG,
           "pm_afile_open: empty path");
  len = strlen(final_path);
  PM_CHECK(len + 32 <= PM_PATH_MAX, PM_ERR_ARG, "path too long: '%.64s...'",
           final_path);
  tmp_size = len + 32;
  f = malloc(sizeof *f + len + 1 + tmp_size);
  PM_ENSURE(f, PM_ERR_MEMORY, "cannot allocate the handle for '%s'",
            final_path);
  f->fp = NULL;
  f->final_path = f->paths;
  f->tmp_path = f->paths + len + 1;
  memcpy(f->final_path, final_path, len + 1);
  n = snprintf(f->tmp_path, tmp_size, "%s.tmp.%ld", final_path, (long)getpid());
  PM_ENSURE(n > 0 && (size_t)n < tmp_size, PM_ERR_INTERNAL,
            "temporary name of '%s' truncated", final_path);
  f->fp = fopen(f->tmp_path, "w");
  PM_ENSURE(f->fp, PM_ERR_IO, "cannot open '%s' for writing: %s", f->tmp_path,
            strerror(errno));
  *out = f;
  f = NULL;
done:
  free(f);
  return ret;
}

FILE *pm_afile_stream(pm_afile *f) { return f ? f->fp : NULL; }

const char *pm_afile_path(const pm_afile *f) {
  return f ? f->final_path : NULL;
}

pm_err pm_afile_commit(pm_afile *f) {
  pm_err ret = PM_SUCCESS;
  FILE *fp;
  if (!f) return PM_SUCCESS;
  fp = f->fp;
  PM_ENSURE(!ferror(fp), PM_ERR_IO, "write error on '%s'", f->tmp_path);
  PM_ENSURE(fflush(fp) == 0, PM_ERR_IO, "cannot write '%s': %s", f->tmp_path,
            strerror(errno));
  PM_ENSURE(fsync(fileno(fp)) == 0, PM_ERR_IO, "cannot sync '%s': %s",
            f->tmp_path, strerror(errno));
  f->fp = NULL; /* closed by fclose even when it fails */
  PM_ENSURE(fclose(fp) == 0, PM_ERR_IO, "cannot close '%s': %s", f->tmp_path,
            strerror(errno));
  PM_TRY(pm_rename(f->tmp_path, f->final_path));
done:
  if (ret != PM_SUCCESS) {
    if (f->fp) fclose(f->fp);
    unlink(f->tmp_path);
  }
  free(f);
  return ret;
}

void pm_afile_abort(pm_afile *f) {
  if (!f) return;
  if (f->fp) fclose(f->fp);
  unlink(f->tmp_path);
  free(f);
}

/* ---- History CSV ------------------------------------------------------- */

struct pm_history {
  FILE *fp;
  int ncols;
  char path[PM_PATH_MAX + 1];
};

/* Write a CSV field, quoting it when it holds a separator. */
static void csv_field(FILE *fp, const char *s) {
  if (!strpbrk(s, ",\"\r\n")) {
    fputs(s, fp);
    return;
  }
  putc('"', fp);
  for (; *s; s++) {
    if (*s == '"') putc('"', fp);
    putc(*s, fp);
  }
  putc('"', fp);
}

static void csv_header(FILE *fp, int ncols, const char *const *names) {
  for (int i = 0; i < ncols; i++) {
    if (i) putc(',', fp);
    csv_field(fp, names[i]);
  }
  putc('\n', fp);
}

/* history.csv of a resumed run: the same header, and its first keep_rows
 * rows, rewritten whole (rows after them came after the checkpoint). */
static pm_err history_truncate(const char *path, int ncols,
                               const char *const *names, long keep_rows) {
  pm_err ret = PM_SUCCESS;
  FILE *in = NULL;
  pm_afile *out = NULL;
  char *line = NULL, *header = NULL;
  size_t cap = 0, hcap = 0;
  long rows = 0;
  in = fopen(path, "r");
  PM_CHECK(in, PM_ERR_IO, "cannot open '%s' to resume it: %s", path,
           strerror(errno));
  /* The header must be the one this run writes. */
  FILE *h = open_memstream(&header, &hcap);
  PM_ENSURE(h, PM_ERR_MEMORY, "cannot build the header of '%s'", path);
  csv_header(h, ncols, names);
  fclose(h);
  PM_ENSURE(getline(&line, &cap, in) >= 0 && strcmp(line, header) == 0,
            PM_ERR_IO,
            "'%s' does not start with the columns this run writes: it "
            "belongs to another scene or program version",
            path);
  PM_TRY(pm_afile_open(path, &out));
  FILE *fp = pm_afile_stream(out);
  fputs(header, fp);
  while (rows < keep_rows && getline(&line, &cap, in) >= 0) {
    PM_ENSURE(strchr(line, '\n'), PM_ERR_IO,
              "'%s' row %ld is cut short: the checkpoint names %ld rows", path,
              rows + 1, keep_rows);
    fputs(line, fp);
    rows++;
  }
  PM_ENSURE(rows == keep_rows, PM_ERR_IO,
            "'%s' holds %ld rows, the checkpoint names %ld", path, rows,
            keep_rows);
  pm_afile *f = out;
  out = NULL;
  PM_TRY(pm_afile_commit(f));
done:
  if (in) fclose(in);
  pm_afile_abort(out);
  free(line);
  free(header);
  return ret;
}

pm_err pm_history_open(const char *dir, int ncols, const char *const *names,
                       long keep_rows, pm_history **out) {
  pm_err ret = PM_SUCCESS;
  pm_history *h = NULL;
  PM_CHECK(out, PM_ERR_ARG, "pm_history_open: NULL out");
  *out = NULL;
  PM_CHECK(ncols >= 1 && names, PM_ERR_ARG,
           "history needs at least one column name (got %d)", ncols);
  for (int i = 0; i < ncols; i++)
    PM_CHECK(names[i], PM_ERR_ARG, "history column %d has no name", i);
  PM_TRY(PM_ALLOC(h, 1, "history writer"));
  h->ncols = ncols;
  PM_TRY(pm_path_join(h->path, sizeof h->path, dir, "history.csv"));
  if (keep_rows >= 0) {
    PM_TRY(history_truncate(h->path, ncols, names, keep_rows));
    h->fp = fopen(h->path, "a");
  } else {
    /* Written in place: every row synced is a whole result. */
    h->fp = fopen(h->path, "w");
  }
  PM_ENSURE(h->fp, PM_ERR_IO, "cannot open '%s' for writing: %s", h->path,
            strerror(errno));
  if (keep_rows < 0) csv_header(h->fp, ncols, names);
  PM_TRY(pm_history_sync(h));
  *out = h;
  h = NULL;
done:
  if (h && h->fp) fclose(h->fp);
  free(h);
  return ret;
}

pm_err pm_history_row(pm_history *h, const double *values) {
  PM_CHECK(h && values, PM_ERR_ARG, "pm_history_row: NULL argument");
  for (int i = 0; i < h->ncols; i++)
    if (fprintf(h->fp, i ? ",%.10g" : "%.10g", values[i]) < 0) break;
  PM_CHECK(putc('\n', h->fp) != EOF && !ferror(h->fp), PM_ERR_IO,
           "cannot write a row of '%s': %s", h->path, strerror(errno));
  return PM_SUCCESS;
}

pm_err pm_history_sync(pm_history *h) {
  PM_CHECK(h, PM_ERR_ARG, "pm_history_sync: NULL history");
  PM_CHECK(fflush(h->fp) == 0 && !ferror(h->fp), PM_ERR_IO,
           "cannot write '%s': %s", h->path, strerror(errno));
  PM_CHECK(fsync(fileno(h->fp)) == 0, PM_ERR_IO, "cannot sync '%s': %s",
           h->path, strerror(errno));
  return PM_SUCCESS;
}

int pm_history_ncols(const pm_history *h) { return h ? h->ncols : 0; }

pm_err pm_history_close(pm_history *h) {
  pm_err ret = PM_SUCCESS;
  if (!h) return PM_SUCCESS;
  ret = pm_history_sync(h);
  if (fclose(h->fp) != 0 && ret == PM_SUCCESS)
    ret =
        PM_ERROR(PM_ERR_IO, "cannot close '%s': %s", h->path, strerror(errno));
  free(h);
  return ret;
}

/* ---- JSON writer ------------------------------------------------------- */

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

/* ---- Output folders ----------------------------------------------------- */

struct pm_outdir {
  int fd;       /* the lock file, flock'ed for the run's life */
  bool created; /* the claim created the folder */
  char dir[PM_PATH_MAX + 1];
};

/* The files a run writes in its folder (results/ holds the frames). */
static const char *const run_files[] = {"summary.json", "history.csv",
                                        "results.h5", "results.xdmf",
                                        "checkpoint.h5"};
#define N_RUN_FILES (sizeof run_files / sizeof *run_files)
#define LOCK_NAME ".pointmech.lock"

void pm_summary_status(const char *dir, char *buf, size_t size) {
  char path[PM_PATH_MAX + 1], line[512];
  buf[0] = '\0';
  if (pm_path_join(path, sizeof path, dir, "summary.json")) return;
  FILE *fp = fopen(path, "r");
  if (!fp) return;
  while (fgets(line, sizeof line, fp)) {
    char *p = strstr(line, "\"status\": \"");
    if (!p) continue;
    p += 11;
    size_t n = strcspn(p, "\"");
    snprintf(buf, size, "%.*s", (int)(n < size ? n : size - 1), p);
    break;
  }
  fclose(fp);
}

/* Remove dir/name when it exists; a folder (results/) with its files. */
static pm_err remove_entry(const char *dir, const char *name) {
  char path[PM_PATH_MAX + 1], child[PM_PATH_MAX + 1];
  struct stat st;
  PM_CALL(pm_path_join(path, sizeof path, dir, name));
  if (lstat(path, &st) != 0) return PM_SUCCESS;
  if (S_ISDIR(st.st_mode)) {
    DIR *d = opendir(path);
    PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
    struct dirent *e;
    pm_err ret = PM_SUCCESS;
    while ((e = readdir(d)) && ret == PM_SUCCESS) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      ret = pm_path_join(child, sizeof child, path, e->d_name);
      if (ret == PM_SUCCESS && unlink(child) != 0)
        ret = PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", child,
                       strerror(errno));
    }
    closedir(d);
    PM_CALL(ret);
    PM_CHECK(rmdir(path) == 0, PM_ERR_IO, "cannot remove '%s': %s", path,
             strerror(errno));
    return PM_SUCCESS;
  }
  PM_CHECK(unlink(path) == 0, PM_ERR_IO, "cannot remove '%s': %s", path,
           strerror(errno));
  return PM_SUCCESS;
}

/* Does dir hold an earlier run's files?  *which names the first. */
static bool holds_run(const char *dir, const char **which) {
  char path[PM_PATH_MAX + 1];
  struct stat st;
  for (size_t k = 0; k < N_RUN_FILES; k++)
    if (!pm_path_join(path, sizeof path, dir, run_files[k]) &&
        stat(path, &st) == 0) {
      *which = run_files[k];
      return true;
    }
  if (!pm_path_join(path, sizeof path, dir, "results") &&
      stat(path, &st) == 0) {
    *which = "results/";
    return true;
  }
  return false;
}

/* Is name a temporary file of a run: RUNFILE.tmp.PID? */
static bool run_tmp_name(const char *name) {
  for (size_t k = 0; k < N_RUN_FILES; k++) {
    size_t len = strlen(run_files[k]);
    if (strncmp(name, run_files[k], len) || strncmp(name + len, ".tmp.", 5))
      continue;
    const char *pid = name + len + 5;
    return *pid && strspn(pid, "0123456789") == strlen(pid);
  }
  return false;
}

/* Remove the temporary files (RUNFILE.tmp.PID) a killed run left in dir;
 * nothing else of the folder's is touched. */
static pm_err drop_tmp(const char *dir) {
  DIR *d = opendir(dir);
  PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", dir, strerror(errno));
  struct dirent *e;
  char path[PM_PATH_MAX + 1];
  pm_err ret = PM_SUCCESS;
  while ((e = readdir(d)) && ret == PM_SUCCESS) {
    struct stat st;
    if (!run_tmp_name(e->d_name) ||
        pm_path_join(path, sizeof path, dir, e->d_name) != PM_SUCCESS ||
        lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
      continue;
    if (unlink(path) != 0 && errno != ENOENT)
      ret =
          PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", path, strerror(errno));
  }
  closedir(d);
  return ret;
}

static pm_err take_lock(const char *dir, int *fd_out) {
  char path[PM_PATH_MAX + 1], pid[32];
  *fd_out = -1;
  PM_CALL(pm_path_join(path, sizeof path, dir, LOCK_NAME));
  int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  PM_CHECK(fd >= 0, PM_ERR_IO, "output folder '%s' is not writable: %s", dir,
           strerror(errno));
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ssize_t n = pread(fd, pid, sizeof pid - 1, 0);
    pid[n > 0 ? n : 0] = '\0';
    pid[strcspn(pid, "\n")] = '\0';
    close(fd);
    return PM_ERROR(PM_ERR_IO,
                    "output folder '%s' is in use by a running pointmech (pid "
                    "%s): wait for it, stop it, or choose another --out",
                    dir, pid[0] ? pid : "unknown");
  }
  int n = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid, (size_t)n, 0) != n) {
    int e = errno;
    close(fd);
    return PM_ERROR(PM_ERR_IO, "cannot write the lock file '%s': %s", path,
                    strerror(e));
  }
  *fd_out = fd;
  return PM_SUCCESS;
}

pm_err pm_outdir_claim(const char *dir, pm_outdir_mode mode, pm_outdir **out) {
  pm_err ret = PM_SUCCESS;
  pm_outdir *d = NULL;
  const char *which = NULL;
  struct stat st;
  PM_CHECK(out && dir && dir[0], PM_ERR_ARG, "pm_outdir_claim: no folder");
  PM_CHECK(strlen(dir) < sizeof d->dir - 32, PM_ERR_ARG,
           "output folder name too long: '%.64s...'", dir);
  *out = NULL;
  bool existed = stat(dir, &st) == 0;
  if (mode == PM_OUTDIR_RESUME)
    PM_CHECK(existed && S_ISDIR(st.st_mode), PM_ERR_IO,
             "cannot resume '%s': %s", dir,
             existed ? "not a folder" : "no such folder");
  else
    PM_CALL(pm_mkdir_p(dir));
  PM_CHECK(access(dir, W_OK | X_OK) == 0, PM_ERR_IO,
           "output folder '%s' is not writable: %s", dir, strerror(errno));
  PM_TRY(PM_ALLOC(d, 1, "output folder"));
  d->fd = -1;
  d->created = !existed;
  snprintf(d->dir, sizeof d->dir, "%s", dir);
  PM_TRY(take_lock(dir, &d->fd));
  if (mode == PM_OUTDIR_NEW && holds_run(dir, &which)) {
    char status[64];
    pm_summary_status(dir, status, sizeof status);
    PM_ENSURE(false, PM_ERR_IO,
              "output folder '%s' already holds the results of another run "
              "(%s%s%s%s): pass --overwrite to replace them, `pointmech "
              "resume %s` to continue that run, or choose another --out",
              dir, which, status[0] ? ", status \"" : "", status,
              status[0] ? "\"" : "", dir);
  }
  PM_TRY(drop_tmp(dir));
  if (mode == PM_OUTDIR_OVERWRITE) {
    for (size_t k = 0; k < N_RUN_FILES; k++)
      PM_TRY(remove_entry(dir, run_files[k]));
    PM_TRY(remove_entry(dir, "results"));
  }
  *out = d;
  d = NULL;
done:
  pm_outdir_release(d);
  return ret;
}

void pm_outdir_release(pm_outdir *d) {
  if (!d) return;
  /* A folder this claim created and nothing was written to goes again. */
  if (d->created && d->fd >= 0) {
    char path[PM_PATH_MAX + 1];
    DIR *dd = opendir(d->dir);
    int others = 0;
    struct dirent *e;
    while (dd && (e = readdir(dd)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
          strcmp(e->d_name, LOCK_NAME))
        others++;
    if (dd) closedir(dd);
    if (dd && others == 0 &&
        pm_path_join(path, sizeof path, d->dir, LOCK_NAME) == PM_SUCCESS &&
        unlink(path) == 0)
      rmdir(d->dir);
  }
  if (d->fd >= 0) close(d->fd); /* releases the lock */
  free(d);
}

pm_err pm_read_text(const char *path, const char *what, char **text,
                    size_t *len) {
  pm_err ret = PM_SUCCESS;
  FILE *f = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0;
  *text = NULL;
  *len = 0;
  PM_ENSURE(f, PM_ERR_IO, "cannot open %s %s: %s", what, path, strerror(errno));
  for (;;) {
    if (n + 4096 + 1 > cap) {
      cap = 2 * (n + 4096 + 1);
      char *grown = realloc(buf, cap);
      PM_ENSURE(grown, PM_ERR_MEMORY, "cannot read %s %s: out of memory", what,
                path);
      buf = grown;
    }
    size_t got = fread(buf + n, 1, cap - n - 1, f);
    n += got;
    if (got == 0) break;
  }
  PM_ENSURE(!ferror(f), PM_ERR_IO, "cannot read %s %s: %s", what, path,
            strerror(errno));
  buf[n] = '\0';
  *text = buf;
  *len = n;
  buf = NULL;
done:
  free(buf);
  if (f) fclose(f);
  return ret;
}
