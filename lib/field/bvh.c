/*
** bvh.c — bounding volume hierarchy construction for blend and union ops.
**
** Top-down median split on the longest axis of the centroids' extent.
** Deterministic: ties are broken by entry index, so the same input always
** gives the same tree. Each split leaves half the leaves (rounded down to
** a whole one) on the left, so n entries make ceil(log2(ceil(n / 8))) + 1
** levels, at most 30 for 2^32: the bound the walks' stack relies on
** (bvhwalk.h), reported by oc_bvh_build and checked by compile.c.
*/
#define _GNU_SOURCE /* qsort_r */
#include <math.h>
#include <stdlib.h>

#include "core/vec.h"
#include "field/program.h"

void oc_box_to_float(oc_aabb b, float lo[3], float hi[3]) {
  const double *l = &b.lo.x, *h = &b.hi.x;
  for (int i = 0; i < 3; i++) {
    float fl = (float)l[i], fh = (float)h[i];
    if ((double)fl > l[i]) fl = nextafterf(fl, -INFINITY);
    if ((double)fh < h[i]) fh = nextafterf(fh, INFINITY);
    lo[i] = fl;
    hi[i] = fh;
  }
}

typedef struct builder {
  const oc_aabb *boxes;
  double *cen; /* 3 per box */
  uint32_t *idx;
  oc_bvhnode *nodes;
  size_t count;
  int levels; /* deepest leaf's depth + 1 */
} builder;

static double cen(const builder *b, uint32_t i, int axis) {
  return b->cen[3 * (size_t)i + axis];
}
typedef struct sortctx {
  const double *cen;
  int axis;
} sortctx;

/* Orders by (centroid on axis, index): a total order, so the tree does not
** depend on the sort algorithm's tie handling. */
static int cmp(const void *x, const void *y, void *ctx) {
  const sortctx *c = ctx;
  uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
  double ca = c->cen[3 * (size_t)a + c->axis],
         cb = c->cen[3 * (size_t)b + c->axis];
  if (ca < cb) return -1;
  if (ca > cb) return 1;
  return a < b ? -1 : a > b;
}

static void select_mid(builder *b, size_t lo, size_t hi, int axis) {
  sortctx c = {b->cen, axis};
  qsort_r(b->idx + lo, hi - lo, sizeof *b->idx, cmp, &c);
}

static void build(builder *b, size_t node, size_t lo, size_t hi, int depth) {
  if (depth + 1 > b->levels) b->levels = depth + 1;
  oc_aabb box = oc_aabb_empty(), cb = oc_aabb_empty();
  for (size_t i = lo; i < hi; i++) {
    uint32_t k = b->idx[i];
    box = oc_aabb_union(box, b->boxes[k]);
    oc_vec3 c = oc_v3(cen(b, k, 0), cen(b, k, 1), cen(b, k, 2));
    cb.lo = oc_vmin(cb.lo, c);
    cb.hi = oc_vmax(cb.hi, c);
  }
  oc_bvhnode *nd = &b->nodes[node];
  oc_box_to_float(box, nd->lo, nd->hi);
  if (hi - lo <= OC_BVH_LEAF) {
    nd->first = (uint32_t)lo;
    nd->count = (uint32_t)(hi - lo);
    return;
  }
  oc_vec3 ext = oc_sub(cb.hi, cb.lo);
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  /* split at a multiple of the leaf size so leaves come out full: fewer
  ** nodes for the same entries */
  size_t nleaves = (hi - lo + OC_BVH_LEAF - 1) / OC_BVH_LEAF;
  size_t mid = lo + (nleaves / 2) * OC_BVH_LEAF;
  select_mid(b, lo, hi, axis);
  size_t left = b->count;
  b->count += 2;
  nd->first = (uint32_t)left;
  nd->count = 0;
  build(b, left, lo, mid, depth + 1);
  build(b, left + 1, mid, hi, depth + 1);
}

size_t oc_bvh_build(const oc_aabb *boxes, size_t n, oc_bvhnode *nodes,
                    uint32_t *perm, int *levels) {
  *levels = 0;
  if (n == 0) return 0;
  builder b = {boxes, malloc(3 * n * sizeof(double)), perm, nodes, 1, 0};
  if (!b.cen) return 0;
  for (size_t i = 0; i < n; i++) {
    perm[i] = (uint32_t)i;
    b.cen[3 * i + 0] = 0.5 * (boxes[i].lo.x + boxes[i].hi.x);
    b.cen[3 * i + 1] = 0.5 * (boxes[i].lo.y + boxes[i].hi.y);
    b.cen[3 * i + 2] = 0.5 * (boxes[i].lo.z + boxes[i].hi.z);
  }
  build(&b, 0, 0, n, 0);
  free(b.cen);
  *levels = b.levels;
  return b.count;
}
