/* pm_output: simulation results as OUT/results.h5 (HDF5) plus OUT/results.xdmf
 * (XDMF 3 temporal collection) so ParaView opens them directly.
 *
 * Layout of results.h5 (every name fixed; readers such as probe rely on it):
 *   /                       attributes: scene (string, full scene text),
 *                           version (string), dim (int: 2 or 3)
 *   /mesh/coordinates       float64 [n_points][3] reference coordinates
 *   /mesh/cells             int64 [n_cells][nodes_per_cell] point indices,
 *                           attribute nodes_per_cell (int)
 *   /frames/NNNNNN          one group per frame, NNNNNN = frame index from
 *                           000000 (links in creation order), attributes
 *                           step (int64) and time (float64)
 *   /frames/NNNNNN/<field>  float64 [n_points] (scalar), [n_points][3]
 *                           (vector) or [n_points][3][3] (tensor, row-major)
 * The file is written as results.h5.tmp.<pid> and renamed on close. */
#ifndef PM_OUTPUT_H
#define PM_OUTPUT_H

#include <stdbool.h>

#include "pm_error.h"

/* One node-centred field of a frame.  name: letters, digits, '_', '-', '.'
 * (not starting with '.'), at most 63 bytes, unique in the frame.  ncomp:
 * 1 (scalar), 3 (vector) or 9 (tensor, row-major 3x3).  data: ncomp values
 * per point, point-major (data[i*ncomp + c]); borrowed for the call. */
typedef struct {
  const char *name;
  int ncomp;
  const double *data;
} pm_field;

typedef struct pm_results pm_results;

/* Create dir/results.h5.tmp.<pid> (dir must exist: see pm_mkdir_p) holding
 * the mesh and the root attributes.
 *   dim:            2 or 3 (stored; 2-D coordinates still carry z)
 *   n_points, x:    n_points >= 1 points, x[3*i + k] (borrowed)
 *   n_cells, nodes_per_cell, cells: cells[c*nodes_per_cell + k], indices in
 *                   [0, n_points) (borrowed).  nodes_per_cell 1 = point
 *                   cloud (XDMF Polyvertex), 3 = triangles, 4 = tetrahedra
 *                   (dim 3) or quadrilaterals (dim 2).  For a point cloud
 *                   cells may be NULL: one cell per point, n_cells ignored.
 *   scene_text, version: stored as root attributes (NULL stored as "").
 * *out is owned by the caller and released by pm_results_close.  Silences
 * HDF5's automatic error printing for the process.  Fails with PM_ERR_ARG
 * (bad sizes, cell index out of range), PM_ERR_IO (dir missing or not
 * writable, naming it), PM_ERR_HDF5 (naming the call and object),
 * PM_ERR_MEMORY.  On failure nothing is left on disk. */
pm_err pm_results_create(const char *dir, int dim, long n_points,
                         const double *x, long n_cells, int nodes_per_cell,
                         const long *cells, const char *scene_text,
                         const char *version, pm_results **out);

/* Append frame /frames/NNNNNN with attributes step and time and one dataset
 * per field, then flush the file so that it stays readable if the run dies.
 * Allocates nothing itself (HDF5 does internally).  Fails with PM_ERR_ARG
 * (bad field: name, ncomp, NULL data, duplicate) before writing anything,
 * or PM_ERR_HDF5; after a PM_ERR_HDF5 the results should be closed with
 * keep = false. */
pm_err pm_results_write_frame(pm_results *r, long step, double time,
                              int n_fields, const pm_field *fields);

/* Number of frames written so far. */
long pm_results_frames(const pm_results *r);

/* keep: write dir/results.xdmf.tmp.<pid> from the frames in the file (one
 * uniform grid per frame, Time = the frame's time; the bare mesh when no
 * frame was written), close the HDF5 file, rename it to dir/results.h5 and
 * commit the XDMF (both replace older files).  !keep: close and delete the
 * temporary file, leaving older results alone.  Always frees r (NULL
 * accepted).  On failure (PM_ERR_HDF5 / PM_ERR_IO) the temporary files are
 * deleted; only a failure of the very last step (XDMF rename) can leave a
 * new results.h5 without its results.xdmf. */
pm_err pm_results_close(pm_results *r, bool keep);

#endif
