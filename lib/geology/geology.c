/*
** geology.c — the node kinds of resistance trees (Paris et al. 2019, section
** 4):
** strata, clamp, taper and fault, with their constructors, compiled
** parameters, value and gradient, column spans and local Lipschitz
** bounds; and the plane layer, built from existing primitives. The
** erosion node, which reads a resistance tree, is in erosion.c.
*/
#include <math.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/vec.h"
#include "geology/geology.h"

/* ---- constructors ------------------------------------------------------ */

oc_node *oc_strata(const oc_noise *noise, oc_error *err) {
  if (!oc_check_noise(noise, err)) return NULL;
  oc_node *n = oc_node_alloc(OC_K_STRATA, NULL, 0, err);
  if (n) n->noise = *noise;
  return n;
}

oc_node *oc_clamp(oc_node *child, double lo, double hi, oc_error *err) {
  if (!child) {
    oc_seterr(err, OC_EINVAL, "no node to clamp");
    return NULL;
  }
  if (!oc_check_finite(lo, "lo", err) || !oc_check_finite(hi, "hi", err))
    return NULL;
  if (!(lo < hi)) {
    oc_seterr(err, OC_EINVAL, "'lo' must be below 'hi' (got %g and %g)", lo,
              hi);
    return NULL;
  }
  oc_node *n = oc_node_alloc(OC_K_CLAMP, &child, 1, err);
  if (n) {
    n->par[OC_GP_LO] = lo;
    n->par[OC_GP_HI] = hi;
  }
  return n;
}

static int unit(oc_vec3 v, const char *what, oc_vec3 *out, oc_error *err) {
  if (!oc_check_vec(v, what, err)) return 0;
  double l = oc_len(v);
  if (!(l > 0) || !isfinite(l)) {
    oc_seterr(err, OC_EINVAL, "'%s' must be a non-zero vector", what);
    return 0;
  }
  *out = oc_mul(v, 1 / l);
  return 1;
}

static void put3(double *par, oc_vec3 v) {
  par[0] = v.x, par[1] = v.y, par[2] = v.z;
}
static oc_vec3 get3(const double *par) {
  return oc_v3(par[0], par[1], par[2]);
}

oc_node *oc_taper(oc_node *child, const oc_taper_params *tp, oc_error *err) {
  oc_vec3 a, b;
  if (!child || !tp) {
    oc_seterr(err, OC_EINVAL, "taper needs a node and its parameters");
    return NULL;
  }
  if (!oc_check_vec(tp->origin, "origin", err) ||
      !unit(tp->axis, "axis", &a, err) || !unit(tp->along, "along", &b, err) ||
      !oc_check_finite(tp->from, "from", err) ||
      !oc_check_finite(tp->to, "to", err) ||
      !oc_check_positive(tp->factor, "factor", err) ||
      !oc_check_positive(tp->height, "height", err))
    return NULL;
  if (!(fabs(tp->to - tp->from) > 1e-12 * (fabs(tp->to) + fabs(tp->from)))) {
    oc_seterr(err, OC_EINVAL, "'to' must differ from 'from' (both %g)", tp->to);
    return NULL;
  }
  oc_node *n = oc_node_alloc(OC_K_TAPER, &child, 1, err);
  if (!n) return NULL;
  put3(n->par + OC_GP_TO, tp->origin);
  put3(n->par + OC_GP_TA, a);
  put3(n->par + OC_GP_TB, b);
  n->par[OC_GP_U0] = tp->from;
  n->par[OC_GP_U1] = tp->to;
  n->par[OC_GP_K] = tp->factor;
  n->par[OC_GP_H] = tp->height;
  return n;
}

oc_node *oc_fault(oc_node *child, const oc_fault_domain *dom, oc_vec3 offset,
                  oc_error *err) {
  if (!child || !dom) {
    oc_seterr(err, OC_EINVAL, "fault needs a node and a domain");
    return NULL;
  }
  if (!oc_check_vec(offset, "offset", err)) return NULL;
  double par[OC_GP_COUNT] = {0};
  put3(par + OC_GP_OFF, offset);
  par[OC_GP_DOM] = dom->kind;
  oc_node *kids[2] = {child, NULL};
  switch (dom->kind) {
  case OC_FAULT_BOX:
    if (!oc_check_vec(dom->lo, "domain.min", err) ||
        !oc_check_vec(dom->hi, "domain.max", err))
      return NULL;
    if (!(dom->lo.x < dom->hi.x && dom->lo.y < dom->hi.y &&
          dom->lo.z < dom->hi.z)) {
      oc_seterr(err, OC_EINVAL,
                "'domain.max' must be above 'domain.min' on every axis");
      return NULL;
    }
    put3(par + OC_GP_DA, dom->lo);
    put3(par + OC_GP_DB, dom->hi);
    break;
  case OC_FAULT_HALF: {
    oc_vec3 nn;
    if (!oc_check_vec(dom->origin, "domain.origin", err) ||
        !unit(dom->normal, "domain.normal", &nn, err))
      return NULL;
    put3(par + OC_GP_DA, dom->origin);
    put3(par + OC_GP_DB, nn);
    break;
  }
  case OC_FAULT_NODE:
    if (!dom->node) {
      oc_seterr(err, OC_EINVAL, "'domain' node is NULL");
      return NULL;
    }
    kids[1] = dom->node;
    break;
  default:
    oc_seterr(err, OC_EINVAL, "unknown fault domain kind %d", (int)dom->kind);
    return NULL;
  }
  oc_node *n = oc_node_alloc(OC_K_FAULT, kids, kids[1] ? 2 : 1, err);
  if (n)
    for (int i = 0; i < OC_GP_COUNT; i++)
      n->par[i] = par[i];
  return n;
}

oc_node *oc_geology_layer(oc_vec3 origin, oc_vec3 normal, double radius,
                          double resistance, const oc_noise *noise,
                          oc_error *err) {
  oc_vec3 nn;
  if (!oc_check_vec(origin, "origin", err) ||
      !unit(normal, "normal", &nn, err) ||
      !oc_check_positive(radius, "radius", err) ||
      !oc_check_finite(resistance, "resistance", err) ||
      (noise && !oc_check_noise(noise, err)))
    return NULL;
  /* E g(max(0, d)/R) and E g(max(0, -d)/R): their min (E >= 0) or max
  ** (E < 0) is E g(|d|/R) */
  oc_node *half[2] = {
      oc_plane(origin, nn, radius, resistance, err),
      oc_plane(origin, oc_mul(nn, -1), radius, resistance, err)};
  oc_node *slab = NULL, *turb = NULL, *out = NULL;
  if (half[0] && half[1])
    slab = resistance >= 0 ? oc_intersection(half, 2, err)
                           : oc_union(half, 2, err);
  if (slab && noise) {
    turb = oc_turbulence(noise, err);
    oc_node *both[2] = {slab, turb};
    if (turb) out = oc_blend(both, 2, err);
  } else if (slab) {
    out = slab;
    oc_node_retain(out);
  }
  oc_node_release(half[0]);
  oc_node_release(half[1]);
  oc_node_release(slab);
  oc_node_release(turb);
  return out;
}

/* ---- compilation ------------------------------------------------------- */

static void pack_noise(const oc_noise *nz, double *v) {
  v[0] = nz->wavelength;
  v[1] = nz->amplitude;
  v[2] = nz->offset;
  v[3] = (double)nz->octaves;
  v[4] = (double)(nz->seed >> 32);
  v[5] = (double)(nz->seed & 0xffffffffu);
}

static oc_aabb shifted(oc_aabb b, oc_vec3 d) {
  if (oc_aabb_is_empty(b)) return b;
  oc_aabb r = {oc_add(b.lo, d), oc_add(b.hi, d)};
  return r;
}

/* Where a fault's domain may hold points (the node's: its support). */
static oc_aabb fault_domain_box(const double *par, const oc_geo_info *kids) {
  switch ((int)par[OC_GP_DOM]) {
  case OC_FAULT_BOX: {
    oc_aabb b = {get3(par + OC_GP_DA), get3(par + OC_GP_DB)};
    return b;
  }
  case OC_FAULT_NODE:
    return kids[1].box;
  default:
    return oc_aabb_all();
  }
}

size_t oc_geo_compile(const oc_node *n, double T, const oc_geo_info *kids,
                      double *par, oc_geo_info *out) {
  const oc_geo_info *C = kids;
  (void)T;
  switch (n->kind) {
  case OC_K_STRATA: {
    const oc_noise *nz = &n->noise;
    double tmax = oc_turb3_max(nz->octaves), A = nz->amplitude;
    pack_noise(nz, par);
    out->box = oc_aabb_all();
    out->lo = nz->offset + fmin(0, A);
    out->hi = nz->offset + fmax(0, A);
    out->lip =
        fabs(A) / tmax * oc_turb3_lipschitz(nz->octaves) / nz->wavelength;
    return 6;
  }
  case OC_K_CLAMP: {
    double lo = n->par[OC_GP_LO], hi = n->par[OC_GP_HI];
    par[OC_GP_LO] = lo;
    par[OC_GP_HI] = hi;
    out->box = lo <= 0 && hi >= 0 ? C->box : oc_aabb_all();
    out->lo = fmin(fmax(C->lo, lo), hi);
    out->hi = fmin(fmax(C->hi, lo), hi);
    out->lip = C->lip;
    return 2;
  }
  case OC_K_TAPER: {
    for (int i = 0; i <= OC_GP_H; i++)
      par[i] = n->par[i];
    double K = n->par[OC_GP_K], H = n->par[OC_GP_H];
    double du = fabs(n->par[OC_GP_U1] - n->par[OC_GP_U0]);
    /* the displacement is at most |K - 1| H along the axis */
    out->box = oc_aabb_grow(C->box, fabs(K - 1) * H);
    out->lo = C->lo;
    out->hi = C->hi;
    out->lip = C->lip * (fmax(1, K) + 1.5 * H * fabs(K - 1) / du);
    return OC_GP_H + 1;
  }
  case OC_K_FAULT: {
    for (int i = 0; i < OC_GP_COUNT; i++)
      par[i] = n->par[i];
    oc_aabb moved = shifted(C->box, get3(par + OC_GP_OFF));
    out->box = oc_aabb_union(C->box,
                             oc_aabb_inter(moved, fault_domain_box(par, kids)));
    out->lo = C->lo;
    out->hi = C->hi;
    out->lip = C->lip > 0 ? INFINITY : 0;
    return OC_GP_COUNT;
  }
  case OC_K_EROSION:
    return oc_erosion_compile(n, kids, par, out);
  default:
    out->box = oc_aabb_all();
    out->lo = -INFINITY;
    out->hi = INFINITY;
    out->lip = INFINITY;
    return 0;
  }
}

/* ---- evaluation -------------------------------------------------------- */

static double strata(const double *par, oc_vec3 p, oc_vec3 *g) {
  double wl = par[0], A = par[1], off = par[2];
  int oct = (int)par[3];
  uint64_t seed = ((uint64_t)par[4] << 32) | (uint64_t)par[5];
  double k = A / oc_turb3_max(oct);
  oc_vec3 gt;
  double t = oc_turb3(seed, oct, oc_v3(OC_STRATA_X, OC_STRATA_Y, p.z / wl),
                      g ? &gt : 0);
  if (g) *g = oc_v3(0, 0, k * gt.z / wl);
  return off + k * t;
}

/* k(u) = 1 + (K - 1) s(r), r = (u - u0) / (u1 - u0) clamped to [0, 1], s
** the smoothstep; its derivative in *dk. */
static double taper_k(const double *par, double u, double *dk) {
  double u0 = par[OC_GP_U0], u1 = par[OC_GP_U1], K = par[OC_GP_K];
  double r = (u - u0) / (u1 - u0);
  if (r <= 0 || r >= 1) {
    *dk = 0;
    return r <= 0 ? 1 : K;
  }
  *dk = (K - 1) * 6 * r * (1 - r) / (u1 - u0);
  return 1 + (K - 1) * r * r * (3 - 2 * r);
}

static double taper(const oc_program *P, const oc_op *o, const double *par,
                    oc_vec3 p, oc_vec3 *g, oc_geo_kid_fn kid) {
  oc_vec3 d = oc_sub(p, get3(par + OC_GP_TO));
  oc_vec3 a = get3(par + OC_GP_TA), b = get3(par + OC_GP_TB);
  double H = par[OC_GP_H], s = oc_dot(d, a), dk;
  double k = taper_k(par, oc_dot(d, b), &dk);
  double c = s < -H ? -H : s > H ? H : s;
  oc_vec3 q = oc_add(p, oc_mul(a, (k - 1) * c));
  uint32_t ch = P->kids[o->kid];
  if (!g) return kid(P, ch, q, NULL);
  oc_vec3 gc;
  double v = kid(P, ch, q, &gc);
  /* grad = J^T gc, J = I + (k - 1) c'(s) a a^T + c k'(u) a b^T */
  double ag = oc_dot(a, gc), dc = s > -H && s < H ? 1 : 0;
  *g = oc_add(gc, oc_add(oc_mul(a, (k - 1) * dc * ag), oc_mul(b, c * dk * ag)));
  return v;
}

static int in_fault(const oc_program *P, const oc_op *o, const double *par,
                    oc_vec3 p, oc_geo_kid_fn kid) {
  switch ((int)par[OC_GP_DOM]) {
  case OC_FAULT_BOX: {
    const double *lo = par + OC_GP_DA, *hi = par + OC_GP_DB;
    return p.x > lo[0] && p.x < hi[0] && p.y > lo[1] && p.y < hi[1] &&
           p.z > lo[2] && p.z < hi[2];
  }
  case OC_FAULT_HALF:
    return oc_dot(oc_sub(p, get3(par + OC_GP_DA)), get3(par + OC_GP_DB)) < 0;
  default:
    return kid(P, P->kids[o->kid + 1], p, NULL) > P->T;
  }
}

double oc_geo_eval(const oc_program *P, const oc_op *o, oc_vec3 p, oc_vec3 *g,
                   oc_geo_kid_fn kid) {
  const double *par = P->par + o->par;
  switch ((oc_kind)o->kind) {
  case OC_K_STRATA:
    return strata(par, p, g);
  case OC_K_CLAMP: {
    double v = kid(P, P->kids[o->kid], p, g);
    if (v <= par[OC_GP_LO] || v >= par[OC_GP_HI]) {
      if (g) *g = oc_v3(0, 0, 0);
      return v <= par[OC_GP_LO] ? par[OC_GP_LO] : par[OC_GP_HI];
    }
    return v; /* NaN falls through unchanged */
  }
  case OC_K_TAPER:
    return taper(P, o, par, p, g, kid);
  case OC_K_FAULT: {
    /* a translation: the gradient is the child's at the moved point */
    oc_vec3 q =
        in_fault(P, o, par, p, kid) ? oc_sub(p, get3(par + OC_GP_OFF)) : p;
    return kid(P, P->kids[o->kid], q, g);
  }
  case OC_K_EROSION:
    return oc_erosion_eval(P, o, p, g, kid);
  default:
    if (g) *g = oc_v3(NAN, NAN, NAN);
    return NAN;
  }
}

/* ---- local queries ----------------------------------------------------- */

static int foot_meets(const float *lo, const float *hi, double x0, double y0,
                      double x1, double y1) {
  return lo[0] <= x1 && hi[0] >= x0 && lo[1] <= y1 && hi[1] >= y0;
}

/* z-range of a float box, or -1 when it is unbounded. */
static int zrange(const float *lo, const float *hi, double *zlo, double *zhi) {
  if (isinf(lo[2]) || isinf(hi[2])) return -1;
  *zlo = lo[2];
  *zhi = hi[2];
  return 1;
}

int oc_geo_column(const oc_program *P, const oc_op *o, double x0, double y0,
                  double x1, double y1, double *zlo, double *zhi) {
  const double *par = P->par + o->par;
  switch ((oc_kind)o->kind) {
  case OC_K_CLAMP:
    return 0; /* constant where the child is */
  case OC_K_FAULT: {
    /* inside the domain's z-range anything may happen; outside the
    ** domain the field is the child's own */
    float lo[3], hi[3];
    switch ((int)par[OC_GP_DOM]) {
    case OC_FAULT_BOX:
      for (int i = 0; i < 3; i++) {
        lo[i] = (float)par[OC_GP_DA + i];
        hi[i] = (float)par[OC_GP_DB + i];
        /* rounded outwards */
        if ((double)lo[i] > par[OC_GP_DA + i])
          lo[i] = nextafterf(lo[i], -INFINITY);
        if ((double)hi[i] < par[OC_GP_DB + i])
          hi[i] = nextafterf(hi[i], INFINITY);
      }
      break;
    case OC_FAULT_NODE: {
      const oc_op *d = &P->ops[P->kids[o->kid + 1]];
      for (int i = 0; i < 3; i++)
        lo[i] = d->lo[i], hi[i] = d->hi[i];
      break;
    }
    default: {
      /* a half-space: nothing to add when the footprint is all outside
      ** at every z, which needs a horizontal normal */
      const double *q = par + OC_GP_DA, *n = par + OC_GP_DB;
      if (n[2] != 0) return -1;
      double m = fmin(n[0] * (x0 - q[0]), n[0] * (x1 - q[0])) +
                 fmin(n[1] * (y0 - q[1]), n[1] * (y1 - q[1]));
      return m >= 0 ? 0 : -1;
    }
    }
    if (!foot_meets(lo, hi, x0, y0, x1, y1)) return 0;
    return zrange(lo, hi, zlo, zhi);
  }
  case OC_K_EROSION: {
    /* f~ = f wherever f_D = 0 (outside the control's support) or f = 0
    ** (outside the terrain's) */
    const oc_op *f = &P->ops[P->kids[o->kid]];
    float lo[3], hi[3];
    for (int i = 0; i < 3; i++)
      lo[i] = f->lo[i], hi[i] = f->hi[i];
    if (par[OC_GP_HASCTL] != 0) {
      const oc_op *c = &P->ops[P->kids[o->kid + 2]];
      for (int i = 0; i < 3; i++) {
        lo[i] = fmaxf(lo[i], c->lo[i]);
        hi[i] = fminf(hi[i], c->hi[i]);
      }
    }
    if (!(lo[2] <= hi[2]) || !foot_meets(lo, hi, x0, y0, x1, y1)) return 0;
    return zrange(lo, hi, zlo, zhi);
  }
  default: /* strata and taper vary along every column */
    return -1;
  }
}

static int box_meets(const float *lo, const float *hi, const oc_aabb *b) {
  return lo[0] <= b->hi.x && hi[0] >= b->lo.x && lo[1] <= b->hi.y &&
         hi[1] >= b->lo.y && lo[2] <= b->hi.z && hi[2] >= b->lo.z;
}

/* Which side of a fault's boundary box b lies on: 1 inside, 0 outside,
** -1 when it may meet the boundary. */
static int fault_side(const oc_program *P, const oc_op *o, const double *par,
                      const oc_aabb *b) {
  switch ((int)par[OC_GP_DOM]) {
  case OC_FAULT_BOX: {
    const double *lo = par + OC_GP_DA, *hi = par + OC_GP_DB;
    if (b->lo.x > lo[0] && b->hi.x < hi[0] && b->lo.y > lo[1] &&
        b->hi.y < hi[1] && b->lo.z > lo[2] && b->hi.z < hi[2])
      return 1;
    if (b->hi.x < lo[0] || b->lo.x > hi[0] || b->hi.y < lo[1] ||
        b->lo.y > hi[1] || b->hi.z < lo[2] || b->lo.z > hi[2])
      return 0;
    return -1;
  }
  case OC_FAULT_HALF: {
    const double *q = par + OC_GP_DA, *n = par + OC_GP_DB;
    double m = 0, M = 0;
    const double *bl = &b->lo.x, *bh = &b->hi.x;
    for (int i = 0; i < 3; i++) {
      double u = n[i] * (bl[i] - q[i]), v = n[i] * (bh[i] - q[i]);
      m += fmin(u, v);
      M += fmax(u, v);
    }
    return M < 0 ? 1 : m >= 0 ? 0 : -1;
  }
  default: {
    const oc_op *d = &P->ops[P->kids[o->kid + 1]];
    return box_meets(d->lo, d->hi, b) ? -1 : 0;
  }
  }
}

double oc_geo_lipschitz_in(const oc_program *P, const oc_op *o,
                           const oc_aabb *b, oc_geo_lip_fn lip, void *ud) {
  const double *par = P->par + o->par;
  uint32_t ch = P->kids[o->kid];
  switch ((oc_kind)o->kind) {
  case OC_K_CLAMP:
    return lip(P, ch, b, ud);
  case OC_K_FAULT: {
    int side = fault_side(P, o, par, b);
    if (side < 0) return o->lip;
    if (side == 0) return lip(P, ch, b, ud);
    oc_aabb m = shifted(*b, oc_mul(get3(par + OC_GP_OFF), -1));
    return lip(P, ch, &m, ud);
  }
  case OC_K_EROSION: {
    /* where f <= 0 the erosion is f itself: 0 where f's support misses
    ** the box (as between islands under one erosion) */
    if (oc_op_zero_in(P, ch, b)) return 0;
    /* L_f, plus depth (L_control + L_rho) where f_D may be non-zero */
    double L = lip(P, ch, b, ud);
    int hasctl = par[OC_GP_HASCTL] != 0;
    if (hasctl && !box_meets(P->ops[P->kids[o->kid + 2]].lo,
                             P->ops[P->kids[o->kid + 2]].hi, b))
      return L;
    double e = lip(P, P->kids[o->kid + 1], b, ud);
    if (hasctl) e += lip(P, P->kids[o->kid + 2], b, ud);
    return fmin(L + par[OC_GP_DEPTH] * e, o->lip);
  }
  default:
    return o->lip;
  }
}
