/*
** etaycheck.h — checking first-order models of elevation trees
** (elevation/etaylor.h) against the tree at points q = p + d of their
** disc (test_elevation.c, test_elevation_lod.c).
*/
#ifndef ETAYCHECK_H
#define ETAYCHECK_H

#include <math.h>

#include "elevation/etaylor.h"
#include "ocheck.h"

/* The tree's f and alpha at (x, y) into fa[0], fa[1]. */
typedef void (*etay_eval_fn)(const void *ctx, double x, double y, double fa[2]);

/* Checks the models m of f and alpha around (x, y) for the radius R on
** 40 random q in the disc: the first ten at 1e-4 R to 0.1 R (where a
** quadratic remainder is tiny and a wrong linear part shows), the others
** out to R. Each error |f(q) - v - g.d| is at most the remainder at |d|
** (with a relative hair of the terms for rounding); what names the tree
** in the message. Returns the largest error over its remainder where
** that exceeds 1e-6 (rounding dominates below), and in *quad (when not
** NULL) the same for f where its remainder is quadratic alone. */
static inline double etay_check(const oc_etaylor *m, double x, double y,
                                double R, oct_rng *r, etay_eval_fn ev,
                                const void *ctx, const char *what,
                                double *quad) {
  const oc_etay *mm[2] = {&m->f, &m->a};
  double worst = 0;
  for (int k = 0; k < 2; k++)
    ck_assert(mm[k]->e0 >= 0 && mm[k]->e1 >= 0 && mm[k]->e2 >= 0);
  for (int j = 0; j < 40; j++) {
    double r0 = R * (j < 10 ? pow(10, oct_unif(r, -4, -1)) : oct_unif(r, 0, 1));
    double th = oct_unif(r, 0, 2 * 3.14159265358979323846);
    double dx = r0 * cos(th), dy = r0 * sin(th), d = hypot(dx, dy), got[2];
    ev(ctx, x + dx, y + dy, got);
    for (int k = 0; k < 2; k++) {
      const oc_etay *t = mm[k];
      double err = fabs(got[k] - t->v - t->gx * dx - t->gy * dy);
      double bound = oc_etay_rem(t, d);
      double pad =
          1e-9 * (1 + fabs(t->v) + fabs(t->gx * dx) + fabs(t->gy * dy));
      ck_assert_msg(err <= bound * (1 + 1e-9) + pad,
                    "%s %s at (%g, %g), R %g, r %g: error %g > %g "
                    "(%g + %g r + %g r^2)",
                    what, k ? "alpha" : "f", x, y, R, d, err, bound, t->e0,
                    t->e1, t->e2);
      if (bound > 1e-6) worst = fmax(worst, err / bound);
      if (quad && !k && bound > 1e-6 && t->e0 == 0 && t->e1 == 0)
        *quad = fmax(*quad, err / bound);
    }
  }
  return worst;
}

#endif
