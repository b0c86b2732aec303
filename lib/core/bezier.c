/*
** bezier.c — one Bézier piece: evaluation, arc length, closest point,
** curvature bound, flattening (see bezier.h).
*/
#include <math.h>

#include "core/bezier.h"
#include "core/vec.h"

/* Binomial coefficients up to 5 (the degree of (B - p) . B' for a cubic). */
static const double binom[6][6] = {
    {1, 0, 0, 0, 0, 0}, {1, 1, 0, 0, 0, 0}, {1, 2, 1, 0, 0, 0},
    {1, 3, 3, 1, 0, 0}, {1, 4, 6, 4, 1, 0}, {1, 5, 10, 10, 5, 1},
};

static void casteljau(const oc_vec3 *p, int n, double t, oc_vec3 *left,
                      oc_vec3 *right) {
  oc_vec3 w[OC_BEZ_MAXDEG + 1];
  for (int i = 0; i <= n; i++)
    w[i] = p[i];
  for (int k = 0;; k++) {
    if (left) left[k] = w[0];
    if (right) right[n - k] = w[n - k];
    if (k == n) break;
    for (int i = 0; i < n - k; i++)
      w[i] = oc_add(oc_mul(w[i], 1 - t), oc_mul(w[i + 1], t));
  }
}

/* (inlined with n a constant by oc_bez_eval: unrolled, the same
** operations) */
static inline __attribute__((always_inline)) oc_vec3 eval_at(const oc_vec3 *p,
                                                             int n, double t) {
  oc_vec3 w[OC_BEZ_MAXDEG + 1];
#pragma GCC unroll 4
  for (int i = 0; i <= n; i++)
    w[i] = p[i];
#pragma GCC unroll 4
  for (int k = n; k > 0; k--)
#pragma GCC unroll 4
    for (int i = 0; i < k; i++)
      w[i] = oc_add(oc_mul(w[i], 1 - t), oc_mul(w[i + 1], t));
  return w[0];
}

oc_vec3 oc_bez_eval(const oc_vec3 *p, int n, double t) {
  switch (n) {
  case 3:
    return eval_at(p, 3, t);
  case 2:
    return eval_at(p, 2, t);
  case 1:
    return eval_at(p, 1, t);
  default:
    return eval_at(p, 0, t);
  }
}

oc_vec3 oc_bez_d1(const oc_vec3 *p, int n, double t) {
  oc_vec3 h[OC_BEZ_MAXDEG];
  for (int i = 0; i < n; i++)
    h[i] = oc_mul(oc_sub(p[i + 1], p[i]), n);
  return oc_bez_eval(h, n - 1, t);
}

oc_vec3 oc_bez_d2(const oc_vec3 *p, int n, double t) {
  if (n < 2) return oc_v3(0, 0, 0);
  oc_vec3 h[OC_BEZ_MAXDEG - 1];
  for (int i = 0; i + 1 < n; i++)
    h[i] = oc_mul(oc_add(oc_sub(p[i + 2], oc_mul(p[i + 1], 2)), p[i]),
                  n * (n - 1));
  return oc_bez_eval(h, n - 2, t);
}

void oc_bez_sub(const oc_vec3 *p, int n, double a, double b, oc_vec3 *out) {
  oc_vec3 left[OC_BEZ_MAXDEG + 1];
  if (b < 1) {
    casteljau(p, n, b, left, NULL);
  } else {
    for (int i = 0; i <= n; i++)
      left[i] = p[i];
  }
  if (a > 0)
    casteljau(left, n, a / b, NULL, out);
  else
    for (int i = 0; i <= n; i++)
      out[i] = left[i];
}

/* ---- arc length ------------------------------------------------------- */

static const double gl_x[4] = {0.1834346424956498049, 0.5255324099163289858,
                               0.7966664774136267396, 0.9602898564975362317};
static const double gl_w[4] = {0.3626837833783619830, 0.3137066458778872873,
                               0.2223810344533744705, 0.1012285362903762592};

static double speed(const oc_vec3 *p, int n, double t) {
  oc_vec3 d = oc_bez_d1(p, n, t);
  return hypot(d.x, d.y);
}

double oc_bez_arclen(const oc_vec3 *p, int n, double a, double b) {
  double c = 0.5 * (a + b), h = 0.5 * (b - a), s = 0;
  for (int i = 0; i < 4; i++)
    s +=
        gl_w[i] * (speed(p, n, c - h * gl_x[i]) + speed(p, n, c + h * gl_x[i]));
  return s * h;
}

/* ---- closest point ------------------------------------------------------ */

/* A polynomial in Bernstein form of degree m <= 5 on some interval, at t:
** de Casteljau, its first level read from c. Its callers are inlined
** with m a constant, so that the compiler unrolls it into registers: the
** same operations in the same order, so the same bits, at half the cost
** (the closest point's Newton steps make most of its calls). */
static inline __attribute__((always_inline)) double bern_at(const double *c,
                                                            int m, double t) {
  double w[6], u = 1 - t;
  if (m == 0) return c[0];
#pragma GCC unroll 6
  for (int i = 0; i < m; i++)
    w[i] = c[i] * u + c[i + 1] * t;
#pragma GCC unroll 6
  for (int k = m - 1; k > 0; k--)
#pragma GCC unroll 6
    for (int i = 0; i < k; i++)
      w[i] = w[i] * u + w[i + 1] * t;
  return w[0];
}

static void bern_halves(const double *c, int m, double *l, double *r) {
  double w[6];
  for (int i = 0; i <= m; i++)
    w[i] = c[i];
  for (int k = 0;; k++) {
    l[k] = w[0];
    r[m - k] = w[m - k];
    if (k == m) break;
    for (int i = 0; i < m - k; i++)
      w[i] = 0.5 * (w[i] + w[i + 1]);
  }
}

static inline int sign_changes(const double *c, int m) {
  int v = 0, last = 0;
  for (int i = 0; i <= m; i++) {
    int s = (c[i] > 0) - (c[i] < 0);
    if (s && last && s != last) v++;
    if (s) last = s;
  }
  return v;
}

typedef struct span {
  double a, b;
  double f[6];         /* (B - p) . B' on [a, b] */
  double qx[4], qy[4]; /* control points of B - p on [a, b] */
  int depth;
} span;

/* The root of f in (a, b), where f(a) and f(b) have opposite signs:
** Newton's steps kept inside the bracket (else bisection), until a step
** or the bracket is under 4e-16 (t lies in [0, 1]), or a step lands on
** an end of the bracket or a hair past it (under 4e-16: that end is the
** root, to rounding; Newton's own error is the square of its step).
** Bisecting there instead, as this did before, halved the bracket
** towards that end some 40 times: 22 iterations a root on bench_elev
** -qq fig22, up to 57; 4.4 on random cubics, whose roots moved by at
** most 2.4e-15 (37 % of them not at all). */
static inline __attribute__((always_inline)) double
solve_bracketed(const double *f, const double *df, int m, double a, double b) {
  double fa = bern_at(f, m, a), t = 0.5 * (a + b);
  for (int it = 0; it < 100; it++) {
    double ft = bern_at(f, m, t);
    if (ft == 0) return t;
    if ((ft > 0) == (fa > 0))
      a = t;
    else
      b = t;
    double d = bern_at(df, m - 1, t);
    double tn = t - ft / d;
    if (!(tn > a && tn < b)) {
      if (tn >= b && tn - b <= 4e-16) return b;
      if (tn <= a && a - tn <= 4e-16) return a;
      tn = 0.5 * (a + b);
    } else if (fabs(tn - t) <= 4e-16) {
      return tn;
    }
    if (tn == t || b - a <= 4e-16) return tn;
    t = tn;
  }
  return t;
}

/* x and y of the piece at t: oc_bez_eval's operations on those two
** coordinates alone (so its bits), unrolled for the degree. */
static inline __attribute__((always_inline)) void
xy_at(const oc_vec3 *p, int n, double t, double *x, double *y) {
  double wx[OC_BEZ_MAXDEG + 1], wy[OC_BEZ_MAXDEG + 1], u = 1 - t;
#pragma GCC unroll 4
  for (int i = 0; i <= n; i++)
    wx[i] = p[i].x, wy[i] = p[i].y;
#pragma GCC unroll 4
  for (int k = n; k > 0; k--)
#pragma GCC unroll 4
    for (int i = 0; i < k; i++) {
      wx[i] = wx[i] * u + wx[i + 1] * t;
      wy[i] = wy[i] * u + wy[i + 1] * t;
    }
  *x = wx[0], *y = wy[0];
}

void oc_bez_xy(const oc_vec3 *p, int n, double t, double *x, double *y) {
  switch (n) {
  case 3:
    xy_at(p, 3, t, x, y);
    return;
  case 2:
    xy_at(p, 2, t, x, y);
    return;
  case 1:
    xy_at(p, 1, t, x, y);
    return;
  default:
    xy_at(p, 0, t, x, y);
    return;
  }
}

void oc_bez_d1_xy(const oc_vec3 *p, int n, double t, double *x, double *y) {
  oc_vec3 h[OC_BEZ_MAXDEG];
  for (int i = 0; i < n; i++)
    h[i] = oc_mul(oc_sub(p[i + 1], p[i]), n);
  oc_bez_xy(h, n - 1, t, x, y);
}

static inline __attribute__((always_inline)) double
dist2_at(const oc_vec3 *p, int n, double x, double y, double t) {
  double qx, qy;
  xy_at(p, n, t, &qx, &qy);
  return (qx - x) * (qx - x) + (qy - y) * (qy - y);
}

/* ---- out of reach ------------------------------------------------------ */

/* The distance from (a, c) to the box [b0, b1] x [b2, b3]. */
static double box_dist(double a, double c, const double b[4]) {
  double da = oc_fmax(oc_fmax(b[0] - a, a - b[1]), 0);
  double dc = oc_fmax(oc_fmax(b[2] - c, c - b[3]), 0);
  return oc_norm2_fast(da, dc);
}

/* The distance from (a, c) to the segment (a1, c1) (a2, c2). */
static double seg_dist(double a, double c, double a1, double c1, double a2,
                       double c2) {
  double da = a2 - a1, dc = c2 - c1, l2 = da * da + dc * dc;
  double t = l2 > 0 ? ((a - a1) * da + (c - c1) * dc) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return hypot(a - a1 - t * da, c - c1 - t * dc);
}

/* The distance from a segment to a box (both convex): 0 where they meet,
** else the least of its ends' distances to the box and the box corners'
** to it. Whether they meet: the segment clipped to the box's slabs. */
static double seg_box_dist(double a1, double c1, double a2, double c2,
                           const double b[4]) {
  double t0 = 0, t1 = 1, d[2] = {a2 - a1, c2 - c1}, o[2] = {a1, c1};
  int meets = 1;
  for (int k = 0; k < 2 && meets; k++) {
    double lo = b[2 * k], hi = b[2 * k + 1];
    if (d[k] == 0) {
      meets = o[k] >= lo && o[k] <= hi;
      continue;
    }
    double u = (lo - o[k]) / d[k], v = (hi - o[k]) / d[k];
    if (u > v) {
      double w = u;
      u = v, v = w;
    }
    t0 = fmax(t0, u), t1 = fmin(t1, v);
    meets = t0 <= t1;
  }
  if (meets) return 0;
  double m = fmin(box_dist(a1, c1, b), box_dist(a2, c2, b));
  for (int i = 0; i < 4; i++)
    m = fmin(m, seg_dist(b[i & 1], b[2 + (i >> 1)], a1, c1, a2, c2));
  return m;
}

/* The one "out of reach" test (oc_bez_far): the control points (px, py)
** of a piece of degree n >= 1 are boxed in the frame of their chord p0
** pn, relative to p0 (tight where an axis-aligned box is loose, as for a
** diagonal piece; the piece lies in their hull, so in that box). 1 when
** the segment (xa, ya) (xb, yb), a point when both ends are one, is
** farther than r + pad from the box: pad is 1e-9 of the sizes in the
** frame (the box's and the query's coordinates relative to p0),
** which dwarfs the rounding of the frame, of the projections and of any
** distance computed later, plus 1e-14 of mag, the size of the absolute
** coordinates the points and the query were taken from (the rounding of
** their differences far from the origin). */
static int frame_far(const double *px, const double *py, int n, double xa,
                     double ya, double xb, double yb, double r, double mag) {
  double ux = px[n] - px[0], uy = py[n] - py[0], l = oc_norm2_fast(ux, uy);
  if (!(l > 0) || !(r < INFINITY)) return 0;
  ux /= l, uy /= l;
  double b[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (int k = 0; k <= n; k++) {
    double dx = px[k] - px[0], dy = py[k] - py[0];
    double a = dx * ux + dy * uy, c = dy * ux - dx * uy;
    b[0] = a < b[0] ? a : b[0], b[1] = a > b[1] ? a : b[1];
    b[2] = c < b[2] ? c : b[2], b[3] = c > b[3] ? c : b[3];
  }
  double dx = xa - px[0], dy = ya - py[0];
  double a1 = dx * ux + dy * uy, c1 = dy * ux - dx * uy;
  double pad = 1e-9 * (fabs(b[0]) + fabs(b[1]) + fabs(b[2]) + fabs(b[3]) +
                       fabs(a1) + fabs(c1)) +
               1e-14 * mag,
         d;
  if (xa == xb && ya == yb) {
    d = box_dist(a1, c1, b);
  } else {
    dx = xb - px[0], dy = yb - py[0];
    double a2 = dx * ux + dy * uy, c2 = dy * ux - dx * uy;
    pad += 1e-9 * (fabs(a2) + fabs(c2));
    d = seg_box_dist(a1, c1, a2, c2, b);
  }
  return d > r + pad;
}

int oc_bez_far(const oc_vec3 *p, int n, double xa, double ya, double xb,
               double yb, double r) {
  double px[OC_BEZ_MAXDEG + 1], py[OC_BEZ_MAXDEG + 1];
  for (int k = 0; k <= n; k++)
    px[k] = p[k].x, py[k] = p[k].y;
  double mag =
      fabs(xa) + fabs(ya) + fabs(xb) + fabs(yb) + fabs(p[0].x) + fabs(p[0].y);
  return frame_far(px, py, n, xa, ya, xb, yb, r, mag);
}

/* The weights of (B - p) . B' in Bernstein form of degree 2 n - 1:
** coefficient i + j gets C(n, i) C(n - 1, j) / C(2 n - 1, i + j) (q_i .
** d_j), q the control points of B - p and d those of B'. (The compiler
** folds each quotient, correctly rounded, as the division at run time
** gave it: the same bits.) */
static const double fw2[3][2] = {{1.0 * 1 / 1, 1.0 * 1 / 3},
                                 {2.0 * 1 / 3, 2.0 * 1 / 3},
                                 {1.0 * 1 / 3, 1.0 * 1 / 1}};
static const double fw3[4][3] = {{1.0 * 1 / 1, 1.0 * 2 / 5, 1.0 * 1 / 10},
                                 {3.0 * 1 / 5, 3.0 * 2 / 10, 3.0 * 1 / 10},
                                 {3.0 * 1 / 10, 3.0 * 2 / 10, 3.0 * 1 / 5},
                                 {1.0 * 1 / 10, 1.0 * 2 / 5, 1.0 * 1 / 1}};

/* The lower corner of the box of a span's control points of B - p: its
** distance to the origin, squared (the points are finite). */
static inline double span_box_d2(const span *s, int n) {
  double lx = s->qx[0], hx = lx, ly = s->qy[0], hy = ly;
  for (int i = 1; i <= n; i++) {
    lx = s->qx[i] < lx ? s->qx[i] : lx, hx = s->qx[i] > hx ? s->qx[i] : hx;
    ly = s->qy[i] < ly ? s->qy[i] : ly, hy = s->qy[i] > hy ? s->qy[i] : hy;
  }
  double bx = lx > -hx ? lx : -hx, by = ly > -hy ? ly : -hy;
  bx = bx > 0 ? bx : 0, by = by > 0 ? by : 0;
  return bx * bx + by * by;
}

/* oc_bez_closest for a degree n of 2 or 3, inlined with n a constant (so
** its small loops unrolled: the same operations, the same bits). */
static inline __attribute__((always_inline)) double
closest_deg(const oc_vec3 *p, int n, double x, double y, double best2,
            double *t) {
  double best = best2;
  int m = 2 * n - 1;
  /* Depth-first with the right half pushed first: the stack holds at most
  ** one pending sibling per level. The whole piece is the first span,
  ** filled in place (most pieces need no other). */
  span st[64];
  span *s = &st[0];
  double dx[3], dy[3], df[5] = {0};
  for (int i = 0; i <= n; i++)
    s->qx[i] = p[i].x - x, s->qy[i] = p[i].y - y;
  const double *qx = s->qx, *qy = s->qy;
  /* (dist2_at at 0 and 1, the same bits: de Casteljau there gives the
  ** end points, up to the sign of a zero coordinate, which squares away) */
  double d0 = qx[0] * qx[0] + qy[0] * qy[0], d1 = qx[n] * qx[n] + qy[n] * qy[n];
  /* the piece out of reach: what the search would give (one test, the
  ** whole span's; sub-spans below take their own). Not where an end is
  ** in reach: the frame's box holds the ends, so the test would say no
  ** (the ends' distances there are these to rounding, far inside its
  ** pad): 36 % of the pieces searched on bench_elev -q fig22's model
  ** queries (replayed), 19.3 k of 53.2 k tests skipped */
  double mag = fabs(x) + fabs(y) + fabs(p[0].x) + fabs(p[0].y);
  if (!(d0 < best || d1 < best) &&
      frame_far(s->qx, s->qy, n, 0, 0, 0, 0, sqrt(best), mag))
    return best2;
  if (d0 < best) best = d0, *t = 0;
  if (d1 < best) best = d1, *t = 1;

  for (int j = 0; j < n; j++)
    dx[j] = n * (qx[j + 1] - qx[j]), dy[j] = n * (qy[j + 1] - qy[j]);
  double *f = s->f;
  for (int l = 0; l < 6; l++)
    f[l] = 0;
  for (int i = 0; i <= n; i++)
    for (int j = 0; j < n; j++)
      f[i + j] +=
          (n == 3 ? fw3[i][j] : fw2[i][j]) * (qx[i] * dx[j] + qy[i] * dy[j]);
  for (int l = 0; l < m; l++)
    df[l] = m * (f[l + 1] - f[l]);
  /* (f of the whole piece kept for Newton: a split reuses st[0]; fixed
  ** sizes, copied in registers) */
  double fp[6];
  for (int l = 0; l < 6; l++)
    fp[l] = f[l];
  s->a = 0, s->b = 1, s->depth = 0;
  int top = 1;
  while (top > 0) {
    s = &st[--top]; /* (read before a push overwrites it) */
    if (span_box_d2(s, n) >= best ||
        (s->depth > 0 &&
         frame_far(s->qx, s->qy, n, 0, 0, 0, 0, sqrt(best), mag)))
      continue;
    /* A root on a split point may leave no sign change on either side. */
    if (s->f[0] == 0 && s->a > 0) {
      double d2 = dist2_at(p, n, x, y, s->a);
      if (d2 < best) best = d2, *t = s->a;
    }
    int v = sign_changes(s->f, m);
    if (v == 0) continue; /* no stationary point inside */
    double cand = -1;
    if (s->f[0] * s->f[m] < 0 && v == 1) {
      cand = solve_bracketed(fp, df, m, s->a, s->b);
    } else if (s->depth >= 52) {
      cand = 0.5 * (s->a + s->b); /* a double root, pinned to rounding */
    } else {
      span l, r;
      double mid = 0.5 * (s->a + s->b);
      l.a = s->a, l.b = mid, r.a = mid, r.b = s->b;
      l.depth = r.depth = s->depth + 1;
      bern_halves(s->f, m, l.f, r.f);
      oc_vec3 c[4], cl[4], cr[4];
      for (int i = 0; i <= n; i++)
        c[i] = oc_v3(s->qx[i], s->qy[i], 0);
      casteljau(c, n, 0.5, cl, cr);
      for (int i = 0; i <= n; i++) {
        l.qx[i] = cl[i].x, l.qy[i] = cl[i].y;
        r.qx[i] = cr[i].x, r.qy[i] = cr[i].y;
      }
      st[top++] = r;
      st[top++] = l;
      continue;
    }
    double d2 = dist2_at(p, n, x, y, cand);
    if (d2 < best) best = d2, *t = cand;
  }
  return best < best2 ? best : best2;
}

double oc_bez_closest(const oc_vec3 *p, int n, double x, double y, double best2,
                      double *t) {
  if (n == 3) return closest_deg(p, 3, x, y, best2, t);
  if (n == 2) return closest_deg(p, 2, x, y, best2, t);
  double dx = p[1].x - p[0].x, dy = p[1].y - p[0].y;
  double ux = x - p[0].x, uy = y - p[0].y, l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? (ux * dx + uy * dy) / l2 : 0;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  double ex = ux - u * dx, ey = uy - u * dy, d2 = ex * ex + ey * ey;
  if (d2 < best2) *t = u;
  return d2;
}

/* ---- curvature ------------------------------------------------------- */

double oc_bez_curvature(const oc_vec3 *p, int n, double t) {
  if (n < 2) return 0;
  oc_vec3 a = oc_bez_d1(p, n, t), b = oc_bez_d2(p, n, t);
  double cr = a.x * b.y - a.y * b.x, v = hypot(a.x, a.y);
  if (v == 0) return cr == 0 && hypot(b.x, b.y) == 0 ? 0 : INFINITY;
  return cr / (v * v * v);
}

/* Distance from the origin to the segment [a, b] of the plane. */
static double seg_dist0(double ax, double ay, double bx, double by) {
  double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? -(ax * dx + ay * dy) / l2 : 0;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  return hypot(ax + u * dx, ay + u * dy);
}

/* Distance from the origin to the convex hull of k <= 3 points. */
static double hull_dist0(const double *x, const double *y, int k) {
  if (k == 1) return hypot(x[0], y[0]);
  if (k == 2) return seg_dist0(x[0], y[0], x[1], y[1]);
  double c1 = (x[1] - x[0]) * (-y[0]) - (y[1] - y[0]) * (-x[0]);
  double c2 = (x[2] - x[1]) * (-y[1]) - (y[2] - y[1]) * (-x[1]);
  double c3 = (x[0] - x[2]) * (-y[2]) - (y[0] - y[2]) * (-x[2]);
  if ((c1 >= 0 && c2 >= 0 && c3 >= 0) || (c1 <= 0 && c2 <= 0 && c3 <= 0))
    return 0;
  return fmin(seg_dist0(x[0], y[0], x[1], y[1]),
              fmin(seg_dist0(x[1], y[1], x[2], y[2]),
                   seg_dist0(x[2], y[2], x[0], y[0])));
}

/* An upper bound of |curvature| of the piece on [a, b]. */
static double kappa_on(const oc_vec3 *p, int n, double a, double b) {
  oc_vec3 s[4];
  oc_bez_sub(p, n, a, b, s);
  double dx[3], dy[3], ex[2], ey[2];
  for (int i = 0; i < n; i++)
    dx[i] = n * (s[i + 1].x - s[i].x), dy[i] = n * (s[i + 1].y - s[i].y);
  for (int j = 0; j + 1 < n; j++)
    ex[j] = (n - 1) * (dx[j + 1] - dx[j]),
    ey[j] = (n - 1) * (dy[j + 1] - dy[j]);
  int m = 2 * n - 3;
  double c[4] = {0};
  for (int i = 0; i < n; i++)
    for (int j = 0; j + 1 < n; j++)
      c[i + j] += binom[n - 1][i] * binom[n - 2][j] / binom[m][i + j] *
                  (dx[i] * ey[j] - dy[i] * ex[j]);
  double num = 0;
  for (int l = 0; l <= m; l++)
    num = fmax(num, fabs(c[l]));
  double lo = hull_dist0(dx, dy, n);
  if (!(lo > 0)) {
    /* The speed may vanish here. Straight (num = 0) and never reversing
    ** (every hodograph point on one side of their sum) is kappa 0; a
    ** straight piece doubling back on itself is a cusp. */
    double sx = 0, sy = 0;
    for (int i = 0; i < n; i++)
      sx += dx[i], sy += dy[i];
    int forward = sx != 0 || sy != 0;
    for (int i = 0; i < n && forward; i++)
      forward = dx[i] * sx + dy[i] * sy >= 0;
    return num == 0 && forward ? 0 : INFINITY;
  }
  return num / (lo * lo * lo);
}

/* An upper bound of |z'| / |xy'| of the piece on [a, b] (depth: splits
** left where the hodograph's hull holds the origin). */
static double grade_on(const oc_vec3 *p, int n, double a, double b, int depth) {
  oc_vec3 s[4];
  oc_bez_sub(p, n, a, b, s);
  double dx[3], dy[3], dz = 0;
  for (int i = 0; i < n; i++) {
    dx[i] = n * (s[i + 1].x - s[i].x), dy[i] = n * (s[i + 1].y - s[i].y);
    dz = fmax(dz, fabs(n * (s[i + 1].z - s[i].z)));
  }
  if (dz == 0) return 0;
  double lo = hull_dist0(dx, dy, n);
  if (lo > 0) return dz / lo * (1 + 1e-9);
  if (depth >= 12) return INFINITY;
  double m = (a + b) / 2;
  return fmax(grade_on(p, n, a, m, depth + 1), grade_on(p, n, m, b, depth + 1));
}

double oc_bez_grade_bound(const oc_vec3 *p, int n) {
  double g = 0;
  for (int k = 0; k < 16; k++)
    g = fmax(g, grade_on(p, n, k / 16.0, (k + 1) / 16.0, 0));
  return g;
}

double oc_bez_kappa_bound(const oc_vec3 *p, int n, double rel_tol,
                          double abs_tol) {
  if (n < 2) return 0;
  double lo = fmax(
      fabs(oc_bez_curvature(p, n, 0)),
      fmax(fabs(oc_bez_curvature(p, n, 0.5)), fabs(oc_bez_curvature(p, n, 1))));
  double hi = 0;
  struct {
    double a, b;
    int depth;
  } st[48];
  int top = 0, evals = 0;
  st[top].a = 0, st[top].b = 1, st[top].depth = 0, top++;
  while (top > 0) {
    double a = st[top - 1].a, b = st[top - 1].b;
    int depth = st[top - 1].depth;
    top--;
    double u = kappa_on(p, n, a, b), mid = 0.5 * (a + b);
    lo = fmax(lo, fabs(oc_bez_curvature(p, n, mid)));
    evals++;
    /* Past the depth or the budget the interval's bound is kept as is:
    ** looser, still an upper bound. */
    if (u <= lo * (1 + rel_tol) + abs_tol || depth >= 40 || evals > 4096) {
      hi = fmax(hi, u);
      continue;
    }
    st[top].a = mid, st[top].b = b, st[top].depth = depth + 1, top++;
    st[top].a = a, st[top].b = mid, st[top].depth = depth + 1, top++;
  }
  return fmax(hi, lo) * (1 + 1e-9);
}

/* ---- flattening -------------------------------------------------------- */

/* Squared distance from (x, y) to the segment [a, b] (xy). */
static double seg_d2(oc_vec3 a, oc_vec3 b, double x, double y) {
  double d = seg_dist0(a.x - x, a.y - y, b.x - x, b.y - y);
  return d * d;
}

size_t oc_bez_flatten(const oc_vec3 *p, int n, double tol,
                      void (*emit)(void *ud, double t), void *ud) {
  struct {
    double a, b;
    int depth;
  } st[40];
  int top = 0;
  size_t k = 0;
  st[top].a = 0, st[top].b = 1, st[top].depth = 0, top++;
  while (top > 0) {
    double a = st[top - 1].a, b = st[top - 1].b;
    int depth = st[top - 1].depth;
    top--;
    int flat = 1;
    if (n > 1 && depth < 30) {
      oc_vec3 s[4];
      oc_bez_sub(p, n, a, b, s);
      for (int i = 1; i < n && flat; i++)
        flat = seg_d2(s[0], s[n], s[i].x, s[i].y) <= tol * tol;
    }
    if (flat) {
      if (emit) emit(ud, b);
      k++;
      continue;
    }
    double mid = 0.5 * (a + b);
    st[top].a = mid, st[top].b = b, st[top].depth = depth + 1, top++;
    st[top].a = a, st[top].b = mid, st[top].depth = depth + 1, top++;
  }
  return k;
}
