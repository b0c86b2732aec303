/*
** test_elevation.c — elevation trees (Génevaux et al. 2015): every
** primitive and operator against its formula, gradients against central
** differences, the Lipschitz bounds and ranges never exceeded (over the
** plane and inside random boxes), transforms concatenated exactly, the
** elevation source, statistics of a DAG, and bad input refused with the
** field named.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/curve.h"
#include "core/rng.h"
#include "elevation/enode.h"
#include "etaycheck.h"
#include "ocheck.h"

#define PI 3.14159265358979323846

static oc_enode *eok_(oc_enode *e, const oc_error *err, const char *what,
                      int line) {
  ck_assert_msg(e != NULL, "line %d: %s failed: %s", line, what, err->msg);
  return e;
}
#define EOK(expr) eok_((expr), &err, #expr, __LINE__)

static oc_enode *disc(double cx, double cy, double r, double h,
                      oc_enoise_kind kind, double amp, double wl, int oct) {
  oc_error err;
  oc_enode_disc_params p = {cx, cy, r, h, {kind, amp, wl, oct, 0, 0, 42}};
  return EOK(oc_enode_disc(&p, &err));
}

static double wyv(double x) {
  if (x >= 1) return 0;
  double k = 1 - x * x;
  return k * k * k;
}

/* f and alpha at (x, y) with central-difference gradients checked
** against the analytic ones (where the function is smooth enough). */
static void check_gradient(const oc_enode *e, double x, double y, double tol) {
  oc_enode_sample s, a, b;
  double h = 1e-5;
  oc_enode_eval(e, x, y, &s);
  oc_enode_eval(e, x + h, y, &a);
  oc_enode_eval(e, x - h, y, &b);
  double fx = (a.f - b.f) / (2 * h), ax = (a.a - b.a) / (2 * h);
  oc_enode_eval(e, x, y + h, &a);
  oc_enode_eval(e, x, y - h, &b);
  double fy = (a.f - b.f) / (2 * h), ay = (a.a - b.a) / (2 * h);
  double sc = 1 + fabs(fx) + fabs(fy);
  ck_assert_msg(fabs(fx - s.fx) <= tol * sc && fabs(fy - s.fy) <= tol * sc,
                "%s grad f at (%g, %g): (%g, %g) vs fd (%g, %g)",
                oc_enode_kind(e), x, y, s.fx, s.fy, fx, fy);
  double sa = 1 + fabs(ax) + fabs(ay);
  ck_assert_msg(fabs(ax - s.ax) <= tol * sa && fabs(ay - s.ay) <= tol * sa,
                "%s grad alpha at (%g, %g): (%g, %g) vs fd (%g, %g)",
                oc_enode_kind(e), x, y, s.ax, s.ay, ax, ay);
}

/* Ranges and Lipschitz bounds of a box hold on random points and pairs
** in it. */
static void check_bound_in(const oc_enode *e, oct_rng *r, double x0, double y0,
                           double x1, double y1) {
  oc_enode_bound b;
  oc_enode_bound_in(e, x0, y0, x1, y1, &b);
  for (int i = 0; i < 256; i++) {
    double px = oct_unif(r, x0, x1), py = oct_unif(r, y0, y1);
    double qx = oct_unif(r, x0, x1), qy = oct_unif(r, y0, y1);
    oc_enode_sample p, q;
    oc_enode_eval(e, px, py, &p);
    oc_enode_eval(e, qx, qy, &q);
    double m = 1e-9 * (1 + fabs(b.flo) + fabs(b.fhi));
    ck_assert_msg(p.f >= b.flo - m && p.f <= b.fhi + m,
                  "%s: f %g outside [%g, %g]", oc_enode_kind(e), p.f, b.flo,
                  b.fhi);
    ck_assert_msg(p.a >= b.alo - 1e-9 && p.a <= b.ahi + 1e-9,
                  "%s: alpha %g outside [%g, %g]", oc_enode_kind(e), p.a, b.alo,
                  b.ahi);
    /* the gradient's norm is the sharpest test of a Lipschitz bound */
    ck_assert_msg(hypot(p.fx, p.fy) <= b.lf * (1 + 1e-9) + m,
                  "%s: |grad f| %g > %g", oc_enode_kind(e), hypot(p.fx, p.fy),
                  b.lf);
    ck_assert_msg(hypot(p.ax, p.ay) <= b.la * (1 + 1e-9) + 1e-12,
                  "%s: |grad alpha| %g > %g", oc_enode_kind(e),
                  hypot(p.ax, p.ay), b.la);
    double d = hypot(px - qx, py - qy);
    ck_assert_msg(fabs(p.f - q.f) <= b.lf * d * (1 + 1e-9) + m,
                  "%s: |df| %g > %g x %g", oc_enode_kind(e), fabs(p.f - q.f),
                  b.lf, d);
    ck_assert_msg(fabs(p.a - q.a) <= b.la * d * (1 + 1e-9) + 1e-12,
                  "%s: |dalpha| %g > %g x %g", oc_enode_kind(e),
                  fabs(p.a - q.a), b.la, d);
  }
}

/* The bounds of e hold in random boxes of every size around (cx, cy). */
static void check_bounds(const oc_enode *e, double cx, double cy, double R) {
  oct_rng r = oct_rng_new(99);
  for (int i = 0; i < 60; i++) {
    double w = R * pow(10, oct_unif(&r, -3, 0.3));
    double x0 = cx + oct_unif(&r, -R, R), y0 = cy + oct_unif(&r, -R, R);
    check_bound_in(e, &r, x0, y0, x0 + w, y0 + w * oct_unif(&r, 0.2, 1));
  }
  /* the whole-plane bounds, through a box wider than the supports */
  double box[4], lo, hi;
  oc_enode_get_bounds(e, box, &lo, &hi);
  oc_enode_bound b;
  oc_enode_bound_in(e, cx - 4 * R, cy - 4 * R, cx + 4 * R, cy + 4 * R, &b);
  ck_assert(b.lf <= oc_enode_lipschitz(e) * (1 + 1e-12));
  ck_assert(b.flo >= lo - 1e-9 && b.fhi <= hi + 1e-9);
}

START_TEST(disc_formula) {
  oc_enode *d = disc(10, -5, 4, 7, OC_ENOISE_NONE, 0, 1, 1);
  oct_rng r = oct_rng_new(1);
  for (int i = 0; i < 200; i++) {
    double x = oct_unif(&r, 4, 16), y = oct_unif(&r, -11, 1);
    oc_enode_sample s;
    oc_enode_eval(d, x, y, &s);
    double dist = hypot(x - 10, y + 5);
    ck_assert_double_eq_tol(s.a, wyv(dist / 4), 1e-14);
    ck_assert(s.f == 7 && s.fx == 0 && s.fy == 0);
  }
  double box[4];
  oc_enode_get_bounds(d, box, NULL, NULL);
  ck_assert(box[0] == 6 && box[1] == -9 && box[2] == 14 && box[3] == -1);
  /* a lone disc shows terrain (alpha >= 1/2) only for d <= 0.4542 r */
  oc_enode_sample s;
  oc_enode_eval(d, 10 + 0.454 * 4, -5, &s);
  ck_assert(s.a > 0.5);
  oc_enode_eval(d, 10 + 0.455 * 4, -5, &s);
  ck_assert(s.a < 0.5);
  ck_assert_str_eq(oc_enode_kind(d), "disc");
  oc_enode_release(d);
}
END_TEST

START_TEST(disc_noises) {
  oc_enoise_kind kinds[3] = {OC_ENOISE_PLAIN, OC_ENOISE_TURBULENCE,
                             OC_ENOISE_RIDGED};
  for (int k = 0; k < 3; k++) {
    oc_enode *d = disc(0, 0, 100, 20, kinds[k], 15, 40, 6);
    double lo, hi;
    oc_enode_get_bounds(d, NULL, &lo, &hi);
    /* ranges: plain [h - sum a, h + sum a], the others [h, h + sum a] */
    double asum = 15 * (2 - ldexp(1, 1 - 6));
    ck_assert_double_eq_tol(hi, 20 + asum, 1e-9);
    ck_assert_double_eq_tol(lo, kinds[k] == OC_ENOISE_PLAIN ? 20 - asum : 20,
                            1e-9);
    oct_rng r = oct_rng_new(3 + k);
    for (int i = 0; i < 100; i++)
      check_gradient(d, oct_unif(&r, -90, 90), oct_unif(&r, -90, 90), 2e-4);
    check_bounds(d, 0, 0, 100);
    /* in a box much smaller than the wavelength, plain and turbulent sums
    ** are bounded from the octaves' values at its centre: the range is a
    ** fraction of the whole plane's (2 lambda rho for the first octave) */
    oc_enode_bound b;
    oc_enode_bound_in(d, 10, 10, 11, 11, &b);
    if (kinds[k] != OC_ENOISE_RIDGED)
      ck_assert_msg(b.fhi - b.flo < 0.7 * (hi - lo), "%s: [%g, %g] in [%g, %g]",
                    oc_enode_kind(d), b.flo, b.fhi, lo, hi);
    /* alpha's slope: 0 on a box of the square outside the circle, below
    ** the global bound near the centre (x < 1/sqrt(5)) */
    oc_enode_bound_in(d, 80, 80, 99, 99, &b);
    ck_assert(b.la == 0 && b.ahi == 0);
    oc_enode_bound_in(d, -10, -10, 10, 10, &b);
    double x = hypot(10, 10) / 100, kk = 1 - x * x;
    ck_assert_double_eq_tol(b.la, 6 * x * kk * kk / 100, 1e-12);
    ck_assert(b.la < 0.9 * 1.7173002067198386 / 100);
    oc_enode_release(d);
  }
}
END_TEST

/* The reference sum of a disc's noise at (u, v) = p - c: octave i is
** a_i eta_i(s_i p) with its own seed, summed one octave at a time through
** oc_eta (plain, |eta| or the ridged chain t_i = w_i (1 - |eta_i|)^2,
** w_i = clamp(2 t_(i-1), 0, 1)), under a footprint ft weighted
** b(log2(w_i / foot)) (the lod filter, with its gradient's terms), t_0
** = log2 w - log2 foot, both logarithms made inline as a disc makes them
** (enode.h, oc_edisc_lw, and disc.c: core/log2.h's oc_log2 and
** oc_log2_any). */
static double ref_noise(const oc_enoise *nz, double u, double v,
                        const oc_efoot *ft, double g[2]) {
  double sum = 0, a = nz->amplitude, s = 1 / nz->wavelength, prev = 1;
  double pg[2] = {0, 0}, t0 = 0, dt = 0, c = 0;
  g[0] = g[1] = 0;
  if (ft) {
    t0 = oc_log2(nz->wavelength) - oc_log2_any(ft->v);
    dt = log2(nz->lacunarity);
    c = -1 / (ft->v * 0.69314718055994530942);
  }
  for (int i = 0; i < nz->octaves; i++, s *= nz->lacunarity) {
    double db = 0, bw = ft ? oc_elod_b(t0 - i * dt, &db) : 1, a0 = a, e[2];
    if (bw == 0) break;
    a = a0 * bw;
    uint64_t sd =
        oc_mix64(nz->seed + 0x9e3779b97f4a7c15ull * (uint64_t)(i + 1));
    double eta = oc_eta(sd, s * u, s * v, e), sg = eta < 0 ? -1 : 1, t;
    double tg[2] = {s * e[0], s * e[1]}; /* grad of the term */
    if (nz->kind == OC_ENOISE_PLAIN) {
      t = eta;
    } else if (nz->kind == OC_ENOISE_TURBULENCE) {
      t = fabs(eta), tg[0] = s * sg * e[0], tg[1] = s * sg * e[1];
    } else {
      double r = 1 - fabs(eta), w = i ? 2 * prev : 1, k = -2 * r * sg * s;
      double gw[2] = {0, 0};
      if (w >= 1 || w <= 0)
        w = w >= 1 ? 1 : 0;
      else if (i)
        gw[0] = 2 * pg[0], gw[1] = 2 * pg[1];
      t = w * r * r, prev = t;
      tg[0] = pg[0] = r * r * gw[0] + w * k * e[0];
      tg[1] = pg[1] = r * r * gw[1] + w * k * e[1];
    }
    sum += a * t;
    g[0] += a * tg[0], g[1] += a * tg[1];
    if (db != 0)
      g[0] += a0 * t * db * c * ft->gx, g[1] += a0 * t * db * c * ft->gy;
    a = a0 * nz->gain;
  }
  return sum;
}

START_TEST(disc_matches_octave_sum) {
  /* A disc evaluates its octaves two at a time (core/noise.c,
  ** oc_noise3_z0_multi); f is height + the reference sum above bit for
  ** bit and its gradient the reference's within a few ulps (the reference
  ** groups the ridged chain's products differently), at full detail and
  ** under footprints that filter some octaves, for every kind, 1 to 16
  ** octaves, default and other gains and lacunarities. */
  oc_enoise_kind kinds[3] = {OC_ENOISE_PLAIN, OC_ENOISE_TURBULENCE,
                             OC_ENOISE_RIDGED};
  oct_rng r = oct_rng_new(91);
  int n = 0;
  double worst = 0;
  for (int k = 0; k < 3; k++)
    for (int oct = 1; oct <= 16; oct++) {
      oc_error err;
      double gain = oct % 3 ? 0.5 : 0.45, lac = oct % 3 ? 2 : 2.13;
      oc_enode_disc_params p = {
          5, -7, 300, 20, {kinds[k], 12, 80, oct, gain, lac, 7 + oct}};
      oc_enode *d = EOK(oc_enode_disc(&p, &err));
      oc_enoise nz;
      oc_edisc_noise(d, &nz);
      for (int i = 0; i < 20; i++, n++) {
        double x = oct_unif(&r, -250, 250), y = oct_unif(&r, -250, 250);
        oc_efoot ft = {oct_unif(&r, 0.01, 40), oct_unif(&r, -0.5, 0.5),
                       oct_unif(&r, -0.5, 0.5)};
        const oc_efoot *fp = i % 2 ? &ft : NULL;
        oc_enode_sample s;
        oc_edisc_ev(d, x, y, fp, OC_EV_GRAD, &s);
        double g[2], f = 20 + ref_noise(&nz, x - 5, y + 7, fp, g);
        double tol = 0, gt = 1e-12 * (1 + hypot(g[0], g[1]));
        ck_assert_msg(fabs(s.f - f) <= tol && fabs(s.fx - g[0]) <= gt &&
                          fabs(s.fy - g[1]) <= gt,
                      "kind %d, %d octaves at (%g, %g): f %.17g vs %.17g, "
                      "grad (%.17g, %.17g) vs (%.17g, %.17g)",
                      k, oct, x, y, s.f, f, s.fx, s.fy, g[0], g[1]);
        worst = fmax(worst,
                     hypot(s.fx - g[0], s.fy - g[1]) / (1 + hypot(g[0], g[1])));
        /* without the gradient: the same f */
        oc_enode_sample s0;
        oc_edisc_ev(d, x, y, fp, 0, &s0);
        ck_assert(s0.f == s.f);
      }
      oc_enode_release(d);
    }
  ck_assert_int_eq(n, 960);
  printf("disc against the octave sum: the same f, gradients within %g "
         "(relative)\n",
         worst);
}
END_TEST

START_TEST(efmax_is_fmax) {
  /* the inline fmax and fmin of the box queries give libm's bits on
  ** every pair of special and ordinary values (signed zeros, infinities,
  ** NaN, denormals). libm's functions through pointers: at -O1 (the
  ** sanitizer build) gcc expands fmax and fmin inline, and its expansion
  ** differs from libm's on the signed zeros. */
  double (*volatile lmax)(double, double) = fmax;
  double (*volatile lmin)(double, double) = fmin;
  const double v[] = {0.0,      -0.0,      1.0, -1.0, 0x1p-1074, -0x1p-1074,
                      INFINITY, -INFINITY, NAN, 3.5,  -2.25,     1e300};
  int n = (int)(sizeof v / sizeof *v), differ = 0, pairs = 0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++, pairs++) {
      double a = oc_fmax(v[i], v[j]), b = lmax(v[i], v[j]);
      double c = oc_fmin(v[i], v[j]), d = lmin(v[i], v[j]);
      differ += memcmp(&a, &b, sizeof a) != 0 || memcmp(&c, &d, sizeof c) != 0;
    }
  ck_assert_int_eq(pairs, 144);
  ck_assert_int_eq(differ, 0);
}
END_TEST

START_TEST(disc_local_bounds) {
  /* In boxes small against the wavelength a disc bounds its noise from
  ** each octave's value and gradient at the box's centre and the proved
  ** Hessian bound of the noise: the ranges and slopes must hold at every
  ** sampled point (corners included) of boxes from 1/1000 to a third of
  ** the wavelength, for every kind and several seeds, and be well below
  ** the whole plane's in the smallest ones. */
  oc_enoise_kind kinds[3] = {OC_ENOISE_PLAIN, OC_ENOISE_TURBULENCE,
                             OC_ENOISE_RIDGED};
  oct_rng r = oct_rng_new(77);
  double worst = 0; /* largest sampled |grad f| / lf */
  for (int k = 0; k < 3; k++) {
    double small = 0, glob = 0; /* mean lf in boxes of wl / 300 */
    int nsmall = 0;
    for (int sd = 0; sd < 6; sd++) {
      oc_error err;
      oc_enode_disc_params p = {
          3, -2, 400, 20, {kinds[k], 12, 50, 5, 0, 0, 1000 + sd}};
      oc_enode *d = EOK(oc_enode_disc(&p, &err));
      glob = oc_enode_lipschitz(d);
      for (int i = 0; i < 150; i++) {
        double w = 50 * pow(10, oct_unif(&r, -3, -0.5));
        double x0 = oct_unif(&r, -150, 150), y0 = oct_unif(&r, -150, 150);
        double x1 = x0 + w, y1 = y0 + w * oct_unif(&r, 0.3, 1);
        oc_enode_bound b;
        oc_enode_bound_in(d, x0, y0, x1, y1, &b);
        for (int j = 0; j < 40; j++) {
          double px = j < 4 ? (j & 1 ? x1 : x0) : oct_unif(&r, x0, x1);
          double py = j < 4 ? (j & 2 ? y1 : y0) : oct_unif(&r, y0, y1);
          oc_enode_sample sp;
          oc_enode_eval(d, px, py, &sp);
          double m = 1e-9 * (1 + fabs(b.flo) + fabs(b.fhi));
          ck_assert_msg(sp.f >= b.flo - m && sp.f <= b.fhi + m,
                        "kind %d: f %.17g outside [%.17g, %.17g]", k, sp.f,
                        b.flo, b.fhi);
          double gn = hypot(sp.fx, sp.fy);
          ck_assert_msg(gn <= b.lf * (1 + 1e-9), "kind %d: |grad f| %g > %g", k,
                        gn, b.lf);
          worst = fmax(worst, gn / b.lf);
        }
        if (w < 50.0 / 300) small += b.lf, nsmall++;
      }
      oc_enode_release(d);
    }
    small /= nsmall;
    printf("disc %s noise: mean slope bound in boxes of 1/300 wavelength "
           "%.3f, whole plane %.3f\n",
           kinds[k] == OC_ENOISE_PLAIN        ? "plain"
           : kinds[k] == OC_ENOISE_TURBULENCE ? "turbulent"
                                              : "ridged",
           small, glob);
    ck_assert(nsmall > 50 && small < 0.6 * glob);
  }
  printf("disc local bounds: sampled |grad f| up to %.3f of the bound\n",
         worst);
  ck_assert(worst > 0.5);
  /* a small box in a corner of the disc's square, outside its circle:
  ** alpha = 0 on it, so no noise evaluated for a local f bound (its f
  ** counts nowhere): the whole plane's f bound, alpha's 0; a box just
  ** inside the circle gets its local bound */
  oc_error err;
  oc_enode_disc_params p = {
      3, -2, 400, 20, {OC_ENOISE_PLAIN, 12, 50, 5, 0, 0, 0}};
  oc_enode *d = EOK(oc_enode_disc(&p, &err));
  double box[4], lo, hi, c = 3 + 400 * 0.95, e = -2 + 400 * 0.95;
  oc_enode_get_bounds(d, box, &lo, &hi);
  oc_enode_bound b;
  oc_enode_bound_in(d, c, e, c + 1, e + 1, &b);
  ck_assert(b.alo == 0 && b.ahi == 0 && b.la == 0);
  ck_assert(b.flo == lo && b.fhi == hi && b.lf == oc_enode_lipschitz(d));
  oc_enode_bound_in(d, 3 + 280, -2 + 280, 3 + 281, -2 + 281, &b);
  ck_assert(b.ahi > 0 && b.fhi - b.flo < 0.5 * (hi - lo));
  oc_enode_release(d);
}
END_TEST

START_TEST(blend_formula) {
  oc_error err;
  oc_enode *a = disc(0, 0, 10, 5, OC_ENOISE_PLAIN, 2, 6, 3);
  oc_enode *b = disc(8, 0, 10, 15, OC_ENOISE_RIDGED, 3, 5, 3);
  oc_enode *k[2] = {a, b};
  oc_enode *e = EOK(oc_enode_blend(k, 2, &err));
  oct_rng r = oct_rng_new(5);
  for (int i = 0; i < 300; i++) {
    double x = oct_unif(&r, -12, 20), y = oct_unif(&r, -12, 12);
    oc_enode_sample s, sa, sb;
    oc_enode_eval(e, x, y, &s);
    oc_enode_eval(a, x, y, &sa);
    oc_enode_eval(b, x, y, &sb);
    double S = sa.a + sb.a, N = sa.a * sa.f + sb.a * sb.f;
    ck_assert_double_eq_tol(s.a, S, 1e-12);
    ck_assert_double_eq_tol(s.f, S >= 0.5 ? N / S : N / 0.5, 1e-9);
    if (fabs(S - 0.5) > 1e-3) check_gradient(e, x, y, 1e-4);
  }
  check_bounds(e, 4, 0, 14);
  /* flat discs: the transition alone, where the appendix's bound is
  ** nearly reached (a bound 0.6 times as large fails here) */
  oc_enode *fa = disc(0, 0, 10, 0, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *fb = disc(12, 0, 10, 10, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *fk[2] = {fa, fb};
  oc_enode *fe = EOK(oc_enode_blend(fk, 2, &err));
  check_bounds(fe, 6, 0, 10);
  oct_rng r2 = oct_rng_new(55);
  double steepest = 0, lf = oc_enode_lipschitz(fe);
  for (int i = 0; i < 20000; i++) {
    oc_enode_sample q;
    oc_enode_eval(fe, oct_unif(&r2, 0, 12), oct_unif(&r2, -6, 6), &q);
    steepest = fmax(steepest, hypot(q.fx, q.fy));
  }
  ck_assert_msg(steepest > 0.6 * lf && steepest <= lf, "steepest %g, bound %g",
                steepest, lf);
  oc_enode_release(fa);
  oc_enode_release(fb);
  oc_enode_release(fe);
  oc_enode_release(a);
  oc_enode_release(b);
  oc_enode_release(e);
}
END_TEST

START_TEST(replace_and_add_formulas) {
  oc_error err;
  oc_enode *a = disc(0, 0, 50, 10, OC_ENOISE_PLAIN, 4, 12, 4);
  oc_enode *b = disc(5, 5, 12, -3, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *rep = EOK(oc_enode_replace(a, b, 0, &err));
  oc_enode *lerp = EOK(oc_enode_replace(a, b, 1, &err));
  oc_enode_add_params ap = {0}, bp = {1, 1, 9, 4, 0, 0, 0, 0};
  oc_enode *add = EOK(oc_enode_add(a, b, &ap, &err));
  oc_enode *addb = EOK(oc_enode_add(a, b, &bp, &err));
  oct_rng r = oct_rng_new(6);
  for (int i = 0; i < 300; i++) {
    double x = oct_unif(&r, -20, 25), y = oct_unif(&r, -20, 25);
    oc_enode_sample s, sa, sb;
    oc_enode_eval(a, x, y, &sa);
    oc_enode_eval(b, x, y, &sb);
    double w = fmin(fmax(sb.a, 0), 1);
    oc_enode_eval(rep, x, y, &s);
    ck_assert_double_eq_tol(s.f, (1 - w) * sa.f + w * sb.f, 1e-9);
    ck_assert_double_eq_tol(s.a, sa.a, 1e-15);
    oc_enode_eval(lerp, x, y, &s);
    ck_assert_double_eq_tol(s.a, (1 - w) * sa.a + w * w, 1e-12);
    oc_enode_eval(add, x, y, &s);
    ck_assert_double_eq_tol(s.f, sa.f + w * sb.f, 1e-9);
    oc_enode_eval(addb, x, y, &s);
    double t = (9 - sa.f) / 4, W = t <= 0   ? 0
                                   : t >= 1 ? 1
                                            : t * t * (3 - 2 * t);
    ck_assert_double_eq_tol(s.f, sa.f + w * W * sb.f, 1e-9);
    ck_assert_double_eq_tol(s.a, sa.a + w * w, 1e-12);
    check_gradient(rep, x, y, 1e-4);
    check_gradient(lerp, x, y, 1e-4);
    check_gradient(add, x, y, 1e-4);
    check_gradient(addb, x, y, 1e-4);
  }
  check_bounds(rep, 5, 5, 30);
  check_bounds(lerp, 5, 5, 30);
  check_bounds(add, 5, 5, 30);
  check_bounds(addb, 5, 5, 30);
  /* in boxes where f_A >= below_z, the altitude weight is 0: addb is A
  ** there; where f_A <= below_z - fade, it is 1: addc (below 16) is add */
  oc_enode_add_params cp = {1, 1, 16, 3, 0, 0, 0, 0}, sp = {.sum_weight = 1};
  oc_enode *addc = EOK(oc_enode_add(a, b, &cp, &err));
  oc_enode *adds = EOK(oc_enode_add(a, b, &sp, &err));
  int above = 0, under = 0;
  for (int i = 0; i < 400; i++) {
    double x0 = oct_unif(&r, -6, 16), y0 = oct_unif(&r, -6, 16);
    oc_enode_bound ba, bb, bc, bd;
    oc_enode_bound_in(a, x0, y0, x0 + 0.2, y0 + 0.2, &ba);
    oc_enode_bound_in(addb, x0, y0, x0 + 0.2, y0 + 0.2, &bb);
    oc_enode_bound_in(addc, x0, y0, x0 + 0.2, y0 + 0.2, &bc);
    oc_enode_bound_in(adds, x0, y0, x0 + 0.2, y0 + 0.2, &bd);
    if (ba.flo >= 9) {
      above++;
      ck_assert(bb.lf == ba.lf && bb.flo == ba.flo && bb.fhi == ba.fhi);
    }
    if (ba.fhi < 13 - 1e-6) {
      under++;
      ck_assert(bc.lf == bd.lf && bc.flo == bd.flo && bc.fhi == bd.fhi);
    }
  }
  ck_assert_msg(above > 0 && under > 0, "above %d, under %d", above, under);
  oc_enode_release(addc);
  oc_enode_release(adds);
  oc_enode *all[6] = {a, b, rep, lerp, add, addb};
  for (int i = 0; i < 6; i++)
    oc_enode_release(all[i]);
}
END_TEST

/* The slope weight of add: A's slope angle from central differences of
** step h, weight 1 up to `slope`, smoothstep down to 0 over `slope_fade`. */
static double slope_weight(const oc_enode *a, double x, double y, double deg,
                           double fade, double h) {
  oc_enode_sample e, w, n, s;
  oc_enode_eval(a, x + h, y, &e);
  oc_enode_eval(a, x - h, y, &w);
  oc_enode_eval(a, x, y + h, &n);
  oc_enode_eval(a, x, y - h, &s);
  double th = atan(hypot((e.f - w.f) / (2 * h), (n.f - s.f) / (2 * h)));
  double t = (th * 180 / PI - deg) / fade;
  return t <= 0 ? 1 : t >= 1 ? 0 : 1 - t * t * (3 - 2 * t);
}

START_TEST(add_slope_weight) {
  oc_error err;
  /* slopes of A from flat to about 60 degrees; B lifts by about 6 */
  oc_enode *a = disc(0, 0, 60, 10, OC_ENOISE_PLAIN, 6, 25, 3);
  oc_enode *b = disc(3, -2, 40, 6, OC_ENOISE_PLAIN, 2, 9, 2);
  oc_enode_add_params sp = {0, 0, 0, 0, 1, 25, 15, 1.5};
  oc_enode_add_params bp = {1, 1, 14, 5, 1, 10, 20, 0.8};
  oc_enode *add = EOK(oc_enode_add(a, b, &sp, &err));
  oc_enode *addb = EOK(oc_enode_add(a, b, &bp, &err));
  oct_rng r = oct_rng_new(61);
  int one = 0, zero = 0, mid = 0;
  for (int i = 0; i < 400; i++) {
    double x = oct_unif(&r, -25, 25), y = oct_unif(&r, -25, 25);
    oc_enode_sample s, sa, sb;
    oc_enode_eval(a, x, y, &sa);
    oc_enode_eval(b, x, y, &sb);
    double c = fmin(fmax(sb.a, 0), 1);
    double S = slope_weight(a, x, y, 25, 15, 1.5);
    one += S == 1, zero += S == 0, mid += S > 0 && S < 1;
    oc_enode_eval(add, x, y, &s);
    ck_assert_double_eq_tol(s.f, sa.f + c * S * sb.f, 1e-9);
    ck_assert_double_eq_tol(s.a, sa.a, 1e-15);
    /* with the altitude weight and the summed weight */
    double t = (14 - sa.f) / 5, W = t <= 0   ? 0
                                    : t >= 1 ? 1
                                             : t * t * (3 - 2 * t);
    double S2 = slope_weight(a, x, y, 10, 20, 0.8);
    oc_enode_eval(addb, x, y, &s);
    ck_assert_double_eq_tol(s.f, sa.f + c * W * S2 * sb.f, 1e-9);
    ck_assert_double_eq_tol(s.a, sa.a + c * c, 1e-12);
    check_gradient(add, x, y, 1e-4);
    check_gradient(addb, x, y, 1e-4);
  }
  /* the test sees the whole weight: 1, 0 and the fade between */
  ck_assert_msg(one > 20 && zero > 20 && mid > 40, "%d %d %d", one, zero, mid);
  check_bounds(add, 0, 0, 30);
  check_bounds(addb, 0, 0, 30);
  /* in boxes where A is gentle by its own bound, the slope weight is 1:
  ** the bounds are those of the add without it */
  oc_enode *a0 = disc(0, 0, 60, 10, OC_ENOISE_PLAIN, 0.5, 25, 3);
  oc_enode_add_params gp = {0, 0, 0, 0, 1, 45, 10, 1}, pp = {0};
  oc_enode *g = EOK(oc_enode_add(a0, b, &gp, &err));
  oc_enode *plain = EOK(oc_enode_add(a0, b, &pp, &err));
  oc_enode_bound bg, bpl;
  oc_enode_bound_in(g, -5, -5, 5, 5, &bg);
  oc_enode_bound_in(plain, -5, -5, 5, 5, &bpl);
  ck_assert(bg.lf == bpl.lf && bg.flo == bpl.flo && bg.fhi == bpl.fhi);
  ck_assert(oc_enode_lipschitz(g) == oc_enode_lipschitz(plain));
  /* bad values name the field */
  struct {
    oc_enode_add_params p;
    const char *field;
  } bad[] = {
      {{0, 0, 0, 0, 1, NAN, 10, 1}, "'slope'"},
      {{0, 0, 0, 0, 1, -1, 10, 1}, "'slope'"},
      {{0, 0, 0, 0, 1, 90, 10, 1}, "'slope'"},
      {{0, 0, 0, 0, 1, INFINITY, 10, 1}, "'slope'"},
      {{0, 0, 0, 0, 1, 30, 0, 1}, "'slope_fade'"},
      {{0, 0, 0, 0, 1, 30, NAN, 1}, "'slope_fade'"},
      {{0, 0, 0, 0, 1, 30, -5, 1}, "'slope_fade'"},
      {{0, 0, 0, 0, 1, 30, 10, -1}, "'slope_step'"},
      {{0, 0, 0, 0, 1, 30, 10, NAN}, "'slope_step'"},
      {{0, 0, 0, 0, 1, 30, 10, INFINITY}, "'slope_step'"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    err.msg[0] = 0;
    ck_assert(oc_enode_add(a, b, &bad[i].p, &err) == NULL);
    ck_assert_msg(strstr(err.msg, bad[i].field), "%zu: %s", i, err.msg);
  }
  oc_enode *all[7] = {a, b, add, addb, a0, g, plain};
  for (int i = 0; i < 7; i++)
    oc_enode_release(all[i]);
}
END_TEST

START_TEST(transform_concatenates) {
  oc_error err;
  oc_enode *a = disc(1, 2, 6, 3, OC_ENOISE_PLAIN, 2, 3, 3);
  oc_enode_xform x1 = {10, -4, 30, 2, 1.5, 7}, x2 = {-3, 5, -75, 0.5, -2, 1};
  oc_enode *t1 = EOK(oc_enode_transform(a, &x1, &err));
  oc_enode *t2 = EOK(oc_enode_transform(t1, &x2, &err));
  oc_enode_stats st;
  ck_assert_int_eq(oc_enode_get_stats(t2, &st, &err), OC_OK);
  ck_assert_uint_eq(st.nodes, 2); /* concatenated: one transform */
  oct_rng r = oct_rng_new(8);
  for (int i = 0; i < 200; i++) {
    double x = oct_unif(&r, -30, 30), y = oct_unif(&r, -30, 30);
    /* p = s2 R2 p' + t2, p' = s1 R1 p'' + t1, by hand */
    double c2 = cos(-75 * PI / 180), s2 = sin(-75 * PI / 180);
    double u = (x + 3) / 0.5, v = (y - 5) / 0.5;
    double px = c2 * u + s2 * v, py = -s2 * u + c2 * v;
    double c1 = cos(30 * PI / 180), s1 = sin(30 * PI / 180);
    u = (px - 10) / 2, v = (py + 4) / 2;
    double qx = c1 * u + s1 * v, qy = -s1 * u + c1 * v;
    oc_enode_sample s, sa;
    oc_enode_eval(t2, x, y, &s);
    oc_enode_eval(a, qx, qy, &sa);
    ck_assert_double_eq_tol(s.a, sa.a, 1e-12);
    ck_assert_double_eq_tol(s.f, -2 * (1.5 * sa.f + 7) + 1, 1e-9);
    check_gradient(t2, x, y, 1e-4);
  }
  double box[4];
  oc_enode_get_bounds(t2, box, NULL, NULL);
  check_bounds(t2, (box[0] + box[2]) / 2, (box[1] + box[3]) / 2,
               box[2] - box[0]);
  oc_enode_release(a);
  oc_enode_release(t1);
  oc_enode_release(t2);
}
END_TEST

START_TEST(warp_bijective_only) {
  oc_error err;
  oc_enode *a = disc(0, 0, 30, 5, OC_ENOISE_RIDGED, 6, 10, 4);
  oc_enode_warp_params ok = {2, 40, 2, 5}, bad = {20, 10, 3, 5};
  oc_enode *w = EOK(oc_enode_warp(a, &ok, &err));
  oct_rng r = oct_rng_new(9);
  for (int i = 0; i < 200; i++)
    check_gradient(w, oct_unif(&r, -25, 25), oct_unif(&r, -25, 25), 2e-4);
  check_bounds(w, 0, 0, 35);
  ck_assert_ptr_null(oc_enode_warp(a, &bad, &err));
  ck_assert_int_eq(err.code, OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(err.msg, "bijection"));
  oc_enode_release(a);
  oc_enode_release(w);
}
END_TEST

START_TEST(dag_stats_and_source) {
  oc_error err;
  oc_enode *base = disc(0, 0, 1000, 50, OC_ENOISE_PLAIN, 30, 300, 5);
  oc_enode *hill = disc(100, 0, 200, 150, OC_ENOISE_RIDGED, 40, 80, 5);
  oc_enode_xform m = {300, 0, 45, 1, 1, 0};
  oc_enode *moved = EOK(oc_enode_transform(hill, &m, &err));
  oc_enode *k[3] = {base, hill, moved};
  oc_enode *e = EOK(oc_enode_blend(k, 3, &err));
  oc_enode_stats st;
  ck_assert_int_eq(oc_enode_get_stats(e, &st, &err), OC_OK);
  ck_assert_uint_eq(st.nodes, 4); /* hill shared */
  ck_assert_uint_eq(st.primitives, 2);
  /* nodes are allocated at their kind's size (enode.h): a noisy disc
  ** 8 + 4 parameters + amplitude, wavelength, seed and the noise's
  ** range and slope over the plane (8 each), gain and lacunarity the
  ** defaults (not stored); a transform 8 + a float box + its child + 8
  ** parameters; a blend 8 + float box and bound + a count + its 3
  ** children; each counted once */
  ck_assert_uint_eq(oc_enode_size(base), 8 + 4 * 8 + 5 * 8);
  ck_assert_uint_eq(oc_enode_size(hill), 80);
  ck_assert_uint_eq(oc_enode_size(moved), 8 + 16 + 8 + 8 * 8);
  ck_assert_uint_eq(oc_enode_size(e), 8 + 16 + 24 + 8 + 3 * 8);
  ck_assert_uint_eq(st.bytes, 80 + 80 + 96 + 80);
  /* the source answers the tree's own values and bounds */
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(e, NULL, &src, &err), OC_OK);
  /* the terrain box: inside Omega_0, around Omega_T (0.4542 r at least) */
  ck_assert(src.x0 >= -1000 && src.x0 <= -454 && src.x1 <= 1000 &&
            src.x1 >= 454);
  double g[2];
  oc_enode_sample s;
  oc_enode_eval(e, 120, 30, &s);
  ck_assert(src.height(src.ud, 120, 30, g) == s.f && g[0] == s.fx);
  double lo, hi;
  src.range(src.ud, 50, -50, 150, 50, &lo, &hi);
  oc_enode_bound b;
  oc_enode_bound_in(e, 50, -50, 150, 50, &b);
  ck_assert(lo == b.flo && hi == b.fhi);
  ck_assert(src.slope(src.ud, 50, -50, 150, 50) == b.lf);
  /* the joint callback: the same range and slope from one traversal */
  double blo, bhi, bl;
  ck_assert(src.bound != NULL);
  src.bound(src.ud, 50, -50, 150, 50, &blo, &bhi, &bl);
  ck_assert(blo == b.flo && bhi == b.fhi && bl == b.lf);
  /* a terrain over it: its surface is f where the base covers */
  oc_terrain_params tp = {0};
  tp.falloff = 20;
  oc_node *t = OCT_OK(oc_terrain(&src, &tp, &err));
  src.release(src.ud);
  oc_program *P = oct_compile(t, 0.5, 0);
  ck_assert_double_eq_tol(oc_program_eval(P, oct_v(120, 30, s.f)), 0.5, 1e-9);
  ck_assert(oc_program_eval(P, oct_v(120, 30, s.f - 5)) > 0.5);
  ck_assert(oc_program_eval(P, oct_v(120, 30, s.f + 5)) < 0.5);
  oc_program_free(P);
  double bad[4] = {0, 0, NAN, 1};
  ck_assert_int_eq(oc_enode_elevation(e, bad, &src, &err), OC_EINVAL);
  oc_enode *all[4] = {base, hill, moved, e};
  for (int i = 0; i < 4; i++)
    oc_enode_release(all[i]);
}
END_TEST

/* A straight river: f = q_z + its cross-section, alpha flat over the
** channel; a winding one: gradients and bounds where alpha > 0. */
START_TEST(curve_river_road) {
  oc_error err;
  oc_vec3 straight[2] = {{0, 0, 10}, {100, 0, 20}};
  oc_enode_river_params rp = {straight, 2, OC_ECURVE_LINEAR, OC_RIVER_RIVER, 0,
                              0,        0};
  oc_enode *r = EOK(oc_enode_river(&rp, &err));
  ck_assert_str_eq(oc_enode_kind(r), "curve");
  oc_enode_sample s;
  oc_enode_eval(r, 50, 0, &s); /* channel centre: bed at q_z - depth */
  ck_assert_double_eq_tol(s.f, 15 - 3, 1e-9);
  ck_assert_double_eq_tol(s.a, 1, 1e-15);
  ck_assert_double_eq_tol(s.fx, 0.1, 1e-9); /* the skeleton's grade */
  oc_enode_eval(r, 50, 10, &s);             /* bank top of the channel, w / 2 */
  ck_assert_double_eq_tol(s.f, 15 - 1.5, 1e-9);
  ck_assert_double_eq_tol(s.a, 1, 1e-15);
  oc_enode_eval(r, 50, -(10 + 12.5), &s); /* half-way up the bank */
  ck_assert_double_eq_tol(s.a, wyv(0.5), 1e-12);
  oc_enode_eval(r, 50, 36, &s); /* beyond the banks */
  ck_assert(s.a == 0 && fabs(s.f - 15) < 1e-9);
  oc_enode_eval(r, 120, 5, &s); /* past the end: straight on, round cap */
  ck_assert_double_eq_tol(s.a, wyv((hypot(20, 5) - 10) / 25), 1e-12);
  /* a winding road and river: gradients and bounds on the support */
  oc_vec3 wind[5] = {
      {0, 0, 0}, {100, 60, 5}, {200, -40, 12}, {300, 50, 8}, {400, 0, 3}};
  oc_enode_road_params dp = {wind, 5, OC_ECURVE_CATMULL, 0, -1, 0};
  oc_enode *road = EOK(oc_enode_road(&dp, &err));
  oc_enode_river_params wp = {wind, 5, OC_ECURVE_CATMULL, OC_RIVER_STREAM, 0,
                              0,    0};
  oc_enode *riv = EOK(oc_enode_river(&wp, &err));
  oc_enode *cs[2] = {road, riv};
  oct_rng g = oct_rng_new(17);
  for (int c = 0; c < 2; c++) {
    double lf = oc_enode_lipschitz(cs[c]),
           la = 1.7173002067198386 / (c ? 4 : 12);
    int n = 0;
    for (int i = 0; i < 20000 && n < 400; i++) {
      double x = oct_unif(&g, 0, 400), y = oct_unif(&g, -80, 80);
      oc_enode_eval(cs[c], x, y, &s);
      if (!(s.a > 1e-6 && s.a < 1 - 1e-6)) continue;
      n++;
      check_gradient(cs[c], x, y, 1e-3);
      ck_assert(hypot(s.fx, s.fy) <= lf);
      ck_assert(hypot(s.ax, s.ay) <= la * (1 + 1e-9));
    }
    ck_assert_int_ge(n, 100);
  }
  /* a corner, and a radius wider than the bends allow */
  oc_vec3 corner[3] = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}};
  oc_enode_river_params bp = {corner, 3, OC_ECURVE_LINEAR, OC_RIVER_STREAM, 0,
                              0,      0};
  ck_assert_ptr_null(oc_enode_river(&bp, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "corner"));
  oc_vec3 tight[4] = {{0, 0, 0}, {10, 10, 0}, {20, 0, 0}, {30, 10, 0}};
  oc_enode_river_params tp = {tight, 4, OC_ECURVE_CATMULL, OC_RIVER_MAIN, 0,
                              0,     0};
  ck_assert_ptr_null(oc_enode_river(&tp, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'radius'"));
  oc_vec3 one[1] = {{0, 0, 0}};
  oc_enode_river_params op = {one, 1, OC_ECURVE_CATMULL, OC_RIVER_STREAM, 0,
                              0,   0};
  ck_assert_ptr_null(oc_enode_river(&op, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'points'"));
  oc_enode_release(r);
  oc_enode_release(road);
  oc_enode_release(riv);
}
END_TEST

/* A replace's weight query of its curve (oc_ecurve_weight_in, the closest
** point out to R + rho answering the box test and the lazy sample): the
** bits of oc_ecurve_bound_in's decision and f bound, alpha's range and
** slope within its and holding on the box (from the distance found),
** and the bits of oc_ecurve_ev (OC_EV_LAZY), at random
** points and at points whose distance to the road is the box test's
** radius to within 1e-7 (where the box test itself decides); no box
** query but there. And a replace's model over the road: no box query near
** it (one per model before). */
START_TEST(curve_weight_in_one_search) {
  oc_error err;
  oc_vec3 P[16];
  for (int i = 0; i < 16; i++) {
    double u = (double)i / 15;
    P[i] = (oc_vec3){150 * sin(7.85 * u), -260 + 520 * u, 30 + 140 * u};
  }
  oc_enode_road_params dp = {P, 16, OC_ECURVE_CATMULL, 0, -1, 0};
  oc_enode *road = EOK(oc_enode_road(&dp, &err));
  oc_pcurve *sk = oc_ecurve_skeleton(P, 16, OC_ECURVE_CATMULL, &err);
  ck_assert_ptr_nonnull(sk);
  double Rc = 3.5 + 1.5 + 12, len = oc_curve_length(sk); /* (the preset's) */
  oct_rng g = oct_rng_new(2211);
  int boxes = 0, near = 0, zero = 0, band = 0, tight = 0;
  for (int i = 0; i < 6000; i++) {
    double x, y, R = 50 * pow(10, oct_unif(&g, -3, 0));
    if (i % 2) {
      x = oct_unif(&g, -200, 200), y = oct_unif(&g, -300, 300);
    } else {
      /* on the normal of a point of the skeleton, at the box test's
      ** radius (R + rho) within a few 1e-8 of it */
      oc_curve_point q;
      ck_assert(oc_curve_at(sk, oct_unif(&g, 0.05, 0.95) * len, &q));
      double rho = R * sqrt(2),
             d = (Rc + rho) * (1 + 3e-8 * oct_unif(&g, -1, 1));
      d *= (i / 2) % 2 ? 1 : -1;
      x = q.q.x + d * q.nx, y = q.q.y + d * q.ny;
    }
    oc_erect b = {x - R, y - R, x + R, y + R};
    oc_ebound ref, got;
    oc_enode_sample rs, gs;
    memset(&rs, 0, sizeof rs), memset(&gs, 0, sizeof gs);
    oc_ecurve_bound_in(road, &b, NULL, &ref);
    int nb = 0, k = oc_ecurve_weight_in(road, x, y, &b, &got, &gs, &nb);
    /* the box test's f bound; alpha's from the distance found, within
    ** the box test's and holding on the box */
    ck_assert(ref.flo == got.flo && ref.fhi == got.fhi && ref.lf == got.lf);
    ck_assert(got.alo >= ref.alo && got.ahi <= ref.ahi && got.la <= ref.la);
    ck_assert_int_eq(k, ref.ahi > 0);
    tight += k && (got.ahi < 1 || got.alo > 0 || got.la < ref.la / 2);
    for (int j = 0; k && j < 20; j++) {
      oc_enode_sample a;
      double px = x + R * oct_unif(&g, -1, 1), py = y + R * oct_unif(&g, -1, 1);
      oc_ecurve_ev(road, px, py, NULL, OC_EV_GRAD, &a);
      ck_assert_msg(a.a >= got.alo && a.a <= got.ahi,
                    "alpha %.17g outside [%.17g, %.17g]", a.a, got.alo,
                    got.ahi);
      ck_assert(hypot(a.ax, a.ay) <= got.la * (1 + 1e-9) + 1e-15);
    }
    boxes += nb;
    band += nb && i % 2 == 0;
    if (!k) {
      zero++;
      continue;
    }
    oc_ecurve_ev(road, x, y, NULL, OC_EV_LAZY, &rs);
    ck_assert_msg(!memcmp(&rs, &gs, sizeof rs), "sample at (%.17g, %.17g)", x,
                  y);
    near += gs.a > 0;
  }
  ck_assert_int_ge(near, 300);
  ck_assert_int_ge(zero, 300);
  ck_assert_int_ge(band, 100); /* the box test decided in the band */
  ck_assert_int_le(boxes - band, 30);
  ck_assert_int_ge(tight, 300);
  /* a replace over the road: near it the model makes no box query */
  oc_enode *hill = EOK(oc_enode_disc(
      &(oc_enode_disc_params){
          0, 0, 900, 50, {OC_ENOISE_NONE, 0, 1, 1, 0, 0, 0}},
      &err));
  oc_enode *rep = EOK(oc_enode_replace(hill, road, 0, &err));
  oc_curve_point q;
  ck_assert(oc_curve_at(sk, 0.5 * len, &q));
  oc_etaylor m;
  int nb = 0;
  oc_enode_taylor(rep, q.q.x + 4 * q.nx, q.q.y + 4 * q.ny, 2, &m, &nb);
  ck_assert_int_eq(nb, 0);
  oc_enode_sample s;
  oc_enode_ev(rep, q.q.x + 4 * q.nx, q.q.y + 4 * q.ny, NULL, 0, &s);
  ck_assert(m.f.v == s.f);
  oc_curve_free(sk);
  oc_enode_release(rep);
  oc_enode_release(hill);
  oc_enode_release(road);
}
END_TEST

/* A curve's f range in a box (where alpha > 0, as its bounds hold) is
** that of the pieces near the box, not the whole curve's: on bench_elev's
** fig22 road, climbing 140 m, boxes up to 40 m wide hold every sampled f
** where alpha > 0 and most span less than 30 m (the replace's model over
** the road is Lipschitz in that span: 22 % fewer height calls on fig22). */
START_TEST(curve_bound_is_local) {
  oc_error err;
  oc_vec3 P[16];
  for (int i = 0; i < 16; i++) {
    double u = (double)i / 15;
    P[i] = (oc_vec3){150 * sin(7.85 * u), -260 + 520 * u, 30 + 140 * u};
  }
  oc_enode_road_params dp = {P, 16, OC_ECURVE_CATMULL, 0, -1, 0};
  oc_enode *road = EOK(oc_enode_road(&dp, &err));
  double box[4], glo, ghi;
  oc_enode_get_bounds(road, box, &glo, &ghi);
  ck_assert(ghi - glo > 140);
  oct_rng g = oct_rng_new(2219);
  int active = 0, narrow = 0, samples = 0;
  for (int i = 0; i < 3000; i++) {
    double x = oct_unif(&g, -200, 200), y = oct_unif(&g, -300, 300);
    double w = 40 * pow(10, oct_unif(&g, -2, 0));
    oc_enode_bound b;
    oc_enode_bound_in(road, x, y, x + w, y + w, &b);
    if (!(b.ahi > 0)) continue;
    active++;
    ck_assert(b.flo >= glo && b.fhi <= ghi);
    narrow += b.fhi - b.flo < 30;
    for (int k = 0; k < 40; k++) {
      oc_enode_sample s;
      oc_enode_eval(road, x + w * oct_unif(&g, 0, 1),
                    y + w * oct_unif(&g, 0, 1), &s);
      if (!(s.a > 0)) continue;
      samples++;
      ck_assert_msg(s.f >= b.flo && s.f <= b.fhi, "f %.15g outside [%g, %g]",
                    s.f, b.flo, b.fhi);
    }
  }
  ck_assert_int_ge(active, 300);
  ck_assert_int_ge(samples, 3000);
  ck_assert_int_ge(narrow, active * 9 / 10);
  oc_enode_release(road);
}
END_TEST

START_TEST(bad_input) {
  oc_error err;
  oc_enode_disc_params p = {0, 0, NAN, 0, {OC_ENOISE_NONE, 0, 1, 1, 0, 0, 0}};
  ck_assert_ptr_null(oc_enode_disc(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'radius'"));
  p.radius = 1;
  p.noise = (oc_enode_noise){OC_ENOISE_PLAIN, 1, 0, 3, 0, 0, 0};
  ck_assert_ptr_null(oc_enode_disc(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'noise.wavelength'"));
  p.noise = (oc_enode_noise){OC_ENOISE_PLAIN, 1e308, 1, 3, 0, 0, 0};
  ck_assert_ptr_null(oc_enode_disc(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "overflow"));
  p.noise = (oc_enode_noise){OC_ENOISE_PLAIN, 1, 1, 17, 0, 0, 0};
  ck_assert_ptr_null(oc_enode_disc(&p, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'noise.octaves'"));
  p.noise.octaves = 3;
  oc_enode *d = EOK(oc_enode_disc(&p, &err));
  oc_enode_xform x = {0, 0, 0, -1, 1, 0};
  ck_assert_ptr_null(oc_enode_transform(d, &x, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'scale'"));
  oc_enode_add_params ap = {.below = 1};
  ck_assert_ptr_null(oc_enode_add(d, d, &ap, &err));
  ck_assert_ptr_nonnull(strstr(err.msg, "'fade'"));
  ck_assert_ptr_null(oc_enode_blend(NULL, 0, &err));
  oc_enode_sample s;
  oc_enode_eval(d, NAN, 0, &s);
  ck_assert(isnan(s.f) && isnan(s.a));
  oc_enode_release(d);
}
END_TEST

/* The altitude weight's slope term of add in a box: chi |W'| lambda_A +
** lambda_c W(thi), |W'| at most its value where f_A can be (6 t (1 - t) /
** fade at the t nearest 1/2), against the whole plane's lambda_c + 1.5 /
** fade lambda_A: never looser, often much tighter, and sound (every box's
** bound holds on random pairs and gradients in it). */
/* The sanitizer pass checks memory on fewer rows and boxes (the release
** pass runs them all). */
#ifdef __SANITIZE_ADDRESS__
#define ROWS_N 3
#define ALT_BOXES 150
#else
#define ROWS_N 9
#define ALT_BOXES 400
#endif

START_TEST(add_altitude_slope_bound) {
  oc_error err;
  oc_enode *a = disc(0, 0, 60, 10, OC_ENOISE_RIDGED, 12, 15, 4);
  oc_enode *b = disc(8, -4, 30, 25, OC_ENOISE_PLAIN, 3, 8, 3);
  oc_enode_add_params bp = {0, 1, 16, 5, 0, 0, 0, 0};
  oc_enode *e = EOK(oc_enode_add(a, b, &bp, &err));
#ifndef __SANITIZE_ADDRESS__ /* (the release pass checks soundness) */
  check_bounds(e, 5, 0, 35);
  check_bounds(e, 5, 0, 4);
#endif
  oct_rng r = oct_rng_new(31);
  double sum = 0;
  int n = 0, tighter = 0;
  for (int i = 0; i < ALT_BOXES; i++) {
    double w = pow(10, oct_unif(&r, -1, 1));
    double x0 = oct_unif(&r, -30, 30), y0 = oct_unif(&r, -30, 30);
    oc_enode_bound A, B, E;
    oc_enode_bound_in(a, x0, y0, x0 + w, y0 + w, &A);
    oc_enode_bound_in(b, x0, y0, x0 + w, y0 + w, &B);
    oc_enode_bound_in(e, x0, y0, x0 + w, y0 + w, &E);
    double chi = fmin(fmax(B.ahi, 0), 1);
    /* the region's weight may be 0 (then E = A) or 1 (then no term) */
    if (!(A.flo < 16 && A.fhi > 11 && chi > 0)) continue;
    double old = A.lf +
                 (B.la + 1.5 / 5 * A.lf) * fmax(fabs(B.flo), fabs(B.fhi)) +
                 chi * B.lf;
    ck_assert_msg(E.lf <= old * (1 + 1e-9), "box %d: %g > %g", i, E.lf, old);
    sum += E.lf / old, n++;
    tighter += E.lf < 0.8 * old;
  }
  printf("add: altitude weight's slope bound in %d boxes, mean %.3f of the "
         "whole plane's rule, %d below 0.8 of it\n",
         n, sum / n, tighter);
  ck_assert_int_gt(n, ALT_BOXES / 4);
  ck_assert_int_gt(tighter, n / 4);
  oc_enode_release(e);
  oc_enode_release(a);
  oc_enode_release(b);
}
END_TEST

/* Rows (oc_enode_ev_row, and the source's height_weight_row) give every
** point's f and alpha bit for bit, for each kind of row code (discs of
** each noise, a lone disc's lazy zeros, blends, replaces plain and
** lerped) and the kinds that take points one by one, under each want;
** rows crossing the children's boxes at their edges and beyond. */
static int same(double a, double b) {
  return !memcmp(&a, &b, sizeof a);
}

/* A river crossing the test trees' discs from west to east. */
static oc_enode *river_across(oc_error *err) {
  oc_vec3 pts[3] = {{-500, -100, 40}, {0, 10, 45}, {500, 120, 50}};
  oc_enode_river_params rp = {pts, 3, OC_ECURVE_CATMULL, OC_RIVER_RIVER, 0,
                              0,   0};
  return oc_enode_river(&rp, err);
}

START_TEST(rows_match_points) {
  oc_error err;
  oc_enode *d[4] = {disc(0, 0, 600, 50, OC_ENOISE_PLAIN, 30, 200, 5),
                    disc(150, 40, 180, 120, OC_ENOISE_RIDGED, 40, 60, 6),
                    disc(-200, -60, 150, 80, OC_ENOISE_TURBULENCE, 20, 40, 4),
                    disc(60, -30, 90, 30, OC_ENOISE_NONE, 0, 0, 0)};
  oc_enode *land = EOK(oc_enode_blend(d, 4, &err));
  oc_enode *river = EOK(river_across(&err));
  oc_enode *rep = EOK(oc_enode_replace(land, river, 0, &err));
  oc_enode *lrep = EOK(oc_enode_replace(land, d[1], 1, &err));
  oc_enode_add_params ap = {0};
  oc_enode *add = EOK(oc_enode_add(rep, d[2], &ap, &err));
  oc_enode *top[3] = {add, lrep, d[3]};
  oc_enode *mix = EOK(oc_enode_blend(top, 3, &err));
  oc_enode *all[] = {d[0], d[1], d[2], d[3], land, rep, lrep, add, mix};
  int wants[4] = {0, OC_EV_LAZY, OC_EV_ALPHA, OC_EV_LAZY | OC_EV_ALPHA};
  size_t n = sizeof all / sizeof *all, checked = 0;
  for (size_t t = 0; t < n; t++)
    for (int row = 0; row < ROWS_N; row++) {
#ifdef __SANITIZE_ADDRESS__
      if (t % 3 != 2) continue; /* a disc, a replace, the whole tree */
#endif
      /* rows 1.3 m apart (points in one lattice cell share corners) or
      ** 23 m, from outside the base disc across it */
      double y = -650 + (row + 0.5) * 1300 / ROWS_N, dx = row % 2 ? 1.3 : 23;
      double x[OC_EROW], f[OC_EROW], a[OC_EROW];
      for (int m = 0; m < OC_EROW; m++)
        x[m] = (row % 2 ? -40 : -700) + m * dx;
      for (int w = 0; w < 4; w++) {
        oc_enode_ev_row(all[t], x, y, OC_EROW, wants[w], f, a);
        for (int m = 0; m < OC_EROW; m++) {
          oc_enode_sample s;
          oc_enode_ev(all[t], x[m], y, NULL, wants[w], &s);
          ck_assert_msg(same(a[m], s.a), "%s alpha at (%g, %g): %.17g vs %.17g",
                        oc_enode_kind(all[t]), x[m], y, a[m], s.a);
          if (wants[w] & OC_EV_ALPHA) continue;
          ck_assert_msg(same(f[m], s.f), "%s f at (%g, %g): %.17g vs %.17g",
                        oc_enode_kind(all[t]), x[m], y, f[m], s.f);
          checked += s.a > 0 && s.f != 0;
        }
      }
    }
  /* most points inside: real values */
  ck_assert_uint_gt(checked, ROWS_N == 9 ? 2000 : 150);
  /* the source's rows: any length (chunks of OC_EROW), = height_weight */
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(mix, NULL, &src, &err), OC_OK);
  ck_assert(src.height_weight_row != NULL);
  enum { LEN = 150 };
  double x[LEN], h[LEN], al[LEN];
  for (int m = 0; m < LEN; m++)
    x[m] = -300 + 4 * m;
  src.height_weight_row(src.ud, x, 25, LEN, h, al);
  for (int m = 0; m < LEN; m++) {
    double am, hm = src.height_weight(src.ud, x[m], 25, NULL, &am, NULL);
    ck_assert(same(hm, h[m]) && same(am, al[m]));
  }
  src.release(src.ud);
  for (size_t t = 0; t < n; t++)
    oc_enode_release(all[t]);
  oc_enode_release(river);
}
END_TEST

/* First-order models (etaylor.h): at random points p and radii R, f and
** alpha at p are the evaluator's bits, and the remainders hold on random
** q in the disc |q - p| <= R (near p, where the linear part must be the
** gradient, and out to R), for every rule: discs of each noise, blends
** (weights above T on the disc, below T, crossing it: the fallback),
** replace by a river (the zero-set rule) and lerped by a disc, add with
** an altitude weight and with alpha_A + w^2, a transform, and a warp and a
** lake (fallbacks). A quadratic remainder is checked at small r too, where
** a wrong gradient would exceed it. */
#ifdef __SANITIZE_ADDRESS__
#define TAY_POINTS 12
#else
#define TAY_POINTS 60
#endif

static double tay_worst; /* largest |error| / remainder seen */

/* f and alpha at full detail */
static void full_eval(const void *e, double x, double y, double fa[2]) {
  oc_enode_sample q;
  oc_enode_ev(e, x, y, NULL, 0, &q);
  fa[0] = q.f, fa[1] = q.a;
}

static void check_taylor(const oc_enode *e, oct_rng *r, double half) {
  for (int i = 0; i < TAY_POINTS; i++) {
    double x = oct_unif(r, -half, half), y = oct_unif(r, -half, half);
    double R = half * pow(10, oct_unif(r, -4, -0.5));
    oc_etaylor m;
    int boxes = 0;
    oc_enode_taylor(e, x, y, R, &m, &boxes);
    oc_enode_sample s, sa;
    oc_enode_ev(e, x, y, NULL, 0, &s);
    oc_enode_ev(e, x, y, NULL, OC_EV_ALPHA, &sa);
    ck_assert_msg(same(m.f.v, s.f), "%s at (%g, %g): f %.17g, eval %.17g",
                  oc_enode_kind(e), x, y, m.f.v, s.f);
    ck_assert_msg(same(m.a.v, sa.a), "%s at (%g, %g): alpha %.17g, eval %.17g",
                  oc_enode_kind(e), x, y, m.a.v, sa.a);
    tay_worst = fmax(tay_worst, etay_check(&m, x, y, R, r, full_eval, e,
                                           oc_enode_kind(e), NULL));
  }
}

START_TEST(taylor_models) {
  oc_error err;
  oc_enode *d[5] = {disc(0, 0, 900, 50, OC_ENOISE_PLAIN, 30, 200, 6),
                    disc(150, 40, 180, 120, OC_ENOISE_RIDGED, 40, 60, 6),
                    disc(-200, -60, 150, 80, OC_ENOISE_TURBULENCE, 20, 40, 5),
                    disc(60, -30, 90, 30, OC_ENOISE_NONE, 0, 0, 0),
                    disc(-60, 120, 70, 60, OC_ENOISE_PLAIN, 8, 25, 4)};
  oc_enode *land = EOK(oc_enode_blend(d, 5, &err));
  oc_enode *islets = EOK(oc_enode_blend(d + 1, 4, &err)); /* S < T too */
  oc_enode *river = EOK(river_across(&err));
  oc_enode *rep = EOK(oc_enode_replace(land, river, 0, &err));
  oc_enode *lrep = EOK(oc_enode_replace(land, d[1], 1, &err));
  oc_enode_add_params below = {0, 1, 90, 20, 0, 0, 0, 0};
  oc_enode *crag = EOK(oc_enode_add(rep, d[2], &below, &err));
  oc_enode_add_params sumw = {1, 0, 0, 0, 0, 0, 0, 0};
  oc_enode *sadd = EOK(oc_enode_add(d[0], d[4], &sumw, &err));
  oc_enode_xform xf = {30, -20, 35, 1.7, 0.6, 5};
  oc_enode *moved = EOK(oc_enode_transform(crag, &xf, &err));
  oc_enode_warp_params wp = {10, 200, 2, 7};
  oc_enode *warped = EOK(oc_enode_warp(land, &wp, &err));
  double radii[3] = {100, 140, 120};
  oc_enode_lake_params lp = {0};
  lp.cx = 10, lp.cy = 20, lp.radii = radii, lp.nradii = 3, lp.level = 40;
  oc_enode *lake = EOK(oc_enode_lake(&lp, &err));
  oc_enode_xform xg = {-250, 180, -50, 0.5, 1.3, 0};
  oc_enode *small = EOK(oc_enode_transform(islets, &xg, &err));
  oc_enode *inst[3] = {d[0], moved, small}; /* children by their weight */
  oc_enode *insts = EOK(oc_enode_blend(inst, 3, &err));
  oc_enode *top[3] = {moved, lrep, lake};
  oc_enode *mix = EOK(oc_enode_blend(top, 3, &err));
  oc_enode *all[] = {d[0], d[1], d[2], d[3],  d[4],   land, islets, rep,
                     lrep, crag, sadd, moved, warped, lake, mix,    insts};
  oct_rng r = oct_rng_new(123);
  tay_worst = 0;
  for (size_t t = 0; t < sizeof all / sizeof *all; t++)
    check_taylor(all[t], &r, 400);
  printf("taylor: the largest error is %.3f of its remainder\n", tay_worst);
  ck_assert(tay_worst > 0.01); /* (the checks do reach the bounds) */
  /* partial f models (OC_EF_PARTIAL, set at allocation): a curve's and a
  ** lake's, and an operator's of one in A's place, a transform's of one */
  oc_enode *rv = EOK(oc_enode_replace(river, land, 0, &err));
  oc_enode *rvm = EOK(oc_enode_transform(rv, &xg, &err));
  oc_enode *rvb[2] = {rvm, d[0]};
  oc_enode *rvbl = EOK(oc_enode_blend(rvb, 2, &err));
  const oc_enode *part[] = {river, lake, rv, rvm};
  const oc_enode *whole[] = {d[0], land, rep, crag, moved, mix, rvbl};
  for (size_t t = 0; t < 4; t++)
    ck_assert(oc_eop_taylor_partial(part[t]));
  for (size_t t = 0; t < 7; t++)
    ck_assert(!oc_eop_taylor_partial(whole[t]));
  oc_enode_release(rvbl);
  oc_enode_release(rvm);
  oc_enode_release(rv);
  oc_enode *rel[] = {land,  islets, river, rep, lrep,  crag, sadd,
                     moved, warped, lake,  mix, small, insts};
  for (size_t t = 0; t < sizeof rel / sizeof *rel; t++)
    oc_enode_release(rel[t]);
  for (int i = 0; i < 5; i++)
    oc_enode_release(d[i]);
}
END_TEST

/* A blend's grid (enode.h, eops.c): blends of 32 and 70 children (one
** and two words a column or row; 20 keep none) answer every query with
** the bits of the same blends without their grid (every child tested in
** turn): values and gradients under each want, rows, first-order models
** (f and alpha, and alpha's alone) and bounds in boxes, at points inside,
** on cell edges and outside the box, for radii from a tenth of a cell to
** the whole box. Its bytes: two scales and 2 G W masks (8 bytes each)
** after the children, G the largest with at most 6 bytes a child. */
#ifdef __SANITIZE_ADDRESS__
#define GRID_POINTS 150
#else
#define GRID_POINTS 1500
#endif

static void same_taylor(const oc_etaylor *a, const oc_etaylor *b) {
  ck_assert(!memcmp(a, b, sizeof *a));
}

START_TEST(blend_grid_matches_flat) {
  oc_error err;
  enum { N = 70 };
  oc_enode *k[N];
  oct_rng r = oct_rng_new(77);
  for (int i = 0; i < N; i++) {
    double x = oct_unif(&r, -500, 500), y = oct_unif(&r, -300, 300);
    double rad = i % 7 == 0 ? oct_unif(&r, 200, 400) : oct_unif(&r, 10, 80);
    k[i] = disc(x, y, rad, oct_unif(&r, 10, 100), (oc_enoise_kind)(i % 4), 5,
                rad / 2, 3);
  }
  /* an operator child (a float box): a moved blend of three */
  oc_enode *three = EOK(oc_enode_blend(k + 1, 3, &err));
  oc_enode_xform xf = {100, 50, 30, 0.7, 1, 0};
  oc_enode *kid0 = k[0];
  k[0] = EOK(oc_enode_transform(three, &xf, &err));
  size_t sizes[3] = {20, 32, N};
  int sides[3] = {0, 11, 12}; /* (none below 24), 8 (2 + 2 G W) <= 6 n */
  for (int t = 0; t < 3; t++) {
    size_t n = sizes[t], W = (n + 63) / 64;
    oc_enode *g = EOK(oc_enode_blend(k, n, &err));
    oc_enode *flat = EOK(oc_enode_blend(k, n, &err));
    ck_assert_int_eq(g->octaves, sides[t]);
    ck_assert_uint_eq(oc_enode_size(g),
                      56 + 8 * n + (sides[t] ? 8 * (2 + 2 * W * sides[t]) : 0));
    flat->octaves = 0; /* (the same blend, every child tested) */
    oc_erect box = oc_enode_box(g);
    double cw = (box.x1 - box.x0) / (sides[t] ? sides[t] : 4);
    int checked = 0;
    for (int i = 0; i < GRID_POINTS; i++) {
      double x = oct_unif(&r, box.x0 - 50, box.x1 + 50);
      double y = oct_unif(&r, box.y0 - 50, box.y1 + 50);
      if (i % 5 == 0) /* on a cell's edge */
        x = box.x0 + cw * (double)(i / 5 % (sides[t] + 2));
      double R = cw * pow(10, oct_unif(&r, -1, 1));
      for (int w = 0; w < 4; w++) {
        int want = (int[]){0, OC_EV_GRAD, OC_EV_LAZY, OC_EV_ALPHA}[w];
        oc_enode_sample a, b;
        oc_enode_ev(g, x, y, NULL, want, &a);
        oc_enode_ev(flat, x, y, NULL, want, &b);
        ck_assert(same(a.a, b.a) && same(a.ax, b.ax) && same(a.ay, b.ay));
        if (want & OC_EV_ALPHA) continue;
        ck_assert(same(a.f, b.f) && same(a.fx, b.fx) && same(a.fy, b.fy));
        checked += w == 1 && a.a > 0 && a.fx != 0;
      }
      oc_etaylor ma, mb;
      int ba = 0, bb = 0;
      oc_enode_taylor(g, x, y, R, &ma, &ba);
      oc_enode_taylor(flat, x, y, R, &mb, &bb);
      same_taylor(&ma, &mb);
      ck_assert_int_eq(ba, bb);
      oc_etay aa, ab;
      int ha = oc_enode_taylor_alpha(g, x, y, R, &aa, &ba);
      int hb = oc_enode_taylor_alpha(flat, x, y, R, &ab, &bb);
      ck_assert_int_eq(ha, hb);
      if (ha) ck_assert(!memcmp(&aa, &ab, sizeof aa));
      oc_erect q = {x - R, y - R * 0.3, x + R * 0.5, y + R};
      oc_ebound qa, qb;
      oc_enode_bnd(g, &q, NULL, &qa);
      oc_enode_bnd(flat, &q, NULL, &qb);
      ck_assert(!memcmp(&qa, &qb, sizeof qa));
      if (i % 50 == 0) { /* a row across the box */
        double xs[OC_EROW], fa[OC_EROW], aa2[OC_EROW], fb[OC_EROW],
            ab2[OC_EROW];
        for (int m = 0; m < OC_EROW; m++)
          xs[m] = x + m * cw / 7;
        oc_enode_ev_row(g, xs, y, OC_EROW, 0, fa, aa2);
        oc_enode_ev_row(flat, xs, y, OC_EROW, 0, fb, ab2);
        ck_assert(!memcmp(fa, fb, sizeof fa) && !memcmp(aa2, ab2, sizeof aa2));
      }
    }
    ck_assert_int_gt(checked, GRID_POINTS / 4); /* real values */
    oc_enode_release(g);
    oc_enode_release(flat);
  }
  /* NaN: no child, as without the grid */
  oc_enode *g = EOK(oc_enode_blend(k, N, &err));
  oc_enode_sample s;
  oc_enode_ev(g, NAN, 3, NULL, OC_EV_GRAD, &s);
  ck_assert(isnan(s.f) && isnan(s.a));
  oc_enode_release(g);
  for (int i = 0; i < N; i++)
    oc_enode_release(k[i]);
  oc_enode_release(three);
  oc_enode_release(kid0);
}
END_TEST

/* A blend of discs alone (OC_EF_DISCS, set at construction) finds the
** children a model's disc meets without branches, every child in order
** (no grid) or through its grid's cells: the same models, bit for bit,
** and the same box counts, as the same blend taking the general walk
** (the flag cleared), at points inside, near and outside its box, for
** radii from a child's tenth to the whole scene; the models hold
** (check_taylor). Blends with another kind of child keep the flag clear. */
#ifdef __SANITIZE_ADDRESS__
#define DISC_BLEND_POINTS 100
#else
#define DISC_BLEND_POINTS 800
#endif

START_TEST(blend_of_discs_fast_path) {
  oc_error err;
  enum { N = 40 };
  oc_enode *k[N];
  oct_rng r = oct_rng_new(91);
  for (int i = 0; i < N; i++) {
    double x = oct_unif(&r, -400, 400), y = oct_unif(&r, -400, 400);
    double rad = i == 0 ? 1500 : oct_unif(&r, 30, 250);
    k[i] = disc(x, y, rad, oct_unif(&r, 10, 120), (oc_enoise_kind)(i % 4),
                oct_unif(&r, 2, 20), rad / 2, 2 + i % 6);
  }
  size_t sizes[2] = {18, N}; /* no grid, and a grid */
  int models = 0;
  for (int t = 0; t < 2; t++) {
    oc_enode *g = EOK(oc_enode_blend(k, sizes[t], &err));
    oc_enode *walk = EOK(oc_enode_blend(k, sizes[t], &err));
    ck_assert(g->flags & OC_EF_DISCS);
    ck_assert_int_eq(g->octaves, t ? 14 : 0); /* (8 words(n, G) <= 6 n) */
    walk->flags &= (uint8_t)~OC_EF_DISCS;
    for (int i = 0; i < DISC_BLEND_POINTS; i++) {
      double x = oct_unif(&r, -600, 600), y = oct_unif(&r, -600, 600);
      double R = pow(10, oct_unif(&r, 0, 3));
      oc_etaylor ma, mb;
      int ba = 0, bb = 0;
      oc_enode_taylor(g, x, y, R, &ma, &ba);
      oc_enode_taylor(walk, x, y, R, &mb, &bb);
      same_taylor(&ma, &mb);
      ck_assert_int_eq(ba, bb);
      models += ba == 0; /* (a rule, not the box bound's fallback) */
    }
    check_taylor(g, &r, 500);
    oc_enode_release(g);
    oc_enode_release(walk);
  }
  ck_assert_int_gt(models, DISC_BLEND_POINTS); /* real models */
  oc_enode *three = EOK(oc_enode_blend(k, 3, &err));
  oc_enode_xform xf = {100, 50, 30, 0.7, 1, 0};
  oc_enode *mixed[2] = {k[1], EOK(oc_enode_transform(three, &xf, &err))};
  oc_enode *mb = EOK(oc_enode_blend(mixed, 2, &err));
  ck_assert(!(mb->flags & OC_EF_DISCS));
  oc_enode_release(mb);
  oc_enode_release(mixed[1]);
  oc_enode_release(three);
  for (int i = 0; i < N; i++)
    oc_enode_release(k[i]);
}
END_TEST

/* A child's box that touches the model's disc (its box, [x - R, x + R]
** x [y - R, y + R]) exactly on one side is met, on each of the four
** sides, by the fast path as by the general walk: the same models, bit
** for bit; the touching child counts (its weight's model, 0 at p but not
** on the whole disc, adds its remainder to the sum's), and a hair
** farther it does not. (Dyadic coordinates: the boxes' sides are exact.) */
START_TEST(blend_of_discs_touching) {
  oc_error err;
  oc_enode *k[2] = {disc(256, 0, 4096, 50, OC_ENOISE_PLAIN, 4, 300, 3),
                    disc(256, 0, 256, 20, OC_ENOISE_PLAIN, 2, 40, 3)};
  oc_enode *g = EOK(oc_enode_blend(k, 2, &err));
  oc_enode *walk = EOK(oc_enode_blend(k, 2, &err));
  ck_assert(g->flags & OC_EF_DISCS);
  walk->flags &= (uint8_t)~OC_EF_DISCS;
  const double R = 16, d = 256 + R;
  const double at[4][2] = {{256 + d, 0}, {256 - d, 0}, {256, d}, {256, -d}};
  for (int side = 0; side < 4; side++) {
    double x = at[side][0], y = at[side][1];
    oc_etaylor ma, mb, mf;
    int ba = 0, bb = 0;
    oc_enode_taylor(g, x, y, R, &ma, &ba);
    oc_enode_taylor(walk, x, y, R, &mb, &bb);
    same_taylor(&ma, &mb);
    ck_assert_int_eq(ba, 0);
    /* a hair away from the small disc: it no longer meets the box */
    double fx = side == 0   ? nextafter(x, INFINITY)
                : side == 1 ? nextafter(x, -INFINITY)
                            : x;
    double fy = side == 2   ? nextafter(y, INFINITY)
                : side == 3 ? nextafter(y, -INFINITY)
                            : y;
    oc_enode_taylor(g, fx, fy, R, &mf, &ba);
    oc_enode_taylor(walk, fx, fy, R, &mb, &bb);
    same_taylor(&mf, &mb);
    /* the touching disc's weight remainder, 3 / r^2, in the sum's */
    ck_assert(ma.a.e2 > mf.a.e2);
    ck_assert_double_eq_tol(ma.a.e2 - mf.a.e2, 3.0 / (256 * 256), 1e-15);
  }
  oc_enode_release(g);
  oc_enode_release(walk);
  oc_enode_release(k[0]);
  oc_enode_release(k[1]);
}
END_TEST

/* A disc's weight model decides "alpha is 0 on the whole disc" and "the
** model is flat" from the squares and from an upper bound of the
** gradient's norm where those are clear of the thresholds: the same
** models, bit for bit, as the rule computed with its square roots
** (written out here), at random points and at points within a few ulps of
** |p - c| = (r + R)(1 + 1e-12), of q = 1 and of the flat switch. */
static void ref_alpha(double cx, double cy, double r, double x, double y,
                      double R, oc_etay *a) {
  double u = x - cx, v = y - cy, q = (u * u + v * v) / (r * r);
  if (sqrt(u * u + v * v) >= (r + R) * (1 + 1e-12)) {
    *a = oc_etay_const(0);
  } else if (q < 1) {
    double k = 1 - q, c = -6 * k * k / (r * r);
    *a = (oc_etay){k * k * k, c * u, c * v, 0, 0, 3 / (r * r)};
  } else {
    *a = (oc_etay){0, 0, 0, 0, 0, 3 / (r * r)};
  }
  double gap = fmax(a->v, 1 - a->v);
  if (oc_etay_dev(a, R) > gap) *a = (oc_etay){a->v, 0, 0, gap, 0, 0};
}

#ifdef __SANITIZE_ADDRESS__
#define ALPHA_POINTS 3000
#else
#define ALPHA_POINTS 20000
#endif

START_TEST(disc_alpha_model_decisions) {
  oct_rng r = oct_rng_new(57);
  int flat = 0, zero = 0, lin = 0;
  for (int i = 0; i < ALPHA_POINTS; i++) {
    double cx = oct_unif(&r, -1e3, 1e3), cy = oct_unif(&r, -1e3, 1e3);
    double rad = pow(10, oct_unif(&r, -2, 4));
    double R = rad * pow(10, oct_unif(&r, -4, 1)), th = oct_unif(&r, 0, 6.28);
    double d = rad * oct_unif(&r, 0, 2) + oct_unif(&r, 0, 1) * R;
    if (i % 4 == 1) /* at the "0 on the whole disc" switch */
      d = nextafter((rad + R) * (1 + 1e-12), 0) * (1 + (i % 9 - 4) * 1e-16);
    if (i % 4 == 2) /* at q = 1 */
      d = rad * (1 + (i % 11 - 5) * 1.1e-16);
    if (i % 4 == 1 || i % 4 == 2) /* (u and v as exact as can be) */
      cx = cy = 0, th = i % 8 < 4 ? 0 : th;
    double x = cx + d * cos(th), y = cy + d * sin(th);
    if (i % 4 == 3) { /* about where the flat model takes over */
      x = cx + rad * oct_unif(&r, 0.1, 0.9), y = cy;
      R = rad * oct_unif(&r, 0.05, 1.5);
    }
    oc_enode *e = disc(cx, cy, rad, 0, OC_ENOISE_NONE, 0, 0, 0);
    oc_etay a, b;
    oc_edisc_taylor_alpha(e, x, y, R, &a);
    ref_alpha(cx, cy, rad, x, y, R, &b);
    ck_assert_msg(!memcmp(&a, &b, sizeof a), "disc %g at (%g, %g), R %g", rad,
                  x - cx, y - cy, R);
    zero += oc_etay_is_const(&a) && a.v == 0;
    flat += a.e0 > 0;
    lin += a.gx != 0;
    oc_enode_release(e);
  }
  ck_assert(zero > ALPHA_POINTS / 10 && flat > ALPHA_POINTS / 40 &&
            lin > ALPHA_POINTS / 10);
  printf("disc alpha models: %d zero, %d flat, %d linear\n", zero, flat, lin);
}
END_TEST

int main(void) {
  Suite *s = suite_create("elevation");
  TCase *tc = tcase_create("elevation");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, disc_formula);
  tcase_add_test(tc, disc_noises);
  tcase_add_test(tc, disc_local_bounds);
  tcase_add_test(tc, disc_matches_octave_sum);
  tcase_add_test(tc, efmax_is_fmax);
  tcase_add_test(tc, blend_formula);
  tcase_add_test(tc, replace_and_add_formulas);
  tcase_add_test(tc, add_slope_weight);
  tcase_add_test(tc, transform_concatenates);
  tcase_add_test(tc, warp_bijective_only);
  tcase_add_test(tc, dag_stats_and_source);
  tcase_add_test(tc, curve_river_road);
  tcase_add_test(tc, curve_bound_is_local);
  tcase_add_test(tc, curve_weight_in_one_search);
  tcase_add_test(tc, bad_input);
  tcase_add_test(tc, rows_match_points);
  tcase_add_test(tc, add_altitude_slope_bound);
  tcase_add_test(tc, taylor_models);
  tcase_add_test(tc, blend_grid_matches_flat);
  tcase_add_test(tc, blend_of_discs_fast_path);
  tcase_add_test(tc, blend_of_discs_touching);
  tcase_add_test(tc, disc_alpha_model_decisions);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
