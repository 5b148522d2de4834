/* ranks_testing: the checks of a test program run under mpirun
 * (ranks_newton, ranks_fpm_setup): each made on every rank, failed where
 * any rank failed, printed once by rank 0. */
#ifndef RANKS_TESTING_H
#define RANKS_TESTING_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_par.h"

static int failures;

static inline void expect(bool ok, const char *what) {
  long bad = !ok;
  pm_par_sum_long(&bad, 1);
  if (pm_par_root()) printf("%s: %s\n", bad ? "FAIL" : "ok", what);
  failures += bad != 0;
}

#endif
