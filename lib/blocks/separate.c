/*
** separate.c — makes the blocks of a tile disjoint. The hull of a cluster
** may reach over points of another: a cluster grows around the rim of a
** disc that cuts it only in part, and the points it refused form the
** next cluster in the same place. For each pair of blocks whose boxes
** meet (periodic images included), the direction that best separates their
** hull vertices is sought among the discs' normals, both hulls' face
** normals and the line of their centroids; when even the best leaves them
** overlapping along it, both are cut by the plane half-way across the
** overlap (a plane added to each hull, so both stay convex, and disjoint).
** Decisions use the hulls as they were, so the result does not depend on
** the order of the pairs.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "core/error.h"

typedef struct cut {
  size_t block;
  double h[4];
} cut;

typedef struct cuts {
  cut *v;
  size_t n, cap;
} cuts;

static int push(cuts *c, size_t b, double nx, double ny, double nz, double o) {
  if (c->n == c->cap) {
    size_t nc = c->cap ? 2 * c->cap : 256;
    cut *v = realloc(c->v, nc * sizeof *v);
    if (!v) return OC_ENOMEM;
    c->v = v;
    c->cap = nc;
  }
  c->v[c->n++] = (cut){b, {nx, ny, nz, o}};
  return 0;
}

/* Range of n . (v + sh) over the vertices. */
static void range(const oc_bblock *b, const double *n, const double *sh,
                  double *lo, double *hi) {
  double l = INFINITY, h = -INFINITY;
  for (size_t k = 0; k < b->nvert; k++) {
    const double *v = b->vert + 3 * k;
    double x =
        n[0] * (v[0] + sh[0]) + n[1] * (v[1] + sh[1]) + n[2] * (v[2] + sh[2]);
    /* fmin and fmax, inline (NaN x skipped as they skip it) */
    l = x < l ? x : l;
    h = x > h ? x : h;
  }
  *lo = l;
  *hi = h;
}

/* Tests one candidate direction n: keeps the best gap (B above A). */
static void try_dir(const oc_bblock *A, const oc_bblock *B, const double *sh,
                    const double *n0, double *best, double *bn, double *bm) {
  static const double zero[3] = {0, 0, 0};
  double l = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
  if (!(l > 0)) return;
  for (int s = -1; s <= 1; s += 2) {
    double n[3] = {s * n0[0] / l, s * n0[1] / l, s * n0[2] / l};
    double alo, ahi, blo, bhi;
    range(A, n, zero, &alo, &ahi);
    range(B, n, sh, &blo, &bhi);
    double gap = blo - ahi;
    if (gap > *best) {
      *best = gap;
      memcpy(bn, n, sizeof n);
      *bm = 0.5 * (ahi + blo);
    }
  }
}

static int boxes_meet(const oc_aabb *a, const oc_aabb *b, const double *sh) {
  return a->lo.x <= b->hi.x + sh[0] && b->lo.x + sh[0] <= a->hi.x &&
         a->lo.y <= b->hi.y + sh[1] && b->lo.y + sh[1] <= a->hi.y &&
         a->lo.z <= b->hi.z + sh[2] && b->lo.z + sh[2] <= a->hi.z;
}

static int pair(const oc_btile *t, size_t i, size_t j, const double *sh,
                cuts *c) {
  const oc_bblock *A = &t->block[i], *B = &t->block[j];
  double best = -INFINITY, n[3] = {0, 0, 1}, m = 0;
  for (size_t d = 0; d < t->nd; d++) {
    double v[3] = {t->disc[d].n.x, t->disc[d].n.y, t->disc[d].n.z};
    try_dir(A, B, sh, v, &best, n, &m);
    if (best >= 0) return 0;
  }
  for (int w = 0; w < 2; w++) {
    const oc_bblock *F = w ? B : A;
    for (size_t k = 0; k < F->nplane; k++) {
      try_dir(A, B, sh, F->plane + 4 * k, &best, n, &m);
      if (best >= 0) return 0;
    }
  }
  double cd[3] = {B->centroid.x + sh[0] - A->centroid.x,
                  B->centroid.y + sh[1] - A->centroid.y,
                  B->centroid.z + sh[2] - A->centroid.z};
  try_dir(A, B, sh, cd, &best, n, &m);
  if (best >= 0) return 0;
  /* A: n . p <= m; B's image: n . (q + sh) >= m */
  double nsh = n[0] * sh[0] + n[1] * sh[1] + n[2] * sh[2];
  if (push(c, i, n[0], n[1], n[2], -m) ||
      push(c, j, -n[0], -n[1], -n[2], m - nsh))
    return OC_ENOMEM;
  return 0;
}

int oc_bblocks_separate(oc_btile *t, oc_error *err) {
  cuts c = {0};
  double s = t->pp.size;
  int rc = 0;
  for (size_t i = 0; i < t->nb && !rc; i++)
    for (size_t j = i + 1; j < t->nb && !rc; j++)
      for (int k = 0; k < 27 && !rc; k++) {
        double sh[3] = {(k % 3 - 1) * s, (k / 3 % 3 - 1) * s, (k / 9 - 1) * s};
        if (boxes_meet(&t->block[i].box, &t->block[j].box, sh))
          rc = pair(t, i, j, sh, &c);
      }
  /* append each block's cuts to its planes, in the order found */
  for (size_t q = 0; q < c.n && !rc; q++) {
    oc_bblock *b = &t->block[c.v[q].block];
    double *p = realloc(b->plane, 4 * (b->nplane + 1) * sizeof *p);
    if (!p) {
      rc = OC_ENOMEM;
      break;
    }
    b->plane = p;
    memcpy(p + 4 * b->nplane++, c.v[q].h, 4 * sizeof *p);
  }
  t->ncut = c.n / 2;
  free(c.v);
  if (rc) return oc_seterr(err, OC_ENOMEM, "out of memory for block cuts");
  return 0;
}
