/*
** test_profile.c — cross-section profiles (lib/core/profile.h): the
** spline interpolates its knots, is C¹ everywhere (central differences of
** the value against the derivative, on a dense scan that crosses every
** breakpoint), keeps monotone and convex data so, and its ranges and
** slope bounds equal dense sampling; blends of two profiles; bad input.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/profile.h"
#include "ocheck.h"

#define MAXK 16

/* Random profiles per test. A profile holds its knots alone and derives
** its pieces at each evaluation, so the dense scans below cost about 2.5
** times what they did when it kept them: 2/5 of the 300 (or 200) random
** profiles keep the test's time, and a sixth in the sanitizer pass. */
#ifdef __SANITIZE_ADDRESS__
#define TRIALS(n) ((n) / 6)
#else
#define TRIALS(n) ((n)*2 / 5)
#endif

static oc_profile *new_ok(const double *x, const double *v, size_t n) {
  oc_error err = {0};
  oc_profile *p = oc_profile_new(x, v, n, &err);
  ck_assert_msg(p, "oc_profile_new: %s", err.msg);
  return p;
}

/* Random knots: spacing from 0.05 to 20 (wild ratios), values by `kind`:
** 0 any, 1 increasing, 2 convex (increasing secant slopes). */
static size_t random_knots(oct_rng *r, int kind, double *x, double *v) {
  size_t n = 2 + (size_t)oct_unif(r, 0, MAXK - 2);
  double s = oct_unif(r, -3, 3);
  x[0] = oct_unif(r, -50, -10), v[0] = oct_unif(r, -5, 5);
  for (size_t i = 1; i < n; i++) {
    double h = exp(oct_unif(r, log(0.05), log(20)));
    x[i] = x[i - 1] + h;
    if (kind == 0)
      v[i] = oct_unif(r, -10, 10);
    else if (kind == 1)
      v[i] = v[i - 1] +
             h * exp(oct_unif(r, -6, 3)) * (oct_unif(r, 0, 1) < 0.2 ? 0 : 1);
    else {
      s += exp(oct_unif(r, -4, 1));
      v[i] = v[i - 1] + h * s;
    }
  }
  return n;
}

/* Dense scan of [a, b]: the value's central differences against the
** derivative (a slope jump anywhere would show as an error of about half
** the jump), and sampled extremes. */
typedef struct scan {
  double vmin, vmax, smax, fd_err, dmin, dmax_jump;
} scan;

typedef struct lerp_args {
  const oc_profile *p, *q;
  double t;
  int what; /* 0: -v, 1: v, 2: |v'| (all maximised) */
} lerp_args;

static double objective(const lerp_args *g, double x) {
  double dv, v = oc_profile_lerp(g->p, g->q, g->t, x, &dv);
  return g->what == 0 ? -v : g->what == 1 ? v : fabs(dv);
}

/* Golden-section refinement of a sampled maximum on [x - h, x + h] (the
** objectives are unimodal that close to a peak: quadratic pieces, or a
** tent of linear slopes), so the sampled extremes are exact to rounding
** rather than to the sampling step. */
static double refine_max(const lerp_args *g, double x, double h, double lo,
                         double hi) {
  double a = fmax(lo, x - h), b = fmin(hi, x + h), k = 0.6180339887498949;
  double best = objective(g, x);
  for (int it = 0; it < 100; it++) {
    double c1 = b - k * (b - a), c2 = a + k * (b - a);
    if (objective(g, c1) > objective(g, c2))
      b = c2;
    else
      a = c1;
  }
  return fmax(best, objective(g, 0.5 * (a + b)));
}

/* The sampled maximum of an objective, refined around every sampled local
** maximum (a narrow peak may fall between samples of the taller one). */
static double scan_max(const lerp_args *g, double a, double b, int n) {
  double h = (b - a) / n, best = -INFINITY;
  double prev = -INFINITY, cur = objective(g, a);
  for (int i = 0; i <= n; i++) {
    double next = i < n ? objective(g, a + h * (i + 1)) : -INFINITY;
    if (cur > prev && cur >= next)
      best = fmax(best, refine_max(g, a + h * i, h, a, b));
    prev = cur, cur = next;
  }
  return best;
}

static scan scan_profile(const oc_profile *p, const oc_profile *q, double t,
                         double a, double b, int n) {
  scan s = {INFINITY, -INFINITY, 0, 0, INFINITY, 0};
  double h = (b - a) / n, e = h * 1e-3, dprev = NAN;
  for (int i = 0; i <= n; i++) {
    double x = a + h * i, dv;
    oc_profile_lerp(p, q, t, x, &dv);
    double fd = (oc_profile_lerp(p, q, t, x + e, NULL) -
                 oc_profile_lerp(p, q, t, x - e, NULL)) /
                (2 * e);
    s.fd_err = fmax(s.fd_err, fabs(fd - dv) / (1 + fabs(dv)));
    s.dmin = fmin(s.dmin, dv);
    if (i > 0) s.dmax_jump = fmax(s.dmax_jump, dprev - dv); /* decrease */
    dprev = dv;
  }
  lerp_args g0 = {p, q, t, 0}, g1 = {p, q, t, 1}, g2 = {p, q, t, 2};
  s.vmin = -scan_max(&g0, a, b, n);
  s.vmax = scan_max(&g1, a, b, n);
  s.smax = scan_max(&g2, a, b, n);
  return s;
}

START_TEST(interpolates_and_is_c1) {
  oct_rng r = oct_rng_new(3);
  double x[MAXK], v[MAXK];
  double worst_fd = 0;
  for (int trial = 0; trial < TRIALS(300); trial++) {
    size_t n = random_knots(&r, trial % 3, x, v);
    oc_profile *p = new_ok(x, v, n);
    ck_assert(oc_profile_nbreaks(p) <= 2 * n - 1);
    for (size_t i = 0; i < n; i++) /* exactly: a piece starts at each knot */
      ck_assert_msg(oc_profile_eval(p, x[i], NULL) == v[i],
                    "knot %zu: %.17g vs %.17g", i,
                    oc_profile_eval(p, x[i], NULL), v[i]);
    /* C¹: central differences match the derivative on a scan through
    ** every breakpoint, and at the ends the slope goes to 0 */
    scan s = scan_profile(p, p, 0, x[0] - 1, x[n - 1] + 1, 20000);
    worst_fd = fmax(worst_fd, s.fd_err);
    ck_assert_msg(s.fd_err < 1e-4, "trial %d: slope jump %g", trial, s.fd_err);
    double d0, d1;
    oc_profile_eval(p, x[0] + 1e-9 * (x[1] - x[0]), &d0);
    oc_profile_eval(p, x[n - 1] - 1e-9 * (x[n - 1] - x[n - 2]), &d1);
    double big = oc_profile_max_slope(p, x[0], x[n - 1]);
    ck_assert(fabs(d0) <= 1e-6 * (1 + big) && fabs(d1) <= 1e-6 * (1 + big));
    oc_profile_eval(p, x[0] - 3, &d0);
    ck_assert(d0 == 0 && oc_profile_eval(p, x[0] - 3, NULL) == v[0]);
    ck_assert(oc_profile_eval(p, x[n - 1] + 3, NULL) == v[n - 1]);
    oc_profile_free(p);
  }
  printf("profile: worst relative central-difference error %.3g\n", worst_fd);
}
END_TEST

START_TEST(monotone_and_convex_data_keep_their_shape) {
  oct_rng r = oct_rng_new(11);
  double x[MAXK], v[MAXK];
  for (int trial = 0; trial < TRIALS(300); trial++) {
    size_t n = random_knots(&r, 1, x, v);
    oc_profile *p = new_ok(x, v, n);
    scan s = scan_profile(p, p, 0, x[0], x[n - 1], 20000);
    ck_assert_msg(s.dmin >= -1e-12 * (1 + s.smax), "trial %d: slope %g", trial,
                  s.dmin);
    /* extremes are the end knots */
    double lo, hi;
    oc_profile_range(p, x[0] - 1, x[n - 1] + 1, &lo, &hi);
    ck_assert(lo == v[0] && hi == v[n - 1]);
    oc_profile_free(p);
  }
  for (int trial = 0; trial < TRIALS(300); trial++) {
    size_t n = random_knots(&r, 2, x, v);
    if (n < 4) continue;
    oc_profile *p = new_ok(x, v, n);
    /* convex on the interior intervals: the slope never decreases */
    scan s = scan_profile(p, p, 0, x[1], x[n - 2], 20000);
    ck_assert_msg(s.dmax_jump <= 1e-9 * (1 + s.smax),
                  "trial %d: slope decreases by %g", trial, s.dmax_jump);
    oc_profile_free(p);
  }
  /* a valley (river bed) does not overshoot below its lowest knot */
  double vx[] = {-30, -12, -4, 0, 4, 12, 30};
  double vv[] = {0, -0.5, -3, -3.2, -3, -0.5, 0};
  oc_profile *p = new_ok(vx, vv, 7);
  double lo, hi;
  oc_profile_range(p, -100, 100, &lo, &hi);
  ck_assert(lo == -3.2 && hi == 0);
  oc_profile_free(p);
}
END_TEST

START_TEST(ranges_and_slopes_are_exact) {
  oct_rng r = oct_rng_new(21);
  double x[MAXK], v[MAXK];
  for (int trial = 0; trial < TRIALS(300); trial++) {
    size_t n = random_knots(&r, 0, x, v);
    oc_profile *p = new_ok(x, v, n);
    double a = oct_unif(&r, x[0] - 5, x[n - 1] + 5);
    double b = oct_unif(&r, x[0] - 5, x[n - 1] + 5);
    if (a > b) {
      double t = a;
      a = b, b = t;
    }
    double lo, hi, sl = oc_profile_max_slope(p, a, b);
    oc_profile_range(p, a, b, &lo, &hi);
    scan s = scan_profile(p, p, 0, a, b, 40000);
    double tol = 1e-9 * (1 + fabs(s.vmax) + fabs(s.vmin));
    ck_assert(lo <= s.vmin + 1e-12 * (1 + fabs(lo)) &&
              hi >= s.vmax - 1e-12 * (1 + fabs(hi)));
    ck_assert_msg(s.vmin - lo < tol && hi - s.vmax < tol,
                  "range [%g, %g] vs sampled [%g, %g]", lo, hi, s.vmin, s.vmax);
    ck_assert(sl >= s.smax * (1 - 1e-12));
    ck_assert_msg(sl - s.smax <= 1e-9 * (1 + sl), "slope %g vs sampled %g", sl,
                  s.smax);
    oc_profile_free(p);
  }
}
END_TEST

START_TEST(support_and_half_width) {
  double x[] = {-30, -20, -5, 0, 5, 12, 40};
  double v[] = {0, 0, -3, -4, -3, 0, 0};
  oc_profile *p = new_ok(x, v, 7);
  double lo, hi;
  oc_profile_support(p, &lo, &hi);
  ck_assert(lo == -20 && hi == 12);
  ck_assert(oc_profile_half_width(p) == 20);
  /* constant beyond the support, exactly */
  for (double t = -40; t <= -20; t += 0.5)
    ck_assert(oc_profile_eval(p, t, NULL) == 0);
  for (double t = 12; t <= 50; t += 0.5)
    ck_assert(oc_profile_eval(p, t, NULL) == 0);
  ck_assert(oc_profile_eval(p, -19.9, NULL) < 0);
  oc_profile_free(p);
  double cv[] = {2, 2, 2};
  p = new_ok(x, cv, 3);
  ck_assert(oc_profile_half_width(p) == 0);
  ck_assert(oc_profile_max_slope(p, -100, 100) == 0);
  oc_profile_free(p);
}
END_TEST

START_TEST(blend_of_two_profiles) {
  oct_rng r = oct_rng_new(41);
  double xa[MAXK], va[MAXK], xb[MAXK], vb[MAXK];
  for (int trial = 0; trial < TRIALS(200); trial++) {
    size_t na = random_knots(&r, 0, xa, va), nb = random_knots(&r, 0, xb, vb);
    oc_profile *a = new_ok(xa, va, na), *b = new_ok(xb, vb, nb);
    double t = oct_unif(&r, 0, 1), x = oct_unif(&r, -60, 60);
    double da, db, dl;
    double fa = oc_profile_eval(a, x, &da), fb = oc_profile_eval(b, x, &db);
    double fl = oc_profile_lerp(a, b, t, x, &dl);
    ck_assert(fabs(fl - ((1 - t) * fa + t * fb)) < 1e-12 * (1 + fabs(fl)));
    ck_assert(fabs(dl - ((1 - t) * da + t * db)) < 1e-12 * (1 + fabs(dl)));
    double lo, hi, sl;
    double x0 = fmin(xa[0], xb[0]) - 2, x1 = fmax(xa[na - 1], xb[nb - 1]) + 2;
    oc_profile_lerp_range(a, b, t, x0, x1, &lo, &hi);
    sl = oc_profile_lerp_max_slope(a, b, t, x0, x1);
    scan s = scan_profile(a, b, t, x0, x1, 40000);
    double tol = 1e-9 * (1 + fabs(s.vmax) + fabs(s.vmin));
    ck_assert(s.fd_err < 1e-4); /* the blend is C¹ too */
    ck_assert(lo <= s.vmin + 1e-12 * (1 + fabs(lo)) &&
              hi >= s.vmax - 1e-12 * (1 + fabs(hi)));
    ck_assert(s.vmin - lo < tol && hi - s.vmax < tol);
    ck_assert_msg(sl >= s.smax * (1 - 1e-12) && sl - s.smax <= 1e-9 * (1 + sl),
                  "slope %.15g vs sampled %.15g", sl, s.smax);
    oc_profile_free(a);
    oc_profile_free(b);
  }
}
END_TEST

START_TEST(bad_input_is_refused) {
  oc_error err = {0};
  double x[] = {0, 1, 2, 3}, v[] = {0, 1, 0, 1};
  ck_assert(!oc_profile_new(x, v, 1, &err));
  ck_assert_int_eq(err.code, OC_EINVAL);
  ck_assert_msg(strstr(err.msg, "'knots'") && strstr(err.msg, "at least 2"),
                "%s", err.msg);
  double xn[] = {0, NAN, 2}, vn[] = {0, 1, INFINITY};
  ck_assert(!oc_profile_new(xn, v, 3, &err));
  ck_assert_msg(strstr(err.msg, "knot 1") && strstr(err.msg, "not finite"),
                "%s", err.msg);
  ck_assert(!oc_profile_new(x, vn, 3, &err));
  ck_assert_msg(strstr(err.msg, "knot 2"), "%s", err.msg);
  double xd[] = {0, 1, 1, 3};
  ck_assert(!oc_profile_new(xd, v, 4, &err));
  ck_assert_msg(strstr(err.msg, "knot 2 must lie after knot 1"), "%s", err.msg);
  double xr[] = {0, 2, 1, 3};
  ck_assert(!oc_profile_new(xr, v, 4, &err));
  ck_assert_msg(strstr(err.msg, "knot 2"), "%s", err.msg);
  double xo[] = {0, 1e-300}, vo[] = {0, 1e300};
  ck_assert(!oc_profile_new(xo, vo, 2, &err));
  ck_assert_msg(strstr(err.msg, "overflows"), "%s", err.msg);
  /* NaN queries answer NaN, no crash */
  oc_profile *p = new_ok(x, v, 4);
  ck_assert(isnan(oc_profile_eval(p, NAN, NULL)));
  oc_profile_free(p);
}
END_TEST

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("profile");
  TCase *tc = tcase_create("profile");
  tcase_set_timeout(tc, 300);
  tcase_add_test(tc, interpolates_and_is_c1);
  tcase_add_test(tc, monotone_and_convex_data_keep_their_shape);
  tcase_add_test(tc, ranges_and_slopes_are_exact);
  tcase_add_test(tc, support_and_half_width);
  tcase_add_test(tc, blend_of_two_profiles);
  tcase_add_test(tc, bad_input_is_refused);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
