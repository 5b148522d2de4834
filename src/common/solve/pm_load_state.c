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
      if (!pm_ckpt_reading(ck) || pm_ckpt_has(ck, NAME("fallback_kept")))
        PM_CALL(pm_ckpt_long(ck, NAME("fallback_kept"), &st->fallback_kept));
      if (!pm_ckpt_reading(ck) || pm_ckpt_has(ck, NAME("relax_first")))
        PM_CALL(pm_ckpt_long(ck, NAME("relax_first"), &st->relax_first));
      /* (a checkpoint of a build before it: carried if relaxed first) */
      if (!pm_ckpt_reading(ck) || pm_ckpt_has(ck, NAME("relax_carried")))
        PM_CALL(pm_ckpt_long(ck, NAME("relax_carried"), &st->relax_carried));
      else
        st->relax_carried = st->relax_first;
    }
  }
  long steps = rep->steps, cuts = rep->cuts, newton = rep->newton_iterations,
       linear = rep->linear_iterations;
  PM_CALL(pm_ckpt_long(ck, NAME("steps"), &steps));
  PM_CALL(pm_ckpt_long(ck, NAME("cuts"), &cuts));
  PM_CALL(pm_ckpt_long(ck, NAME("newton_iterations"), &newton));
  PM_CALL(pm_ckpt_long(ck, NAME("linear_iterations"), &linear));
  PM_CALL(pm_ckpt_double(ck, NAME("dlambda_min"), &rep->dlambda_min));
#undef NAME
  rep->steps = (int)steps;
  rep->cuts = (int)cuts;
  rep->newton_iterations = (int)newton;
  rep->linear_iterations = (int)linear;
  if (st) rep->lambda = st->lambda;
  return PM_SUCCESS;
}
