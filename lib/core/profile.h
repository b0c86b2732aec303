/*
** profile.h — cross-section profiles: C¹ piecewise quadratic functions v(x)
** of the signed distance x to a skeleton curve, given as knots (x_i, v_i).
** The cross-sections of the curve primitives (rivers, roads, lakes) of
** elevation trees (Génevaux et al. 2015: "a 1D piecewise quadric
** function").
**
** The interpolant is a shape-preserving quadratic spline after Schumaker
** 1983: it passes through every knot, is C¹, adds at most one breakpoint
** per knot interval, and is monotone on every interval between knots
** (so monotone data give a monotone profile, and the profile's extremes
** are knot values); convex or concave runs of data stay so, except next
** to three collinear knots and in the two end intervals. Knot slopes are
** the harmonic mean of the neighbouring secant slopes where those have
** the same sign, else 0 (Fritsch–Butland's choice: it never exceeds
** twice the smaller secant, which is what monotonicity needs), and 0 at
** both ends, so the profile continues as a constant beyond the end knots
** and stays C¹ there.
**
** A profile is immutable; queries are read-only, allocate nothing and are
** safe from any number of threads.
*/
#ifndef OC_PROFILE_H
#define OC_PROFILE_H

#include <stddef.h>

#include "outcrop.h"

typedef struct oc_profile oc_profile;

/* Builds the profile through n >= 2 knots (x[i], v[i]), x strictly
** increasing, all finite. Errors name the knot index (from 0) and the
** field ('knots'). The caller frees it with oc_profile_free; NULL (err
** set) on failure. */
oc_profile *oc_profile_new(const double *x, const double *v, size_t n,
                           oc_error *err);
void oc_profile_free(oc_profile *p);

/* v(x), and v'(x) in *dv when dv is not NULL (0 beyond the end knots). */
double oc_profile_eval(const oc_profile *p, double x, double *dv);

/* The exact minimum and maximum of v over [a, b] (a <= b), and the exact
** max |v'| there (v' is piecewise linear, so it peaks at a breakpoint). */
void oc_profile_range(const oc_profile *p, double a, double b, double *lo,
                      double *hi);
double oc_profile_max_slope(const oc_profile *p, double a, double b);

/* [*lo, *hi]: the smallest interval outside which v is constant (both 0
** for a constant profile); the half-width is max(|lo|, |hi|), the reach of
** the non-constant part from the skeleton (x = 0). */
void oc_profile_support(const oc_profile *p, double *lo, double *hi);
double oc_profile_half_width(const oc_profile *p);

/* The bytes p holds: a header of 8 and its knots (as floats when every
** coordinate is one exactly, else as doubles; the spline's pieces are
** derived from them as they are read, with the same values either way). */
size_t oc_profile_bytes(const oc_profile *p);

/* 1 when a and b have the same knots (so the same values everywhere). */
int oc_profile_same(const oc_profile *a, const oc_profile *b);

/* Breakpoints of the spline (knots plus inserted points), for tests. */
size_t oc_profile_nbreaks(const oc_profile *p);

/* The blend (1 - t) A + t B of two profiles (t in [0, 1]: the curve
** primitive interpolates its cross-sections by arc length). Its value and
** derivative; its exact min / max and max |slope| over [a, b] (the blend
** is piecewise quadratic on the union of both breakpoint lists). Over a
** range of t the blend's extremes are those at the two ends of the range,
** as it is linear in t. */
double oc_profile_lerp(const oc_profile *a, const oc_profile *b, double t,
                       double x, double *dv);
void oc_profile_lerp_range(const oc_profile *pa, const oc_profile *pb, double t,
                           double a, double b, double *lo, double *hi);
double oc_profile_lerp_max_slope(const oc_profile *pa, const oc_profile *pb,
                                 double t, double a, double b);

#endif
