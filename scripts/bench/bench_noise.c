/*
** bench_noise.c — the cost of one octave of the plane noise that
** elevation discs sum (oc_noise3_z0_multi, lib/core/noise.c), against
** the scalar oc_noise3 it matches bit for bit.
**
** A call takes the octaves of one point of a disc: OCT points whose
** coordinates double from octave to octave, each with its own seed, as
** elevation/disc.c's octave_noise passes them. Times are the thread's
** CPU time (best of REPS runs over NCALL calls), divided by the octaves
** computed. Prints `name: value unit` lines; '#' lines are context.
**   noise.z0_ns_per_octave       values and x/y gradients, 7 octaves a call
**   noise.z0_values_ns_per_octave the values alone
**   noise.noise3_ns_per_octave   oc_noise3 with its gradient, a point a call
** and the same for 5 octaves a call and for each path this machine runs
** (oc_noise3_z0_multi_isa: the portable two-lane one and AVX-512).
*/
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "core/noise.h"
#include "core/rng.h"

#define NCALL 20000
#define MAXOCT 8
#define REPS 5

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static uint64_t seeds[NCALL][MAXOCT];
static double xs[NCALL][MAXOCT], ys[NCALL][MAXOCT];
static double val[MAXOCT], gx[MAXOCT], gy[MAXOCT];
static volatile double sink;

/* ns per octave of oc_noise3_z0_multi_isa(isa) with oct octaves a call,
** the gradients when wg; -1 where the machine lacks isa. */
static double z0_ns(oc_noise_isa isa, int oct, int wg) {
  if (!oc_noise_isa_supported(isa)) return -1;
  double best = 1e30, acc = 0;
  for (int r = 0; r < REPS; r++) {
    double t0 = cpu_now();
    for (int c = 0; c < NCALL; c++) {
      oc_noise3_z0_multi_isa(isa, seeds[c], xs[c], ys[c], (size_t)oct, val,
                             wg ? gx : NULL, wg ? gy : NULL);
      acc += val[oct - 1] + gx[0];
    }
    double t = cpu_now() - t0;
    if (t < best) best = t;
  }
  sink = acc;
  return best * 1e9 / ((double)NCALL * oct);
}

static double noise3_ns(void) {
  double best = 1e30, acc = 0;
  for (int r = 0; r < REPS; r++) {
    double t0 = cpu_now();
    for (int c = 0; c < NCALL; c++)
      for (int o = 0; o < 7; o++) {
        oc_vec3 g;
        acc += oc_noise3(seeds[c][o], (oc_vec3){xs[c][o], ys[c][o], 0}, &g) +
               g.x + g.y;
      }
    double t = cpu_now() - t0;
    if (t < best) best = t;
  }
  sink = acc;
  return best * 1e9 / ((double)NCALL * 7);
}

static void put(const char *name, double ns) {
  if (ns >= 0) printf("%s: %.2f ns\n", name, ns);
}

int main(void) {
  oc_rng r = oc_rng_stream(2026, 14);
  for (int c = 0; c < NCALL; c++) {
    double u = oc_rng_range(&r, -1000, 1000), v = oc_rng_range(&r, -1000, 1000);
    double s = 1 / 250.0;
    uint64_t base = oc_rng_next(&r);
    for (int o = 0; o < MAXOCT; o++, s *= 2) {
      seeds[c][o] = oc_mix64(base + 0x9e3779b97f4a7c15ull * (uint64_t)(o + 1));
      xs[c][o] = s * u, ys[c][o] = s * v;
    }
  }
  printf("# %d calls of 7 (and 5) octaves; thread CPU time, best of %d; "
         "AVX-512 path %s\n",
         NCALL, REPS,
         oc_noise_isa_supported(OC_NOISE_ISA_AVX512) ? "available"
                                                     : "not available");
  put("noise.z0_ns_per_octave", z0_ns(OC_NOISE_ISA_AUTO, 7, 1));
  put("noise.z0_values_ns_per_octave", z0_ns(OC_NOISE_ISA_AUTO, 7, 0));
  put("noise.z0_ns_per_octave_5", z0_ns(OC_NOISE_ISA_AUTO, 5, 1));
  put("noise.z0_sse2_ns_per_octave", z0_ns(OC_NOISE_ISA_SSE2, 7, 1));
  put("noise.z0_sse2_ns_per_octave_5", z0_ns(OC_NOISE_ISA_SSE2, 5, 1));
  put("noise.z0_avx512_ns_per_octave", z0_ns(OC_NOISE_ISA_AVX512, 7, 1));
  put("noise.z0_avx512_ns_per_octave_5", z0_ns(OC_NOISE_ISA_AVX512, 5, 1));
  put("noise.noise3_ns_per_octave", noise3_ns());
  return 0;
}
