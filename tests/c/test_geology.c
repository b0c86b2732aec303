/*
** test_geology.c — resistance trees and the erosion node against their
** formulas (docs/fields.md, "Geology"): strata, layers, clamp, taper,
** faults (discontinuous exactly on the domain's boundary), erosion (never
** adds material), gradients, Lipschitz bounds (global and local), column
** spans, parameter errors, and meshes of an eroded cliff identical for 1
** and 2 threads.
*/
#include <omp.h>
#include <string.h>

#include "core/noise.h"
#include "geology/geology.h"
#include "ocheck.h"

static const oc_vec3 LO = {-40, -40, -40}, HI = {40, 40, 40};

static oc_noise noise(double wl, double amp, double off, int oct,
                      uint64_t seed) {
  oc_noise n = {wl, amp, off, oct, seed};
  return n;
}

/* The strata formula, written from docs/fields.md. */
static double strata_ref(const oc_noise *n, double z) {
  double tmax = 2 - ldexp(1, 1 - n->octaves);
  double t = oc_turb3(n->seed, n->octaves,
                      oct_v(OC_STRATA_X, OC_STRATA_Y, z / n->wavelength), NULL);
  return n->offset + n->amplitude * t / tmax;
}

static double clampd(double v, double lo, double hi) {
  return v < lo ? lo : v > hi ? hi : v;
}

START_TEST(strata_formula) {
  oc_error err;
  oct_rng r = oct_rng_new(11);
  oc_noise nz = noise(7.5, 0.8, 0.1, 5, 42);
  oc_program *pr = oct_compile(OCT_OK(oc_strata(&nz, &err)), 0, 0);
  double vmin = INFINITY, vmax = -INFINITY;
  for (int i = 0; i < 2000; i++) {
    oc_vec3 p = oct_in_box(&r, LO, HI);
    double v = oc_program_eval(pr, p);
    ck_assert_double_eq_tol(v, strata_ref(&nz, p.z), 1e-13);
    /* a function of z alone */
    ck_assert(v == oc_program_eval(pr, oct_v(oct_unif(&r, -1e4, 1e4),
                                             oct_unif(&r, -1e4, 1e4), p.z)));
    ck_assert(v >= 0.1 - 1e-15 && v <= 0.9 + 1e-15);
    vmin = fmin(vmin, v);
    vmax = fmax(vmax, v);
    oc_vec3 g;
    oc_program_gradient(pr, p, &g);
    ck_assert(g.x == 0 && g.y == 0);
    if (i < 200) oct_check_grad(pr, p, 1e-5, 1e-7);
  }
  ck_assert(vmax - vmin > 0.3); /* real layering, not a constant */
  oct_check_lipschitz(pr, LO, HI, 3000, &r);
  oc_aabb b = oc_program_bounds(pr);
  ck_assert(isinf(b.lo.z) && isinf(b.hi.z));
  /* the bound is the formula's: |A| / tmax * Ln * o / wl */
  double L = 0.8 / (2 - ldexp(1, -4)) * oc_turb3_lipschitz(5) / 7.5;
  ck_assert_double_eq_tol(oc_program_lipschitz(pr), L, 1e-12 * L);
  oc_program_free(pr);
}
END_TEST

START_TEST(strata_deterministic_by_seed) {
  oc_error err;
  oc_noise a = noise(5, 1, 0, 4, 1), b = a, c = a;
  c.seed = 2;
  oc_program *pa = oct_compile(OCT_OK(oc_strata(&a, &err)), 0, 0);
  oc_program *pb = oct_compile(OCT_OK(oc_strata(&b, &err)), 0, 0);
  oc_program *pc = oct_compile(OCT_OK(oc_strata(&c, &err)), 0, 0);
  int differ = 0;
  for (int i = 0; i < 100; i++) {
    oc_vec3 p = oct_v(0, 0, i * 0.37);
    ck_assert(oc_program_eval(pa, p) == oc_program_eval(pb, p));
    differ += fabs(oc_program_eval(pa, p) - oc_program_eval(pc, p)) > 1e-3;
  }
  ck_assert_int_gt(differ, 80);
  oc_program_free(pa);
  oc_program_free(pb);
  oc_program_free(pc);
}
END_TEST

START_TEST(layer_formula) {
  oc_error err;
  oct_rng r = oct_rng_new(12);
  oc_vec3 o = oct_v(1, -2, 3), n = oct_v(0.3, -0.2, 1);
  oc_vec3 nu = oct_mul(n, 1 / oct_len(n));
  oc_noise nz = noise(6, 0.15, 0.05, 3, 9);
  for (int variant = 0; variant < 3; variant++) {
    double E = variant == 1 ? -0.7 : 0.6;
    const oc_noise *pn = variant == 2 ? &nz : NULL;
    oc_program *pr =
        oct_compile(OCT_OK(oc_geology_layer(o, n, 4, E, pn, &err)), 0, 0);
    for (int i = 0; i < 1000; i++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      if (i % 2)
        p = oct_add(o, oct_add(oct_mul(nu, oct_unif(&r, -5, 5)),
                               oct_v(oct_unif(&r, -9, 9), 0, 0)));
      double d = oct_dot(oct_sub(p, o), nu);
      double want = E * oct_g(fabs(d) / 4);
      if (pn)
        want += nz.offset + nz.amplitude * oc_turb3(nz.seed, nz.octaves,
                                                    oct_mul(p, 1 / 6.0), NULL);
      ck_assert_double_eq_tol(oc_program_eval(pr, p), want, 1e-12);
      if (i < 150) oct_check_grad(pr, p, 1e-5, 1e-7);
    }
    oct_check_lipschitz(pr, LO, HI, 2000, &r);
    oc_program_free(pr);
  }
}
END_TEST

START_TEST(clamp_to_unit) {
  oc_error err;
  oct_rng r = oct_rng_new(13);
  oc_noise nz = noise(5, 2.0, -0.5, 4, 3); /* spans [-0.5, 1.5] */
  oc_node *s = OCT_OK(oc_strata(&nz, &err));
  oc_program *raw = oct_compile(s, 0, 0);
  oc_node_retain(s);
  oc_program *pr = oct_compile(OCT_OK(oc_clamp(s, 0, 1, &err)), 0, 0);
  oc_node_release(s);
  int below = 0, above = 0;
  for (int i = 0; i < 2000; i++) {
    oc_vec3 p = oct_in_box(&r, LO, HI);
    double v = oc_program_eval(pr, p), f = oc_program_eval(raw, p);
    ck_assert(v >= 0 && v <= 1);
    ck_assert(v == clampd(f, 0, 1));
    below += f < 0;
    above += f > 1;
    oc_vec3 g;
    oc_program_gradient(pr, p, &g);
    if (f < 0 || f > 1) ck_assert(g.x == 0 && g.y == 0 && g.z == 0);
  }
  ck_assert(below > 10 && above > 10); /* both clamps were exercised */
  ck_assert(oc_program_lipschitz(pr) == oc_program_lipschitz(raw));
  oct_check_lipschitz(pr, LO, HI, 2000, &r);
  oc_program_free(pr);
  oc_program_free(raw);
}
END_TEST

/* ---- taper --------------------------------------------------------------- */

static const oc_taper_params TP = {
    {2, 1, -3}, {0.2, 0, 1}, {1, 0.5, 0}, -10, 15, 3, 8};

static oc_vec3 unitv(oc_vec3 v) {
  return oct_mul(v, 1 / oct_len(v));
}

/* p + (k(u) - 1) clamp(s, -H, H) a, written from docs/fields.md */
static oc_vec3 taper_ref(oc_vec3 p) {
  oc_vec3 a = unitv(TP.axis), b = unitv(TP.along), d = oct_sub(p, TP.origin);
  double s = oct_dot(d, a), u = oct_dot(d, b);
  double x = clampd((u - TP.from) / (TP.to - TP.from), 0, 1);
  double k = 1 + (TP.factor - 1) * x * x * (3 - 2 * x);
  return oct_add(p, oct_mul(a, (k - 1) * clampd(s, -TP.height, TP.height)));
}

START_TEST(taper_formula) {
  oc_error err;
  oct_rng r = oct_rng_new(14);
  oc_noise nz = noise(3, 1, 0, 3, 5);
  oc_node *s = OCT_OK(oc_strata(&nz, &err));
  oc_program *raw = oct_compile(s, 0, 0);
  oc_node_retain(s);
  oc_program *pr = oct_compile(OCT_OK(oc_taper(s, &TP, &err)), 0, 0);
  oc_node_release(s);
  oc_vec3 a = unitv(TP.axis);
  for (int i = 0; i < 2000; i++) {
    oc_vec3 p = oct_in_box(&r, LO, HI);
    double v = oc_program_eval(pr, p);
    ck_assert_double_eq_tol(v, oc_program_eval(raw, taper_ref(p)), 1e-12);
    double sd = oct_dot(oct_sub(p, TP.origin), a);
    if (i < 300 && fabs(fabs(sd) - TP.height) > 1e-3)
      oct_check_grad(pr, p, 1e-6, 1e-6);
  }
  /* strata are compressed by `factor` past `to`, untouched before `from` */
  oc_vec3 b = unitv(TP.along);
  oc_vec3 far = oct_add(TP.origin, oct_mul(b, 30)); /* u = 30 > to */
  oc_vec3 near = oct_add(TP.origin, oct_mul(b, -30));
  double ab = oct_dot(a, b);
  for (int i = 0; i < 50; i++) {
    /* s = (p - o).a = s0 inside the band; u stays beyond `to` */
    double s0 = oct_unif(&r, -TP.height, TP.height);
    oc_vec3 p = oct_add(far, oct_mul(a, s0 - 30 * ab));
    ck_assert_double_eq_tol(
        oc_program_eval(pr, p),
        oc_program_eval(raw, oct_add(p, oct_mul(a, 2 * s0))), 1e-12);
    oc_vec3 q = oct_add(near, oct_mul(a, s0 + 30 * ab));
    ck_assert(oc_program_eval(pr, q) == oc_program_eval(raw, q));
  }
  double ratio = oct_check_lipschitz(pr, LO, HI, 4000, &r);
  ck_assert(ratio > 0.05); /* the bound is not absurdly loose */
  oc_program_free(pr);
  oc_program_free(raw);
}
END_TEST

/* ---- fault --------------------------------------------------------------- */

START_TEST(fault_translates_inside_only) {
  oc_error err;
  oct_rng r = oct_rng_new(15);
  oc_noise nz = noise(4, 1, 0, 4, 8);
  oc_vec3 off = oct_v(1.5, -0.5, 3.25);
  oc_node *s = OCT_OK(oc_strata(&nz, &err));
  oc_program *raw = oct_compile(s, 0, 0);
  oc_node *dn = OCT_OK(oc_sphere(oct_v(-5, 5, 0), 25, 3, 1, &err));
  oc_program *dp = oct_compile(dn, 0, 0);
  for (int kind = 0; kind < 3; kind++) {
    oc_fault_domain d;
    memset(&d, 0, sizeof d);
    d.kind = (oc_fault_kind)kind;
    d.lo = oct_v(-20, -30, -25);
    d.hi = oct_v(20, 30, 15);
    d.origin = oct_v(3, 0, 0);
    d.normal = oct_v(1, 0.5, 0); /* a vertical fault plane */
    d.node = dn;
    oc_program *pr = oct_compile(OCT_OK(oc_fault(s, &d, off, &err)), 0, 0);
    int in = 0, out = 0;
    for (int i = 0; i < 3000; i++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      int inside;
      if (kind == 0)
        inside = p.x > d.lo.x && p.x < d.hi.x && p.y > d.lo.y && p.y < d.hi.y &&
                 p.z > d.lo.z && p.z < d.hi.z;
      else if (kind == 1)
        inside = oct_dot(oct_sub(p, d.origin), d.normal) < 0;
      else
        inside = oc_program_eval(dp, p) > 0.5;
      double want = oc_program_eval(raw, inside ? oct_sub(p, off) : p);
      ck_assert(oc_program_eval(pr, p) == want);
      in += inside;
      out += !inside;
    }
    ck_assert_msg(in > 100 && out > 100, "domain %d: %d in, %d out", kind, in,
                  out);
    ck_assert(isinf(oc_program_lipschitz(pr)));
    oc_program_free(pr);
  }
  oc_program_free(dp);
  oc_program_free(raw);
}
END_TEST

START_TEST(fault_discontinuous_exactly_on_boundary) {
  oc_error err;
  oct_rng r = oct_rng_new(16);
  oc_noise nz = noise(4, 1, 0, 4, 8);
  oc_node *s = OCT_OK(oc_strata(&nz, &err));
  oc_program *raw = oct_compile(s, 0, 0);
  oc_fault_domain d;
  memset(&d, 0, sizeof d);
  d.kind = OC_FAULT_BOX;
  d.lo = oct_v(-10, -10, -10);
  d.hi = oct_v(10, 10, 10);
  oc_vec3 off = oct_v(0, 0, 1.7);
  oc_program *pr = oct_compile(OCT_OK(oc_fault(s, &d, off, &err)), 0, 0);
  int jumps = 0;
  for (int i = 0; i < 500; i++) {
    /* a point on the face x = 10: outside (the domain is open) */
    oc_vec3 p = oct_v(10, oct_unif(&r, -9, 9), oct_unif(&r, -9, 9));
    oc_vec3 q = oct_v(nextafter(10, 0), p.y, p.z);
    ck_assert(oc_program_eval(pr, p) == oc_program_eval(raw, p));
    ck_assert(oc_program_eval(pr, q) == oc_program_eval(raw, oct_sub(q, off)));
    double jump = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q));
    jumps += jump > 1e-3;
    /* continuous on either side: tiny steps away from the face give tiny
    ** changes */
    oc_vec3 p2 = oct_v(10 + 1e-7, p.y, p.z), q2 = oct_v(10 - 1e-7, p.y, p.z);
    double L = oc_program_lipschitz(raw);
    ck_assert(fabs(oc_program_eval(pr, p2) - oc_program_eval(pr, p)) <=
              L * 2e-7);
    ck_assert(fabs(oc_program_eval(pr, q2) - oc_program_eval(pr, q)) <=
              L * 2e-7);
  }
  ck_assert_int_gt(jumps, 400);
  /* local bounds: finite and valid away from the boundary, infinite
  ** across it */
  double Lc = oc_program_lipschitz(raw);
  oc_aabb inner = {oct_v(-5, -5, -5), oct_v(5, 5, 5)};
  oc_aabb outer = {oct_v(12, -5, -5), oct_v(20, 5, 5)};
  oc_aabb across = {oct_v(8, -5, -5), oct_v(12, 5, 5)};
  ck_assert(oc_program_lipschitz_in(pr, inner) <= Lc);
  ck_assert(oc_program_lipschitz_in(pr, outer) <= Lc);
  ck_assert(isinf(oc_program_lipschitz_in(pr, across)));
  for (int i = 0; i < 1000; i++) {
    oc_aabb b = i % 2 ? inner : outer;
    oc_vec3 p = oct_in_box(&r, b.lo, b.hi), q = oct_in_box(&r, b.lo, b.hi);
    double Lb = oc_program_lipschitz_in(pr, b);
    ck_assert(fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q)) <=
              Lb * oct_len(oct_sub(p, q)) * (1 + 1e-9));
  }
  oc_program_free(pr);
  oc_program_free(raw);
}
END_TEST

/* ---- erosion ------------------------------------------------------------- */

typedef struct eroded {
  oc_program *pr, *f, *rho, *ctl;
  double depth;
} eroded;

/* A cliff: a box of rock, strata, and a control region on its +x face. */
static eroded eroded_cliff(int with_control) {
  oc_error err;
  eroded e;
  oc_node *t =
      OCT_OK(oc_box(oct_v(-30, -30, -30), oct_v(10, 30, 20), 4, 1, &err));
  oc_noise nz = noise(6, 1.2, -0.1, 4, 21); /* [-0.1, 1.1]: clamped */
  oc_node *g = OCT_OK(oc_strata(&nz, &err));
  oc_node *c =
      with_control
          ? OCT_OK(oc_box(oct_v(5, -40, -40), oct_v(40, 40, 40), 10, 1, &err))
          : NULL;
  e.depth = 0.7;
  oc_node *n = OCT_OK(oc_erosion(t, g, c, e.depth, &err));
  e.pr = oct_compile(n, 0, 0);
  e.f = oct_compile(t, 0, 0);
  e.rho = oct_compile(g, 0, 0);
  e.ctl = c ? oct_compile(c, 0, 0) : NULL;
  return e;
}

static void eroded_free(eroded *e) {
  oc_program_free(e->pr);
  oc_program_free(e->f);
  oc_program_free(e->rho);
  oc_program_free(e->ctl);
}

static double erosion_ref(const eroded *e, oc_vec3 p) {
  double f = oc_program_eval(e->f, p);
  double rho = clampd(oc_program_eval(e->rho, p), 0, 1);
  double w = e->ctl ? clampd(oc_program_eval(e->ctl, p), 0, 1) : 1;
  return fmax(f - e->depth * w * (1 - rho), fmin(f, 0));
}

START_TEST(erosion_formula) {
  oct_rng r = oct_rng_new(17 + (uint64_t)_i);
  eroded e = eroded_cliff(_i);
  oc_vec3 lo = oct_v(-40, -40, -40), hi = oct_v(40, 40, 30);
  int eroded_pts = 0, grads = 0;
  for (int i = 0; i < 5000; i++) {
    oc_vec3 p = oct_in_box(&r, lo, hi);
    double v = oc_program_eval(e.pr, p), f = oc_program_eval(e.f, p);
    ck_assert_double_eq_tol(v, erosion_ref(&e, p), 1e-13);
    ck_assert(v <= f);             /* erosion only removes material */
    if (f == 0) ck_assert(v == 0); /* and never outside the rock */
    ck_assert(v >= fmin(f, 0));
    eroded_pts += v < f - 0.05;
    if (v > 0.02 && grads < 400) {
      oct_check_grad(e.pr, p, 1e-6, 1e-6);
      grads++;
    }
  }
  ck_assert_int_gt(eroded_pts, 200);
  /* the support is the terrain's */
  oc_aabb b = oc_program_bounds(e.pr), bf = oc_program_bounds(e.f);
  ck_assert(memcmp(&b, &bf, sizeof b) == 0);
  /* L = L_f + depth (L_control + L_rho) */
  double L = oc_program_lipschitz(e.f) +
             e.depth * ((e.ctl ? oc_program_lipschitz(e.ctl) : 0) +
                        oc_program_lipschitz(e.rho));
  ck_assert_double_eq_tol(oc_program_lipschitz(e.pr), L, 1e-12 * L);
  oct_check_lipschitz(e.pr, lo, hi, 4000, &r);
  ck_assert(isnan(oc_program_eval(e.pr, oct_v(NAN, 0, 0))));
  eroded_free(&e);
}
END_TEST

START_TEST(erosion_local_queries) {
  oct_rng r = oct_rng_new(19);
  eroded e = eroded_cliff(1);
  double L = oc_program_lipschitz(e.pr);
  int smaller = 0;
  for (int i = 0; i < 300; i++) {
    oc_vec3 lo = oct_in_box(&r, oct_v(-45, -45, -45), oct_v(40, 40, 30));
    double w = oct_unif(&r, 0.5, 10);
    oc_aabb box = {lo, oct_add(lo, oct_v(w, w, w))};
    double Lb = oc_program_lipschitz_in(e.pr, box);
    ck_assert(Lb <= L * (1 + 1e-12));
    smaller += Lb < 0.5 * L;
    for (int t = 0; t < 100; t++) {
      oc_vec3 p = oct_in_box(&r, box.lo, box.hi);
      oc_vec3 q = t % 2 ? oct_in_box(&r, box.lo, box.hi)
                        : oct_add(p, oct_mul(oct_dir(&r), w * 1e-4));
      if (!oct_box_contains(box, q)) continue;
      double d = fabs(oc_program_eval(e.pr, p) - oc_program_eval(e.pr, q));
      ck_assert(d <= Lb * oct_len(oct_sub(p, q)) * (1 + 1e-9) + 1e-14);
    }
  }
  ck_assert_int_gt(smaller, 30); /* outside the control: the terrain's */
  /* column spans: the field is constant between them over the footprint */
  for (int i = 0; i < 200; i++) {
    double x0 = oct_unif(&r, -45, 40), y0 = oct_unif(&r, -45, 40);
    double w = oct_unif(&r, 0.2, 6);
    oc_zspan s[8];
    int n = oc_program_column_spans(e.pr, x0, y0, x0 + w, y0 + w, s, 8);
    ck_assert_int_ge(n, 0); /* bounded: a box terrain, a box control */
    for (int g = 0; g <= n; g++) {
      double zl = g == 0 ? -100 : s[g - 1].hi, zh = g == n ? 100 : s[g].lo;
      double ref = NAN;
      for (int t = 0; t < 30 && zh > zl; t++) {
        oc_vec3 p = oct_v(oct_unif(&r, x0, x0 + w), oct_unif(&r, y0, y0 + w),
                          oct_unif(&r, zl, zh));
        if (p.z <= zl || p.z >= zh) continue;
        double v = oc_program_eval(e.pr, p);
        if (isnan(ref)) ref = v;
        ck_assert_msg(v == ref, "field varies between spans at z %g", p.z);
      }
    }
  }
  eroded_free(&e);
}
END_TEST

/* Erosion over two separate rocks: between them, where neither rock's
** support reaches, the local bound is 0 (rays between islands take long
** steps), and every local bound holds for point pairs. */
START_TEST(erosion_zero_between_rocks) {
  oc_error err;
  oc_node *k[2] = {
      OCT_OK(oc_box(oct_v(-40, -10, -10), oct_v(-20, 10, 10), 3, 1, &err)),
      OCT_OK(oc_sphere(oct_v(30, 0, 0), 8, 3, 1, &err))};
  oc_node *u = OCT_OK(oc_union(k, 2, &err));
  oc_noise nz = noise(5, 1, 0, 3, 8);
  oc_node *g = OCT_OK(oc_strata(&nz, &err));
  oc_node *n = OCT_OK(oc_erosion(u, g, NULL, 0.6, &err));
  for (int i = 0; i < 2; i++)
    oc_node_release(k[i]);
  oc_node_release(u);
  oc_node_release(g);
  oc_program *pr = oct_compile(n, 0, 0);
  oct_rng r = oct_rng_new(29);
  int zero = 0;
  for (int i = 0; i < 400; i++) {
    oc_vec3 lo = oct_in_box(&r, oct_v(-50, -20, -20), oct_v(45, 15, 15));
    double w = oct_unif(&r, 0.5, 8);
    oc_aabb box = {lo, oct_add(lo, oct_v(w, w, w))};
    double Lb = oc_program_lipschitz_in(pr, box);
    zero += Lb == 0;
    for (int t = 0; t < 60; t++) {
      oc_vec3 p = oct_in_box(&r, box.lo, box.hi);
      oc_vec3 q = oct_in_box(&r, box.lo, box.hi);
      double d = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q));
      ck_assert_msg(d <= Lb * oct_len(oct_sub(p, q)) * (1 + 1e-9) + 1e-14,
                    "local bound %g exceeded in a box at %g %g %g", Lb, lo.x,
                    lo.y, lo.z);
    }
  }
  ck_assert_int_gt(zero, 60);
  /* a box between the rocks, inside the union's box */
  oc_aabb mid = {oct_v(-10, -5, -5), oct_v(10, 5, 5)};
  ck_assert(oc_program_lipschitz_in(pr, mid) == 0);
  oc_program_free(pr);
}
END_TEST

/* An eroded cliff meshes to the same bytes with 1 and 2 threads, and
** erosion removes volume: fewer inside samples than the plain box. */
START_TEST(erosion_mesh_deterministic) {
  eroded e = eroded_cliff(1);
  oc_error err;
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{-36, -20, -36}, {16, 20, 26}};
  pp.cell = 0.5;
  oc_mesh *m[2];
  for (int k = 0; k < 2; k++) {
    omp_set_num_threads(k + 1);
    m[k] = oc_polygonize(e.pr, &pp, &err);
    ck_assert_msg(m[k] != NULL, "%s", err.msg);
  }
  omp_set_num_threads(2);
  size_t nv = oc_mesh_vertex_count(m[0]), nt = oc_mesh_triangle_count(m[0]);
  ck_assert_uint_gt(nt, 1000);
  ck_assert_uint_eq(nv, oc_mesh_vertex_count(m[1]));
  ck_assert_uint_eq(nt, oc_mesh_triangle_count(m[1]));
  ck_assert(memcmp(oc_mesh_positions(m[0]), oc_mesh_positions(m[1]),
                   nv * 3 * sizeof(float)) == 0);
  ck_assert(memcmp(oc_mesh_indices(m[0]), oc_mesh_indices(m[1]),
                   nt * 3 * sizeof(uint32_t)) == 0);
  /* every vertex off the box's caps lies on f~ = T */
  const float *pos = oc_mesh_positions(m[0]);
  for (size_t i = 0; i < nv; i += 7) {
    oc_vec3 p = oct_v(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
    oc_aabb in = {oct_add(pp.box.lo, oct_v(1e-3, 1e-3, 1e-3)),
                  oct_sub(pp.box.hi, oct_v(1e-3, 1e-3, 1e-3))};
    if (!oct_box_contains(in, p)) continue;
    ck_assert_msg(fabs(oc_program_eval(e.pr, p) - 0.5) < 0.05,
                  "vertex %zu (%g %g %g): f = %g", i, p.x, p.y, p.z,
                  oc_program_eval(e.pr, p));
  }
  oc_mesh_free(m[0]);
  oc_mesh_free(m[1]);
  eroded_free(&e);
}
END_TEST

START_TEST(parameter_errors) {
  oc_error err;
  oc_noise bad = noise(-1, 1, 0, 4, 1), ok = noise(5, 1, 0, 4, 1);
  OCT_EINVAL(oc_strata(&bad, &err), err, "wavelength");
  bad = noise(5, NAN, 0, 4, 1);
  OCT_EINVAL(oc_strata(&bad, &err), err, "amplitude");
  bad = noise(5, 1, 0, 40, 1);
  OCT_EINVAL(oc_strata(&bad, &err), err, "octaves");
  oc_node *s = OCT_OK(oc_strata(&ok, &err));
  OCT_EINVAL(oc_clamp(s, 1, 0, &err), err, "lo");
  OCT_EINVAL(oc_clamp(s, NAN, 1, &err), err, "lo");
  oc_taper_params tp = TP;
  tp.factor = 0;
  OCT_EINVAL(oc_taper(s, &tp, &err), err, "factor");
  tp = TP;
  tp.to = tp.from;
  OCT_EINVAL(oc_taper(s, &tp, &err), err, "to");
  tp = TP;
  tp.axis = oct_v(0, 0, 0);
  OCT_EINVAL(oc_taper(s, &tp, &err), err, "axis");
  tp = TP;
  tp.height = INFINITY;
  OCT_EINVAL(oc_taper(s, &tp, &err), err, "height");
  oc_fault_domain d;
  memset(&d, 0, sizeof d);
  d.kind = OC_FAULT_BOX;
  d.lo = oct_v(0, 0, 0);
  d.hi = oct_v(1, -1, 1);
  OCT_EINVAL(oc_fault(s, &d, oct_v(0, 0, 1), &err), err, "domain.max");
  d.hi = oct_v(1, 1, 1);
  OCT_EINVAL(oc_fault(s, &d, oct_v(0, NAN, 1), &err), err, "offset");
  d.kind = OC_FAULT_HALF;
  OCT_EINVAL(oc_fault(s, &d, oct_v(0, 0, 1), &err), err, "domain.normal");
  d.kind = OC_FAULT_NODE;
  OCT_EINVAL(oc_fault(s, &d, oct_v(0, 0, 1), &err), err, "domain");
  OCT_EINVAL(oc_erosion(s, s, NULL, 0, &err), err, "depth");
  OCT_EINVAL(oc_erosion(s, s, NULL, INFINITY, &err), err, "depth");
  OCT_EINVAL(
      oc_geology_layer(oct_v(0, 0, 0), oct_v(0, 0, 1), -1, 1, NULL, &err), err,
      "radius");
  OCT_EINVAL(oc_geology_layer(oct_v(0, 0, 0), oct_v(0, 0, 0), 1, 1, NULL, &err),
             err, "normal");
  OCT_EINVAL(
      oc_geology_layer(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, NAN, NULL, &err), err,
      "resistance");
  ck_assert_str_eq(oc_node_kind(s), "strata");
  oc_node_release(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("geology");
  TCase *tc = tcase_create("geology");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, strata_formula);
  tcase_add_test(tc, strata_deterministic_by_seed);
  tcase_add_test(tc, layer_formula);
  tcase_add_test(tc, clamp_to_unit);
  tcase_add_test(tc, taper_formula);
  tcase_add_test(tc, fault_translates_inside_only);
  tcase_add_test(tc, fault_discontinuous_exactly_on_boundary);
  tcase_add_loop_test(tc, erosion_formula, 0, 2);
  tcase_add_test(tc, erosion_local_queries);
  tcase_add_test(tc, erosion_zero_between_rocks);
  tcase_add_test(tc, erosion_mesh_deterministic);
  tcase_add_test(tc, parameter_errors);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
