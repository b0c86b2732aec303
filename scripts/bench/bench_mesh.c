/*
** bench_mesh.c — polygonization speed (issue 3).
**
** 1. A terrain-like scene: an implicitized fBm heightfield as the ground,
**    with about 2 % of its area covered by 3D features (carved spheres,
**    boulders, a perturbed arch), meshed over the same box and cell on
**    the full grid (root finding on every edge) and with surface bounds
**    and direct elevation extraction (Paris et al. 2019's t0 and t); the meshes
**    must have the same triangles on the same grid edges. Surface bounds
**    with root finding everywhere, for context, must give the full grid's
**    mesh to the bit.
** 2. The same kind of scene over 2000 x 2000 columns, a band 64 cells
**    thick, 2 threads: seconds and peak memory (in a child process, so the
**    peak is that run's own).
** 3. 1000 spheres blended with a ground plane at cell 0.25.
** 4. A 2048 x 2048 fBm DEM implicitized and meshed at its cell, with
**    direct elevation extraction and without (issue 5).
** Prints `name: value unit` lines; '#' lines are context. The parts
** (band, speedup, spheres1000, direct) can be chosen and their meshes
** kept (scripts/bench/benchout.h).
*/
#define _GNU_SOURCE
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/rng.h"
#include "benchout.h"
#include "meshcmp.h"
#include "outcrop.h"

static oc_node *must(oc_node *n, const oc_error *err) {
  if (!n) {
    fprintf(stderr, "bench_mesh: %s\n", err->msg);
    exit(1);
  }
  return n;
}

/* An fBm grid of n x n samples at cell 1 from the origin, heights
** around 0 (amplitude a), implicitized. *hf gets the grid (a reference). */
static oc_node *fbm_terrain(int n, double a, uint64_t seed,
                            oc_heightfield **hf) {
  oc_error err;
  oc_heightfield_grid g = {n, n, 1, 0, 0};
  oc_noise nz = {150, a, -a * 0.75, 5, seed};
  *hf = oc_heightfield_fbm(&g, &nz, (oc_progress){0}, &err);
  if (!*hf) {
    fprintf(stderr, "bench_mesh: %s\n", err.msg);
    exit(1);
  }
  oc_elevation src;
  if (oc_heightfield_elevation(*hf, &src, &err)) {
    fprintf(stderr, "bench_mesh: %s\n", err.msg);
    exit(1);
  }
  oc_terrain_params tp = {.falloff = 4, .transition = 1};
  oc_node *t = must(oc_terrain(&src, &tp, &err), &err);
  src.release(src.ud);
  return t;
}

/* Ground over [0, w] x [0, w] (a plane at z = 0, or the implicitized
** fBm grid hf) with 3D features covering ~2 % of its area (the issue's
** scene): carved spheres, rocks, and a perturbed arch near the middle,
** placed on the ground. */
static oc_node *terrain(double w, uint64_t seed, oc_node *ground,
                        const oc_heightfield *hf) {
  oc_error err;
  oc_rng r = oc_rng_stream(seed, 1);
  size_t cap = 64 + (size_t)(w * w * 0.02 / 20), n = 0;
  oc_node **k = malloc(cap * sizeof *k);
  if (ground) {
    oc_node_retain(ground);
    k[n++] = ground;
  } else {
    k[n++] = must(oc_plane((oc_vec3){0, 0, 0}, (oc_vec3){0, 0, 1}, 4, 1, &err),
                  &err);
  }
#define GROUND(x, y) (hf ? oc_heightfield_height(hf, (x), (y), NULL) : 0)
  /* each feature covers ~ pi 4^2 = 50 m^2 of ground: 2 % of w^2 */
  size_t nf = (size_t)(0.02 * w * w / 50);
  oc_noise nz = {6, 1.5, 0, 3, seed};
  for (size_t i = 0; i < nf && n + 2 < cap; i++) {
    oc_vec3 c = {oc_rng_range(&r, 0, w), oc_rng_range(&r, 0, w),
                 oc_rng_range(&r, -3, 3)};
    c.z += GROUND(c.x, c.y);
    double kind = oc_rng_uniform(&r);
    if (kind < 0.5) /* carved hollow */
      k[n++] = must(oc_sphere(c, oc_rng_range(&r, 1, 3), 2, -1.5, &err), &err);
    else /* a rock on the ground */
      k[n++] = must(oc_sphere(c, oc_rng_range(&r, 1.5, 3), 1.5, 1, &err), &err);
  }
  /* an arch near the middle */
  double m = w / 2, g0 = GROUND(m - 20, m), g1 = GROUND(m + 20, m);
  oc_vec3 spine[4] = {{m - 20, m, g0 - 2},
                      {m - 22, m, g0 + 28},
                      {m + 22, m, g1 + 28},
                      {m + 20, m, g1 - 2}};
#undef GROUND
  oc_node *arch = must(oc_curve(spine, 4, 1, 6, 1, &err), &err);
  k[n++] = must(oc_perturb(arch, &nz, &err), &err);
  oc_node_release(arch);
  oc_node *b = must(oc_blend(k, n, &err), &err);
  for (size_t i = 0; i < n; i++)
    oc_node_release(k[i]);
  free(k);
  return b;
}

/* The best of `reps` runs (the mesh of the last). */
static oc_mesh *mesh_best(const oc_program *p, oc_aabb box, double cell,
                          int full, int no_direct, int reps, double *sec) {
  oc_mesh *m = NULL;
  *sec = INFINITY;
  for (int r = 0; r < reps; r++) {
    double s;
    oc_mesh_free(m);
    m = timed_mesh("bench_mesh", p, box, cell, full, no_direct, &s);
    *sec = fmin(*sec, s);
  }
  return m;
}

/* One cell size of the speedup scene: the full grid (standard marching
** cubes, root finding on every edge) against surface bounds with direct
** elevation extraction (Paris et al. 2019's optimized polygonization: Table 1's
** t0 / t), and against surface bounds alone (root finding everywhere,
** the same mesh to the bit). Returns 0 when a mesh differs. */
static int speedup_at(const oc_program *p, oc_aabb box, double cell,
                      int figures) {
  double sf, sb, sr;
  omp_set_num_threads(2);
  oc_mesh *mf = mesh_best(p, box, cell, 1, 1, 2, &sf);
  oc_mesh *mb = mesh_best(p, box, cell, 0, 0, 3, &sb);
  oc_mesh *mr = mesh_best(p, box, cell, 0, 1, 3, &sr);
  oc_mesh_stats stf, stb, str;
  oc_mesh_get_stats(mf, &stf);
  oc_mesh_get_stats(mb, &stb);
  oc_mesh_get_stats(mr, &str);
  double n[3], dev;
  grid_cells(box, cell, n);
  int same_bits = same_mesh(mr, mf);
  int same = same_edges(mb, mf, box, cell, &dev);
  printf("# cell %g m (%.0f x %.0f x %.0f cells): %zu triangles; full grid "
         "%.2f s (%zu field calls); surface bounds + direct extraction %.3f "
         "s (%zu calls, %zu cells visited): %.1f x, %s (vertices within "
         "%.1e m); surface bounds, root finding everywhere %.3f s: %.1f x, "
         "%s\n",
         cell, n[0], n[1], n[2], stf.triangles, sf, stf.field_calls, sb,
         stb.field_calls, stb.cells_visited, sf / sb,
         same ? "same triangles on the same edges" : "DIFFERENT TRIANGLES", dev,
         sr, sf / sr, same_bits ? "same mesh to the bit" : "DIFFERENT MESH");
  if (figures) {
    bench_keep_mesh("bench_mesh", "terrain_full_grid.ply", mf);
    bench_keep_mesh("bench_mesh", "terrain_bounds_direct.ply", mb);
    bench_keep_mesh("bench_mesh", "terrain_bounds_root.ply", mr);
    printf("mesh.bounds_speedup: %.1f x\n", sf / sb);
    printf("mesh.field_call_ratio: %.1f x\n",
           (double)stf.field_calls / (double)stb.field_calls);
  }
  oc_mesh_free(mf);
  oc_mesh_free(mb);
  oc_mesh_free(mr);
  return same && same_bits && dev < 1e-2 * cell;
}

/* The scene: a 400 m wide implicitized fBm ground with features on
** 2 % of it, in a box 128 m high. The figure is at cell 0.5 m (800 x 800
** x 256 cells, the proportions of Paris et al. 2019, Table 1's karst scene,
** whose
** 3D coverage is also 2 %: 1520 x 1520 x 447); 1 m for context. */
static void terrain_speedup(void) {
  oc_error err;
  double w = 400;
  oc_heightfield *hf;
  oc_node *ground = fbm_terrain(401, 24, 11, &hf);
  oc_node *t = terrain(w, 11, ground, hf);
  oc_node_release(ground);
  oc_program *p = oc_compile(t, NULL, &err);
  if (!p) {
    fprintf(stderr, "bench_mesh: %s\n", err.msg);
    exit(1);
  }
  oc_aabb box = {{0, 0, -64}, {w, w, 64}};
  printf("# terrain %g x %g m (implicitized fBm ground, features on 2 %% of "
         "it), box z -64..64, 2 threads:\n",
         w, w);
  int ok = speedup_at(p, box, 0.5, 1) & speedup_at(p, box, 1.0, 0);
  oc_program_free(p);
  oc_node_release(t);
  oc_heightfield_release(hf);
  if (!ok) exit(1);
}

/* Issue 5: a 2048 x 2048 DEM, implicitized, meshed at its cell over its
** whole extent and elevation range (closed: the prism's sides and floor
** too), with and without direct elevation extraction, 2 threads. */
static void direct_speedup(void) {
  oc_error err;
  oc_heightfield *hf;
  oc_node *t = fbm_terrain(2048, 120, 21, &hf);
  oc_program *p = oc_compile(t, NULL, &err);
  if (!p) exit(1);
  oc_aabb b = oc_program_bounds(p);
  oc_aabb box = {{-1, -1, b.lo.z - 1}, {2048, 2048, b.hi.z + 1}};
  double sd = INFINITY, sr = INFINITY;
  omp_set_num_threads(2);
  oc_mesh *md = NULL, *mr = NULL;
  for (int rep = 0; rep < 2; rep++) { /* best of 2 */
    double s;
    oc_mesh_free(md);
    md = timed_mesh("bench_mesh", p, box, 1.0, 0, 0, &s);
    sd = fmin(sd, s);
    oc_mesh_free(mr);
    mr = timed_mesh("bench_mesh", p, box, 1.0, 0, 1, &s);
    sr = fmin(sr, s);
  }
  oc_mesh_stats std, str;
  oc_mesh_get_stats(md, &std);
  oc_mesh_get_stats(mr, &str);
  printf("# DEM 2048 x 2048 (fBm, relief %.0f m), cell 1 m, %.0f cells "
         "high: direct %.2f s (%zu triangles, %zu field calls), root finding "
         "%.2f s (%zu triangles, %zu field calls)\n",
         b.hi.z - b.lo.z, (box.hi.z - box.lo.z), sd, std.triangles,
         std.field_calls, sr, str.triangles, str.field_calls);
  bench_keep_mesh("bench_mesh", "dem2048_direct.ply", md);
  printf("mesh.direct_elevation_speedup: %.2f x\n", sr / sd);
  oc_mesh_free(md);
  oc_mesh_free(mr);
  oc_program_free(p);
  oc_node_release(t);
  oc_heightfield_release(hf);
}

/* Runs fn in a child process and reports its peak resident memory. */
static double child_peak_mb(void (*fn)(void)) {
  fflush(stdout);
  pid_t pid = fork();
  if (pid == 0) {
    fn();
    fflush(stdout);
    _exit(0);
  }
  int status;
  struct rusage ru;
  if (wait4(pid, &status, 0, &ru) < 0 || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0) {
    fprintf(stderr, "bench_mesh: child failed\n");
    exit(1);
  }
  return ru.ru_maxrss / 1024.0;
}

static void band_run(void) {
  oc_error err;
  double w = 2000;
  oc_node *t = terrain(w, 12, NULL, NULL);
  oc_program *p = oc_compile(t, NULL, &err);
  if (!p) exit(1);
  oc_aabb box = {{0, 0, -32}, {w, w, 32}};
  double s;
  omp_set_num_threads(2);
  oc_mesh *m = timed_mesh("bench_mesh", p, box, 1.0, 0, 0, &s);
  oc_mesh_stats st;
  oc_mesh_get_stats(m, &st);
  printf("# band: %g x %g columns, 64 cells thick, cell 1 m: %zu triangles, "
         "%zu cells visited, %zu field calls\n",
         w, w, st.triangles, st.cells_visited, st.field_calls);
  printf("mesh.band_seconds_2t: %.2f s\n", s);
  oc_mesh_free(m);
  oc_program_free(p);
  oc_node_release(t);
}

static void spheres1000(void) {
  oc_error err;
  oc_rng r = oc_rng_stream(1000, 3);
  oc_node *k[1001];
  k[0] =
      must(oc_plane((oc_vec3){0, 0, 0}, (oc_vec3){0, 0, 1}, 1, 1, &err), &err);
  for (int i = 1; i <= 1000; i++) {
    oc_vec3 c = {oc_rng_range(&r, 0, 100), oc_rng_range(&r, 0, 100),
                 oc_rng_range(&r, 0, 20)};
    k[i] = must(oc_sphere(c, oc_rng_range(&r, 1, 3), 1, 1, &err), &err);
  }
  oc_node *b = must(oc_blend(k, 1001, &err), &err);
  for (int i = 0; i <= 1000; i++)
    oc_node_release(k[i]);
  oc_program *p = oc_compile(b, NULL, &err);
  oc_aabb box = {{-13.75, -13.75, -5}, {113.75, 113.75, 122.5}};
  double s1, s2;
  omp_set_num_threads(1);
  oc_mesh *m1 = timed_mesh("bench_mesh", p, box, 0.25, 0, 0, &s1);
  omp_set_num_threads(2);
  oc_mesh *m2 = timed_mesh("bench_mesh", p, box, 0.25, 0, 0, &s2);
  oc_mesh_stats st;
  oc_mesh_get_stats(m2, &st);
  int same = oc_mesh_vertex_count(m1) == oc_mesh_vertex_count(m2) &&
             oc_mesh_triangle_count(m1) == oc_mesh_triangle_count(m2) &&
             !memcmp(oc_mesh_positions(m1), oc_mesh_positions(m2),
                     3 * sizeof(float) * oc_mesh_vertex_count(m1)) &&
             !memcmp(oc_mesh_indices(m1), oc_mesh_indices(m2),
                     3 * sizeof(uint32_t) * oc_mesh_triangle_count(m1));
  printf("# 1000 spheres + ground, cell 0.25: %zu triangles, %zu field "
         "calls; 1 thread %.2f s; 1 and 2 threads %s\n",
         st.triangles, st.field_calls, s1, same ? "byte-identical" : "DIFFER");
  bench_keep_mesh("bench_mesh", "spheres1000.ply", m2);
  printf("mesh.spheres1000_seconds_2t: %.2f s\n", s2);
  printf("mesh.spheres1000_triangles: %zu triangles\n", st.triangles);
  oc_mesh_free(m1);
  oc_mesh_free(m2);
  oc_program_free(p);
  oc_node_release(b);
  if (!same) exit(1);
}

int main(void) {
  printf("# targets: mesh.bounds_speedup >= 8, mesh.band_seconds_2t <= 10, "
         "mesh.spheres1000_seconds_2t <= 1.0, "
         "mesh.direct_elevation_speedup >= 1.5\n");
  /* the child first: libgomp cannot run parallel regions in a child
  ** forked after the parent has used them */
  if (bench_wanted("band")) {
    double peak = child_peak_mb(band_run);
    printf("mesh.peak_mb: %.0f MB\n", peak);
  }
  if (bench_wanted("speedup")) terrain_speedup();
  if (bench_wanted("spheres1000")) spheres1000();
  if (bench_wanted("direct")) direct_speedup();
  return 0;
}
