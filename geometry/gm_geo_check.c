/* gm_geo_check: a gmsh script (.geo) read as text before gmsh runs it.
 * gmsh's script language can start programs (SystemCall,
 * NonBlockingSystemCall, OnelabRun, a solver's executable option); a scene
 * names its .geo like any input, so a .geo that would run a program is
 * refused, with its file and line, and so is one that includes or merges a
 * file this check cannot follow.  The files a .geo includes or merges by a
 * plain string are checked the same way. */
#include "gm_gmsh.h"

#include <ctype.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "pm_files.h"
#include "pm_table_read.h"

#define GEO_DEPTH 8 /* nested Include / Merge followed */

/* Words that start a program, matched whole outside comments. */
static const char *const running[] = {"SystemCall", "NonBlockingSystemCall",
                                      "OnelabRun", "Executable", NULL};
/* Words that read another file. */
static const char *const reading[] = {"Include", "Merge",
                                      "MergeWithBoundingBox", NULL};

static bool ends_geo(const char *path) {
  size_t n = strlen(path);
  return n >= 4 && strcasecmp(path + n - 4, ".geo") == 0;
}

static bool ident(int c) { return isalnum(c) || c == '_'; }

/* The word at s (whole: not inside a longer identifier) among list. */
static const char *word_at(const char *s, const char *start,
                           const char *const *list) {
  if (s > start && ident((unsigned char)s[-1])) return NULL;
  for (int k = 0; list[k]; k++) {
    size_t n = strlen(list[k]);
    if (strncmp(s, list[k], n) == 0 && !ident((unsigned char)s[n]))
      return list[k];
  }
  return NULL;
}

static long line_of(const char *start, const char *s) {
  long line = 1;
  for (const char *p = start; p < s; p++) line += *p == '\n';
  return line;
}

/* via: where path was included from, for messages ("" at the top). */
static pm_err check(const char *path, const char *via, int depth);

/* After Include / Merge at s (of word w): a plain "string" naming a file
 * beside path, which is checked in turn when it is a .geo. */
static pm_err check_included(const char *path, const char *via,
                             const char *text, const char *s, const char *w,
                             int depth) {
  const char *p = s + strlen(w);
  while (isspace((unsigned char)*p)) p++;
  const char *q = *p == '"' ? strchr(p + 1, '"') : NULL;
  PM_CHECK(q && memchr(p + 1, '\n', (size_t)(q - p - 1)) == NULL, PM_ERR_MESH,
           "%s:%ld: %s of a file not named by a plain string: the gmsh "
           "script cannot be checked before it runs%s",
           path, line_of(text, s), w, via);
  char name[PM_PATH_MAX + 1], full[PM_PATH_MAX + 1];
  PM_CHECK((size_t)(q - p - 1) < sizeof name, PM_ERR_MESH,
           "%s:%ld: %s of a file name too long", path, line_of(text, s), w);
  memcpy(name, p + 1, (size_t)(q - p - 1));
  name[q - p - 1] = '\0';
  if (!ends_geo(name)) return PM_SUCCESS; /* data, not a script */
  if (name[0] == '/') {
    snprintf(full, sizeof full, "%s", name);
  } else {
    const char *slash = strrchr(path, '/');
    int dir = slash ? (int)(slash - path) : 1;
    PM_CHECK(snprintf(full, sizeof full, "%.*s/%s", dir, slash ? path : ".",
                      name) < (int)sizeof full,
             PM_ERR_MESH, "%s:%ld: %s of a file name too long", path,
             line_of(text, s), w);
  }
  char from[2 * PM_PATH_MAX + 64];
  snprintf(from, sizeof from, " (included from %s:%ld%s)", path,
           line_of(text, s), via[0] ? ", and on" : "");
  return check(full, from, depth + 1);
}

static pm_err check(const char *path, const char *via, int depth) {
  pm_err ret = PM_SUCCESS;
  char *text = NULL;
  size_t len = 0;
  PM_CHECK(depth <= GEO_DEPTH, PM_ERR_MESH,
           "'%s': gmsh scripts included more than %d deep", path, GEO_DEPTH);
  PM_CALL(pm_read_text(path, "gmsh script", &text, &len));
  for (const char *s = text; *s; s++) {
    if (s[0] == '/' && s[1] == '/') { /* a comment to the end of the line */
      while (*s && *s != '\n') s++;
      if (!*s) break;
      continue;
    }
    if (s[0] == '/' && s[1] == '*') {
      const char *e = strstr(s + 2, "*/");
      if (!e) break;
      s = e + 1;
      continue;
    }
    if (*s == '"') { /* a string: its words run nothing */
      const char *e = strchr(s + 1, '"');
      if (!e) break;
      s = e;
      continue;
    }
    const char *w = word_at(s, text, running);
    PM_ENSURE(!w, PM_ERR_MESH,
              "%s:%ld: the gmsh script calls %s, which starts a program: "
              "refused (mesh it with gmsh yourself and give the .msh)%s",
              path, line_of(text, s), w, via);
    if ((w = word_at(s, text, reading)))
      PM_TRY(check_included(path, via, text, s, w, depth));
  }
done:
  free(text);
  return ret;
}

pm_err gm_geo_check(const char *path) {
  return ends_geo(path) ? check(path, "", 0) : PM_SUCCESS;
}
