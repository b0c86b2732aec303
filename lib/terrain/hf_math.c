/*
** hf_math.c — grids from grids, sample by sample: sums, differences and
** products of two grids or of a grid and a number, clamping, and masks
** of where a grid lies above or below a level.
**
** Every result is a new grid on the same layout; a sample that comes out
** non-finite (an overflow of float range) is an error naming it, so no
** grid ever holds one.
*/
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "outcrop.h"

static oc_heightfield *like(const oc_heightfield *a, oc_error *err) {
  double x0, y0;
  oc_heightfield_origin(a, &x0, &y0);
  return oc_heightfield_new(oc_heightfield_nx(a), oc_heightfield_ny(a),
                            oc_heightfield_cell(a), x0, y0, NULL, err);
}

/* Stores v at sample k of out, or fails naming it. */
static int put(oc_heightfield *out, size_t k, double v, const char *what,
               oc_error *err) {
  if (!(fabs(v) <= FLT_MAX)) {
    size_t nx = (size_t)oc_heightfield_nx(out);
    return oc_seterr(err, OC_EINVAL,
                     "%s gives %g at sample (%zu, %zu): not a finite float",
                     what, v, k % nx + 1, k / nx + 1);
  }
  oc_heightfield_samples_mut(out)[k] = (float)v;
  return OC_OK;
}

static double apply(oc_heightfield_op op, double a, double b) {
  switch (op) {
  case OC_HEIGHTFIELD_ADD:
    return a + b;
  case OC_HEIGHTFIELD_SUB:
    return a - b;
  case OC_HEIGHTFIELD_RSUB:
    return b - a;
  case OC_HEIGHTFIELD_MUL:
    return a * b;
  }
  return NAN;
}

static const char *const op_names[] = {"the sum", "the difference",
                                       "the difference", "the product"};

/* A new grid like a holding op of a's samples and zb's (or of k when zb
** is NULL), sample by sample; NULL when a result is not a finite float. */
static oc_heightfield *combine(const oc_heightfield *a, const float *zb,
                               double k, oc_heightfield_op op, oc_error *err) {
  oc_heightfield *out = like(a, err);
  if (!out) return NULL;
  const float *za = oc_heightfield_samples(a);
  size_t n = (size_t)oc_heightfield_nx(a) * (size_t)oc_heightfield_ny(a);
  for (size_t s = 0; s < n; s++)
    if (put(out, s, apply(op, za[s], zb ? zb[s] : k), op_names[op], err)) {
      oc_heightfield_release(out);
      return NULL;
    }
  return out;
}

static int check_op(oc_heightfield_op op, oc_error *err) {
  if (op < OC_HEIGHTFIELD_ADD || op > OC_HEIGHTFIELD_MUL)
    return oc_seterr(err, OC_EINVAL, "unknown grid operation %d", (int)op);
  return OC_OK;
}

oc_heightfield *oc_heightfield_combine(const oc_heightfield *a,
                                       const oc_heightfield *b,
                                       oc_heightfield_op op, oc_error *err) {
  if (!a || !b) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  if (check_op(op, err)) return NULL;
  double ax, ay, bx, by;
  oc_heightfield_origin(a, &ax, &ay);
  oc_heightfield_origin(b, &bx, &by);
  int nx = oc_heightfield_nx(a), ny = oc_heightfield_ny(a);
  if (nx != oc_heightfield_nx(b) || ny != oc_heightfield_ny(b) ||
      oc_heightfield_cell(a) != oc_heightfield_cell(b) || ax != bx ||
      ay != by) {
    oc_seterr(err, OC_EINVAL,
              "the grids differ: %d x %d, cell %g, origin (%g, %g) against "
              "%d x %d, cell %g, origin (%g, %g) (resample or crop one to "
              "the other)",
              nx, ny, oc_heightfield_cell(a), ax, ay, oc_heightfield_nx(b),
              oc_heightfield_ny(b), oc_heightfield_cell(b), bx, by);
    return NULL;
  }
  return combine(a, oc_heightfield_samples(b), 0, op, err);
}

oc_heightfield *oc_heightfield_scalar(const oc_heightfield *a, double k,
                                      oc_heightfield_op op, oc_error *err) {
  if (!a) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  if (check_op(op, err)) return NULL;
  if (!isfinite(k)) {
    oc_seterr(err, OC_EINVAL, "the number must be finite (got %g)", k);
    return NULL;
  }
  return combine(a, NULL, k, op, err);
}

oc_heightfield *oc_heightfield_clamp(const oc_heightfield *a, double lo,
                                     double hi, oc_error *err) {
  if (!a) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  if (isnan(lo) || isnan(hi) || !(lo <= hi)) {
    oc_seterr(err, OC_EINVAL,
              "'lo' and 'hi' must be numbers with lo <= hi (got %g, %g)", lo,
              hi);
    return NULL;
  }
  oc_heightfield *out = like(a, err);
  if (!out) return NULL;
  const float *z = oc_heightfield_samples(a);
  float *o = oc_heightfield_samples_mut(out);
  size_t n = (size_t)oc_heightfield_nx(a) * (size_t)oc_heightfield_ny(a);
  for (size_t s = 0; s < n; s++) {
    double v = z[s];
    o[s] = (float)(v < lo ? lo : v > hi ? hi : v);
  }
  return out;
}

/* 1 at and past the level on its side, 0 before it; with a falloff w, a
** linear ramp through 1/2 at the level over [level - w/2, level + w/2]
** (so that mask >= 0.5, as terrain masks read it, is the hard mask). */
static double ramp(double d, double w) {
  if (w == 0) return d >= 0 ? 1 : 0;
  double t = d / w + 0.5;
  return t <= 0 ? 0 : t >= 1 ? 1 : t;
}

oc_heightfield *oc_heightfield_mask(const oc_heightfield *a,
                                    const oc_heightfield_mask_params *p,
                                    oc_error *err) {
  if (!a || !p) {
    oc_seterr(err, OC_EINVAL,
              "the heightfield or the mask parameters are "
              "NULL");
    return NULL;
  }
  if (!p->has_above && !p->has_below) {
    oc_seterr(err, OC_EINVAL, "give 'above', 'below' or both");
    return NULL;
  }
  if ((p->has_above && !isfinite(p->above)) ||
      (p->has_below && !isfinite(p->below))) {
    oc_seterr(err, OC_EINVAL, "'%s' must be finite (got %g)",
              p->has_above && !isfinite(p->above) ? "above" : "below",
              p->has_above && !isfinite(p->above) ? p->above : p->below);
    return NULL;
  }
  if (!(p->falloff >= 0) || !isfinite(p->falloff)) {
    oc_seterr(err, OC_EINVAL, "'falloff' must be a number >= 0 (got %g)",
              p->falloff);
    return NULL;
  }
  oc_heightfield *out = like(a, err);
  if (!out) return NULL;
  const float *z = oc_heightfield_samples(a);
  float *o = oc_heightfield_samples_mut(out);
  size_t n = (size_t)oc_heightfield_nx(a) * (size_t)oc_heightfield_ny(a);
  for (size_t s = 0; s < n; s++) {
    double m = 1;
    if (p->has_above) m *= ramp(z[s] - p->above, p->falloff);
    if (p->has_below) m *= ramp(p->below - z[s], p->falloff);
    o[s] = (float)m;
  }
  return out;
}
