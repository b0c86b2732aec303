/*
** heightfield.c — the elevation grid: storage, reference counting and
** C1 bicubic (Catmull-Rom) interpolation with its analytic gradient.
**
** Catmull-Rom interpolates the samples and is C1 across cells, which is
** what implicitization needs: the surface f = sigma(h - z) inherits the
** continuity of h, and its gradient must exist everywhere for Newton steps
** and shading.
*/
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "outcrop.h"

#define MAX_SIDE 65535

struct oc_heightfield {
  int refs;
  int nx, ny;
  double cell, x0, y0;
  float *z;
};

oc_heightfield *oc_heightfield_new(int nx, int ny, double cell, double x0,
                                   double y0, const float *z, oc_error *err) {
  if (nx < 2 || nx > MAX_SIDE || ny < 2 || ny > MAX_SIDE) {
    oc_seterr(err, OC_EINVAL,
              "'size' must be in 2..%d samples per side (got %d x %d)",
              MAX_SIDE, nx, ny);
    return NULL;
  }
  unsigned long long n = (unsigned long long)nx * (unsigned long long)ny;
  if (n > OC_HEIGHTFIELD_MAX_SAMPLES) {
    oc_seterr(err, OC_ENOMEM,
              "'size' %d x %d is %llu samples (%llu MiB), over the limit of "
              "%llu (%llu MiB)",
              nx, ny, n, (n * sizeof(float)) >> 20, OC_HEIGHTFIELD_MAX_SAMPLES,
              (OC_HEIGHTFIELD_MAX_SAMPLES * sizeof(float)) >> 20);
    return NULL;
  }
  /* a subnormal cell has no half (0.5 * 5e-324 == 0) and no finite
  ** reciprocal: steps of a fraction of a cell would never advance */
  if (!(cell >= DBL_MIN) || !isfinite(cell)) {
    oc_seterr(err, OC_EINVAL,
              "'cell' must be a positive normal number (>= %g; got %g)",
              DBL_MIN, cell);
    return NULL;
  }
  if (!isfinite(x0) || !isfinite(y0)) {
    oc_seterr(err, OC_EINVAL, "'origin' must be finite");
    return NULL;
  }
  if (z) {
    for (size_t k = 0; k < (size_t)n; k++)
      if (!isfinite(z[k])) {
        oc_seterr(err, OC_EINVAL,
                  "elevation at sample (%zu, %zu) is not finite",
                  k % (size_t)nx, k / (size_t)nx);
        return NULL;
      }
  }
  oc_heightfield *hf = malloc(sizeof *hf);
  float *data =
      z ? malloc((size_t)n * sizeof *data) : calloc((size_t)n, sizeof *data);
  if (!hf || !data) {
    free(hf);
    free(data);
    oc_seterr(err, OC_ENOMEM, "out of memory for a %d x %d heightfield", nx,
              ny);
    return NULL;
  }
  if (z) memcpy(data, z, (size_t)n * sizeof *data);
  hf->refs = 1;
  hf->nx = nx;
  hf->ny = ny;
  hf->cell = cell;
  hf->x0 = x0;
  hf->y0 = y0;
  hf->z = data;
  return hf;
}

/* Grids are shared between Lua objects and nodes that may be released from
** the threads of a parallel loop; the count is atomic for that reason. */
void oc_heightfield_retain(oc_heightfield *hf) {
  if (hf) __atomic_add_fetch(&hf->refs, 1, __ATOMIC_RELAXED);
}

void oc_heightfield_release(oc_heightfield *hf) {
  if (hf && __atomic_sub_fetch(&hf->refs, 1, __ATOMIC_ACQ_REL) == 0) {
    free(hf->z);
    free(hf);
  }
}

int oc_heightfield_nx(const oc_heightfield *hf) {
  return hf->nx;
}
int oc_heightfield_ny(const oc_heightfield *hf) {
  return hf->ny;
}
double oc_heightfield_cell(const oc_heightfield *hf) {
  return hf->cell;
}

void oc_heightfield_origin(const oc_heightfield *hf, double *x0, double *y0) {
  if (x0) *x0 = hf->x0;
  if (y0) *y0 = hf->y0;
}

const float *oc_heightfield_samples(const oc_heightfield *hf) {
  return hf->z;
}
float *oc_heightfield_samples_mut(oc_heightfield *hf) {
  return hf->z;
}

void oc_heightfield_minmax(const oc_heightfield *hf, double *lo, double *hi) {
  size_t n = (size_t)hf->nx * (size_t)hf->ny;
  float a = hf->z[0], b = hf->z[0];
  for (size_t k = 1; k < n; k++) {
    if (hf->z[k] < a) a = hf->z[k];
    if (hf->z[k] > b) b = hf->z[k];
  }
  if (lo) *lo = a;
  if (hi) *hi = b;
}

/* Catmull-Rom weights of samples -1, 0, 1, 2 at t in [0, 1], and their
** derivatives. */
static void cr_weights(double t, double w[4], double dw[4]) {
  double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2 * t2 - t);
  w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
  dw[0] = 0.5 * (-3 * t2 + 4 * t - 1);
  dw[1] = 0.5 * (9 * t2 - 10 * t);
  dw[2] = 0.5 * (-9 * t2 + 8 * t + 1);
  dw[3] = 0.5 * (3 * t2 - 2 * t);
}

/* Cell index and fraction along one axis, the position clamped to the
** grid; `inside` is 0 when clamping happened (the gradient there is 0). */
static int locate(double u, int n, double *t, int *inside) {
  *inside = 1;
  if (!(u > 0)) { /* also NaN: handled by the caller */
    *inside = u == 0;
    *t = 0;
    return 0;
  }
  if (u >= n - 1) {
    *inside = 0;
    *t = 1;
    return n - 2;
  }
  int i = (int)u;
  *t = u - i;
  return i;
}

double oc_heightfield_height(const oc_heightfield *hf, double x, double y,
                             double grad[2]) {
  double u = (x - hf->x0) / hf->cell, v = (y - hf->y0) / hf->cell;
  if (isnan(u) || isnan(v)) {
    if (grad) grad[0] = grad[1] = NAN;
    return NAN;
  }
  double tu, tv;
  int inu, inv;
  int i = locate(u, hf->nx, &tu, &inu), j = locate(v, hf->ny, &tv, &inv);
  double wu[4], dwu[4], wv[4], dwv[4];
  cr_weights(tu, wu, dwu);
  cr_weights(tv, wv, dwv);
  double h = 0, hu = 0, hv = 0;
  if (i >= 1 && i + 2 < hf->nx && j >= 1 && j + 2 < hf->ny) {
    /* inside: no clamping; the same sums in the same order */
    const float *row = hf->z + (size_t)(j - 1) * (size_t)hf->nx + (i - 1);
    for (int b = 0; b < 4; b++, row += hf->nx) {
      double r =
          wu[0] * row[0] + wu[1] * row[1] + wu[2] * row[2] + wu[3] * row[3];
      h += wv[b] * r;
      if (grad) {
        double dr = dwu[0] * row[0] + dwu[1] * row[1] + dwu[2] * row[2] +
                    dwu[3] * row[3];
        hu += wv[b] * dr;
        hv += dwv[b] * r;
      }
    }
  } else {
    for (int b = 0; b < 4; b++) {
      int jj = j - 1 + b;
      jj = jj < 0 ? 0 : jj >= hf->ny ? hf->ny - 1 : jj;
      const float *row = hf->z + (size_t)jj * (size_t)hf->nx;
      double r = 0, dr = 0;
      for (int a = 0; a < 4; a++) {
        int ii = i - 1 + a;
        ii = ii < 0 ? 0 : ii >= hf->nx ? hf->nx - 1 : ii;
        r += wu[a] * row[ii];
        dr += dwu[a] * row[ii];
      }
      h += wv[b] * r;
      hu += wv[b] * dr;
      hv += dwv[b] * r;
    }
  }
  if (grad) {
    grad[0] = inu ? hu / hf->cell : 0;
    grad[1] = inv ? hv / hf->cell : 0;
  }
  return h;
}
