/* pm_run_resume: a run resumed from its output folder's checkpoint: the
 * checks that it can be, the scene it names, and every rank's part. */
#include <stdio.h>
#include <string.h>

#include "pm_h5_vet.h"
#include "pm_memory.h"
#include "pm_output.h"
#include "pm_par.h"
#include "pm_run_impl.h"

/* The overrides of a checkpoint (one per line) as an argument vector
 * pointing into text (changed in place). */
static int split_overrides(char *text, char **argv, int max) {
  int n = 0;
  for (char *p = text; *p && n < max;) {
    char *nl = strchr(p, '\n');
    if (nl) *nl = '\0';
    argv[n++] = p;
    if (!nl) break;
    p = nl + 1;
  }
  return n;
}

/* What every rank reads and checks before a resumed run is set up: rank 0
 * claims the folder and checks that its run can be resumed; each rank
 * opens the checkpoint, reads the driver's items and loads the scene they
 * name, which must be the one the checkpoint was made of. */
static pm_err resume_open(const char *out_dir, pm_run_resume_info *rs,
                          pm_outdir **outdir, pm_scene **s, char **argv) {
  if (pm_par_root()) {
    PM_CALL(pm_outdir_claim(out_dir, PM_OUTDIR_RESUME, outdir));
    /* A run that ended by itself has nothing to resume; one that was
     * interrupted, killed (still "running") or failed on I/O has. */
    char status[64];
    pm_summary_status(out_dir, status, sizeof status);
    PM_CHECK(!status[0] || !strcmp(status, "interrupted") ||
                 !strcmp(status, "running") || !strcmp(status, "failed"),
             PM_ERR_ARG,
             "cannot resume '%s': its run has ended (status \"%s\"); start "
             "a new run (--overwrite) to run it again",
             out_dir, status);
  }
  PM_CALL(pm_ckpt_vet(out_dir));
  PM_CALL(pm_ckpt_open(out_dir, &rs->ck));
  PM_CALL(pm_run_header_items(rs->ck, &rs->h));
  PM_CHECK(strcmp(rs->h.version, PM_VERSION) == 0, PM_ERR_ARG,
           "cannot resume '%s': its checkpoint was written by pointmech %s, "
           "this is pointmech %s",
           out_dir, rs->h.version, PM_VERSION);
  int n_sets = split_overrides(rs->h.overrides, argv, 256);
  PM_CALL(
      pm_scene_load(rs->h.scene_path, n_sets, (const char *const *)argv, s));
  PM_CHECK(strcmp((*s)->text, rs->h.scene_text) == 0, PM_ERR_ARG,
           "cannot resume '%s': the scene %s has changed since its "
           "checkpoint (step %ld); restore it, or start a new run",
           out_dir, rs->h.scene_path, rs->h.step);
  PM_CHECK(strcmp((*s)->method, rs->h.method) == 0, PM_ERR_ARG,
           "cannot resume '%s': the checkpoint is of method %s, the scene "
           "now names %s",
           out_dir, rs->h.method, (*s)->method);
  return PM_SUCCESS;
}

/* A rank other than 0 resuming a run across ranks: it reads the
 * backend's items of the checkpoint too (into the whole state it holds
 * until the run starts), then steps its share. */
static pm_err resume_worker(const pm_scene *s, void *sim,
                            pm_run_resume_info *rs, pm_outcome *o) {
  pm_err e = s->backend->checkpoint
                 ? s->backend->checkpoint(sim, rs->ck)
                 : PM_ERROR(PM_ERR_ARG, "method %s cannot resume", s->method);
  if (!e) {
    pm_ckpt *ck = rs->ck;
    rs->ck = NULL;
    e = pm_ckpt_finish(ck);
  }
  if (e) return pm_par_agree(e); /* rank 0 hears it before its run */
  return pm_run_worker(s, sim, o);
}

pm_err pm_resume(const char *out_dir, unsigned flags, pm_outcome *o) {
  pm_err ret = PM_SUCCESS;
  pm_run_resume_info rs = {0};
  pm_outdir *outdir = NULL;
  pm_scene *s = NULL;
  void *sim = NULL;
  char *argv[256];
  PM_CALL(pm_run_check_not_interrupted(o));
  PM_TRY(pm_par_agree(resume_open(out_dir, &rs, &outdir, &s, argv)));
  PM_TRY(pm_par_agree(pm_memory_check(s)));
  PM_TRY(s->backend->create(s, &sim));
  if (pm_par_root())
    ret = pm_run_root(s, sim, out_dir, flags, o, &outdir, &rs, NULL);
  else
    ret = resume_worker(s, sim, &rs, o);
  ret = pm_par_agree(ret); /* rank 0's conclusion, on every rank */
done:
  if (sim) s->backend->destroy(sim);
  pm_scene_destroy(s);
  pm_ckpt_abort(rs.ck);
  pm_outdir_release(outdir);
  pm_run_header_free(&rs.h);
  return ret;
}
