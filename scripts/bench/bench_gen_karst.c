/*
** bench_gen_karst.c — karst invasion percolation against Paris et al. 2019,
** Table 1
** (figure 17: 165 773 primitives on a 5.2 x 5.2 km plateau in 6.2 s).
**
** A 521 x 521 grid at 10 m: a plateau 300 m above a plain, its top
** roughened by fBm (its pits are the sinks), over strata with soft beds.
** Prints gen.karst_165k_seconds (the generation, the node included),
** gen.karst_mb (the compiled scene: terrain and cavities) and
** mesh.karst_bounds_speedup (meshing the scene with surface bounds
** against the full grid; the meshes must be the same up to vertex order).
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshcmp.h"
#include "outcrop.h"

#define N 521
#define CELL 10.0

static void die(const oc_error *err) {
  fprintf(stderr, "bench_gen_karst: %s\n", err->msg);
  exit(1);
}

static oc_heightfield *plateau(void) {
  oc_error err;
  oc_heightfield_grid g = {N, N, CELL, 0, 0};
  oc_noise nz = {400, 30, 0, 6, 5};
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, (oc_progress){0}, &err);
  if (!hf) die(&err);
  float *z = oc_heightfield_samples_mut(hf);
  double c = (N - 1) * CELL / 2;
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double x = i * CELL - c, y = j * CELL - c;
      double r = sqrt(x * x + y * y) / 2300;
      double t = fmin(1, fmax(0, (r - 0.8) / 0.2));
      z[j * N + i] = (float)(300 * (1 - t * t * (3 - 2 * t)) + z[j * N + i]);
    }
  return hf;
}

int main(int argc, char **argv) {
  oc_error err;
  double mcell = argc > 1 ? atof(argv[1]) : 6;
  omp_set_num_threads(2);
  oc_heightfield *hf = plateau();
  oc_elevation src;
  if (oc_heightfield_elevation(hf, &src, &err)) die(&err);
  oc_terrain_params tp = {.falloff = 4 * CELL, .transition = 2};
  oc_node *terr = oc_terrain(&src, &tp, &err);
  src.release(src.ud);
  if (!terr) die(&err);
  oc_noise gn = {60, 2, -0.5, 3, 9};
  oc_node *geo = oc_strata(&gn, &err);
  if (!geo) die(&err);
  oc_gen_karst_params p;
  oc_gen_karst_defaults(&p);
  p.heightfield = hf;
  p.terrain = terr;
  p.geology = geo;
  p.radius = argc > 2 ? atof(argv[2]) : 6;
  p.rho0 = argc > 3 ? atof(argv[3]) : 0.72;
  p.max_primitives = 165773;
  p.seed = 3;
  oc_gen_karst_stats st;
  double t0 = omp_get_wtime();
  oc_node *k = oc_generate_karst(&p, &st, &err);
  double sec = omp_get_wtime() - t0;
  if (!k) die(&err);
  oc_program *prog = oc_compile(k, NULL, &err);
  if (!prog) die(&err);
  oc_program_stats ps;
  oc_program_get_stats(prog, &ps);
  printf("# plateau %g x %g km, %zu sinks, %zu candidates, %zu cavities "
         "(radius %g m)\n",
         (N - 1) * CELL / 1000, (N - 1) * CELL / 1000, st.sinks, st.candidates,
         st.primitives, p.radius);
  printf("gen.karst_165k_seconds: %.3f s\n", sec);
  printf("gen.karst_mb: %.2f MB\n", ps.bytes / 1048576.0);
  double lo, hi;
  oc_heightfield_minmax(hf, &lo, &hi);
  oc_aabb box = {{0, 0, lo - 20}, {(N - 1) * CELL, (N - 1) * CELL, hi + 20}};
  /* Paris et al. 2019's t0 and t: the full grid with root finding on every
  ** edge,
  ** surface bounds with direct elevation extraction; and surface bounds
  ** alone, which must give the full grid's mesh to the bit */
  double sb, sf, sr, dev;
  oc_mesh *mf = timed_mesh("bench_gen_karst", prog, box, mcell, 1, 1, &sf);
  oc_mesh *mb = timed_mesh("bench_gen_karst", prog, box, mcell, 0, 0, &sb);
  oc_mesh *mr = timed_mesh("bench_gen_karst", prog, box, mcell, 0, 1, &sr);
  int same = same_edges(mb, mf, box, mcell, &dev) && dev < 1e-2 * mcell;
  int same_bits = same_mesh(mr, mf);
  printf("# mesh at cell %g m: %zu triangles; full grid %.2f s; surface "
         "bounds + direct extraction %.2f s, %s (vertices within %.1e m); "
         "surface bounds, root finding everywhere %.2f s (%.1f x), %s\n",
         mcell, oc_mesh_triangle_count(mf), sf, sb,
         same ? "same triangles on the same edges" : "DIFFERENT TRIANGLES", dev,
         sr, sf / sr, same_bits ? "same mesh to the bit" : "DIFFERENT MESH");
  printf("mesh.karst_bounds_speedup: %.1f x\n", sf / sb);
  same = same && same_bits;
  oc_mesh_free(mr);
  oc_mesh_free(mb);
  oc_mesh_free(mf);
  oc_program_free(prog);
  oc_node_release(k);
  oc_node_release(geo);
  oc_node_release(terr);
  oc_heightfield_release(hf);
  return same ? 0 : 1;
}
