/*
** test_prims.c — every field primitive against its formula in
** docs/fields.md, recomputed here from our own distance functions: value,
** gradient, bounds of the support, Lipschitz bound, parameter checks.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/noise.h"
#include "ocheck.h"

/* ---- a primitive described on the test side --------------------------- */

enum {
  P_POINT,
  P_SPHERE,
  P_BOX,
  P_SEGMENT,
  P_CURVE,
  P_BEZIER,
  P_CONE,
  P_PLANE,
  P_NKINDS
};
static const char *kind_name[] = {"point", "sphere", "box",  "segment",
                                  "curve", "bezier", "cone", "plane"};

#define MAXPTS 10
#define DENSE 1000 /* samples per Bezier piece for the reference */

typedef struct prim {
  int kind;
  oc_vec3 a, b; /* centre / min / a / base / origin ; max / b / apex / normal */
  double r;     /* sphere and cone radius */
  double R;     /* radius of skeletal, falloff of volumetric primitives */
  double E;
  oc_vec3 pts[MAXPTS];
  size_t n;
  oc_vec3 *dense; /* Bezier flattened by the test, n_dense points */
  size_t ndense;
} prim;

static double rand_energy(oct_rng *r) {
  double m = oct_unif(r, 0.3, 2.0);
  return oct_unif(r, 0, 1) < 0.3 ? -m : m;
}

static oc_vec3 bez(const oc_vec3 *P, double t) {
  double s = 1 - t;
  oc_vec3 v = oct_mul(P[0], s * s * s);
  v = oct_add(v, oct_mul(P[1], 3 * s * s * t));
  v = oct_add(v, oct_mul(P[2], 3 * s * t * t));
  return oct_add(v, oct_mul(P[3], t * t * t));
}

static void densify(prim *pm) {
  size_t k = (pm->n - 1) / 3;
  pm->ndense = k * DENSE + 1;
  pm->dense = malloc(pm->ndense * sizeof *pm->dense);
  ck_assert_ptr_nonnull(pm->dense);
  for (size_t j = 0; j < k; j++)
    for (int i = 0; i < DENSE; i++)
      pm->dense[j * DENSE + i] = bez(pm->pts + 3 * j, (double)i / DENSE);
  pm->dense[pm->ndense - 1] = pm->pts[pm->n - 1];
}

static prim prim_random(int kind, oct_rng *r) {
  prim pm;
  memset(&pm, 0, sizeof pm);
  pm.kind = kind;
  oc_vec3 lo = oct_v(-5, -5, -5), hi = oct_v(5, 5, 5);
  pm.a = oct_in_box(r, lo, hi);
  pm.R = oct_unif(r, 0.5, 3);
  pm.E = rand_energy(r);
  switch (kind) {
  case P_SPHERE:
    pm.r = oct_unif(r, 0.2, 3);
    break;
  case P_BOX:
    pm.b = oct_add(pm.a, oct_v(oct_unif(r, 0.1, 4), oct_unif(r, 0.1, 4),
                               oct_unif(r, 0.1, 4)));
    break;
  case P_SEGMENT:
    pm.b = oct_in_box(r, lo, hi);
    break;
  case P_CURVE:
    pm.n = 2 + (size_t)oct_unif(r, 0, 6);
    pm.pts[0] = pm.a;
    for (size_t i = 1; i < pm.n; i++)
      pm.pts[i] =
          oct_add(pm.pts[i - 1], oct_mul(oct_dir(r), oct_unif(r, 1, 4)));
    break;
  case P_BEZIER: {
    /* Gentle pieces (curvature radius well above R), joined with a
    ** continuous tangent, so the flattened polyline's kinks are tiny. */
    pm.R = oct_unif(r, 0.3, 0.8);
    int k = 1 + (int)oct_unif(r, 0, 3);
    pm.n = (size_t)(3 * k + 1);
    pm.pts[0] = pm.a;
    oc_vec3 t = oct_dir(r);
    for (int j = 0; j < k; j++) {
      oc_vec3 *P = pm.pts + 3 * j;
      P[1] = oct_add(P[0], oct_mul(t, 3));
      oc_vec3 t2 = oct_dir(r);
      t2 = oct_add(t, oct_mul(t2, 0.4));
      t2 = oct_mul(t2, 1.0 / oct_len(t2));
      P[3] = oct_add(P[1], oct_mul(oct_add(t, t2), 3));
      P[2] = oct_sub(P[3], oct_mul(t2, 3));
      t = t2;
    }
    densify(&pm);
    break;
  }
  case P_CONE:
    pm.b = oct_add(pm.a, oct_mul(oct_dir(r), oct_unif(r, 0.5, 5)));
    pm.r = oct_unif(r, 0.3, 3);
    break;
  case P_PLANE:
    pm.b = oct_mul(oct_dir(r), oct_unif(r, 0.1, 10)); /* not unit */
    break;
  }
  return pm;
}

static void prim_free(prim *pm) {
  free(pm->dense);
}

static oc_node *prim_node(const prim *pm, oc_error *e) {
  switch (pm->kind) {
  case P_POINT:
    return oc_point(pm->a, pm->R, pm->E, e);
  case P_SPHERE:
    return oc_sphere(pm->a, pm->r, pm->R, pm->E, e);
  case P_BOX:
    return oc_box(pm->a, pm->b, pm->R, pm->E, e);
  case P_SEGMENT:
    return oc_segment(pm->a, pm->b, pm->R, pm->E, e);
  case P_CURVE:
    return oc_curve(pm->pts, pm->n, 0, pm->R, pm->E, e);
  case P_BEZIER:
    return oc_curve(pm->pts, pm->n, 1, pm->R, pm->E, e);
  case P_CONE:
    return oc_cone(pm->a, pm->b, pm->r, pm->R, pm->E, e);
  case P_PLANE:
    return oc_plane(pm->a, pm->b, pm->R, pm->E, e);
  }
  return NULL;
}

/* Distance to the solid cone, in the meridian half-plane: (radial x,
** axial y) against the triangle (0,0) (r,0) (0,h). */
static double cone_dist(oc_vec3 p, oc_vec3 base, oc_vec3 apex, double r) {
  oc_vec3 ax = oct_sub(apex, base);
  double h = oct_len(ax);
  ax = oct_mul(ax, 1.0 / h);
  oc_vec3 q = oct_sub(p, base);
  double y = oct_dot(q, ax);
  double x = oct_len(oct_sub(q, oct_mul(ax, y)));
  if (y >= 0 && x / r + y / h <= 1) return 0;
  oc_vec3 p2 = oct_v(x, y, 0);
  double d1 = oct_dist_segment(p2, oct_v(0, 0, 0), oct_v(r, 0, 0), NULL);
  double d2 = oct_dist_segment(p2, oct_v(r, 0, 0), oct_v(0, h, 0), NULL);
  return fmin(d1, d2);
}

/* Reference distance (the argument of g, times R); *gap ~0 near a medial
** axis where the field is not differentiable. */
static double prim_dist(const prim *pm, oc_vec3 p, double *gap) {
  if (gap) *gap = INFINITY;
  switch (pm->kind) {
  case P_POINT:
    return oct_len(oct_sub(p, pm->a));
  case P_SPHERE:
    return fmax(0, oct_len(oct_sub(p, pm->a)) - pm->r);
  case P_BOX:
    return oct_dist_box(p, pm->a, pm->b);
  case P_SEGMENT:
    return oct_dist_segment(p, pm->a, pm->b, NULL);
  case P_CURVE:
    return oct_dist_polyline(p, pm->pts, pm->n, gap);
  case P_BEZIER:
    return oct_dist_polyline(p, pm->dense, pm->ndense, NULL);
  case P_CONE:
    return cone_dist(p, pm->a, pm->b, pm->r);
  case P_PLANE:
    return fmax(0, oct_dot(oct_sub(p, pm->a), pm->b) / oct_len(pm->b));
  }
  return NAN;
}

static double prim_ref(const prim *pm, oc_vec3 p) {
  return pm->E * oct_g(prim_dist(pm, p, NULL) / pm->R);
}

/* Exact bounding box of the support (for Bezier: of the control polygon,
** an outer box by the convex hull property). */
static oc_aabb prim_support(const prim *pm) {
  oc_aabb b;
  double g = pm->R;
  switch (pm->kind) {
  case P_POINT:
    b.lo = pm->a, b.hi = pm->a;
    break;
  case P_SPHERE:
    g += pm->r;
    b.lo = pm->a, b.hi = pm->a;
    break;
  case P_BOX:
  case P_SEGMENT:
    b.lo = oct_v(fmin(pm->a.x, pm->b.x), fmin(pm->a.y, pm->b.y),
                 fmin(pm->a.z, pm->b.z));
    b.hi = oct_v(fmax(pm->a.x, pm->b.x), fmax(pm->a.y, pm->b.y),
                 fmax(pm->a.z, pm->b.z));
    break;
  case P_CURVE:
  case P_BEZIER:
    b.lo = b.hi = pm->pts[0];
    for (size_t i = 1; i < pm->n; i++) {
      oc_vec3 q = pm->pts[i];
      b.lo = oct_v(fmin(b.lo.x, q.x), fmin(b.lo.y, q.y), fmin(b.lo.z, q.z));
      b.hi = oct_v(fmax(b.hi.x, q.x), fmax(b.hi.y, q.y), fmax(b.hi.z, q.z));
    }
    break;
  case P_CONE: {
    oc_vec3 ax = oct_sub(pm->b, pm->a);
    ax = oct_mul(ax, 1 / oct_len(ax));
    oc_vec3 ext = oct_v(pm->r * sqrt(fmax(0, 1 - ax.x * ax.x)),
                        pm->r * sqrt(fmax(0, 1 - ax.y * ax.y)),
                        pm->r * sqrt(fmax(0, 1 - ax.z * ax.z)));
    b.lo = oct_sub(pm->a, ext), b.hi = oct_add(pm->a, ext);
    b.lo = oct_v(fmin(b.lo.x, pm->b.x), fmin(b.lo.y, pm->b.y),
                 fmin(b.lo.z, pm->b.z));
    b.hi = oct_v(fmax(b.hi.x, pm->b.x), fmax(b.hi.y, pm->b.y),
                 fmax(b.hi.z, pm->b.z));
    break;
  }
  default: /* plane: unbounded */
    b.lo = oct_v(-INFINITY, -INFINITY, -INFINITY);
    b.hi = oct_v(INFINITY, INFINITY, INFINITY);
    return b;
  }
  b.lo = oct_sub(b.lo, oct_v(g, g, g));
  b.hi = oct_add(b.hi, oct_v(g, g, g));
  return b;
}

/* Where the test samples: the support box grown by half its size, or a
** box around the origin for the plane. */
static void sample_box(const prim *pm, oc_vec3 *lo, oc_vec3 *hi) {
  oc_aabb s = prim_support(pm);
  if (pm->kind == P_PLANE) {
    *lo = oct_v(-15, -15, -15), *hi = oct_v(15, 15, 15);
    return;
  }
  oc_vec3 m = oct_mul(oct_sub(s.hi, s.lo), 0.5);
  *lo = oct_sub(s.lo, m), *hi = oct_add(s.hi, m);
}

/* A point near the primitive: on its skeleton (or in its solid), pushed
** out by up to 1.3 R in a random direction, so that the falloff zone,
** thin for skeletal primitives, is sampled densely. */
static oc_vec3 sample_near(const prim *pm, oct_rng *r) {
  oc_vec3 s;
  switch (pm->kind) {
  case P_POINT:
    s = pm->a;
    break;
  case P_SPHERE:
    s = oct_add(pm->a, oct_mul(oct_dir(r), oct_unif(r, 0, pm->r)));
    break;
  case P_BOX:
    s = oct_in_box(r, pm->a, pm->b);
    break;
  case P_SEGMENT:
    s = oct_add(pm->a, oct_mul(oct_sub(pm->b, pm->a), oct_unif(r, 0, 1)));
    break;
  case P_CURVE: {
    size_t i = (size_t)oct_unif(r, 0, (double)(pm->n - 1));
    s = oct_add(pm->pts[i], oct_mul(oct_sub(pm->pts[i + 1], pm->pts[i]),
                                    oct_unif(r, 0, 1)));
    break;
  }
  case P_BEZIER:
    s = pm->dense[(size_t)oct_unif(r, 0, (double)pm->ndense)];
    break;
  case P_CONE: {
    double t = oct_unif(r, 0, 1);
    s = oct_add(pm->a, oct_mul(oct_sub(pm->b, pm->a), t));
    s = oct_add(s, oct_mul(oct_dir(r), oct_unif(r, 0, 1) * pm->r * (1 - t)));
    break;
  }
  default: { /* plane: a random point of it */
    oc_vec3 q = oct_in_box(r, oct_v(-12, -12, -12), oct_v(12, 12, 12));
    oc_vec3 n = oct_mul(pm->b, 1 / oct_len(pm->b));
    s = oct_sub(q, oct_mul(n, oct_dot(oct_sub(q, pm->a), n)));
  }
  }
  return oct_add(s, oct_mul(oct_dir(r), oct_unif(r, 0, 1.3 * pm->R)));
}

/* Half the samples uniform over the sampling box, half near. */
static oc_vec3 sample(const prim *pm, oct_rng *r, int i, oc_vec3 lo,
                      oc_vec3 hi) {
  return i % 2 ? sample_near(pm, r) : oct_in_box(r, lo, hi);
}

#define NRAND 12 /* random primitives per kind */

/* ---- values ------------------------------------------------------------ */

START_TEST(value_matches_formula) {
  int kind = _i;
  oct_rng r = oct_rng_new(100 + (uint64_t)kind);
  int inside = 0, falloff = 0, outside = 0;
  for (int t = 0; t < NRAND; t++) {
    prim pm = prim_random(kind, &r);
    oc_error e;
    oc_program *pr = oct_compile(OCT_OK(prim_node(&pm, &e)), 0, 0);
    double tol =
        kind == P_BEZIER ? fabs(pm.E) * OCT_LG * 1e-3 : 1e-9 * fabs(pm.E);
    oc_vec3 lo, hi;
    sample_box(&pm, &lo, &hi);
    for (int i = 0; i < 400; i++) {
      oc_vec3 p = sample(&pm, &r, i, lo, hi);
      double f = oc_program_eval(pr, p), ref = prim_ref(&pm, p);
      ck_assert_msg(fabs(f - ref) <= tol,
                    "%s #%d: f=%.17g, formula %.17g at (%.9g %.9g %.9g)",
                    kind_name[kind], t, f, ref, p.x, p.y, p.z);
      double d = prim_dist(&pm, p, NULL);
      if (d == 0)
        inside++;
      else if (d < pm.R)
        falloff++;
      else
        outside++;
    }
    oc_program_free(pr);
    prim_free(&pm);
  }
  /* The sampling must have seen every regime (skeletal primitives have
  ** no interior of positive measure). */
  ck_assert_int_gt(falloff, 100);
  ck_assert_int_gt(outside, 100);
  if (kind == P_SPHERE || kind == P_BOX || kind == P_CONE || kind == P_PLANE)
    ck_assert_int_gt(inside, 20);
}
END_TEST

/* On and around the skeleton / boundary, where the regimes meet. */
START_TEST(value_on_boundaries) {
  oc_error e;
  oc_vec3 c = oct_v(1, 2, 3);
  double R = 2, E = -1.5;
  oc_program *pr = oct_compile(OCT_OK(oc_point(c, R, E, &e)), 0, 0);
  ck_assert_double_eq(oc_program_eval(pr, c), E);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(3, 2, 3)), 0.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1, 2, 5.0000001)), 0.0);
  ck_assert(oc_program_eval(pr, oct_v(1, 2, 4.9999)) < 0);
  double x = 0.3;
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(1 + x * R, 2, 3)),
                          E * pow(1 - x * x, 3), 1e-14);
  oc_program_free(pr);

  /* Sphere: E everywhere in the ball, falls over R from its surface. */
  pr = oct_compile(OCT_OK(oc_sphere(c, 1.5, 0.5, 2.0, &e)), 0, 0);
  ck_assert_double_eq(oc_program_eval(pr, c), 2.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1, 2, 4.5)), 2.0);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(1, 2, 4.75)),
                          2.0 * pow(0.75, 3), 1e-13);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1, 2, 5.0)), 0.0);
  oc_program_free(pr);

  /* Box: E inside and on the faces; corner falloff is Euclidean. */
  pr = oct_compile(OCT_OK(oc_box(oct_v(0, 0, 0), oct_v(1, 2, 3), 1.0, 1.0, &e)),
                   0, 0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(0.5, 1, 1.5)), 1.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1, 2, 3)), 1.0);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(1.3, 2.4, 1)),
                          pow(1 - 0.25, 3), 1e-13);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1.6, 2.8001, 1)), 0.0);
  oc_program_free(pr);

  /* Segment: capsule; a segment with a = b is a point. */
  pr = oct_compile(OCT_OK(oc_segment(oct_v(0, 0, 0), oct_v(4, 0, 0), 1, 1, &e)),
                   0, 0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(2, 0, 0)), 1.0);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(2, 0.5, 0)), pow(0.75, 3),
                          1e-14);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(-0.5, 0, 0)), pow(0.75, 3),
                          1e-14);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(5, 0, 0)), 0.0);
  oc_program_free(pr);
  oc_program *ps = oct_compile(OCT_OK(oc_segment(c, c, R, E, &e)), 0, 0);
  oc_program *pp = oct_compile(OCT_OK(oc_point(c, R, E, &e)), 0, 0);
  oct_rng r = oct_rng_new(7);
  for (int i = 0; i < 200; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-2, -1, 0), oct_v(4, 5, 6));
    double a = oc_program_eval(ps, p), b = oc_program_eval(pp, p);
    ck_assert_msg(fabs(a - b) <= 1e-14 && !isnan(a),
                  "degenerate segment %.17g vs point %.17g", a, b);
    oc_vec3 g;
    oc_program_gradient(ps, p, &g);
    ck_assert(!isnan(g.x) && !isnan(g.y) && !isnan(g.z));
  }
  oc_program_free(ps);
  oc_program_free(pp);

  /* Cone: E on the axis, in the base disc and at the apex; falls along
  ** the axis beyond the apex and below the base. */
  pr = oct_compile(OCT_OK(oc_cone(oct_v(0, 0, 0), oct_v(0, 0, 4), 2, 1, 1, &e)),
                   0, 0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(0, 0, 2)), 1.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(0, 0, 4)), 1.0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1.9, 0, 0)), 1.0);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(0, 0, 4.5)), pow(0.75, 3),
                          1e-13);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(0, 1, -0.5)), pow(0.75, 3),
                          1e-13);
  /* Beyond the rim, radially: distance to the rim circle. */
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(2.3, 0, -0.4)),
                          pow(0.75, 3), 1e-13);
  /* The slant face: x/2 + z/4 = 1 at (1, 0, 2); outward normal (2,0,1)/√5. */
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(1 + 0.5 * 2 / sqrt(5.0), 0,
                                                    2 + 0.5 / sqrt(5.0))),
                          pow(0.75, 3), 1e-12);
  oc_program_free(pr);

  /* Plane: E on the side opposite to the normal, falls over R along it;
  ** the normal is normalised. */
  pr = oct_compile(OCT_OK(oc_plane(oct_v(0, 0, 1), oct_v(0, 0, 5), 2, 0.8, &e)),
                   0, 0);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(10, -7, 1)), 0.8);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(1e6, 1e6, -1e6)), 0.8);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(3, 3, 2)),
                          0.8 * pow(0.75, 3), 1e-14);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(3, 3, 3)), 0.0);
  oc_program_free(pr);
}
END_TEST

/* Curves: closed polylines, repeated points, a straight Bezier. */
START_TEST(curve_special_cases) {
  oc_error e;
  oc_vec3 sq[5] = {{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, {0, 0, 0}};
  oc_program *pr = oct_compile(OCT_OK(oc_curve(sq, 5, 0, 1, 1, &e)), 0, 0);
  /* The closing edge counts. */
  ck_assert_double_eq(oc_program_eval(pr, oct_v(0, 2, 0)), 1.0);
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(-0.5, 2, 0)), pow(0.75, 3),
                          1e-14);
  ck_assert_double_eq(oc_program_eval(pr, oct_v(2, 2, 0)), 0.0);
  oc_program_free(pr);

  oc_vec3 rep[5] = {{0, 0, 0}, {0, 0, 0}, {3, 0, 0}, {3, 0, 0}, {3, 2, 0}};
  pr = oct_compile(OCT_OK(oc_curve(rep, 5, 0, 1, 1, &e)), 0, 0);
  oct_rng r = oct_rng_new(11);
  for (int i = 0; i < 300; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-1, -1, -1), oct_v(4, 3, 1));
    double ref = oct_g(oct_dist_polyline(p, rep, 5, NULL));
    oc_vec3 g;
    double f = oc_program_gradient(pr, p, &g);
    ck_assert_msg(fabs(f - ref) < 1e-12, "repeated points: %.17g vs %.17g", f,
                  ref);
    ck_assert(!isnan(g.x) && !isnan(g.y) && !isnan(g.z));
  }
  oc_program_free(pr);

  /* Evenly spaced collinear control points: the Bezier is the segment. */
  oc_vec3 line[4] = {{0, 0, 0}, {1, 1, 0}, {2, 2, 0}, {3, 3, 0}};
  oc_program *pb = oct_compile(OCT_OK(oc_curve(line, 4, 1, 0.7, 1, &e)), 0, 0);
  oc_program *ps =
      oct_compile(OCT_OK(oc_segment(line[0], line[3], 0.7, 1, &e)), 0, 0);
  for (int i = 0; i < 300; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-1, -1, -1), oct_v(4, 4, 1));
    double a = oc_program_eval(pb, p), b = oc_program_eval(ps, p);
    ck_assert_msg(fabs(a - b) <= 1e-4 * OCT_LG,
                  "straight Bezier %.17g vs "
                  "segment %.17g",
                  a, b);
  }
  oc_program_free(pb);
  oc_program_free(ps);
}
END_TEST

/* ---- gradients --------------------------------------------------------- */

/* Whether the probes p +- s e_i straddle the solid's boundary d = 0. */
static int straddles(const prim *pm, oc_vec3 p, double s) {
  int in = prim_dist(pm, p, NULL) == 0;
  for (int a = 0; a < 3; a++)
    for (int sg = -1; sg <= 1; sg += 2) {
      oc_vec3 q = p;
      (&q.x)[a] += sg * s;
      if ((prim_dist(pm, q, NULL) == 0) != in) return 1;
    }
  return 0;
}

START_TEST(gradient_matches_differences) {
  int kind = _i;
  oct_rng r = oct_rng_new(200 + (uint64_t)kind);
  int checked = 0;
  for (int t = 0; t < NRAND; t++) {
    prim pm = prim_random(kind, &r);
    oc_error e;
    oc_program *pr = oct_compile(OCT_OK(prim_node(&pm, &e)), 0, 0);
    double h = 1e-6 * pm.R;
    oc_vec3 lo, hi;
    sample_box(&pm, &lo, &hi);
    for (int i = 0; i < 150; i++) {
      oc_vec3 p = sample(&pm, &r, i, lo, hi);
      double gap;
      double d = prim_dist(&pm, p, &gap);
      if (gap < 1e-4 * pm.R) continue; /* medial axis of a polyline */
      /* Skip the solid's boundary d = 0 (g' = 0 there, so f is C1, but
      ** the second derivative jumps and central differences straddling
      ** it lose their second order). */
      if (straddles(&pm, p, 2 * h) || (d > 0 && d < 1e-4 * pm.R)) continue;
      if (d >= pm.R * (1 + 1e-3)) {
        /* Outside the support the gradient is exactly zero. */
        oc_vec3 g;
        oc_program_gradient(pr, p, &g);
        ck_assert_msg(g.x == 0 && g.y == 0 && g.z == 0,
                      "%s: nonzero gradient outside the support",
                      kind_name[kind]);
        continue;
      }
      if (d >= pm.R * (1 - 1e-3)) continue;
      oct_check_grad(pr, p, h, 1e-8 * fabs(pm.E) / pm.R);
      checked++;
    }
    oc_program_free(pr);
    prim_free(&pm);
  }
  ck_assert_int_gt(checked, 300);
}
END_TEST

/* For a skeletal primitive inside the falloff the gradient is
** E g'(d/R)/R times the unit vector away from the skeleton. */
START_TEST(gradient_direction) {
  oc_error e;
  oc_vec3 c = oct_v(0.5, -1, 2);
  oc_program *pr = oct_compile(OCT_OK(oc_point(c, 3, 2, &e)), 0, 0);
  oct_rng r = oct_rng_new(5);
  for (int i = 0; i < 200; i++) {
    oc_vec3 u = oct_dir(&r);
    double d = oct_unif(&r, 0.01, 2.99);
    oc_vec3 p = oct_add(c, oct_mul(u, d));
    oc_vec3 g;
    oc_program_gradient(pr, p, &g);
    double x = d / 3;
    double dg = -6 * x * (1 - x * x) * (1 - x * x); /* g'(x) */
    oc_vec3 ref = oct_mul(u, 2 * dg / 3);
    ck_assert_msg(oct_len(oct_sub(g, ref)) <= 1e-10 * (1 + oct_len(ref)),
                  "point gradient (%g %g %g) vs (%g %g %g)", g.x, g.y, g.z,
                  ref.x, ref.y, ref.z);
  }
  oc_vec3 g;
  oc_program_gradient(pr, c, &g);
  ck_assert(g.x == 0 && g.y == 0 && g.z == 0);
  oc_program_free(pr);
}
END_TEST

/* ---- bounds ------------------------------------------------------------ */

START_TEST(bounds_contain_support) {
  int kind = _i;
  oct_rng r = oct_rng_new(300 + (uint64_t)kind);
  for (int t = 0; t < NRAND; t++) {
    prim pm = prim_random(kind, &r);
    oc_error e;
    oc_program *pr = oct_compile(OCT_OK(prim_node(&pm, &e)), 0, 0);
    oc_vec3 lo, hi;
    sample_box(&pm, &lo, &hi);
    oct_check_bounds(pr, lo, hi, 1500, &r);
    /* and near the primitive, where the support is */
    oc_aabb b = oc_program_bounds(pr), s = prim_support(&pm);
    int nz = 0;
    for (int i = 0; i < 1500; i++) {
      oc_vec3 p = sample_near(&pm, &r);
      double f = oc_program_eval(pr, p);
      nz += f != 0;
      if (!oct_box_contains(b, p))
        ck_assert_msg(f == 0, "%s #%d: f != 0 outside the bounds",
                      kind_name[kind], t);
    }
    ck_assert_int_gt(nz, 500);

    if (kind == P_PLANE) {
      /* Only axis-aligned half-spaces can have a finite side. */
      ck_assert(!(b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z));
      oc_program_free(pr);
      continue;
    }
    if (kind == P_BEZIER) {
      /* The true support box, from the dense curve. */
      s.lo = s.hi = pm.dense[0];
      for (size_t i = 1; i < pm.ndense; i++) {
        oc_vec3 q = pm.dense[i];
        s.lo = oct_v(fmin(s.lo.x, q.x), fmin(s.lo.y, q.y), fmin(s.lo.z, q.z));
        s.hi = oct_v(fmax(s.hi.x, q.x), fmax(s.hi.y, q.y), fmax(s.hi.z, q.z));
      }
      s.lo = oct_sub(s.lo, oct_v(pm.R, pm.R, pm.R));
      s.hi = oct_add(s.hi, oct_v(pm.R, pm.R, pm.R));
    }
    double *bl = &b.lo.x, *bh = &b.hi.x, *sl = &s.lo.x, *sh = &s.hi.x;
    for (int a = 0; a < 3; a++) {
      /* A Bezier is flattened within 1e-4 R: its extremes may be cut. */
      double ext = sh[a] - sl[a],
             eps = kind == P_BEZIER ? 1.1e-4 * pm.R : 1e-9 * ext;
      ck_assert_msg(bl[a] <= sl[a] + eps && bh[a] >= sh[a] - eps,
                    "%s #%d axis %d: bounds [%g, %g] miss the support [%g, %g]",
                    kind_name[kind], t, a, bl[a], bh[a], sl[a], sh[a]);
      ck_assert_msg(bh[a] - bl[a] <= 1.5 * ext,
                    "%s #%d axis %d: bounds [%g, %g] too loose for [%g, %g]",
                    kind_name[kind], t, a, bl[a], bh[a], sl[a], sh[a]);
    }
    oc_program_free(pr);
    prim_free(&pm);
  }
}
END_TEST

START_TEST(bounds_of_axis_plane) {
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 2), oct_v(0, 0, 1), 0.5, 1, &e)), 0, 0);
  oc_aabb b = oc_program_bounds(pr);
  /* The support is z < 2.5, unbounded elsewhere. */
  ck_assert(b.hi.z >= 2.5);
  ck_assert(isinf(b.lo.x) && isinf(b.hi.x) && isinf(b.lo.y) && isinf(b.hi.y) &&
            isinf(b.lo.z));
  oc_program_free(pr);
}
END_TEST

/* ---- Lipschitz --------------------------------------------------------- */

START_TEST(lipschitz_bound) {
  int kind = _i;
  oct_rng r = oct_rng_new(400 + (uint64_t)kind);
  double worst = 0, Lbad = 0, Lref = 0;
  for (int t = 0; t < NRAND; t++) {
    prim pm = prim_random(kind, &r);
    oc_error e;
    oc_program *pr = oct_compile(OCT_OK(prim_node(&pm, &e)), 0, 0);
    double L = oc_program_lipschitz(pr), ref = fabs(pm.E) * OCT_LG / pm.R;
    if (fabs(L - ref) > 1e-9 * ref) Lbad = L, Lref = ref;
    oc_vec3 lo, hi;
    sample_box(&pm, &lo, &hi);
    double w = oct_check_lipschitz(pr, lo, hi, 1200, &r);
    if (w > worst) worst = w;
    oc_program_free(pr);
    prim_free(&pm);
  }
  /* The bound is tight for every primitive: the falloff's steepest slope
  ** is reached along some ray. */
  ck_assert_msg(worst > 0.3, "%s: largest slope only %g of L", kind_name[kind],
                worst);
  ck_assert_msg(Lbad == 0, "%s: L = %.17g, expected |E| Lg / R = %.17g",
                kind_name[kind], Lbad, Lref);
}
END_TEST

START_TEST(lipschitz_point_exact) {
  oc_error e;
  double R = 1.7, E = -0.6;
  oc_vec3 c = oct_v(3, 0, -1);
  oc_program *pr = oct_compile(OCT_OK(oc_point(c, R, E, &e)), 0, 0);
  double L = oc_program_lipschitz(pr);
  double ref = fabs(E) * 96 * sqrt(5.0) / 125 / R;
  ck_assert_msg(fabs(L - ref) <= 1e-9 * ref, "L = %.17g, expected %.17g", L,
                ref);
  /* The bound is reached at d = R/sqrt(5), radially. */
  oc_vec3 p = oct_add(c, oct_v(R / sqrt(5.0), 0, 0));
  oc_vec3 q = oct_add(p, oct_v(1e-6, 0, 0));
  double s = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q)) / 1e-6;
  /* (a difference quotient carries ~1e-10 of rounding at this step) */
  ck_assert_msg(s <= L * (1 + 1e-8) && s > 0.9999 * L, "slope %.17g vs L %.17g",
                s, L);
  oc_program_free(pr);
}
END_TEST

/* ---- turbulence -------------------------------------------------------- */

static oc_node *turb(double wl, double A, double off, int oct, uint64_t seed) {
  oc_noise n = {wl, A, off, oct, seed};
  oc_error e;
  return OCT_OK(oc_turbulence(&n, &e));
}

START_TEST(turbulence_values) {
  oct_rng r = oct_rng_new(500);
  oc_program *t1 = oct_compile(turb(3, 1, 0, 4, 42), 0, 0);
  oc_program *t2 = oct_compile(turb(3, -2.5, 0.7, 4, 42), 0, 0);
  oc_program *t3 = oct_compile(turb(1, 1, 0, 4, 42), 0, 0);
  oc_program *t4 = oct_compile(turb(3, 1, 0, 4, 43), 0, 0);
  oc_program *t5 = oct_compile(turb(3, 1, 0, 1, 42), 0, 0);
  double tmax = 2 - pow(2, 1 - 4);
  double lo1 = INFINITY, hi1 = -INFINITY;
  int differ = 0;
  for (int i = 0; i < 3000; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-50, -50, -50), oct_v(50, 50, 50));
    double f1 = oc_program_eval(t1, p);
    ck_assert_msg(f1 >= 0 && f1 <= tmax, "t = %.17g outside [0, %g]", f1, tmax);
    lo1 = fmin(lo1, f1), hi1 = fmax(hi1, f1);
    /* Linear in amplitude and offset. */
    double f2 = oc_program_eval(t2, p);
    ck_assert_double_eq_tol(f2, 0.7 - 2.5 * f1, 1e-12);
    /* Wavelength scales space. */
    double f3 = oc_program_eval(t3, oct_mul(p, 1.0 / 3));
    ck_assert_double_eq_tol(f1, f3, 1e-12);
    if (fabs(oc_program_eval(t4, p) - f1) > 1e-3) differ++;
    double f5 = oc_program_eval(t5, p);
    ck_assert(f5 >= 0 && f5 <= 1);
  }
  /* Not a constant: covers a good part of its range. */
  ck_assert_msg(hi1 - lo1 > 0.5 * tmax, "range [%g, %g]", lo1, hi1);
  ck_assert_int_gt(differ, 2500); /* another seed, another field */
  oc_program_free(t1);
  oc_program_free(t2);
  oc_program_free(t3);
  oc_program_free(t4);
  oc_program_free(t5);
}
END_TEST

/* The node is the core turbulence, scaled: offset + A t(p / wl). */
START_TEST(turbulence_is_core_turbulence) {
  oct_rng r = oct_rng_new(501);
  oc_program *pr = oct_compile(turb(2.5, 1.5, -0.25, 5, 1234), 0, 0);
  for (int i = 0; i < 500; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-20, -20, -20), oct_v(20, 20, 20));
    double ref = -0.25 + 1.5 * oc_turb3(1234, 5, oct_mul(p, 1 / 2.5), NULL);
    ck_assert_double_eq_tol(oc_program_eval(pr, p), ref, 1e-12);
  }
  oc_program_free(pr);
}
END_TEST

START_TEST(turbulence_gradient_bounds_lipschitz) {
  oct_rng r = oct_rng_new(502);
  double wl = 4, A = -1.3;
  int oct = 3;
  oc_program *pr = oct_compile(turb(wl, A, 0.2, oct, 9), 0, 0);
  double L = oc_program_lipschitz(pr);
  double ref = fabs(A) * oct * oc_noise3_lipschitz / wl;
  ck_assert_msg(fabs(L - ref) <= 1e-9 * ref, "L = %.17g, expected %.17g", L,
                ref);
  for (int i = 0; i < 500; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-30, -30, -30), oct_v(30, 30, 30));
    oct_check_grad(pr, p, 1e-6 * wl, 1e-8 * ref);
  }
  oct_check_lipschitz(pr, oct_v(-30, -30, -30), oct_v(30, 30, 30), 3000, &r);
  oc_aabb b = oc_program_bounds(pr);
  ck_assert(isinf(b.lo.x) && b.lo.x < 0 && isinf(b.hi.z) && b.hi.z > 0);
  oct_check_bounds(pr, oct_v(-1e3, -1e3, -1e3), oct_v(1e3, 1e3, 1e3), 500, &r);
  oc_program_free(pr);
}
END_TEST

/* ---- parameter checks -------------------------------------------------- */

START_TEST(invalid_parameters) {
  oc_error e;
  oc_vec3 o = {0, 0, 0}, x = {1, 0, 0}, bad = {NAN, 0, 0},
          inf = {0, INFINITY, 0};
  double radii[] = {0, -1, NAN, INFINITY, -INFINITY};
  for (int i = 0; i < 5; i++) {
    double v = radii[i];
    OCT_EINVAL(oc_point(o, v, 1, &e), e, "radius");
    OCT_EINVAL(oc_sphere(o, v, 1, 1, &e), e, "radius");
    OCT_EINVAL(oc_sphere(o, 1, v, 1, &e), e, "falloff");
    OCT_EINVAL(oc_box(o, x, v, 1, &e), e, "falloff");
    OCT_EINVAL(oc_segment(o, x, v, 1, &e), e, "radius");
    oc_vec3 two[2] = {{0, 0, 0}, {1, 0, 0}};
    OCT_EINVAL(oc_curve(two, 2, 0, v, 1, &e), e, "radius");
    OCT_EINVAL(oc_cone(o, x, v, 1, 1, &e), e, "radius");
    OCT_EINVAL(oc_cone(o, x, 1, v, 1, &e), e, "falloff");
    OCT_EINVAL(oc_plane(o, x, v, 1, &e), e, "falloff");
  }
  OCT_EINVAL(oc_point(o, 1, NAN, &e), e, "energy");
  OCT_EINVAL(oc_point(o, 1, INFINITY, &e), e, "energy");
  OCT_EINVAL(oc_box(o, x, 1, -INFINITY, &e), e, "energy");
  OCT_EINVAL(oc_point(bad, 1, 1, &e), e, "center");
  OCT_EINVAL(oc_point(inf, 1, 1, &e), e, "center");
  OCT_EINVAL(oc_sphere(bad, 1, 1, 1, &e), e, "center");
  OCT_EINVAL(oc_box(bad, x, 1, 1, &e), e, "min");
  OCT_EINVAL(oc_box(o, inf, 1, 1, &e), e, "max");
  OCT_EINVAL(oc_segment(bad, x, 1, 1, &e), e, "a");
  OCT_EINVAL(oc_segment(o, inf, 1, 1, &e), e, "b");
  OCT_EINVAL(oc_cone(bad, x, 1, 1, 1, &e), e, "base");
  OCT_EINVAL(oc_cone(o, inf, 1, 1, 1, &e), e, "apex");
  OCT_EINVAL(oc_cone(x, x, 1, 1, 1, &e), e, "apex|base");
  OCT_EINVAL(oc_plane(bad, x, 1, 1, &e), e, "origin");
  OCT_EINVAL(oc_plane(o, o, 1, 1, &e), e, "normal");
  OCT_EINVAL(oc_plane(o, bad, 1, 1, &e), e, "normal");

  oc_vec3 pts[7] = {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 0, 0},
                    {4, 0, 1}, {5, 0, 0}, {6, 1, 0}};
  OCT_EINVAL(oc_curve(pts, 1, 0, 1, 1, &e), e, "points");
  OCT_EINVAL(oc_curve(pts, 0, 0, 1, 1, &e), e, "points");
  OCT_EINVAL(oc_curve(NULL, 0, 0, 1, 1, &e), e, "points");
  OCT_EINVAL(oc_curve(pts, 5, 1, 1, 1, &e), e, "points");
  OCT_EINVAL(oc_curve(pts, 2, 1, 1, 1, &e), e, "points");
  OCT_EINVAL(oc_curve(pts, 1, 1, 1, 1, &e), e, "points");
  pts[2].y = NAN;
  OCT_EINVAL(oc_curve(pts, 4, 0, 1, 1, &e), e, "points");
  pts[2].y = 1;
  /* The valid neighbours of the invalid counts are accepted. */
  oc_node *n = OCT_OK(oc_curve(pts, 4, 1, 1, 1, &e));
  oc_node_release(n);
  n = OCT_OK(oc_curve(pts, 7, 1, 1, 1, &e));
  oc_node_release(n);
  n = OCT_OK(oc_curve(pts, 5, 0, 1, 1, &e));
  oc_node_release(n);

  oc_noise nz = {1, 1, 0, 3, 0};
  oc_node *t = OCT_OK(oc_turbulence(&nz, &e));
  oc_node_release(t);
  oc_noise bads[] = {{0, 1, 0, 3, 0},   {-2, 1, 0, 3, 0},
                     {NAN, 1, 0, 3, 0}, {INFINITY, 1, 0, 3, 0},
                     {1, NAN, 0, 3, 0}, {1, INFINITY, 0, 3, 0},
                     {1, 1, NAN, 3, 0}, {1, 1, 0, 0, 0},
                     {1, 1, 0, 17, 0},  {1, 1, 0, -1, 0}};
  const char *names[] = {"wavelength", "wavelength", "wavelength", "wavelength",
                         "amplitude",  "amplitude",  "offset",     "octaves",
                         "octaves",    "octaves"};
  for (int i = 0; i < 10; i++)
    OCT_EINVAL(oc_turbulence(&bads[i], &e), e, names[i]);
  nz.octaves = 16;
  t = OCT_OK(oc_turbulence(&nz, &e));
  oc_node_release(t);
}
END_TEST

/* err may be NULL: the constructor still refuses, without crashing. */
START_TEST(invalid_with_null_err) {
  oc_vec3 o = {0, 0, 0}, x = {1, 0, 0};
  ck_assert_ptr_null(oc_point(o, -1, 1, NULL));
  ck_assert_ptr_null(oc_sphere(o, 1, 0, 1, NULL));
  ck_assert_ptr_null(oc_box(o, x, NAN, 1, NULL));
  ck_assert_ptr_null(oc_segment(o, x, INFINITY, 1, NULL));
  ck_assert_ptr_null(oc_curve(&o, 1, 0, 1, 1, NULL));
  ck_assert_ptr_null(oc_cone(o, o, 1, 1, 1, NULL));
  ck_assert_ptr_null(oc_plane(o, o, 1, 1, NULL));
  oc_noise nz = {0, 1, 0, 3, 0};
  ck_assert_ptr_null(oc_turbulence(&nz, NULL));
}
END_TEST

/* Node introspection of primitives. */
START_TEST(node_kinds) {
  oc_error e;
  oc_vec3 o = {0, 0, 0}, x = {1, 0, 0};
  oc_node *n = OCT_OK(oc_point(o, 1, 1, &e));
  ck_assert_str_eq(oc_node_kind(n), "point");
  ck_assert_uint_eq(oc_node_child_count(n), 0);
  oc_node_release(n);
  n = OCT_OK(oc_cone(o, x, 1, 1, 1, &e));
  ck_assert_str_eq(oc_node_kind(n), "cone");
  oc_node_release(n);
  oc_noise nz = {1, 1, 0, 3, 0};
  n = OCT_OK(oc_turbulence(&nz, &e));
  ck_assert_str_eq(oc_node_kind(n), "turbulence");
  oc_node_release(n);
}
END_TEST

int main(void) {
  Suite *s = suite_create("prims");
  TCase *tc = tcase_create("prims");
  tcase_set_timeout(tc, 120);
  tcase_add_loop_test(tc, value_matches_formula, 0, P_NKINDS);
  tcase_add_test(tc, value_on_boundaries);
  tcase_add_test(tc, curve_special_cases);
  tcase_add_loop_test(tc, gradient_matches_differences, 0, P_NKINDS);
  tcase_add_test(tc, gradient_direction);
  tcase_add_loop_test(tc, bounds_contain_support, 0, P_NKINDS);
  tcase_add_test(tc, bounds_of_axis_plane);
  tcase_add_loop_test(tc, lipschitz_bound, 0, P_NKINDS);
  tcase_add_test(tc, lipschitz_point_exact);
  tcase_add_test(tc, turbulence_values);
  tcase_add_test(tc, turbulence_is_core_turbulence);
  tcase_add_test(tc, turbulence_gradient_bounds_lipschitz);
  tcase_add_test(tc, invalid_parameters);
  tcase_add_test(tc, invalid_with_null_err);
  tcase_add_test(tc, node_kinds);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
