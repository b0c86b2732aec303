/*
** test_render.c — the renderer against analytic answers: a sphere's
** silhouette and depth, hit distances against a dense fixed-step march
** (a thin wall in a 1 km scene included), the ray bounds it relies on,
** shadows, thread-count determinism, cancellation, bad parameters and
** the sRGB encoding of written renders.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "field/raybound.h"
#include "io/oiio.h"
#include "ocheck.h"
#include "outcrop.h"
#include "render/tone.h"
#include "render/trace.h"

#define PI 3.14159265358979323846

/* Surface radius of a point primitive (R, E) at level T: E g(r/R) = T. */
static double point_radius(double R, double E, double T) {
  return R * sqrt(1 - cbrt(T / E));
}

static oc_render_params view(oc_vec3 eye, oc_vec3 target, double fov, int w,
                             int h) {
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = eye;
  rp.camera.target = target;
  rp.camera.up = oct_v(0, 0, 1);
  rp.camera.fov = fov;
  rp.width = w;
  rp.height = h;
  return rp;
}

/* The pinhole ray through pixel (i, j), written independently of lib/. */
static oc_vec3 pixel_ray(const oc_render_params *rp, int i, int j) {
  oc_vec3 w = oct_sub(rp->camera.target, rp->camera.eye);
  w = oct_mul(w, 1 / oct_len(w));
  oc_vec3 r = oct_cross(w, rp->camera.up);
  r = oct_mul(r, 1 / oct_len(r));
  oc_vec3 u = oct_cross(r, w);
  double th = tan(rp->camera.fov * PI / 360);
  double x = ((i + 0.5) / rp->width * 2 - 1) * th * rp->width / rp->height;
  double y = (1 - (j + 0.5) / rp->height * 2) * th;
  oc_vec3 d = oct_add(w, oct_add(oct_mul(r, x), oct_mul(u, y)));
  return oct_mul(d, 1 / oct_len(d));
}

/* First t of o + t d on the sphere (c, r), or INFINITY. */
static double ray_sphere(oc_vec3 o, oc_vec3 d, oc_vec3 c, double r) {
  oc_vec3 m = oct_sub(o, c);
  double b = oct_dot(m, d), q = oct_dot(m, m) - r * r, disc = b * b - q;
  if (disc < 0) return INFINITY;
  double t = -b - sqrt(disc);
  return t >= 0 ? t : INFINITY;
}

static const float *px(const oc_image *img, int i, int j) {
  return oc_image_cdata(img) +
         ((size_t)j * oc_image_width(img) + i) * oc_image_channels(img);
}

/* ---- sphere: silhouette and depth ------------------------------------- */

START_TEST(sphere_silhouette_and_depth) {
  double R = 2, T = 0.5, rs = point_radius(R, 1, T);
  oc_vec3 c = oct_v(0.3, 0.2, -0.1);
  oc_program *pr = oct_compile(OCT_OK(oc_point(c, R, 1, NULL)), 0, 0);
  for (int tracer = 0; tracer < 2; tracer++) {
    oc_render_params rp = view(oct_v(0, -10, 0), oct_v(0, 0, 0), 30, 160, 120);
    rp.tracer = tracer ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
    oc_error e;
    oc_image *g = oc_render_geometry(pr, &rp, &e);
    ck_assert_msg(g, "%s", e.msg);
    double pixel = 2 * tan(15 * PI / 180) / 120; /* radians */
    int hits = 0, expect = 0, bad = 0;
    double zerr = 0;
    for (int j = 0; j < 120; j++)
      for (int i = 0; i < 160; i++) {
        oc_vec3 d = pixel_ray(&rp, i, j);
        double t = ray_sphere(rp.camera.eye, d, c, rs);
        const float *p = px(g, i, j);
        int hit = p[OC_RG_HIT] > 0;
        hits += hit;
        expect += isfinite(t);
        if (hit != isfinite(t)) {
          /* only on the silhouette: the ray passes within a pixel */
          oc_vec3 m = oct_sub(c, rp.camera.eye);
          double ang = acos(oct_dot(m, d) / oct_len(m));
          double alpha = asin(rs / oct_len(m));
          if (fabs(ang - alpha) > pixel) bad++;
          continue;
        }
        if (hit) {
          zerr = fmax(zerr, fabs(p[OC_RG_Z] - t));
          /* normal: radial */
          oc_vec3 q = oct_add(rp.camera.eye, oct_mul(d, t));
          oc_vec3 nr = oct_mul(oct_sub(q, c), 1 / rs);
          ck_assert_double_lt(fabs(p[OC_RG_NX] - nr.x), 1e-3);
          ck_assert_double_lt(fabs(p[OC_RG_NX + 2] - nr.z), 1e-3);
          ck_assert_double_lt(fabs(p[OC_RG_PX + 1] - q.y), 2e-3);
        } else {
          ck_assert(isinf(p[OC_RG_Z]));
        }
      }
    /* coverage of the analytic disc, to within its rim of pixels */
    ck_assert_int_eq(bad, 0);
    double D = oct_len(oct_sub(c, rp.camera.eye));
    double rho = tan(asin(rs / D)) / pixel; /* disc radius, pixels */
    ck_assert_double_lt(fabs(hits - PI * rho * rho), 2 * PI * rho * 0.5);
    ck_assert_int_lt(abs(hits - expect), (int)(2 * PI * rho * 0.25) + 1);
    /* depth within a small fraction of a pixel's footprint (2.7 cm) */
    ck_assert_msg(zerr < 1e-3, "tracer %d: depth error %g", tracer, zerr);
    oc_image_free(g);
  }
  oc_program_free(pr);
}
END_TEST

/* ---- reference march ---------------------------------------------------- */

/* First t in [0, tmax] with f >= T on a fixed grid of step h, refined by
** bisection; INFINITY when none. */
static double march(const oc_program *pr, oc_vec3 o, oc_vec3 d, double T,
                    double tmax, double h) {
  double prev = 0;
  for (double t = 0; t <= tmax; t += h) {
    if (oc_program_eval(pr, oct_add(o, oct_mul(d, t))) >= T) {
      double a = prev, b = t;
      for (int k = 0; k < 40; k++) {
        double m = 0.5 * (a + b);
        if (oc_program_eval(pr, oct_add(o, oct_mul(d, m))) >= T)
          b = m;
        else
          a = m;
      }
      return b;
    }
    prev = t;
  }
  return INFINITY;
}

/* A 1 km scene: ground plane, a 1 m wall seen edge-on, bumps, a carving. */
static oc_program *wall_scene(void) {
  oct_rng r = oct_rng_new(44);
  oc_node *kids[203];
  int n = 0;
  kids[n++] = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 3, 1, NULL));
  kids[n++] =
      OCT_OK(oc_box(oct_v(-0.5, -200, 0), oct_v(0.5, 200, 40), 0.25, 1, NULL));
  for (int k = 0; k < 200; k++) {
    oc_vec3 c = oct_in_box(&r, oct_v(-500, -500, -2), oct_v(500, 500, 4));
    double E = oct_unif(&r, 0, 1) < 0.2 ? -0.8 : 1;
    kids[n++] = OCT_OK(oc_point(c, oct_unif(&r, 3, 12), E, NULL));
  }
  oc_node *b = OCT_OK(oc_blend(kids, (size_t)n, NULL));
  for (int k = 0; k < n; k++)
    oc_node_release(kids[k]);
  return oct_compile(b, 0, 0);
}

START_TEST(thin_wall_against_march) {
  oc_program *pr = wall_scene();
  double T = oc_program_threshold(pr);
  for (int mode = 0; mode < 2; mode++) {
    oc_tracer tr;
    /* tolerance of a 1000-pixel-high image */
    oc_tracer_init(&tr, pr, T, mode ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT,
                   0.25 * 0.8 / 1000, 1e-6);
    oc_vec3 eye = oct_v(0, -1000, 20);
    int nhit = 0;
    for (int k = 0; k <= 60; k++) {
      /* aim across the wall's end, from 1.5 m left to 1.5 m right; then
      ** level rays that graze its side (x = 0.6135) at 1 / 2000 and meet
      ** it 18 to 360 m behind its end */
      oc_vec3 d;
      if (k <= 40) {
        d = oct_sub(oct_v(-1.5 + 3.0 * k / 40, -200, 20 + 0.1 * k), eye);
      } else {
        eye = oct_v(0.6135 + 0.4 + 0.009 * (k - 40), -1000, 20);
        d = oct_v(-0.0005, 1, 0);
      }
      d = oct_mul(d, 1 / oct_len(d));
      double tref = march(pr, eye, d, T, 2000, 0.02);
      double t, ev = 0;
      int hit = oc_trace(&tr, eye, d, 0, 2000, 0, &t, &ev);
      ck_assert_msg(hit == isfinite(tref), "ray %d mode %d: hit %d ref %g", k,
                    mode, hit, tref);
      if (hit) {
        nhit++;
        /* within the march's step and the tracer's tolerance */
        ck_assert_msg(fabs(t - tref) < 0.02 + tr.eps_k * t + 1e-6,
                      "ray %d mode %d: t %.6f ref %.6f", k, mode, t, tref);
      }
    }
    ck_assert_int_ge(nhit, 32); /* the wall is really there */
  }
  oc_program_free(pr);
}
END_TEST

/* An open terrain (a flat grid at z = 10 over [0, 40]^2, falloff 2, so a
** 0.91 m solid) seen from outside its side x = 0, from below the top, so
** that rays climb through the corner where the side wall meets the top:
** the rays that cross the wall just under z = 10 are in the solid for
** less than one sphere-tracing step (T / L = 0.5 m). Both tracers must
** hit the same pixels, as the march does; without the step check at the
** jump the sphere tracer leaps over the corner. With a ball beside it
** the terrain is under a blend, whose own bound must not hide the jump. */
static oc_program *open_terrain_block(int ball) {
  float z[41 * 41];
  for (int k = 0; k < 41 * 41; k++)
    z[k] = 10;
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(41, 41, 1, 0, 0, z, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {.falloff = 2, .transition = 1};
  oc_node *n = oc_terrain(&src, &tp, &e);
  src.release(src.ud);
  oc_heightfield_release(hf);
  ck_assert_msg(n != NULL, "%s", e.msg);
  if (ball) {
    oc_node *k[2] = {n, OCT_OK(oc_point(oct_v(20, 20, 30), 3, 1, &e))};
    n = OCT_OK(oc_blend(k, 2, &e));
    oc_node_release(k[0]);
    oc_node_release(k[1]);
  }
  return oct_compile(n, 0, 0);
}

START_TEST(open_edge_both_tracers) {
  oc_program *pr = open_terrain_block(_i);
  double T = oc_program_threshold(pr);
  oc_render_params rp = view(oct_v(-20, 20, 6), oct_v(0, 20, 10), 10, 64, 48);
  oc_image *g[2];
  for (int m = 0; m < 2; m++) {
    rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
    oc_error e;
    g[m] = oc_render_geometry(pr, &rp, &e);
    ck_assert_msg(g[m], "%s", e.msg);
  }
  int differ = 0, corner = 0, hits = 0;
  for (int j = 0; j < 48; j++)
    for (int i = 0; i < 64; i++) {
      const float *a = px(g[0], i, j), *b = px(g[1], i, j);
      int ha = a[OC_RG_HIT] > 0, hb = b[OC_RG_HIT] > 0;
      oc_vec3 d = pixel_ray(&rp, i, j);
      double tref = march(pr, rp.camera.eye, d, T, 60, 0.002);
      for (int m = 0; m < 2; m++) {
        int h = m ? hb : ha;
        if (h != isfinite(tref)) differ++;
      }
      if (ha != hb) differ++;
      if (ha && hb) {
        hits++;
        ck_assert_msg(fabs(a[OC_RG_Z] - b[OC_RG_Z]) < 0.05,
                      "pixel %d %d: Z %g vs %g", i, j, a[OC_RG_Z], b[OC_RG_Z]);
        /* hit on the wall, within the top 0.25 m of it */
        if (a[OC_RG_PX] < 0.01 && a[OC_RG_PX + 2] > 9.75) corner++;
      }
    }
  oc_image_free(g[0]);
  oc_image_free(g[1]);
  oc_program_free(pr);
  ck_assert_int_gt(hits, 500);
  ck_assert_int_ge(corner, 64); /* the sliver rows are in view */
  ck_assert_msg(differ <= 4, "%d disagreements", differ);
}
END_TEST

/* A terrain thinner than the rays' tolerance (falloff 0.01, a 4.5 mm
** solid, seen from 25 m by 32 x 24 pixels) shows as a pixel or two, or
** nothing, and the render says why; one of falloff 4 (1.8 m) shows and
** says nothing, and neither does a view that misses the scene. */
START_TEST(thin_terrain_render_warns) {
  float z[16 * 16] = {0};
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(16, 16, 1, 0, 0, z, &e);
  ck_assert(hf);
  for (int pass = 0; pass < 3; pass++) {
    oc_elevation src;
    ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
    oc_terrain_params tp = {.falloff = pass == 1 ? 4 : 0.01};
    oc_node *n = OCT_OK(oc_terrain(&src, &tp, &e));
    src.release(src.ud);
    oc_program *pr = oct_compile(n, 0, 0);
    oc_render_params rp =
        view(oct_v(-10, -12, 9), oct_v(pass == 2 ? -40 : 8, 8, 0), 45, 32, 24);
    char warn[300] = "x";
    rp.warning = warn;
    rp.warning_size = sizeof warn;
    for (int m = 0; m < 2; m++) {
      rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
      oc_image *g = oc_render_geometry(pr, &rp, &e);
      ck_assert_msg(g, "%s", e.msg);
      int hits = 0;
      for (int j = 0; j < 24; j++)
        for (int i = 0; i < 32; i++)
          hits += px(g, i, j)[OC_RG_HIT] > 0;
      oc_image_free(g);
      if (pass == 0) {
        ck_assert_int_le(hits, 8);
        ck_assert_msg(strstr(warn, "hit tolerance") &&
                          strstr(warn, "falloff") && strstr(warn, "thickness"),
                      "warning: '%s'", warn);
      } else {
        ck_assert_int_eq(hits > 100, pass == 1);
        ck_assert_str_eq(warn, "");
      }
    }
    oc_program_free(pr);
  }
  oc_heightfield_release(hf);
}
END_TEST

/* A ray whose far end is 1e300 away (a scene's box grown by a huge warp)
** with a pixel-sized tolerance would take millions of steps: both tracers
** give up after OC_TRACE_MAX_STEPS, a miss. */
START_TEST(ray_step_budget) {
  oc_error e = {0};
  /* a plane seen edge-on from above: f < T all along the ray, never a
  ** hit, and no support interval ends the ray early */
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 4, 1, &e)), 0, 0);
  for (int mode = 0; mode < 2; mode++) {
    oc_tracer tr;
    oc_tracer_init(&tr, pr, oc_program_threshold(pr),
                   mode ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT, 1e-12, 1e-12);
    double t, ev = 0;
    oc_vec3 eye = oct_v(0, 0, 3), d = oct_v(1, 0, 0);
    int hit = oc_trace(&tr, eye, d, 0, 1e300, 0, &t, &ev);
    ck_assert_int_eq(hit, 0);
    ck_assert_msg(ev <= OC_TRACE_MAX_STEPS + 1, "mode %d: %g evaluations", mode,
                  ev);
    if (mode) ck_assert(ev >= 1000); /* it did march */
  }
  oc_program_free(pr);
}
END_TEST

/* Random pixels of a blob-and-plane view, both tracers, against the
** march. */
START_TEST(image_against_march) {
  oct_rng r = oct_rng_new(7);
  oc_node *kids[41];
  kids[0] = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, NULL));
  for (int k = 1; k < 41; k++)
    kids[k] =
        oct_random_prim(&r, oct_v(-10, -10, -1), oct_v(10, 10, 6), 1, 3, 0.25);
  oc_node *b = OCT_OK(oc_blend(kids, 41, NULL));
  for (int k = 0; k < 41; k++)
    oc_node_release(kids[k]);
  oc_program *pr = oct_compile(b, 0, 0);
  oc_render_params rp = view(oct_v(18, -22, 14), oct_v(0, 0, 1), 50, 96, 64);
  rp.max_distance = 200;
  oc_image *g[2];
  for (int m = 0; m < 2; m++) {
    rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
    g[m] = oc_render_geometry(pr, &rp, NULL);
    ck_assert(g[m]);
  }
  double T = oc_program_threshold(pr), ev[2] = {0, 0};
  for (int j = 0; j < 64; j++)
    for (int i = 0; i < 96; i++)
      for (int m = 0; m < 2; m++)
        ev[m] += px(g[m], i, j)[OC_RG_EVALS];
  for (int s = 0; s < 300; s++) {
    int i = (int)oct_unif(&r, 0, 96), j = (int)oct_unif(&r, 0, 64);
    oc_vec3 d = pixel_ray(&rp, i, j);
    double tref = march(pr, rp.camera.eye, d, T, 200, 0.004);
    for (int m = 0; m < 2; m++) {
      const float *p = px(g[m], i, j);
      ck_assert_msg((p[OC_RG_HIT] > 0) == isfinite(tref),
                    "pixel %d %d tracer %d", i, j, m);
      if (isfinite(tref))
        ck_assert_msg(fabs(p[OC_RG_Z] - tref) < 0.004 + 0.01,
                      "pixel %d %d tracer %d: %g vs %g", i, j, m, p[OC_RG_Z],
                      tref);
    }
  }
  /* the local bounds pay off even on 40 primitives */
  ck_assert_double_gt(ev[1], 2 * ev[0]);
  oc_image_free(g[0]);
  oc_image_free(g[1]);
  oc_program_free(pr);
}
END_TEST

/* ---- the bounds the tracer relies on ------------------------------------ */

START_TEST(ray_bounds_hold) {
  oct_rng r = oct_rng_new(3);
  oc_node *kids[80];
  kids[0] = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0.2, 0, 1), 2, 1, NULL));
  for (int k = 1; k < 80; k++)
    kids[k] =
        k < 60
            ? OCT_OK(oc_point(oct_in_box(&r, oct_v(-8, -8, -8), oct_v(8, 8, 8)),
                              oct_unif(&r, 0.5, 3), oct_unif(&r, -1, 1), NULL))
            : oct_random_prim(&r, oct_v(-8, -8, -8), oct_v(8, 8, 8), 0.5, 3,
                              0.3);
  oc_node *b = OCT_OK(oc_blend(kids, 80, NULL));
  for (int k = 0; k < 80; k++)
    oc_node_release(kids[k]);
  oc_program *pr = oct_compile(b, 0, 0);
  int inside = 0;
  for (int s = 0; s < 400; s++) {
    oc_vec3 o = oct_in_box(&r, oct_v(-12, -12, -12), oct_v(12, 12, 12));
    oc_ray ray = oc_ray_make(o, oct_dir(&r));
    double t0 = oct_unif(&r, 0, 5), t1 = t0 + oct_unif(&r, 0.01, 10);
    double lo, hi;
    oc_ray_dbound(pr, &ray, t0, t1, &lo, &hi);
    ck_assert(lo <= 0 && hi >= 0);
    double fp = oc_program_eval(pr, oct_add(o, oct_mul(ray.u, t0)));
    for (int k = 1; k <= 200; k++) {
      double t = t0 + (t1 - t0) * k / 200;
      double f = oc_program_eval(pr, oct_add(o, oct_mul(ray.u, t)));
      double dt = (t1 - t0) / 200;
      ck_assert_msg(f - fp <= hi * dt * (1 + 1e-9) + 1e-12, "sample %d", s);
      ck_assert_msg(f - fp >= lo * dt * (1 + 1e-9) - 1e-12, "sample %d", s);
      fp = f;
    }
    /* outside the support intervals the field is exactly 0 */
    oc_zspan iv[64];
    int n = oc_ray_supports(pr, &ray, 0, 30, iv, 64);
    for (int k = 0; k + 1 < n; k++)
      ck_assert(iv[k].hi < iv[k + 1].lo);
    for (int k = 0; k <= 600; k++) {
      double t = 30.0 * k / 600;
      int in = 0;
      for (int q = 0; q < n; q++)
        in |= t >= iv[q].lo && t <= iv[q].hi;
      inside += in;
      if (!in)
        ck_assert(oc_program_eval(pr, oct_add(o, oct_mul(ray.u, t))) == 0);
    }
  }
  ck_assert_int_gt(inside, 1000);
  oc_program_free(pr);
}
END_TEST

/* ---- shading ------------------------------------------------------------ */

static oc_program *ball_over_ground(void) {
  oc_node *k[2] = {OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, NULL)),
                   OCT_OK(oc_point(oct_v(0, 0, 5), 3, 1, NULL))};
  oc_node *b = OCT_OK(oc_blend(k, 2, NULL));
  oc_node_release(k[0]);
  oc_node_release(k[1]);
  return oct_compile(b, 0, 0);
}

/* Mean red of ground pixels under the ball (r < 1) and far from it. */
static void ground_means(const oc_image *img, double *under, double *lit) {
  double su = 0, sl = 0;
  int nu = 0, nl = 0;
  for (int j = 0; j < oc_image_height(img); j++)
    for (int i = 0; i < oc_image_width(img); i++) {
      const float *p = px(img, i, j);
      if (!(p[4] < INFINITY) || p[4 + 6] > 0.6) continue; /* Z, P.z */
      double r = hypot(p[4 + 4], p[4 + 5]);
      if (r < 1) su += p[0], nu++;
      if (r > 5 && r < 9) sl += p[0], nl++;
    }
  ck_assert_int_gt(nu, 20);
  ck_assert_int_gt(nl, 200);
  *under = su / nu;
  *lit = sl / nl;
}

START_TEST(shadow_under_ball) {
  oc_program *pr = ball_over_ground();
  oc_render_params rp = view(oct_v(0, -16, 12), oct_v(0, 0, 0), 50, 120, 90);
  rp.sun_direction = oct_v(0, 0, 1);
  rp.ao = 0;
  rp.texture = 0;
  rp.aov = 1;
  oc_image *a = oc_render(pr, &rp, NULL);
  ck_assert(a);
  double under, lit;
  ground_means(a, &under, &lit);
  /* in shadow only the sky lights the ground */
  ck_assert_msg(under < 0.4 * lit, "under %g lit %g", under, lit);
  rp.shadows = 0;
  oc_image *b = oc_render(pr, &rp, NULL);
  ground_means(b, &under, &lit);
  ck_assert_msg(fabs(under - lit) < 0.02 * lit, "under %g lit %g", under, lit);
  oc_image_free(a);
  oc_image_free(b);
  oc_program_free(pr);
}
END_TEST

/* Two phases equal one call; a given albedo replaces the rules. */
START_TEST(two_phases_and_albedo) {
  oc_program *pr = ball_over_ground();
  oc_render_params rp = view(oct_v(10, -14, 9), oct_v(0, 0, 2), 45, 64, 48);
  rp.aov = 1;
  oc_image *one = oc_render(pr, &rp, NULL);
  oc_image *g = oc_render_geometry(pr, &rp, NULL);
  oc_image *two = oc_render_shade(pr, &rp, g, NULL, NULL);
  ck_assert(one && g && two);
  size_t n = (size_t)64 * 48 * 12;
  ck_assert(
      memcmp(oc_image_cdata(one), oc_image_cdata(two), n * sizeof(float)) == 0);
  ck_assert_str_eq(oc_image_channel_name(one, 4), "Z");
  ck_assert_str_eq(oc_image_channel_name(one, 11), "evals");
  /* black albedo, no fog: hits are black */
  float *alb = calloc((size_t)64 * 48 * 3, sizeof *alb);
  oc_image *blk = oc_render_shade(pr, &rp, g, alb, NULL);
  int nhit = 0;
  for (int j = 0; j < 48; j++)
    for (int i = 0; i < 64; i++)
      if (px(g, i, j)[OC_RG_HIT] > 0) {
        nhit++;
        ck_assert(px(blk, i, j)[0] == 0 && px(blk, i, j)[3] == 1);
      } else {
        ck_assert(px(blk, i, j)[0] > 0);
      }
  ck_assert_int_gt(nhit, 100);
  free(alb);
  oc_image_free(blk);
  oc_image_free(one);
  oc_image_free(two);
  oc_image_free(g);
  oc_program_free(pr);
}
END_TEST

START_TEST(field_palette_and_fog) {
  oc_program *pr = ball_over_ground();
  /* colour by height: a palette from red (z <= 0.5) to blue (z >= 8) */
  oc_node *zf = OCT_OK(oc_plane(oct_v(0, 0, 8), oct_v(0, 0, -1), 8, 1, NULL));
  oc_program *col = oct_compile(zf, 0, 0);
  double stops[] = {0.01, 1, 0, 0, 1.0, 0, 0, 1};
  oc_render_params rp = view(oct_v(0, -16, 12), oct_v(0, 0, 0), 50, 80, 60);
  rp.color = OC_COLOR_FIELD;
  rp.color_field = col;
  rp.stops = stops;
  rp.nstops = 2;
  rp.texture = 0;
  rp.aov = 1;
  oc_image *a = oc_render(pr, &rp, NULL);
  ck_assert(a);
  int ground = 0;
  for (int j = 0; j < 60; j++)
    for (int i = 0; i < 80; i++) {
      const float *p = px(a, i, j);
      if (p[4] < INFINITY && p[10] < 0.5) { /* ground: field of zf ~0 */
        ground++;
        ck_assert(p[0] > 0 && p[2] == 0);
      }
    }
  ck_assert_int_gt(ground, 100);
  /* thick fog: every hit tends to the fog colour */
  rp.fog_density = 10;
  rp.fog_color[0] = 0.25, rp.fog_color[1] = 0.5, rp.fog_color[2] = 0.75;
  oc_image *f = oc_render(pr, &rp, NULL);
  for (int j = 0; j < 60; j++)
    for (int i = 0; i < 80; i++) {
      const float *p = px(f, i, j);
      if (p[4] < INFINITY)
        ck_assert(fabs(p[1] - 0.5) < 1e-6 && fabs(p[2] - 0.75) < 1e-6);
    }
  oc_image_free(a);
  oc_image_free(f);
  oc_program_free(col);
  oc_program_free(pr);
}
END_TEST

/* ---- threads, progress, errors ------------------------------------------ */

START_TEST(threads_byte_identical) {
  oc_program *pr = wall_scene();
  oc_render_params rp = view(oct_v(60, -300, 80), oct_v(0, 0, 0), 40, 120, 80);
  rp.aov = 1;
  int nt0 = omp_get_max_threads();
  omp_set_num_threads(1);
  oc_image *a = oc_render(pr, &rp, NULL);
  omp_set_num_threads(2);
  oc_image *b = oc_render(pr, &rp, NULL);
  omp_set_num_threads(nt0);
  ck_assert(a && b);
  ck_assert(memcmp(oc_image_cdata(a), oc_image_cdata(b),
                   (size_t)120 * 80 * 12 * sizeof(float)) == 0);
  oc_image_free(a);
  oc_image_free(b);
  oc_program_free(pr);
}
END_TEST

typedef struct pcount {
  int calls, cancel_at;
  double last;
  int monotone;
} pcount;

static int on_progress(void *ud, double f) {
  pcount *c = ud;
  if (f < c->last) c->monotone = 0;
  c->last = f;
  return ++c->calls >= c->cancel_at;
}

START_TEST(progress_and_cancel) {
  oc_program *pr = ball_over_ground();
  oc_render_params rp = view(oct_v(10, -14, 9), oct_v(0, 0, 2), 45, 200, 150);
  pcount c = {0, 1 << 30, 0, 1};
  rp.progress.fn = on_progress;
  rp.progress.ud = &c;
  oc_image *a = oc_render(pr, &rp, NULL);
  ck_assert(a);
  ck_assert(c.monotone && c.last == 1.0 && c.calls > 2);
  oc_image_free(a);
  for (int at = 1; at <= 3; at++) {
    pcount d = {0, at, 0, 1};
    rp.progress.ud = &d;
    oc_error e = {0};
    ck_assert(oc_render(pr, &rp, &e) == NULL);
    ck_assert_int_eq(e.code, OC_ECANCEL);
    ck_assert(oc_render_geometry(pr, &rp, &e) == NULL);
    ck_assert_int_eq(e.code, OC_ECANCEL);
  }
  oc_program_free(pr);
}
END_TEST

static void expect_err(const oc_program *pr, const oc_render_params *rp,
                       oc_status code, const char *param) {
  oc_error e = {0};
  ck_assert(oc_render(pr, rp, &e) == NULL);
  ck_assert_msg(e.code == code, "%s: code %d (%s)", param, e.code, e.msg);
  char q[64];
  snprintf(q, sizeof q, "'%s", param);
  ck_assert_msg(strstr(e.msg, q), "'%s' not named in: %s", param, e.msg);
}

START_TEST(bad_params) {
  oc_program *pr = ball_over_ground();
  oc_render_params ok = view(oct_v(10, -14, 9), oct_v(0, 0, 2), 45, 8, 8), rp;
#define BAD(stmt, code, name)                                                  \
  do {                                                                         \
    rp = ok;                                                                   \
    stmt;                                                                      \
    expect_err(pr, &rp, code, name);                                           \
  } while (0)
  BAD(rp.camera.fov = NAN, OC_EINVAL, "camera.fov");
  BAD(rp.camera.fov = 180, OC_EINVAL, "camera.fov");
  BAD(rp.camera.target = rp.camera.eye, OC_EINVAL, "camera.target");
  BAD(rp.camera.eye.x = INFINITY, OC_EINVAL, "camera.eye");
  BAD(rp.camera.up = oct_v(-10, 14, -7), OC_EINVAL, "camera.up");
  BAD(rp.width = 0, OC_EINVAL, "size");
  BAD(rp.height = 20000, OC_EINVAL, "size");
  BAD((rp.width = 16384, rp.height = 16384), OC_ENOMEM, "size");
  BAD(rp.sun_direction = oct_v(0, 0, 0), OC_EINVAL, "sun.direction");
  BAD(rp.sun_intensity = -1, OC_EINVAL, "sun.intensity");
  BAD(rp.sun_color[1] = NAN, OC_EINVAL, "sun.color");
  BAD(rp.sky[0] = -1, OC_EINVAL, "sky");
  BAD(rp.fog_density = -0.1, OC_EINVAL, "fog");
  BAD((rp.has_background = 1, rp.background[3] = NAN), OC_EINVAL, "background");
  BAD(rp.threshold = NAN, OC_EINVAL, "threshold");
  BAD(rp.texture = 2, OC_EINVAL, "texture");
  BAD(rp.rules.rock_slope = 100, OC_EINVAL, "rock_slope");
  double desc[] = {1, 0, 0, 0, 0, 1, 1, 1};
  BAD((rp.color = OC_COLOR_FIELD, rp.color_field = pr, rp.stops = desc,
       rp.nstops = 2),
      OC_EINVAL, "palette");
  BAD((rp.color = OC_COLOR_FIELD, rp.color_field = NULL), OC_EINVAL, "color");
  BAD(rp.exposure = NAN, OC_EINVAL, "exposure");
  BAD(rp.exposure = 20.5, OC_EINVAL, "exposure");
  BAD(rp.exposure = -INFINITY, OC_EINVAL, "exposure");
  BAD(rp.tone = (oc_render_tone)7, OC_EINVAL, "tone");
#undef BAD
  /* a geometry image of the wrong size */
  oc_image *g = oc_render_geometry(pr, &ok, NULL);
  rp = ok;
  rp.width = 9;
  oc_error e;
  ck_assert(oc_render_shade(pr, &rp, g, NULL, &e) == NULL);
  ck_assert(strstr(e.msg, "'geometry'"));
  oc_image_free(g);
  oc_program_free(pr);
}
END_TEST

/* ---- written files ------------------------------------------------------ */

START_TEST(srgb_on_write) {
  const char *dir = oct_tmpdir("render");
  oc_image *img = oc_image_new(2, 1, 4, NULL);
  float *d = oc_image_data(img);
  float v[8] = {0.5f, 0.0031308f * 0.5f, 1, 0.5f, 0.2f, 0.2f, 0.2f, 1};
  memcpy(d, v, sizeof v);
  /* display-referred: as given */
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "a.png"), 8, NULL), 0);
  oc_image *a = oc_oiio_read(oct_in_dir(dir, "a.png"), NULL);
  ck_assert(fabs(oc_image_cdata(a)[0] - 128 / 255.0) < 1e-6);
  /* linear: sRGB-encoded colour, alpha untouched */
  oc_image_set_meta(img, "outcrop:colorspace", "linear", NULL);
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "b.png"), 16, NULL), 0);
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "b.exr"), 32, NULL), 0);
  oc_image *b = oc_oiio_read(oct_in_dir(dir, "b.png"), NULL);
  oc_image *x = oc_oiio_read(oct_in_dir(dir, "b.exr"), NULL);
  const float *pb = oc_image_cdata(b), *px_ = oc_image_cdata(x);
  double s = 1.055 * pow(0.5, 1 / 2.4) - 0.055;
  ck_assert(fabs(pb[0] - s) < 1e-4);
  ck_assert(fabs(pb[1] - 12.92 * 0.0031308 * 0.5) < 1e-4);
  ck_assert(fabs(pb[3] - 0.5) < 1e-4); /* alpha */
  ck_assert(px_[0] == 0.5f && px_[4] == 0.2f);
  /* the encoded file says so: read back and written again, it is not
  ** encoded twice; the EXR stays linear */
  ck_assert_str_eq(oc_image_meta_get(b, "outcrop:colorspace"), "sRGB");
  ck_assert_str_eq(oc_image_meta_get(x, "outcrop:colorspace"), "linear");
  ck_assert_int_eq(oc_image_write(b, oct_in_dir(dir, "c.png"), 16, NULL), 0);
  oc_image *c = oc_oiio_read(oct_in_dir(dir, "c.png"), NULL);
  ck_assert(fabs(oc_image_cdata(c)[0] - s) < 1e-4);
  oc_image_free(c);
  oc_image_free(a);
  oc_image_free(b);
  oc_image_free(x);
  oc_image_free(img);
  oct_rm_tree(dir);
}
END_TEST

/* ---- exposure and tone --------------------------------------------------- */

/* Narkowicz's (2015) fit as he gives it, in single steps. */
static double aces_fit(double x) {
  double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  double y = (x * (a * x + b)) / (x * (c * x + d) + e);
  return y < 0 ? 0 : y > 1 ? 1 : y;
}

START_TEST(filmic_formula) {
  static const double xs[] = {1e-6, 0.01, 0.05, 0.18, 0.5, 1, 2, 4, 10, 100};
  for (size_t k = 0; k < sizeof xs / sizeof *xs; k++) {
    double f = oc_tone_filmic(xs[k]);
    ck_assert_msg(fabs(f - aces_fit(xs[k])) < 1e-15, "f(%g) = %.17g", xs[k], f);
    if (k) ck_assert(f >= oc_tone_filmic(xs[k - 1])); /* monotonic */
  }
  /* a few values worked by hand: f(1) = 2.54 / 3.16, f(0.18) */
  ck_assert(fabs(oc_tone_filmic(1) - 2.54 / 3.16) < 1e-15);
  ck_assert(fabs(oc_tone_filmic(0.18) - 0.086724 / 0.324932) < 1e-6);
  /* bright albedos no longer clip: 2 stays below white */
  ck_assert(oc_tone_filmic(2) < 0.93);
  ck_assert(oc_tone_filmic(0) == 0 && oc_tone_filmic(-1) == 0);
  ck_assert(oc_tone_filmic(NAN) == 0);
  ck_assert(oc_tone_filmic(INFINITY) == 1 && oc_tone_filmic(1e30) == 1);
  /* the clamp is the writer's old rule */
  ck_assert(oc_tone_apply(OC_TONE_CLAMP, 1.5) == 1);
  ck_assert(oc_tone_apply(OC_TONE_CLAMP, 0.25) == 0.25);
  ck_assert(oc_tone_apply(OC_TONE_CLAMP, NAN) == 0);
  ck_assert(oc_tone_from_name(oc_tone_name(OC_TONE_FILMIC)) == OC_TONE_FILMIC);
  ck_assert(oc_tone_from_name(NULL) == OC_TONE_CLAMP);
}
END_TEST

START_TEST(exposure_and_tone) {
  oc_program *pr = ball_over_ground();
  oc_render_params rp = view(oct_v(10, -14, 9), oct_v(0, 0, 2), 45, 12, 9);
  oc_render_params def = rp;
  ck_assert(def.exposure == 0 && def.tone == OC_TONE_CLAMP && def.aov == 1);
  oc_image *base = oc_render(pr, &rp, NULL);
  rp.exposure = -1.25;
  rp.tone = OC_TONE_FILMIC;
  oc_image *img = oc_render(pr, &rp, NULL);
  ck_assert_ptr_nonnull(base);
  ck_assert_ptr_nonnull(img);
  ck_assert_int_eq(oc_image_channels(img), 12);
  ck_assert_str_eq(oc_image_meta_get(img, "outcrop:tone"), "filmic");
  ck_assert_ptr_null(oc_image_meta_get(base, "outcrop:tone"));
  const float *a = oc_image_cdata(base), *b = oc_image_cdata(img);
  size_t n = 12 * 9;
  for (size_t p = 0; p < n; p++)
    for (int c = 0; c < 12; c++) {
      double want = c < 3 ? (double)a[p * 12 + c] * exp2(-1.25) : a[p * 12 + c];
      ck_assert_msg(fabs(b[p * 12 + c] - want) <= 1e-6 * fabs(want),
                    "pixel %zu channel %d: %g, want %g", p, c, b[p * 12 + c],
                    want);
    }
  /* PNG: the curve, then sRGB; EXR: the linear values as they are */
  const char *dir = oct_tmpdir("tone");
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "f.png"), 16, NULL), 0);
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "f.exr"), 32, NULL), 0);
  oc_image *png = oc_oiio_read(oct_in_dir(dir, "f.png"), NULL);
  oc_image *exr = oc_oiio_read(oct_in_dir(dir, "f.exr"), NULL);
  ck_assert_int_eq(oc_image_channels(png), 4);
  ck_assert_int_eq(oc_image_channels(exr), 12);
  const float *q = oc_image_cdata(png);
  for (size_t p = 0; p < n; p++)
    for (int c = 0; c < 3; c++) {
      double v = aces_fit(b[p * 12 + c]);
      v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
      ck_assert_msg(fabs(q[p * 4 + c] - v) <= 0.6 / 65535, "%g, want %g",
                    q[p * 4 + c], v);
    }
  /* (the EXR stores channels in its own order: compare by name) */
  for (int c = 0; c < 12; c++)
    for (int k = 0; k < 12; k++)
      if (strcmp(oc_image_channel_name(exr, k),
                 oc_image_channel_name(img, c)) == 0)
        for (size_t p = 0; p < n; p++)
          ck_assert(oc_image_cdata(exr)[p * 12 + k] == b[p * 12 + c]);
  oc_image_free(png);
  oc_image_free(exr);
  oc_image_free(img);
  oc_image_free(base);
  oct_rm_tree(dir);
  oc_program_free(pr);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("render");
  TCase *t = tcase_create("tracing");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, sphere_silhouette_and_depth);
  tcase_add_test(t, thin_wall_against_march);
  tcase_add_test(t, ray_step_budget);
  tcase_add_loop_test(t, open_edge_both_tracers, 0, 2);
  tcase_add_test(t, image_against_march);
  tcase_add_test(t, ray_bounds_hold);
  suite_add_tcase(s, t);
  t = tcase_create("shading");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, shadow_under_ball);
  tcase_add_test(t, two_phases_and_albedo);
  tcase_add_test(t, field_palette_and_fog);
  tcase_add_test(t, srgb_on_write);
  tcase_add_test(t, filmic_formula);
  tcase_add_test(t, exposure_and_tone);
  suite_add_tcase(s, t);
  t = tcase_create("running");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, threads_byte_identical);
  tcase_add_test(t, progress_and_cancel);
  tcase_add_test(t, bad_params);
  tcase_add_test(t, thin_terrain_render_warns);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
