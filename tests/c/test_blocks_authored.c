/*
** test_blocks_authored.c — authored blocks in a fracture tile (points
** inside removed, edges across cut, generated blocks kept out, the
** authored block itself a block with its own planes), the prismatic and
** columnar types (blocks convex and disjoint, columns taller than wide),
** and the errors naming the field. Small tiles (10 m, r = 0.5) keep it
** cheap.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"
#include "outcrop.h"

#ifdef __SANITIZE_ADDRESS__
#define SAMPLES 2000
#else
#define SAMPLES 8000
#endif

static void small(oc_block_type type, oc_btile_params *pp) {
  oc_btile_defaults(type, pp);
  pp->size = 10;
  pp->radius = 0.5;
  pp->disc_lo *= 0.5;
  pp->disc_hi *= 0.5;
  pp->spacing *= 0.5;
  pp->seed = 9;
}

static oc_btile *make(const oc_btile_params *pp) {
  oc_error e = {0};
  oc_btile *t = oc_btile_new(pp, &e);
  ck_assert_msg(t != NULL, "oc_btile_new: %s", e.msg);
  return t;
}

/* The box of block i's hull vertices. */
static void vbox(const oc_btile *t, size_t i, double *lo, double *hi) {
  size_t nv;
  const double *v = oc_btile_vertices(t, i, &nv);
  for (int a = 0; a < 3; a++)
    lo[a] = INFINITY, hi[a] = -INFINITY;
  for (size_t k = 0; k < nv; k++)
    for (int a = 0; a < 3; a++) {
      lo[a] = fmin(lo[a], v[3 * k + a]);
      hi[a] = fmax(hi[a], v[3 * k + a]);
    }
}

/* How many blocks of t (periodic images included) hold p deeper than
** tol; the last one found in *which. */
static int holders(const oc_btile *t, size_t nb, const double *p, double tol,
                   size_t *which) {
  int n = 0;
  for (size_t i = 0; i < nb; i++) {
    size_t np;
    const double *h = oc_btile_planes(t, i, &np);
    double lo[3], hi[3];
    vbox(t, i, lo, hi);
    for (int k = 0; k < 27; k++) {
      double s = 10, q[3] = {p[0] + (k % 3 - 1) * s, p[1] + (k / 3 % 3 - 1) * s,
                             p[2] + (k / 9 - 1) * s};
      if (q[0] < lo[0] || q[0] > hi[0] || q[1] < lo[1] || q[1] > hi[1] ||
          q[2] < lo[2] || q[2] > hi[2])
        continue;
      double m = -INFINITY;
      for (size_t j = 0; j < np; j++) {
        const double *c = h + 4 * j;
        m = fmax(m, c[0] * q[0] + c[1] * q[1] + c[2] * q[2] + c[3]);
      }
      if (m < -tol) n++, *which = i;
    }
  }
  return n;
}

START_TEST(authored_box_honoured) {
  oc_btile_params pp;
  small(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  oc_btile *plain = make(&pp);
  /* a 4 x 2.5 x 1.5 box, and a tetrahedron across the tile's face x = 0
  ** (its centroid moved into the tile by s) */
  const double tet[12] = {-2, 6, 6, 0.5, 6, 6, -1, 8.5, 6, -1, 7, 8.5};
  oc_block_shape sh[2] = {
      {(const double[24]){2, 2, 2,   6, 2, 2,   2, 4.5, 2,   6, 4.5, 2,
                          2, 2, 3.5, 6, 2, 3.5, 2, 4.5, 3.5, 6, 4.5, 3.5},
       8, NULL, 0},
      {tet, 4, NULL, 0}};
  pp.blocks = sh;
  pp.nblocks = 2;
  oc_btile *t = make(&pp);
  oc_btile_stats sp, st;
  oc_btile_stats_get(plain, &sp);
  oc_btile_stats_get(t, &st);
  printf("authored: %zu points (%zu without), %zu blocks, %zu authored\n",
         st.points, sp.points, st.blocks, st.authored);
  ck_assert_uint_eq(st.authored, 2);
  /* the points in the box grown by r/2 (4.5 x 3 x 2 m) and in the
  ** tetrahedron (2.6 m^3, more with its shell) are gone: 0.73 per r^3 */
  double lost = 0.7336 / 0.125 * (4.5 * 3 * 2 + 2.6);
  ck_assert_double_ge((double)(sp.points - st.points), 0.95 * lost);
  ck_assert_double_le((double)(sp.points - st.points), 1.3 * lost);
  /* the box is the block before last, with its 6 faces and 8 corners */
  size_t nbx = st.blocks - 2, np, nv;
  const double *h = oc_btile_planes(t, nbx, &np);
  const double *v = oc_btile_vertices(t, nbx, &nv);
  ck_assert_uint_eq(np, 6);
  ck_assert_uint_eq(nv, 8);
  for (size_t k = 0; k < nv; k++) {
    ck_assert(fabs(v[3 * k] - 2) < 1e-12 || fabs(v[3 * k] - 6) < 1e-12);
    ck_assert(fabs(v[3 * k + 2] - 2) < 1e-12 ||
              fabs(v[3 * k + 2] - 3.5) < 1e-12);
  }
  (void)h;
  /* the tetrahedron (centroid x -0.875) moved by +10 in x */
  v = oc_btile_vertices(t, nbx + 1, &nv);
  ck_assert_uint_eq(nv, 4);
  for (size_t k = 0; k < nv; k++)
    ck_assert(v[3 * k] >= 8 - 1e-12 && v[3 * k] <= 10.5 + 1e-12);
  /* inside the authored blocks only they hold a point; anywhere at most
  ** one block does */
  oct_rng r = oct_rng_new(5);
  size_t inside = 0, which = 0;
  for (int k = 0; k < SAMPLES; k++) {
    oc_vec3 q = oct_in_box(&r, oct_v(0, 0, 0), oct_v(10, 10, 10));
    double p[3] = {q.x, q.y, q.z};
    int n = holders(t, st.blocks, p, 1e-9, &which);
    ck_assert_int_le(n, 1);
    if (p[0] > 2.01 && p[0] < 5.99 && p[1] > 2.01 && p[1] < 4.49 &&
        p[2] > 2.01 && p[2] < 3.49) {
      ck_assert_int_eq(n, 1);
      ck_assert_uint_eq(which, nbx);
      inside++;
    }
  }
  ck_assert_uint_gt(inside, SAMPLES / 100);
  /* as a node: f > T at the box's centre */
  oc_error e = {0};
  oc_node *b = OCT_OK(oc_btile_block(t, nbx, &e));
  oc_program *pr = oct_compile(b, 0.5, 0);
  ck_assert_double_gt(oc_program_eval(pr, oct_v(4, 3.25, 2.75)), 0.5);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(4, 3.25, 5)), 0);
  oc_program_free(pr);
  oc_btile_free(t);
  oc_btile_free(plain);
}
END_TEST

/* An octahedron given by its 8 faces: 6 corners. */
START_TEST(authored_planes) {
  oc_btile_params pp;
  small(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  double pl[32];
  for (int k = 0; k < 8; k++) {
    double sx = k & 1 ? 1 : -1, sy = k & 2 ? 1 : -1, sz = k & 4 ? 1 : -1;
    double c[4] = {sx, sy, sz, -(5 * sx + 5 * sy + 5 * sz) - 2};
    memcpy(pl + 4 * k, c, sizeof c);
  }
  oc_block_shape sh = {NULL, 0, pl, 8};
  pp.blocks = &sh;
  pp.nblocks = 1;
  oc_btile *t = make(&pp);
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  size_t nv;
  const double *v = oc_btile_vertices(t, st.blocks - 1, &nv);
  ck_assert_uint_eq(nv, 6);
  for (size_t k = 0; k < nv; k++)
    ck_assert_double_eq_tol(fabs(v[3 * k] - 5) + fabs(v[3 * k + 1] - 5) +
                                fabs(v[3 * k + 2] - 5),
                            2, 1e-9);
  oc_btile_free(t);
}
END_TEST

static void expect(const oc_btile_params *pp, const char *what) {
  oc_error e = {0};
  ck_assert_ptr_null(oc_btile_new(pp, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_msg(strstr(e.msg, what) != NULL, "'%s' not in: %s", what, e.msg);
}

START_TEST(authored_errors) {
  oc_btile_params pp;
  small(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  const double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const double big[12] = {0, 0, 0, 9, 0, 0, 0, 1, 0, 0, 0, 1};
  const double open[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, -1, 0, -1};
  oc_block_shape sh = {flat, 4, NULL, 0};
  pp.blocks = &sh;
  pp.nblocks = 1;
  expect(&pp, "'blocks[1]' is flat");
  sh = (oc_block_shape){big, 4, NULL, 0};
  expect(&pp, "'blocks[1]' is 9 x 1 x 1: it must be less than");
  sh = (oc_block_shape){NULL, 0, open, 4};
  expect(&pp, "'blocks[1].planes' do not bound a block");
  sh = (oc_block_shape){flat, 3, NULL, 0};
  expect(&pp, "'blocks[1].points' must hold 4 ..");
}
END_TEST

/* Prismatic and columnar tiles: no point in two blocks (each block an
** intersection of half-spaces, so convex), most of the tile in blocks,
** columns taller than wide. */
START_TEST(extension_types) {
  for (int ty = OC_BLOCKS_PRISMATIC; ty <= OC_BLOCKS_COLUMNAR; ty++) {
    oc_btile_params pp;
    small((oc_block_type)ty, &pp);
    oc_btile *t = make(&pp);
    oc_btile_stats st;
    oc_btile_stats_get(t, &st);
    double ez = 0, eh = 0;
    for (size_t i = 0; i < st.blocks; i++) {
      double lo[3], hi[3];
      vbox(t, i, lo, hi);
      ez += hi[2] - lo[2];
      eh += 0.5 * (hi[0] - lo[0] + hi[1] - lo[1]);
    }
    oct_rng r = oct_rng_new(7);
    size_t one = 0, which;
    for (int k = 0; k < SAMPLES; k++) {
      oc_vec3 q = oct_in_box(&r, oct_v(0, 0, 0), oct_v(10, 10, 10));
      double p[3] = {q.x, q.y, q.z};
      int n = holders(t, st.blocks, p, 1e-9, &which);
      ck_assert_int_le(n, 1);
      one += n == 1;
    }
    printf("%s: %zu blocks, %.1f points each, height / width %.2f, %.0f %% "
           "of the tile in blocks\n",
           oc_block_type_name((oc_block_type)ty), st.blocks,
           st.points_per_block, ez / eh, 100.0 * one / SAMPLES);
    ck_assert_uint_gt(st.blocks, 20);
    ck_assert_uint_gt(one, SAMPLES / 2);
    if (ty == OC_BLOCKS_COLUMNAR)
      ck_assert_double_gt(ez / eh, 1.5);
    else
      ck_assert_double_lt(ez / eh, 1.5);
    oc_btile_free(t);
  }
  ck_assert_str_eq(oc_block_type_name(OC_BLOCKS_COLUMNAR), "columnar");
  ck_assert_int_eq(oc_block_type_find("prismatic"), OC_BLOCKS_PRISMATIC);
}
END_TEST

int main(void) {
  Suite *s = suite_create("blocks_authored");
  TCase *tc = tcase_create("blocks_authored");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, authored_box_honoured);
  tcase_add_test(tc, authored_planes);
  tcase_add_test(tc, authored_errors);
  tcase_add_test(tc, extension_types);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
