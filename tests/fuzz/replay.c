/* replay: runs a fuzz harness (fuzz_TARGET.c) over every file of the
 * folders given (their subfolders aside), without a fuzzer, so that a build
 * with any compiler replays the corpus and the regression inputs.  Exits 1 when
 * a folder cannot be read or holds no input; a crash or a sanitizer report is
 * the failure the replay exists to catch. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Feed one file to the harness; 0 on success. */
static int replay_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "replay: cannot open %s\n", path);
    return 1;
  }
  uint8_t *buf = NULL;
  size_t size = 0, cap = 0;
  int ret = 0;
  for (;;) {
    if (size + 4096 > cap) {
      cap = 2 * (size + 4096);
      uint8_t *grown = realloc(buf, cap);
      if (!grown) {
        ret = 1;
        goto done;
      }
      buf = grown;
    }
    size_t got = fread(buf + size, 1, cap - size, f);
    size += got;
    if (got == 0) break;
  }
  if (ferror(f)) {
    fprintf(stderr, "replay: cannot read %s\n", path);
    ret = 1;
    goto done;
  }
  LLVMFuzzerTestOneInput(buf, size);
done:
  free(buf);
  fclose(f);
  return ret;
}

/* Replay every file of dir (README files and folders aside); *count adds the
 * inputs replayed. */
static int replay_dir(const char *dir, long *count) {
  DIR *d = opendir(dir);
  if (!d) {
    fprintf(stderr, "replay: cannot open folder %s\n", dir);
    return 1;
  }
  int ret = 0;
  char path[4096];
  for (struct dirent *e; (e = readdir(d)) && !ret;) {
    if (e->d_name[0] == '.' || strncmp(e->d_name, "README", 6) == 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) continue;
    ret = replay_file(path);
    (*count)++;
  }
  closedir(d);
  return ret;
}

int main(int argc, char **argv) {
  long total = 0;
  for (int k = 1; k < argc; k++) {
    long count = 0;
    if (replay_dir(argv[k], &count)) return 1;
    if (count == 0) {
      fprintf(stderr, "replay: no inputs in %s\n", argv[k]);
      return 1;
    }
    printf("replayed %ld inputs from %s\n", count, argv[k]);
    total += count;
  }
  if (total == 0) {
    fprintf(stderr, "usage: replay DIR...\n");
    return 1;
  }
  return 0;
}
