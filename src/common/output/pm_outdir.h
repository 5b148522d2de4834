/* pm_outdir: a run's output folder, claimed and locked for one run at a
 * time.  Included by pm_files.h. */
#ifndef PM_OUTDIR_H
#define PM_OUTDIR_H

#include <stddef.h>

#include "pm_error.h"

/* How a run takes its output folder. */
typedef enum {
  PM_OUTDIR_NEW = 0,   /* refuse a folder holding another run's files */
  PM_OUTDIR_OVERWRITE, /* remove another run's files first */
  PM_OUTDIR_RESUME     /* continue the run whose files are there */
} pm_outdir_mode;

/* A folder held by this process for a run. */
typedef struct pm_outdir pm_outdir;

/* Claim dir for a run: create it (and its parents) unless resuming, check
 * that it is writable, lock it (DIR/.pointmech.lock holds the pid; the
 * lock dies with the process, so a killed run never blocks the next one),
 * remove the temporary files a killed run left (RUNFILE.tmp.PID; nothing
 * else), and apply mode to the files
 * a run writes (summary.json, history.csv, results.h5, results.xdmf,
 * checkpoint.h5, results/).  Fails with PM_ERR_IO naming the folder and the
 * reason: not writable, in use by a running pointmech (its pid), or, for
 * PM_OUTDIR_NEW, holding another run's files (and its status).  Release
 * with pm_outdir_release. */
pm_err pm_outdir_claim(const char *dir, pm_outdir_mode mode, pm_outdir **out);

/* The status member of dir/summary.json into buf ("" when there is
 * none). */
void pm_summary_status(const char *dir, char *buf, size_t size);

/* Unlock and free (NULL accepted).  A folder the claim created and
 * nothing was written to is removed. */
void pm_outdir_release(pm_outdir *d);

#endif
