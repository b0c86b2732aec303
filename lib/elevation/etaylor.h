/*
** etaylor.h — first-order (Taylor) models of elevation trees (internal):
** what the tracer asks at a ray's sample p instead of a slope bound.
**
** A model of a function g around p, for a radius R, is its value v =
** g(p), a linear part (gx, gy) and a remainder polynomial with
** nonnegative coefficients such that
**
**   |g(p + d) - v - (gx, gy).d| <= e0 + e1 r + e2 r^2   for r = |d| <= R
**
** (Euclidean norm). The linear part is usually the gradient, but any
** vector works (a fine noise octave keeps none and counts its whole
** variation in the remainder). Near p the remainder of a smooth tree is
** quadratic, so a ray's height above the model is nearly linear in its
** distance and the tracer's step is Newton-like; a slope bound instead
** counts every octave's largest slope.
**
** The rules below compose models; each says why it is conservative.
** Products of remainder polynomials have degree 4, truncated back to 2
** with r^3 <= R r^2 and r^4 <= R^2 r^2 (valid for r <= R).
*/
#ifndef OC_ETAYLOR_H
#define OC_ETAYLOR_H

#include <math.h>

#include "core/vec.h"

typedef struct oc_etay {
  double v, gx, gy;  /* value and linear part at p */
  double e0, e1, e2; /* the remainder's coefficients, >= 0 */
} oc_etay;

/* Models of f and alpha of a node (etaylor.c, oc_enode_taylor). */
typedef struct oc_etaylor {
  oc_etay f, a;
} oc_etaylor;

/* Where a term may be bounded in two ways (an octave quadratic or flat, a
** box bound's slope or range), the one smaller at r = OC_ETAY_CHOICE R is
** taken: the tracer's steps end well inside the candidate's disc. On
** bench_elev -qq, 1, 0.5, 0.25, 0.1 gave fig3 23.8, 20.2, 19.5, 23.3
** calls a pixel (without over-relaxation), 0.5, 0.35, 0.2, 0.1 gave 17.3,
** 15.9, 14.9, 16.2 with it. Since the tracer hands its beams' models on
** and aims at the models' zeros (render/etrace.c), at bench_elev -q
** (fig3, fig22, fig1, fig20) 0.15, 0.25, 0.35, 0.4, 0.5, 0.6, 0.7 gave
** fig3 9.8, 8.9, 8.4, 8.3, 8.2, 8.4, 8.7 and fig22 13.6, 12.7, 12.2,
** 12.1, 12.0, 12.1, 12.4; 0.4, 0.5, 0.6 fig1 11.8, 11.7, 11.9 (0.25:
** 12.9) and fig20 12.8, 12.6, 12.8 (13.9); but at 1920 x 1080 0.5 made
** the calls dearer than it saved (idle, primary rays and normals: 0.5
** against 0.25, fig3 7.6 against 5.3 s, fig22 15.5 against 12.7, fig21
** 8.5 against 6.9, fig1 9.8 against 10.7): wider discs keep more octaves
** quadratic and more blends' weights cross T. Seconds, not calls, chose. */
#define OC_ETAY_CHOICE 0.25

/* The same choice for the LoD (view) noise models' octaves (disc.c,
** noise_taylor_lod). Their far steps are limited by the quadratic
** remainder of octaves of wavelength about R, which LoD keeps; splitting
** at a wider r makes more of them flat there. bench_elev_lod (fig21) at
** 960 x 540, LoD primary / total calls a pixel (exact 14.57 / 23.26,
** unchanged) for 0.15, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.7: 15.0 /
** 20.7, 11.13 / 16.51, 10.41 / 15.73, 10.03 / 15.43, 9.82 / 15.43, 9.75
** / 15.65, 9.78 / 15.95, 10.7 / 17.2; at 1920 x 1080 0.25 against 0.4
** 10.40 / 16.54 against 8.86 / 15.19, the image's difference to the
** exact one the same (mean 0.0106, 1.25 % of pixels off by > 0.1). LoD
** CPU seconds on a busy machine, alternating, min of 8 rounds at 960 x
** 540 6.58 against 6.24 (medians 6.81, 6.42), of 3 at 1920 x 1080 27.0
** against 25.8: less than the calls, the calls saved being far ones
** with few octaves. The split costs nothing per call (no blend weights
** involved, unlike OC_ETAY_CHOICE's boxes): calls chose. */
#ifndef OC_ETAY_LOD_CHOICE
#define OC_ETAY_LOD_CHOICE 0.4
#endif
static inline oc_etay oc_etay_const(double c) {
  return (oc_etay){c, 0, 0, 0, 0, 0};
}

/* The remainder bound at r. */
static inline double oc_etay_rem(const oc_etay *m, double r) {
  return m->e0 + r * (m->e1 + r * m->e2);
}

static inline double oc_etay_gnorm(const oc_etay *m) {
  return sqrt(m->gx * m->gx + m->gy * m->gy);
}

/* The largest |g(q) - g(p)| for |q - p| <= R: the linear part's |G| R
** plus the remainder (both maximal at r = R, their coefficients being
** nonnegative). */
static inline double oc_etay_dev(const oc_etay *m, double R) {
  return oc_etay_gnorm(m) * R + oc_etay_rem(m, R);
}

/* Exact when the model is the constant it holds. */
static inline int oc_etay_is_const(const oc_etay *m) {
  return m->gx == 0 && m->gy == 0 && m->e0 == 0 && m->e1 == 0 && m->e2 == 0;
}

/* a + b: values, linear parts and remainders add (triangle inequality). */
static inline void oc_etay_add(oc_etay *a, const oc_etay *b) {
  a->v += b->v, a->gx += b->gx, a->gy += b->gy;
  a->e0 += b->e0, a->e1 += b->e1, a->e2 += b->e2;
}

/* k a: the remainder scales by |k|. */
static inline oc_etay oc_etay_scale(const oc_etay *a, double k) {
  double q = fabs(k);
  return (oc_etay){k * a->v,  k * a->gx, k * a->gy,
                   q * a->e0, q * a->e1, q * a->e2};
}

/* The product of two polynomials p(r) q(r) (coefficients >= 0) bounded
** by a quadratic on [0, R]: r^3 <= R r^2, r^4 <= R^2 r^2. */
static inline void oc_etay_polymul(const double p[3], const double q[3],
                                   double R, double o[3]) {
  o[0] = p[0] * q[0];
  o[1] = p[0] * q[1] + p[1] * q[0];
  o[2] = p[0] * q[2] + p[1] * q[1] + p[2] * q[0] +
         R * (p[1] * q[2] + p[2] * q[1]) + R * R * p[2] * q[2];
}

/* a b. With a(p + d) = a + A.d + x, b(p + d) = b + B.d + y (|x| <= Ea,
** |y| <= Eb), ab(p + d) = ab + (a B + b A).d + [a y + b x + (A.d + x)
** (B.d + y)], the bracket at most |a| Eb + |b| Ea + (|A| r + Ea)(|B| r +
** Eb). The value is a->v * b->v. */
/* (forced inline: as a call it showed in callgrind's LoD sums, its
** operands and result through memory) */
static inline __attribute__((always_inline)) oc_etay
oc_etay_mul(const oc_etay *a, const oc_etay *b, double R) {
  double pa[3] = {a->e0, oc_etay_gnorm(a) + a->e1, a->e2};
  double pb[3] = {b->e0, oc_etay_gnorm(b) + b->e1, b->e2}, c[3];
  oc_etay_polymul(pa, pb, R, c);
  double ka = fabs(a->v), kb = fabs(b->v);
  return (oc_etay){a->v * b->v,
                   a->v * b->gx + b->v * a->gx,
                   a->v * b->gy + b->v * a->gy,
                   ka * b->e0 + kb * a->e0 + c[0],
                   ka * b->e1 + kb * a->e1 + c[1],
                   ka * b->e2 + kb * a->e2 + c[2]};
}

/* A model without a linear part for a function whose value is v at p,
** which is lip-Lipschitz on the disc and differs from v by at most gap
** there: whichever of lip r and gap is smaller at r = k R (oc_etay_flat:
** OC_ETAY_CHOICE R). */
static inline oc_etay oc_etay_flat_at(double v, double lip, double gap,
                                      double R, double k) {
  oc_etay m = {v, 0, 0, 0, 0, 0};
  if (lip * R * k <= gap)
    m.e1 = lip;
  else
    m.e0 = gap;
  return m;
}

static inline oc_etay oc_etay_flat(double v, double lip, double gap, double R) {
  return oc_etay_flat_at(v, lip, gap, R, OC_ETAY_CHOICE);
}

/* phi(g) for phi C1 with |phi''| <= M (almost everywhere) on the values g
** takes on the disc, phi(v) = pv, phi'(v) = dv: phi(g') - phi(g) -
** phi'(g)(g' - g) is at most M (g' - g)^2 / 2 (Taylor with the integral
** remainder), and g' - g = G.d + x with |x| <= E, so
** |phi(g') - pv - dv G.d| <= |dv| E + M (|G| r + E)^2 / 2. */
static inline oc_etay oc_etay_compose(const oc_etay *g, double pv, double dv,
                                      double M, double R) {
  double p[3] = {g->e0, oc_etay_gnorm(g) + g->e1, g->e2}, q[3];
  oc_etay_polymul(p, p, R, q);
  double k = fabs(dv), h = 0.5 * M;
  return (oc_etay){pv,
                   dv * g->gx,
                   dv * g->gy,
                   k * g->e0 + h * q[0],
                   k * g->e1 + h * q[1],
                   k * g->e2 + h * q[2]};
}

/* clamp(g, 0, 1): g itself where its range on the disc lies in [0, 1],
** a constant where the range lies beyond one end, else a model without a
** linear part (the clamp is 1-Lipschitz: |clamp g' - clamp g| <= |g' -
** g| <= |G| r + E, and at most the gap to the far end of [0, 1]). */
static inline oc_etay oc_etay_clamp01(const oc_etay *g, double R) {
  double dev = oc_etay_dev(g, R), lo = g->v - dev, hi = g->v + dev;
  if (lo >= 0 && hi <= 1) return *g;
  if (hi <= 0) return oc_etay_const(0);
  if (lo >= 1) return oc_etay_const(1);
  double c = g->v <= 0 ? 0 : g->v >= 1 ? 1 : g->v;
  oc_etay m = {c, 0, 0, g->e0, oc_etay_gnorm(g) + g->e1, g->e2};
  double gap = oc_fmax(c, 1 - c);
  if (oc_etay_rem(&m, R) > gap) m.e0 = gap, m.e1 = m.e2 = 0;
  return m;
}

#endif
