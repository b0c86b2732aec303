/*
** river.c — river erosion (Paris et al. 2019, section 6.1, figure 15): canyons
** whose walls are undercut where the strata are soft.
**
** The stress is the stream power A^(1/2) s of the heightfield: samples
** above `power` are the riverbed (sigma = 1), and a small max-convolution
** with a tent of `banks` + 1 cells widens it to the banks, sigma falling
** linearly to 0 (the paper's flooding). Bed columns carve straight down at
** the surface; bank columns cast horizontal rays away from the river (up
** the slope) at heights drawn below their surface, so they reach the
** canyon wall at every level of it and carve most into soft layers.
*/
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "gen/erode.h"
#include "terrain/analysis.h"

/* Below this slope a column is riverbed floor: carve at z = h. */
#define FLAT 0.05

void oc_gen_river_defaults(oc_gen_river_params *p) {
  memset(p, 0, sizeof *p);
  oc_gen_erode_defaults(&p->erode);
  p->erode.strength = 2;
  p->erode.steps = 2;
  p->banks = 3;
}

static int cmpf(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* The q-quantile of the grid's samples (sorted copy). */
static int quantile(const float *v, size_t n, double q, double *out,
                    oc_error *err) {
  float *c = malloc(n * sizeof *c);
  if (!c) return oc_seterr(err, OC_ENOMEM, "out of memory");
  memcpy(c, v, n * sizeof *c);
  qsort(c, n, sizeof *c, cmpf);
  *out = c[(size_t)(q * (double)(n - 1))];
  free(c);
  return OC_OK;
}

/* sigma: 1 on the bed, 1 - d / (banks + 1) at d cells from it; up to
** (2 banks + 1)^2 reads per sample. */
typedef struct widening {
  const float *pw;
  double thr;
  int banks;
} widening;

static void widen_row(const void *ctx, oc_heightfield *sig, int j) {
  const widening *W = ctx;
  int nx = oc_heightfield_nx(sig), ny = oc_heightfield_ny(sig);
  int banks = W->banks, r = banks + 1;
  float *row = oc_heightfield_samples_mut(sig) + (size_t)j * nx;
  for (int i = 0; i < nx; i++) {
    double best = 0;
    for (int dj = -banks; dj <= banks; dj++) {
      int jj = j + dj;
      if (jj < 0 || jj >= ny) continue;
      for (int di = -banks; di <= banks; di++) {
        int ii = i + di;
        if (ii < 0 || ii >= nx) continue;
        double w = 1 - sqrt((double)(di * di + dj * dj)) / r;
        if (w > best && W->pw[(size_t)jj * nx + ii] >= W->thr) best = w;
      }
    }
    row[i] = (float)best;
  }
}

typedef struct bed {
  const oc_heightfield *sig;
  double x0, y0, cell;
  int nx, ny;
} bed;

/* sigma at the nearest sample. */
static double sigma_at(const bed *B, double x, double y) {
  int i = (int)lround((x - B->x0) / B->cell);
  int j = (int)lround((y - B->y0) / B->cell);
  i = i < 0 ? 0 : i >= B->nx ? B->nx - 1 : i;
  j = j < 0 ? 0 : j >= B->ny ? B->ny - 1 : j;
  return oc_heightfield_samples(B->sig)[(size_t)j * B->nx + i];
}

static int keep_column(void *ud, double x, double y) {
  return sigma_at(ud, x, y) > 0;
}

static int check(const oc_gen_river_params *p, oc_gen_river_params *q,
                 oc_error *err) {
  *q = *p;
  if (!p->erode.heightfield)
    return oc_seterr(err, OC_EINVAL, "'heightfield' is required");
  double cell = oc_heightfield_cell(p->erode.heightfield);
  if (!(p->power >= 0 && isfinite(p->power)))
    return oc_seterr(err, OC_EINVAL, "'power' must be > 0 (got %g)", p->power);
  if (p->banks < 0 || p->banks > 64)
    return oc_seterr(err, OC_EINVAL, "'banks' must be in 0..64 (got %d)",
                     p->banks);
  if (q->erode.radius == 0) q->erode.radius = 1.5 * cell;
  if (q->erode.spacing == 0) q->erode.spacing = q->erode.radius / 2;
  if (q->depth == 0) q->depth = fmin(3 * q->erode.radius, DBL_MAX);
  if (oc_erode_check(&q->erode, err)) return err ? err->code : OC_EINVAL;
  if (!(q->depth > 0 && isfinite(q->depth)))
    return oc_seterr(err, OC_EINVAL, "'depth' must be > 0 (got %g)", q->depth);
  return OC_OK;
}

oc_node *oc_generate_river(const oc_gen_river_params *pin, oc_gen_sea_stats *st,
                           oc_error *err) {
  oc_gen_river_params p;
  if (check(pin, &p, err)) return NULL;
  oc_heightfield *hf = p.erode.heightfield, *pw = NULL, *sig = NULL;
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double x0, y0, cell = oc_heightfield_cell(hf), *xy = NULL;
  oc_heightfield_origin(hf, &x0, &y0);
  oc_erode_cand *cand = NULL;
  unsigned char *mask = NULL;
  oc_node *base = NULL, *out = NULL;
  size_t ncol = 0, nc = 0;
  double thr = p.power;

  if (!(base = oc_erode_base(hf, p.erode.terrain, err))) return NULL;
  oc_heightfield_flow_params fp = {0, 0, p.erode.progress};
  if (!(pw = oc_heightfield_stream_power(hf, &fp, err))) goto done;
  if (thr == 0 &&
      quantile(oc_heightfield_samples(pw), (size_t)nx * ny, 0.95, &thr, err))
    goto done;
  if (!(thr > 0)) thr = 1e-30; /* a flat grid: anything that flows */
  if (!(sig = oc_heightfield_new(nx, ny, cell, x0, y0, NULL, err))) goto done;
  widening W = {oc_heightfield_samples(pw), thr, p.banks};
  if (oc_heightfield_each_row(sig, widen_row, &W, p.erode.progress,
                              "river erosion", err))
    goto done;
  bed B = {sig, x0, y0, cell, nx, ny};
  size_t ns = (size_t)nx * ny;
  if (!(mask = malloc(ns))) {
    oc_seterr(err, OC_ENOMEM, "out of memory for the riverbed mask");
    goto done;
  }
  for (size_t k = 0; k < ns; k++)
    mask[k] = oc_heightfield_samples(sig)[k] > 0;
  xy = oc_erode_columns(hf, mask, p.erode.spacing, p.erode.seed, keep_column,
                        &B, p.erode.progress, 0.3, &ncol, err);
  if (!xy) goto done;
  cand = malloc((ncol ? ncol : 1) * sizeof *cand);
  if (!cand) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu columns", ncol);
    goto done;
  }
  for (size_t i = 0; i < ncol; i++) {
    oc_erode_cand *c = &cand[nc++];
    double g[2], x = xy[2 * i], y = xy[2 * i + 1];
    double h = oc_heightfield_height(hf, x, y, g), s = hypot(g[0], g[1]);
    c->x = x;
    c->y = y;
    c->stress = sigma_at(&B, x, y);
    c->fwd = p.erode.steps * p.erode.radius + cell;
    if (s < FLAT) { /* the bed floor */
      c->zlo = c->zhi = h;
      c->ux = c->uy = 0;
      c->back = 0;
      continue;
    }
    c->ux = g[0] / s;
    c->uy = g[1] / s;
    c->zlo = h - p.depth;
    c->zhi = h;
    double back = p.depth / s;
    if (back > 4 * p.depth) back = 4 * p.depth;
    c->back = back + p.erode.radius + cell;
  }

  oc_erode_params ep;
  oc_erode_shared(&ep, base, hf, &p.erode);
  ep.pbase = 0.3;
  ep.pspan = 0.7;
  out = oc_erode_run(&ep, cand, nc, st, err);
done:
  oc_node_release(base);
  oc_heightfield_release(pw);
  oc_heightfield_release(sig);
  free(xy);
  free(cand);
  free(mask);
  return out;
}
