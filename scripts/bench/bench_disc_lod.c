/*
** bench_disc_lod.c — the cost of one first-order model of a noisy disc,
** exact (oc_edisc_taylor_f) and under a view (oc_edisc_taylor_f_view,
** the level of detail's: tau = log2 w - log2 foot, the footprint's part
** prepared once per query by oc_etfoot_prep, as the tracer does).
**
** One disc of 10 octaves, wavelength 2 km, amplitude 200 m (default gain
** and lacunarity), seen from (-46, -43, 3) km at 8.6e-4 rad a pixel
** (fig21's camera, bench_elev_lod); 4096 points 20-90 km away, each with
** a model radius of 1/256 of its distance (where the tracer asks),
** prepared beforehand. Times are wall time per call, best of REPS runs
** of 100 passes, for each noise kind. Prints `name: value unit` lines.
**   disc_lod.<kind>_exact_ns   oc_edisc_taylor_f
**   disc_lod.<kind>_view_ns    oc_edisc_taylor_f_view
**   disc_lod.<kind>_eval_ns    oc_enode_ev under the point's footprint
**                              (f and its gradient: the filtered sum)
*/
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "elevation/enode.h"
#include "outcrop.h"

#define NPT 4096
#define REPS 7

int main(void) {
  static const char *names[] = {"", "plain", "turbulent", "ridged"};
  static double xs[NPT], ys[NPT];
  static oc_etfoot tfs[NPT];
  oc_eview v = {-46000, -43000, 3000, 8.6e-4};
  unsigned long long z = 1; /* (a fixed LCG: the same points every run) */
  for (int i = 0; i < NPT; i++) {
    z = z * 6364136223846793005ull + 1442695040888963407ull;
    xs[i] = -20000 + 50000.0 * (double)(z >> 11) / 9007199254740992.0;
    z = z * 6364136223846793005ull + 1442695040888963407ull;
    ys[i] = -20000 + 50000.0 * (double)(z >> 11) / 9007199254740992.0;
    double R = hypot(xs[i] - v.ex, ys[i] - v.ey) / 256;
    oc_erect r = {xs[i] - R, ys[i] - R, xs[i] + R, ys[i] + R};
    oc_eview_foot(&v, xs[i], ys[i], &tfs[i].p);
    oc_eview_footb(&v, &r, &tfs[i].b);
    oc_etfoot_prep(&tfs[i], R);
  }
  double chk = 0;
  for (int kind = 1; kind <= 3; kind++) {
    oc_error err;
    oc_enode_disc_params p = {
        10000, 10000, 60000, 300, {kind, 200, 2000, 10, 0, 0, 7}};
    oc_enode *d = oc_enode_disc(&p, &err);
    if (!d) {
      fprintf(stderr, "bench_disc_lod: %s\n", err.msg);
      return 1;
    }
    double best[3] = {1e9, 1e9, 1e9};
    for (int rep = 0; rep < REPS; rep++)
      for (int m = 0; m < 3; m++) {
        double t0 = omp_get_wtime();
        for (int it = 0; it < 100; it++)
          for (int i = 0; i < NPT; i++) {
            oc_etay f;
            if (m == 2) {
              oc_enode_sample s;
              oc_enode_ev(d, xs[i], ys[i], &tfs[i].p, OC_EV_GRAD, &s);
              chk += s.f + s.fx;
              continue;
            }
            if (m)
              oc_edisc_taylor_f_view(d, xs[i], ys[i], tfs[i].R, &tfs[i], &f);
            else
              oc_edisc_taylor_f(d, xs[i], ys[i], tfs[i].R, &f);
            chk += f.v + f.e0 + f.e1 + f.e2 + f.gx;
          }
        double t = (omp_get_wtime() - t0) / (100.0 * NPT) * 1e9;
        if (t < best[m]) best[m] = t;
      }
    printf("disc_lod.%s_exact_ns: %.1f ns\n", names[kind], best[0]);
    printf("disc_lod.%s_view_ns: %.1f ns\n", names[kind], best[1]);
    printf("disc_lod.%s_eval_ns: %.1f ns\n", names[kind], best[2]);
    oc_enode_release(d);
  }
  printf("# checksum %.17g\n", chk);
  return 0;
}
