/*
** bench_hf.c — heightfield flow analysis speed (issue 5).
**
** hf.flow_4k_seconds_2t: filling, drainage and stream power (one
** oc_heightfield_stream_power call on the raw grid) of a 4096 x 4096 fBm grid
** on
** 2 threads; target <= 15 s. The grid is made here with lib/core/noise.h
** so the bench depends on nothing but the analysis. Also reports, as
** context, the phases alone and the 1-thread time, and checks that both
** thread counts give the same bytes.
** Prints `name: value unit` lines; '#' lines are context.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/noise.h"
#include "outcrop.h"

#define N 4096
#define CELL 2.0

static void *must(void *p, const oc_error *err) {
  if (!p) {
    fprintf(stderr, "bench_hf: %s\n", err->msg);
    exit(1);
  }
  return p;
}

/* fBm of 8 octaves, 2 km features, 400 m relief: many depressions. */
static oc_heightfield *terrain(void) {
  oc_error err;
  oc_heightfield *hf =
      must(oc_heightfield_new(N, N, CELL, 0, 0, NULL, &err), &err);
  float *z = oc_heightfield_samples_mut(hf);
#pragma omp parallel for schedule(static)
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      oc_vec3 p = {i * CELL / 2000, j * CELL / 2000, 0};
      z[(size_t)j * N + i] = (float)(400 * oc_turb3(7, 8, p, NULL));
    }
  return hf;
}

static double timed_power(const oc_heightfield *hf, int threads,
                          oc_heightfield **out) {
  oc_error err;
  omp_set_num_threads(threads);
  double t0 = omp_get_wtime();
  *out = must(oc_heightfield_stream_power(hf, NULL, &err), &err);
  return omp_get_wtime() - t0;
}

int main(void) {
  oc_error err;
  oc_heightfield *hf = terrain();
  omp_set_num_threads(2);
  double t0 = omp_get_wtime();
  oc_heightfield *f =
      must(oc_heightfield_fill(hf, (oc_progress){0}, &err), &err);
  double t_fill = omp_get_wtime() - t0;
  oc_heightfield_flow_params fp = {0, 1, {0}};
  t0 = omp_get_wtime();
  oc_heightfield *a = must(oc_heightfield_drainage(f, &fp, &err), &err);
  double t_drain = omp_get_wtime() - t0;
  printf("# %d x %d fBm: fill %.2f s (sequential), drainage %.2f s "
         "(2 threads)\n",
         N, N, t_fill, t_drain);
  oc_heightfield *p2, *p1;
  double s2 = timed_power(hf, 2, &p2);
  double s1 = timed_power(hf, 1, &p1);
  int same = memcmp(oc_heightfield_samples(p1), oc_heightfield_samples(p2),
                    (size_t)N * N * sizeof(float)) == 0;
  printf("# 1 thread: %.2f s; 1 and 2 threads give %s\n", s1,
         same ? "the same bytes" : "DIFFERENT BYTES");
  printf("hf.flow_4k_seconds_2t: %.2f s\n", s2);
  oc_heightfield_release(p1);
  oc_heightfield_release(p2);
  oc_heightfield_release(a);
  oc_heightfield_release(f);
  oc_heightfield_release(hf);
  return same ? 0 : 1;
}
