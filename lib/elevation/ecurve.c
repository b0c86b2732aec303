/*
** ecurve.c — the curve primitive of elevation trees (Génevaux et al. 2015,
** section 4.1) and its river and road presets: a skeleton Gamma carrying
** an elevation (core/curve.h) and cross-section profiles (core/profile.h)
** interpolated linearly by arc length,
**
**   f(p) = q_z + c(s, d),   alpha(p) = g(max(0, |p - q| - core) / (R - core)),
**
** q the closest point of Gamma (arc length s, signed distance d > 0 on the
** left), g Wyvill's falloff; alpha is 1 over a core band (a road's
** carriageway, a river's channel, fully replaced) and falls to 0 at R.
** Beyond an end of an open skeleton, d is the offset along the end's
** normal (the cross-section continues straight) and alpha falls off with
** the distance to the end (a round cap): f and alpha stay continuous.
**
** The bounds hold where alpha > 0 (|d| < R), which is where a curve's f
** counts in blends, replacements and additions: R kappa_max < 1 keeps the
** closest point unique and smooth there, |grad s| <= 1 / (1 - R kappa),
** so lambda_f <= (grade + max|dc/ds|) / (1 - R kappa_max) + max|dc/dd|.
** A skeleton with a corner (infinite curvature) is refused: the closest
** point jumps across the corner's bisector.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/curve.h"
#include "core/error.h"
#include "core/falloff.h"
#include "core/profile.h"
#include "core/vec.h"
#include "elevation/enode.h"

typedef struct ecurve {
  oc_pcurve *c;
  size_t np;
  double *at; /* arc lengths of the profiles, increasing */
  oc_profile **prof;
  double R, core;
  double clo, chi; /* the profiles' range of c */
} ecurve;

void oc_ecurve_free(void *data) {
  ecurve *d = data;
  if (!d) return;
  oc_curve_free(d->c);
  for (size_t i = 0; d->prof && i < d->np; i++)
    if (i == 0 || d->prof[i] != d->prof[i - 1]) /* (shared: once) */
      oc_profile_free(d->prof[i]);
  free(d->prof);
  free(d->at);
  free(d);
}

/* The profile interval holding s: index i and t in [0, 1] between
** profiles i and i + 1 (i + 1 = i at the ends). */
static size_t interval(const ecurve *d, double s, double *t, size_t *j) {
  if (d->np == 1 || s <= d->at[0]) {
    *t = 0;
    *j = 0;
    return 0;
  }
  if (s >= d->at[d->np - 1]) {
    *t = 0;
    *j = d->np - 1;
    return d->np - 1;
  }
  size_t a = 0, b = d->np - 1; /* at[a] <= s < at[b] */
  while (b - a > 1) {
    size_t m = (a + b) / 2;
    if (d->at[m] <= s)
      a = m;
    else
      b = m;
  }
  *t = (s - d->at[a]) / (d->at[b] - d->at[a]);
  *j = b;
  return a;
}

void oc_ecurve_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                      int want, double *f, double *a) {
  const ecurve *d = OC_EPRIM(n)->data;
  /* lazy or alpha alone: the points farther than R have alpha = 0 and f
  ** = 0, as oc_ecurve_ev finds (no closest point within R) */
  if (want & (OC_EV_LAZY | OC_EV_ALPHA) && cnt > 0 &&
      oc_curve_far_from_segment(d->c, x[0], y, x[cnt - 1], y, d->R)) {
    for (int m = 0; m < cnt; m++) {
      a[m] = 0;
      if (!(want & OC_EV_ALPHA)) f[m] = 0;
    }
    return;
  }
  for (int m = 0; m < cnt; m++) {
    oc_enode_sample s;
    oc_ecurve_ev(n, x[m], y, NULL, want, &s);
    a[m] = s.a;
    if (!(want & OC_EV_ALPHA)) f[m] = s.f;
  }
}

/* The sample at (x, y) from its closest point pt (oc_ecurve_ev's after
** its search; lazy when the search was within R). */
static void sample_at(const ecurve *d, double x, double y, oc_curve_point *pt_,
                      int want, int lazy, oc_enode_sample *s) {
  oc_curve_point pt = *pt_;
  int grad = want & OC_EV_GRAD;
  double ex = x - pt.q.x, ey = y - pt.q.y, dist = hypot(ex, ey);
  /* alpha */
  double w = d->R - d->core, u = fmax(0, dist - d->core) / w;
  if (u < 1) {
    double k = 1 - u * u;
    s->a = k * k * k;
    if (grad && u > 0) {
      double g = -6 * u * k * k / w / dist;
      s->ax = g * ex;
      s->ay = g * ey;
    }
  } else {
    s->a = 0;
    if (lazy) {
      s->f = 0;
      return;
    }
  }
  if (want & OC_EV_ALPHA) return;
  /* f: the lateral coordinate and the gradients of s and of it */
  double dl, gsx = 0, gsy = 0, gz = 0;
  if (pt.end) {
    dl = ex * pt.nx + ey * pt.ny;
  } else {
    dl = pt.d;
    /* (the curvature only for the gradient of s) */
    double den = grad ? 1 - oc_curve_curvature_at(d->c, &pt) * dl : 0;
    if (den > 0) {
      gsx = pt.tx / den;
      gsy = pt.ty / den;
      gz = oc_curve_grade_at(d->c, &pt);
    }
  }
  double t, dc, dcs = 0, c;
  if (d->np > 1) pt.s = oc_curve_s_at(d->c, &pt);
  size_t j, i = interval(d, pt.s, &t, &j);
  if (i == j) {
    c = oc_profile_eval(d->prof[i], dl, &dc);
  } else {
    c = oc_profile_lerp(d->prof[i], d->prof[j], t, dl, &dc);
    if (grad)
      dcs = (oc_profile_eval(d->prof[j], dl, NULL) -
             oc_profile_eval(d->prof[i], dl, NULL)) /
            (d->at[j] - d->at[i]);
  }
  s->f = pt.q.z + c;
  if (grad) {
    s->fx = (gz + dcs) * gsx + dc * pt.nx;
    s->fy = (gz + dcs) * gsy + dc * pt.ny;
  }
}

/* (No scale of a curve is dropped by the level of detail: ft unused.) */
void oc_ecurve_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                  int want, oc_enode_sample *s) {
  (void)ft;
  const ecurve *d = OC_EPRIM(n)->data;
  int lazy = want & OC_EV_LAZY;
  oc_curve_point pt;
  s->ax = s->ay = s->fx = s->fy = 0;
  if (want & OC_EV_ALPHA) lazy = 1; /* no f: only the nearby curve */
  /* (the arc length only where profiles are interpolated by it) */
  if (!oc_curve_closest_t(d->c, x, y, lazy ? d->R : INFINITY, &pt)) {
    s->a = s->f = 0;
    return;
  }
  sample_at(d, x, y, &pt, want, lazy, s);
}

/* f's range where alpha > 0 in a box: q within R of a point of the box,
** so within r = R + rho of its centre (cx, cy), its z that of the pieces
** near there (oc_curve_z_near) rather than the whole curve's (a road
** climbing 140 m has pieces rising 10: the replace's model over the
** road, psi_flat, is Lipschitz in |f_B - f_A| over the box). o holds the
** bound over the plane, tightened. */
static void local_f(const ecurve *d, double cx, double cy, double r,
                    oc_ebound *o) {
  double zlo, zhi;
  if (!oc_curve_z_near(d->c, cx, cy, r, &zlo, &zhi)) return;
  o->flo = fmax(o->flo, zlo + d->clo);
  o->fhi = fmin(o->fhi, zhi + d->chi);
}

/* The bound's test (oc_ecurve_bound_in) and the lazy sample at the box's
** centre from one closest-point search out to R + rho, rather than the
** box test's search and then the sample's: the search answers the box
** test where its distance is clear of R + rho by a margin (1e-7 of it,
** which dwarfs the roundings of the distances, plus the offset of (x, y)
** from the box's centre as oc_ecurve_bound_in rounds it); within that
** margin the box test itself decides (the same answer). The same f
** bound as oc_ecurve_bound_in; alpha's range and slope tighter, from the
** distance found. */
int oc_ecurve_weight_in(const oc_enode *n, double x, double y,
                        const oc_erect *b, oc_ebound *o, oc_enode_sample *s,
                        int *boxes) {
  const ecurve *d = OC_EPRIM(n)->data;
  *o = OC_EPRIM(n)->glob;
  s->ax = s->ay = s->fx = s->fy = 0;
  s->a = s->f = 0;
  if (!oc_erect_meets(&OC_EPRIM(n)->box, b)) {
    o->alo = o->ahi = o->la = 0;
    return 0;
  }
  /* (oc_ecurve_bound_in's radius, the same bits) */
  double cx = 0.5 * (b->x0 + b->x1), cy = 0.5 * (b->y0 + b->y1);
  double rho = 0.5 * oc_norm2_fast(b->x1 - b->x0, b->y1 - b->y0);
  double r = (d->R + rho) * (1 + 1e-12) + 1e-9;
  double m = 1e-7 * r + 2 * (fabs(cx - x) + fabs(cy - y));
  oc_curve_point pt;
  double d2;
  int got = oc_curve_closest_within(d->c, x, y, d->R, r + m, &pt, &d2);
  if (got == 0 || (!(d2 < (r - m) * (r - m)) &&
                   (++*boxes, !oc_curve_within(d->c, cx, cy, r)))) {
    o->alo = o->ahi = o->la = 0;
    return 0;
  }
  if (got == 2) sample_at(d, x, y, &pt, OC_EV_LAZY, 1, s);
  local_f(d, cx, cy, r, o);
  /* alpha's range and slope from the distance found: the box's points
  ** lie within rho of (x, y) (and the offset of the centre, and a hair
  ** for the roundings of the distances), so at dc -+ rho of the curve,
  ** u = (dist - core) / (R - core) in [umin, umax]; g falls, and |g'|
  ** peaks at 1/sqrt(5) (oc_falloff_slope_in). A tighter bound than
  ** oc_ecurve_bound_in's, which finds no distance (fig22 at -q: 7.9 ->
  ** 7.5 height calls a pixel) */
  double dc = sqrt(d2), rr = (rho + fabs(cx - x) + fabs(cy - y)) * (1 + 1e-9) +
                             1e-9 * (1 + dc);
  double w = d->R - d->core;
  double umin = (dc - rr - d->core) / w, umax = (dc + rr - d->core) / w;
  double ahi = umin <= 0 ? 1 : oc_falloff(umin) * (1 + 1e-12) + 1e-15;
  double alo = umax <= 0   ? 1
               : umax >= 1 ? 0
                           : oc_falloff(umax) * (1 - 1e-12) - 1e-15;
  o->ahi = fmin(o->ahi, ahi);
  o->alo = fmax(o->alo, alo);
  o->la = fmin(o->la, oc_falloff_slope_in(umin, umax) / w * (1 + 1e-12));
  return 1;
}

void oc_ecurve_bound_in(const oc_enode *n, const oc_erect *b,
                        const oc_efootb *fb, oc_ebound *o) {
  (void)fb;
  const ecurve *d = OC_EPRIM(n)->data;
  *o = OC_EPRIM(n)->glob;
  if (!oc_erect_meets(&OC_EPRIM(n)->box, b)) {
    o->alo = o->ahi = o->la = 0;
    return;
  }
  /* alpha = 0 on the box when no point of the skeleton is within R of
  ** it: none within R + rho of its centre, rho its half-diagonal (and a
  ** hair for rounding) */
  double cx = 0.5 * (b->x0 + b->x1), cy = 0.5 * (b->y0 + b->y1);
  double rho = 0.5 * oc_norm2_fast(b->x1 - b->x0, b->y1 - b->y0);
  double r = (d->R + rho) * (1 + 1e-12) + 1e-9;
  if (!oc_curve_within(d->c, cx, cy, r))
    o->alo = o->ahi = o->la = 0;
  else
    local_f(d, cx, cy, r, o);
}

oc_pcurve *oc_ecurve_skeleton(const oc_vec3 *P, size_t m,
                              oc_ecurve_spline spline, oc_error *err) {
  if (spline != OC_ECURVE_CATMULL)
    return oc_curve_from_points(P, m, spline == OC_ECURVE_BEZIER ? 3 : 1, err);
  return oc_curve_catmull(P, m, err);
}

oc_enode *oc_enode_curve(const oc_enode_curve_params *p, oc_error *err) {
  if (!p || !p->points) {
    oc_seterr(err, OC_EINVAL, "curve: no 'points'");
    return NULL;
  }
  if (p->npoints < 2) {
    oc_seterr(err, OC_EINVAL, "'points' must hold at least 2 points (got %zu)",
              p->npoints);
    return NULL;
  }
  if (!(isfinite(p->radius) && p->radius > 0)) {
    oc_seterr(err, OC_EINVAL, "'radius' must be a positive number (got %g)",
              p->radius);
    return NULL;
  }
  if (!(isfinite(p->core) && p->core >= 0 && p->core < p->radius)) {
    oc_seterr(err, OC_EINVAL,
              "'core' must be >= 0 and below 'radius' %g (got %g)", p->radius,
              p->core);
    return NULL;
  }
  if (p->nprofiles < 1 || !p->profiles) {
    oc_seterr(err, OC_EINVAL, "'profiles' must hold at least one profile");
    return NULL;
  }
  ecurve *d = calloc(1, sizeof *d);
  if (!d) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  d->R = p->radius;
  d->core = p->core;
  d->c = oc_ecurve_skeleton(p->points, p->npoints, p->spline, err);
  if (!d->c) goto fail;
  double kap = oc_curve_kappa_max(d->c), turn = oc_curve_max_turn(d->c);
  if (turn > 1e-6) {
    oc_seterr(err, OC_EINVAL,
              "'points': the skeleton has a corner of %g degrees, where the "
              "closest point jumps: use spline = \"catmull\" (the default) "
              "or smooth Bézier joins",
              turn * 180 / 3.14159265358979323846);
    goto fail;
  }
  if (!(kap * p->radius < 1)) {
    oc_seterr(err, OC_EINVAL,
              "'radius' %g is not below the skeleton's smallest radius of "
              "curvature %g: the cross-sections would overlap (space the "
              "points out or lower 'radius')",
              p->radius, 1 / kap);
    goto fail;
  }
  /* the profiles, by arc length */
  double len = oc_curve_length(d->c);
  d->np = p->nprofiles;
  d->at = malloc(d->np * sizeof *d->at);
  d->prof = calloc(d->np, sizeof *d->prof);
  if (!d->at || !d->prof) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    goto fail;
  }
  double clo = INFINITY, chi = -INFINITY, dcd = 0, dcs = 0;
  for (size_t i = 0; i < d->np; i++) {
    const oc_enode_profile *q = &p->profiles[i];
    if (!(q->at >= 0 && q->at <= 1) ||
        (i > 0 && !(q->at > p->profiles[i - 1].at))) {
      oc_seterr(err, OC_EINVAL,
                "'profiles[%zu].at' must be in [0, 1] and above the "
                "previous profile's (got %g)",
                i + 1, q->at);
      goto fail;
    }
    d->at[i] = q->at * len;
    if (!(d->prof[i] = oc_profile_new(q->d, q->v, q->n, err))) {
      char m[sizeof err->msg];
      snprintf(m, sizeof m, "%s", err->msg);
      oc_seterr(err, OC_EINVAL, "'profiles[%zu]': %s", i + 1, m);
      goto fail;
    }
    /* a profile the same as the one before is stored once */
    if (i > 0 && oc_profile_same(d->prof[i], d->prof[i - 1])) {
      oc_profile_free(d->prof[i]);
      d->prof[i] = d->prof[i - 1];
    }
    double lo, hi;
    oc_profile_range(d->prof[i], -INFINITY, INFINITY, &lo, &hi);
    clo = fmin(clo, lo);
    chi = fmax(chi, hi);
    dcd = fmax(dcd, oc_profile_max_slope(d->prof[i], -INFINITY, INFINITY));
    if (i > 0) {
      double plo, phi;
      oc_profile_range(d->prof[i - 1], -INFINITY, INFINITY, &plo, &phi);
      dcs = fmax(dcs, fmax(hi - plo, phi - lo) / (d->at[i] - d->at[i - 1]));
    }
  }
  d->clo = clo, d->chi = chi;
  oc_aabb bx = oc_curve_bounds(d->c, p->radius);
  double grade = oc_curve_grade_max(d->c);
  double lf = (grade + dcs) / (1 - p->radius * kap) + dcd;
  if (!isfinite(lf) || !isfinite(bx.lo.z + clo) || !isfinite(bx.hi.z + chi)) {
    oc_seterr(err, OC_EINVAL,
              "curve: its elevations or slopes overflow (a vertical step or "
              "profiles too close along the curve)");
    goto fail;
  }
  oc_eprim *n =
      (oc_eprim *)oc_enode_alloc(OC_E_CURVE, sizeof(oc_eprim), NULL, 0, err);
  if (!n) goto fail;
  n->data = d;
  n->box = (oc_erect){bx.lo.x, bx.lo.y, bx.hi.x, bx.hi.y};
  n->glob = (oc_ebound){bx.lo.z + clo,
                        bx.hi.z + chi,
                        0,
                        1,
                        lf,
                        OC_FALLOFF_LIPSCHITZ / (p->radius - p->core)};
  return &n->h;
fail:
  oc_ecurve_free(d);
  return NULL;
}

/* ---- presets ---------------------------------------------------------- */

/* Channel width, depth and bank width (metres) of each river kind. */
static const double river_kinds[4][3] = {
    {3, 0.8, 4},     /* stream */
    {20, 3, 25},     /* river */
    {40, 4, 60},     /* meander: wide, shallow, a broad floodplain */
    {150, 10, 200}}; /* main stem */

oc_enode *oc_enode_river(const oc_enode_river_params *p, oc_error *err) {
  if (!p || (unsigned)p->kind > OC_RIVER_MAIN) {
    oc_seterr(err, OC_EINVAL, "river: unknown 'kind'");
    return NULL;
  }
  const double *k = river_kinds[p->kind];
  double w = p->width > 0 ? p->width : k[0];
  double dp = p->depth > 0 ? p->depth : k[1];
  double bank = p->bank > 0 ? p->bank : k[2] * w / k[0];
  if (!isfinite(w) || !isfinite(dp) || !isfinite(bank)) {
    oc_seterr(err, OC_EINVAL,
              "river: 'width', 'depth' and 'bank' must be "
              "finite");
    return NULL;
  }
  double h = w / 2 + bank;
  double x[6] = {-h, -w / 2, -w / 4, w / 4, w / 2, h};
  double v[6] = {0, -0.5 * dp, -dp, -dp, -0.5 * dp, 0};
  oc_enode_profile pr = {0, x, v, 6};
  oc_enode_curve_params c = {p->points, p->npoints, p->spline, h,
                             w / 2,     &pr,        1};
  return oc_enode_curve(&c, err);
}

oc_enode *oc_enode_road(const oc_enode_road_params *p, oc_error *err) {
  if (!p) {
    oc_seterr(err, OC_EINVAL, "road: no parameters");
    return NULL;
  }
  double w = p->width > 0 ? p->width : 7;
  double sh = p->shoulder >= 0 ? p->shoulder : 1.5;
  double em = p->embankment > 0 ? p->embankment : 12;
  if (!isfinite(w) || !isfinite(sh) || !isfinite(em)) {
    oc_seterr(err, OC_EINVAL,
              "road: 'width', 'shoulder' and 'embankment' "
              "must be finite");
    return NULL;
  }
  /* a 1 % crown on the carriageway, level shoulders */
  double x[5] = {-w / 2 - sh, -w / 2, 0, w / 2, w / 2 + sh};
  double v[5] = {-0.005 * w, -0.005 * w, 0, -0.005 * w, -0.005 * w};
  oc_enode_profile pr = {0, x, v, 5};
  oc_enode_curve_params c = {p->points,  p->npoints, p->spline, w / 2 + sh + em,
                             w / 2 + sh, &pr,        1};
  return oc_enode_curve(&c, err);
}

size_t oc_ecurve_bytes(const void *data) {
  const ecurve *d = data;
  size_t b = sizeof *d + oc_curve_bytes(d->c) +
             d->np * (sizeof *d->at + sizeof *d->prof);
  for (size_t i = 0; i < d->np; i++)
    if (i == 0 || d->prof[i] != d->prof[i - 1])
      b += oc_profile_bytes(d->prof[i]);
  return b;
}
