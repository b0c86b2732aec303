/*
** test_gen_hoodoos.c — the hoodoo generator (Paris et al. 2019, section 6.3):
** the
** grammar's derivations are words of b+ (c b+)* (c | d) no longer than
** max_depth, stacked and scaled as the productions say; forced words for
** extreme probabilities; every base symbol is sunk into the ground and
** rises above it; placement follows P = probability * slope factor *
** mask (counts against binomial bounds, none where the mask is 0);
** determinism by seed and across thread counts; primitive counts against
** the compiled tree; errors and cancellation.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "gen/hoodoos.h"
#include "ocheck.h"
#include "outcrop.h"

/* A plane z = k x on n x n samples of cell 1 (slope exactly k). */
static oc_heightfield *plane(int n, double k) {
  float *z = malloc((size_t)n * (size_t)n * sizeof *z);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++)
      z[j * n + i] = (float)(k * i);
  oc_heightfield *hf = oc_heightfield_new(n, n, 1, 0, 0, z, NULL);
  free(z);
  ck_assert_ptr_nonnull(hf);
  return hf;
}

/* A bumpy grid: hills with slopes of every steepness. */
static oc_heightfield *hills(int n) {
  oc_heightfield_grid g = {n, n, 1, 0, 0};
  oc_noise nz = {30, 25, 0, 4, 7};
  oc_progress none = {NULL, NULL};
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, none, NULL);
  ck_assert_ptr_nonnull(hf);
  return hf;
}

static oc_node *constant(double v) {
  oc_noise nz = {1, 0, v, 1, 0};
  return oc_turbulence(&nz, NULL);
}

/* ---- the grammar --------------------------------------------------------- */

/* Recognizes b+ (c b+)* (c | d) by its automaton. */
static int in_language(const char *w, int n) {
  int st = 0; /* 0: need b, 1: in a b run, 2: after a final c or d */
  for (int i = 0; i < n; i++) {
    char ch = w[i];
    if (st == 0 && ch == 'b')
      st = 1;
    else if (st == 1 && ch == 'b')
      st = 1;
    else if (st == 1 && ch == 'c')
      st = i + 1 < n ? 0 : 2;
    else if (st == 1 && ch == 'd')
      st = 2;
    else
      return 0;
    if (st == 2 && i + 1 < n) return 0;
  }
  return st == 2;
}

START_TEST(test_language_recognizer) {
  ck_assert(in_language("bd", 2));
  ck_assert(in_language("bbcbc", 5));
  ck_assert(!in_language("bcd", 3));
  ck_assert(!in_language("cb", 2));
  ck_assert(!in_language("bb", 2));
  ck_assert(!in_language("bdb", 3));
}
END_TEST

START_TEST(test_derivations_are_words) {
  oc_hoodoo_symbol out[OC_HOODOO_MAX_DEPTH];
  int seen_cb = 0, seen_c_end = 0, seen_d_end = 0, seen_long = 0;
  const double rhos[] = {0, 0.3, 0.5, 0.8, 1};
  for (int r = 0; r < 5; r++) {
    oc_node *geo = constant(rhos[r]);
    oc_program *gp = oc_compile(geo, NULL, NULL);
    for (int D = 2; D <= 9; D++) {
      oc_hoodoo_grammar g = {D, 0.6, 0.6, 0.8, 2, 0.2, gp};
      for (uint32_t h = 0; h < 300; h++) {
        oc_rng rng = oc_rng_stream(11, h * 16u + (uint32_t)D);
        oc_vec3 base = {1, 2, 3};
        int n = oc_hoodoo_derive(&g, base, 4, h, &rng, out);
        char w[OC_HOODOO_MAX_DEPTH];
        ck_assert_int_ge(n, 2);
        ck_assert_int_le(n, D);
        double z = 3, s = 4, wd = 2;
        for (int k = 0; k < n; k++) {
          w[k] = out[k].kind;
          ck_assert_int_eq(out[k].depth, k);
          ck_assert_uint_eq(out[k].hoodoo, h);
          ck_assert_double_eq_tol(out[k].base.z, z, 1e-12);
          ck_assert_double_eq(out[k].base.x, 1);
          ck_assert_double_eq_tol(out[k].size, s, 1e-12);
          ck_assert_double_eq_tol(out[k].rho, rhos[r], 1e-12);
          ck_assert_double_eq_tol(out[k].width, wd * (0.5 + rhos[r]), 1e-12);
          ck_assert(out[k].tilt >= 0 && out[k].tilt <= 0.2);
          z += s;
          s *= 0.8;
          wd *= 0.8;
        }
        ck_assert_msg(in_language(w, n), "not a word: %.*s", n, w);
        for (int k = 0; k + 1 < n; k++)
          seen_cb += w[k] == 'c' && w[k + 1] == 'b';
        seen_c_end += w[n - 1] == 'c';
        seen_d_end += w[n - 1] == 'd';
        seen_long += n == D && D > 4;
      }
    }
    oc_program_free(gp);
    oc_node_release(geo);
  }
  ck_assert_int_gt(seen_cb, 0);
  ck_assert_int_gt(seen_c_end, 0);
  ck_assert_int_gt(seen_d_end, 0);
  ck_assert_int_gt(seen_long, 0);
}
END_TEST

/* p_B = p_block (0.5 + rho), p_C = p_cone (1.5 - rho): with rho = 0.5,
** p_block = 1 and p_cone = 0 every B continues while the budget allows,
** and every C is a caprock: b^(D-1) d. With p_block = 0: b d. */
START_TEST(test_forced_words) {
  oc_hoodoo_symbol out[OC_HOODOO_MAX_DEPTH];
  for (int D = 2; D <= 12; D++) {
    oc_hoodoo_grammar g = {D, 1, 0, 0.9, 1, 0, NULL};
    oc_rng rng = oc_rng_stream(3, (uint64_t)D);
    int n = oc_hoodoo_derive(&g, oct_v(0, 0, 0), 1, 0, &rng, out);
    ck_assert_int_eq(n, D);
    for (int k = 0; k < D - 1; k++)
      ck_assert_int_eq(out[k].kind, 'b');
    ck_assert_int_eq(out[D - 1].kind, 'd');
    g.p_block = 0;
    n = oc_hoodoo_derive(&g, oct_v(0, 0, 0), 1, 0, &rng, out);
    ck_assert_int_eq(n, 2);
    ck_assert_int_eq(out[0].kind, 'b');
    ck_assert_int_eq(out[1].kind, 'd');
  }
  /* rho = 1 makes p_C = p_cone / 2: with p_cone = 1, C -> d half the
  ** time; over many hoodoos of max_depth 2 (b then c or d), the share of
  ** d is 1/2 (c -> B needs room). */
  oc_node *geo = constant(1);
  oc_program *gp = oc_compile(geo, NULL, NULL);
  oc_hoodoo_grammar g = {2, 1, 1, 0.9, 1, 0, gp};
  int d = 0, N = 4000;
  for (int h = 0; h < N; h++) {
    oc_rng rng = oc_rng_stream(5, (uint64_t)h);
    oc_hoodoo_derive(&g, oct_v(0, 0, 0), 1, 0, &rng, out);
    d += out[1].kind == 'd';
  }
  /* C -> c (1/4) | d (1/2), renormalized without c B: d with 2/3 */
  ck_assert_int_gt(d, (int)(N * 2.0 / 3 - 4 * sqrt(N * 2.0 / 9)));
  ck_assert_int_lt(d, (int)(N * 2.0 / 3 + 4 * sqrt(N * 2.0 / 9)));
  oc_program_free(gp);
  oc_node_release(geo);
}
END_TEST

/* ---- placement ----------------------------------------------------------- */

static size_t count_hoodoos(oc_gen_hoodoos_params *p) {
  oc_hoodoo_symbol *s;
  size_t n;
  oc_gen_hoodoos_stats st;
  oc_error err;
  ck_assert_int_eq(oc_hoodoo_symbols(p, &s, &n, &st, &err), OC_OK);
  size_t bases = 0;
  for (size_t i = 0; i < n; i++)
    bases += s[i].depth == 0;
  ck_assert_uint_eq(bases, st.hoodoos);
  free(s);
  return st.hoodoos;
}

static double left_zero(void *ud, double x, double y) {
  (void)y;
  return x < *(double *)ud ? 0 : 1;
}

START_TEST(test_density_follows_probability) {
  oc_heightfield *hf = plane(101, 0.6);
  oc_gen_hoodoos_params p;
  oc_gen_hoodoos_defaults(&p, hf);
  p.radius = 3;
  p.margin = 2;
  p.seed = 9;
  p.slope = 0.6; /* the plane's: slope factor 1 */
  p.drainage = 1e15;
  size_t all = count_hoodoos(&p);
  ck_assert_uint_gt(all, 500);
  /* P = probability * exp(-((s - slope) / spread)^2) / (1 + A / A0) */
  const struct {
    double prob, slope;
  } cases[] = {{0.3, 0.6}, {1, 0.2}, {0.5, 1.0}};
  for (int c = 0; c < 3; c++) {
    p.probability = cases[c].prob;
    p.slope = cases[c].slope;
    double q = (0.6 - p.slope) / p.slope_spread;
    double P = p.probability * exp(-q * q);
    double m = all * P, sd = sqrt(all * P * (1 - P));
    size_t k = count_hoodoos(&p);
    ck_assert_msg(fabs((double)k - m) < 4 * sd + 1, "%zu kept, %g expected", k,
                  m);
  }
  p.probability = 1;
  p.slope = 0.6;
  /* nothing where the mask is 0 */
  double mid = 50;
  p.mask_fn = left_zero;
  p.mask_ud = &mid;
  oc_hoodoo_symbol *s;
  size_t n;
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &s, &n, NULL, NULL), OC_OK);
  ck_assert_uint_gt(n, 0);
  for (size_t i = 0; i < n; i++)
    if (s[i].depth == 0) ck_assert(s[i].base.x >= mid);
  free(s);
  /* a heightfield mask, 0 on the upper half */
  oc_heightfield *mask = plane(101, 0);
  float *mz = oc_heightfield_samples_mut(mask);
  for (int j = 0; j < 101; j++)
    for (int i = 0; i < 101; i++)
      mz[j * 101 + i] = j <= 60 ? 1.0f : 0.0f;
  p.mask_fn = NULL;
  p.mask = mask;
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &s, &n, NULL, NULL), OC_OK);
  ck_assert_uint_gt(n, 0);
  for (size_t i = 0; i < n; i++)
    if (s[i].depth == 0) ck_assert(s[i].base.y <= 61);
  free(s);
  oc_heightfield_release(mask);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- standing on the ground ---------------------------------------------- */

START_TEST(test_bases_stand_on_terrain) {
  oc_heightfield *hf = hills(81);
  oc_node *geo = constant(0.5);
  oc_gen_hoodoos_params p;
  oc_gen_hoodoos_defaults(&p, hf);
  p.geology = geo;
  p.slope_spread = 10; /* everywhere, the steep parts too */
  p.seed = 4;
  oc_hoodoo_symbol *s;
  size_t n;
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &s, &n, NULL, NULL), OC_OK);
  size_t bases = 0;
  for (size_t i = 0; i < n; i++) {
    if (s[i].depth != 0) continue;
    bases++;
    double x = s[i].base.x, y = s[i].base.y;
    double h = oc_heightfield_height(hf, x, y, NULL);
    oc_node *nd = oc_hoodoo_symbol_node(&s[i], p.roughness, 0, NULL);
    oc_program *pg = oc_compile(nd, NULL, NULL);
    double lo = INFINITY, hi = -INFINITY;
    for (double z = h - 40; z <= h + 60; z += 0.01)
      if (oc_program_eval(pg, oct_v(x, y, z)) > 0.5) {
        if (z < lo) lo = z;
        hi = z;
      }
    ck_assert_msg(lo <= h && hi > h, "hoodoo %zu: solid [%g, %g], ground %g",
                  bases, lo, hi, h);
    oc_program_free(pg);
    oc_node_release(nd);
  }
  ck_assert_uint_gt(bases, 20);
  free(s);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- determinism, counts ------------------------------------------------- */

START_TEST(test_deterministic) {
  oc_heightfield *hf = hills(121);
  oc_node *geo = constant(0.4);
  oc_gen_hoodoos_params p;
  oc_gen_hoodoos_defaults(&p, hf);
  p.geology = geo;
  p.seed = 21;
  oc_hoodoo_symbol *a, *b, *c;
  size_t na, nb, nc;
  omp_set_num_threads(1);
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &a, &na, NULL, NULL), OC_OK);
  omp_set_num_threads(2);
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &b, &nb, NULL, NULL), OC_OK);
  ck_assert_uint_gt(na, 50);
  ck_assert_uint_eq(na, nb);
  ck_assert_int_eq(memcmp(a, b, na * sizeof *a), 0);
  p.seed = 22;
  ck_assert_int_eq(oc_hoodoo_symbols(&p, &c, &nc, NULL, NULL), OC_OK);
  ck_assert(nc != na || memcmp(a, c, na * sizeof *a) != 0);
  free(a);
  free(b);
  free(c);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(test_counts_match_tree) {
  oc_heightfield *hf = hills(101);
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, NULL), OC_OK);
  oc_terrain_params tp = {4, 1, 0, 0, NULL, OC_TERRAIN_SLAB};
  oc_node *ter = oc_terrain(&src, &tp, NULL);
  src.release(src.ud);
  oc_gen_hoodoos_params p;
  oc_gen_hoodoos_defaults(&p, hf);
  p.terrain = ter;
  p.seed = 2;
  oc_gen_hoodoos_stats st;
  oc_error err;
  oc_node *n = oc_generate_hoodoos(&p, &st, &err);
  ck_assert_ptr_nonnull(n);
  ck_assert_uint_gt(st.hoodoos, 10);
  ck_assert_uint_eq(st.blocks + st.cones + st.boxes, st.primitives);
  ck_assert_uint_ge(st.blocks, st.hoodoos); /* every word starts with b */
  ck_assert_uint_eq(oc_node_child_count(n), st.primitives + 1);
  oc_program *pg = oc_compile(n, NULL, NULL);
  oc_program_stats ps;
  oc_program_get_stats(pg, &ps);
  ck_assert_uint_eq(ps.primitives, st.primitives + 1); /* + the terrain */
  /* the blend adds the hoodoos to the ground: above the surface, near a
  ** base, the field exceeds the terrain's */
  oc_program_free(pg);
  oc_node_release(n);
  /* without the terrain: the hoodoos alone */
  p.terrain = NULL;
  p.no_terrain = 1;
  n = oc_generate_hoodoos(&p, &st, &err);
  ck_assert_ptr_nonnull(n);
  ck_assert_uint_eq(oc_node_child_count(n), st.primitives);
  oc_node_release(n);
  /* terrain NULL: the default terrain of the grid comes first, the node
  ** oc_heightfield_terrain makes (the Lua API's default) */
  p.no_terrain = 0;
  n = oc_generate_hoodoos(&p, &st, &err);
  ck_assert_ptr_nonnull(n);
  ck_assert_uint_eq(oc_node_child_count(n), st.primitives + 1);
  oc_node *dt = oc_heightfield_terrain(hf, NULL, &err);
  oc_program *p1 = oc_compile(oc_node_child(n, 0), NULL, NULL);
  oc_program *p2 = oc_compile(dt, NULL, NULL);
  for (int k = 0; k < 20; k++) {
    oc_vec3 q = {3.0 * k, 2.5 * k, -1 + 0.5 * k};
    ck_assert_double_eq(oc_program_eval(p1, q), oc_program_eval(p2, q));
  }
  oc_program_free(p1);
  oc_program_free(p2);
  oc_node_release(dt);
  oc_node_release(n);
  oc_node_release(ter);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- errors ----------------------------------------------------------------
 */

static double bad_mask(void *ud, double x, double y) {
  (void)ud;
  (void)x;
  (void)y;
  return 2;
}

static int cancel_fn(void *ud, double f) {
  (void)ud;
  return f > 0.5;
}

#define EXPECT_ERR(code, word)                                                 \
  do {                                                                         \
    oc_error e = {OC_OK, ""};                                                  \
    oc_hoodoo_symbol *s = (void *)1;                                           \
    size_t n = 7;                                                              \
    ck_assert_int_eq(oc_hoodoo_symbols(&p, &s, &n, NULL, &e), code);           \
    ck_assert_ptr_null(s);                                                     \
    ck_assert_uint_eq(n, 0);                                                   \
    ck_assert_msg(strstr(e.msg, word) != NULL, "message: %s", e.msg);          \
  } while (0)

START_TEST(test_errors) {
  oc_heightfield *hf = hills(41);
  oc_gen_hoodoos_params p, d;
  oc_gen_hoodoos_defaults(&d, hf);
  p = d;
  p.heightfield = NULL;
  EXPECT_ERR(OC_EINVAL, "'heightfield'");
  p = d;
  p.radius = -1;
  EXPECT_ERR(OC_EINVAL, "'radius'");
  p = d;
  p.radius = NAN;
  EXPECT_ERR(OC_EINVAL, "'radius'");
  p = d;
  p.height_lo = 5;
  p.height_hi = 2;
  EXPECT_ERR(OC_EINVAL, "'height'");
  p = d;
  p.max_depth = 1;
  EXPECT_ERR(OC_EINVAL, "'max_depth'");
  p = d;
  p.p_block = 1.5;
  EXPECT_ERR(OC_EINVAL, "'p_block'");
  p = d;
  p.shrink = 0;
  EXPECT_ERR(OC_EINVAL, "'shrink'");
  p = d;
  p.margin = 30;
  EXPECT_ERR(OC_EINVAL, "'margin'");
  p = d;
  p.mask_fn = bad_mask;
  EXPECT_ERR(OC_EINVAL, "'mask'");
  p = d;
  p.radius = 1e-4; /* a maximal set of ~1e11 samples */
  EXPECT_ERR(OC_ENOMEM, "");
  p = d;
  p.progress.fn = cancel_fn;
  EXPECT_ERR(OC_ECANCEL, "");
  p = d;
  p.probability = 0;
  p.no_terrain = 1; /* else the default terrain alone comes back */
  oc_error e;
  ck_assert_ptr_null(oc_generate_hoodoos(&p, NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, "no hoodoo"));
  oc_heightfield_release(hf);
}
END_TEST

int main(void) {
  Suite *s = suite_create("gen_hoodoos");
  TCase *tc = tcase_create("core");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, test_language_recognizer);
  tcase_add_test(tc, test_derivations_are_words);
  tcase_add_test(tc, test_forced_words);
  tcase_add_test(tc, test_density_follows_probability);
  tcase_add_test(tc, test_bases_stand_on_terrain);
  tcase_add_test(tc, test_deterministic);
  tcase_add_test(tc, test_counts_match_tree);
  tcase_add_test(tc, test_errors);
  suite_add_tcase(s, tc);
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
