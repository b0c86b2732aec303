/*
** bench_render.c — sphere-tracing speed (issue 4).
**
** 1. A terrain scene of 10 001 primitives (a ground plane blended with
**    10 000 boulders and hollows, radius 3..10 m, over 1 km^2) at 1920 x 1080:
*seconds for the
**    shaded image with shadows and AO on 2 threads, field evaluations per
**    pixel of the segment tracer, and the ratio to plain sphere tracing
**    with the global Lipschitz bound. Plain tracing is far too slow for
**    every pixel, so both tracers are compared on the same subsample of
**    primary rays (every STRIDE-th pixel in each direction), through the
**    same tracer code and tolerance as the renderer.
** 2. The blob tree of Galin et al. 2020: 1 000 points (radius 2.25,
**    energy 1, T = 0.5) spread in a 40^3 box, 500 x 500, seen whole:
**    mean steps per pixel of primary rays (evaluations before the hit is
**    located), segment tracer on every pixel, plain sphere tracing on a
**    subsample.
** Prints `name: value unit` lines; '#' lines are context. The parts
** (hd, blob1000) can be chosen and the HD image kept
** (scripts/bench/benchout.h).
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "benchout.h"
#include "core/rng.h"
#include "outcrop.h"
#include "render/trace.h"

#define STRIDE 8

static void die(const char *what, const oc_error *err) {
  fprintf(stderr, "bench_render: %s: %s\n", what, err->msg);
  exit(1);
}

static oc_program *terrain(void) {
  oc_error err;
  enum { N = 10000 };
  oc_node **k = malloc((N + 1) * sizeof *k);
  k[0] = oc_plane((oc_vec3){0, 0, 0}, (oc_vec3){0, 0, 1}, 4, 1, &err);
  oc_rng r = oc_rng_stream(2024, 4);
  for (int i = 1; i <= N; i++) {
    oc_vec3 c = {oc_rng_range(&r, -500, 500), oc_rng_range(&r, -500, 500),
                 oc_rng_range(&r, -4, 3)};
    double R = oc_rng_range(&r, 3, 10);
    double E = oc_rng_uniform(&r) < 0.2 ? -0.7 : oc_rng_range(&r, 0.6, 1.2);
    k[i] = oc_point(c, R, E, &err);
    if (!k[i]) die("point", &err);
  }
  oc_node *b = oc_blend(k, N + 1, &err);
  if (!b) die("blend", &err);
  for (int i = 0; i <= N; i++)
    oc_node_release(k[i]);
  free(k);
  oc_program *p = oc_compile(b, NULL, &err);
  if (!p) die("compile", &err);
  oc_node_release(b);
  return p;
}

static oc_program *blobs(void) {
  oc_error err;
  enum { N = 1000 };
  oc_node *k[N];
  oc_rng r = oc_rng_stream(2020, 1000);
  for (int i = 0; i < N; i++) {
    oc_vec3 c = {oc_rng_range(&r, -20, 20), oc_rng_range(&r, -20, 20),
                 oc_rng_range(&r, -20, 20)};
    k[i] = oc_point(c, 2.25, 1, &err);
  }
  oc_node *b = oc_blend(k, N, &err);
  if (!b) die("blend", &err);
  for (int i = 0; i < N; i++)
    oc_node_release(k[i]);
  oc_compile_options o = {0.5, 0};
  oc_program *p = oc_compile(b, &o, &err);
  if (!p) die("compile", &err);
  oc_node_release(b);
  return p;
}

/* The renderer's primary ray through pixel (i, j). */
static oc_vec3 ray(const oc_render_params *rp, int i, int j) {
  const oc_camera *c = &rp->camera;
  oc_vec3 w = {c->target.x - c->eye.x, c->target.y - c->eye.y,
               c->target.z - c->eye.z};
  double lw = sqrt(w.x * w.x + w.y * w.y + w.z * w.z);
  w = (oc_vec3){w.x / lw, w.y / lw, w.z / lw};
  oc_vec3 r = {w.y * c->up.z - w.z * c->up.y, w.z * c->up.x - w.x * c->up.z,
               w.x * c->up.y - w.y * c->up.x};
  double lr = sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
  r = (oc_vec3){r.x / lr, r.y / lr, r.z / lr};
  oc_vec3 u = {r.y * w.z - r.z * w.y, r.z * w.x - r.x * w.z,
               r.x * w.y - r.y * w.x};
  double th = tan(c->fov * 3.14159265358979323846 / 360);
  double x = (2 * (i + 0.5) / rp->width - 1) * th * rp->width / rp->height;
  double y = (1 - 2 * (j + 0.5) / rp->height) * th;
  oc_vec3 d = {w.x + x * r.x + y * u.x, w.y + x * r.y + y * u.y,
               w.z + x * r.z + y * u.z};
  double ld = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  return (oc_vec3){d.x / ld, d.y / ld, d.z / ld};
}

/* Mean evaluations per primary ray over every stride-th pixel; *hits
** gets the fraction that hit. */
static double sampled(const oc_program *p, const oc_render_params *rp,
                      oc_render_tracer mode, int stride, double far,
                      double *hits) {
  oc_tracer tr;
  double pixel =
      2 * tan(rp->camera.fov * 3.14159265358979323846 / 360) / rp->height;
  oc_vec3 d0 = {rp->camera.target.x - rp->camera.eye.x,
                rp->camera.target.y - rp->camera.eye.y,
                rp->camera.target.z - rp->camera.eye.z};
  double scale = sqrt(d0.x * d0.x + d0.y * d0.y + d0.z * d0.z);
  oc_tracer_init(&tr, p, oc_program_threshold(p), mode, 0.25 * pixel,
                 1e-7 * scale);
  int nx = (rp->width + stride - 1) / stride;
  int ny = (rp->height + stride - 1) / stride;
  double ev = 0, nh = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : ev, nh)
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      double t, e = 0;
      nh += oc_trace(&tr, rp->camera.eye, ray(rp, i * stride, j * stride), 0,
                     far, 0, &t, &e);
      ev += e;
    }
  *hits = nh / ((double)nx * ny);
  return ev / ((double)nx * ny);
}

static void hd(void) {
  oc_program *p = terrain();
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = (oc_vec3){-620, -680, 260};
  rp.camera.target = (oc_vec3){0, 0, 0};
  rp.camera.fov = 45;
  rp.width = 1920;
  rp.height = 1080;
  omp_set_num_threads(2);
  oc_error err;
  double t0 = omp_get_wtime();
  oc_image *img = oc_render(p, &rp, &err);
  double secs = omp_get_wtime() - t0;
  if (!img) die("render", &err);
  bench_keep_image("bench_render", "hd.exr", img);
  oc_image_free(img);
  t0 = omp_get_wtime();
  oc_image *g = oc_render_geometry(p, &rp, &err);
  double gsecs = omp_get_wtime() - t0;
  if (!g) die("geometry", &err);
  const float *d = oc_image_cdata(g);
  size_t n = (size_t)rp.width * rp.height;
  double ev = 0, hits = 0;
  for (size_t k = 0; k < n; k++) {
    ev += d[k * OC_RG_COUNT + OC_RG_EVALS];
    hits += d[k * OC_RG_COUNT + OC_RG_HIT];
  }
  oc_image_free(g);
  double far = 1000 * sqrt(620.0 * 620 + 680 * 680 + 260 * 260);
  double hs, hp;
  double seg = sampled(p, &rp, OC_TRACE_SEGMENT, STRIDE, far, &hs);
  t0 = omp_get_wtime();
  double pl = sampled(p, &rp, OC_TRACE_SPHERE, STRIDE, far, &hp);
  double psecs = omp_get_wtime() - t0;
  printf("# terrain: ground plane + 10000 points over 1 km^2, 1920 x 1080, "
         "%.0f%% of pixels hit\n",
         100 * hits / n);
  printf("# primary rays alone: %.2f s; global Lipschitz bound %.3g\n", gsecs,
         oc_program_lipschitz(p));
  printf("# on every %dth pixel each way: segment %.1f, sphere %.1f "
         "evaluations per ray (hits %.3f / %.3f; sphere tracing took %.1f "
         "s)\n",
         STRIDE, seg, pl, hs, hp, psecs);
  printf("render.hd_seconds_2t: %.2f s\n", secs);
  printf("render.calls_per_pixel: %.1f calls\n", ev / n);
  printf("render.accel_call_ratio: %.1f x\n", pl / seg);
  oc_program_free(p);
}

static void blob1000(void) {
  oc_program *p = blobs();
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = (oc_vec3){60, -75, 45};
  rp.camera.target = (oc_vec3){0, 0, 0};
  rp.camera.fov = 40;
  rp.width = 500;
  rp.height = 500;
  omp_set_num_threads(2);
  oc_error err;
  oc_image *g = oc_render_geometry(p, &rp, &err);
  if (!g) die("geometry", &err);
  const float *d = oc_image_cdata(g);
  size_t n = (size_t)rp.width * rp.height;
  double ev = 0, hits = 0;
  for (size_t k = 0; k < n; k++) {
    ev += d[k * OC_RG_COUNT + OC_RG_EVALS];
    hits += d[k * OC_RG_COUNT + OC_RG_HIT];
  }
  oc_image_free(g);
  /* steps: evaluations of the march, without the gradient at the hit */
  double hs, hp;
  double seg = sampled(p, &rp, OC_TRACE_SEGMENT, 1, INFINITY, &hs);
  double pl = sampled(p, &rp, OC_TRACE_SPHERE, 25, INFINITY, &hp);
  printf("# blob1000: 1000 points R 2.25 in 40^3, 500 x 500, %.0f%% of "
         "pixels hit; renderer's evals per pixel %.2f (with bisection and "
         "normal)\n",
         100 * hits / n, ev / n);
  printf("# segment tracing steps include the bisection locating each hit; "
         "sphere tracing on every 25th pixel each way\n");
  printf("render.blob1000_steps_per_pixel: %.2f steps (sphere tracing: %.0f "
         "steps)\n",
         seg, pl);
  oc_program_free(p);
}

int main(void) {
  if (bench_wanted("hd")) hd();
  if (bench_wanted("blob1000")) blob1000();
  return 0;
}
