/*
** test_query.c — local queries: column spans (surface bounds) and
** Lipschitz bounds restricted to a box.
**
** Spans are checked by their contract: between spans the field is constant
** over the whole footprint, so many random points of a gap must all give
** the same value. Local Lipschitz bounds must never be exceeded by point
** pairs inside their box and never exceed the global bound.
*/
#include <stdlib.h>

#include "field/bvhwalk.h"
#include "field/hfsurf.h"
#include "field/query.h"
#include "field/raybound.h"
#include "ocheck.h"

/* A terrain-like scene: a ground plane (optionally tilted), carved and
** raised primitives, a transformed instance and a warped one. */
static oc_program *scene(int tilted, int with_warp) {
  oct_rng r = oct_rng_new(7);
  oc_error err;
  enum { N = 300 };
  oc_node *k[N + 4];
  size_t n = 0;
  oc_vec3 nrm = tilted ? oct_v(0.2, -0.1, 1) : oct_v(0, 0, 1);
  k[n++] = OCT_OK(oc_plane(oct_v(0, 0, 0), nrm, 3, 1, &err));
  for (int i = 0; i < N; i++)
    k[n++] =
        oct_random_prim(&r, oct_v(0, 0, -8), oct_v(200, 200, 8), 1, 6, 0.5);
  oc_node *rock = OCT_OK(oc_sphere(oct_v(0, 0, 0), 3, 2, 1, &err));
  double m[12] = {2, 0, 0, 50, 0, 2, 0, 60, 0, 0, 1.5, 10};
  k[n++] = OCT_OK(oc_transform(rock, m, &err));
  if (with_warp) {
    oc_noise nz = {8, 2, 0, 2, 5};
    k[n++] = OCT_OK(oc_warp(rock, &nz, NULL, &err));
  }
  oc_node_release(rock);
  oc_node *b = OCT_OK(oc_blend(k, n, &err));
  for (size_t i = 0; i < n; i++)
    oc_node_release(k[i]);
  return oct_compile(b, 0, 0);
}

static void check_gaps(const oc_program *pr, oct_rng *r, double x0, double y0,
                       double x1, double y1) {
  oc_zspan s[8];
  int n = oc_program_column_spans(pr, x0, y0, x1, y1, s, 8);
  if (n < 0) return;
  ck_assert_int_le(n, 8);
  for (int i = 0; i + 1 < n; i++)
    ck_assert(s[i].hi < s[i + 1].lo);
  /* gaps: below the first, between, above the last (bounded for sampling) */
  for (int g = 0; g <= n; g++) {
    double lo = g == 0 ? -60 : s[g - 1].hi, hi = g == n ? 60 : s[g].lo;
    if (g == 0 && n > 0) lo = fmin(lo, s[0].lo - 10);
    if (g == n && n > 0) hi = fmax(hi, s[n - 1].hi + 10);
    if (!(hi > lo)) continue;
    double ref = NAN;
    for (int t = 0; t < 40; t++) {
      oc_vec3 p =
          oct_v(oct_unif(r, x0, x1), oct_unif(r, y0, y1), oct_unif(r, lo, hi));
      if (p.z <= lo || p.z >= hi) continue;
      double v = oc_program_eval(pr, p);
      if (isnan(ref))
        ref = v;
      else
        ck_assert_msg(
            fabs(v - ref) <= 1e-12,
            "field varies in a gap (%g, %g) of column [%g,%g]x[%g,%g]:"
            " %.17g vs %.17g at z %g",
            lo, hi, x0, x1, y0, y1, v, ref, p.z);
    }
  }
}

START_TEST(spans_cover_variation) {
  for (int tilted = 0; tilted < 2; tilted++) {
    oc_program *pr = scene(tilted, 1);
    oct_rng r = oct_rng_new(11 + tilted);
    int bounded = 0;
    for (int c = 0; c < 400; c++) {
      double x = oct_unif(&r, -20, 220), y = oct_unif(&r, -20, 220);
      double w = oct_unif(&r, 0.1, 6);
      oc_zspan s[8];
      if (oc_program_column_spans(pr, x, y, x + w, y + w, s, 8) >= 0) bounded++;
      check_gaps(pr, &r, x, y, x + w, y + w);
    }
    /* the point of spans: most columns are bounded */
    ck_assert_int_gt(bounded, 300);
    oc_program_free(pr);
  }
}
END_TEST

/* Curves, plain and perturbed (an arch): spans per chunk of segments keep
** the contract, and a column under the arch's top spans the top only, not
** the legs. */
START_TEST(spans_of_curves_follow_them) {
  oc_error err;
  oc_vec3 spine[4] = {{-20, 0, -2}, {-22, 0, 28}, {22, 0, 28}, {20, 0, -2}};
  oc_vec3 zig[5] = {
      {0, -30, 0}, {10, -25, 12}, {20, -30, 0}, {30, -25, 9}, {40, -30, 1}};
  oc_noise nz = {6, 1.5, 0, 3, 9};
  oc_node *arch = OCT_OK(oc_curve(spine, 4, 1, 6, 1, &err));
  oc_node *k[2] = {OCT_OK(oc_perturb(arch, &nz, &err)),
                   OCT_OK(oc_curve(zig, 5, 0, 2, 1, &err))};
  oc_node_release(arch);
  oc_node *b = OCT_OK(oc_blend(k, 2, &err));
  oc_node_release(k[0]);
  oc_node_release(k[1]);
  oc_program *pr = oct_compile(b, 0, 0);
  oct_rng r = oct_rng_new(19);
  for (int c = 0; c < 300; c++) {
    double x = oct_unif(&r, -35, 45), y = oct_unif(&r, -40, 12);
    double w = oct_unif(&r, 0.2, 4);
    check_gaps(pr, &r, x, y, x + w, y + w);
  }
  /* above the middle of the arch: its top is near z = 20.5 */
  oc_zspan s[8];
  int n = oc_program_column_spans(pr, -1, -1, 1, 1, s, 8);
  ck_assert_int_ge(n, 1);
  ck_assert_msg(s[0].lo > 0, "arch top column spans from %g", s[0].lo);
  oc_program_free(pr);
}
END_TEST

/* Spans along columns (what the mesher evaluates one by one): outside
** them the field is constant along every column of the footprint, they
** lie within the spans, and near a terrain's walls, where the field
** varies across the footprint at every height, they keep only the floor
** and the surface. */
START_TEST(column_z_spans) {
  enum { N = 41 };
  float *z = malloc(N * N * sizeof *z);
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++)
      z[j * N + i] = (float)(4 * sin(0.3 * i) * cos(0.2 * j));
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(N, N, 1, 0, 0, z, &e);
  free(z);
  ck_assert(hf != NULL);
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {4, 1, 0, 0, NULL, OC_TERRAIN_SLAB};
  oc_node *k[3];
  k[0] = OCT_OK(oc_terrain(&src, &tp, &e));
  tp.invert = 1;
  tp.thickness = 10;
  k[1] = OCT_OK(oc_terrain(&src, &tp, &e)); /* ground above: a roof */
  src.release(src.ud);
  k[2] = OCT_OK(oc_sphere(oct_v(20, 20, 0), 3, 2, -1, &e));
  oc_node *b = OCT_OK(oc_blend(k, 3, &e));
  for (int i = 0; i < 3; i++)
    oc_node_release(k[i]);
  oc_program *pr = oct_compile(b, 0, 0);
  oct_rng r = oct_rng_new(23);
  int tighter = 0;
  for (int c = 0; c < 300; c++) {
    double x = oct_unif(&r, -3, 43), y = oct_unif(&r, -3, 43);
    double w = oct_unif(&r, 0.2, 3);
    oc_zspan s[8], zs[8];
    int nz;
    int n =
        oc_program_column_query_z(pr, x, y, x + w, y + w, s, 8, NULL, zs, &nz);
    if (n < 0) {
      ck_assert_int_lt(nz, 0);
      continue;
    }
    ck_assert_int_ge(nz, 0);
    double zlen = 0, slen = 0;
    for (int q = 0; q < nz; q++) {
      int in = 0;
      for (int p = 0; p < n; p++)
        in |= zs[q].lo >= s[p].lo && zs[q].hi <= s[p].hi;
      ck_assert_msg(in, "z-span %g..%g outside the spans", zs[q].lo, zs[q].hi);
      zlen += zs[q].hi - zs[q].lo;
    }
    for (int p = 0; p < n; p++)
      slen += s[p].hi - s[p].lo;
    tighter += zlen < 0.5 * slen;
    /* gaps of zs: f constant along each column */
    for (int g = 0; g <= nz; g++) {
      double lo = g == 0 ? -40 : zs[g - 1].hi, hi = g == nz ? 40 : zs[g].lo;
      if (!(hi > lo)) continue;
      for (int t = 0; t < 6; t++) {
        double px = oct_unif(&r, x, x + w), py = oct_unif(&r, y, y + w);
        double za = oct_unif(&r, lo, hi), zb = oct_unif(&r, lo, hi);
        if (za <= lo || za >= hi || zb <= lo || zb >= hi) continue;
        double fa = oc_program_eval(pr, oct_v(px, py, za));
        double fb = oc_program_eval(pr, oct_v(px, py, zb));
        ck_assert_msg(fabs(fa - fb) <= 1e-12,
                      "varies along the column at %g %g in gap %g..%g: "
                      "%.17g at %g, %.17g at %g",
                      px, py, lo, hi, fa, za, fb, zb);
      }
    }
  }
  ck_assert_int_gt(tighter, 10); /* the walls' columns */
  oc_program_free(pr);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(spans_of_plane_are_thin) {
  oc_error err;
  oc_node *pl = OCT_OK(oc_plane(oct_v(0, 0, 5), oct_v(0, 0, 1), 2, 1, &err));
  oc_program *pr = oct_compile(pl, 0, 0);
  oc_zspan s[4];
  int n = oc_program_column_spans(pr, 0, 0, 10, 10, s, 4);
  ck_assert_int_eq(n, 1);
  ck_assert(s[0].lo <= 5 && s[0].lo > 4.99);
  ck_assert(s[0].hi >= 7 && s[0].hi < 7.01);
  oc_program_free(pr);
  /* a vertical plane varies at every z */
  pl = OCT_OK(oc_plane(oct_v(3, 0, 0), oct_v(1, 0, 0), 2, 1, &err));
  pr = oct_compile(pl, 0, 0);
  ck_assert_int_eq(oc_program_column_spans(pr, 0, 0, 10, 10, s, 4), -1);
  /* but not in a column away from its slab */
  ck_assert_int_eq(oc_program_column_spans(pr, 20, 0, 30, 10, s, 4), 0);
  oc_program_free(pr);
}
END_TEST

START_TEST(spans_merge_to_max) {
  oc_error err;
  oc_node *k[10];
  for (int i = 0; i < 10; i++)
    k[i] = OCT_OK(oc_point(oct_v(0, 0, 10.0 * i), 1, 1, &err));
  oc_node *b = OCT_OK(oc_blend(k, 10, &err));
  for (int i = 0; i < 10; i++)
    oc_node_release(k[i]);
  oc_program *pr = oct_compile(b, 0, 0);
  oc_zspan s[10];
  ck_assert_int_eq(oc_program_column_spans(pr, -0.5, -0.5, 0.5, 0.5, s, 10),
                   10);
  oc_zspan t[3];
  ck_assert_int_eq(oc_program_column_spans(pr, -0.5, -0.5, 0.5, 0.5, t, 3), 3);
  ck_assert(t[0].lo <= s[0].lo && t[2].hi >= s[9].hi);
  ck_assert_int_eq(oc_program_column_spans(pr, 5, 5, 6, 6, t, 3), 0);
  oc_program_free(pr);
}
END_TEST

START_TEST(local_lipschitz_holds) {
  oc_program *pr = scene(1, 1);
  oct_rng r = oct_rng_new(3);
  double L = oc_program_lipschitz(pr);
  int smaller = 0;
  for (int b = 0; b < 300; b++) {
    oc_vec3 lo = oct_v(oct_unif(&r, -10, 200), oct_unif(&r, -10, 200),
                       oct_unif(&r, -15, 15));
    double w = oct_unif(&r, 0.5, 12);
    oc_aabb box = {lo, oct_add(lo, oct_v(w, w, w))};
    double Lb = oc_program_lipschitz_in(pr, box);
    ck_assert(Lb <= L * (1 + 1e-12));
    if (Lb < 0.5 * L) smaller++;
    for (int t = 0; t < 200; t++) {
      oc_vec3 p = oct_in_box(&r, box.lo, box.hi);
      oc_vec3 q = t % 2 ? oct_in_box(&r, box.lo, box.hi)
                        : oct_add(p, oct_mul(oct_dir(&r), w * 1e-4));
      if (!oct_box_contains(box, q)) continue;
      double d = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q));
      ck_assert_msg(d <= Lb * oct_len(oct_sub(p, q)) * (1 + 1e-9) + 1e-14,
                    "local bound %g exceeded: %g over %g", Lb, d,
                    oct_len(oct_sub(p, q)));
    }
  }
  ck_assert_int_gt(smaller, 100); /* local bounds are worth having */
  oc_program_free(pr);
}
END_TEST

START_TEST(local_lipschitz_zero_far_away) {
  oc_error err;
  oc_node *p = OCT_OK(oc_point(oct_v(0, 0, 0), 2, 1, &err));
  oc_program *pr = oct_compile(p, 0, 0);
  oc_aabb far = {oct_v(10, 10, 10), oct_v(11, 11, 11)};
  ck_assert(oc_program_lipschitz_in(pr, far) == 0);
  oc_aabb near = {oct_v(-1, -1, -1), oct_v(1, 1, 1)};
  ck_assert(oc_program_lipschitz_in(pr, near) == oc_program_lipschitz(pr));
  oc_program_free(pr);
}
END_TEST

/* A blend of inline points under a hand-built BVH skewed to the left, d
** interior nodes deep: every node's box holds every query, each right
** child is a leaf with a far point, and the deepest leaf holds the one
** point that matters (at the origin, radius 1, energy 1). A walk stacks
** one right sibling per level, so past OC_BVH_STACK levels the deepest
** leaf is out of reach; compile.c never builds such a tree (bvh.c's are
** at most 30 levels deep). */
#define DEEP_LIP 1.75 /* the op's global bound (>= OCT_LG) */

static oc_program *deep_bvh(int d) {
  oc_program *P = calloc(1, sizeof *P);
  ck_assert(P != NULL);
  P->nops = 1;
  P->ops = calloc(1, sizeof *P->ops);
  P->npar = 1;
  P->par = calloc(1, sizeof *P->par);
  P->nent = (size_t)d + 1;
  P->ent = calloc(P->nent, sizeof *P->ent);
  P->nbvh = 2 * (size_t)d + 1;
  P->bvh = calloc(P->nbvh, sizeof *P->bvh);
  ck_assert(P->ops && P->par && P->ent && P->bvh);
  for (size_t i = 0; i < P->nent; i++) {
    oc_ent *e = &P->ent[i];
    e->c[0] = i < (size_t)d ? 1000.0f + 10.0f * (float)i : 0;
    e->ir2 = 1;
    e->e = 1;
    e->ref = OC_NONE;
  }
  for (size_t i = 0; i < P->nbvh; i++)
    for (int a = 0; a < 3; a++) {
      P->bvh[i].lo[a] = -2000;
      P->bvh[i].hi[a] = 2000;
    }
  /* interior node k at index 0 (k = 0) or 2k - 1; its children at 2k + 1
  ** (the next interior node, or the deepest leaf) and 2k + 2 (a leaf) */
  for (int k = 0; k < d; k++) {
    oc_bvhnode *nd = &P->bvh[k ? 2 * k - 1 : 0];
    nd->first = 2 * (uint32_t)k + 1;
    nd->count = 0;
    P->bvh[2 * k + 2].first = (uint32_t)k;
    P->bvh[2 * k + 2].count = 1;
  }
  P->bvh[2 * d - 1].first = (uint32_t)d;
  P->bvh[2 * d - 1].count = 1;
  oc_op *o = &P->ops[0];
  o->kind = OC_K_BLEND;
  o->nent = (uint32_t)P->nent;
  o->ntotal = o->nent;
  o->bvh = 0;
  o->lip = DEEP_LIP;
  for (int a = 0; a < 3; a++) {
    o->lo[a] = -2000;
    o->hi[a] = 2000;
  }
  P->T = 0.5;
  P->lip = DEEP_LIP;
  P->bounds = (oc_aabb){oct_v(-2000, -2000, -2000), oct_v(2000, 2000, 2000)};
  return P;
}

static void deep_free(oc_program *P) {
  free(P->ops);
  free(P->par);
  free(P->ent);
  free(P->bvh);
  free(P);
}

/* Within the stack, the walks reach the deepest leaf: exact answers. */
START_TEST(bvh_walk_reaches_deep_leaf) {
  oc_program *P = deep_bvh(OC_BVH_STACK - 1);
  oc_aabb near = {oct_v(-0.5, -0.5, -0.5), oct_v(0.5, 0.5, 0.5)};
  ck_assert_double_eq_tol(oc_program_eval(P, oct_v(0, 0, 0)), 1, 1e-12);
  double l = oc_program_lipschitz_in(P, near);
  ck_assert_msg(l >= OCT_LG && l < DEEP_LIP, "local bound %g", l);
  oc_zspan s[4];
  int n = oc_program_column_spans(P, -0.5, -0.5, 0.5, 0.5, s, 4);
  ck_assert_int_eq(n, 1);
  ck_assert(s[0].lo <= -0.8 && s[0].hi >= 0.8 && s[0].hi < 1.1);
  deep_free(P);
}
END_TEST

/* Past the stack, every query answers its conservative bound instead of
** dropping the subtree it cannot reach. */
START_TEST(bvh_full_stack_is_conservative) {
  oc_program *P = deep_bvh(OC_BVH_STACK + 16);
  oc_aabb near = {oct_v(-0.5, -0.5, -0.5), oct_v(0.5, 0.5, 0.5)};
  ck_assert_double_eq(oc_program_lipschitz_in(P, near), DEEP_LIP);
  ck_assert_int_eq(oc_op_zero_in(P, 0, &near), 0);
  oc_zspan s[4];
  ck_assert_int_eq(oc_program_column_spans(P, -0.5, -0.5, 0.5, 0.5, s, 4), -1);
  /* along x through the point, whose derivative reaches +-OCT_LG */
  oc_ray r = oc_ray_make(oct_v(-5, 0, 0), oct_v(1, 0, 0));
  double lo, hi;
  oc_ray_dbound(P, &r, 0, 10, &lo, &hi);
  ck_assert_msg(lo <= -OCT_LG && hi >= OCT_LG, "derivative in [%g, %g]", lo,
                hi);
  int m = oc_ray_supports(P, &r, 0, 10, s, 4);
  int covered = 0;
  for (int k = 0; k < m; k++)
    covered |= s[k].lo <= 4 && s[k].hi >= 6;
  ck_assert_msg(covered, "the point's chord [4, 6] is not covered");
  deep_free(P);
}
END_TEST

int main(void) {
  Suite *s = suite_create("query");
  TCase *tc = tcase_create("query");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, spans_cover_variation);
  tcase_add_test(tc, spans_of_curves_follow_them);
  tcase_add_test(tc, column_z_spans);
  tcase_add_test(tc, spans_of_plane_are_thin);
  tcase_add_test(tc, spans_merge_to_max);
  tcase_add_test(tc, local_lipschitz_holds);
  tcase_add_test(tc, local_lipschitz_zero_far_away);
  tcase_add_test(tc, bvh_walk_reaches_deep_leaf);
  tcase_add_test(tc, bvh_full_stack_is_conservative);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
