/*
** bench_layers.c — material stacks (Peytavie et al. 2009): memory of
** scenes at the effective resolutions of the paper's Table 1, and the
** stabilisation after a large sand deposit, on all threads.
**
**   layers.mb                  the cave scene (1000 x 750 stacks); also
**                              per scene, layers.mb.cave, .canyon
**                              (1000 x 500) and .cliff (2000 x 500)
**   layers.stabilize_seconds_2t  1000 x 750 stacks of 1 m, a 10^5 m^3
**                              sand deposit (R = 50 m) stabilised
**   layers.edit_ms             a sculpt stroke of radius 10 cells on the
**                              same grid under 1 m of sand (re-layering
**                              and local stabilisation), best of 3
**   layers.mesh_seconds_2t     the cave scene's convolution surface
**                              (bedrock, sand, rocks) polygonized at one
**                              cell: field, compile and mesh
**
** The scenes are synthetic stand-ins built stack by stack (the paper's
** scenes are not available): a ground of bedrock under a sand cover,
** with a meandering cave (air and a bedrock roof, rocks on its floor)
** under part of it; a canyon (bedrock, sand and rock screes on its
** floor and slopes); a cliff with two levels of arches (two air layers).
** Their layer counts per stack are printed with the figures, since the
** memory is 4 bytes a stack plus 5 a layer.
** Prints `name: value unit` lines; '#' lines are context.
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "benchout.h"
#include "layers/layers.h"

/* Layers of stack (i, j) of scene `kind` into l (canonical after). */
static size_t scene_stack(int kind, int i, int j, oc_layer *l) {
  double x = i, y = j;
  size_t n = 0;
  double w = sin(x * 0.013 + 2 * sin(y * 0.007)) + 0.5 * sin(y * 0.021);
  double ground = 60 + 20 * sin(x * 0.004) * cos(y * 0.005);
  if (kind == 0) { /* cave */
    int cave = fabs(w) < 0.35;
    if (cave) {
      double floor = ground - 40 + 5 * sin(x * 0.05);
      l[n++] = (oc_layer){floor, OC_MAT_BEDROCK};
      if (fmod(x * 0.37 + y * 0.11, 1) < 0.3)
        l[n++] = (oc_layer){1.5, OC_MAT_ROCKS};
      l[n++] = (oc_layer){10 + 4 * cos(y * 0.03), OC_MAT_AIR};
      l[n++] = (oc_layer){25, OC_MAT_BEDROCK};
    } else {
      l[n++] = (oc_layer){ground, OC_MAT_BEDROCK};
    }
    if (w > 0) l[n++] = (oc_layer){0.5 + 0.5 * w, OC_MAT_SAND};
  } else if (kind == 1) { /* canyon */
    double d = fabs(y - 250 - 40 * sin(x * 0.01));
    double top = d < 30 ? 20 : d < 80 ? 20 + (d - 30) * 1.6 : 100;
    l[n++] = (oc_layer){top, OC_MAT_BEDROCK};
    if (d < 30)
      l[n++] = (oc_layer){2, OC_MAT_SAND};
    else if (d < 90 && fmod(x * 0.13, 1) < 0.5)
      l[n++] = (oc_layer){1, OC_MAT_ROCKS};
  } else { /* cliff with arches */
    double face = 250 + 30 * sin(x * 0.02);
    if (y < face) {
      l[n++] = (oc_layer){80, OC_MAT_BEDROCK};
      if (fabs(w) < 0.5) {
        l[n++] = (oc_layer){15, OC_MAT_AIR};
        l[n++] = (oc_layer){20, OC_MAT_BEDROCK};
      }
      if (fabs(w) > 0.8) {
        l[n++] = (oc_layer){10, OC_MAT_AIR};
        l[n++] = (oc_layer){15, OC_MAT_BEDROCK};
      }
      l[n++] = (oc_layer){1, OC_MAT_SAND};
    } else {
      l[n++] = (oc_layer){5, OC_MAT_BEDROCK};
      if (y < face + 40) l[n++] = (oc_layer){3, OC_MAT_ROCKS};
      l[n++] = (oc_layer){1, OC_MAT_SAND};
    }
  }
  return n;
}

static oc_stacks *scene(int kind, int nx, int ny) {
  oc_error err;
  oc_stacks *s = oc_stacks_alloc(nx, ny, 1, 0, 0, 0, &err);
  oc_stacks_builder b;
  if (!s || oc_builder_init(&b, (size_t)nx * ny, (size_t)nx * ny * 3, &err)) {
    fprintf(stderr, "bench_layers: %s\n", err.msg);
    return NULL;
  }
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      oc_layer l[8], c[8];
      size_t m = oc_layers_canon(l, scene_stack(kind, i, j, l), c);
      oc_builder_push(&b, c, m, &err);
    }
  oc_builder_commit(&b, s);
  return s;
}

static double memory(int kind, int nx, int ny, const char *name) {
  oc_stacks *s = scene(kind, nx, ny);
  if (!s) return NAN;
  oc_stacks_stats st;
  oc_stacks_get_stats(s, &st);
  printf("# %s %d x %d stacks: %zu layers, %.2f layers a stack, %.2f bytes "
         "a layer (stack offsets included), %.2f MB\n",
         name, nx, ny, st.layers, (double)st.layers / st.stacks,
         (double)st.bytes / st.layers, st.bytes / 1e6);
  oc_stacks_free(s);
  return st.bytes / 1e6;
}

static double stabilize_seconds(double *cpu, long *iters, double *moved) {
  oc_error err;
  oc_stacks *s = oc_stacks_new(1000, 750, 1, 0, 0, 0, &err);
  uint8_t m = OC_MAT_BEDROCK;
  double t = 50;
  oc_stacks_fill(s, &m, &t, 1, &err);
  /* A with A pi R^2 / 4 = 10^5 m^3 (the falloff's integral over the disc) */
  double R = 50, A = 1e5 / (3.14159265358979323846 * R * R / 4);
  oc_deposit_params dp = {500, 375, R, A, OC_MAT_SAND, 1, NULL};
  oc_stabilize_result res;
  double added;
  clock_t c0 = clock();
  double t0 = omp_get_wtime();
  int rc = oc_stacks_deposit(s, &dp, &added, &res, &err);
  double sec = omp_get_wtime() - t0;
  *cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (rc) {
    fprintf(stderr, "bench_layers: %s\n", err.msg);
    sec = NAN;
  }
  *iters = res.iterations;
  *moved = res.moved;
  printf("# deposit %.0f m^3 (peak %.1f m), %s\n", added, A,
         res.converged ? "converged" : "NOT converged");
  oc_stacks_free(s);
  return sec;
}

static double edit_ms(void) {
  oc_error err;
  oc_stacks *s = oc_stacks_new(1000, 750, 1, 0, 0, 0, &err);
  uint8_t m[2] = {OC_MAT_BEDROCK, OC_MAT_SAND};
  double t[2] = {50, 1}, best = INFINITY, cpu = INFINITY;
  oc_stacks_fill(s, m, t, 2, &err);
  for (int r = 0; r < 3; r++) {
    oc_sculpt_params sp = {{500 + 30 * r, 375, 50}, 10, 1, NAN, 0, 0, 1, NULL};
    double dv;
    clock_t c0 = clock();
    double t0 = omp_get_wtime();
    if (oc_stacks_sculpt(s, &sp, &dv, NULL, &err)) {
      fprintf(stderr, "bench_layers: %s\n", err.msg);
      break;
    }
    best = fmin(best, omp_get_wtime() - t0);
    cpu = fmin(cpu, (double)(clock() - c0) / CLOCKS_PER_SEC);
  }
  printf("# sculpt stroke: %.1f ms of CPU (both threads), best of 3\n",
         cpu * 1e3);
  oc_stacks_free(s);
  return best * 1e3;
}

/* The cave scene's surface (bedrock, sand and rocks; sigma one cell)
** polygonized at one cell over all its stacks, on all threads; *cpu gets
** the CPU seconds and *tris the triangle count. */
static double mesh_seconds(double *cpu, size_t *tris) {
  oc_error err;
  *tris = 0;
  *cpu = NAN;
  oc_stacks *s = scene(0, 1000, 750);
  if (!s) return NAN;
  unsigned mask = 1u << OC_MAT_BEDROCK | 1u << OC_MAT_SAND | 1u << OC_MAT_ROCKS;
  clock_t c0 = clock();
  double t0 = omp_get_wtime();
  oc_node *n = oc_stacks_field(s, mask, NAN, &err);
  oc_compile_options co = {OC_DEFAULT_THRESHOLD, 0};
  oc_program *P = n ? oc_compile(n, &co, &err) : NULL;
  oc_node_release(n);
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  /* from 1 m above the base (the stacks' flat bottom is no ground) */
  pp.box = (oc_aabb){{-1, -1, 1}, {1000, 750, 90}};
  pp.cell = 1;
  pp.open = 1; /* the ground mesh: no caps on the box's faces */
  pp.max_triangles = (size_t)1 << 30;
  oc_mesh *m = P ? oc_polygonize(P, &pp, &err) : NULL;
  double sec = omp_get_wtime() - t0;
  *cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (!m) {
    fprintf(stderr, "bench_layers: %s\n", err.msg);
    sec = NAN;
  } else {
    *tris = oc_mesh_triangle_count(m);
    bench_keep_mesh("bench_layers", "layers_cave.ply", m);
  }
  oc_mesh_free(m);
  oc_program_free(P);
  oc_stacks_free(s);
  return sec;
}

/* Parts (OUTCROP_BENCH_ONLY): mb, edit, stabilize, mesh. */
int main(void) {
  if (bench_wanted("mb")) {
    double cave = memory(0, 1000, 750, "cave");
    double canyon = memory(1, 1000, 500, "canyon");
    double cliff = memory(2, 2000, 500, "cliff");
    printf("layers.mb: %.2f MB\n", cave);
    printf("layers.mb.cave: %.2f MB\n", cave);
    printf("layers.mb.canyon: %.2f MB\n", canyon);
    printf("layers.mb.cliff: %.2f MB\n", cliff);
  }
  if (bench_wanted("edit")) printf("layers.edit_ms: %.1f ms\n", edit_ms());
  if (bench_wanted("stabilize")) {
    double cpu, moved;
    long it;
    double sec = stabilize_seconds(&cpu, &it, &moved);
    printf("# %d threads; %ld iterations, %.0f m^3 moved, %.2f s CPU\n",
           omp_get_max_threads(), it, moved, cpu);
    printf("layers.stabilize_seconds_2t: %.3f s\n", sec);
  }
  if (bench_wanted("mesh")) {
    double cpu;
    size_t tris;
    double sec = mesh_seconds(&cpu, &tris);
    printf("# cave 1000 x 750 stacks meshed at one cell: %zu triangles "
           "(paper: about 820 k), %.2f s CPU, %d threads\n",
           tris, cpu, omp_get_max_threads());
    printf("layers.mesh_seconds_2t: %.3f s\n", sec);
  }
  return 0;
}
