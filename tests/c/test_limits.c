/*
** test_limits.c — huge and odd numbers straight into the C API: every
** size derived from them is checked before anything is allocated, so a
** call returns an error naming the parameter (or a valid result), never
** writes out of bounds (run under ASan), and work that would not end in
** reasonable time is refused up front with the projected figure.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"

/* A valley along y sloping down to y = 0, 41 x 41 samples of 1 m. */
static oc_heightfield *slope(void) {
  oc_error err;
  oc_heightfield *hf = oc_heightfield_new(41, 41, 1, 0, 0, NULL, &err);
  ck_assert_ptr_nonnull(hf);
  float *z = oc_heightfield_samples_mut(hf);
  for (int j = 0; j < 41; j++)
    for (int i = 0; i < 41; i++)
      z[j * 41 + i] = (float)(0.2 * j + 0.6 * fabs(i - 20.0));
  return hf;
}

/* Either a node, or an error whose message names `field`. */
static void node_or_error(oc_node *n, const oc_error *err, const char *field) {
  if (n) {
    oc_node_release(n);
    return;
  }
  ck_assert_msg(strstr(err->msg, field), "'%s' not in \"%s\"", field, err->msg);
}

/* Runs the river generator with these lengths (0: defaults); the result
** must be a node or an error naming `field`. */
static void river(oc_heightfield *hf, double spacing, double radius,
                  double depth, const char *field) {
  oc_error err = {OC_OK, ""};
  oc_gen_sea_stats st;
  oc_gen_river_params r;
  oc_gen_river_defaults(&r);
  r.erode.heightfield = hf;
  r.erode.spacing = spacing;
  r.erode.radius = radius;
  r.depth = depth;
  node_or_error(oc_generate_river(&r, &st, &err), &err, field);
}

/* spacing = 1e308 made the candidate tiles' count 0, and the tile of a
** masked sample was clamped to index -1: a write before the array. */
START_TEST(erosion_huge_spacing) {
  oc_heightfield *hf = slope();
  static const double odd[] = {1e308, INFINITY, 1e300, 1e-308, 5e-324};
  for (size_t k = 0; k < sizeof odd / sizeof *odd; k++) {
    oc_error err = {OC_OK, ""};
    oc_gen_sea_stats st;
    river(hf, odd[k], 0, 0, "'spacing'");
    oc_gen_sea_params s;
    oc_gen_sea_defaults(&s);
    s.erode.heightfield = hf;
    s.erode.spacing = odd[k];
    node_or_error(oc_generate_sea(&s, &st, &err), &err, "'spacing'");
  }
  oc_heightfield_release(hf);
}
END_TEST

/* The river's bank rays ran `depth / slope` long (and radius lengthened
** them too): depth = 1e7 marched for minutes without polling (1e6: 20 s),
** radius = 1e5 as long; 1e9 overflowed the step count. They are cut
** to the footprint now, so any depth costs what the grid allows. */
START_TEST(river_long_rays) {
  oc_heightfield *hf = slope();
  static const double depth[] = {1e7, 1e9, 1e308, 0, 0.01, 0};
  static const double radius[] = {0, 0, 0, 1e308, 1e5, 1e-300};
  for (int k = 0; k < 6; k++) {
    double t0 = omp_get_wtime();
    river(hf, 1, radius[k], depth[k], "'radius'");
    ck_assert_msg(omp_get_wtime() - t0 < 10, "case %d took %.1f s", k,
                  omp_get_wtime() - t0);
  }
  oc_heightfield_release(hf);
}
END_TEST

static oc_program *plane(void) {
  oc_error err;
  oc_node *n = oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &err);
  ck_assert_ptr_nonnull(n);
  return oct_compile(n, 0, 0);
}

/* A plane over 500 x 500 km at 2 m cells would mesh until memory runs
** out: refused before meshing, with the projected figure. */
START_TEST(polygonize_projected_output) {
  oc_program *p = plane();
  oc_error err = {OC_OK, ""};
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{-250000, -250000, -1}, {250000, 250000, 1}};
  pp.cell = 2;
  double t0 = omp_get_wtime();
  ck_assert_ptr_null(oc_polygonize(p, &pp, &err));
  ck_assert_int_eq(err.code, OC_ENOMEM);
  ck_assert_msg(strstr(err.msg, "about 2.5e+11 triangles") &&
                    strstr(err.msg, "'max_triangles' (134217728)"),
                "%s", err.msg);
  ck_assert(omp_get_wtime() - t0 < 1);
  /* The estimate against the real count: a plane and its bottom cap
  ** over 100 x 100 cells make 2 x 2 x 101^2 triangles and a few more. */
  pp.box = (oc_aabb){{0, 0, -2}, {100, 100, 2}};
  pp.cell = 1;
  pp.max_triangles = 30000;
  ck_assert_ptr_null(oc_polygonize(p, &pp, &err));
  ck_assert_msg(strstr(err.msg, "about 4.08e+04 triangles"), "%s", err.msg);
  pp.max_triangles = 50000;
  oc_mesh *m = oc_polygonize(p, &pp, &err);
  ck_assert_ptr_nonnull(m);
  size_t nt = oc_mesh_triangle_count(m); /* the walls add a few more */
  ck_assert(nt >= 40804 && nt < 1.05 * 40804);
  oc_mesh_free(m);
  oc_program_free(p);
}
END_TEST

/* Boxes and radii at the ends of the double range: a result or an error
** naming the field, quickly. A box 1e-308 wide gave subnormal sub-cells
** whose darts never landed inside, and gap filling split them for ever. */
START_TEST(poisson_odd_numbers) {
  static const double odd[] = {1e308, 1e-308, 5e-324, 1e-300, 1e300};
  for (size_t k = 0; k < sizeof odd / sizeof *odd; k++)
    for (int d = 2; d <= 3; d++)
      for (int which = 0; which < 3; which++) {
        oc_poisson_params pp;
        memset(&pp, 0, sizeof pp);
        pp.box = (oc_aabb){{0, 0, 0}, {10, 10, 10}};
        pp.radius = 1;
        const char *field = "'box'";
        if (which == 0) pp.box.hi.x = odd[k];
        if (which == 1) pp.box.lo.y = -odd[k];
        if (which == 2) pp.radius = odd[k], field = "'radius'";
        oc_error err = {OC_OK, ""};
        double t0 = omp_get_wtime();
        oc_samples *s =
            d == 2 ? oc_poisson2d(&pp, &err) : oc_poisson3d(&pp, &err);
        ck_assert_msg(omp_get_wtime() - t0 < 5, "%dD %d %g: %.1f s", d, which,
                      odd[k], omp_get_wtime() - t0);
        if (s)
          ck_assert_msg(oc_samples_count(s) >= 1, "%dD %d %g: no sample", d,
                        which, odd[k]);
        else
          ck_assert_msg(strstr(err.msg, field) || strstr(err.msg, "'radius'"),
                        "%dD %d %g: %s", d, which, odd[k], err.msg);
        oc_samples_free(s);
      }
}
END_TEST

/* Columns x steps beyond OC_ERODE_MAX_PRIMITIVES: refused once the
** columns are known, before hours of rays, naming both fields. */
START_TEST(erosion_primitive_budget) {
  oc_heightfield *hf = slope();
  oc_error err = {OC_OK, ""};
  oc_gen_sea_stats st;
  oc_gen_river_params r;
  oc_gen_river_defaults(&r);
  r.erode.heightfield = hf;
  r.banks = 64; /* the whole valley is bank */
  r.erode.spacing = 0.04;
  r.erode.steps = 64;
  double t0 = omp_get_wtime();
  ck_assert_ptr_null(oc_generate_river(&r, &st, &err));
  ck_assert_int_eq(err.code, OC_ENOMEM);
  ck_assert_msg(strstr(err.msg, "'spacing'") && strstr(err.msg, "'steps'") &&
                    strstr(err.msg, "primitives (at most 20 million)"),
                "%s", err.msg);
  ck_assert(omp_get_wtime() - t0 < 20);
  oc_heightfield_release(hf);
}
END_TEST

/* A slice of 16384 x 16384 pixels of 5 floats is 5 GiB: refused with the
** renderer's pixel limit before anything is allocated. */
START_TEST(slice_pixel_limit) {
  oc_program *p = plane();
  oc_error err = {OC_OK, ""};
  oc_slice_params sp;
  memset(&sp, 0, sizeof sp);
  sp.plane = OC_PLANE_XZ;
  sp.u0 = sp.v0 = -1;
  sp.u1 = sp.v1 = 1;
  sp.width = sp.height = 16384;
  ck_assert_ptr_null(oc_slice(p, &sp, &err));
  ck_assert_int_eq(err.code, OC_ENOMEM);
  ck_assert_msg(strstr(err.msg, "'size' 16384 x 16384 is 268435456 pixels"),
                "%s", err.msg);
  sp.width = sp.height = 64;
  oc_image *img = oc_slice(p, &sp, &err);
  ck_assert_ptr_nonnull(img);
  oc_image_free(img);
  oc_program_free(p);
}
END_TEST

/* Cancels at the n-th progress call. */
static int cancel_at(void *ud, double fraction) {
  (void)fraction;
  return --*(int *)ud == 0;
}

/* Every progress poll of the sea and river generators (stream power,
** widening the bed, the column tiles, the rays) cancels cleanly: an error
** and nothing leaked, or the node once the polls are used up. */
START_TEST(erosion_cancels_at_every_poll) {
  oc_heightfield *hf = slope();
  for (int sea = 0; sea < 2; sea++) {
    int cancelled = 0;
    for (int n = 1; n < 400; n++) {
      int left = n;
      oc_error err = {OC_OK, ""};
      oc_gen_sea_stats st;
      oc_progress pr = {cancel_at, &left};
      oc_gen_river_params r;
      oc_gen_river_defaults(&r);
      r.erode.heightfield = hf;
      r.banks = 64;
      r.erode.progress = pr;
      oc_gen_sea_params q;
      oc_gen_sea_defaults(&q);
      q.erode.heightfield = hf;
      q.sea_level = 4;
      q.erode.progress = pr;
      oc_node *nd = sea ? oc_generate_sea(&q, &st, &err)
                        : oc_generate_river(&r, &st, &err);
      if (nd) {
        oc_node_release(nd);
        break;
      }
      ck_assert_int_eq(err.code, OC_ECANCEL);
      cancelled++;
    }
    ck_assert_int_ge(cancelled, 3);
  }
  oc_heightfield_release(hf);
}
END_TEST

int main(void) {
  Suite *s = suite_create("limits");
  TCase *tc = tcase_create("limits");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, erosion_huge_spacing);
  tcase_add_test(tc, river_long_rays);
  tcase_add_test(tc, polygonize_projected_output);
  tcase_add_test(tc, poisson_odd_numbers);
  tcase_add_test(tc, erosion_cancels_at_every_poll);
  tcase_add_test(tc, erosion_primitive_budget);
  tcase_add_test(tc, slice_pixel_limit);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
