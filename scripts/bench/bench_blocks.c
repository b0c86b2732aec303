/*
** bench_blocks.c — fracture tiles (Paris et al. 2020, Table 1): wall
** seconds to build a 20 m tile of each type at the defaults (best of 3, on
** all threads), the tile's statistics against Table 1's, and the seconds
** to polygonize one equidimensional tile at 10 cm cells (200^3) on all
** threads, and the mean cost of a field query on a wall amplified by
** blocks.replicate (one thread).
** Prints `name: value unit` lines; '#' lines are context.
** Parts (OUTCROP_BENCH_ONLY): tiles, mesh, query.
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "benchout.h"
#include "outcrop.h"

#define REPS 3

/* Table 1: #D, #B, #Pi, seconds */
static const double table1[4][4] = {{15, 125, 110, 6.9},
                                    {24, 78, 161, 12.0},
                                    {44, 100, 140, 25.4},
                                    {30, 82, 143, 16.3}};

static double cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int tiles(void) {
  for (int ty = 0; ty < OC_BLOCKS_TABLE1; ty++) {
    oc_btile_params pp;
    oc_btile_defaults((oc_block_type)ty, &pp);
    pp.seed = 2026;
    double best = INFINITY, c = 0;
    oc_btile_stats st;
    for (int r = 0; r < REPS; r++) {
      oc_error err;
      double c0 = cpu(), t0 = omp_get_wtime();
      oc_btile *t = oc_btile_new(&pp, &err);
      double w = omp_get_wtime() - t0;
      c = cpu() - c0;
      if (!t) {
        fprintf(stderr, "bench_blocks: %s\n", err.msg);
        return 1;
      }
      oc_btile_stats_get(t, &st);
      oc_btile_free(t);
      if (w < best) best = w;
    }
    const char *name = oc_block_type_name((oc_block_type)ty);
    printf("# %s: %zu points, %zu edges (%zu cut), %zu thick clusters, %zu "
           "pairs separated; %.3f s CPU; paper %.1f s\n",
           name, st.points, st.edges, st.cut, st.thick, st.separated, c,
           table1[ty][3]);
    printf("blocks.tile_seconds.%s: %.3f s\n", name, best);
    printf("blocks.tile_stats.%s: D %zu B %zu Pi %.1f (Table 1: %g %g %g)\n",
           name, st.fractures, st.blocks, st.points_per_block, table1[ty][0],
           table1[ty][1], table1[ty][2]);
  }
  return 0;
}

static int mesh(void) {
  oc_btile_params pp;
  oc_error err;
  oc_btile_defaults(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  pp.seed = 2026;
  oc_btile *t = oc_btile_new(&pp, &err);
  oc_node *n = t ? oc_btile_node(t, &err) : NULL;
  oc_program *pr = n ? oc_compile(n, NULL, &err) : NULL;
  oc_node_release(n);
  oc_btile_free(t);
  if (!pr) {
    fprintf(stderr, "bench_blocks: %s\n", err.msg);
    return 1;
  }
  oc_polygonize_params mp;
  memset(&mp, 0, sizeof mp);
  mp.box = (oc_aabb){{0, 0, 0}, {20, 20, 20}};
  mp.cell = 0.1;
  double t0 = omp_get_wtime();
  oc_mesh *m = oc_polygonize(pr, &mp, &err);
  double w = omp_get_wtime() - t0;
  if (!m) {
    fprintf(stderr, "bench_blocks: %s\n", err.msg);
    oc_program_free(pr);
    return 1;
  }
  oc_mesh_stats ms;
  oc_mesh_get_stats(m, &ms);
  printf("# mesh: %zu triangles, %zu field calls, %d threads\n", ms.triangles,
         ms.field_calls, omp_get_max_threads());
  printf("blocks.mesh_tile_seconds_2t: %.2f s\n", w);
  oc_mesh_free(m);
  oc_program_free(pr);
  return 0;
}

/* A 100 x 100 x 30 m box (falloff 8) with equidimensional blocks on its
** walls: the mean time of oc_program_eval at points of the slab x in
** [-4, 1] along the wall x = 0, one thread. */
static int query(void) {
  oc_btile_params pp;
  oc_error err;
  oc_btile_defaults(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  pp.seed = 2026;
  oc_btile *t = oc_btile_new(&pp, &err);
  oc_node *box =
      oc_box((oc_vec3){0, 0, 0}, (oc_vec3){100, 100, 30}, 8, 1, &err);
  oc_replicate_tile rt = {t, 0, 0};
  oc_replicate_params rp;
  oc_replicate_defaults(&rp);
  rp.tiles = &rt;
  rp.ntiles = 1;
  rp.slope = 0.5;
  rp.va = -2;
  rp.vb = 2;
  oc_node *rep = t && box ? oc_blocks_replicate(box, &rp, &err) : NULL;
  oc_program *pr = rep ? oc_compile(rep, NULL, &err) : NULL;
  size_t ni = 0;
  if (rep) oc_blocks_instances(rep, &ni);
  oc_node_release(rep);
  oc_node_release(box);
  oc_btile_free(t);
  if (!pr) {
    fprintf(stderr, "bench_blocks: %s\n", err.msg);
    return 1;
  }
  enum { N = 1000000 };
  static oc_vec3 pts[N];
  uint64_t z = 2026;
  for (int i = 0; i < N; i++) {
    double u[3];
    for (int a = 0; a < 3; a++) {
      z = z * 6364136223846793005ull + 1442695040888963407ull;
      u[a] = (double)(z >> 11) * 0x1.0p-53;
    }
    pts[i] = (oc_vec3){-4 + 5 * u[0], 100 * u[1], 30 * u[2]};
  }
  double sum = 0, t0 = cpu();
  for (int i = 0; i < N; i++)
    sum += oc_program_eval(pr, pts[i]);
  double c = cpu() - t0;
  printf("# query: %zu instances on the walls, mean f %.4f over %d points\n",
         ni, sum / N, N);
  printf("blocks.query_ns: %.0f ns\n", 1e9 * c / N);
  oc_program_free(pr);
  return 0;
}

int main(void) {
  int rc = 0;
  if (bench_wanted("tiles")) rc |= tiles();
  if (bench_wanted("mesh")) rc |= mesh();
  if (bench_wanted("query")) rc |= query();
  return rc;
}
