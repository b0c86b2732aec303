/*
** palette.c — colour maps (see palette.h).
*/
#include <math.h>

#include "core/error.h"
#include "core/palette.h"

int oc_palette_check(const double *stops, int n, oc_error *err) {
  if (n < 1)
    return oc_seterr(err, OC_EINVAL,
                     "'stops' must hold at least 1 stop (got %d)", n);
  if (!stops) return oc_seterr(err, OC_EINVAL, "'stops' is NULL");
  for (int k = 0; k < n; k++) {
    const double *s = stops + 4 * k;
    if (!isfinite(s[0]))
      return oc_seterr(err, OC_EINVAL,
                       "'stops' value of stop %d must be finite (got %g)",
                       k + 1, s[0]);
    if (k > 0 && s[0] < s[-4])
      return oc_seterr(err, OC_EINVAL,
                       "'stops' must be sorted by value (stop %d: %g after "
                       "%g)",
                       k + 1, s[0], s[-4]);
    for (int c = 1; c <= 3; c++)
      if (!(s[c] >= 0 && s[c] <= 1))
        return oc_seterr(err, OC_EINVAL,
                         "'stops' colour of stop %d must be in [0, 1] "
                         "(got %g)",
                         k + 1, s[c]);
  }
  return OC_OK;
}

void oc_palette_eval(const double *stops, int n, double v, double rgb[3]) {
  const double *s = stops;
  if (!(v >= stops[0]) || n == 1) {
    s = stops;
  } else if (v >= stops[4 * (n - 1)]) {
    s = stops + 4 * (n - 1);
  } else {
    int k = 0;
    while (v >= stops[4 * (k + 1)])
      k++; /* stops[4k] <= v < stops[4k+4] */
    const double *a = stops + 4 * k, *b = a + 4;
    double t = (v - a[0]) / (b[0] - a[0]);
    for (int c = 1; c <= 3; c++) {
      double x = a[c] + t * (b[c] - a[c]);
      rgb[c - 1] = x < 0 ? 0 : x > 1 ? 1 : x;
    }
    return;
  }
  for (int c = 1; c <= 3; c++)
    rgb[c - 1] = s[c];
}
