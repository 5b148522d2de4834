/* fuzz_file: a private temporary folder for the fuzz harnesses (see
 * fuzz_file.h). */
#define _XOPEN_SOURCE 700
#include "fuzz_file.h"

#include <errno.h>
#include <ftw.h>
#include <pthread.h>
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

/* The sanitizers' hook, which libFuzzer sets to write the input that
 * killed the process (absent without a sanitizer). */
void __sanitizer_set_death_callback(void (*callback)(void))
    __attribute__((weak));

/* The input being read, for a child that dies with a sanitizer's report:
 * a refusal to the program, but the report may be of the project's code
 * the child ran (gm_gmsh_read, the vetting), so the input is kept for
 * triage as PM_FUZZ_CHILD_FINDINGS/child-PID. */
static const uint8_t *input;
static size_t input_size;

static void child_died(void) {
  const char *dir = getenv("PM_FUZZ_CHILD_FINDINGS");
  char at[512];
  if (!dir || !input) return;
  snprintf(at, sizeof at, "%s/child-%ld", dir, (long)getpid());
  FILE *f = fopen(at, "wb");
  if (!f) return;
  fwrite(input, 1, input_size, f);
  fclose(f);
}

static void in_child(void) {
  if (__sanitizer_set_death_callback)
    __sanitizer_set_death_callback(child_died);
}

void fuzz_isolate(const uint8_t *data, size_t size) {
  static bool done = false;
  input = data;
  input_size = size;
  if (done) return;
  done = true;
  setenv("PM_ISOLATE_CPU_SECONDS", "1", 0);
  pthread_atfork(NULL, NULL, in_child);
}

#define SEP "\n--pm-fuzz-file--\n"
#define MAX_FRAMES 8

/* The next part of the input from *at (to the separator or the end). */
static size_t next_part(const uint8_t *data, size_t size, size_t *at,
                        size_t *len) {
  const size_t sep = sizeof SEP - 1, start = *at;
  for (size_t k = start; k + sep <= size; k++)
    if (memcmp(data + k, SEP, sep) == 0) {
      *len = k - start;
      *at = k + sep;
      return start;
    }
  *len = size - start;
  *at = size + 1;
  return start;
}

bool fuzz_results_folder(const uint8_t *data, size_t size, long *n_points,
                         long *n_frames) {
  if (size < 4) return false;
  *n_points = (long)((uint32_t)data[0] | (uint32_t)data[1] << 8 |
                     (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24);
  size_t at = 4, len;
  long n = -2; /* the index and the mesh come first */
  char name[64];
  while (at <= size && n < MAX_FRAMES) {
    size_t start = next_part(data, size, &at, &len);
    if (n == -2)
      snprintf(name, sizeof name, "results.h5");
    else if (n == -1)
      snprintf(name, sizeof name, "results/mesh.h5");
    else
      snprintf(name, sizeof name, "results/frame_%06ld.h5", n);
    (void)fuzz_file(name, data + start, len);
    n++;
  }
  *n_frames = n;
  return true;
}
