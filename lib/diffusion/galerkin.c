/*
** galerkin.c — the coarse operators of the converged mode's V-cycles
** (solve.c): A_{k+1} = R A_k P (Galerkin), R the sum over the 2 x 2
** children, P a prolongation that is 0 on the constrained samples (as
** the V-cycle's prolongation leaves them). Level 0's operator is the
** relaxation's A = I - M of the correction equation (jacobi.c), so each
** coarse stencil holds what the finer one does: a coarse sample with one
** constrained child, the upwind gradient terms of slope bands and
** conflicts beside the Laplace ones, each at its own scale. (The
** rediscretised coarse levels of the cascade, "constrained if any child
** is" with the residual scaled by 4 or 2, represent neither: there the
** elevation's V-cycles stalled at 0.7-0.9 a cycle and the Laplace maps'
** took 6 or 7 cycles.) A coarse sample all of whose children are
** constrained is dead (inverse diagonal 0): its correction stays 0.
**
** - Laplace maps: P bilinear (with R piecewise constant the orders add
**   to 3 > 2, as a second-order operator needs, and the coarse stencils
**   stay 3 x 3). Smoothing: 4-colour Gauss-Seidel, the colour of (i, j)
**   (i mod 2, j mod 2), so that no two samples of a colour share a
**   stencil.
** - The elevation: with bilinear P the upwind terms' coarse stencils
**   lose diagonal dominance (measured: rows 45 times off at 512^2) and
**   Gauss-Seidel diverges, so P is piecewise constant there (the coarse
**   sample's value on its 4 children): the coarse stencils stay 5-point
**   M-matrices, smoothed red-black. Summed over 4 children, that P
**   keeps the first-order upwind term at its scale but doubles the
**   Laplace part's couplings (2 fine edges per coarse edge), so each
**   level keeps its Laplace part apart and the coarse one takes half
**   of it: the elevation's remaining error took 19 V-cycles to the
**   tolerance on the benchmark canyon without the half, 12 with it.
**
** Either way the V-cycle prolongs the corrections bilinearly. Every
** coefficient is computed from its own children, every sweep colour by
** colour, so the result is the same for any thread count.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

/* The plane of offset (di, dj) in {-1, 0, 1}^2; GQ_C the diagonal. */
#define GQ(di, dj) (((dj) + 1) * 3 + (di) + 1)
#define GQ_C 4
#define GQ_INV 9 /* 1 / diagonal, 0 where dead */

/* The row of level 0's correction operator A = I - M at free sample
** (i, j), in two parts (GQ order; 0 for a missing or constrained
** neighbour: Neumann folds the missing one into the diagonal): aL the
** Laplace part (weight alpha), aG the upwind gradient part (beta; 0 on
** the samples the gradient does not guide). */
static void row0(const oc_dop *op, const oc_dlevel *lv, uint8_t fix, int i,
                 int j, double aL[9], double aG[9]) {
  size_t nx = (size_t)lv->nx, k = (size_t)j * nx + (size_t)i;
  uint8_t f = lv->flags[k];
  double wl = 0.25, wg[4] = {0, 0, 0, 0}; /* W, E, S, N weights of M */
  double dl = 1, dg = 0;
  if (oc_dguided(op, lv, k)) {
    double t = lv->map[MAP_GX][k];
    wl = 0.125, dl = 0.5, dg = 0.5;
    wg[(f & DF_SX) ? 1 : 0] += t;
    wg[(f & DF_SY) ? 3 : 2] += 0.5 - t;
  }
  static const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
  memset(aL, 0, 9 * sizeof *aL);
  memset(aG, 0, 9 * sizeof *aG);
  for (int q = 0; q < 4; q++) {
    int ii = i + di[q], jj = j + dj[q];
    if (ii < 0 || jj < 0 || ii >= lv->nx || jj >= lv->ny) {
      dl -= wl, dg -= wg[q]; /* Neumann: the sample itself */
      continue;
    }
    if (lv->flags[(size_t)jj * nx + (size_t)ii] & fix) continue; /* 0 */
    aL[GQ(di[q], dj[q])] = -wl;
    aG[GQ(di[q], dj[q])] = -wg[q];
  }
  aL[GQ_C] = dl;
  aG[GQ_C] = dg;
}

/* The planes of the Laplace part kept for the next level's build (five
** point stencils): W, E, S, N, centre. */
static const int LQ[5] = {GQ(-1, 0), GQ(1, 0), GQ(0, -1), GQ(0, 1), GQ_C};

/* The bilinear weights (oc_dsplit) of fine index g (of a level whose
** coarse one has nc samples) on the coarse samples C - 1, C, C + 1 into
** w[3], C the parent of a child next to g. */
static inline void weights(int g, int nc, int C, double w[3]) {
  /* away from the ends, by g - (2 C - 1) in 0 .. 3 */
  static const double tab[4][3] = {
      {0.75, 0.25, 0}, {0.25, 0.75, 0}, {0, 0.75, 0.25}, {0, 0.25, 0.75}};
  if (C > 0 && C < nc - 1) {
    memcpy(w, tab[g - 2 * C + 1], 3 * sizeof *w);
    return;
  }
  w[0] = w[1] = w[2] = 0;
  int a, b;
  float wb;
  oc_dsplit(g, nc, &a, &b, &wb);
  w[a - C + 1] += 1 - (double)wb;
  w[b - C + 1] += (double)wb;
}

/* The slots s[2] (ascending) and weights w2[2] of the nonzero weights
** of w[3] (a second weight 0 on the first slot when there is one). */
static inline void nonzero(const double w[3], int s[2], double w2[2]) {
  int n = 0;
  s[0] = s[1] = 0, w2[0] = w2[1] = 0;
  for (int q = 0; q < 3 && n < 2; q++)
    if (w[q] != 0) s[n] = q, w2[n] = w[q], n++;
  if (n == 1) s[1] = s[0];
}

/* The stencil of coarse sample (I, J) of a level of ncx ncy samples
** (nsc in all) into the planes gc, from the finer level: level 0 (lv0)
** when ga is NULL, else the Galerkin planes ga of nfx nfy samples. */
static void build_one(int aggregate, double half, const oc_dop *op,
                      const oc_dlevel *lv0, uint8_t fix, const float *ga,
                      const uint8_t *gdead, const float *gl, int nfx, int nfy,
                      float *gc, float *lc, int ncx, int ncy, size_t nsc, int I,
                      int J) {
  double acc[9] = {0}, accl[9] = {0};
  /* the weights of the fine indices 2 I - 1 .. 2 I + 2 (2 J - 1 ..) */
  /* as the slots and weights of their (at most 2) nonzero weights */
  int sx[4][2] = {{0}}, sy[4][2] = {{0}};
  double wxs[4][2] = {{0}}, wys[4][2] = {{0}};
  if (!aggregate)
    for (int q = 0; q < 4; q++) {
      double w[3];
      if (2 * I - 1 + q >= 0 && 2 * I - 1 + q < nfx) {
        weights(2 * I - 1 + q, ncx, I, w);
        nonzero(w, sx[q], wxs[q]);
      }
      if (2 * J - 1 + q >= 0 && 2 * J - 1 + q < nfy) {
        weights(2 * J - 1 + q, ncy, J, w);
        nonzero(w, sy[q], wys[q]);
      }
    }
  int alive = 0;
  size_t nsf = (size_t)nfx * (size_t)nfy;
  for (int b = 0; b < 2; b++)
    for (int a = 0; a < 2; a++) {
      int i = 2 * I + a, j = 2 * J + b;
      if (i >= nfx || j >= nfy) continue;
      size_t k = (size_t)j * (size_t)nfx + (size_t)i;
      double row[9], rl[9] = {0};
      if (ga) {
        if (gdead[k]) continue;
        for (int q = 0; q < 9; q++)
          row[q] = ga[(size_t)q * nsf + k];
        if (gl)
          for (int q = 0; q < 5; q++)
            rl[LQ[q]] = gl[(size_t)q * nsf + k];
      } else {
        if (lv0->flags[k] & fix) continue;
        row0(op, lv0, fix, i, j, rl, row);
        for (int q = 0; q < 9; q++)
          row[q] += rl[q];
      }
      alive = 1;
      for (int dj = -1; dj <= 1; dj++) {
        int gj = j + dj;
        const double *wy = wys[gj - 2 * J + 1];
        const int *ky = sy[gj - 2 * J + 1];
        for (int di = -1; di <= 1; di++) {
          double v = row[GQ(di, dj)], vl = rl[GQ(di, dj)];
          if (v == 0 && vl == 0) continue;
          int gi = i + di;
          if (gdead && gdead[(size_t)gj * (size_t)nfx + (size_t)gi])
            continue;      /* dead: its correction is 0 */
          if (aggregate) { /* one coarse sample: g's parent */
            int q = (gj / 2 - J + 1) * 3 + (gi / 2 - I + 1);
            acc[q] += v, accl[q] += vl;
            continue;
          }
          const double *wx = wxs[gi - 2 * I + 1];
          const int *kx = sx[gi - 2 * I + 1];
          for (int y = 0; y < 2; y++)
            for (int x = 0; x < 2; x++)
              acc[ky[y] * 3 + kx[x]] += v * wy[y] * wx[x];
        }
      }
    }
  size_t kc = (size_t)J * (size_t)ncx + (size_t)I;
  /* the whole row: its Laplace part scaled by half */
  for (int q = 0; q < 9; q++)
    acc[q] = alive ? acc[q] - (1 - half) * accl[q] : 0;
  for (int q = 0; q < 9; q++)
    gc[(size_t)q * nsc + kc] = (float)acc[q];
  if (lc)
    for (int q = 0; q < 5; q++)
      lc[(size_t)q * nsc + kc] = alive ? (float)(half * accl[LQ[q]]) : 0;
  gc[GQ_INV * nsc + kc] =
      alive && acc[GQ_C] > 0 ? (float)(1 / (double)(float)acc[GQ_C]) : 0;
}

int oc_dgalerkin_build(oc_dgalerkin *g, const oc_dpyramid *py, const oc_dop *op,
                       oc_error *err) {
  int L = py->nlevels;
  size_t total = 0, samples = 0;
  /* the elevation: piecewise constant P, its Laplace part kept apart (5
  ** planes a level) and halved, 5-point stencils */
  int aggregate = op->kind == DK_GUIDED;
  for (int k = 1; k < L; k++) {
    size_t ns = (size_t)py->lv[k].nx * (size_t)py->lv[k].ny;
    total += ns * (GQ_PLANES + (aggregate ? 5 : 0));
    samples += ns;
  }
  /* (a block of an earlier build is used again when large enough) */
  if (g->cap < total + samples) {
    oc_dgalerkin_free(g);
    g->block = malloc((total + samples) * sizeof(float));
    if (!g->block) return oc_seterr(err, OC_ENOMEM, "out of memory");
    g->cap = total + samples;
  }
  g->nlevels = L;
  uint8_t fix = op->kind == DK_LAPLACE ? op->mask : DF_H;
  float *at = g->block;
  uint8_t *dead = (uint8_t *)(g->block + total);
  g->five = aggregate;
  double half = aggregate ? 0.5 : 1;
  float *prevl = NULL;
  for (int k = 1; k < L; k++) {
    const oc_dlevel *f = &py->lv[k - 1], *c = &py->lv[k];
    size_t nsc = (size_t)c->nx * (size_t)c->ny;
    g->a[k] = at;
    const float *ga = k > 1 ? g->a[k - 1] : NULL, *gl = k > 1 ? prevl : NULL;
    float *lc = aggregate ? at + nsc * GQ_PLANES : NULL;
    int ncx = c->nx, ncy = c->ny;
#pragma omp parallel for schedule(static) if (OC_DPAR(c))
    for (int J = 0; J < ncy; J++)
      for (int I = 0; I < ncx; I++)
        build_one(aggregate, half, op, &py->lv[0], fix, ga,
                  k > 1 ? g->dead[k - 1] : NULL, gl, f->nx, f->ny, at, lc, ncx,
                  ncy, nsc, I, J);
    g->dead[k] = dead;
    const float *inv = at + GQ_INV * nsc;
    for (size_t q = 0; q < nsc; q++)
      dead[q] = inv[q] == 0;
    dead += nsc;
    prevl = lc;
    at += nsc * (GQ_PLANES + (aggregate ? 5 : 0));
  }
  return OC_OK;
}

void oc_dgalerkin_free(oc_dgalerkin *g) {
  free(g->block);
  memset(g, 0, sizeof *g);
}

#define INLINE static inline __attribute__((always_inline))

/* b - (A x without the diagonal) at sample i of row r (k = r + i), its
** neighbours' columns iw, ie; five: the stencil has no corners. */
INLINE float offsum(int five, const float *a, size_t ns, size_t k,
                    const float *xs, const float *xr, const float *xn,
                    const float *b, int i, int iw, int ie) {
  float s = b[k];
  if (!five)
    s -= a[GQ(-1, -1) * ns + k] * xs[iw] + a[GQ(1, -1) * ns + k] * xs[ie] +
         a[GQ(-1, 1) * ns + k] * xn[iw] + a[GQ(1, 1) * ns + k] * xn[ie];
  s -= a[GQ(0, -1) * ns + k] * xs[i] + a[GQ(-1, 0) * ns + k] * xr[iw] +
       a[GQ(1, 0) * ns + k] * xr[ie] + a[GQ(0, 1) * ns + k] * xn[i];
  return s;
}

/* The samples i0, i0 + 2, ... of row j relaxed in place: they read only
** samples of other colours, so the iterations are independent. */
INLINE void gs_row(int five, const float *a, size_t ns, int nx, int ny,
                   float *x, const float *b, int i0, int j) {
  size_t r = (size_t)j * (size_t)nx;
  const float *xs = j > 0 ? x + r - nx : x + r, *xr = x + r,
              *xn = j + 1 < ny ? x + r + nx : x + r;
  const float *inv = a + GQ_INV * ns;
  if (i0 == 0) { /* the west border */
    int ie = nx > 1 ? 1 : 0;
    x[r] = offsum(five, a, ns, r, xs, xr, xn, b, 0, 0, ie) * inv[r];
    i0 = 2;
  }
  int nk = i0 < nx - 1 ? (nx - 1 - i0 + 1) / 2 : 0; /* i <= nx - 2 */
#pragma omp simd
  for (int q = 0; q < nk; q++) {
    int i = i0 + 2 * q;
    size_t k = r + (size_t)i;
    x[k] = offsum(five, a, ns, k, xs, xr, xn, b, i, i - 1, i + 1) * inv[k];
  }
  int last = nx - 1;
  if (last > 0 && ((last - i0) & 1) == 0 && last >= i0) { /* the east */
    size_t k = r + (size_t)last;
    x[k] = offsum(five, a, ns, k, xs, xr, xn, b, last, last - 1, last) * inv[k];
  }
}

static void gs_rows(int five, const float *a, size_t ns, int nx, int ny,
                    float *x, const float *b, int colour, int par) {
  if (five) { /* red-black: colour (i + j) & 1 */
#pragma omp parallel for schedule(static) if (par)
    for (int j = 0; j < ny; j++)
      gs_row(1, a, ns, nx, ny, x, b, (colour + j) & 1, j);
  } else { /* colour (i & 1) + 2 (j & 1) */
#pragma omp parallel for schedule(static) if (par)
    for (int j = colour >> 1; j < ny; j += 2)
      gs_row(0, a, ns, nx, ny, x, b, colour & 1, j);
  }
}

void oc_dgalerkin_smooth(const oc_dgalerkin *g, const oc_dlevel *lv, int k,
                         float *x, const float *b, int n) {
  const float *a = g->a[k];
  int nx = lv->nx, ny = lv->ny, par = OC_DPAR(lv) != 0;
  size_t ns = (size_t)nx * (size_t)ny;
  for (int it = 0; it < n; it++)
    for (int c = 0; c < (g->five ? 2 : 4); c++)
      gs_rows(g->five, a, ns, nx, ny, x, b, c, par);
}

/* r = b - A x on row j (0 where dead). */
INLINE void res_row(int five, const float *a, size_t ns, int nx, int ny,
                    const float *x, const float *b, float *r, int j) {
  size_t rr = (size_t)j * (size_t)nx;
  const float *xs = j > 0 ? x + rr - nx : x + rr, *xr = x + rr,
              *xn = j + 1 < ny ? x + rr + nx : x + rr;
  const float *ac = a + GQ_C * ns, *inv = a + GQ_INV * ns;
#pragma omp simd
  for (int i = 1; i < nx - 1; i++) {
    size_t q = rr + (size_t)i;
    float s = offsum(five, a, ns, q, xs, xr, xn, b, i, i - 1, i + 1);
    s -= ac[q] * xr[i];
    r[q] = inv[q] != 0 ? s : 0;
  }
  for (int i = 0; i < nx; i = i ? nx : nx - 1) { /* the border columns */
    int iw = i > 0 ? i - 1 : i, ie = i + 1 < nx ? i + 1 : i;
    size_t q = rr + (size_t)i;
    float s = offsum(five, a, ns, q, xs, xr, xn, b, i, iw, ie);
    s -= ac[q] * xr[i];
    r[q] = inv[q] != 0 ? s : 0;
    if (nx == 1) break;
  }
}

void oc_dgalerkin_residual(const oc_dgalerkin *g, const oc_dlevel *lv, int k,
                           const float *x, const float *b, float *r) {
  const float *a = g->a[k];
  int nx = lv->nx, ny = lv->ny, five = g->five;
  size_t ns = (size_t)nx * (size_t)ny;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (int j = 0; j < ny; j++)
    if (five)
      res_row(1, a, ns, nx, ny, x, b, r, j);
    else
      res_row(0, a, ns, nx, ny, x, b, r, j);
}

void oc_dgalerkin_restrict(const oc_dlevel *f, const float *r,
                           const oc_dlevel *c, float *b) {
  size_t nxf = (size_t)f->nx, nxc = (size_t)c->nx;
#pragma omp parallel for schedule(static) if (OC_DPAR(f))
  for (int J = 0; J < c->ny; J++) {
    size_t j0 = 2 * (size_t)J;
    int two = (int)j0 + 1 < f->ny;
    const float *r0 = r + j0 * nxf, *r1 = r0 + nxf;
    float *br = b + (size_t)J * nxc;
    for (size_t I = 0; I < nxc; I++) {
      size_t i0 = 2 * I;
      int cols = i0 + 1 < nxf;
      float s = r0[i0] + (cols ? r0[i0 + 1] : 0);
      if (two) s += r1[i0] + (cols ? r1[i0 + 1] : 0);
      br[I] = s;
    }
  }
}

void oc_dgalerkin_prolong(const oc_dgalerkin *g, int kf, const oc_dlevel *lc,
                          const float *c, const oc_dlevel *lf, float *f) {
  /* the cascade's prolongation, with the dead samples as constrained */
  oc_dlevel d = {lf->nx, lf->ny, lf->cell, {NULL}, g->dead[kf]};
  oc_dop op = {DK_LAPLACE, MAP_H, 1, 0, 1};
  oc_dprolong(&op, lc, c, &d, f, 1);
}
