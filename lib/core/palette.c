/*
** palette.c — colour maps (outcrop.h, "palettes"): checks, evaluation
** and the built-in palettes.
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

/* Strata colours for a resistance in [0, 1]: soft sandstone to hard
** limestone, so that layers of different hardness read as bands on
** cliffs. */
static const double strata[] = {0.00, 0.36, 0.22, 0.11, 0.30, 0.28, 0.13,
                                0.07, 0.50, 0.40, 0.32, 0.20, 0.70, 0.16,
                                0.11, 0.08, 1.00, 0.30, 0.29, 0.27};

/* Pale for hard rock, dark for soft (Paris et al. 2019, figure 4). */
static const double resistance[] = {0.00, 0.22, 0.13, 0.08, 0.35, 0.45,
                                    0.30, 0.18, 0.65, 0.72, 0.58, 0.40,
                                    1.00, 0.95, 0.91, 0.82};

const double *oc_palette_strata(int *n) {
  if (n) *n = (int)(sizeof strata / sizeof strata[0] / 4);
  return strata;
}

const double *oc_palette_resistance(int *n) {
  if (n) *n = (int)(sizeof resistance / sizeof resistance[0] / 4);
  return resistance;
}
