/*
** slope.c — oc_heightfield_slope: the magnitude of the elevation gradient, rise
** over run (the tangent of the slope angle).
**
** Derivatives are central differences, (z[i+1] - z[i-1]) / 2 cell, which
** is also the derivative of the Catmull-Rom interpolant at a sample, so
** the slope agrees with oc_heightfield_height's gradient there. On the
** border the difference is one-sided, which is exact for a plane where a
** clamped central difference would halve it.
*/
#include <math.h>

#include "core/error.h"
#include "terrain/analysis.h"

static double deriv(const float *z, ptrdiff_t stride, int i, int n) {
  if (i == 0) return (double)z[stride] - z[0];
  if (i == n - 1) return (double)z[0] - z[-stride];
  return 0.5 * ((double)z[stride] - z[-stride]);
}

void oc_heightfield_slope_samples(const float *z, int nx, int ny, double cell,
                                  float *out) {
#pragma omp parallel for schedule(static)
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      const float *p = z + (size_t)j * (size_t)nx + (size_t)i;
      double gx = deriv(p, 1, i, nx) / cell;
      double gy = deriv(p, nx, j, ny) / cell;
      out[(size_t)j * (size_t)nx + (size_t)i] =
          oc_heightfield_float(hypot(gx, gy));
    }
}

oc_heightfield *oc_heightfield_slope(const oc_heightfield *hf, oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "slope needs a heightfield");
    return NULL;
  }
  oc_heightfield *out = oc_heightfield_like(hf, err);
  if (!out) return NULL;
  oc_heightfield_slope_samples(
      oc_heightfield_samples(hf), oc_heightfield_nx(hf), oc_heightfield_ny(hf),
      oc_heightfield_cell(hf), oc_heightfield_samples_mut(out));
  return out;
}
