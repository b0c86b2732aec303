/*
** raybound.c — queries along a ray for the tracer: bounds on the field's
** derivative over a segment (the local, directional Lipschitz bounds of
** segment tracing, Galin et al. 2020, after Génevaux et al. 2015, section 7.2)
** and the
** intervals where the ray crosses a support (empty-space skipping, seed
** 000 section 7). Both prune by support boxes and through the BVHs like
** evaluation does; read-only and allocation-free.
*/
#include <math.h>

#include "core/falloff.h"
#include "core/spanset.h"
#include "core/vec.h"
#include "field/bvhwalk.h"
#include "field/prim.h"
#include "field/program.h"
#include "field/raybound.h"

#define IV_CAP 64
/* Rounding slack: bounds are inflated, intervals widened, by this much. */
#define REL 1e-6

oc_ray oc_ray_make(oc_vec3 o, oc_vec3 u) {
  oc_ray r = {o, u,
              oc_v3(u.x != 0 ? 1 / u.x : INFINITY,
                    u.y != 0 ? 1 / u.y : INFINITY,
                    u.z != 0 ? 1 / u.z : INFINITY)};
  return r;
}

static int clip_axis(double o, double u, double inv, double lo, double hi,
                     double *t0, double *t1) {
  if (u == 0) return o >= lo && o <= hi;
  double a = (lo - o) * inv, b = (hi - o) * inv;
  if (a > b) {
    double c = a;
    a = b;
    b = c;
  }
  /* widen for the rounding of the division: a box is a superset */
  if (isfinite(a)) a -= 1e-12 * fabs(a) + 1e-300;
  if (isfinite(b)) b += 1e-12 * fabs(b) + 1e-300;
  if (a > *t0) *t0 = a;
  if (b < *t1) *t1 = b;
  return *t0 <= *t1;
}

int oc_ray_clip(const oc_ray *r, const float lo[3], const float hi[3],
                double *t0, double *t1) {
  return clip_axis(r->o.x, r->u.x, r->inv.x, lo[0], hi[0], t0, t1) &&
         clip_axis(r->o.y, r->u.y, r->inv.y, lo[1], hi[1], t0, t1) &&
         clip_axis(r->o.z, r->u.z, r->inv.z, lo[2], hi[2], t0, t1);
}

/* The part [s0, s1] of the ray, in coordinates s = t - tc around the
** point closest to c, where it lies within the ball (c, sqrt(1/ir2)); a
** = 1 - d^2 ir2 with d the ray's distance to c. Returns 0 when missed. */
static int ball_chord(const oc_ray *r, double cx, double cy, double cz,
                      double ir2, double t0, double t1, double *tc, double *a,
                      double *s0, double *s1) {
  double wx = cx - r->o.x, wy = cy - r->o.y, wz = cz - r->o.z;
  double c = wx * r->u.x + wy * r->u.y + wz * r->u.z;
  double px = wx - c * r->u.x, py = wy - c * r->u.y, pz = wz - c * r->u.z;
  double q = 1 - (px * px + py * py + pz * pz) * ir2;
  if (!(q > 0)) return 0;
  double h = sqrt(q / ir2) * (1 + REL);
  double lo = fmax(t0 - c, -h), hi = fmin(t1 - c, h);
  if (!(lo <= hi)) return 0;
  *tc = c;
  *a = q;
  *s0 = lo;
  *s1 = hi;
  return 1;
}

/* max of phi(s) = 6 |s| (a - s^2 ir2)^2 ir2 over |s| in [m0, m1]: phi
** grows up to |s| = sqrt(a / (5 ir2)) and falls after it. */
static double phi_max(double a, double ir2, double m0, double m1) {
  double s = sqrt(a / (5 * ir2));
  s = s < m0 ? m0 : s > m1 ? m1 : s;
  double w = a - s * s * ir2;
  if (w < 0) w = 0;
  return 6 * s * w * w * ir2;
}

/* Directional derivative of E g(|p - c|^2 ir2) along the ray over
** [t0, t1]: it is -6 E s (a - s^2 ir2)^2 ir2, so a positive E adds only
** while the ray approaches c (s < 0) and subtracts only after. */
static void point_db(const oc_ray *r, double cx, double cy, double cz,
                     double ir2, double E, double t0, double t1, double *lo,
                     double *hi) {
  double tc, a, s0, s1;
  if (!ball_chord(r, cx, cy, cz, ir2, t0, t1, &tc, &a, &s0, &s1)) return;
  double up = s0 < 0 ? phi_max(a, ir2, fmax(0, -s1), -s0) : 0;
  double down = s1 > 0 ? phi_max(a, ir2, fmax(0, s0), s1) : 0;
  double k = fabs(E) * (1 + REL);
  if (E > 0) {
    *hi += k * up;
    *lo -= k * down;
  } else {
    *hi += k * down;
    *lo -= k * up;
  }
}

static void op_db(const oc_program *P, uint32_t i, const oc_ray *r, double t0,
                  double t1, double *lo, double *hi, int depth);

/* Whether the ray's segment [t0, t1] meets node nd. A leaf passes here
** and is clipped by its visit, which needs its part of the segment: each
** node is clipped once. */
static inline int ray_meets(const oc_ray *r, const oc_bvhnode *nd, double t0,
                            double t1) {
  return nd->count || oc_ray_clip(r, nd->lo, nd->hi, &t0, &t1);
}

static void group_db(const oc_program *P, const oc_op *o, const oc_ray *r,
                     double t0, double t1, double *lo, double *hi, int depth) {
  int uni = o->kind == OC_K_UNION;
  double L = 0, H = 0;
  /* a union's derivative is one of its children's, or 0 */
#define ACC(l, h)                                                              \
  do {                                                                         \
    if (uni) {                                                                 \
      L = fmin(L, l);                                                          \
      H = fmax(H, h);                                                          \
    } else {                                                                   \
      L += l;                                                                  \
      H += h;                                                                  \
    }                                                                          \
  } while (0)
  /* entry j over [a, b] */
#define ENT_DB(j, a, b)                                                        \
  do {                                                                         \
    const oc_ent *e = &P->ent[j];                                              \
    double l = 0, h = 0;                                                       \
    if (e->ref != OC_NONE)                                                     \
      op_db(P, e->ref, r, a, b, &l, &h, depth + 1);                            \
    else                                                                       \
      point_db(r, e->c[0], e->c[1], e->c[2], e->ir2, e->e, a, b, &l, &h);      \
    ACC(l, h);                                                                 \
  } while (0)
  for (uint32_t k = 0; k < o->nkid; k++) {
    double l = 0, h = 0;
    op_db(P, P->kids[o->kid + k], r, t0, t1, &l, &h, depth + 1);
    ACC(l, h);
  }
  if (o->nent && (o->nobvh || o->bvh == OC_NONE)) {
    for (uint32_t j = o->ent; j < o->ent + o->nent; j++)
      ENT_DB(j, t0, t1);
  } else if (o->nent) {
    int full = 0;
#define MEETS(x) ray_meets(r, x, t0, t1)
    OC_BVH_FOREACH(P->bvh, o->bvh, nd, MEETS, full, {
      double a = t0, b = t1;
      if (oc_ray_clip(r, nd->lo, nd->hi, &a, &b))
        for (uint32_t j = nd->first; j < nd->first + nd->count; j++)
          ENT_DB(j, a, b);
    });
#undef MEETS
    if (full) {
      /* a subtree left out: the group's global bound (none across a
      ** jump) */
      double k = P->njump ? INFINITY : o->lip;
      *lo -= k;
      *hi += k;
      return;
    }
  }
#undef ENT_DB
#undef ACC
  /* never looser than the group's own bound, which holds off jumps
  ** only: an infinite child's stays infinite */
  *lo += isinf(L) ? L : fmax(L, -o->lip);
  *hi += isinf(H) ? H : fmin(H, o->lip);
}

static void op_db(const oc_program *P, uint32_t i, const oc_ray *r, double t0,
                  double t1, double *lo, double *hi, int depth) {
  const oc_op *o = &P->ops[i];
  if (!oc_ray_clip(r, o->lo, o->hi, &t0, &t1)) return; /* f == 0 there */
  const double *par = P->par + o->par;
  if (depth > OC_MAX_DEPTH + 8) {
    *lo -= o->lip;
    *hi += o->lip;
    return;
  }
  switch ((oc_kind)o->kind) {
  case OC_K_BLEND:
  case OC_K_UNION:
    group_db(P, o, r, t0, t1, lo, hi, depth);
    return;
  case OC_K_INTER:
  case OC_K_DIFF: {
    /* min(fa, fb) and min(fa, 2T - fb): the derivative is a child's
    ** (negated for the subtrahend) */
    double L = 0, H = 0;
    for (uint32_t k = 0; k < o->nkid; k++) {
      double l = 0, h = 0;
      op_db(P, P->kids[o->kid + k], r, t0, t1, &l, &h, depth + 1);
      if (o->kind == OC_K_DIFF && k == 1) {
        double s = l;
        l = -h;
        h = -s;
      }
      L = fmin(L, l);
      H = fmax(H, h);
    }
    *lo += L;
    *hi += H;
    return;
  }
  case OC_K_SCALE: {
    double l = 0, h = 0, c = par[OC_P_FACTOR];
    op_db(P, P->kids[o->kid], r, t0, t1, &l, &h, depth + 1);
    if (c == 0) return; /* f == 0, whatever jumps below (0 * inf) */
    *lo += c >= 0 ? c * l : c * h;
    *hi += c >= 0 ? c * h : c * l;
    return;
  }
  case OC_K_XFORM: {
    /* the child along the preimage ray, whose parameter runs |v| times
    ** faster */
    const double *m = par + OC_P_INV;
    oc_vec3 q = oc_v3(m[0] * r->o.x + m[1] * r->o.y + m[2] * r->o.z + m[3],
                      m[4] * r->o.x + m[5] * r->o.y + m[6] * r->o.z + m[7],
                      m[8] * r->o.x + m[9] * r->o.y + m[10] * r->o.z + m[11]);
    oc_vec3 v = oc_v3(m[0] * r->u.x + m[1] * r->u.y + m[2] * r->u.z,
                      m[4] * r->u.x + m[5] * r->u.y + m[6] * r->u.z,
                      m[8] * r->u.x + m[9] * r->u.y + m[10] * r->u.z);
    double n = oc_len(v);
    if (!(n > 0) || !oc_vfinite(q)) {
      *lo -= o->lip;
      *hi += o->lip;
      return;
    }
    oc_ray c = oc_ray_make(q, oc_mul(v, 1 / n));
    double l = 0, h = 0;
    op_db(P, P->kids[o->kid], &c, t0 * n, t1 * n, &l, &h, depth + 1);
    *lo += isinf(l) ? l : fmax(l * n * (1 + REL), -o->lip);
    *hi += isinf(h) ? h : fmin(h * n * (1 + REL), o->lip);
    return;
  }
  case OC_K_POINT: {
    double R = par[OC_P_R];
    point_db(r, par[OC_P_C], par[OC_P_C + 1], par[OC_P_C + 2], 1 / (R * R),
             par[OC_P_E], t0, t1, lo, hi);
    return;
  }
  case OC_K_SPHERE: {
    /* radial: a positive energy only grows while the ray approaches the
    ** centre */
    double R = par[OC_P_R] + par[OC_P_RAD];
    double tc, a, s0, s1;
    if (!ball_chord(r, par[OC_P_C], par[OC_P_C + 1], par[OC_P_C + 2],
                    1 / (R * R), t0, t1, &tc, &a, &s0, &s1))
      return;
    double up = s0 < 0 ? o->lip : 0, down = s1 > 0 ? o->lip : 0;
    if (par[OC_P_E] > 0) {
      *hi += up;
      *lo -= down;
    } else {
      *hi += down;
      *lo -= up;
    }
    return;
  }
  case OC_K_PLANE: {
    /* E g(d / R), d the distance along n, g decreasing: the sign of the
    ** derivative is fixed by u . n */
    double un = r->u.x * par[OC_P_N] + r->u.y * par[OC_P_N + 1] +
                r->u.z * par[OC_P_N + 2];
    double k = o->lip * fabs(un) * (1 + REL);
    if ((un < 0) == (par[OC_P_E] > 0))
      *hi += k;
    else
      *lo -= k;
    return;
  }
  default: {
    /* terrains, geology, erosion, perturb, warp, smooth operators: the
    ** op's local bound over the segment's box (a terrain's is 0 where the
    ** segment runs wholly above the elevations under it, so rays over a
    ** heightfield take long steps) */
    oc_vec3 a = oc_add(r->o, oc_mul(r->u, t0));
    oc_vec3 b = oc_add(r->o, oc_mul(r->u, t1));
    oc_aabb box = {oc_vmin(a, b), oc_vmax(a, b)};
    /* infinite across a jump (an open terrain's side): no step over it */
    double l = oc_op_lipschitz_in(P, i, &box);
    double k = isinf(l) ? l : fmin(l * (1 + REL), o->lip);
    *lo -= k;
    *hi += k;
    return;
  }
  }
}

void oc_ray_dbound(const oc_program *P, const oc_ray *r, double t0, double t1,
                   double *lo, double *hi) {
  *lo = 0;
  *hi = 0;
  if (!(t0 <= t1)) return;
  op_db(P, P->root, r, t0, t1, lo, hi, 0);
}

/* ---- support intervals -------------------------------------------------- */

typedef struct ivset {
  oc_zspan s[IV_CAP];
  int n;
} ivset;

/* Keeps the set sorted and disjoint; past the capacity, closes the
** smallest gap (still a cover, just looser). */
static void iv_add(ivset *S, double lo, double hi) {
  if (!(lo <= hi)) return;
  double pad = REL * 1e-3 * (fabs(lo) + fabs(hi) + 1);
  oc_spanset_add(S->s, &S->n, IV_CAP, lo - pad, hi + pad);
}

static void op_sup(const oc_program *P, uint32_t i, const oc_ray *r, double t0,
                   double t1, ivset *S, int depth);

static void op_sup(const oc_program *P, uint32_t i, const oc_ray *r, double t0,
                   double t1, ivset *S, int depth) {
  const oc_op *o = &P->ops[i];
  if (!oc_ray_clip(r, o->lo, o->hi, &t0, &t1)) return;
  const double *par = P->par + o->par;
  double tc, a, s0, s1;
  switch ((oc_kind)o->kind) {
  case OC_K_BLEND:
  case OC_K_UNION:
    if (depth > OC_MAX_DEPTH) break;
    for (uint32_t k = 0; k < o->nkid; k++)
      op_sup(P, P->kids[o->kid + k], r, t0, t1, S, depth + 1);
    if (!o->nent) return;
    if (o->nobvh || o->bvh == OC_NONE) {
      /* brute-force groups (tests): their children's boxes together */
      iv_add(S, t0, t1);
      return;
    }
    {
      int full = 0;
#define MEETS(x) ray_meets(r, x, t0, t1)
      OC_BVH_FOREACH(P->bvh, o->bvh, nd, MEETS, full, {
        double ta = t0, tb = t1;
        if (oc_ray_clip(r, nd->lo, nd->hi, &ta, &tb))
          for (uint32_t j = nd->first; j < nd->first + nd->count; j++) {
            const oc_ent *e = &P->ent[j];
            if (e->ref != OC_NONE)
              op_sup(P, e->ref, r, ta, tb, S, depth + 1);
            else if (ball_chord(r, e->c[0], e->c[1], e->c[2], e->ir2, ta, tb,
                                &tc, &a, &s0, &s1))
              iv_add(S, tc + s0, tc + s1);
          }
      });
#undef MEETS
      /* a subtree left out: the group's whole segment */
      if (full) iv_add(S, t0, t1);
    }
    return;
  case OC_K_POINT:
  case OC_K_SPHERE: {
    double R = par[OC_P_R] + (o->kind == OC_K_SPHERE ? par[OC_P_RAD] : 0);
    if (ball_chord(r, par[OC_P_C], par[OC_P_C + 1], par[OC_P_C + 2],
                   1 / (R * R), t0, t1, &tc, &a, &s0, &s1))
      iv_add(S, tc + s0, tc + s1);
    return;
  }
  default:
    break;
  }
  iv_add(S, t0, t1);
}

int oc_ray_supports(const oc_program *P, const oc_ray *r, double t0, double t1,
                    oc_zspan *out, int max) {
  if (!(t0 <= t1) || max < 1) return 0;
  ivset S;
  S.n = 0;
  op_sup(P, P->root, r, t0, t1, &S, 0);
  oc_spanset_reduce(S.s, &S.n, max);
  for (int k = 0; k < S.n; k++) {
    out[k].lo = fmax(S.s[k].lo, t0);
    out[k].hi = fmin(S.s[k].hi, t1);
  }
  return S.n;
}
