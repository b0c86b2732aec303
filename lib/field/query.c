/*
** query.c — local queries on a compiled program: the z-spans where a
** column may vary (surface bounds for the mesher, Paris et al. 2019, section
** 7) and
** Lipschitz bounds restricted to a box (for culling and sphere tracing).
** Both walk the program like evaluation does, pruning by support boxes and
** through the BVHs, and are read-only and allocation-free.
*/
#include <math.h>

#include "core/falloff.h"
#include "core/spanset.h"
#include "core/noise.h"
#include "core/vec.h"
#include "field/bvhwalk.h"
#include "field/prim.h"
#include "field/program.h"
#include "field/query.h"

#define SPAN_CAP 64

/* ---- span sets ---------------------------------------------------------- */

typedef struct oc_colq {
  oc_zspan s[SPAN_CAP];
  int n;
  /* when wz, terrains keep theirs apart: where they may vary (t), and
  ** where they may vary along a column (z); the others' are in s alone,
  ** the same for both */
  oc_zspan t[SPAN_CAP], z[SPAN_CAP];
  int nt, nz, wz;
  int all;     /* the whole column */
  int nleaf;   /* ops met other than blends and unions */
  uint32_t hf; /* a heightfield-like op met through blends and unions only,
               ** governing its column alone where nothing else is met */
} spans;

static void span_add(spans *S, double lo, double hi) {
  if (S->all || !(lo <= hi)) return;
  if (isinf(lo) && isinf(hi)) {
    S->all = 1;
    return;
  }
  oc_spanset_add(S->s, &S->n, SPAN_CAP, lo, hi);
}
static void span_add_v(void *S, double lo, double hi) {
  span_add(S, lo, hi);
}
/* A terrain's, when wz. */
static void span_add_t(void *v, double lo, double hi) {
  spans *S = v;
  if (!S->all && lo <= hi) oc_spanset_add(S->t, &S->nt, SPAN_CAP, lo, hi);
}
static void span_add_z(void *v, double lo, double hi) {
  spans *S = v;
  if (!S->all && lo <= hi) oc_spanset_add(S->z, &S->nz, SPAN_CAP, lo, hi);
}

/* kind.h's names for them */
void oc_col_add(void *q, double lo, double hi) {
  span_add(q, lo, hi);
}
void oc_col_add_xy(void *q, double lo, double hi) {
  spans *S = q;
  if (S->wz)
    span_add_t(S, lo, hi);
  else
    span_add(S, lo, hi);
}
void oc_col_add_z(void *q, double lo, double hi) {
  spans *S = q;
  if (S->wz) span_add_z(S, lo, hi);
}
int oc_col_wants_z(const oc_colq *q) {
  return q->wz;
}
void oc_col_whole(oc_colq *q) {
  q->all = 1;
}

typedef oc_foot foot;

/* Squared distance from (x, y) to the footprint rectangle. */
static double foot_d2(const foot *f, double x, double y) {
  double dx = fmax(fmax(f->x0 - x, x - f->x1), 0);
  double dy = fmax(fmax(f->y0 - y, y - f->y1), 0);
  return dx * dx + dy * dy;
}

/* A ball of radius R around c varies only over the z-range its section
** above the footprint covers: tighter than its box for round supports. */
static void ball_span(const foot *f, double cx, double cy, double cz, double R,
                      void (*add)(void *, double, double), void *S) {
  double d2 = foot_d2(f, cx, cy);
  if (d2 >= R * R) return;
  double h = sqrt(R * R - d2);
  add(S, cz - h, cz + h);
}

/* A curve's field varies within R of its segments: over the footprint,
** within the z-ranges (grown by R) of the chunks whose boxes, grown by R,
** meet it. An arch's top column then spans the top only, not the legs. */
static void curve_spans(const double *par, double R, const foot *f, spans *S) {
  size_t n;
  const double *b = oc_prim_curve_boxes(par, &n);
  if (!n) { /* a single point */
    ball_span(f, par[3], par[4], par[5], R * (1 + 1e-9), span_add_v, S);
    return;
  }
  double m = R * (1 + 1e-9);
  for (size_t c = 0; c < n; c++, b += 6)
    if (b[0] - m <= f->x1 && b[3] + m >= f->x0 && b[1] - m <= f->y1 &&
        b[4] + m >= f->y0)
      span_add(S, b[2] - m, b[5] + m);
}

static int foot_meets(const float *lo, const float *hi, const foot *f) {
  return lo[0] <= f->x1 && hi[0] >= f->x0 && lo[1] <= f->y1 && hi[1] >= f->y0;
}

/* The slab 0 < (p - o).n < R where a plane's field varies, over the
** footprint. */
static void plane_spans(const double *par, const foot *f, spans *S) {
  double ox = par[OC_P_O], oy = par[OC_P_O + 1], oz = par[OC_P_O + 2];
  double nx = par[OC_P_N], ny = par[OC_P_N + 1], nz = par[OC_P_N + 2];
  double R = par[OC_P_R];
  /* range of n_x (x - ox) + n_y (y - oy) over the footprint */
  double a = fmin(nx * (f->x0 - ox), nx * (f->x1 - ox)) +
             fmin(ny * (f->y0 - oy), ny * (f->y1 - oy));
  double b = fmax(nx * (f->x0 - ox), nx * (f->x1 - ox)) +
             fmax(ny * (f->y0 - oy), ny * (f->y1 - oy));
  if (fabs(nz) < 1e-12) {
    /* vertical: varies at every z wherever the slab meets the footprint */
    if (b > 0 && a < R) S->all = 1;
    return;
  }
  /* z = oz + (s - h) / nz for s in [0, R], h in [a, b] */
  double z1 = oz + (0 - a) / nz, z2 = oz + (0 - b) / nz;
  double z3 = oz + (R - a) / nz, z4 = oz + (R - b) / nz;
  double lo = fmin(fmin(z1, z2), fmin(z3, z4));
  double hi = fmax(fmax(z1, z2), fmax(z3, z4));
  /* pad by a relative epsilon for the rounding of the formula */
  double pad = 1e-9 * (fabs(lo) + fabs(hi) + R);
  span_add(S, lo - pad, hi + pad);
}

static void op_spans(const oc_program *P, uint32_t i, const foot *f, spans *S,
                     int depth, int direct);

/* A column query's walk under a group's BVH. */
typedef struct spanwalk {
  const oc_program *P;
  const foot *f;
  spans *S;
  int depth, direct;
} spanwalk;

static int spans_meets(const oc_bvhnode *nd, void *q) {
  return foot_meets(nd->lo, nd->hi, ((const spanwalk *)q)->f);
}

static int spans_leaf(const oc_bvhnode *nd, void *q) {
  spanwalk *w = q;
  const foot *f = w->f;
  for (uint32_t j = nd->first; j < nd->first + nd->count && !w->S->all; j++) {
    const oc_ent *e = &w->P->ent[j];
    if (e->ref != OC_NONE) {
      op_spans(w->P, e->ref, f, w->S, w->depth + 1, w->direct);
      continue;
    }
    double R = 1.0 / sqrt((double)e->ir2) * (1 + 1e-6);
    if (e->c[0] - R > f->x1 || e->c[0] + R < f->x0 || e->c[1] - R > f->y1 ||
        e->c[1] + R < f->y0)
      continue;
    w->S->nleaf++;
    span_add(w->S, e->c[2] - R, e->c[2] + R);
  }
  return w->S->all;
}

/* `direct`: every operator above is a blend or a union, whose value is
** the child's own where the other children are 0. */
static void group_spans(const oc_program *P, const oc_op *o, const foot *f,
                        spans *S, int depth, int direct) {
  for (uint32_t k = 0; k < o->nkid && !S->all; k++)
    op_spans(P, P->kids[o->kid + k], f, S, depth + 1, direct);
  if (!o->nent || S->all) return;
  spanwalk w = {P, f, S, depth, direct};
  /* a subtree left out: the whole column */
  if (oc_bvh_walk(P->bvh, o->bvh, spans_meets, spans_leaf, &w) == OC_WALK_FULL)
    S->all = 1;
}

/* A transform keeps columns when it maps z to z and xy to xy. */
static int column_preserving(const double *m) {
  return m[2] == 0 && m[6] == 0 && m[8] == 0 && m[9] == 0 && m[10] != 0;
}

/* The z-range of the op's support box: where any op may vary. */
static void box_spans(const oc_op *o, spans *S) {
  if (isinf(o->lo[2]) || isinf(o->hi[2]))
    S->all = 1;
  else
    span_add(S, o->lo[2], o->hi[2]);
}

static void op_spans(const oc_program *P, uint32_t i, const foot *f, spans *S,
                     int depth, int direct) {
  const oc_op *o = &P->ops[i];
  if (S->all) return;
  if (depth > OC_MAX_DEPTH + 8) {
    S->all = 1;
    return;
  }
  if (!foot_meets(o->lo, o->hi, f)) return; /* f == 0 over the column */
  const double *par = P->par + o->par;
  if (o->kind != OC_K_BLEND && o->kind != OC_K_UNION) S->nleaf++;
  switch ((oc_kind)o->kind) {
  case OC_K_PLANE:
    plane_spans(par, f, S);
    if (direct) S->hf = i;
    return;
  case OC_K_TURB:
    S->all = 1;
    return;
  case OC_K_EXT: {
    const oc_pext *x = &P->ext[o->ext];
    if (!x->def->column) {
      box_spans(o, S);
      return;
    }
    oc_kctx k = {par, x->data, P->T, o->lip, P, i, depth};
    if (x->def->column(&k, f, S) && direct) S->hf = i;
    return;
  }
  case OC_K_BLEND:
  case OC_K_UNION:
    group_spans(P, o, f, S, depth, direct);
    return;
  case OC_K_INTER:
  case OC_K_DIFF:
  case OC_K_SUNION:
  case OC_K_SINTER:
  case OC_K_SCALE:
    if (o->kind == OC_K_SCALE && par[0] == 0) return;
    for (uint32_t k = 0; k < o->nkid && !S->all; k++)
      op_spans(P, P->kids[o->kid + k], f, S, depth + 1, 0);
    return;
  case OC_K_WARP: {
    /* the child's spans around the displaced column, grown by the
    ** largest displacement */
    oc_noise nz = oc_noise_unpack(par);
    double A = fabs(nz.amplitude) * oc_turb3_max(nz.octaves) / 2;
    foot g = {f->x0 - A, f->y0 - A, f->x1 + A, f->y1 + A};
    spans C;
    C.n = C.nt = C.nz = C.wz = C.all = C.nleaf = 0;
    C.hf = OC_NONE;
    op_spans(P, P->kids[o->kid], &g, &C, depth + 1, 0);
    if (C.all) {
      S->all = 1;
      return;
    }
    for (int k = 0; k < C.n; k++)
      span_add(S, C.s[k].lo - A, C.s[k].hi + A);
    return;
  }
  case OC_K_XFORM: {
    const double *m = par + OC_P_FWD, *inv = par + OC_P_INV;
    if (column_preserving(m)) {
      /* the footprint's preimage (its box), then z back to world */
      double xs[2] = {f->x0, f->x1}, ys[2] = {f->y0, f->y1};
      foot g = {INFINITY, INFINITY, -INFINITY, -INFINITY};
      for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
          double u = inv[0] * xs[a] + inv[1] * ys[b] + inv[3];
          double v = inv[4] * xs[a] + inv[5] * ys[b] + inv[7];
          g.x0 = fmin(g.x0, u);
          g.x1 = fmax(g.x1, u);
          g.y0 = fmin(g.y0, v);
          g.y1 = fmax(g.y1, v);
        }
      spans C;
      C.n = C.nt = C.nz = C.wz = C.all = C.nleaf = 0;
      C.hf = OC_NONE;
      op_spans(P, P->kids[o->kid], &g, &C, depth + 1, 0);
      if (C.all) {
        S->all = 1;
        return;
      }
      for (int k = 0; k < C.n; k++) {
        double z1 = m[10] * C.s[k].lo + m[11], z2 = m[10] * C.s[k].hi + m[11];
        span_add(S, fmin(z1, z2), fmax(z1, z2));
      }
      return;
    }
    if (isinf(o->lo[2]) || isinf(o->hi[2]))
      S->all = 1;
    else
      span_add(S, o->lo[2], o->hi[2]);
    return;
  }
  case OC_K_CURVE:
    curve_spans(par, par[OC_P_R], f, S);
    return;
  case OC_K_PERTURB:
    if (o->sub == OC_K_CURVE) {
      curve_spans(par, oc_perturb_reach(o, par), f, S);
      return;
    }
    span_add(S, o->lo[2], o->hi[2]);
    return;
  case OC_K_POINT:
  case OC_K_SPHERE: {
    double R = par[OC_P_R] + (o->kind == OC_K_SPHERE ? par[OC_P_RAD] : 0);
    ball_span(f, par[OC_P_C], par[OC_P_C + 1], par[OC_P_C + 2], R * (1 + 1e-9),
              span_add_v, S);
    return;
  }
  default: /* bounded primitives and perturb: their support box */
    box_spans(o, S);
    return;
  }
}

void oc_child_spans(const oc_kctx *k, size_t i, const oc_foot *f, oc_colq *q) {
  const oc_program *P = k->P_;
  op_spans(P, P->kids[P->ops[k->op_].kid + i], f, q, k->depth_ + 1, 0);
}

/* Closes the smallest gaps of set s (n spans) until at most max remain,
** and copies it to out. */
static int reduce(oc_zspan *s, int n, oc_zspan *out, int max) {
  oc_spanset_reduce(s, &n, max);
  for (int k = 0; k < n; k++)
    out[k] = s[k];
  return n;
}

int oc_program_column_query_z(const oc_program *P, double x0, double y0,
                              double x1, double y1, oc_zspan *out, int max,
                              uint32_t *hf, oc_zspan *zout, int *nz) {
  if (hf) *hf = OC_NONE;
  if (nz) *nz = -1;
  if (!(x0 <= x1 && y0 <= y1) || max < 1) return -1;
  foot f = {x0, y0, x1, y1};
  spans S; /* the span arrays are filled as needed, not cleared */
  S.n = S.nt = S.nz = S.all = S.nleaf = 0;
  S.wz = zout != NULL;
  S.hf = OC_NONE;
  op_spans(P, P->root, &f, &S, 0, 1);
  if (S.all) return -1;
  if (hf && S.nleaf == 1) *hf = S.hf;
  if (zout) {
    for (int k = 0; k < S.n; k++)
      oc_spanset_add(S.z, &S.nz, SPAN_CAP, S.s[k].lo, S.s[k].hi);
    for (int k = 0; k < S.nt; k++)
      oc_spanset_add(S.s, &S.n, SPAN_CAP, S.t[k].lo, S.t[k].hi);
    *nz = reduce(S.z, S.nz, zout, max);
  }
  return reduce(S.s, S.n, out, max);
}

int oc_program_column_query(const oc_program *P, double x0, double y0,
                            double x1, double y1, oc_zspan *out, int max,
                            uint32_t *hf) {
  return oc_program_column_query_z(P, x0, y0, x1, y1, out, max, hf, NULL, NULL);
}

int oc_program_column_spans(const oc_program *P, double x0, double y0,
                            double x1, double y1, oc_zspan *out, int max) {
  return oc_program_column_query(P, x0, y0, x1, y1, out, max, NULL);
}

/* ---- local Lipschitz bounds --------------------------------------------- */

static int box_meets(const float *lo, const float *hi, const oc_aabb *b) {
  return lo[0] <= b->hi.x && hi[0] >= b->lo.x && lo[1] <= b->hi.y &&
         hi[1] >= b->lo.y && lo[2] <= b->hi.z && hi[2] >= b->lo.z;
}

/* Squared distance from a point to the box, and to its farthest corner. */
static double box_d2(const oc_aabb *b, double x, double y, double z) {
  double dx = fmax(fmax(b->lo.x - x, x - b->hi.x), 0);
  double dy = fmax(fmax(b->lo.y - y, y - b->hi.y), 0);
  double dz = fmax(fmax(b->lo.z - z, z - b->hi.z), 0);
  return dx * dx + dy * dy + dz * dz;
}
static double box_far2(const oc_aabb *b, double x, double y, double z) {
  double dx = fmax(fabs(b->lo.x - x), fabs(b->hi.x - x));
  double dy = fmax(fabs(b->lo.y - y), fabs(b->hi.y - y));
  double dz = fmax(fabs(b->lo.z - z), fabs(b->hi.z - z));
  return dx * dx + dy * dy + dz * dz;
}

static double op_lip(const oc_program *P, uint32_t i, const oc_aabb *b,
                     int depth);

static int op_zero(const oc_program *P, uint32_t i, const oc_aabb *b,
                   int depth);

double oc_child_lipschitz_in(const oc_kctx *k, size_t i, const oc_aabb *b) {
  const oc_program *P = k->P_;
  return op_lip(P, P->kids[P->ops[k->op_].kid + i], b, k->depth_ + 1);
}
int oc_child_zero_in(const oc_kctx *k, size_t i, const oc_aabb *b) {
  const oc_program *P = k->P_;
  return oc_aabb_is_empty(*b) ||
         op_zero(P, P->kids[P->ops[k->op_].kid + i], b, k->depth_ + 1);
}

/* A box query's walk under a group's BVH (local bounds, zero tests). */
typedef struct lipwalk {
  const oc_program *P;
  const oc_aabb *b;
  int depth, uni;
  double acc; /* the bound so far; for zero tests, 1 while all zero */
} lipwalk;

static int box_meets_nd(const oc_bvhnode *nd, void *q) {
  return box_meets(nd->lo, nd->hi, ((const lipwalk *)q)->b);
}

static int lip_leaf(const oc_bvhnode *nd, void *q) {
  lipwalk *w = q;
  const oc_aabb *b = w->b;
  for (uint32_t j = nd->first; j < nd->first + nd->count; j++) {
    const oc_ent *e = &w->P->ent[j];
    double l;
    if (e->ref != OC_NONE) {
      l = op_lip(w->P, e->ref, b, w->depth + 1);
    } else {
      double R = 1.0 / sqrt((double)e->ir2);
      double Rp = R * (1 + 1e-6);
      if (box_d2(b, e->c[0], e->c[1], e->c[2]) >= Rp * Rp) continue;
      l = fabs((double)e->e) * OC_FALLOFF_LIPSCHITZ / R * (1 + 1e-6);
    }
    w->acc = w->uni ? fmax(w->acc, l) : w->acc + l;
  }
  return 0;
}

static int op_zero(const oc_program *P, uint32_t i, const oc_aabb *b,
                   int depth);

/* Ends the walk at the first entry that may be non-zero in the box. */
static int zero_leaf(const oc_bvhnode *nd, void *q) {
  lipwalk *w = q;
  for (uint32_t j = nd->first; j < nd->first + nd->count; j++) {
    const oc_ent *e = &w->P->ent[j];
    int zero;
    if (e->ref != OC_NONE) {
      zero = op_zero(w->P, e->ref, w->b, w->depth + 1);
    } else {
      double Rp = 1.0 / sqrt((double)e->ir2) * (1 + 1e-6);
      zero = box_d2(w->b, e->c[0], e->c[1], e->c[2]) >= Rp * Rp;
    }
    if (!zero) {
      w->acc = 0;
      return 1;
    }
  }
  return 0;
}

static double op_lip(const oc_program *P, uint32_t i, const oc_aabb *b,
                     int depth) {
  const oc_op *o = &P->ops[i];
  if (!box_meets(o->lo, o->hi, b)) return 0; /* f == 0 on the box */
  if (depth > OC_MAX_DEPTH + 8) return o->lip;
  const double *par = P->par + o->par;
  switch ((oc_kind)o->kind) {
  case OC_K_BLEND:
  case OC_K_UNION: {
    int uni = o->kind == OC_K_UNION;
    double acc = 0;
    for (uint32_t k = 0; k < o->nkid; k++) {
      double l = op_lip(P, P->kids[o->kid + k], b, depth + 1);
      acc = uni ? fmax(acc, l) : acc + l;
    }
    if (!o->nent) return acc;
    lipwalk w = {P, b, depth, uni, acc};
    /* a subtree left out: the group's global bound (none across a jump) */
    if (oc_bvh_walk(P->bvh, o->bvh, box_meets_nd, lip_leaf, &w) == OC_WALK_FULL)
      return P->njump ? INFINITY : o->lip;
    acc = w.acc;
    /* (the group's own bound holds off jumps only) */
    return isinf(acc) ? acc : fmin(acc, o->lip);
  }
  case OC_K_INTER:
  case OC_K_DIFF: {
    double m = 0;
    for (uint32_t k = 0; k < o->nkid; k++)
      m = fmax(m, op_lip(P, P->kids[o->kid + k], b, depth + 1));
    return m;
  }
  case OC_K_SCALE:
    if (par[0] == 0) return 0; /* f == 0, whatever jumps below */
    return fabs(par[0]) * op_lip(P, P->kids[o->kid], b, depth + 1);
  case OC_K_XFORM: {
    /* the child's bound on the preimage of the box */
    const double *inv = par + OC_P_INV;
    oc_aabb c = {{INFINITY, INFINITY, INFINITY},
                 {-INFINITY, -INFINITY, -INFINITY}};
    for (int k = 0; k < 8; k++) {
      oc_vec3 p = oc_v3(k & 1 ? b->hi.x : b->lo.x, k & 2 ? b->hi.y : b->lo.y,
                        k & 4 ? b->hi.z : b->lo.z);
      oc_vec3 q = oc_v3(inv[0] * p.x + inv[1] * p.y + inv[2] * p.z + inv[3],
                        inv[4] * p.x + inv[5] * p.y + inv[6] * p.z + inv[7],
                        inv[8] * p.x + inv[9] * p.y + inv[10] * p.z + inv[11]);
      c.lo = oc_vmin(c.lo, q);
      c.hi = oc_vmax(c.hi, q);
    }
    if (!oc_vfinite(c.lo) || !oc_vfinite(c.hi)) return o->lip;
    return par[OC_NPAR] * op_lip(P, P->kids[o->kid], &c, depth + 1);
  }
  case OC_K_POINT:
  case OC_K_SPHERE: {
    /* zero outside the ball of support, and inside a sphere's core where
    ** the field is constant */
    double cx = par[OC_P_C], cy = par[OC_P_C + 1], cz = par[OC_P_C + 2];
    double r = o->kind == OC_K_SPHERE ? par[OC_P_RAD] : 0;
    double R = (par[OC_P_R] + r) * (1 + 1e-9);
    if (box_d2(b, cx, cy, cz) >= R * R) return 0;
    if (r > 0 && box_far2(b, cx, cy, cz) < r * r * (1 - 1e-9)) return 0;
    return o->lip;
  }
  case OC_K_EXT: {
    const oc_pext *x = &P->ext[o->ext];
    if (!x->def->lipschitz_in) return o->lip;
    oc_kctx k = {par, x->data, P->T, o->lip, P, i, depth};
    return x->def->lipschitz_in(&k, b);
  }
  default: /* primitives, perturb, warp, smooth operators: their bound */
    return o->lip;
  }
}

/* 1 when op i is 0 all over box b: its support misses b, or it is a
** blend or union whose every child's does (0 otherwise, also when it
** cannot tell). */
static int op_zero(const oc_program *P, uint32_t i, const oc_aabb *b,
                   int depth) {
  const oc_op *o = &P->ops[i];
  if (!box_meets(o->lo, o->hi, b)) return 1;
  if (depth > OC_MAX_DEPTH + 8) return 0;
  if (o->kind == OC_K_EXT) {
    const oc_pext *x = &P->ext[o->ext];
    if (!x->def->zero_in) return 0;
    oc_kctx k = {P->par + o->par, x->data, P->T, o->lip, P, i, depth};
    return x->def->zero_in(&k, b);
  }
  if (o->kind != OC_K_BLEND && o->kind != OC_K_UNION) return 0;
  for (uint32_t k = 0; k < o->nkid; k++)
    if (!op_zero(P, P->kids[o->kid + k], b, depth + 1)) return 0;
  if (!o->nent) return 1;
  lipwalk w = {P, b, depth, 0, 1};
  /* a subtree left out: "not zero" */
  return oc_bvh_walk(P->bvh, o->bvh, box_meets_nd, zero_leaf, &w) ==
                 OC_WALK_FULL
             ? 0
             : w.acc != 0;
}

int oc_op_zero_in(const oc_program *P, uint32_t op, const oc_aabb *b) {
  return oc_aabb_is_empty(*b) || op_zero(P, op, b, 0);
}

double oc_op_lipschitz_in(const oc_program *P, uint32_t op, const oc_aabb *b) {
  if (oc_aabb_is_empty(*b)) return 0;
  return op_lip(P, op, b, 0);
}

double oc_program_lipschitz_in(const oc_program *P, oc_aabb box) {
  if (oc_aabb_is_empty(box)) return 0;
  return op_lip(P, P->root, &box, 0);
}
