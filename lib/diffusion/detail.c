/*
** detail.c — the noise detail of the terrain (Hnaidi et al. 2010,
** section 4.3), driven by the diffused amplitude A and roughness R:
**
**   N(p) = A sum_{k=0..n} r^(-k (1 - R)) S(r^k p / lambda_0),
**
** S the simplex noise of core/noise.c scaled to [-1, 1] (zero mean), each
** octave with its own seed drawn from the stream of the scene seed
** (core/rng.h), lambda_0 a wavelength in metres so that grids of any
** resolution over the same area give the same terrain. R = 1 blends the
** octaves equally, lower R damps the higher ones; with r = 2 and n = 3
** the weights sum to 1.875 at R = 0 and to 4 at R = 1, the bound of
** |N| / A.
*/
#include <math.h>

#include "core/noise.h"
#include "core/rng.h"
#include "diffusion/diffusion.h"

#define DETAIL_STREAM 0x646966667573ull /* "diffus" */

double oc_ddetail_at(const oc_ddetail *d, double x, double y, double A,
                     double R) {
  if (A == 0) return 0;
  oc_rng st = oc_rng_stream(d->seed, DETAIL_STREAM);
  double q = exp(-(1 - R) * log(d->ratio)), w = 1, f = 1 / d->wavelength;
  double sum = 0;
  for (int k = 0; k < d->octaves; k++) {
    oc_vec3 p = {x * f, y * f, 0};
    double s = 2 * oc_noise3(oc_rng_next(&st), p, NULL) - 1;
    sum += w * s;
    w *= q;
    f *= d->ratio;
  }
  return A * sum;
}
