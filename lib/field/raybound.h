/*
** raybound.h — queries of a compiled program along a ray, for tracing
** (internal): bounds on the field's derivative along a ray segment, and
** the intervals of a ray outside of which the field is zero.
*/
#ifndef OC_RAYBOUND_H
#define OC_RAYBOUND_H

#include "outcrop.h"

/* A ray o + t u with u of unit length; inv holds 1 / u per axis (infinite
** for a zero component). */
typedef struct oc_ray {
  oc_vec3 o, u, inv;
} oc_ray;

oc_ray oc_ray_make(oc_vec3 o, oc_vec3 u);

/* Clips [*t0, *t1] to the part of the ray inside the box [lo, hi] (float
** boxes as stored in programs, possibly infinite). Returns 0 when
** nothing is left. */
int oc_ray_clip(const oc_ray *r, const float lo[3], const float hi[3],
                double *t0, double *t1);

/* Bounds lo <= d/dt f(o + t u) <= hi valid for every t in [t0, t1]
** (where the derivative exists; f is Lipschitz, so f(t + s) <= f(t) +
** hi s for [t, t + s] inside the segment). Only nodes whose support the
** segment crosses count, found through the BVHs; point primitives give
** exact, sign-aware bounds of their directional derivative (segment
** tracing), half-spaces and balls their sign, other nodes +-their
** Lipschitz bound. lo <= 0 <= hi. */
void oc_ray_dbound(const oc_program *prog, const oc_ray *r, double t0,
                   double t1, double *lo, double *hi);

/* Sorted disjoint intervals of [t0, t1] outside of which f == 0 along
** the ray (the union of the supports the ray crosses: blends and unions
** are opened down to their children, points and spheres are balls).
** Writes at most `max` intervals (closing the smallest gaps when there
** are more) and returns the count (0: the ray meets no support). */
int oc_ray_supports(const oc_program *prog, const oc_ray *r, double t0,
                    double t1, oc_zspan *out, int max);

#endif
