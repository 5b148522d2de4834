/* pm_wait_policy: OpenMP threads that sleep when idle, unless the user
 * chose otherwise, so that a run sharing its cores with another job is not
 * slowed down by its own spinning threads (or theirs by ours). */
#ifndef PM_WAIT_POLICY_H
#define PM_WAIT_POLICY_H

/* When neither OMP_WAIT_POLICY nor GOMP_SPINCOUNT is set, and
 * POINTMECH_WAIT_POLICY is not "default", set OMP_WAIT_POLICY=passive and
 * execute the program again with argv (the OpenMP runtime reads its
 * environment once, when it is loaded).  Returns only when nothing was to
 * be done or the new image could not be started (the run then keeps the
 * runtime's default). */
void pm_wait_policy_apply(char **argv);

#endif
