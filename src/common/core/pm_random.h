/* pm_random: a counter-based generator (splitmix64).  Draw k of a stream is
 * a function of (seed, k) alone, computed with integer arithmetic, so a
 * seeded result repeats bit for bit on every machine and compiler. */
#ifndef PM_RANDOM_H
#define PM_RANDOM_H

#include <stdint.h>

/* The golden-ratio increment of splitmix64. */
#define PM_RANDOM_GOLDEN 0x9E3779B97F4A7C15ull

/* splitmix64's output function: a bijection of 64-bit words whose outputs
 * for consecutive inputs pass the usual statistical tests. */
static inline uint64_t pm_mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/* A stream: its key (from the seed) and the number of draws taken. */
typedef struct {
  uint64_t key;
  uint64_t count;
} pm_random;

static inline pm_random pm_random_seed(uint64_t seed) {
  pm_random r = {pm_mix64(seed + PM_RANDOM_GOLDEN), 0};
  return r;
}

/* The next 64-bit draw of r. */
static inline uint64_t pm_random_next(pm_random *r) {
  r->count++;
  return pm_mix64(r->key + r->count * PM_RANDOM_GOLDEN);
}

/* The next draw of r, uniform in [0, 1) on a grid of 2^-53. */
static inline double pm_random_uniform(pm_random *r) {
  return (double)(pm_random_next(r) >> 11) * 0x1.0p-53;
}

#endif
