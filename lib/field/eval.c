/*
** eval.c — evaluation of a compiled program: value, and value with
** gradient. Read-only on the program, allocation-free, recursion bounded by
** OC_MAX_DEPTH (checked at compile time).
*/
#include <math.h>

#include "core/falloff.h"
#include "core/noise.h"
#include "core/rng.h"
#include "core/vec.h"
#include "field/bvhwalk.h"
#include "field/prim.h"
#include "field/program.h"

static double ev(const oc_program *P, uint32_t i, oc_vec3 p);
static double evg(const oc_program *P, uint32_t i, oc_vec3 p, oc_vec3 *g);

/* ---- extension kinds (kind.h) ----------------------------------------- */

static inline double ext(const oc_program *P, const oc_op *o, oc_vec3 p,
                         oc_vec3 *g) {
  const oc_pext *x = &P->ext[o->ext];
  return x->def->eval(&x->ev, p, g);
}

double oc_child_eval(const oc_kctx *k, size_t i, oc_vec3 p, oc_vec3 *g) {
  const oc_program *P = k->P_;
  uint32_t c = P->kids[P->ops[k->op_].kid + i];
  return g ? evg(P, c, p, g) : ev(P, c, p);
}

static inline int in_op_box(const oc_op *o, oc_vec3 p) {
  return p.x >= o->lo[0] && p.x <= o->hi[0] && p.y >= o->lo[1] &&
         p.y <= o->hi[1] && p.z >= o->lo[2] && p.z <= o->hi[2];
}

static inline int in_node(const oc_bvhnode *nd, oc_vec3 p) {
  return p.x >= nd->lo[0] && p.x <= nd->hi[0] && p.y >= nd->lo[1] &&
         p.y <= nd->hi[1] && p.z >= nd->lo[2] && p.z <= nd->hi[2];
}

/* ---- distance primitives -------------------------------------------- */

static double prim(oc_kind kind, const double *par, oc_vec3 p, oc_vec3 *g) {
  double E = par[OC_P_E], R = par[OC_P_R];
  if (kind == OC_K_POINT) {
    oc_vec3 d =
        oc_v3(p.x - par[OC_P_C], p.y - par[OC_P_C + 1], p.z - par[OC_P_C + 2]);
    double q = oc_dot(d, d) / (R * R);
    if (g) *g = oc_mul(d, E * oc_falloff_dq(q) * 2 / (R * R));
    return E * oc_falloff_q(q);
  }
  oc_vec3 s;
  double d = oc_prim_project(kind, par, p, &s, R);
  double x = d / R;
  if (g) {
    double gd = E * oc_falloff_d(x) / R;
    *g = d > 0 ? oc_mul(oc_sub(p, s), gd / d) : oc_v3(0, 0, 0);
  }
  return E * oc_falloff(x);
}

/* ---- perturbation ----------------------------------------------------- */

/* The largest radius the perturbation can reach: R + max(0, A) tmax. */
static inline double rho_max(const oc_op *o, const double *par) {
  oc_noise nz = oc_noise_unpack(par + o->nkid);
  return par[OC_P_R] + fmax(0, nz.amplitude) * oc_turb3_max(nz.octaves);
}

double oc_perturb_reach(const oc_op *o, const double *par) {
  return rho_max(o, par);
}

/* The perturbed primitive's value in *val; with g, its gradient too,
** analytically: with u = (p - s) / d, v = s + R u and
** rho = R + A t(v / wl),
**   grad f = E g'(d / rho) (u / rho - d grad rho / rho^2),
**   grad rho = (A / wl) Jv^T grad t, Jv = S + (R / d) (I - u u^T)(I - S),
** S = ds/dp from the projection (symmetric). Returns 0 (and nothing)
** when g is asked for a kind without that Jacobian. */
static int perturb_at(const oc_op *o, const double *par, oc_vec3 p, double *val,
                      oc_vec3 *g) {
  double E = par[OC_P_E], R = par[OC_P_R];
  oc_noise nz = oc_noise_unpack(par + o->nkid);
  oc_vec3 s;
  double d, J[9];
  double rmax = rho_max(o, par);
  if (!g)
    d = oc_prim_project((oc_kind)o->sub, par, p, &s, rmax);
  else if (!oc_prim_project_jac((oc_kind)o->sub, par, p, &s, rmax, &d, J))
    return 0;
  if (g) *g = oc_v3(0, 0, 0);
  if (!(d > 0)) {
    *val = d == 0 ? E : d; /* NaN propagates */
    return 1;
  }
  if (d >= rmax) { /* beyond any perturbed radius */
    *val = 0;
    return 1;
  }
  oc_vec3 u = oc_mul(oc_sub(p, s), 1 / d);
  oc_vec3 v = oc_add(s, oc_mul(u, R));
  oc_vec3 gt;
  double rho =
      R + nz.amplitude * oc_turb3(nz.seed, nz.octaves,
                                  oc_mul(v, 1 / nz.wavelength), g ? &gt : NULL);
  double x = d / rho;
  *val = E * oc_falloff(x);
  if (!g) return 1;
  /* Jv^T w = S w + (R / d) (I - S)(w - u (u.w)), w = grad t */
  oc_vec3 w = oc_sub(gt, oc_mul(u, oc_dot(u, gt)));
  oc_vec3 Sg = oc_v3(J[0] * gt.x + J[1] * gt.y + J[2] * gt.z,
                     J[3] * gt.x + J[4] * gt.y + J[5] * gt.z,
                     J[6] * gt.x + J[7] * gt.y + J[8] * gt.z);
  oc_vec3 Sw = oc_v3(J[0] * w.x + J[1] * w.y + J[2] * w.z,
                     J[3] * w.x + J[4] * w.y + J[5] * w.z,
                     J[6] * w.x + J[7] * w.y + J[8] * w.z);
  oc_vec3 jt = oc_add(Sg, oc_mul(oc_sub(w, Sw), R / d));
  oc_vec3 grho = oc_mul(jt, nz.amplitude / nz.wavelength);
  double k = E * oc_falloff_d(x);
  *g = oc_mul(oc_sub(oc_mul(u, 1 / rho), oc_mul(grho, d / (rho * rho))), k);
  return 1;
}

static double perturb(const oc_op *o, const double *par, oc_vec3 p) {
  double v;
  perturb_at(o, par, p, &v, NULL);
  return v;
}
static double perturb_fd(const void *o, const void *P, oc_vec3 p) {
  return perturb(o, ((const oc_program *)P)->par + ((const oc_op *)o)->par, p);
}

/* ---- groups ------------------------------------------------------------ */

static inline double point_ent(const oc_ent *e, oc_vec3 p, oc_vec3 *g) {
  double dx = p.x - e->c[0], dy = p.y - e->c[1], dz = p.z - e->c[2];
  double q = (dx * dx + dy * dy + dz * dz) * e->ir2;
  if (!(q < 1)) return 0;
  double u = 1 - q, E = e->e;
  if (g) {
    double k = -6 * E * u * u * e->ir2;
    *g = oc_v3(k * dx, k * dy, k * dz);
  }
  return E * u * u * u;
}

/* One child's contribution: value (and gradient when g). Returns 0 without
** evaluating when p is outside the child's box; *hit tells whether the
** child was evaluated (unions need to know). */
static inline double ent_eval(const oc_program *P, const oc_ent *e, oc_vec3 p,
                              oc_vec3 *g, int *hit) {
  if (e->ref == OC_NONE) {
    *hit = 1;
    return point_ent(e, p, g);
  }
  const oc_op *o = &P->ops[e->ref];
  if (!in_op_box(o, p)) {
    *hit = 0;
    return 0;
  }
  *hit = 1;
  return g ? evg(P, e->ref, p, g) : ev(P, e->ref, p);
}

static double group(const oc_program *P, const oc_op *o, oc_vec3 p,
                    oc_vec3 *g) {
  int uni = o->kind == OC_K_UNION;
  double acc = uni ? -INFINITY : 0;
  oc_vec3 gacc = oc_v3(0, 0, 0), gk;
  uint32_t visited = 0;
#define TAKE(val)                                                              \
  do {                                                                         \
    double v_ = (val);                                                         \
    if (uni) {                                                                 \
      if (v_ > acc || visited == 0) {                                          \
        acc = v_;                                                              \
        if (g) gacc = gk;                                                      \
      }                                                                        \
    } else {                                                                   \
      acc += v_;                                                               \
      if (g) gacc = oc_add(gacc, gk);                                          \
    }                                                                          \
    visited++;                                                                 \
  } while (0)
  gk = oc_v3(0, 0, 0);
  for (uint32_t k = 0; k < o->nkid; k++) {
    uint32_t ki = P->kids[o->kid + k];
    TAKE(g ? evg(P, ki, p, &gk) : ev(P, ki, p));
  }
  const oc_ent *ent = P->ent;
#define TAKE_ENT(j)                                                            \
  do {                                                                         \
    int hit;                                                                   \
    gk = oc_v3(0, 0, 0);                                                       \
    double v = ent_eval(P, &ent[j], p, g ? &gk : NULL, &hit);                  \
    if (hit) TAKE(v);                                                          \
  } while (0)
  if (o->nent && (o->nobvh || o->bvh == OC_NONE)) {
    for (uint32_t j = o->ent; j < o->ent + o->nent; j++)
      TAKE_ENT(j);
  } else if (o->nent) {
    /* full cannot happen: compile.c refuses trees deeper than the stack
    ** (bvhwalk.h) */
    int full = 0;
#define IN_P(x) in_node(x, p)
    OC_BVH_FOREACH(P->bvh, o->bvh, nd, IN_P, full, {
      for (uint32_t j = nd->first; j < nd->first + nd->count; j++)
        TAKE_ENT(j);
    });
#undef IN_P
    (void)full;
  }
#undef TAKE_ENT
#undef TAKE
  /* children not visited are exactly 0 here */
  if (uni && visited < o->ntotal && acc < 0) {
    acc = 0;
    gacc = oc_v3(0, 0, 0);
  }
  if (g) *g = gacc;
  return acc;
}

/* ---- smooth operators --------------------------------------------------- */

/* C^1 ramp: 3u^2 - 2u^3 on [0, 1]; derivative through *d. */
static inline double ramp(double s, double *d) {
  if (s <= 0) {
    *d = 0;
    return 0;
  }
  if (s >= 1) {
    *d = 0;
    return 1;
  }
  *d = 6 * s * (1 - s);
  return s * s * (3 - 2 * s);
}

/* Value of the smooth operator and its partial derivatives da, db. */
static double smooth(int uni, double a, double b, double r, double T,
                     double *da, double *db) {
  double gd, re, dre_da, dre_db;
  if (uni) {
    re = r * ramp((a + b) / T, &gd);
    dre_da = dre_db = r * gd / T;
  } else {
    re = r * ramp(a * b / (T * T), &gd);
    dre_da = r * gd * b / (T * T);
    dre_db = r * gd * a / (T * T);
  }
  double m, ma, mb;
  if (a == b) {
    m = a;
    ma = mb = 0.5;
  } else if ((a > b) == uni) {
    m = a;
    ma = 1;
    mb = 0;
  } else {
    m = b;
    ma = 0;
    mb = 1;
  }
  double delta = fabs(a - b);
  double sg = a > b ? 1 : a < b ? -1 : 0;
  double corr = 0, ca = 0, cb = 0;
  if (re > 0 && delta < re) {
    double k = 1 - delta / re;
    corr = re * k * k * k / 6;
    double cdelta = -k * k / 2;                    /* d corr / d delta */
    double cre = k * k * (1 + 2 * delta / re) / 6; /* d corr / d re */
    ca = cdelta * sg + cre * dre_da;
    cb = -cdelta * sg + cre * dre_db;
  }
  if (uni) {
    *da = ma + ca;
    *db = mb + cb;
    return m + corr;
  }
  *da = ma - ca;
  *db = mb - cb;
  return m - corr;
}

/* ---- warp ---------------------------------------------------------------- */

/* Displacement delta(p) = A (t_i(p / wl) - tmax/2), i = 1..3; with jac
** (when not NULL) its Jacobian rows. */
static oc_vec3 displacement(const oc_noise *nz, oc_vec3 p, oc_vec3 jac[3]) {
  oc_vec3 q = oc_mul(p, 1 / nz->wavelength);
  double half = oc_turb3_max(nz->octaves) / 2, d[3];
  for (int i = 0; i < 3; i++) {
    uint64_t seed = oc_mix64(nz->seed + 0x9e3779b97f4a7c15ull * (i + 1));
    oc_vec3 gr;
    d[i] = nz->amplitude *
           (oc_turb3(seed, nz->octaves, q, jac ? &gr : NULL) - half);
    if (jac) jac[i] = oc_mul(gr, nz->amplitude / nz->wavelength);
  }
  return oc_v3(d[0], d[1], d[2]);
}

static double warp(const oc_program *P, const oc_op *o, oc_vec3 p, oc_vec3 *g) {
  oc_noise nz = oc_noise_unpack(P->par + o->par);
  uint32_t child = P->kids[o->kid];
  double w = 1;
  oc_vec3 gw = oc_v3(0, 0, 0);
  if (o->nkid > 1) {
    uint32_t ctl = P->kids[o->kid + 1];
    w = g ? evg(P, ctl, p, &gw) : ev(P, ctl, p);
    if (w <= 0) {
      w = 0;
      gw = oc_v3(0, 0, 0);
    } else if (w >= 1) {
      w = 1;
      gw = oc_v3(0, 0, 0);
    }
    if (w == 0) return g ? evg(P, child, p, g) : ev(P, child, p);
  }
  oc_vec3 jac[3];
  oc_vec3 dsp = displacement(&nz, p, g ? jac : NULL);
  oc_vec3 q = oc_add(p, oc_mul(dsp, w));
  if (!g) return ev(P, child, q);
  oc_vec3 gc;
  double v = evg(P, child, q, &gc);
  /* grad = Jq^T gc, Jq = I + w J_delta + delta gw^T */
  oc_vec3 r = gc;
  r = oc_add(r, oc_mul(jac[0], w * gc.x));
  r = oc_add(r, oc_mul(jac[1], w * gc.y));
  r = oc_add(r, oc_mul(jac[2], w * gc.z));
  r = oc_add(r, oc_mul(gw, oc_dot(dsp, gc)));
  *g = r;
  return v;
}

/* ---- dispatch ------------------------------------------------------------ */

static inline oc_vec3 affine(const double *m, oc_vec3 p) {
  return oc_v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
               m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
               m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

static double ev(const oc_program *P, uint32_t i, oc_vec3 p) {
  const oc_op *o = &P->ops[i];
  const double *par = P->par + o->par;
  switch ((oc_kind)o->kind) {
  case OC_K_BLEND:
  case OC_K_UNION:
    return group(P, o, p, NULL);
  case OC_K_TURB: {
    oc_noise nz = oc_noise_unpack(par);
    return nz.offset + nz.amplitude * oc_turb3(nz.seed, nz.octaves,
                                               oc_mul(p, 1 / nz.wavelength),
                                               NULL);
  }
  case OC_K_INTER: {
    double m = INFINITY;
    for (uint32_t k = 0; k < o->nkid; k++) {
      double v = ev(P, P->kids[o->kid + k], p);
      if (v < m || isnan(v)) m = v;
    }
    return m;
  }
  case OC_K_DIFF: {
    double a = ev(P, P->kids[o->kid], p);
    double b = ev(P, P->kids[o->kid + 1], p);
    double c = 2 * P->T - b;
    return isnan(b) ? b : a < c ? a : c;
  }
  case OC_K_SUNION:
  case OC_K_SINTER: {
    double da, db;
    double a = ev(P, P->kids[o->kid], p), b = ev(P, P->kids[o->kid + 1], p);
    return smooth(o->kind == OC_K_SUNION, a, b, par[0], P->T, &da, &db);
  }
  case OC_K_SCALE:
    return par[0] * ev(P, P->kids[o->kid], p);
  case OC_K_WARP:
    return warp(P, o, p, NULL);
  case OC_K_XFORM:
    return ev(P, P->kids[o->kid], affine(par + OC_P_INV, p));
  case OC_K_PERTURB:
    return perturb(o, par, p);
  case OC_K_EXT:
    return ext(P, o, p, NULL);
  default:
    return prim((oc_kind)o->kind, par, p, NULL);
  }
}

static double evg(const oc_program *P, uint32_t i, oc_vec3 p, oc_vec3 *g) {
  const oc_op *o = &P->ops[i];
  const double *par = P->par + o->par;
  switch ((oc_kind)o->kind) {
  case OC_K_BLEND:
  case OC_K_UNION:
    return group(P, o, p, g);
  case OC_K_TURB: {
    oc_noise nz = oc_noise_unpack(par);
    oc_vec3 gt;
    double t = oc_turb3(nz.seed, nz.octaves, oc_mul(p, 1 / nz.wavelength), &gt);
    *g = oc_mul(gt, nz.amplitude / nz.wavelength);
    return nz.offset + nz.amplitude * t;
  }
  case OC_K_INTER: {
    double m = INFINITY;
    *g = oc_v3(0, 0, 0);
    for (uint32_t k = 0; k < o->nkid; k++) {
      oc_vec3 gk;
      double v = evg(P, P->kids[o->kid + k], p, &gk);
      if (v < m || isnan(v)) {
        m = v;
        *g = gk;
      }
    }
    return m;
  }
  case OC_K_DIFF: {
    oc_vec3 ga, gb;
    double a = evg(P, P->kids[o->kid], p, &ga);
    double b = evg(P, P->kids[o->kid + 1], p, &gb);
    double c = 2 * P->T - b;
    if (a < c) {
      *g = ga;
      return a;
    }
    *g = oc_mul(gb, -1);
    return c;
  }
  case OC_K_SUNION:
  case OC_K_SINTER: {
    oc_vec3 ga, gb;
    double da, db;
    double a = evg(P, P->kids[o->kid], p, &ga);
    double b = evg(P, P->kids[o->kid + 1], p, &gb);
    double v = smooth(o->kind == OC_K_SUNION, a, b, par[0], P->T, &da, &db);
    *g = oc_add(oc_mul(ga, da), oc_mul(gb, db));
    return v;
  }
  case OC_K_SCALE: {
    double v = evg(P, P->kids[o->kid], p, g);
    *g = oc_mul(*g, par[0]);
    return par[0] * v;
  }
  case OC_K_WARP:
    return warp(P, o, p, g);
  case OC_K_XFORM: {
    const double *m = par + OC_P_INV;
    oc_vec3 gc;
    double v = evg(P, P->kids[o->kid], affine(m, p), &gc);
    /* grad = Minv^T gc */
    *g = oc_v3(m[0] * gc.x + m[4] * gc.y + m[8] * gc.z,
               m[1] * gc.x + m[5] * gc.y + m[9] * gc.z,
               m[2] * gc.x + m[6] * gc.y + m[10] * gc.z);
    return v;
  }
  case OC_K_PERTURB: {
    /* Analytic for every kind but cones, whose projection's Jacobian
    ** takes central differences. */
    double v;
    if (perturb_at(o, par, p, &v, g)) return v;
    return oc_fd_gradient(perturb_fd, o, P, p, 1e-6 * fmax(par[OC_P_R], 1e-3),
                          g);
  }
  case OC_K_EXT:
    return ext(P, o, p, g);
  default:
    return prim((oc_kind)o->kind, par, p, g);
  }
}

/* NaN in gives NaN out: checked once here, since deep inside a NaN would
** simply fail every support test and read as 0. */
static inline int has_nan(oc_vec3 p) {
  return isnan(p.x) || isnan(p.y) || isnan(p.z);
}

double oc_program_eval(const oc_program *P, oc_vec3 p) {
  if (has_nan(p)) return NAN;
  return ev(P, P->root, p);
}

double oc_program_gradient(const oc_program *P, oc_vec3 p, oc_vec3 *grad) {
  oc_vec3 g;
  if (has_nan(p)) {
    if (grad) *grad = oc_v3(NAN, NAN, NAN);
    return NAN;
  }
  double v = evg(P, P->root, p, &g);
  if (grad) *grad = g;
  return v;
}

void oc_program_eval_many(const oc_program *P, const oc_vec3 *p, double *out,
                          size_t n) {
  long long nn = (long long)n;
#pragma omp parallel for schedule(static, 4096) if (nn > 8192)
  for (long long i = 0; i < nn; i++)
    out[i] = has_nan(p[i]) ? NAN : ev(P, P->root, p[i]);
}
