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

static const oc_kind_def strata_kind, clamp_kind, taper_kind, fault_kind;

oc_node *oc_strata(const oc_noise *noise, oc_error *err) {
  double par[OC_NOISE_NPAR];
  if (!oc_check_noise(noise, err)) return NULL;
  oc_noise_pack(noise, par);
  return oc_kind_node(&strata_kind, NULL, 0, par, OC_NOISE_NPAR, NULL, err);
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
  double par[2] = {lo, hi};
  return oc_kind_node(&clamp_kind, &child, 1, par, 2, NULL, err);
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
  double par[OC_GP_H + 1];
  put3(par + OC_GP_TO, tp->origin);
  put3(par + OC_GP_TA, a);
  put3(par + OC_GP_TB, b);
  par[OC_GP_U0] = tp->from;
  par[OC_GP_U1] = tp->to;
  par[OC_GP_K] = tp->factor;
  par[OC_GP_H] = tp->height;
  return oc_kind_node(&taper_kind, &child, 1, par, OC_GP_H + 1, NULL, err);
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
  return oc_kind_node(&fault_kind, kids, kids[1] ? 2 : 1, par, OC_GP_COUNT,
                      NULL, err);
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

/* The node's parameters, unchanged by T, are the op's. */
static void copy_par(oc_kcompile *c) {
  for (size_t i = 0; i < c->node_npar; i++)
    c->par[i] = c->node_par[i];
  c->npar = c->node_npar;
}

static oc_aabb shifted(oc_aabb b, oc_vec3 d) {
  if (oc_aabb_is_empty(b)) return b;
  oc_aabb r = {oc_add(b.lo, d), oc_add(b.hi, d)};
  return r;
}

static int strata_compile(oc_kcompile *c, oc_error *err) {
  oc_noise nz = oc_noise_unpack(c->node_par);
  double wl = nz.wavelength, A = nz.amplitude, off = nz.offset;
  int oct = nz.octaves;
  (void)err;
  copy_par(c);
  c->info.box = oc_aabb_all();
  c->info.lo = off + fmin(0, A);
  c->info.hi = off + fmax(0, A);
  c->info.lip = fabs(A) / oc_turb3_max(oct) * oc_turb3_lipschitz(oct) / wl;
  return OC_OK;
}

static int clamp_compile(oc_kcompile *c, oc_error *err) {
  const oc_kinfo *C = c->kid;
  double lo = c->node_par[OC_GP_LO], hi = c->node_par[OC_GP_HI];
  (void)err;
  copy_par(c);
  c->info.box = lo <= 0 && hi >= 0 ? C->box : oc_aabb_all();
  c->info.lo = fmin(fmax(C->lo, lo), hi);
  c->info.hi = fmin(fmax(C->hi, lo), hi);
  c->info.lip = C->lip;
  return OC_OK;
}

static int taper_compile(oc_kcompile *c, oc_error *err) {
  const oc_kinfo *C = c->kid;
  const double *n = c->node_par;
  double K = n[OC_GP_K], H = n[OC_GP_H];
  double du = fabs(n[OC_GP_U1] - n[OC_GP_U0]);
  (void)err;
  copy_par(c);
  /* the displacement is at most |K - 1| H along the axis */
  c->info.box = oc_aabb_grow(C->box, fabs(K - 1) * H);
  c->info.lo = C->lo;
  c->info.hi = C->hi;
  c->info.lip = C->lip * (fmax(1, K) + 1.5 * H * fabs(K - 1) / du);
  return OC_OK;
}

/* Where a fault's domain may hold points (the node's: its support). */
static oc_aabb fault_domain_box(const double *par, const oc_kinfo *kids) {
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

static int fault_compile(oc_kcompile *c, oc_error *err) {
  const oc_kinfo *C = c->kid;
  (void)err;
  copy_par(c);
  oc_aabb moved = shifted(C->box, get3(c->par + OC_GP_OFF));
  c->info.box = oc_aabb_union(
      C->box, oc_aabb_inter(moved, fault_domain_box(c->par, c->kid)));
  c->info.lo = C->lo;
  c->info.hi = C->hi;
  c->info.lip = C->lip > 0 ? INFINITY : 0;
  return OC_OK;
}

/* ---- evaluation -------------------------------------------------------- */

static double strata_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  oc_noise nz = oc_noise_unpack(k->par);
  double wl = nz.wavelength, A = nz.amplitude, off = nz.offset;
  int oct = nz.octaves;
  uint64_t seed = nz.seed;
  double kk = A / oc_turb3_max(oct);
  oc_vec3 gt;
  double t = oc_turb3(seed, oct, oc_v3(OC_STRATA_X, OC_STRATA_Y, p.z / wl),
                      g ? &gt : 0);
  if (g) *g = oc_v3(0, 0, kk * gt.z / wl);
  return off + kk * t;
}

static double clamp_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const double *par = k->par;
  double v = oc_child_eval(k, 0, p, g);
  if (v <= par[OC_GP_LO] || v >= par[OC_GP_HI]) {
    if (g) *g = oc_v3(0, 0, 0);
    return v <= par[OC_GP_LO] ? par[OC_GP_LO] : par[OC_GP_HI];
  }
  return v; /* NaN falls through unchanged */
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

static double taper_eval(const oc_kctx *kc, oc_vec3 p, oc_vec3 *g) {
  const double *par = kc->par;
  oc_vec3 d = oc_sub(p, get3(par + OC_GP_TO));
  oc_vec3 a = get3(par + OC_GP_TA), b = get3(par + OC_GP_TB);
  double H = par[OC_GP_H], s = oc_dot(d, a), dk;
  double k = taper_k(par, oc_dot(d, b), &dk);
  double c = s < -H ? -H : s > H ? H : s;
  oc_vec3 q = oc_add(p, oc_mul(a, (k - 1) * c));
  if (!g) return oc_child_eval(kc, 0, q, NULL);
  oc_vec3 gc;
  double v = oc_child_eval(kc, 0, q, &gc);
  /* grad = J^T gc, J = I + (k - 1) c'(s) a a^T + c k'(u) a b^T */
  double ag = oc_dot(a, gc), dc = s > -H && s < H ? 1 : 0;
  *g = oc_add(gc, oc_add(oc_mul(a, (k - 1) * dc * ag), oc_mul(b, c * dk * ag)));
  return v;
}

static int in_fault(const oc_kctx *k, oc_vec3 p) {
  const double *par = k->par;
  switch ((int)par[OC_GP_DOM]) {
  case OC_FAULT_BOX: {
    const double *lo = par + OC_GP_DA, *hi = par + OC_GP_DB;
    return p.x > lo[0] && p.x < hi[0] && p.y > lo[1] && p.y < hi[1] &&
           p.z > lo[2] && p.z < hi[2];
  }
  case OC_FAULT_HALF:
    return oc_dot(oc_sub(p, get3(par + OC_GP_DA)), get3(par + OC_GP_DB)) < 0;
  default:
    return oc_child_eval(k, 1, p, NULL) > k->T;
  }
}

/* A translation: the gradient is the child's at the moved point. */
static double fault_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  oc_vec3 q = in_fault(k, p) ? oc_sub(p, get3(k->par + OC_GP_OFF)) : p;
  return oc_child_eval(k, 0, q, g);
}

/* ---- local queries ----------------------------------------------------- */

static int foot_meets(oc_aabb b, const oc_foot *f) {
  return b.lo.x <= f->x1 && b.hi.x >= f->x0 && b.lo.y <= f->y1 &&
         b.hi.y >= f->y0;
}

/* The z-range of box b, or the whole column when it is unbounded. */
static void zrange(oc_aabb b, oc_colq *q) {
  if (isinf(b.lo.z) || isinf(b.hi.z))
    oc_col_whole(q);
  else
    oc_col_add(q, b.lo.z, b.hi.z);
}

/* Strata and taper vary along every column. */
static int column_whole(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  (void)k, (void)f;
  oc_col_whole(q);
  return 0;
}

/* Constant where the child is. */
static int clamp_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  oc_child_spans(k, 0, f, q);
  return 0;
}

/* The domain's box rounded outwards to floats, as every support box. */
static oc_aabb fault_box(const double *par) {
  float lo[3], hi[3];
  for (int i = 0; i < 3; i++) {
    lo[i] = (float)par[OC_GP_DA + i];
    hi[i] = (float)par[OC_GP_DB + i];
    if ((double)lo[i] > par[OC_GP_DA + i]) lo[i] = nextafterf(lo[i], -INFINITY);
    if ((double)hi[i] < par[OC_GP_DB + i]) hi[i] = nextafterf(hi[i], INFINITY);
  }
  oc_aabb b = {oc_v3(lo[0], lo[1], lo[2]), oc_v3(hi[0], hi[1], hi[2])};
  return b;
}

/* Inside the domain's z-range anything may happen; outside the domain
** the field is the child's own. */
static int fault_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  const double *par = k->par;
  oc_aabb d;
  switch ((int)par[OC_GP_DOM]) {
  case OC_FAULT_BOX:
    d = fault_box(par);
    break;
  case OC_FAULT_NODE:
    d = oc_child_box(k, 1);
    break;
  default: {
    /* a half-space: nothing to add when the footprint is all outside at
    ** every z, which needs a horizontal normal */
    const double *o = par + OC_GP_DA, *n = par + OC_GP_DB;
    double m = fmin(n[0] * (f->x0 - o[0]), n[0] * (f->x1 - o[0])) +
               fmin(n[1] * (f->y0 - o[1]), n[1] * (f->y1 - o[1]));
    if (n[2] != 0 || m < 0) {
      oc_col_whole(q);
      return 0;
    }
    oc_child_spans(k, 0, f, q);
    return 0;
  }
  }
  if (foot_meets(d, f)) zrange(d, q);
  oc_child_spans(k, 0, f, q);
  return 0;
}

static int box_meets(oc_aabb a, const oc_aabb *b) {
  return a.lo.x <= b->hi.x && a.hi.x >= b->lo.x && a.lo.y <= b->hi.y &&
         a.hi.y >= b->lo.y && a.lo.z <= b->hi.z && a.hi.z >= b->lo.z;
}

/* Which side of a fault's boundary box b lies on: 1 inside, 0 outside,
** -1 when it may meet the boundary. */
static int fault_side(const oc_kctx *k, const oc_aabb *b) {
  const double *par = k->par;
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
    const double *o = par + OC_GP_DA, *n = par + OC_GP_DB;
    double m = 0, M = 0;
    const double *bl = &b->lo.x, *bh = &b->hi.x;
    for (int i = 0; i < 3; i++) {
      double u = n[i] * (bl[i] - o[i]), v = n[i] * (bh[i] - o[i]);
      m += fmin(u, v);
      M += fmax(u, v);
    }
    return M < 0 ? 1 : m >= 0 ? 0 : -1;
  }
  default:
    return box_meets(oc_child_box(k, 1), b) ? -1 : 0;
  }
}

static double clamp_lip_in(const oc_kctx *k, const oc_aabb *b) {
  return oc_child_lipschitz_in(k, 0, b);
}

static double fault_lip_in(const oc_kctx *k, const oc_aabb *b) {
  int side = fault_side(k, b);
  if (side < 0) return k->lip;
  if (side == 0) return oc_child_lipschitz_in(k, 0, b);
  oc_aabb m = shifted(*b, oc_mul(get3(k->par + OC_GP_OFF), -1));
  return oc_child_lipschitz_in(k, 0, &m);
}

/* ---- the kinds (field/kind.h) ------------------------------------------ */

static const oc_kind_def strata_kind = {
    .name = "strata",
    .flags = OC_KF_PRIM,
    .compile = strata_compile,
    .eval = strata_eval,
    .column = column_whole,
};

static const oc_kind_def clamp_kind = {
    .name = "clamp",
    .compile = clamp_compile,
    .eval = clamp_eval,
    .lipschitz_in = clamp_lip_in,
    .column = clamp_column,
};

static const oc_kind_def taper_kind = {
    .name = "taper",
    .compile = taper_compile,
    .eval = taper_eval,
    .column = column_whole,
};

static const oc_kind_def fault_kind = {
    .name = "fault",
    .compile = fault_compile,
    .eval = fault_eval,
    .lipschitz_in = fault_lip_in,
    .column = fault_column,
};
