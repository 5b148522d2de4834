/* pm_output: results as one synced file per frame, an index (results.h5)
 * of external links and results.xdmf, both rewritten atomically after each
 * frame. */
#include "pm_output.h"

#include <dirent.h>
#include <stdarg.h>
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"

#define FIELD_NAME_MAX 63
#define OBJ_NAME_MAX 128
#define RESULTS_SUBDIR "results"
#define FRAME_FMT "frame_%06ld.h5"
#define POINTS_GRID "points" /* the cells' grid beside a surface's */
#define SURFACE_NAME "membrane"

/* Text grown as it is written. */
typedef struct {
  char *s;
  size_t len, cap;
} xml_text;

struct pm_results {
  int dim, nodes_per_cell;
  long n_points, n_cells, n_frames;
  long n_surface; /* triangles in mesh.h5's /surface (grid SURFACE_NAME) */
  bool created;   /* by pm_results_create: removed by close(!keep, no frame) */
  char *scene_text, *version;
  /* The XDMF of the frames so far (one <Grid> each), rewritten whole. */
  xml_text frames;
  char dir[PM_PATH_MAX + 1];
  char sub[PM_PATH_MAX + 1];        /* dir/results */
  char index_path[PM_PATH_MAX + 1]; /* dir/results.h5 */
  char xdmf_path[PM_PATH_MAX + 1];  /* dir/results.xdmf */
  char mesh_path[PM_PATH_MAX + 1];  /* dir/results/mesh.h5 */
};

static bool field_name_ok(const char *name) {
  size_t len = name ? strlen(name) : 0;
  if (len == 0 || len > FIELD_NAME_MAX || name[0] == '.') return false;
  for (const char *p = name; *p; p++) {
    char c = *p;
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
              (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

/* ---- Files written whole ------------------------------------------------ */

/* path + ".tmp.<pid>" into buf. */
static void tmp_name(char *buf, size_t size, const char *path) {
  snprintf(buf, size, "%s.tmp.%ld", path, (long)getpid());
}

/* Close the HDF5 file written under tmp and commit it to path. */
static pm_err close_and_commit(hid_t *file, const char *tmp, const char *path) {
  hid_t f = *file;
  *file = -1;
  PM_CHECK(H5Fclose(f) >= 0, PM_ERR_HDF5, "H5Fclose(/) failed on '%s': %s", tmp,
           pm_h5_message());
  return pm_sync_rename(tmp, path);
}

/* An HDF5 failure that the system caused (no space, file too large, no
 * permission) is an I/O error, named with the system's reason. */
static pm_err classify(pm_err e, int saved_errno, const char *path) {
  if (e != PM_ERR_HDF5) return e;
  if (saved_errno == ENOSPC || saved_errno == EFBIG || saved_errno == EDQUOT ||
      saved_errno == EACCES || saved_errno == EROFS || saved_errno == EIO) {
    pm_error_clear();
    return PM_ERROR(PM_ERR_IO, "cannot write '%s': %s", path,
                    strerror(saved_errno));
  }
  return e;
}

/* Refuse a file of about bytes that the file size limit or the free space
 * on dir's disk cannot hold, before HDF5 meets it half-way (a file HDF5
 * cannot flush cannot be closed either). */
static pm_err check_room(const char *dir, const char *path, double bytes) {
  struct rlimit rl;
  struct statvfs vfs;
  if (getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
      bytes > (double)rl.rlim_cur)
    return PM_ERROR(PM_ERR_IO,
                    "cannot write '%s': File too large (about %.0f bytes; "
                    "the file size limit, ulimit -f, is %.0f bytes)",
                    path, bytes, (double)rl.rlim_cur);
  if (statvfs(dir, &vfs) == 0 &&
      bytes > (double)vfs.f_bavail * (double)vfs.f_frsize)
    return PM_ERROR(PM_ERR_IO,
                    "cannot write '%s': No space left on device (about %.0f "
                    "bytes, %.0f free)",
                    path, bytes, (double)vfs.f_bavail * (double)vfs.f_frsize);
  return PM_SUCCESS;
}

/* HDF5's own overhead of a small file, bytes (headers, attributes). */
#define H5_OVERHEAD 16384.0

/* ---- Datasets ----------------------------------------------------------- */

/* Write the dataset loc/name of rank dims (file type ftype, memory mtype). */
static pm_err write_dataset(hid_t loc, const char *name, int rank,
                            const hsize_t *dims, hid_t ftype, hid_t mtype,
                            const void *data, const char *path,
                            hid_t *keep_open) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, dset = -1;
  H5_OK(space = H5Screate_simple(rank, dims, NULL), "H5Screate_simple", name,
        path);
  H5_OK(dset = H5Dcreate2(loc, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT),
        "H5Dcreate2", name, path);
  H5_OK(H5Dwrite(dset, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "H5Dwrite",
        name, path);
  if (keep_open) {
    *keep_open = dset;
    dset = -1;
  } else {
    H5_OK(H5Dclose(dset), "H5Dclose", name, path);
    dset = -1;
  }
done:
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&space);
  return ret;
}

/* ---- Checks ------------------------------------------------------------- */

/* n items of npc point indices each, all in [0, n_points). */
static pm_err check_indices(const char *what, long n, int npc, const long *ids,
                            long n_points) {
  PM_CHECK(n >= 1 && ids, PM_ERR_ARG,
           "results: need at least one %s (%ld given)", what, n);
  for (long i = 0; i < n * npc; i++)
    PM_CHECK(ids[i] >= 0 && ids[i] < n_points, PM_ERR_ARG,
             "results: %s %ld refers to point %ld (%ld points)", what, i / npc,
             ids[i], n_points);
  return PM_SUCCESS;
}

static pm_err check_mesh(int dim, const pm_points *p) {
  int npc = p->nodes_per_cell;
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "results: dim %d is not 2 or 3",
           dim);
  PM_CHECK(p->n >= 1 && p->x, PM_ERR_ARG,
           "results: need at least one point (n_points %ld)", p->n);
  PM_CHECK(npc == 1 || npc == 3 || npc == 4, PM_ERR_ARG,
           "results: %d nodes per cell (1, 3 or 4 expected)", npc);
  if (npc != 1 || p->cells)
    PM_CALL(check_indices("cell", p->n_cells, npc, p->cells, p->n));
  PM_CHECK(p->n_surface >= 0, PM_ERR_ARG, "results: %ld surface triangles",
           p->n_surface);
  if (p->n_surface == 0) return PM_SUCCESS;
  return check_indices("surface triangle", p->n_surface, 3, p->surface, p->n);
}

/* The output directory must exist and be writable. */
static pm_err check_dir(const char *dir) {
  struct stat st;
  PM_CHECK(dir && dir[0], PM_ERR_ARG, "results: empty output directory");
  PM_CHECK(stat(dir, &st) == 0, PM_ERR_IO,
           "output directory '%s' is not accessible: %s", dir, strerror(errno));
  PM_CHECK(S_ISDIR(st.st_mode), PM_ERR_IO,
           "output directory '%s' is not a directory", dir);
  PM_CHECK(access(dir, W_OK | X_OK) == 0, PM_ERR_IO,
           "output directory '%s' is not writable: %s", dir, strerror(errno));
  return PM_SUCCESS;
}

static pm_err check_fields(int n_fields, const pm_field *fields) {
  PM_CHECK(n_fields >= 0 && (n_fields == 0 || fields), PM_ERR_ARG,
           "results frame: %d fields", n_fields);
  for (int i = 0; i < n_fields; i++) {
    const pm_field *f = &fields[i];
    PM_CHECK(field_name_ok(f->name), PM_ERR_ARG,
             "results frame: field %d name '%s' is not a plain name "
             "(letters, digits, _ - ., at most %d bytes)",
             i, f->name ? f->name : "(null)", FIELD_NAME_MAX);
    PM_CHECK(f->ncomp == 1 || f->ncomp == 3 || f->ncomp == 9, PM_ERR_ARG,
             "results frame: field '%s' has %d components (1, 3 or 9)", f->name,
             f->ncomp);
    PM_CHECK(f->data, PM_ERR_ARG, "results frame: field '%s' has no data",
             f->name);
    for (int k = 0; k < i; k++)
      PM_CHECK(strcmp(fields[k].name, f->name) != 0, PM_ERR_ARG,
               "results frame: field '%s' given twice", f->name);
  }
  return PM_SUCCESS;
}

/* ---- Paths -------------------------------------------------------------- */

static pm_err set_paths(pm_results *r, const char *dir) {
  PM_CHECK(strlen(dir) + 40 < sizeof r->dir, PM_ERR_ARG,
           "output directory name too long: '%.64s...'", dir);
  snprintf(r->dir, sizeof r->dir, "%s", dir);
  PM_CALL(pm_path_join(r->sub, sizeof r->sub, dir, RESULTS_SUBDIR));
  PM_CALL(pm_path_join(r->index_path, sizeof r->index_path, dir, "results.h5"));
  PM_CALL(pm_path_join(r->xdmf_path, sizeof r->xdmf_path, dir, "results.xdmf"));
  return pm_path_join(r->mesh_path, sizeof r->mesh_path, r->sub, "mesh.h5");
}

static void frame_path(const pm_results *r, long k, char *buf, size_t size) {
  char name[32];
  snprintf(name, sizeof name, FRAME_FMT, k);
  /* r->sub leaves room for the name (set_paths checks the length). */
  if (pm_path_join(buf, size, r->sub, name) != PM_SUCCESS) buf[0] = '\0';
}

/* ---- XDMF --------------------------------------------------------------- */

/* Append printf-formatted text to t. */
static pm_err text_add(xml_text *t, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static pm_err text_add(xml_text *t, const char *fmt, ...) {
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    size_t room = t->cap - t->len;
    int n = vsnprintf(t->s ? t->s + t->len : NULL, room, fmt, ap);
    va_end(ap);
    PM_CHECK(n >= 0, PM_ERR_INTERNAL, "XDMF text formatting failed");
    if ((size_t)n < room) {
      t->len += (size_t)n;
      return PM_SUCCESS;
    }
    size_t cap = t->cap ? 2 * t->cap : 16384;
    while (cap < t->len + (size_t)n + 1) cap *= 2;
    char *grown = realloc(t->s, cap);
    PM_CHECK(grown, PM_ERR_MEMORY, "cannot grow the XDMF text to %zu bytes",
             cap);
    t->s = grown;
    t->cap = cap;
  }
}

/* Shortest of %.15g / %.17g that reads back as v. */
static void format_double(char *buf, size_t size, double v) {
  snprintf(buf, size, "%.15g", v);
  if (strtod(buf, NULL) != v) snprintf(buf, size, "%.17g", v);
}

/* A topology of n elements of npc points, mesh.h5's dataset, indented by
 * ind. */
static pm_err topology_add(xml_text *t, int ind, const char *type, long n,
                           int npc, const char *dataset) {
  return text_add(
      t,
      "%*s<Topology TopologyType=\"%s\" NumberOfElements=\"%ld\"%s>\n"
      "%*s<DataItem Dimensions=\"%ld %d\" NumberType=\"Int\" "
      "Precision=\"8\" Format=\"HDF\">" RESULTS_SUBDIR
      "/mesh.h5:/%s</DataItem>\n%*s</Topology>\n",
      ind, "", type, n, npc == 1 ? " NodesPerElement=\"1\"" : "", ind + 2, "",
      n, npc, dataset, ind, "");
}

/* What a frame's grids show: the frame's file and its fields (file NULL
 * and no field for the bare mesh). */
typedef struct {
  const char *file;
  int nf;
  const char *const *names;
  const int *ncomp;
} grid_data;

/* One uniform grid's body, indented by ind: the topology of the cells (or
 * of the surface), the geometry (the frame's "position" or the reference
 * coordinates) and every other field as a node-centred attribute. */
static pm_err grid_body(xml_text *t, const pm_results *r, int ind, bool surface,
                        const grid_data *g) {
  const char *geometry = NULL;
  for (int i = 0; i < g->nf; i++)
    if (g->ncomp[i] == 3 && strcmp(g->names[i], "position") == 0)
      geometry = g->names[i];
  if (surface) {
    PM_CALL(topology_add(t, ind, "Triangle", r->n_surface, 3, "surface"));
  } else {
    const char *type = r->nodes_per_cell == 1   ? "Polyvertex"
                       : r->nodes_per_cell == 3 ? "Triangle"
                       : r->dim == 3            ? "Tetrahedron"
                                                : "Quadrilateral";
    PM_CALL(topology_add(t, ind, type, r->n_cells, r->nodes_per_cell, "cells"));
  }
  PM_CALL(text_add(t,
                   "%*s<Geometry GeometryType=\"XYZ\">\n"
                   "%*s<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" "
                   "Precision=\"8\" Format=\"HDF\">" RESULTS_SUBDIR
                   "/%s:/%s</DataItem>\n%*s</Geometry>\n",
                   ind, "", ind + 2, "", r->n_points,
                   geometry ? g->file : "mesh.h5",
                   geometry ? "position" : "coordinates", ind, ""));
  for (int i = 0; i < g->nf; i++) {
    int nc = g->ncomp[i];
    if (g->names[i] == geometry) continue;
    PM_CALL(text_add(
        t,
        "%*s<Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n"
        "%*s<DataItem Dimensions=\"%ld%s\" NumberType=\"Float\" "
        "Precision=\"8\" Format=\"HDF\">" RESULTS_SUBDIR "/%s:/%s</DataItem>\n"
        "%*s</Attribute>\n",
        ind, "", g->names[i],
        nc == 1   ? "Scalar"
        : nc == 3 ? "Vector"
                  : "Tensor",
        ind + 2, "", r->n_points,
        nc == 1   ? ""
        : nc == 3 ? " 3"
                  : " 3 3",
        g->file, g->names[i], ind, ""));
  }
  return PM_SUCCESS;
}

/* The grid named name, indented by ind, head (its Time and Information
 * lines, or "") first: one uniform grid, or with a surface a spatial
 * collection of two, the cells' ("points") and the surface's. */
static pm_err grid_add(xml_text *t, const pm_results *r, int ind,
                       const char *name, const char *head, const grid_data *g) {
  bool two = r->n_surface > 0;
  PM_CALL(text_add(
      t, "%*s<Grid Name=\"%s\" GridType=\"%s\">\n%s", ind, "", name,
      two ? "Collection\" CollectionType=\"Spatial" : "Uniform", head));
  if (!two) PM_CALL(grid_body(t, r, ind + 2, false, g));
  for (int k = 0; two && k < 2; k++) {
    PM_CALL(text_add(t, "%*s<Grid Name=\"%s\" GridType=\"Uniform\">\n", ind + 2,
                     "", k ? SURFACE_NAME : POINTS_GRID));
    PM_CALL(grid_body(t, r, ind + 4, k == 1, g));
    PM_CALL(text_add(t, "%*s</Grid>\n", ind + 2, ""));
  }
  return text_add(t, "%*s</Grid>\n", ind, "");
}

/* Frame k's grid, from its field names and component counts, appended to
 * the frames' XDMF. */
static pm_err xdmf_frame(pm_results *r, long k, long step, double time, int nf,
                         const char *const *names, const int *ncomp) {
  char tbuf[40], file[32], name[32], head[160];
  format_double(tbuf, sizeof tbuf, time);
  snprintf(file, sizeof file, FRAME_FMT, k);
  snprintf(name, sizeof name, "frame_%06ld", k);
  snprintf(head, sizeof head,
           "        <Time Value=\"%s\"/>\n"
           "        <Information Name=\"step\" Value=\"%ld\"/>\n",
           tbuf, step);
  grid_data g = {file, nf, names, ncomp};
  return grid_add(&r->frames, r, 6, name, head, &g);
}

/* results.xdmf: the frames' temporal collection (or the bare mesh). */
static pm_err xdmf_commit(const pm_results *r) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  xml_text bare = {0};
  const xml_text *grids = &r->frames;
  if (r->n_frames == 0) {
    grid_data none = {NULL, 0, NULL, NULL};
    PM_TRY(grid_add(&bare, r, 4, "mesh", "", &none));
    grids = &bare;
  }
  PM_TRY(pm_afile_open(r->xdmf_path, &f));
  FILE *fp = pm_afile_stream(f);
  fprintf(fp, "<?xml version=\"1.0\" ?>\n"
              "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
              "<Xdmf Version=\"3.0\">\n  <Domain>\n");
  if (r->n_frames > 0)
    fprintf(fp, "    <Grid Name=\"pointmech\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
  fwrite(grids->s, 1, grids->len, fp);
  if (r->n_frames > 0) fprintf(fp, "    </Grid>\n");
  fprintf(fp, "  </Domain>\n</Xdmf>\n");
  ret = pm_afile_commit(f);
done:
  free(bare.s);
  return ret;
}

/* ---- Index -------------------------------------------------------------- */

/* results.h5: attributes and external links to the mesh and the frames. */
static pm_err index_commit(const pm_results *r) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, frames = -1, gcpl = -1;
  char tmp[PM_PATH_MAX + 40], name[32], target[64];
  const char *path = tmp;
  long nf = r->n_frames;
  tmp_name(tmp, sizeof tmp, r->index_path);
  H5_OK(file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        "H5Fcreate", "/", path);
  PM_TRY(pm_h5_write_string_attr(file, "scene", r->scene_text, path));
  PM_TRY(pm_h5_write_string_attr(file, "version", r->version, path));
  PM_TRY(pm_h5_write_attr(file, "dim", H5T_STD_I32LE, H5T_NATIVE_INT, &r->dim,
                          path));
  PM_TRY(pm_h5_write_attr(file, "frames", H5T_STD_I64LE, H5T_NATIVE_LONG, &nf,
                          path));
  H5_OK(H5Lcreate_external(RESULTS_SUBDIR "/mesh.h5", "/", file, "mesh",
                           H5P_DEFAULT, H5P_DEFAULT),
        "H5Lcreate_external", "/mesh", path);
  /* Frames keep their creation order (frame names sort only to 999999). */
  H5_OK(gcpl = H5Pcreate(H5P_GROUP_CREATE), "H5Pcreate", "gcpl", path);
  H5_OK(H5Pset_link_creation_order(gcpl, H5P_CRT_ORDER_TRACKED |
                                             H5P_CRT_ORDER_INDEXED),
        "H5Pset_link_creation_order", "gcpl", path);
  H5_OK(frames = H5Gcreate2(file, "frames", H5P_DEFAULT, gcpl, H5P_DEFAULT),
        "H5Gcreate2", "/frames", path);
  for (long k = 0; k < nf; k++) {
    snprintf(name, sizeof name, "%06ld", k);
    snprintf(target, sizeof target, RESULTS_SUBDIR "/" FRAME_FMT, k);
    H5_OK(
        H5Lcreate_external(target, "/", frames, name, H5P_DEFAULT, H5P_DEFAULT),
        "H5Lcreate_external", name, path);
  }
  H5_OK(H5Gclose(frames), "H5Gclose", "/frames", path);
  frames = -1;
  PM_TRY(close_and_commit(&file, tmp, r->index_path));
done:
  pm_h5_close_quiet(&gcpl);
  pm_h5_close_quiet(&frames);
  pm_h5_close_quiet(&file);
  if (ret != PM_SUCCESS) unlink(tmp);
  return ret;
}

/* Index, then XDMF: each replaced whole. */
static pm_err publish(const pm_results *r) {
  PM_CALL(index_commit(r));
  return xdmf_commit(r);
}

/* ---- Create, reopen, close ---------------------------------------------- */

static void results_free(pm_results *r) {
  if (!r) return;
  free(r->scene_text);
  free(r->version);
  free(r->frames.s);
  free(r);
}

static pm_err write_mesh(const pm_results *r, const double *x,
                         const long *cells, const long *surface) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, dset = -1;
  char tmp[PM_PATH_MAX + 40];
  const char *path = tmp;
  int npc = r->nodes_per_cell;
  hsize_t xd[2] = {(hsize_t)r->n_points, 3};
  hsize_t cd[2] = {(hsize_t)r->n_cells, (hsize_t)npc};
  hsize_t sd[2] = {(hsize_t)r->n_surface, 3};
  tmp_name(tmp, sizeof tmp, r->mesh_path);
  PM_TRY(check_room(r->sub, r->mesh_path,
                    H5_OVERHEAD + 8.0 * (3.0 * (double)r->n_points +
                                         (double)r->n_cells * npc +
                                         3.0 * (double)r->n_surface)));
  H5_OK(file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        "H5Fcreate", "/", path);
  PM_TRY(write_dataset(file, "coordinates", 2, xd, H5T_IEEE_F64LE,
                       H5T_NATIVE_DOUBLE, x, path, NULL));
  PM_TRY(write_dataset(file, "cells", 2, cd, H5T_STD_I64LE, H5T_NATIVE_LONG,
                       cells, path, &dset));
  PM_TRY(pm_h5_write_attr(dset, "nodes_per_cell", H5T_STD_I32LE, H5T_NATIVE_INT,
                          &npc, path));
  H5_OK(H5Dclose(dset), "H5Dclose", "/cells", path);
  dset = -1;
  if (r->n_surface > 0) {
    PM_TRY(write_dataset(file, "surface", 2, sd, H5T_STD_I64LE, H5T_NATIVE_LONG,
                         surface, path, &dset));
    PM_TRY(pm_h5_write_string_attr(dset, "name", SURFACE_NAME, path));
    H5_OK(H5Dclose(dset), "H5Dclose", "/surface", path);
    dset = -1;
  }
  PM_TRY(close_and_commit(&file, tmp, r->mesh_path));
done:
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&file);
  if (ret != PM_SUCCESS) unlink(tmp);
  return ret;
}

pm_err pm_results_create_ex(const char *dir, int dim, const pm_points *p,
                            const char *scene_text, const char *version,
                            pm_results **out) {
  pm_err ret = PM_SUCCESS;
  pm_results *r = NULL;
  long *ids = NULL;
  PM_CHECK(out && p, PM_ERR_ARG, "pm_results_create: NULL out or points");
  *out = NULL;
  PM_CALL(check_mesh(dim, p));
  PM_CALL(check_dir(dir));
  /* No clean-up at exit: after a write the system refused, HDF5's own
   * would close a file it cannot flush again. */
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  const long *cells = p->cells;
  long n_cells = p->n_cells;
  if (p->nodes_per_cell == 1 && !cells) { /* point cloud: cell i is point i */
    PM_TRY(PM_ALLOC(ids, p->n, "point cloud cells"));
    for (long i = 0; i < p->n; i++) ids[i] = i;
    cells = ids;
    n_cells = p->n;
  }
  PM_TRY(PM_ALLOC(r, 1, "results writer"));
  r->dim = dim;
  r->nodes_per_cell = p->nodes_per_cell;
  r->n_points = p->n;
  r->n_cells = n_cells;
  r->n_surface = p->n_surface;
  PM_TRY(set_paths(r, dir));
  r->scene_text = strdup(scene_text ? scene_text : "");
  r->version = strdup(version ? version : "");
  PM_ENSURE(r->scene_text && r->version, PM_ERR_MEMORY,
            "cannot copy the scene text");
  PM_TRY(pm_mkdir_p(r->sub));
  r->created = true;
  int saved = 0;
  errno = 0;
  ret = write_mesh(r, p->x, cells, p->surface);
  if (ret == PM_SUCCESS) ret = publish(r);
  saved = errno;
  PM_TRY(classify(ret, saved, r->mesh_path));
  *out = r;
  r = NULL;
done:
  if (r) {
    pm_results_close(r, false);
    r = NULL;
  }
  free(ids);
  return ret;
}

pm_err pm_results_create(const char *dir, int dim, long n_points,
                         const double *x, long n_cells, int nodes_per_cell,
                         const long *cells, const char *scene_text,
                         const char *version, pm_results **out) {
  pm_points p = {.n = n_points,
                 .x = x,
                 .n_cells = n_cells,
                 .nodes_per_cell = nodes_per_cell,
                 .cells = cells};
  return pm_results_create_ex(dir, dim, &p, scene_text, version, out);
}

/* Remove frame files of index >= n_keep and temporary files left in
 * dir/results by a run that was killed. */
static pm_err drop_later_frames(const pm_results *r, long n_keep) {
  DIR *d = opendir(r->sub);
  PM_CHECK(d, PM_ERR_IO, "cannot read '%s': %s", r->sub, strerror(errno));
  struct dirent *e;
  char path[PM_PATH_MAX + 1];
  pm_err ret = PM_SUCCESS;
  while ((e = readdir(d))) {
    long k;
    int used = 0;
    bool tmp = strstr(e->d_name, ".tmp.") != NULL;
    bool later = sscanf(e->d_name, "frame_%ld.h5%n", &k, &used) == 1 &&
                 e->d_name[used] == '\0' && k >= n_keep;
    if (!tmp && !later) continue;
    if (pm_path_join(path, sizeof path, r->sub, e->d_name) != PM_SUCCESS)
      continue;
    if (unlink(path) != 0 && errno != ENOENT) {
      ret =
          PM_ERROR(PM_ERR_IO, "cannot remove '%s': %s", path, strerror(errno));
      break;
    }
  }
  closedir(d);
  return ret;
}

/* Frame k's attributes and field list, read back into the XDMF. */
static pm_err reread_frame(pm_results *r, long k) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, dset = -1, space = -1;
  char path[PM_PATH_MAX + 1], names_buf[16][FIELD_NAME_MAX + 2];
  const char *names[16];
  int ncomp[16], nf = 0;
  H5G_info_t info;
  double time;
  long step;
  frame_path(r, k, path, sizeof path);
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(pm_h5_read_attr(file, "time", H5T_NATIVE_DOUBLE, &time, "/", path));
  PM_TRY(pm_h5_read_attr(file, "step", H5T_NATIVE_LONG, &step, "/", path));
  H5_OK(H5Gget_info(file, &info), "H5Gget_info", "/", path);
  PM_ENSURE(info.nlinks <= 16, PM_ERR_HDF5,
            "'%s' holds %llu fields (16 at most)", path,
            (unsigned long long)info.nlinks);
  for (hsize_t i = 0; i < info.nlinks; i++, nf++) {
    ssize_t len;
    hssize_t count;
    H5_OK(len = H5Lget_name_by_idx(file, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC,
                                   i, names_buf[nf], sizeof names_buf[nf],
                                   H5P_DEFAULT),
          "H5Lget_name_by_idx", "/", path);
    PM_ENSURE((size_t)len < sizeof names_buf[nf], PM_ERR_HDF5,
              "field name too long in '%s'", path);
    names[nf] = names_buf[nf];
    H5_OK(dset = H5Dopen2(file, names[nf], H5P_DEFAULT), "H5Dopen2", names[nf],
          path);
    H5_OK(space = H5Dget_space(dset), "H5Dget_space", names[nf], path);
    H5_OK(count = H5Sget_simple_extent_npoints(space),
          "H5Sget_simple_extent_npoints", names[nf], path);
    ncomp[nf] = (int)(count / r->n_points);
    PM_ENSURE(count == (hssize_t)ncomp[nf] * r->n_points &&
                  (ncomp[nf] == 1 || ncomp[nf] == 3 || ncomp[nf] == 9),
              PM_ERR_HDF5, "field %s of '%s' has %lld values for %ld points",
              names[nf], path, (long long)count, r->n_points);
    pm_h5_close_quiet(&space);
    pm_h5_close_quiet(&dset);
  }
  PM_TRY(xdmf_frame(r, k, step, time, nf, names, ncomp));
done:
  pm_h5_close_quiet(&space);
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&file);
  return ret;
}

/* The sizes of mesh.h5's table (a rank-2 dataset) /name. */
static pm_err table_dims(hid_t file, const char *name, hsize_t dims[2],
                         const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t dset = -1, space = -1;
  H5_OK(dset = H5Dopen2(file, name, H5P_DEFAULT), "H5Dopen2", name, path);
  H5_OK(space = H5Dget_space(dset), "H5Dget_space", name, path);
  PM_ENSURE(H5Sget_simple_extent_ndims(space) == 2, PM_ERR_HDF5,
            "'%s': /%s is not a table", path, name);
  H5_OK(H5Sget_simple_extent_dims(space, dims, NULL),
        "H5Sget_simple_extent_dims", name, path);
done:
  pm_h5_close_quiet(&space);
  pm_h5_close_quiet(&dset);
  return ret;
}

/* The mesh's sizes (and its surface's) from mesh.h5. */
static pm_err reread_mesh(pm_results *r) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1;
  hsize_t dims[2];
  htri_t has_surface;
  const char *path = r->mesh_path;
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(table_dims(file, "cells", dims, path));
  r->n_cells = (long)dims[0];
  r->nodes_per_cell = (int)dims[1];
  PM_TRY(table_dims(file, "coordinates", dims, path));
  r->n_points = (long)dims[0];
  H5_OK(has_surface = H5Lexists(file, "surface", H5P_DEFAULT), "H5Lexists",
        "surface", path);
  if (has_surface) {
    PM_TRY(table_dims(file, "surface", dims, path));
    PM_ENSURE(dims[0] >= 1 && dims[1] == 3, PM_ERR_HDF5,
              "'%s': /surface is not a table of triangles (%llu x %llu)", path,
              (unsigned long long)dims[0], (unsigned long long)dims[1]);
    r->n_surface = (long)dims[0];
  }
done:
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_results_reopen(const char *dir, long n_points, long n_keep,
                         pm_results **out) {
  pm_err ret = PM_SUCCESS;
  pm_results *r = NULL;
  hid_t file = -1;
  const char *path = "";
  PM_CHECK(out && n_keep >= 0, PM_ERR_ARG, "pm_results_reopen: bad arguments");
  *out = NULL;
  PM_CALL(check_dir(dir));
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  PM_TRY(PM_ALLOC(r, 1, "results writer"));
  PM_TRY(set_paths(r, dir));
  path = r->index_path;
  H5_OK(file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", "/",
        path);
  PM_TRY(pm_h5_read_string_attr(file, "scene", &r->scene_text, path));
  PM_TRY(pm_h5_read_string_attr(file, "version", &r->version, path));
  PM_TRY(pm_h5_read_attr(file, "dim", H5T_NATIVE_INT, &r->dim, "/", path));
  pm_h5_close_quiet(&file);
  PM_TRY(reread_mesh(r));
  PM_ENSURE(r->n_points == n_points, PM_ERR_ARG,
            "'%s' holds %ld points, the run has %ld", r->mesh_path, r->n_points,
            n_points);
  /* The frames kept must all be readable before anything changes. */
  for (long k = 0; k < n_keep; k++) PM_TRY(reread_frame(r, k));
  r->n_frames = n_keep;
  PM_TRY(publish(r));
  PM_TRY(drop_later_frames(r, n_keep));
  *out = r;
  r = NULL;
done:
  pm_h5_close_quiet(&file);
  results_free(r);
  return ret;
}

void pm_results_close(pm_results *r, bool keep) {
  if (!r) return;
  if (!keep && r->created && r->n_frames == 0) {
    unlink(r->index_path);
    unlink(r->xdmf_path);
    unlink(r->mesh_path);
    rmdir(r->sub);
  }
  results_free(r);
}

/* ---- Frames ------------------------------------------------------------- */

/* The frame's HDF5 file, under tmp. */
static pm_err write_frame_file(const pm_results *r, const char *tmp, long step,
                               double time, int n_fields,
                               const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, fcpl = -1;
  const char *path = tmp;
  /* The fields keep their order (read back when a run resumes). */
  H5_OK(fcpl = H5Pcreate(H5P_FILE_CREATE), "H5Pcreate", "fcpl", path);
  H5_OK(H5Pset_link_creation_order(fcpl, H5P_CRT_ORDER_TRACKED |
                                             H5P_CRT_ORDER_INDEXED),
        "H5Pset_link_creation_order", "fcpl", path);
  H5_OK(file = H5Fcreate(tmp, H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), "H5Fcreate",
        "/", path);
  PM_TRY(pm_h5_write_attr(file, "step", H5T_STD_I64LE, H5T_NATIVE_LONG, &step,
                          path));
  PM_TRY(pm_h5_write_attr(file, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                          &time, path));
  for (int i = 0; i < n_fields; i++) {
    const pm_field *f = &fields[i];
    hsize_t dims[3] = {(hsize_t)r->n_points, 3, 3};
    int rank = f->ncomp == 1 ? 1 : f->ncomp == 3 ? 2 : 3;
    PM_TRY(write_dataset(file, f->name, rank, dims, H5T_IEEE_F64LE,
                         H5T_NATIVE_DOUBLE, f->data, path, NULL));
  }
  H5_OK(H5Fclose(file), "H5Fclose", "/", path);
  file = -1;
done:
  pm_h5_close_quiet(&fcpl);
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_results_write_frame(pm_results *r, long step, double time,
                              int n_fields, const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  char path[PM_PATH_MAX + 1], tmp[PM_PATH_MAX + 40];
  const char *names[16];
  int ncomp[16];
  size_t frames_len;
  PM_CHECK(r, PM_ERR_ARG, "pm_results_write_frame: NULL results");
  PM_CALL(check_fields(n_fields, fields));
  PM_CHECK(n_fields <= 16, PM_ERR_ARG, "results frame: %d fields (16 at most)",
           n_fields);
  frame_path(r, r->n_frames, path, sizeof path);
  tmp_name(tmp, sizeof tmp, path);
  double bytes = H5_OVERHEAD;
  for (int i = 0; i < n_fields; i++)
    bytes += 8.0 * fields[i].ncomp * (double)r->n_points;
  PM_CALL(check_room(r->sub, path, bytes));
  frames_len = r->frames.len;
  errno = 0;
  ret = write_frame_file(r, tmp, step, time, n_fields, fields);
  int saved = errno;
  PM_TRY(classify(ret, saved, path));
  PM_TRY(pm_sync_rename(tmp, path));
  for (int i = 0; i < n_fields; i++) {
    names[i] = fields[i].name;
    ncomp[i] = fields[i].ncomp;
  }
  PM_TRY(xdmf_frame(r, r->n_frames, step, time, n_fields, names, ncomp));
  r->n_frames++;
  errno = 0;
  ret = publish(r);
  saved = errno;
  if (ret != PM_SUCCESS) { /* back to the frames before */
    r->n_frames--;
    r->frames.len = frames_len;
    unlink(path);
    /* The index may already list the frame: list the others again (best
     * effort; the earlier index and XDMF stay otherwise). */
    pm_err first = ret;
    if (index_commit(r) != PM_SUCCESS) pm_error_clear();
    ret = first;
    PM_TRY(classify(ret, saved, r->index_path));
  }
done:
  unlink(tmp);
  return ret;
}

long pm_results_frames(const pm_results *r) { return r ? r->n_frames : 0; }
