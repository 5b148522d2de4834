/* pm_sorted: searches in arrays sorted in increasing order. */
#ifndef PM_SORTED_H
#define PM_SORTED_H

/* The first of the n increasing a[] that is at least v (n where none
 * is). */
static inline long pm_lower_bound(const long *a, long n, long v) {
  long lo = 0, hi = n;
  while (lo < hi) {
    const long mid = lo + (hi - lo) / 2;
    if (a[mid] < v)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

#endif
