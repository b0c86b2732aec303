/*
** checked.h — sizes derived from user numbers, in checked arithmetic.
**
** A script can pass any double (NaN, inf, 1e308, subnormals) or any
** integer; a size computed from one must fail before it wraps or before a
** double too large for the integer type is converted (undefined
** behaviour). Each helper returns 1 when the result fits, 0 otherwise,
** and the caller refuses the request naming its field.
*/
#ifndef OC_CHECKED_H
#define OC_CHECKED_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* *out = a * b, or 0 when it overflows size_t. */
static inline int oc_mul_size(size_t a, size_t b, size_t *out) {
  return !__builtin_mul_overflow(a, b, out);
}

/* *out = a + b, or 0 when it overflows size_t. */
static inline int oc_add_size(size_t a, size_t b, size_t *out) {
  return !__builtin_add_overflow(a, b, out);
}

/* *out = the product of the n sizes v[], or 0 when it overflows. */
static inline int oc_prod_size(const size_t *v, int n, size_t *out) {
  size_t p = 1;
  for (int k = 0; k < n; k++)
    if (!oc_mul_size(p, v[k], &p)) return 0;
  *out = p;
  return 1;
}

/* x as a count in [lo, hi], or 0 when x is NaN, infinite or outside (the
** comparisons are made in double, before any conversion). */
static inline int oc_double_to_size(double x, size_t lo, size_t hi,
                                    size_t *out) {
  if (!(x >= (double)lo && x < (double)SIZE_MAX))
    return 0; /* (double)SIZE_MAX rounds up to SIZE_MAX + 1 */
  size_t v = (size_t)x;
  if (v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

/* x as an int in [lo, hi], or 0 when x is NaN, infinite or outside. */
static inline int oc_double_to_int(double x, int lo, int hi, int *out) {
  if (!(x >= (double)lo && x <= (double)hi)) return 0;
  *out = (int)x;
  return 1;
}

#endif
