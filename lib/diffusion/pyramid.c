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

static void free_level(oc_dlevel *lv) {
  free(lv->map[0]);
  free(lv->flags);
  for (int q = 0; q < MAP_COUNT; q++)
    lv->map[q] = NULL;
  lv->flags = NULL;
}

void oc_dpyramid_free(oc_dpyramid *py) {
  if (!py->lv) return;
  for (int k = 0; k < py->nlevels; k++)
    free_level(&py->lv[k]);
  free(py->lv);
  free(py->scratch);
  py->lv = NULL;
  py->scratch = NULL;
}

void oc_dpyramid_shrink(oc_dpyramid *py) {
  for (int k = 1; k < py->nlevels; k++)
    free_level(&py->lv[k]);
  free(py->scratch);
  py->scratch = NULL;
}

static int alloc_level(oc_dlevel *lv) {
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
  float *m = malloc(MAP_COUNT * ns * sizeof *m);
  lv->flags = calloc(ns, 1);
  if (!m || !lv->flags) {
    free(m);
    free(lv->flags);
    lv->flags = NULL;
    return OC_ENOMEM;
  }
  for (int q = 0; q < MAP_COUNT; q++)
    lv->map[q] = m + (size_t)q * ns;
  return OC_OK;
}

int oc_dpyramid_init(oc_dpyramid *py, int nx, int ny, double cell,
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
  if (alloc_level(&py->lv[0])) {
    oc_dpyramid_free(py);
    return oc_seterr(err, OC_ENOMEM, "out of memory (%d x %d grid)", nx, ny);
  }
  return OC_OK;
}

int oc_dpyramid_grow(oc_dpyramid *py, oc_error *err) {
  for (int k = 1; k < py->nlevels; k++)
    if (alloc_level(&py->lv[k]))
      return oc_seterr(err, OC_ENOMEM, "out of memory (level %d)", k);
  size_t ns = (size_t)py->lv[0].nx * (size_t)py->lv[0].ny;
  py->scratch = malloc(ns * sizeof *py->scratch);
  if (!py->scratch) return oc_seterr(err, OC_ENOMEM, "out of memory");
  return OC_OK;
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
