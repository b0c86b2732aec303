/*
** pyramid.c — the multigrid levels of the diffusion (Hnaidi et al. 2010,
** section 5.2): each level halves the grid (cell-centred: coarse sample
** I covers fine samples 2I and 2I + 1 on each axis, the last one alone
** when the count is odd) down to a coarsest grid of at most 8 samples a
** side. Restriction of the constraint maps: a coarse sample is
** constrained if any child is, with the mean of the constrained
** children (the guide direction re-normalised).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define COARSEST 8
#define MAX_LEVELS 32

void oc_dpyramid_free(oc_dpyramid *py) {
  if (!py->lv) return;
  free(py->lv[0].flags);
  free(py->own0);
  free(py->block);
  free(py->lv);
  memset(py, 0, sizeof *py);
}

void oc_dpyramid_shrink(oc_dpyramid *py) {
  for (int k = 1; k < py->nlevels; k++) {
    memset(py->lv[k].map, 0, sizeof py->lv[k].map);
    py->lv[k].flags = NULL;
  }
  free(py->block);
  py->block = NULL;
  py->scratch = NULL;
}

/* Bytes of the block: the coarse levels' maps, then their flags, then
** the scratch grid (each part 64-byte aligned), and at least the
** counters. */
static size_t block_size(const oc_dpyramid *py, size_t *flags_at,
                         size_t *scratch_at) {
  size_t maps = 0, flags = 0, ns0 = (size_t)py->lv[0].nx * (size_t)py->lv[0].ny;
  for (int k = 1; k < py->nlevels; k++) {
    size_t ns = (size_t)py->lv[k].nx * (size_t)py->lv[k].ny;
    maps += MAP_COUNT * ns * sizeof(float);
    flags += ns;
  }
  maps = (maps + 63) & ~(size_t)63;
  flags = (flags + 63) & ~(size_t)63;
  *flags_at = maps, *scratch_at = maps + flags;
  size_t all = maps + flags + ns0 * sizeof(float), cnt = 4 * ns0 * 2;
  return all > cnt ? all : cnt;
}

int oc_dpyramid_init(oc_dpyramid *py, int nx, int ny, double cell, float *h,
                     oc_error *err) {
  memset(py, 0, sizeof *py);
  int n = 1;
  for (int a = nx, b = ny; (a > COARSEST || b > COARSEST) && n < MAX_LEVELS;
       n++)
    a = (a + 1) / 2, b = (b + 1) / 2;
  py->lv = calloc((size_t)n, sizeof *py->lv);
  if (!py->lv) return oc_seterr(err, OC_ENOMEM, "out of memory");
  py->nlevels = n;
  for (int k = 0; k < n; k++) {
    oc_dlevel *lv = &py->lv[k];
    lv->nx = k ? (py->lv[k - 1].nx + 1) / 2 : nx;
    lv->ny = k ? (py->lv[k - 1].ny + 1) / 2 : ny;
    lv->cell = k ? 2 * py->lv[k - 1].cell : cell;
  }
  size_t ns = (size_t)nx * (size_t)ny, fa, sa;
  int own = MAP_COUNT - (h != NULL);
  /* (not zeroed: the rasteriser zeroes its rows as it paints them) */
  py->own0 = malloc((size_t)own * ns * sizeof(float));
  py->lv[0].flags = malloc(ns);
  py->block = malloc(block_size(py, &fa, &sa));
  if (!py->own0 || !py->lv[0].flags || !py->block) {
    oc_dpyramid_free(py);
    return oc_seterr(err, OC_ENOMEM, "out of memory (%d x %d grid)", nx, ny);
  }
  for (int q = 0, o = 0; q < MAP_COUNT; q++)
    py->lv[0].map[q] = q == MAP_H && h ? h : py->own0 + (size_t)o++ * ns;
  return OC_OK;
}

uint16_t *oc_dpyramid_counters(oc_dpyramid *py) {
  return py->block;
}

void oc_dpyramid_grow(oc_dpyramid *py) {
  size_t fa, sa;
  block_size(py, &fa, &sa);
  char *b = py->block;
  float *m = (float *)b;
  uint8_t *f = (uint8_t *)b + fa;
  for (int k = 1; k < py->nlevels; k++) {
    oc_dlevel *lv = &py->lv[k];
    size_t ns = (size_t)lv->nx * (size_t)lv->ny;
    for (int q = 0; q < MAP_COUNT; q++)
      lv->map[q] = m + (size_t)q * ns;
    lv->flags = f;
    m += MAP_COUNT * ns;
    f += ns;
  }
  py->scratch = (float *)(b + sa);
}

/* Coarse sample (I, J) of c from the children in f. */
static void restrict_one(const oc_dlevel *f, oc_dlevel *c, int I, int J) {
  double sum[MAP_COUNT] = {0};
  int nh = 0, ng = 0, nn = 0;
  uint8_t fl = 0;
  for (int b = 0; b < 2; b++)
    for (int a = 0; a < 2; a++) {
      int i = 2 * I + a, j = 2 * J + b;
      if (i >= f->nx || j >= f->ny) continue;
      size_t k = (size_t)j * (size_t)f->nx + (size_t)i;
      uint8_t g = f->flags[k];
      fl |= g;
      if (g & DF_H) sum[MAP_H] += f->map[MAP_H][k], nh++;
      if (g & DF_SLOPE) {
        sum[MAP_GX] += f->map[MAP_GX][k];
        sum[MAP_GY] += f->map[MAP_GY][k];
        sum[MAP_GD] += f->map[MAP_GD][k];
        ng++;
      }
      if (g & DF_NOISE) {
        sum[MAP_A] += f->map[MAP_A][k];
        sum[MAP_R] += f->map[MAP_R][k];
        nn++;
      }
    }
  size_t k = (size_t)J * (size_t)c->nx + (size_t)I;
  for (int q = 0; q < MAP_COUNT; q++)
    c->map[q][k] = 0;
  if (nh) c->map[MAP_H][k] = (float)(sum[MAP_H] / nh);
  if (nn) {
    c->map[MAP_A][k] = (float)(sum[MAP_A] / nn);
    c->map[MAP_R][k] = (float)(sum[MAP_R] / nn);
  }
  if (ng) {
    double gx = sum[MAP_GX], gy = sum[MAP_GY], g = sqrt(gx * gx + gy * gy);
    if (g > 1e-6) {
      c->map[MAP_GX][k] = (float)(gx / g);
      c->map[MAP_GY][k] = (float)(gy / g);
      c->map[MAP_GD][k] = (float)(sum[MAP_GD] / ng);
    } else {
      fl = (uint8_t)((fl & ~DF_SLOPE) | DF_CONFLICT);
    }
  }
  c->flags[k] = fl;
}

void oc_dpyramid_restrict(oc_dpyramid *py) {
  for (int k = 1; k < py->nlevels; k++) {
    const oc_dlevel *f = &py->lv[k - 1];
    oc_dlevel *c = &py->lv[k];
#pragma omp parallel for schedule(static) if (OC_DPAR(f))
    for (int J = 0; J < c->ny; J++)
      for (int I = 0; I < c->nx; I++)
        restrict_one(f, c, I, J);
  }
}
