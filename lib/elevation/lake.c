/*
** lake.c — the contour primitive of elevation trees (Génevaux et al. 2015,
** section 4, figure 7): a closed shore around a centre c given in polar
** coordinates as r(theta), and radial cross-sections placed at angles,
**
**   delta(p) = |p - c| - r(theta(p))      (< 0 inside, metres)
**   f(p)     = level + c(theta, delta),   alpha = 1 inside, g(delta / R)
**
** with g Wyvill's falloff. r is the shape-preserving C1 quadratic spline
** of core/profile.c through the given radii, made periodic by wrapping
** its knots (a knot's slope depends only on its neighbours), so the shore
** is a smooth closed curve through the polygon's vertices and r stays
** within the radii given (r > 0). Cross-sections are blended between
** consecutive angles by a smoothstep, so f is C1 away from the centre.
**
** Bounds. grad f = c_d grad rho + (c_t - c_d r') grad theta, with grad rho
** and grad theta orthogonal of norms 1 and 1 / rho, so
** |grad f| <= sqrt(S^2 + ((D + S max|r'|) / rho)^2), S the profiles'
** largest slope, D the sectors' largest 1.5 sup|c_j - c_i| / (angle
** between them). The 1 / rho blows up at the centre, where theta is not
** defined: so every profile must be flat, all at the same depth, below
** some d_lo > -min r; then f is constant for rho < rho_0 = min r + d_lo
** and rho_0 > 0 bounds the term. alpha varies only outside the shore,
** where rho >= min r. In a box, rho's range gives delta's, and the
** profiles' exact ranges and slopes over it (core/profile.h) give the rest.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/falloff.h"
#include "core/profile.h"
#include "elevation/enode.h"

#define PI 3.14159265358979323846
#define TAU (2 * PI)
#define MAX_KNOTS (1 << 20)

typedef struct elake {
  double cx, cy, level, R;
  oc_profile *shore; /* r(theta) for theta in [th0, th0 + 2 pi) */
  double th0, rmin, rmax, drmax;
  size_t np;
  double *ang; /* the profiles' angles (radians), increasing, < ang[0] + 2 pi */
  oc_profile **prof;
  double rho0; /* f is constant nearer the centre */
} elake;

void oc_elake_free(void *data) {
  elake *d = data;
  if (!d) return;
  oc_profile_free(d->shore);
  for (size_t i = 0; d->prof && i < d->np; i++)
    if (i == 0 || d->prof[i] != d->prof[i - 1]) /* (shared: once) */
      oc_profile_free(d->prof[i]);
  free(d->prof);
  free(d->ang);
  free(d);
}

/* theta brought into [base, base + 2 pi). */
static double wrap(double th, double base) {
  double t = th - base;
  t -= TAU * floor(t / TAU);
  if (!(t < TAU)) t = 0; /* rounding of floor */
  return base + t;
}

/* The sector holding angle th: profiles i and j = i + 1 (cyclic), the
** smoothstep weight of j in *s and its derivative in theta in *ds. */
static size_t sector(const elake *d, double th, size_t *j, double *s,
                     double *ds) {
  double t = wrap(th, d->ang[0]);
  size_t a = 0, b = d->np; /* ang[a] <= t < ang[b] (ang[np]: ang[0] + 2 pi) */
  while (b - a > 1) {
    size_t m = (a + b) / 2;
    if (d->ang[m] <= t)
      a = m;
    else
      b = m;
  }
  double hi = a + 1 < d->np ? d->ang[a + 1] : d->ang[0] + TAU;
  double w = hi - d->ang[a], u = (t - d->ang[a]) / w;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  *s = u * u * (3 - 2 * u);
  *ds = 6 * u * (1 - u) / w;
  *j = a + 1 < d->np ? a + 1 : 0;
  return a;
}

/* The angle from profile i to the next (cyclic). */
static double gap(const elake *d, size_t i) {
  return i + 1 < d->np ? d->ang[i + 1] - d->ang[i]
                       : d->ang[0] + TAU - d->ang[i];
}

void oc_elake_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s) {
  (void)ft; /* no detail to filter */
  const elake *d = OC_EPRIM(n)->data;
  int grad = want & OC_EV_GRAD;
  double u = x - d->cx, v = y - d->cy, rho = hypot(u, v), th = atan2(v, u);
  double dr, r = oc_profile_eval(d->shore, wrap(th, d->th0), &dr);
  double del = rho - r;
  /* grad delta = grad rho - r' grad theta; grad theta = (-v, u) / rho^2 */
  double gdx = 0, gdy = 0, gtx = 0, gty = 0;
  if (grad && rho > 0) {
    double ir = 1 / rho, ir2 = ir * ir;
    gtx = -v * ir2;
    gty = u * ir2;
    gdx = u * ir - dr * gtx;
    gdy = v * ir - dr * gty;
  }
  s->ax = s->ay = s->fx = s->fy = 0;
  if (del <= 0) {
    s->a = 1;
  } else if (del < d->R) {
    double q = del / d->R, k = 1 - q * q;
    s->a = k * k * k;
    if (grad) {
      double g = -6 * q * k * k / d->R;
      s->ax = g * gdx;
      s->ay = g * gdy;
    }
  } else {
    s->a = 0;
    if (want & OC_EV_LAZY) {
      s->f = 0;
      return;
    }
  }
  double c, cd, ct = 0;
  if (d->np == 1) {
    c = oc_profile_eval(d->prof[0], del, &cd);
  } else {
    size_t j;
    double w, dw, di, dj;
    size_t i = sector(d, th, &j, &w, &dw);
    double ci = oc_profile_eval(d->prof[i], del, &di);
    double cj = oc_profile_eval(d->prof[j], del, &dj);
    c = ci + w * (cj - ci);
    cd = di + w * (dj - di);
    ct = dw * (cj - ci);
  }
  s->f = d->level + c;
  if (grad) {
    s->fx = cd * gdx + ct * gtx;
    s->fy = cd * gdy + ct * gty;
  }
}

/* alpha as a function of delta: 1 inside, g(delta / R) outside. */
static double wyvill_or_one(double del, double R) {
  return del <= 0 ? 1 : oc_falloff(del / R);
}

/* Bounds where |p - c| lies in [rl, rh]. */
static void bound_rho(const elake *d, double rl, double rh, oc_ebound *o) {
  double dl = rl - d->rmax, dh = rh - d->rmin; /* delta's range */
  double lo = INFINITY, hi = -INFINITY, S = 0, D = 0;
  for (size_t i = 0; i < d->np; i++) {
    double l, h;
    oc_profile_range(d->prof[i], dl, dh, &l, &h);
    lo = fmin(lo, l);
    hi = fmax(hi, h);
    S = fmax(S, oc_profile_max_slope(d->prof[i], dl, dh));
    if (d->np > 1) {
      size_t j = i + 1 < d->np ? i + 1 : 0;
      double lj, hj;
      oc_profile_range(d->prof[j], dl, dh, &lj, &hj);
      D = fmax(D, 1.5 * fmax(fmax(hj - l, h - lj), 0) / gap(d, i));
    }
  }
  double m = 1e-12 * (1 + fabs(d->level) + fmax(fabs(lo), fabs(hi)));
  o->flo = d->level + lo - m;
  o->fhi = d->level + hi + m;
  double re = fmax(rl, d->rho0), k = (D + S * d->drmax) / re;
  o->lf = S == 0 && D == 0 ? 0 : sqrt(S * S + k * k) * (1 + 1e-9);
  /* alpha: 1 for delta <= 0, g(delta / R) after */
  o->ahi = fmin(1, wyvill_or_one(dl, d->R) * (1 + 1e-12));
  o->alo = fmax(0, wyvill_or_one(dh, d->R) * (1 - 1e-12) - 1e-300);
  double ra = fmax(rl, d->rmin), kr = d->drmax / ra;
  o->la = oc_falloff_slope_in(dl / d->R, dh / d->R) / d->R * sqrt(1 + kr * kr) *
          (1 + 1e-9);
}

void oc_elake_bound_in(const oc_enode *n, const oc_erect *b,
                       const oc_efootb *fb, oc_ebound *o) {
  (void)fb;
  const elake *d = OC_EPRIM(n)->data;
  double dx = fmax(fmax(b->x0 - d->cx, d->cx - b->x1), 0);
  double dy = fmax(fmax(b->y0 - d->cy, d->cy - b->y1), 0);
  double fx = fmax(fabs(b->x0 - d->cx), fabs(b->x1 - d->cx));
  double fy = fmax(fabs(b->y0 - d->cy), fabs(b->y1 - d->cy));
  bound_rho(d, hypot(dx, dy) * (1 - 1e-12), hypot(fx, fy) * (1 + 1e-12), o);
}

/* ---- construction ----------------------------------------------------- */

/* The periodic shore through knots (th[k], r[k]), th increasing over less
** than one turn: the spline of the knots repeated on both sides (two
** turns' worth is more than the slopes of one turn's knots look at). */
static oc_profile *periodic(const double *th, const double *r, size_t n,
                            oc_error *err) {
  size_t m = n + 4;
  double *x = malloc(2 * m * sizeof *x);
  if (!x) {
    oc_seterr(err, OC_ENOMEM, "out of memory (%zu shore points)", n);
    return NULL;
  }
  double *v = x + m;
  for (size_t k = 0; k < m; k++) {
    long i = (long)k - 2, q = i < 0 ? -1 : i >= (long)n ? 1 : 0;
    size_t a = (size_t)(i - q * (long)n);
    x[k] = th[a] + q * TAU;
    v[k] = r[a];
  }
  oc_profile *p = oc_profile_new(x, v, m, err);
  free(x);
  return p;
}

/* The shore's knots from the radii or the contour; 0, or an error. */
static int shore_knots(const oc_enode_lake_params *p, double **th, double **r,
                       size_t *n, oc_error *err) {
  int poly = p->contour != NULL;
  size_t m = poly ? p->ncontour : p->nradii;
  const char *name = poly ? "contour" : "radius";
  if (poly == (p->radii != NULL))
    return oc_seterr(err, OC_EINVAL, "lake: give either 'radius' or 'contour'");
  if ((poly && m < 3) || (!poly && m != 1 && m < 3))
    return oc_seterr(err, OC_EINVAL, "'%s' must hold at least 3 %s (got %zu)",
                     name, poly ? "points" : "radii", m);
  if (m > MAX_KNOTS)
    return oc_seterr(err, OC_EINVAL, "'%s': %zu entries, at most %d", name, m,
                     MAX_KNOTS);
  size_t k = m == 1 ? 3 : m; /* one radius: a circle */
  *th = malloc(2 * k * sizeof **th);
  if (!*th) return oc_seterr(err, OC_ENOMEM, "out of memory");
  *r = *th + k;
  *n = k;
  double *T = *th, *Rr = *r;
  if (!poly) {
    for (size_t i = 0; i < k; i++) {
      double ri = p->radii[m == 1 ? 0 : i];
      if (!(isfinite(ri) && ri > 0))
        return oc_seterr(err, OC_EINVAL,
                         "'radius[%zu]' must be a positive number (got %g)",
                         i + 1, ri);
      T[i] = TAU * (double)i / (double)k;
      Rr[i] = ri;
    }
    return OC_OK;
  }
  for (size_t i = 0; i < k; i++) {
    double u = p->contour[2 * i] - p->cx, v = p->contour[2 * i + 1] - p->cy;
    if (!isfinite(u) || !isfinite(v))
      return oc_seterr(err, OC_EINVAL,
                       "'contour[%zu]' must have finite coordinates", i + 1);
    Rr[i] = hypot(u, v);
    T[i] = atan2(v, u);
    if (!(Rr[i] > 0) || !isfinite(Rr[i]))
      return oc_seterr(err, OC_EINVAL,
                       "'contour[%zu]' lies on the centre (or too far)", i + 1);
  }
  /* turns between consecutive points: all one way and one turn in all,
  ** or the polygon is not star-shaped around the centre */
  double sum = 0;
  int pos = 0, neg = 0;
  for (size_t i = 0; i < k; i++) {
    double t = T[(i + 1) % k] - T[i];
    t -= TAU * floor((t + PI) / TAU);
    pos += t > 1e-9;
    neg += t < -1e-9;
    sum += t;
  }
  if (!((pos == (int)k || neg == (int)k) && fabs(fabs(sum) - TAU) < 1e-6))
    return oc_seterr(err, OC_EINVAL,
                     "'contour' must go once round 'center', every point at "
                     "a larger angle than the one before (a polygon "
                     "star-shaped around the centre)");
  if (neg) { /* clockwise: reverse */
    for (size_t i = 0, j = k - 1; i < j; i++, j--) {
      double a = T[i], b = Rr[i];
      T[i] = T[j], Rr[i] = Rr[j];
      T[j] = a, Rr[j] = b;
    }
  }
  for (size_t i = 1; i < k; i++) { /* unwrap, increasing from T[0] */
    double t = T[i] - T[i - 1];
    t -= TAU * floor(t / TAU);
    T[i] = T[i - 1] + t;
  }
  return OC_OK;
}

oc_enode *oc_enode_lake(const oc_enode_lake_params *p, oc_error *err) {
  if (!p) {
    oc_seterr(err, OC_EINVAL, "lake: no parameters");
    return NULL;
  }
  if (!isfinite(p->cx) || !isfinite(p->cy)) {
    oc_seterr(err, OC_EINVAL, "'center' must have finite coordinates");
    return NULL;
  }
  if (!isfinite(p->level)) {
    oc_seterr(err, OC_EINVAL, "'level' must be a finite number (got %g)",
              p->level);
    return NULL;
  }
  if (!(isfinite(p->falloff) && p->falloff >= 0)) {
    oc_seterr(err, OC_EINVAL, "'falloff' must be a positive number (got %g)",
              p->falloff);
    return NULL;
  }
  double depth = p->depth == 0 ? 5 : p->depth, bank = p->bank < 0 ? 2 : p->bank;
  if (!(isfinite(depth) && depth > 0)) {
    oc_seterr(err, OC_EINVAL, "'depth' must be a positive number (got %g)",
              p->depth);
    return NULL;
  }
  if (!isfinite(bank)) {
    oc_seterr(err, OC_EINVAL, "'bank' must be a finite number >= 0 (got %g)",
              p->bank);
    return NULL;
  }
  elake *d = calloc(1, sizeof *d);
  double *th = NULL, *rr = NULL;
  size_t nk = 0;
  if (!d) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  d->cx = p->cx;
  d->cy = p->cy;
  d->level = p->level;
  if (shore_knots(p, &th, &rr, &nk, err)) {
    free(th);
    oc_elake_free(d);
    return NULL;
  }
  d->th0 = th[0];
  d->shore = periodic(th, rr, nk, err);
  free(th);
  if (!d->shore) {
    char m[sizeof err->msg];
    snprintf(m, sizeof m, "%s", err->msg);
    oc_seterr(err, OC_EINVAL, "'%s': %s", p->contour ? "contour" : "radius", m);
    oc_elake_free(d);
    return NULL;
  }
  oc_profile_range(d->shore, d->th0, d->th0 + TAU, &d->rmin, &d->rmax);
  d->drmax = oc_profile_max_slope(d->shore, d->th0, d->th0 + TAU) * (1 + 1e-12);
  d->R = p->falloff > 0 ? p->falloff : d->rmax / 2;
  /* the cross-sections */
  oc_enode_profile def;
  double dk[4], dv[4];
  const oc_enode_profile *pr = p->profiles;
  size_t np = p->nprofiles;
  if (np == 0) {
    double D = fmin(d->rmin / 2, 20 * depth);
    dk[0] = -D, dv[0] = -depth;
    dk[1] = 0, dv[1] = 0;
    dk[2] = d->R / 4, dv[2] = 0;
    dk[3] = d->R, dv[3] = bank;
    def = (oc_enode_profile){0, dk, dv, 4};
    pr = &def;
    np = 1;
  } else if (!pr || np > 4096) {
    oc_seterr(err, OC_EINVAL, "'profiles' must hold 1 to 4096 profiles");
    oc_elake_free(d);
    return NULL;
  }
  d->ang = malloc(np * sizeof *d->ang);
  d->prof = calloc(np, sizeof *d->prof);
  if (!d->ang || !d->prof) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    oc_elake_free(d);
    return NULL;
  }
  d->np = np;
  double dlo = INFINITY;
  for (size_t i = 0; i < np; i++) {
    const oc_enode_profile *q = &pr[i];
    if (!(q->at >= 0 && q->at < 360) || (i > 0 && !(q->at > pr[i - 1].at))) {
      oc_seterr(err, OC_EINVAL,
                "'profiles[%zu].angle' must be in [0, 360) degrees and above "
                "the previous profile's (got %g)",
                i + 1, q->at);
      oc_elake_free(d);
      return NULL;
    }
    d->ang[i] = q->at * (PI / 180);
    if (!(d->prof[i] = oc_profile_new(q->d, q->v, q->n, err))) {
      char m[sizeof err->msg];
      snprintf(m, sizeof m, "%s", err->msg);
      if (p->nprofiles)
        oc_seterr(err, OC_EINVAL, "'profiles[%zu]': %s", i + 1, m);
      else
        oc_seterr(err, OC_EINVAL,
                  "lake: the default bed (depth %g, bank %g, falloff %g): %s",
                  depth, bank, d->R, m);
      oc_elake_free(d);
      return NULL;
    }
    /* a sector's profile the same as the one before is stored once */
    if (i > 0 && oc_profile_same(d->prof[i], d->prof[i - 1])) {
      oc_profile_free(d->prof[i]);
      d->prof[i] = d->prof[i - 1];
    }
    double lo, hi;
    oc_profile_support(d->prof[i], &lo, &hi);
    if (lo < hi) dlo = fmin(dlo, lo);
  }
  if (dlo == INFINITY) dlo = 0; /* all flat */
  /* flat, and at one depth, round the centre (theta has no value there) */
  double deep = oc_profile_eval(d->prof[0], dlo, NULL);
  for (size_t i = 0; i < np; i++) {
    double v = oc_profile_eval(d->prof[i], dlo, NULL);
    if (!(dlo > -d->rmin) || fabs(v - deep) > 1e-9 * (1 + fabs(deep))) {
      oc_seterr(err, OC_EINVAL,
                "'profiles': every cross-section must be flat, all at the "
                "same depth, for d <= %g and above (within %g of the shore, "
                "the smallest radius: nearer the centre the sectors meet); "
                "profile %zu is not (it varies from d = %g, value %g there "
                "against %g)",
                dlo, d->rmin, i + 1, dlo, v, deep);
      oc_elake_free(d);
      return NULL;
    }
  }
  d->rho0 = d->rmin + dlo;
  oc_eprim *n =
      (oc_eprim *)oc_enode_alloc(OC_E_LAKE, sizeof(oc_eprim), NULL, 0, err);
  if (!n) {
    oc_elake_free(d);
    return NULL;
  }
  n->data = d;
  double e = d->rmax + d->R;
  n->box = (oc_erect){d->cx - e, d->cy - e, d->cx + e, d->cy + e};
  bound_rho(d, 0, INFINITY, &n->glob);
  n->glob.alo = 0;
  n->glob.ahi = 1;
  if (!isfinite(n->glob.lf) || !isfinite(n->glob.la) ||
      !isfinite(n->glob.flo) || !isfinite(n->glob.fhi) ||
      !isfinite(n->box.x0) || !isfinite(n->box.x1) || !isfinite(n->box.y0) ||
      !isfinite(n->box.y1)) {
    oc_seterr(err, OC_EINVAL,
              "lake: its elevations or slopes overflow (radii %g..%g, "
              "falloff %g)",
              d->rmin, d->rmax, d->R);
    oc_enode_release(&n->h);
    return NULL;
  }
  return &n->h;
}

size_t oc_elake_bytes(const void *data) {
  const elake *d = data;
  size_t b = sizeof *d + oc_profile_bytes(d->shore) +
             d->np * (sizeof *d->ang + sizeof *d->prof);
  for (size_t i = 0; i < d->np; i++)
    if (i == 0 || d->prof[i] != d->prof[i - 1])
      b += oc_profile_bytes(d->prof[i]);
  return b;
}
