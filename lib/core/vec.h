/*
** vec.h — small 3D vector and box helpers, all inline, all by value.
*/
#ifndef OC_VEC_H
#define OC_VEC_H

#include <math.h>

#include "outcrop.h"

static inline oc_vec3 oc_v3(double x, double y, double z) {
  oc_vec3 v = {x, y, z};
  return v;
}
static inline oc_vec3 oc_add(oc_vec3 a, oc_vec3 b) {
  return oc_v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline oc_vec3 oc_sub(oc_vec3 a, oc_vec3 b) {
  return oc_v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline oc_vec3 oc_mul(oc_vec3 a, double s) {
  return oc_v3(a.x * s, a.y * s, a.z * s);
}
static inline double oc_dot(oc_vec3 a, oc_vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline oc_vec3 oc_cross(oc_vec3 a, oc_vec3 b) {
  return oc_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
               a.x * b.y - a.y * b.x);
}
static inline double oc_len(oc_vec3 a) {
  return sqrt(oc_dot(a, a));
}
/* |(a, b)| for tests against a margin that dwarfs an ulp: a square root
** where the squares neither overflow nor lose their precision to
** underflow, hypot (a libm call, 5x the time) else. */
static inline double oc_norm2_fast(double a, double b) {
  double s = a * a + b * b;
  return s < 1e300 && (s > 1e-300 || s == 0) ? sqrt(s) : hypot(a, b);
}

/* fmax and fmin as glibc computes them on x86-64 (maxsd and minsd: the
** second operand where they are equal, the other operand where one is
** NaN), inline: libm's are calls in this build (no -ffinite-math-only),
** and box queries, models and curves' closest points make many. */
static inline double oc_fmax(double x, double y) {
  return x > y || y != y ? x : y;
}
static inline double oc_fmin(double x, double y) {
  return x < y || y != y ? x : y;
}
static inline oc_vec3 oc_vmin(oc_vec3 a, oc_vec3 b) {
  return oc_v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z));
}
static inline oc_vec3 oc_vmax(oc_vec3 a, oc_vec3 b) {
  return oc_v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z));
}
static inline int oc_vfinite(oc_vec3 a) {
  return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}

/* The empty box: lo = +inf, hi = -inf, so that union with it is identity. */
static inline oc_aabb oc_aabb_empty(void) {
  oc_aabb b = {{INFINITY, INFINITY, INFINITY},
               {-INFINITY, -INFINITY, -INFINITY}};
  return b;
}
static inline oc_aabb oc_aabb_all(void) {
  oc_aabb b = {{-INFINITY, -INFINITY, -INFINITY},
               {INFINITY, INFINITY, INFINITY}};
  return b;
}
static inline int oc_aabb_is_empty(oc_aabb b) {
  return !(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z);
}
static inline oc_aabb oc_aabb_union(oc_aabb a, oc_aabb b) {
  oc_aabb r = {oc_vmin(a.lo, b.lo), oc_vmax(a.hi, b.hi)};
  return r;
}
static inline oc_aabb oc_aabb_inter(oc_aabb a, oc_aabb b) {
  oc_aabb r = {oc_vmax(a.lo, b.lo), oc_vmin(a.hi, b.hi)};
  return oc_aabb_is_empty(r) ? oc_aabb_empty() : r;
}
static inline oc_aabb oc_aabb_grow(oc_aabb a, double r) {
  if (oc_aabb_is_empty(a)) return a;
  oc_aabb b = {oc_sub(a.lo, oc_v3(r, r, r)), oc_add(a.hi, oc_v3(r, r, r))};
  return b;
}
static inline int oc_aabb_contains(oc_aabb b, oc_vec3 p) {
  return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y &&
         p.z >= b.lo.z && p.z <= b.hi.z;
}
static inline int oc_aabb_overlaps(oc_aabb a, oc_aabb b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y &&
         b.lo.y <= a.hi.y && a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}
static inline int oc_aabb_is_bounded(oc_aabb b) {
  return oc_vfinite(b.lo) && oc_vfinite(b.hi);
}

#endif
