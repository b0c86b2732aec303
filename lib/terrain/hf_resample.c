/*
** hf_resample.c — what a caller asks of a grid in its own terms, turned
** into the grid operations' exact arguments: the target grid of a
** resampling given a cell or a size, the sample range of a crop given a
** box, and the sum of the samples. The front ends call these so that a C
** program and a script get the same grids and the same refusals.
*/
#include <math.h>

#include "core/error.h"
#include "outcrop.h"

/* Largest grid side, as oc_heightfield_new. */
#define MAX_SIDE 65535

/* Samples along an axis of extent w at spacing c: floor(w / c) + 1, with
** a relative slack so that 100 / 0.1 counts 1001 samples. */
static double count_samples(double w, double c) {
  return floor(w / c * (1 + 1e-12)) + 1;
}

int oc_heightfield_resample_grid(const oc_heightfield *hf, double cell, int nx,
                                 int ny, oc_heightfield_grid *g,
                                 oc_error *err) {
  char a[OC_NUMSTR], b[OC_NUMSTR], c[OC_NUMSTR];
  if (!hf || !g) return oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
  int bysize = nx != 0 || ny != 0;
  if (bysize == (cell != 0))
    return oc_seterr(err, OC_EINVAL, "give either 'cell' or 'size' = {nx, ny}");
  double sc = oc_heightfield_cell(hf);
  double wx = (oc_heightfield_nx(hf) - 1) * sc,
         wy = (oc_heightfield_ny(hf) - 1) * sc;
  oc_heightfield_grid out;
  oc_heightfield_origin(hf, &out.x0, &out.y0);
  if (bysize) {
    if (nx < 2 || nx > MAX_SIDE || ny < 2 || ny > MAX_SIDE)
      return oc_seterr(err, OC_EINVAL,
                       "'size' must be {nx, ny} with integers in 2..%d (got "
                       "{%d, %d})",
                       MAX_SIDE, nx, ny);
    double cx = wx / (nx - 1), cy = wy / (ny - 1);
    if (fabs(cx - cy) > 1e-6 * fmax(cx, cy))
      return oc_seterr(err, OC_EINVAL,
                       "'size' {%d, %d} needs cells of %s along x but %s "
                       "along y (cells are square): keep the grid's "
                       "proportions or give 'cell'",
                       nx, ny, oc_numstr(cx, a), oc_numstr(cy, b));
    out.nx = nx, out.ny = ny, out.cell = cx;
  } else {
    if (!(cell > 0) || !isfinite(cell))
      return oc_seterr(err, OC_EINVAL, "'cell' must be > 0 (got %s)",
                       oc_numstr(cell, a));
    double fx = count_samples(wx, cell), fy = count_samples(wy, cell);
    if (fx < 2 || fy < 2)
      return oc_seterr(err, OC_EINVAL,
                       "'cell' %s is larger than the grid (%s x %s): it "
                       "would leave fewer than 2 samples per side",
                       oc_numstr(cell, a), oc_numstr(wx, b), oc_numstr(wy, c));
    if (fx > MAX_SIDE || fy > MAX_SIDE)
      return oc_seterr(err, OC_EINVAL,
                       "'cell' %s gives %lld x %lld samples (at most %d per "
                       "side)",
                       oc_numstr(cell, a), (long long)fmin(fx, 1e18),
                       (long long)fmin(fy, 1e18), MAX_SIDE);
    if (fx * fy > (double)OC_HEIGHTFIELD_MAX_SAMPLES)
      return oc_seterr(err, OC_EINVAL,
                       "'cell' %s gives %lld x %lld samples, over the limit "
                       "of %lld",
                       oc_numstr(cell, a), (long long)fx, (long long)fy,
                       (long long)OC_HEIGHTFIELD_MAX_SAMPLES);
    out.nx = (int)fx, out.ny = (int)fy, out.cell = cell;
  }
  *g = out;
  return OC_OK;
}

int oc_heightfield_crop_range(const oc_heightfield *hf, double x0, double y0,
                              double x1, double y1, int ij[4], oc_error *err) {
  if (!hf || !ij) return oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
  if (!(x0 < x1 && y0 < y1))
    return oc_seterr(err, OC_EINVAL,
                     "'box' = {x0, y0, x1, y1} needs x0 < x1 and y0 < y1");
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double ox, oy, c = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &ox, &oy);
  /* The samples inside, with a relative slack for rounding. */
  double e = 1e-9;
  double a[4] = {ceil((x0 - ox) / c - e), ceil((y0 - oy) / c - e),
                 floor((x1 - ox) / c + e), floor((y1 - oy) / c + e)};
  a[0] = fmax(a[0], 0), a[1] = fmax(a[1], 0);
  a[2] = fmin(a[2], nx - 1), a[3] = fmin(a[3], ny - 1);
  if (!(a[2] - a[0] >= 1 && a[3] - a[1] >= 1))
    return oc_seterr(err, OC_EINVAL,
                     "'box' holds fewer than 2 x 2 samples of the grid");
  for (int k = 0; k < 4; k++)
    ij[k] = (int)a[k];
  return OC_OK;
}

oc_heightfield *oc_heightfield_crop_box(const oc_heightfield *hf, double x0,
                                        double y0, double x1, double y1,
                                        oc_error *err) {
  int ij[4];
  if (oc_heightfield_crop_range(hf, x0, y0, x1, y1, ij, err)) return NULL;
  return oc_heightfield_crop(hf, ij[0], ij[1], ij[2], ij[3], err);
}

/* In index order, in double: the same sum for any thread count. */
double oc_heightfield_sum(const oc_heightfield *hf) {
  if (!hf) return 0;
  size_t n = (size_t)oc_heightfield_nx(hf) * (size_t)oc_heightfield_ny(hf);
  const float *z = oc_heightfield_samples(hf);
  double s = 0;
  for (size_t k = 0; k < n; k++)
    s += z[k];
  return s;
}
