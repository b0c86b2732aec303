/*
** test_noise.c — simplex noise and turbulence (lib/core/noise.c).
**
** Besides the behavioural checks (range, gradient against differences,
** Lipschitz on pairs, determinism, seeds, mean, continuity, huge inputs),
** this file holds the computer-assisted proof of the two constants noise.c
** is scaled by: an interval branch-and-bound over the reference simplex for
** all 12^4 gradient assignments. A reference evaluator, fed with gradients
** read off the implementation at lattice points, ties that proof to the
** code: it checks that oc_noise3 computes exactly the analysed sum.
*/
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/noise.h"
#include "core/rng.h"
#include "core/vec.h"

/* The constants the proof establishes; noise.c must scale by them. */
#define CERT_RAW_MAX 0.013008
#define CERT_RAW_GRAD_MAX 0.0908
/* ... and the bound of the Hessian on coordinate planes it states. */
#define CERT_RAW_HESS_MAX 0.64
/* A point of the reference simplex (skewed) where some assignment reaches
** 0.62360, and the share of the bound that is. */
#define WIT_HESS 0.97984, 0.97070, 0.66960
#define WIT_HESS_SHARE 0.97

static oc_vec3 rand_point(oc_rng *r, double half) {
  return oc_v3(oc_rng_range(r, -half, half), oc_rng_range(r, -half, half),
               oc_rng_range(r, -half, half));
}

static oc_vec3 rand_dir(oc_rng *r) {
  for (;;) {
    oc_vec3 d = rand_point(r, 1);
    double l = oc_len(d);
    if (l > 0.1 && l <= 1) return oc_mul(d, 1 / l);
  }
}

typedef double (*field_fn)(uint64_t seed, int oct, oc_vec3 p, oc_vec3 *g);

static double f_noise(uint64_t seed, int oct, oc_vec3 p, oc_vec3 *g) {
  (void)oct;
  return oc_noise3(seed, p, g);
}
static double f_turb(uint64_t seed, int oct, oc_vec3 p, oc_vec3 *g) {
  return oc_turb3(seed, oct, p, g);
}

/* Gradient by central differences; the step actually taken is measured so
** that rounding of p +- h does not bias the quotient. */
static oc_vec3 central_diff(field_fn f, uint64_t seed, int oct, oc_vec3 p,
                            double h) {
  double c[3];
  for (int a = 0; a < 3; a++) {
    oc_vec3 lo = p, hi = p;
    double *pl = a == 0 ? &lo.x : a == 1 ? &lo.y : &lo.z;
    double *ph = a == 0 ? &hi.x : a == 1 ? &hi.y : &hi.z;
    *pl -= h, *ph += h;
    c[a] = (f(seed, oct, hi, NULL) - f(seed, oct, lo, NULL)) / (*ph - *pl);
  }
  return oc_v3(c[0], c[1], c[2]);
}

/* ---- range, mean, gradient ------------------------------------------- */

START_TEST(noise_in_unit_interval) {
  oc_rng r = oc_rng_stream(1, 1);
  double lo = 1, hi = 0;
  int bad = 0;
  for (int i = 0; i < 1000000; i++) {
    const double scale[4] = {1, 20, 1e3, 1e6};
    double v =
        oc_noise3((uint64_t)(i % 97), rand_point(&r, scale[i & 3]), NULL);
    bad += !(v >= 0 && v <= 1);
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  printf("noise: range over 1e6 points [%.6f, %.6f]\n", lo, hi);
  ck_assert_int_eq(bad, 0);
  /* The scale is tight: the range is actually used. */
  ck_assert(lo < 0.01 && hi > 0.99);
}
END_TEST

START_TEST(noise_mean_is_half) {
  oc_rng r = oc_rng_stream(2, 2);
  double s = 0, s2 = 0;
  const int n = 1000000;
  for (int i = 0; i < n; i++) {
    double v = oc_noise3(77, rand_point(&r, 5000), NULL);
    s += v, s2 += v * v;
  }
  double mean = s / n, sd = sqrt(s2 / n - mean * mean);
  printf("noise: mean %.5f, standard deviation %.5f\n", mean, sd);
  /* Points this far apart are independent: standard error sd/1000. */
  ck_assert_double_eq_tol(mean, 0.5, 0.002);
  ck_assert(sd > 0.05 && sd < 0.3);
}
END_TEST

START_TEST(noise_gradient_matches_differences) {
  oc_rng r = oc_rng_stream(3, 3);
  double worst = 0;
  for (int i = 0; i < 100000; i++) {
    oc_vec3 p = rand_point(&r, 50), g;
    oc_noise3(5, p, &g);
    oc_vec3 fd = central_diff(f_noise, 5, 0, p, 1e-6);
    double err = oc_len(oc_sub(fd, g)) / (1 + oc_len(g));
    if (err > worst) worst = err;
  }
  printf("noise: worst gradient error vs differences %.2e\n", worst);
  ck_assert(worst < 1e-6);
}
END_TEST

/* ---- Lipschitz ------------------------------------------------------- */

START_TEST(noise_gradient_below_bound) {
  oc_rng r = oc_rng_stream(4, 4);
  const double L = oc_noise3_lipschitz;
  double best = 0;
  oc_vec3 best_p = {0, 0, 0};
  for (int i = 0; i < 1000000; i++) {
    oc_vec3 p = rand_point(&r, 100), g;
    oc_noise3(11, p, &g);
    double m = oc_len(g);
    if (m > best) best = m, best_p = p;
  }
  /* Climb from the best sample to see how close the bound is. */
  double climbed = best, step = 0.02;
  oc_vec3 q = best_p;
  for (int it = 0; it < 20000; it++) {
    oc_vec3 t = oc_add(q, oc_mul(rand_dir(&r), step)), g;
    oc_noise3(11, t, &g);
    if (oc_len(g) > climbed) climbed = oc_len(g), q = t;
    if (it % 2000 == 1999) step *= 0.5;
  }
  printf("noise: Lipschitz bound %.6f; max |grad| over 1e6 random points "
         "%.6f (%.2f %%), after a local climb %.6f (%.2f %%)\n",
         L, best, 100 * best / L, climbed, 100 * climbed / L);
  ck_assert(best <= L && climbed <= L);
  /* The bound is tight, not merely valid. */
  ck_assert(climbed > 0.98 * L);
}
END_TEST

START_TEST(noise_lipschitz_on_pairs) {
  oc_rng r = oc_rng_stream(5, 5);
  const double L = oc_noise3_lipschitz;
  double worst = 0;
  int bad = 0;
  for (int i = 0; i < 1000000; i++) {
    oc_vec3 p = rand_point(&r, 100);
    double dist = pow(10, oc_rng_range(&r, -9, 1));
    oc_vec3 q = oc_add(p, oc_mul(rand_dir(&r), dist));
    double d = oc_len(oc_sub(q, p));
    double dv = fabs(oc_noise3(9, p, NULL) - oc_noise3(9, q, NULL));
    /* 1e-15: rounding of two values near 1/2. */
    bad += dv > L * d + 1e-15;
    if (d > 1e-6 && dv / d > worst) worst = dv / d;
  }
  /* Pairs along the steepest direction, the hardest case. */
  for (int i = 0; i < 100000; i++) {
    oc_vec3 p = rand_point(&r, 100), g;
    oc_noise3(9, p, &g);
    if (oc_len(g) < 0.9 * L) continue;
    double dist = pow(10, oc_rng_range(&r, -9, -3));
    oc_vec3 q = oc_add(p, oc_mul(g, dist / oc_len(g)));
    double d = oc_len(oc_sub(q, p));
    double dv = fabs(oc_noise3(9, p, NULL) - oc_noise3(9, q, NULL));
    bad += dv > L * d + 1e-15;
    if (d > 1e-6 && dv / d > worst) worst = dv / d;
  }
  printf("noise: steepest slope seen on pairs %.6f <= %.6f\n", worst, L);
  ck_assert_int_eq(bad, 0);
  ck_assert(worst > 0.9 * L);
}
END_TEST

/* ---- determinism and seeds ------------------------------------------- */

START_TEST(noise_is_deterministic) {
  enum { N = 20000 };
  static oc_vec3 pts[N];
  static double v1[N], v2[N];
  static oc_vec3 g1[N], g2[N];
  oc_rng r = oc_rng_stream(6, 6);
  for (int i = 0; i < N; i++) {
    pts[i] = rand_point(&r, 1e4);
    v1[i] = oc_noise3(123, pts[i], &g1[i]);
  }
  /* The same points evaluated in parallel, in another order. */
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = N - 1; i >= 0; i--) {
    v2[i] = oc_noise3(123, pts[i], &g2[i]);
  }
  ck_assert(memcmp(v1, v2, sizeof v1) == 0);
  ck_assert(memcmp(g1, g2, sizeof g1) == 0);
  /* Asking for the gradient does not change the value. */
  int differ = 0;
  for (int i = 0; i < N; i++) {
    double v = oc_noise3(123, pts[i], NULL);
    differ += memcmp(&v, &v1[i], sizeof v) != 0;
    double t1 = oc_turb3(123, 5, pts[i], NULL),
           t2 = oc_turb3(123, 5, pts[i], NULL);
    oc_vec3 tg;
    double t3 = oc_turb3(123, 5, pts[i], &tg);
    differ +=
        memcmp(&t1, &t2, sizeof t1) != 0 || memcmp(&t1, &t3, sizeof t1) != 0;
  }
  ck_assert_int_eq(differ, 0);
}
END_TEST

static double noise_corr(uint64_t s1, uint64_t s2, double scale) {
  oc_rng r = oc_rng_stream(s1 ^ 0x55, s2);
  double a = 0, b = 0, aa = 0, bb = 0, ab = 0;
  const int n = 200000;
  for (int i = 0; i < n; i++) {
    oc_vec3 p = rand_point(&r, scale);
    double x = oc_noise3(s1, p, NULL), y = oc_noise3(s2, p, NULL);
    a += x, b += y, aa += x * x, bb += y * y, ab += x * y;
  }
  a /= n, b /= n;
  return (ab / n - a * b) / sqrt((aa / n - a * a) * (bb / n - b * b));
}

START_TEST(seeds_are_decorrelated) {
  const uint64_t pairs[][2] = {{0, 1},
                               {1, 2},
                               {0, 1ull << 32},
                               {0, 1ull << 63},
                               {7, 7 ^ 0xd1b54a32d192ed03ull},
                               {12, 13}};
  for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
    double c = noise_corr(pairs[k][0], pairs[k][1], 300);
    printf("noise: correlation of seeds %llu and %llu: %+.4f\n",
           (unsigned long long)pairs[k][0], (unsigned long long)pairs[k][1], c);
    /* sd of the estimate: 1/sqrt(2e5) = 0.0022. */
    ck_assert(fabs(c) < 0.015);
  }
  /* Same seed: correlation 1 (the estimator works). */
  ck_assert(noise_corr(3, 3, 300) > 0.999999);
  /* Neighbouring points are strongly correlated (it is a smooth noise, not
  ** white noise), so the near-zero figures above are meaningful. */
  oc_rng r = oc_rng_stream(8, 8);
  double a = 0, b = 0, aa = 0, bb = 0, ab = 0;
  const int n = 100000;
  for (int i = 0; i < n; i++) {
    oc_vec3 p = rand_point(&r, 300);
    double x = oc_noise3(4, p, NULL);
    double y = oc_noise3(4, oc_add(p, oc_mul(rand_dir(&r), 0.1)), NULL);
    a += x, b += y, aa += x * x, bb += y * y, ab += x * y;
  }
  a /= n, b /= n;
  double near = (ab / n - a * b) / sqrt((aa / n - a * a) * (bb / n - b * b));
  printf("noise: correlation at distance 0.1: %.3f\n", near);
  ck_assert(near > 0.8);
}
END_TEST

/* ---- continuity across simplex boundaries --------------------------- */

/* Moves p onto a boundary plane of its simplex, returns the plane normal.
** Inside a cube the planes are x = y, y = z, x = z (skewing adds the same
** to all coordinates); cube faces are x + (x+y+z)/3 = integer, whose normal
** is S e_x = (4/3, 1/3, 1/3). */
static oc_vec3 onto_boundary(oc_vec3 *p, int kind) {
  switch (kind) {
  case 0: {
    double m = 0.5 * (p->x + p->y);
    p->x = p->y = m;
    return oc_mul(oc_v3(1, -1, 0), 1 / sqrt(2.0));
  }
  case 1: {
    double m = 0.5 * (p->y + p->z);
    p->y = p->z = m;
    return oc_mul(oc_v3(0, 1, -1), 1 / sqrt(2.0));
  }
  case 2: {
    double m = 0.5 * (p->x + p->z);
    p->x = p->z = m;
    return oc_mul(oc_v3(1, 0, -1), 1 / sqrt(2.0));
  }
  default: {
    double xs = p->x + (p->x + p->y + p->z) / 3;
    p->x += (round(xs) - xs) * 0.75; /* d(xs)/dx = 4/3 */
    return oc_mul(oc_v3(4, 1, 1), 1 / sqrt(18.0));
  }
  }
}

START_TEST(noise_continuous_across_boundaries) {
  oc_rng r = oc_rng_stream(9, 9);
  double worst_v = 0, worst_g = 0;
  for (int i = 0; i < 200000; i++) {
    oc_vec3 p = rand_point(&r, 20);
    oc_vec3 nrm = onto_boundary(&p, i & 3);
    oc_vec3 a = oc_add(p, oc_mul(nrm, 5e-10)),
            b = oc_sub(p, oc_mul(nrm, 5e-10));
    oc_vec3 ga, gb;
    double dv = fabs(oc_noise3(21, a, &ga) - oc_noise3(21, b, &gb));
    double dg = oc_len(oc_sub(ga, gb));
    if (dv > worst_v) worst_v = dv;
    if (dg > worst_g) worst_g = dg;
  }
  printf("noise: across boundaries 1e-9 apart: |dn| <= %.2e, |dgrad| <= %.2e\n",
         worst_v, worst_g);
  /* L * 1e-9 = 3.5e-9 bounds dn; a kernel reaching past its star (r0^2 =
  ** 0.6) jumps by 8e-3 in value and 0.4 in gradient here. The gradient is
  ** continuous too. */
  ck_assert(worst_v < 4e-9);
  ck_assert(worst_g < 1e-6);
}
END_TEST

/* ---- the reference evaluator ---------------------------------------- */

static const double GR[12][3] = {
    {1, 1, 0},  {-1, -1, 0}, {1, -1, 0}, {-1, 1, 0},  {1, 0, 1},  {-1, 0, -1},
    {1, 0, -1}, {-1, 0, 1},  {0, 1, 1},  {0, -1, -1}, {0, 1, -1}, {0, -1, 1}};

static oc_vec3 lattice_point(int64_t i, int64_t j, int64_t k) {
  double t = (double)(i + j + k) / 6;
  return oc_v3((double)i - t, (double)j - t, (double)k - t);
}

/* The gradient vector the implementation gave the lattice point (i, j, k),
** read off grad n there: the point's own kernel gives scale * g / 16 and
** every other lattice point is at least sqrt(3)/2 > sqrt(1/2) away.
** Returns the index in GR, or -1; *scale receives |grad| * 16 / sqrt 2. */
static int read_gradient(uint64_t seed, int64_t i, int64_t j, int64_t k,
                         double *scale) {
  oc_vec3 g;
  double v = oc_noise3(seed, lattice_point(i, j, k), &g);
  if (fabs(v - 0.5) > 1e-12) return -1;
  double m = oc_len(g);
  *scale = m * 16 / sqrt(2.0);
  oc_vec3 u = oc_mul(g, sqrt(2.0) / m);
  for (int q = 0; q < 12; q++)
    if (oc_len(oc_sub(u, oc_v3(GR[q][0], GR[q][1], GR[q][2]))) < 1e-9) return q;
  return -1;
}

/* n by brute force: every lattice point within reach, not just the four of
** p's simplex, with w(s) = (1/2 - s)^4. */
static double reference_noise(uint64_t seed, double scale, oc_vec3 p,
                              oc_vec3 *grad, int *bad) {
  double s = (p.x + p.y + p.z) / 3;
  int64_t bi = (int64_t)floor(p.x + s), bj = (int64_t)floor(p.y + s),
          bk = (int64_t)floor(p.z + s);
  double v = 0;
  oc_vec3 g = {0, 0, 0};
  /* |unskew(x)| >= |x| / 2, so points within sqrt(1/2) lie within
  ** sqrt 2 < 2 of p in skewed space: offsets -1..2 around the cell. */
  for (int64_t a = bi - 1; a <= bi + 2; a++)
    for (int64_t b = bj - 1; b <= bj + 2; b++)
      for (int64_t c = bk - 1; c <= bk + 2; c++) {
        oc_vec3 d = oc_sub(p, lattice_point(a, b, c));
        double w = 0.5 - oc_dot(d, d);
        if (w <= 0) continue;
        double sc;
        int q = read_gradient(seed, a, b, c, &sc);
        if (q < 0 || fabs(sc - scale) > 1e-9 * scale) {
          (*bad)++;
          continue;
        }
        oc_vec3 gv = oc_v3(GR[q][0], GR[q][1], GR[q][2]);
        double t = oc_dot(gv, d);
        v += w * w * w * w * t;
        g = oc_add(g,
                   oc_mul(oc_sub(oc_mul(gv, w), oc_mul(d, 8 * t)), w * w * w));
      }
  if (grad) *grad = oc_mul(g, scale);
  return 0.5 + scale * v;
}

/* The implementation's scale, read at the origin. */
static double implementation_scale(void) {
  double scale = 0;
  ck_assert_int_ge(read_gradient(1, 0, 0, 0, &scale), 0);
  return scale;
}

START_TEST(noise_matches_reference) {
  double scale = implementation_scale();
  printf("noise: implementation scale %.6f = 1 / (2 * %.8f)\n", scale,
         0.5 / scale);
  oc_rng r = oc_rng_stream(10, 10);
  int bad = 0, used[12] = {0};
  double worst_v = 0, worst_g = 0;
  for (int i = 0; i < 20000; i++) {
    uint64_t seed = (uint64_t)(i % 5);
    oc_vec3 p = rand_point(&r, 40), g, gr;
    double v = oc_noise3(seed, p, &g);
    double vr = reference_noise(seed, scale, p, &gr, &bad);
    if (fabs(v - vr) > worst_v) worst_v = fabs(v - vr);
    if (oc_len(oc_sub(g, gr)) > worst_g) worst_g = oc_len(oc_sub(g, gr));
  }
  for (int i = 0; i < 12000; i++) {
    double sc;
    int q = read_gradient(2, i % 23 - 11, i / 23 % 23 - 11, i / 529 - 11, &sc);
    if (q >= 0)
      used[q]++;
    else
      bad++;
  }
  printf("noise: implementation vs brute-force reference: |dn| <= %.2e, "
         "|dgrad| <= %.2e\n",
         worst_v, worst_g);
  ck_assert_int_eq(bad, 0);
  ck_assert(worst_v < 1e-13 && worst_g < 1e-11);
  /* All 12 gradients occur, about equally (1000 expected each). */
  for (int q = 0; q < 12; q++)
    ck_assert(used[q] > 850 && used[q] < 1150);
}
END_TEST

/* ---- the proof of the scale and of the Lipschitz constant ------------- */

/* Interval arithmetic, round-to-nearest. Every certified bound is compared
** with a margin of 1e-12; the quantities are below 1 and come out of fewer
** than 100 operations, so rounding moves them by less than 1e-13. */
typedef struct {
  double lo, hi;
} iv;

static iv iv_c(double a) {
  return (iv){a, a};
}
static iv iv_add(iv a, iv b) {
  return (iv){a.lo + b.lo, a.hi + b.hi};
}
static iv iv_scale(iv a, double k) {
  return k >= 0 ? (iv){a.lo * k, a.hi * k} : (iv){a.hi * k, a.lo * k};
}
/* min and max by comparison: fmin and fmax are calls in this build, and
** the proof spends its time here. */
static double dmin(double a, double b) {
  return a < b ? a : b;
}
static double dmax(double a, double b) {
  return a > b ? a : b;
}
static iv iv_mul(iv a, iv b) {
  double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
  return (iv){dmin(dmin(p0, p1), dmin(p2, p3)),
              dmax(dmax(p0, p1), dmax(p2, p3))};
}
static iv iv_sq(iv a) {
  double l = fabs(a.lo), h = fabs(a.hi);
  double lo = a.lo <= 0 && a.hi >= 0 ? 0 : dmin(l, h), hi = dmax(l, h);
  return (iv){lo * lo, hi * hi};
}
static iv iv_meet(iv a, iv b) {
  return (iv){dmax(a.lo, b.lo), dmin(a.hi, b.hi)};
}

#define MARGIN 1e-12

/* The reference simplex {1 >= x >= y >= z >= 0} (skewed), unskewed. */
static double SV[4][3];

static void init_simplex(void) {
  const int c[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
  for (int i = 0; i < 4; i++) {
    oc_vec3 v = lattice_point(c[i][0], c[i][1], c[i][2]);
    SV[i][0] = v.x, SV[i][1] = v.y, SV[i][2] = v.z;
  }
}

/* One corner's bounds over all directions (|g| = sqrt 2) as functions of
** s = r^2: value sqrt2 (1/2-s)^4 r, gradient sqrt2 (1/2-s)^3 max(1/2-s,
** |1/2-9s|); see noise.c. Their maxima over an interval of s: value peaks
** at s = 1/18; the gradient falls on [0, 0.1], rises to s = 1/6, falls. */
static double one_value(double s) {
  if (s >= 0.5) return 0;
  double a = 0.5 - s;
  return sqrt(2.0) * a * a * a * a * sqrt(dmax(s, 0));
}
static double one_grad(double s) {
  if (s >= 0.5) return 0;
  double a = 0.5 - s;
  return sqrt(2.0) * a * a * a * dmax(a, fabs(0.5 - 9 * s));
}
/* The Hessian H = -8 a^3 (g d^T + d g^T + t I) + 48 a^2 t d d^T of one
** corner's term (t = g.d): its operator norm is at most 8 a^3 (2 sqrt2 r +
** sqrt2 r) + 48 a^2 sqrt2 r^3 = sqrt2 a^2 r (12 + 24 s). Unimodal in s (its
** log's derivative -2/a + 1/(2s) + 1/(1/2 + s) decreases), peak by
** bisection. */
static double one_hess(double s) {
  if (s >= 0.5) return 0;
  double a = 0.5 - s;
  return sqrt(2.0) * a * a * sqrt(dmax(s, 0)) * (12 + 24 * s);
}
static double hess_peak(void) {
  double lo = 0.01, hi = 0.4;
  for (int k = 0; k < 200; k++) {
    double m = 0.5 * (lo + hi);
    if (-2 / (0.5 - m) + 0.5 / m + 1 / (0.5 + m) > 0)
      lo = m;
    else
      hi = m;
  }
  return lo;
}
static double one_max(int mode, double slo, double shi) {
  double (*f)(double) = mode == 2 ? one_hess : mode ? one_grad : one_value;
  double peak = mode == 2 ? hess_peak() : mode ? 1.0 / 6 : 1.0 / 18;
  double m = dmax(f(slo), f(shi));
  if (slo < peak && shi > peak) m = dmax(m, f(peak));
  return m;
}

/* Enclosures of every corner term over a box, for each of the 12
** gradients: mode 0 the value (one component), mode 1 the gradient, mode 2
** the Hessian (its entries 00, 11, 22, 01, 02, 12). */
typedef struct {
  iv c[6];
} ivec;

static const int HR[6] = {0, 1, 2, 0, 0, 1}, HC[6] = {0, 1, 2, 1, 2, 2};

static iv iv_dd(const iv *D, int r, int c) {
  return r == c ? iv_sq(D[r]) : iv_mul(D[r], D[c]);
}

typedef struct {
  int n;           /* corners within reach of the box */
  int corner[4];   /* which ones, in increasing order */
  ivec w[4][12];   /* their terms per gradient */
  double bound[4]; /* one_max: their norm for any gradient */
} enclosure;

static void enclose(int mode, const double lo[3], const double hi[3],
                    enclosure *e) {
  iv X = {lo[0], hi[0]}, Y = {lo[1], hi[1]}, Z = {lo[2], hi[2]};
  /* unskew: u = x - (x+y+z)/6, per component exactly linear */
  iv U[3] = {
      iv_scale(iv_add(iv_scale(X, 5), iv_scale(iv_add(Y, Z), -1)), 1.0 / 6),
      iv_scale(iv_add(iv_scale(Y, 5), iv_scale(iv_add(X, Z), -1)), 1.0 / 6),
      iv_scale(iv_add(iv_scale(Z, 5), iv_scale(iv_add(X, Y), -1)), 1.0 / 6)};
  e->n = 0;
  for (int i = 0; i < 4; i++) {
    iv D[3], s = {0, 0}, R[3];
    double dc[3];
    for (int c = 0; c < 3; c++) {
      D[c] = iv_add(U[c], iv_c(-SV[i][c]));
      s = iv_add(s, iv_sq(D[c]));
      dc[c] = 0.5 * (D[c].lo + D[c].hi);
      R[c] = (iv){D[c].lo - dc[c], D[c].hi - dc[c]};
    }
    if (s.lo >= 0.5) continue;
    double shi = dmin(s.hi, 0.5);
    iv a = {0.5 - shi, 0.5 - s.lo};
    iv a2 = iv_mul(a, a), a3 = iv_mul(a2, a), a4 = iv_mul(a2, a2);
    double sc = dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2];
    double ac = dmax(0.5 - sc, 0);
    int n = e->n++;
    e->corner[n] = i;
    e->bound[n] = one_max(mode, s.lo, shi);
    for (int q = 0; q < 12; q++) {
      const double *g = GR[q];
      iv t = iv_c(0);
      for (int c = 0; c < 3; c++)
        t = iv_add(t, iv_scale(D[c], g[c]));
      double tc = g[0] * dc[0] + g[1] * dc[1] + g[2] * dc[2];
      iv k8 = iv_scale(iv_mul(a3, t), -8);
      /* h(D) = a^3 (a g - 8 t d): the value's gradient, the gradient term */
      iv h[3];
      for (int c = 0; c < 3; c++)
        h[c] = iv_add(iv_scale(a4, g[c]), iv_mul(k8, D[c]));
      /* Centred forms (mean value theorem on the hull of D), met with the
      ** direct enclosures: f(D) in f(dc) + f'(D) (D - dc). */
      for (int c = 3; c < 6; c++)
        e->w[n][q].c[c] = iv_c(0);
      if (mode == 0) {
        iv acc = iv_c(ac * ac * ac * ac * tc);
        for (int c = 0; c < 3; c++)
          acc = iv_add(acc, iv_mul(h[c], R[c]));
        e->w[n][q].c[0] = iv_meet(acc, iv_mul(a4, t));
        e->w[n][q].c[1] = e->w[n][q].c[2] = iv_c(0);
      } else if (mode == 2) {
        /* H = A M + B d d^T with A = -8 a^3, M = g d^T + d g^T + t I,
        ** B = 48 a^2 t; its derivative along d_k (a' = -2 d_k, t' = g_k):
        ** 48 a^2 d_k M + A M'_k + (48 a^2 g_k - 192 a t d_k) d d^T
        ** + B (e_k d^T + d e_k^T); the centred form as above. */
        iv A = iv_scale(a3, -8), B = iv_scale(iv_mul(a2, t), 48);
        iv a48 = iv_scale(a2, 48), at192 = iv_scale(iv_mul(a, t), 192);
        double Ac = -8 * ac * ac * ac, Bc = 48 * ac * ac * tc;
        for (int m = 0; m < 6; m++) {
          int r = HR[m], c = HC[m];
          iv M = iv_add(iv_scale(D[c], g[r]), iv_scale(D[r], g[c]));
          if (r == c) M = iv_add(M, t);
          iv DD = iv_dd(D, r, c);
          iv direct = iv_add(iv_mul(A, M), iv_mul(B, DD));
          double Mc = g[r] * dc[c] + dc[r] * g[c] + (r == c ? tc : 0);
          iv acc = iv_c(Ac * Mc + Bc * dc[r] * dc[c]);
          for (int k = 0; k < 3; k++) {
            double dM =
                (c == k ? g[r] : 0) + (r == k ? g[c] : 0) + (r == c ? g[k] : 0);
            iv Tk = iv_add(iv_mul(iv_mul(a48, D[k]), M), iv_scale(A, dM));
            iv coef =
                iv_add(iv_scale(a48, g[k]), iv_scale(iv_mul(at192, D[k]), -1));
            Tk = iv_add(Tk, iv_mul(coef, DD));
            iv ed = iv_c(0);
            if (r == k) ed = iv_add(ed, D[c]);
            if (c == k) ed = iv_add(ed, D[r]);
            Tk = iv_add(Tk, iv_mul(B, ed));
            acc = iv_add(acc, iv_mul(Tk, R[k]));
          }
          e->w[n][q].c[m] = iv_meet(acc, direct);
        }
      } else {
        /* Jacobian of h: -8 a^3 (g d^T + d g^T + t I) + 48 a^2 t d d^T. */
        iv m8a3 = iv_scale(a3, -8), k48 = iv_scale(iv_mul(a2, t), 48);
        for (int row = 0; row < 3; row++) {
          iv acc = iv_c(ac * ac * ac * (ac * g[row] - 8 * tc * dc[row]));
          for (int c = 0; c < 3; c++) {
            iv m = iv_add(iv_scale(D[c], g[row]), iv_scale(D[row], g[c]));
            if (row == c) m = iv_add(m, t);
            iv j = iv_add(iv_mul(m8a3, m), iv_mul(k48, iv_mul(D[row], D[c])));
            acc = iv_add(acc, iv_mul(j, R[c]));
          }
          e->w[n][q].c[row] = iv_meet(acc, h[row]);
        }
      }
    }
  }
}

static double iv_abs(iv a) {
  return dmax(fabs(a.lo), fabs(a.hi));
}

/* The norm the proofs bound: Euclidean for modes 0 and 1; for the Hessian
** (mode 2), the largest operator norm of its three principal 2 x 2 blocks,
** |a + c| / 2 + sqrt(((a - c) / 2)^2 + b^2) for the block (a b; b c).
** Each simplex is the reference one moved by a lattice translation and an
** axis permutation, so the Hessian of n on any coordinate plane is such a
** block of the reference simplex's. */
static double block_norm_ub(iv a, iv b, iv c) {
  double sm = iv_abs(iv_add(a, c)), dm = iv_abs(iv_add(a, iv_scale(c, -1)));
  double bm = iv_abs(b);
  return 0.5 * sm + sqrt(0.25 * dm * dm + bm * bm);
}

static double ivec_norm_ub(int mode, const ivec *v) {
  if (mode == 2)
    return dmax(dmax(block_norm_ub(v->c[0], v->c[3], v->c[1]),
                     block_norm_ub(v->c[0], v->c[4], v->c[2])),
                block_norm_ub(v->c[1], v->c[5], v->c[2]));
  double m = 0;
  for (int c = 0; c < 3; c++) {
    double q = dmax(fabs(v->c[c].lo), fabs(v->c[c].hi));
    m += q * q;
  }
  return sqrt(m);
}

/* 1 when some gradient assignment may exceed T on the box. The first
** corner takes one of each pair g, -g only: negating every gradient
** negates the sum. */
static int may_exceed(int mode, const enclosure *e, int i, ivec acc,
                      double rest, double T) {
  if (i == e->n) return ivec_norm_ub(mode, &acc) > T - MARGIN;
  int nc = mode == 2 ? 6 : 3;
  for (int q = 0; q < 12; q += i == 0 ? 2 : 1) {
    ivec s = acc;
    for (int c = 0; c < nc; c++)
      s.c[c] = iv_add(s.c[c], e->w[i][q].c[c]);
    double r = rest - e->bound[i];
    if (ivec_norm_ub(mode, &s) + r <= T - MARGIN) continue;
    if (may_exceed(mode, e, i + 1, s, r, T)) return 1;
  }
  return 0;
}

/* Proves sup |raw| <= T (mode 0), sup |grad raw| <= T (mode 1) or the
** Hessian's bound of ivec_norm_ub <= T (mode 2) over the
** reference simplex and every gradient assignment, by bisection down to
** boxes of width min_w. Returns 1 when proved, 0 when a box of width below
** min_w could not be discharged. */
static int certify(int mode, double T, double min_w, long *boxes) {
  typedef struct {
    double lo[3], hi[3];
  } box;
  box stack[512];
  int sp = 0;
  stack[sp++] = (box){{0, 0, 0}, {1, 1, 1}};
  *boxes = 0;
  while (sp) {
    box b = stack[--sp];
    /* entirely outside x >= y >= z */
    if (b.hi[0] < b.lo[1] || b.hi[1] < b.lo[2]) continue;
    ++*boxes;
    enclosure e;
    enclose(mode, b.lo, b.hi, &e);
    double total = 0;
    for (int i = 0; i < e.n; i++)
      total += e.bound[i];
    ivec zero;
    for (int c = 0; c < 6; c++)
      zero.c[c] = iv_c(0);
    if (total <= T - MARGIN || !may_exceed(mode, &e, 0, zero, total, T))
      continue;
    int k = 0;
    for (int c = 1; c < 3; c++)
      if (b.hi[c] - b.lo[c] > b.hi[k] - b.lo[k]) k = c;
    if (b.hi[k] - b.lo[k] < min_w) return 0;
    if (sp + 2 > 512) return 0;
    double mid = 0.5 * (b.lo[k] + b.hi[k]);
    box b1 = b, b2 = b;
    b1.hi[k] = mid, b2.lo[k] = mid;
    stack[sp++] = b1, stack[sp++] = b2;
  }
  return 1;
}

/* The exact terms at one point, for the soundness check. */
static void point_terms(int mode, const double p[3], int i, int q,
                        double out[6]) {
  double d[3], s = 0;
  for (int c = 0; c < 3; c++)
    d[c] = p[c] - SV[i][c], s += d[c] * d[c];
  double a = fmax(0.5 - s, 0), t = 0;
  for (int c = 0; c < 3; c++)
    t += GR[q][c] * d[c];
  for (int c = 0; c < 6; c++)
    out[c] = 0;
  if (mode == 0) {
    out[0] = a * a * a * a * t;
  } else if (mode == 1) {
    for (int c = 0; c < 3; c++)
      out[c] = a * a * a * (a * GR[q][c] - 8 * t * d[c]);
  } else {
    for (int m = 0; m < 6; m++) {
      int r = HR[m], c = HC[m];
      double M = GR[q][r] * d[c] + d[r] * GR[q][c] + (r == c ? t : 0);
      out[m] = -8 * a * a * a * M + 48 * a * a * t * d[r] * d[c];
    }
  }
}

/* The norm of a point value (ivec_norm_ub of an exact vector). */
static double point_norm(int mode, const double v[6]) {
  ivec x;
  for (int c = 0; c < 6; c++)
    x.c[c] = iv_c(v[c]);
  return ivec_norm_ub(mode, &x);
}

/* The largest |sum| over every gradient assignment at one point p of the
** reference simplex (unskewed): a lower bound of the supremum. */
static double witness(int mode, const double p[3]) {
  double term[4][12][6];
  int n = 0;
  for (int i = 0; i < 4; i++) {
    double s = 0;
    for (int c = 0; c < 3; c++)
      s += (p[c] - SV[i][c]) * (p[c] - SV[i][c]);
    if (s >= 0.5) continue;
    for (int q = 0; q < 12; q++)
      point_terms(mode, p, i, q, term[n][q]);
    n++;
  }
  int total = 1;
  for (int i = 0; i < n; i++)
    total *= 12;
  double best = 0;
  for (int k = 0; k < total; k++) {
    double v[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 0, kk = k; i < n; i++, kk /= 12)
      for (int c = 0; c < 6; c++)
        v[c] += term[i][kk % 12][c];
    best = dmax(best, point_norm(mode, v));
  }
  return best;
}

START_TEST(enclosures_are_sound) {
  /* The proof is only as good as enclose(): every exact term at points of
  ** a box must lie in the box's enclosure. */
  init_simplex();
  oc_rng r = oc_rng_stream(11, 11);
  int bad = 0, checked = 0;
  for (int it = 0; it < 3000; it++) {
    double lo[3], hi[3], w = pow(10, oc_rng_range(&r, -4, -0.5));
    for (int c = 0; c < 3; c++)
      lo[c] = oc_rng_range(&r, -0.1, 1), hi[c] = lo[c] + w;
    for (int mode = 0; mode < 3; mode++) {
      enclosure e;
      enclose(mode, lo, hi, &e);
      for (int k = 0; k < 20; k++) {
        double ps[3], p[3];
        for (int c = 0; c < 3; c++)
          ps[c] = oc_rng_range(&r, lo[c], hi[c]);
        double t = (ps[0] + ps[1] + ps[2]) / 6;
        for (int c = 0; c < 3; c++)
          p[c] = ps[c] - t;
        int slot = 0;
        for (int i = 0; i < 4; i++) {
          int in = slot < e.n && e.corner[slot] == i;
          for (int q = 0; q < 12; q++) {
            double v[6];
            point_terms(mode, p, i, q, v);
            double nv = point_norm(mode, v);
            checked++;
            /* a corner left out must be out of reach */
            if (!in) {
              bad += nv != 0;
              continue;
            }
            bad += nv > e.bound[slot] + 1e-14;
            for (int c = 0; c < 6; c++)
              bad += v[c] < e.w[slot][q].c[c].lo - 1e-14 ||
                     v[c] > e.w[slot][q].c[c].hi + 1e-14;
          }
          slot += in;
        }
      }
    }
  }
  printf("noise: %d enclosure checks, %d violations\n", checked, bad);
  ck_assert_int_eq(bad, 0);
  ck_assert_int_gt(checked, 100000);
}
END_TEST

START_TEST(bounds_are_proved) {
  init_simplex();
  long boxes;
  clock_t t0 = clock();
  int value_ok = certify(0, CERT_RAW_MAX, 1e-7, &boxes);
  printf("noise: proof of sup |raw| <= %.6f: %s (%ld boxes)\n", CERT_RAW_MAX,
         value_ok ? "done" : "FAILED", boxes);
  int grad_ok = certify(1, CERT_RAW_GRAD_MAX, 1e-7, &boxes);
  printf("noise: proof of sup |grad raw| <= %.4f: %s (%ld boxes, %.1f s in "
         "all)\n",
         CERT_RAW_GRAD_MAX, grad_ok ? "done" : "FAILED", boxes,
         (double)(clock() - t0) / CLOCKS_PER_SEC);
  ck_assert(value_ok && grad_ok);

  /* The bounds are nearly attained: witnesses in the simplex (skewed
  ** coordinates, some gradient assignment) reach 0.0130071 and 0.0906200. */
  const double wit[2][3] = {{0.83315, 0.16685, 0}, {0.94047, 0.5, 0.05953}};
  double reach[2];
  for (int mode = 0; mode < 2; mode++) {
    double t = (wit[mode][0] + wit[mode][1] + wit[mode][2]) / 6;
    double p[3] = {wit[mode][0] - t, wit[mode][1] - t, wit[mode][2] - t};
    reach[mode] = witness(mode, p);
  }
  printf("noise: witnesses reach %.7f (%.3f %% of the bound) and %.7f "
         "(%.3f %%)\n",
         reach[0], 100 * reach[0] / CERT_RAW_MAX, reach[1],
         100 * reach[1] / CERT_RAW_GRAD_MAX);
  ck_assert(reach[0] > 0.999 * CERT_RAW_MAX && reach[0] <= CERT_RAW_MAX);
  ck_assert(reach[1] > 0.997 * CERT_RAW_GRAD_MAX &&
            reach[1] <= CERT_RAW_GRAD_MAX);
  /* The prover can fail: below the true suprema it must, and quickly with
  ** coarse boxes. */
  ck_assert(!certify(0, 0.0125, 1e-3, &boxes));
  ck_assert(!certify(1, 0.085, 1e-3, &boxes));

  /* Tie the proof to the implementation: its scale keeps n in [0, 1] and
  ** its Lipschitz constant covers the proved gradient bound. */
  double scale = implementation_scale();
  ck_assert(scale * CERT_RAW_MAX <= 0.5 * (1 + 1e-12));
  ck_assert(scale * CERT_RAW_GRAD_MAX <= oc_noise3_lipschitz * (1 + 1e-12));
  /* ... and neither wastes range: both within 1e-9 of the proved values. */
  ck_assert_double_eq_tol(scale * CERT_RAW_MAX, 0.5, 1e-9);
  ck_assert_double_eq_tol(oc_noise3_lipschitz, scale * CERT_RAW_GRAD_MAX, 1e-9);
}
END_TEST

START_TEST(hessian_bound_is_proved) {
  /* The Hessian of n on any coordinate plane (the plane z = 0 of the
  ** elevation discs' noise): the largest operator norm of a principal 2 x 2
  ** block of the raw sum's Hessian, over the reference simplex and every
  ** assignment. */
  init_simplex();
  long boxes;
  clock_t t0 = clock();
  int ok = certify(2, CERT_RAW_HESS_MAX, 1e-7, &boxes);
  printf("noise: proof of the plane Hessian bound %.4f: %s (%ld boxes, %.1f "
         "s)\n",
         CERT_RAW_HESS_MAX, ok ? "done" : "FAILED", boxes,
         (double)(clock() - t0) / CLOCKS_PER_SEC);
  ck_assert(ok);
  const double wit[3] = {WIT_HESS};
  double t = (wit[0] + wit[1] + wit[2]) / 6;
  double p[3] = {wit[0] - t, wit[1] - t, wit[2] - t};
  double reach = witness(2, p);
  printf("noise: a witness reaches %.5f (%.2f %% of the bound)\n", reach,
         100 * reach / CERT_RAW_HESS_MAX);
  ck_assert(reach > WIT_HESS_SHARE * CERT_RAW_HESS_MAX &&
            reach <= CERT_RAW_HESS_MAX);
  ck_assert(!certify(2, 0.95 * reach, 1e-3, &boxes));
  double scale = implementation_scale();
  ck_assert_double_eq_tol(oc_noise3_hessian, scale * CERT_RAW_HESS_MAX, 1e-9);
}
END_TEST

START_TEST(noise_hessian_on_planes) {
  /* The gradient's part in a coordinate plane changes by at most
  ** oc_noise3_hessian times the distance along that plane. */
  oc_rng r = oc_rng_stream(16, 16);
  double worst = 0;
  for (int i = 0; i < 100000; i++) {
    int ax = i % 3; /* the axis normal to the plane */
    oc_vec3 p = rand_point(&r, 30), d = rand_dir(&r), gp, gq;
    double len = pow(10, oc_rng_range(&r, -4, -0.5));
    double *dd = ax == 0 ? &d.x : ax == 1 ? &d.y : &d.z;
    *dd = 0;
    oc_vec3 q = oc_add(p, oc_mul(d, len));
    double dist = oc_len(oc_sub(q, p));
    if (!(dist > 0)) continue;
    oc_noise3(3, p, &gp);
    oc_noise3(3, q, &gq);
    oc_vec3 dg = oc_sub(gq, gp);
    double *dgn = ax == 0 ? &dg.x : ax == 1 ? &dg.y : &dg.z;
    *dgn = 0;
    double ratio = oc_len(dg) / dist;
    if (ratio > worst) worst = ratio;
  }
  printf("noise: plane Hessian sampled up to %.3f, bound %.3f\n", worst,
         oc_noise3_hessian);
  ck_assert(worst <= oc_noise3_hessian);
  ck_assert(worst > 0.6 * oc_noise3_hessian);
}
END_TEST

/* ---- huge and invalid input ----------------------------------------- */

START_TEST(noise_huge_coordinates) {
  oc_rng r = oc_rng_stream(12, 12);
  int bad = 0;
  double worst = 0;
  for (int i = 0; i < 100000; i++) {
    oc_vec3 p = rand_point(&r, 1e9), g;
    double v = oc_noise3(3, p, &g);
    bad += !(v >= 0 && v <= 1) || !oc_vfinite(g) ||
           oc_len(g) > oc_noise3_lipschitz;
    if (i < 2000) {
      /* Positions are quantized to 1.2e-7 here: a coarser step. */
      oc_vec3 fd = central_diff(f_noise, 3, 0, p, 1e-3);
      double e = oc_len(oc_sub(fd, g));
      if (e > worst) worst = e;
    }
  }
  printf("noise: at |p| ~ 1e9, worst gradient error vs differences %.2e\n",
         worst);
  ck_assert_int_eq(bad, 0);
  ck_assert(worst < 0.02);
  /* Far beyond: finite values in range, no undefined behaviour (the
  ** sanitizer build runs this), and the documented reduction. */
  const double far[] = {1e15,     -1e15,  1e18,       -3e200,     1.7e308,
                        -1.7e308, 0x1p62, 3 * 0x1p48, -3 * 0x1p48};
  for (size_t i = 0; i < sizeof far / sizeof far[0]; i++) {
    oc_vec3 g, p = oc_v3(far[i], 0.3, -far[i] / 7);
    double v = oc_noise3(3, p, &g);
    ck_assert(v >= 0 && v <= 1 && oc_vfinite(g));
    double t = oc_turb3(3, 8, p, &g);
    ck_assert(t >= 0 && t <= oc_turb3_max(8) && oc_vfinite(g));
  }
  double P = 3 * 0x1p48, x = 12345 * P + 0.25;
  ck_assert(oc_noise3(4, oc_v3(x, 1, 2), NULL) ==
            oc_noise3(4, oc_v3(fmod(x, P), 1, 2), NULL));
  /* Past 2^101 the reduction is computed without fmod's loop: it must
  ** still be fmod's, bit for bit, at every exponent and both signs. */
  int differ = 0;
  for (int e = 90; e <= 1023; e++)
    for (int k = 0; k < 8; k++) {
      double m = 1 + oc_rng_uniform(&r) * (1 - 0x1p-52);
      double v = ldexp(k % 2 ? -m : m, e);
      oc_vec3 a = oc_v3(v, -v / 3, 0.5), b;
      b = oc_v3(fmod(a.x, P), fmod(a.y, P), fmod(a.z, P));
      differ += oc_noise3(9, a, NULL) != oc_noise3(9, b, NULL) ||
                oc_turb3(9, 4, a, NULL) != oc_turb3(9, 4, b, NULL);
    }
  ck_assert_int_eq(differ, 0);
  /* NaN and infinities give NaN, value and gradient. */
  const double odd[] = {NAN, INFINITY, -INFINITY};
  for (int i = 0; i < 3; i++) {
    for (int axis = 0; axis < 3; axis++) {
      oc_vec3 p = oc_v3(1, 2, 3), g;
      if (axis == 0) p.x = odd[i];
      if (axis == 1) p.y = odd[i];
      if (axis == 2) p.z = odd[i];
      ck_assert(isnan(oc_noise3(1, p, &g)));
      ck_assert(isnan(g.x) && isnan(g.y) && isnan(g.z));
      ck_assert(isnan(oc_turb3(1, 3, p, &g)) && isnan(g.x));
    }
  }
}
END_TEST

/* Rows on z = 0 are oc_noise3's values bit for bit: rows of every length
** (odd ones take the scalar tail), dense (many points per lattice cell:
** shared corners) and sparse, across zero and negative coordinates and
** signed zeros, near the lattice's integers, and past the range where
** coordinates are used as given (huge, infinite and NaN points). */
static int same_bits(double a, double b) {
  return !memcmp(&a, &b, sizeof a);
}

START_TEST(noise_rows_on_plane) {
  oc_rng r = oc_rng_stream(21, 3);
  enum { L = 150 };
  double x[L], y[L], v[L];
  int differ = 0, rows = 0;
  for (int k = 0; k < 60; k++) {
    int n = 1 + (int)(oc_rng_uniform(&r) * L);
    double step = k % 3 == 0 ? 0.013 : k % 3 == 1 ? 0.4 : 3.7;
    double x0 = (oc_rng_uniform(&r) - 0.5) * (k < 50 ? 40 : 1e15);
    double y0 = (oc_rng_uniform(&r) - 0.5) * 40;
    for (int m = 0; m < n; m++)
      x[m] = x0 + m * step, y[m] = k % 2 ? y0 : y0 - m * step / 3;
    if (k == 55) x[n / 2] = NAN, y[0] = INFINITY;
    if (k == 56) x[0] = -0.0, y[0] = -0.0, x[n - 1] = 3 * 0x1p48;
    if (k == 57) /* integers and their neighbours in skewed space */
      for (int m = 0; m < n; m++)
        x[m] = (m / 3) + (m % 3 - 1) * 0x1p-40, y[m] = 0;
    oc_noise3_z0_row((uint64_t)k, x, y, (size_t)n, v);
    for (int m = 0; m < n; m++)
      differ +=
          !same_bits(v[m], oc_noise3((uint64_t)k, oc_v3(x[m], y[m], 0), NULL));
    rows++;
  }
  ck_assert_int_eq(rows, 60);
  ck_assert_int_eq(differ, 0);
}
END_TEST

/* oc_noise3_z0_multi (the octaves of an elevation disc, several points
** at a time) gives oc_noise3's values and gradients' x and y parts bit
** for bit: every count up to 17 (counts that are not a multiple of the
** lanes end on padding lanes), seeds and scales that differ point to
** point as octaves do, signed zeros, lattice integers, and huge,
** infinite and NaN points among ordinary ones. */
START_TEST(noise_z0_multi_matches) {
  oc_rng r = oc_rng_stream(23, 5);
  enum { L = 17 };
  uint64_t seed[L];
  double x[L], y[L], v[L], gx[L], gy[L], w[L];
  int differ = 0, points = 0;
  for (int k = 0; k < 400; k++) {
    int n = k % (L + 1);
    for (int m = 0; m < n; m++) {
      double sc = ldexp(1, (int)(oc_rng_uniform(&r) * 30) - 6);
      seed[m] = oc_rng_next(&r);
      x[m] = (oc_rng_uniform(&r) - 0.5) * sc;
      y[m] = (oc_rng_uniform(&r) - 0.5) * sc;
    }
    if (n > 3 && k % 50 == 1) x[1] = 1e300, y[2] = NAN, x[3] = -INFINITY;
    if (n > 2 && k % 50 == 2) x[0] = y[0] = -0.0, x[1] = 3 * 0x1p48, y[2] = 2;
    if (n > 0 && k % 50 == 3) x[n - 1] = 3 * 0x1p48 + 1e6;
    oc_noise3_z0_multi(seed, x, y, (size_t)n, v, gx, gy);
    oc_noise3_z0_multi(seed, x, y, (size_t)n, w, NULL, NULL);
    for (int m = 0; m < n; m++, points++) {
      oc_vec3 g;
      double ref = oc_noise3(seed[m], oc_v3(x[m], y[m], 0), &g);
      differ += !same_bits(v[m], ref) || !same_bits(w[m], ref) ||
                !same_bits(gx[m], g.x) || !same_bits(gy[m], g.y);
    }
  }
  ck_assert_int_eq(points, 3372); /* 22 rounds of 0..17 points, then 0..3 */
  ck_assert_int_eq(differ, 0);
}
END_TEST

/* Each path of oc_noise3_z0_multi (oc_noise3_z0_multi_isa: the portable
** two lanes, AVX-512's eight, and the automatic choice) gives oc_noise3's
** bits, values alone and with gradients, for every count from 0 to 19
** (full vectors, padding lanes in the last one), mixed seeds and scales,
** points at lattice integers and their neighbours, signed zeros, huge
** points (reduced as noise3 reduces them) and NaN or infinite ones in
** any lane; and writes nothing past n. AVX-512 is there exactly where the
** processor has AVX-512 F and DQ; a path it lacks is refused. */
START_TEST(noise_z0_multi_paths) {
  enum { L = 19, PAD = 4 };
  const oc_noise_isa isa[3] = {OC_NOISE_ISA_AUTO, OC_NOISE_ISA_SSE2,
                               OC_NOISE_ISA_AVX512};
#if defined(__x86_64__) && defined(__GNUC__)
  int avx =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  ck_assert_int_eq(oc_noise_isa_supported(OC_NOISE_ISA_AVX512), avx);
#else
  ck_assert_int_eq(oc_noise_isa_supported(OC_NOISE_ISA_AVX512), 0);
#endif
  ck_assert_int_eq(oc_noise_isa_supported(OC_NOISE_ISA_AUTO), 1);
  ck_assert_int_eq(oc_noise_isa_supported(OC_NOISE_ISA_SSE2), 1);
  ck_assert_int_eq(oc_noise_isa_supported((oc_noise_isa)7), 0);
  double z[1] = {5};
  ck_assert_int_eq(
      oc_noise3_z0_multi_isa((oc_noise_isa)7, NULL, z, z, 1, z, NULL, NULL),
      -1);
  ck_assert(z[0] == 5);
  oc_rng r = oc_rng_stream(29, 7);
  uint64_t seed[L];
  double x[L], y[L], v[L + PAD], gx[L + PAD], gy[L + PAD], w[L + PAD];
  int differ = 0, points = 0, spilled = 0, paths = 0;
  for (int k = 0; k < 200; k++) {
    int n = k % (L + 1);
    for (int m = 0; m < n; m++) {
      double sc = ldexp(1, (int)(oc_rng_uniform(&r) * 40) - 8);
      seed[m] = k % 7 == 0 ? (uint64_t)m : oc_rng_next(&r);
      x[m] = (oc_rng_uniform(&r) - 0.5) * sc;
      y[m] = (oc_rng_uniform(&r) - 0.5) * sc;
    }
    if (k % 20 == 5) /* integers of the skewed lattice and neighbours */
      for (int m = 0; m < n; m++)
        x[m] = (m / 3) + (m % 3 - 1) * 0x1p-40, y[m] = (m % 2) * 0x1p-50;
    if (n > 0 && k % 20 == 6) x[n - 1] = 1e300, y[n / 2] = -3 * 0x1p48;
    if (n > 8 && k % 20 == 7) /* (x[1], y[1]: skewed x is -0) */
      x[0] = NAN, y[3] = INFINITY, x[7] = -INFINITY, y[8] = -0.0, x[8] = -0.0,
      x[1] = -0.0, y[1] = -0x1p-1074;
    if (n > 0 && k % 20 == 8) x[n - 1] = NAN, y[n - 1] = 3 * 0x1p48 + 2e6;
    if (n > 9 && k % 20 == 9) y[9] = -1e308, x[2] = 0x1p101;
    for (int p = 0; p < 3; p++) {
      for (int m = 0; m < L + PAD; m++)
        v[m] = gx[m] = gy[m] = w[m] = -7;
      if (!oc_noise_isa_supported(isa[p])) {
        ck_assert_int_eq(
            oc_noise3_z0_multi_isa(isa[p], seed, x, y, (size_t)n, v, gx, gy),
            -1);
        spilled += v[0] != -7;
        continue;
      }
      paths++;
      ck_assert_int_eq(
          oc_noise3_z0_multi_isa(isa[p], seed, x, y, (size_t)n, v, gx, gy), 0);
      ck_assert_int_eq(
          oc_noise3_z0_multi_isa(isa[p], seed, x, y, (size_t)n, w, NULL, NULL),
          0);
      for (int m = 0; m < n; m++, points++) {
        oc_vec3 g;
        double ref = oc_noise3(seed[m], oc_v3(x[m], y[m], 0), &g);
        differ += !same_bits(v[m], ref) || !same_bits(w[m], ref) ||
                  !same_bits(gx[m], g.x) || !same_bits(gy[m], g.y);
      }
      for (int m = n; m < L + PAD; m++)
        spilled += v[m] != -7 || gx[m] != -7 || gy[m] != -7 || w[m] != -7;
    }
  }
  /* 10 rounds of 0..19 points per path that runs */
  ck_assert_int_eq(points, paths / 200 * 1900);
  ck_assert_int_eq(paths % 200, 0);
  ck_assert_int_eq(differ, 0);
  ck_assert_int_eq(spilled, 0);
  printf("noise_z0_multi_paths: %d paths, %d points\n", paths / 200, points);
}
END_TEST

/* oc_noise3_z0_octaves (a disc's octaves at one point, their seeds and
** points made inside) gives, through each path, oc_noise3's bits at the
** seeds oc_mix64(seed + 0x9e3779b97f4a7c15 (m + 1)) (the formula, here
** written out) and the points (s[m] u, s[m] v): every count up to 16
** (one or two vectors, padding lanes), frequencies growing as octaves'
** do and arbitrary ones, signed zeros, huge and NaN points; writes
** nothing past its room of 16 values, and refuses more than 16 octaves
** or a missing path. */
START_TEST(noise_z0_octaves_paths) {
  enum { L = OC_NOISE_MAXOCT, PAD = 3 };
  const oc_noise_isa isa[3] = {OC_NOISE_ISA_AUTO, OC_NOISE_ISA_SSE2,
                               OC_NOISE_ISA_AVX512};
  oc_rng r = oc_rng_stream(31, 9);
  double s[L + 1] = {0}, v[L + PAD], gx[L + PAD], gy[L + PAD], w[L + PAD];
  ck_assert_int_eq(
      oc_noise3_z0_octaves_isa(OC_NOISE_ISA_SSE2, 1, s, 0, 0, L + 1, v, gx, gy),
      -1);
  int differ = 0, points = 0, spilled = 0, paths = 0;
  for (int k = 0; k < 120; k++) {
    int n = k % (L + 1);
    uint64_t seed = k % 5 == 0 ? (uint64_t)k : oc_rng_next(&r);
    double u = (oc_rng_uniform(&r) - 0.5) * 4000;
    double vv = (oc_rng_uniform(&r) - 0.5) * 4000;
    double f = ldexp(1, (int)(oc_rng_uniform(&r) * 12) - 10);
    for (int m = 0; m < n; m++, f *= k % 3 ? 2 : 1.7)
      s[m] = k % 7 == 3 ? oc_rng_uniform(&r) * 3 : f;
    if (k % 11 == 4) u = -0.0, vv = 0.0;
    if (n > 2 && k % 11 == 5) s[n - 1] = 1e300;
    if (n > 1 && k % 11 == 6) u = NAN;
    if (k % 11 == 7) vv = 3 * 0x1p48;
    for (int p = 0; p < 3; p++) {
      for (int m = 0; m < L + PAD; m++)
        v[m] = gx[m] = gy[m] = w[m] = -7;
      if (!oc_noise_isa_supported(isa[p])) {
        ck_assert_int_eq(oc_noise3_z0_octaves_isa(isa[p], seed, s, u, vv,
                                                  (size_t)n, v, gx, gy),
                         -1);
        spilled += v[0] != -7;
        continue;
      }
      paths++;
      ck_assert_int_eq(oc_noise3_z0_octaves_isa(isa[p], seed, s, u, vv,
                                                (size_t)n, v, gx, gy),
                       0);
      ck_assert_int_eq(oc_noise3_z0_octaves_isa(isa[p], seed, s, u, vv,
                                                (size_t)n, w, NULL, NULL),
                       0);
      for (int m = 0; m < n; m++, points++) {
        uint64_t sd =
            oc_mix64(seed + 0x9e3779b97f4a7c15ull * (uint64_t)(m + 1));
        differ += sd != oc_noise_octave_seed(seed, m);
        oc_vec3 g;
        double ref = oc_noise3(sd, oc_v3(s[m] * u, s[m] * vv, 0), &g);
        differ += !same_bits(v[m], ref) || !same_bits(w[m], ref) ||
                  !same_bits(gx[m], g.x) || !same_bits(gy[m], g.y);
      }
      for (int m = L; m < L + PAD; m++)
        spilled += v[m] != -7 || gx[m] != -7 || gy[m] != -7 || w[m] != -7;
    }
  }
  /* 7 rounds of 0..16 octaves, then 0..0, per path that runs */
  ck_assert_int_eq(points, paths / 120 * (7 * 136 + 0));
  ck_assert_int_eq(paths % 120, 0);
  ck_assert_int_eq(differ, 0);
  ck_assert_int_eq(spilled, 0);
  /* the automatic path is the default call's */
  for (int m = 0; m < L; m++)
    s[m] = ldexp(1, m - 8);
  oc_noise3_z0_octaves(77, s, 123.25, -40.5, L, v, gx, gy);
  oc_noise3_z0_octaves_isa(OC_NOISE_ISA_AUTO, 77, s, 123.25, -40.5, L, w, NULL,
                           NULL);
  for (int m = 0; m < L; m++)
    differ += !same_bits(v[m], w[m]);
  ck_assert_int_eq(differ, 0);
}
END_TEST

/* oc_noise3_z0_octaves2 (the frequencies f 2^m made inside) gives, through
** each path, oc_noise3_z0_octaves' bits at s[m] = f doubled m times: every
** count up to 16, f ordinary, subnormal, 0, and so large that the last
** octaves' frequencies overflow to infinity (their points NaN) or their
** points are huge; NaN and signed-zero points; writes nothing past its
** room of 16 values, and refuses more than 16 octaves or a missing path. */
START_TEST(noise_z0_octaves2_paths) {
  enum { L = OC_NOISE_MAXOCT, PAD = 3 };
  const oc_noise_isa isa[3] = {OC_NOISE_ISA_AUTO, OC_NOISE_ISA_SSE2,
                               OC_NOISE_ISA_AVX512};
  oc_rng r = oc_rng_stream(32, 9);
  double s[L], v[L + PAD], gx[L + PAD], gy[L + PAD], w[L + PAD];
  double rv[L + PAD], rgx[L + PAD], rgy[L + PAD];
  ck_assert_int_eq(oc_noise3_z0_octaves2_isa(OC_NOISE_ISA_SSE2, 1, 1, 0, 0,
                                             L + 1, v, gx, gy),
                   -1);
  int differ = 0, points = 0, spilled = 0, paths = 0, infinite = 0;
  for (int k = 0; k < 136; k++) {
    int n = k % (L + 1);
    uint64_t seed = k % 5 == 0 ? (uint64_t)k : oc_rng_next(&r);
    double u = (oc_rng_uniform(&r) - 0.5) * 4000;
    double vv = (oc_rng_uniform(&r) - 0.5) * 4000;
    double f =
        ldexp(1 + oc_rng_uniform(&r), (int)(oc_rng_uniform(&r) * 12) - 10);
    if (k % 9 == 1) f = 0x1.8p-1070;    /* subnormal */
    if (k % 9 == 2) f = 0;              /* (an infinite wavelength) */
    if (k % 9 == 3) f = 0x1.fp1015;     /* f 2^m overflows from m = 8 */
    if (k % 9 == 4) f = ldexp(1.5, 40); /* huge points, reduced */
    if (k % 11 == 4) u = -0.0, vv = 0.0;
    if (n > 1 && k % 11 == 6) u = NAN;
    double fm = f;
    for (int m = 0; m < n; m++, fm *= 2)
      s[m] = fm, infinite += isinf(fm);
    for (int p = 0; p < 3; p++) {
      for (int m = 0; m < L + PAD; m++)
        v[m] = gx[m] = gy[m] = w[m] = -7;
      if (!oc_noise_isa_supported(isa[p])) {
        ck_assert_int_eq(oc_noise3_z0_octaves2_isa(isa[p], seed, f, u, vv,
                                                   (size_t)n, v, gx, gy),
                         -1);
        spilled += v[0] != -7;
        continue;
      }
      paths++;
      ck_assert_int_eq(oc_noise3_z0_octaves2_isa(isa[p], seed, f, u, vv,
                                                 (size_t)n, v, gx, gy),
                       0);
      ck_assert_int_eq(oc_noise3_z0_octaves2_isa(isa[p], seed, f, u, vv,
                                                 (size_t)n, w, NULL, NULL),
                       0);
      ck_assert_int_eq(oc_noise3_z0_octaves_isa(isa[p], seed, s, u, vv,
                                                (size_t)n, rv, rgx, rgy),
                       0);
      for (int m = 0; m < n; m++, points++)
        differ += !same_bits(v[m], rv[m]) || !same_bits(w[m], rv[m]) ||
                  !same_bits(gx[m], rgx[m]) || !same_bits(gy[m], rgy[m]);
      for (int m = L; m < L + PAD; m++)
        spilled += v[m] != -7 || gx[m] != -7 || gy[m] != -7 || w[m] != -7;
    }
  }
  /* 8 rounds of 0..16 octaves per path that runs */
  ck_assert_int_eq(points, paths / 136 * (8 * 136));
  ck_assert_int_eq(paths % 136, 0);
  ck_assert_int_eq(differ, 0);
  ck_assert_int_eq(spilled, 0);
  ck_assert_int_gt(infinite, 0);
  /* the automatic path is the default call's */
  oc_noise3_z0_octaves2(77, 0x1p-8, 123.25, -40.5, L, v, gx, gy);
  oc_noise3_z0_octaves2_isa(OC_NOISE_ISA_AUTO, 77, 0x1p-8, 123.25, -40.5, L, w,
                            NULL, NULL);
  for (int m = 0; m < L; m++)
    differ += !same_bits(v[m], w[m]);
  ck_assert_int_eq(differ, 0);
}
END_TEST

/* ---- turbulence ------------------------------------------------------ */

START_TEST(turbulence_bounds_and_definition) {
  ck_assert_double_eq(oc_turb3_max(1), 1.0);
  ck_assert_double_eq(oc_turb3_max(4), 1.875);
  ck_assert_double_eq(oc_turb3_max(16), 2 - 0x1p-15);
  ck_assert_double_eq(oc_turb3_lipschitz(1), oc_noise3_lipschitz);
  ck_assert_double_eq(oc_turb3_lipschitz(5), 5 * oc_noise3_lipschitz);
  oc_rng r = oc_rng_stream(13, 13);
  int bad = 0;
  for (int o = 1; o <= 16; o++) {
    double tmax = oc_turb3_max(o), hi = 0;
    for (int i = 0; i < 20000; i++) {
      oc_vec3 p = rand_point(&r, 100);
      double t = oc_turb3(17, o, p, NULL);
      bad += !(t >= 0 && t <= tmax);
      if (t > hi) hi = t;
    }
    /* the octaves add up: the top of the range is reached in part */
    bad += o > 1 && hi <= oc_turb3_max(o - 1) * 0.6;
  }
  ck_assert_int_eq(bad, 0);
  /* The definition, exactly: octave k is 2^-k n(hash2(seed, k), 2^k p). */
  for (int i = 0; i < 1000; i++) {
    oc_vec3 p = rand_point(&r, 100);
    double sum = 0;
    for (int k = 0; k < 6; k++)
      sum += ldexp(
          oc_noise3(oc_hash2(99, (uint64_t)k), oc_mul(p, ldexp(1, k)), NULL),
          -k);
    ck_assert(sum == oc_turb3(99, 6, p, NULL));
  }
}
END_TEST

START_TEST(turbulence_gradient_and_lipschitz) {
  oc_rng r = oc_rng_stream(14, 14);
  const int octs[] = {1, 3, 8};
  for (int n = 0; n < 3; n++) {
    int o = octs[n];
    double worst = 0, L = oc_turb3_lipschitz(o), steepest = 0;
    int bad = 0;
    for (int i = 0; i < 20000; i++) {
      oc_vec3 p = rand_point(&r, 30), g;
      oc_turb3(7, o, p, &g);
      /* the finest octave has frequency 2^(o-1): scale the step */
      oc_vec3 fd = central_diff(f_turb, 7, o, p, 1e-6 / (1 << (o - 1)));
      double e = oc_len(oc_sub(fd, g)) / (1 + oc_len(g));
      if (e > worst) worst = e;
      double dist = pow(10, oc_rng_range(&r, -9, 0));
      oc_vec3 q = oc_add(p, oc_mul(rand_dir(&r), dist));
      double d = oc_len(oc_sub(q, p));
      double dv = fabs(oc_turb3(7, o, p, NULL) - oc_turb3(7, o, q, NULL));
      bad += dv > L * d + 1e-14;
      if (oc_len(g) > steepest) steepest = oc_len(g);
    }
    printf("turbulence, %d octaves: gradient error %.2e, max |grad| %.3f <= "
           "%.3f\n",
           o, worst, steepest, L);
    ck_assert(worst < 1e-5);
    ck_assert_int_eq(bad, 0);
    ck_assert(steepest <= L);
  }
  /* Zero octaves: the empty sum. */
  oc_vec3 g;
  ck_assert(oc_turb3(1, 0, oc_v3(1, 2, 3), &g) == 0 && g.x == 0 &&
            oc_turb3_max(0) == 0);
}
END_TEST

/* ---- speed ----------------------------------------------------------- */

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

START_TEST(noise_speed) {
  enum { N = 1 << 16, REP = 30 };
  static oc_vec3 pts[N];
  oc_rng r = oc_rng_stream(15, 15);
  for (int i = 0; i < N; i++)
    pts[i] = rand_point(&r, 100);
  double acc = 0, t0 = now();
  for (int k = 0; k < REP; k++)
    for (int i = 0; i < N; i++) {
      oc_vec3 g;
      acc += oc_noise3((uint64_t)k, pts[i], &g) + g.x;
    }
  double t1 = now();
  for (int k = 0; k < REP; k++)
    for (int i = 0; i < N; i++)
      acc += oc_noise3((uint64_t)k, pts[i], NULL);
  double t2 = now();
  for (int k = 0; k < REP / 5; k++)
    for (int i = 0; i < N; i++) {
      oc_vec3 g;
      acc += oc_turb3((uint64_t)k, 4, pts[i], &g) + g.y;
    }
  double t3 = now();
  printf("noise: %.1f ns per call with gradient, %.1f without; turbulence "
         "(4 octaves, gradient) %.1f ns\n",
         (t1 - t0) * 1e9 / (N * REP), (t2 - t1) * 1e9 / (N * REP),
         (t3 - t2) * 1e9 / (N * (REP / 5)));
  /* Timing depends on the machine and the build; only sanity is asserted. */
  ck_assert(isfinite(acc));
}
END_TEST

int main(void) {
  /* Line buffering: a failing test's child would lose its report. */
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("noise");
  TCase *tc = tcase_create("noise");
  tcase_set_timeout(tc, 300);
  tcase_add_test(tc, noise_in_unit_interval);
  tcase_add_test(tc, noise_mean_is_half);
  tcase_add_test(tc, noise_gradient_matches_differences);
  tcase_add_test(tc, noise_gradient_below_bound);
  tcase_add_test(tc, noise_lipschitz_on_pairs);
  tcase_add_test(tc, noise_is_deterministic);
  tcase_add_test(tc, seeds_are_decorrelated);
  tcase_add_test(tc, noise_continuous_across_boundaries);
  tcase_add_test(tc, noise_matches_reference);
  tcase_add_test(tc, noise_huge_coordinates);
  tcase_add_test(tc, noise_rows_on_plane);
  tcase_add_test(tc, noise_z0_multi_matches);
  tcase_add_test(tc, noise_z0_multi_paths);
  tcase_add_test(tc, noise_z0_octaves_paths);
  tcase_add_test(tc, noise_z0_octaves2_paths);
  tcase_add_test(tc, turbulence_bounds_and_definition);
  tcase_add_test(tc, turbulence_gradient_and_lipschitz);
  tcase_add_test(tc, noise_hessian_on_planes);
  tcase_add_test(tc, noise_speed);
  suite_add_tcase(s, tc);
  TCase *proof = tcase_create("proof");
  tcase_set_timeout(proof, 600);
  tcase_add_test(proof, enclosures_are_sound);
  /* The proofs are arithmetic on the same code in both builds: the
  ** release pass runs them, the sanitizer pass (7x slower) does not. */
#ifndef __SANITIZE_ADDRESS__
  tcase_add_test(proof, bounds_are_proved);
  tcase_add_test(proof, hessian_bound_is_proved);
#else
  (void)bounds_are_proved;
  (void)hessian_bound_is_proved;
#endif
  suite_add_tcase(s, proof);
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed ? 1 : 0;
}
