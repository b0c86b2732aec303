/*
** bezier.h — one Bézier piece of degree 1, 2 or 3 with control points
** (x, y, z): evaluation, subdivision, planar arc length, closest point,
** a curvature upper bound and flattening. The planar geometry is in xy;
** z is carried along the parameter (the skeleton elevation of a curve
** primitive). lib/core/curve.c strings pieces together.
**
** Everything here is read-only on its arguments and allocates nothing.
*/
#ifndef OC_BEZIER_H
#define OC_BEZIER_H

#include <stddef.h>

#include "outcrop.h"

#define OC_BEZ_MAXDEG 3

/* The point at t in [0, 1] (de Casteljau, all three coordinates). */
oc_vec3 oc_bez_eval(const oc_vec3 *p, int n, double t);
/* Its x and y alone, the bits oc_bez_eval gives them (n 0 to 3). */
void oc_bez_xy(const oc_vec3 *p, int n, double t, double *x, double *y);
/* Its first derivative's x and y alone (oc_bez_d1's bits). */
void oc_bez_d1_xy(const oc_vec3 *p, int n, double t, double *x, double *y);
/* First and second derivatives with respect to t (zero beyond the degree). */
oc_vec3 oc_bez_d1(const oc_vec3 *p, int n, double t);
oc_vec3 oc_bez_d2(const oc_vec3 *p, int n, double t);
/* The control points of the piece restricted to [a, b] (0 <= a < b <= 1). */
void oc_bez_sub(const oc_vec3 *p, int n, double a, double b, oc_vec3 *out);

/* Planar arc length of the piece between t = a and t = b, by 8-point
** Gauss–Legendre quadrature on [a, b] (callers keep [a, b] short enough;
** curve.c builds a table where this is accurate to ~1e-14). */
double oc_bez_arclen(const oc_vec3 *p, int n, double a, double b);

/* The smallest squared planar distance from (x, y) to the piece, when it
** is below best2, with its parameter in *t; otherwise returns a value >=
** best2 and leaves *t alone. The global minimum: the stationary points are
** the roots of (B(t) - p) . B'(t), isolated in Bernstein form (a
** coefficient list with one sign change holds exactly one root, solved by
** safeguarded Newton), and sub-intervals whose control box is farther
** than best2 are pruned. Exact to rounding for degree 1. */
double oc_bez_closest(const oc_vec3 *p, int n, double x, double y, double best2,
                      double *t);

/* 1 when every point of the piece is provably farther than r (finite) in
** xy from the segment (xa, ya) (xb, yb), a point when both ends are one:
** the control points' box in the frame of the chord p[0] p[n] (the piece
** lies in their hull) is farther than r plus a margin of 1e-9 of the
** frame's sizes and 1e-14 of the coordinates' (rounding far from the
** origin). 0 when that is not shown (and for a piece with p[0] = p[n]).
** oc_bez_closest runs the same test on the whole piece and on each span. */
int oc_bez_far(const oc_vec3 *p, int n, double xa, double ya, double xb,
               double yb, double r);

/* The planar curvature (signed, > 0 turning left) at t; +-INFINITY where
** the derivative vanishes with a turning second derivative. */
double oc_bez_curvature(const oc_vec3 *p, int n, double t);

/* An upper bound of |curvature| over the piece, rigorous up to rounding
** (a relative margin of 1e-9 is added): on a sub-interval, |B' x B''| is
** bounded by its Bernstein coefficients and |B'| from below by the
** distance of the origin to the hull of the hodograph's control points;
** intervals are split (branch and bound against sampled curvature) until
** the bound is within rel_tol of the sampled maximum or below abs_tol.
** INFINITY when the derivative vanishes where the curve turns (a cusp). */
double oc_bez_kappa_bound(const oc_vec3 *p, int n, double rel_tol,
                          double abs_tol);

/* An upper bound of the grade |dz/ds| (z against planar arc length) over
** the piece, rigorous up to rounding: on 16 sub-intervals (split further
** where needed) the largest |z'| of the hodograph's control points over
** the distance of the origin to the hull of their xy. INFINITY where the
** planar speed may vanish while z changes. */
double oc_bez_grade_bound(const oc_vec3 *p, int n);

/* Flattening: calls emit(ud, t) (when emit is not NULL) for the
** increasing parameters 0 < t_1 < ... < t_k = 1 at which to cut the piece
** so that every point of the piece lies within tol (in xy) of the chord of
** its span (the span's control points are), and returns k. Spans stop
** splitting at depth 30. */
size_t oc_bez_flatten(const oc_vec3 *p, int n, double tol,
                      void (*emit)(void *ud, double t), void *ud);

#endif
