/*
** compile.c — turns a node DAG into a flat evaluation program.
**
** Each distinct node becomes one op (instancing costs nothing). Nested
** blends are flattened into one n-ary blend, with multiplicities and scale
** factors pushed down (a sum is linear); nested unions and intersections
** are flattened likewise; a chain of differences (a - b) - c becomes
** a - (b | c). Blends and unions get a BVH over their bounded children.
** Bounds of the support, value ranges and Lipschitz bounds are computed
** bottom-up here, because several depend on the threshold T.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/falloff.h"
#include "core/grow.h"
#include "core/noise.h"
#include "core/pmap.h"
#include "core/vec.h"
#include "field/node.h"
#include "field/bvhwalk.h"
#include "field/prim.h"
#include "field/program.h"

/* Groups with at least this many plain point children store them inline
** in single precision; smaller groups keep every child as a double op. */
#define INLINE_MIN 32

/* 1 when arr (n used, capacity cap) has room for need more (core/grow.h) */
#define GROW OC_GROW

/* ---- compiler state -------------------------------------------------- */

typedef struct info {
  oc_aabb box;   /* support */
  double lo, hi; /* value range (contains 0 for compact nodes) */
  double lip;    /* Lipschitz bound */
  int depth;
} info;

typedef struct comp {
  oc_program *P;
  size_t capops, cappar, capkids, capent, capbvh, capext;
  info *inf; /* parallel to ops */
  size_t capinf;
  oc_pmap memo;
  double T;
  int nobvh;
  oc_error *err;
  int depth;
} comp;

static int nomem(comp *c) {
  return oc_seterr(c->err, OC_ENOMEM, "out of memory while compiling");
}

static uint32_t new_op(comp *c, oc_kind kind) {
  oc_program *P = c->P;
  if (P->nops >= OC_NONE - 1) return OC_NONE;
  if (!GROW(P->ops, P->nops, c->capops, 1) ||
      !GROW(c->inf, P->nops, c->capinf, 1))
    return OC_NONE;
  oc_op *op = &P->ops[P->nops];
  memset(op, 0, sizeof *op);
  op->kind = (uint8_t)kind;
  op->bvh = OC_NONE;
  memset(&c->inf[P->nops], 0, sizeof(info));
  return P->nops++;
}

static uint32_t add_par(comp *c, const double *v, size_t n) {
  oc_program *P = c->P;
  if (!GROW(P->par, P->npar, c->cappar, n)) return OC_NONE;
  uint32_t at = (uint32_t)P->npar;
  if (v) memcpy(P->par + at, v, n * sizeof *v);
  P->npar += n;
  return at;
}

static uint32_t add_kids(comp *c, const uint32_t *k, size_t n) {
  oc_program *P = c->P;
  if (!GROW(P->kids, P->nkids, c->capkids, n ? n : 1)) return OC_NONE;
  uint32_t at = (uint32_t)P->nkids;
  if (n) memcpy(P->kids + at, k, n * sizeof *k);
  P->nkids += n;
  return at;
}

static void set_box(comp *c, uint32_t op, oc_aabb b) {
  c->inf[op].box = b;
  oc_box_to_float(b, c->P->ops[op].lo, c->P->ops[op].hi);
}

/* Largest singular value of the linear part of a 3x4 matrix, from the
** eigenvalues of A^T A by cyclic Jacobi rotations. */
static double sigma_max(const double *m) {
  double a[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0;
      for (int k = 0; k < 3; k++)
        s += m[k * 4 + i] * m[k * 4 + j];
      a[i][j] = s;
    }
  for (int sweep = 0; sweep < 50; sweep++) {
    double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
    if (off < 1e-300) break;
    for (int p = 0; p < 2; p++)
      for (int q = p + 1; q < 3; q++) {
        if (a[p][q] == 0) continue;
        double th = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        double t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
        double cs = 1 / sqrt(t * t + 1), sn = t * cs;
        for (int k = 0; k < 3; k++) { /* columns */
          double kp = a[k][p], kq = a[k][q];
          a[k][p] = cs * kp - sn * kq;
          a[k][q] = sn * kp + cs * kq;
        }
        for (int k = 0; k < 3; k++) { /* rows */
          double pk = a[p][k], qk = a[q][k];
          a[p][k] = cs * pk - sn * qk;
          a[q][k] = sn * pk + cs * qk;
        }
      }
  }
  double e = fmax(a[0][0], fmax(a[1][1], a[2][2]));
  /* a relative margin covers the rounding of the iteration */
  return sqrt(fmax(e, 0)) * (1 + 1e-12);
}

/* Exact box of an affine image of a box, by interval arithmetic. */
static oc_aabb xform_box(const double *m, oc_aabb b) {
  if (oc_aabb_is_empty(b)) return b;
  oc_aabb r;
  const double *lo = &b.lo.x, *hi = &b.hi.x;
  double *rl = &r.lo.x, *rh = &r.hi.x;
  for (int i = 0; i < 3; i++) {
    double l = m[i * 4 + 3], h = m[i * 4 + 3];
    for (int j = 0; j < 3; j++) {
      double k = m[i * 4 + j];
      if (k == 0) continue;
      double x = k * lo[j], y = k * hi[j];
      l += fmin(x, y);
      h += fmax(x, y);
    }
    rl[i] = l;
    rh[i] = h;
  }
  return r;
}

static double tmax_of(int octaves) {
  return oc_turb3_max(octaves);
}

/* ---- primitives ------------------------------------------------------ */

static void prim_info(comp *c, uint32_t op, oc_kind kind, const double *par,
                      double reach) {
  double E = par[OC_P_E];
  info *in = &c->inf[op];
  in->lo = fmin(0, E);
  in->hi = fmax(0, E);
  set_box(c, op, oc_aabb_grow(oc_prim_skeleton_box(kind, par), reach));
}

static uint32_t compile_prim(comp *c, const oc_node *n) {
  uint32_t op = new_op(c, n->kind);
  if (op == OC_NONE) return op;
  size_t np = oc_prim_npar(n);
  uint32_t at = add_par(c, NULL, np);
  if (at == OC_NONE) return OC_NONE;
  double *par = c->P->par + at;
  oc_prim_pack(n, par);
  c->P->ops[op].par = at;
  prim_info(c, op, n->kind, par, par[OC_P_R]);
  c->inf[op].lip = fabs(par[OC_P_E]) * OC_FALLOFF_LIPSCHITZ / par[OC_P_R];
  return op;
}

/* Turbulence and noise-driven ops keep their noise packed
** (oc_noise_pack). */
static uint32_t pack_noise(comp *c, const oc_noise *nz) {
  double v[OC_NOISE_NPAR];
  oc_noise_pack(nz, v);
  return add_par(c, v, OC_NOISE_NPAR);
}

static uint32_t compile_turb(comp *c, const oc_node *n) {
  uint32_t op = new_op(c, OC_K_TURB);
  if (op == OC_NONE) return op;
  uint32_t at = pack_noise(c, &n->noise);
  if (at == OC_NONE) return OC_NONE;
  c->P->ops[op].par = at;
  const oc_noise *nz = &n->noise;
  double a = nz->offset, b = nz->offset + nz->amplitude * tmax_of(nz->octaves);
  c->inf[op].lo = fmin(a, b);
  c->inf[op].hi = fmax(a, b);
  set_box(c, op, oc_aabb_all());
  c->inf[op].lip =
      fabs(nz->amplitude) * oc_turb3_lipschitz(nz->octaves) / nz->wavelength;
  return op;
}

/* ---- groups (blend, union) ------------------------------------------ */

static uint32_t compile_node(comp *c, const oc_node *n);

typedef struct leaf {
  const oc_node *node;
  double w; /* multiplicity (blend only) */
} leaf;

/* Collects the leaves of the sub-DAG of nested `kind` nodes under root
** (and, for blends, of scale nodes, whose factor multiplies the weight),
** in first-visit order, each once with its accumulated weight. The sub-DAG
** is walked in topological order so shared sub-blends cost their size once,
** however many paths lead to them. */
static int collect(comp *c, const oc_node *root, oc_kind kind, leaf **out,
                   size_t *nout) {
  int is_blend = kind == OC_K_BLEND;
#define FLAT(x) ((x)->kind == kind || (is_blend && (x)->kind == OC_K_SCALE))
  oc_pmap seen = {0};
  const oc_node **order = NULL, **stack = NULL;
  size_t norder = 0, caporder = 0, nstack = 0, capstack = 0;
  unsigned char *done = NULL;
  size_t capdone = 0;
  double *w = NULL;
  size_t capw = 0;
  leaf *lv = NULL;
  size_t nl = 0, capl = 0;
  int ok = 0;
  /* iterative DFS post-order over internal (flattenable) nodes */
  if (!oc_pmap_slot(&seen, root, 1)) goto fail;
  *oc_pmap_slot(&seen, root, 0) = 0;
  if (!GROW(stack, nstack, capstack, 1) || !GROW(done, 0, capdone, 1))
    goto fail;
  stack[nstack++] = root;
  done[0] = 0;
  {
    /* state per internal node index: 0 new, 1 expanded */
    const oc_node **idxnode = NULL;
    size_t nidx = 0, capidx = 0;
    if (!GROW(idxnode, nidx, capidx, 1)) goto fail;
    idxnode[nidx++] = root;
    while (nstack) {
      const oc_node *x = stack[nstack - 1];
      uint32_t xi = *oc_pmap_slot(&seen, x, 0);
      if (!done[xi]) {
        done[xi] = 1;
        for (size_t i = x->nkids; i-- > 0;) {
          const oc_node *k = x->kids[i];
          if (!FLAT(k) || oc_pmap_slot(&seen, k, 0)) continue;
          uint32_t *s = oc_pmap_slot(&seen, k, 1);
          if (!s || !GROW(idxnode, nidx, capidx, 1) ||
              !GROW(done, nidx, capdone, 1) ||
              !GROW(stack, nstack, capstack, 1)) {
            free(idxnode);
            goto fail;
          }
          *s = (uint32_t)nidx;
          done[nidx] = 0;
          idxnode[nidx++] = k;
          stack[nstack++] = k;
        }
      } else {
        nstack--;
        if (!GROW(order, norder, caporder, 1)) {
          free(idxnode);
          goto fail;
        }
        order[norder++] = x;
      }
    }
    free(idxnode);
    /* weights: reverse post-order is a topological order (parents first) */
    if (!GROW(w, 0, capw, nidx)) goto fail;
    for (size_t i = 0; i < nidx; i++)
      w[i] = 0;
    w[0] = 1;
    oc_pmap lmap = {0};
    for (size_t oi = norder; oi-- > 0;) {
      const oc_node *x = order[oi];
      double wx = w[*oc_pmap_slot(&seen, x, 0)];
      double f = x->kind == OC_K_SCALE ? x->par[OC_P_FACTOR] : 1;
      for (size_t i = 0; i < x->nkids; i++) {
        const oc_node *k = x->kids[i];
        if (FLAT(k)) {
          w[*oc_pmap_slot(&seen, k, 0)] += wx * f;
          continue;
        }
        uint32_t *s = oc_pmap_slot(&lmap, k, 0);
        if (s) {
          lv[*s].w += wx * f;
          continue;
        }
        s = oc_pmap_slot(&lmap, k, 1);
        if (!s || !GROW(lv, nl, capl, 1)) {
          oc_pmap_free(&lmap);
          goto fail;
        }
        *s = (uint32_t)nl;
        lv[nl].node = k;
        lv[nl].w = wx * f;
        nl++;
      }
    }
    oc_pmap_free(&lmap);
  }
  ok = 1;
fail:
#undef FLAT
  oc_pmap_free(&seen);
  free(order);
  free(stack);
  free(done);
  free(w);
  if (!ok) {
    free(lv);
    return nomem(c);
  }
  *out = lv;
  *nout = nl;
  return 0;
}

static uint32_t scaled(comp *c, uint32_t kid, double f);

/* A group under construction: its bounded children ("entries": inline
** points or ops, each with its box and Lipschitz bound), its unbounded
** ones, always evaluated, its BVH, and what it knows of its value. */
typedef struct group {
  int is_blend, inl;
  oc_aabb *box; /* per entry */
  oc_ent *ent;
  double *lip;
  size_t nent;
  uint32_t *unb; /* unbounded children's ops */
  size_t nunb;
  size_t ncount;  /* children with a non-zero weight */
  double lo, hi;  /* value range */
  double lipmax;  /* largest child bound (unions) */
  double lipunb;  /* sum of the unbounded children's bounds (blends) */
  int depth;      /* deepest child */
  oc_aabb all;    /* union of the supports */
  uint32_t *perm; /* BVH order of the entries */
  oc_bvhnode *nodes;
  size_t nnodes;
  uint32_t *leaves; /* scratch of the blend's bound: one per node */
} group;

static void group_free(group *g) {
  free(g->box);
  free(g->ent);
  free(g->lip);
  free(g->unb);
  free(g->perm);
  free(g->nodes);
  free(g->leaves);
}

/* An inline point entry, weighted by w; its box and bound are those of
** what is stored, single precision, with a margin for the rounding. */
static void inline_point(const oc_node *n, double w, oc_ent *e, oc_aabb *cb,
                         double *clo, double *chi, double *clip) {
  double R = n->par[OC_P_R];
  e->c[0] = (float)n->par[OC_P_C];
  e->c[1] = (float)n->par[OC_P_C + 1];
  e->c[2] = (float)n->par[OC_P_C + 2];
  e->ir2 = (float)(1.0 / (R * R));
  e->e = (float)(n->par[OC_P_E] * w);
  e->ref = OC_NONE;
  double Rf = 1.0 / sqrt((double)e->ir2) * (1 + 1e-6);
  oc_vec3 cf = oc_v3(e->c[0], e->c[1], e->c[2]);
  cb->lo = oc_sub(cf, oc_v3(Rf, Rf, Rf));
  cb->hi = oc_add(cf, oc_v3(Rf, Rf, Rf));
  *clo = fmin(0, e->e);
  *chi = fmax(0, e->e);
  *clip = fabs((double)e->e) * OC_FALLOFF_LIPSCHITZ / R * (1 + 1e-6);
}

/* Step 1: compiles the children that are not inline points (their ops
** precede the group's), sorts them into entries and unbounded children,
** and sums up their value ranges and bounds. */
static int group_children(comp *c, group *g, const leaf *lv, size_t nl) {
  int is_blend = g->is_blend;
  g->lo = g->hi = is_blend ? 0 : -INFINITY;
  g->all = oc_aabb_empty();
  for (size_t i = 0; i < nl; i++) {
    const oc_node *n = lv[i].node;
    double w = is_blend ? lv[i].w : 1;
    if (w == 0) continue;
    g->ncount++;
    double clo, chi, clip;
    oc_aabb cb;
    if (g->inl && n->kind == OC_K_POINT) {
      inline_point(n, w, &g->ent[g->nent], &cb, &clo, &chi, &clip);
    } else {
      uint32_t k = compile_node(c, n);
      if (k == OC_NONE) return -1;
      if (w != 1 && (k = scaled(c, k, w)) == OC_NONE) return -1;
      info *ci = &c->inf[k];
      cb = ci->box;
      clo = ci->lo;
      chi = ci->hi;
      clip = ci->lip;
      if (ci->depth > g->depth) g->depth = ci->depth;
      if (!oc_aabb_is_bounded(cb)) {
        g->unb[g->nunb++] = k;
        g->lipunb += clip;
        goto acc;
      }
      oc_ent *e = &g->ent[g->nent];
      e->ref = k;
      memset(e->c, 0, sizeof e->c);
      e->ir2 = e->e = 0;
    }
    if (oc_aabb_is_empty(cb)) continue; /* identically zero */
    g->box[g->nent] = cb;
    g->lip[g->nent] = clip;
    g->nent++;
  acc:
    g->all = oc_aabb_union(g->all, cb);
    if (is_blend) {
      g->lo += clo;
      g->hi += chi;
    } else {
      g->lo = fmax(g->lo, clo);
      g->hi = fmax(g->hi, chi);
      g->lipmax = fmax(g->lipmax, clip);
    }
  }
  if (!is_blend && g->ncount == 0) g->lo = g->hi = 0;
  if (!is_blend && g->ncount > g->nent + g->nunb) {
    /* identically zero children */
    g->lo = fmax(g->lo, 0);
    g->hi = fmax(g->hi, 0);
  }
  return 0;
}

/* Step 2: a bounded child spanning most of the group (a terrain under
** scattered features) would sit in every BVH path and every query would
** descend to its leaf: it is evaluated always, as the unbounded ones. */
static void group_hoist_wide(group *g) {
  if (g->nent <= 2 * OC_BVH_LEAF) return;
  size_t keep = 0;
  for (size_t i = 0; i < g->nent; i++) {
    int wide = 0;
    for (int a = 0; a < 2; a++) {
      double ga = a ? g->all.hi.y - g->all.lo.y : g->all.hi.x - g->all.lo.x;
      double ca =
          a ? g->box[i].hi.y - g->box[i].lo.y : g->box[i].hi.x - g->box[i].lo.x;
      wide += ca > 0.5 * ga;
    }
    if (wide == 2 && g->ent[i].ref != OC_NONE) {
      g->unb[g->nunb++] = g->ent[i].ref;
      g->lipunb += g->lip[i];
      continue;
    }
    g->box[keep] = g->box[i];
    g->ent[keep] = g->ent[i];
    g->lip[keep] = g->lip[i];
    keep++;
  }
  g->nent = keep;
}

/* Step 3: the BVH over the entries (also used for the blend's bound),
** refused when deeper than the walks' stack (bvhwalk.h: it cannot
** happen, and evaluation has no bound to fall back to). */
static int group_bvh(comp *c, group *g) {
  if (!g->nent) return 0;
  g->perm = malloc(g->nent * sizeof *g->perm);
  g->nodes = malloc(2 * g->nent * sizeof *g->nodes);
  g->leaves = malloc(2 * g->nent * sizeof *g->leaves);
  if (!g->perm || !g->nodes || !g->leaves) return nomem(c);
  int levels;
  g->nnodes = oc_bvh_build(g->box, g->nent, g->nodes, g->perm, &levels);
  if (!g->nnodes) return nomem(c);
  if (levels > OC_BVH_STACK)
    return oc_seterr(c->err, OC_ETOODEEP,
                     "bounding volume hierarchy of %d levels: deeper than "
                     "its walks allow (%d)",
                     levels, OC_BVH_STACK);
  return 0;
}

/* The leaves whose boxes meet one entry's box. */
typedef struct lipsum {
  const oc_bvhnode *nodes;
  float lo[3], hi[3];
  uint32_t *leaf; /* their nodes' indices, in the walk's order */
  size_t n;
} lipsum;

static int lipsum_meets(const oc_bvhnode *nd, void *q) {
  const lipsum *w = q;
  return !(nd->lo[0] > w->hi[0] || nd->hi[0] < w->lo[0] ||
           nd->lo[1] > w->hi[1] || nd->hi[1] < w->lo[1] ||
           nd->lo[2] > w->hi[2] || nd->hi[2] < w->lo[2]);
}

static int lipsum_leaf(const oc_bvhnode *nd, void *q) {
  lipsum *w = q;
  w->leaf[w->n++] = (uint32_t)(nd - w->nodes);
  return 0;
}

/* Step 4: the group's Lipschitz bound. A union's is its largest child's;
** a blend's, the largest sum over children overlapping one child, plus
** the unbounded children's. */
static double group_lipschitz(const group *g) {
  if (!g->is_blend) return g->lipmax;
  double best = 0, total = 0;
  for (size_t i = 0; i < g->nent; i++)
    total += g->lip[i];
  for (size_t i = 0; i < g->nent; i++) {
    lipsum w = {g->nodes, {0}, {0}, g->leaves, 0};
    oc_box_to_float(g->box[i], w.lo, w.hi);
    double s = 0;
    /* a subtree left out: every entry's bound */
    if (oc_bvh_walk(g->nodes, 0, lipsum_meets, lipsum_leaf, &w) ==
        OC_WALK_FULL) {
      s = total;
    } else {
      /* summed over the leaves last first, as before the walk was
      ** shared (it went right first): the same bits */
      for (size_t k = w.n; k-- > 0;) {
        const oc_bvhnode *nd = &g->nodes[w.leaf[k]];
        for (uint32_t j = nd->first; j < nd->first + nd->count; j++)
          if (oc_aabb_overlaps(g->box[g->perm[j]], g->box[i]))
            s += g->lip[g->perm[j]];
      }
    }
    if (s > best) best = s;
  }
  return best + g->lipunb;
}

/* Step 5: the op, its entries in BVH order and its nodes, re-indexed
** into the program's arrays. */
static uint32_t group_emit(comp *c, oc_kind kind, const group *g, double lipv) {
  uint32_t op = new_op(c, kind);
  if (op == OC_NONE) return (void)nomem(c), OC_NONE;
  oc_program *P = c->P;
  oc_op *o = &P->ops[op];
  o->ntotal = (uint32_t)g->ncount;
  o->nobvh = (uint8_t)c->nobvh;
  o->kid = add_kids(c, g->unb, g->nunb);
  if (o->kid == OC_NONE) return (void)nomem(c), OC_NONE;
  o->nkid = (uint32_t)g->nunb;
  if (!GROW(P->ent, P->nent, c->capent, g->nent) ||
      !GROW(P->bvh, P->nbvh, c->capbvh, g->nnodes))
    return (void)nomem(c), OC_NONE;
  o = &P->ops[op];
  o->ent = (uint32_t)P->nent;
  o->nent = (uint32_t)g->nent;
  for (size_t j = 0; j < g->nent; j++)
    P->ent[P->nent + j] = g->ent[g->perm[j]];
  P->nent += g->nent;
  if (g->nnodes) {
    o->bvh = (uint32_t)P->nbvh;
    for (size_t j = 0; j < g->nnodes; j++) {
      oc_bvhnode nd = g->nodes[j];
      if (nd.count)
        nd.first += o->ent;
      else
        nd.first += o->bvh;
      P->bvh[P->nbvh + j] = nd;
    }
    P->nbvh += g->nnodes;
  }
  c->inf[op].lo = g->lo;
  c->inf[op].hi = g->hi;
  c->inf[op].lip = lipv;
  c->inf[op].depth = g->depth + 1;
  set_box(c, op, g->all);
  return op;
}

/* Builds a blend or union op over leaves. */
static uint32_t make_group(comp *c, oc_kind kind, const leaf *lv, size_t nl) {
  group g = {0};
  g.is_blend = kind == OC_K_BLEND;
  size_t npoints = 0;
  for (size_t i = 0; i < nl; i++)
    if (lv[i].node->kind == OC_K_POINT) npoints++;
  g.inl = npoints >= INLINE_MIN;
  size_t cap = nl ? nl : 1;
  g.box = malloc(cap * sizeof *g.box);
  g.ent = malloc(cap * sizeof *g.ent);
  g.lip = malloc(cap * sizeof *g.lip);
  g.unb = malloc(cap * sizeof *g.unb);
  uint32_t op = OC_NONE;
  if (!g.box || !g.ent || !g.lip || !g.unb)
    nomem(c);
  else if (!group_children(c, &g, lv, nl)) {
    group_hoist_wide(&g);
    if (!group_bvh(c, &g)) op = group_emit(c, kind, &g, group_lipschitz(&g));
  }
  group_free(&g);
  return op;
}

static uint32_t compile_group(comp *c, const oc_node *n) {
  leaf *lv = NULL;
  size_t nl = 0;
  if (collect(c, n, n->kind, &lv, &nl)) return OC_NONE;
  uint32_t op = make_group(c, n->kind, lv, nl);
  free(lv);
  return op;
}

/* ---- unary and binary operators ------------------------------------- */

static uint32_t scaled(comp *c, uint32_t kid, double f) {
  uint32_t at = add_par(c, &f, 1);
  uint32_t k = add_kids(c, &kid, 1);
  uint32_t op = new_op(c, OC_K_SCALE);
  if (at == OC_NONE || k == OC_NONE || op == OC_NONE) {
    nomem(c);
    return OC_NONE;
  }
  c->P->ops[op].par = at;
  c->P->ops[op].kid = k;
  c->P->ops[op].nkid = 1;
  info *ci = &c->inf[kid], *in = &c->inf[op];
  in->lo = fmin(f * ci->lo, f * ci->hi);
  in->hi = fmax(f * ci->lo, f * ci->hi);
  in->lip = fabs(f) * ci->lip;
  in->depth = ci->depth + 1;
  set_box(c, op, f == 0 ? oc_aabb_empty() : ci->box);
  return op;
}

static uint32_t emit(comp *c, oc_kind kind, const uint32_t *kids, size_t n,
                     const double *par, size_t npar) {
  uint32_t k = add_kids(c, kids, n);
  uint32_t at = npar ? add_par(c, par, npar) : 0;
  uint32_t op = new_op(c, kind);
  if (k == OC_NONE || at == OC_NONE || op == OC_NONE) {
    nomem(c);
    return OC_NONE;
  }
  oc_op *o = &c->P->ops[op];
  o->kid = k;
  o->nkid = (uint32_t)n;
  o->par = at;
  int d = 0;
  for (size_t i = 0; i < n; i++)
    if (c->inf[kids[i]].depth > d) d = c->inf[kids[i]].depth;
  c->inf[op].depth = d + 1;
  return op;
}

static uint32_t compile_inter(comp *c, const oc_node *n) {
  leaf *lv = NULL;
  size_t nl = 0;
  if (collect(c, n, OC_K_INTER, &lv, &nl)) return OC_NONE;
  uint32_t *k = malloc(nl * sizeof *k);
  uint32_t op = OC_NONE;
  if (!k) {
    nomem(c);
    goto done;
  }
  for (size_t i = 0; i < nl; i++)
    if ((k[i] = compile_node(c, lv[i].node)) == OC_NONE) goto done;
  op = emit(c, OC_K_INTER, k, nl, NULL, 0);
  if (op == OC_NONE) goto done;
  {
    info *in = &c->inf[op];
    oc_aabb all = oc_aabb_all(), neg = oc_aabb_empty();
    in->lo = in->hi = INFINITY;
    for (size_t i = 0; i < nl; i++) {
      info *ci = &c->inf[k[i]];
      all = oc_aabb_inter(all, ci->box);
      if (ci->lo < 0) neg = oc_aabb_union(neg, ci->box);
      in->lo = fmin(in->lo, ci->lo);
      in->hi = fmin(in->hi, ci->hi);
      in->lip = fmax(in->lip, ci->lip);
    }
    set_box(c, op, oc_aabb_union(all, neg));
  }
done:
  free(k);
  free(lv);
  return op;
}

/* (a - b) - c  ==  a - (b | c): min(min(fa, 2T - fb), 2T - fc)
** = min(fa, 2T - max(fb, fc)); the chain becomes one difference. */
static uint32_t compile_diff(comp *c, const oc_node *n) {
  const oc_node *a = n;
  size_t nb = 0;
  while (a->kind == OC_K_DIFF) {
    nb++;
    a = a->kids[0];
  }
  uint32_t ka = compile_node(c, a), kb;
  if (ka == OC_NONE) return OC_NONE;
  if (nb == 1) {
    kb = compile_node(c, n->kids[1]);
  } else {
    leaf *lv = malloc(nb * sizeof *lv);
    if (!lv) return (void)nomem(c), OC_NONE;
    size_t i = 0;
    for (const oc_node *x = n; x->kind == OC_K_DIFF; x = x->kids[0]) {
      lv[nb - 1 - i].node = x->kids[1];
      lv[nb - 1 - i].w = 1;
      i++;
    }
    kb = make_group(c, OC_K_UNION, lv, nb);
    free(lv);
  }
  if (kb == OC_NONE) return OC_NONE;
  uint32_t k[2] = {ka, kb};
  uint32_t op = emit(c, OC_K_DIFF, k, 2, NULL, 0);
  if (op == OC_NONE) return op;
  info *A = &c->inf[ka], *B = &c->inf[kb], *in = &c->inf[op];
  double T2 = 2 * c->T;
  in->lo = fmin(A->lo, T2 - B->hi);
  in->hi = fmin(A->hi, T2 - B->lo);
  in->lip = fmax(A->lip, B->lip);
  set_box(c, op, B->hi > T2 ? oc_aabb_union(A->box, B->box) : A->box);
  return op;
}

static uint32_t compile_smooth(comp *c, const oc_node *n) {
  uint32_t k[2];
  for (int i = 0; i < 2; i++)
    if ((k[i] = compile_node(c, n->kids[i])) == OC_NONE) return OC_NONE;
  double r = n->par[OC_P_SRAD];
  uint32_t op = emit(c, n->kind, k, 2, &r, 1);
  if (op == OC_NONE) return op;
  info *A = &c->inf[k[0]], *B = &c->inf[k[1]], *in = &c->inf[op];
  double T = c->T;
  if (n->kind == OC_K_SUNION) {
    in->lo = fmax(A->lo, B->lo);
    in->hi = fmax(A->hi, B->hi) + r / 6;
    in->lip = fmax(A->lip, B->lip) + r * (A->lip + B->lip) / (4 * T);
    set_box(c, op, oc_aabb_union(A->box, B->box));
  } else {
    double Ma = fmax(fabs(A->lo), fabs(A->hi)),
           Mb = fmax(fabs(B->lo), fabs(B->hi));
    in->lo = fmin(A->lo, B->lo) - r / 6;
    in->hi = fmin(A->hi, B->hi);
    in->lip =
        fmax(A->lip, B->lip) + r * (Mb * A->lip + Ma * B->lip) / (4 * T * T);
    oc_aabb b = oc_aabb_inter(A->box, B->box);
    if (A->lo < 0) b = oc_aabb_union(b, A->box);
    if (B->lo < 0) b = oc_aabb_union(b, B->box);
    set_box(c, op, b);
  }
  return op;
}

static uint32_t compile_warp(comp *c, const oc_node *n) {
  uint32_t k[2];
  for (size_t i = 0; i < n->nkids; i++)
    if ((k[i] = compile_node(c, n->kids[i])) == OC_NONE) return OC_NONE;
  uint32_t op = emit(c, OC_K_WARP, k, n->nkids, NULL, 0);
  if (op == OC_NONE) return op;
  uint32_t at = pack_noise(c, &n->noise);
  if (at == OC_NONE) return (void)nomem(c), OC_NONE;
  c->P->ops[op].par = at;
  const oc_noise *nz = &n->noise;
  double A = fabs(nz->amplitude), half = tmax_of(nz->octaves) / 2;
  double lt = oc_turb3_lipschitz(nz->octaves) / nz->wavelength;
  info *C = &c->inf[k[0]], *in = &c->inf[op];
  double lctl = n->nkids > 1 ? c->inf[k[1]].lip : 0;
  in->lo = C->lo;
  in->hi = C->hi;
  in->lip = C->lip * (1 + sqrt(3.0) * A * lt + sqrt(3.0) * A * half * lctl);
  set_box(c, op, oc_aabb_grow(C->box, A * half));
  return op;
}

static uint32_t compile_xform(comp *c, const oc_node *n) {
  uint32_t k = compile_node(c, n->kids[0]);
  if (k == OC_NONE) return k;
  double par[OC_NPAR + 1];
  memcpy(par, n->par, OC_NPAR * sizeof *par);
  par[OC_NPAR] = sigma_max(n->par + OC_P_INV); /* for local bounds */
  uint32_t op = emit(c, OC_K_XFORM, &k, 1, par, OC_NPAR + 1);
  if (op == OC_NONE) return op;
  info *C = &c->inf[k], *in = &c->inf[op];
  in->lo = C->lo;
  in->hi = C->hi;
  in->lip = C->lip * par[OC_NPAR];
  set_box(c, op, xform_box(n->par + OC_P_FWD, C->box));
  return op;
}

/* The perturbed primitive's parameters are stored in the perturb op
** itself, followed by the noise. */
static uint32_t compile_perturb(comp *c, const oc_node *n) {
  const oc_node *p = n->kids[0];
  uint32_t op = new_op(c, OC_K_PERTURB);
  if (op == OC_NONE) return (void)nomem(c), OC_NONE;
  size_t np = oc_prim_npar(p);
  uint32_t at = add_par(c, NULL, np);
  if (at == OC_NONE || pack_noise(c, &n->noise) == OC_NONE)
    return (void)nomem(c), OC_NONE;
  oc_prim_pack(p, c->P->par + at);
  oc_op *o = &c->P->ops[op];
  o->par = at;
  o->sub = (uint8_t)p->kind;
  o->nkid = (uint32_t)np; /* where the noise starts, relative to par */
  const oc_noise *nz = &n->noise;
  double R = p->par[OC_P_R], E = p->par[OC_P_E];
  double At = nz->amplitude * tmax_of(nz->octaves);
  double rmin = R + fmin(0, At), rmax = R + fmax(0, At);
  double lt =
      fabs(nz->amplitude) * oc_turb3_lipschitz(nz->octaves) / nz->wavelength;
  prim_info(c, op, p->kind, c->P->par + at, rmax);
  c->inf[op].lip = fabs(E) * OC_FALLOFF_LIPSCHITZ *
                   (1 / rmin + lt * (rmax + R) / (rmin * rmin));
  c->inf[op].depth = 1;
  return op;
}

/* ---- extension kinds (kind.h) --------------------------------------- */

static uint32_t compile_ext(comp *c, const oc_node *n) {
  const oc_kind_def *def = n->def;
  oc_kcompile kc;
  uint32_t inl[4], *k = n->nkids <= 4 ? inl : malloc(n->nkids * sizeof *k);
  oc_kinfo kinl[4], *ki = n->nkids <= 4 ? kinl : malloc(n->nkids * sizeof *ki);
  uint32_t op = OC_NONE;
  if (!k || !ki) {
    nomem(c);
    goto done;
  }
  for (size_t i = 0; i < n->nkids; i++) {
    if ((k[i] = compile_node(c, n->kids[i])) == OC_NONE) goto done;
    info *ci = &c->inf[k[i]];
    ki[i] = (oc_kinfo){ci->box, ci->lo, ci->hi, ci->lip};
  }
  kc.data = n->data;
  kc.npar = 0;
  kc.node_par = n->par;
  kc.node_npar = n->nnpar;
  kc.T = c->T;
  kc.nkids = n->nkids;
  kc.kid = ki;
  kc.info = (oc_kinfo){oc_aabb_all(), -INFINITY, INFINITY, INFINITY};
  kc.jump = 0;
  if (def->compile && def->compile(&kc, c->err) != OC_OK) goto done;
  if (kc.npar > OC_KIND_MAXPAR) {
    oc_seterr(c->err, OC_EINVAL, "%s: compiled to %zu parameters", def->name,
              kc.npar);
    goto done;
  }
  oc_program *P = c->P;
  if (!GROW(P->ext, P->next, c->capext, 1)) {
    nomem(c);
    goto done;
  }
  op = emit(c, OC_K_EXT, k, n->nkids, kc.par, kc.npar);
  if (op == OC_NONE) goto done;
  P->ops[op].ext = (uint32_t)P->next;
  P->ext[P->next++] = (oc_pext){def, n->data, {0}};
  if (kc.jump) P->njump++;
  c->inf[op].lo = kc.info.lo;
  c->inf[op].hi = kc.info.hi;
  c->inf[op].lip = kc.info.lip;
  set_box(c, op, kc.info.box);
done:
  if (k != inl) free(k);
  if (ki != kinl) free(ki);
  return op;
}

static uint32_t compile_node(comp *c, const oc_node *n) {
  uint32_t *memo = oc_pmap_slot(&c->memo, n, 0);
  if (memo) return *memo;
  if (++c->depth > OC_MAX_DEPTH) {
    oc_seterr(c->err, OC_ETOODEEP,
              "tree too deep: more than %d nested operators after "
              "flattening blends, unions and difference chains",
              OC_MAX_DEPTH);
    return OC_NONE;
  }
  uint32_t op;
  switch (n->kind) {
  case OC_K_TURB:
    op = compile_turb(c, n);
    break;
  case OC_K_BLEND:
  case OC_K_UNION:
    op = compile_group(c, n);
    break;
  case OC_K_INTER:
    op = compile_inter(c, n);
    break;
  case OC_K_DIFF:
    op = compile_diff(c, n);
    break;
  case OC_K_SUNION:
  case OC_K_SINTER:
    op = compile_smooth(c, n);
    break;
  case OC_K_SCALE: {
    uint32_t k = compile_node(c, n->kids[0]);
    op = k == OC_NONE ? k : scaled(c, k, n->par[OC_P_FACTOR]);
    break;
  }
  case OC_K_WARP:
    op = compile_warp(c, n);
    break;
  case OC_K_XFORM:
    op = compile_xform(c, n);
    break;
  case OC_K_PERTURB:
    op = compile_perturb(c, n);
    break;
  case OC_K_EXT:
    op = compile_ext(c, n);
    break;
  default:
    op = compile_prim(c, n);
    if (op != OC_NONE) c->inf[op].depth = 1;
  }
  c->depth--;
  if (op == OC_NONE) {
    if (c->err && c->err->code == OC_OK) nomem(c);
    return op;
  }
  if (c->inf[op].depth > OC_MAX_DEPTH) {
    oc_seterr(c->err, OC_ETOODEEP, "tree too deep: more than %d levels",
              OC_MAX_DEPTH);
    return OC_NONE;
  }
  uint32_t *slot = oc_pmap_slot(&c->memo, n, 1);
  if (!slot) return (void)nomem(c), OC_NONE;
  *slot = op;
  return op;
}

/* ---- statistics ------------------------------------------------------ */

static int count_nodes(const oc_node *root, size_t *nodes, size_t *prims) {
  oc_pmap seen = {0};
  const oc_node **stack = NULL;
  size_t n = 0, cap = 0;
  int ok = 0;
  *nodes = *prims = 0;
  if (!oc_pmap_slot(&seen, root, 1) || !GROW(stack, n, cap, 1)) goto done;
  stack[n++] = root;
  while (n) {
    const oc_node *x = stack[--n];
    (*nodes)++;
    if (oc_node_is_prim(x)) (*prims)++;
    for (size_t i = 0; i < x->nkids; i++) {
      const oc_node *k = x->kids[i];
      if (oc_pmap_slot(&seen, k, 0)) continue;
      if (!oc_pmap_slot(&seen, k, 1) || !GROW(stack, n, cap, 1)) goto done;
      stack[n++] = k;
    }
  }
  ok = 1;
done:
  oc_pmap_free(&seen);
  free(stack);
  return ok;
}

/* ---- entry points ---------------------------------------------------- */

oc_program *oc_compile(oc_node *root, const oc_compile_options *opts,
                       oc_error *err) {
  oc_clearerr(err);
  if (!root) {
    oc_seterr(err, OC_EINVAL, "no node to compile");
    return NULL;
  }
  double T =
      opts && opts->threshold != 0 ? opts->threshold : OC_DEFAULT_THRESHOLD;
  if (!(isfinite(T) && T > 0)) {
    oc_seterr(err, OC_EINVAL, "'threshold' must be a positive number (got %g)",
              T);
    return NULL;
  }
  oc_program *P = calloc(1, sizeof *P);
  oc_error local;
  comp c = {0};
  c.P = P;
  c.T = T;
  c.nobvh = opts ? opts->no_bvh : 0;
  c.err = err ? err : &local;
  oc_clearerr(c.err);
  if (!P) {
    nomem(&c);
    return NULL;
  }
  P->T = T;
  /* an array even without parameters: every op reads P->par + offset
  ** (NULL + 0 is undefined) */
  uint32_t r = GROW(P->par, P->npar, c.cappar, 1) ? compile_node(&c, root)
                                                  : (nomem(&c), OC_NONE);
  size_t nn, np;
  if (r == OC_NONE || !count_nodes(root, &nn, &np)) {
    if (r != OC_NONE) nomem(&c);
    free(c.inf);
    oc_pmap_free(&c.memo);
    P->node = NULL;
    oc_program_free(P);
    return NULL;
  }
  for (uint32_t i = 0; i < P->nops; i++) {
    oc_op *o = &P->ops[i];
    o->lip = c.inf[i].lip;
    if (o->kind == OC_K_EXT) {
      oc_pext *x = &P->ext[o->ext];
      x->ev = (oc_kctx){P->par + o->par, x->data, P->T, o->lip, P, i, 0};
    }
  }
  P->root = r;
  P->bounds = c.inf[r].box;
  P->lip = c.inf[r].lip;
  P->node = root;
  oc_node_retain(root);
  P->stats.nodes = nn;
  P->stats.primitives = np;
  P->stats.bytes = sizeof *P + P->nops * sizeof *P->ops +
                   P->npar * sizeof *P->par + P->nkids * sizeof *P->kids +
                   P->nent * sizeof *P->ent + P->nbvh * sizeof *P->bvh +
                   P->next * sizeof *P->ext;
  free(c.inf);
  oc_pmap_free(&c.memo);
  return P;
}
