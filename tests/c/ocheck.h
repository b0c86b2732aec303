/*
** ocheck.h — shared support of the C field tests.
**
** A fixed-seed random stream (so a failure replays), vector helpers and
** reference distances written independently of lib/ (the tests are the
** check of the engine, so they must not borrow its geometry), and the
** checks every field test repeats: gradient against central differences,
** Lipschitz bound on point pairs, support inside the reported bounds.
*/
#ifndef OCHECK_H
#define OCHECK_H

#include <check.h>
#include <math.h>
#include <stdint.h>

#include "outcrop.h"

/* 96 sqrt(5) / 125, max |g'| of Wyvill's falloff, recomputed here. */
#define OCT_LG (96.0 * 2.23606797749978969641 / 125.0)

/* ---- random stream (splitmix64; fixed seed per test) ------------------ */

typedef struct oct_rng {
  uint64_t s;
} oct_rng;

oct_rng oct_rng_new(uint64_t seed);
double oct_unif(oct_rng *r, double lo, double hi);
oc_vec3 oct_in_box(oct_rng *r, oc_vec3 lo, oc_vec3 hi);
oc_vec3 oct_dir(oct_rng *r); /* uniform on the unit sphere */

/* ---- vectors ---------------------------------------------------------- */

static inline oc_vec3 oct_v(double x, double y, double z) {
  oc_vec3 v = {x, y, z};
  return v;
}
static inline oc_vec3 oct_add(oc_vec3 a, oc_vec3 b) {
  return oct_v(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline oc_vec3 oct_sub(oc_vec3 a, oc_vec3 b) {
  return oct_v(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline oc_vec3 oct_mul(oc_vec3 a, double s) {
  return oct_v(a.x * s, a.y * s, a.z * s);
}
static inline double oct_dot(oc_vec3 a, oc_vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline double oct_len(oc_vec3 a) {
  return sqrt(oct_dot(a, a));
}
static inline oc_vec3 oct_cross(oc_vec3 a, oc_vec3 b) {
  return oct_v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
               a.x * b.y - a.y * b.x);
}

static inline int oct_box_contains(oc_aabb b, oc_vec3 p) {
  return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y &&
         p.z >= b.lo.z && p.z <= b.hi.z;
}

/* ---- reference falloff and distances ---------------------------------- */

double oct_g(double x);    /* (1 - x^2)^3 on [0, 1), else 0 */
double oct_ginv(double y); /* x in [0, 1] with g(x) = y, y in [0, 1] */
/* Distance to segment [a, b]; closest point in *cp when cp != NULL. */
double oct_dist_segment(oc_vec3 p, oc_vec3 a, oc_vec3 b, oc_vec3 *cp);
double oct_dist_box(oc_vec3 p, oc_vec3 lo, oc_vec3 hi); /* 0 inside */
/* Distance to the polyline; *gap (if non-NULL) gets the difference between
** the two smallest segment distances whose closest points differ, which
** is ~0 on the medial axis where the distance is not differentiable. */
double oct_dist_polyline(oc_vec3 p, const oc_vec3 *pts, size_t n, double *gap);

/* ---- building and compiling ------------------------------------------- */

/* A random point, sphere, segment or box with its support inside [lo, hi]
** grown by rmax, radius / falloff in [rmin, rmax], energy of magnitude
** 0.3..2, negative with probability `pneg`. */
oc_node *oct_random_prim(oct_rng *r, oc_vec3 lo, oc_vec3 hi, double rmin,
                         double rmax, double pneg);

/* Asserts that a constructor succeeded; returns the node. */
#define OCT_OK(expr) oct_ok_((expr), #expr, __FILE__, __LINE__)
oc_node *oct_ok_(oc_node *n, const char *what, const char *file, int line);
/* Compiles `n` with threshold T (0: default) and releases the caller's
** reference to `n` (the program keeps its own). Asserts success. */
oc_program *oct_compile(oc_node *n, double T, int no_bvh);

/* ---- checks ----------------------------------------------------------- */

/* Central-difference gradient with step h. */
oc_vec3 oct_fd_grad(const oc_program *pr, oc_vec3 p, double h);
/* |grad - fd| <= 1e-5 |fd| + atol, with fd of step h; also asserts that
** the value returned by oc_program_gradient equals oc_program_eval. */
void oct_check_grad(const oc_program *pr, oc_vec3 p, double h, double atol);
/* Random pairs in [lo, hi], far and close (down to 1e-7 of the box
** size): |f(p) - f(q)| <= L |p - q| with L = oc_program_lipschitz.
** Returns the largest ratio |f(p) - f(q)| / (L |p - q|) seen. */
double oct_check_lipschitz(const oc_program *pr, oc_vec3 lo, oc_vec3 hi,
                           int npairs, oct_rng *r);
/* Samples [lo, hi] and the faces just outside oc_program_bounds: wherever
** a point is outside the bounds, f must be exactly 0. Returns how many
** sampled points had f != 0 (so callers can check the sampling hit the
** support at all). */
int oct_check_bounds(const oc_program *pr, oc_vec3 lo, oc_vec3 hi, int n,
                     oct_rng *r);

/* Asserts err says EINVAL and names 'param' in single quotes. */
#define OCT_EINVAL(expr, err, param)                                           \
  oct_einval_((expr), &(err), (param), #expr, __FILE__, __LINE__)
void oct_einval_(oc_node *n, const oc_error *err, const char *param,
                 const char *what, const char *file, int line);

/* ---- scratch folders ---------------------------------------------------- */

/* Creates a fresh folder /tmp/oc-test-TAG-XXXXXX; returns its path (static
** storage, valid until the next call). */
const char *oct_tmpdir(const char *tag);
/* "dir/name" in one of 8 rotating static buffers. */
const char *oct_in_dir(const char *dir, const char *name);
/* Number of entries in d (without . and ..); their names, space-separated,
** in `names` when not NULL. */
int oct_count_entries(const char *d, char *names, size_t size);
/* Removes a folder tree (making sub-folders writable first). */
void oct_rm_tree(const char *d);

/* Runs a suite (CK_ENV verbosity) and returns the process exit status. */
int oct_run(Suite *s);

#endif
