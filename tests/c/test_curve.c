/*
** test_curve.c — piecewise planar curves (lib/core/curve.h): closest
** points against a dense brute-force search, arc length against a fine
** numeric integral, signed distance, frames, the curvature bound against
** sampled curvature, flattening tolerance, bounds, closed curves, bad
** input. The references below (Bernstein sums, Simpson's rule, golden
** section search) are written here, independently of lib/core/bezier.c.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/bezier.h"
#include "core/curve.h"
#include "ocheck.h"

/* 4/3 (sqrt 2 - 1): the cubic closest to a quarter circle. */
#define OCT_PI 3.14159265358979323846
#define KAPPA_Q 0.55228474983079339840

/* ---- references --------------------------------------------------------- */

static oc_vec3 ref_eval(const oc_curve_piece *pc, double t) {
  double u = 1 - t, w[4];
  switch (pc->degree) {
  case 1:
    w[0] = u, w[1] = t;
    break;
  case 2:
    w[0] = u * u, w[1] = 2 * u * t, w[2] = t * t;
    break;
  default:
    w[0] = u * u * u, w[1] = 3 * u * u * t, w[2] = 3 * u * t * t,
    w[3] = t * t * t;
  }
  oc_vec3 q = {0, 0, 0};
  for (int i = 0; i <= pc->degree; i++)
    q = oct_add(q, oct_mul(pc->p[i], w[i]));
  return q;
}

/* Derivatives by the power form of each degree. */
static void ref_deriv(const oc_curve_piece *pc, double t, oc_vec3 *d1,
                      oc_vec3 *d2) {
  const oc_vec3 *p = pc->p;
  double u = 1 - t;
  if (pc->degree == 1) {
    *d1 = oct_sub(p[1], p[0]);
    *d2 = oct_v(0, 0, 0);
  } else if (pc->degree == 2) {
    *d1 = oct_add(oct_mul(oct_sub(p[1], p[0]), 2 * u),
                  oct_mul(oct_sub(p[2], p[1]), 2 * t));
    *d2 = oct_mul(oct_add(oct_sub(p[2], oct_mul(p[1], 2)), p[0]), 2);
  } else {
    *d1 = oct_add(oct_add(oct_mul(oct_sub(p[1], p[0]), 3 * u * u),
                          oct_mul(oct_sub(p[2], p[1]), 6 * u * t)),
                  oct_mul(oct_sub(p[3], p[2]), 3 * t * t));
    *d2 =
        oct_add(oct_mul(oct_add(oct_sub(p[2], oct_mul(p[1], 2)), p[0]), 6 * u),
                oct_mul(oct_add(oct_sub(p[3], oct_mul(p[2], 2)), p[1]), 6 * t));
  }
}

static double ref_speed(const oc_curve_piece *pc, double t) {
  oc_vec3 a, b;
  ref_deriv(pc, t, &a, &b);
  return hypot(a.x, a.y);
}

static double ref_kappa(const oc_curve_piece *pc, double t) {
  oc_vec3 a, b;
  ref_deriv(pc, t, &a, &b);
  double v = hypot(a.x, a.y);
  return fabs(a.x * b.y - a.y * b.x) / (v * v * v);
}

/* Composite Simpson on [a, b] with 2m intervals. */
static double ref_arclen(const oc_curve_piece *pc, double a, double b, int m) {
  double h = (b - a) / (2 * m), s = ref_speed(pc, a) + ref_speed(pc, b);
  for (int i = 1; i < 2 * m; i++)
    s += (i % 2 ? 4 : 2) * ref_speed(pc, a + i * h);
  return s * h / 3;
}

static double d2xy(oc_vec3 q, double x, double y) {
  return (q.x - x) * (q.x - x) + (q.y - y) * (q.y - y);
}

/* Closest point by dense sampling then golden-section refinement around
** the best samples (the distance is unimodal near a local minimum). */
static double ref_closest(const oc_curve_piece *pcs, int n, double x, double y,
                          int *bp, double *bt) {
  const int N = 4000;
  double best = INFINITY;
  for (int i = 0; i < n; i++)
    for (int k = 0; k <= N; k++) {
      double t = (double)k / N, d = d2xy(ref_eval(&pcs[i], t), x, y);
      if (d < best) best = d, *bp = i, *bt = t;
    }
  /* refine every sample within a margin of the best (several basins) */
  double out = INFINITY;
  int op = *bp;
  double ot = *bt;
  for (int i = 0; i < n; i++)
    for (int k = 0; k <= N; k++) {
      double t = (double)k / N;
      double d = d2xy(ref_eval(&pcs[i], t), x, y);
      if (d > best * 1.01 + 1e-12) continue;
      double a = fmax(0, t - 1.0 / N), b = fmin(1, t + 1.0 / N);
      const double g = 0.6180339887498949;
      for (int it = 0; it < 80; it++) {
        double c1 = b - g * (b - a), c2 = a + g * (b - a);
        if (d2xy(ref_eval(&pcs[i], c1), x, y) <
            d2xy(ref_eval(&pcs[i], c2), x, y))
          b = c2;
        else
          a = c1;
      }
      double tm = 0.5 * (a + b), dm = d2xy(ref_eval(&pcs[i], tm), x, y);
      if (dm < out) out = dm, op = i, ot = tm;
    }
  *bp = op, *bt = ot;
  return sqrt(out);
}

/* A wiggly G1 spline of m cubic pieces (shared tangents at joins). */
static int make_wiggle(oc_curve_piece *pcs, int m, oct_rng *r) {
  oc_vec3 p = oct_v(0, 0, 5), v = oct_v(10, 0, 0);
  for (int i = 0; i < m; i++) {
    oc_vec3 q = oct_add(p, oct_v(20 + oct_unif(r, -5, 5), oct_unif(r, -15, 15),
                                 oct_unif(r, -2, 2)));
    oc_vec3 w = oct_v(oct_unif(r, 5, 12), oct_unif(r, -8, 8), 0);
    pcs[i].degree = 3;
    pcs[i].p[0] = p;
    pcs[i].p[1] = oct_add(p, v);
    pcs[i].p[2] = oct_sub(q, w);
    pcs[i].p[3] = q;
    p = q, v = w;
  }
  return m;
}

static oc_pcurve *new_ok(const oc_curve_piece *pcs, int n) {
  oc_error err = {0};
  oc_pcurve *c = oc_curve_new(pcs, n, &err);
  ck_assert_msg(c, "oc_curve_new: %s", err.msg);
  return c;
}

/* ---- tests ----------------------------------------------------------- */

START_TEST(closest_matches_brute_force) {
  oct_rng r = oct_rng_new(17);
  oc_curve_piece pcs[8];
  int n = make_wiggle(pcs, 5, &r);
  /* one quadratic and one segment at the end, joined */
  oc_vec3 e = pcs[n - 1].p[3];
  pcs[n].degree = 2;
  pcs[n].p[0] = e;
  pcs[n].p[1] = oct_add(e, oct_v(10, 10, 1));
  pcs[n].p[2] = oct_add(e, oct_v(0, 20, 0));
  n++;
  pcs[n].degree = 1;
  pcs[n].p[0] = pcs[n - 1].p[2];
  pcs[n].p[1] = oct_add(pcs[n].p[0], oct_v(-30, 5, -3));
  n++;
  oc_pcurve *c = new_ok(pcs, n);
  oc_aabb b = oc_curve_bounds(c, 15);
  double worst = 0;
  int signs_bad = 0;
  for (int k = 0; k < 400; k++) {
    double x = oct_unif(&r, b.lo.x, b.hi.x), y = oct_unif(&r, b.lo.y, b.hi.y);
    int bp;
    double bt, ref = ref_closest(pcs, n, x, y, &bp, &bt);
    oc_curve_point cp;
    ck_assert(oc_curve_closest(c, x, y, INFINITY, &cp));
    double got = fabs(cp.d);
    worst = fmax(worst, fabs(got - ref));
    ck_assert_msg(fabs(got - ref) <= 1e-9 * (1 + ref),
                  "closest (%g, %g): %.15g vs reference %.15g", x, y, got, ref);
    /* q is on the curve at (piece, t) and at distance |d| */
    oc_vec3 q = ref_eval(&pcs[cp.piece], cp.t);
    ck_assert(hypot(q.x - cp.q.x, q.y - cp.q.y) < 1e-9);
    ck_assert(fabs(q.z - cp.q.z) < 1e-9);
    ck_assert(fabs(sqrt(d2xy(cp.q, x, y)) - got) < 1e-9);
    /* the sign from the reference tangent, where it is unambiguous */
    oc_vec3 d1, d2;
    ref_deriv(&pcs[cp.piece], cp.t, &d1, &d2);
    double cr = d1.x * (y - q.y) - d1.y * (x - q.x);
    if (cp.end == 0 && got > 1e-6 && (cr > 0) != (cp.d > 0)) signs_bad++;
    /* s against the reference arc length */
    double s = 0;
    for (size_t i = 0; i < cp.piece; i++)
      s += ref_arclen(&pcs[i], 0, 1, 2000);
    s += ref_arclen(&pcs[cp.piece], 0, cp.t, 2000);
    ck_assert_msg(fabs(s - cp.s) < 1e-8 * oc_curve_length(c),
                  "s %.12g vs %.12g", cp.s, s);
    /* without the arc length: the same point, s NaN, then its bits */
    oc_curve_point ct, cq;
    memset(&ct, 0, sizeof ct), memset(&cq, 0, sizeof cq); /* (padding) */
    ck_assert(oc_curve_closest(c, x, y, INFINITY, &cq));
    ck_assert(oc_curve_closest_t(c, x, y, INFINITY, &ct));
    ck_assert(isnan(ct.s));
    ct.s = oc_curve_s_at(c, &ct);
    ck_assert(!memcmp(&ct, &cq, sizeof ct));
    /* within r: the reference distance against r (away from the tie) */
    for (int m = 0; m < 3; m++) {
      double rad = ref * (m == 0 ? 0.97 : m == 1 ? 1.03 : 2.5);
      ck_assert_int_eq(oc_curve_within(c, x, y, rad), m > 0);
    }
  }
  printf("curve: closest vs brute force, worst |difference| %.3g\n", worst);
  ck_assert_int_eq(signs_bad, 0);
  oc_curve_free(c);
}
END_TEST

/* A segment said to be farther than r from the curve: every point of it
** finds no closest point within r (and the reference distance is above
** r); the test says so for most far segments, not for near ones. */
#ifdef __SANITIZE_ADDRESS__ /* (fewer segments in the sanitizer pass) */
#define FAR_SEGMENTS 100
#else
#define FAR_SEGMENTS 300
#endif

START_TEST(far_from_segment_is_sound) {
  oct_rng r = oct_rng_new(23);
  oc_curve_piece pcs[8];
  int n = make_wiggle(pcs, 6, &r);
  oc_pcurve *c = new_ok(pcs, n);
  oc_aabb b = oc_curve_bounds(c, 40);
  int far = 0, near = 0;
  for (int k = 0; k < FAR_SEGMENTS; k++) {
    double xa = oct_unif(&r, b.lo.x, b.hi.x), ya = oct_unif(&r, b.lo.y, b.hi.y);
    double xb = xa + oct_unif(&r, -20, 20), yb = ya + oct_unif(&r, -3, 3);
    double rad = oct_unif(&r, 0.5, 8);
    if (!oc_curve_far_from_segment(c, xa, ya, xb, yb, rad)) {
      near++;
      continue;
    }
    far++;
    for (int i = 0; i <= 40; i++) {
      double t = i / 40.0, x = xa + t * (xb - xa), y = ya + t * (yb - ya);
      oc_curve_point cp;
      int bp;
      double bt;
      ck_assert(!oc_curve_closest(c, x, y, rad, &cp));
      if (far <= 10 && i % 20 == 0) /* (the reference is slow) */
        ck_assert(ref_closest(pcs, n, x, y, &bp, &bt) > rad);
    }
  }
  ck_assert_msg(far > FAR_SEGMENTS / 6 && near > FAR_SEGMENTS / 15,
                "far %d, near %d", far, near);
  /* a segment through the curve, and a point on it, are never far */
  oc_vec3 q = pcs[1].p[0];
  ck_assert(!oc_curve_far_from_segment(c, q.x - 5, q.y, q.x + 5, q.y, 0.1));
  ck_assert(!oc_curve_far_from_segment(c, q.x, q.y, q.x, q.y, 0));
  ck_assert(
      !oc_curve_far_from_segment(c, q.x + 50, q.y, q.x + 60, q.y, INFINITY));
  oc_curve_free(c);
}
END_TEST

START_TEST(closest_within_radius) {
  oc_curve_piece seg = {1, {{0, 0, 0}, {10, 0, 2}}};
  oc_pcurve *c = new_ok(&seg, 1);
  oc_curve_point cp;
  ck_assert(!oc_curve_closest(c, 5, 3, 2.9, &cp));
  ck_assert(oc_curve_closest(c, 5, 3, 3.0, &cp)); /* exactly r: within */
  ck_assert_double_eq_tol(cp.d, 3, 1e-15);
  ck_assert_double_eq_tol(cp.s, 5, 1e-15);
  ck_assert_double_eq_tol(cp.q.z, 1, 1e-15);
  ck_assert(!oc_curve_closest(c, NAN, 0, 1, &cp));
  ck_assert(!oc_curve_closest(c, 0, 0, -1, &cp));
  ck_assert(!oc_curve_within(c, 5, 3, 2.9));
  ck_assert(oc_curve_within(c, 5, 3, 3.0));
  ck_assert(oc_curve_within(c, 10.5, 0, 0.6)); /* an end */
  ck_assert(!oc_curve_within(c, NAN, 0, 1));
  ck_assert(!oc_curve_within(c, 0, 0, -1));
  oc_curve_free(c);
  /* a diagonal cubic bulging to the upper left: (9, 1) is inside its
  ** axis-aligned box, 5.66 from its chord's frame (the line y = x) */
  oc_curve_piece cub = {3, {{0, 0, 0}, {3, 5, 0}, {7, 9, 0}, {10, 10, 0}}};
  c = new_ok(&cub, 1);
  double x = 9, y = 1, ref = INFINITY; /* the distance by dense sampling */
  for (int k = 0; k <= 100000; k++) {
    double t = k / 100000.0, u = 1 - t;
    double bx = 3 * u * u * t * 3 + 3 * u * t * t * 7 + t * t * t * 10;
    double by = 3 * u * u * t * 5 + 3 * u * t * t * 9 + t * t * t * 10;
    ref = fmin(ref, hypot(bx - x, by - y));
  }
  ck_assert(ref > 5.66);
  ck_assert(!oc_curve_within(c, x, y, 5.0));
  ck_assert(!oc_curve_within(c, x, y, 0.999 * ref));
  ck_assert(oc_curve_within(c, x, y, 1.001 * ref));
  oc_curve_free(c);
}
END_TEST

START_TEST(signed_distance_sign) {
  oc_curve_piece seg = {1, {{0, 0, 0}, {10, 0, 0}}};
  oc_pcurve *c = new_ok(&seg, 1);
  oc_curve_point cp;
  ck_assert(oc_curve_closest(c, 5, 2, INFINITY, &cp));
  ck_assert_double_eq_tol(cp.d, 2, 1e-15);
  ck_assert(oc_curve_closest(c, 5, -3, INFINITY, &cp));
  ck_assert_double_eq_tol(cp.d, -3, 1e-15);
  ck_assert(oc_curve_closest(c, -4, 3, INFINITY, &cp)); /* beyond the start */
  ck_assert_int_eq(cp.end, -1);
  ck_assert_double_eq_tol(cp.d, 5, 1e-15);
  oc_curve_free(c);
  /* a counter-clockwise circle of four cubics: the inside is on the left */
  oc_curve_piece q[4];
  double R = 50;
  for (int i = 0; i < 4; i++) {
    double a0 = i * OCT_PI / 2, a1 = (i + 1) * OCT_PI / 2;
    oc_vec3 p0 = oct_v(R * cos(a0), R * sin(a0), 0);
    oc_vec3 p3 = oct_v(R * cos(a1), R * sin(a1), 0);
    q[i].degree = 3;
    q[i].p[0] = p0;
    q[i].p[1] =
        oct_add(p0, oct_v(-R * KAPPA_Q * sin(a0), R * KAPPA_Q * cos(a0), 0));
    q[i].p[2] =
        oct_add(p3, oct_v(R * KAPPA_Q * sin(a1), -R * KAPPA_Q * cos(a1), 0));
    q[i].p[3] = p3;
  }
  c = new_ok(q, 4);
  ck_assert(oc_curve_closed(c));
  ck_assert(oc_curve_max_turn(c) < 1e-12);
  ck_assert(oc_curve_closest(c, 5, 7, INFINITY, &cp));
  ck_assert(cp.d > 0 && cp.end == 0);
  ck_assert_double_eq_tol(cp.d, R - hypot(5, 7), 1e-3 * R);
  ck_assert(oc_curve_closest(c, 80, -10, INFINITY, &cp));
  ck_assert(cp.d < 0);
  /* at the closing point: no end, the tangent is the bisector (0, 1) */
  ck_assert(oc_curve_closest(c, R + 5, 0, INFINITY, &cp));
  ck_assert(cp.end == 0 && cp.d < 0);
  ck_assert_double_eq_tol(cp.d, -5, 1e-12);
  ck_assert(fabs(cp.tx) < 1e-12 && fabs(cp.ty - 1) < 1e-12);
  ck_assert(cp.s == 0 || cp.s == oc_curve_length(c));
  oc_curve_free(c);
}
END_TEST

START_TEST(arclength_quarter_circle) {
  double R = 100;
  oc_curve_piece q = {
      3, {{R, 0, 0}, {R, R * KAPPA_Q, 1}, {R * KAPPA_Q, R, 2}, {0, R, 3}}};
  oc_pcurve *c = new_ok(&q, 1);
  double ref = ref_arclen(&q, 0, 1, 200000);
  double L = oc_curve_length(c);
  printf("curve: quarter-circle cubic length %.15g, Simpson %.15g, "
         "rel. difference %.3g (circle %.15g)\n",
         L, ref, fabs(L - ref) / ref, OCT_PI * R / 2);
  ck_assert(fabs(L - ref) <= 1e-9 * ref);
  ck_assert(fabs(L - OCT_PI * R / 2) < 1e-3 * L); /* it is circle-like */
  /* arc length parametrization: s -> t -> reference s */
  double worst = 0;
  for (int k = 0; k <= 64; k++) {
    double s = L * k / 64;
    oc_curve_point p;
    ck_assert(oc_curve_at(c, s, &p));
    double back = ref_arclen(&q, 0, p.t, 20000);
    worst = fmax(worst, fabs(back - s) / L);
    oc_vec3 e = ref_eval(&q, p.t);
    ck_assert(hypot(e.x - p.q.x, e.y - p.q.y) < 1e-9 * R);
    ck_assert(fabs(e.z - p.q.z) < 1e-12 * R);
    ck_assert_double_eq_tol(p.s, s, 1e-12 * L);
  }
  printf("curve: s(t(s)) worst relative error %.3g\n", worst);
  ck_assert(worst < 1e-9);
  oc_curve_point p;
  ck_assert(!oc_curve_at(c, NAN, &p));
  ck_assert(oc_curve_at(c, -5, &p) && p.s == 0 && p.q.x == R);
  ck_assert(oc_curve_at(c, 1e300, &p) && p.s == L && p.q.y == R);
  oc_curve_free(c);
}
END_TEST

START_TEST(frames_are_unit_and_left) {
  oct_rng r = oct_rng_new(5);
  oc_curve_piece pcs[4];
  int n = make_wiggle(pcs, 4, &r);
  oc_pcurve *c = new_ok(pcs, n);
  double L = oc_curve_length(c);
  for (int k = 1; k < 200; k++) {
    oc_curve_point p;
    ck_assert(oc_curve_at(c, L * k / 200, &p));
    oc_vec3 d1, d2;
    ref_deriv(&pcs[p.piece], p.t, &d1, &d2);
    double v = hypot(d1.x, d1.y);
    ck_assert(fabs(p.tx - d1.x / v) < 1e-9 && fabs(p.ty - d1.y / v) < 1e-9);
    ck_assert(fabs(hypot(p.tx, p.ty) - 1) < 1e-14);
    ck_assert(p.nx == -p.ty && p.ny == p.tx);
  }
  oc_curve_free(c);
}
END_TEST

START_TEST(kappa_bound_holds_and_is_tight) {
  double R = 100;
  oc_curve_piece q = {
      3, {{R, 0, 0}, {R, R * KAPPA_Q, 0}, {R * KAPPA_Q, R, 0}, {0, R, 0}}};
  oct_rng r = oct_rng_new(9);
  oc_curve_piece w[6];
  make_wiggle(w, 6, &r);
  oc_curve_piece quad = {2, {{0, 0, 0}, {10, 20, 0}, {30, 0, 0}}};
  struct {
    const oc_curve_piece *p;
    int n;
    const char *name;
  } cases[] = {{&q, 1, "quarter circle"}, {w, 6, "wiggle"}, {&quad, 1, "quad"}};
  for (int k = 0; k < 3; k++) {
    oc_pcurve *c = new_ok(cases[k].p, cases[k].n);
    double bound = oc_curve_kappa_max(c), sampled = 0;
    for (int i = 0; i < cases[k].n; i++)
      for (int j = 0; j <= 100000; j++)
        sampled = fmax(sampled, ref_kappa(&cases[k].p[i], j / 100000.0));
    printf("curve: kappa_max %s %.9g, sampled %.9g (ratio %.5f)\n",
           cases[k].name, bound, sampled, bound / sampled);
    ck_assert(bound >= sampled);
    ck_assert(bound <= 1.05 * sampled);
    if (k == 0) ck_assert(bound <= 2.0 / R);
    oc_curve_free(c);
  }
  /* a polyline has kappa 0 and corners */
  oc_vec3 sq[5] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}};
  oc_error err = {0};
  oc_pcurve *c = oc_curve_from_points(sq, 5, 1, &err);
  ck_assert(c && oc_curve_closed(c));
  ck_assert(oc_curve_kappa_max(c) == 0);
  ck_assert_double_eq_tol(oc_curve_max_turn(c), OCT_PI / 2, 1e-12);
  ck_assert_double_eq_tol(oc_curve_length(c), 4, 1e-15);
  oc_curve_free(c);
  /* a cusp: the derivative vanishes where the curve turns */
  oc_curve_piece cusp = {3, {{0, 0, 0}, {10, 10, 0}, {0, 10, 0}, {10, 0, 0}}};
  c = new_ok(&cusp, 1);
  ck_assert(isinf(oc_curve_kappa_max(c)));
  oc_curve_free(c);
  /* a straight cubic has kappa 0; one that doubles back along its line
  ** is a cusp */
  oc_curve_piece line = {3, {{0, 0, 0}, {1, 2, 0}, {5, 10, 0}, {6, 12, 0}}};
  c = new_ok(&line, 1);
  ck_assert(oc_curve_kappa_max(c) == 0);
  oc_curve_free(c);
  oc_curve_piece back = {3, {{0, 0, 0}, {6, 0, 0}, {-2, 0, 0}, {3, 0, 0}}};
  c = new_ok(&back, 1);
  ck_assert(isinf(oc_curve_kappa_max(c)));
  oc_curve_free(c);
}
END_TEST

START_TEST(flatten_within_tolerance) {
  oct_rng r = oct_rng_new(23);
  oc_curve_piece pcs[5];
  int n = make_wiggle(pcs, 5, &r);
  oc_pcurve *c = new_ok(pcs, n);
  double tol = 1e-2;
  size_t count = 0;
  oc_error err = {0};
  ck_assert_int_eq(oc_curve_flatten(c, tol, NULL, 0, &count, &err), OC_OK);
  ck_assert(count > 10);
  oc_curve_vertex *v = malloc(count * sizeof *v);
  size_t again = 0;
  ck_assert_int_eq(oc_curve_flatten(c, tol, v, count, &again, &err), OC_OK);
  ck_assert_uint_eq(again, count);
  ck_assert(v[0].s == 0 && v[count - 1].s == oc_curve_length(c));
  for (size_t i = 1; i < count; i++)
    ck_assert(v[i].s > v[i - 1].s);
  /* every dense sample of the curve is within tol of the polyline */
  double worst = 0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j <= 2000; j++) {
      oc_vec3 q = ref_eval(&pcs[i], j / 2000.0);
      double best = INFINITY;
      for (size_t k = 1; k < count; k++) {
        oc_vec3 a = oct_v(v[k - 1].x, v[k - 1].y, 0),
                b = oct_v(v[k].x, v[k].y, 0);
        best = fmin(best, oct_dist_segment(oct_v(q.x, q.y, 0), a, b, NULL));
      }
      worst = fmax(worst, best);
    }
  printf("curve: flatten tol %g: %zu vertices, worst distance %.3g\n", tol,
         count, worst);
  ck_assert(worst <= tol);
  /* vertices lie on the curve, at their arc length */
  for (size_t k = 0; k < count; k += 7) {
    oc_curve_point p;
    oc_curve_at(c, v[k].s, &p);
    ck_assert(hypot(p.q.x - v[k].x, p.q.y - v[k].y) < 1e-7);
  }
  free(v);
  ck_assert_int_eq(oc_curve_flatten(c, 0, NULL, 0, &count, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'tolerance'"));
  ck_assert_int_eq(oc_curve_flatten(c, NAN, NULL, 0, &count, &err), OC_EINVAL);
  oc_curve_free(c);
}
END_TEST

START_TEST(bounds_contain_the_curve) {
  oct_rng r = oct_rng_new(31);
  oc_curve_piece pcs[4];
  int n = make_wiggle(pcs, 4, &r);
  oc_pcurve *c = new_ok(pcs, n);
  oc_aabb b = oc_curve_bounds(c, 0), g = oc_curve_bounds(c, 3);
  oc_vec3 lo = oct_v(INFINITY, INFINITY, INFINITY), hi = oct_mul(lo, -1);
  for (int i = 0; i < n; i++)
    for (int j = 0; j <= 5000; j++) {
      oc_vec3 q = ref_eval(&pcs[i], j / 5000.0);
      ck_assert(q.x >= b.lo.x - 1e-12 && q.x <= b.hi.x + 1e-12);
      ck_assert(q.y >= b.lo.y - 1e-12 && q.y <= b.hi.y + 1e-12);
      ck_assert(q.z >= b.lo.z - 1e-12 && q.z <= b.hi.z + 1e-12);
      lo = oct_v(fmin(lo.x, q.x), fmin(lo.y, q.y), fmin(lo.z, q.z));
      hi = oct_v(fmax(hi.x, q.x), fmax(hi.y, q.y), fmax(hi.z, q.z));
    }
  /* tight: the sampled extremes reach the box */
  ck_assert(b.lo.x > lo.x - 1e-5 && b.lo.y > lo.y - 1e-5 &&
            b.lo.z > lo.z - 1e-5);
  ck_assert(b.hi.x < hi.x + 1e-5 && b.hi.y < hi.y + 1e-5 &&
            b.hi.z < hi.z + 1e-5);
  ck_assert(g.lo.x == b.lo.x - 3 && g.hi.y == b.hi.y + 3 && g.lo.z == b.lo.z);
  oc_curve_free(c);
}
END_TEST

START_TEST(bad_input_is_refused) {
  oc_error err = {0};
  oc_vec3 one = {1, 2, 3};
  ck_assert(!oc_curve_from_points(&one, 1, 3, &err));
  ck_assert_int_eq(err.code, OC_EINVAL);
  ck_assert(strstr(err.msg, "'points'"));
  oc_vec3 five[5] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  ck_assert(!oc_curve_from_points(five, 5, 3, &err)); /* not 3m + 1 */
  ck_assert(strstr(err.msg, "'points'"));
  ck_assert(!oc_curve_new(NULL, 0, &err));
  oc_curve_piece p[3] = {{1, {{0, 0, 0}, {1, 0, 0}}},
                         {1, {{1, 0, 0}, {2, NAN, 0}}},
                         {1, {{2, 0, 0}, {3, 0, 0}}}};
  ck_assert(!oc_curve_new(p, 3, &err));
  ck_assert_msg(strstr(err.msg, "piece 1") && strstr(err.msg, "finite"), "%s",
                err.msg);
  p[1].p[1].y = 0;
  p[2].p[0].x = 2.5;
  ck_assert(!oc_curve_new(p, 3, &err));
  ck_assert_msg(strstr(err.msg, "piece 2 does not start"), "%s", err.msg);
  p[2].p[0].x = 2;
  p[1].degree = 4;
  ck_assert(!oc_curve_new(p, 3, &err));
  ck_assert_msg(strstr(err.msg, "piece 1: degree"), "%s", err.msg);
  /* zero length everywhere, and a vertical step */
  oc_curve_piece dot = {3, {{1, 1, 0}, {1, 1, 0}, {1, 1, 0}, {1, 1, 0}}};
  ck_assert(!oc_curve_new(&dot, 1, &err));
  ck_assert_msg(strstr(err.msg, "no length"), "%s", err.msg);
  oc_curve_piece step[2] = {{1, {{0, 0, 0}, {1, 0, 0}}},
                            {1, {{1, 0, 0}, {1, 0, 5}}}};
  ck_assert(!oc_curve_new(step, 2, &err));
  ck_assert_msg(strstr(err.msg, "piece 1") && strstr(err.msg, "z changes"),
                "%s", err.msg);
  /* a zero-length piece with constant z is dropped */
  step[1].p[1].z = 0;
  oc_pcurve *c = oc_curve_new(step, 2, &err);
  ck_assert(c && oc_curve_npieces(c) == 1);
  oc_curve_free(c);
  /* finite points whose differences overflow (a fuzz finding, tests/corpus/
  ** elevation-river-huge-points: the arc length's subdivision went to depth
  ** 24, 25 s): refused at once */
  oc_vec3 far[4] = {
      {20, -0x1p63, -2}, {3, 1e308, 20}, {10, 1.5, 2}, {0, -2, 8}};
  ck_assert(!oc_curve_from_points(far, 4, 3, &err));
  ck_assert_msg(strstr(err.msg, "piece 0 is too long"), "%s", err.msg);
}
END_TEST

START_TEST(many_pieces_answer_fast) {
  /* a meandering G1 spline of 1000 pieces; queries near and far */
  oct_rng r = oct_rng_new(77);
  int n = 1000;
  oc_curve_piece *pcs = malloc(n * sizeof *pcs);
  make_wiggle(pcs, n, &r);
  clock_t tb = clock();
  oc_pcurve *c = new_ok(pcs, n);
  printf("curve: 1000 cubic pieces built in %.3f s (CPU)\n",
         (double)(clock() - tb) / CLOCKS_PER_SEC);
  oc_aabb b = oc_curve_bounds(c, 20);
  int nq = 20000, hits = 0;
  clock_t t0 = clock();
  double sum = 0;
  for (int k = 0; k < nq; k++) {
    double x = oct_unif(&r, b.lo.x, b.hi.x), y = oct_unif(&r, b.lo.y, b.hi.y);
    oc_curve_point cp;
    if (oc_curve_closest(c, x, y, 10, &cp)) hits++, sum += cp.d;
  }
  double sec = (double)(clock() - t0) / CLOCKS_PER_SEC;
  printf("curve: 1000 pieces, %d queries within r = 10 in %.3f s (%.2f us "
         "each, %d hits)\n",
         nq, sec, 1e6 * sec / nq, hits);
  ck_assert(hits > 0);
  /* a few answers against the reference over all pieces */
  for (int k = 0; k < 5; k++) {
    int i = (int)oct_unif(&r, 0, n - 1);
    oc_vec3 q = ref_eval(&pcs[i], 0.37);
    double x = q.x + 3, y = q.y - 2;
    oc_curve_point cp;
    ck_assert(oc_curve_closest(c, x, y, INFINITY, &cp));
    int bp;
    double bt, ref = ref_closest(pcs, n, x, y, &bp, &bt);
    ck_assert(fabs(fabs(cp.d) - ref) < 1e-9 * (1 + ref));
  }
  ck_assert(sec < 5.0); /* generous: 20000 queries, any machine */
  oc_curve_free(c);
  free(pcs);
}
END_TEST

START_TEST(hard_closest_cases) {
  /* the centre of a circle-like arc (every point nearly equidistant), the
  ** cusp curve near its cusp, a looping cubic near its crossing, points
  ** right on the curve */
  double R = 100;
  oc_curve_piece cases[3] = {
      {3, {{R, 0, 0}, {R, R * KAPPA_Q, 0}, {R * KAPPA_Q, R, 0}, {0, R, 0}}},
      {3, {{0, 0, 0}, {10, 10, 0}, {0, 10, 0}, {10, 0, 0}}},
      {3, {{0, 0, 0}, {30, 20, 1}, {-10, 20, 2}, {20, 0, 3}}}};
  oct_rng r = oct_rng_new(99);
  for (int k = 0; k < 3; k++) {
    oc_pcurve *c = new_ok(&cases[k], 1);
    oc_aabb b = oc_curve_bounds(c, 2);
    for (int i = 0; i < 300; i++) {
      double x, y;
      if (i == 0 && k == 0) {
        x = 0, y = 0;
      } else if (i % 3 == 0) {
        oc_vec3 q = ref_eval(&cases[k], oct_unif(&r, 0, 1));
        x = q.x + oct_unif(&r, -1e-7, 1e-7),
        y = q.y + oct_unif(&r, -1e-7, 1e-7);
      } else if (k == 1 && i % 3 == 1) {
        x = 5 + oct_unif(&r, -1, 1), y = 7.5 + oct_unif(&r, -1, 1);
      } else {
        x = oct_unif(&r, b.lo.x, b.hi.x), y = oct_unif(&r, b.lo.y, b.hi.y);
      }
      int bp;
      double bt, ref = ref_closest(&cases[k], 1, x, y, &bp, &bt);
      oc_curve_point cp;
      ck_assert(oc_curve_closest(c, x, y, INFINITY, &cp));
      ck_assert_msg(fabs(fabs(cp.d) - ref) <= 1e-9 * (1 + ref),
                    "case %d (%g, %g): %.15g vs %.15g", k, x, y, fabs(cp.d),
                    ref);
    }
    oc_curve_free(c);
  }
}
END_TEST

START_TEST(queries_are_thread_safe) {
  /* the same queries from two threads and from one give the same bits */
  oct_rng r = oct_rng_new(8);
  oc_curve_piece pcs[30];
  make_wiggle(pcs, 30, &r);
  oc_pcurve *c = new_ok(pcs, 30);
  enum { NQ = 20000 };
  static double xs[NQ], ys[NQ], d1[NQ], d2[NQ], s1[NQ], s2[NQ];
  oc_aabb b = oc_curve_bounds(c, 10);
  for (int i = 0; i < NQ; i++)
    xs[i] = oct_unif(&r, b.lo.x, b.hi.x), ys[i] = oct_unif(&r, b.lo.y, b.hi.y);
  for (int i = 0; i < NQ; i++) {
    oc_curve_point cp;
    oc_curve_closest(c, xs[i], ys[i], INFINITY, &cp);
    d1[i] = cp.d, s1[i] = cp.s;
  }
#pragma omp parallel for num_threads(2) schedule(dynamic, 64)
  for (int i = 0; i < NQ; i++) {
    oc_curve_point cp;
    oc_curve_closest(c, xs[i], ys[i], INFINITY, &cp);
    d2[i] = cp.d, s2[i] = cp.s;
  }
  ck_assert(memcmp(d1, d2, sizeof d1) == 0 && memcmp(s1, s2, sizeof s1) == 0);
  oc_curve_free(c);
}
END_TEST

static int same_cp(const oc_curve_point *a, const oc_curve_point *b) {
  return a->s == b->s && a->q.x == b->q.x && a->q.y == b->q.y &&
         a->q.z == b->q.z && a->tx == b->tx && a->ty == b->ty &&
         a->nx == b->nx && a->ny == b->ny && a->d == b->d &&
         a->piece == b->piece && a->t == b->t && a->end == b->end;
}

/* Two curves answer the same bits: closest points (near and far, within
** r or not), points at arc lengths, flattening, bounds and the bounds
** of curvature, turn and grade. */
static void same_answers(const oc_pcurve *a, const oc_pcurve *b, oct_rng *r) {
  ck_assert_uint_eq(oc_curve_npieces(a), oc_curve_npieces(b));
  ck_assert(oc_curve_length(a) == oc_curve_length(b));
  ck_assert(oc_curve_kappa_max(a) == oc_curve_kappa_max(b));
  ck_assert(oc_curve_max_turn(a) == oc_curve_max_turn(b));
  ck_assert(oc_curve_grade_max(a) == oc_curve_grade_max(b));
  oc_aabb ba = oc_curve_bounds(a, 5), bb = oc_curve_bounds(b, 5);
  ck_assert(memcmp(&ba, &bb, sizeof ba) == 0);
  for (int k = 0; k < 300; k++) {
    double x = oct_unif(r, ba.lo.x - 20, ba.hi.x + 20);
    double y = oct_unif(r, ba.lo.y - 20, ba.hi.y + 20), rad = k % 2 ? 6 : 1e9;
    oc_curve_point pa, pb;
    int ha = oc_curve_closest(a, x, y, rad, &pa);
    ck_assert_int_eq(ha, oc_curve_closest(b, x, y, rad, &pb));
    ck_assert_int_eq(oc_curve_within(a, x, y, 6), oc_curve_within(b, x, y, 6));
    ck_assert_int_eq(oc_curve_far_from_segment(a, x, y, x + 9, y + 2, 4),
                     oc_curve_far_from_segment(b, x, y, x + 9, y + 2, 4));
    if (ha) {
      ck_assert(same_cp(&pa, &pb));
      ck_assert(oc_curve_curvature_at(a, &pa) == oc_curve_curvature_at(b, &pb));
      ck_assert(oc_curve_grade_at(a, &pa) == oc_curve_grade_at(b, &pb));
    }
    double s = oct_unif(r, -1, 1.1) * oc_curve_length(a);
    ck_assert(oc_curve_at(a, s, &pa) && oc_curve_at(b, s, &pb));
    ck_assert(same_cp(&pa, &pb));
  }
  oc_error err;
  oc_curve_vertex va[400], vb[400];
  size_t na, nb;
  ck_assert_int_eq(oc_curve_flatten(a, 0.05, va, 400, &na, &err), OC_OK);
  ck_assert_int_eq(oc_curve_flatten(b, 0.05, vb, 400, &nb, &err), OC_OK);
  ck_assert(na == nb && na <= 400 && memcmp(va, vb, na * sizeof *va) == 0);
}

/* A Catmull-Rom curve keeps its through-points and derives the control
** points: it answers as the same pieces given explicitly, in fewer bytes
** (the layout of curve.c: a 16-byte header, an arc length per piece and
** at the end, the points, 2 n - 1 float boxes, and 12 bytes an inner
** arc-length knot plus 4 a piece when some piece has one). */
START_TEST(catmull_keeps_its_points) {
  oct_rng r = oct_rng_new(41);
  oc_vec3 P[9];
  for (int i = 0; i < 9; i++)
    P[i] = oct_v(30 * i, 25 * sin(0.9 * i) + oct_unif(&r, -3, 3), 10 - i);
  oc_error err = {0};
  for (int m = 2; m <= 9; m += 7) {
    oc_pcurve *c = oc_curve_catmull(P, (size_t)m, &err);
    ck_assert_msg(c, "%s", err.msg);
    oc_curve_piece pcs[8];
    for (int i = 0; i + 1 < m; i++) {
      oc_vec3 a = i > 0 ? P[i - 1] : oct_sub(oct_mul(P[0], 2), P[1]);
      oc_vec3 e =
          i + 2 < m ? P[i + 2] : oct_sub(oct_mul(P[m - 1], 2), P[m - 2]);
      pcs[i].degree = 3;
      pcs[i].p[0] = P[i], pcs[i].p[3] = P[i + 1];
      pcs[i].p[1] = oct_add(P[i], oct_mul(oct_sub(P[i + 1], a), 1.0 / 6));
      pcs[i].p[2] = oct_sub(P[i + 1], oct_mul(oct_sub(e, P[i]), 1.0 / 6));
    }
    oc_pcurve *x = new_ok(pcs, m - 1);
    same_answers(c, x, &r);
    size_t n = (size_t)m - 1, base = 16 + (n + 1) * 8 + (2 * n - 1) * 16;
    size_t bc = oc_curve_bytes(c), bx = oc_curve_bytes(x);
    ck_assert_uint_ge(bc, base + (size_t)m * 24);
    ck_assert_uint_eq((bc - base - (size_t)m * 24) % 4, 0);
    /* the explicit curve holds 3 n + 1 control points, the same knots */
    ck_assert_uint_eq(bx - bc, (3 * n + 1 - (size_t)m) * 24);
    if (m == 9) ck_assert_uint_eq(bc, 640); /* (golden: five inner knots) */
    oc_curve_free(c);
    oc_curve_free(x);
  }
  /* a last point within 1e-9 of the first closes the curve, snapped to
  ** it: the pieces are no longer those the points give, so the curve
  ** keeps their control points (3 n + 1 of them) */
  oc_vec3 Q[5] = {P[0], P[1], P[2], P[3], oct_add(P[0], oct_v(1e-12, 0, 0))};
  oc_pcurve *c = oc_curve_catmull(Q, 5, &err);
  ck_assert_msg(c, "%s", err.msg);
  ck_assert(oc_curve_closed(c) && oc_curve_npieces(c) == 4);
  oc_pcurve *q = oc_curve_catmull(Q, 4, &err);
  ck_assert_uint_ge(oc_curve_bytes(c), 16 + 5 * 8 + 13 * 24 + 7 * 16);
  ck_assert_uint_lt(oc_curve_bytes(q), 16 + 4 * 8 + 10 * 24 + 5 * 16);
  oc_curve_point pt;
  ck_assert(oc_curve_closest(c, P[0].x, P[0].y - 1, INFINITY, &pt));
  ck_assert(fabs(pt.d) <= 1 && pt.end == 0);
  oc_curve_free(c);
  oc_curve_free(q);
  ck_assert(!oc_curve_catmull(P, 1, &err));
  ck_assert_msg(strstr(err.msg, "'points'"), "%s", err.msg);
}
END_TEST

/* Curves of one degree and of mixed degrees store their control points
** (each shared end once) and answer as before: a polyline, a quadratic
** spline, and mixed pieces (their degrees kept per piece). */
START_TEST(stored_layouts_answer_alike) {
  oct_rng r = oct_rng_new(43);
  oc_vec3 pts[7];
  for (int i = 0; i < 7; i++)
    pts[i] = oct_v(20 * i, oct_unif(&r, -15, 15), i);
  oc_error err = {0};
  for (int deg = 1; deg <= 3; deg++) {
    oc_pcurve *c = oc_curve_from_points(pts, 7, deg, &err);
    ck_assert_msg(c, "%s", err.msg);
    size_t n = 6 / (size_t)deg;
    oc_curve_piece pcs[6];
    for (size_t i = 0; i < n; i++) {
      pcs[i].degree = deg;
      for (int k = 0; k <= deg; k++)
        pcs[i].p[k] = pts[i * (size_t)deg + (size_t)k];
    }
    oc_pcurve *x = new_ok(pcs, (int)n);
    same_answers(c, x, &r);
    if (deg == 1) /* header, n + 1 arc lengths, 7 points, 2 n - 1 boxes */
      ck_assert_uint_eq(oc_curve_bytes(c), 16 + 7 * 8 + 7 * 24 + 11 * 16);
    oc_curve_free(c);
    oc_curve_free(x);
  }
  /* mixed: a cubic, a segment, a quadratic; 7 points and n + 1 offsets */
  oc_curve_piece mix[3] = {{3, {pts[0], pts[1], pts[2], pts[3]}},
                           {1, {pts[3], pts[4]}},
                           {2, {pts[4], pts[5], pts[6]}}};
  oc_pcurve *c = new_ok(mix, 3);
  ck_assert_uint_ge(oc_curve_bytes(c), 16 + 4 * 8 + 7 * 24 + 4 * 4 + 5 * 16);
  for (int k = 0; k < 200; k++) {
    double x = oct_unif(&r, -10, 130), y = oct_unif(&r, -25, 25);
    oc_curve_point p;
    int bp;
    double bt, ref = ref_closest(mix, 3, x, y, &bp, &bt);
    ck_assert(oc_curve_closest(c, x, y, INFINITY, &p));
    ck_assert(fabs(fabs(p.d) - ref) <= 1e-9 * (1 + ref));
  }
  oc_curve_free(c);
}
END_TEST

/* The closest point of a piece (oc_bez_closest) keeps its bits: golden
** squared distances and parameters (hex) of cubic and quadratic pieces,
** queries near and far, within a radius and not, as the Bernstein search
** with de Casteljau's loops gave them before it was unrolled (bezier.c);
** and the x-y fast paths give oc_bez_eval's and oc_bez_d1's bits. */
START_TEST(closest_keeps_its_bits) {
  double R = 100, K = KAPPA_Q;
  oc_vec3 P[4][4] = {
      {{R, 0, 0}, {R, R * K, 0}, {R * K, R, 0}, {0, R, 0}},
      {{0, 0, 0}, {30, 20, 1}, {-10, 20, 2}, {20, 0, 3}},
      {{-150, -260, 30}, {-120, -220, 40}, {-60, -200, 50}, {0, -180, 60}},
      {{5, 5, 0}, {40, 10, 2}, {20, 60, 5}, {0, 0, 0}}};
  int deg[4] = {3, 3, 3, 2};
  double Q[6][3] = {{0, 0, INFINITY}, {60, 50, INFINITY}, {-90, -215, 17},
                    {10, 12, 400},    {25, 30, INFINITY}, {-100, -250, 9}};
  /* piece, query, d^2 (INFINITY: none within the radius), t */
  static const struct {
    int k, q;
    double d2, t;
  } gold[] = {
      {0, 0, 0x1.388p+13, 0x0p+0},
      {0, 1, 0x1.df9c1304a93bp+8, 0x1.c3a7f773e937ap-2},
      {0, 2, INFINITY, -0x1p+0},
      {0, 3, 0x1.bd04ee78d4357p+12, 0x1.1d49675e0f91ap-1},
      {0, 4, 0x1.d061a63a72552p+11, 0x1.1df23ba71052bp-1},
      {0, 5, INFINITY, -0x1p+0},
      {1, 0, 0x0p+0, 0x0p+0},
      {1, 1, 0x1.c6039bdb80e6ap+11, 0x1.8e40d60f0523fp-2},
      {1, 2, INFINITY, -0x1p+0},
      {1, 3, 0x1.7c61506a2936p+1, 0x1.06dcae8aba687p-2},
      {1, 4, 0x1.acea8c2f1ec29p+8, 0x1.a65fa2b3344edp-2},
      {1, 5, INFINITY, -0x1p+0},
      {2, 0, 0x1.fa4p+14, 0x1p+0},
      {2, 1, 0x1.b968p+15, 0x1p+0},
      {2, 2, 0x1.81ab7c1db5496p-2, 0x1.e5a7e0b8a21adp-2},
      {2, 3, 0x1.20c8p+15, 0x1p+0},
      {2, 4, 0x1.5d6ap+15, 0x1p+0},
      {2, 5, INFINITY, -0x1p+0},
      {3, 0, 0x1.9p+5, 0x0p+0},
      {3, 1, 0x1.3523ed19ab209p+10, 0x1.9c7705f10ba1ap-1},
      {3, 2, INFINITY, -0x1p+0},
      {3, 3, 0x1.063c3662ec592p+5, 0x1.b39367befb622p-4},
      {3, 4, 0x1.49f2181b470f3p+2, 0x1.4921486431043p-1},
      {3, 5, INFINITY, -0x1p+0},
  };
  for (size_t i = 0; i < sizeof gold / sizeof gold[0]; i++) {
    int k = gold[i].k, q = gold[i].q;
    double t = -1, b2 = Q[q][2] * Q[q][2];
    double d2 = oc_bez_closest(P[k], deg[k], Q[q][0], Q[q][1], b2, &t);
    if (gold[i].d2 == INFINITY) {
      ck_assert(d2 >= b2 && t == -1);
      continue;
    }
    ck_assert_msg(d2 == gold[i].d2 && t == gold[i].t,
                  "piece %d query %d: %a at %a, golden %a at %a", k, q, d2, t,
                  gold[i].d2, gold[i].t);
  }
  oct_rng r = oct_rng_new(41);
  for (int i = 0; i < 2000; i++) {
    oc_vec3 p[4];
    for (int j = 0; j < 4; j++)
      p[j] = (oc_vec3){oct_unif(&r, -1e3, 1e3), oct_unif(&r, -1e3, 1e3), 0};
    double t = oct_unif(&r, 0, 1), x, y;
    for (int n = 0; n <= 3; n++) {
      oc_vec3 e = oc_bez_eval(p, n, t);
      oc_bez_xy(p, n, t, &x, &y);
      ck_assert(!memcmp(&x, &e.x, sizeof x) && !memcmp(&y, &e.y, sizeof y));
      if (n == 0) continue;
      e = oc_bez_d1(p, n, t);
      oc_bez_d1_xy(p, n, t, &x, &y);
      ck_assert(!memcmp(&x, &e.x, sizeof x) && !memcmp(&y, &e.y, sizeof y));
    }
  }
}
END_TEST

/* Two radii in one search (oc_curve_closest_within): 2 with the bits of
** oc_curve_closest_t at the inner radius where it finds a point, 1 where
** only the outer radius holds one, 0 where neither does, on a winding
** Catmull-Rom road (bench_elev's fig22) and queries all round it. */
START_TEST(closest_within_answers_both) {
  oc_error err;
  oc_vec3 P[16];
  for (int i = 0; i < 16; i++) {
    double u = (double)i / 15;
    P[i] = oct_v(150 * sin(7.85 * u), -260 + 520 * u, 30 + 140 * u);
  }
  oc_pcurve *c = oc_curve_catmull(P, 16, &err);
  ck_assert_ptr_nonnull(c);
  oct_rng g = oct_rng_new(2207);
  int seen[3] = {0, 0, 0};
  for (int i = 0; i < 4000; i++) {
    double x = oct_unif(&g, -260, 260), y = oct_unif(&g, -330, 330);
    double rin = oct_unif(&g, 1, 40), r = rin + oct_unif(&g, 0, 60);
    oc_curve_point ref, got;
    memset(&ref, 0, sizeof ref), memset(&got, 0, sizeof got); /* (padding) */
    int in = oc_curve_closest_t(c, x, y, rin, &ref);
    double d2 = -1;
    int k = oc_curve_closest_within(c, x, y, rin, r, &got, &d2);
    ck_assert_int_eq(k == 2, in);
    ck_assert_int_eq(k >= 1, oc_curve_within(c, x, y, r));
    if (k == 2) ck_assert(!memcmp(&got, &ref, sizeof got));
    if (k >= 1) {
      oc_curve_point all;
      ck_assert(oc_curve_closest_t(c, x, y, INFINITY, &all));
      ck_assert(d2 == all.d * all.d ||
                fabs(sqrt(d2) - fabs(all.d)) <= 1e-12 * (1 + fabs(all.d)));
      ck_assert(d2 < r * r * (1 + 1e-12));
    }
    seen[k]++;
  }
  for (int k = 0; k < 3; k++)
    ck_assert_int_ge(seen[k], 200);
  oc_curve_free(c);
}
END_TEST

/* The elevations near a point (oc_curve_z_near): every point of the
** winding, climbing road of closest_within_answers_both within r of the
** query, sampled densely by arc length, has its z in the range; the range
** is local (a few pieces' rise, not the road's 140 m) and 0 is returned
** where no piece's box comes within r. */
START_TEST(z_near_holds_and_is_local) {
  oc_error err;
  oc_vec3 P[16];
  for (int i = 0; i < 16; i++) {
    double u = (double)i / 15;
    P[i] = oct_v(150 * sin(7.85 * u), -260 + 520 * u, 30 + 140 * u);
  }
  oc_pcurve *c = oc_curve_catmull(P, 16, &err);
  ck_assert_ptr_nonnull(c);
  double len = oc_curve_length(c);
  enum { NS = 4000 };
  static oc_curve_point at[NS + 1];
  for (int k = 0; k <= NS; k++)
    ck_assert(oc_curve_at(c, len * k / NS, &at[k]));
  oct_rng g = oct_rng_new(2213);
  int got = 0, none = 0, narrow = 0;
  for (int i = 0; i < 3000; i++) {
    double x = oct_unif(&g, -260, 260), y = oct_unif(&g, -330, 330);
    double r = oct_unif(&g, 1, 60), lo = NAN, hi = NAN;
    int k = oc_curve_z_near(c, x, y, r, &lo, &hi);
    int within = oc_curve_within(c, x, y, r);
    if (!k) {
      ck_assert(!within);
      ck_assert(isnan(lo) && isnan(hi)); /* (untouched) */
      none++;
      continue;
    }
    got++;
    for (int j = 0; j <= NS; j++)
      if (hypot(at[j].q.x - x, at[j].q.y - y) <= r)
        ck_assert_msg(at[j].q.z >= lo && at[j].q.z <= hi,
                      "z %.15g at s %g outside [%.15g, %.15g]", at[j].q.z,
                      at[j].s, lo, hi);
    narrow += within && hi - lo < 40;
  }
  ck_assert_int_ge(got, 500);
  ck_assert_int_ge(none, 500);
  ck_assert_int_ge(narrow, 300);
  /* (the whole road's range: 140 m; a piece rises 9.3 m) */
  double lo, hi;
  ck_assert(oc_curve_z_near(c, P[7].x, P[7].y, 1, &lo, &hi));
  ck_assert(lo <= P[7].z && hi >= P[7].z && hi - lo < 2 * 9.4);
  ck_assert(!oc_curve_z_near(c, 1000, 0, 10, &lo, &hi));
  ck_assert(!oc_curve_z_near(c, NAN, 0, 10, &lo, &hi));
  ck_assert(!oc_curve_z_near(c, 0, 0, -1, &lo, &hi));
  oc_curve_free(c);
}
END_TEST

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("curve");
  TCase *tc = tcase_create("curve");
  tcase_set_timeout(tc, 300);
  tcase_add_test(tc, closest_matches_brute_force);
  tcase_add_test(tc, closest_within_radius);
  tcase_add_test(tc, far_from_segment_is_sound);
  tcase_add_test(tc, signed_distance_sign);
  tcase_add_test(tc, arclength_quarter_circle);
  tcase_add_test(tc, frames_are_unit_and_left);
  tcase_add_test(tc, kappa_bound_holds_and_is_tight);
  tcase_add_test(tc, flatten_within_tolerance);
  tcase_add_test(tc, bounds_contain_the_curve);
  tcase_add_test(tc, bad_input_is_refused);
  tcase_add_test(tc, many_pieces_answer_fast);
  tcase_add_test(tc, hard_closest_cases);
  tcase_add_test(tc, queries_are_thread_safe);
  tcase_add_test(tc, catmull_keeps_its_points);
  tcase_add_test(tc, stored_layouts_answer_alike);
  tcase_add_test(tc, closest_keeps_its_bits);
  tcase_add_test(tc, closest_within_answers_both);
  tcase_add_test(tc, z_near_holds_and_is_local);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
