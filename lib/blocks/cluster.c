/*
** cluster.c — clusters of a tile's points (Paris et al. 2020, section
** 4.1): greedy flood fill over the uncut edges of the neighbour graph with
** the mutual-visibility check, unwrapped to contiguous coordinates.
**
** Clusters start at the points in a random order (keyed by the seed); a
** cluster grows breadth-first: a neighbour joins when the edge to it is not
** cut, no disc image crosses the segment from it to any member (so a
** cluster never wraps around a disc's rim), and the cluster stays less
** than s - 2 k r across on every axis (a block must not meet its own
** periodic images; larger clusters, such as an uncut bed of a tabular
** tile, are split). A point refused by a cluster waits for the next one.
** Each joining point gets the image of itself nearest the member it came
** from (merge.c then merges the smallest clusters and moves each
** centroid into the tile).
*/
#include <math.h>
#include <stdlib.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "core/grow.h"
#include "core/rng.h"

#define KEY_ORDER 0x6f72646572ull
#define NONE UINT32_MAX
/* the candidate images are those near the cluster's box grown by this
** many k r (remade when the box leaves it) */
#define CACHE_GROW 2.0

/* A member and its signed distance to a candidate's plane. */
typedef struct held {
  double a;
  uint32_t m;
} held;

/* A candidate's members not strictly above its plane (side <= 0) and not
** strictly below it, in order of joining: a point above the plane can
** only be cut off from the first, one below from the second. */
typedef struct sides {
  held *le, *ge;
  size_t nle, nge, caple, capge;
} sides;

typedef struct grow {
  oc_btile *t;
  const oc_bimage *im;
  size_t nim;
  size_t *near; /* the images meeting the cluster's box (places in cand) */
  /* the images meeting the box clo .. chi (the cluster's box grown by
  ** CACHE_GROW k r when last made), in the order of im: may_join looks
  ** through these only */
  const oc_bimage **cand;
  size_t ncand;
  /* per candidate: the members strictly above its plane and below it (a
  ** disc with all members on q's side cannot separate q from them) */
  uint32_t *above, *below;
  sides *sd; /* per candidate */
  int nomem;
  double clo[3], chi[3];
  uint32_t *mem; /* members, in order of joining */
  size_t nm;
  double lo[3], hi[3];
} grow;

/* The signed distance of p to D's plane, as oc_bimage_cuts has it. */
static double side(const oc_bimage *D, const double *p) {
  return (p[0] - D->c.x) * D->n.x + (p[1] - D->c.y) * D->n.y +
         (p[2] - D->c.z) * D->n.z;
}

/* Counts member p on the sides of candidate d's plane. */
static void count(grow *w, size_t d, uint32_t m, const double *p) {
  double a = side(w->cand[d], p);
  sides *sd = &w->sd[d];
  w->above[d] += a > 0;
  w->below[d] += a < 0;
  if (!(a > 0)) {
    if (!OC_GROW(sd->le, sd->nle, sd->caple, 1))
      w->nomem = 1;
    else
      sd->le[sd->nle++] = (held){a, m};
  }
  if (!(a < 0)) {
    if (!OC_GROW(sd->ge, sd->nge, sd->capge, 1))
      w->nomem = 1;
    else
      sd->ge[sd->nge++] = (held){a, m};
  }
}

/* Remakes the list of candidate images for the box lo .. hi grown. */
static void cache(grow *w, const double *lo, const double *hi) {
  double g = CACHE_GROW * w->t->pp.neighbour * w->t->pp.radius;
  for (int a = 0; a < 3; a++) {
    w->clo[a] = lo[a] - g;
    w->chi[a] = hi[a] + g;
  }
  w->ncand = 0;
  for (size_t d = 0; d < w->nim; d++) {
    const oc_aabb *b = &w->im[d].box;
    if (b->lo.x > w->chi[0] || b->hi.x < w->clo[0] || b->lo.y > w->chi[1] ||
        b->hi.y < w->clo[1] || b->lo.z > w->chi[2] || b->hi.z < w->clo[2])
      continue;
    w->above[w->ncand] = w->below[w->ncand] = 0;
    w->sd[w->ncand].nle = w->sd[w->ncand].nge = 0;
    w->cand[w->ncand++] = &w->im[d];
  }
  for (size_t d = 0; d < w->ncand; d++)
    for (size_t m = 0; m < w->nm; m++)
      count(w, d, w->mem[m], w->t->unwrap + 3 * (size_t)w->mem[m]);
}

/* May the point at q (unwrapped) join the cluster? */
static int may_join(grow *w, const double *q) {
  double lo[3], hi[3],
      most = w->t->pp.size - 2 * w->t->pp.neighbour * w->t->pp.radius;
  for (int a = 0; a < 3; a++) {
    lo[a] = q[a] < w->lo[a] ? q[a] : w->lo[a];
    hi[a] = q[a] > w->hi[a] ? q[a] : w->hi[a];
    if (hi[a] - lo[a] > most) return 0;
  }
  if (lo[0] < w->clo[0] || lo[1] < w->clo[1] || lo[2] < w->clo[2] ||
      hi[0] > w->chi[0] || hi[1] > w->chi[1] || hi[2] > w->chi[2])
    cache(w, lo, hi);
  size_t nn = 0;
  for (size_t d = 0; d < w->ncand; d++) {
    const oc_aabb *b = &w->cand[d]->box;
    if (b->lo.x > hi[0] || b->hi.x < lo[0] || b->lo.y > hi[1] ||
        b->hi.y < lo[1] || b->lo.z > hi[2] || b->hi.z < lo[2])
      continue;
    /* the disc's plane must cross the box too */
    const oc_bimage *D = w->cand[d];
    double ctr = (0.5 * (lo[0] + hi[0]) - D->c.x) * D->n.x +
                 (0.5 * (lo[1] + hi[1]) - D->c.y) * D->n.y +
                 (0.5 * (lo[2] + hi[2]) - D->c.z) * D->n.z;
    double ext =
        0.5 * (fabs(D->n.x) * (hi[0] - lo[0]) + fabs(D->n.y) * (hi[1] - lo[1]) +
               fabs(D->n.z) * (hi[2] - lo[2]));
    if (fabs(ctr) > ext) continue;
    w->near[nn++] = d;
  }
  /* per disc image: q's side once, none of the members when all are on
  ** that side, else only those on the other side (or on the plane) get
  ** the full test (oc_bimage_cuts' arithmetic) */
  for (size_t d = 0; d < nn; d++) {
    size_t k = w->near[d];
    const oc_bimage *D = w->cand[k];
    double b = side(D, q);
    if ((b > 0 && w->above[k] == w->nm) || (b < 0 && w->below[k] == w->nm))
      continue;
    if (b > 0 || b < 0) {
      /* the members on the other side or on the plane, their distances
      ** as side() gave them when they joined */
      const held *h = b > 0 ? w->sd[k].le : w->sd[k].ge;
      size_t nh = b > 0 ? w->sd[k].nle : w->sd[k].nge;
      for (size_t m = 0; m < nh; m++)
        if (oc_bimage_cuts_at(D, w->t->unwrap + 3 * (size_t)h[m].m, q, h[m].a,
                              b))
          return 0;
      continue;
    }
    for (size_t m = 0; m < w->nm; m++) {
      const double *p = w->t->unwrap + 3 * (size_t)w->mem[m];
      if (oc_bimage_cuts_at(D, p, q, side(D, p), b)) return 0;
    }
  }
  return 1;
}

static void join(grow *w, uint32_t i, uint32_t c, const double *q) {
  double *u = w->t->unwrap + 3 * (size_t)i;
  for (int a = 0; a < 3; a++) {
    u[a] = q[a];
    w->lo[a] = q[a] < w->lo[a] ? q[a] : w->lo[a];
    w->hi[a] = q[a] > w->hi[a] ? q[a] : w->hi[a];
  }
  w->t->label[i] = c;
  w->mem[w->nm++] = i;
  for (size_t d = 0; d < w->ncand; d++)
    count(w, d, i, u);
}

/* Grows cluster c from point i. */
static void flood(grow *w, uint32_t i, uint32_t c, uint32_t *tried) {
  oc_btile *t = w->t;
  const oc_bgraph *g = &t->g;
  double s = t->pp.size;
  w->nm = 0;
  for (int a = 0; a < 3; a++)
    w->lo[a] = w->hi[a] = t->pts[3 * (size_t)i + a];
  cache(w, w->lo, w->hi);
  join(w, i, c, t->pts + 3 * (size_t)i);
  for (size_t head = 0; head < w->nm; head++) {
    uint32_t u = w->mem[head];
    const double *pu = t->unwrap + 3 * (size_t)u;
    for (size_t k = g->start[u]; k < g->start[u + 1]; k++) {
      uint32_t e = g->adj[k];
      if (g->cut[e]) continue;
      uint32_t v = g->a[e] == u ? g->b[e] : g->a[e];
      if (t->label[v] != NONE || tried[v] == c) continue;
      double sg = g->a[e] == u ? 1 : -1, q[3];
      const double *pv = t->pts + 3 * (size_t)v;
      for (int a = 0; a < 3; a++) {
        /* the exact image of v nearest u */
        double x = pu[a] + sg * g->v[3 * e + a];
        q[a] = pv[a] + s * round((x - pv[a]) / s);
      }
      if (may_join(w, q))
        join(w, v, c, q);
      else
        tried[v] = c;
    }
  }
}

int oc_bclusters_make(oc_btile *t, oc_error *err) {
  size_t n = t->np;
  double s = t->pp.size;
  grow w = {.t = t};
  uint32_t *order = malloc((n ? n : 1) * sizeof *order);
  uint32_t *tried = malloc((n ? n : 1) * sizeof *tried);
  t->label = malloc((n ? n : 1) * sizeof *t->label);
  t->unwrap = malloc((n ? n : 1) * 3 * sizeof *t->unwrap);
  w.mem = malloc((n ? n : 1) * sizeof *w.mem);
  oc_bimage *im = NULL;
  int rc = OC_ENOMEM;
  if (!order || !tried || !t->label || !t->unwrap || !w.mem) goto done;
  oc_aabb in = {{-s, -s, -s}, {2 * s, 2 * s, 2 * s}};
  if ((rc = oc_bdiscs_images(t, in, &im, &w.nim, err))) goto done;
  rc = OC_ENOMEM;
  w.im = im;
  w.near = malloc((w.nim ? w.nim : 1) * sizeof *w.near);
  w.cand = malloc((w.nim ? w.nim : 1) * sizeof *w.cand);
  w.above = malloc((w.nim ? w.nim : 1) * sizeof *w.above);
  w.below = malloc((w.nim ? w.nim : 1) * sizeof *w.below);
  w.sd = calloc(w.nim ? w.nim : 1, sizeof *w.sd);
  if (!w.near || !w.cand || !w.above || !w.below || !w.sd) goto done;
  for (size_t i = 0; i < n; i++) {
    order[i] = (uint32_t)i;
    t->label[i] = NONE;
    tried[i] = NONE;
  }
  oc_rng u = oc_rng_stream(t->pp.seed, KEY_ORDER);
  for (size_t i = n; i > 1; i--) {
    size_t j = (size_t)(((unsigned __int128)oc_rng_next(&u) * i) >> 64);
    uint32_t x = order[i - 1];
    order[i - 1] = order[j];
    order[j] = x;
  }
  t->ncl = 0;
  for (size_t k = 0; k < n && !w.nomem; k++)
    if (t->label[order[k]] == NONE)
      flood(&w, order[k], (uint32_t)t->ncl++, tried);
  if (!w.nomem) rc = 0;
done:
  if (rc == OC_ENOMEM) oc_seterr(err, OC_ENOMEM, "out of memory for clusters");
  free(order);
  free(tried);
  free(w.mem);
  free(w.near);
  free(w.cand);
  free(w.above);
  free(w.below);
  for (size_t d = 0; w.sd && d < w.nim; d++) {
    free(w.sd[d].le);
    free(w.sd[d].ge);
  }
  free(w.sd);
  free(im);
  return rc;
}
