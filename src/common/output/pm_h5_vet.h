/* pm_h5_vet: HDF5 files a run reads back (its checkpoint, its results
 * folder) read whole by HDF5 in a child process (pm_isolate.h) before the
 * process reads them itself: libhdf5 1.10 stops the process on some
 * damaged files (reads past a damaged link or global heap, loops in one),
 * and such a file is refused by name instead.  The child visits every
 * object the readers could reach through the library: groups and their
 * links (a soft link's value, and the object it leads to), every attribute
 * read in its own type (strings as the readers read them), datasets'
 * shapes and types and, where asked, their values. */
#ifndef PM_H5_VET_H
#define PM_H5_VET_H

#include <stdbool.h>

#include "pm_error.h"
#include "pm_output.h"

/* The most CPU seconds the child may spend on each file (SIGXCPU past
 * it): a damaged global heap can loop HDF5 for ever, and reading a file
 * from the page cache takes a small fraction of this.  Memory: 1 GB and 16
 * times the file's size more than the process had. */
#define PM_H5_VET_CPU_SECONDS 10.0

/* Vet the n files paths[0..n) in one child: values read when data is
 * true.  A child stopped by a signal: code with "PATH: HDF5 stopped with
 * SIGSEGV while reading it: the file is damaged or not WHAT", PATH the
 * file it was reading; a value HDF5 fails to read (in the child's memory:
 * PM_H5_VET_CPU_SECONDS): code with "PATH: HDF5 cannot read attribute
 * NAME of OBJECT (WHY): ...".  HDF5's other errors (a file it cannot open,
 * an object it cannot open) pass: the readers report them in their
 * words. */
pm_err pm_h5_vet(const char *const *paths, int n, bool data, const char *what,
                 pm_err code);

/* dir/checkpoint.h5 vetted with its values, when there is one: what
 * `resume` reads before it trusts the checkpoint (PM_ERR_IO). */
pm_err pm_ckpt_vet(const char *dir);

/* The results a resumed run reopens (pm_results_reopen: r's paths set),
 * vetted without their values: the index, the mesh and frames 0 to
 * n_keep - 1 (PM_ERR_HDF5). */
pm_err pm_results_vet(const pm_results *r, long n_keep);

/* What `pointmech vet PATH` vets, with the values: the file PATH, or every
 * .h5 file of the folder PATH and of its results/ (a run's index, mesh,
 * frames and checkpoint), in one child (PM_ERR_HDF5; PM_ERR_IO for a PATH
 * that is neither).  For a reader outside the program (the Python module)
 * before it opens them. */
pm_err pm_h5_vet_path(const char *path);

#endif
