/*
** profile.c — shape-preserving C¹ quadratic splines for cross-section
** profiles (see profile.h): construction, evaluation, exact ranges and
** slopes, linear blends of two profiles.
*/
#include <math.h>
#include <stdlib.h>

#include "core/checked.h"
#include "core/error.h"
#include "core/profile.h"

/* Piece k covers [bx[k], bx[k + 1]] with v = pv + u (ps + u pc), u = x - bx[k];
** beyond bx[0] and bx[np] the profile is constant. */
struct oc_profile {
  size_t np;
  double *bx; /* np + 1 breakpoints */
  double *pv, *ps, *pc;
  double vfirst, vlast;
  double slo, shi; /* support */
};

static void set_piece(oc_profile *p, double x0, double v0, double s0, double s1,
                      double x1) {
  size_t k = p->np++;
  p->bx[k] = x0, p->pv[k] = v0, p->ps[k] = s0;
  p->pc[k] = (s1 - s0) / (2 * (x1 - x0));
}

/* One knot interval [a, b] with values va, vb and end slopes sa, sb: one
** quadratic when the slopes' mean is the secant, else two joined at xi
** with slope sbar there. xi is the midpoint unless the slopes straddle
** the secant (convex or concave data) and the midpoint's sbar would leave
** [sa, sb]; then xi is where sbar equals the nearer end slope, so the
** slope stays monotone (Schumaker 1983's lemma: any xi whose sbar lies
** between sa and sb keeps the shape). */
static void interval(oc_profile *p, double a, double b, double va, double vb,
                     double sa, double sb) {
  double h = b - a, d = (vb - va) / h;
  if (sa + sb == 2 * d) {
    set_piece(p, a, va, sa, sb, b);
    return;
  }
  double xi = a + 0.5 * h, sbar = 2 * d - 0.5 * (sa + sb);
  if ((sa - d) * (sb - d) < 0 && (sbar - sa) * (sbar - sb) > 0) {
    double u = fabs(sbar - sb) < fabs(sbar - sa)
                   ? h * (2 * sb - 2 * d) / (sb - sa)   /* sbar = sb */
                   : h * (sa + sb - 2 * d) / (sb - sa); /* sbar = sa */
    if (u > 0 && u < h) {
      xi = a + u;
      sbar = 2 * d - sb + u * (sb - sa) / h;
    }
  }
  set_piece(p, a, va, sa, sbar, xi);
  set_piece(p, xi, va + (xi - a) * 0.5 * (sa + sbar), sbar, sb, b);
}

/* a, of n doubles or more, cut to n (kept as it is if realloc fails). */
static double *shrink(double *a, size_t n) {
  double *b = realloc(a, n * sizeof *a);
  return b ? b : a;
}

oc_profile *oc_profile_new(const double *x, const double *v, size_t n,
                           oc_error *err) {
  if (n < 2 || !x || !v) {
    oc_seterr(err, OC_EINVAL, "'knots' must number at least 2 (got %zu)", n);
    return NULL;
  }
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(x[i]) || !isfinite(v[i])) {
      oc_seterr(err, OC_EINVAL, "'knots': knot %zu is not finite (%g, %g)", i,
                x[i], v[i]);
      return NULL;
    }
    if (i > 0 && !(x[i] > x[i - 1])) {
      oc_seterr(err, OC_EINVAL,
                "'knots': knot %zu must lie after knot %zu (x %g after %g)", i,
                i - 1, x[i], x[i - 1]);
      return NULL;
    }
    if (i > 0 && !isfinite((v[i] - v[i - 1]) / (x[i] - x[i - 1]))) {
      oc_seterr(err, OC_EINVAL,
                "'knots': the slope between knots %zu and %zu overflows", i - 1,
                i);
      return NULL;
    }
  }
  oc_profile *p = calloc(1, sizeof *p);
  size_t m, bytes;
  if (!p || !oc_mul_size(n - 1, 2, &m) ||
      !oc_mul_size(m + 1, sizeof(double), &bytes) || !(p->bx = malloc(bytes)) ||
      !(p->pv = malloc(bytes)) || !(p->ps = malloc(bytes)) ||
      !(p->pc = malloc(bytes))) {
    oc_profile_free(p);
    oc_seterr(err, OC_ENOMEM, "out of memory for a profile of %zu knots", n);
    return NULL;
  }
  double sprev = 0; /* slope at knot i */
  for (size_t i = 0; i + 1 < n; i++) {
    double snext = 0;
    if (i + 2 < n) {
      double d0 = (v[i + 1] - v[i]) / (x[i + 1] - x[i]);
      double d1 = (v[i + 2] - v[i + 1]) / (x[i + 2] - x[i + 1]);
      /* harmonic mean, written so it cannot overflow */
      if ((d0 > 0 && d1 > 0) || (d0 < 0 && d1 < 0))
        snext = 2 / (1 / d0 + 1 / d1);
    }
    interval(p, x[i], x[i + 1], v[i], v[i + 1], sprev, snext);
    sprev = snext;
  }
  p->bx[p->np] = x[n - 1];
  /* the capacity of breakpoints not inserted, given back */
  p->bx = shrink(p->bx, p->np + 1);
  p->pv = shrink(p->pv, p->np + 1);
  p->ps = shrink(p->ps, p->np + 1);
  p->pc = shrink(p->pc, p->np + 1);
  p->vfirst = v[0], p->vlast = v[n - 1];
  /* flat runs of equal values at the ends are exactly constant */
  size_t j = 0, k = n - 1;
  while (j + 1 < n && v[j + 1] == v[0])
    j++;
  while (k > 0 && v[k - 1] == v[n - 1])
    k--;
  if (j == n - 1)
    p->slo = p->shi = 0;
  else
    p->slo = x[j], p->shi = x[k];
  return p;
}

void oc_profile_free(oc_profile *p) {
  if (!p) return;
  free(p->bx);
  free(p->pv);
  free(p->ps);
  free(p->pc);
  free(p);
}

size_t oc_profile_bytes(const oc_profile *p) {
  return sizeof *p + 4 * (p->np + 1) * sizeof(double);
}

size_t oc_profile_nbreaks(const oc_profile *p) {
  return p->np + 1;
}

double oc_profile_eval(const oc_profile *p, double x, double *dv) {
  if (dv) *dv = 0;
  if (isnan(x)) return x;
  if (x <= p->bx[0]) return p->vfirst;
  if (x >= p->bx[p->np]) return p->vlast;
  size_t lo = 0, hi = p->np;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (p->bx[m] <= x)
      lo = m;
    else
      hi = m;
  }
  double u = x - p->bx[lo];
  if (dv) *dv = p->ps[lo] + 2 * p->pc[lo] * u;
  return p->pv[lo] + u * (p->ps[lo] + u * p->pc[lo]);
}

void oc_profile_support(const oc_profile *p, double *lo, double *hi) {
  *lo = p->slo, *hi = p->shi;
}

double oc_profile_half_width(const oc_profile *p) {
  return fmax(fabs(p->slo), fabs(p->shi));
}

double oc_profile_lerp(const oc_profile *a, const oc_profile *b, double t,
                       double x, double *dv) {
  double da, db, va = oc_profile_eval(a, x, &da),
                 vb = oc_profile_eval(b, x, &db);
  if (dv) *dv = (1 - t) * da + t * db;
  return (1 - t) * va + t * vb;
}

/* The first breakpoint index of p strictly after x (np + 1 if none). */
static size_t first_after(const oc_profile *p, double x) {
  size_t lo = 0, hi = p->np + 1;
  while (lo < hi) {
    size_t m = lo + (hi - lo) / 2;
    if (p->bx[m] <= x)
      lo = m + 1;
    else
      hi = m;
  }
  return lo;
}

/* Walks the union of both breakpoint lists over [a, b]: the blend is one
** quadratic between consecutive points and C¹ across them, so its extremes
** are at the points or at a zero of its (linear) derivative between them,
** and its largest |slope| at a point. */
static void walk(const oc_profile *pa, const oc_profile *pb, double t, double a,
                 double b, double *lo, double *hi, double *smax) {
  if (a > b) {
    double s = a;
    a = b, b = s;
  }
  double vlo = INFINITY, vhi = -INFINITY, sm = 0;
  size_t i = first_after(pa, a), j = first_after(pb, a);
  double u = a, du, fu = oc_profile_lerp(pa, pb, t, a, &du);
  for (;;) {
    vlo = fmin(vlo, fu), vhi = fmax(vhi, fu), sm = fmax(sm, fabs(du));
    if (u >= b) break;
    double w = b;
    if (i <= pa->np) w = fmin(w, pa->bx[i]);
    if (j <= pb->np) w = fmin(w, pb->bx[j]);
    double dw, fw = oc_profile_lerp(pa, pb, t, w, &dw);
    if ((du > 0 && dw < 0) || (du < 0 && dw > 0)) {
      double xs = u + (w - u) * du / (du - dw);
      if (xs > u && xs < w) {
        double fs = oc_profile_lerp(pa, pb, t, xs, NULL);
        vlo = fmin(vlo, fs), vhi = fmax(vhi, fs);
      }
    }
    while (i <= pa->np && pa->bx[i] <= w)
      i++;
    while (j <= pb->np && pb->bx[j] <= w)
      j++;
    u = w, fu = fw, du = dw;
  }
  if (lo) *lo = vlo;
  if (hi) *hi = vhi;
  if (smax) *smax = sm;
}

void oc_profile_range(const oc_profile *p, double a, double b, double *lo,
                      double *hi) {
  walk(p, p, 0, a, b, lo, hi, NULL);
}

double oc_profile_max_slope(const oc_profile *p, double a, double b) {
  double s;
  walk(p, p, 0, a, b, NULL, NULL, &s);
  return s;
}

void oc_profile_lerp_range(const oc_profile *pa, const oc_profile *pb, double t,
                           double a, double b, double *lo, double *hi) {
  walk(pa, pb, t, a, b, lo, hi, NULL);
}

double oc_profile_lerp_max_slope(const oc_profile *pa, const oc_profile *pb,
                                 double t, double a, double b) {
  double s;
  walk(pa, pb, t, a, b, NULL, NULL, &s);
  return s;
}
