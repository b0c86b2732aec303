/*
** bench_blocks.c — fracture tiles (Paris et al. 2020, Table 1): wall
** seconds to build a 20 m tile of each type at the defaults (best of 3, on
** all threads), the tile's statistics against Table 1's, and the seconds
** to polygonize one equidimensional tile at 10 cm cells (200^3) on all
** threads, and the mean cost of a field query on a wall amplified by
** blocks.replicate (one thread).
** Prints `name: value unit` lines; '#' lines are context.
** Table 2's scenes (stand-ins of primitives): instances and memory, and
** the sea cliff meshed at 10 cm.
** Parts (OUTCROP_BENCH_ONLY): tiles, mesh, query, scenes, cliffmesh.
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

/* Blocks of the tiles rt over the terrain's steep walls (slope 0.5,
** distance -2 .. 2): the replication node, or NULL with err. */
static oc_node *on_walls(oc_node *ter, const oc_replicate_tile *rt, size_t n,
                         oc_node *geo, oc_error *err) {
  oc_replicate_params rp;
  oc_replicate_defaults(&rp);
  rp.tiles = rt;
  rp.ntiles = n;
  rp.geology = geo;
  rp.slope = 0.5;
  rp.va = -2;
  rp.vb = 2;
  return ter ? oc_blocks_replicate(ter, &rp, err) : NULL;
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
  oc_node *rep = t ? on_walls(box, &rt, 1, NULL, &err) : NULL;
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

/* ---- Table 2's scenes ---------------------------------------------------
** Stand-ins made of primitives (falloff 8 m, so the distance estimate
** holds over a block's size), amplified by default tiles of seed 2026
** with slope 0.5 and distance {-2, 2}:
**  - sea cliff, 100 x 100 m: a plateau 60 m high (from -20) ending in a
**    straight wall along y = 60 (sea in front), equidimensional blocks;
**  - canyon, 100 x 50 m: a slot 14 m wide and 60 m deep along x (two
**    plateaus and a floor), with equidimensional blocks below z = 20 and
**    tabular ones above (by a geology: 1 below 20 m, 0.5 above);
** the terrains reach past the scenes, and a geology of value 0 outside
** their footprints keeps the blocks of the walls beyond out;
**  - sea spire, 150 x 150 m: a cone 80 m high, 30 m in radius, standing
**    in the sea, rhombohedral blocks. */
typedef struct scene {
  const char *name;
  double R, mb; /* Table 2 */
} scene;

/* The footprint 0 .. x1, 0 .. y1 between z0 and z1 as a geology of
** value e (0 outside): blocks outside the scene's footprint are not
** counted. */
static oc_node *foot(double x1, double y1, double z0, double z1, double e,
                     oc_error *err) {
  return oc_box((oc_vec3){0, 0, z0}, (oc_vec3){x1, y1, z1}, 0.01, e, err);
}

static oc_node *scene_terrain(int k, oc_node **geo, oc_error *err) {
  *geo = NULL;
  if (k == 0) {
    *geo = foot(100, 100, -100, 100, 1, err);
    return oc_box((oc_vec3){-40, -40, -20}, (oc_vec3){140, 60, 40}, 8, 1, err);
  }
  if (k == 1) {
    /* two plateaus and the floor between them */
    oc_node *w[3] = {
        oc_box((oc_vec3){-40, -40, -20}, (oc_vec3){140, 18, 60}, 8, 1, err),
        oc_box((oc_vec3){-40, 32, -20}, (oc_vec3){140, 90, 60}, 8, 1, err),
        oc_box((oc_vec3){-40, -40, -20}, (oc_vec3){140, 90, 0}, 8, 1, err)};
    oc_node *d = w[0] && w[1] && w[2] ? oc_union(w, 3, err) : NULL;
    for (int i = 0; i < 3; i++)
      oc_node_release(w[i]);
    /* 1 below 20 m (equidimensional), 0.5 above (tabular) */
    oc_node *lo = foot(100, 50, -100, 20, 1, err);
    oc_node *hi = foot(100, 50, 20, 100, 0.5, err);
    oc_node *kids[2] = {lo, hi};
    *geo = lo && hi ? oc_blend(kids, 2, err) : NULL;
    oc_node_release(lo);
    oc_node_release(hi);
    return d;
  }
  return oc_cone((oc_vec3){75, 75, -10}, (oc_vec3){75, 75, 80}, 30, 8, 1, err);
}

static oc_btile *scene_tile(oc_block_type ty, oc_error *err) {
  oc_btile_params pp;
  oc_btile_defaults(ty, &pp);
  pp.seed = 2026;
  return oc_btile_new(&pp, err);
}

static int scenes(void) {
  static const scene sc[3] = {{"sea_cliff", 959, 0.57},
                              {"canyon", 1041, 0.54},
                              {"sea_spire", 1680, 0.53}};
  oc_error err;
  oc_btile *eq = scene_tile(OC_BLOCKS_EQUIDIMENSIONAL, &err);
  oc_btile *tab = eq ? scene_tile(OC_BLOCKS_TABULAR, &err) : NULL;
  oc_btile *rh = tab ? scene_tile(OC_BLOCKS_RHOMBOHEDRAL, &err) : NULL;
  int rc = !rh;
  for (int k = 0; k < 3 && !rc; k++) {
    oc_node *geo, *ter = scene_terrain(k, &geo, &err);
    oc_replicate_tile rt[2] = {{k == 2 ? rh : eq, 0.9, 2}, {tab, 0.4, 0.6}};
    double c0 = cpu();
    oc_node *rep = on_walls(ter, rt, k == 1 ? 2 : 1, geo, &err);
    double c = cpu() - c0;
    size_t ni = 0, bytes = 0;
    if (rep) {
      oc_blocks_instances(rep, &ni);
      oc_blocks_memory(rep, &bytes);
    } else {
      fprintf(stderr, "bench_blocks: %s\n", err.msg);
      rc = 1;
    }
    printf("# scene %s: replicate built in %.2f s CPU\n", sc[k].name, c);
    printf("blocks.scene_instances.%s: %zu (Table 2: %g)\n", sc[k].name, ni,
           sc[k].R);
    printf("blocks.scene_mb.%s: %.3f MB (Table 2: %g)\n", sc[k].name,
           bytes / 1e6, sc[k].mb);
    if (k == 0) { /* the names without a scene: the sea cliff */
      printf("blocks.scene_instances: %zu (sea cliff; Table 2: %g)\n", ni,
             sc[k].R);
      printf("blocks.scene_mb: %.3f MB (sea cliff; Table 2: %g)\n", bytes / 1e6,
             sc[k].mb);
    }
    oc_node_release(rep);
    oc_node_release(ter);
    oc_node_release(geo);
  }
  if (rc) fprintf(stderr, "bench_blocks: %s\n", err.msg);
  oc_btile_free(eq);
  oc_btile_free(tab);
  oc_btile_free(rh);
  return rc;
}

/* The sea cliff meshed at 10 cm over its 100 x 100 m (z -10 .. 50) on
** all threads: wall and CPU seconds. */
static int cliff_mesh(void) {
  oc_error err;
  oc_node *geo, *ter = scene_terrain(0, &geo, &err);
  oc_btile *eq = ter ? scene_tile(OC_BLOCKS_EQUIDIMENSIONAL, &err) : NULL;
  oc_replicate_tile rt = {eq, 0.9, 2};
  oc_node *rep = eq ? on_walls(ter, &rt, 1, geo, &err) : NULL;
  oc_program *pr = rep ? oc_compile(rep, NULL, &err) : NULL;
  oc_node_release(rep);
  oc_node_release(ter);
  oc_node_release(geo);
  oc_btile_free(eq);
  if (!pr) {
    fprintf(stderr, "bench_blocks: %s\n", err.msg);
    return 1;
  }
  oc_polygonize_params mp;
  memset(&mp, 0, sizeof mp);
  mp.box = (oc_aabb){{0, 0, -10}, {100, 100, 50}};
  mp.cell = 0.1;
  double c0 = cpu(), t0 = omp_get_wtime();
  oc_mesh *m = oc_polygonize(pr, &mp, &err);
  double w = omp_get_wtime() - t0, c = cpu() - c0;
  oc_program_free(pr);
  if (!m) {
    fprintf(stderr, "bench_blocks: %s\n", err.msg);
    return 1;
  }
  oc_mesh_stats ms;
  oc_mesh_get_stats(m, &ms);
  printf("# cliff mesh: %zu triangles, %zu field calls, %.1f s CPU, %d "
         "threads\n",
         ms.triangles, ms.field_calls, c, omp_get_max_threads());
  printf("blocks.cliff_mesh_seconds_2t: %.2f s\n", w);
  oc_mesh_free(m);
  return 0;
}

int main(void) {
  int rc = 0;
  if (bench_wanted("tiles")) rc |= tiles();
  if (bench_wanted("mesh")) rc |= mesh();
  if (bench_wanted("query")) rc |= query();
  if (bench_wanted("scenes")) rc |= scenes();
  if (bench_wanted("cliffmesh")) rc |= cliff_mesh();
  return rc;
}
