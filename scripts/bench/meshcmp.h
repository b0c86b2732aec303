/*
** meshcmp.h — timing meshes, and comparing two up to vertex order, for the
** benchmarks that check a faster path gives the same mesh (bench_mesh.c,
** bench_gen_karst.c): to the bit, or as the same triangles on the same
** grid edges with vertices placed differently along their edges (root
** finding against direct elevation extraction).
*/
#ifndef MESHCMP_H
#define MESHCMP_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>
#include <stdio.h>

#include "outcrop.h"

/* Meshes box at cell (full grid and/or root finding everywhere when
** asked), its seconds in *sec; exits naming `who` on error. */
static inline oc_mesh *timed_mesh(const char *who, const oc_program *p,
                                  oc_aabb box, double cell, int full,
                                  int no_direct, double *sec) {
  oc_error err;
  oc_polygonize_params pp = {0};
  pp.box = box;
  pp.cell = cell;
  pp.full_grid = full;
  pp.no_direct = no_direct;
  double t0 = omp_get_wtime();
  oc_mesh *m = oc_polygonize(p, &pp, &err);
  *sec = omp_get_wtime() - t0;
  if (!m) {
    fprintf(stderr, "%s: %s\n", who, err.msg);
    exit(1);
  }
  return m;
}

typedef struct tri9 {
  float v[9];
} tri9;

static inline int cmp3(const float *a, const float *b) {
  for (int i = 0; i < 3; i++)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}

static inline int cmp9(const void *x, const void *y) {
  int c = memcmp(x, y, sizeof(tri9));
  return (c > 0) - (c < 0);
}

/* Triangles as position triples, each rotated so its smallest vertex
** comes first (orientation kept), sorted. */
static inline tri9 *canon(const oc_mesh *m, size_t *n) {
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
static inline int same_mesh(const oc_mesh *a, const oc_mesh *b) {
  size_t na, nb;
  tri9 *ta = canon(a, &na), *tb = canon(b, &nb);
  int same = na == nb && !memcmp(ta, tb, na * sizeof *ta);
  free(ta);
  free(tb);
  return same;
}

/* Cells per axis of the polygonizer's grid for box and cell (the rule of
** polygonize.c). */
static inline void grid_cells(oc_aabb box, double cell, double n[3]) {
  double ext[3] = {box.hi.x - box.lo.x, box.hi.y - box.lo.y,
                   box.hi.z - box.lo.z};
  for (int a = 0; a < 3; a++)
    n[a] = ceil(ext[a] / cell * (1 - 1e-12));
}

/* The sampling-grid edge a vertex lies on (samples at lo + (i + 1/2) h,
** padding at the box faces): the two coordinates on the grid, and the
** lower sample along the third, the one farthest from any grid plane. */
static inline uint64_t edge_key(const float *p, const double lo[3],
                                const double h[3]) {
  double u[3], r[3];
  int ax = 0;
  for (int a = 0; a < 3; a++) {
    u[a] = (p[a] - lo[a]) / h[a] - 0.5;
    r[a] = fabs(u[a] - floor(u[a] + 0.5));
    if (r[a] > r[ax]) ax = a;
  }
  uint64_t k = (uint64_t)ax;
  for (int a = 0; a < 3; a++) {
    double i = a == ax ? floor(u[a]) : floor(u[a] + 0.5);
    k = (k << 20) | (uint64_t)(int64_t)(i + 1); /* 2 + 3 x 20 bits */
  }
  return k;
}

typedef struct keyidx {
  uint64_t key;
  uint32_t v;
} keyidx;

static inline int cmp_key(const void *x, const void *y) {
  uint64_t a = ((const keyidx *)x)->key, b = ((const keyidx *)y)->key;
  return (a > b) - (a < b);
}

static inline int cmp_tri3(const void *x, const void *y) {
  const uint32_t *a = x, *b = y;
  for (int k = 0; k < 3; k++)
    if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
  return 0;
}

/* Triangles of m as triples of vertex ranks in edge-key order, each
** rotated to start at its smallest (orientation kept), sorted; the keys
** sorted in *ks. NULL when two vertices share an edge. */
static inline uint32_t *canon_edges(const oc_mesh *m, const double lo[3],
                                    const double h[3], keyidx **ks) {
  size_t nv = oc_mesh_vertex_count(m), nt = oc_mesh_triangle_count(m);
  const float *P = oc_mesh_positions(m);
  const uint32_t *I = oc_mesh_indices(m);
  keyidx *k = malloc((nv ? nv : 1) * sizeof *k);
  uint32_t *rank = malloc((nv ? nv : 1) * sizeof *rank);
  uint32_t *t = malloc((nt ? 3 * nt : 1) * sizeof *t);
  for (size_t v = 0; v < nv; v++)
    k[v] = (keyidx){edge_key(P + 3 * v, lo, h), (uint32_t)v};
  qsort(k, nv, sizeof *k, cmp_key);
  int dup = 0;
  for (size_t r = 0; r < nv; r++) {
    rank[k[r].v] = (uint32_t)r;
    if (r && k[r].key == k[r - 1].key) dup = 1;
  }
  for (size_t i = 0; i < nt; i++) {
    uint32_t a[3] = {rank[I[3 * i]], rank[I[3 * i + 1]], rank[I[3 * i + 2]]};
    int s = a[1] < a[0] ? (a[2] < a[1] ? 2 : 1) : (a[2] < a[0] ? 2 : 0);
    for (int c = 0; c < 3; c++)
      t[3 * i + c] = a[(s + c) % 3];
  }
  qsort(t, nt, 3 * sizeof *t, cmp_tri3);
  free(rank);
  *ks = k;
  if (dup) {
    free(t);
    return NULL;
  }
  return t;
}

/* 1 when a and b, meshed over box at cell, have the same triangles on
** the same grid edges, whatever the vertex order; *dev gets the largest
** distance between the two vertices of an edge. */
static inline int same_edges(const oc_mesh *a, const oc_mesh *b, oc_aabb box,
                             double cell, double *dev) {
  double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, h[3], n[3];
  grid_cells(box, cell, n);
  h[0] = (box.hi.x - box.lo.x) / n[0];
  h[1] = (box.hi.y - box.lo.y) / n[1];
  h[2] = (box.hi.z - box.lo.z) / n[2];
  size_t nv = oc_mesh_vertex_count(a), nt = oc_mesh_triangle_count(a);
  *dev = INFINITY;
  if (nv != oc_mesh_vertex_count(b) || nt != oc_mesh_triangle_count(b))
    return 0;
  keyidx *ka, *kb;
  uint32_t *ta = canon_edges(a, lo, h, &ka), *tb = canon_edges(b, lo, h, &kb);
  int same = ta && tb && !memcmp(ta, tb, 3 * nt * sizeof *ta);
  const float *pa = oc_mesh_positions(a), *pb = oc_mesh_positions(b);
  double worst = 0;
  for (size_t r = 0; same && r < nv; r++) {
    if (ka[r].key != kb[r].key) {
      same = 0;
      break;
    }
    double d2 = 0;
    for (int c = 0; c < 3; c++) {
      double d = (double)pa[3 * ka[r].v + c] - pb[3 * kb[r].v + c];
      d2 += d * d;
    }
    worst = fmax(worst, sqrt(d2));
  }
  if (same) *dev = worst;
  free(ta);
  free(tb);
  free(ka);
  free(kb);
  return same;
}

#endif
