/* fuzz_file: a private temporary folder for the fuzz harnesses (see
 * fuzz_file.h). */
#define _XOPEN_SOURCE 700
#include "fuzz_file.h"

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[256];
static char path[512];

static int remove_entry(const char *p, const struct stat *st, int flag,
                        struct FTW *ftw) {
  (void)st;
  (void)flag;
  /* The folder itself (level 0) stays: remove_dir removes it last. */
  if (ftw->level > 0) remove(p);
  return 0;
}

void fuzz_clear(void) {
  if (dir[0]) nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

static void remove_dir(void) {
  fuzz_clear();
  if (dir[0]) rmdir(dir);
}

const char *fuzz_dir(void) {
  if (dir[0]) return dir;
  const char *base = "/dev/shm";
  struct stat st;
  if (stat(base, &st) != 0 || !S_ISDIR(st.st_mode) || access(base, W_OK))
    base = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
  snprintf(dir, sizeof dir, "%s/pm-fuzz-XXXXXX", base);
  if (!mkdtemp(dir)) {
    fprintf(stderr, "fuzz: cannot make a folder in %s: %s\n", base,
            strerror(errno));
    abort();
  }
  atexit(remove_dir);
  return dir;
}

const char *fuzz_path(const char *name) {
  snprintf(path, sizeof path, "%s/%s", fuzz_dir(), name);
  return path;
}

const char *fuzz_file(const char *name, const uint8_t *data, size_t size) {
  fuzz_path(name);
  /* Parent folders of a name such as "results/mesh.h5". */
  for (char *s = strchr(path + strlen(dir) + 1, '/'); s;
       s = strchr(s + 1, '/')) {
    *s = '\0';
    mkdir(path, 0700);
    *s = '/';
  }
  FILE *f = fopen(path, "wb");
  if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f)) {
    fprintf(stderr, "fuzz: cannot write %s: %s\n", path, strerror(errno));
    abort();
  }
  return path;
}
