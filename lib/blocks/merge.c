/*
** merge.c — the last step of clustering: the smallest clusters join a
** neighbour, then every cluster is moved so that its centroid lies in the
** tile.
**
** The greedy flood fill leaves crumbs: points refused by the cluster
** around them (a disc between them and some member) that found no cluster
** of their own kind. A cluster of fewer than MERGE_BELOW points joins the
** first neighbouring cluster, over an uncut edge, that is at least as
** large, with the union less than s - 2 k r across, and with no disc
** image between any of its points and the other's points within 2 k r of
** it: the crumbs failed the flood fill's visibility test against far
** members, so merging checks it locally (the overlaps this may leave
** are cut apart by separate.c). Clusters are visited in label order
** and merged ones drop out, so the result depends on the seed alone.
** Labels are then renumbered in order.
*/
#include <math.h>
#include <stdlib.h>

#include "blocks/btile.h"
#include "core/error.h"

#define MERGE_BELOW 8
/* visibility is checked up to NEAR k r from the small cluster's points */
#define NEAR 2.0
#define NONE UINT32_MAX

typedef struct lists {
  uint32_t *head, *tail, *next;
  size_t *count;
} lists;

static void bbox_of(const oc_btile *t, const lists *l, uint32_t c,
                    const double *sh, double *lo, double *hi) {
  for (uint32_t i = l->head[c]; i != NONE; i = l->next[i])
    for (int a = 0; a < 3; a++) {
      double x = t->unwrap[3 * (size_t)i + a] + sh[a];
      lo[a] = fmin(lo[a], x);
      hi[a] = fmax(hi[a], x);
    }
}

/* May cluster c, shifted by sh, join cluster d? */
static int may_merge(const oc_btile *t, const lists *l, uint32_t c, uint32_t d,
                     const double *sh, const oc_bimage *im, size_t nim) {
  static const double zero[3] = {0, 0, 0};
  double lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double most = t->pp.size - 2 * t->pp.neighbour * t->pp.radius;
  double near = NEAR * t->pp.neighbour * t->pp.radius, near2 = near * near;
  bbox_of(t, l, c, sh, lo, hi);
  bbox_of(t, l, d, zero, lo, hi);
  for (int a = 0; a < 3; a++)
    if (hi[a] - lo[a] > most) return 0;
  for (size_t k = 0; k < nim; k++) {
    const oc_aabb *b = &im[k].box;
    if (b->lo.x > hi[0] || b->hi.x < lo[0] || b->lo.y > hi[1] ||
        b->hi.y < lo[1] || b->lo.z > hi[2] || b->hi.z < lo[2])
      continue;
    for (uint32_t i = l->head[c]; i != NONE; i = l->next[i]) {
      const double *u = t->unwrap + 3 * (size_t)i;
      double p[3] = {u[0] + sh[0], u[1] + sh[1], u[2] + sh[2]};
      for (uint32_t j = l->head[d]; j != NONE; j = l->next[j]) {
        const double *q = t->unwrap + 3 * (size_t)j;
        double d2 = (p[0] - q[0]) * (p[0] - q[0]) +
                    (p[1] - q[1]) * (p[1] - q[1]) +
                    (p[2] - q[2]) * (p[2] - q[2]);
        if (d2 <= near2 && oc_bimage_cuts(&im[k], p, q)) return 0;
      }
    }
  }
  return 1;
}

static void join(oc_btile *t, lists *l, uint32_t c, uint32_t d,
                 const double *sh) {
  for (uint32_t i = l->head[c]; i != NONE; i = l->next[i]) {
    t->label[i] = d;
    for (int a = 0; a < 3; a++)
      t->unwrap[3 * (size_t)i + a] += sh[a];
  }
  l->next[l->tail[d]] = l->head[c];
  l->tail[d] = l->tail[c];
  l->count[d] += l->count[c];
  l->head[c] = l->tail[c] = NONE;
  l->count[c] = 0;
}

/* Tries the neighbours of cluster c over uncut edges. */
static void merge_one(oc_btile *t, lists *l, uint32_t c, const oc_bimage *im,
                      size_t nim) {
  const oc_bgraph *g = &t->g;
  double s = t->pp.size;
  for (uint32_t u = l->head[c]; u != NONE; u = l->next[u])
    for (size_t k = g->start[u]; k < g->start[u + 1]; k++) {
      uint32_t e = g->adj[k];
      if (g->cut[e]) continue;
      uint32_t v = g->a[e] == u ? g->b[e] : g->a[e], d = t->label[v];
      if (d == c || l->count[d] < l->count[c]) continue;
      /* u as seen from v's image in d, against u's own image in c */
      double sg = g->a[e] == u ? -1 : 1, sh[3];
      for (int a = 0; a < 3; a++) {
        double x = t->unwrap[3 * (size_t)v + a] + sg * g->v[3 * e + a];
        sh[a] = s * round((x - t->unwrap[3 * (size_t)u + a]) / s);
      }
      if (may_merge(t, l, c, d, sh, im, nim)) {
        join(t, l, c, d, sh);
        return;
      }
    }
}

static void centre(oc_btile *t, const lists *l, uint32_t c) {
  double m[3] = {0, 0, 0}, s = t->pp.size;
  for (uint32_t i = l->head[c]; i != NONE; i = l->next[i])
    for (int a = 0; a < 3; a++)
      m[a] += t->unwrap[3 * (size_t)i + a];
  for (int a = 0; a < 3; a++) {
    double sh = -s * floor(m[a] / (double)l->count[c] / s);
    if (sh != 0)
      for (uint32_t i = l->head[c]; i != NONE; i = l->next[i])
        t->unwrap[3 * (size_t)i + a] += sh;
  }
}

int oc_bclusters_merge(oc_btile *t, oc_error *err) {
  size_t n = t->np, nc = t->ncl;
  lists l;
  l.head = malloc((nc ? nc : 1) * sizeof *l.head);
  l.tail = malloc((nc ? nc : 1) * sizeof *l.tail);
  l.count = calloc(nc ? nc : 1, sizeof *l.count);
  l.next = malloc((n ? n : 1) * sizeof *l.next);
  uint32_t *renum = malloc((nc ? nc : 1) * sizeof *renum);
  oc_bimage *im = NULL;
  size_t nim = 0;
  int rc = OC_ENOMEM;
  double s = t->pp.size;
  oc_aabb in = {{-s, -s, -s}, {2 * s, 2 * s, 2 * s}};
  if (!l.head || !l.tail || !l.count || !l.next || !renum) goto done;
  if ((rc = oc_bdiscs_images(t, in, &im, &nim, err))) goto done;
  rc = OC_ENOMEM;
  for (size_t c = 0; c < nc; c++)
    l.head[c] = l.tail[c] = NONE;
  for (size_t i = 0; i < n; i++) {
    uint32_t c = t->label[i];
    l.next[i] = NONE;
    if (l.head[c] == NONE)
      l.head[c] = (uint32_t)i;
    else
      l.next[l.tail[c]] = (uint32_t)i;
    l.tail[c] = (uint32_t)i;
    l.count[c]++;
  }
  for (size_t c = 0; c < nc; c++)
    if (l.count[c] && l.count[c] < MERGE_BELOW)
      merge_one(t, &l, (uint32_t)c, im, nim);
  size_t m = 0;
  for (size_t c = 0; c < nc; c++) {
    renum[c] = l.count[c] ? (uint32_t)m++ : NONE;
    if (l.count[c]) centre(t, &l, (uint32_t)c);
  }
  for (size_t i = 0; i < n; i++)
    t->label[i] = renum[t->label[i]];
  t->merged = nc - m;
  t->ncl = m;
  rc = 0;
done:
  if (rc == OC_ENOMEM)
    oc_seterr(err, OC_ENOMEM, "out of memory for merging clusters");
  free(l.head);
  free(l.tail);
  free(l.count);
  free(l.next);
  free(renum);
  free(im);
  return rc;
}
