/* pm_output_pieces: a frame written in pieces, each by the rank that holds
 * its points, joined by a frame file of HDF5 virtual datasets (pm_output.h).
 * A piece is written as a frame's file is (under a temporary name, synced,
 * renamed), so a frame file never names a piece that is not whole; the
 * frame file maps the pieces' datasets one after the other (a block a
 * piece), which costs the same whatever the decomposition, where writing
 * scattered one-process places would cost a piece per run of points. */
#include <errno.h>
#include <hdf5.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_h5.h"
#include "pm_output_impl.h"

#define PIECE_FMT "frame_%06ld.piece_%04d.h5"

pm_err pm_results_write_piece(const char *dir, long frame, int piece, long n,
                              const long *index, long step, double time,
                              int n_fields, const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  char sub[PM_PATH_MAX + 1], name[64], path[PM_PATH_MAX + 1],
      tmp[PM_PATH_MAX + 40];
  PM_CHECK(frame >= 0 && piece >= 0 && n >= 0 && (n == 0 || index), PM_ERR_ARG,
           "results piece %d of frame %ld: %ld points", piece, frame, n);
  PM_CALL(pm_output_check_fields(n_fields, fields));
  PM_CALL(pm_path_join(sub, sizeof sub, dir, RESULTS_SUBDIR));
  snprintf(name, sizeof name, PIECE_FMT, frame, piece);
  PM_CALL(pm_path_join(path, sizeof path, sub, name));
  pm_output_tmp_name(tmp, sizeof tmp, path);
  double bytes = H5_OVERHEAD + 8.0 * (double)n;
  for (int i = 0; i < n_fields; i++) bytes += 8.0 * fields[i].ncomp * (double)n;
  PM_CALL(pm_output_check_room(sub, path, bytes));
  errno = 0;
  ret = pm_output_frame_file(tmp, n, index, step, time, n_fields, fields);
  int saved = errno;
  PM_TRY(pm_output_classify(ret, saved, path));
  PM_TRY(pm_sync_rename(tmp, path));
done:
  unlink(tmp);
  return ret;
}

/* Dataset name of the frame file under tmp: the pieces' datasets of that
 * name, of ncomp components (file type ftype), one block after another. */
static pm_err join_dataset(hid_t file, const char *name, int ncomp, hid_t ftype,
                           long frame, int n_pieces, const long *counts,
                           const char *tmp) {
  pm_err ret = PM_SUCCESS;
  hid_t vspace = -1, sspace = -1, dcpl = -1, dset = -1;
  const char *path = tmp;
  const int rank = ncomp == 1 ? 1 : ncomp == 3 ? 2 : 3;
  long total = 0;
  for (int k = 0; k < n_pieces; k++) total += counts[k];
  hsize_t dims[3] = {(hsize_t)total, 3, 3}, start[3] = {0, 0, 0};
  H5_OK(vspace = H5Screate_simple(rank, dims, NULL), "H5Screate_simple", name,
        path);
  H5_OK(dcpl = H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate", name, path);
  for (int k = 0; k < n_pieces; k++) {
    if (counts[k] == 0) continue;
    char source[64];
    snprintf(source, sizeof source, PIECE_FMT, frame, k);
    hsize_t block[3] = {(hsize_t)counts[k], 3, 3};
    H5_OK(H5Sselect_hyperslab(vspace, H5S_SELECT_SET, start, NULL, block, NULL),
          "H5Sselect_hyperslab", name, path);
    H5_OK(sspace = H5Screate_simple(rank, block, NULL), "H5Screate_simple",
          name, path);
    /* A source named without a folder is found beside the frame file. */
    H5_OK(H5Pset_virtual(dcpl, vspace, source, name, sspace), "H5Pset_virtual",
          name, path);
    pm_h5_close_quiet(&sspace);
    start[0] += block[0];
  }
  H5_OK(H5Sselect_all(vspace), "H5Sselect_all", name, path);
  H5_OK(dset = H5Dcreate2(file, name, ftype, vspace, H5P_DEFAULT, dcpl,
                          H5P_DEFAULT),
        "H5Dcreate2", name, path);
  H5_OK(H5Dclose(dset), "H5Dclose", name, path);
  dset = -1;
done:
  pm_h5_close_quiet(&dset);
  pm_h5_close_quiet(&dcpl);
  pm_h5_close_quiet(&sspace);
  pm_h5_close_quiet(&vspace);
  return ret;
}

/* The frame file of frame (under tmp) joining its pieces. */
static pm_err join_file(const char *tmp, long frame, long step, double time,
                        int n_pieces, const long *counts, int n_fields,
                        const pm_field *fields) {
  pm_err ret = PM_SUCCESS;
  hid_t file = -1;
  const char *path = tmp;
  PM_TRY(pm_output_frame_open(tmp, step, time, &file));
  PM_TRY(pm_h5_write_attr(file, "pieces", H5T_STD_I32LE, H5T_NATIVE_INT,
                          &n_pieces, path));
  for (int i = 0; i < n_fields; i++)
    PM_TRY(join_dataset(file, fields[i].name, fields[i].ncomp, H5T_IEEE_F64LE,
                        frame, n_pieces, counts, tmp));
  PM_TRY(join_dataset(file, PM_PIECE_INDEX, 1, H5T_STD_I64LE, frame, n_pieces,
                      counts, tmp));
  H5_OK(H5Fclose(file), "H5Fclose", "/", path);
  file = -1;
done:
  pm_h5_close_quiet(&file);
  return ret;
}

pm_err pm_results_join_pieces(pm_results *r, long step, double time,
                              int n_pieces, const long *counts, int n_fields,
                              const pm_field *fields) {
  char path[PM_PATH_MAX + 1], tmp[PM_PATH_MAX + 40];
  PM_CHECK(r && n_pieces >= 1 && counts, PM_ERR_ARG,
           "pm_results_join_pieces: no results or no pieces");
  PM_CALL(pm_output_check_fields(n_fields, fields));
  PM_CHECK(n_fields <= 16, PM_ERR_ARG, "results frame: %d fields (16 at most)",
           n_fields);
  /* The pieces' rows are in piece order: the mesh's coordinates, cells
   * and triangles, in one-process order, cannot be drawn over them. */
  PM_CHECK(r->nodes_per_cell == 1 && r->n_surface == 0, PM_ERR_ARG,
           "results frame in pieces: only points without cells or a surface "
           "(these have %ld cells of %d points and %ld triangles)",
           r->n_cells, r->nodes_per_cell, r->n_surface);
  bool geometry = false;
  for (int i = 0; i < n_fields; i++)
    geometry |= fields[i].ncomp == 3 && strcmp(fields[i].name, "position") == 0;
  PM_CHECK(geometry, PM_ERR_ARG,
           "results frame in pieces: no field \"position\" (each piece's "
           "points, the frame's geometry)");
  long total = 0;
  for (int k = 0; k < n_pieces; k++) {
    PM_CHECK(counts[k] >= 0, PM_ERR_ARG, "results piece %d: %ld points", k,
             counts[k]);
    total += counts[k];
  }
  PM_CHECK(total == r->n_points, PM_ERR_ARG,
           "results frame: its pieces hold %ld points, the results %ld", total,
           r->n_points);
  pm_output_frame_path(r, r->n_frames, path, sizeof path);
  pm_output_tmp_name(tmp, sizeof tmp, path);
  PM_CALL(pm_output_check_room(r->sub, path, H5_OVERHEAD * (n_fields + 1)));
  errno = 0;
  pm_err written = join_file(tmp, r->n_frames, step, time, n_pieces, counts,
                             n_fields, fields);
  return pm_output_add_frame(r, tmp, written, errno, step, time, n_fields,
                             fields);
}
