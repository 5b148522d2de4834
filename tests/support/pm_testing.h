/* pm_testing: helpers shared by the unit and verification tests (include
 * after cmocka.h): a success check that prints the error message, a
 * failure check on the code and the message, a temporary directory per
 * test (cmocka setup/teardown) removed with everything in it, a file's
 * text and a folder's entries, and reproducible uniform numbers. */
#ifndef PM_TESTING_H
#define PM_TESTING_H

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_error.h"

/* |a - b| <= rel max(|a|, |b|) + abs_tol; NaN fails. */
#define assert_close(a, b, rel, abs_tol)                                       \
  do {                                                                         \
    double a_ = (a), b_ = (b);                                                 \
    if (!(fabs(a_ - b_) <= (rel)*fmax(fabs(a_), fabs(b_)) + (abs_tol)))        \
      fail_msg("%s = %.17g, expected %.17g (%s)", #a, a_, b_, #b);             \
  } while (0)

/* |a - b| <= tol with both values in the message (NaN fails). */
#define assert_near(a, b, tol) pm_test_near((a), (b), (tol), #a, __LINE__)
static inline void pm_test_near(double a, double b, double tol,
                                const char *what, int line) {
  if (!(fabs(a - b) <= tol))
    fail_msg("line %d: %s = %.17g, expected %.17g (tol %g, off by %g)", line,
             what, a, b, tol, fabs(a - b));
}

/* Expect success; on failure show the recorded message. */
#define assert_ok(expr)                                                        \
  do {                                                                         \
    pm_err e_ = (expr);                                                        \
    if (e_ != PM_SUCCESS)                                                      \
      fail_msg("%s: %s\n%s", pm_err_name(e_), pm_error_message(),              \
               pm_error_traceback());                                          \
  } while (0)

/* Expect code and a message containing text. */
#define assert_fails(expr, code, text)                                         \
  do {                                                                         \
    pm_err e_ = (expr);                                                        \
    if (e_ != (code) || !strstr(pm_error_message(), (text)))                   \
      fail_msg("expected %s with '%s', got %s: %s", pm_err_name(code), (text), \
               pm_err_name(e_), pm_error_message());                           \
  } while (0)

static inline void pm_test_remove_tree(const char *path) {
  struct stat st;
  if (lstat(path, &st) != 0) return;
  if (S_ISDIR(st.st_mode)) {
    DIR *d = opendir(path);
    struct dirent *e;
    char sub[1024];
    while (d && (e = readdir(d))) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      int len = snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
      if (len > 0 && (size_t)len < sizeof sub) pm_test_remove_tree(sub);
    }
    if (d) closedir(d);
    rmdir(path);
  } else {
    unlink(path);
  }
}

/* cmocka setup: *state = a new empty directory under /tmp. */
static inline int pm_test_make_dir(void **state) {
  char *dir = malloc(64);
  strcpy(dir, "/tmp/pm_test_XXXXXX");
  if (!mkdtemp(dir)) {
    free(dir);
    return -1;
  }
  *state = dir;
  return 0;
}

/* cmocka teardown: remove the directory of pm_test_make_dir. */
static inline int pm_test_drop_dir(void **state) {
  pm_test_remove_tree(*state);
  free(*state);
  return 0;
}

/* Writes text to dir/name; path receives the full name. */
static inline void pm_test_write_file(const char *dir, const char *name,
                                      const char *text, char path[512]) {
  int len = snprintf(path, 512, "%s/%s", dir, name);
  assert_true(len > 0 && len < 512);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  assert_true(fputs(text, f) >= 0);
  assert_int_equal(fclose(f), 0);
}

/* The whole file at path, NUL-terminated, in a new buffer (the caller
 * frees it); fails the test when it cannot be read. */
static inline char *pm_test_slurp(const char *path) {
  FILE *fp = fopen(path, "r");
  char *buf;
  long n;
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  n = ftell(fp);
  rewind(fp);
  buf = calloc((size_t)n + 1, 1);
  assert_int_equal(fread(buf, 1, (size_t)n, fp), (size_t)n);
  fclose(fp);
  return buf;
}

/* The file at path holds exactly text. */
static inline void pm_test_assert_file(const char *path, const char *text) {
  char *s = pm_test_slurp(path);
  assert_string_equal(s, text);
  free(s);
}

/* Number of entries of folder dir (not . and ..); *tmp, unless tmp is
 * NULL, counts those whose name holds ".tmp.". */
static inline int pm_test_count_entries(const char *dir, int *tmp) {
  DIR *d = opendir(dir);
  struct dirent *e;
  int n = 0;
  assert_non_null(d);
  if (tmp) *tmp = 0;
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    n++;
    if (tmp && strstr(e->d_name, ".tmp.")) (*tmp)++;
  }
  closedir(d);
  return n;
}

/* Deterministic uniform numbers in [0, 1) (xorshift64*): the next of the
 * stream whose state *s is (seeded nonzero). */
static inline double pm_test_uniform(uint64_t *s) {
  *s ^= *s >> 12;
  *s ^= *s << 25;
  *s ^= *s >> 27;
  return (double)((*s * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
}

/* "path:line:col" of the first occurrence of needle in text (where a
 * located message about it points). */
static inline void pm_test_locate(const char *path, const char *text,
                                  const char *needle, char *buf, size_t size) {
  const char *at = strstr(text, needle);
  assert_non_null(at);
  int line = 1;
  const char *bol = text;
  for (const char *c = text; c < at; c++)
    if (*c == '\n') line++, bol = c + 1;
  snprintf(buf, size, "%s:%d:%d", path, line, (int)(at - bol) + 1);
}

#endif
