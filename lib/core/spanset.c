/*
** spanset.c — sorted sets of disjoint intervals (see spanset.h).
*/
#include <math.h>

#include "core/spanset.h"

void oc_spanset_reduce(oc_zspan *s, int *n, int max) {
  while (*n > max && *n > 1) {
    int best = 0;
    double gap = INFINITY;
    for (int k = 0; k + 1 < *n; k++)
      if (s[k + 1].lo - s[k].hi < gap) {
        gap = s[k + 1].lo - s[k].hi;
        best = k;
      }
    s[best].hi = s[best + 1].hi;
    for (int k = best + 1; k + 1 < *n; k++)
      s[k] = s[k + 1];
    (*n)--;
  }
}

void oc_spanset_add(oc_zspan *s, int *n, int cap, double lo, double hi) {
  if (!(lo <= hi)) return;
  int i = 0;
  while (i < *n && s[i].hi < lo)
    i++;
  /* merge every interval overlapping [lo, hi] */
  int j = i;
  while (j < *n && s[j].lo <= hi) {
    lo = fmin(lo, s[j].lo);
    hi = fmax(hi, s[j].hi);
    j++;
  }
  int removed = j - i;
  if (removed == 0) {
    if (*n == cap) {
      if (cap < 2) { /* one interval: the hull */
        s[0].lo = fmin(s[0].lo, lo);
        s[0].hi = fmax(s[0].hi, hi);
        return;
      }
      /* merge the closest pair to make room */
      oc_spanset_reduce(s, n, cap - 1);
      oc_spanset_add(s, n, cap, lo, hi);
      return;
    }
    for (int k = *n; k > i; k--)
      s[k] = s[k - 1];
    (*n)++;
  } else if (removed > 1) {
    for (int k = i + 1; k + removed - 1 < *n; k++)
      s[k] = s[k + removed - 1];
    *n -= removed - 1;
  }
  s[i].lo = lo;
  s[i].hi = hi;
}
