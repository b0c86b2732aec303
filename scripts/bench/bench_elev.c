/*
** bench_elev.c — rendering elevation surfaces z = f(x, y) (issue 14):
** a 2 x 2 km fBm heightfield (1025 x 1025 samples, 8 octaves, 300 m of
** relief) at 1920 x 1080 on 2 threads, shaded with shadows and AO.
** Prints the seconds of the whole render, the height calls per pixel of
** the primary rays (normals included, as Génevaux et al. 2015 count
** theirs), and the ratio of plain sphere tracing's calls to the
** accelerated tracer's on the same view (geometry pass only, every
** pixel). Prints `name: value unit` lines; '#' lines are context.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "outcrop.h"

static void die(const char *what, const oc_error *err) {
  fprintf(stderr, "bench_elev: %s: %s\n", what, err->msg);
  exit(1);
}

/* Height calls of the primary rays of a geometry image, and its hits. */
static double primary_calls(const oc_image *g, double *hits) {
  size_t n = (size_t)oc_image_width(g) * oc_image_height(g);
  const float *d = oc_image_cdata(g);
  double ev = 0;
  *hits = 0;
  for (size_t k = 0; k < n; k++) {
    ev += d[k * OC_RG_COUNT + OC_RG_EVALS];
    *hits += d[k * OC_RG_COUNT + OC_RG_HIT];
  }
  return ev;
}

int main(void) {
  oc_error err;
  oc_heightfield_grid grid = {1025, 1025, 2, -1024, -1024};
  oc_noise nz = {600, 300, 0, 8, 14};
  oc_progress none = {0};
  oc_heightfield *hf = oc_heightfield_fbm(&grid, &nz, none, &err);
  if (!hf) die("fbm", &err);
  oc_elevation src;
  if (oc_heightfield_elevation(hf, &src, &err)) die("source", &err);
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = (oc_vec3){-1500, -1700, 900};
  rp.camera.target = (oc_vec3){0, 0, 50};
  rp.camera.fov = 40;
  rp.width = 1920;
  rp.height = 1080;
  omp_set_num_threads(2);
  oc_render_stats st;
  double t0 = omp_get_wtime();
  clock_t c0 = clock();
  oc_image *img = oc_render_elevation(&src, &rp, &st, &err);
  double secs = omp_get_wtime() - t0;
  double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (!img) die("render", &err);
  oc_image_free(img);
  double calls[2], hits[2], gsecs[2];
  for (int m = 0; m < 2; m++) {
    rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
    t0 = omp_get_wtime();
    oc_image *g = oc_render_elevation_geometry(&src, &rp, &err);
    gsecs[m] = omp_get_wtime() - t0;
    if (!g) die("geometry", &err);
    calls[m] = primary_calls(g, &hits[m]);
    oc_image_free(g);
  }
  double n = (double)rp.width * rp.height;
  printf("# fBm heightfield 1025 x 1025 (2 km, 8 octaves), 1920 x 1080, "
         "%.0f%% of pixels hit\n",
         100 * st.hits / n);
  /* on a shared machine the wall time is what the other processes left */
  printf("# the render took %.2f s of CPU over both threads\n", cpu);
  printf("# primary rays alone: accelerated %.2f s, sphere %.2f s; "
         "%.1f calls per pixel with shadows and AO\n",
         gsecs[0], gsecs[1], st.calls_total_per_pixel);
  printf("# sphere tracing: %.1f calls per pixel (hits %.0f / %.0f)\n",
         calls[1] / n, hits[0], hits[1]);
  printf("elev.render_hd_seconds_2t.hf: %.2f s\n", secs);
  printf("elev.calls_per_pixel.hf: %.1f calls\n", st.calls_per_pixel);
  printf("elev.accel_ratio: %.2f x\n", calls[1] / calls[0]);
  src.release(src.ud);
  oc_heightfield_release(hf);
  return 0;
}
