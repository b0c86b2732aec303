/*
** spanset.h — a sorted set of disjoint intervals in a fixed array, for
** covers that may loosen but never shrink: column spans (query.c) and
** ray support intervals (raybound.c).
*/
#ifndef OC_SPANSET_H
#define OC_SPANSET_H

#include "outcrop.h"

/* Adds [lo, hi] to the n sorted, disjoint intervals of s (capacity cap),
** merging every interval it overlaps; when full, the two neighbours with
** the smallest gap are merged first (still a cover, just looser). An
** empty or NaN interval is ignored. */
void oc_spanset_add(oc_zspan *s, int *n, int cap, double lo, double hi);

/* Closes the smallest gaps of the n sorted, disjoint intervals of s
** (merging each closest pair of neighbours, the leftmost on ties) until
** at most max remain (at least one). */
void oc_spanset_reduce(oc_zspan *s, int *n, int max);

#endif
