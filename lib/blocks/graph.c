/*
** graph.c — the neighbour graph of a tile's points (Paris et al. 2020,
** section 4.1) and the edges the fracture discs cut.
**
** An edge joins two points closer than k r on the torus (k = neighbour,
** 2 by default: under a Poisson radius r, "closer than r" would give no
** edge at all). Points are bucketed in cells of side >= k r (at least 3 per
** axis, so each neighbour is met once, at its nearest image). An edge is
** cut when its segment, from a point to the nearest image of the other,
** crosses any periodic image of a disc.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "core/error.h"

typedef struct cells {
  int n; /* per axis */
  double side;
  size_t *start; /* n^3 + 1 */
  uint32_t *idx;
} cells;

static int cell_of(double x, const cells *c) {
  int i = (int)(x / c->side);
  return i < 0 ? 0 : i >= c->n ? c->n - 1 : i;
}

static int cells_make(const oc_btile *t, cells *c, oc_error *err) {
  double reach = t->pp.neighbour * t->pp.radius;
  c->n = (int)floor(t->pp.size / reach);
  c->side = t->pp.size / c->n;
  size_t nc = (size_t)c->n * c->n * c->n;
  c->start = calloc(nc + 1, sizeof *c->start);
  c->idx = malloc((t->np ? t->np : 1) * sizeof *c->idx);
  size_t *fill = calloc(nc, sizeof *fill);
  if (!c->start || !c->idx || !fill) {
    free(fill);
    return oc_seterr(err, OC_ENOMEM, "out of memory for the point cells");
  }
  for (size_t i = 0; i < t->np; i++) {
    const double *p = t->pts + 3 * i;
    size_t k = ((size_t)cell_of(p[2], c) * c->n + cell_of(p[1], c)) * c->n +
               cell_of(p[0], c);
    c->start[k + 1]++;
  }
  for (size_t k = 0; k < nc; k++)
    c->start[k + 1] += c->start[k];
  for (size_t i = 0; i < t->np; i++) {
    const double *p = t->pts + 3 * i;
    size_t k = ((size_t)cell_of(p[2], c) * c->n + cell_of(p[1], c)) * c->n +
               cell_of(p[0], c);
    c->idx[c->start[k] + fill[k]++] = (uint32_t)i;
  }
  free(fill);
  return 0;
}

void oc_bgraph_free(oc_bgraph *g) {
  free(g->a);
  free(g->b);
  free(g->v);
  free(g->cut);
  free(g->start);
  free(g->adj);
  memset(g, 0, sizeof *g);
}

static int push_edge(oc_bgraph *g, size_t *cap, uint32_t a, uint32_t b,
                     const double *v) {
  if (g->ne == *cap) {
    size_t nc = *cap ? 2 * *cap : 4096;
    uint32_t *na = realloc(g->a, nc * sizeof *na);
    if (na) g->a = na;
    uint32_t *nb = realloc(g->b, nc * sizeof *nb);
    if (nb) g->b = nb;
    float *nv = realloc(g->v, 3 * nc * sizeof *nv);
    if (nv) g->v = nv;
    if (!na || !nb || !nv) return OC_ENOMEM;
    *cap = nc;
  }
  g->a[g->ne] = a;
  g->b[g->ne] = b;
  for (int k = 0; k < 3; k++)
    g->v[3 * g->ne + k] = (float)v[k];
  g->ne++;
  return 0;
}

static int edges(oc_btile *t, const cells *c, oc_error *err) {
  oc_bgraph *g = &t->g;
  double s = t->pp.size, reach = t->pp.neighbour * t->pp.radius;
  double r2 = reach * reach;
  size_t cap = 0;
  int n = c->n;
  for (size_t i = 0; i < t->np; i++) {
    const double *p = t->pts + 3 * i;
    int ci[3] = {cell_of(p[0], c), cell_of(p[1], c), cell_of(p[2], c)};
    for (int dz = -1; dz <= 1; dz++)
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
          int q[3] = {ci[0] + dx, ci[1] + dy, ci[2] + dz};
          double sh[3];
          for (int a = 0; a < 3; a++) {
            int w = q[a] < 0 ? -1 : q[a] >= n ? 1 : 0;
            q[a] -= w * n;
            sh[a] = w * s;
          }
          size_t k = ((size_t)q[2] * n + q[1]) * n + q[0];
          for (size_t m = c->start[k]; m < c->start[k + 1]; m++) {
            uint32_t j = c->idx[m];
            if (j <= i) continue;
            const double *o = t->pts + 3 * (size_t)j;
            double v[3] = {o[0] + sh[0] - p[0], o[1] + sh[1] - p[1],
                           o[2] + sh[2] - p[2]};
            if (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] >= r2) continue;
            if (push_edge(g, &cap, (uint32_t)i, j, v))
              return oc_seterr(err, OC_ENOMEM, "out of memory for edges");
          }
        }
  }
  return 0;
}

static int adjacency(oc_btile *t, oc_error *err) {
  oc_bgraph *g = &t->g;
  g->start = calloc(t->np + 1, sizeof *g->start);
  g->adj = malloc((g->ne ? 2 * g->ne : 1) * sizeof *g->adj);
  g->cut = calloc(g->ne ? g->ne : 1, 1);
  size_t *fill = calloc(t->np ? t->np : 1, sizeof *fill);
  if (!g->start || !g->adj || !g->cut || !fill) {
    free(fill);
    return oc_seterr(err, OC_ENOMEM, "out of memory for the graph");
  }
  for (size_t e = 0; e < g->ne; e++) {
    g->start[g->a[e] + 1]++;
    g->start[g->b[e] + 1]++;
  }
  for (size_t i = 0; i < t->np; i++)
    g->start[i + 1] += g->start[i];
  for (size_t e = 0; e < g->ne; e++) {
    g->adj[g->start[g->a[e]] + fill[g->a[e]]++] = (uint32_t)e;
    g->adj[g->start[g->b[e]] + fill[g->b[e]]++] = (uint32_t)e;
  }
  free(fill);
  return 0;
}

/* Marks the edges cut by the disc images meeting the tile grown by the
** reach: each is tested against the edges from the points near it. */
static int cut(oc_btile *t, const cells *c, oc_error *err) {
  oc_bgraph *g = &t->g;
  double s = t->pp.size, reach = t->pp.neighbour * t->pp.radius;
  oc_bimage *im;
  size_t nim;
  oc_aabb in = {{-reach, -reach, -reach}, {s + reach, s + reach, s + reach}};
  int rc = oc_bdiscs_images(t, in, &im, &nim, err);
  if (rc) return rc;
  for (size_t d = 0; d < nim; d++) {
    const oc_bimage *D = &im[d];
    double lo[3] = {D->box.lo.x - reach, D->box.lo.y - reach,
                    D->box.lo.z - reach};
    double hi[3] = {D->box.hi.x + reach, D->box.hi.y + reach,
                    D->box.hi.z + reach};
    int c0[3], c1[3];
    for (int a = 0; a < 3; a++) {
      if (hi[a] < 0 || lo[a] >= s) goto next;
      c0[a] = cell_of(fmax(lo[a], 0), c);
      c1[a] = cell_of(fmin(hi[a], s), c);
    }
    for (int z = c0[2]; z <= c1[2]; z++)
      for (int y = c0[1]; y <= c1[1]; y++)
        for (int x = c0[0]; x <= c1[0]; x++) {
          size_t k = ((size_t)z * c->n + y) * c->n + x;
          for (size_t m = c->start[k]; m < c->start[k + 1]; m++) {
            uint32_t i = c->idx[m];
            const double *p = t->pts + 3 * (size_t)i;
            for (size_t q = g->start[i]; q < g->start[i + 1]; q++) {
              uint32_t e = g->adj[q];
              if (g->a[e] != i || g->cut[e]) continue;
              double o[3] = {p[0] + g->v[3 * e], p[1] + g->v[3 * e + 1],
                             p[2] + g->v[3 * e + 2]};
              if (oc_bimage_cuts(D, p, o)) g->cut[e] = 1;
            }
          }
        }
  next:;
  }
  free(im);
  return 0;
}

int oc_bgraph_make(oc_btile *t, oc_error *err) {
  cells c = {0};
  int rc = cells_make(t, &c, err);
  if (!rc) rc = edges(t, &c, err);
  if (!rc) rc = adjacency(t, err);
  if (!rc) rc = cut(t, &c, err);
  free(c.start);
  free(c.idx);
  return rc;
}
