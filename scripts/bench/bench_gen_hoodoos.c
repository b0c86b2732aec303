/*
** bench_gen_hoodoos.c — the hoodoo generator on a field of about 500
** hoodoos (Paris et al. 2019, figure 19: 0.35 x 0.35 km): placement (slope,
** drainage, Poisson disks), derivation and the node tree, then compiling
** it. Prints gen.hoodoos_seconds (generation, best of 3), the counts, and
** the compiled tree's size.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "outcrop.h"

int main(void) {
  oc_error err = {OC_OK, ""};
  oc_heightfield_grid g = {257, 257, 1.4, 0, 0};
  oc_noise nz = {120, 60, 0, 6, 3};
  oc_progress none = {NULL, NULL};
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, none, &err);
  oc_noise sn = {6, 0.9, 0.05, 2, 5};
  oc_node *geo = hf ? oc_strata(&sn, &err) : NULL;
  if (!geo) {
    fprintf(stderr, "bench_gen_hoodoos: %s\n", err.msg);
    return 1;
  }
  oc_gen_hoodoos_params p;
  oc_gen_hoodoos_defaults(&p, hf);
  p.geology = geo;
  p.no_terrain = 1; /* the hoodoos alone, as measured before */
  p.radius = 6.5;
  p.seed = 1;
  double best = 1e30;
  oc_gen_hoodoos_stats st;
  oc_node *n = NULL;
  for (int r = 0; r < 3; r++) {
    if (n) oc_node_release(n);
    double t0 = omp_get_wtime();
    n = oc_generate_hoodoos(&p, &st, &err);
    double t = omp_get_wtime() - t0;
    if (!n) {
      fprintf(stderr, "bench_gen_hoodoos: %s\n", err.msg);
      return 1;
    }
    if (t < best) best = t;
  }
  double t0 = omp_get_wtime();
  oc_program *pg = oc_compile(n, NULL, &err);
  double tc = omp_get_wtime() - t0;
  oc_program_stats ps = {0};
  if (pg) oc_program_get_stats(pg, &ps);
  printf("# %d threads; 360 x 360 m grid of 257^2, radius %.1f m, max_depth "
         "%d: %zu blocks, %zu cones, %zu caprocks\n",
         omp_get_max_threads(), p.radius, p.max_depth, st.blocks, st.cones,
         st.boxes);
  printf("gen.hoodoos_seconds: %.4f s\n", best);
  printf("gen.hoodoos_count: %zu hoodoos\n", st.hoodoos);
  printf("gen.hoodoos_primitives: %zu primitives\n", st.primitives);
  printf("gen.hoodoos_compile_seconds: %.4f s\n", tc);
  printf("gen.hoodoos_mb: %.2f MB\n", (double)ps.bytes / 1e6);
  oc_program_free(pg);
  oc_node_release(n);
  oc_node_release(geo);
  oc_heightfield_release(hf);
  return 0;
}
