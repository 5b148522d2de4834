/* pm_wait_policy: the passive OpenMP wait policy by default.  With
 * libgomp's default (threads spin up to 300000 times at every barrier
 * before sleeping), an explicit FPM run of F2 on two threads beside another
 * such run took 15-150 s instead of 3-7 s alone; passive, 4.5-18 s, at a
 * cost of 1.4-1.7x alone (README, "A shared machine"). */
#include "pm_wait_policy.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_omp.h"

void pm_wait_policy_apply(char **argv) {
  if (!PM_OMP_AVAILABLE) return;
  if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT")) return;
  const char *own = getenv("POINTMECH_WAIT_POLICY");
  if (own && strcmp(own, "default") == 0) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  /* Not restarted: the runtime keeps the policy it started with, and the
   * environment says so again. */
  unsetenv("OMP_WAIT_POLICY");
}
