/*
** profile.c — shape-preserving C¹ quadratic splines for cross-section
** profiles (see profile.h): construction, evaluation, exact ranges and
** slopes, linear blends of two profiles.
*/
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/checked.h"
#include "core/error.h"
#include "core/profile.h"

/* A profile holds its knots alone (x then v; as floats when every one is
** a float exactly, else doubles): the spline's pieces on a knot interval
** are derived when it is read (pieces_on), by the arithmetic that defines
** them, so every value is the same whichever way it is stored. */
struct oc_profile {
  uint32_t n;   /* knots */
  uint32_t f32; /* knots stored as floats */
  double k[];   /* (or 2 n floats) */
};

static double kx(const oc_profile *p, size_t i) {
  return p->f32 ? (double)((const float *)p->k)[i] : p->k[i];
}
static double kv(const oc_profile *p, size_t i) {
  return p->f32 ? (double)((const float *)p->k)[p->n + i] : p->k[p->n + i];
}

/* One quadratic piece: v = v0 + u (s0 + u c), u = x - x0. */
typedef struct qpiece {
  double x0, v0, s0, c;
} qpiece;

static qpiece make_piece(double x0, double v0, double s0, double s1,
                         double x1) {
  qpiece q = {x0, v0, s0, (s1 - s0) / (2 * (x1 - x0))};
  return q;
}

/* The slope at knot i: the harmonic mean of the neighbouring secant
** slopes where they have the same sign (written so it cannot overflow),
** else 0; 0 at both ends. */
static double knot_slope(const oc_profile *p, size_t i) {
  if (i == 0 || i + 1 >= p->n) return 0;
  double d0 = (kv(p, i) - kv(p, i - 1)) / (kx(p, i) - kx(p, i - 1));
  double d1 = (kv(p, i + 1) - kv(p, i)) / (kx(p, i + 1) - kx(p, i));
  if ((d0 > 0 && d1 > 0) || (d0 < 0 && d1 < 0)) return 2 / (1 / d0 + 1 / d1);
  return 0;
}

/* The pieces on knot interval i, [a, b] with values va, vb and end
** slopes sa, sb (1 or 2, returned): one quadratic when the slopes' mean
** is the secant, else two joined at xi with slope sbar there. xi is the
** midpoint unless the slopes straddle the secant (convex or concave data)
** and the midpoint's sbar would leave [sa, sb]; then xi is where sbar
** equals the nearer end slope, so the slope stays monotone (Schumaker
** 1983's lemma: any xi whose sbar lies between sa and sb keeps the
** shape). */
static int pieces_on(const oc_profile *p, size_t i, qpiece q[2]) {
  double a = kx(p, i), b = kx(p, i + 1), va = kv(p, i), vb = kv(p, i + 1);
  double sa = knot_slope(p, i), sb = knot_slope(p, i + 1);
  double h = b - a, d = (vb - va) / h;
  if (sa + sb == 2 * d) {
    q[0] = make_piece(a, va, sa, sb, b);
    return 1;
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
  q[0] = make_piece(a, va, sa, sbar, xi);
  q[1] = make_piece(xi, va + (xi - a) * 0.5 * (sa + sbar), sbar, sb, b);
  return 2;
}

/* The knot interval holding x (knot i <= x < knot i + 1), for x strictly
** inside the knots' span. */
static size_t interval_of(const oc_profile *p, double x) {
  size_t lo = 0, hi = p->n - 1;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (kx(p, m) <= x)
      lo = m;
    else
      hi = m;
  }
  return lo;
}

oc_profile *oc_profile_new(const double *x, const double *v, size_t n,
                           oc_error *err) {
  if (n < 2 || !x || !v) {
    oc_seterr(err, OC_EINVAL, "'knots' must number at least 2 (got %zu)", n);
    return NULL;
  }
  if (n > UINT32_MAX / 2) {
    oc_seterr(err, OC_EINVAL, "'knots' must number at most %u (got %zu)",
              UINT32_MAX / 2, n);
    return NULL;
  }
  int f32 = 1;
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
    f32 &= (double)(float)x[i] == x[i] && (double)(float)v[i] == v[i];
  }
  size_t bytes;
  oc_profile *p = NULL;
  if (!oc_mul_size(2 * n, f32 ? sizeof(float) : sizeof(double), &bytes) ||
      !oc_add_size(bytes, sizeof *p, &bytes) || !(p = malloc(bytes))) {
    oc_seterr(err, OC_ENOMEM, "out of memory for a profile of %zu knots", n);
    return NULL;
  }
  p->n = (uint32_t)n, p->f32 = (uint32_t)f32;
  for (size_t i = 0; i < n; i++) {
    if (f32) {
      float *k = (float *)p->k;
      k[i] = (float)x[i], k[n + i] = (float)v[i];
    } else {
      p->k[i] = x[i], p->k[n + i] = v[i];
    }
  }
  return p;
}

void oc_profile_free(oc_profile *p) {
  free(p);
}

size_t oc_profile_bytes(const oc_profile *p) {
  return sizeof *p +
         2 * (size_t)p->n * (p->f32 ? sizeof(float) : sizeof(double));
}

int oc_profile_same(const oc_profile *a, const oc_profile *b) {
  if (a->n != b->n) return 0;
  for (size_t i = 0; i < a->n; i++)
    if (kx(a, i) != kx(b, i) || kv(a, i) != kv(b, i)) return 0;
  return 1;
}

size_t oc_profile_nbreaks(const oc_profile *p) {
  size_t nb = 1;
  for (size_t i = 0; i + 1 < p->n; i++) {
    qpiece q[2];
    nb += (size_t)pieces_on(p, i, q);
  }
  return nb;
}

double oc_profile_eval(const oc_profile *p, double x, double *dv) {
  if (dv) *dv = 0;
  if (isnan(x)) return x;
  if (x <= kx(p, 0)) return kv(p, 0);
  if (x >= kx(p, p->n - 1)) return kv(p, p->n - 1);
  qpiece q[2];
  int m = pieces_on(p, interval_of(p, x), q);
  const qpiece *k = m == 2 && x >= q[1].x0 ? &q[1] : &q[0];
  double u = x - k->x0;
  if (dv) *dv = k->s0 + 2 * k->c * u;
  return k->v0 + u * (k->s0 + u * k->c);
}

void oc_profile_support(const oc_profile *p, double *lo, double *hi) {
  /* flat runs of equal values at the ends are exactly constant */
  size_t n = p->n, j = 0, k = n - 1;
  while (j + 1 < n && kv(p, j + 1) == kv(p, 0))
    j++;
  while (k > 0 && kv(p, k - 1) == kv(p, n - 1))
    k--;
  if (j == n - 1)
    *lo = *hi = 0;
  else
    *lo = kx(p, j), *hi = kx(p, k);
}

double oc_profile_half_width(const oc_profile *p) {
  double lo, hi;
  oc_profile_support(p, &lo, &hi);
  return fmax(fabs(lo), fabs(hi));
}

double oc_profile_lerp(const oc_profile *a, const oc_profile *b, double t,
                       double x, double *dv) {
  double da, db, va = oc_profile_eval(a, x, &da),
                 vb = oc_profile_eval(b, x, &db);
  if (dv) *dv = (1 - t) * da + t * db;
  return (1 - t) * va + t * vb;
}

/* The first breakpoint (a knot or a join inside a knot interval) strictly
** after x; INFINITY if none. */
static double next_break(const oc_profile *p, double x) {
  if (x < kx(p, 0)) return kx(p, 0);
  if (x >= kx(p, p->n - 1)) return INFINITY;
  size_t i = interval_of(p, x);
  qpiece q[2];
  if (pieces_on(p, i, q) == 2 && q[1].x0 > x) return q[1].x0;
  return kx(p, i + 1);
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
  double u = a, du, fu = oc_profile_lerp(pa, pb, t, a, &du);
  for (;;) {
    vlo = fmin(vlo, fu), vhi = fmax(vhi, fu), sm = fmax(sm, fabs(du));
    if (u >= b) break;
    double w = fmin(b, fmin(next_break(pa, u), next_break(pb, u)));
    double dw, fw = oc_profile_lerp(pa, pb, t, w, &dw);
    if ((du > 0 && dw < 0) || (du < 0 && dw > 0)) {
      double xs = u + (w - u) * du / (du - dw);
      if (xs > u && xs < w) {
        double fs = oc_profile_lerp(pa, pb, t, xs, NULL);
        vlo = fmin(vlo, fs), vhi = fmax(vhi, fs);
      }
    }
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
