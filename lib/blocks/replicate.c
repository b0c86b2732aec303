/*
** replicate.c — the replication operator (Paris et al. 2020, section 5):
** f~ = max(f, t), t(p) = max_i b_i(p - s c_i) over the instances (c_i a
** tile cell, b_i a block of a tile), a node kind over the terrain.
**
** Presence is decided once, when the node is built: every block of every
** tile, in every cell of the tile lattice near the terrain's bounds, is an
** instance when a majority of its anchors (the centroid and up to
** anchors - 1 hull vertices, evenly picked) meet the criteria, with f and
** its gradient from the terrain compiled at threshold T:
**  - distance estimate (f - T) / |grad f| (> 0 inside) in [va, vb];
**  - steep walls only: |g . z| < slope, g the unit gradient;
**  - with a geology node, its value (resistance) in the tile's range.
** The instances are kept in a uniform grid over their supports (cells of
** GRID_CELL = 4 metres or more, about a block: 2 m cells took 0.53 MB
** instead of 0.22 MB for bench_blocks' sea spire, for a query 5 % faster),
** so a query visits only the instances of its
** cell, and never evaluates presence. Blocks straddling a tile's faces are
** instances of the cell of their centroid and reach into the next cells
** as they are.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "field/kind.h"

#define GRID_CELL 4.0
#define GRID_MAX 4000000.0
/* cells x blocks examined at most */
#define WORK_MAX 5e7
/* tiles at most: each needs sigma's 4 constants in the op's parameters */
#define TILES_MAX 7

typedef struct rinst {
  uint32_t b;    /* block */
  double off[3]; /* s c */
  oc_aabb box;   /* support, shifted */
} rinst;

typedef struct rdata {
  size_t nb;
  oc_bfield **bf;
  uint32_t *tile; /* tile of each block */
  size_t ntile;
  double *W; /* width of each tile */
  size_t ni;
  rinst *in;
  oc_aabb all; /* union of the instances' supports */
  double g0[3], gc;
  int gn[3];
  uint32_t *gstart; /* (the grid's entries are checked < 2^32) */
  uint32_t *gidx;
} rdata;

static void rdata_free(void *data) {
  rdata *r = data;
  if (!r) return;
  for (size_t i = 0; i < r->nb && r->bf; i++)
    free(r->bf[i]);
  free(r->bf);
  free(r->tile);
  free(r->W);
  free(r->in);
  free(r->gstart);
  free(r->gidx);
  free(r);
}

void oc_replicate_defaults(oc_replicate_params *rp) {
  memset(rp, 0, sizeof *rp);
  rp->slope = 1;
  rp->va = -1;
  rp->vb = 1;
  rp->anchors = 9;
  rp->inset = 0;
}

/* ---- grid ---------------------------------------------------------------- */

static void cell_range(const rdata *r, const oc_aabb *b, int c0[3], int c1[3]) {
  const double lo[3] = {b->lo.x, b->lo.y, b->lo.z},
               hi[3] = {b->hi.x, b->hi.y, b->hi.z};
  for (int a = 0; a < 3; a++) {
    double u0 = floor((lo[a] - r->g0[a]) / r->gc),
           u1 = floor((hi[a] - r->g0[a]) / r->gc);
    c0[a] = (int)fmax(0, fmin(u0, r->gn[a] - 1));
    c1[a] = (int)fmax(0, fmin(u1, r->gn[a] - 1));
  }
}

static size_t gcell(const rdata *r, int x, int y, int z) {
  return ((size_t)z * r->gn[1] + y) * r->gn[0] + x;
}

static int grid_make(rdata *r) {
  if (!r->ni) return 0;
  r->all = r->in[0].box;
  for (size_t i = 1; i < r->ni; i++) {
    const oc_aabb *b = &r->in[i].box;
    r->all.lo =
        (oc_vec3){fmin(r->all.lo.x, b->lo.x), fmin(r->all.lo.y, b->lo.y),
                  fmin(r->all.lo.z, b->lo.z)};
    r->all.hi =
        (oc_vec3){fmax(r->all.hi.x, b->hi.x), fmax(r->all.hi.y, b->hi.y),
                  fmax(r->all.hi.z, b->hi.z)};
  }
  double ext[3] = {r->all.hi.x - r->all.lo.x, r->all.hi.y - r->all.lo.y,
                   r->all.hi.z - r->all.lo.z};
  r->g0[0] = r->all.lo.x, r->g0[1] = r->all.lo.y, r->g0[2] = r->all.lo.z;
  r->gc = GRID_CELL;
  while ((ext[0] / r->gc + 1) * (ext[1] / r->gc + 1) * (ext[2] / r->gc + 1) >
         GRID_MAX)
    r->gc *= 2;
  for (int a = 0; a < 3; a++)
    r->gn[a] = (int)floor(ext[a] / r->gc) + 1;
  size_t nc = (size_t)r->gn[0] * r->gn[1] * r->gn[2];
  r->gstart = calloc(nc + 1, sizeof *r->gstart);
  if (!r->gstart) return OC_ENOMEM;
  size_t total = 0;
  for (int pass = 0; pass < 2; pass++) {
    uint32_t *fill = NULL;
    if (pass == 1) {
      if (total > UINT32_MAX) return OC_ENOMEM;
      for (size_t c = 0; c < nc; c++)
        r->gstart[c + 1] += r->gstart[c];
      r->gidx = malloc((r->gstart[nc] ? r->gstart[nc] : 1) * sizeof *r->gidx);
      fill = calloc(nc, sizeof *fill);
      if (!r->gidx || !fill) {
        free(fill);
        return OC_ENOMEM;
      }
    }
    for (size_t i = 0; i < r->ni; i++) {
      int c0[3], c1[3];
      cell_range(r, &r->in[i].box, c0, c1);
      for (int z = c0[2]; z <= c1[2]; z++)
        for (int y = c0[1]; y <= c1[1]; y++)
          for (int x = c0[0]; x <= c1[0]; x++) {
            size_t c = gcell(r, x, y, z);
            if (pass == 0)
              r->gstart[c + 1] += total++ < UINT32_MAX;
            else
              r->gidx[r->gstart[c] + fill[c]++] = (uint32_t)i;
          }
    }
    free(fill);
  }
  return 0;
}

/* ---- the kind ------------------------------------------------------------ */

static int in_box(const oc_aabb *b, oc_vec3 p) {
  return p.x >= b->lo.x && p.x <= b->hi.x && p.y >= b->lo.y && p.y <= b->hi.y &&
         p.z >= b->lo.z && p.z <= b->hi.z;
}

static int boxes_meet(const oc_aabb *a, const oc_aabb *b) {
  return a->lo.x <= b->hi.x && b->lo.x <= a->hi.x && a->lo.y <= b->hi.y &&
         b->lo.y <= a->hi.y && a->lo.z <= b->hi.z && b->lo.z <= a->hi.z;
}

static int rep_compile(oc_kcompile *c, oc_error *err) {
  const rdata *r = c->data;
  (void)err;
  const oc_kinfo *k = &c->kid[0];
  c->par[0] = c->T;
  double lip = k->lip, lipt = 0;
  for (size_t t = 0; t < r->ntile; t++) {
    oc_bfield_sigma(c->T, r->W[t], c->par + 1 + OC_BSIGMA_N * t);
    lipt = fmax(lipt, c->par[1 + OC_BSIGMA_N * t + 3]);
  }
  lip = fmax(lip, lipt);
  c->npar = 1 + OC_BSIGMA_N * r->ntile;
  /* inset: the terrain sinks by k m(t), k = inset L (inset metres where
  ** its slope is its bound), m = min(1, t / T); Lipschitz L + k lip_t / T */
  double kin =
      c->node_npar ? c->node_par[0] * (isfinite(k->lip) ? k->lip : 1) : 0;
  c->par[c->npar++] = kin;
  if (kin > 0) lip = fmax(lip, k->lip + kin * lipt / c->T);
  c->info.lo = fmin(k->lo, 0);
  c->info.hi = fmax(k->hi, 2 * c->T);
  c->info.lip = lip;
  c->info.box = k->box;
  if (r->ni) {
    c->info.box.lo = (oc_vec3){fmin(k->box.lo.x, r->all.lo.x),
                               fmin(k->box.lo.y, r->all.lo.y),
                               fmin(k->box.lo.z, r->all.lo.z)};
    c->info.box.hi = (oc_vec3){fmax(k->box.hi.x, r->all.hi.x),
                               fmax(k->box.hi.y, r->all.hi.y),
                               fmax(k->box.hi.z, r->all.hi.z)};
  }
  return OC_OK;
}

/* max(f, the blocks of the cell at p); *g (when g) becomes the gradient of
** the first block above f. */
static double top(const oc_kctx *k, const rdata *r, size_t cell, oc_vec3 p,
                  double f, oc_vec3 *g) {
  for (uint32_t m = r->gstart[cell]; m < r->gstart[cell + 1]; m++) {
    const rinst *in = &r->in[r->gidx[m]];
    if (!in_box(&in->box, p)) continue;
    oc_vec3 lp = {p.x - in->off[0], p.y - in->off[1], p.z - in->off[2]}, gb;
    const double *sp = k->par + 1 + OC_BSIGMA_N * r->tile[in->b];
    double v = oc_bfield_eval(r->bf[in->b], sp, lp, g ? &gb : NULL);
    if (v > f) {
      f = v;
      if (g) *g = gb;
    }
  }
  return f;
}

static double rep_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const rdata *r = k->data;
  double f = oc_child_eval(k, 0, p, g);
  if (!r->ni || !in_box(&r->all, p)) return f;
  int c[3];
  const double q[3] = {p.x, p.y, p.z};
  for (int a = 0; a < 3; a++) {
    c[a] = (int)floor((q[a] - r->g0[a]) / r->gc);
    if (c[a] < 0 || c[a] >= r->gn[a]) return f;
  }
  size_t cell = gcell(r, c[0], c[1], c[2]);
  double kin = k->par[1 + OC_BSIGMA_N * r->ntile];
  if (!(kin > 0)) return top(k, r, cell, p, f, g);
  /* with an inset: t the largest block at p, f~ = max(f - kin m, t),
  ** m = min(1, t / T): the terrain sinks where blocks are and the joints
  ** between them stay open */
  double T = k->par[0];
  oc_vec3 gt = {0, 0, 0};
  double t = top(k, r, cell, p, 0, g ? &gt : NULL);
  if (!(t > 0)) return f;
  double m = t < T ? t / T : 1, fs = f - kin * m;
  if (t > fs) {
    if (g) *g = gt;
    return t;
  }
  if (g && t < T)
    *g = (oc_vec3){g->x - kin / T * gt.x, g->y - kin / T * gt.y,
                   g->z - kin / T * gt.z};
  return fs;
}

static int rep_zero_in(const oc_kctx *k, const oc_aabb *b) {
  const rdata *r = k->data;
  if (!oc_child_zero_in(k, 0, b)) return 0;
  if (!r->ni || !boxes_meet(&r->all, b)) return 1;
  int c0[3], c1[3];
  cell_range(r, b, c0, c1);
  for (int z = c0[2]; z <= c1[2]; z++)
    for (int y = c0[1]; y <= c1[1]; y++)
      for (int x = c0[0]; x <= c1[0]; x++) {
        size_t c = gcell(r, x, y, z);
        for (uint32_t m = r->gstart[c]; m < r->gstart[c + 1]; m++)
          if (boxes_meet(&r->in[r->gidx[m]].box, b)) return 0;
      }
  return 1;
}

static int rep_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  const rdata *r = k->data;
  oc_child_spans(k, 0, f, q);
  if (!r->ni) return 0;
  oc_aabb b = {{f->x0, f->y0, r->all.lo.z}, {f->x1, f->y1, r->all.hi.z}};
  if (!boxes_meet(&r->all, &b)) return 0;
  int c0[3], c1[3];
  cell_range(r, &b, c0, c1);
  for (int z = c0[2]; z <= c1[2]; z++)
    for (int y = c0[1]; y <= c1[1]; y++)
      for (int x = c0[0]; x <= c1[0]; x++) {
        size_t c = gcell(r, x, y, z);
        for (uint32_t m = r->gstart[c]; m < r->gstart[c + 1]; m++) {
          const oc_aabb *ib = &r->in[r->gidx[m]].box;
          if (boxes_meet(ib, &b)) oc_col_add(q, ib->lo.z, ib->hi.z);
        }
      }
  return 0;
}

static const oc_kind_def replicate_kind = {
    .name = "replicate",
    .compile = rep_compile,
    .eval = rep_eval,
    .zero_in = rep_zero_in,
    .column = rep_column,
    .release = rdata_free,
};

/* ---- presence ------------------------------------------------------------ */

typedef struct crit {
  const oc_program *terrain, *geology;
  double T, va, vb, slope, lo, hi;
  int (*present)(void *ctx, oc_vec3 anchor);
  void *ctx;
} crit;

static int anchor_ok(const crit *c, oc_vec3 a) {
  if (c->present) return c->present(c->ctx, a) != 0;
  oc_vec3 g;
  double f = oc_program_gradient(c->terrain, a, &g);
  double gl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
  if (!(gl > 0)) return 0;
  double d = (f - c->T) / gl;
  if (!(d >= c->va && d <= c->vb)) return 0;
  if (!(fabs(g.z) / gl < c->slope)) return 0;
  if (c->geology) {
    double e = oc_program_eval(c->geology, a);
    if (!(e >= c->lo && e <= c->hi)) return 0;
  }
  return 1;
}

static int push_inst(rdata *r, size_t *cap, uint32_t b, const double *off,
                     oc_aabb box) {
  if (r->ni == *cap) {
    size_t nc = *cap ? 2 * *cap : 256;
    rinst *v = realloc(r->in, nc * sizeof *v);
    if (!v) return OC_ENOMEM;
    r->in = v;
    *cap = nc;
  }
  rinst *in = &r->in[r->ni++];
  in->b = b;
  memcpy(in->off, off, sizeof in->off);
  in->box = box;
  return 0;
}

static int place(rdata *r, const oc_replicate_params *rp, crit *c, oc_aabb tb,
                 oc_error *err) {
  size_t cap = 0, b0 = 0;
  for (size_t t = 0; t < rp->ntiles; t++) {
    const oc_btile *tile = rp->tiles[t].tile;
    double s = tile->pp.size;
    c->lo = rp->tiles[t].lo;
    c->hi = rp->tiles[t].hi;
    int k0[3], k1[3];
    const double lo[3] = {tb.lo.x, tb.lo.y, tb.lo.z},
                 hi[3] = {tb.hi.x, tb.hi.y, tb.hi.z};
    double cells = 1;
    for (int a = 0; a < 3; a++) {
      k0[a] = (int)floor(lo[a] / s) - 1;
      k1[a] = (int)floor(hi[a] / s) + 1;
      cells *= k1[a] - k0[a] + 1;
    }
    if (cells * (double)tile->nb > WORK_MAX)
      return oc_seterr(err, OC_EINVAL,
                       "the terrain (%g x %g x %g) is too large for "
                       "'tiles[%zu]' of size %g (%g cells x %zu blocks, at "
                       "most %g)",
                       hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], t + 1, s,
                       cells, tile->nb, WORK_MAX);
    for (int z = k0[2]; z <= k1[2]; z++)
      for (int y = k0[1]; y <= k1[1]; y++)
        for (int x = k0[0]; x <= k1[0]; x++) {
          double off[3] = {x * s, y * s, z * s};
          for (size_t i = 0; i < tile->nb; i++) {
            const oc_bblock *bl = &tile->block[i];
            oc_aabb sb = oc_bfield_support(r->bf[b0 + i]);
            sb.lo =
                (oc_vec3){sb.lo.x + off[0], sb.lo.y + off[1], sb.lo.z + off[2]};
            sb.hi =
                (oc_vec3){sb.hi.x + off[0], sb.hi.y + off[1], sb.hi.z + off[2]};
            if (!boxes_meet(&sb, &tb)) continue;
            int na = rp->anchors, votes = 0;
            for (int a = 0; a < na; a++) {
              oc_vec3 p = bl->centroid;
              if (a > 0 && bl->nvert) {
                size_t v = (size_t)(a - 1) * bl->nvert / (size_t)(na - 1);
                const double *q = bl->vert + 3 * v;
                p = (oc_vec3){q[0], q[1], q[2]};
              }
              p = (oc_vec3){p.x + off[0], p.y + off[1], p.z + off[2]};
              votes += anchor_ok(c, p);
            }
            if (2 * votes > na &&
                push_inst(r, &cap, (uint32_t)(b0 + i), off, sb))
              return oc_seterr(err, OC_ENOMEM, "out of memory for instances");
          }
        }
    b0 += tile->nb;
  }
  return 0;
}

oc_node *oc_blocks_replicate(oc_node *terrain, const oc_replicate_params *rp,
                             oc_error *err) {
  if (!terrain || !rp) {
    oc_seterr(err, OC_EINVAL, "blocks.replicate needs a terrain and params");
    return NULL;
  }
  if (rp->ntiles < 1 || rp->ntiles > TILES_MAX || !rp->tiles) {
    oc_seterr(err, OC_EINVAL, "'tiles' must hold 1 .. %d tiles (got %zu)",
              TILES_MAX, rp->ntiles);
    return NULL;
  }
  for (size_t t = 0; t < rp->ntiles; t++)
    if (!rp->tiles[t].tile || !(rp->tiles[t].lo <= rp->tiles[t].hi)) {
      oc_seterr(err, OC_EINVAL,
                "'tiles[%zu]' needs a tile and resistance {lo, hi} with lo "
                "<= hi",
                t + 1);
      return NULL;
    }
  if (!(rp->va <= rp->vb) || !isfinite(rp->va) || !isfinite(rp->vb)) {
    oc_seterr(err, OC_EINVAL,
              "'distance' must be {va, vb} with va <= vb (got %g, %g)", rp->va,
              rp->vb);
    return NULL;
  }
  if (!(rp->slope > 0) || !isfinite(rp->slope)) {
    oc_seterr(err, OC_EINVAL, "'slope' must be > 0 (got %g)", rp->slope);
    return NULL;
  }
  if (rp->anchors < 1 || rp->anchors > 64) {
    oc_seterr(err, OC_EINVAL, "'anchors' must be in 1 .. 64 (got %d)",
              rp->anchors);
    return NULL;
  }
  if (!(rp->inset >= 0) || !isfinite(rp->inset)) {
    oc_seterr(err, OC_EINVAL, "'inset' must be >= 0 (got %g)", rp->inset);
    return NULL;
  }
  oc_compile_options co = {rp->threshold, 0};
  oc_program *tp = oc_compile(terrain, &co, err);
  if (!tp) return NULL;
  oc_program *gp = rp->geology ? oc_compile(rp->geology, &co, err) : NULL;
  rdata *r = calloc(1, sizeof *r);
  oc_node *out = NULL;
  oc_aabb tb = oc_program_bounds(tp);
  if (!r || (rp->geology && !gp)) goto done;
  if (rp->where) tb = *rp->where; /* instead of the terrain's bounds */
  if (!isfinite(tb.lo.x) || !isfinite(tb.lo.y) || !isfinite(tb.lo.z) ||
      !isfinite(tb.hi.x) || !isfinite(tb.hi.y) || !isfinite(tb.hi.z)) {
    oc_seterr(err, OC_EINVAL, "the terrain's bounds must be finite");
    goto done;
  }
  for (size_t t = 0; t < rp->ntiles; t++)
    r->nb += rp->tiles[t].tile->nb;
  r->ntile = rp->ntiles;
  r->bf = calloc(r->nb ? r->nb : 1, sizeof *r->bf);
  r->tile = malloc((r->nb ? r->nb : 1) * sizeof *r->tile);
  r->W = malloc(r->ntile * sizeof *r->W);
  if (!r->bf || !r->tile || !r->W) goto nomem;
  for (size_t t = 0, b = 0; t < rp->ntiles; t++) {
    const oc_btile *tile = rp->tiles[t].tile;
    r->W[t] = tile->pp.width;
    for (size_t i = 0; i < tile->nb; i++, b++) {
      r->tile[b] = (uint32_t)t;
      r->bf[b] =
          oc_bfield_new(&tile->block[i], tile->pp.rounding, tile->pp.width);
      if (!r->bf[b]) goto nomem;
    }
  }
  crit c = {tp,        gp,       oc_program_threshold(tp),
            rp->va,    rp->vb,   rp->slope,
            -INFINITY, INFINITY, rp->present,
            rp->ctx};
  if (place(r, rp, &c, tb, err)) goto done;
  if (grid_make(r)) goto nomem;
  out = oc_kind_node(&replicate_kind, &terrain, 1, &rp->inset, 1, r, err);
  r = NULL; /* the node owns it, also on failure */
  goto done;
nomem:
  oc_seterr(err, OC_ENOMEM, "out of memory for blocks.replicate");
done:
  rdata_free(r);
  oc_program_free(tp);
  oc_program_free(gp);
  return out;
}

int oc_blocks_instances(const oc_node *n, size_t *count) {
  if (oc_node_def(n) != &replicate_kind) return 0;
  *count = ((const rdata *)oc_node_data(n))->ni;
  return 1;
}

int oc_blocks_instance(const oc_node *n, size_t i, size_t *block,
                       double off[3]) {
  if (oc_node_def(n) != &replicate_kind) return 0;
  const rdata *r = oc_node_data(n);
  if (i >= r->ni) return 0;
  *block = r->in[i].b;
  memcpy(off, r->in[i].off, sizeof r->in[i].off);
  return 1;
}

int oc_blocks_memory(const oc_node *n, size_t *bytes) {
  if (oc_node_def(n) != &replicate_kind) return 0;
  const rdata *r = oc_node_data(n);
  size_t b = sizeof *r + r->nb * (sizeof *r->bf + sizeof *r->tile) +
             r->ntile * sizeof *r->W + r->ni * sizeof *r->in;
  for (size_t i = 0; i < r->nb; i++)
    b += oc_bfield_bytes(r->bf[i]);
  if (r->gstart) {
    size_t nc = (size_t)r->gn[0] * r->gn[1] * r->gn[2];
    b += (nc + 1) * sizeof *r->gstart + r->gstart[nc] * sizeof *r->gidx;
  }
  *bytes = b;
  return 1;
}
