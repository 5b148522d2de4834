/* pm_output: results.h5 written frame by frame under a temporary name, and
 * results.xdmf generated from the file's own frames when it is closed. */
#include "pm_output.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"

#define FIELD_NAME_MAX 63
#define OBJ_NAME_MAX 128

struct pm_results {
  hid_t file, frames, gcpl;
  hid_t space[3]; /* dataspaces of scalar, vector and tensor fields */
  int dim, nodes_per_cell;
  long n_points, n_cells, n_frames;
  char tmp_path[PM_PATH_MAX + 40]; /* final_path + ".tmp.<pid>" */
  char final_path[PM_PATH_MAX + 1];
  char xdmf_path[PM_PATH_MAX + 1];
};

/* Close an identifier if open, ignoring errors (cleanup paths only). */
static void h5_close_quiet(hid_t *id) {
  if (*id < 0) return;
  switch (H5Iget_type(*id)) {
  case H5I_FILE: H5Fclose(*id); break;
  case H5I_GROUP: H5Gclose(*id); break;
  case H5I_DATASET: H5Dclose(*id); break;
  case H5I_DATASPACE: H5Sclose(*id); break;
  case H5I_DATATYPE: H5Tclose(*id); break;
  case H5I_ATTR: H5Aclose(*id); break;
  case H5I_GENPROP_LST: H5Pclose(*id); break;
  default: break;
  }
  *id = -1;
}

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

/* ---- Attributes -------------------------------------------------------- */

/* Scalar attribute name of file type ftype on loc written from value. */
static pm_err write_attr(hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                         const void *value, const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, attr = -1;
  H5_OK(space = H5Screate(H5S_SCALAR), "H5Screate", name, path);
  H5_OK(attr = H5Acreate2(loc, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT),
        "H5Acreate2", name, path);
  H5_OK(H5Awrite(attr, mtype, value), "H5Awrite", name, path);
  H5_OK(H5Aclose(attr), "H5Aclose", name, path);
  attr = -1;
done:
  h5_close_quiet(&attr);
  h5_close_quiet(&space);
  return ret;
}

/* Variable-length UTF-8 string attribute (no size limit: the text lives in
 * the global heap). */
static pm_err write_string_attr(hid_t loc, const char *name, const char *text,
                                const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t type = -1;
  const char *value = text ? text : "";
  H5_OK(type = H5Tcopy(H5T_C_S1), "H5Tcopy", name, path);
  H5_OK(H5Tset_size(type, H5T_VARIABLE), "H5Tset_size", name, path);
  H5_OK(H5Tset_cset(type, H5T_CSET_UTF8), "H5Tset_cset", name, path);
  PM_TRY(write_attr(loc, name, type, type, &value, path));
done:
  h5_close_quiet(&type);
  return ret;
}

/* ---- Create ------------------------------------------------------------ */

/* Check the arguments of pm_results_create. */
static pm_err check_mesh(int dim, long n_points, const double *x, long n_cells,
                         int npc, const long *cells) {
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "results: dim %d is not 2 or 3",
           dim);
  PM_CHECK(n_points >= 1 && x, PM_ERR_ARG,
           "results: need at least one point (n_points %ld)", n_points);
  PM_CHECK(npc == 1 || npc == 3 || npc == 4, PM_ERR_ARG,
           "results: %d nodes per cell (1, 3 or 4 expected)", npc);
  if (npc == 1 && !cells) return PM_SUCCESS;
  PM_CHECK(n_cells >= 1 && cells, PM_ERR_ARG,
           "results: need at least one cell (n_cells %ld)", n_cells);
  for (long i = 0; i < n_cells * npc; i++)
    PM_CHECK(cells[i] >= 0 && cells[i] < n_points, PM_ERR_ARG,
             "results: cell %ld refers to point %ld (%ld points)", i / npc,
             cells[i], n_points);
  return PM_SUCCESS;
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

/* Write a 2-D dataset loc/name of file type ftype from memory type mtype. */
static pm_err write_2d(hid_t loc, const char *name, hsize_t rows, hsize_t cols,
                       hid_t ftype, hid_t mtype, const void *data,
                       const char *path, hid_t *keep_open) {
  pm_err ret = PM_SUCCESS;
  hid_t space = -1, dset = -1;
  hsize_t dims[2] = {rows, cols};
  H5_OK(space = H5Screate_simple(2, dims, NULL), "H5Screate_simple", name,
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
  h5_close_quiet(&dset);
  h5_close_quiet(&space);
  return ret;
}

static void results_free(pm_results *r, bool unlink_tmp) {
  if (!r) return;
  h5_close_quiet(&r->frames);
  h5_close_quiet(&r->gcpl);
  for (int i = 0; i < 3; i++) h5_close_quiet(&r->space[i]);
  h5_close_quiet(&r->file);
  if (unlink_tmp && r->tmp_path[0]) unlink(r->tmp_path);
  free(r);
}

pm_err pm_results_create(const char *dir, int dim, long n_points,
                         const double *x, long n_cells, int nodes_per_cell,
                         const long *cells, const char *scene_text,
                         const char *version, pm_results **out) {
  pm_err ret = PM_SUCCESS;
  pm_results *r = NULL;
  long *ids = NULL;
  hid_t mesh = -1, dset = -1;
  const char *path = "";
  int npc = nodes_per_cell;
  PM_CHECK(out, PM_ERR_ARG, "pm_results_create: NULL out");
  *out = NULL;
  PM_CALL(check_mesh(dim, n_points, x, n_cells, npc, cells));
  PM_CALL(check_dir(dir));
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);

  if (npc == 1 && !cells) { /* point cloud: cell i is point i */
    PM_TRY(PM_ALLOC(ids, n_points, "point cloud cells"));
    for (long i = 0; i < n_points; i++) ids[i] = i;
    cells = ids;
    n_cells = n_points;
  }
  PM_TRY(PM_ALLOC(r, 1, "results writer"));
  r->file = r->frames = r->gcpl = -1;
  r->space[0] = r->space[1] = r->space[2] = -1;
  r->dim = dim;
  r->nodes_per_cell = npc;
  r->n_points = n_points;
  r->n_cells = n_cells;
  PM_TRY(pm_path_join(r->final_path, sizeof r->final_path, dir, "results.h5"));
  PM_TRY(pm_path_join(r->xdmf_path, sizeof r->xdmf_path, dir, "results.xdmf"));
  snprintf(r->tmp_path, sizeof r->tmp_path, "%s.tmp.%ld", r->final_path,
           (long)getpid());
  path = r->tmp_path;

  H5_OK(r->file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
        "H5Fcreate", "/", path);
  PM_TRY(write_string_attr(r->file, "scene", scene_text, path));
  PM_TRY(write_string_attr(r->file, "version", version, path));
  PM_TRY(write_attr(r->file, "dim", H5T_STD_I32LE, H5T_NATIVE_INT, &dim, path));

  H5_OK(mesh =
            H5Gcreate2(r->file, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        "H5Gcreate2", "/mesh", path);
  PM_TRY(write_2d(mesh, "coordinates", (hsize_t)n_points, 3, H5T_IEEE_F64LE,
                  H5T_NATIVE_DOUBLE, x, path, NULL));
  PM_TRY(write_2d(mesh, "cells", (hsize_t)n_cells, (hsize_t)npc, H5T_STD_I64LE,
                  H5T_NATIVE_LONG, cells, path, &dset));
  PM_TRY(write_attr(dset, "nodes_per_cell", H5T_STD_I32LE, H5T_NATIVE_INT, &npc,
                    path));
  H5_OK(H5Dclose(dset), "H5Dclose", "/mesh/cells", path);
  dset = -1;
  H5_OK(H5Gclose(mesh), "H5Gclose", "/mesh", path);
  mesh = -1;

  /* Frames keep their creation order (frame names sort only to 999999). */
  H5_OK(r->gcpl = H5Pcreate(H5P_GROUP_CREATE), "H5Pcreate", "gcpl", path);
  H5_OK(H5Pset_link_creation_order(r->gcpl, H5P_CRT_ORDER_TRACKED |
                                                H5P_CRT_ORDER_INDEXED),
        "H5Pset_link_creation_order", "gcpl", path);
  H5_OK(r->frames =
            H5Gcreate2(r->file, "frames", H5P_DEFAULT, r->gcpl, H5P_DEFAULT),
        "H5Gcreate2", "/frames", path);
  hsize_t dims[3] = {(hsize_t)n_points, 3, 3};
  for (int i = 0; i < 3; i++)
    H5_OK(r->space[i] = H5Screate_simple(i + 1, dims, NULL), "H5Screate_simple",
          "field space", path);
  H5_OK(H5Fflush(r->file, H5F_SCOPE_LOCAL), "H5Fflush", "/", path);
  *out = r;
  r = NULL;
done:
  h5_close_quiet(&dset);
  h5_close_quiet(&mesh);
  results_free(r, true);
  free(ids);
  return ret;
}

/* ---- Frames ------------------------------------------------------------ */

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

pm_err pm_results_write_frame(pm_results *r, long step, double time,
                              int n_fields, const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  hid_t group = -1, dset = -1;
  char gname[32], obj[OBJ_NAME_MAX];
  const char *path;
  PM_CHECK(r, PM_ERR_ARG, "pm_results_write_frame: NULL results");
  PM_CALL(check_fields(n_fields, fields));
  path = r->tmp_path;
  snprintf(gname, sizeof gname, "%06ld", r->n_frames);
  snprintf(obj, sizeof obj, "/frames/%s", gname);
  H5_OK(group = H5Gcreate2(r->frames, gname, H5P_DEFAULT, r->gcpl, H5P_DEFAULT),
        "H5Gcreate2", obj, path);
  r->n_frames++; /* the name is taken even if the frame fails below */
  PM_TRY(
      write_attr(group, "step", H5T_STD_I64LE, H5T_NATIVE_LONG, &step, path));
  PM_TRY(write_attr(group, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time,
                    path));
  for (int i = 0; i < n_fields; i++) {
    const pm_field *f = &fields[i];
    hid_t space = r->space[f->ncomp == 1 ? 0 : f->ncomp == 3 ? 1 : 2];
    snprintf(obj, sizeof obj, "/frames/%s/%s", gname, f->name);
    H5_OK(dset = H5Dcreate2(group, f->name, H5T_IEEE_F64LE, space, H5P_DEFAULT,
                            H5P_DEFAULT, H5P_DEFAULT),
          "H5Dcreate2", obj, path);
    H5_OK(H5Dwrite(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                   f->data),
          "H5Dwrite", obj, path);
    H5_OK(H5Dclose(dset), "H5Dclose", obj, path);
    dset = -1;
  }
  snprintf(obj, sizeof obj, "/frames/%s", gname);
  H5_OK(H5Gclose(group), "H5Gclose", obj, path);
  group = -1;
  H5_OK(H5Fflush(r->file, H5F_SCOPE_LOCAL), "H5Fflush", "/", path);
done:
  h5_close_quiet(&dset);
  h5_close_quiet(&group);
  return ret;
}

long pm_results_frames(const pm_results *r) { return r ? r->n_frames : 0; }

/* ---- XDMF -------------------------------------------------------------- */

/* Shortest of %.15g / %.17g that reads back as v. */
static void format_double(char *buf, size_t size, double v) {
  snprintf(buf, size, "%.15g", v);
  if (strtod(buf, NULL) != v) snprintf(buf, size, "%.17g", v);
}

static void xdmf_mesh(const pm_results *r, FILE *fp, int ind) {
  const char *topo = r->nodes_per_cell == 1   ? "Polyvertex"
                     : r->nodes_per_cell == 3 ? "Triangle"
                     : r->dim == 3            ? "Tetrahedron"
                                              : "Quadrilateral";
  fprintf(fp, "%*s<Topology TopologyType=\"%s\" NumberOfElements=\"%ld\"", ind,
          "", topo, r->n_cells);
  if (r->nodes_per_cell == 1) fprintf(fp, " NodesPerElement=\"1\"");
  fprintf(fp,
          ">\n%*s<DataItem Dimensions=\"%ld %d\" NumberType=\"Int\" "
          "Precision=\"8\" Format=\"HDF\">results.h5:/mesh/cells</DataItem>\n"
          "%*s</Topology>\n",
          ind + 2, "", r->n_cells, r->nodes_per_cell, ind, "");
  fprintf(fp,
          "%*s<Geometry GeometryType=\"XYZ\">\n"
          "%*s<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" "
          "Precision=\"8\" Format=\"HDF\">results.h5:/mesh/coordinates"
          "</DataItem>\n%*s</Geometry>\n",
          ind, "", ind + 2, "", r->n_points, ind, "");
}

/* Read scalar attribute name of loc into value (memory type mtype). */
static pm_err read_attr(hid_t loc, const char *name, hid_t mtype, void *value,
                        const char *obj, const char *path) {
  pm_err ret = PM_SUCCESS;
  hid_t attr = -1;
  H5_OK(attr = H5Aopen(loc, name, H5P_DEFAULT), "H5Aopen", obj, path);
  H5_OK(H5Aread(attr, mtype, value), "H5Aread", obj, path);
  H5_OK(H5Aclose(attr), "H5Aclose", obj, path);
  attr = -1;
done:
  h5_close_quiet(&attr);
  return ret;
}

/* One frame's uniform grid, its fields listed from the file itself. */
static pm_err xdmf_frame(const pm_results *r, long index, FILE *fp) {
  pm_err ret = PM_SUCCESS;
  hid_t group = -1, dset = -1, space = -1;
  char gname[32], obj[OBJ_NAME_MAX], name[FIELD_NAME_MAX + 2], tbuf[40];
  const char *path = r->tmp_path;
  H5G_info_t info;
  double time;
  long step;
  snprintf(gname, sizeof gname, "%06ld", index);
  snprintf(obj, sizeof obj, "/frames/%s", gname);
  H5_OK(group = H5Gopen2(r->frames, gname, H5P_DEFAULT), "H5Gopen2", obj, path);
  PM_TRY(read_attr(group, "time", H5T_NATIVE_DOUBLE, &time, obj, path));
  PM_TRY(read_attr(group, "step", H5T_NATIVE_LONG, &step, obj, path));
  H5_OK(H5Gget_info(group, &info), "H5Gget_info", obj, path);
  format_double(tbuf, sizeof tbuf, time);
  fprintf(fp,
          "      <Grid Name=\"frame_%s\" GridType=\"Uniform\">\n"
          "        <Time Value=\"%s\"/>\n"
          "        <Information Name=\"step\" Value=\"%ld\"/>\n",
          gname, tbuf, step);
  xdmf_mesh(r, fp, 8);
  for (hsize_t k = 0; k < info.nlinks; k++) {
    ssize_t len;
    int rank;
    H5_OK(len = H5Lget_name_by_idx(group, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC,
                                   k, name, sizeof name, H5P_DEFAULT),
          "H5Lget_name_by_idx", obj, path);
    PM_ENSURE((size_t)len < sizeof name, PM_ERR_HDF5,
              "field name in %s too long in '%s'", obj, path);
    snprintf(obj, sizeof obj, "/frames/%s/%s", gname, name);
    H5_OK(dset = H5Dopen2(group, name, H5P_DEFAULT), "H5Dopen2", obj, path);
    H5_OK(space = H5Dget_space(dset), "H5Dget_space", obj, path);
    H5_OK(rank = H5Sget_simple_extent_ndims(space),
          "H5Sget_simple_extent_ndims", obj, path);
    PM_ENSURE(rank >= 1 && rank <= 3, PM_ERR_HDF5,
              "dataset %s in '%s' has rank %d", obj, path, rank);
    fprintf(fp,
            "        <Attribute Name=\"%s\" AttributeType=\"%s\" "
            "Center=\"Node\">\n"
            "          <DataItem Dimensions=\"%ld%s\" NumberType=\"Float\" "
            "Precision=\"8\" Format=\"HDF\">results.h5:%s</DataItem>\n"
            "        </Attribute>\n",
            name,
            rank == 1   ? "Scalar"
            : rank == 2 ? "Vector"
                        : "Tensor",
            r->n_points,
            rank == 1   ? ""
            : rank == 2 ? " 3"
                        : " 3 3",
            obj);
    H5_OK(H5Sclose(space), "H5Sclose", obj, path);
    space = -1;
    H5_OK(H5Dclose(dset), "H5Dclose", obj, path);
    dset = -1;
    snprintf(obj, sizeof obj, "/frames/%s", gname);
  }
  fprintf(fp, "      </Grid>\n");
  H5_OK(H5Gclose(group), "H5Gclose", obj, path);
  group = -1;
done:
  h5_close_quiet(&space);
  h5_close_quiet(&dset);
  h5_close_quiet(&group);
  return ret;
}

/* The whole XDMF document (written before the HDF5 file is closed). */
static pm_err xdmf_write(const pm_results *r, FILE *fp) {
  fprintf(fp, "<?xml version=\"1.0\" ?>\n"
              "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
              "<Xdmf Version=\"3.0\">\n  <Domain>\n");
  if (r->n_frames == 0) {
    fprintf(fp, "    <Grid Name=\"mesh\" GridType=\"Uniform\">\n");
    xdmf_mesh(r, fp, 6);
    fprintf(fp, "    </Grid>\n");
  } else {
    fprintf(fp, "    <Grid Name=\"pointmech\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
    for (long i = 0; i < r->n_frames; i++) PM_CALL(xdmf_frame(r, i, fp));
    fprintf(fp, "    </Grid>\n");
  }
  fprintf(fp, "  </Domain>\n</Xdmf>\n");
  PM_CHECK(!ferror(fp), PM_ERR_IO, "write error on '%s'", r->xdmf_path);
  return PM_SUCCESS;
}

/* ---- Close ------------------------------------------------------------- */

pm_err pm_results_close(pm_results *r, bool keep) {
  pm_err ret = PM_SUCCESS;
  pm_afile *xdmf = NULL;
  const char *path;
  bool renamed = false;
  if (!r) return PM_SUCCESS;
  path = r->tmp_path;
  if (keep) {
    PM_TRY(pm_afile_open(r->xdmf_path, &xdmf));
    PM_TRY(xdmf_write(r, pm_afile_stream(xdmf)));
  }
  for (int i = 0; i < 3; i++) {
    H5_OK(H5Sclose(r->space[i]), "H5Sclose", "field space", path);
    r->space[i] = -1;
  }
  H5_OK(H5Pclose(r->gcpl), "H5Pclose", "gcpl", path);
  r->gcpl = -1;
  H5_OK(H5Gclose(r->frames), "H5Gclose", "/frames", path);
  r->frames = -1;
  H5_OK(H5Fclose(r->file), "H5Fclose", "/", path);
  r->file = -1;
  if (keep) {
    PM_TRY(pm_rename(r->tmp_path, r->final_path));
    renamed = true;
    pm_afile *x = xdmf; /* commit frees it, even on failure */
    xdmf = NULL;
    PM_TRY(pm_afile_commit(x));
  }
done:
  pm_afile_abort(xdmf);
  results_free(r, !renamed);
  return ret;
}
