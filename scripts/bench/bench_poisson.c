/*
** bench_poisson.c — maximal Poisson disk sampling: seconds for one million
** samples in 2D and in 3D, on all threads.
**
** The box is sized from the measured density of maximal sets (about
** 0.696 samples per r^2 in 2D, 0.734 per r^3 in 3D) so that each run
** gives close to a million samples; the counts are printed as context.
** Prints `name: value unit` lines; '#' lines are context.
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "outcrop.h"

#define TARGET 1e6
#define REPS 3

static double run(int d, double side, size_t *count) {
  oc_poisson_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{0, 0, 0}, {side, side, d == 3 ? side : 0}};
  pp.radius = 1;
  pp.seed = 2026;
  double best = INFINITY;
  for (int r = 0; r < REPS; r++) {
    oc_error err;
    double t0 = omp_get_wtime();
    oc_samples *s = d == 2 ? oc_poisson2d(&pp, &err) : oc_poisson3d(&pp, &err);
    double t = omp_get_wtime() - t0;
    if (!s) {
      fprintf(stderr, "bench_poisson: %s\n", err.msg);
      return NAN;
    }
    *count = oc_samples_count(s);
    oc_samples_free(s);
    if (t < best) best = t;
  }
  return best;
}

int main(void) {
  size_t n2 = 0, n3 = 0;
  double side2 = sqrt(TARGET / 0.696), side3 = cbrt(TARGET / 0.734);
  double t2 = run(2, side2, &n2);
  double t3 = run(3, side3, &n3);
  printf("# %d threads; 2D box %.1f^2 gives %zu samples, 3D box %.1f^3 "
         "gives %zu (radius 1, best of %d)\n",
         omp_get_max_threads(), side2, n2, side3, n3, REPS);
  printf("poisson.1m_seconds: %.3f s\n", t2);
  printf("poisson.3d_1m_seconds: %.3f s\n", t3);
  return isnan(t2) || isnan(t3);
}
