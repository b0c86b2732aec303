/*
** test_gen_karst.c — karst invasion percolation (oc_karst_cavities,
** oc_generate_karst): every cavity under the surface, inside the domain
** and above the floor, softer than rho0, spaced by the Poisson radius;
** the cavities form a graph connected through overlapping supports and
** rooted at the sinks; the budget holds; carving prefers soft rock;
** determinism by seed and thread count; the node really carves; errors
** and cancellation.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"
#include "outcrop.h"

#define N 129
#define CELL 2.0

/* A plateau (z 100) on a plain (z 20) with a few dimples on its top: the
** dimples' centres are the grid's only pits. */
static const double dimples[4][2] = {
    {100, 100}, {150, 120}, {110, 160}, {140, 80}};

static double plateau_z(double x, double y) {
  double r = sqrt((x - 128) * (x - 128) + (y - 128) * (y - 128));
  double t = fmin(1, fmax(0, (r - 70) / 30));
  double z = 20 + 80 * (1 - t * t * (3 - 2 * t));
  for (int k = 0; k < 4; k++) {
    double dx = x - dimples[k][0], dy = y - dimples[k][1];
    z -= 3 * exp(-(dx * dx + dy * dy) / 50);
  }
  return z;
}

static oc_heightfield *plateau(void) {
  static float z[N * N];
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++)
      z[j * N + i] = (float)plateau_z(i * CELL, j * CELL);
  oc_heightfield *hf = oc_heightfield_new(N, N, CELL, 0, 0, z, NULL);
  ck_assert_ptr_nonnull(hf);
  return hf;
}

/* Hard rock (0.7 .. 0.9) with a soft bed around z = 94, just under the
** plateau's top: rho < 0.5 where |z - 94| < about 6.5. */
static oc_node *strata(void) {
  oc_noise nz = {10, 0.2, 0.7, 3, 11};
  return OCT_OK(
      oc_geology_layer(oct_v(0, 0, 94), oct_v(0, 0, 1), 10, -0.6, &nz, NULL));
}

static oc_gen_karst_params params(oc_heightfield *hf, oc_node *geo) {
  oc_gen_karst_params p;
  oc_gen_karst_defaults(&p);
  p.heightfield = hf;
  p.geology = geo;
  p.radius = 4;
  p.max_primitives = 3000;
  p.seed = 7;
  return p;
}

static oc_karst_cavity *run(const oc_gen_karst_params *p, size_t *n,
                            oc_gen_karst_stats *st) {
  oc_error err = {OC_OK, ""};
  oc_karst_cavity *c = NULL;
  int rc = oc_karst_cavities(p, &c, n, st, &err);
  ck_assert_msg(rc == OC_OK, "karst failed: %s", err.msg);
  return c;
}

static double d3(oc_vec3 a, oc_vec3 b) {
  return oct_len(oct_sub(a, b));
}

START_TEST(invariants) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_node_retain(geo); /* oct_compile releases one reference */
  oc_program *gp = oct_compile(geo, 0.5, 0);
  oc_gen_karst_params p = params(hf, geo);
  oc_gen_karst_stats st;
  size_t n;
  oc_karst_cavity *c = run(&p, &n, &st);
  ck_assert_uint_eq(st.sinks,
                    4); /* the dimples, found by oc_heightfield_sinks */
  ck_assert_uint_gt(n, 200);
  ck_assert_uint_le(n, p.max_primitives);
  ck_assert_uint_eq(st.primitives, n);
  double cover = p.radius / 4, floor = 20 + p.radius;
  size_t roots = 0;
  for (size_t i = 0; i < n; i++) {
    oc_vec3 q = c[i].center;
    double h = oc_heightfield_height(hf, q.x, q.y, NULL);
    ck_assert_msg(q.z <= h - cover + 1e-9, "cavity %zu above the surface", i);
    ck_assert(q.z >= floor);
    ck_assert(q.x >= 4 && q.x <= 252 && q.y >= 4 && q.y <= 252);
    double v = oc_program_eval(gp, q);
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    ck_assert_double_eq_tol(c[i].rho, v, 1e-12);
    ck_assert(c[i].rho < p.rho0);
    ck_assert_double_eq_tol(c[i].energy, -1.5 * (0.5 + 0.5 * (1 - c[i].rho)),
                            1e-12);
    ck_assert_double_eq(c[i].radius, 4);
    if (c[i].parent < 0) {
      roots++;
      /* a root is a dimple, lowered under the cover if needed */
      int found = 0;
      for (int k = 0; k < 4; k++)
        found |= fabs(q.x - dimples[k][0]) < 1e-9 &&
                 fabs(q.y - dimples[k][1]) < 1e-9;
      ck_assert(found);
    } else {
      ck_assert_int_lt(c[i].parent, (int64_t)i);
      ck_assert_double_eq_tol(d3(q, c[c[i].parent].center), p.radius, 1e-9);
      /* lower hemisphere */
      ck_assert(q.z <= c[c[i].parent].center.z + 1e-12);
    }
    for (size_t j = 0; j < i; j++)
      ck_assert_msg(d3(q, c[j].center) >= p.radius / 2 - 1e-9,
                    "cavities %zu and %zu closer than the spacing", i, j);
  }
  ck_assert_uint_ge(roots, 1);
  /* Connected through overlapping supports (|a - b| < 2R), rooted at the
  ** sinks: a search that ignores the parent links. */
  char *seen = calloc(n, 1);
  size_t *stack = malloc(n * sizeof *stack), top = 0, reached = 0;
  for (size_t i = 0; i < n; i++)
    if (c[i].parent < 0) seen[i] = 1, stack[top++] = i;
  while (top) {
    size_t i = stack[--top];
    reached++;
    for (size_t j = 0; j < n; j++)
      if (!seen[j] && d3(c[i].center, c[j].center) < 2 * p.radius)
        seen[j] = 1, stack[top++] = j;
  }
  ck_assert_uint_eq(reached, n);
  free(seen);
  free(stack);
  free(c);
  oc_program_free(gp);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

/* Carving prefers soft rock: the mean rho at the cavities is well below
** the mean over the rock under the plateau. */
START_TEST(prefers_soft_strata) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_node_retain(geo); /* oct_compile releases one reference */
  oc_program *gp = oct_compile(geo, 0.5, 0);
  oc_gen_karst_params p = params(hf, geo);
  size_t n;
  oc_karst_cavity *c = run(&p, &n, NULL);
  double sc = 0;
  for (size_t i = 0; i < n; i++)
    sc += c[i].rho;
  sc /= n;
  double sv = 0;
  int m = 0;
  oct_rng r = oct_rng_new(3);
  while (m < 20000) {
    oc_vec3 q =
        oct_in_box(&r, oct_v(60, 60, 20 + p.radius), oct_v(196, 196, 100));
    if (q.z > oc_heightfield_height(hf, q.x, q.y, NULL)) continue;
    double v = oc_program_eval(gp, q);
    sv += v < 0 ? 0 : v > 1 ? 1 : v;
    m++;
  }
  sv /= m;
  ck_assert_msg(sc < sv - 0.1, "mean rho at cavities %g, in the rock %g", sc,
                sv);
  free(c);
  oc_program_free(gp);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(budget_and_given_sinks) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_gen_karst_params p = params(hf, geo);
  oc_vec3 s = {128, 128, 95}; /* in the soft bed, kept as given */
  p.sinks = &s;
  p.nsinks = 1;
  size_t n, n2;
  oc_karst_cavity *c = run(&p, &n, NULL);
  ck_assert_uint_gt(n, 60);
  ck_assert_int_eq(c[0].parent, -1);
  ck_assert_double_eq(c[0].center.z, 95);
  for (size_t i = 1; i < n; i++)
    ck_assert_int_ge(c[i].parent, 0);
  /* a budget cuts the same run short: a prefix of it */
  p.max_primitives = 50;
  oc_karst_cavity *c2 = run(&p, &n2, NULL);
  ck_assert_uint_eq(n2, 50);
  ck_assert_mem_eq(c2, c, 50 * sizeof *c);
  free(c);
  free(c2);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(deterministic) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_gen_karst_params p = params(hf, geo);
  size_t n1, n2, n3;
  omp_set_num_threads(1);
  oc_karst_cavity *a = run(&p, &n1, NULL);
  omp_set_num_threads(2);
  oc_karst_cavity *b = run(&p, &n2, NULL);
  ck_assert_uint_eq(n1, n2);
  ck_assert_mem_eq(a, b, n1 * sizeof *a);
  p.seed = 8;
  oc_karst_cavity *c = run(&p, &n3, NULL);
  size_t same = 0, m = n1 < n3 ? n1 : n3;
  for (size_t i = 0; i < m; i++)
    same += memcmp(&a[i], &c[i], sizeof *a) == 0;
  ck_assert_msg(same < m / 2, "seeds 7 and 8 share %zu of %zu cavities", same,
                m);
  /* the default geology depends on the seed too */
  p.geology = NULL;
  p.seed = 7;
  oc_karst_cavity *d = run(&p, &n3, NULL);
  free(d);
  free(a);
  free(b);
  free(c);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

/* The node: the terrain and one point per cavity; each cavity's centre
** is outside (f < T), since its own energy is <= -1.125 against a terrain
** of at most 2T = 1. */
START_TEST(node_carves) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_gen_karst_params p = params(hf, geo);
  p.max_primitives = 400;
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, NULL), OC_OK);
  oc_terrain_params tp = {8, 1, 0, 0, NULL, OC_TERRAIN_SLAB};
  oc_node *terr = OCT_OK(oc_terrain(&src, &tp, NULL));
  src.release(src.ud);
  p.terrain = terr;
  oc_gen_karst_stats st;
  oc_node *k = OCT_OK(oc_generate_karst(&p, &st, NULL));
  ck_assert_str_eq(oc_node_kind(k), "blend");
  ck_assert_uint_eq(oc_node_child_count(k), st.primitives + 1);
  ck_assert_ptr_eq(oc_node_child(k, 0), terr);
  size_t n;
  oc_karst_cavity *c = run(&p, &n, NULL);
  ck_assert_uint_eq(n, st.primitives);
  oc_node_retain(k);
  oc_node_retain(terr);
  oc_program *pr = oct_compile(k, 0.5, 0);
  oc_program *pt = oct_compile(terr, 0.5, 0);
  for (size_t i = 0; i < n; i++) {
    ck_assert(oc_program_eval(pr, c[i].center) < 0.5);
    /* far above the network, the terrain alone */
  }
  oc_vec3 q = {128, 128, 150};
  ck_assert_double_eq(oc_program_eval(pr, q), oc_program_eval(pt, q));
  /* the cavities alone: a blend of points */
  p.terrain = NULL;
  p.no_terrain = 1;
  oc_node *k2 = OCT_OK(oc_generate_karst(&p, NULL, NULL));
  ck_assert_uint_eq(oc_node_child_count(k2), n);
  ck_assert_str_eq(oc_node_kind(oc_node_child(k2, 0)), "point");
  oc_node_release(k2);
  /* terrain NULL without no_terrain: the grid's default terrain first */
  p.no_terrain = 0;
  oc_node *k3 = OCT_OK(oc_generate_karst(&p, NULL, NULL));
  ck_assert_uint_eq(oc_node_child_count(k3), n + 1);
  ck_assert_str_eq(oc_node_kind(oc_node_child(k3, 0)), oc_node_kind(terr));
  ck_assert_str_eq(oc_node_kind(oc_node_child(k3, 1)), "point");
  oc_node_release(k3);
  free(c);
  oc_program_free(pr);
  oc_program_free(pt);
  oc_node_release(k);
  oc_node_release(terr);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

static void einval(oc_gen_karst_params p, const char *param) {
  oc_error err = {OC_OK, ""};
  oc_karst_cavity *c = (void *)1;
  size_t n = 99;
  ck_assert_int_eq(oc_karst_cavities(&p, &c, &n, NULL, &err), OC_EINVAL);
  ck_assert_int_eq(err.code, OC_EINVAL);
  ck_assert_msg(strstr(err.msg, param) != NULL, "'%s' not in: %s", param,
                err.msg);
  ck_assert_ptr_null(c);
  ck_assert_uint_eq(n, 0);
  ck_assert_ptr_null(oc_generate_karst(&p, NULL, &err));
}

START_TEST(errors) {
  oc_heightfield *hf = plateau();
  oc_gen_karst_params p = params(hf, NULL), q;
  q = p, q.heightfield = NULL, einval(q, "'heightfield'");
  q = p, q.radius = -1, einval(q, "'radius'");
  q = p, q.radius = NAN, einval(q, "'radius'");
  q = p, q.radius = 1e6, einval(q, "'radius'");
  q = p, q.step = INFINITY, einval(q, "'step'");
  q = p, q.spacing = 1e-12, einval(q, "'spacing'");
  q = p, q.cover = -1, einval(q, "'cover'");
  q = p, q.floor = -1e300, einval(q, "'floor'");
  q = p, q.epsilon = NAN, einval(q, "'epsilon'");
  q = p, q.rho0 = 0, einval(q, "'rho0'");
  q = p, q.energy = 0, einval(q, "'energy'");
  q = p, q.beta = 2, einval(q, "'beta'");
  q = p, q.branches = 0, einval(q, "'branches'");
  q = p, q.branches = 65, einval(q, "'branches'");
  q = p, q.max_primitives = 0, einval(q, "'max_primitives'");
  q = p, q.max_primitives = OC_KARST_MAX + 1, einval(q, "'max_primitives'");
  oc_vec3 s[2] = {{128, 128, 50}, {-10, 128, 50}};
  q = p, q.sinks = s, q.nsinks = 2, einval(q, "'sinks'[2]");
  s[1] = (oc_vec3){128, NAN, 0};
  q = p, q.sinks = s, q.nsinks = 2, einval(q, "'sinks'[2]");
  /* nothing carved and no terrain: an error, not an empty blend */
  q = p, q.rho0 = 1e-9, q.epsilon = 0, q.no_terrain = 1;
  oc_error err = {OC_OK, ""};
  ck_assert_ptr_null(oc_generate_karst(&q, NULL, &err));
  ck_assert_int_eq(err.code, OC_EINVAL);
  oc_heightfield_release(hf);
}
END_TEST

static int cancel_at(void *ud, double f) {
  int *calls = ud;
  ck_assert(f >= 0 && f <= 1);
  return ++*calls >= 1;
}

START_TEST(cancel) {
  oc_heightfield *hf = plateau();
  oc_node *geo = strata();
  oc_gen_karst_params p = params(hf, geo);
  int calls = 0;
  p.progress = (oc_progress){cancel_at, &calls};
  p.max_primitives = 100000;
  p.radius = 2;
  oc_error err = {OC_OK, ""};
  oc_karst_cavity *c = NULL;
  size_t n = 5;
  ck_assert_int_eq(oc_karst_cavities(&p, &c, &n, NULL, &err), OC_ECANCEL);
  ck_assert_ptr_null(c);
  ck_assert_uint_eq(n, 0);
  ck_assert_int_eq(calls, 1);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

int main(void) {
  Suite *s = suite_create("gen_karst");
  TCase *tc = tcase_create("karst");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, invariants);
  tcase_add_test(tc, prefers_soft_strata);
  tcase_add_test(tc, budget_and_given_sinks);
  tcase_add_test(tc, deterministic);
  tcase_add_test(tc, node_carves);
  tcase_add_test(tc, errors);
  tcase_add_test(tc, cancel);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
