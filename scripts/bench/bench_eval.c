/*
** bench_eval.c — point-query throughput of a compiled blend of 100 000
** point primitives, with its BVH and by brute force, and its memory.
**
** Scene (issue 2): radius 4..12, centres uniform in 2000 x 2000 x 200,
** energy -1; queries uniform in the blend's bounds. Prints `name: value
** unit` lines; '#' lines are context. The parts (qps, brute: the
** brute-force check) can be chosen and the values of the queries kept
** (scripts/bench/benchout.h).
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "benchout.h"
#include "core/rng.h"
#include "outcrop.h"

#define NPRIM 100000
#define NQUERY 4000000
#define NBRUTE 40000

static double best_qps(const oc_program *p, const oc_vec3 *q, double *out,
                       size_t n, int reps) {
  double best = 0;
  for (int r = 0; r < reps; r++) {
    double t0 = omp_get_wtime();
    oc_program_eval_many(p, q, out, n);
    double t = omp_get_wtime() - t0;
    if (n / t > best) best = n / t;
  }
  return best;
}

int main(void) {
  oc_error err;
  oc_rng rng = oc_rng_stream(2026, 1);
  oc_node **kids = malloc(NPRIM * sizeof *kids);
  for (int i = 0; i < NPRIM; i++) {
    oc_vec3 c = {oc_rng_range(&rng, 0, 2000), oc_rng_range(&rng, 0, 2000),
                 oc_rng_range(&rng, 0, 200)};
    kids[i] = oc_point(c, oc_rng_range(&rng, 4, 12), -1, &err);
  }
  oc_node *blend = oc_blend(kids, NPRIM, &err);
  for (int i = 0; i < NPRIM; i++)
    oc_node_release(kids[i]);
  double t0 = omp_get_wtime();
  oc_program *bvh = oc_compile(blend, NULL, &err);
  double tc = omp_get_wtime() - t0;
  oc_compile_options brute_opts = {0, 1};
  oc_program *brute = oc_compile(blend, &brute_opts, &err);
  if (!bvh || !brute) {
    fprintf(stderr, "bench_eval: %s\n", err.msg);
    return 1;
  }
  oc_aabb b = oc_program_bounds(bvh);
  oc_vec3 *q = malloc(NQUERY * sizeof *q);
  double *out = malloc(NQUERY * sizeof *out);
  double *ref = malloc(NBRUTE * sizeof *ref);
  for (int i = 0; i < NQUERY; i++)
    q[i] = (oc_vec3){oc_rng_range(&rng, b.lo.x, b.hi.x),
                     oc_rng_range(&rng, b.lo.y, b.hi.y),
                     oc_rng_range(&rng, b.lo.z, b.hi.z)};

  omp_set_num_threads(2);
  double qps2 = best_qps(bvh, q, out, NQUERY, 3);
  omp_set_num_threads(1);
  double qps1 = best_qps(bvh, q, out, NQUERY, 2);
  /* the brute-force pass (the check and the BVH's speedup) is the part
  ** "brute" */
  int brute_on = bench_wanted("brute");
  omp_set_num_threads(2);
  double bq2 = brute_on ? best_qps(brute, q, ref, NBRUTE, 1) : 0;
  size_t mismatch = 0, nonzero = 0;
  for (int i = 0; i < NBRUTE; i++) {
    if (brute_on && memcmp(&ref[i], &out[i], sizeof *out)) mismatch++;
    if (out[i] != 0) nonzero++;
  }
  oc_program_stats st;
  oc_program_get_stats(bvh, &st);

  printf("# blend of %d point primitives, compiled in %.3f s; %d queries, "
         "%.1f %% inside some support\n",
         NPRIM, tc, NQUERY, 100.0 * nonzero / NBRUTE);
  printf("# targets: eval.qps_2t >= 5e6, eval.bvh_speedup >= 100, "
         "eval.bytes_per_point <= 40\n");
  printf("eval.qps_2t: %.3g queries/s\n", qps2);
  printf("eval.qps_1t: %.3g queries/s\n", qps1);
  if (brute_on) {
    printf("eval.brute_qps_2t: %.3g queries/s\n", bq2);
    printf("eval.bvh_speedup: %.0f x\n", qps2 / bq2);
    printf("eval.bvh_mismatches: %zu of %d\n", mismatch, NBRUTE);
  }
  printf("eval.bytes_per_point: %.1f bytes\n", (double)st.bytes / NPRIM);
  bench_keep_values("bench_eval", "eval_bvh.f64", out, NQUERY);
  if (brute_on) bench_keep_values("bench_eval", "eval_brute.f64", ref, NBRUTE);
  oc_program_free(bvh);
  oc_program_free(brute);
  oc_node_release(blend);
  free(q);
  free(out);
  free(ref);
  free(kids);
  return mismatch ? 1 : 0;
}
