/* pm_output_index: the files that describe the frames written whole:
 * results.xdmf (a temporal collection of grids) and results.h5 (attributes
 * and external links to the mesh and the frames); and the XDMF grid of a
 * frame.  pm_output_append.c appends to them. */
#include <hdf5.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_output_impl.h"

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
pm_err pm_output_xdmf_frame(pm_results *r, long k, long step, double time,
                            int nf, const char *const *names,
                            const int *ncomp) {
  char tbuf[40], file[32], name[32], head[160];
  format_double(tbuf, sizeof tbuf, time);
  snprintf(file, sizeof file, FRAME_FMT, k);
  snprintf(name, sizeof name, "frame_%06ld", k);
  snprintf(head, sizeof head,
           "        <Time Value=\"%s\"/>\n"
           "        <Information Name=\"step\" Value=\"%ld\"/>\n",
           tbuf, step);
  grid_data g = {file, nf, names, ncomp};
  r->last_at = r->frames.len;
  return grid_add(&r->frames, r, 6, name, head, &g);
}

/* results.xdmf: the frames' temporal collection (or the bare mesh). */
pm_err pm_output_xdmf_commit(const pm_results *r) {
  pm_err ret = PM_SUCCESS;
  pm_afile *f = NULL;
  xml_text bare = {0};
  const xml_text *grids = &r->frames;
  PM_CHECK(r->text_from == 0, PM_ERR_INTERNAL,
           "results.xdmf: the grids of frames before %ld are not at hand",
           r->text_from);
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
  fputs(r->n_frames > 0 ? XDMF_TAIL : "  </Domain>\n</Xdmf>\n", fp);
  ret = pm_afile_commit(f);
done:
  free(bare.s);
  return ret;
}

/* ---- Index -------------------------------------------------------------- */

/* results.h5: attributes and external links to the mesh and the frames. */
pm_err pm_output_index_commit(const pm_results *r) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1, frames = -1, gcpl = -1;
  char tmp[PM_PATH_MAX + 40], name[32], target[64];
  const char *path = tmp;
  long nf = r->n_frames;
  pm_output_tmp_name(tmp, sizeof tmp, r->index_path);
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
  PM_TRY(pm_output_commit(&file, tmp, r->index_path));
done:
  pm_h5_close_quiet(&gcpl);
  pm_h5_close_quiet(&frames);
  pm_h5_close_quiet(&file);
  if (ret != PM_SUCCESS) unlink(tmp);
  return ret;
}
