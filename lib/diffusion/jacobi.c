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
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "diffusion/diffusion.h"

/* The relaxation rows select between sample kinds; gcc's default cost
** model at -O2 ("very cheap") leaves such loops scalar. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("vect-cost-model=cheap")
#endif

/* The row kernels are compiled for AVX-512, AVX2 and the baseline, the
** best the processor has chosen at load time: the same IEEE operations
** on every sample whatever the vector width (floating-point contraction
** is off), so the same bytes, 2 to 4 times the samples an instruction. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CLONES                                                                 \
  __attribute__((                                                              \
      noinline, target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CLONES __attribute__((noinline))
#endif

#define INLINE static inline __attribute__((always_inline))

/* Samples [k0, k1) of oc_dguide_prepare (after the gradient's diffusion
** with renorm, as renormalise did and then the folding, in one pass). */
INLINE void guide_body(int renorm, int paper, uint8_t *flags, float *gx,
                       float *gy, const float *gd, size_t k0, size_t k1,
                       double cell, double coherent) {
  for (size_t k = k0; k < k1; k++) {
    uint8_t fl = flags[k];
    float fx = gx[k], fy = gy[k];
    if (renorm) {
      double g = sqrt((double)fx * fx + (double)fy * fy);
      int keep = g > ((fl & DF_SLOPE) ? 1e-6 : coherent);
      float ux = (float)(fx / g), uy = (float)(fy / g);
      fx = keep ? ux : 0;
      fy = keep ? uy : 0;
    }
    uint8_t f = (uint8_t)(fl & ~(DF_GACT | DF_SX | DF_SY));
    double nx = fx, ny = fy, ax = fabs(nx), ay = fabs(ny);
    int on = ((f & DF_GUIDE) != 0) & (ax + ay > 1e-6);
    double G = gd[k] * cell;
    float t, c;
    if (paper) {
      t = (float)(0.5 * nx * nx / (nx * nx + ny * ny));
      c = (float)(-0.5 * G);
    } else {
      t = (float)(0.5 * ax / (ax + ay));
      c = (float)(-0.5 * G / (ax + ay));
    }
    uint8_t sx = nx < 0 ? DF_SX : 0, sy = ny < 0 ? DF_SY : 0; /* upwind +1 */
    flags[k] = on ? (uint8_t)(f | DF_GACT | sx | sy) : f;
    gx[k] = on ? t : 0;
    gy[k] = on ? c : 0;
  }
}

/* One function per combination, with them constant (no branch on them
** in the loop). */
#define GUIDEFN(RN, PA)                                                        \
  static CLONES void guide_##RN##PA(uint8_t *flags, float *gx, float *gy,      \
                                    const float *gd, size_t k0, size_t k1,     \
                                    double cell, double coherent) {            \
    guide_body(RN, PA, flags, gx, gy, gd, k0, k1, cell, coherent);             \
  }
GUIDEFN(0, 0)
GUIDEFN(0, 1)
GUIDEFN(1, 0)
GUIDEFN(1, 1)

void oc_dguide_prepare(oc_dlevel *lv, int paper, double coherent) {
  size_t nx = (size_t)lv->nx;
  void (*fn)(uint8_t *, float *, float *, const float *, size_t, size_t, double,
             double) = coherent >= 0 ? (paper ? guide_11 : guide_10)
                                     : (paper ? guide_01 : guide_00);
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (int j = 0; j < lv->ny; j++)
    fn(lv->flags, lv->map[MAP_GX], lv->map[MAP_GY], lv->map[MAP_GD],
       (size_t)j * nx, (size_t)j * nx + nx, lv->cell, coherent);
}

/* a where c != 0, else b, by bit masks: a conditional expression lets
** the compiler move the work of one side into a branch, and a loop with
** branches is not vectorised. */
INLINE float sel(unsigned c, float a, float b) {
  uint32_t ua, ub, m = 0u - (uint32_t)(c != 0), r;
  memcpy(&ua, &a, sizeof ua);
  memcpy(&ub, &b, sizeof ub);
  r = (ua & m) | (ub & ~m);
  float f;
  memcpy(&f, &r, sizeof f);
  return f;
}

/* The bits of a float >= 0 (or NaN), ordered as the values. */
INLINE uint32_t fbits(float d) {
  uint32_t u;
  memcpy(&u, &d, sizeof u);
  return u;
}

/* The update of one sample from its neighbours w, e, s, n. */
INLINE float update(int guided, float w, float e, float s, float n, uint8_t f,
                    float t, float c, float chom) {
  float L = 0.25f * ((w + e) + (s + n));
  if (!guided) return L;
  float fx = sel(f & DF_SX, e, w), fy = sel(f & DF_SY, n, s);
  float g = 0.5f * L + t * fx + (0.5f - t) * fy + chom * c;
  return sel(f & DF_GACT, g, L);
}

enum { R_JACOBI, R_RED, R_BLACK, R_RESIDUAL };

/* One row j from its rows below (xs), itself (xr) and above (xn) into
** yr: mode R_JACOBI writes every sample, R_RED / R_BLACK the samples of
** that colour (yr == xr), R_RESIDUAL the update v - x (0 where fixed).
** Returns the largest |v - x| over the free samples written (with
** want_big; else 0). */
INLINE float row3(int guided, int mode, int has_rhs, int want_big,
                  const oc_dlevel *lv, uint8_t fix, float keep, float chom,
                  const float *xs, const float *xr, const float *xn, float *yr,
                  const float *rhs, int j) {
  size_t nx = (size_t)lv->nx, r0 = (size_t)j * nx;
  const uint8_t *fl = lv->flags + r0;
  const float *t = guided ? lv->map[MAP_GX] + r0 : NULL;
  const float *c = guided ? lv->map[MAP_GY] + r0 : NULL;
  const float *b = has_rhs ? rhs + r0 : NULL;
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
    float v = update(guided, xr[iw], xr[ie], xs[i], xn[i], fl[i],
                     guided ? t[i] : 0, guided ? c[i] : 0, chom);
    if (has_rhs) v += b[i];
    int fixed = (fl[i] & fix) != 0;
    float d = fixed || !want_big ? 0 : fabsf(v - xv);
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
    size_t i0 = 2 - (((size_t)j + (size_t)want) & 1);
    size_t nk = last > i0 ? (last - i0 + 1) / 2 : 0;
    uint32_t bb = fbits(big);
    /* (the iterations are independent: each writes its own sample and
    ** reads only samples of the other colour besides it) */
#pragma omp simd reduction(max : bb)
    for (size_t q = 0; q < nk; q++) {
      size_t i = i0 + 2 * q;
      float xv = xr[i];
      float v = update(guided, xr[i - 1], xr[i + 1], xs[i], xn[i], fl[i],
                       guided ? t[i] : 0, guided ? c[i] : 0, chom);
      if (has_rhs) v += b[i];
      unsigned fixed = fl[i] & fix;
      yr[i] = sel(fixed, keep * xv, v);
      if (want_big) {
        uint32_t d = fbits(sel(fixed, 0, fabsf(v - xv)));
        bb = d > bb ? d : bb;
      }
    }
    memcpy(&big, &bb, sizeof big);
    return big;
  }
  uint32_t bigb = fbits(big);
#pragma omp simd reduction(max : bigb)
  for (size_t i = 1; i < last; i++) {
    float xv = xr[i];
    float v = update(guided, xr[i - 1], xr[i + 1], xs[i], xn[i], fl[i],
                     guided ? t[i] : 0, guided ? c[i] : 0, chom);
    if (has_rhs) v += b[i];
    unsigned fixed = fl[i] & fix;
    yr[i] =
        mode == R_RESIDUAL ? sel(fixed, 0, v - xv) : sel(fixed, keep * xv, v);
    if (want_big) {
      uint32_t d = fbits(sel(fixed, 0, fabsf(v - xv)));
      bigb = d > bigb ? d : bigb;
    }
  }
  memcpy(&big, &bigb, sizeof big);
  return big;
}

INLINE float row(int guided, int mode, int has_rhs, const oc_dlevel *lv,
                 uint8_t fix, float keep, float chom, const float *x, float *y,
                 const float *rhs, int j) {
  size_t nx = (size_t)lv->nx, r0 = (size_t)j * nx;
  const float *xr = x + r0, *xs = j > 0 ? xr - nx : xr,
              *xn = j + 1 < lv->ny ? xr + nx : xr;
  return row3(guided, mode, has_rhs, 1, lv, fix, keep, chom, xs, xr, xn, y + r0,
              rhs, j);
}

/* One out-of-line kernel (cloned per instruction set) for each
** combination of kind, mode and right-hand side, with them constant so
** that the unused branches drop and the row vectorises. */
#define ROWFN(G, M, B)                                                         \
  static CLONES float row_##G##M##B(const oc_dlevel *lv, uint8_t fix,          \
                                    float keep, float chom, const float *x,    \
                                    float *y, const float *rhs, int j) {       \
    return row(G, M, B, lv, fix, keep, chom, x, y, rhs, j);                    \
  }
ROWFN(0, R_JACOBI, 0)
ROWFN(0, R_JACOBI, 1)
ROWFN(0, R_RED, 0)
ROWFN(0, R_RED, 1)
ROWFN(0, R_BLACK, 0)
ROWFN(0, R_BLACK, 1)
ROWFN(0, R_RESIDUAL, 0)
ROWFN(0, R_RESIDUAL, 1)
ROWFN(1, R_JACOBI, 0)
ROWFN(1, R_JACOBI, 1)
ROWFN(1, R_RED, 0)
ROWFN(1, R_RED, 1)
ROWFN(1, R_BLACK, 0)
ROWFN(1, R_BLACK, 1)
ROWFN(1, R_RESIDUAL, 0)
ROWFN(1, R_RESIDUAL, 1)

/* The rows of one relaxation, each by its kernel. */
// clang-format off
#define SWEEP(G, M, B)                                                         \
  _Pragma("omp parallel for schedule(static) reduction(max:big) if(par)")      \
  for (int j = 0; j < ny; j++) {                                               \
    float b = row_##G##M##B(lv, fix, keep, chom, x, y, rhs, j);                \
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

/* n Jacobi sweeps of rows [j0, j1) fused, in place in x: stage s (sweep
** s) of row j is computed as soon as stage s - 1 has rows j - 1 .. j + 1,
** each intermediate stage keeping 3 rows in ring (3 nx floats a stage);
** the stages reach n - s rows beyond the block (recomputed by the
** neighbouring block: the same values), the last writes row j of x once
** stage 1 no longer reads it (n >= 2). Stage 1 reads the rows of the
** neighbouring blocks, which they overwrite meanwhile, from copies made
** before: lo holds rows [j0 - n, j0 + n), hi rows [j1 - n, j1 + n) (NULL
** at the grid's ends). Every value comes from the same inputs by the
** same arithmetic as in n separate sweeps. */
INLINE float fused_block(int guided, const oc_dlevel *lv, uint8_t fix, float *x,
                         const float *lo, const float *hi, int n, float *ring,
                         int j0, int j1) {
  int ny = lv->ny;
  size_t nx = (size_t)lv->nx;
  float big = 0;
  for (int t = j0 - (n - 1); t < j1 + n - 1; t++)
    for (int s = 1; s <= n; s++) {
      int j = t - (s - 1), reach = n - s;
      int jlo = j0 - reach < 0 ? 0 : j0 - reach;
      int jhi = j1 + reach > ny ? ny : j1 + reach;
      if (j < jlo || j >= jhi) continue;
      int js = j > 0 ? j - 1 : 0, jn = j + 1 < ny ? j + 1 : ny - 1;
      const float *xs, *xr, *xn;
      if (s == 1) {
        const float *src[3];
        int rows[3] = {js, j, jn};
        for (int q = 0; q < 3; q++) {
          int r = rows[q];
          src[q] = r < j0    ? lo + (size_t)(r - (j0 - n)) * nx
                   : r >= j1 ? hi + (size_t)(r - (j1 - n)) * nx
                             : x + (size_t)r * nx;
        }
        xs = src[0], xr = src[1], xn = src[2];
      } else {
        float *rg = ring + (size_t)(s - 2) * 3 * nx;
        xs = rg + (size_t)(js % 3) * nx, xr = rg + (size_t)(j % 3) * nx,
        xn = rg + (size_t)(jn % 3) * nx;
      }
      if (s == n) {
        float b = row3(guided, R_JACOBI, 0, 1, lv, fix, 1, 1, xs, xr, xn,
                       x + (size_t)j * nx, NULL, j);
        big = b > big ? b : big;
      } else {
        row3(guided, R_JACOBI, 0, 0, lv, fix, 1, 1, xs, xr, xn,
             ring + ((size_t)(s - 1) * 3 + (size_t)(j % 3)) * nx, NULL, j);
      }
    }
  return big;
}

static CLONES float fused_laplace(const oc_dlevel *lv, uint8_t fix, float *x,
                                  const float *lo, const float *hi, int n,
                                  float *ring, int j0, int j1) {
  return fused_block(0, lv, fix, x, lo, hi, n, ring, j0, j1);
}

static CLONES float fused_guided(const oc_dlevel *lv, uint8_t fix, float *x,
                                 const float *lo, const float *hi, int n,
                                 float *ring, int j0, int j1) {
  return fused_block(1, lv, fix, x, lo, hi, n, ring, j0, j1);
}

#define FUSED_BLOCK 64
#define FUSED_MAX 32 /* <= FUSED_BLOCK: halos from the next block only */

double oc_djacobi_n(const oc_dop *op, const oc_dlevel *lv, float *x, float *scr,
                    int n) {
  size_t nx = (size_t)lv->nx, ns = nx * (size_t)lv->ny;
  int ny = lv->ny, threads = omp_get_max_threads();
  int nb = (ny + FUSED_BLOCK - 1) / FUSED_BLOCK;
  float *ring = NULL;
  /* fused from two blocks and a quarter million updates on: the work of
  ** the coarser levels' many sweeps is worth a parallel region too */
  if (n > 1 && n <= FUSED_MAX && nb > 1 && ns * (size_t)n >= 262144 && !op->hom)
    ring = malloc(((size_t)threads * (size_t)(n - 1) * 3 +
                   (size_t)(nb - 1) * 2 * (size_t)n) *
                  nx * sizeof *ring);
  if (!ring) { /* separate sweeps */
    double big = 0;
    for (int it = 0; it < n; it++)
      big = (it & 1) ? oc_djacobi(op, lv, scr, x, NULL)
                     : oc_djacobi(op, lv, x, scr, NULL);
    if (n & 1) memcpy(x, scr, ns * sizeof *x);
    return big;
  }
  /* the halos: rows [e - n, e + n) at each boundary e between blocks */
  float *halo = ring + (size_t)threads * (size_t)(n - 1) * 3 * nx;
  size_t hrows = 2 * (size_t)n;
  uint8_t fix = op->kind == DK_LAPLACE ? op->mask : DF_H;
  int guided = op->kind == DK_GUIDED;
  float big = 0;
#pragma omp parallel reduction(max : big)
  {
#pragma omp for schedule(static)
    for (int b = 0; b < nb - 1; b++) {
      int e = (b + 1) * FUSED_BLOCK, r1 = e + n < ny ? e + n : ny;
      memcpy(halo + (size_t)b * hrows * nx, x + (size_t)(e - n) * nx,
             (size_t)(r1 - (e - n)) * nx * sizeof *x);
    }
    float *rg = ring + (size_t)omp_get_thread_num() * (size_t)(n - 1) * 3 * nx;
#pragma omp for schedule(static)
    for (int b = 0; b < nb; b++) {
      int j0 = b * FUSED_BLOCK,
          j1 = j0 + FUSED_BLOCK < ny ? j0 + FUSED_BLOCK : ny;
      const float *lo = b ? halo + (size_t)(b - 1) * hrows * nx : NULL;
      const float *hi = b + 1 < nb ? halo + (size_t)b * hrows * nx : NULL;
      float m = guided ? fused_guided(lv, fix, x, lo, hi, n, rg, j0, j1)
                       : fused_laplace(lv, fix, x, lo, hi, n, rg, j0, j1);
      big = m > big ? m : big;
    }
  }
  free(ring);
  return big;
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

/* The interior of fine row fr (samples 1 .. 2 nI) from coarse rows ca,
** cb blended by uy, wy: fine 2I + 1 and 2I + 2 lie between coarse I and
** I + 1 (weights 1/4 and 3/4 of I + 1); unchanged where fixed. */
INLINE void prolong_inner(int add, float *fr, const uint8_t *fl, uint8_t fix,
                          const float *ca, const float *cb, float uy, float wy,
                          int nI) {
#pragma omp simd
  for (int I = 0; I < nI; I++) {
    float va = uy * ca[I] + wy * cb[I], vb = uy * ca[I + 1] + wy * cb[I + 1];
    float v1 = 0.75f * va + 0.25f * vb, v2 = 0.25f * va + 0.75f * vb;
    int i = 2 * I + 1;
    float o1 = add ? fr[i] + v1 : v1, o2 = add ? fr[i + 1] + v2 : v2;
    fr[i] = sel(fl[i] & fix, fr[i], o1);
    fr[i + 1] = sel(fl[i + 1] & fix, fr[i + 1], o2);
  }
}

static CLONES void prolong_set(float *fr, const uint8_t *fl, uint8_t fix,
                               const float *ca, const float *cb, float uy,
                               float wy, int nI) {
  prolong_inner(0, fr, fl, fix, ca, cb, uy, wy, nI);
}

static CLONES void prolong_add(float *fr, const uint8_t *fl, uint8_t fix,
                               const float *ca, const float *cb, float uy,
                               float wy, int nI) {
  prolong_inner(1, fr, fl, fix, ca, cb, uy, wy, nI);
}

/* Fine sample i of a row from the y-blended coarse values at a, b. */
INLINE void put_fine(float *fr, const uint8_t *fl, uint8_t fix, int add, int i,
                     float v) {
  float o = add ? fr[i] + v : v;
  fr[i] = (fl[i] & fix) ? fr[i] : o;
}

void oc_dprolong(const oc_dop *op, const oc_dlevel *lc, const float *c,
                 const oc_dlevel *lf, float *f, int add) {
  uint8_t fix = op->kind == DK_LAPLACE ? op->mask : DF_H;
  int ncx = lc->nx, nfx = lf->nx;
  /* the interior pairs: coarse I + 1 < ncx and fine 2 I + 2 < nfx */
  int nI = ncx - 1 < (nfx - 1) / 2 ? ncx - 1 : (nfx - 1) / 2;
#pragma omp parallel for schedule(static) if (OC_DPAR(lf))
  for (int j = 0; j < lf->ny; j++) {
    int ja, jb;
    float wy;
    oc_dsplit(j, lc->ny, &ja, &jb, &wy);
    const float *ca = c + (size_t)ja * (size_t)ncx,
                *cb = c + (size_t)jb * (size_t)ncx;
    float *fr = f + (size_t)j * (size_t)nfx;
    const uint8_t *fl = lf->flags + (size_t)j * (size_t)nfx;
    float uy = 1 - wy;
    if (add)
      prolong_add(fr, fl, fix, ca, cb, uy, wy, nI);
    else
      prolong_set(fr, fl, fix, ca, cb, uy, wy, nI);
    /* fine 0 and the last ones, clamped */
    for (int i = 0; i < nfx; i = i ? i + 1 : 2 * nI + 1) {
      int ia, ib;
      float wx;
      oc_dsplit(i, ncx, &ia, &ib, &wx);
      float va = uy * ca[ia] + wy * cb[ia], vb = uy * ca[ib] + wy * cb[ib];
      put_fine(fr, fl, fix, add, i, (1 - wx) * va + wx * vb);
    }
  }
}
