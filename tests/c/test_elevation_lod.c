/*
** test_elevation_lod.c — level of detail of elevation trees (Génevaux et
** al. 2015, section 6): the footprint 0 gives the full-detail tree bit for
** bit; continuous-LoD discs against the octave sum written here (each
** octave's term read as the difference of two discs, its weight b(t) from
** a footprint computed here); the lod operator against its formula; no
** jump across the thresholds beyond the Lipschitz bound times the step;
** gradients against central differences and the bounds never exceeded
** with LoD on; and a LoD render against a dense march.
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "elevation/enode.h"
#include "etaycheck.h"
#include "ocheck.h"
#include "render/etrace.h"

#define PI 3.14159265358979323846

/* Sizes: the sanitizer pass (about 7x slower) samples less, the release
** pass the full sets. */
#ifdef __SANITIZE_ADDRESS__
#define MARCH_NX 10 /* rays against a 0.5 m march */
#define MARCH_NY 6
#define LINE_STEP 1.0 /* metres between samples along the lines */
#else
#define MARCH_NX 20
#define MARCH_NY 12
#define LINE_STEP 0.25
#endif

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

/* the filter and the footprint, written independently of lib/ */
static double bfilt(double t) {
  if (t <= 0) return 0;
  if (t >= 1) return 1;
  double q = 1 - t * t;
  return 1 - q * q * q;
}

static double foot(const oc_enode_view *v, double dz, double x, double y) {
  double u = x - v->eye[0], w = y - v->eye[1];
  return v->k * sqrt(u * u + w * w + dz * dz);
}

static double mid_dz(const oc_enode *e, const oc_enode_view *v) {
  double lo, hi;
  oc_enode_get_bounds(e, NULL, &lo, &hi);
  return fabs(v->eye[2] - (lo + hi) / 2);
}

static void evalv(const oc_enode *e, double x, double y, const oc_enode_view *v,
                  oc_enode_sample *s) {
  oc_error err;
  ck_assert_msg(oc_enode_eval_view(e, x, y, v, s, &err) == OC_OK, "%s",
                err.msg);
}

/* The bound of e in a box under view v (internal: what the view source
** gives the tracer). */
static void bound_view(const oc_enode *e, const oc_enode_view *v, double x0,
                       double y0, double x1, double y1, oc_ebound *b) {
  oc_eview w = {v->eye[0], v->eye[1], mid_dz(e, v), v->k};
  oc_erect r = {x0, y0, x1, y1};
  oc_efootb fb;
  oc_eview_footb(&w, &r, &fb);
  oc_enode_bnd(e, &r, &fb, b);
}

/* A scene with every operator: a covering base, noisy discs of every
** kind, an instanced patch (transformed twice, scaled and rotated), a
** warp, a lod node, blend, replace and add. */
static oc_enode *scene(void) {
  oc_error err;
  oc_enode *base = disc(0, 0, 4000, 100, OC_ENOISE_PLAIN, 60, 900, 8);
  oc_enode *m = disc(0, 0, 300, 200, OC_ENOISE_RIDGED, 150, 250, 9);
  oc_enode_xform x1 = {600, 200, 30, 2, 1, 0},
                 x2 = {-700, -300, -75, 1.5, 0.8, 20};
  oc_enode *i1 = EOK(oc_enode_transform(m, &x1, &err));
  oc_enode *i2 = EOK(oc_enode_transform(m, &x2, &err));
  oc_enode *t = disc(200, -800, 500, 150, OC_ENOISE_TURBULENCE, 80, 200, 8);
  oc_enode_warp_params wp = {30, 600, 2, 7};
  oc_enode *tw = EOK(oc_enode_warp(t, &wp, &err));
  oc_enode *coarse = disc(-300, 900, 600, 120, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *fine = disc(-300, 900, 600, 120, OC_ENOISE_PLAIN, 40, 60, 5);
  oc_enode_lod_params lp = {60, 0, 1};
  oc_enode *ld = EOK(oc_enode_lod(coarse, fine, &lp, &err));
  oc_enode *kids[] = {base, i1, i2, tw, ld};
  oc_enode *bl = EOK(oc_enode_blend(kids, 5, &err));
  oc_enode *crater = disc(900, 900, 250, 40, OC_ENOISE_PLAIN, 10, 50, 6);
  oc_enode *rp = EOK(oc_enode_replace(bl, crater, 0, &err));
  oc_enode *dunes = disc(-900, -900, 400, 0, OC_ENOISE_RIDGED, 15, 40, 8);
  oc_enode_add_params ap = {.below = 1, .below_z = 150, .fade = 30};
  oc_enode *top = EOK(oc_enode_add(rp, dunes, &ap, &err));
  oc_enode *all[] = {base, m,  i1, i2,     t,  tw,   coarse,
                     fine, ld, bl, crater, rp, dunes};
  for (size_t k = 0; k < sizeof all / sizeof *all; k++)
    oc_enode_release(all[k]);
  return top;
}

/* The scene with sand added where it is gentle (the slope weight): A's
** f at four more points, each with p's footprint. */
static oc_enode *slope_scene(void) {
  oc_error err;
  oc_enode *a = scene();
  oc_enode *sand = disc(-200, 300, 1800, 2, OC_ENOISE_RIDGED, 8, 120, 6);
  oc_enode_add_params p = {
      .slope = 1, .slope_deg = 8, .slope_fade = 12, .slope_step = 6};
  oc_enode *e = EOK(oc_enode_add(a, sand, &p, &err));
  oc_enode_release(a);
  oc_enode_release(sand);
  return e;
}

/* lod between two flat discs: all its slope is the footprint's term */
static oc_enode *step_tree(void) {
  oc_error err;
  oc_enode *a = disc(0, 0, 9000, 10, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *b = disc(0, 0, 9000, 60, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode_lod_params p = {300, 0.2, 0.7};
  oc_enode *l = EOK(oc_enode_lod(a, b, &p, &err));
  oc_enode_release(a);
  oc_enode_release(b);
  return l;
}

/* The step tree as an instance, scaled, rotated and warped: the
** footprint's units and slope change on the way down, and all the slope
** is theirs. */
static oc_enode *step_instance(void) {
  oc_error err;
  oc_enode *st = step_tree();
  oc_enode_xform x = {-200, 100, 40, 3, 1, 0};
  oc_enode *t = EOK(oc_enode_transform(st, &x, &err));
  oc_enode_warp_params wp = {40, 900, 2, 3};
  oc_enode *w = EOK(oc_enode_warp(t, &wp, &err));
  oc_enode_release(st);
  oc_enode_release(t);
  return w;
}

START_TEST(footprint_zero_is_full_detail) {
  oc_enode *e = scene();
  oc_enode_view v0 = {{100, -200, 900}, 0};
  /* a view so close that every octave keeps full weight */
  oc_enode_view vn = {{100, -200, 900}, 1e-9};
  oct_rng r = oct_rng_new(3);
  for (int i = 0; i < 4000; i++) {
    double x = oct_unif(&r, -4000, 4000), y = oct_unif(&r, -4000, 4000);
    oc_enode_sample a, b, c;
    oc_enode_eval(e, x, y, &a);
    evalv(e, x, y, &v0, &b);
    evalv(e, x, y, &vn, &c);
    ck_assert_msg(memcmp(&a, &b, sizeof a) == 0, "k = 0 differs at (%g, %g)", x,
                  y);
    /* values bit for bit; the gradients gain the filters' zero terms */
    ck_assert_msg(a.f == c.f && a.a == c.a, "tiny k differs at (%g, %g)", x, y);
  }
  /* bounds too: NULL and k = 0 agree */
  oc_ebound b0, b1;
  oc_erect box = {-500, -500, 800, 300};
  oc_efootb z = {0, 0, 0};
  oc_enode_bnd(e, &box, NULL, &b0);
  oc_enode_bnd(e, &box, &z, &b1);
  ck_assert(memcmp(&b0, &b1, sizeof b0) == 0);
  oc_enode_release(e);
}
END_TEST

/* Discs d[i] with i octaves (d[0] one) of wavelength OCT_WL over height
** OCT_H, for i <= OCT_N. */
#define OCT_N 8
#define OCT_WL 400.0
#define OCT_H 50.0
static void octave_discs(oc_enode **d, oc_enoise_kind kind) {
  for (int i = 0; i <= OCT_N; i++)
    d[i] = disc(0, 0, 20000, OCT_H, kind, 100, OCT_WL, i ? i : 1);
}

/* d[OCT_N]'s f at (x, y) under footprint ft: h + sum b(t_i) term_i,
** term_i the difference of discs with i + 1 and i octaves at full
** detail; *ramps counts the octaves on their filter's ramp. */
static double octave_ref(oc_enode *const *d, double h, double wl, double ft,
                         double x, double y, int *ramps) {
  double ref = h;
  for (int i = 0; i < OCT_N; i++) {
    oc_enode_sample a, b;
    oc_enode_eval(d[i + 1], x, y, &a);
    if (i) oc_enode_eval(d[i], x, y, &b);
    double term = i ? a.f - b.f : a.f - h;
    double t = log2(wl / pow(2, i) / ft);
    *ramps += t > 0 && t < 1;
    ref += bfilt(t) * term;
  }
  return ref;
}

/* The disc's f under a view against octave_ref. */
static void check_disc_kind(oc_enoise_kind kind) {
  const int N = OCT_N;
  const double wl = OCT_WL, h = OCT_H;
  oc_enode *d[OCT_N + 1];
  octave_discs(d, kind);
  oc_enode_view v = {{-3000, 500, 2500}, 2e-3};
  double dz = mid_dz(d[N], &v);
  oct_rng r = oct_rng_new(11 + kind);
  int ramps = 0;
  for (int k = 0; k < 3000; k++) {
    double x = oct_unif(&r, -12000, 12000), y = oct_unif(&r, -12000, 12000);
    double ft = foot(&v, dz, x, y);
    double ref = octave_ref(d, h, wl, ft, x, y, &ramps);
    oc_enode_sample s;
    evalv(d[N], x, y, &v, &s);
    ck_assert_msg(fabs(s.f - ref) <= 1e-9 * (1 + fabs(ref)),
                  "kind %d at (%g, %g): %.12g, sum %.12g", kind, x, y, s.f,
                  ref);
    /* beyond the first octave's ramp nothing is left of the noise */
    if (wl / ft <= 1) ck_assert(s.f == h && s.fx == 0 && s.fy == 0);
  }
  ck_assert_msg(ramps > 1000, "only %d samples on a ramp", ramps);
  for (int i = 0; i <= N; i++)
    oc_enode_release(d[i]);
}

START_TEST(disc_octaves_filtered) {
  check_disc_kind(OC_ENOISE_PLAIN);
  check_disc_kind(OC_ENOISE_TURBULENCE);
  check_disc_kind(OC_ENOISE_RIDGED);
}
END_TEST

START_TEST(lod_operator_formula) {
  oc_error err;
  oc_enode *a = disc(0, 0, 5000, 10, OC_ENOISE_PLAIN, 30, 700, 3);
  oc_enode *b = disc(100, 0, 5000, 40, OC_ENOISE_RIDGED, 60, 300, 6);
  double ks[][2] = {{0, 1}, {0.25, 0.75}, {0, 0.3}, {0.6, 1}};
  for (int q = 0; q < 4; q++) {
    oc_enode_lod_params p = {250, ks[q][0], ks[q][1]};
    oc_enode *l = EOK(oc_enode_lod(a, b, &p, &err));
    ck_assert_str_eq(oc_enode_kind(l), "lod");
    oc_enode_view v = {{0, 0, 800}, 0.08};
    double dz = mid_dz(l, &v);
    oct_rng r = oct_rng_new(5 + q);
    int mixed = 0, onlya = 0, onlyb = 0;
    for (int k = 0; k < 2000; k++) {
      double x = oct_unif(&r, -4000, 4000), y = oct_unif(&r, -4000, 4000);
      double kap = bfilt(log2(250 / foot(&v, dz, x, y)));
      double t = (kap - p.k0) / (p.k1 - p.k0);
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      /* the children under the lod node's footprint (its dz) */
      oc_enode_sample s, fa, fb;
      oc_eview w = {v.eye[0], v.eye[1], dz, v.k};
      oc_efoot ft;
      oc_eview_foot(&w, x, y, &ft);
      ck_assert(fabs(ft.v - foot(&v, dz, x, y)) <= 1e-12 * ft.v);
      evalv(l, x, y, &v, &s);
      oc_enode_ev(a, x, y, &ft, OC_EV_GRAD, &fa);
      oc_enode_ev(b, x, y, &ft, OC_EV_GRAD, &fb);
      if (t == 0) {
        onlya++;
        ck_assert(memcmp(&s, &fa, sizeof s) == 0);
      } else if (t == 1) {
        onlyb++;
        ck_assert(memcmp(&s, &fb, sizeof s) == 0);
      } else {
        mixed++;
        double f = (1 - t) * fa.f + t * fb.f, al = (1 - t) * fa.a + t * fb.a;
        ck_assert_msg(fabs(s.f - f) < 1e-9 && fabs(s.a - al) < 1e-12,
                      "t %g: f %g vs %g", t, s.f, f);
      }
    }
    ck_assert_msg(mixed > 50 && onlya > 50 && onlyb > 50, "%d %d %d", mixed,
                  onlya, onlyb);
    /* no view: b */
    oc_enode_sample s, sb;
    oc_enode_eval(l, 123, 456, &s);
    oc_enode_eval(b, 123, 456, &sb);
    ck_assert(memcmp(&s, &sb, sizeof s) == 0);
    ck_assert(oc_enode_lipschitz(l) == oc_enode_lipschitz(b));
    oc_enode_release(l);
  }
  /* bad input names the field */
  oc_enode_lod_params bad[] = {
      {0, 0, 1}, {NAN, 0, 1}, {10, 0.5, 0.5}, {10, -0.1, 1}, {10, 0, 1.5}};
  const char *field[] = {"'wavelength'", "'wavelength'", "'k0'", "'k0'",
                         "'k1'"};
  for (int i = 0; i < 5; i++) {
    ck_assert(oc_enode_lod(a, b, &bad[i], &err) == NULL);
    ck_assert_msg(strstr(err.msg, field[i]), "%s", err.msg);
  }
  oc_enode_view bv = {{0, NAN, 0}, 1e-3};
  oc_enode_sample s;
  ck_assert(oc_enode_eval_view(a, 0, 0, &bv, &s, &err) == OC_EINVAL);
  ck_assert(strstr(err.msg, "'eye'"));
  bv = (oc_enode_view){{0, 0, 0}, -1};
  ck_assert(oc_enode_eval_view(a, 0, 0, &bv, &s, &err) == OC_EINVAL);
  ck_assert(strstr(err.msg, "'k'"));
  oc_enode_release(a);
  oc_enode_release(b);
}
END_TEST

/* Dense samples along lines that cross every octave ramp and the lod
** thresholds: no step changes f (or alpha) by more than the bound of the
** step's box times its length. */
START_TEST(continuous_across_thresholds) {
  oc_error err;
  oc_enode *e = scene(), *st = step_tree(), *si = step_instance();
  oc_enode *a = disc(0, 0, 9000, 10, OC_ENOISE_NONE, 0, 1, 1);
  oc_enode *b = disc(0, 0, 9000, 10, OC_ENOISE_PLAIN, 50, 300, 6);
  oc_enode_lod_params p = {300, 0.2, 0.7};
  oc_enode *l = EOK(oc_enode_lod(a, b, &p, &err));
  oc_enode *trees[] = {e, l, st, si};
  /* the step tree's ramp (foot from 150 to 300) crosses the lines */
  oc_enode_view views[] = {{{-3500, -3500, 700}, 4e-3},
                           {{-3500, -3500, 700}, 0.1}};
  for (int q = 0; q < 4; q++) {
    const oc_enode *t = trees[q];
    const oc_enode_view v = views[q >= 2];
    double step = LINE_STEP, jumps = 0;
    for (int line = 0; line < 3; line++) {
      double y = -3500 + 1200 * line;
      oc_enode_sample s0, s1;
      evalv(t, -3500, y, &v, &s0);
      for (double x = -3500; x < 3500; x += step) {
        evalv(t, x + step, y, &v, &s1);
        oc_ebound bd;
        bound_view(t, &v, x, y, x + step, y, &bd);
        double df = fabs(s1.f - s0.f), da = fabs(s1.a - s0.a);
        ck_assert_msg(df <= bd.lf * step * (1 + 1e-9) + 1e-9,
                      "%s: jump %g at x %g > %g x %g", oc_enode_kind(t), df, x,
                      bd.lf, step);
        ck_assert(da <= bd.la * step * (1 + 1e-9) + 1e-12);
        jumps = fmax(jumps, df / step);
        s0 = s1;
      }
    }
    ck_assert(jumps > 0);
  }
  oc_enode_release(l);
  oc_enode_release(a);
  oc_enode_release(b);
  oc_enode_release(st);
  oc_enode_release(si);
  oc_enode_release(e);
}
END_TEST

START_TEST(gradients_with_lod) {
  oc_enode *e = _i ? slope_scene() : scene();
  oc_enode_view v = {{-500, 300, 900}, 3e-3};
  oct_rng r = oct_rng_new(17);
  int n = 0;
  for (int k = 0; k < 3000; k++) {
    double x = oct_unif(&r, -4000, 4000), y = oct_unif(&r, -4000, 4000);
    oc_enode_sample s, a, b;
    double h = 1e-4;
    evalv(e, x, y, &v, &s);
    evalv(e, x + h, y, &v, &a);
    evalv(e, x - h, y, &v, &b);
    double fx = (a.f - b.f) / (2 * h), ax = (a.a - b.a) / (2 * h);
    evalv(e, x, y + h, &v, &a);
    evalv(e, x, y - h, &v, &b);
    double fy = (a.f - b.f) / (2 * h), ay = (a.a - b.a) / (2 * h);
    /* turbulence and ridges have kinks, and the altitude weight's
    ** smoothstep: skip the rare sample where the differences disagree
    ** between step sizes */
    oc_enode_sample c, d;
    evalv(e, x + 2 * h, y, &v, &c);
    evalv(e, x - 2 * h, y, &v, &d);
    double fx2 = (c.f - d.f) / (4 * h);
    if (fabs(fx2 - fx) > 1e-5 * (1 + fabs(fx))) continue;
    n++;
    double sc = 1 + fabs(fx) + fabs(fy);
    ck_assert_msg(fabs(fx - s.fx) <= 1e-5 * sc && fabs(fy - s.fy) <= 1e-5 * sc,
                  "grad f at (%g, %g): (%.9g, %.9g) vs fd (%.9g, %.9g)", x, y,
                  s.fx, s.fy, fx, fy);
    double sa = 1 + fabs(ax) + fabs(ay);
    ck_assert_msg(fabs(ax - s.ax) <= 1e-6 * sa && fabs(ay - s.ay) <= 1e-6 * sa,
                  "grad alpha at (%g, %g)", x, y);
  }
  ck_assert_msg(n > 2500, "only %d smooth samples", n);
  oc_enode_release(e);
}
END_TEST

/* With LoD on, the ranges and Lipschitz bounds of random boxes hold on
** random points and pairs, and a footprint's term is in them: the
** unfiltered slope bound alone would not do where the ramps are steep. */
START_TEST(bounds_with_lod) {
  oc_enode *trees[] = {scene(), step_tree(),
                       disc(0, 0, 9000, 10, OC_ENOISE_PLAIN, 50, 300, 2),
                       step_instance(), slope_scene()};
  oc_enode_view views[] = {
      {{-500, 300, 900}, 3e-3}, {{3000, 0, 5000}, 0.02}, {{100, 0, 10}, 1}};
  for (int q = 0; q < 15; q++) {
    const oc_enode_view *v = &views[q % 3];
    const oc_enode *e = trees[q / 3];
    oct_rng r = oct_rng_new(23 + q);
    double worst = 0, maxlf = 0; /* the largest slope over its bound */
    for (int i = 0; i < 300; i++) {
      double w = 4000 * pow(10, oct_unif(&r, -3.5, 0.3));
      double x0 = oct_unif(&r, -4500, 4000), y0 = oct_unif(&r, -4500, 4000);
      double x1 = x0 + w, y1 = y0 + w * oct_unif(&r, 0.2, 1);
      oc_ebound b;
      bound_view(e, v, x0, y0, x1, y1, &b);
      for (int k = 0; k < 64; k++) {
        double px = oct_unif(&r, x0, x1), py = oct_unif(&r, y0, y1);
        double qx = oct_unif(&r, x0, x1), qy = oct_unif(&r, y0, y1);
        oc_enode_sample p, s;
        evalv(e, px, py, v, &p);
        evalv(e, qx, qy, v, &s);
        double m = 1e-9 * (1 + fabs(b.flo) + fabs(b.fhi));
        ck_assert_msg(p.f >= b.flo - m && p.f <= b.fhi + m,
                      "f %g outside [%g, %g]", p.f, b.flo, b.fhi);
        ck_assert(p.a >= b.alo - 1e-9 && p.a <= b.ahi + 1e-9);
        ck_assert_msg(hypot(p.fx, p.fy) <= b.lf * (1 + 1e-9) + m,
                      "|grad f| %g > %g", hypot(p.fx, p.fy), b.lf);
        if (b.lf > 0) worst = fmax(worst, hypot(p.fx, p.fy) / b.lf);
        maxlf = fmax(maxlf, b.lf);
        ck_assert(hypot(p.ax, p.ay) <= b.la * (1 + 1e-9) + 1e-12);
        double d = hypot(px - qx, py - qy);
        ck_assert(fabs(p.f - s.f) <= b.lf * d * (1 + 1e-9) + m);
        ck_assert(fabs(p.a - s.a) <= b.la * d * (1 + 1e-9) + 1e-12);
      }
    }
    /* bounds that hold but say nothing would pass the above too (where
    ** a view's ramp lies beyond the boxes, the step tree is flat and its
    ** bounds say so) */
    ck_assert_msg(worst > 0.05 || maxlf == 0,
                  "tree %d view %d: slopes reach only %g of "
                  "the bounds",
                  q / 3, q % 3, worst);
  }
  for (int q = 0; q < 5; q++)
    oc_enode_release(trees[q]);
}
END_TEST

/* ---- first-order models under a view ---------------------------------- */

#ifdef __SANITIZE_ADDRESS__
#define TAY_POINTS 8 /* points a tree and view, each with 40 q */
#else
#define TAY_POINTS 40
#endif

/* The largest |error| / remainder seen, and on the step trees' ramps
** that of the models with a remainder of degree 2 (the footprint's
** curvature terms alone: its e2 and b''s). */
/* The footprint at (x, y) and over the box of the model's disc of radius
** R under w, prepared for R (as the tracer asks) where it is positive. */
static void ball_foot(const oc_eview *w, double x, double y, double R,
                      oc_etfoot *tf) {
  oc_erect box = {x - R, y - R, x + R, y + R};
  oc_eview_foot(w, x, y, &tf->p);
  oc_eview_footb(w, &box, &tf->b);
  if (tf->p.v > 0) oc_etfoot_prep(tf, R);
}

static double tay_worst, ramp_worst;

/* f and alpha under a view, with the footprint at the point */
typedef struct view_ctx {
  const oc_enode *e;
  const oc_eview *w;
} view_ctx;
static void view_eval(const void *ctx, double x, double y, double fa[2]) {
  const view_ctx *c = ctx;
  oc_efoot ft;
  oc_enode_sample q;
  oc_eview_foot(c->w, x, y, &ft);
  oc_enode_ev(c->e, x, y, &ft, 0, &q);
  fa[0] = q.f, fa[1] = q.a;
}

/* At random p and R under view v, the model of f and alpha (the view
** source's: the footprint at p and over the disc's box) holds on random
** q in the disc, near p (where the linear part must be the gradient) and
** out to R; its values are the evaluator's bits with p's footprint. With
** ramp (the step trees), p lies where the lod node's t ramps: its
** footprint in [170, 225] m. */
static void check_view_taylor(const oc_enode *e, const oc_enode_view *v,
                              oct_rng *r, int ramp) {
  oc_eview w = {v->eye[0], v->eye[1], mid_dz(e, v), v->k};
  double d0 = 0, d1 = 0, z2 = w.dz * w.dz;
  if (ramp) {
    d0 = sqrt(fmax(0, 170 * 170 / (w.k * w.k) - z2));
    d1 = sqrt(fmax(0, 225 * 225 / (w.k * w.k) - z2));
  }
  for (int i = 0; i < TAY_POINTS; i++) {
    double x = oct_unif(r, -4500, 4000), y = oct_unif(r, -4500, 4000);
    double R = 4000 * pow(10, oct_unif(r, -3.5, -0.3));
    if (ramp) {
      double d = oct_unif(r, d0, d1), th = oct_unif(r, 0, 2 * PI);
      x = w.ex + d * cos(th), y = w.ey + d * sin(th);
      R = d1 * pow(10, oct_unif(r, -4, -1));
    }
    oc_etfoot tf;
    ball_foot(&w, x, y, R, &tf);
    oc_etaylor m;
    int boxes = 0;
    oc_enode_taylor_view(e, x, y, R, tf.p.v > 0 ? &tf : NULL, &m, &boxes);
    if (tf.p.v > 0) {
      /* tau's shared parts prepared for another disc (here or under a
      ** transform: R is not the disc's) are made afresh: the same bits */
      oc_etfoot other = tf;
      oc_etfoot_prep(&other, 2 * R);
      oc_etaylor m2;
      int boxes2 = 0;
      oc_enode_taylor_view(e, x, y, R, &other, &m2, &boxes2);
      ck_assert_msg(!memcmp(&m, &m2, sizeof m) && boxes == boxes2,
                    "%s at (%g, %g): the model with tau's parts prepared "
                    "for 2R differs",
                    oc_enode_kind(e), x, y);
    }
    oc_enode_sample s, sa;
    oc_enode_ev(e, x, y, &tf.p, 0, &s);
    oc_enode_ev(e, x, y, &tf.p, OC_EV_ALPHA, &sa);
    ck_assert_msg(m.f.v == s.f && m.a.v == sa.a,
                  "%s at (%g, %g): f %.17g alpha %.17g, eval %.17g %.17g",
                  oc_enode_kind(e), x, y, m.f.v, m.a.v, s.f, sa.a);
    char what[64];
    snprintf(what, sizeof what, "%s under k %g", oc_enode_kind(e), v->k);
    view_ctx c = {e, &w};
    tay_worst = fmax(tay_worst, etay_check(&m, x, y, R, r, view_eval, &c, what,
                                           ramp ? &ramp_worst : NULL));
  }
}

/* Models under views (disc.c, lod.c, etaylor.h) on trees with every
** operator: continuous-LoD discs of each noise (one with a lacunarity
** of 2.5), the lod operator between flat discs (all its curvature the
** footprint's), that tree scaled and rotated by a transform (the
** footprint in the child's units) and warped (a fallback), the scene of
** every operator, and an add by a slope weight (a fallback); far, near
** and grazing views, and one whose eye is level with the tree's middle
** (the footprint reaches 0: no rule for tau next to the eye).
** Remainders never exceeded; on the step trees' ramps the errors reach
** a good part of the remainders, so that zeroing the footprint's terms
** (tau's curvature or b''s) fails the check. */
START_TEST(lod_taylor_models) {
  oc_error err;
  oc_enode *st = step_tree();
  oc_enode_xform x = {300, -200, 25, 2.5, 1.3, 5};
  oc_enode *xst = EOK(oc_enode_transform(st, &x, &err));
  /* a lacunarity other than 2 (the octave counts by loops, not ceil) */
  oc_enode_disc_params lp = {
      0, 0, 20000, 50, {OC_ENOISE_RIDGED, 100, 400, 8, 0.6, 2.5, 42}};
  oc_enode *trees[] = {disc(0, 0, 20000, 50, OC_ENOISE_PLAIN, 100, 400, 8),
                       EOK(oc_enode_disc(&lp, &err)),
                       disc(0, 0, 20000, 50, OC_ENOISE_TURBULENCE, 100, 400, 8),
                       disc(0, 0, 20000, 50, OC_ENOISE_RIDGED, 100, 400, 8),
                       st,
                       xst,
                       step_instance(),
                       scene(),
                       slope_scene()};
  size_t nt = sizeof trees / sizeof *trees;
  oc_enode_view views[] = {{{-500, 300, 900}, 3e-3},
                           {{3000, 0, 5000}, 0.02},
                           {{100, 0, 10}, 1},
                           {{0, 0, 35}, 0.05}};
  oct_rng r = oct_rng_new(77);
  tay_worst = ramp_worst = 0;
  for (size_t t = 0; t < nt; t++)
    for (int q = 0; q < 4; q++) {
      if (q == 3 && t != 4) continue; /* level with the step tree's middle */
      check_view_taylor(trees[t], &views[q], &r, 0);
      if ((t == 4 || t == 5) && q > 0) /* (the first view has no ramp) */
        check_view_taylor(trees[t], &views[q], &r, 1);
    }
  printf("lod taylor: the largest error is %.3f of its remainder, %.3f "
         "on the ramps of the footprint's curvature alone\n",
         tay_worst, ramp_worst);
  ck_assert(tay_worst <= 1 && tay_worst > 0.01);
  ck_assert_msg(ramp_worst > 0.2, "ramps: errors reach only %g of remainders",
                ramp_worst);
  for (size_t t = 0; t < nt; t++)
    oc_enode_release(trees[t]);
}
END_TEST

/* A view source's weight (oc_enode_view_weight: alpha alone, no noise
** sums, OC_EV_ALPHA) is bit for bit alpha of the full evaluation under
** the view (oc_enode_eval_view) and of a lazy one, on the step trees
** (lod operators: half the points where their t ramps, the alpha-only
** path through both children), transformed and instanced, and the
** scenes of every operator, under near, far and grazing views. */
START_TEST(view_weight_alpha_only) {
  oc_error err;
  oc_enode *st = step_tree();
  oc_enode_xform x = {300, -200, 25, 2.5, 1.3, 5};
  oc_enode *trees[] = {st, EOK(oc_enode_transform(st, &x, &err)),
                       step_instance(), scene(), slope_scene()};
  oc_enode_view views[] = {
      {{-500, 300, 900}, 3e-3}, {{3000, 0, 5000}, 0.02}, {{100, 0, 10}, 1}};
  oct_rng r = oct_rng_new(83);
  int n = 0;
  for (size_t t = 0; t < sizeof trees / sizeof *trees; t++)
    for (int q = 0; q < 3; q++) {
      oc_elevation src;
      ck_assert(oc_enode_elevation_view(trees[t], NULL, &views[q], &src,
                                        &err) == OC_OK);
      const oc_enode_view *v = &views[q];
      double dz = mid_dz(trees[t], v);
      double d0 = sqrt(fmax(0, 170 * 170 / (v->k * v->k) - dz * dz));
      double d1 = sqrt(fmax(0, 225 * 225 / (v->k * v->k) - dz * dz));
      for (int i = 0; i < 400; i++) {
        double px = oct_unif(&r, -4500, 4000), py = oct_unif(&r, -4500, 4000);
        if (i % 2 && d1 > d0) {
          double d = oct_unif(&r, d0, d1), th = oct_unif(&r, 0, 2 * PI);
          px = v->eye[0] + d * cos(th), py = v->eye[1] + d * sin(th);
        }
        oc_enode_sample s, l;
        ck_assert(oc_enode_eval_view(trees[t], px, py, v, &s, &err) == OC_OK);
        oc_efoot ft;
        oc_eview w = {v->eye[0], v->eye[1], dz, v->k};
        oc_eview_foot(&w, px, py, &ft);
        oc_enode_ev(trees[t], px, py, &ft, OC_EV_LAZY, &l);
        double a = oc_enode_view_weight(src.ud, px, py);
        ck_assert_msg(!memcmp(&a, &s.a, sizeof a) &&
                          !memcmp(&a, &l.a, sizeof a),
                      "%s at (%g, %g): weight %.17g, alpha %.17g (lazy %.17g)",
                      oc_enode_kind(trees[t]), px, py, a, s.a, l.a);
        n += a > 0 && a < 1;
      }
      src.release(src.ud);
    }
  ck_assert(n > 500);
  for (size_t t = 0; t < sizeof trees / sizeof *trees; t++)
    oc_enode_release(trees[t]);
}
END_TEST

/* tau's shared parts (oc_etfoot_prep, two divisions): on random views
** (the eye level with the point too: footprints near 0) and discs, dlo
** and dhi bound log2(fhi / foot(p)) and log2(foot(p) / flo) no less
** tightly than the rule of five divisions did (within 1e-12 of (fhi /
** foot(p) - 1) / ln 2 and (foot(p) / flo - 1) / ln 2, and no less, long
** double's), e2 k^2 / (2 ln 2 flo^2) within 1e-11. A
** similarity's child (oc_etfoot_scaled, eops.c's transforms: scales 0.2
** to 5, any rotation) has the direct prep's tc, lf, curved, R and
** footprints bit for bit and dlo, dhi, e2 and tg no less, within 1e-9
** (dhi and e2: 1e-11 (1 + dhi), the pads for the radius' hair);
** the same bits when tf was prepared for another radius; where the
** footprint comes near 0 on the disc, the direct prep's all. */
START_TEST(footprint_prep_rules) {
  oct_rng r = oct_rng_new(61);
  int derived = 0, direct = 0;
  for (int i = 0; i < 20000; i++) {
    oc_eview w = {oct_unif(&r, -5000, 5000), oct_unif(&r, -5000, 5000),
                  i % 4   ? oct_unif(&r, 10, 3000)
                  : i % 8 ? oct_unif(&r, 0, 1e-5)
                          : 0,
                  pow(10, oct_unif(&r, -4, -1))};
    double x = oct_unif(&r, -5000, 5000), y = oct_unif(&r, -5000, 5000);
    if (i % 4 == 0) x = w.ex + oct_unif(&r, -3, 3), y = w.ey;
    double R = 4000 * pow(10, oct_unif(&r, -4, -0.3));
    oc_etfoot tf;
    ball_foot(&w, x, y, R, &tf);
    if (!(tf.p.v > 0)) continue;
    const oc_efoot *ft = &tf.p;
    double kr = tf.b.k * R * (1 + 1e-12);
    double flo = fmax(tf.b.lo, ft->v - kr), fhi = fmin(tf.b.hi, ft->v + kr);
    /* (the bounds ln(1 + x) <= x and -ln y <= 1 / y - 1: as tight as
    ** the five divisions' (fhi / v - 1) / ln 2 and (v / flo - 1) / ln 2) */
    long double lo2 =
        log1pl(((long double)fmax(fhi, ft->v) - ft->v) / ft->v) / logl(2);
    long double dlo = ((long double)fmax(fhi, ft->v) - ft->v) / ft->v / logl(2);
    ck_assert_msg(tf.dlo >= lo2 && tf.dlo >= dlo &&
                      tf.dlo <= dlo * (1 + 1e-12L) + 1e-300,
                  "dlo %.17g against %.17Lg", tf.dlo, dlo);
    ck_assert(tf.curved == (flo > 0));
    if (tf.curved) {
      long double fl = fmin(flo, ft->v);
      long double hi2 = log1pl(((long double)ft->v - fl) / fl) / logl(2);
      long double dhi = ((long double)ft->v - fl) / fl / logl(2);
      long double e2 = 0.5L * tf.b.k * tf.b.k / (logl(2) * flo * flo);
      ck_assert_msg(tf.dhi >= hi2 && tf.dhi >= dhi &&
                        tf.dhi <= dhi * (1 + 1e-12L) + 1e-300,
                    "dhi %.17g against %.17Lg", tf.dhi, dhi);
      ck_assert_msg(tf.e2 >= e2 && tf.e2 <= e2 * (1 + 1e-11L),
                    "e2 %.17g against %.17Lg", tf.e2, e2);
    }
    /* the child's */
    double s = pow(5, oct_unif(&r, -1, 1)), th = oct_unif(&r, 0, 2 * PI);
    double is = 1 / s, Rc = R * is * (1 + 1e-12);
    oc_efoot cp = {ft->v * is, cos(th) * ft->gx - sin(th) * ft->gy,
                   sin(th) * ft->gx + cos(th) * ft->gy};
    oc_etfoot d, c, c2, other = tf;
    d.p = cp;
    d.b = (oc_efootb){tf.b.lo * is, tf.b.hi * is, tf.b.k};
    oc_etfoot_prep(&d, Rc);
    c.p = c2.p = cp;
    c.b = c2.b = d.b;
    oc_etfoot_scaled(&tf, R, s, Rc, &c);
    oc_etfoot_prep(&other, 2 * R);
    oc_etfoot_scaled(&other, R, s, Rc, &c2);
    /* (field by field: the struct's tail padding is not written) */
    double cf[] = {c.p.v, c.p.gx, c.p.gy, c.b.lo, c.b.hi, c.b.k, c.R,
                   c.tc,  c.dlo,  c.dhi,  c.e2,   c.tg,   c.lf,  c.curved};
    double cf2[] = {c2.p.v, c2.p.gx, c2.p.gy, c2.b.lo,  c2.b.hi,
                    c2.b.k, c2.R,    c2.tc,   c2.dlo,   c2.dhi,
                    c2.e2,  c2.tg,   c2.lf,   c2.curved};
    ck_assert(!memcmp(cf, cf2, sizeof cf));
    ck_assert(!memcmp(&c.p, &d.p, sizeof d.p) &&
              !memcmp(&c.b, &d.b, sizeof d.b));
    ck_assert(c.R == d.R && c.tc == d.tc && c.lf == d.lf &&
              c.curved == d.curved);
    if (!tf.curved || tf.dhi > 0x1p20) {
      ck_assert(c.dlo == d.dlo && c.dhi == d.dhi && c.e2 == d.e2 &&
                c.tg == d.tg);
      direct++;
      continue;
    }
    derived++;
    ck_assert_msg(c.dlo >= d.dlo && c.dlo <= d.dlo * (1 + 1e-9) + 1e-14,
                  "dlo %.17g, direct %.17g (s %g)", c.dlo, d.dlo, s);
    ck_assert_msg(c.dhi >= d.dhi &&
                      c.dhi <= d.dhi * (1 + 1e-11 * (1 + tf.dhi)) + 1e-14,
                  "dhi %.17g, direct %.17g (s %g)", c.dhi, d.dhi, s);
    ck_assert_msg(c.e2 >= d.e2 && c.e2 <= d.e2 * (1 + 1e-11 * (1 + tf.dhi)),
                  "e2 %.17g, direct %.17g (s %g)", c.e2, d.e2, s);
    ck_assert_msg(c.tg >= d.tg && c.tg <= d.tg * (1 + 1e-9),
                  "tg %.17g, direct %.17g (s %g)", c.tg, d.tg, s);
  }
  printf("footprint prep: %d children derived, %d prepared\n", derived, direct);
  ck_assert(derived > 5000 && direct > 50);
}
END_TEST

/* The disc's box bounds' filter factor (disc.c, noise_bounds): per box
** min(k / (ln 2 lo), 2 k s_i / ln 2) (1 + 1e-14), s_i the octave's
** frequency by products, no less than oc_elod_kappa_bound_t's k / (ln 2
** max(lo, w_i / 2)) with w_i = 1 / s_i and within 1e-13 of it;
** oc_elod_kappa_bound_c with that factor gives kappa_bound_t's range bit
** for bit and its Lipschitz bound within 1e-13, on random footprint
** ranges (lo 0 too) and octaves from 10 m to 10 km, lacunarities 1.7 to
** 2.5. */
START_TEST(kappa_bound_factor) {
  oct_rng r = oct_rng_new(67);
  int ramps = 0;
  for (int i = 0; i < 20000; i++) {
    double k = pow(10, oct_unif(&r, -4, -1));
    double lo = i % 16 ? pow(10, oct_unif(&r, -1, 3)) : 0;
    oc_efootb fb = {lo, lo * oct_unif(&r, 1, 3) + oct_unif(&r, 0.1, 10), k};
    double wl = pow(10, oct_unif(&r, 1, 4)), lac = oct_unif(&r, 1.7, 2.5);
    double s = 1 / wl, dt = log2(lac);
    double tmin = log2(wl / fb.hi) - 1e-12;
    double tmax = lo > 0 ? log2(wl / lo) + 1e-12 : INFINITY;
    double clo = lo > 0 ? k / (0.69314718055994530942 * lo) : INFINITY;
    double cs = 2 * k / 0.69314718055994530942;
    for (int o = 0; o < 12; o++, s *= lac) {
      double c = fmin(clo, cs * s) * (1 + 1e-14);
      double ct = k / (0.69314718055994530942 * fmax(lo, 1 / s / 2));
      ck_assert_msg(c >= ct && c <= ct * (1 + 1e-13), "c %.17g against %.17g",
                    c, ct);
      double l0, h0, p0, l1, h1, p1;
      oc_elod_kappa_bound_t(1 / s, tmin - o * dt, tmax - o * dt, &fb, &l0, &h0,
                            &p0);
      oc_elod_kappa_bound_c(tmin - o * dt, tmax - o * dt, c, &l1, &h1, &p1);
      ck_assert(l0 == l1 && h0 == h1);
      ck_assert_msg(p1 >= p0 && p1 <= p0 * (1 + 1e-13),
                    "lip %.17g against %.17g", p1, p0);
      ramps += p0 > 0;
    }
  }
  ck_assert(ramps > 10000);
}
END_TEST

/* oc_log2 (core/log2.h), the log2 of a disc's wavelength under a view:
** within 2e-15 + 2^-52 |log2 w| of log2 w (long double's, 64 bits) on
** 10^5 wavelengths from 1e-3 to 1e9 and on mantissas j / 128, (j +
** 1/2) / 128 (where its table's index turns) and just below (j + 1) /
** 128 in several octaves, powers of two exact; oc_log2_coarse within
** log2(1 / (1 - 2^-8)) < 0.00565 of it,
** the margin disc.c's octave counts take below their 2^-7; oc_log2_any
** libm's log2 off the normal numbers. */
START_TEST(log2_inline_accuracy) {
  oct_rng r = oct_rng_new(59);
  double worst = 0, cworst = 0;
  for (int i = 0; i < 100000 + 128 * 3 * 12; i++) {
    double w;
    if (i < 100000) {
      w = pow(10, oct_unif(&r, -3, 9));
    } else {
      int k = i - 100000, j = k % 128, e = (k / 384) - 5;
      double m = 1 + (j + 0.5 * ((k / 128) % 3)) / 128; /* j, j + 1/2 */
      if ((k / 128) % 3 == 2) m = nextafter(1 + (j + 1) / 128.0, 0);
      w = ldexp(m, 3 * e);
    }
    double lw = oc_log2(w), lc = oc_log2_coarse(w);
    long double ex = log2l((long double)w);
    double err = (double)fabsl((long double)lw - ex);
    ck_assert_msg(err <= 2e-15 + 0x1p-52 * fabs(lw), "log2 %.17g: %g off", w,
                  err);
    if (err > worst) worst = err;
    double cerr = fabs(lc - lw);
    ck_assert_msg(cerr < 0.00565, "coarse log2 %.17g: %g off", w, cerr);
    if (cerr > cworst) cworst = cerr;
  }
  for (int e = -20; e <= 40; e++)
    ck_assert(oc_log2(ldexp(1, e)) == e);
  /* oc_log2_any (footprints, user numbers): oc_log2 on normal numbers,
  ** libm's log2 where oc_log2's table would read a wrong exponent */
  ck_assert(oc_log2_any(437.0) == oc_log2(437.0));
  ck_assert(oc_log2_any(0x1p-1022) == -1022);
  ck_assert(oc_log2_any(0x1p-1060) == -1060); /* subnormal */
  ck_assert(oc_log2_any(0) == -INFINITY && oc_log2_any(INFINITY) == INFINITY);
  ck_assert(isnan(oc_log2_any(NAN)) && isnan(oc_log2_any(-1)));
  /* (the bound is not loose by orders: the polynomial and sums round) */
  ck_assert(worst > 1e-17 && cworst > 0.005);
  printf("oc_log2: at most %.3g from log2, coarse %.5f\n", worst, cworst);
}
END_TEST

/* A disc's log2 of its wavelength, made inline (enode.h, oc_edisc_lw:
** core/log2.h, no bytes kept: a noisy disc is 80 bytes, 88 with float
** gain and lacunarity, 96 else), within 1e-14 of log2's; under a view
** its models' tau(p) is that minus the footprint's log2 made once per
** query (oc_etfoot_prep: lf, oc_log2_any of the footprint, within 1e-14
** of libm's, and tg the norm of tau's linear part, the bits the per-disc
** rule computed), the evaluator's t0 the same bits,
** so that for each storage the LoD models are the evaluator's values and
** hold (check_view_taylor), on ramping octaves too (a near view: every
** point's finest kept octave ramps), the octave counts made from the
** coarse log2 where it is sure and from tau's range where not. */
START_TEST(disc_lod_wavelength_log) {
  oc_error err;
  double gl[3][2] = {{0, 0}, {0.375, 2}, {0.45, 2.13}};
  size_t bytes[3] = {80, 88, 96};
  oc_enoise_kind kinds[3] = {OC_ENOISE_PLAIN, OC_ENOISE_TURBULENCE,
                             OC_ENOISE_RIDGED};
  oc_enode_view views[2] = {{{-500, 300, 900}, 3e-3}, {{3000, 0, 5000}, 0.02}};
  oct_rng r = oct_rng_new(31);
  tay_worst = ramp_worst = 0;
  for (int g = 0; g < 3; g++) {
    oc_enode_disc_params p = {
        0, 0, 20000, 50, {kinds[g], 100, 437, 9, gl[g][0], gl[g][1], 5 + g}};
    oc_enode *d = EOK(oc_enode_disc(&p, &err));
    ck_assert_uint_eq(oc_enode_size(d), bytes[g]);
    double lw = oc_edisc_lw(d);
    ck_assert(lw == oc_log2(437.0) && fabs(lw - log2(437.0)) <= 1e-14);
    for (int q = 0; q < 2; q++) {
      check_view_taylor(d, &views[q], &r, 0);
      oc_eview w = {views[q].eye[0], views[q].eye[1], mid_dz(d, &views[q]),
                    views[q].k};
      for (int i = 0; i < 50; i++) {
        double x = oct_unif(&r, -4500, 4000), y = oct_unif(&r, -4500, 4000);
        double R = 4000 * pow(10, oct_unif(&r, -3.5, -0.3));
        oc_etfoot tf;
        ball_foot(&w, x, y, R, &tf);
        oc_etay m, ml;
        double lo, hi, lol, hil;
        int c = oc_elod_tau_taylor(437, &tf, R, &m, &lo, &hi);
        int cl = oc_elod_tau_taylor_l(lw, &tf, &ml, &lol, &hil);
        ck_assert(tf.lf == oc_log2_any(tf.p.v) && tf.tg == oc_etay_gnorm(&m));
        ck_assert(fabs(tf.lf - log2(tf.p.v)) <= 1e-14 * (1 + fabs(tf.lf)));
        ck_assert(ml.v == lw - tf.lf && c == cl);
        ck_assert(ml.gx == m.gx && ml.gy == m.gy && ml.e2 == m.e2);
        /* log2(w / foot) and log2 w - log2 foot: a few ulps apart, well
        ** inside the ranges' padding of 1e-12 */
        ck_assert(fabs(ml.v - m.v) <= 1e-14 * (1 + fabs(m.v)));
        ck_assert(lol <= ml.v && ml.v <= hil);
        /* the evaluator's filtered sum is the model's value */
        oc_enode_sample s;
        oc_etay f;
        oc_enode_ev(d, x, y, &tf.p, 0, &s);
        ck_assert(oc_edisc_taylor_f_view(d, x, y, R, &tf, &f));
        ck_assert_msg(f.v == s.f, "f %.17g, eval %.17g", f.v, s.f);
      }
      /* a sweep across footprints (a line away from the eye, tau moving
      ** by 1e-3 octave or less a step, the radius scattered): the octave
      ** counts near each threshold, from the coarse log2 where it is sure
      ** and from tau's range where not, keep model and evaluator equal
      ** (a count one too low, or a ramping octave taken whole, would not:
      ** with a margin of 2^-11 instead of 2^-7, below the coarse log2's
      ** error, point 2156 of the near view differs by 1.2e-9) */
      for (int i = 0; i < 3000; i++) {
        double x = -4500 + 8500 * (i / 3000.0), y = 0.2 * x + 100;
        double R = 4000 * pow(10, -3.5 + 3.2 * ((i * 7) % 3000) / 3000.0);
        oc_etfoot tf;
        ball_foot(&w, x, y, R, &tf);
        oc_enode_sample s;
        oc_etay f;
        oc_enode_ev(d, x, y, &tf.p, 0, &s);
        if (oc_edisc_taylor_f_view(d, x, y, R, &tf, &f))
          ck_assert_msg(f.v == s.f, "sweep %d: f %.17g, eval %.17g", i, f.v,
                        s.f);
      }
    }
    oc_enode_release(d);
  }
  ck_assert(tay_worst <= 1 && tay_worst > 0.01);
}
END_TEST

/* The LoD models split an octave into quadratic or flat at r =
** OC_ETAY_LOD_CHOICE R (etaylor.h), not the exact models' OC_ETAY_CHOICE
** R. Under a view whose footprint is far below every octave (each
** filter 1: the exact octaves, the same value bits) a plain and a
** turbulent disc's LoD model is never above the exact one's remainder
** at that radius (each octave's smaller bound there) and below it where
** an octave's choice differs (at 0.25 both: the same models, no point
** lower). */
START_TEST(lod_octave_choice) {
  oc_enoise_kind kinds[2] = {OC_ENOISE_PLAIN, OC_ENOISE_TURBULENCE};
  oc_enode_view v = {{-500, 300, 900}, 1e-9};
  oct_rng r = oct_rng_new(12);
  int lower = 0, n = 0;
  for (int g = 0; g < 2; g++) {
    oc_enode *d = disc(0, 0, 20000, 50, kinds[g], 100, 400, 8);
    oc_eview w = {v.eye[0], v.eye[1], mid_dz(d, &v), v.k};
    for (int i = 0; i < 400; i++, n++) {
      double x = oct_unif(&r, -4500, 4000), y = oct_unif(&r, -4500, 4000);
      double R = 4000 * pow(10, oct_unif(&r, -3.5, -0.3));
      oc_etfoot tf;
      ball_foot(&w, x, y, R, &tf);
      ck_assert(tf.p.v > 0 && tf.p.v < 1e-3);
      oc_etay fl, fe;
      ck_assert(oc_edisc_taylor_f_view(d, x, y, R, &tf, &fl));
      oc_edisc_taylor_f(d, x, y, R, &fe);
      ck_assert(fl.v == fe.v);
      double rk = OC_ETAY_LOD_CHOICE * R;
      double el = oc_etay_rem(&fl, rk), ee = oc_etay_rem(&fe, rk);
      ck_assert_msg(el <= ee * (1 + 1e-12), "(%g, %g) R %g: %.17g > %.17g", x,
                    y, R, el, ee);
      lower += el < ee * (1 - 1e-9);
    }
    oc_enode_release(d);
  }
  printf("lod octave choice: %d of %d LoD models below the exact ones' "
         "remainder at %g R\n",
         lower, n, OC_ETAY_LOD_CHOICE);
  ck_assert_int_gt(lower, n / 20);
}
END_TEST

/* ---- tracing --------------------------------------------------------- */

/* First t where o + t d is on or below the surface (inside the domain,
** where the weight allows), by fixed steps then bisection. */
static double march(const oc_esurface *es, oc_vec3 o, oc_vec3 d, double t1,
                    double ds) {
  const oc_elevation *s = es->src;
  double prev = 0, zlo, zhi;
  s->range(s->ud, s->x0, s->y0, s->x1, s->y1, &zlo, &zhi);
  int above = 0;
  for (double t = 0; t <= t1; prev = t, t += ds) {
    oc_vec3 p = oct_add(o, oct_mul(d, t));
    if (p.x < s->x0 || p.x > s->x1 || p.y < s->y0 || p.y > s->y1 || p.z < zlo) {
      above = 0;
      continue;
    }
    double h = p.z - s->height(s->ud, p.x, p.y, NULL);
    int hole = es->weight(es->wud, p.x, p.y) < es->T;
    if (hole || h > 0) {
      above = h > 0;
      continue;
    }
    if (!above) return t;
    double a = prev, b = t;
    for (int k = 0; k < 40; k++) {
      double m = 0.5 * (a + b);
      oc_vec3 q = oct_add(o, oct_mul(d, m));
      if (q.z - s->height(s->ud, q.x, q.y, NULL) > 0)
        a = m;
      else
        b = m;
    }
    return b;
  }
  return INFINITY;
}

START_TEST(lod_trace_against_march) {
  oc_error err;
  oc_enode *e = _i ? slope_scene() : scene();
  oc_vec3 eye = {-2600, -2400, 1100}, target = {300, 300, 0};
  /* a coarse pixel, so that the LoD drops octaves across the view */
  oc_enode_view v = {{eye.x, eye.y, eye.z}, 4e-3};
  oc_elevation src;
  ck_assert_msg(oc_enode_elevation_view(e, NULL, &v, &src, &err) == OC_OK, "%s",
                err.msg);
  /* rays in holes (beyond the base disc's Omega_T) cross them on the
  ** view's weight bounds */
  oc_esurface es = {&src, oc_enode_view_weight, src.ud, OC_ENODE_T,
                    oc_enode_view_weight_bound};
  /* the joint query (one traversal a step) answers range and slope; the
  ** march steps on first-order models; the weight's bounds are the
  ** view's box bounds' (bounds_with_lod checks those) */
  ck_assert(src.bound && src.taylor);
  for (int k = 0; k < 40; k++) {
    double x0 = -2000 + 97.3 * k, y0 = -1500 + 71.9 * k, sz = 3.0 * (k + 1);
    double lo, hi, lam, rlo, rhi;
    src.bound(src.ud, x0, y0, x0 + sz, y0 + 0.5 * sz, &lo, &hi, &lam);
    src.range(src.ud, x0, y0, x0 + sz, y0 + 0.5 * sz, &rlo, &rhi);
    ck_assert(lo == rlo && hi == rhi && lo < hi);
    ck_assert(lam == src.slope(src.ud, x0, y0, x0 + sz, y0 + 0.5 * sz));
    oc_ebound b;
    bound_view(e, &v, x0, y0, x0 + sz, y0 + 0.5 * sz, &b);
    oc_enode_view_weight_bound(src.ud, x0, y0, x0 + sz, y0 + 0.5 * sz, &rlo,
                               &rhi, &lam);
    ck_assert(rlo == b.alo && rhi == b.ahi && lam == b.la && b.flo == lo);
  }
  oc_vec3 w = oct_sub(target, eye);
  w = oct_mul(w, 1 / oct_len(w));
  oc_vec3 rt = oct_cross(w, oct_v(0, 0, 1));
  rt = oct_mul(rt, 1 / oct_len(rt));
  oc_vec3 up = oct_cross(rt, w);
  double eps_k = 1e-4, eps_min = 1e-4;
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  int hits = 0, differ = 0, n = 0;
  double ev = 0;
  for (int j = 0; j < MARCH_NY; j++)
    for (int i = 0; i < MARCH_NX; i++) {
      double x = (i + 0.5) / MARCH_NX * 2 - 1,
             y = ((j + 0.5) / MARCH_NY * 2 - 1) * 0.3;
      oc_vec3 d = oct_add(w, oct_add(oct_mul(rt, 0.6 * x), oct_mul(up, y)));
      d = oct_mul(d, 1 / oct_len(d));
      double t, tref = march(&es, eye, d, 20000, 0.5);
      int h = oc_etrace(&tr, eye, d, 0, 1e6, 0, &t, &ev);
      n++;
      if ((h != 0) != isfinite(tref)) {
        differ++;
        continue;
      }
      if (!h) continue;
      hits++;
      ck_assert_msg(fabs(t - tref) <= 0.5 + 4 * (eps_k * tref + eps_min),
                    "ray %d %d: traced %.4f, march %.4f", i, j, t, tref);
    }
  ck_assert_msg(hits > n / 2, "%d of %d hit", hits, n);
  ck_assert_msg(differ <= 2, "%d rays disagree", differ);
  /* the models save calls against the box bounds' march on those rays
  ** (where the top node has rules: a slope-weighted add has none, its
  ** models are the box bound's flat ones) */
  oc_elevation boxed = src;
  boxed.taylor = NULL;
  oc_esurface eb = {&boxed, oc_enode_view_weight, src.ud, OC_ENODE_T, NULL};
  oc_etracer tb;
  oc_etracer_init(&tb, &eb, OC_TRACE_SEGMENT, eps_k, eps_min);
  double evb = 0;
  for (int j = 0; j < MARCH_NY; j++)
    for (int i = 0; i < MARCH_NX; i++) {
      double x = (i + 0.5) / MARCH_NX * 2 - 1,
             y = ((j + 0.5) / MARCH_NY * 2 - 1) * 0.3, t;
      oc_vec3 d = oct_add(w, oct_add(oct_mul(rt, 0.6 * x), oct_mul(up, y)));
      oc_etrace(&tb, eye, oct_mul(d, 1 / oct_len(d)), 0, 1e6, 0, &t, &evb);
    }
  printf("lod trace%s: %.1f calls a ray on models, %.1f on box bounds\n",
         _i ? " (slope weight)" : "", ev / n, evb / n);
  if (!_i) ck_assert_msg(ev < evb, "models %g calls, box bounds %g", ev, evb);
  /* a whole render: the same image on 1 and 2 threads */
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = eye;
  rp.camera.target = target;
  rp.camera.up = oct_v(0, 0, 1);
  rp.width = 48;
  rp.height = 32;
  oc_image *img[2];
  for (int k = 0; k < 2; k++) {
    omp_set_num_threads(k + 1);
    img[k] = oc_render_surface(&es, &rp, NULL, &err);
    ck_assert_msg(img[k], "%s", err.msg);
  }
  omp_set_num_threads(2);
  ck_assert(
      memcmp(oc_image_cdata(img[0]), oc_image_cdata(img[1]),
             (size_t)48 * 32 * oc_image_channels(img[0]) * sizeof(float)) == 0);
  oc_image_free(img[0]);
  oc_image_free(img[1]);
  src.release(src.ud);
  oc_enode_release(e);
}
END_TEST

/* A coarser level (oc_elevation's coarser: shadow rays and AO of LoD
** renders): the disc's f with every footprint foot replaced by sqrt(foot^2
** + m^2), the octave sum of check_disc_kind; m = 0 the source bit for
** bit; exact sources have no levels, so their renders ignore the sun's
** radius that widens the shadow rays' cones. */
START_TEST(coarser_levels) {
  const int N = OCT_N;
  const double wl = OCT_WL, h = OCT_H;
  oc_enode *d[OCT_N + 1], **dd = d;
  oc_enode_view v = {{-3000, 500, 2500}, 1e-3};
  octave_discs(dd, OC_ENOISE_PLAIN);
  double dz = mid_dz(d[N], &v);
  oc_error err;
  oc_elevation src;
  ck_assert_msg(oc_enode_elevation_view(d[N], NULL, &v, &src, &err) == OC_OK,
                "%s", err.msg);
  ck_assert(src.coarser != NULL);
  const double ms[] = {0, 3, 40, 250};
  oct_rng r = oct_rng_new(5);
  int ramps = 0;
  for (size_t j = 0; j < sizeof ms / sizeof *ms; j++) {
    oc_elevation c;
    ck_assert_msg(src.coarser(src.ud, ms[j], &c, &err) == OC_OK, "%s", err.msg);
    ck_assert(c.x0 == src.x0 && c.y0 == src.y0 && c.x1 == src.x1 &&
              c.y1 == src.y1);
    for (int k = 0; k < 400; k++) {
      double x = oct_unif(&r, -6000, 6000), y = oct_unif(&r, -6000, 6000);
      double ft = hypot(foot(&v, dz, x, y), ms[j]);
      double ref = octave_ref(d, h, wl, ft, x, y, &ramps);
      double f = c.height(c.ud, x, y, NULL);
      ck_assert_msg(fabs(f - ref) <= 1e-9 * (1 + fabs(ref)),
                    "m %g at (%g, %g): %.12g, sum %.12g", ms[j], x, y, f, ref);
      if (ms[j] == 0) ck_assert(f == src.height(src.ud, x, y, NULL));
      /* its weight is the tree's under the level's view */
      ck_assert(oc_enode_view_weight(c.ud, x, y) ==
                oc_enode_view_weight(src.ud, x, y));
    }
    c.release(c.ud);
  }
  ck_assert_msg(ramps > 1000, "only %d samples on a ramp", ramps);
  oc_elevation bad;
  ck_assert(src.coarser(src.ud, -1, &bad, &err) == OC_EINVAL);
  ck_assert(src.coarser(src.ud, NAN, &bad, &err) == OC_EINVAL);
  src.release(src.ud);
  /* the exact source: no levels, the same image for any sun radius */
  oc_elevation ex;
  ck_assert(oc_enode_elevation(d[N], NULL, &ex, &err) == OC_OK);
  ck_assert(ex.coarser == NULL);
  oc_esurface es = {&ex, NULL, NULL, OC_ENODE_T, NULL};
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = oct_v(-3000, 500, 2500);
  rp.camera.target = oct_v(0, 0, 0);
  rp.width = 24;
  rp.height = 16;
  rp.sun_direction = oct_v(-1, 0, 0.3); /* low: some shadows */
  oc_image *img[2];
  for (int k = 0; k < 2; k++) {
    rp.sun_radius = k ? 0.1 : 0;
    img[k] = oc_render_surface(&es, &rp, NULL, &err);
    ck_assert_msg(img[k], "%s", err.msg);
  }
  ck_assert(
      memcmp(oc_image_cdata(img[0]), oc_image_cdata(img[1]),
             (size_t)24 * 16 * oc_image_channels(img[0]) * sizeof(float)) == 0);
  oc_image_free(img[0]);
  oc_image_free(img[1]);
  rp.sun_radius = 0.2;
  ck_assert(oc_render_check_shade(&rp, &err) == OC_EINVAL);
  ck_assert(strstr(err.msg, "sun.radius") != NULL);
  ex.release(ex.ud);
  for (int i = 0; i <= N; i++)
    oc_enode_release(d[i]);
}
END_TEST

int main(void) {
  Suite *s = suite_create("elevation_lod");
  TCase *tc = tcase_create("lod");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, footprint_zero_is_full_detail);
  tcase_add_test(tc, disc_octaves_filtered);
  tcase_add_test(tc, lod_operator_formula);
  tcase_add_test(tc, continuous_across_thresholds);
  tcase_add_loop_test(tc, gradients_with_lod, 0, 2);
  tcase_add_test(tc, bounds_with_lod);
  tcase_add_test(tc, lod_taylor_models);
  tcase_add_test(tc, footprint_prep_rules);
  tcase_add_test(tc, view_weight_alpha_only);
  tcase_add_test(tc, kappa_bound_factor);
  tcase_add_test(tc, log2_inline_accuracy);
  tcase_add_test(tc, disc_lod_wavelength_log);
  tcase_add_test(tc, lod_octave_choice);
  tcase_add_loop_test(tc, lod_trace_against_march, 0, 2);
  tcase_add_test(tc, coarser_levels);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
