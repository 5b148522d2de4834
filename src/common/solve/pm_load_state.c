/* pm_load_state: load stepping's state (pm_load_steps_from), its
 * arrays and its items in a checkpoint, with the report's counts. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_newton.h"
#include "pm_newton_impl.h"

pm_err pm_load_state_init(pm_load_state *state, long n) {
  memset(state, 0, sizeof *state);
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(state->xc, n, "converged state"));
  PM_TRY(PM_ALLOC(state->xprev, n, "previous converged state"));
  PM_TRY(PM_ALLOC(state->pc_x, n, "kept factorisation's state"));
done:
  if (ret != PM_SUCCESS) pm_load_state_free(state);
  return ret;
}

void pm_load_state_free(pm_load_state *state) {
  free(state->xc);
  free(state->xprev);
  free(state->pc_x);
  state->xc = state->xprev = state->pc_x = NULL;
}

/* Checkpoint items added after the format's first builds: an item that
 * a checkpoint of a build before it lacks is left as it is when read (a
 * state's 0, or the resumed part's count).  ckpt_count: an int count. */
static pm_err ckpt_count(pm_ckpt *ck, const char *name, int *v) {
  if (pm_ckpt_reading(ck) && !pm_ckpt_has(ck, name)) return PM_SUCCESS;
  long t = *v;
  PM_CALL(pm_ckpt_long(ck, name, &t));
  *v = (int)t;
  return PM_SUCCESS;
}

static pm_err ckpt_long(pm_ckpt *ck, const char *name, long *v) {
  if (pm_ckpt_reading(ck) && !pm_ckpt_has(ck, name)) return PM_SUCCESS;
  return pm_ckpt_long(ck, name, v);
}

static pm_err ckpt_double(pm_ckpt *ck, const char *name, double *v) {
  if (pm_ckpt_reading(ck) && !pm_ckpt_has(ck, name)) return PM_SUCCESS;
  return pm_ckpt_double(ck, name, v);
}

pm_err pm_load_checkpoint(pm_ckpt *ck, const char *prefix, long n,
                          pm_load_state *st, pm_load_report *rep) {
  char name[96];
#define NAME(item) (snprintf(name, sizeof name, "%s.%s", prefix, item), name)
  if (st) {
    PM_CALL(pm_ckpt_double(ck, NAME("lambda"), &st->lambda));
    PM_CALL(pm_ckpt_double(ck, NAME("lambda_prev"), &st->lambda_prev));
    PM_CALL(pm_ckpt_double(ck, NAME("dl"), &st->dl));
    PM_CALL(pm_ckpt_long(ck, NAME("good"), &st->good));
    PM_CALL(pm_ckpt_long(ck, NAME("have_prev"), &st->have_prev));
    if (n > 0) {
      PM_CALL(pm_ckpt_doubles(ck, NAME("xc"), n, st->xc));
      PM_CALL(pm_ckpt_doubles(ck, NAME("xprev"), n, st->xprev));
      PM_CALL(pm_ckpt_long(ck, NAME("pc_built"), &st->pc_built));
      PM_CALL(pm_ckpt_long(ck, NAME("pc_its"), &st->pc_its));
      PM_CALL(pm_ckpt_long(ck, NAME("pc_failed"), &st->pc_failed));
      PM_CALL(pm_ckpt_double(ck, NAME("pc_lambda"), &st->pc_lambda));
      PM_CALL(pm_ckpt_doubles(ck, NAME("pc_x"), n, st->pc_x));
      PM_CALL(pm_ckpt_long(ck, NAME("pc_first_its"), &st->pc_first_its));
      /* (not in a checkpoint of a build before it: 0) */
      PM_CALL(ckpt_long(ck, NAME("fallback_kept"), &st->fallback_kept));
      PM_CALL(ckpt_long(ck, NAME("relax_first"), &st->relax_first));
      /* (a checkpoint of a build before it: carried if relaxed first) */
      if (!pm_ckpt_reading(ck) || pm_ckpt_has(ck, NAME("relax_carried")))
        PM_CALL(pm_ckpt_long(ck, NAME("relax_carried"), &st->relax_carried));
      else
        st->relax_carried = st->relax_first;
    }
  }
  /* Written: the counts as the last converged step left them (the
   * state's); read: into the report, and the state's copy with them. */
  pm_load_report *live = rep;
  if (st && !pm_ckpt_reading(ck)) rep = &st->done;
  long steps = rep->steps, cuts = rep->cuts, newton = rep->newton_iterations,
       linear = rep->linear_iterations;
  PM_CALL(pm_ckpt_long(ck, NAME("steps"), &steps));
  PM_CALL(pm_ckpt_long(ck, NAME("cuts"), &cuts));
  PM_CALL(pm_ckpt_long(ck, NAME("newton_iterations"), &newton));
  PM_CALL(pm_ckpt_long(ck, NAME("linear_iterations"), &linear));
  PM_CALL(pm_ckpt_double(ck, NAME("dlambda_min"), &rep->dlambda_min));
  /* The fallbacks' counts, so that a resumed run's summary counts the
   * whole run's (its seconds are its own process's). */
  struct {
    const char *item;
    int *count;
  } counts[] = {{"relaxations", &rep->relaxations},
                {"relaxed_steps", &rep->relaxed_steps},
                {"ptc_runs", &rep->ptc_runs},
                {"ptc_steps", &rep->ptc_steps},
                {"mode_runs", &rep->mode_runs},
                {"branch_switches", &rep->branch_switches},
                {"arc_runs", &rep->arc_runs},
                {"arc_passes", &rep->arc_passes},
                {"snap_steps", &rep->snap_steps},
                {"fallbacks_timed_out", &rep->fallbacks_timed_out},
                {"resolves", &rep->resolves},
                {"unsettled", &rep->unsettled}};
  for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++)
    PM_CALL(ckpt_count(ck, NAME(counts[k].item), counts[k].count));
  PM_CALL(ckpt_long(ck, NAME("relax_iterations"), &rep->relax_iterations));
  PM_CALL(ckpt_long(ck, NAME("ptc_iterations"), &rep->ptc_iterations));
  PM_CALL(ckpt_long(ck, NAME("arc_steps"), &rep->arc_steps));
  PM_CALL(ckpt_long(ck, NAME("arc_iterations"), &rep->arc_iterations));
  PM_CALL(ckpt_double(ck, NAME("ptc_curvature"), &rep->ptc_curvature));
  PM_CALL(ckpt_double(ck, NAME("mode_eigenvalue"), &rep->mode_eigenvalue));
  PM_CALL(ckpt_double(ck, NAME("snap_lambda"), &rep->snap_lambda));
  PM_CALL(ckpt_double(ck, NAME("snap_eigenvalue"), &rep->snap_eigenvalue));
#undef NAME
  if (st && pm_ckpt_reading(ck)) st->done = *live;
  rep->steps = (int)steps;
  rep->cuts = (int)cuts;
  rep->newton_iterations = (int)newton;
  rep->linear_iterations = (int)linear;
  if (st) rep->lambda = st->lambda;
  return PM_SUCCESS;
}
