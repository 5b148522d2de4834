/* pm_h5_vet: HDF5 files read whole in a child process before the process
 * trusts them (see pm_h5_vet.h). */
#define _DEFAULT_SOURCE
#include "pm_h5_vet.h"

#include <dirent.h>
#include <errno.h>
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_isolate.h"
#include "pm_output_impl.h"

/* Guards against a damaged file's cycles and sizes: links followed from
 * the root, objects visited, and the bytes of one value read. */
#define VET_DEPTH 16
#define VET_OBJECTS 100000
#define VET_STRING_MAX 4096

typedef struct {
  const char *const *paths;
  int n;
  bool data;
  char *current; /* shared with the parent: the file being read */
  const char *what;
  pm_err code, err; /* the refusal's code; the first value HDF5 failed on */
  long objects;
  size_t value_max; /* bytes: the file's size (a value is in the file) */
  /* The objects reached by hard links, by address, with the shallowest
   * depth each was walked from: a group that tracks its links' creation
   * order lists every link twice (by name, by creation order), and an
   * object is one object however often it is linked. */
  haddr_t *seen_addr;
  int *seen_depth;
  size_t seen_cap, seen_n;
} vet_arg;

static void vet_object(vet_arg *a, hid_t obj, const char *name, int depth);

/* HDF5 failed to read a value the readers may read (it may have needed
 * more memory than the child has): the file is refused. */
static void read_failed(vet_arg *a, hid_t id, bool attr, const char *name) {
  char obj[256] = "", why[512];
  if (a->err) return;
  /* HDF5's message before another call clears its error stack. */
  snprintf(why, sizeof why, "%s", pm_h5_message());
  if (attr) H5Iget_name(id, obj, sizeof obj);
  a->err = PM_ERROR(a->code,
                    "%s: HDF5 cannot read %s %s%s%s (%s): the file is damaged "
                    "or not %s",
                    a->current, attr ? "attribute" : "dataset", name,
                    attr ? " of " : "", attr ? obj : "", why, a->what);
}

/* An attribute or a dataset's values, read in the native type of its own
 * (strings of variable length as the readers read them). */
static void read_values(vet_arg *a, hid_t id, bool attr, const char *name) {
  /* A dataset's shape and type are read whatever a->data says. */
  hid_t type = attr ? H5Aget_type(id) : H5Dget_type(id);
  hid_t space = attr ? H5Aget_space(id) : H5Dget_space(id);
  hid_t mem = -1;
  hssize_t count = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
  if (type < 0 || count < 0 || (!attr && !a->data)) goto done;
  const H5T_class_t cls = H5Tget_class(type);
  if (cls == H5T_STRING && H5Tis_variable_str(type) > 0) {
    if (count < 1 || count > VET_STRING_MAX) goto done;
    char **s = calloc((size_t)count, sizeof *s);
    if (!s) goto done;
    herr_t r = attr ? H5Aread(id, type, s)
                    : H5Dread(id, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, s);
    if (r >= 0)
      for (hssize_t k = 0; k < count; k++)
        if (s[k]) H5free_memory(s[k]);
    free(s);
    if (r < 0) read_failed(a, id, attr, name);
    goto done;
  }
  if (cls != H5T_INTEGER && cls != H5T_FLOAT && cls != H5T_STRING) goto done;
  mem = H5Tget_native_type(type, H5T_DIR_DEFAULT);
  const size_t size = mem >= 0 ? H5Tget_size(mem) : 0;
  if (size == 0 || (size_t)count > a->value_max / size) goto done;
  void *buf = malloc((size_t)count * size + 1);
  if (!buf) goto done;
  herr_t r = attr ? H5Aread(id, mem, buf)
                  : H5Dread(id, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
  free(buf);
  if (r < 0) read_failed(a, id, attr, name);
done:
  pm_h5_close_quiet(&mem);
  pm_h5_close_quiet(&space);
  pm_h5_close_quiet(&type);
}

static herr_t vet_attr(hid_t loc, const char *name, const H5A_info_t *info,
                       void *p) {
  (void)info;
  hid_t attr = H5Aopen(loc, name, H5P_DEFAULT);
  if (attr >= 0) read_values(p, attr, true, name);
  pm_h5_close_quiet(&attr);
  return ((vet_arg *)p)->err ? 1 : 0;
}

typedef struct {
  vet_arg *a;
  int depth;
} link_walk;

/* Whether the object at addr was walked from depth or nearer to the root
 * (its links then reached as deep as they can be again); if not, it is
 * recorded as walked from depth.  The table is open-addressed and doubles
 * at half full; without memory an object is walked again. */
static bool walked(vet_arg *a, haddr_t addr, int depth) {
  if (2 * (a->seen_n + 1) > a->seen_cap) {
    const size_t cap = a->seen_cap ? 2 * a->seen_cap : 64;
    haddr_t *ad = malloc(cap * sizeof *ad);
    int *de = malloc(cap * sizeof *de);
    if (!ad || !de) {
      free(ad);
      free(de);
      return false;
    }
    for (size_t k = 0; k < cap; k++) ad[k] = HADDR_UNDEF;
    for (size_t k = 0; k < a->seen_cap; k++) {
      if (a->seen_addr[k] == HADDR_UNDEF) continue;
      size_t h = (size_t)(a->seen_addr[k] * 0x9e3779b97f4a7c15u) & (cap - 1);
      while (ad[h] != HADDR_UNDEF) h = (h + 1) & (cap - 1);
      ad[h] = a->seen_addr[k];
      de[h] = a->seen_depth[k];
    }
    free(a->seen_addr);
    free(a->seen_depth);
    a->seen_addr = ad;
    a->seen_depth = de;
    a->seen_cap = cap;
  }
  size_t h = (size_t)(addr * 0x9e3779b97f4a7c15u) & (a->seen_cap - 1);
  while (a->seen_addr[h] != HADDR_UNDEF && a->seen_addr[h] != addr)
    h = (h + 1) & (a->seen_cap - 1);
  if (a->seen_addr[h] == addr) {
    if (a->seen_depth[h] <= depth) return true;
    a->seen_depth[h] = depth;
    return false;
  }
  a->seen_addr[h] = addr;
  a->seen_depth[h] = depth;
  a->seen_n++;
  return false;
}

/* A link of a group: a soft link's value, and the object a hard or soft
 * link leads to (an external link's file is vetted by itself). */
static herr_t vet_link(hid_t group, const char *name, const H5L_info_t *info,
                       void *p) {
  link_walk *w = p;
  if (w->a->objects >= VET_OBJECTS) return 1;
  if (info->type == H5L_TYPE_SOFT || info->type == H5L_TYPE_EXTERNAL) {
    size_t n = info->u.val_size;
    char *val = n > 0 && n <= VET_STRING_MAX ? malloc(n) : NULL;
    if (val) H5Lget_val(group, name, val, n, H5P_DEFAULT);
    free(val);
  }
  if (info->type != H5L_TYPE_HARD && info->type != H5L_TYPE_SOFT) return 0;
  if (info->type == H5L_TYPE_HARD && info->u.address != HADDR_UNDEF &&
      walked(w->a, info->u.address, w->depth + 1))
    return 0;
  hid_t obj = H5Oopen(group, name, H5P_DEFAULT);
  if (obj >= 0) vet_object(w->a, obj, name, w->depth + 1);
  pm_h5_close_quiet(&obj);
  return w->a->err ? 1 : 0;
}

/* HDF5 failed to list what obj holds: a reader that opens one by name
 * would meet what the listing did not reach (a damaged attribute message
 * hid an attribute whose string loops HDF5), so the file is refused. */
static void list_failed(vet_arg *a, hid_t obj, const char *what) {
  char name[256] = "", why[512];
  if (a->err) return;
  snprintf(why, sizeof why, "%s", pm_h5_message());
  H5Iget_name(obj, name, sizeof name);
  a->err = PM_ERROR(a->code,
                    "%s: HDF5 cannot list the %s of %s (%s): the file is "
                    "damaged or not %s",
                    a->current, what, name[0] ? name : "/", why, a->what);
}

/* An object: its attributes, a group's links, a dataset's values. */
static void vet_object(vet_arg *a, hid_t obj, const char *name, int depth) {
  if (a->err || depth > VET_DEPTH || a->objects++ >= VET_OBJECTS) return;
  if (H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, NULL, vet_attr, a) < 0)
    list_failed(a, obj, "attributes");
  const H5I_type_t kind = H5Iget_type(obj);
  if (!a->err && (kind == H5I_GROUP || kind == H5I_FILE)) {
    H5G_info_t info;
    H5Gget_info(obj, &info);
    link_walk w = {a, depth};
    if (H5Literate(obj, H5_INDEX_NAME, H5_ITER_INC, NULL, vet_link, &w) < 0)
      list_failed(a, obj, "links");
    /* By creation order only where the group tracks it: no failure of
     * this listing is a damage. */
    H5Literate(obj, H5_INDEX_CRT_ORDER, H5_ITER_INC, NULL, vet_link, &w);
  } else if (kind == H5I_DATASET) {
    read_values(a, obj, false, name);
  }
}

static pm_err vet_files(vet_arg *a) {
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  for (int k = 0; k < a->n; k++) {
    struct stat st;
    if (stat(a->paths[k], &st) != 0 || !S_ISREG(st.st_mode)) continue;
    snprintf(a->current, PM_PATH_MAX + 1, "%s", a->paths[k]);
    pm_isolate_cpu_limit(PM_H5_VET_CPU_SECONDS);
    /* What HDF5 needs of memory follows the file's size: a value that
     * claims more than is in the file fails to allocate, cleanly. */
    pm_isolate_memory_limit(((size_t)1 << 30) + 16 * (size_t)st.st_size);
    a->objects = 0;
    a->seen_n = 0;
    for (size_t j = 0; j < a->seen_cap; j++) a->seen_addr[j] = HADDR_UNDEF;
    a->value_max = (size_t)st.st_size + 4096;
    hid_t file = H5Fopen(a->paths[k], H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) continue;
    vet_object(a, file, "/", 0);
    pm_h5_close_quiet(&file);
    if (a->err) return a->err;
  }
  return PM_SUCCESS;
}

static pm_err vet_work(void *p) {
  vet_arg *a = p;
  const pm_err ret = vet_files(a);
  free(a->seen_addr);
  free(a->seen_depth);
  a->seen_addr = NULL;
  a->seen_depth = NULL;
  a->seen_cap = a->seen_n = 0;
  return ret;
}

pm_err pm_h5_vet(const char *const *paths, int n, bool data, const char *what,
                 pm_err code) {
  /* Not isolated: the readers meet whatever HDF5 does themselves. */
  if (n <= 0 || !pm_isolate_enabled()) return PM_SUCCESS;
  /* The file being read, where the parent finds it once the child is
   * gone. */
  char *current = mmap(NULL, PM_PATH_MAX + 1, PROT_READ | PROT_WRITE,
                       MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  PM_CHECK(current != MAP_FAILED, PM_ERR_MEMORY,
           "cannot map a page to check '%s'", paths[0]);
  snprintf(current, PM_PATH_MAX + 1, "%s", paths[0]);
  vet_arg a = {.paths = paths,
               .n = n,
               .data = data,
               .current = current,
               .what = what,
               .code = code};
  const pm_isolate_job job = {.path = current,
                              .library = "HDF5",
                              .what = what,
                              .code = code,
                              .cpu_seconds = PM_H5_VET_CPU_SECONDS,
                              .work = vet_work,
                              .arg = &a};
  pm_err ret = pm_isolate_run(&job);
  munmap(current, PM_PATH_MAX + 1);
  return ret;
}

pm_err pm_ckpt_vet(const char *dir) {
  char path[PM_PATH_MAX + 1];
  PM_CALL(pm_path_join(path, sizeof path, dir, "checkpoint.h5"));
  const char *paths[1] = {path};
  return pm_h5_vet(paths, 1, true, "a checkpoint of this program", PM_ERR_IO);
}

pm_err pm_results_vet(const pm_results *r, long n_keep) {
  pm_err ret = PM_SUCCESS;
  char **paths = NULL;
  const long n = n_keep + 2;
  PM_CHECK(n_keep >= 0 && n_keep < (1L << 24), PM_ERR_ARG,
           "pm_results_vet: %ld frames", n_keep);
  if (!pm_isolate_enabled()) return PM_SUCCESS;
  PM_TRY(PM_ALLOC(paths, n, "paths of the results"));
  for (long k = 0; k < n; k++)
    PM_TRY(PM_ALLOC(paths[k], PM_PATH_MAX + 1, "paths of the results"));
  snprintf(paths[0], PM_PATH_MAX + 1, "%s", r->index_path);
  snprintf(paths[1], PM_PATH_MAX + 1, "%s", r->mesh_path);
  for (long k = 0; k < n_keep; k++)
    pm_output_frame_path(r, k, paths[k + 2], PM_PATH_MAX + 1);
  ret = pm_h5_vet((const char *const *)paths, (int)n, false,
                  "results of this program", PM_ERR_HDF5);
done:
  if (paths)
    for (long k = 0; k < n; k++) free(paths[k]);
  free(paths);
  return ret;
}

/* Add dir's .h5 files to *paths (n of cap). */
static pm_err add_h5_files(const char *dir, char ***paths, int *n, int *cap) {
  DIR *d = opendir(dir);
  if (!d) return PM_SUCCESS; /* a folder without results/ */
  pm_err ret = PM_SUCCESS;
  for (struct dirent *e; (e = readdir(d));) {
    const size_t len = strlen(e->d_name);
    if (len < 4 || strcmp(e->d_name + len - 3, ".h5") != 0) continue;
    if (*n == *cap) {
      PM_ENSURE(*cap < (1 << 24), PM_ERR_ARG, "'%s' holds too many files", dir);
      char **grown = realloc(*paths, 2 * (size_t)*cap * sizeof *grown);
      PM_ENSURE(grown, PM_ERR_MEMORY, "paths of '%s'", dir);
      *paths = grown;
      *cap *= 2;
    }
    (*paths)[*n] = malloc(PM_PATH_MAX + 1);
    PM_ENSURE((*paths)[*n], PM_ERR_MEMORY, "paths of '%s'", dir);
    PM_TRY(pm_path_join((*paths)[(*n)++], PM_PATH_MAX + 1, dir, e->d_name));
  }
done:
  closedir(d);
  return ret;
}

pm_err pm_h5_vet_path(const char *path) {
  struct stat st;
  PM_CHECK(stat(path, &st) == 0, PM_ERR_IO, "cannot read '%s': %s", path,
           strerror(errno));
  const char *what = "an HDF5 file of this program";
  if (!S_ISDIR(st.st_mode)) return pm_h5_vet(&path, 1, true, what, PM_ERR_HDF5);
  pm_err ret = PM_SUCCESS;
  int n = 0, cap = 16;
  char **paths = malloc((size_t)cap * sizeof *paths);
  char results[PM_PATH_MAX + 1];
  PM_CHECK(paths, PM_ERR_MEMORY, "paths of '%s'", path);
  PM_TRY(pm_path_join(results, sizeof results, path, "results"));
  PM_TRY(add_h5_files(path, &paths, &n, &cap));
  PM_TRY(add_h5_files(results, &paths, &n, &cap));
  ret = pm_h5_vet((const char *const *)paths, n, true, what, PM_ERR_HDF5);
done:
  for (int k = 0; k < n; k++) free(paths[k]);
  free(paths);
  return ret;
}
