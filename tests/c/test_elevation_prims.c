/*
** test_elevation_prims.c — the lake (contour) and image primitives of
** elevation trees (Génevaux et al. 2015, sections 4 and 4.2): values
** against the formulas at chosen points (the default lake bed's knots,
** the shore through the polygon's vertices, the image's corners and its
** forward bilinear map), gradients against central differences, ranges
** and Lipschitz bounds never exceeded in random boxes and on random pairs,
** alpha 1 inside the shore and 0 beyond the falloff, the grids retained,
** and bad input refused with the field named.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/curve.h"
#include "elevation/enode.h"
#include "ocheck.h"

#define PI 3.14159265358979323846

static oc_enode *eok_(oc_enode *e, const oc_error *err, const char *what,
                      int line) {
  ck_assert_msg(e != NULL, "line %d: %s failed: %s", line, what, err->msg);
  return e;
}
#define EOK(expr) eok_((expr), &err, #expr, __LINE__)

static double wyv(double x) {
  if (x >= 1) return 0;
  if (x <= 0) return 1;
  double k = 1 - x * x;
  return k * k * k;
}

static void check_gradient(const oc_enode *e, double x, double y, double tol) {
  oc_enode_sample s, a, b;
  double h = 1e-6 * (1 + fabs(x) + fabs(y));
  oc_enode_eval(e, x, y, &s);
  oc_enode_eval(e, x + h, y, &a);
  oc_enode_eval(e, x - h, y, &b);
  double fx = (a.f - b.f) / (2 * h), ax = (a.a - b.a) / (2 * h);
  oc_enode_eval(e, x, y + h, &a);
  oc_enode_eval(e, x, y - h, &b);
  double fy = (a.f - b.f) / (2 * h), ay = (a.a - b.a) / (2 * h);
  double sc = 1 + fabs(fx) + fabs(fy);
  ck_assert_msg(fabs(fx - s.fx) <= tol * sc && fabs(fy - s.fy) <= tol * sc,
                "%s grad f at (%.9g, %.9g): (%g, %g) vs fd (%g, %g)",
                oc_enode_kind(e), x, y, s.fx, s.fy, fx, fy);
  double sa = 1 + fabs(ax) + fabs(ay);
  ck_assert_msg(fabs(ax - s.ax) <= tol * sa && fabs(ay - s.ay) <= tol * sa,
                "%s grad alpha at (%.9g, %.9g): (%g, %g) vs fd (%g, %g)",
                oc_enode_kind(e), x, y, s.ax, s.ay, ax, ay);
}

/* The bounds of box b hold at random points and pairs in it; the largest
** ratio of a seen slope to the bound goes to *ratio (a bound that is
** never approached is not a test of much). */
static void check_box(const oc_enode *e, oct_rng *r, double x0, double y0,
                      double x1, double y1, double *ratio) {
  oc_enode_bound b;
  oc_enode_bound_in(e, x0, y0, x1, y1, &b);
  for (int i = 0; i < 200; i++) {
    double px = oct_unif(r, x0, x1), py = oct_unif(r, y0, y1);
    double qx = oct_unif(r, x0, x1), qy = oct_unif(r, y0, y1);
    if (i == 0) px = x0, py = y0;
    if (i == 1) px = x1, py = y1;
    oc_enode_sample p, q;
    oc_enode_eval(e, px, py, &p);
    oc_enode_eval(e, qx, qy, &q);
    double m = 1e-9 * (1 + fabs(b.flo) + fabs(b.fhi));
    ck_assert_msg(p.f >= b.flo - m && p.f <= b.fhi + m,
                  "%s: f %.12g at (%g, %g) outside [%.12g, %.12g] of box "
                  "[%g, %g] x [%g, %g]",
                  oc_enode_kind(e), p.f, px, py, b.flo, b.fhi, x0, x1, y0, y1);
    ck_assert_msg(p.a >= b.alo - 1e-12 && p.a <= b.ahi + 1e-12,
                  "%s: alpha %.12g at (%g, %g) outside [%.12g, %.12g]",
                  oc_enode_kind(e), p.a, px, py, b.alo, b.ahi);
    ck_assert_msg(hypot(p.fx, p.fy) <= b.lf * (1 + 1e-9) + 1e-12,
                  "%s: |grad f| %g > %g at (%g, %g)", oc_enode_kind(e),
                  hypot(p.fx, p.fy), b.lf, px, py);
    ck_assert_msg(hypot(p.ax, p.ay) <= b.la * (1 + 1e-9) + 1e-12,
                  "%s: |grad alpha| %g > %g at (%g, %g)", oc_enode_kind(e),
                  hypot(p.ax, p.ay), b.la, px, py);
    double d = hypot(px - qx, py - qy);
    ck_assert(fabs(p.f - q.f) <= b.lf * d * (1 + 1e-9) + m);
    ck_assert(fabs(p.a - q.a) <= b.la * d * (1 + 1e-9) + 1e-12);
    if (b.lf > 0 && ratio) *ratio = fmax(*ratio, hypot(p.fx, p.fy) / b.lf);
  }
}

/* Random boxes of every size round (cx, cy), and the plane's bound. */
static double check_bounds(const oc_enode *e, double cx, double cy, double R) {
  oct_rng r = oct_rng_new(7);
  double ratio = 0;
  for (int i = 0; i < 150; i++) {
    double w = R * pow(10, oct_unif(&r, -3, 0.3));
    double x0 = cx + oct_unif(&r, -1.5 * R, 1.5 * R);
    double y0 = cy + oct_unif(&r, -1.5 * R, 1.5 * R);
    check_box(e, &r, x0, y0, x0 + w, y0 + w * oct_unif(&r, 0.2, 1), &ratio);
  }
  oc_enode_bound b;
  oc_enode_bound_in(e, cx - 3 * R, cy - 3 * R, cx + 3 * R, cy + 3 * R, &b);
  ck_assert(b.lf <= oc_enode_lipschitz(e) * (1 + 1e-12));
  double box[4], lo, hi;
  oc_enode_get_bounds(e, box, &lo, &hi);
  ck_assert(b.flo >= lo - 1e-9 && b.fhi <= hi + 1e-9);
  /* the global bound against the steepest slope of a dense sampling */
  double worst = 0;
  for (int i = 0; i < 20000; i++) {
    oc_enode_sample s;
    oc_enode_eval(e, cx + oct_unif(&r, -2 * R, 2 * R),
                  cy + oct_unif(&r, -2 * R, 2 * R), &s);
    worst = fmax(worst, hypot(s.fx, s.fy));
    ck_assert(s.f >= lo - 1e-9 && s.f <= hi + 1e-9);
  }
  ck_assert(worst <= oc_enode_lipschitz(e));
  if (getenv("OCT_VERBOSE"))
    fprintf(stderr, "%s: box ratio %.3f, plane ratio %.3f (%g / %g)\n",
            oc_enode_kind(e), ratio, worst / oc_enode_lipschitz(e), worst,
            oc_enode_lipschitz(e));
  return ratio;
}

/* ---- lake -------------------------------------------------------------- */

START_TEST(lake_default_bed) {
  oc_error err;
  double r1 = 100;
  oc_enode_lake_params p = {0};
  p.cx = 20, p.cy = -30, p.radii = &r1, p.nradii = 1, p.level = 10;
  p.bank = -1; /* the default, 2 */
  oc_enode *e = EOK(oc_enode_lake(&p, &err));
  ck_assert_str_eq(oc_enode_kind(e), "lake");
  /* falloff 50 (half the radius), bed 5 deep reached 50 in (D = min(50,
  ** 100)), flat shore, a 2 m bank at the falloff's end */
  struct {
    double rho, f;
  } knots[] = {{0, 5},      {30, 5},   {50, 5},  {100, 10},
               {112.5, 10}, {150, 12}, {400, 12}};
  for (size_t i = 0; i < sizeof knots / sizeof *knots; i++)
    for (int k = 0; k < 8; k++) {
      double a = k * PI / 4 + 0.1;
      oc_enode_sample s;
      oc_enode_eval(e, 20 + knots[i].rho * cos(a), -30 + knots[i].rho * sin(a),
                    &s);
      ck_assert_msg(fabs(s.f - knots[i].f) < 1e-9, "f(%g) = %.12g, not %g",
                    knots[i].rho, s.f, knots[i].f);
    }
  /* alpha: 1 inside the shore, g(delta / 50) outside, 0 beyond */
  oct_rng r = oct_rng_new(3);
  for (int i = 0; i < 2000; i++) {
    double rho = oct_unif(&r, 0, 170), a = oct_unif(&r, -PI, PI);
    oc_enode_sample s;
    oc_enode_eval(e, 20 + rho * cos(a), -30 + rho * sin(a), &s);
    ck_assert_double_eq_tol(s.a, wyv((rho - 100) / 50), 1e-12);
    if (rho <= 100) ck_assert(s.a == 1);
    if (rho >= 150) ck_assert(s.a == 0);
  }
  double box[4];
  oc_enode_get_bounds(e, box, NULL, NULL);
  ck_assert_double_eq_tol(box[0], 20 - 150, 1e-9);
  ck_assert_double_eq_tol(box[3], -30 + 150, 1e-9);
  double ratio = check_bounds(e, 20, -30, 150);
  ck_assert_msg(ratio > 0.5, "the lake's bounds are loose (%g)", ratio);
  for (int i = 0; i < 300; i++) {
    double rho = oct_unif(&r, 1, 200), a = oct_unif(&r, -PI, PI);
    check_gradient(e, 20 + rho * cos(a), -30 + rho * sin(a), 1e-5);
  }
  oc_enode_release(e);
}
END_TEST

/* A star-shaped pentagon, given clockwise, with three sectors whose bank
** differs. */
static oc_enode *pentagon_lake(double *vx, double *vy) {
  oc_error err;
  static double cont[10];
  double rr[5] = {80, 120, 95, 140, 70};
  for (int k = 0; k < 5; k++) { /* clockwise */
    double a = -2 * PI * k / 5 + 0.3;
    vx[k] = cont[2 * k] = 500 + rr[k] * cos(a);
    vy[k] = cont[2 * k + 1] = 200 + rr[k] * sin(a);
  }
  static const double d0[] = {-30, -10, 0, 15, 40};
  static const double v0[] = {-8, -6, 0, 0, 3};
  static const double v1[] = {-8, -4, 0, 2, 10};
  static const double v2[] = {-8, -7, 0, 0, 0};
  oc_enode_profile pr[3] = {
      {10, d0, v0, 5}, {130, d0, v1, 5}, {250, d0, v2, 5}};
  oc_enode_lake_params p = {0};
  p.cx = 500, p.cy = 200, p.contour = cont, p.ncontour = 5, p.level = -2;
  p.profiles = pr, p.nprofiles = 3, p.falloff = 40;
  return EOK(oc_enode_lake(&p, &err));
}

START_TEST(lake_contour_sectors) {
  double vx[5], vy[5];
  oc_enode *e = pentagon_lake(vx, vy);
  /* the shore passes through every vertex: level there, and alpha 1 */
  for (int k = 0; k < 5; k++) {
    oc_enode_sample s, o;
    oc_enode_eval(e, vx[k], vy[k], &s);
    ck_assert_msg(fabs(s.f + 2) < 1e-9 && fabs(s.a - 1) < 1e-12,
                  "vertex %d: f %.12g alpha %.12g", k, s.f, s.a);
    double ux = vx[k] - 500, uy = vy[k] - 200, L = hypot(ux, uy);
    oc_enode_eval(e, vx[k] + ux / L * 20, vy[k] + uy / L * 20, &o);
    ck_assert_double_eq_tol(o.a, wyv(20.0 / 40), 1e-9);
    oc_enode_eval(e, vx[k] + ux / L * 40.001, vy[k] + uy / L * 40.001, &o);
    ck_assert(o.a == 0);
  }
  /* at a profile's own angle, f is that profile: 130 degrees, d = 15 */
  oc_enode_sample s;
  double a = 130 * PI / 180;
  /* find the shore along the ray by bisection on alpha < 1 */
  double lo = 50, hi = 150;
  for (int i = 0; i < 80; i++) {
    double m = (lo + hi) / 2;
    oc_enode_eval(e, 500 + m * cos(a), 200 + m * sin(a), &s);
    if (s.a >= 1)
      lo = m;
    else
      hi = m;
  }
  oc_enode_eval(e, 500 + (lo + 15) * cos(a), 200 + (lo + 15) * sin(a), &s);
  ck_assert_msg(fabs(s.f - (-2 + 2)) < 1e-6, "f %.12g at 130 degrees", s.f);
  oc_enode_eval(e, 500 + (lo + 40) * cos(a), 200 + (lo + 40) * sin(a), &s);
  ck_assert(fabs(s.f - 8) < 1e-6);
  /* the centre: the common bed */
  oc_enode_eval(e, 500, 200, &s);
  ck_assert(fabs(s.f + 10) < 1e-12 && s.fx == 0 && s.fy == 0);
  oct_rng r = oct_rng_new(11);
  for (int i = 0; i < 400; i++) {
    double rho = oct_unif(&r, 5, 200), t = oct_unif(&r, -PI, PI);
    check_gradient(e, 500 + rho * cos(t), 200 + rho * sin(t), 1e-5);
  }
  double ratio = check_bounds(e, 500, 200, 200);
  ck_assert_msg(ratio > 0.3, "the lake's bounds are loose (%g)", ratio);
  oc_enode_release(e);
}
END_TEST

START_TEST(lake_radii_in_a_blend) {
  oc_error err;
  double radii[6] = {60, 90, 70, 110, 65, 80};
  oc_enode_lake_params p = {0};
  p.radii = radii, p.nradii = 6, p.level = 3, p.depth = 4, p.bank = 1;
  oc_enode *lake = EOK(oc_enode_lake(&p, &err));
  /* radius k lies at 60 k degrees from +x */
  for (int k = 0; k < 6; k++) {
    oc_enode_sample s;
    double a = k * PI / 3;
    oc_enode_eval(lake, radii[k] * cos(a), radii[k] * sin(a), &s);
    ck_assert(fabs(s.f - 3) < 1e-9 && s.a == 1);
    oc_enode_eval(lake, (radii[k] + 1e-3) * cos(a), (radii[k] + 1e-3) * sin(a),
                  &s);
    ck_assert(s.a < 1);
  }
  oc_enode_disc_params dp = {
      0, 0, 400, 20, {OC_ENOISE_PLAIN, 10, 80, 3, 0, 0, 5}};
  oc_enode *base = EOK(oc_enode_disc(&dp, &err));
  oc_enode *t = EOK(oc_enode_replace(base, lake, 0, &err));
  oc_enode_sample s;
  oc_enode_eval(t, 0, 0, &s);
  ck_assert(fabs(s.f - (3 - 4)) < 1e-9); /* fully replaced inside */
  check_bounds(t, 0, 0, 200);
  oc_enode_stats st;
  ck_assert_int_eq(oc_enode_get_stats(t, &st, &err), OC_OK);
  ck_assert_uint_eq(st.primitives, 2);
  oc_enode_release(base);
  oc_enode_release(lake);
  oc_enode_release(t);
}
END_TEST

START_TEST(lake_bad_input) {
  oc_error err;
  double r1 = 100, bad = -1;
  oc_enode_lake_params p = {0};
  p.radii = &r1, p.nradii = 1, p.level = NAN;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'level'"));
  p.level = 0;
  p.radii = &bad;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'radius[1]'"));
  p.radii = NULL;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'radius' or 'contour'"));
  /* a polygon that doubles back round the centre */
  double zig[8] = {10, 0, 0, 10, 10, 1, -10, 0};
  p.contour = zig, p.ncontour = 4;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'contour'"));
  double nanc[6] = {10, 0, NAN, 10, -10, -10};
  p.contour = nanc, p.ncontour = 3;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'contour[2]'"));
  /* a bed that varies right up to the centre */
  p.contour = NULL, p.radii = &r1, p.nradii = 1;
  double d[3] = {-150, 0, 10}, v[3] = {-9, 0, 1};
  oc_enode_profile pr = {0, d, v, 3};
  p.profiles = &pr, p.nprofiles = 1;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'profiles'"));
  /* sectors at different depths near the centre */
  double d2[3] = {-20, 0, 10}, v2a[3] = {-9, 0, 1}, v2b[3] = {-5, 0, 1};
  oc_enode_profile two[2] = {{0, d2, v2a, 3}, {180, d2, v2b, 3}};
  p.profiles = two, p.nprofiles = 2;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "same depth"));
  two[1].v = v2a;
  two[1].at = 360;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'profiles[2].angle'"));
  two[1].at = 180;
  oc_enode *ok = EOK(oc_enode_lake(&p, &err));
  oc_enode_release(ok);
  p.falloff = INFINITY;
  ck_assert_ptr_null(oc_enode_lake(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'falloff'"));
}
END_TEST

/* ---- image ------------------------------------------------------------- */

/* A grid of a smooth function: 41 x 29 samples, cell 2.5, origin (-7, 3). */
static oc_heightfield *grid(double (*fn)(double, double)) {
  oc_error err;
  enum { NX = 41, NY = 29 };
  float z[NX * NY];
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++)
      z[j * NX + i] = (float)fn(-7 + 2.5 * i, 3 + 2.5 * j);
  oc_heightfield *hf = oc_heightfield_new(NX, NY, 2.5, -7, 3, z, &err);
  ck_assert_msg(hf != NULL, "%s", err.msg);
  return hf;
}
static double hill(double x, double y) {
  return 30 * exp(-((x - 40) * (x - 40) + (y - 30) * (y - 30)) / 400) + 0.1 * x;
}
static double wfun(double x, double y) {
  return 0.55 + 0.3 * sin(x / 15) * cos(y / 11);
}
static double wclamped(double x, double y) {
  return 2 * sin(x / 9) + 0.5 * cos(y / 7);
}

static const double QUAD[8] = {100, 50, 260, 80, 240, 190, 90, 160};

static void forward(double u, double v, double *x, double *y) {
  *x = (1 - u) * (1 - v) * QUAD[0] + u * (1 - v) * QUAD[2] + u * v * QUAD[4] +
       (1 - u) * v * QUAD[6];
  *y = (1 - u) * (1 - v) * QUAD[1] + u * (1 - v) * QUAD[3] + u * v * QUAD[5] +
       (1 - u) * v * QUAD[7];
}

START_TEST(image_quad_formula) {
  oc_error err;
  oc_heightfield *hf = grid(hill), *wg = grid(wfun);
  oc_enode_image_params p = {0};
  p.heightfield = hf, p.weight = wg, p.height = 2, p.offset = -5;
  p.falloff = 12;
  memcpy(p.quad, QUAD, sizeof QUAD);
  oc_enode *e = EOK(oc_enode_image(&p, &err));
  /* the caller's references may go: the node keeps both grids */
  oc_heightfield_release(hf);
  oc_heightfield_release(wg);
  hf = grid(hill);
  wg = grid(wfun);
  ck_assert_str_eq(oc_enode_kind(e), "image");
  /* the grid's extent: x in [-7, 93], y in [3, 73] */
  oct_rng r = oct_rng_new(5);
  for (int i = 0; i < 3000; i++) {
    double u = oct_unif(&r, 0, 1), v = oct_unif(&r, 0, 1), x, y;
    if (i < 4) u = i & 1, v = i >> 1;
    forward(u, v, &x, &y);
    oc_enode_sample s;
    oc_enode_eval(e, x, y, &s);
    double X = -7 + 100 * u, Y = 3 + 70 * v;
    double want = -5 + 2 * oc_heightfield_height(hf, X, Y, NULL);
    ck_assert_msg(fabs(s.f - want) < 1e-8, "(u, v) = (%g, %g): %.12g vs %.12g",
                  u, v, s.f, want);
    /* alpha = w prod G(d_k / 12) */
    double P[4][2] = {{QUAD[0], QUAD[1]},
                      {QUAD[2], QUAD[3]},
                      {QUAD[4], QUAD[5]},
                      {QUAD[6], QUAD[7]}};
    double ab = 1;
    for (int k = 0; k < 4; k++) {
      double ex = P[(k + 1) & 3][0] - P[k][0], ey = P[(k + 1) & 3][1] - P[k][1];
      double dk = (-(ey) * (x - P[k][0]) + ex * (y - P[k][1])) / hypot(ex, ey);
      ab *= 1 - wyv(dk / 12);
    }
    double wi = oc_heightfield_height(wg, X, Y, NULL);
    ck_assert_double_eq_tol(s.a, fmin(1, fmax(0, wi)) * ab, 1e-9);
  }
  /* outside: alpha 0, f the value at the closest point of the border */
  for (int i = 0; i < 500; i++) {
    double t = oct_unif(&r, 0.02, 0.98), off = oct_unif(&r, 0.01, 80);
    double x, y, ox, oy;
    forward(t, 0, &x, &y); /* edge 0: outward normal (right of P0 -> P1) */
    double ex = QUAD[2] - QUAD[0], ey = QUAD[3] - QUAD[1], L = hypot(ex, ey);
    ox = x + ey / L * off;
    oy = y - ex / L * off;
    oc_enode_sample in, out;
    oc_enode_eval(e, x, y, &in);
    oc_enode_eval(e, ox, oy, &out);
    ck_assert(out.a == 0);
    ck_assert_double_eq_tol(out.f, in.f, 1e-8);
    check_gradient(e, ox, oy, 1e-4);
  }
  for (int i = 0; i < 400; i++) {
    double x, y;
    forward(oct_unif(&r, 0.01, 0.99), oct_unif(&r, 0.01, 0.99), &x, &y);
    check_gradient(e, x, y, 1e-4);
  }
  double ratio = check_bounds(e, 175, 120, 120);
  ck_assert_msg(ratio > 0.5, "the image's bounds are loose (%g)", ratio);
  oc_enode_release(e);
  oc_heightfield_release(hf);
  oc_heightfield_release(wg);
}
END_TEST

START_TEST(image_segment_and_clamped_weight) {
  oc_error err;
  oc_heightfield *hf = grid(hill), *wg = grid(wclamped);
  oc_enode_image_params p = {0};
  p.heightfield = hf, p.weight = wg, p.segment = 1;
  p.seg[0] = 0, p.seg[1] = 0, p.seg[2] = 300, p.seg[3] = 400;
  p.width = 140;
  oc_enode *e = EOK(oc_enode_image(&p, &err));
  /* the rectangle: corners at (0, 0) -/+ 70 n, n = (-0.8, 0.6) */
  double box[4], lo, hi;
  oc_enode_get_bounds(e, box, &lo, &hi);
  ck_assert_double_eq_tol(box[0], -56, 1e-9);
  ck_assert_double_eq_tol(box[1], -42, 1e-9);
  ck_assert_double_eq_tol(box[2], 356, 1e-9);
  ck_assert_double_eq_tol(box[3], 442, 1e-9);
  /* along the axis at s, across at t: the grid at (s / 500, t / 140 + 1/2) */
  oct_rng r = oct_rng_new(9);
  int clamped = 0;
  for (int i = 0; i < 2000; i++) {
    double s = oct_unif(&r, 0, 500), t = oct_unif(&r, -70, 70);
    double x = 0.6 * s - 0.8 * t, y = 0.8 * s + 0.6 * t;
    oc_enode_sample q;
    oc_enode_eval(e, x, y, &q);
    double X = -7 + 100 * s / 500, Y = 3 + 70 * (t / 140 + 0.5);
    ck_assert_double_eq_tol(q.f, oc_heightfield_height(hf, X, Y, NULL), 1e-8);
    double w = oc_heightfield_height(wg, X, Y, NULL);
    clamped += w <= 0 || w >= 1;
    /* the falloff: a tenth of sqrt(500 x 140) */
    double F = sqrt(500.0 * 140) / 10;
    double ab = (1 - wyv(s / F)) * (1 - wyv((500 - s) / F)) *
                (1 - wyv((70 - t) / F)) * (1 - wyv((t + 70) / F));
    ck_assert_double_eq_tol(q.a, fmin(1, fmax(0, w)) * ab, 1e-9);
  }
  ck_assert(clamped > 200); /* the clamp was exercised */
  ck_assert(lo >= -10 && hi <= 50);
  check_bounds(e, 150, 200, 260);
  oc_enode_release(e);
  oc_heightfield_release(hf);
  oc_heightfield_release(wg);
}
END_TEST

/* ---- image along a curve ---------------------------------------------- */

/* Bounds in random boxes for a primitive whose slope bounds hold where
** alpha > 0 (along a curve): ranges of f and alpha and alpha's slope
** everywhere, f's slope where alpha > 0. The largest ratio of a slope
** seen to the bound goes to *ratio. */
static void check_band_boxes(const oc_enode *e, double cx, double cy, double R,
                             double *ratio) {
  oct_rng r = oct_rng_new(23);
  int inband = 0;
  for (int i = 0; i < 300; i++) {
    double w = R * pow(10, oct_unif(&r, -3, 0.3));
    double x0 = cx + oct_unif(&r, -R, R), y0 = cy + oct_unif(&r, -R, R);
    double x1 = x0 + w, y1 = y0 + w * oct_unif(&r, 0.2, 1);
    oc_enode_bound b;
    oc_enode_bound_in(e, x0, y0, x1, y1, &b);
    for (int k = 0; k < 100; k++) {
      double px = oct_unif(&r, x0, x1), py = oct_unif(&r, y0, y1);
      double qx = oct_unif(&r, x0, x1), qy = oct_unif(&r, y0, y1);
      oc_enode_sample p, q;
      oc_enode_eval(e, px, py, &p);
      oc_enode_eval(e, qx, qy, &q);
      double m = 1e-9 * (1 + fabs(b.flo) + fabs(b.fhi));
      ck_assert_msg(p.f >= b.flo - m && p.f <= b.fhi + m,
                    "f %.12g at (%g, %g) outside [%.12g, %.12g]", p.f, px, py,
                    b.flo, b.fhi);
      ck_assert_msg(p.a >= b.alo - 1e-12 && p.a <= b.ahi + 1e-12,
                    "alpha %.12g at (%g, %g) outside [%.12g, %.12g]", p.a, px,
                    py, b.alo, b.ahi);
      ck_assert_msg(hypot(p.ax, p.ay) <= b.la * (1 + 1e-9) + 1e-12,
                    "|grad alpha| %g > %g at (%g, %g)", hypot(p.ax, p.ay), b.la,
                    px, py);
      double d = hypot(px - qx, py - qy);
      ck_assert(fabs(p.a - q.a) <= b.la * d * (1 + 1e-9) + 1e-12);
      if (p.a > 0) {
        inband++;
        ck_assert_msg(hypot(p.fx, p.fy) <= b.lf * (1 + 1e-9) + 1e-12,
                      "|grad f| %g > %g at (%g, %g)", hypot(p.fx, p.fy), b.lf,
                      px, py);
        *ratio = fmax(*ratio, hypot(p.fx, p.fy) / b.lf);
      }
    }
  }
  ck_assert_int_gt(inband, 3000);
}

static const oc_vec3 WIND[5] = {
    {0, 0, 0}, {100, 60, 0}, {200, -40, 0}, {300, 50, 0}, {400, 0, 0}};

START_TEST(image_curve_formula) {
  oc_error err;
  oc_heightfield *hf = grid(hill), *wg = grid(wfun);
  /* a straight curve is the segment: the same f, alpha and gradients
  ** everywhere, beyond the ends and the sides too */
  oc_vec3 line[3] = {{0, 0, 0}, {150, 200, 0}, {300, 400, 0}};
  oc_enode_image_params sp = {0}, cp = {0};
  sp.heightfield = cp.heightfield = hf;
  sp.weight = cp.weight = wg;
  sp.segment = 1, sp.seg[2] = 300, sp.seg[3] = 400;
  sp.width = cp.width = 140;
  sp.falloff = cp.falloff = 20;
  sp.height = cp.height = 1.5, sp.offset = cp.offset = 4;
  cp.curve = line, cp.ncurve = 3, cp.spline = OC_ECURVE_CATMULL;
  oc_enode *seg = EOK(oc_enode_image(&sp, &err));
  oc_enode *str = EOK(oc_enode_image(&cp, &err));
  oct_rng r = oct_rng_new(31);
  for (int i = 0; i < 2000; i++) {
    double x = oct_unif(&r, -100, 400), y = oct_unif(&r, -100, 500);
    oc_enode_sample a, b;
    oc_enode_eval(seg, x, y, &a);
    oc_enode_eval(str, x, y, &b);
    ck_assert_msg(fabs(a.f - b.f) < 1e-8 && fabs(a.a - b.a) < 1e-9,
                  "(%g, %g): f %.12g vs %.12g, alpha %.12g vs %.12g", x, y, a.f,
                  b.f, a.a, b.a);
    ck_assert(fabs(a.fx - b.fx) < 1e-7 && fabs(a.fy - b.fy) < 1e-7);
    ck_assert(fabs(a.ax - b.ax) < 1e-7 && fabs(a.ay - b.ay) < 1e-7);
  }
  /* a winding curve: the point at arc length s and offset t maps to the
  ** grid at (s / L, t / w + 1/2) */
  oc_enode_image_params wp = cp;
  wp.curve = WIND, wp.ncurve = 5, wp.width = 30, wp.falloff = 0;
  wp.weight = NULL;
  oc_enode *e = EOK(oc_enode_image(&wp, &err));
  oc_pcurve *c = oc_ecurve_skeleton(WIND, 5, OC_ECURVE_CATMULL, &err);
  ck_assert_ptr_nonnull(c);
  double L = oc_curve_length(c);
  double F = fmin(sqrt(L * 30) / 10, 7.5); /* the default falloff */
  int full = 0;
  for (int i = 0; i < 2000; i++) {
    double s = oct_unif(&r, 0, L), t = oct_unif(&r, -15, 15);
    if (i < 4) s = (i & 1) * L, t = i & 2 ? 15 : -15;
    oc_curve_point pt;
    ck_assert(oc_curve_at(c, s, &pt));
    double x = pt.q.x + t * pt.nx, y = pt.q.y + t * pt.ny;
    oc_enode_sample q;
    oc_enode_eval(e, x, y, &q);
    double X = -7 + 100 * s / L, Y = 3 + 70 * (t / 30 + 0.5);
    double want = 4 + 1.5 * oc_heightfield_height(hf, X, Y, NULL);
    ck_assert_msg(fabs(q.f - want) < 1e-7, "(s, t) = (%g, %g): %.12g vs %.12g",
                  s, t, q.f, want);
    double ab = (1 - wyv(s / F)) * (1 - wyv((L - s) / F)) *
                (1 - wyv((15 - t) / F)) * (1 - wyv((t + 15) / F));
    ck_assert_double_eq_tol(q.a, ab, 1e-9);
    full += q.a == 1;
    if (i >= 4 && fabs(t) < 14.9) check_gradient(e, x, y, 1e-4);
  }
  ck_assert_int_gt(full, 500);
  /* beyond the sides (within the curvature's reach): f at the clamped
  ** offset, alpha 0; the gradient exact there too */
  for (int i = 0; i < 400; i++) {
    double s = oct_unif(&r, 1, L - 1), t = oct_unif(&r, 15.5, 25);
    oc_curve_point pt;
    ck_assert(oc_curve_at(c, s, &pt));
    double sg = i & 1 ? 1 : -1;
    if (1 / fabs(oc_curve_curvature_at(c, &pt)) < 30) continue;
    double x = pt.q.x + sg * t * pt.nx, y = pt.q.y + sg * t * pt.ny;
    oc_enode_sample q, in;
    oc_enode_eval(e, x, y, &q);
    oc_enode_eval(e, pt.q.x + sg * 15 * pt.nx, pt.q.y + sg * 15 * pt.ny, &in);
    ck_assert(q.a == 0);
    ck_assert_double_eq_tol(q.f, in.f, 1e-7);
    check_gradient(e, x, y, 1e-4);
  }
  double ratio = 0;
  check_band_boxes(e, 200, 0, 150, &ratio);
  ck_assert_msg(ratio > 0.3, "the curve image's bounds are loose (%g)", ratio);
  /* and with a weight grid */
  wp.weight = wg;
  oc_enode *ew = EOK(oc_enode_image(&wp, &err));
  for (int i = 0; i < 300; i++) {
    double s = oct_unif(&r, 0, L), t = oct_unif(&r, -14.9, 14.9);
    oc_curve_point pt;
    ck_assert(oc_curve_at(c, s, &pt));
    check_gradient(ew, pt.q.x + t * pt.nx, pt.q.y + t * pt.ny, 1e-4);
  }
  ratio = 0;
  check_band_boxes(ew, 200, 0, 150, &ratio);
  /* a long thin grid, steep along the curve: the bound's along-curve term
  ** 1 / (1 - kappa w/2) counts, on the inner side of the bends */
  enum { NX = 201, NY = 5 };
  float z[NX * NY];
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++)
      z[j * NX + i] = (float)(20 * sin(i / 6.0) + j);
  oc_heightfield *thin = oc_heightfield_new(NX, NY, 2.5, 0, 0, z, &err);
  ck_assert_ptr_nonnull(thin);
  wp.heightfield = thin, wp.weight = NULL;
  oc_enode *et = EOK(oc_enode_image(&wp, &err));
  oc_heightfield_release(thin);
  ratio = 0;
  check_band_boxes(et, 200, 0, 150, &ratio);
  ck_assert_msg(ratio > 0.2, "loose along the curve (%g)", ratio);
  /* the plane's bounds */
  double box[4], lo, hi;
  oc_enode_get_bounds(e, box, &lo, &hi);
  ck_assert(box[0] <= -15 && box[2] >= 415);
  for (int i = 0; i < 3000; i++) {
    oc_enode_sample q;
    oc_enode_eval(e, oct_unif(&r, -500, 900), oct_unif(&r, -500, 500), &q);
    ck_assert(q.f >= lo - 1e-9 && q.f <= hi + 1e-9);
    if (q.a > 0) ck_assert(hypot(q.fx, q.fy) <= oc_enode_lipschitz(e));
  }
  oc_curve_free(c);
  oc_enode *all[5] = {seg, str, e, ew, et};
  for (int i = 0; i < 5; i++)
    oc_enode_release(all[i]);
  oc_heightfield_release(hf);
  oc_heightfield_release(wg);
}
END_TEST

START_TEST(image_curve_bad_input) {
  oc_error err;
  oc_heightfield *hf = grid(hill);
  oc_enode_image_params p = {0};
  p.heightfield = hf;
  p.curve = WIND, p.ncurve = 5, p.width = 30;
  oc_enode *ok = EOK(oc_enode_image(&p, &err));
  oc_enode_release(ok);
  /* wider than the bends allow (radius of curvature about 33 here) */
  p.width = 80;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_msg(strstr(err.msg, "'width'") && strstr(err.msg, "curvature"),
                "%s", err.msg);
  p.width = NAN;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'width'"));
  p.width = 30;
  p.ncurve = 1;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'curve'"));
  oc_vec3 corner[3] = {{0, 0, 0}, {100, 0, 0}, {100, 100, 0}};
  p.curve = corner, p.ncurve = 3, p.spline = OC_ECURVE_LINEAR;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_msg(strstr(err.msg, "'curve'") && strstr(err.msg, "corner"), "%s",
                err.msg);
  oc_vec3 nanp[3] = {{0, 0, 0}, {100, NAN, 0}, {200, 0, 0}};
  p.curve = nanp, p.spline = OC_ECURVE_CATMULL;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'curve'"));
  /* a closed loop: the grid's x would jump where the ends meet */
  oc_vec3 loop[4] = {{0, 0, 0}, {100, 0, 0}, {50, 80, 0}, {0, 0, 0}};
  p.curve = loop, p.ncurve = 4, p.spline = OC_ECURVE_BEZIER;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_msg(strstr(err.msg, "'curve'") && strstr(err.msg, "open"), "%s",
                err.msg);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(image_bad_input) {
  oc_error err;
  oc_heightfield *hf = grid(hill);
  oc_enode_image_params p = {0};
  p.heightfield = hf;
  double concave[8] = {0, 0, 10, 0, 3, 3, 0, 10};
  memcpy(p.quad, concave, sizeof concave);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'quad' must be convex"));
  double cw[8] = {0, 0, 0, 10, 10, 10, 10, 0};
  memcpy(p.quad, cw, sizeof cw);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "counter-clockwise"));
  double flat[8] = {0, 0, 5, 0, 10, 0, 0, 10};
  memcpy(p.quad, flat, sizeof flat);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "degenerate"));
  double twice[8] = {0, 0, 10, 0, 10, 0, 0, 10};
  memcpy(p.quad, twice, sizeof twice);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "degenerate"));
  double crossed[8] = {0, 0, 10, 10, 10, 0, 0, 10};
  memcpy(p.quad, crossed, sizeof crossed);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'quad'"));
  double nanq[8] = {0, 0, 10, 0, 10, NAN, 0, 10};
  memcpy(p.quad, nanq, sizeof nanq);
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'quad[3]'"));
  double sq[8] = {0, 0, 10, 0, 10, 10, 0, 10};
  memcpy(p.quad, sq, sizeof sq);
  p.height = NAN;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'height'"));
  p.height = 1;
  p.falloff = -1;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'falloff'"));
  p.falloff = 0;
  p.segment = 1;
  p.width = 3;
  ck_assert_ptr_null(oc_enode_image(&p, &err)); /* seg all zeros */
  ck_assert_ptr_nonnull(strstr(err.msg, "'segment'"));
  p.seg[2] = 5;
  p.width = 0;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'width'"));
  p.heightfield = NULL;
  ck_assert_ptr_null(oc_enode_image(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'heightfield'"));
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(source_of_a_lake_and_image_tree) {
  /* the tree as a terrain source: ranges and slopes from its bounds hold */
  oc_error err;
  oc_heightfield *hf = grid(hill);
  oc_enode_image_params ip = {0};
  ip.heightfield = hf;
  memcpy(ip.quad, QUAD, sizeof QUAD);
  oc_enode *img = EOK(oc_enode_image(&ip, &err));
  double r1 = 40;
  oc_enode_lake_params lp = {0};
  lp.cx = 175, lp.cy = 120, lp.radii = &r1, lp.nradii = 1, lp.level = 20;
  oc_enode *lake = EOK(oc_enode_lake(&lp, &err));
  oc_enode *t = EOK(oc_enode_replace(img, lake, 1, &err));
  oc_elevation src;
  double dom[4] = {90, 50, 260, 190};
  ck_assert_int_eq(oc_enode_elevation(t, dom, &src, &err), OC_OK);
  oct_rng r = oct_rng_new(21);
  for (int i = 0; i < 200; i++) {
    double x0 = oct_unif(&r, 90, 250), y0 = oct_unif(&r, 50, 180);
    double x1 = x0 + oct_unif(&r, 0.1, 20), y1 = y0 + oct_unif(&r, 0.1, 20);
    double lo, hi, sl = src.slope(src.ud, x0, y0, x1, y1);
    src.range(src.ud, x0, y0, x1, y1, &lo, &hi);
    for (int k = 0; k < 20; k++) {
      double g[2],
          h = src.height(src.ud, oct_unif(&r, x0, x1), oct_unif(&r, y0, y1), g);
      ck_assert(h >= lo - 1e-9 && h <= hi + 1e-9);
      ck_assert(hypot(g[0], g[1]) <= sl * (1 + 1e-9));
    }
  }
  src.release(src.ud);
  oc_enode_release(t);
  oc_enode_release(lake);
  oc_enode_release(img);
  oc_heightfield_release(hf);
}
END_TEST

int main(void) {
  Suite *s = suite_create("elevation_prims");
  TCase *tc = tcase_create("elevation_prims");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, lake_default_bed);
  tcase_add_test(tc, lake_contour_sectors);
  tcase_add_test(tc, lake_radii_in_a_blend);
  tcase_add_test(tc, lake_bad_input);
  tcase_add_test(tc, image_quad_formula);
  tcase_add_test(tc, image_segment_and_clamped_weight);
  tcase_add_test(tc, image_bad_input);
  tcase_add_test(tc, image_curve_formula);
  tcase_add_test(tc, image_curve_bad_input);
  tcase_add_test(tc, source_of_a_lake_and_image_tree);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
