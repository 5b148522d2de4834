/* mpm_par_x0set: a set of particles known by their reference positions,
 * which a share's seeding asks of each particle it seeds
 * (mpm_par_pick.keep): open addressing on the positions' bits. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_par.h"

static uint64_t hash_x(const double x[3]) {
  uint64_t h = 1469598103934665603ull;
  for (int a = 0; a < 3; a++) {
    uint64_t b;
    memcpy(&b, &x[a], sizeof b);
    h = (h ^ b) * 0x9e3779b97f4a7c15ull;
    h ^= h >> 29;
  }
  return h;
}

static const double *x0_of(const mpm_x0_set *set, long k) {
  return set->x0 + k * set->stride;
}

pm_err mpm_x0_set_index(mpm_x0_set *set) {
  uint64_t size = 16;
  while (size < 2 * (uint64_t)set->n) size *= 2;
  set->mask = size - 1;
  free(set->slot);
  PM_CALL(PM_ALLOC(set->slot, (long)size, "particles kept"));
  for (uint64_t i = 0; i < size; i++) set->slot[i] = -1;
  for (long k = 0; k < set->n; k++) {
    uint64_t i = hash_x(x0_of(set, k)) & set->mask;
    while (set->slot[i] >= 0) i = (i + 1) & set->mask;
    set->slot[i] = k;
  }
  return PM_SUCCESS;
}

bool mpm_x0_set_has(const mpm_x0_set *set, const double x[3]) {
  for (uint64_t i = hash_x(x) & set->mask;; i = (i + 1) & set->mask) {
    const long k = set->slot[i];
    if (k < 0) return false;
    if (!memcmp(x0_of(set, k), x, 3 * sizeof(double))) return true;
  }
}

void mpm_x0_set_free(mpm_x0_set *set) {
  free(set->slot);
  set->slot = NULL;
}
