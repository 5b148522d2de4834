/* pm_output_impl: the results' state and the functions the files of
 * pm_output share (files written whole, paths, index and XDMF); not for
 * callers of pm_output.h. */
#ifndef PM_OUTPUT_IMPL_H
#define PM_OUTPUT_IMPL_H

#include <hdf5.h>
#include <stdbool.h>
#include <stddef.h>

#include "pm_files.h"
#include "pm_output.h"

#define FIELD_NAME_MAX 63
#define OBJ_NAME_MAX 128
#define RESULTS_SUBDIR "results"
#define FRAME_FMT "frame_%06ld.h5"
#define POINTS_GRID "points" /* the cells' grid beside a surface's */
#define SURFACE_NAME "membrane"

/* HDF5's own overhead of a small file, bytes (headers, attributes). */
#define H5_OVERHEAD 16384.0

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
  /* The XDMF grids of frames [text_from, n_frames), the last one from
   * byte last_at: all of them after a reopen, else the one or two that
   * the spare XDMF lacks. */
  xml_text frames;
  long text_from;
  size_t last_at;
  /* results.h5 and results.xdmf each have a spare, the file they replaced
   * (results/.spare-*): the next frame is appended to the spare in place,
   * which then replaces the published file, so a frame costs the same at
   * any length of run.  Frames each holds; -1: unknown (rebuilt). */
  long index_published, index_spare, xdmf_published, xdmf_spare;
  char dir[PM_PATH_MAX + 1];
  char sub[PM_PATH_MAX + 1];        /* dir/results */
  char index_path[PM_PATH_MAX + 1]; /* dir/results.h5 */
  char xdmf_path[PM_PATH_MAX + 1];  /* dir/results.xdmf */
  char mesh_path[PM_PATH_MAX + 1];  /* dir/results/mesh.h5 */
  char index_spare_path[PM_PATH_MAX + 1], index_prev_path[PM_PATH_MAX + 1];
  char xdmf_spare_path[PM_PATH_MAX + 1], xdmf_prev_path[PM_PATH_MAX + 1];
};

/* The names of the spares in dir/results (with ".prev": the published
 * file's second name while a spare replaces it). */
#define SPARE_PREFIX ".spare-"
#define INDEX_SPARE SPARE_PREFIX "results.h5"
#define XDMF_SPARE SPARE_PREFIX "results.xdmf"

/* How results.xdmf ends once it holds a frame (its temporal collection
 * closed). */
#define XDMF_TAIL "    </Grid>\n  </Domain>\n</Xdmf>\n"

/* ---- pm_output_write.c ---- */

/* path + ".tmp.<pid>" into buf. */
void pm_output_tmp_name(char *buf, size_t size, const char *path);

/* Close the HDF5 file written under tmp (*file = -1) and commit it to
 * path. */
pm_err pm_output_commit(hid_t *file, const char *tmp, const char *path);

/* An HDF5 failure e that the system caused (saved_errno: no space, file
 * too large, no permission) as an I/O error naming path; else e. */
pm_err pm_output_classify(pm_err e, int saved_errno, const char *path);

/* PM_ERR_IO for a file of about bytes that the file size limit or the free
 * space on dir's disk cannot hold. */
pm_err pm_output_check_room(const char *dir, const char *path, double bytes);

/* Write the dataset loc/name of rank dims (file type ftype, memory mtype;
 * data NULL: made, its values left for the caller to write);
 * keep_open: its handle is left open there (else NULL). */
pm_err pm_output_dataset(hid_t loc, const char *name, int rank,
                         const hsize_t *dims, hid_t ftype, hid_t mtype,
                         const void *data, const char *path, hid_t *keep_open);

/* ---- pm_output.c ---- */

/* PM_ERR_IO unless output folder dir exists and is writable (PM_ERR_ARG
 * when empty). */
pm_err pm_output_check_dir(const char *dir);

/* r's paths below dir (PM_ERR_ARG when too long). */
pm_err pm_output_set_paths(pm_results *r, const char *dir);

/* The path of frame k's file into buf. */
void pm_output_frame_path(const pm_results *r, long k, char *buf, size_t size);

/* Frees r and all it holds (NULL accepted). */
void pm_output_free(pm_results *r);

/* PM_ERR_ARG unless n_fields fields are well formed (plain unique names,
 * 1, 3 or 9 components, data). */
pm_err pm_output_check_fields(int n_fields, const pm_field *fields);

/* A frame's HDF5 file created under tmp (*out, open) with its attributes
 * step and time, its datasets to keep their order of creation. */
pm_err pm_output_frame_open(const char *tmp, long step, double time,
                            hid_t *out);

/* A frame's HDF5 file of n points under tmp: attributes step and time, a
 * dataset per field, and with index (a piece of a frame across ranks) the
 * points' one-process indices as dataset PM_PIECE_INDEX. */
pm_err pm_output_frame_file(const char *tmp, long n, const long *index,
                            long step, double time, int n_fields,
                            const pm_field *fields);

/* Frame r->n_frames, written under tmp (written: how that went, with the
 * errno it left), renamed into place, then into the XDMF text, the index
 * and results.xdmf; tmp is gone after, and after a failure the frame too,
 * the index and XDMF being those of the frames before. */
pm_err pm_output_add_frame(pm_results *r, const char *tmp, pm_err written,
                           int written_errno, long step, double time,
                           int n_fields, const pm_field *fields);

/* ---- pm_output_index.c ---- */

/* Appends frame k's grid (nf fields: their names and component counts)
 * to r's XDMF text. */
pm_err pm_output_xdmf_frame(pm_results *r, long k, long step, double time,
                            int nf, const char *const *names, const int *ncomp);

/* Rewrites results.h5 whole (attributes and external links to the mesh
 * and the frames). */
pm_err pm_output_index_commit(const pm_results *r);

/* Rewrites results.xdmf whole from r's text, which must hold every
 * frame's grid. */
pm_err pm_output_xdmf_commit(const pm_results *r);

/* ---- pm_output_append.c ---- */

/* Brings results.h5, then results.xdmf, to r's n_frames frames: through
 * the spares when they lack one or two frames, else rewritten whole (r's
 * text then holds every frame's grid). */
pm_err pm_output_publish(pm_results *r);

/* Forget the spares' contents (after a failure: they are rebuilt). */
void pm_output_spares_unknown(pm_results *r);

#endif
