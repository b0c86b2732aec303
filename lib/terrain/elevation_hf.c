/*
** elevation_hf.c — a heightfield as an elevation source (oc_elevation):
** its Catmull-Rom interpolant, and a min/max pyramid answering ranges and
** slope bounds over footprints.
**
** On one cell the interpolant is a bicubic patch; its Bezier coefficients
** (1D: p1, p1 + (p2 - p0)/6, p2 - (p3 - p1)/6, p2 along each axis) bound
** it (convex hull), and 3 times their largest difference along an axis
** bounds its derivative there; the value also stays within the 4 x 4
** samples' range widened by OC_HEIGHTFIELD_OVERSHOOT times their spread, and
** the
** tighter of the two bounds is kept. Level 0 of the pyramid keeps those bounds
** per cell (12 bytes a cell: three times the grid), each next level per
** 2 x 2 blocks of the previous one; a query reads at most 4 x 4 blocks of
** the finest level that covers the footprint so. Flat and planar grids
** get exact ranges (the hull of a linear patch is its corners).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/fround.h"
#include "outcrop.h"
#include "terrain/terrain.h"

#define MAX_LEVELS 20

typedef struct level {
  int w, h;
  float *lo, *hi, *gs; /* per block: range, and bound of |grad h| */
} level;

typedef struct hfsrc {
  int refs;
  oc_heightfield *hf;
  const float *z;
  int nx, ny;
  double cell, x0, y0;
  double pad; /* absorbs the rounding of the interpolant's evaluation */
  int nlev;
  level lev[MAX_LEVELS];
} hfsrc;

/* Hull and derivative bounds of the patch of cell (ci, cj). */
static void cell_bounds(const hfsrc *s, int ci, int cj, double *lo, double *hi,
                        double *gs) {
  double P[4][4], U[4][4], B[4][4];
  for (int b = 0; b < 4; b++) {
    int jj = cj - 1 + b;
    jj = jj < 0 ? 0 : jj >= s->ny ? s->ny - 1 : jj;
    const float *row = s->z + (size_t)jj * s->nx;
    for (int a = 0; a < 4; a++) {
      int ii = ci - 1 + a;
      ii = ii < 0 ? 0 : ii >= s->nx ? s->nx - 1 : ii;
      P[b][a] = row[ii];
    }
  }
  for (int b = 0; b < 4; b++) {
    U[b][0] = P[b][1];
    U[b][1] = P[b][1] + (P[b][2] - P[b][0]) / 6;
    U[b][2] = P[b][2] - (P[b][3] - P[b][1]) / 6;
    U[b][3] = P[b][2];
  }
  for (int a = 0; a < 4; a++) {
    B[0][a] = U[1][a];
    B[1][a] = U[1][a] + (U[2][a] - U[0][a]) / 6;
    B[2][a] = U[2][a] - (U[3][a] - U[1][a]) / 6;
    B[3][a] = U[2][a];
  }
  double l = B[0][0], h = B[0][0], gu = 0, gv = 0, pl = P[0][0], ph = P[0][0];
  for (int b = 0; b < 4; b++)
    for (int a = 0; a < 4; a++) {
      pl = fmin(pl, P[b][a]);
      ph = fmax(ph, P[b][a]);
      l = fmin(l, B[b][a]);
      h = fmax(h, B[b][a]);
      if (a < 3) gu = fmax(gu, fabs(B[b][a + 1] - B[b][a]));
      if (b < 3) gv = fmax(gv, fabs(B[b + 1][a] - B[b][a]));
    }
  /* the hull is usually tighter than the interpolation's overshoot bound,
  ** but not always: both hold, so does their intersection */
  *lo = fmax(l, pl - OC_HEIGHTFIELD_OVERSHOOT * (ph - pl));
  *hi = fmin(h, ph + OC_HEIGHTFIELD_OVERSHOOT * (ph - pl));
  *gs = 3 * sqrt(gu * gu + gv * gv) / s->cell * (1 + 1e-9);
}

static void free_levels(hfsrc *s) {
  for (int l = 0; l < s->nlev; l++) {
    free(s->lev[l].lo);
    free(s->lev[l].hi);
    free(s->lev[l].gs);
  }
}

static int alloc_level(level *L, int w, int h) {
  size_t n = (size_t)w * (size_t)h;
  L->w = w;
  L->h = h;
  L->lo = malloc(n * sizeof *L->lo);
  L->hi = malloc(n * sizeof *L->hi);
  L->gs = malloc(n * sizeof *L->gs);
  return L->lo && L->hi && L->gs ? 0 : -1;
}

static int build(hfsrc *s) {
  int w = s->nx - 1, h = s->ny - 1; /* cells */
  s->nlev = 1;
  if (alloc_level(&s->lev[0], w, h)) return -1;
  level *L0 = &s->lev[0];
#pragma omp parallel for schedule(static)
  for (int cj = 0; cj < h; cj++)
    for (int ci = 0; ci < w; ci++) {
      double lo, hi, gs;
      cell_bounds(s, ci, cj, &lo, &hi, &gs);
      size_t q = (size_t)cj * w + ci;
      L0->lo[q] = oc_float_down(lo);
      L0->hi[q] = oc_float_up(hi);
      L0->gs[q] = oc_float_up(gs);
    }
  while ((w > 1 || h > 1) && s->nlev < MAX_LEVELS) {
    level *P = &s->lev[s->nlev - 1], *L = &s->lev[s->nlev];
    int nw = (w + 1) / 2, nh = (h + 1) / 2;
    if (alloc_level(L, nw, nh)) {
      s->nlev++; /* so that free_levels frees what was allocated */
      return -1;
    }
    s->nlev++;
    for (int bj = 0; bj < nh; bj++)
      for (int bi = 0; bi < nw; bi++) {
        float lo = INFINITY, hi = -INFINITY, gs = 0;
        for (int j = 2 * bj; j <= 2 * bj + 1 && j < h; j++)
          for (int i = 2 * bi; i <= 2 * bi + 1 && i < w; i++) {
            size_t q = (size_t)j * w + i;
            lo = fminf(lo, P->lo[q]);
            hi = fmaxf(hi, P->hi[q]);
            gs = fmaxf(gs, P->gs[q]);
          }
        size_t q = (size_t)bj * nw + bi;
        L->lo[q] = lo;
        L->hi[q] = hi;
        L->gs[q] = gs;
      }
    w = nw;
    h = nh;
  }
  return 0;
}

/* Cell range of a footprint, clamped to the grid (positions outside it
** are clamped by the interpolation too). */
static int blocks(const hfsrc *s, double x0, double y0, double x1, double y1,
                  int b[4]) {
  double u[2] = {(x0 - s->x0) / s->cell, (x1 - s->x0) / s->cell};
  double v[2] = {(y0 - s->y0) / s->cell, (y1 - s->y0) / s->cell};
  for (int k = 0; k < 2; k++) {
    double a = u[k], e = v[k];
    if (!(a == a) || !(e == e)) return -1;
    a = a < 0 ? 0 : a > s->nx - 2 ? s->nx - 2 : a;
    e = e < 0 ? 0 : e > s->ny - 2 ? s->ny - 2 : e;
    b[k] = (int)a;
    b[2 + k] = (int)e;
  }
  return 0;
}

/* Visits the blocks covering the footprint at the finest level where
** they are at most 4 x 4. */
#define VISIT(s, b, body)                                                      \
  do {                                                                         \
    int l_ = 0;                                                                \
    while (l_ + 1 < (s)->nlev && ((b[1] >> l_) - (b[0] >> l_) > 3 ||           \
                                  (b[3] >> l_) - (b[2] >> l_) > 3))            \
      l_++;                                                                    \
    const level *L_ = &(s)->lev[l_];                                           \
    for (int j_ = b[2] >> l_; j_ <= b[3] >> l_; j_++)                          \
      for (int i_ = b[0] >> l_; i_ <= b[1] >> l_; i_++) {                      \
        size_t q_ = (size_t)j_ * L_->w + i_;                                   \
        body;                                                                  \
      }                                                                        \
  } while (0)

static void hf_range(void *ud, double x0, double y0, double x1, double y1,
                     double *lo, double *hi) {
  const hfsrc *s = ud;
  int b[4];
  if (x0 > x1 || y0 > y1 || blocks(s, x0, y0, x1, y1, b)) {
    *lo = -INFINITY;
    *hi = INFINITY;
    return;
  }
  double l = INFINITY, h = -INFINITY;
  VISIT(s, b, {
    l = fmin(l, L_->lo[q_]);
    h = fmax(h, L_->hi[q_]);
  });
  *lo = l - s->pad;
  *hi = h + s->pad;
}

static double hf_slope(void *ud, double x0, double y0, double x1, double y1) {
  const hfsrc *s = ud;
  int b[4];
  if (x0 > x1 || y0 > y1 || blocks(s, x0, y0, x1, y1, b)) return INFINITY;
  double g = 0;
  VISIT(s, b, g = fmax(g, L_->gs[q_]));
  return g;
}

static double hf_height(void *ud, double x, double y, double grad[2]) {
  const hfsrc *s = ud;
  return oc_heightfield_height(s->hf, x, y, grad);
}

static void hf_retain(void *ud) {
  hfsrc *s = ud;
  __atomic_add_fetch(&s->refs, 1, __ATOMIC_RELAXED);
}

static void hf_release(void *ud) {
  hfsrc *s = ud;
  if (__atomic_sub_fetch(&s->refs, 1, __ATOMIC_ACQ_REL) != 0) return;
  free_levels(s);
  oc_heightfield_release(s->hf);
  free(s);
}

int oc_heightfield_elevation(oc_heightfield *hf, oc_elevation *src,
                             oc_error *err) {
  if (!hf || !src)
    return oc_seterr(err, OC_EINVAL, "no heightfield to make a source of");
  hfsrc *s = calloc(1, sizeof *s);
  if (!s) return oc_seterr(err, OC_ENOMEM, "out of memory");
  s->refs = 1;
  s->hf = hf;
  s->z = oc_heightfield_samples(hf);
  s->nx = oc_heightfield_nx(hf);
  s->ny = oc_heightfield_ny(hf);
  s->cell = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &s->x0, &s->y0);
  double zl, zh;
  oc_heightfield_minmax(hf, &zl, &zh);
  s->pad = 1e-12 * (1 + fmax(fabs(zl), fabs(zh)));
  if (build(s)) {
    int nx = s->nx, ny = s->ny;
    free_levels(s);
    free(s);
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory for the pyramid of a %d x %d heightfield",
                     nx, ny);
  }
  oc_heightfield_retain(hf);
  memset(src, 0, sizeof *src); /* hooks a grid lacks (coarser...) NULL */
  src->height = hf_height;
  src->range = hf_range;
  src->slope = hf_slope;
  src->retain = hf_retain;
  src->release = hf_release;
  src->height_weight = NULL; /* a grid's surface covers its domain */
  src->weight_range = NULL;
  src->bound = NULL; /* range and slope, each from the pyramid */
  src->height_weight_row = NULL;
  src->taylor = NULL; /* the tracer asks for slopes */
  src->ud = s;
  src->x0 = s->x0;
  src->y0 = s->y0;
  src->x1 = s->x0 + (s->nx - 1) * s->cell;
  src->y1 = s->y0 + (s->ny - 1) * s->cell;
  return OC_OK;
}

size_t oc_hfsrc_bytes(const oc_elevation *src, const oc_heightfield **hf,
                      size_t *hf_bytes) {
  *hf = NULL;
  *hf_bytes = 0;
  if (src->height != hf_height) return 0;
  const hfsrc *s = src->ud;
  size_t b = sizeof *s;
  for (int l = 0; l < s->nlev; l++)
    b += (size_t)s->lev[l].w * (size_t)s->lev[l].h * 3 * sizeof(float);
  *hf = s->hf;
  *hf_bytes = (size_t)s->nx * (size_t)s->ny * sizeof *s->z;
  return b;
}
