/* mpm_report: what an MPM run reports about itself: summary.json at the
 * end of a run, and the plan (mpm_run_plan, declared in mpm_driver.h). */
#ifndef MPM_REPORT_H
#define MPM_REPORT_H

#include "mpm_driver.h"

/* Write out_dir/summary.json of run r: status, counts, options, step
 * figures, energies (totals and per stage), field figures, timings,
 * errors and reactions.  Uses r->scratch.  Fails with PM_ERR_IO. */
pm_err mpm_report_summary(const mpm_run *r, const char *out_dir);

#endif
