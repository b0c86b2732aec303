/*
** hf_make.c — grids made from something else: fBm noise, the surface of
** a 3D field, another grid (resampling, cropping).
**
** Each sample depends on its position alone, so rows run in parallel in
** any order and the grid is the same to the byte for any thread count.
*/
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "field/node.h"
#include "outcrop.h"
#include "terrain/analysis.h"

static oc_heightfield *new_grid(const oc_heightfield_grid *g, oc_error *err) {
  if (!g) {
    oc_seterr(err, OC_EINVAL, "the grid layout is NULL");
    return NULL;
  }
  return oc_heightfield_new(g->nx, g->ny, g->cell, g->x0, g->y0, NULL, err);
}

static oc_heightfield *run(oc_heightfield *out, oc_heightfield_row_fn fn,
                           const void *ctx, oc_progress pr, const char *what,
                           oc_error *err) {
  if (out && oc_heightfield_each_row(out, fn, ctx, pr, what, err) != OC_OK) {
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}

/* ---- fBm ------------------------------------------------------------- */

typedef struct fbm_ctx {
  oc_noise nz;
  double x0, y0, cell;
} fbm_ctx;

/* The arithmetic of the turbulence primitive (field/eval.c), so that the
** grid holds exactly what that node gives on z = 0. */
static void fbm_row(const void *ctx, oc_heightfield *out, int j) {
  const fbm_ctx *c = ctx;
  int nx = oc_heightfield_nx(out);
  float *row = oc_heightfield_samples_mut(out) + (size_t)j * (size_t)nx;
  double s = 1 / c->nz.wavelength, y = c->y0 + j * c->cell;
  for (int i = 0; i < nx; i++) {
    double x = c->x0 + i * c->cell;
    oc_vec3 p = {x * s, y * s, 0 * s};
    row[i] =
        (float)(c->nz.offset +
                c->nz.amplitude * oc_turb3(c->nz.seed, c->nz.octaves, p, NULL));
  }
}

oc_heightfield *oc_heightfield_fbm(const oc_heightfield_grid *g,
                                   const oc_noise *noise, oc_progress progress,
                                   oc_error *err) {
  if (!oc_check_noise(noise, err)) return NULL;
  double hmax = fabs(noise->offset) +
                fabs(noise->amplitude) * oc_turb3_max(noise->octaves);
  if (!(hmax <= FLT_MAX)) {
    oc_seterr(err, OC_EINVAL,
              "'amplitude' and 'offset' give elevations beyond float range");
    return NULL;
  }
  oc_heightfield *out = new_grid(g, err);
  if (!out) return NULL;
  fbm_ctx c = {*noise, g->x0, g->y0, g->cell};
  return run(out, fbm_row, &c, progress, "fbm", err);
}

/* ---- the surface of a field ------------------------------------------ */

#define MAX_SPANS 32
#define MAX_BISECT 200
/* A column's steps: a bound so loose that steps shrink to hmin would
** take (z1 - z0) / hmin = 1e5 evaluations per sample (a taper tree took
** 12 s on a 24 x 24 grid). Past COLUMN_BUDGET steps (real scenes take
** tens) the smallest step becomes (z1 - z0) / COARSE_STEPS, so a sample
** costs at most about 2 COLUMN_BUDGET evaluations. */
#define COLUMN_BUDGET 1024
#define COARSE_STEPS 1024
#define UNBOUNDED_STEPS 4096 /* step (z1 - z0) / 4096 where L is infinite */

typedef struct surf_ctx {
  const oc_program *prog;
  double x0, y0, cell, z0, z1, T;
  double hmin; /* smallest step down a column */
  double tol;  /* bisection stops at this bracket width */
} surf_ctx;

static double eval_at(const surf_ctx *c, double x, double y, double z) {
  return oc_program_eval(c->prog, (oc_vec3){x, y, z});
}

/* The crossing between `in` (f > T) and `out` (f <= T) above it. */
static double bisect(const surf_ctx *c, double x, double y, double in,
                     double out) {
  for (int k = 0; k < MAX_BISECT && out - in > c->tol; k++) {
    double mid = 0.5 * (in + out);
    if (eval_at(c, x, y, mid) > c->T)
      in = mid;
    else
      out = mid;
  }
  return 0.5 * (in + out);
}

/* Steps down [lo, z] from z (f(z) = *f <= T) by at most the distance the
** local Lipschitz bound of the span proves free of the surface. Returns 1
** with the crossing in *hit, or 0 with z = lo and *f = f(lo). (Bounds over
** shorter pieces of the span cost more queries than they save steps.) */
static int descend(const surf_ctx *c, double x, double y, double lo, double *z,
                   double *f, double *hit, long *steps) {
  oc_aabb box = {{x, y, lo}, {x, y, *z}};
  double L = oc_program_lipschitz_in(c->prog, box);
  double coarse = (c->z1 - c->z0) / COARSE_STEPS;
  double blind = (c->z1 - c->z0) / UNBOUNDED_STEPS;
  while (*z > lo) {
    double step;
    if (L == 0)
      step = *z - lo; /* constant here */
    else if (isfinite(L))
      step = (c->T - *f) / L;
    else
      step = blind;
    step = fmax(step, ++*steps > COLUMN_BUDGET ? coarse : c->hmin);
    double zn = fmax(*z - step, lo);
    if (!(zn < *z)) zn = lo; /* no progress in floating point */
    double fn = eval_at(c, x, y, zn);
    if (fn > c->T) {
      *hit = bisect(c, x, y, zn, *z);
      return 1;
    }
    *z = zn;
    *f = fn;
  }
  return 0;
}

static double surface(const surf_ctx *c, double x, double y) {
  double z = c->z1, f = eval_at(c, x, y, z), hit;
  long steps = 0;
  if (f > c->T) return c->z1;
  oc_zspan sp[MAX_SPANS];
  int n = oc_program_column_spans(c->prog, x, y, x, y, sp, MAX_SPANS);
  if (n < 0) {
    sp[0] = (oc_zspan){c->z0, c->z1};
    n = 1;
  }
  /* Between spans the field is constant, so only spans need stepping;
  ** the value at a span's top equals the one left below the span above. */
  for (int k = n - 1; k >= 0; k--) {
    double lo = fmax(sp[k].lo, c->z0), hi = fmin(sp[k].hi, c->z1);
    if (lo > hi || lo >= z) continue;
    if (hi < z) {
      double fh = eval_at(c, x, y, hi);
      if (fh > c->T) return bisect(c, x, y, hi, z);
      z = hi;
      f = fh;
    }
    if (descend(c, x, y, lo, &z, &f, &hit, &steps)) return hit;
  }
  return c->z0;
}

static void surf_row(const void *ctx, oc_heightfield *out, int j) {
  const surf_ctx *c = ctx;
  int nx = oc_heightfield_nx(out);
  float *row = oc_heightfield_samples_mut(out) + (size_t)j * (size_t)nx;
  double y = c->y0 + j * c->cell;
  for (int i = 0; i < nx; i++)
    row[i] = (float)surface(c, c->x0 + i * c->cell, y);
}

oc_heightfield *oc_heightfield_from_program(
    const oc_program *prog, const oc_heightfield_grid *g, double z0, double z1,
    double threshold, oc_progress progress, oc_error *err) {
  if (!prog) {
    oc_seterr(err, OC_EINVAL, "the program is NULL");
    return NULL;
  }
  if (!isfinite(z0) || !isfinite(z1) || !(z0 < z1) || !isfinite(z1 - z0) ||
      fmax(fabs(z0), fabs(z1)) > FLT_MAX) {
    oc_seterr(err, OC_EINVAL,
              "'zrange' must be {z0, z1} with finite z0 < z1 (got %g, %g)", z0,
              z1);
    return NULL;
  }
  /* The smallest step, (z1 - z0) 1e-5, must move z in double precision. */
  if (z1 - z0 < 1e-9 * fmax(fabs(z0), fabs(z1))) {
    oc_seterr(err, OC_EINVAL,
              "'zrange' {%g, %g} is too thin for its distance from 0", z0, z1);
    return NULL;
  }
  double T = threshold != 0 ? threshold : oc_program_threshold(prog);
  if (!isfinite(T)) {
    oc_seterr(err, OC_EINVAL, "'threshold' must be finite (got %g)", T);
    return NULL;
  }
  oc_heightfield *out = new_grid(g, err);
  if (!out) return NULL;
  surf_ctx c = {.prog = prog,
                .x0 = g->x0,
                .y0 = g->y0,
                .cell = g->cell,
                .z0 = z0,
                .z1 = z1,
                .T = T,
                .hmin = (z1 - z0) * 1e-5,
                .tol = (z1 - z0) * 1e-9};
  return run(out, surf_row, &c, progress, "the surface sampling", err);
}

/* ---- resampling -------------------------------------------------------- */

typedef struct resample_ctx {
  const oc_heightfield *src;
  double x0, y0, cell; /* the new grid's */
  double r;            /* tent radius in source cells; 0: interpolate */
} resample_ctx;

static double clampd(double v, double lo, double hi) {
  return v < lo ? lo : v > hi ? hi : v;
}

/* The source samples around (u, v) (in source cells) averaged under the
** tent of radius r: separable weights (1 - |d| / r), renormalized where
** the grid ends. r > 1/2, so the nearest sample always has weight. */
static double tent(const oc_heightfield *src, double u, double v, double r) {
  int nx = oc_heightfield_nx(src), ny = oc_heightfield_ny(src);
  const float *z = oc_heightfield_samples(src);
  int i0 = (int)ceil(u - r), i1 = (int)floor(u + r);
  int j0 = (int)ceil(v - r), j1 = (int)floor(v + r);
  i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0;
  i1 = i1 > nx - 1 ? nx - 1 : i1, j1 = j1 > ny - 1 ? ny - 1 : j1;
  double sum = 0, wsum = 0;
  for (int j = j0; j <= j1; j++) {
    double wy = 1 - fabs(j - v) / r;
    if (wy <= 0) continue;
    const float *row = z + (size_t)j * (size_t)nx;
    double s = 0, w = 0;
    for (int i = i0; i <= i1; i++) {
      double wx = 1 - fabs(i - u) / r;
      if (wx <= 0) continue;
      s += wx * row[i];
      w += wx;
    }
    sum += wy * s;
    wsum += wy * w;
  }
  return sum / wsum;
}

static void resample_row(const void *ctx, oc_heightfield *out, int j) {
  const resample_ctx *c = ctx;
  const oc_heightfield *src = c->src;
  int nx = oc_heightfield_nx(out);
  int snx = oc_heightfield_nx(src), sny = oc_heightfield_ny(src);
  double sx0, sy0, sc = oc_heightfield_cell(src);
  oc_heightfield_origin(src, &sx0, &sy0);
  float *row = oc_heightfield_samples_mut(out) + (size_t)j * (size_t)nx;
  double v = clampd((c->y0 + j * c->cell - sy0) / sc, 0, sny - 1);
  for (int i = 0; i < nx; i++) {
    double u = clampd((c->x0 + i * c->cell - sx0) / sc, 0, snx - 1);
    row[i] = c->r > 0 ? (float)tent(src, u, v, c->r)
                      : (float)oc_heightfield_height(src, sx0 + u * sc,
                                                     sy0 + v * sc, NULL);
  }
}

oc_heightfield *oc_heightfield_resample(const oc_heightfield *hf,
                                        const oc_heightfield_grid *g,
                                        oc_progress progress, oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  oc_heightfield *out = new_grid(g, err);
  if (!out) return NULL;
  double sc = oc_heightfield_cell(hf);
  resample_ctx c = {hf, g->x0, g->y0, g->cell, 0};
  /* The same cell (up to rounding) interpolates, which reproduces the
  ** samples where the grids align. */
  if (g->cell > sc * (1 + 1e-12)) c.r = g->cell / sc;
  return run(out, resample_row, &c, progress, "resampling", err);
}

/* ---- cropping ---------------------------------------------------------- */

oc_heightfield *oc_heightfield_crop(const oc_heightfield *hf, int i0, int j0,
                                    int i1, int j1, oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  if (i0 < 0 || j0 < 0 || i1 >= nx || j1 >= ny || i1 - i0 < 1 || j1 - j0 < 1) {
    oc_seterr(err, OC_EINVAL,
              "the crop must keep at least 2 x 2 samples inside the %d x %d "
              "grid (got i %d..%d, j %d..%d, 0-based)",
              nx, ny, i0, i1, j0, j1);
    return NULL;
  }
  double x0, y0, cell = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  oc_heightfield *out =
      oc_heightfield_new(i1 - i0 + 1, j1 - j0 + 1, cell, x0 + i0 * cell,
                         y0 + j0 * cell, NULL, err);
  if (!out) return NULL;
  int w = i1 - i0 + 1;
  for (int j = j0; j <= j1; j++)
    memcpy(oc_heightfield_samples_mut(out) + (size_t)(j - j0) * w,
           oc_heightfield_samples(hf) + (size_t)j * nx + i0,
           (size_t)w * sizeof(float));
  return out;
}
