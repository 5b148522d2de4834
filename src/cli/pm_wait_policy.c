/* pm_wait_policy: a short OpenMP spin by default.  With libgomp's default
 * (threads spin up to 300000 times at every barrier before sleeping), an
 * explicit FPM run of F2 on two threads beside another such run took 5-20
 * times its time alone; with a spin of 3000 before sleeping, 2.6-3 times,
 * at no measurable cost alone; passive waiting shares best (1.0-1.7 times)
 * but costs 1.5-1.7 times alone (docs/validation.md, "A shared machine"). */
#include "pm_wait_policy.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pm_omp.h"

/* Spins of an idle thread before it sleeps. */
#define PM_SPINCOUNT "3000"

void pm_wait_policy_apply(char **argv) {
  if (!PM_OMP_AVAILABLE) return;
  if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT")) return;
  const char *own = getenv("POINTMECH_WAIT_POLICY");
  if (own && strcmp(own, "default") == 0) return;
  if (setenv("GOMP_SPINCOUNT", PM_SPINCOUNT, 1) != 0) return;
  execv("/proc/self/exe", argv);
  /* Not restarted: the runtime keeps the policy it started with, and the
   * environment says so again. */
  unsetenv("GOMP_SPINCOUNT");
}
