/*
** edt.c — oc_heightfield_distance_to_level: horizontal distance from each
** sample
** to the nearest sample at or below a level, by the exact Euclidean
** distance transform of Felzenszwalb and Huttenlocher (2012).
**
** The squared distance separates: a pass along rows finds, for each
** sample, the squared distance to the nearest wet sample of its row; a
** pass along columns then takes, for each sample, the lower envelope of
** the parabolas (y - y')^2 + row distance at y'. Every quantity is an
** integer below 2^53 held in a double, so the result is exact (the same
** float as sqrt(di^2 + dj^2) cell for the true nearest sample). Rows, then
** columns, are independent: each pass runs in parallel.
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "terrain/analysis.h"

/* Squared distance of the lower envelope of the parabolas (q - p)^2 + f[p]
** over the p with finite f[p], into d; all infinite when there is none.
** v and zb are scratch of n and n + 1 entries. */
static void envelope(const double *f, double *d, int n, int *v, double *zb) {
  int k = -1;
  for (int q = 0; q < n; q++) {
    if (isinf(f[q])) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      zb[0] = -INFINITY;
      zb[1] = INFINITY;
      continue;
    }
    double s;
    for (;;) {
      int p = v[k];
      s = ((f[q] + (double)q * q) - (f[p] + (double)p * p)) / (2.0 * (q - p));
      if (s > zb[k]) break;
      k--; /* zb[0] is -inf, so k stays >= 0 */
    }
    k++;
    v[k] = q;
    zb[k] = s;
    zb[k + 1] = INFINITY;
  }
  if (k < 0) {
    for (int q = 0; q < n; q++)
      d[q] = INFINITY;
    return;
  }
  for (int q = 0, j = 0; q < n; q++) {
    while (zb[j + 1] < q)
      j++;
    double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
  }
}

oc_heightfield *oc_heightfield_distance_to_level(const oc_heightfield *hf,
                                                 double level, oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "distance_to_level needs a heightfield");
    return NULL;
  }
  if (isnan(level)) {
    oc_seterr(err, OC_EINVAL, "'z' must be a number (got nan)");
    return NULL;
  }
  double lo;
  oc_heightfield_minmax(hf, &lo, NULL);
  if (!(lo <= level)) {
    oc_seterr(err, OC_EINVAL,
              "no sample is at or below 'z' = %g (the lowest is %g)", level,
              lo);
    return NULL;
  }
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  size_t n = (size_t)nx * (size_t)ny;
  int side = nx > ny ? nx : ny;
  const float *z = oc_heightfield_samples(hf);
  double *d2 = malloc(n * sizeof *d2);
  oc_heightfield *out = d2 ? oc_heightfield_like(hf, err) : NULL;
  if (!out) {
    if (!d2)
      oc_seterr(err, OC_ENOMEM,
                "out of memory for the distances of a %d x %d "
                "grid",
                nx, ny);
    free(d2);
    return NULL;
  }
  float *o = oc_heightfield_samples_mut(out);
  double cell = oc_heightfield_cell(hf);
  int failed = 0;
#pragma omp parallel
  {
    /* per thread: f, d, v, zb */
    double *f = malloc((3 * (size_t)side + 1) * sizeof *f);
    int *v = malloc((size_t)side * sizeof *v);
    if (!f || !v) {
#pragma omp atomic write
      failed = 1;
    }
#pragma omp for schedule(static)
    for (int j = 0; j < ny; j++) {
      if (!f || !v) continue;
      const float *zr = z + (size_t)j * (size_t)nx;
      for (int i = 0; i < nx; i++)
        f[i] = zr[i] <= level ? 0 : INFINITY;
      envelope(f, d2 + (size_t)j * (size_t)nx, nx, v, f + 2 * side);
    }
#pragma omp for schedule(static)
    for (int i = 0; i < nx; i++) {
      if (!f || !v) continue;
      double *d = f + side;
      for (int j = 0; j < ny; j++)
        f[j] = d2[(size_t)j * (size_t)nx + (size_t)i];
      envelope(f, d, ny, v, f + 2 * side);
      for (int j = 0; j < ny; j++)
        o[(size_t)j * (size_t)nx + (size_t)i] =
            oc_heightfield_float(sqrt(d[j]) * cell);
    }
    free(f);
    free(v);
  }
  free(d2);
  if (failed) {
    oc_seterr(err, OC_ENOMEM,
              "out of memory for the distances of a %d x %d "
              "grid",
              nx, ny);
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}
