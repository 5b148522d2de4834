/* pm_probe_impl: what pm_probe.c (the displacement at points) and
 * pm_probe_points.c (the points' own values) share: the results file
 * opened at a frame, and the query points of a CSV file. */
#ifndef PM_PROBE_IMPL_H
#define PM_PROBE_IMPL_H

#include <hdf5.h>

#include "pm_error.h"
#include "pm_mls.h"

#define OBJ_NAME_MAX 64

/* The result points, the chosen frame's displacement and their
 * moving-least-squares cloud. */
typedef struct {
  long n;
  double *x, *u; /* [n][3] each */
  pm_mls *mls;
} cloud;

/* The query points and the CSV line each came from (for messages). */
typedef struct {
  long m, cap;
  double *p; /* [m][3] */
  long *line;
} queries;

/* The results file: its handle, the reference coordinates, and frame
 * `frame` (last when < 0) opened as a group, with that frame's index.
 * HDF5's own error printing is off while it is open (pm_probe_results_close
 * restores the caller's). */
typedef struct {
  hid_t file, group;
  long frame;
  long *order; /* the frame's rows' one-process indices, or NULL */
  H5E_auto2_t old_func;
  void *old_data;
} results;

/* Open path at frame `frame` (last when < 0): the reference coordinates
 * into c (one-process order), the frame's group and row order into r. */
pm_err pm_probe_results_open(const char *path, long frame, cloud *c,
                             results *r);
void pm_probe_results_close(results *r);
/* Rows v[n][width] in piece order into one-process order (index from the
 * file; nothing to do when NULL). */
pm_err pm_probe_in_order(double *v, long n, int width, const long *index);
/* Every point of the CSV file, skipping blanks, comments and a header. */
pm_err pm_probe_read_points(const char *csv, queries *qs);
void pm_probe_cloud_free(cloud *c);
/* A read of the results file path by HDF5 in a child (pm_isolate.h):
 * work there, its result passed back by put and taken by get. */
pm_err pm_probe_isolate(const char *path, pm_err (*work)(void *),
                        pm_err (*put)(void *, int), pm_err (*get)(void *, int),
                        void *arg);
/* The cloud's fit structure, named by its results file in messages. */
pm_err pm_probe_index_cloud(cloud *c, const char *path);

#endif
