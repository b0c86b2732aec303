/*
** test_ops.c — field operators against docs/fields.md: n-ary blend, union
** and intersection, difference, the smooth operators (with their fading
** radius), scale, transform, warp, perturb; DAG instancing, deep chains
** and the depth limit.
**
** References are built from the children's own compiled programs, so
** these tests check the operators, not the primitives again.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/noise.h"
#include "ocheck.h"

static const oc_vec3 LO = {-6, -6, -6}, HI = {6, 6, 6};

static oc_node *pt(double x, double y, double z, double R, double E) {
  oc_error e;
  return OCT_OK(oc_point(oct_v(x, y, z), R, E, &e));
}

static double gam(double s) {
  double u = s < 0 ? 0 : s > 1 ? 1 : s;
  return u * u * (3 - 2 * u);
}

static double ref_sunion(double a, double b, double r, double T) {
  double re = r * gam((a + b) / T), m = fmax(a, b);
  if (!(re > 0)) return m;
  double k = fmax(0, 1 - fabs(a - b) / re);
  return m + re * k * k * k / 6;
}

static double ref_sinter(double a, double b, double r, double T) {
  double re = r * gam(a * b / (T * T)), m = fmin(a, b);
  if (!(re > 0)) return m;
  double k = fmax(0, 1 - fabs(a - b) / re);
  return m - re * k * k * k / 6;
}

/* ---- n-ary operators --------------------------------------------------- */

enum { OP_BLEND, OP_UNION, OP_INTER };

static oc_node *nary(int op, oc_node **c, size_t n, oc_error *e) {
  switch (op) {
  case OP_BLEND:
    return oc_blend(c, n, e);
  case OP_UNION:
    return oc_union(c, n, e);
  default:
    return oc_intersection(c, n, e);
  }
}

START_TEST(nary_equals_sum_max_min) {
  int op = _i;
  oct_rng r = oct_rng_new(10 + (uint64_t)op);
  for (int t = 0; t < 30; t++) {
    size_t n = 1 + (size_t)oct_unif(&r, 0, 7);
    oc_node *c[8];
    oc_program *cp[8];
    for (size_t i = 0; i < n; i++) {
      c[i] = oct_random_prim(&r, oct_v(-3, -3, -3), oct_v(3, 3, 3), 1, 3, 0.3);
      oc_node_retain(c[i]);
      cp[i] = oct_compile(c[i], 0, 0);
    }
    oc_error e;
    oc_node *root = OCT_OK(nary(op, c, n, &e));
    ck_assert_uint_eq(oc_node_child_count(root), n);
    for (size_t i = 0; i < n; i++) {
      ck_assert_ptr_eq(oc_node_child(root, i), c[i]);
      oc_node_release(c[i]); /* the operator retained its own */
    }
    oc_program *pr = oct_compile(root, 0, 0);
    for (int k = 0; k < 300; k++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      double acc = op == OP_BLEND ? 0 : op == OP_UNION ? -INFINITY : INFINITY;
      double mag = 0;
      for (size_t i = 0; i < n; i++) {
        double f = oc_program_eval(cp[i], p);
        mag += fabs(f);
        acc = op == OP_BLEND   ? acc + f
              : op == OP_UNION ? fmax(acc, f)
                               : fmin(acc, f);
      }
      double f = oc_program_eval(pr, p);
      if (op == OP_BLEND)
        ck_assert_msg(fabs(f - acc) <= 1e-12 * (1 + mag),
                      "blend %.17g, sum %.17g", f, acc);
      else
        ck_assert_msg(f == acc, "op %d: %.17g, expected %.17g", op, f, acc);
    }
    oct_check_bounds(pr, LO, HI, 1000, &r);
    oct_check_lipschitz(pr, LO, HI, 1000, &r);
    oc_program_free(pr);
    for (size_t i = 0; i < n; i++)
      oc_program_free(cp[i]);
  }
}
END_TEST

/* Gradients of n-ary nodes away from the creases of max / min. */
START_TEST(nary_gradients) {
  int op = _i;
  oct_rng r = oct_rng_new(20 + (uint64_t)op);
  oc_node *c[3] = {pt(-1, 0, 0, 2, 1), pt(1, 0.5, 0, 2.5, 0.8),
                   pt(0, -1, 1, 1.5, -0.6)};
  oc_program *cp[3];
  for (int i = 0; i < 3; i++) {
    oc_node_retain(c[i]);
    cp[i] = oct_compile(c[i], 0, 0);
  }
  oc_error e;
  oc_program *pr = oct_compile(OCT_OK(nary(op, c, 3, &e)), 0, 0);
  for (int i = 0; i < 3; i++)
    oc_node_release(c[i]);
  int checked = 0;
  for (int k = 0; k < 400; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-4, -4, -4), oct_v(4, 4, 4));
    double v[3];
    for (int i = 0; i < 3; i++)
      v[i] = oc_program_eval(cp[i], p);
    if (op != OP_BLEND) {
      /* Distance of the two extreme values: skip near ties. */
      double a = v[0], b = v[1], cc = v[2], gap;
      if (op == OP_UNION) {
        double m = fmax(a, fmax(b, cc));
        double s = a == m ? fmax(b, cc) : b == m ? fmax(a, cc) : fmax(a, b);
        gap = m - s;
      } else {
        double m = fmin(a, fmin(b, cc));
        double s = a == m ? fmin(b, cc) : b == m ? fmin(a, cc) : fmin(a, b);
        gap = s - m;
      }
      if (gap < 1e-4) continue;
    }
    oct_check_grad(pr, p, 1e-6, 1e-8);
    checked++;
  }
  /* An intersection of three points is nonzero only where all overlap. */
  ck_assert_int_gt(checked, op == OP_BLEND ? 100 : op == OP_UNION ? 40 : 10);
  oc_program_free(pr);
  for (int i = 0; i < 3; i++)
    oc_program_free(cp[i]);
}
END_TEST

START_TEST(nary_invalid) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 1, 1);
  oc_node *kids[2] = {a, NULL};
  e.code = OC_OK;
  ck_assert_ptr_null(oc_blend(kids, 0, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert(e.msg[0] != 0);
  e.code = OC_OK;
  ck_assert_ptr_null(oc_union(kids, 2, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  e.code = OC_OK;
  ck_assert_ptr_null(oc_intersection(NULL, 2, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_difference(a, NULL, NULL));
  ck_assert_ptr_null(oc_smooth_union(NULL, a, 0.1, NULL));
  ck_assert_ptr_null(oc_scale_field(NULL, 2, NULL));
  oc_node_release(a);
}
END_TEST

/* ---- difference -------------------------------------------------------- */

START_TEST(difference_values) {
  double T = _i == 0 ? 0.5 : 0.3;
  oct_rng r = oct_rng_new(30 + (uint64_t)_i);
  for (int t = 0; t < 20; t++) {
    oc_node *a =
        oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1, 3, 0.2);
    oc_node *b =
        oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1, 3, 0.2);
    oc_error e;
    oc_node *d = OCT_OK(oc_difference(a, b, &e));
    ck_assert_ptr_eq(oc_node_child(d, 0), a);
    ck_assert_ptr_eq(oc_node_child(d, 1), b);
    oc_program *pa = oct_compile(a, T, 0), *pb = oct_compile(b, T, 0);
    /* _i == 0: default threshold through a NULL options pointer. */
    oc_program *pr;
    if (_i == 0) {
      pr = oc_compile(d, NULL, &e);
      ck_assert_ptr_nonnull(pr);
      oc_node_release(d);
    } else {
      pr = oct_compile(d, T, 0);
    }
    ck_assert_double_eq(oc_program_threshold(pr), T);
    for (int k = 0; k < 400; k++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      double fa = oc_program_eval(pa, p), fb = oc_program_eval(pb, p);
      double f = oc_program_eval(pr, p), ref = fmin(fa, 2 * T - fb);
      ck_assert_msg(fabs(f - ref) <= 1e-15 * (1 + fabs(ref)),
                    "T=%g: %.17g, expected min(%.17g, 2T - %.17g)", T, f, fa,
                    fb);
      if (k % 4 == 0 && fabs(fa - (2 * T - fb)) > 1e-4)
        oct_check_grad(pr, p, 1e-6, 1e-8);
    }
    oct_check_bounds(pr, LO, HI, 1000, &r);
    oct_check_lipschitz(pr, LO, HI, 600, &r);
    oc_program_free(pa);
    oc_program_free(pb);
    oc_program_free(pr);
  }
}
END_TEST

/* A subtracted child stronger than 2T makes the difference negative
** outside the first child: the bounds must cover that too. */
START_TEST(difference_strong_subtrahend) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 1, 1), *b = pt(4, 0, 0, 1, 3);
  oc_program *pr = oct_compile(OCT_OK(oc_difference(a, b, &e)), 0, 0);
  oc_node_release(a);
  oc_node_release(b);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(0, 0, 0)), 1.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(4, 0, 0)), -2.0);
  oct_rng r = oct_rng_new(33);
  int nz = oct_check_bounds(pr, oct_v(-3, -3, -3), oct_v(7, 3, 3), 4000, &r);
  ck_assert_int_gt(nz, 50);
  oc_program_free(pr);
}
END_TEST

/* (a - b) - c == a - (b | c), value for value. */
START_TEST(difference_chain_flattens) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 3, 1), *b = pt(1, 0, 0, 1, 0.9),
          *c = pt(-1, 0.5, 0, 1.2, 1.1);
  oc_node *ab = OCT_OK(oc_difference(a, b, &e));
  oc_node *abc = OCT_OK(oc_difference(ab, c, &e));
  oc_node *bc2[2] = {b, c};
  oc_node *bc = OCT_OK(oc_union(bc2, 2, &e));
  oc_node *alt = OCT_OK(oc_difference(a, bc, &e));
  oc_node_release(a), oc_node_release(b), oc_node_release(c);
  oc_node_release(ab), oc_node_release(bc);
  oc_program *p1 = oct_compile(abc, 0.4, 0), *p2 = oct_compile(alt, 0.4, 0);
  oct_rng r = oct_rng_new(34);
  for (int k = 0; k < 1000; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-4, -4, -4), oct_v(4, 4, 4));
    ck_assert_double_eq(oc_program_eval(p1, p), oc_program_eval(p2, p));
  }
  oc_program_free(p1);
  oc_program_free(p2);
}
END_TEST

/* ---- smooth union / intersection --------------------------------------- */

/* A point near the crease fa = fb, found by bisection between p and a
** random q where fa - fb changes sign (p itself when it does not). */
static oc_vec3 near_crease(const oc_program *pa, const oc_program *pb,
                           oct_rng *r, oc_vec3 p) {
  oc_vec3 q = oct_in_box(r, oct_v(-4, -4, -4), oct_v(4, 4, 4));
  double hp = oc_program_eval(pa, p) - oc_program_eval(pb, p);
  double hq = oc_program_eval(pa, q) - oc_program_eval(pb, q);
  if (!(hp * hq < 0)) return p;
  for (int i = 0; i < 50; i++) {
    oc_vec3 m = oct_mul(oct_add(p, q), 0.5);
    double hm = oc_program_eval(pa, m) - oc_program_eval(pb, m);
    if (hm * hp < 0)
      q = m;
    else
      p = m, hp = hm;
  }
  return oct_add(p, oct_mul(oct_dir(r), oct_unif(r, 0, 0.05)));
}

START_TEST(smooth_values) {
  int inter = _i & 1;
  double T = (_i & 2) ? 0.3 : 0.5;
  double rad = (_i & 4) ? 0.35 : 0.1;
  oct_rng r = oct_rng_new(40 + (uint64_t)_i);
  int smoothed = 0;
  for (int t = 0; t < 15; t++) {
    oc_node *a = oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1.5, 3,
                                 t % 5 == 4 ? 0.5 : 0);
    oc_node *b = oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1.5, 3,
                                 t % 5 == 4 ? 0.5 : 0);
    oc_error e;
    oc_node *s = OCT_OK(inter ? oc_smooth_intersection(a, b, rad, &e)
                              : oc_smooth_union(a, b, rad, &e));
    oc_program *pa = oct_compile(a, T, 0), *pb = oct_compile(b, T, 0);
    oc_program *pr = oct_compile(s, T, 0);
    for (int k = 0; k < 500; k++) {
      oc_vec3 p = oct_in_box(&r, oct_v(-4, -4, -4), oct_v(4, 4, 4));
      if (k % 2) p = near_crease(pa, pb, &r, p);
      double fa = oc_program_eval(pa, p), fb = oc_program_eval(pb, p);
      double ref =
          inter ? ref_sinter(fa, fb, rad, T) : ref_sunion(fa, fb, rad, T);
      double f = oc_program_eval(pr, p);
      ck_assert_msg(fabs(f - ref) <= 1e-13 * (1 + fabs(ref)),
                    "%s r=%g T=%g: %.17g, expected %.17g (fa=%.17g "
                    "fb=%.17g)",
                    inter ? "smooth_intersection" : "smooth_union", rad, T, f,
                    ref, fa, fb);
      if (ref != (inter ? fmin(fa, fb) : fmax(fa, fb))) smoothed++;
      /* Gradient where the operator is C1 (everywhere but the
      ** crease of a plain max/min, i.e. where the radius has faded). */
      double re = rad * (inter ? gam(fa * fb / (T * T)) : gam((fa + fb) / T));
      if (k % 3 == 0 && (re > 1e-3 || fabs(fa - fb) > 1e-4))
        oct_check_grad(pr, p, 1e-6, 1e-7);
    }
    oct_check_bounds(pr, LO, HI, 800, &r);
    oct_check_lipschitz(pr, LO, HI, 800, &r);
    oc_program_free(pa);
    oc_program_free(pb);
    oc_program_free(pr);
  }
  ck_assert_int_gt(smoothed, 20); /* the test saw the blending zone */
}
END_TEST

START_TEST(smooth_lipschitz_formula) {
  oc_error e;
  double T = 0.4, rad = 0.3;
  oc_node *a = pt(0, 0, 0, 2, 1), *b = pt(1, 0, 0, 1.5, 1);
  double La = OCT_LG / 2, Lb = OCT_LG / 1.5;
  oc_program *pu = oct_compile(OCT_OK(oc_smooth_union(a, b, rad, &e)), T, 0);
  oc_program *pi =
      oct_compile(OCT_OK(oc_smooth_intersection(a, b, rad, &e)), T, 0);
  oc_node_release(a);
  oc_node_release(b);
  double Lu = fmax(La, Lb) + rad * (La + Lb) / (4 * T);
  double Li = fmax(La, Lb) + rad * (1 * La + 1 * Lb) / (4 * T * T);
  ck_assert_msg(fabs(oc_program_lipschitz(pu) - Lu) <= 1e-9 * Lu,
                "smooth union L %.17g, expected %.17g",
                oc_program_lipschitz(pu), Lu);
  ck_assert_msg(fabs(oc_program_lipschitz(pi) - Li) <= 1e-9 * Li,
                "smooth intersection L %.17g, expected %.17g",
                oc_program_lipschitz(pi), Li);
  oc_program_free(pu);
  oc_program_free(pi);
}
END_TEST

/* C1 across fa = fb: analytic and central-difference gradients agree on
** both sides of the crease; a plain union has a jump there (so the test
** can tell). */
START_TEST(smooth_union_c1) {
  oc_error e;
  oc_node *a = pt(-0.6, 0, 0, 1.5, 1), *b = pt(0.6, 0, 0, 1.5, 1);
  oc_node *ab[2] = {a, b};
  oc_program *ps = oct_compile(OCT_OK(oc_smooth_union(a, b, 0.3, &e)), 0, 0);
  oc_program *pu = oct_compile(OCT_OK(oc_union(ab, 2, &e)), 0, 0);
  oc_node_release(a);
  oc_node_release(b);
  oct_rng r = oct_rng_new(50);
  int n = 0;
  for (int k = 0; k < 200; k++) {
    /* On the crease x = 0, where fa + fb is near or above T. */
    oc_vec3 p0 = oct_v(0, oct_unif(&r, -0.5, 0.5), oct_unif(&r, -0.5, 0.5));
    double d = 1e-5;
    oc_vec3 pl = oct_add(p0, oct_v(-d, 0, 0)), pr = oct_add(p0, oct_v(d, 0, 0));
    oc_vec3 gl = oct_fd_grad(ps, pl, 1e-7), gr = oct_fd_grad(ps, pr, 1e-7);
    oc_vec3 al, ar;
    oc_program_gradient(ps, pl, &al);
    oc_program_gradient(ps, pr, &ar);
    double L = oc_program_lipschitz(ps);
    ck_assert_msg(oct_len(oct_sub(gl, gr)) < 1e-3 * L,
                  "smooth union: gradient jumps across the crease at "
                  "(0 %g %g): %g",
                  p0.y, p0.z, oct_len(oct_sub(gl, gr)));
    ck_assert_msg(oct_len(oct_sub(al, ar)) < 1e-3 * L,
                  "smooth union: analytic gradient jumps: %g",
                  oct_len(oct_sub(al, ar)));
    ck_assert(oct_len(oct_sub(al, gl)) < 1e-4 * L);
    oc_vec3 ul = oct_fd_grad(pu, pl, 1e-7), ur = oct_fd_grad(pu, pr, 1e-7);
    if (oct_len(oct_sub(ul, ur)) > 0.05 * L) n++;
  }
  ck_assert_int_gt(n, 150);
  oc_program_free(ps);
  oc_program_free(pu);
}
END_TEST

/* The radius fades where both fields vanish: far-apart primitives keep
** compact support and exact zeros in between. */
START_TEST(smooth_compact_support) {
  oc_error e;
  oc_node *a = pt(-5, 0, 0, 2, 1), *b = pt(5, 0, 0, 2, 1);
  oc_program *pu = oct_compile(OCT_OK(oc_smooth_union(a, b, 0.5, &e)), 0, 0);
  oc_program *pi =
      oct_compile(OCT_OK(oc_smooth_intersection(a, b, 0.5, &e)), 0, 0);
  oc_node_release(a);
  oc_node_release(b);
  oct_rng r = oct_rng_new(60);
  for (int k = 0; k < 2000; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-2.9, -4, -4), oct_v(2.9, 4, 4));
    ck_assert_double_eq(oc_program_eval(pu, p), 0.0);
    oc_vec3 q = oct_in_box(&r, oct_v(-9, -4, -4), oct_v(9, 4, 4));
    ck_assert_double_eq(oc_program_eval(pi, q), 0.0);
  }
  /* Away from the other primitive the union is just the primitive. */
  ck_assert_double_eq(oc_program_eval(pu, oct_v(-5, 0, 0)), 1.0);
  ck_assert_double_eq_tol(oc_program_eval(pu, oct_v(-4, 0, 0)),
                          ref_sunion(pow(0.75, 3), 0, 0.5, 0.5), 1e-15);
  ck_assert_double_eq(oc_program_eval(pu, oct_v(-5, 2, 0)), 0.0);
  oct_check_bounds(pu, oct_v(-10, -4, -4), oct_v(10, 4, 4), 2000, &r);
  oc_aabb b1 = oc_program_bounds(pu);
  ck_assert(b1.lo.x <= -7 && b1.hi.x >= 7 && b1.hi.x < 10 && b1.hi.y < 4);
  oc_program_free(pu);
  oc_program_free(pi);
}
END_TEST

/* ---- scale ------------------------------------------------------------- */

START_TEST(scale_field) {
  oct_rng r = oct_rng_new(70);
  double factors[] = {-1, 2.5, -0.3};
  for (int t = 0; t < 3; t++) {
    oc_node *a =
        oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1, 3, 0.3);
    oc_error e;
    oc_node *s = OCT_OK(oc_scale_field(a, factors[t], &e));
    oc_program *pa = oct_compile(a, 0, 0), *ps = oct_compile(s, 0, 0);
    double La = oc_program_lipschitz(pa), Ls = oc_program_lipschitz(ps);
    ck_assert_double_eq_tol(Ls, fabs(factors[t]) * La, 1e-12 * La);
    for (int k = 0; k < 500; k++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      ck_assert_double_eq_tol(oc_program_eval(ps, p),
                              factors[t] * oc_program_eval(pa, p), 1e-15);
      if (k % 5 == 0) oct_check_grad(ps, p, 1e-6, 1e-8);
    }
    oct_check_bounds(ps, LO, HI, 500, &r);
    oct_check_lipschitz(ps, LO, HI, 500, &r);
    oc_program_free(pa);
    oc_program_free(ps);
  }
  oc_error e;
  oc_node *a = pt(0, 0, 0, 1, 1);
  ck_assert_ptr_null(oc_scale_field(a, NAN, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_scale_field(a, INFINITY, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  oc_node_release(a);
}
END_TEST

/* ---- transform --------------------------------------------------------- */

/* 3x3 inverse by cofactors. */
static void inv3(const double a[9], double out[9]) {
  double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8],
         c02 = a[3] * a[7] - a[4] * a[6];
  double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  out[0] = c00 / det;
  out[1] = (a[2] * a[7] - a[1] * a[8]) / det;
  out[2] = (a[1] * a[5] - a[2] * a[4]) / det;
  out[3] = c01 / det;
  out[4] = (a[0] * a[8] - a[2] * a[6]) / det;
  out[5] = (a[2] * a[3] - a[0] * a[5]) / det;
  out[6] = c02 / det;
  out[7] = (a[1] * a[6] - a[0] * a[7]) / det;
  out[8] = (a[0] * a[4] - a[1] * a[3]) / det;
}

static oc_vec3 mat_apply(const double a[9], oc_vec3 v) {
  return oct_v(a[0] * v.x + a[1] * v.y + a[2] * v.z,
               a[3] * v.x + a[4] * v.y + a[5] * v.z,
               a[6] * v.x + a[7] * v.y + a[8] * v.z);
}

/* Largest singular value: sqrt of the largest eigenvalue of B^T B, by
** cyclic Jacobi rotations. */
static double sigma_max(const double b[9]) {
  double s[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      s[i][j] = 0;
      for (int k = 0; k < 3; k++)
        s[i][j] += b[3 * k + i] * b[3 * k + j];
    }
  for (int sweep = 0; sweep < 50; sweep++)
    for (int p = 0; p < 2; p++)
      for (int q = p + 1; q < 3; q++) {
        if (fabs(s[p][q]) < 1e-300) continue;
        double th = 0.5 * atan2(2 * s[p][q], s[q][q] - s[p][p]);
        double c = cos(th), sn = sin(th);
        for (int k = 0; k < 3; k++) { /* columns */
          double kp = s[k][p], kq = s[k][q];
          s[k][p] = c * kp - sn * kq;
          s[k][q] = sn * kp + c * kq;
        }
        for (int k = 0; k < 3; k++) { /* rows */
          double pk = s[p][k], qk = s[q][k];
          s[p][k] = c * pk - sn * qk;
          s[q][k] = sn * pk + c * qk;
        }
      }
  return sqrt(fmax(s[0][0], fmax(s[1][1], s[2][2])));
}

/* Rotation about a unit axis (Rodrigues). */
static void rotation(oc_vec3 u, double ang, double m[9]) {
  double c = cos(ang), s = sin(ang), t = 1 - c;
  m[0] = c + u.x * u.x * t, m[1] = u.x * u.y * t - u.z * s,
  m[2] = u.x * u.z * t + u.y * s;
  m[3] = u.y * u.x * t + u.z * s, m[4] = c + u.y * u.y * t,
  m[5] = u.y * u.z * t - u.x * s;
  m[6] = u.z * u.x * t - u.y * s, m[7] = u.z * u.y * t + u.x * s,
  m[8] = c + u.z * u.z * t;
}

static void to34(const double a[9], oc_vec3 t, double m[12]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      m[4 * i + j] = a[3 * i + j];
  m[3] = t.x, m[7] = t.y, m[11] = t.z;
}

/* Kinds: 0 translate, 1 rotate, 2 uniform scale, 3 per-axis scale,
** 4 general affine (translate . rotate . scale . shear). */
static void random_affine(oct_rng *r, int kind, double a[9], oc_vec3 *t) {
  static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  memcpy(a, id, sizeof id);
  *t = oct_v(0, 0, 0);
  if (kind == 0 || kind == 4)
    *t = oct_in_box(r, oct_v(-3, -3, -3), oct_v(3, 3, 3));
  if (kind == 1) rotation(oct_dir(r), oct_unif(r, -3, 3), a);
  if (kind == 2) {
    double s = oct_unif(r, 0.3, 3);
    a[0] = a[4] = a[8] = s;
  }
  if (kind == 3)
    a[0] = oct_unif(r, 0.3, 3), a[4] = oct_unif(r, 0.3, 3),
    a[8] = oct_unif(r, 0.3, 3);
  if (kind == 4) {
    /* Well conditioned: sigma_min(A) > 0.3. */
    double ai[9];
    do {
      for (int i = 0; i < 9; i++)
        a[i] = id[i] + oct_unif(r, -0.6, 0.6);
      inv3(a, ai);
    } while (!(sigma_max(ai) < 1 / 0.3));
  }
}

START_TEST(transform_values) {
  int kind = _i;
  oct_rng r = oct_rng_new(80 + (uint64_t)kind);
  for (int t = 0; t < 10; t++) {
    double a[9], ai[9], m[12];
    oc_vec3 tr;
    random_affine(&r, kind, a, &tr);
    to34(a, tr, m);
    inv3(a, ai);
    oc_node *c =
        oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1, 2.5, 0.2);
    oc_error e;
    oc_node *x = OCT_OK(oc_transform(c, m, &e));
    oc_program *pc = oct_compile(c, 0, 0), *px = oct_compile(x, 0, 0);
    for (int k = 0; k < 400; k++) {
      oc_vec3 p = oct_in_box(&r, oct_v(-9, -9, -9), oct_v(9, 9, 9));
      oc_vec3 lp = mat_apply(ai, oct_sub(p, tr));
      double f = oc_program_eval(px, p), ref = oc_program_eval(pc, lp);
      ck_assert_msg(fabs(f - ref) <= 1e-9,
                    "transform kind %d: %.17g, expected f(M^-1 p) = %.17g",
                    kind, f, ref);
      if (k % 4 == 0 && ref != 0) {
        /* grad f_T(p) = A^-T grad f(A^-1 (p - t)) */
        oc_vec3 gc, gx;
        oc_program_gradient(pc, lp, &gc);
        oc_program_gradient(px, p, &gx);
        oc_vec3 g = oct_v(ai[0] * gc.x + ai[3] * gc.y + ai[6] * gc.z,
                          ai[1] * gc.x + ai[4] * gc.y + ai[7] * gc.z,
                          ai[2] * gc.x + ai[5] * gc.y + ai[8] * gc.z);
        ck_assert_msg(oct_len(oct_sub(g, gx)) <= 1e-8 * (1 + oct_len(g)),
                      "transform gradient (%g %g %g) vs (%g %g %g)", gx.x, gx.y,
                      gx.z, g.x, g.y, g.z);
        oct_check_grad(px, p, 1e-6, 1e-7);
      }
    }
    double L = oc_program_lipschitz(px), Lc = oc_program_lipschitz(pc);
    double Lref = Lc * sigma_max(ai);
    ck_assert_msg(fabs(L - Lref) <= 1e-6 * Lref,
                  "transform L %.17g, expected L sigma_max(M^-1) = %.17g", L,
                  Lref);
    oct_check_bounds(px, oct_v(-12, -12, -12), oct_v(12, 12, 12), 2000, &r);
    oct_check_lipschitz(px, oct_v(-9, -9, -9), oct_v(9, 9, 9), 800, &r);
    oc_program_free(pc);
    oc_program_free(px);
  }
}
END_TEST

/* A rigid motion of a point primitive is the point primitive moved. */
START_TEST(transform_moves_point) {
  oct_rng r = oct_rng_new(90);
  for (int t = 0; t < 20; t++) {
    double a[9], m[12];
    rotation(oct_dir(&r), oct_unif(&r, -3, 3), a);
    oc_vec3 tr = oct_in_box(&r, oct_v(-3, -3, -3), oct_v(3, 3, 3));
    to34(a, tr, m);
    oc_vec3 c = oct_in_box(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2));
    double R = oct_unif(&r, 0.5, 2);
    oc_error e;
    oc_node *p0 = OCT_OK(oc_point(c, R, 1.3, &e));
    oc_node *x = OCT_OK(oc_transform(p0, m, &e));
    oc_node_release(p0);
    oc_vec3 c2 = oct_add(mat_apply(a, c), tr);
    oc_program *px = oct_compile(x, 0, 0);
    oc_program *pm = oct_compile(OCT_OK(oc_point(c2, R, 1.3, &e)), 0, 0);
    for (int k = 0; k < 200; k++) {
      oc_vec3 p = oct_add(c2, oct_mul(oct_dir(&r), oct_unif(&r, 0, 1.2 * R)));
      ck_assert_double_eq_tol(oc_program_eval(px, p), oc_program_eval(pm, p),
                              1e-12);
    }
    /* A rotation does not change the Lipschitz bound. */
    ck_assert_double_eq_tol(oc_program_lipschitz(px), oc_program_lipschitz(pm),
                            1e-9 * oc_program_lipschitz(pm));
    oc_program_free(px);
    oc_program_free(pm);
  }
}
END_TEST

START_TEST(transform_invalid) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 1, 1);
  double sing[12] = {1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0}; /* rows 2, 3 equal */
  e.code = OC_OK;
  ck_assert_ptr_null(oc_transform(a, sing, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert(e.msg[0] != 0);
  double zero[12] = {0};
  ck_assert_ptr_null(oc_transform(a, zero, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  double nan[12] = {1, 0, 0, NAN, 0, 1, 0, 0, 0, 0, 1, 0};
  ck_assert_ptr_null(oc_transform(a, nan, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  double inf[12] = {1, 0, 0, 0, 0, INFINITY, 0, 0, 0, 0, 1, 0};
  ck_assert_ptr_null(oc_transform(a, inf, NULL));
  double id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  ck_assert_ptr_null(oc_transform(NULL, id, NULL));
  oc_node_release(a);
}
END_TEST

/* ---- warp -------------------------------------------------------------- */

static double tmax_of(int o) {
  return 2 - pow(2, 1 - o);
}

START_TEST(warp_amplitude_zero_and_control) {
  oc_error e;
  oc_node *c = OCT_OK(oc_segment(oct_v(-2, 0, 0), oct_v(2, 1, 0), 1.5, 1, &e));
  oc_noise n0 = {2, 0, 0, 3, 7}, n1 = {2, 0.6, 0, 3, 7};
  oc_node *ctl = pt(2, 0, 0, 1.5, 1);
  oc_node *ctl3 = pt(-1.5, 0, 0, 2, 3); /* clamps to 1 near its centre */
  oc_node_retain(c);
  oc_program *pc = oct_compile(c, 0, 0);
  oc_program *pw0 = oct_compile(OCT_OK(oc_warp(c, &n0, NULL, &e)), 0, 0);
  oc_program *pw = oct_compile(OCT_OK(oc_warp(c, &n1, NULL, &e)), 0, 0);
  oc_program *pwc = oct_compile(OCT_OK(oc_warp(c, &n1, ctl, &e)), 0, 0);
  oc_program *pw3 = oct_compile(OCT_OK(oc_warp(c, &n1, ctl3, &e)), 0, 0);
  oc_program *pctl = oct_compile(ctl, 0, 0);
  oc_program *pctl3 = oct_compile(ctl3, 0, 0);
  oc_node_release(c);
  oct_rng r = oct_rng_new(100);
  int differ = 0, active = 0, ctl_out = 0, ctl_in = 0, clamp = 0;
  for (int k = 0; k < 3000; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-4, -3, -3), oct_v(4, 3, 3));
    double f = oc_program_eval(pc, p), fw = oc_program_eval(pw, p);
    ck_assert_double_eq(oc_program_eval(pw0, p), f);
    if (f != 0 || fw != 0) active++;
    if (fabs(fw - f) > 1e-6) differ++;
    double w = oc_program_eval(pctl, p), fwc = oc_program_eval(pwc, p);
    if (w == 0) {
      ck_assert_msg(fwc == f, "control 0 but warped: %.17g vs %.17g", fwc, f);
      ctl_out++;
    } else if (fabs(fwc - f) > 1e-9) {
      ctl_in++;
    }
    if (oc_program_eval(pctl3, p) >= 1) {
      ck_assert_double_eq_tol(oc_program_eval(pw3, p), fw, 1e-12);
      clamp++;
    } else if (oc_program_eval(pctl3, p) == 0) {
      ck_assert_double_eq(oc_program_eval(pw3, p), f);
    }
  }
  ck_assert_int_gt(active, 300);
  ck_assert_int_gt(differ, 0.8 * active);
  ck_assert_int_gt(ctl_out, 1000);
  ck_assert_int_gt(ctl_in, 50);
  ck_assert_int_gt(clamp, 20);
  /* At the control's centre w = 1: the full warp. */
  ck_assert_double_eq_tol(oc_program_eval(pwc, oct_v(2, 0, 0)),
                          oc_program_eval(pw, oct_v(2, 0, 0)), 1e-12);
  oc_program_free(pc);
  oc_program_free(pw0);
  oc_program_free(pw);
  oc_program_free(pwc);
  oc_program_free(pw3);
  oc_program_free(pctl);
  oc_program_free(pctl3);
}
END_TEST

/* With a point child the warped value gives back |p + delta - c|, and
** each component of delta is within A tmax / 2. */
START_TEST(warp_displacement_bounded) {
  oc_error e;
  oc_vec3 c = oct_v(0.5, 0, -0.5);
  double R = 3, A = 0.8;
  int o = 4;
  oc_noise nz = {1.5, A, 0, o, 3};
  oc_node *p0 = OCT_OK(oc_point(c, R, 1, &e));
  oc_program *pw = oct_compile(OCT_OK(oc_warp(p0, &nz, NULL, &e)), 0, 0);
  oc_node_release(p0);
  double dmax = sqrt(3.0) * fabs(A) * tmax_of(o) / 2;
  oct_rng r = oct_rng_new(101);
  double seen = 0;
  for (int k = 0; k < 3000; k++) {
    oc_vec3 p = oct_add(c, oct_mul(oct_dir(&r), oct_unif(&r, 0, R + dmax)));
    double f = oc_program_eval(pw, p), d = oct_len(oct_sub(p, c));
    ck_assert(f >= 0 && f <= 1);
    if (f > 1e-6 && f < 0.999) {
      double dw = oct_ginv(f) * R;
      ck_assert_msg(fabs(dw - d) <= dmax * (1 + 1e-9), "warp moved by %g > %g",
                    fabs(dw - d), dmax);
      seen = fmax(seen, fabs(dw - d));
    } else if (f == 0) {
      ck_assert(d >= R - dmax * (1 + 1e-9));
    }
  }
  ck_assert_msg(seen > 0.2 * dmax, "displacement only %g of %g", seen, dmax);
  oc_program_free(pw);
}
END_TEST

START_TEST(warp_bounds_lipschitz_gradient) {
  int with_ctl = _i;
  oc_error e;
  double A = -0.7, wl = 2.5;
  int o = 3;
  oc_noise nz = {wl, A, 0, o, 11};
  oc_node *c =
      OCT_OK(oc_box(oct_v(-1, -1, -0.5), oct_v(1, 0.5, 1), 1.2, 1, &e));
  oc_node *ctl = with_ctl ? pt(1, 0, 0, 2, 1) : NULL;
  oc_node_retain(c);
  oc_program *pc = oct_compile(c, 0, 0);
  oc_program *pw = oct_compile(OCT_OK(oc_warp(c, &nz, ctl, &e)), 0, 0);
  oc_node_release(c);
  double Lc = oc_program_lipschitz(pc);
  double Lctl = with_ctl ? OCT_LG / 2 : 0;
  double Lref = Lc * (1 + sqrt(3.0) * fabs(A) * o * oc_noise3_lipschitz / wl +
                      sqrt(3.0) * fabs(A) * tmax_of(o) / 2 * Lctl);
  double L = oc_program_lipschitz(pw);
  oct_rng r = oct_rng_new(102 + (uint64_t)with_ctl);
  oc_vec3 lo = oct_v(-5, -5, -5), hi = oct_v(5, 5, 5);
  int nz_count = oct_check_bounds(pw, lo, hi, 4000, &r);
  ck_assert_int_gt(nz_count, 100);
  oct_check_lipschitz(pw, lo, hi, 4000, &r);
  int checked = 0;
  for (int k = 0; k < 400; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-3, -3, -3), oct_v(3, 3, 3));
    double f = oc_program_eval(pw, p);
    if (f == 0 || f == 1) continue;
    oct_check_grad(pw, p, 1e-6, 1e-7 * L);
    checked++;
  }
  ck_assert_int_gt(checked, 50);
  ck_assert_msg(fabs(L - Lref) <= 1e-9 * Lref, "warp L %.17g, expected %.17g",
                L, Lref);
  if (ctl) oc_node_release(ctl);
  oc_program_free(pc);
  oc_program_free(pw);
}
END_TEST

START_TEST(warp_invalid) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 1, 1);
  oc_noise bad_wl = {0, 1, 0, 3, 0}, bad_o = {1, 1, 0, 0, 0},
           bad_a = {1, NAN, 0, 3, 0}, ok = {1, 1, 0, 3, 0};
  OCT_EINVAL(oc_warp(a, &bad_wl, NULL, &e), e, "wavelength");
  OCT_EINVAL(oc_warp(a, &bad_o, NULL, &e), e, "octaves");
  OCT_EINVAL(oc_warp(a, &bad_a, NULL, &e), e, "amplitude");
  ck_assert_ptr_null(oc_warp(NULL, &ok, NULL, NULL));
  ck_assert_ptr_null(oc_warp(a, NULL, NULL, NULL));
  OCT_EINVAL(oc_perturb(a, &bad_wl, &e), e, "wavelength");
  OCT_EINVAL(oc_perturb(a, &bad_o, &e), e, "octaves");
  oc_node_release(a);
}
END_TEST

/* ---- perturb ----------------------------------------------------------- */

START_TEST(perturb_amplitude_zero) {
  oct_rng r = oct_rng_new(110);
  oc_noise n0 = {1.5, 0, 0, 3, 5};
  for (int t = 0; t < 20; t++) {
    oc_node *a =
        oct_random_prim(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2), 1, 3, 0.3);
    oc_error e;
    oc_node *pn = OCT_OK(oc_perturb(a, &n0, &e));
    oc_program *pa = oct_compile(a, 0, 0), *pp = oct_compile(pn, 0, 0);
    for (int k = 0; k < 400; k++) {
      oc_vec3 p = oct_in_box(&r, LO, HI);
      double fa = oc_program_eval(pa, p), fp = oc_program_eval(pp, p);
      ck_assert_msg(fabs(fa - fp) <= 1e-12, "amplitude 0: %.17g vs %.17g", fp,
                    fa);
    }
    oc_program_free(pa);
    oc_program_free(pp);
  }
}
END_TEST

/* Along a ray from the skeleton the radius is fixed, so f = E g(d / rho)
** with one rho per ray, inside [rho_min, rho_max]. */
static void check_ray(const oc_program *pp, oc_vec3 s, oc_vec3 u, double E,
                      double rmin, double rmax) {
  double prev = INFINITY, ratio = NAN;
  for (int k = 1; k <= 60; k++) {
    double d = rmax * 1.1 * k / 60;
    double f = oc_program_eval(pp, oct_add(s, oct_mul(u, d))) / E;
    ck_assert_msg(f <= prev,
                  "not star-shaped: f grows from %.17g to %.17g "
                  "at d=%g",
                  prev, f, d);
    prev = f;
    if (f > 0.01 && f < 0.99) {
      double rho = d / oct_ginv(f);
      ck_assert_msg(rho >= rmin * (1 - 1e-9) && rho <= rmax * (1 + 1e-9),
                    "radius %g outside [%g, %g]", rho, rmin, rmax);
      if (isnan(ratio)) ratio = rho;
      ck_assert_msg(fabs(rho - ratio) <= 1e-7 * ratio,
                    "radius changes along a ray: %.12g vs %.12g", rho, ratio);
    }
  }
  ck_assert(prev == 0);
}

START_TEST(perturb_star_shaped) {
  double A = _i == 0 ? 0.8 : -0.6;
  int o = 3;
  double R = 2, E = 1.4;
  oc_noise nz = {1.5, A, 0, o, 21};
  double rmin = R + fmin(0, A * tmax_of(o)), rmax = R + fmax(0, A * tmax_of(o));
  oc_error e;
  oc_vec3 c = oct_v(1, -1, 0.5);
  oc_node *p0 = OCT_OK(oc_point(c, R, E, &e));
  oc_program *pp = oct_compile(OCT_OK(oc_perturb(p0, &nz, &e)), 0, 0);
  oc_node_release(p0);
  oct_rng r = oct_rng_new(120 + (uint64_t)_i);
  for (int k = 0; k < 300; k++)
    check_ray(pp, c, oct_dir(&r), E, rmin, rmax);
  oc_program_free(pp);

  /* A segment: rays perpendicular to it from an interior point. */
  oc_vec3 a = oct_v(-2, 0, 0), b = oct_v(2, 1, 0);
  oc_node *s0 = OCT_OK(oc_segment(a, b, R, E, &e));
  pp = oct_compile(OCT_OK(oc_perturb(s0, &nz, &e)), 0, 0);
  oc_node_release(s0);
  oc_vec3 ax = oct_sub(b, a);
  ax = oct_mul(ax, 1 / oct_len(ax));
  for (int k = 0; k < 200; k++) {
    oc_vec3 s = oct_add(a, oct_mul(oct_sub(b, a), oct_unif(&r, 0.05, 0.95)));
    oc_vec3 u = oct_dir(&r);
    u = oct_sub(u, oct_mul(ax, oct_dot(u, ax)));
    if (oct_len(u) < 0.1) continue;
    check_ray(pp, s, oct_mul(u, 1 / oct_len(u)), E, rmin, rmax);
  }
  /* The perturbation varies from ray to ray (not a constant radius). */
  double lo = INFINITY, hi = -INFINITY;
  for (int k = 0; k < 200; k++) {
    double f = oc_program_eval(pp, oct_add(c, oct_mul(oct_dir(&r), R * 0.8)));
    lo = fmin(lo, f), hi = fmax(hi, f);
  }
  ck_assert_msg(hi - lo > 0.01, "perturbation has no effect: [%g, %g]", lo, hi);
  oc_program_free(pp);
}
END_TEST

/* Point, sphere, box, segment: bounds, Lipschitz (formula and pairs) and
** gradients away from the skeleton and the projection's region seams. */
START_TEST(perturb_queries) {
  int kind = _i % 4;
  double A = _i < 4 ? 0.7 : -0.5;
  int o = 3;
  double wl = 1.2, R = 1.5, E = _i % 2 ? -1.2 : 0.9;
  oc_noise nz = {wl, A, 0, o, 31};
  oc_error e;
  oc_vec3 lo0 = oct_v(-1, -0.5, -1), hi0 = oct_v(1, 1, 0.5);
  oc_node *p0 = NULL;
  switch (kind) {
  case 0:
    p0 = oc_point(lo0, R, E, &e);
    break;
  case 1:
    p0 = oc_sphere(lo0, 0.8, R, E, &e);
    break;
  case 2:
    p0 = oc_box(lo0, hi0, R, E, &e);
    break;
  case 3:
    p0 = oc_segment(lo0, hi0, R, E, &e);
    break;
  }
  OCT_OK(p0);
  oc_program *pp = oct_compile(OCT_OK(oc_perturb(p0, &nz, &e)), 0, 0);
  oc_node_release(p0);
  double tm = tmax_of(o);
  double rmin = R + fmin(0, A * tm), rmax = R + fmax(0, A * tm);
  double Lref = fabs(E) * OCT_LG *
                (1 / rmin + fabs(A) * o * oc_noise3_lipschitz / wl *
                                (rmax + R) / (rmin * rmin));
  double L = oc_program_lipschitz(pp);
  oct_rng r = oct_rng_new(130 + (uint64_t)_i);
  oc_vec3 lo = oct_v(-6, -6, -6), hi = oct_v(6, 6, 6);
  ck_assert_int_gt(oct_check_bounds(pp, lo, hi, 4000, &r), 5);
  oc_aabb b = oc_program_bounds(pp);
  ck_assert(oc_program_eval(pp, lo0) == E);
  ck_assert(b.lo.x >= -1 - 0.8 - rmax - 1 && b.hi.x <= 1 + rmax + 1);
  oct_check_lipschitz(pp, oct_v(-4, -4, -4), oct_v(4, 4, 4), 4000, &r);
  int checked = 0;
  for (int k = 0; k < 600; k++) {
    /* near the skeleton / solid, within the support */
    oc_vec3 s =
        kind == 0   ? lo0
        : kind == 1 ? oct_add(lo0, oct_mul(oct_dir(&r), 0.8))
        : kind == 2
            ? oct_in_box(&r, lo0, hi0)
            : oct_add(lo0, oct_mul(oct_sub(hi0, lo0), oct_unif(&r, 0, 1)));
    oc_vec3 p = oct_add(s, oct_mul(oct_dir(&r), oct_unif(&r, 0, rmax)));
    double d;
    const double *pc = &p.x, *l = &lo0.x, *h = &hi0.x;
    int seam = 0;
    switch (kind) {
    case 0:
      d = oct_len(oct_sub(p, lo0));
      break;
    case 1:
      d = oct_len(oct_sub(p, lo0)) - 0.8;
      break;
    case 2:
      d = oct_dist_box(p, lo0, hi0);
      for (int a = 0; a < 3; a++)
        if (fabs(pc[a] - l[a]) < 1e-4 || fabs(pc[a] - h[a]) < 1e-4) seam = 1;
      break;
    default: {
      oc_vec3 ax = oct_sub(hi0, lo0);
      double t = oct_dot(oct_sub(p, lo0), ax) / oct_dot(ax, ax);
      if (fabs(t) < 1e-4 || fabs(t - 1) < 1e-4) seam = 1;
      d = oct_dist_segment(p, lo0, hi0, NULL);
    }
    }
    if (seam || d < 0.05 * R || d > rmax) continue;
    double f = oc_program_eval(pp, p);
    if (f == 0) continue;
    oct_check_grad(pp, p, 1e-6 * R, 1e-7 * L);
    checked++;
  }
  ck_assert_int_gt(checked, 40);
  ck_assert_msg(fabs(L - Lref) <= 1e-9 * Lref,
                "perturb kind %d: L %.17g, expected %.17g", kind, L, Lref);
  oc_program_free(pp);
}
END_TEST

/* The analytic gradient of perturbed curves (segment interiors and vertex
** regions; the other kinds: perturb_queries) against central
** differences, and its value against eval. */
START_TEST(perturb_gradient_curves) {
  oct_rng r = oct_rng_new(150);
  oc_noise nz = {1.1, 0.6, 0, 3, 43};
  oc_error e;
  oc_vec3 pts[5] = {
      {-2, 0, 0}, {0, 1.5, 0}, {2, 0, 0.5}, {3, 2, 0}, {1, 3, -1}};
  oc_node *k[2] = {
      OCT_OK(oc_curve(pts, 5, 0, 1.3, 1, &e)),
      OCT_OK(oc_curve(pts, 4, 1, 1.3, -0.8, &e))}; /* a flattened Bezier */
  for (int i = 0; i < 2; i++) {
    oc_program *pp = oct_compile(OCT_OK(oc_perturb(k[i], &nz, &e)), 0, 0);
    oc_node_release(k[i]);
    double L = oc_program_lipschitz(pp);
    int checked = 0;
    for (int n = 0; n < 2000; n++) {
      oc_vec3 p = oct_in_box(&r, oct_v(-4, -3, -3), oct_v(5, 5, 3));
      double f = oc_program_eval(pp, p);
      if (f == 0 || fabs(f) == 1 || f == -0.8) continue;
      oct_check_grad(pp, p, 1e-6, 1e-7 * L);
      checked++;
    }
    ck_assert_int_gt(checked, 200);
    oc_program_free(pp);
  }
}
END_TEST

/* Curves and cones: the perturbed radius stays within [rho_min, rho_max],
** so g(d / rho_min) <= f <= g(d / rho_max) (E = 1), d recovered from the
** unperturbed field. */
START_TEST(perturb_bracket) {
  oct_rng r = oct_rng_new(140);
  double A = 0.9;
  int o = 2;
  oc_noise nz = {1, A, 0, o, 41};
  double R = 1.2, rmin = R, rmax = R + A * tmax_of(o);
  oc_error e;
  oc_vec3 pts[4] = {{-2, 0, 0}, {0, 1.5, 0}, {2, 0, 0.5}, {3, 2, 0}};
  oc_node *cv = OCT_OK(oc_curve(pts, 4, 0, R, 1, &e));
  oc_node *cn = OCT_OK(oc_cone(oct_v(0, 0, -1), oct_v(0, 1, 2), 1, R, 1, &e));
  oc_node *kids[2] = {cv, cn};
  for (int i = 0; i < 2; i++) {
    oc_program *pp = oct_compile(OCT_OK(oc_perturb(kids[i], &nz, &e)), 0, 0);
    oc_program *p0 = oct_compile(kids[i], 0, 0);
    for (int k = 0; k < 3000; k++) {
      oc_vec3 p = oct_in_box(&r, oct_v(-5, -5, -5), oct_v(6, 6, 6));
      /* d/R from the unperturbed field, where it is invertible */
      double f0 = oc_program_eval(p0, p);
      double f = oc_program_eval(pp, p);
      ck_assert(f >= 0 && f <= 1);
      if (f0 <= 0 || f0 >= 1) continue;
      double d = oct_ginv(f0) * R;
      ck_assert_msg(f >= oct_g(d / rmin) - 1e-9 && f <= oct_g(d / rmax) + 1e-9,
                    "perturbed %.17g outside [%.17g, %.17g]", f,
                    oct_g(d / rmin), oct_g(d / rmax));
    }
    oc_program_free(pp);
    oc_program_free(p0);
  }
}
END_TEST

START_TEST(perturb_rejects_non_primitives) {
  oc_error e;
  oc_noise nz = {1, 0.5, 0, 3, 0};
  oc_node *pl = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e));
  oc_node *tb = OCT_OK(oc_turbulence(&nz, &e));
  oc_node *a = pt(0, 0, 0, 1, 1);
  oc_node *ab[2] = {a, a};
  oc_node *bl = OCT_OK(oc_blend(ab, 2, &e));
  e.code = OC_OK;
  ck_assert_ptr_null(oc_perturb(pl, &nz, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  e.code = OC_OK;
  ck_assert_ptr_null(oc_perturb(tb, &nz, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  e.code = OC_OK;
  ck_assert_ptr_null(oc_perturb(bl, &nz, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_perturb(NULL, &nz, NULL));
  oc_node_release(pl);
  oc_node_release(tb);
  oc_node_release(a);
  oc_node_release(bl);
}
END_TEST

/* ---- DAG instancing ---------------------------------------------------- */

START_TEST(dag_instancing) {
  oc_error e;
  oc_node *a = pt(0, 0, 0, 2, 0.7), *b = pt(1, 0, 0, 1, 0.4);
  oc_node *aa[2] = {a, a};
  oc_node_retain(a);
  oc_program *pa = oct_compile(a, 0, 0);
  oc_node *bl = OCT_OK(oc_blend(aa, 2, &e));
  ck_assert_ptr_eq(oc_node_child(bl, 0), oc_node_child(bl, 1));
  oc_program *pb = oct_compile(bl, 0, 0);
  oc_program_stats st;
  oc_program_get_stats(pb, &st);
  ck_assert_uint_eq(st.nodes, 2);
  ck_assert_uint_eq(st.primitives, 1);
  ck_assert_uint_gt(st.bytes, 0);

  oc_node *ab[2] = {a, b};
  oc_node *x = OCT_OK(oc_blend(ab, 2, &e));
  oc_node *xx[2] = {x, x};
  oc_node *y = OCT_OK(oc_union(xx, 2, &e));
  oc_node *yz[2] = {y, x};
  oc_node *z = OCT_OK(oc_blend(yz, 2, &e));
  oc_node_release(x), oc_node_release(y);
  oc_node_retain(oc_node_child(z, 1)); /* oct_compile releases one */
  oc_program *pb2 = oct_compile(oc_node_child(z, 1), 0, 0);
  oc_program *pz = oct_compile(z, 0, 0);
  oc_program_get_stats(pz, &st);
  ck_assert_uint_eq(st.primitives, 2);
  oct_rng r = oct_rng_new(150);
  for (int k = 0; k < 500; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-3, -3, -3), oct_v(3, 3, 3));
    double fa = oc_program_eval(pa, p);
    ck_assert_double_eq_tol(oc_program_eval(pb, p), 2 * fa, 1e-15);
    double fx = oc_program_eval(pb2, p);
    ck_assert_double_eq_tol(oc_program_eval(pz, p), 2 * fx, 1e-15);
  }
  oc_node_release(a);
  oc_node_release(b);
  oc_program_free(pa);
  oc_program_free(pb);
  oc_program_free(pb2);
  oc_program_free(pz);
}
END_TEST

/* ---- deep chains ------------------------------------------------------- */

START_TEST(deep_blend_chain) {
  enum { N = 100000 };
  oc_error e;
  oc_node *a = pt(0.5, 0, 0, 2, 1);
  oc_node *n = a;
  oc_node_retain(n);
  for (int i = 1; i < N; i++) {
    oc_node *two[2] = {n, a};
    oc_node *m = oc_blend(two, 2, &e);
    ck_assert_msg(m != NULL, "blend %d: %s", i, e.msg);
    oc_node_release(n);
    n = m;
  }
  oc_program *pa = oct_compile(a, 0, 0);
  oc_program *pr = oct_compile(n, 0, 0);
  oc_program_stats st;
  oc_program_get_stats(pr, &st);
  ck_assert_uint_eq(st.primitives, 1);
  oct_rng r = oct_rng_new(160);
  for (int k = 0; k < 20; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-2, -2, -2), oct_v(3, 2, 2));
    double f = oc_program_eval(pr, p), ref = N * oc_program_eval(pa, p);
    ck_assert_msg(fabs(f - ref) <= 1e-9 * (1 + fabs(ref)),
                  "deep blend %.17g, expected %.17g", f, ref);
  }
  oc_program_free(pa);
  oc_program_free(pr);
}
END_TEST

/* ((a - b1) - b2) - ... flattens to a - (b1 | b2 | ...). */
START_TEST(deep_difference_chain) {
  enum { N = 10000 };
  oc_error e;
  oc_node *a = OCT_OK(oc_box(oct_v(-10, -10, -1), oct_v(10, 10, 1), 1, 1, &e));
  oc_node_retain(a);
  oc_program *pa = oct_compile(a, 0, 0);
  oc_node *n = a;
  oct_rng r = oct_rng_new(170);
  oc_vec3 c[N];
  for (int i = 0; i < N; i++) {
    c[i] = oct_in_box(&r, oct_v(-10, -10, -1), oct_v(10, 10, 1));
    oc_node *b = OCT_OK(oc_point(c[i], 0.3, 1, &e));
    oc_node *m = oc_difference(n, b, &e);
    ck_assert_msg(m != NULL, "difference %d: %s", i, e.msg);
    oc_node_release(n);
    oc_node_release(b);
    n = m;
  }
  oc_program *pr = oct_compile(n, 0, 0);
  for (int k = 0; k < 200; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-11, -11, -2), oct_v(11, 11, 2));
    double fb = 0;
    for (int i = 0; i < N; i++)
      fb = fmax(fb, oct_g(oct_len(oct_sub(p, c[i])) / 0.3));
    double ref = fmin(oc_program_eval(pa, p), 1.0 - fb);
    /* Large groups of plain points are stored in single precision by the
    ** engine (lib/field/compile.c, INLINE_MIN): ~1e-6 on values. */
    ck_assert_double_eq_tol(oc_program_eval(pr, p), ref, 2e-5);
  }
  oc_program_free(pa);
  oc_program_free(pr);
}
END_TEST

static void expect_too_deep(oc_node *n, const char *what) {
  oc_error e = {OC_OK, ""};
  oc_program *pr = oc_compile(n, NULL, &e);
  if (pr) oc_program_free(pr);
  ck_assert_msg(pr == NULL && e.code == OC_ETOODEEP,
                "%s: compiled (%d) instead of OC_ETOODEEP", what, (int)e.code);
  ck_assert_msg(e.msg[0] != 0, "%s: OC_ETOODEEP without a message", what);
}

START_TEST(depth_limit) {
  oc_error e;
  double m[12] = {1, 0, 0, 0.001, 0, 1, 0, 0, 0, 0, 1, 0};
  oc_node *n = pt(0, 0, 0, 1, 1);
  for (int i = 0; i < 1000; i++) {
    oc_node *t = oc_transform(n, m, &e);
    ck_assert_msg(t != NULL, "transform %d: %s", i, e.msg);
    oc_node_release(n);
    n = t;
    if (i == 399) {
      /* Well under the limit: compiles and evaluates. */
      oc_program *pr = oc_compile(n, NULL, &e);
      ck_assert_msg(pr != NULL, "400 transforms: %s", e.msg);
      ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(0.4, 0, 0)), 1.0, 1e-9);
      oc_program_free(pr);
    }
  }
  expect_too_deep(n, "1000 nested transforms");
  oc_node_release(n);

  /* a - (b - (c - ...)) is not a chain that flattens. */
  n = pt(0, 0, 0, 1, 1);
  for (int i = 0; i < 1000; i++) {
    oc_node *b = pt(i * 0.01, 0, 0, 1, 1);
    oc_node *d = OCT_OK(oc_difference(b, n, &e));
    oc_node_release(b);
    oc_node_release(n);
    n = d;
  }
  expect_too_deep(n, "1000 right-nested differences");
  oc_node_release(n);
}
END_TEST

/* Releasing a very deep tree must not recurse. */
START_TEST(release_huge_tree) {
  enum { N = 500000 };
  oc_error e;
  oc_node *n = pt(0, 0, 0, 1, 1);
  for (int i = 0; i < N; i++) {
    oc_node *s = oc_scale_field(n, 1.0, &e);
    ck_assert_msg(s != NULL, "scale %d: %s", i, e.msg);
    oc_node_release(n);
    n = s;
  }
  ck_assert_str_eq(oc_node_kind(oc_node_child(n, 0)), "scale");
  oc_node_release(n);
  /* And a deep right-nested blend, whose children are shared. */
  oc_node *a = pt(0, 0, 0, 1, 1);
  n = a;
  oc_node_retain(n);
  for (int i = 0; i < N / 5; i++) {
    oc_node *two[2] = {a, n};
    oc_node *m = OCT_OK(oc_blend(two, 2, &e));
    oc_node_release(n);
    n = m;
  }
  oc_node_release(n);
  oc_node_release(a);
}
END_TEST

int main(void) {
  Suite *s = suite_create("ops");
  TCase *tc = tcase_create("ops");
  tcase_set_timeout(tc, 120);
  tcase_add_loop_test(tc, nary_equals_sum_max_min, 0, 3);
  tcase_add_loop_test(tc, nary_gradients, 0, 3);
  tcase_add_test(tc, nary_invalid);
  tcase_add_loop_test(tc, difference_values, 0, 2);
  tcase_add_test(tc, difference_strong_subtrahend);
  tcase_add_test(tc, difference_chain_flattens);
  tcase_add_loop_test(tc, smooth_values, 0, 8);
  tcase_add_test(tc, smooth_lipschitz_formula);
  tcase_add_test(tc, smooth_union_c1);
  tcase_add_test(tc, smooth_compact_support);
  tcase_add_test(tc, scale_field);
  tcase_add_loop_test(tc, transform_values, 0, 5);
  tcase_add_test(tc, transform_moves_point);
  tcase_add_test(tc, transform_invalid);
  tcase_add_test(tc, warp_amplitude_zero_and_control);
  tcase_add_test(tc, warp_displacement_bounded);
  tcase_add_loop_test(tc, warp_bounds_lipschitz_gradient, 0, 2);
  tcase_add_test(tc, warp_invalid);
  tcase_add_test(tc, perturb_amplitude_zero);
  tcase_add_loop_test(tc, perturb_star_shaped, 0, 2);
  tcase_add_loop_test(tc, perturb_queries, 0, 8);
  tcase_add_test(tc, perturb_gradient_curves);
  tcase_add_test(tc, perturb_bracket);
  tcase_add_test(tc, perturb_rejects_non_primitives);
  tcase_add_test(tc, dag_instancing);
  tcase_add_test(tc, deep_blend_chain);
  tcase_add_test(tc, deep_difference_chain);
  tcase_add_test(tc, depth_limit);
  tcase_add_test(tc, release_huge_tree);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
