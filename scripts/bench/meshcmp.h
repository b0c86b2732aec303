/*
** meshcmp.h — comparing two meshes up to vertex order, for the benchmarks
** that check a faster path gives the same mesh (bench_mesh.c,
** bench_gen_karst.c).
*/
#ifndef MESHCMP_H
#define MESHCMP_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "outcrop.h"

typedef struct tri9 {
  float v[9];
} tri9;

static int cmp3(const float *a, const float *b) {
  for (int i = 0; i < 3; i++)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}

static int cmp9(const void *x, const void *y) {
  int c = memcmp(x, y, sizeof(tri9));
  return (c > 0) - (c < 0);
}

/* Triangles as position triples, each rotated so its smallest vertex
** comes first (orientation kept), sorted. */
static tri9 *canon(const oc_mesh *m, size_t *n) {
  *n = oc_mesh_triangle_count(m);
  const float *P = oc_mesh_positions(m);
  const uint32_t *I = oc_mesh_indices(m);
  tri9 *t = malloc((*n ? *n : 1) * sizeof *t);
  for (size_t i = 0; i < *n; i++) {
    int s = 0;
    for (int k = 1; k < 3; k++)
      if (cmp3(P + 3 * I[3 * i + k], P + 3 * I[3 * i + s]) < 0) s = k;
    for (int k = 0; k < 3; k++)
      memcpy(t[i].v + 3 * k, P + 3 * I[3 * i + (s + k) % 3], 3 * sizeof(float));
  }
  qsort(t, *n, sizeof *t, cmp9);
  return t;
}

/* 1 when a and b hold the same triangles up to vertex order. */
static int same_mesh(const oc_mesh *a, const oc_mesh *b) {
  size_t na, nb;
  tri9 *ta = canon(a, &na), *tb = canon(b, &nb);
  int same = na == nb && !memcmp(ta, tb, na * sizeof *ta);
  free(ta);
  free(tb);
  return same;
}

#endif
