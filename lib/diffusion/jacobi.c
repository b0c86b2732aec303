/*
** jacobi.c — one Jacobi relaxation of a level and the bilinear
** prolongation between levels (Hnaidi et al. 2010, section 5.2):
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
**   paper            F_G = nx^2 F(i - sx, j) + ny^2 F(i, j - sy) - G
**
** The upwind form holds every plane of slope g along n exactly; the
** printed one makes 45-degree slopes sqrt 2 too steep (the two
** neighbours each differ by g cell / sqrt 2, weighted 1/2 each).
** Neumann border: a missing neighbour is the sample itself.
**
** A sweep reads x and writes y, so rows run in parallel in any order and
** the result does not depend on the thread count; the largest update is
** a max, exact in any order.
*/
#include <math.h>

#include "diffusion/diffusion.h"

static inline float at(const float *x, const oc_dlevel *lv, int i, int j) {
  i = i < 0 ? 0 : i >= lv->nx ? lv->nx - 1 : i;
  j = j < 0 ? 0 : j >= lv->ny ? lv->ny - 1 : j;
  return x[(size_t)j * (size_t)lv->nx + (size_t)i];
}

static double sweep_row(const oc_dop *op, const oc_dlevel *lv, const float *x,
                        float *y, const float *rhs, double w, int j) {
  const float *gx = lv->map[MAP_GX], *gy = lv->map[MAP_GY],
              *gd = lv->map[MAP_GD];
  size_t nx = (size_t)lv->nx, row = (size_t)j * nx;
  /* the rows around, the row itself at the border (Neumann) */
  const float *xr = x + row, *xs = j > 0 ? xr - nx : xr,
              *xn = j + 1 < lv->ny ? xr + nx : xr;
  int guided = op->kind == DK_GUIDED;
  double big = 0;
  for (size_t i = 0; i < nx; i++) {
    size_t k = row + i;
    uint8_t fl = lv->flags[k];
    if (oc_dfixed(op, lv, k)) {
      y[k] = op->hom ? 0 : x[k];
      continue;
    }
    size_t iw = i > 0 ? i - 1 : 0, ie = i + 1 < nx ? i + 1 : i;
    double L = 0.25 * ((double)xr[iw] + xr[ie] + xs[i] + xn[i]);
    double v = L;
    if (guided && (fl & DF_GUIDE)) {
      double nxv = gx[k], nyv = gy[k], ax = fabs(nxv), ay = fabs(nyv);
      if (ax + ay > 1e-6) {
        /* the upwind neighbours: i - sx and j - sy */
        double fx = nxv >= 0 ? xr[iw] : xr[ie];
        double fy = nyv >= 0 ? xs[i] : xn[i];
        double G = op->hom ? 0 : gd[k] * lv->cell, F;
        if (op->paper)
          F = (nxv * nxv * fx + nyv * nyv * fy) / (nxv * nxv + nyv * nyv) - G;
        else
          F = (ax * fx + ay * fy - G) / (ax + ay);
        v = 0.5 * L + 0.5 * F;
      }
    }
    if (rhs) v += rhs[k];
    if (w != 1) v = x[k] + w * (v - x[k]);
    y[k] = (float)v;
    double d = fabs(v - x[k]);
    if (d > big) big = d;
  }
  return big;
}

double oc_djacobi(const oc_dop *op, const oc_dlevel *lv, const float *x,
                  float *y, const float *rhs, double w) {
  double big = 0;
#pragma omp parallel for schedule(static) reduction(max : big) if (OC_DPAR(lv))
  for (int j = 0; j < lv->ny; j++) {
    double b = sweep_row(op, lv, x, y, rhs, w, j);
    if (b > big) big = b;
  }
  return big;
}

/* Fine index i in coarse coordinates: (i - 1/2) / 2; the two coarse
** samples around it and the weight of the second. */
static inline void split(int i, int nc, int *a, int *b, double *w) {
  double xc = 0.5 * i - 0.25;
  int a0 = (int)floor(xc);
  *w = xc - a0;
  *a = a0 < 0 ? 0 : a0 >= nc ? nc - 1 : a0;
  *b = a0 + 1 < 0 ? 0 : a0 + 1 >= nc ? nc - 1 : a0 + 1;
}

void oc_dprolong(const oc_dop *op, const oc_dlevel *lc, const float *c,
                 const oc_dlevel *lf, float *f, int add) {
#pragma omp parallel for schedule(static) if (OC_DPAR(lf))
  for (int j = 0; j < lf->ny; j++) {
    int ja, jb;
    double wy;
    split(j, lc->ny, &ja, &jb, &wy);
    for (int i = 0; i < lf->nx; i++) {
      size_t k = (size_t)j * (size_t)lf->nx + (size_t)i;
      if (oc_dfixed(op, lf, k)) continue;
      int ia, ib;
      double wx;
      split(i, lc->nx, &ia, &ib, &wx);
      double v0 = (1 - wx) * at(c, lc, ia, ja) + wx * at(c, lc, ib, ja);
      double v1 = (1 - wx) * at(c, lc, ia, jb) + wx * at(c, lc, ib, jb);
      double v = (1 - wy) * v0 + wy * v1;
      f[k] = (float)(add ? f[k] + v : v);
    }
  }
}
