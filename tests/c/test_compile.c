/*
** test_compile.c — the compiled program: BVH evaluation against brute
** force, memory per primitive, batch evaluation, determinism across
** thread counts, NaN input and concurrent evaluation.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"

static const oc_vec3 WLO = {-50, -50, -50}, WHI = {50, 50, 50};

/* n random primitives of mixed kinds over the world box (some carving),
** plus optionally one plane and one turbulence (unbounded). */
static oc_node **random_children(oct_rng *r, size_t n, int unbounded,
                                 size_t *count) {
  oc_node **c = malloc((n + 2) * sizeof *c);
  ck_assert_ptr_nonnull(c);
  oc_error e;
  for (size_t i = 0; i < n; i++) {
    double u = oct_unif(r, 0, 1);
    if (u < 0.03) {
      oc_vec3 pts[4];
      pts[0] = oct_in_box(r, WLO, WHI);
      for (int k = 1; k < 4; k++)
        pts[k] = oct_add(pts[k - 1], oct_mul(oct_dir(r), oct_unif(r, 1, 4)));
      c[i] = OCT_OK(oc_curve(pts, 4, u < 0.015, oct_unif(r, 1, 3),
                             oct_unif(r, -1, 1.5), &e));
    } else if (u < 0.06) {
      oc_vec3 b = oct_in_box(r, WLO, WHI);
      c[i] = OCT_OK(oc_cone(b, oct_add(b, oct_mul(oct_dir(r), 3)), 1.5,
                            oct_unif(r, 1, 3), 1, &e));
    } else {
      c[i] = oct_random_prim(r, WLO, WHI, 1, 5, 0.25);
    }
  }
  *count = n;
  if (unbounded) {
    c[n] = OCT_OK(oc_plane(oct_v(0, 0, -20), oct_v(0.1, 0.2, 1), 4, 0.8, &e));
    oc_noise nz = {10, 0.3, -0.1, 3, 77};
    c[n + 1] = OCT_OK(oc_turbulence(&nz, &e));
    *count = n + 2;
  }
  return c;
}

static void free_children(oc_node **c, size_t n) {
  for (size_t i = 0; i < n; i++)
    oc_node_release(c[i]);
  free(c);
}

enum { OP_BLEND, OP_UNION, OP_INTER };

static oc_node *nary(int op, oc_node **c, size_t n) {
  oc_error e;
  oc_node *r = op == OP_BLEND   ? oc_blend(c, n, &e)
               : op == OP_UNION ? oc_union(c, n, &e)
                                : oc_intersection(c, n, &e);
  ck_assert_msg(r != NULL, "n-ary node: %s", e.msg);
  return r;
}

/* _i: operator, and (for blend and union) the size. */
START_TEST(bvh_equals_brute_force) {
  static const struct {
    int op;
    size_t n;
  } cases[] = {
      {OP_BLEND, 1000},  {OP_BLEND, 5000}, {OP_BLEND, 20000}, {OP_UNION, 1000},
      {OP_UNION, 20000}, {OP_INTER, 1000}, {OP_BLEND, 3},
  };
  int op = cases[_i].op;
  size_t n = cases[_i].n, count;
  oct_rng r = oct_rng_new(1000 + (uint64_t)_i);
  oc_node **c = random_children(&r, n, 1, &count);
  oc_node *root = nary(op, c, count);
  free_children(c, count);
  oc_node_retain(root);
  oc_program *fast = oct_compile(root, 0, 0);
  oc_program *brute = oct_compile(root, 0, 1);
  int npts = n > 5000 ? 400 : 1500;
  for (int k = 0; k < npts; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-60, -60, -60), oct_v(60, 60, 60));
    oc_vec3 gf, gb;
    double ff = oc_program_gradient(fast, p, &gf);
    double fb = oc_program_gradient(brute, p, &gb);
    ck_assert_msg(fabs(ff - fb) <= 1e-9 * (1 + fabs(fb)),
                  "op %d n %zu: BVH %.17g vs brute force %.17g at "
                  "(%g %g %g)",
                  op, n, ff, fb, p.x, p.y, p.z);
    ck_assert_msg(oct_len(oct_sub(gf, gb)) <= 1e-9 * (1 + oct_len(gb)),
                  "op %d n %zu: BVH gradient (%g %g %g) vs (%g %g %g)", op, n,
                  gf.x, gf.y, gf.z, gb.x, gb.y, gb.z);
    ck_assert(oc_program_eval(fast, p) == ff);
  }
  ck_assert_double_eq(oc_program_lipschitz(fast), oc_program_lipschitz(brute));
  oc_program_free(fast);
  oc_program_free(brute);
}
END_TEST

/* Bounded children only: bounds, Lipschitz, and the BVH's pruning near
** the edges of supports. */
START_TEST(bvh_bounded_queries) {
  oct_rng r = oct_rng_new(1100 + (uint64_t)_i);
  size_t count;
  oc_node **c = random_children(&r, 3000, 0, &count);
  oc_node *root = nary(_i == 0 ? OP_BLEND : OP_UNION, c, count);
  free_children(c, count);
  oc_program *pr = oct_compile(root, 0, 0);
  oc_aabb b = oc_program_bounds(pr);
  ck_assert_msg(b.lo.x >= -60 && b.hi.x <= 60 && b.lo.x < -45 && b.hi.x > 45,
                "bounds x [%g, %g]", b.lo.x, b.hi.x);
  int nz =
      oct_check_bounds(pr, oct_v(-70, -70, -70), oct_v(70, 70, 70), 3000, &r);
  ck_assert_int_gt(nz, 100);
  oct_check_lipschitz(pr, oct_v(-55, -55, -55), oct_v(55, 55, 55), 3000, &r);
  oc_program_free(pr);
}
END_TEST

START_TEST(stats_and_memory) {
  enum { N = 10000 };
  oct_rng r = oct_rng_new(1200);
  oc_node **c = malloc(N * sizeof *c);
  oc_error e;
  for (int i = 0; i < N; i++)
    c[i] =
        OCT_OK(oc_point(oct_in_box(&r, WLO, WHI), oct_unif(&r, 1, 4), 1, &e));
  oc_node *root = nary(OP_BLEND, c, N);
  free_children(c, N);
  oc_program *pr = oct_compile(root, 0, 0);
  oc_program_stats st;
  memset(&st, 0xff, sizeof st);
  oc_program_get_stats(pr, &st);
  ck_assert_uint_eq(st.nodes, N + 1);
  ck_assert_uint_eq(st.primitives, N);
  ck_assert_uint_gt(st.bytes, 0);
  ck_assert_msg(st.bytes <= 40 * (size_t)N,
                "blend of %d points takes %zu bytes (%.1f per point)", N,
                st.bytes, (double)st.bytes / N);
  oc_program_free(pr);

  /* A single primitive: the minimal program. */
  pr = oct_compile(OCT_OK(oc_point(oct_v(0, 0, 0), 1, 1, &e)), 0, 0);
  oc_program_get_stats(pr, &st);
  ck_assert_uint_eq(st.nodes, 1);
  ck_assert_uint_eq(st.primitives, 1);
  ck_assert_uint_gt(st.bytes, 0);
  oc_program_free(pr);
}
END_TEST

/* Many plain points: the engine's compact storage for them must still give
** the formula, up to the rounding of single precision (2^-24 relative on
** coordinates and parameters), which is what the tolerance allows. */
START_TEST(large_point_blend_matches_formula) {
  enum { N = 2000 };
  oct_rng r = oct_rng_new(1250);
  static oc_vec3 c[N];
  static double R[N], E[N];
  oc_node **kids = malloc(N * sizeof *kids);
  oc_error e;
  for (int i = 0; i < N; i++) {
    c[i] = oct_in_box(&r, oct_v(-30, -30, -30), oct_v(30, 30, 30));
    R[i] = oct_unif(&r, 1, 5);
    E[i] = oct_unif(&r, -1, 2);
    kids[i] = OCT_OK(oc_point(c[i], R[i], E[i], &e));
  }
  oc_node *root = nary(OP_BLEND, kids, N);
  free_children(kids, N);
  oc_program *pr = oct_compile(root, 0, 0);
  for (int k = 0; k < 2000; k++) {
    /* near a random point, so that several overlap */
    int j = (int)oct_unif(&r, 0, N);
    oc_vec3 p = oct_add(c[j], oct_mul(oct_dir(&r), oct_unif(&r, 0, R[j])));
    double ref = 0, tol = 1e-12;
    for (int i = 0; i < N; i++) {
      double d = oct_len(oct_sub(p, c[i]));
      if (d >= R[i] * (1 + 1e-6)) continue;
      ref += E[i] * oct_g(d / R[i]);
      double cmax = fmax(fabs(c[i].x), fmax(fabs(c[i].y), fabs(c[i].z)));
      tol += fabs(E[i]) *
             (OCT_LG / R[i] * 2 * cmax * 0x1p-24 * sqrt(3.0) + 8 * 0x1p-24);
    }
    double f = oc_program_eval(pr, p);
    ck_assert_msg(fabs(f - ref) <= tol,
                  "blend of %d points: %.17g, formula %.17g (allowed %g)", N, f,
                  ref, tol);
    if (k % 10 == 0) oct_check_grad(pr, p, 1e-5, 1e-6);
  }
  oct_rng r2 = oct_rng_new(1251);
  oct_check_lipschitz(pr, oct_v(-35, -35, -35), oct_v(35, 35, 35), 3000, &r2);
  oc_program_free(pr);
}
END_TEST

static oc_program *medium_program(uint64_t seed) {
  oct_rng r = oct_rng_new(seed);
  size_t count;
  oc_node **c = random_children(&r, 2000, 1, &count);
  oc_node *root = nary(OP_BLEND, c, count);
  free_children(c, count);
  return oct_compile(root, 0, 0);
}

static oc_vec3 *random_points(uint64_t seed, size_t n) {
  oct_rng r = oct_rng_new(seed);
  oc_vec3 *p = malloc(n * sizeof *p);
  ck_assert_ptr_nonnull(p);
  for (size_t i = 0; i < n; i++)
    p[i] = oct_in_box(&r, oct_v(-55, -55, -55), oct_v(55, 55, 55));
  return p;
}

START_TEST(eval_many_matches_eval) {
  enum { N = 40000 };
  oc_program *pr = medium_program(1300);
  oc_vec3 *p = random_points(1301, N);
  double *o1 = malloc(N * sizeof *o1), *o2 = malloc(N * sizeof *o2);
  omp_set_num_threads(1);
  oc_program_eval_many(pr, p, o1, N);
  omp_set_num_threads(2);
  oc_program_eval_many(pr, p, o2, N);
  ck_assert_msg(memcmp(o1, o2, N * sizeof *o1) == 0,
                "eval_many differs between 1 and 2 threads");
  int nz = 0;
  for (int i = 0; i < N; i++) {
    double f = oc_program_eval(pr, p[i]);
    ck_assert_msg(memcmp(&f, &o1[i], sizeof f) == 0,
                  "eval_many[%d] = %.17g, eval = %.17g", i, o1[i], f);
    nz += f != 0;
  }
  ck_assert_int_gt(nz, N / 2);
  /* Small and empty batches. */
  oc_program_eval_many(pr, p, o1, 0);
  oc_program_eval_many(pr, p + 5, o1, 1);
  ck_assert(o1[0] == oc_program_eval(pr, p[5]));
  free(o1);
  free(o2);
  free(p);
  oc_program_free(pr);
}
END_TEST

START_TEST(concurrent_eval) {
  enum { N = 20000 };
  oc_program *pr = medium_program(1400);
  oc_vec3 *p = random_points(1401, N);
  double *ref = malloc(N * sizeof *ref);
  oc_vec3 *gref = malloc(N * sizeof *gref);
  for (int i = 0; i < N; i++)
    ref[i] = oc_program_gradient(pr, p[i], &gref[i]);
  double *out[2];
  oc_vec3 *gout[2];
  for (int t = 0; t < 2; t++) {
    out[t] = malloc(N * sizeof *out[t]);
    gout[t] = malloc(N * sizeof *gout[t]);
  }
  int nthreads = 0;
#pragma omp parallel num_threads(2)
  {
    int t = omp_get_thread_num();
#pragma omp atomic
    nthreads++;
    /* Both threads walk the same points, in opposite orders. */
    for (int k = 0; k < N; k++) {
      int i = t == 0 ? k : N - 1 - k;
      out[t][i] = oc_program_gradient(pr, p[i], &gout[t][i]);
    }
  }
  ck_assert_int_eq(nthreads, 2);
  for (int t = 0; t < 2; t++) {
    ck_assert(memcmp(out[t], ref, N * sizeof *ref) == 0);
    ck_assert(memcmp(gout[t], gref, N * sizeof *gref) == 0);
    free(out[t]);
    free(gout[t]);
  }
  free(ref);
  free(gref);
  free(p);
  oc_program_free(pr);
}
END_TEST

/* NaN in gives NaN out, for every kind of program, without crashing. */
START_TEST(nan_input) {
  oc_error e;
  oc_noise nz = {3, 0.5, 0, 3, 1};
  oc_node *pt = OCT_OK(oc_point(oct_v(0, 0, 0), 2, 1, &e));
  oc_vec3 pts[3] = {{0, 0, 0}, {1, 1, 0}, {2, 0, 1}};
  oc_node *kids[8];
  int nk = 0;
  kids[nk++] = pt;
  oc_node_retain(pt);
  kids[nk++] = OCT_OK(oc_curve(pts, 3, 0, 1, 1, &e));
  kids[nk++] = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e));
  kids[nk++] = OCT_OK(oc_turbulence(&nz, &e));
  kids[nk++] = OCT_OK(oc_warp(pt, &nz, NULL, &e));
  kids[nk++] = OCT_OK(oc_perturb(pt, &nz, &e));
  double m[12] = {2, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0};
  kids[nk++] = OCT_OK(oc_transform(pt, m, &e));
  oct_rng r = oct_rng_new(1500);
  size_t count;
  oc_node **c = random_children(&r, 1000, 0, &count);
  kids[nk++] = nary(OP_BLEND, c, count);
  free_children(c, count);
  oc_node_release(pt);
  oc_vec3 nanp[3] = {{NAN, 0, 0}, {0, NAN, 0}, {0.5, 0.5, NAN}};
  /* Every case runs (no crash allowed), failures are listed at the end. */
  char bad[512] = "";
  for (int k = 0; k < nk; k++) {
    const char *kind = oc_node_kind(kids[k]);
    oc_program *pr = oct_compile(kids[k], 0, 0);
    int ok = 1;
    for (int j = 0; j < 3; j++) {
      ok &= isnan(oc_program_eval(pr, nanp[j]));
      oc_vec3 g;
      ok &= isnan(oc_program_gradient(pr, nanp[j], &g));
      double out[2];
      oc_vec3 two[2] = {nanp[j], {0, 0, 0}};
      oc_program_eval_many(pr, two, out, 2);
      ok &= isnan(out[0]) && !isnan(out[1]);
    }
    if (!ok && strlen(bad) + strlen(kind) + 2 < sizeof bad) {
      strcat(bad, " ");
      strcat(bad, kind);
    }
    oc_program_free(pr);
  }
  ck_assert_msg(bad[0] == 0, "f(NaN) is not NaN for:%s", bad);
}
END_TEST

START_TEST(compile_options_and_errors) {
  oc_error e = {OC_OK, ""};
  ck_assert_ptr_null(oc_compile(NULL, NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_compile(NULL, NULL, NULL));
  oc_node *a = OCT_OK(oc_point(oct_v(0, 0, 0), 1, 1, &e));
  oc_compile_options o = {0, 0};
  oc_program *p1 = oc_compile(a, &o, &e);
  ck_assert_ptr_nonnull(p1);
  ck_assert_double_eq(oc_program_threshold(p1), OC_DEFAULT_THRESHOLD);
  o.threshold = 0.25;
  oc_program *p2 = oc_compile(a, &o, &e);
  ck_assert_double_eq(oc_program_threshold(p2), 0.25);
  oc_compile_options bad = {NAN, 0};
  e.code = OC_OK;
  oc_program *p3 = oc_compile(a, &bad, &e);
  ck_assert_ptr_null(p3);
  ck_assert_int_eq(e.code, OC_EINVAL);
  /* The program outlives the caller's reference to the node. */
  oc_node_release(a);
  ck_assert_double_eq(oc_program_eval(p1, oct_v(0, 0, 0)), 1.0);
  oc_aabb b = oc_program_bounds(p1);
  ck_assert(b.lo.x <= -1 && b.hi.z >= 1 && b.hi.z <= 1.5);
  oc_program_free(p1);
  oc_program_free(p2);
}
END_TEST

/* Compiling the same DAG twice gives the same answers, bit for bit. */
START_TEST(compile_is_deterministic) {
  oc_program *a = medium_program(1600), *b = medium_program(1600);
  oc_vec3 *p = random_points(1601, 3000);
  for (int i = 0; i < 3000; i++) {
    double fa = oc_program_eval(a, p[i]), fb = oc_program_eval(b, p[i]);
    ck_assert(memcmp(&fa, &fb, sizeof fa) == 0);
  }
  oc_program_stats sa, sb;
  oc_program_get_stats(a, &sa);
  oc_program_get_stats(b, &sb);
  ck_assert(sa.bytes == sb.bytes && sa.nodes == sb.nodes);
  free(p);
  oc_program_free(a);
  oc_program_free(b);
}
END_TEST

int main(void) {
  Suite *s = suite_create("compile");
  TCase *tc = tcase_create("compile");
  tcase_set_timeout(tc, 120);
  tcase_add_loop_test(tc, bvh_equals_brute_force, 0, 7);
  tcase_add_loop_test(tc, bvh_bounded_queries, 0, 2);
  tcase_add_test(tc, stats_and_memory);
  tcase_add_test(tc, large_point_blend_matches_formula);
  tcase_add_test(tc, eval_many_matches_eval);
  tcase_add_test(tc, concurrent_eval);
  tcase_add_test(tc, nan_input);
  tcase_add_test(tc, compile_options_and_errors);
  tcase_add_test(tc, compile_is_deterministic);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
