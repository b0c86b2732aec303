/*
** terrain.c — the terrain primitive (Paris et al. 2019, section 5.1): an
** elevation
** source h over a domain Omega made a 3D field f = min(f_T, f_P), with
** f_T = sigma(v), v = h(x, y) - z (z - h when inverted), and
** f_P = 2T g(d / R), d the distance to the prism (Omega shrunk by R) x
** [zlo, zhi]. Constructor, value, gradient, support, Lipschitz bounds and
** column spans.
**
** A source with a weight alpha (elevation trees) adds a third term:
** f = min(f_T, f_P, f_W), f_W = 2T clamp(1/2 + K (alpha - 1/2), 0, 1)
** with K = WEIGHT_GAIN, so f_W >= T exactly on Omega_T = {alpha >= 1/2}:
** there the surface is z = h, and where alpha < 1/2 nothing is solid (the
** solid ends in vertical walls along alpha = 1/2). f_W is constant along
** columns: column spans and direct extraction are those of the prism
** wherever alpha > 1/2. The gain makes f exactly 0 where alpha <= 1/2 -
** 1/(2K), so the mesher and the tracers skip most of the holes of the
** tree at the price of a K times steeper wall.
**
** sigma is the paper's piecewise odd cubic around (0, T): sigma(0) = T,
** sigma(+-W) = 2T or 0, flat beyond. With s = sigma'(0) W / T = k, on
** u = |v| / W in [0, 1]: sigma = T +- T (k u + (3 - 2k) u^2 + (k - 2) u^3).
** The paper takes sigma'(0) = 1 (k = W / T); past k = 3 that cubic
** overshoots 2T and stops being monotone, so k is capped at 3.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/falloff.h"
#include "core/sigma.h"
#include "field/kind.h"
#include "terrain/terrain.h"

/* g(x) = 1/2: where f_P = 2T g crosses T. sqrt(1 - 2^(-1/3)). */
#define X_HALF 0.45420201894740647
#define DEFAULT_W 1.0
/* K of the weight term: f_W is 0 below alpha = 3/8, 2T above 5/8 */
#define WEIGHT_GAIN 4.0
#define WEIGHT_ZERO (0.5 - 0.5 / WEIGHT_GAIN)
#define WEIGHT_FULL (0.5 + 0.5 / WEIGHT_GAIN)

/* ---- sigma ------------------------------------------------------------ */

void oc_terrain_sigma(double T, double W, double par[OC_TPAR_N]) {
  oc_sigma_params(T, W, par);
}

static inline double sigma(const double *par, double v, double *ds) {
  return oc_sigma(par, v, ds);
}

/* ---- the prism ---------------------------------------------------------- */

/* Distance to the prism; its gradient in *g when g is not NULL (0 where
** the distance is 0). INFINITY off a mask's grid. */
static double prism_dist(const oc_tdata *t, oc_vec3 p, oc_vec3 *g) {
  double dz = 0, sz = 0;
  if (p.z < t->zlo) {
    dz = t->zlo - p.z;
    sz = -1;
  } else if (p.z > t->zhi) {
    dz = p.z - t->zhi;
    sz = 1;
  }
  double gx = 0, gy = 0, d2;
  if (t->dist) {
    double gh[2];
    double dh = oc_terrain_mask_dist(t, p.x, p.y, g ? gh : NULL);
    d2 = dh * dh + dz * dz;
    if (g && d2 > 0 && d2 < INFINITY) {
      gx = dh * gh[0];
      gy = dh * gh[1];
    }
  } else if (t->open) {
    /* inside the domain (sides included) f_P depends on z alone; off it
    ** f = 0: an infinite distance */
    if (!(p.x >= t->sx0 && p.x <= t->sx1 && p.y >= t->sy0 && p.y <= t->sy1))
      d2 = INFINITY;
    else
      d2 = dz * dz;
  } else {
    double ax = 0, ay = 0;
    if (p.x < t->ix0)
      ax = p.x - t->ix0;
    else if (p.x > t->ix1)
      ax = p.x - t->ix1;
    if (p.y < t->iy0)
      ay = p.y - t->iy0;
    else if (p.y > t->iy1)
      ay = p.y - t->iy1;
    d2 = ax * ax + ay * ay + dz * dz;
    gx = ax;
    gy = ay;
  }
  double d = sqrt(d2);
  if (g)
    *g = d > 0 && d < INFINITY ? (oc_vec3){gx / d, gy / d, dz * sz / d}
                               : (oc_vec3){0, 0, 0};
  return d;
}

/* ---- value and gradient ------------------------------------------------- */

/* The kind's eval hook (the table below). */
static double terrain_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const oc_tdata *t = k->data;
  const double *par = k->par;
  double T2 = 2 * par[OC_TPAR_T], W = par[OC_TPAR_W];
  if (g) *g = (oc_vec3){0, 0, 0};
  /* f_T is 0 beyond the elevation range: no need to look h up */
  if (t->invert ? p.z <= t->zlo - W : p.z >= t->zhi + W) return 0;
  oc_vec3 gd;
  double d = prism_dist(t, p, g ? &gd : NULL);
  if (!(d < t->R)) return 0;
  double x = d / t->R;
  double fp = T2 * oc_falloff(x);
  double gh[2], a = 1, ga[2] = {0, 0};
  double h = t->src.height_weight
                 ? t->src.height_weight(t->src.ud, p.x, p.y, g ? gh : NULL, &a,
                                        g ? ga : NULL)
                 : t->src.height(t->src.ud, p.x, p.y, g ? gh : NULL);
  double v = t->invert ? p.z - h : h - p.z, ds;
  double ft = sigma(par, v, &ds);
  /* f_W (no weight: alpha = 1, f_W = 2T, never below the rest) */
  double fw = a >= WEIGHT_FULL  ? T2
              : a > WEIGHT_ZERO ? T2 * (0.5 + WEIGHT_GAIN * (a - 0.5))
                                : 0;
  if (fw < ft && fw < fp) {
    if (g) {
      double k = a > WEIGHT_ZERO && a < WEIGHT_FULL ? T2 * WEIGHT_GAIN : 0;
      *g = (oc_vec3){k * ga[0], k * ga[1], 0};
    }
    return fw;
  }
  if (ft <= fp || isnan(ft)) {
    if (g) {
      double s = t->invert ? -ds : ds;
      *g = (oc_vec3){s * gh[0], s * gh[1], -s};
    }
    return ft;
  }
  if (g) {
    double k = T2 * oc_falloff_d(x) / t->R;
    *g = (oc_vec3){k * gd.x, k * gd.y, k * gd.z};
  }
  return fp;
}

double oc_terrain_column_value(const oc_tdata *t, const double *par, double h,
                               double z) {
  double ds, dz = z < t->zlo ? t->zlo - z : z > t->zhi ? z - t->zhi : 0;
  double fp = 2 * par[OC_TPAR_T] * oc_falloff(dz / t->R);
  double ft = sigma(par, t->invert ? z - h : h - z, &ds);
  return ft < fp ? ft : fp;
}

double oc_terrain_cap_z(const oc_tdata *t) {
  return t->invert ? t->zhi + X_HALF * t->R : t->zlo - X_HALF * t->R;
}

/* ---- bounds ---------------------------------------------------------------
 */

oc_aabb oc_terrain_box(const oc_tdata *t) {
  double zl = t->invert ? t->zlo - t->W : t->zlo - t->R;
  double zh = t->invert ? t->zhi + t->R : t->zhi + t->W;
  return (oc_aabb){{t->sx0, t->sy0, zl}, {t->sx1, t->sy1, zh}};
}

static double lip_prism(const oc_tdata *t, const double *par) {
  /* |grad d| <= max(|grad d_h|, 1): sqrt 2 for the bilinear mask
  ** distance (with a margin for its single-precision nodes), 1 else (open
  ** edges: d varies along z alone, and the jump at the sides is no
  ** derivative: oc_terrain_lipschitz_in answers for boxes across them) */
  double ld = t->dist ? sqrt(2.0) * (1 + 1e-6) : 1;
  return 2 * par[OC_TPAR_T] * OC_FALLOFF_LIPSCHITZ / t->R * ld;
}

static double lip_surface(const double *par, double slope) {
  return par[OC_TPAR_DS] * sqrt(1 + slope * slope);
}

double oc_terrain_lipschitz(const oc_tdata *t, const double *par) {
  return fmax(fmax(lip_surface(par, t->slope), lip_prism(t, par)),
              2 * par[OC_TPAR_T] * WEIGHT_GAIN * t->wlip);
}

/* A weighted source on the footprint: *zero when f_W is 0 there (alpha
** <= WEIGHT_ZERO), *full when alpha > 1/2 throughout (f_W > T: the
** surface and the sign of f - T are those without it), and the Lipschitz
** bound of f_W (0 where it is 2T). Without a weight: full, bound 0. */
static double foot_weight(const oc_tdata *t, const double *par, double x0,
                          double y0, double x1, double y1, int *zero,
                          int *full) {
  *zero = 0;
  *full = 1;
  if (!t->src.weight_range) return 0;
  double lo, hi, lip;
  t->src.weight_range(t->src.ud, x0, y0, x1, y1, &lo, &hi, &lip);
  *zero = hi <= WEIGHT_ZERO;
  *full = lo > 0.5;
  return lo >= WEIGHT_FULL || *zero ? 0
                                    : 2 * par[OC_TPAR_T] * WEIGHT_GAIN * lip;
}

/* Whether f_P is 2T over the whole footprint between zlo and zhi (the
** prism's interior), and whether it is 0 over the whole footprint. */
static void foot_prism(const oc_tdata *t, double x0, double y0, double x1,
                       double y1, int *inside, int *outside) {
  if (t->dist) {
    double lo, hi;
    oc_terrain_mask_range(t, x0, y0, x1, y1, &lo, &hi);
    *inside = hi == 0;
    *outside = lo >= t->R;
    return;
  }
  *inside = x0 >= t->ix0 && x1 <= t->ix1 && y0 >= t->iy0 && y1 <= t->iy1;
  /* open edges: f != 0 on the sides themselves */
  if (t->open)
    *outside = x1 < t->sx0 || x0 > t->sx1 || y1 < t->sy0 || y0 > t->sy1;
  else
    *outside = x1 <= t->sx0 || x0 >= t->sx1 || y1 <= t->sy0 || y0 >= t->sy1;
}

double oc_terrain_lipschitz_in(const oc_tdata *t, const double *par,
                               const oc_aabb *b) {
  double W = par[OC_TPAR_W];
  int inside, outside, wzero, wfull;
  foot_prism(t, b->lo.x, b->lo.y, b->hi.x, b->hi.y, &inside, &outside);
  if (outside) return 0;
  double lw =
      foot_weight(t, par, b->lo.x, b->lo.y, b->hi.x, b->hi.y, &wzero, &wfull);
  if (wzero) return 0;
  double hlo, hhi;
  t->src.range(t->src.ud, b->lo.x, b->lo.y, b->hi.x, b->hi.y, &hlo, &hhi);
  /* f_T is 0 on the whole box: so is f */
  if (t->invert ? b->hi.z <= hlo - W : b->lo.z >= hhi + W) return 0;
  /* open edges: across a side f jumps from 0 to up to 2T, which no
  ** finite bound covers (callers then take small steps, or none) */
  if (t->open && !inside) {
    oc_aabb s = oc_terrain_box(t);
    if (b->hi.z < s.lo.z || b->lo.z > s.hi.z) return 0;
    return INFINITY;
  }
  double lt = 0, lp = 0;
  if (b->hi.z > hlo - W && b->lo.z < hhi + W)
    lt = lip_surface(
        par, t->src.slope(t->src.ud, b->lo.x, b->lo.y, b->hi.x, b->hi.y));
  if (!(inside && b->lo.z >= t->zlo && b->hi.z <= t->zhi))
    lp = lip_prism(t, par);
  return fmax(fmax(lt, lp), lw);
}

int oc_terrain_spans(const oc_tdata *t, const double *par, double x0, double y0,
                     double x1, double y1, int zvar,
                     void (*add)(void *, double, double), void *S) {
  double W = par[OC_TPAR_W], R = t->R;
  int inside, outside, wzero, wfull;
  foot_prism(t, x0, y0, x1, y1, &inside, &outside);
  if (outside) return 0;
  foot_weight(t, par, x0, y0, x1, y1, &wzero, &wfull);
  if (wzero) return 0;
  /* where alpha may be <= 1/2, f_W varies across the footprint at every
  ** z where f may be > 0: no direct case */
  inside = inside && wfull;
  double hlo, hhi;
  t->src.range(t->src.ud, x0, y0, x1, y1, &hlo, &hhi);
  /* margin for the rounding of v = h - z and of u = v / W */
  double pad = 1e-9 * (fabs(hlo) + fabs(hhi) + W + R);
  double alo = hlo - W - pad, ahi = hhi + W + pad;
  add(S, alo, ahi);
  /* where f_P varies, clipped to where f_T > 0 (elsewhere f = 0); along
  ** a column, f_P depends on z only below zlo and above zhi */
  oc_zspan b[2] = {{t->zlo - R - pad, t->zlo + pad},
                   {t->zhi - pad, t->zhi + R + pad}};
  if (!inside && !zvar) {
    b[0].hi = b[1].hi;
    b[1].lo = 1, b[1].hi = 0;
  }
  for (int k = 0; k < 2; k++) {
    if (t->invert)
      b[k].lo = fmax(b[k].lo, alo);
    else
      b[k].hi = fmin(b[k].hi, ahi);
    if (b[k].lo <= b[k].hi) add(S, b[k].lo, b[k].hi);
  }
  return inside;
}

/* ---- empty meshes ------------------------------------------------------ */

static const oc_kind_def terrain_kind;

int oc_terrain_thin_reason(const struct oc_program *P, double size,
                           const char *what, char *buf, size_t n) {
  size_t it = 0;
  for (const oc_tdata *t; (t = oc_program_kind_data(P, &terrain_kind, &it));) {
    /* the solid ends at the cap, X_HALF R past [zlo, zhi] on its side:
    ** thinnest under the lowest elevation (over the highest inverted) */
    double lo, hi;
    t->src.range(t->src.ud, t->sx0, t->sy0, t->sx1, t->sy1, &lo, &hi);
    double solid =
        t->invert ? oc_terrain_cap_z(t) - hi : lo - oc_terrain_cap_z(t);
    if (solid < size) {
      snprintf(buf, n,
               "the terrain's solid is %g thick where thinnest (%g x "
               "'falloff' %g + 'thickness' %g), less than %s %g: "
               "give a larger 'falloff' or a 'thickness'",
               solid, X_HALF, t->R, solid - X_HALF * t->R, what, size);
      return 1;
    }
  }
  return 0;
}

/* ---- the kind (field/kind.h) ------------------------------------------ */

/* The data stays with the node; the op holds sigma's constants for its T. */
static int terrain_compile(oc_kcompile *c, oc_error *err) {
  const oc_tdata *t = c->data;
  (void)err;
  oc_terrain_sigma(c->T, t->W, c->par);
  c->npar = OC_TPAR_N;
  c->jump = t->open;
  c->info.lo = 0;
  c->info.hi = 2 * c->T;
  c->info.lip = oc_terrain_lipschitz(t, c->par);
  c->info.box = oc_terrain_box(t);
  return OC_OK;
}

/* Infinite across the sides of open edges, where f jumps: the global
** bound holds only off them. */
static double terrain_lip_in(const oc_kctx *k, const oc_aabb *b) {
  double l = oc_terrain_lipschitz_in(k->data, k->par, b);
  return isinf(l) ? l : fmin(l, k->lip);
}

static int terrain_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  int wz = oc_col_wants_z(q);
  int in = oc_terrain_spans(k->data, k->par, f->x0, f->y0, f->x1, f->y1, 0,
                            wz ? oc_col_add_xy : oc_col_add, q);
  if (wz)
    oc_terrain_spans(k->data, k->par, f->x0, f->y0, f->x1, f->y1, 1,
                     oc_col_add_z, q);
  return in;
}

static double terrain_surface_value(const oc_kctx *k, double e, double z) {
  return oc_terrain_column_value(k->data, k->par, e, z);
}

/* Its sigma is compiled for one T: no surface for another. */
static int terrain_surface(const oc_kctx *k, double T, oc_ksurf *s) {
  const oc_tdata *t = k->data;
  s->height = t->src.height;
  s->range = t->src.range;
  s->ud = t->src.ud;
  s->value = terrain_surface_value;
  s->up = t->invert ? -1 : 1;
  s->cap = oc_terrain_cap_z(t);
  return T == k->T;
}

static void terrain_release(void *data) {
  oc_tdata_free(data);
}

static const oc_kind_def terrain_kind = {
    .name = "terrain",
    .flags = OC_KF_PRIM | OC_KF_HFLIKE | OC_KF_DIRECT,
    .compile = terrain_compile,
    .eval = terrain_eval,
    .lipschitz_in = terrain_lip_in,
    .column = terrain_column,
    .surface = terrain_surface,
    .release = terrain_release,
};

/* ---- construction ----------------------------------------------------- */

void oc_tdata_free(oc_tdata *t) {
  if (!t) return;
  if (t->src.release) t->src.release(t->src.ud);
  free(t->dist);
  free(t->mpyr);
  free(t);
}

static int check_source(const oc_elevation *s, oc_error *err) {
  if (!s || !s->height || !s->range || !s->slope)
    return oc_seterr(err, OC_EINVAL,
                     "the elevation source needs height, range and slope");
  if (!s->height_weight != !s->weight_range)
    return oc_seterr(err, OC_EINVAL,
                     "the elevation source needs both height_weight and "
                     "weight_range, or neither");
  if (!isfinite(s->x0) || !isfinite(s->y0) || !isfinite(s->x1) ||
      !isfinite(s->y1) || !(s->x0 < s->x1) || !(s->y0 < s->y1))
    return oc_seterr(err, OC_EINVAL,
                     "the elevation source's domain must be finite and "
                     "non-empty (got %g %g to %g %g)",
                     s->x0, s->y0, s->x1, s->y1);
  return 0;
}

oc_node *oc_terrain(const oc_elevation *src, const oc_terrain_params *tp,
                    oc_error *err) {
  if (check_source(src, err)) return NULL;
  if (!tp) {
    oc_seterr(err, OC_EINVAL, "terrain parameters missing");
    return NULL;
  }
  double R = tp->falloff, W = tp->transition == 0 ? DEFAULT_W : tp->transition;
  if (!oc_check_positive(R, "falloff", err) ||
      !oc_check_positive(W, "transition", err))
    return NULL;
  if (!(tp->thickness >= 0) || !isfinite(tp->thickness)) {
    oc_seterr(err, OC_EINVAL, "'thickness' must be a number >= 0 (got %g)",
              tp->thickness);
    return NULL;
  }
  if (tp->edges != OC_TERRAIN_EDGES_DEFAULT && tp->edges != OC_TERRAIN_OPEN &&
      tp->edges != OC_TERRAIN_SLAB) {
    oc_seterr(err, OC_EINVAL, "'edges' must be open or slab (got %d)",
              tp->edges);
    return NULL;
  }
  if (tp->mask && tp->edges == OC_TERRAIN_OPEN) {
    oc_seterr(err, OC_EINVAL,
              "'edges' = open does not apply with a mask: the mask's "
              "domain falls off over 'falloff' (use edges = slab or none)");
    return NULL;
  }
  int open = !tp->mask && tp->edges != OC_TERRAIN_SLAB;
  double wx = src->x1 - src->x0, wy = src->y1 - src->y0;
  if (!open && !tp->mask && !(2 * R < wx && 2 * R < wy)) {
    oc_seterr(err, OC_EINVAL,
              "'falloff' %g must be less than half the domain's width "
              "(%g x %g)",
              R, wx, wy);
    return NULL;
  }
  double lo, hi;
  src->range(src->ud, src->x0, src->y0, src->x1, src->y1, &lo, &hi);
  double slope = src->slope(src->ud, src->x0, src->y0, src->x1, src->y1);
  if (!isfinite(lo) || !isfinite(hi) || !(lo <= hi) || !(slope >= 0) ||
      !isfinite(slope)) {
    oc_seterr(err, OC_EINVAL,
              "the elevation source reports a range %g .. %g and slope %g: "
              "they must be finite",
              lo, hi, slope);
    return NULL;
  }
  oc_tdata *t = calloc(1, sizeof *t);
  if (!t) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  t->src = *src;
  t->src.retain = t->src.release = NULL; /* until retained below */
  t->R = R;
  t->W = W;
  t->invert = tp->invert != 0;
  t->zlo = t->invert ? lo : lo - tp->thickness;
  t->zhi = t->invert ? hi + tp->thickness : hi;
  t->slope = slope;
  t->open = open;
  if (src->height_weight) {
    double alo, ahi;
    src->weight_range(src->ud, src->x0, src->y0, src->x1, src->y1, &alo, &ahi,
                      &t->wlip);
    if (!(t->wlip >= 0) || !isfinite(t->wlip)) {
      oc_seterr(err, OC_EINVAL,
                "the elevation source reports a weight slope %g: it must be "
                "finite",
                t->wlip);
      free(t);
      return NULL;
    }
  }
  double in = open ? 0 : R;
  t->ix0 = src->x0 + in;
  t->iy0 = src->y0 + in;
  t->ix1 = src->x1 - in;
  t->iy1 = src->y1 - in;
  t->sx0 = src->x0;
  t->sy0 = src->y0;
  t->sx1 = src->x1;
  t->sy1 = src->y1;
  if (tp->mask && oc_terrain_mask(t, tp->mask, err)) {
    oc_tdata_free(t);
    return NULL;
  }
  if (src->retain) src->retain(src->ud);
  t->src.retain = src->retain;
  t->src.release = src->release;
  return oc_kind_node(&terrain_kind, NULL, 0, NULL, 0, t, err);
}
