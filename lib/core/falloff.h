/*
** falloff.h — Wyvill's compactly supported falloff g(x) = (1 - x^2)^3.
**
** Written in terms of q = x^2 where possible so point primitives need no
** square root.
*/
#ifndef OC_FALLOFF_H
#define OC_FALLOFF_H

/* max |g'(x)| on [0, 1], reached at x = 1/sqrt(5): 96 sqrt(5) / 125.
** For a radius R the bound is this divided by R (Génevaux et al. 2015,
** appendix). */
#define OC_FALLOFF_LIPSCHITZ 1.7173002067198386 /* 96*sqrt(5)/125 */

/* g as a function of q = x^2. */
static inline double oc_falloff_q(double q) {
  if (!(q < 1.0)) return 0.0;
  double u = 1.0 - q;
  return u * u * u;
}
/* dg/dq = -3 (1 - q)^2 */
static inline double oc_falloff_dq(double q) {
  if (!(q < 1.0)) return 0.0;
  double u = 1.0 - q;
  return -3.0 * u * u;
}
static inline double oc_falloff(double x) {
  return oc_falloff_q(x * x);
}
/* dg/dx = -6 x (1 - x^2)^2 */
static inline double oc_falloff_d(double x) {
  if (!(x < 1.0) || x < 0.0) return 0.0;
  double u = 1.0 - x * x;
  return -6.0 * x * u * u;
}
/* max |g'(x)| over [a, b] clipped to [0, 1], a hair over for rounding:
** |g'| rises to OC_FALLOFF_LIPSCHITZ at 1/sqrt(5), then falls. */
static inline double oc_falloff_slope_in(double a, double b) {
  a = a > 0.0 ? a : 0.0;
  b = b < 1.0 ? b : 1.0;
  if (!(a <= b)) return 0.0;
  double pk = 0.44721359549995793928; /* 1/sqrt(5) */
  if (a <= pk && pk <= b) return OC_FALLOFF_LIPSCHITZ;
  double da = -oc_falloff_d(a), db = -oc_falloff_d(b);
  return (da > db ? da : db) * (1 + 1e-12);
}

#endif
