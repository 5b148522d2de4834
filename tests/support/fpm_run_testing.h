/* fpm_run_testing: what the FPM verification programs share
 * (verify_fpm_static, verify_fpm_loads): a scene run whole through the FPM
 * backend with overrides, kept for its model, state and figures.  Include
 * after cmocka.h. */
#ifndef FPM_RUN_TESTING_H
#define FPM_RUN_TESTING_H

#include "fpm_backend.h"
#include "pm_run.h"
#include "pm_scene.h"

#define CASES PM_SOURCE_DIR "/cases/fpm/"

typedef struct {
  pm_scene *scene;
  fpm_sim *sim;
  pm_outcome out;
} run_t;

/* Load file with the n_sets overrides sets and run it (a failure to load
 * or an error of the run fails the test; the status is the caller's to
 * check). */
static inline void fpm_test_run(const char *file, int n_sets, const char **sets,
                                run_t *r) {
  if (pm_scene_load(file, n_sets, sets, &r->scene) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (fpm_sim_create(r->scene, &r->sim) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
  if (pm_run_sim(r->scene, r->sim, NULL, true, &r->out) != PM_SUCCESS)
    fail_msg("%s", pm_error_message());
}

static inline void done(run_t *r) {
  fpm_sim_destroy(r->sim);
  pm_scene_destroy(r->scene);
}

#endif
