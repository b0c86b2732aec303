/*
** test_slice.c — oc_slice: parameter checks, the raw field against the
** point primitive's formula on all three planes, the colour map, the
** iso-line position, and equality across thread counts.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "ocheck.h"
#include "outcrop.h"

static const oc_vec3 C = {1.0, 2.0, 3.0};
#define R 2.0

static oc_program *point_program(double energy, double T) {
  oc_error e = {0};
  oc_node *n = oc_point(C, R, energy, &e);
  ck_assert_msg(n != NULL, "oc_point: %s", e.msg);
  return oct_compile(n, T, 0);
}

static oc_slice_params params(oc_plane_axis plane, double at, int w, int h) {
  /* A window not centred on the point, so a flipped axis shows. */
  oc_slice_params sp = {plane, at, -1.7, -0.6, 3.1, 4.9, w, h};
  return sp;
}

static oc_image *slice_ok(const oc_program *pr, const oc_slice_params *sp) {
  oc_error e = {0};
  oc_image *img = oc_slice(pr, sp, &e);
  ck_assert_msg(img != NULL, "oc_slice: %s", e.msg);
  return img;
}

/* The world point of pixel (i, j), written from the header's contract. */
static oc_vec3 pixel_point(const oc_slice_params *sp, int i, int j) {
  double u = sp->u0 + (i + 0.5) * (sp->u1 - sp->u0) / sp->width;
  double v = sp->v1 - (j + 0.5) * (sp->v1 - sp->v0) / sp->height;
  switch (sp->plane) {
  case OC_PLANE_XY:
    return oct_v(u, v, sp->at);
  case OC_PLANE_XZ:
    return oct_v(u, sp->at, v);
  default:
    return oct_v(sp->at, u, v);
  }
}

static const float *px(const oc_image *img, int i, int j) {
  return oc_image_cdata(img) + ((size_t)j * oc_image_width(img) + i) * 5;
}

static int is_black(const float *p) {
  return p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f;
}

START_TEST(bad_params) {
  oc_program *pr = point_program(1.0, 0.5);
  struct {
    oc_slice_params sp;
    const char *param;
  } bad[] = {
      {{OC_PLANE_XY, 0, 0, 0, 1, 1, 0, 10}, "'width'"},
      {{OC_PLANE_XY, 0, 0, 0, 1, 1, 16385, 10}, "'width'"},
      {{OC_PLANE_XY, 0, 0, 0, 1, 1, 10, -3}, "'height'"},
      {{OC_PLANE_XY, 0, 0, 0, 1, 1, 10, 16385}, "'height'"},
      {{OC_PLANE_XY, 0, 1, 0, 1, 1, 10, 10}, "'u0'"},
      {{OC_PLANE_XY, 0, 2, 0, 1, 1, 10, 10}, "'u0'"},
      {{OC_PLANE_XY, 0, NAN, 0, 1, 1, 10, 10}, "'u0'"},
      {{OC_PLANE_XY, 0, 0, 0, INFINITY, 1, 10, 10}, "'u0'"},
      {{OC_PLANE_XY, 0, -1e308, 0, 1e308, 1, 10, 10}, "'u0'"},
      {{OC_PLANE_XY, 0, 0, 1, 1, 1, 10, 10}, "'v0'"},
      {{OC_PLANE_XY, 0, 0, 0, 1, NAN, 10, 10}, "'v0'"},
      {{OC_PLANE_XY, NAN, 0, 0, 1, 1, 10, 10}, "'at'"},
      {{OC_PLANE_XY, -INFINITY, 0, 0, 1, 1, 10, 10}, "'at'"},
      {{(oc_plane_axis)7, 0, 0, 0, 1, 1, 10, 10}, "'plane'"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    oc_error e = {0};
    oc_image *img = oc_slice(pr, &bad[k].sp, &e);
    ck_assert_msg(img == NULL, "case %zu accepted", k);
    ck_assert_int_eq(e.code, OC_EINVAL);
    ck_assert_msg(strstr(e.msg, bad[k].param), "case %zu: '%s' lacks %s", k,
                  e.msg, bad[k].param);
  }
  oc_slice_params ok = params(OC_PLANE_XY, 3, 4, 4);
  oc_error e = {0};
  ck_assert_ptr_null(oc_slice(NULL, &ok, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_slice(pr, NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  /* The largest side is allowed (a thin strip, to stay small). */
  oc_slice_params big = {OC_PLANE_XY, 3, -1, 1, 3, 2, 16384, 1};
  oc_image *img = slice_ok(pr, &big);
  ck_assert_int_eq(oc_image_width(img), 16384);
  oc_image_free(img);
  oc_program_free(pr);
}
END_TEST

/* Raw values against energy * (1 - (d/R)^2)^3 on every plane. */
START_TEST(field_channel) {
  const double energies[] = {1.0, 1.5};
  for (int k = 0; k < 2; k++) {
    oc_program *pr = point_program(energies[k], 0.5);
    const oc_plane_axis planes[] = {OC_PLANE_XY, OC_PLANE_XZ, OC_PLANE_YZ};
    const double ats[] = {C.z, C.y + 0.4, C.x - 0.7};
    for (int a = 0; a < 3; a++) {
      oc_slice_params sp = params(planes[a], ats[a], 61, 47);
      oc_image *img = slice_ok(pr, &sp);
      ck_assert_int_eq(oc_image_width(img), 61);
      ck_assert_int_eq(oc_image_height(img), 47);
      ck_assert_int_eq(oc_image_channels(img), 5);
      static const char *const names[] = {"R", "G", "B", "A", "field"};
      for (int c = 0; c < 5; c++)
        ck_assert_str_eq(oc_image_channel_name(img, c), names[c]);
      int inside = 0, zero = 0;
      for (int j = 0; j < 47; j++)
        for (int i = 0; i < 61; i++) {
          oc_vec3 p = pixel_point(&sp, i, j);
          double d = oct_len(oct_sub(p, C));
          double want = energies[k] * oct_g(d / R);
          float got = px(img, i, j)[4];
          ck_assert_msg(fabs(got - want) <= 1e-5,
                        "plane %d pixel (%d %d) at (%g %g %g): field %.9g, "
                        "want %.9g",
                        a, i, j, p.x, p.y, p.z, got, want);
          if (d > R * (1 + 1e-5)) {
            ck_assert_msg(got == 0.0f, "f = %g outside the support", got);
            zero++;
          }
          if (want > 0.5) inside++;
        }
      ck_assert_int_gt(inside, 10);
      ck_assert_int_gt(zero, 10);
      oc_image_free(img);
    }
    oc_program_free(pr);
  }
}
END_TEST

START_TEST(colour_map) {
  oc_program *pr = point_program(1.0, 0.5);
  oc_slice_params sp = params(OC_PLANE_XY, C.z, 80, 80);
  oc_image *img = slice_ok(pr, &sp);
  int warm = 0, cool = 0, white = 0;
  for (int j = 0; j < 80; j++)
    for (int i = 0; i < 80; i++) {
      const float *p = px(img, i, j);
      ck_assert_float_eq(p[3], 1.0f);
      for (int c = 0; c < 3; c++)
        ck_assert_msg(p[c] >= 0.0f && p[c] <= 1.0f, "channel %d: %g", c, p[c]);
      if (is_black(p)) continue;
      float f = p[4];
      if (f > 0.5f) {
        ck_assert_msg(p[0] > p[2] + 0.2f, "inside not warm: %g %g %g", p[0],
                      p[1], p[2]);
        warm++;
      } else if (f > 0.0f) {
        ck_assert_msg(p[2] > p[0] + 0.05f, "outside not cool: %g %g %g", p[0],
                      p[1], p[2]);
        cool++;
      } else {
        ck_assert_float_eq(f, 0.0f);
        ck_assert_msg(p[0] > 0.9f && p[1] > 0.9f && p[2] > 0.9f,
                      "zero not white: %g %g %g", p[0], p[1], p[2]);
        white++;
      }
    }
  ck_assert_int_gt(warm, 50);
  ck_assert_int_gt(cool, 50);
  ck_assert_int_gt(white, 50);
  /* Darker brown deeper inside: the pixel of largest f is darker than
  ** any inside pixel just above T. */
  float fmax_ = -1, dark = 0, light = 3;
  for (int j = 0; j < 80; j++)
    for (int i = 0; i < 80; i++) {
      const float *p = px(img, i, j);
      if (is_black(p)) continue;
      float sum = p[0] + p[1] + p[2];
      if (p[4] > fmax_) fmax_ = p[4], dark = sum;
      if (p[4] > 0.5f && p[4] < 0.6f && sum < light) light = sum;
    }
  ck_assert_float_gt(fmax_, 0.95f);
  ck_assert_msg(dark < light - 0.5f, "centre %g vs rim %g", dark, light);
  oc_image_free(img);
  oc_program_free(pr);

  /* Carving: negative values are purple, distinct from every other hue. */
  pr = point_program(-1.0, 0.5);
  img = slice_ok(pr, &sp);
  int purple = 0;
  for (int j = 0; j < 80; j++)
    for (int i = 0; i < 80; i++) {
      const float *p = px(img, i, j);
      ck_assert_msg(!is_black(p), "iso-line drawn where f < T everywhere");
      if (p[4] < 0) {
        ck_assert_msg(p[0] > p[1] && p[2] > p[1],
                      "negative not purple: %g %g "
                      "%g",
                      p[0], p[1], p[2]);
        purple++;
      }
    }
  ck_assert_int_gt(purple, 50);
  oc_image_free(img);
  oc_program_free(pr);
}
END_TEST

/* The black pixels sit where f = T: at R sqrt(1 - (T/e)^(1/3)) from the
** centre, within a pixel; and wherever two 4-neighbours straddle T, one
** of them is black, so the line has no gaps. */
static void check_line(double energy, double T, oc_plane_axis plane) {
  oc_program *pr = point_program(energy, T);
  oc_slice_params sp = params(plane,
                              plane == OC_PLANE_XY   ? C.z
                              : plane == OC_PLANE_XZ ? C.y
                                                     : C.x,
                              120, 138);
  oc_image *img = slice_ok(pr, &sp);
  double r_iso = R * sqrt(1.0 - cbrt(T / energy));
  double pix = fmax((sp.u1 - sp.u0) / sp.width, (sp.v1 - sp.v0) / sp.height);
  int black = 0;
  for (int j = 0; j < sp.height; j++)
    for (int i = 0; i < sp.width; i++) {
      const float *p = px(img, i, j);
      if (is_black(p)) {
        double d = oct_len(oct_sub(pixel_point(&sp, i, j), C));
        ck_assert_msg(fabs(d - r_iso) <= pix,
                      "black pixel (%d %d) at distance %g, iso-line at %g "
                      "(pixel %g)",
                      i, j, d, r_iso, pix);
        black++;
      }
      if (i + 1 < sp.width) {
        const float *q = px(img, i + 1, j);
        if ((p[4] > T) != (q[4] > T))
          ck_assert_msg(is_black(p) || is_black(q), "gap at (%d %d)", i, j);
      }
      if (j + 1 < sp.height) {
        const float *q = px(img, i, j + 1);
        if ((p[4] > T) != (q[4] > T))
          ck_assert_msg(is_black(p) || is_black(q), "gap at (%d %d)", i, j);
      }
    }
  /* About one pixel wide: a digital circle one pixel thick has about
  ** 4 sqrt(2) r / pixel pixels; marking both sides would double that. */
  double ring = 4.0 * sqrt(2.0) * r_iso / pix;
  ck_assert_msg(black >= 0.75 * ring && black <= 1.3 * ring,
                "%d black pixels for a ring of about %.0f", black, ring);
  oc_image_free(img);
  oc_program_free(pr);
}

START_TEST(iso_line) {
  check_line(1.0, 0.5, OC_PLANE_XY);
  check_line(1.0, 0.3, OC_PLANE_XZ);
  check_line(1.7, 0.5, OC_PLANE_YZ);
}
END_TEST

START_TEST(threads_agree) {
  oc_error e = {0};
  oc_node *kids[3] = {oc_point(C, R, 1.0, &e),
                      oc_point(oct_v(2.2, 2.5, 3.1), 1.3, 0.8, &e),
                      oc_point(oct_v(0.2, 3.0, 2.9), 1.0, -0.6, &e)};
  for (int k = 0; k < 3; k++)
    ck_assert_msg(kids[k] != NULL, "%s", e.msg);
  oc_node *b = oc_blend(kids, 3, &e);
  ck_assert_msg(b != NULL, "%s", e.msg);
  for (int k = 0; k < 3; k++)
    oc_node_release(kids[k]);
  oc_program *pr = oct_compile(b, 0.5, 0);
  oc_slice_params sp = params(OC_PLANE_XY, 3.0, 97, 83);
  int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  oc_image *one = slice_ok(pr, &sp);
  omp_set_num_threads(2);
  oc_image *two = slice_ok(pr, &sp);
  omp_set_num_threads(saved);
  ck_assert_int_eq(memcmp(oc_image_cdata(one), oc_image_cdata(two),
                          sizeof(float) * 97 * 83 * 5),
                   0);
  /* Non-trivial content: the blend has inside, outside and carved parts. */
  int neg = 0, in = 0;
  for (int i = 0; i < 97 * 83; i++) {
    float f = oc_image_cdata(one)[i * 5 + 4];
    neg += f < 0;
    in += f > 0.5f;
  }
  ck_assert_int_gt(neg, 0);
  ck_assert_int_gt(in, 0);
  oc_image_free(one);
  oc_image_free(two);
  oc_program_free(pr);
}
END_TEST

START_TEST(single_pixel) {
  oc_program *pr = point_program(1.0, 0.5);
  /* One pixel centred on the point: f = energy, no neighbours, no line. */
  oc_slice_params sp = {OC_PLANE_YZ, C.x,     C.y - 1, C.z - 1,
                        C.y + 1,     C.z + 1, 1,       1};
  oc_image *img = slice_ok(pr, &sp);
  const float *p = px(img, 0, 0);
  ck_assert_float_eq_tol(p[4], 1.0f, 1e-6);
  ck_assert(!is_black(p));
  ck_assert_float_eq(p[3], 1.0f);
  oc_image_free(img);
  oc_program_free(pr);
}
END_TEST

int main(void) {
  Suite *s = suite_create("slice");
  TCase *t = tcase_create("slice");
  tcase_add_test(t, bad_params);
  tcase_add_test(t, field_channel);
  tcase_add_test(t, colour_map);
  tcase_add_test(t, iso_line);
  tcase_add_test(t, threads_agree);
  tcase_add_test(t, single_pixel);
  suite_add_tcase(s, t);
  return oct_run(s);
}
