/*
** jacobi.c — the relaxations of a level and the bilinear prolongation
** between levels (Hnaidi et al. 2010, section 5.2):
**
**   F' = alpha F_L + beta F_G + (1 - alpha - beta) F_I,
**
** F_L the mean of the 4 neighbours, F_I the strict value, alpha = beta =
** 1/2 in gradient regions, alpha = beta = 0 on strict samples, alpha = 1
** elsewhere. The gradient term, with s = sign(n) and G = g cell (g the
** drop per metre along n, rescaled at every level by its cell):
**
**   upwind (default) F_G = (|nx| F(i - sx, j) + |ny| F(i, j - sy) - G)
**                          / (|nx| + |ny|)
**   paper            F_G = (nx^2 F(i - sx, j) + ny^2 F(i, j - sy))
**                          / (nx^2 + ny^2) - G
**
** The upwind form holds every plane of slope g along n exactly; the
** printed one makes 45-degree slopes sqrt 2 too steep (the two
** neighbours each differ by g cell / sqrt 2, weighted 1/2 each).
** Neumann border: a missing neighbour is the sample itself.
**
** oc_dguide_prepare folds n and g of a gradient sample into two numbers
** and two flag bits, F' = F_L / 2 + t F(i - sx, j) + (1/2 - t)
** F(i, j - sy) + c, so that a relaxation reads per sample one flag byte
** and (gradient samples of the elevation) two floats, with no branch:
** the kinds of sample are selected arithmetically and the rows vectorise.
** Arithmetic in float (the maps are float; the elevation's solves end
** far above float's rounding).
**
** Jacobi reads x and writes y; red-black Gauss-Seidel updates the samples
** of one colour ((i + j) even: red) in place from those of the other.
** Either way every value depends only on values of the previous step, so
** rows run in parallel in any order and the result does not depend on the
** thread count; the largest update is a max, exact in any order.
*/
#include <math.h>

#include "diffusion/diffusion.h"

/* The relaxation rows select between sample kinds; gcc's default cost
** model at -O2 ("very cheap") leaves such loops scalar. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("vect-cost-model=cheap")
#endif

void oc_dguide_prepare(oc_dlevel *lv, int paper) {
  float *gx = lv->map[MAP_GX], *gy = lv->map[MAP_GY];
  const float *gd = lv->map[MAP_GD];
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
  double cell = lv->cell;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (size_t k = 0; k < ns; k++) {
    uint8_t f = (uint8_t)(lv->flags[k] & ~(DF_GACT | DF_SX | DF_SY));
    double nx = gx[k], ny = gy[k], ax = fabs(nx), ay = fabs(ny);
    float t = 0, c = 0;
    if ((f & DF_GUIDE) && ax + ay > 1e-6) {
      double G = gd[k] * cell;
      f |= DF_GACT;
      if (nx < 0) f |= DF_SX; /* upwind: i + 1 */
      if (ny < 0) f |= DF_SY; /* upwind: j + 1 */
      if (paper) {
        t = (float)(0.5 * nx * nx / (nx * nx + ny * ny));
        c = (float)(-0.5 * G);
      } else {
        t = (float)(0.5 * ax / (ax + ay));
        c = (float)(-0.5 * G / (ax + ay));
      }
    }
    lv->flags[k] = f;
    gx[k] = t;
    gy[k] = c;
  }
}

#define INLINE static inline __attribute__((always_inline))

/* The update of one sample from its neighbours w, e, s, n and itself xv. */
INLINE float update(int guided, float w, float e, float s, float n, float xv,
                    uint8_t f, float t, float c, float chom) {
  (void)xv;
  float L = 0.25f * ((w + e) + (s + n));
  if (!guided) return L;
  float fx = (f & DF_SX) ? e : w, fy = (f & DF_SY) ? n : s;
  float g = 0.5f * L + t * fx + (0.5f - t) * fy + chom * c;
  return (f & DF_GACT) ? g : L;
}

enum { R_JACOBI, R_RED, R_BLACK, R_RESIDUAL };

/* One row j: mode R_JACOBI writes every sample of y, R_RED / R_BLACK the
** samples of that colour (y == x), R_RESIDUAL the update v - x (0 where
** fixed). Returns the largest |v - x| over the free samples written. */
INLINE float row(int guided, int mode, int has_rhs, const oc_dlevel *lv,
                 uint8_t fix, float keep, float chom, const float *x, float *y,
                 const float *rhs, int j) {
  size_t nx = (size_t)lv->nx, r0 = (size_t)j * nx;
  const float *xr = x + r0, *xs = j > 0 ? xr - nx : xr,
              *xn = j + 1 < lv->ny ? xr + nx : xr;
  const uint8_t *fl = lv->flags + r0;
  const float *t = guided ? lv->map[MAP_GX] + r0 : NULL;
  const float *c = guided ? lv->map[MAP_GY] + r0 : NULL;
  const float *b = has_rhs ? rhs + r0 : NULL;
  float *yr = y + r0;
  float big = 0;
  /* colour of sample i: (i + j) & 1; the one updated: */
  int want = mode == R_BLACK;
  size_t last = nx - 1;
  /* the border columns (Neumann: the sample itself for the missing one) */
  for (size_t q = 0; q < 2 && q <= last; q++) {
    size_t i = q ? last : 0;
    if (q && last == 0) break;
    size_t iw = i ? i - 1 : 0, ie = i < last ? i + 1 : last;
    float xv = xr[i];
    float v = update(guided, xr[iw], xr[ie], xs[i], xn[i], xv, fl[i],
                     guided ? t[i] : 0, guided ? c[i] : 0, chom);
    if (has_rhs) v += b[i];
    int fixed = (fl[i] & fix) != 0;
    float d = fixed ? 0 : fabsf(v - xv);
    if (mode == R_RESIDUAL) {
      yr[i] = fixed ? 0 : v - xv;
    } else if (mode == R_JACOBI) {
      yr[i] = fixed ? keep * xv : v;
    } else {
      if ((int)((i + (size_t)j) & 1) != want) continue;
      yr[i] = fixed ? keep * xv : v;
    }
    big = d > big ? d : big;
  }
  if (mode == R_RED || mode == R_BLACK) {
    /* only the samples of that colour are written: no sample another row
    ** (thread) reads is written in this half-sweep */
    for (size_t i = 2 - (((size_t)j + (size_t)want) & 1); i < last; i += 2) {
      float xv = xr[i];
      float v = update(guided, xr[i - 1], xr[i + 1], xs[i], xn[i], xv, fl[i],
                       guided ? t[i] : 0, guided ? c[i] : 0, chom);
      if (has_rhs) v += b[i];
      int fixed = (fl[i] & fix) != 0;
      yr[i] = fixed ? keep * xv : v;
      float d = fixed ? 0 : fabsf(v - xv);
      big = d > big ? d : big;
    }
    return big;
  }
#pragma omp simd reduction(max : big)
  for (size_t i = 1; i < last; i++) {
    float xv = xr[i];
    float v = update(guided, xr[i - 1], xr[i + 1], xs[i], xn[i], xv, fl[i],
                     guided ? t[i] : 0, guided ? c[i] : 0, chom);
    if (has_rhs) v += b[i];
    int fixed = (fl[i] & fix) != 0;
    float d = fixed ? 0 : fabsf(v - xv);
    float o =
        mode == R_RESIDUAL ? (fixed ? 0 : v - xv) : (fixed ? keep * xv : v);
    yr[i] = o;
    big = d > big ? d : big;
  }
  return big;
}

/* The rows of one relaxation. Each combination of kind, mode and rhs has
** its own parallel loop with constant arguments: the loop body the
** compiler outlines for the threads must see them as constants to drop
** the unused branches and vectorise. */
// clang-format off
#define SWEEP(G, M, B)                                                         \
  _Pragma("omp parallel for schedule(static) reduction(max:big) if(par)")      \
  for (int j = 0; j < ny; j++) {                                               \
    float b = row(G, M, B, lv, fix, keep, chom, x, y, rhs, j);                 \
    big = b > big ? b : big;                                                   \
  }                                                                            \
  break
// clang-format on

static double relax(int mode, const oc_dop *op, const oc_dlevel *lv,
                    const float *x, float *y, const float *rhs) {
  uint8_t fix = op->kind == DK_LAPLACE ? op->mask : DF_H;
  float keep = op->hom ? 0.0f : 1.0f, chom = op->hom ? 0.0f : 1.0f;
  float big = 0;
  int ny = lv->ny, par = OC_DPAR(lv);
  switch ((op->kind == DK_GUIDED) * 8 + mode * 2 + (rhs != NULL)) {
  case 0:
    SWEEP(0, R_JACOBI, 0);
  case 1:
    SWEEP(0, R_JACOBI, 1);
  case 2:
    SWEEP(0, R_RED, 0);
  case 3:
    SWEEP(0, R_RED, 1);
  case 4:
    SWEEP(0, R_BLACK, 0);
  case 5:
    SWEEP(0, R_BLACK, 1);
  case 6:
    SWEEP(0, R_RESIDUAL, 0);
  case 7:
    SWEEP(0, R_RESIDUAL, 1);
  case 8:
    SWEEP(1, R_JACOBI, 0);
  case 9:
    SWEEP(1, R_JACOBI, 1);
  case 10:
    SWEEP(1, R_RED, 0);
  case 11:
    SWEEP(1, R_RED, 1);
  case 12:
    SWEEP(1, R_BLACK, 0);
  case 13:
    SWEEP(1, R_BLACK, 1);
  case 14:
    SWEEP(1, R_RESIDUAL, 0);
  default:
    SWEEP(1, R_RESIDUAL, 1);
  }
  return big;
}

double oc_djacobi(const oc_dop *op, const oc_dlevel *lv, const float *x,
                  float *y, const float *rhs) {
  return relax(R_JACOBI, op, lv, x, y, rhs);
}

double oc_dgauss_seidel(const oc_dop *op, const oc_dlevel *lv, float *x,
                        const float *rhs) {
  double a = relax(R_RED, op, lv, x, x, rhs);
  double b = relax(R_BLACK, op, lv, x, x, rhs);
  return a > b ? a : b;
}

double oc_dresidual(const oc_dop *op, const oc_dlevel *lv, const float *x,
                    const float *rhs, float *r) {
  return relax(R_RESIDUAL, op, lv, x, r, rhs);
}

/* Fine sample i lies at coarse coordinate (i - 1/2) / 2: between coarse
** samples i/2 - 1 and i/2 with weights 1/4, 3/4 when i is even, between
** (i-1)/2 and (i+1)/2 with 3/4, 1/4 when odd; clamped at the ends. */
static inline void split(int i, int nc, int *a, int *b, float *wb) {
  int a0 = (i & 1) ? (i - 1) / 2 : i / 2 - 1;
  *wb = (i & 1) ? 0.25f : 0.75f;
  *a = a0 < 0 ? 0 : a0 >= nc ? nc - 1 : a0;
  *b = a0 + 1 >= nc ? nc - 1 : a0 + 1;
}

void oc_dprolong(const oc_dop *op, const oc_dlevel *lc, const float *c,
                 const oc_dlevel *lf, float *f, int add) {
  uint8_t fix = op->kind == DK_LAPLACE ? op->mask : DF_H;
  int ncx = lc->nx, nfx = lf->nx;
#pragma omp parallel for schedule(static) if (OC_DPAR(lf))
  for (int j = 0; j < lf->ny; j++) {
    int ja, jb;
    float wy;
    split(j, lc->ny, &ja, &jb, &wy);
    const float *ca = c + (size_t)ja * (size_t)ncx,
                *cb = c + (size_t)jb * (size_t)ncx;
    float *fr = f + (size_t)j * (size_t)nfx;
    const uint8_t *fl = lf->flags + (size_t)j * (size_t)nfx;
    for (int i = 0; i < nfx; i++) {
      int ia, ib;
      float wx;
      split(i, ncx, &ia, &ib, &wx);
      float v0 = (1 - wx) * ca[ia] + wx * ca[ib];
      float v1 = (1 - wx) * cb[ia] + wx * cb[ib];
      float v = (1 - wy) * v0 + wy * v1;
      float o = add ? fr[i] + v : v;
      fr[i] = (fl[i] & fix) ? fr[i] : o;
    }
  }
}
