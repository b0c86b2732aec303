/*
** terrain_mask.c — a terrain's horizontal domain given by a mask grid:
** the distance from each mask node to Omega shrunk by R, by two exact
** Euclidean distance transforms, and its bilinear interpolation.
**
** Omega is the set of nodes where mask >= 0.5 that lie in the source's
** domain and not on the grid's border (so the distance is >= R on the
** border and the field falls to 0 before the grid ends). Omega shrunk by
** R is the set of its nodes at least R from every node outside it. The
** transforms are Felzenszwalb and Huttenlocher's lower envelope of
** parabolas, columns then rows, each line independent (parallel, and the
** same result for any thread count).
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "terrain/terrain.h"

/* Largest node count a range query scans exactly; larger footprints read
** the pyramid, at most 4 x 4 blocks. */
#define RANGE_SCAN 64

/* Squared distance transform of one line: d[q] = min_p (q - p)^2 + f[p]
** over the sites p with finite f. v, z: scratch of n and n + 1. */
static void edt_line(const double *f, int n, double *d, int *v, double *z) {
  int k = -1;
  double s = 0;
  for (int q = 0; q < n; q++) {
    if (f[q] == INFINITY) continue;
    while (k >= 0) {
      int p = v[k];
      s = ((f[q] + (double)q * q) - (f[p] + (double)p * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      k--;
    }
    k++;
    v[k] = q;
    z[k] = k == 0 ? -INFINITY : s;
  }
  if (k < 0) {
    for (int q = 0; q < n; q++)
      d[q] = INFINITY;
    return;
  }
  z[k + 1] = INFINITY;
  int j = 0;
  for (int q = 0; q < n; q++) {
    while (z[j + 1] < q)
      j++;
    double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
  }
}

/* Squared distances (in cells) of every node to the nodes where site[] is
** set, into out (floats). Returns 0, or -1 when out of memory. */
static int edt(const unsigned char *site, int nx, int ny, float *out) {
  int m = nx > ny ? nx : ny, fail = 0;
#pragma omp parallel
  {
    double *f = malloc(2 * (size_t)m * sizeof *f);
    double *zz = malloc(((size_t)m + 1) * sizeof *zz);
    int *v = malloc((size_t)m * sizeof *v);
    if (!f || !zz || !v) {
#pragma omp atomic write
      fail = 1;
    }
#pragma omp for schedule(static)
    for (int i = 0; i < nx; i++) {
      if (!f || !zz || !v) continue;
      for (int j = 0; j < ny; j++)
        f[j] = site[(size_t)j * nx + i] ? 0 : INFINITY;
      edt_line(f, ny, f + m, v, zz);
      for (int j = 0; j < ny; j++)
        out[(size_t)j * nx + i] = (float)f[m + j];
    }
#pragma omp for schedule(static)
    for (int j = 0; j < ny; j++) {
      if (!f || !zz || !v) continue;
      float *row = out + (size_t)j * nx;
      for (int i = 0; i < nx; i++)
        f[i] = row[i];
      edt_line(f, nx, f + m, v, zz);
      for (int i = 0; i < nx; i++)
        row[i] = (float)f[m + i];
    }
    free(f);
    free(zz);
    free(v);
  }
  return fail ? -1 : 0;
}

/* The min/max pyramid of t->dist (levels of 2 x 2 blocks, the last
** block of a row or column possibly narrower). 0, or -1 out of memory. */
static int mask_pyramid(oc_tdata *t) {
  int w = t->mnx, h = t->mny, k = 0;
  size_t total = 0;
  while ((w > 1 || h > 1) && k + 1 < OC_TMASK_LEVELS) {
    w = (w + 1) / 2, h = (h + 1) / 2, k++;
    t->mw[k] = w, t->mh[k] = h, t->moff[k] = total;
    total += 2 * (size_t)w * (size_t)h;
  }
  t->mlev = k;
  t->mpyr = total ? malloc(total * sizeof *t->mpyr) : NULL;
  if (total && !t->mpyr) return -1;
  for (int l = 1; l <= k; l++) {
    float *out = t->mpyr + t->moff[l];
    int pw = l > 1 ? t->mw[l - 1] : t->mnx, ph = l > 1 ? t->mh[l - 1] : t->mny;
    for (int b = 0; b < t->mh[l]; b++)
      for (int a = 0; a < t->mw[l]; a++) {
        float lo = INFINITY, hi = 0;
        for (int q = 0; q < 4; q++) {
          int i = 2 * a + (q & 1), j = 2 * b + (q >> 1);
          if (i >= pw || j >= ph) continue;
          size_t c = (size_t)j * (size_t)pw + (size_t)i;
          float cl = l > 1 ? t->mpyr[t->moff[l - 1] + 2 * c] : t->dist[c];
          float ch = l > 1 ? t->mpyr[t->moff[l - 1] + 2 * c + 1] : t->dist[c];
          lo = cl < lo ? cl : lo;
          hi = ch > hi ? ch : hi;
        }
        size_t o = 2 * ((size_t)b * (size_t)t->mw[l] + (size_t)a);
        out[o] = lo;
        out[o + 1] = hi;
      }
  }
  return 0;
}

int oc_terrain_mask(oc_tdata *t, const oc_heightfield *mask, oc_error *err) {
  int nx = oc_heightfield_nx(mask), ny = oc_heightfield_ny(mask);
  double c = oc_heightfield_cell(mask), x0, y0;
  oc_heightfield_origin(mask, &x0, &y0);
  const float *m = oc_heightfield_samples(mask);
  size_t n = (size_t)nx * (size_t)ny;
  unsigned char *site = malloc(n);
  float *d = malloc(n * sizeof *d);
  if (!site || !d) {
    free(site);
    free(d);
    return oc_seterr(err, OC_ENOMEM, "out of memory for a %d x %d mask", nx,
                     ny);
  }
  /* 1. distance from each node to the nodes outside Omega */
  size_t nin = 0;
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      size_t q = (size_t)j * nx + i;
      double x = x0 + i * c, y = y0 + j * c;
      int in = m[q] >= 0.5f && i > 0 && j > 0 && i < nx - 1 && j < ny - 1 &&
               x >= t->src.x0 && x <= t->src.x1 && y >= t->src.y0 &&
               y <= t->src.y1;
      site[q] = !in;
      nin += (size_t)in;
    }
  int rc = 0;
  if (nin == 0) {
    rc = oc_seterr(err, OC_EINVAL,
                   "'mask' has no sample >= 0.5 inside the heightfield's "
                   "domain (away from the mask's border)");
    goto done;
  }
  if (edt(site, nx, ny, d)) goto nomem;
  /* 2. Omega shrunk by R, then the distance to it */
  double R2 = (t->R / c) * (t->R / c);
  size_t ncore = 0;
  for (size_t q = 0; q < n; q++) {
    site[q] = !site[q] && (double)d[q] >= R2;
    ncore += site[q];
  }
  if (ncore == 0) {
    rc = oc_seterr(err, OC_EINVAL,
                   "'falloff' %g leaves nothing of the mask: no inside "
                   "sample lies that far from its edge",
                   t->R);
    goto done;
  }
  if (edt(site, nx, ny, d)) goto nomem;
  /* 3. metres; the support is where the distance is below R, grown by a
  ** cell for the interpolation */
  int i0 = nx, i1 = -1, j0 = ny, j1 = -1;
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      float *dq = &d[(size_t)j * nx + i];
      *dq = (float)(sqrt((double)*dq) * c);
      if (*dq < t->R) {
        i0 = i < i0 ? i : i0;
        i1 = i > i1 ? i : i1;
        j0 = j < j0 ? j : j0;
        j1 = j > j1 ? j : j1;
      }
    }
  t->sx0 = x0 + (i0 > 0 ? i0 - 1 : 0) * c;
  t->sx1 = x0 + (i1 < nx - 1 ? i1 + 1 : nx - 1) * c;
  t->sy0 = y0 + (j0 > 0 ? j0 - 1 : 0) * c;
  t->sy1 = y0 + (j1 < ny - 1 ? j1 + 1 : ny - 1) * c;
  t->dist = d;
  t->mnx = nx;
  t->mny = ny;
  t->mcell = c;
  t->mx0 = x0;
  t->my0 = y0;
  d = NULL;
  if (mask_pyramid(t)) goto nomem;
  goto done;
nomem:
  rc = oc_seterr(err, OC_ENOMEM, "out of memory for a %d x %d mask", nx, ny);
done:
  free(site);
  free(d);
  return rc;
}

double oc_terrain_mask_dist(const oc_tdata *t, double x, double y,
                            double grad[2]) {
  double u = (x - t->mx0) / t->mcell, v = (y - t->my0) / t->mcell;
  if (!(u >= 0 && v >= 0 && u <= t->mnx - 1 && v <= t->mny - 1)) {
    if (grad) grad[0] = grad[1] = 0;
    return INFINITY;
  }
  int i = (int)u, j = (int)v;
  if (i > t->mnx - 2) i = t->mnx - 2;
  if (j > t->mny - 2) j = t->mny - 2;
  double a = u - i, b = v - j;
  const float *r0 = t->dist + (size_t)j * t->mnx + i, *r1 = r0 + t->mnx;
  double d00 = r0[0], d10 = r0[1], d01 = r1[0], d11 = r1[1];
  double lo = d00 + a * (d10 - d00), hi = d01 + a * (d11 - d01);
  if (grad) {
    grad[0] = ((1 - b) * (d10 - d00) + b * (d11 - d01)) / t->mcell;
    grad[1] = (hi - lo) / t->mcell;
  }
  return lo + b * (hi - lo);
}

void oc_terrain_mask_range(const oc_tdata *t, double x0, double y0, double x1,
                           double y1, double *lo, double *hi) {
  double u0 = (x0 - t->mx0) / t->mcell, u1 = (x1 - t->mx0) / t->mcell;
  double v0 = (y0 - t->my0) / t->mcell, v1 = (y1 - t->my0) / t->mcell;
  *lo = 0;
  *hi = INFINITY;
  /* off the grid the distance is infinite */
  int off = !(u0 >= 0 && v0 >= 0 && u1 <= t->mnx - 1 && v1 <= t->mny - 1);
  u0 = fmax(u0, 0), v0 = fmax(v0, 0);
  u1 = fmin(u1, t->mnx - 1), v1 = fmin(v1, t->mny - 1);
  if (!(u0 <= u1 && v0 <= v1)) { /* wholly off the grid, or NaN */
    if (off) *lo = INFINITY;
    return;
  }
  int i0 = (int)u0, i1 = (int)ceil(u1), j0 = (int)v0, j1 = (int)ceil(v1);
  if (t->mlev >= 1 && (double)(i1 - i0 + 1) * (j1 - j0 + 1) > RANGE_SCAN) {
    /* the coarsest blocks that cover the nodes 4 x 4 at most: a range
    ** over a superset of them */
    int k = 1;
    while (k < t->mlev &&
           ((i1 >> k) - (i0 >> k) >= 4 || (j1 >> k) - (j0 >> k) >= 4))
      k++;
    const float *lv = t->mpyr + t->moff[k];
    double a = INFINITY, b = 0;
    for (int j = j0 >> k; j <= j1 >> k; j++)
      for (int i = i0 >> k; i <= i1 >> k; i++) {
        size_t o = 2 * ((size_t)j * (size_t)t->mw[k] + (size_t)i);
        a = fmin(a, lv[o]);
        b = fmax(b, lv[o + 1]);
      }
    *lo = a;
    *hi = off ? INFINITY : b;
    return;
  }
  double a = INFINITY, b = 0;
  for (int j = j0; j <= j1; j++)
    for (int i = i0; i <= i1; i++) {
      double d = t->dist[(size_t)j * t->mnx + i];
      a = fmin(a, d);
      b = fmax(b, d);
    }
  *lo = a;
  *hi = off ? INFINITY : b;
}
