/*
** bench_layers_rocks.c — rock piles (Peytavie et al. 2009, section 5):
** making a tile of rocks, and placing rocks over material stacks.
**
**   layers.rocks_tile_seconds      a tile of about 50 rocks (size 6.2,
**                                  radius 1.5: Voronoi cells, contacts,
**                                  erosion, hulls); the paper: 19-30 s
**   layers.rocks_instance_seconds  the rocks of that tile placed over
**                                  200 x 200 stacks of 1 m with a 3 m rocks
**                                  layer on 100 x 98 of them (about 6 100
**                                  instances, the paper's 6 113 took
**                                  0.9 s): presence of every site, culled
**                                  below twice the largest rock radius,
**                                  and the instances' grid
**
** Both single-threaded; best of 3 wall times, CPU seconds as context.
** Prints `name: value unit` lines; '#' lines are context.
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <time.h>

#include "benchout.h"
#include "outcrop.h"

int main(void) {
  oc_error err;
  oc_rocks_params rp;
  oc_rocks_defaults(&rp);
  rp.size = 6.2;
  rp.radius = 1.5;
  rp.seed = 1;
  oc_btile *t = NULL;
  double best = INFINITY, cpu = INFINITY;
  for (int r = 0; r < 3; r++) {
    oc_btile_free(t);
    clock_t c0 = clock();
    double t0 = omp_get_wtime();
    t = oc_rocks_tile(&rp, &err);
    best = fmin(best, omp_get_wtime() - t0);
    cpu = fmin(cpu, (double)(clock() - c0) / CLOCKS_PER_SEC);
    if (!t) {
      fprintf(stderr, "bench_layers_rocks: %s\n", err.msg);
      return 1;
    }
  }
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  if (bench_wanted("tile")) {
    printf("# a tile of %zu rocks (size %g, radius %g): %.3f s of CPU, "
           "largest reach %.2f m\n",
           st.blocks, rp.size, rp.radius, cpu, oc_rocks_reach(t));
    printf("layers.rocks_tile_seconds: %.3f s\n", best);
  }
  if (bench_wanted("instance")) {
    oc_stacks *s = oc_stacks_new(200, 200, 1, 0, 0, 0, &err);
    uint8_t m[2] = {OC_MAT_BEDROCK, OC_MAT_ROCKS};
    double th[2] = {10, 3};
    for (int j = 0; j < 200 && s; j++)
      for (int i = 0; i < 200; i++)
        oc_stacks_set(s, i, j, m, th, i < 100 && j < 98 ? 2 : 1, &err);
    size_t n = 0;
    best = cpu = INFINITY;
    for (int r = 0; r < 3 && s; r++) {
      oc_stacks_rocks_params p = {NAN, 0};
      clock_t c0 = clock();
      double t0 = omp_get_wtime();
      oc_node *node = oc_stacks_rocks(s, t, NULL, &p, &err);
      best = fmin(best, omp_get_wtime() - t0);
      cpu = fmin(cpu, (double)(clock() - c0) / CLOCKS_PER_SEC);
      if (!node) {
        fprintf(stderr, "bench_layers_rocks: %s\n", err.msg);
        return 1;
      }
      oc_blocks_instances(node, &n);
      oc_node_release(node);
    }
    printf("# %zu rocks placed over 200 x 200 stacks: %.3f s of CPU\n", n, cpu);
    printf("layers.rocks_instance_seconds: %.3f s\n", best);
    oc_stacks_free(s);
  }
  oc_btile_free(t);
  return 0;
}
