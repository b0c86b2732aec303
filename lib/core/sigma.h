/*
** sigma.h — the cubic sigma that maps a signed vertical or surface distance
** v into the field convention (Paris et al. 2019, section 5.1): sigma(0) =
** T, sigma(v) = 2T for v >= W and 0 for v <= -W, odd about (0, T), with
** slope k T / W at 0 (k = min(W / T, 3)). Terrains and rock blocks share it.
*/
#ifndef OC_SIGMA_H
#define OC_SIGMA_H

#include <math.h>

/* Parameters: T, W, k, and a bound of sigma's slope (with a hair of
** margin, since it bounds a Lipschitz constant). */
enum { OC_SIG_T, OC_SIG_W, OC_SIG_K, OC_SIG_DS, OC_SIG_N };

static inline void oc_sigma_params(double T, double W, double par[OC_SIG_N]) {
  double k = fmin(W / T, 3.0);
  /* s'(u) = k + 2 (3 - 2k) u + 3 (k - 2) u^2 on [0, 1]: its largest value
  ** is at u = 0 or at the vertex */
  double m = k;
  if (k != 2) {
    double u = (2 * k - 3) / (3 * (k - 2));
    if (u > 0 && u < 1)
      m = fmax(m, k + u * (2 * (3 - 2 * k) + 3 * (k - 2) * u));
  }
  par[OC_SIG_T] = T;
  par[OC_SIG_W] = W;
  par[OC_SIG_K] = k;
  par[OC_SIG_DS] = T / W * m * (1 + 1e-12);
}

/* sigma(v), and its derivative in *ds. */
static inline double oc_sigma(const double *par, double v, double *ds) {
  double T = par[OC_SIG_T], W = par[OC_SIG_W], k = par[OC_SIG_K];
  double u = v / W;
  if (u >= 1) {
    *ds = 0;
    return 2 * T;
  }
  if (u <= -1) {
    *ds = 0;
    return 0;
  }
  double a = fabs(u);
  double s = a * (k + a * ((3 - 2 * k) + a * (k - 2)));
  *ds = T / W * (k + a * (2 * (3 - 2 * k) + 3 * (k - 2) * a));
  return u >= 0 ? T + T * s : T - T * s;
}

#endif
