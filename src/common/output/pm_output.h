/* pm_output: simulation results that survive interruption, as
 * OUT/results.h5 (HDF5) plus OUT/results.xdmf (XDMF 3 temporal collection)
 * so ParaView opens them directly, also while the run goes on.
 *
 * Every frame is a file of its own, written under a temporary name, synced
 * and renamed; then the index (results.h5) and results.xdmf are replaced
 * the same way, by spares one frame behind (results/.spare-results.h5 and
 * .spare-results.xdmf) given the new frame in place, so that a frame costs
 * the same at any length of run.  A process killed at any moment leaves
 * every earlier frame whole and an index and XDMF that point only at
 * frames that exist; no file is held open between frames, so readers never
 * meet a lock.
 *
 * Layout (every name fixed; readers such as probe rely on it):
 *   OUT/results/mesh.h5          /coordinates float64 [n_points][3]
 *                                reference coordinates; /cells int64
 *                                [n_cells][nodes_per_cell] point indices,
 *                                attribute nodes_per_cell (int); with a
 *                                surface, /surface int64 [n][3] triangles
 *                                over the same points, attribute name
 *                                (string: "membrane")
 *   OUT/results/frame_NNNNNN.h5  one frame, NNNNNN = frame index from
 *                                000000: root attributes step (int64) and
 *                                time (float64); one dataset per field,
 *                                float64 [n_points] (scalar), [n_points][3]
 *                                (vector) or [n_points][3][3] (tensor,
 *                                row-major).  A vector field named
 *                                "position" is the frame's geometry
 *                                (particles that move).
 *   OUT/results.h5               the index: attributes scene (string, full
 *                                scene text), version (string), dim (int: 2
 *                                or 3), frames (int64); /mesh an external
 *                                link to results/mesh.h5, /frames/NNNNNN
 *                                external links to the frames (creation
 *                                order tracked), so that results.h5 reads
 *                                as one file (/frames/000003/displacement).
 *   OUT/results.xdmf             a temporal collection of one uniform grid
 *                                per frame (Name frame_NNNNNN; Time, and
 *                                Information step), or before the first
 *                                frame the bare mesh (Name mesh).  With a
 *                                surface, each of these is instead a
 *                                spatial collection of the same name
 *                                holding two uniform grids, "points" (the
 *                                cells) and "membrane" (the surface's
 *                                triangles), with the same geometry and
 *                                attributes. */
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

/* The points results are written on (and a run measures): n >= 1
 * reference positions x[3*i + k]; for a mesh its cells, cells[c *
 * nodes_per_cell + k] point indices (nodes_per_cell 1 = point cloud, XDMF
 * Polyvertex, where cells may be NULL: one cell per point, n_cells
 * ignored; 3 = triangles; 4 = tetrahedra in 3-D, quadrilaterals in 2-D);
 * and triangles over the same points, surface[3*t + k] (an MPM membrane),
 * written as a second grid named "membrane" (n_surface 0 / NULL: none).
 * Indices are in [0, n).  Borrowed: a backend's, for as long as it
 * lives. */
typedef struct {
  long n;
  const double *x;
  long n_cells;
  int nodes_per_cell;
  const long *cells;
  long n_surface;
  const long *surface;
} pm_points;

/* Start results in dir (which must exist: see pm_mkdir_p) on the points
 * p (dim 2 or 3, stored; 2-D coordinates still carry z): writes
 * results/mesh.h5, an index with no frame and results.xdmf with the bare
 * mesh, replacing older ones.  scene_text, version: stored in the index
 * (NULL stored as "").  *out is owned by the caller and released by
 * pm_results_close.  Silences HDF5's automatic error printing for the
 * process.  Fails with PM_ERR_ARG (bad sizes, a cell or triangle index out
 * of range), PM_ERR_IO (dir missing or not writable, a write refused:
 * naming the path and the system's reason), PM_ERR_HDF5 (naming the call
 * and object), PM_ERR_MEMORY.  On failure nothing is left on disk. */
pm_err pm_results_create_ex(const char *dir, int dim, const pm_points *p,
                            const char *scene_text, const char *version,
                            pm_results **out);

/* pm_results_create_ex on points without a surface. */
pm_err pm_results_create(const char *dir, int dim, long n_points,
                         const double *x, long n_cells, int nodes_per_cell,
                         const long *cells, const char *scene_text,
                         const char *version, pm_results **out);

/* Continue the results in dir with their first n_keep frames (a resumed
 * run): later frames and the spares are deleted, the index and
 * results.xdmf rewritten whole from the frames kept (and mesh.h5's
 * surface, if any).  n_points must match the mesh.  Fails with
 * PM_ERR_IO / PM_ERR_HDF5 naming what is missing or unreadable. */
pm_err pm_results_reopen(const char *dir, long n_points, long n_keep,
                         pm_results **out);

/* Append frame NNNNNN (the next index) with attributes step and time and
 * one dataset per field, synced to disk, then replace the index and the
 * XDMF (through their spares).  Fails with PM_ERR_ARG (bad field: name, ncomp,
 * NULL data, duplicate) before writing anything, PM_ERR_IO (a write refused,
 * e.g. the disk is full or the file size limit is reached: naming the file and
 * the reason) or PM_ERR_HDF5; after a failure the frame's temporary file is
 * gone and the earlier frames, index and XDMF are as they were. */
pm_err pm_results_write_frame(pm_results *r, long step, double time,
                              int n_fields, const pm_field *fields);

/* ---- A frame in pieces (a run shared among ranks) ----------------------
 * Each rank writes its own points of a frame, and no process holds them
 * all:
 *   OUT/results/frame_NNNNNN.piece_RRRR.h5  piece RRRR (a rank's points):
 *                                root attributes step and time, one
 *                                dataset per field over its points (as a
 *                                frame's), and /index int64 [n] their
 *                                one-process indices
 * then rank 0, once every piece is on disk, the frame's own file
 * frame_NNNNNN.h5, whose datasets (each field, and /index) are HDF5
 * virtual datasets joining the pieces in piece order, and the index and
 * results.xdmf as for any frame: ParaView and h5py read one dataset per
 * field a frame.  Its points are in piece order; /index puts them in one
 * process's order (point index[i] is row i).  Points only (no cells, no
 * surface: those index one-process order), with a field "position", the
 * frame's geometry. */
#define PM_PIECE_INDEX "index"

/* Piece piece (>= 0) of frame frame of the results in dir: n >= 0 points,
 * their one-process indices index[0..n), the fields over them (as
 * pm_results_write_frame's), synced and renamed whole.  Errors as
 * pm_results_write_frame's. */
pm_err pm_results_write_piece(const char *dir, long frame, int piece, long n,
                              const long *index, long step, double time,
                              int n_fields, const pm_field *fields);

/* The next frame of r from its n_pieces pieces already on disk, counts[k]
 * points in piece k (summing to r's points), with the fields the pieces
 * hold (names and components as given; data unread): frame_NNNNNN.h5 of
 * virtual datasets, then the index and XDMF.  Errors as
 * pm_results_write_frame's. */
pm_err pm_results_join_pieces(pm_results *r, long step, double time,
                              int n_pieces, const long *counts, int n_fields,
                              const pm_field *fields);

/* Number of frames written so far (with those kept by pm_results_reopen). */
long pm_results_frames(const pm_results *r);

/* Release r (NULL accepted).  keep false and no frame written: the files
 * pm_results_create wrote are removed (a run that failed before its first
 * frame leaves nothing).  Frames are never removed.  Cannot fail. */
void pm_results_close(pm_results *r, bool keep);

#endif
