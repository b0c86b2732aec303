/*
** detail.c — the noise detail of the terrain (Hnaidi et al. 2010,
** section 4.3), driven by the diffused amplitude A and roughness R:
**
**   N(p) = A sum_{k=0..n} r^(-k (1 - R)) S(r^k p / lambda_0),
**
** S the simplex noise of core/noise.c scaled to [-1, 1] (zero mean), each
** octave with its own seed drawn from the stream of the scene seed
** (core/rng.h), lambda_0 a wavelength in metres so that grids of any
** resolution over the same area give the same terrain. R = 1 blends the
** octaves equally, lower R damps the higher ones; with r = 2 and n = 3
** the weights sum to 1.875 at R = 0 and to 4 at R = 1, the bound of
** |N| / A.
**
** On a grid (oc_ddetail_grid) each octave is, as in the paper's section
** 5.3, an interpolated noise: S sampled on a lattice of 8 nodes per
** wavelength, anchored at the world origin (so the same for every grid
** over the same area), and interpolated by Catmull-Rom cubics in x and y
** (measured: within 0.026 of S, 1.5 % of its rms, at 8 nodes per unit).
** An octave whose lattice would be finer than the grid is sampled
** directly; an octave of wavelength below 2 cells is dropped (it would
** only alias).
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/rng.h"
#include "diffusion/diffusion.h"

#define DETAIL_STREAM 0x646966667573ull /* "diffus" */
#define NODES 8                         /* lattice nodes per wavelength */
#define MAX_OCT 16

double oc_ddetail_at(const oc_ddetail *d, double x, double y, double A,
                     double R) {
  if (A == 0) return 0;
  oc_rng st = oc_rng_stream(d->seed, DETAIL_STREAM);
  double q = exp(-(1 - R) * log(d->ratio)), w = 1, f = 1 / d->wavelength;
  double sum = 0;
  for (int k = 0; k < d->octaves; k++) {
    oc_vec3 p = {x * f, y * f, 0};
    double s = 2 * oc_noise3(oc_rng_next(&st), p, NULL) - 1;
    sum += w * s;
    w *= q;
    f *= d->ratio;
  }
  return A * sum;
}

/* Catmull-Rom weights of the 4 nodes around t in [0, 1). */
static void cr_weights(double t, float w[4]) {
  double t2 = t * t, t3 = t2 * t;
  w[0] = (float)(0.5 * (-t3 + 2 * t2 - t));
  w[1] = (float)(0.5 * (3 * t3 - 5 * t2 + 2));
  w[2] = (float)(0.5 * (-3 * t3 + 4 * t2 + t));
  w[3] = (float)(0.5 * (t3 - t2));
}

/* One octave on the grid: a lattice (spacing h metres, first node index
** i0, j0, ni x nj nodes) with the columns' first node and weights, or
** (lat == NULL) direct samples. */
typedef struct octave {
  uint64_t seed;
  double f; /* 1 / wavelength */
  double h;
  long i0, j0;
  size_t ni, nj;
  float *lat;
  int *col;  /* nx: first node of sample i's 4 (relative to i0) */
  float *wx; /* 4 nx */
} octave;

typedef struct grid_noise {
  const oc_ddetail *d;
  int nx, ny, n;
  octave o[MAX_OCT];
  size_t maxni;
} grid_noise;

static void free_noise(grid_noise *g) {
  for (int k = 0; k < g->n; k++) {
    free(g->o[k].lat);
    free(g->o[k].col);
    free(g->o[k].wx);
  }
}

/* The first node index and weights of coordinate x on a lattice of
** spacing h. */
static long node(double x, double h, float w[4]) {
  double u = x / h, fu = floor(u);
  cr_weights(u - fu, w);
  return (long)fu - 1;
}

static int init_noise(grid_noise *g, const oc_ddetail *d, int nx, int ny,
                      oc_error *err) {
  memset(g, 0, sizeof *g);
  g->d = d, g->nx = nx, g->ny = ny;
  oc_rng st = oc_rng_stream(d->seed, DETAIL_STREAM);
  double f = 1 / d->wavelength;
  for (int k = 0; k < d->octaves && k < MAX_OCT; k++, f *= d->ratio) {
    uint64_t seed = oc_rng_next(&st);
    if (1 / f < 2 * d->cell) break; /* below 2 cells: aliasing only */
    octave *o = &g->o[g->n++];
    o->seed = seed, o->f = f, o->h = 1 / (f * NODES);
    double far = fmax(fabs(d->x0), fabs(d->y0)) + (nx + ny) * d->cell;
    if (o->h <= d->cell || !(far / o->h < 0x1p40))
      continue; /* direct samples: cheaper, or node indices too large */
    float w[4];
    o->i0 = node(d->x0, o->h, w);
    o->j0 = node(d->y0, o->h, w);
    o->ni = (size_t)(node(d->x0 + (nx - 1) * d->cell, o->h, w) - o->i0 + 4);
    o->nj = (size_t)(node(d->y0 + (ny - 1) * d->cell, o->h, w) - o->j0 + 4);
    o->lat = malloc(o->ni * o->nj * sizeof *o->lat);
    o->col = malloc((size_t)nx * sizeof *o->col);
    o->wx = malloc(4 * (size_t)nx * sizeof *o->wx);
    if (!o->lat || !o->col || !o->wx) {
      free_noise(g);
      return oc_seterr(err, OC_ENOMEM, "out of memory (noise lattice)");
    }
    if (o->ni > g->maxni) g->maxni = o->ni;
    for (int i = 0; i < nx; i++)
      o->col[i] = (int)(node(d->x0 + i * d->cell, o->h, o->wx + 4 * i) - o->i0);
    size_t ni = o->ni;
    /* (a node costs a simplex evaluation, some hundred instructions:
    ** worth two threads from a few thousand on) */
#pragma omp parallel for schedule(static) if (o->ni * o->nj > 4096)
    for (size_t J = 0; J < o->nj; J++)
      for (size_t I = 0; I < ni; I++) {
        /* node (i0 + I, j0 + J) at S coordinates (i, j) / NODES */
        oc_vec3 p = {(double)(o->i0 + (long)I) / NODES,
                     (double)(o->j0 + (long)J) / NODES, 0};
        o->lat[J * ni + I] = (float)(2 * oc_noise3(o->seed, p, NULL) - 1);
      }
  }
  return OC_OK;
}

/* Row j of the detail into out (nx), with the thread's scratch (maxni +
** 3 nx floats). */
/* (compiled for AVX-512, AVX2 and the baseline, as the relaxation rows
** of jacobi.c: the same operations per sample, the same bytes) */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((noinline,
               target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
static void
noise_row(const grid_noise *g, int j, const float *A, const float *R,
          float *out, float *scr) {
  const oc_ddetail *d = g->d;
  size_t nx = (size_t)g->nx;
  float *q = scr, *w = scr + nx, *sum = scr + 2 * nx, *tmp = scr + 3 * nx;
  double lr = log(d->ratio), y = d->y0 + j * d->cell;
  for (size_t i = 0; i < nx; i++) {
    q[i] = (float)exp(-(1 - (double)R[i]) * lr);
    w[i] = 1;
    sum[i] = 0;
  }
  for (int k = 0; k < g->n; k++) {
    const octave *o = &g->o[k];
    if (!o->lat) {
      for (size_t i = 0; i < nx; i++) {
        oc_vec3 p = {(d->x0 + (double)i * d->cell) * o->f, y * o->f, 0};
        float s = (float)(2 * oc_noise3(o->seed, p, NULL) - 1);
        sum[i] += w[i] * s;
        w[i] *= q[i];
      }
      continue;
    }
    float wy[4];
    size_t J = (size_t)(node(y, o->h, wy) - o->j0), ni = o->ni;
    const float *l0 = o->lat + J * ni, *l1 = l0 + ni, *l2 = l1 + ni,
                *l3 = l2 + ni;
#pragma omp simd
    for (size_t I = 0; I < ni; I++)
      tmp[I] = wy[0] * l0[I] + wy[1] * l1[I] + wy[2] * l2[I] + wy[3] * l3[I];
      /* (q, w, sum and tmp are disjoint parts of the scratch) */
#pragma omp simd
    for (size_t i = 0; i < nx; i++) {
      const float *t = tmp + o->col[i], *wx = o->wx + 4 * i;
      float s = wx[0] * t[0] + wx[1] * t[1] + wx[2] * t[2] + wx[3] * t[3];
      sum[i] += w[i] * s;
      w[i] *= q[i];
    }
  }
#pragma omp simd
  for (size_t i = 0; i < nx; i++)
    out[i] = A[i] * sum[i];
}

int oc_ddetail_grid(const oc_ddetail *d, const oc_dlevel *lv, float *z,
                    float *detail, oc_progress pr, double lo, double span,
                    oc_error *err) {
  grid_noise g;
  int rc = init_noise(&g, d, lv->nx, lv->ny, err);
  if (rc) return rc;
  size_t nx = (size_t)lv->nx;
  int ny = lv->ny, stop = 0, fail = 0, done = 0;
#pragma omp parallel
  {
    float *scr = malloc((g.maxni + 4 * nx) * sizeof *scr);
    if (!scr) {
#pragma omp atomic write
      fail = 1;
    }
#pragma omp for schedule(dynamic, 4)
    for (int j = 0; j < ny; j++) {
      int halt;
#pragma omp atomic read
      halt = stop;
      if (halt || !scr) continue;
      size_t row = (size_t)j * nx;
      float *n = detail ? detail + row : scr + g.maxni + 3 * nx;
      noise_row(&g, j, lv->map[MAP_A] + row, lv->map[MAP_R] + row, n, scr);
      const float *h = lv->map[MAP_H] + row;
      for (size_t i = 0; i < nx; i++)
        z[row + i] = h[i] + n[i];
      int dn;
#pragma omp atomic capture
      dn = ++done;
      if (pr.fn && omp_get_thread_num() == 0 &&
          pr.fn(pr.ud, lo + span * 0.99 * dn / ny)) {
#pragma omp atomic write
        stop = 1;
      }
    }
    free(scr);
  }
  free_noise(&g);
  if (fail) return oc_seterr(err, OC_ENOMEM, "out of memory (noise rows)");
  if (stop || (pr.fn && pr.fn(pr.ud, lo + span)))
    return oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
  return OC_OK;
}
