/*
** test_etrace.c — rendering elevation surfaces z = f(x, y): traced
** depths against a dense fixed-step march (an fBm heightfield and an
** analytic source defined here), the accelerated and sphere tracers
** against each other and their height-call counts, holes from a weight,
** whole renders (AOVs, statistics, thread-count determinism) and bad
** sources.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"
#include "outcrop.h"
#include "render/etrace.h"
#include "render/render.h"

#define PI 3.14159265358979323846

/* ---- an analytic source: f = B + A sin(x / w) cos(y / w) ---------------- */

typedef struct wave {
  double A, B, w;
} wave;

static double wave_h(void *ud, double x, double y, double g[2]) {
  const wave *s = ud;
  double sx = sin(x / s->w), cx = cos(x / s->w);
  double sy = sin(y / s->w), cy = cos(y / s->w);
  if (g) {
    g[0] = s->A / s->w * cx * cy;
    g[1] = -s->A / s->w * sx * sy;
  }
  return s->B + s->A * sx * cy;
}

/* |grad f| <= A / w everywhere: a local range from the centre's value. */
static void wave_range(void *ud, double x0, double y0, double x1, double y1,
                       double *lo, double *hi) {
  const wave *s = ud;
  double c = wave_h(ud, 0.5 * (x0 + x1), 0.5 * (y0 + y1), NULL);
  double r = s->A / s->w * 0.5 * hypot(x1 - x0, y1 - y0);
  *lo = fmax(c - r, s->B - s->A);
  *hi = fmin(c + r, s->B + s->A);
}

static double wave_slope(void *ud, double x0, double y0, double x1, double y1) {
  (void)x0, (void)y0, (void)x1, (void)y1;
  const wave *s = ud;
  return s->A / s->w;
}

static wave WAVE = {40, 10, 60};

static oc_elevation wave_source(void) {
  /* no weight, no joint bound, no row path, no model, no coarser levels
  ** (the last six): a surface everywhere */
  oc_elevation e = {wave_h, wave_range, wave_slope, NULL, NULL, &WAVE,
                    -500,   -500,       500,        500,  NULL, NULL,
                    NULL,   NULL,       NULL,       NULL};
  return e;
}

/* ---- an fBm heightfield ------------------------------------------------ */

static oc_heightfield *fbm_grid(void) {
  oc_heightfield_grid g = {257, 257, 4, 0, 0};
  oc_noise nz = {300, 120, 0, 6, 7};
  oc_progress none = {0};
  oc_error e;
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, none, &e);
  ck_assert_msg(hf, "%s", e.msg);
  return hf;
}

/* ---- rays -------------------------------------------------------------- */

static oc_render_params view(oc_vec3 eye, oc_vec3 target, int w, int h) {
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = eye;
  rp.camera.target = target;
  rp.camera.up = oct_v(0, 0, 1);
  rp.camera.fov = 50;
  rp.width = w;
  rp.height = h;
  return rp;
}

/* The pinhole ray through pixel (i, j), written independently of lib/. */
static oc_vec3 pixel_ray(const oc_render_params *rp, int i, int j) {
  oc_vec3 w = oct_sub(rp->camera.target, rp->camera.eye);
  w = oct_mul(w, 1 / oct_len(w));
  oc_vec3 r = oct_cross(w, rp->camera.up);
  r = oct_mul(r, 1 / oct_len(r));
  oc_vec3 u = oct_cross(r, w);
  double th = tan(rp->camera.fov * PI / 360);
  double x = ((i + 0.5) / rp->width * 2 - 1) * th * rp->width / rp->height;
  double y = (1 - (j + 0.5) / rp->height * 2) * th;
  oc_vec3 d = oct_add(w, oct_add(oct_mul(r, x), oct_mul(u, y)));
  return oct_mul(d, 1 / oct_len(d));
}

/* First t in [0, t1] where o + t d is on or below the surface inside the
** domain x [its lowest elevation, oo) (and where the weight allows), by
** fixed steps ds then bisection; INFINITY when none. */
static double march(const oc_esurface *es, oc_vec3 o, oc_vec3 d, double t1,
                    double ds) {
  const oc_elevation *s = es->src;
  double prev = 0, zlo, zhi;
  s->range(s->ud, s->x0, s->y0, s->x1, s->y1, &zlo, &zhi);
  int above = 0; /* the sample before was above the surface */
  for (double t = 0; t <= t1; prev = t, t += ds) {
    oc_vec3 p = oct_add(o, oct_mul(d, t));
    if (p.x < s->x0 || p.x > s->x1 || p.y < s->y0 || p.y > s->y1 || p.z < zlo) {
      above = 0;
      continue;
    }
    double h = p.z - s->height(s->ud, p.x, p.y, NULL);
    int hole = es->weight && es->weight(es->wud, p.x, p.y) < es->T;
    if (hole || h > 0) {
      above = h > 0;
      continue;
    }
    if (!above) return t; /* through a side of the domain or a hole's */
    double a = prev, b = t;
    for (int k = 0; k < 40; k++) {
      double m = 0.5 * (a + b);
      oc_vec3 q = oct_add(o, oct_mul(d, m));
      if (q.z - s->height(s->ud, q.x, q.y, NULL) > 0)
        a = m;
      else
        b = m;
    }
    return b;
  }
  return INFINITY;
}

/* Traces nx x ny pixel rays with both tracers and the march: every hit
** within the march's step and the tracers' tolerance, the same pixels hit
** (a grazing ray or two may differ), the tracers within the tolerance of
** each other; returns the height calls of each tracer. */
static void compare(const oc_esurface *es, const oc_render_params *rp,
                    double ds, double evals[2]) {
  /* the tolerance of a 1080-line image: the rays are a sparse sample */
  double pixel = 2 * tan(rp->camera.fov * PI / 360) / 1080;
  double eps_k = 0.25 * pixel;
  oc_vec3 tw = oct_sub(rp->camera.target, rp->camera.eye);
  double scale = oct_len(tw), eps_min = 1e-7 * scale;
  oc_etracer tr[2];
  oc_etracer_init(&tr[0], es, OC_TRACE_SEGMENT, eps_k, eps_min);
  oc_etracer_init(&tr[1], es, OC_TRACE_SPHERE, eps_k, eps_min);
  int hits = 0, differ = 0, n = rp->width * rp->height;
  evals[0] = evals[1] = 0;
  for (int j = 0; j < rp->height; j++)
    for (int i = 0; i < rp->width; i++) {
      oc_vec3 d = pixel_ray(rp, i, j);
      double t[2];
      int h0 =
          oc_etrace(&tr[0], rp->camera.eye, d, 0, 1e5, 0, &t[0], &evals[0]);
      int h1 =
          oc_etrace(&tr[1], rp->camera.eye, d, 0, 1e5, 0, &t[1], &evals[1]);
      double tref = march(es, rp->camera.eye, d, 4 * scale, ds);
      if ((h0 != 0) != isfinite(tref) || (h1 != 0) != isfinite(tref)) {
        differ++;
        continue;
      }
      if (!h0) continue;
      hits++;
      double e = eps_k * tref + eps_min;
      /* a step can cross a ridge thinner than itself: the march's step
      ** and the tolerance bound the difference, but it is in depth */
      ck_assert_msg(fabs(t[0] - tref) <= ds + 4 * e,
                    "pixel %d %d: accelerated %.6f, march %.6f", i, j, t[0],
                    tref);
      ck_assert_msg(fabs(t[1] - tref) <= ds + 4 * e,
                    "pixel %d %d: sphere %.6f, march %.6f", i, j, t[1], tref);
      ck_assert_msg(fabs(t[0] - t[1]) <= 4 * e,
                    "pixel %d %d: accelerated %.6f, sphere %.6f", i, j, t[0],
                    t[1]);
    }
  ck_assert_msg(hits > n / 3, "only %d of %d rays hit", hits, n);
  ck_assert_msg(differ <= n / 100, "%d of %d rays disagree on a hit", differ,
                n);
}

START_TEST(heightfield_against_march) {
  oc_heightfield *hf = fbm_grid();
  oc_elevation src;
  oc_error e;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  oc_render_params rp =
      view(oct_v(-150, -250, 450), oct_v(600, 500, 20), 24, 16);
  double ev[2];
  compare(&es, &rp, 0.05, ev);
  /* the local bounds and the doubling step save most of the calls */
  ck_assert_msg(ev[0] * 2 < ev[1], "accelerated %g calls, sphere %g", ev[0],
                ev[1]);
  src.release(src.ud);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(analytic_against_march) {
  oc_elevation src = wave_source();
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  oc_render_params rp =
      view(oct_v(-600, -700, 300), oct_v(100, 100, -60), 24, 16);
  double ev[2];
  compare(&es, &rp, 0.05, ev);
  ck_assert_msg(ev[0] < ev[1], "accelerated %g calls, sphere %g", ev[0], ev[1]);
  /* also from straight above, where the steps are the heights */
  rp = view(oct_v(1, 2, 400), oct_v(0, 0, 0), 16, 16);
  compare(&es, &rp, 0.02, ev);
}
END_TEST

/* An elevation tree, traced on its first-order models (oc_elevation's
** taylor: model steps, over-relaxed), against the dense march and the
** sphere tracer: noisy hills blended on a base, a river replaced in (the
** zero-set rule and a box-bound fallback), crags added below an altitude,
** the whole moved by a transform; its holes from the weight. */
#ifdef __SANITIZE_ADDRESS__
#define TREE_W 8
#define TREE_H 6
#else
#define TREE_W 14
#define TREE_H 10
#endif

static double tree_weight(void *wud, double x, double y) {
  return oc_enode_weight(wud, x, y);
}

START_TEST(tree_models_against_march) {
  oc_error err;
  oc_enode *k[4];
  oc_enode_disc_params dp[4] = {
      {0, 0, 900, 40, {OC_ENOISE_PLAIN, 20, 250, 6, 0, 0, 1}},
      {120, 80, 220, 110, {OC_ENOISE_PLAIN, 25, 120, 5, 0, 0, 2}},
      {-150, 60, 160, 90, {OC_ENOISE_RIDGED, 20, 90, 5, 0, 0, 3}},
      {60, -140, 130, 60, {OC_ENOISE_TURBULENCE, 15, 60, 5, 0, 0, 4}}};
  for (int i = 0; i < 4; i++)
    ck_assert_ptr_nonnull(k[i] = oc_enode_disc(&dp[i], &err));
  oc_enode *land = oc_enode_blend(k, 4, &err);
  oc_vec3 pts[3] = {{-400, -300, 35}, {0, -20, 40}, {400, 250, 45}};
  oc_enode_river_params rp = {pts, 3, OC_ECURVE_CATMULL, OC_RIVER_RIVER, 0,
                              0,   0};
  oc_enode *river = oc_enode_river(&rp, &err);
  oc_enode *rep = oc_enode_replace(land, river, 0, &err);
  oc_enode_disc_params cp = {
      -80, -60, 120, 12, {OC_ENOISE_TURBULENCE, 8, 30, 4, 0, 0, 5}};
  oc_enode *crags = oc_enode_disc(&cp, &err);
  oc_enode_add_params ap = {0, 1, 70, 15, 0, 0, 0, 0};
  oc_enode *add = oc_enode_add(rep, crags, &ap, &err);
  oc_enode_xform xf = {20, -10, 20, 1.2, 1, 0};
  oc_enode *tree = oc_enode_transform(add, &xf, &err);
  ck_assert_ptr_nonnull(tree);
  oc_elevation src;
  double dom[4] = {-450, -450, 450, 450};
  ck_assert_int_eq(oc_enode_elevation(tree, dom, &src, &err), OC_OK);
  ck_assert_ptr_nonnull(src.taylor);
  oc_esurface es = {&src, tree_weight, tree, 0.5, NULL};
  oc_render_params v =
      view(oct_v(-600, -550, 380), oct_v(60, 60, -150), TREE_W, TREE_H);
  double ev[2];
  compare(&es, &v, 0.25, ev);
  ck_assert_msg(ev[0] * 2 < ev[1], "models %g calls, sphere %g", ev[0], ev[1]);
  /* grazing, from low down */
  v = view(oct_v(-500, 420, 150), oct_v(100, -100, -20), TREE_W, TREE_H / 2);
  compare(&es, &v, 0.25, ev);
  src.release(src.ud);
  oc_enode *rel[] = {k[0],  k[1], k[2],  k[3], land,
                     river, rep,  crags, add,  tree};
  for (size_t i = 0; i < sizeof rel / sizeof *rel; i++)
    oc_enode_release(rel[i]);
}
END_TEST

/* A flat ground f = 0 whose models declare a curvature remainder C r^2
** (a loose but valid bound): a ray descending at a shallow slope takes
** model steps the remainder limits, relaxed (etrace.c TRELAX). Each
** taylor call records its sample. */
typedef struct curved_flat {
  double C, top; /* the remainder's r^2 term, the ranges' top */
  int n;
  double x[4096];
} curved_flat;

static double flat_h(void *ud, double x, double y, double g[2]) {
  (void)ud, (void)x, (void)y;
  if (g) g[0] = g[1] = 0;
  return 0;
}

static void flat_range(void *ud, double x0, double y0, double x1, double y1,
                       double *lo, double *hi) {
  const curved_flat *c = ud;
  (void)x0, (void)y0, (void)x1, (void)y1;
  *lo = 0, *hi = c->top; /* loose */
}

static double flat_slope(void *ud, double x0, double y0, double x1, double y1) {
  (void)ud, (void)x0, (void)y0, (void)x1, (void)y1;
  return 1;
}

static double flat_taylor(void *ud, double x, double y, double R, double g[2],
                          double e[3], int *boxes) {
  curved_flat *c = ud;
  (void)y, (void)R, (void)boxes;
  if (c->n < 4096) c->x[c->n++] = x;
  g[0] = g[1] = 0;
  e[0] = e[1] = 0, e[2] = c->C;
  return 0;
}

/* z = 0 over a 4 km square, its models' remainder cf's */
static oc_elevation curved_flat_source(curved_flat *cf) {
  oc_elevation src = {flat_h, flat_range, flat_slope,  NULL, NULL, cf,
                      -2000,  -2000,      2000,        2000, NULL, NULL,
                      NULL,   NULL,       flat_taylor, NULL};
  return src;
}

/* Flat ground z = 0 whose models have no linear part and a slope a (a
** remainder a r), its range queries counted. */
typedef struct rough_flat {
  double a;
  int ranges;
} rough_flat;

static void rough_range(void *ud, double x0, double y0, double x1, double y1,
                        double *lo, double *hi) {
  (void)x0, (void)y0, (void)x1, (void)y1;
  ((rough_flat *)ud)->ranges++;
  *lo = 0, *hi = 50; /* loose */
}

static double rough_taylor(void *ud, double x, double y, double R, double g[2],
                           double e[3], int *boxes) {
  (void)x, (void)y, (void)R, (void)boxes;
  g[0] = g[1] = 0;
  e[0] = e[2] = 0, e[1] = ((rough_flat *)ud)->a;
  return 0;
}

/* A ray on models asks the box bound only where a model's step is under
** TBOX (1 %) of its candidate (the model is poor there, the box may stride
** on): from a first step of about 9 % of its candidate (models of slope
** 1) the ray makes no range query (3 at TBOX 0.1); from one of 0.5 %
** (slope 20) it does (none at TBOX 0); both hit z = 0 where the ray
** does. */
START_TEST(models_ask_boxes_only_when_poor) {
  for (int k = 0; k < 2; k++) {
    rough_flat rf = {k ? 20 : 1, 0};
    oc_elevation src = {flat_h, rough_range, flat_slope,   NULL, NULL, &rf,
                        -2000,  -2000,       2000,         2000, NULL, NULL,
                        NULL,   NULL,        rough_taylor, NULL};
    oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
    oc_etracer tr;
    oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, 1e-4, 1e-6);
    rf.ranges = 0;
    oc_vec3 o = oct_v(0, 0, 10), u = oct_v(1, 0, -0.1), n;
    u = oct_mul(u, 1 / oct_len(u));
    double t, ev = 0, exact = -o.z / u.z;
    /* (starting on models, a candidate of 100 m: the first step 9.1 and
    ** 0.50 m) */
    ck_assert_int_eq(
        oc_etrace_hit(&tr, o, u, 0, 1e4, 0, 100, NULL, &t, &n, &ev), 1);
    ck_assert_msg(fabs(t - exact) <= 1e-4 * exact + 1e-6, "hit %.6f, %.6f", t,
                  exact);
    if (k)
      ck_assert_msg(rf.ranges > 0, "a %g: %d ranges, %g calls", rf.a, rf.ranges,
                    ev);
    else
      ck_assert_msg(rf.ranges == 0, "a %g: %d ranges, %g calls", rf.a,
                    rf.ranges, ev);
  }
}
END_TEST

/* A relaxed model step goes a tolerance past TRELAX times the proved one
** (the tolerance a step may leave unproved), and never further: every
** step is at most TRELAX times the first zero of the model's bound plus
** the tolerance, and the steps well above the tolerance take that
** tolerance; the hit is where the ray meets z = 0. */
START_TEST(relaxed_steps_take_the_tolerance) {
  /* (the ray starts inside the domain's box) */
  curved_flat cf = {1e-3, 50, 0, {0}};
  oc_elevation src = curved_flat_source(&cf);
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  double eps_k = 1e-3, eps_min = 1e-6;
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  oc_vec3 o = oct_v(-1500, 0, 10), u = oct_v(1, 0, -0.005);
  u = oct_mul(u, 1 / oct_len(u));
  double t, ev = 0;
  oc_vec3 nrm;
  /* a candidate step: the ray starts on models */
  ck_assert_int_eq(oc_etrace_hit(&tr, o, u, 0, 1e5, 0, 10, NULL, &t, &nrm, &ev),
                   1);
  double exact = -o.z / u.z;
  ck_assert_msg(fabs(t - exact) <= eps_k * exact + eps_min, "hit %.6f, %.6f", t,
                exact);
  ck_assert(fabs(nrm.z - 1) < 1e-12);
  ck_assert_int_gt(cf.n, 3);
  int wide = 0, long_steps = 0;
  for (int i = 0; i + 1 < cf.n; i++) {
    double ta = (cf.x[i] - o.x) / u.x, tb = (cf.x[i + 1] - o.x) / u.x;
    double h = o.z + ta * u.z, c2 = cf.C * u.x * u.x;
    /* the first zero of h - (-u_z) s - C s^2 */
    double root = 2 * h / (-u.z + sqrt(u.z * u.z + 4 * c2 * h));
    double tl = eps_k * tb + eps_min;
    ck_assert_msg(tb - ta <= 1.6 * root + tl + 1e-9 * tb,
                  "step %d: %.6f from %.6f, proved %.6f", i, tb - ta, ta, root);
    if (root > 2 * tl && tb > ta) {
      long_steps++;
      wide += tb - ta > 1.6 * root + 0.5 * tl;
    }
  }
  ck_assert_int_gt(long_steps, 3);
  ck_assert_msg(wide * 2 > long_steps,
                "%d of %d relaxed steps took the tolerance", wide, long_steps);
  /* steeply down on a tighter remainder, where a relaxed sample lands
  ** under the ground: it is the ray's last model query (its model
  ** brackets the hit: no plain step back) */
  cf.C = 0.05, cf.n = 0;
  u = oct_v(1, 0, -1);
  u = oct_mul(u, 1 / oct_len(u));
  ck_assert_int_eq(oc_etrace_hit(&tr, o, u, 0, 1e5, 0, 1, NULL, &t, &nrm, &ev),
                   1);
  exact = -o.z / u.z;
  ck_assert_msg(fabs(t - exact) <= eps_k * exact + eps_min, "hit %.6f, %.6f", t,
                exact);
  ck_assert_int_gt(cf.n, 2);
  for (int i = 0; i + 1 < cf.n; i++) {
    double ti = (cf.x[i] - o.x) / u.x;
    ck_assert_msg(o.z + ti * u.z > 0, "sample %d of %d under the ground", i,
                  cf.n);
  }
}
END_TEST

/* A beam's model steps are over-relaxed as a ray's (etrace.c BRELAX): on
** the curved flat ground, some of its steps go past the least first zero
** of its corners' bounds (a plain step never does), and the depth it
** returns is still free for every corner ray. */
START_TEST(beam_steps_relaxed) {
  /* (the beam strides on the ranges down to z = 5, then on models) */
  curved_flat cf = {1e-3, 5, 0, {0}};
  oc_elevation src = curved_flat_source(&cf);
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, 1e-4, 1e-6);
  oc_ebeam b;
  b.o = oct_v(-1500, 0, 10);
  b.w = oct_v(1, 0, -0.005);
  b.w = oct_mul(b.w, 1 / oct_len(b.w));
  b.r = oct_v(0, 1, 0);
  b.v = oct_v(0.005, 0, 1);
  b.v = oct_mul(b.v, 1 / oct_len(b.v));
  b.x0 = b.y0 = -1e-4, b.x1 = b.y1 = 1e-4;
  double evals = 0, next = 0;
  oc_emodel m = {0};
  double d = oc_etrace_beam(&tr, &b, 0, 1e5, NULL, &evals, &next, &m);
  ck_assert(isfinite(d) && d > 0);
  ck_assert_int_gt(cf.n, 3);
  oc_vec3 D[4], c = b.w; /* the corners' rays, the axis (x = y = 0) */
  for (int j = 0; j < 4; j++) {
    double x = j & 1 ? b.x1 : b.x0, y = j & 2 ? b.y1 : b.y0;
    D[j] = oct_add(b.w, oct_add(oct_mul(b.r, x), oct_mul(b.v, y)));
    /* descending: free before d when above the ground at d */
    ck_assert_msg(b.o.z + d * D[j].z > 0, "corner %d under at %.6f", j, d);
  }
  int past = 0;
  for (int i = 0; i + 1 < cf.n; i++) {
    double da = (cf.x[i] - b.o.x) / c.x, db = (cf.x[i + 1] - b.o.x) / c.x;
    double least = INFINITY;
    for (int j = 0; j < 4; j++) {
      double ax = da * (D[j].x - c.x), ay = da * (D[j].y - c.y);
      double ra = hypot(ax, ay), bxy = hypot(D[j].x, D[j].y);
      double c0 = b.o.z + da * D[j].z - cf.C * ra * ra;
      double c1 = 2 * cf.C * ra * bxy - D[j].z, c2 = cf.C * bxy * bxy;
      least = fmin(least, 2 * c0 / (c1 + sqrt(c1 * c1 + 4 * c2 * c0)));
    }
    past += db - da > 1.2 * least;
  }
  ck_assert_msg(past > 0, "no beam step past its proof in %d", cf.n);
}
END_TEST

/* A hit is located to OC_ETRACE_REFINE_STOP of the tolerance, on
** the near side: from straight above (h falls along every ray, one
** crossing), h > 0 at the hit and h <= 0 that much further. Its normal
** is the height gradient's there, mostly taken from the refinement's
** samples. */
START_TEST(hits_located) {
  oc_elevation src = wave_source();
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  oc_render_params rp = view(oct_v(1, 2, 400), oct_v(0, 0, 0), 16, 16);
  double eps_k = 0.25 * 2 * tan(rp.camera.fov * PI / 360) / 1080;
  double eps_min = 1e-7 * 400, ev = 0, calls = 0;
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  for (int j = 0; j < rp.height; j++)
    for (int i = 0; i < rp.width; i++) {
      oc_vec3 d = pixel_ray(&rp, i, j), o = rp.camera.eye;
      double t, tn, evn = 0;
      ck_assert_int_eq(oc_etrace(&tr, o, d, 0, 1e5, 0, &t, &ev), 1);
      double q = t + OC_ETRACE_REFINE_STOP * (eps_k * t + eps_min) * (1 + 1e-9);
      oc_vec3 p = oct_add(o, oct_mul(d, t)), r = oct_add(o, oct_mul(d, q));
      ck_assert_msg(p.z - wave_h(&WAVE, p.x, p.y, NULL) > 0, "pixel %d %d", i,
                    j);
      ck_assert_msg(r.z - wave_h(&WAVE, r.x, r.y, NULL) <= 0,
                    "pixel %d %d: the hit %.9f is short of the surface", i, j,
                    t);
      oc_vec3 nm;
      ck_assert_int_eq(
          oc_etrace_hit(&tr, o, d, 0, 1e5, 0, 0, NULL, &tn, &nm, &evn), 1);
      ck_assert(tn == t);
      double g[2];
      wave_h(&WAVE, p.x, p.y, g);
      double l = sqrt(1 + g[0] * g[0] + g[1] * g[1]);
      ck_assert_msg(fabs(nm.x + g[0] / l) < 1e-12 &&
                        fabs(nm.y + g[1] / l) < 1e-12 &&
                        fabs(nm.z - 1 / l) < 1e-12,
                    "pixel %d %d: normal %g %g %g", i, j, nm.x, nm.y, nm.z);
      calls += evn;
    }
  /* the normals from the refinement's samples: a call of its own only
  ** where every sample fell under the surface (the last one closing the
  ** bracket from below: 3 of these 256 hits; 3 % of them at most) */
  ck_assert_msg(calls >= ev && calls <= ev + 0.03 * rp.width * rp.height,
                "%g calls with normals, %g without", calls, ev);
}
END_TEST

/* On an elevation tree's models, a hit that the model of the sample
** under the surface locates alone takes its normal from that model's
** linear part (the gradient at the sample, a tenth of a tolerance or
** so past the hit) where the model is quadratic, no call: every normal is
** the height gradient's at a point of the ray within a tolerance past
** the hit, to 1e-3 (radians), some of them not the hit's own, and the
** normals cost at most a call on 3 % of the hits. */
START_TEST(model_hit_normals) {
  oc_error err;
  oc_enode *k[2];
  oc_enode_disc_params dp[2] = {
      {0, 0, 900, 40, {OC_ENOISE_PLAIN, 20, 250, 6, 0, 0, 1}},
      {120, 80, 220, 110, {OC_ENOISE_PLAIN, 25, 120, 5, 0, 0, 2}}};
  for (int i = 0; i < 2; i++)
    ck_assert_ptr_nonnull(k[i] = oc_enode_disc(&dp[i], &err));
  oc_enode *tree = oc_enode_blend(k, 2, &err);
  ck_assert_ptr_nonnull(tree);
  oc_elevation src;
  double dom[4] = {-400, -400, 400, 400};
  ck_assert_int_eq(oc_enode_elevation(tree, dom, &src, &err), OC_OK);
  oc_esurface es = {&src, tree_weight, tree, 0.5, NULL};
  oc_render_params rp = view(oct_v(-500, -450, 300), oct_v(60, 60, 40), 24, 16);
  double eps_k = 0.25 * 2 * tan(rp.camera.fov * PI / 360) / 1080;
  double eps_min = 1e-7 * 400, ev = 0, calls = 0;
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  int hits = 0, off = 0;
  for (int j = 0; j < rp.height; j++)
    for (int i = 0; i < rp.width; i++) {
      oc_vec3 d = pixel_ray(&rp, i, j), o = rp.camera.eye, nm;
      double t, tn, evn = 0;
      double ev0 = ev;
      if (oc_etrace(&tr, o, d, 0, 1e5, 0, &t, &ev) != 1) {
        ev = ev0; /* (misses and walls: not counted) */
        continue;
      }
      ck_assert_int_eq(
          oc_etrace_hit(&tr, o, d, 0, 1e5, 0, 0, NULL, &tn, &nm, &evn), 1);
      ck_assert(tn == t);
      calls += evn, hits++;
      /* the closest normal along [t, t + tol] (401 samples) */
      double tl = eps_k * t + eps_min, best = INFINITY, at_hit = 0;
      for (int m = 0; m <= 400; m++) {
        oc_vec3 p = oct_add(o, oct_mul(d, t + tl * m / 400));
        double g[2];
        src.height(src.ud, p.x, p.y, g);
        double l = sqrt(1 + g[0] * g[0] + g[1] * g[1]);
        oc_vec3 n = oct_v(-g[0] / l, -g[1] / l, 1 / l);
        double a = oct_len(oct_sub(n, nm));
        if (m == 0) at_hit = a;
        best = fmin(best, a);
      }
      ck_assert_msg(best < 1e-3, "pixel %d %d: normal %g off", i, j, best);
      off += at_hit > 1e-9;
    }
  ck_assert_int_gt(hits, rp.width * rp.height / 4);
  ck_assert_msg(off > 0, "no normal from a model (%d hits)", hits);
  ck_assert_msg(calls >= ev && calls <= ev + 0.03 * hits,
                "%g calls with normals, %g without", calls, ev);
  src.release(src.ud);
  oc_enode_release(tree);
  for (int i = 0; i < 2; i++)
    oc_enode_release(k[i]);
}
END_TEST

/* No surface where x < 0: those rays go on to the far side of the hole,
** or out. */
static double half(void *wud, double x, double y) {
  (void)wud, (void)y;
  return x < 0 ? 0 : 1;
}

START_TEST(weight_makes_holes) {
  oc_elevation src = wave_source();
  oc_esurface es = {&src, half, NULL, 0.5, NULL};
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, 1e-4, 1e-6);
  double ev = 0, t;
  /* straight down into the hole: nothing */
  ck_assert(!oc_etrace(&tr, oct_v(-100, 30, 200), oct_v(0, 0, -1), 0, 1e4, 0,
                       &t, &ev));
  /* straight down beside it: the surface */
  ck_assert(
      oc_etrace(&tr, oct_v(100, 30, 200), oct_v(0, 0, -1), 0, 1e4, 0, &t, &ev));
  ck_assert(fabs(200 - t - wave_h(&WAVE, 100, 30, NULL)) < 1e-3);
  /* oblique rays against the march, which honours the weight too */
  oc_render_params rp = view(oct_v(-600, 0, 200), oct_v(100, 0, 0), 16, 12);
  int hits = 0;
  for (int j = 0; j < rp.height; j++)
    for (int i = 0; i < rp.width; i++) {
      oc_vec3 d = pixel_ray(&rp, i, j);
      double tref = march(&es, rp.camera.eye, d, 3000, 0.05);
      int h = oc_etrace(&tr, rp.camera.eye, d, 0, 1e5, 0, &t, &ev);
      if (!h || !isfinite(tref)) continue;
      hits++;
      oc_vec3 p = oct_add(rp.camera.eye, oct_mul(d, t));
      ck_assert_msg(p.x >= -0.5, "hit in the hole at x = %g", p.x);
      ck_assert_msg(fabs(t - tref) < 0.05 + 4e-4 * t,
                    "pixel %d %d: %g, march %g", i, j, t, tref);
    }
  ck_assert(hits > 20);
}
END_TEST

static oc_esurface tree_surface(oc_enode *tree, const double dom[4],
                                oc_elevation *src);

/* The tree's weight bound on a box (oc_esurface's weight_bound: the
** source's weight_range), its calls counted (one thread). */
static long weight_bounds;
static const oc_elevation *weight_src;
static void counted_weight_range(void *wud, double x0, double y0, double x1,
                                 double y1, double *lo, double *hi,
                                 double *lip) {
  weight_src->weight_range(wud, x0, y0, x1, y1, lo, hi, lip);
  weight_bounds++;
}

/* Rays under the surface level of a hole cross it on the weight's bound
** (oc_esurface's weight_bound) instead of tolerance steps: a disc whose
** terrain ends at 0.4542 of its radius (182 m), a second one beyond the
** hole (from 509 m), and a pillar 6 m wide in the hole at x = 300 (its
** terrain 3 m about its centre: alpha_A + alpha_C >= 1/2). The hits,
** walls included, are the dense march's and those without the bound, and
** the bound saves most calls; a ray along the hole's floor meets the
** pillar's wall (the weight's slope keeps it from stepping over it). */
#ifdef __SANITIZE_ADDRESS__
#define HOLE_W 8
#define HOLE_H 6
#else
#define HOLE_W 16
#define HOLE_H 12
#endif

START_TEST(holes_crossed_on_weight_bound) {
  oc_error err;
  oc_enode_disc_params dp[3] = {
      {0, 0, 400, 20, {OC_ENOISE_PLAIN, 6, 80, 4, 0, 0, 1}},
      {600, 0, 200, 60, {OC_ENOISE_PLAIN, 10, 60, 4, 0, 0, 2}},
      {300, 0, 6, 80, {OC_ENOISE_NONE, 0, 0, 0, 0, 0, 0}}};
  oc_enode *k[4];
  for (int i = 0; i < 3; i++)
    ck_assert_ptr_nonnull(k[i] = oc_enode_disc(&dp[i], &err));
  ck_assert_ptr_nonnull(k[3] = oc_enode_blend(k, 3, &err));
  const double dom[4] = {-300, -250, 850, 250};
  oc_elevation src;
  oc_esurface plain = tree_surface(k[3], dom, &src), es = plain;
  weight_src = &src;
  es.weight_bound = counted_weight_range;
  oc_etracer tb, tn;
  double eps_k = 1e-4, eps_min = 1e-6;
  oc_etracer_init(&tb, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  oc_etracer_init(&tn, &plain, OC_TRACE_SEGMENT, eps_k, eps_min);
  /* along the hole's floor (10 m, under A's f of about 20): the pillar's
  ** wall at x = 297 (alpha_C = 0.416 there) */
  double t, evb = 0, evn = 0;
  weight_bounds = 0;
  ck_assert_int_eq(
      oc_etrace(&tb, oct_v(200, 0, 10), oct_v(1, 0, 0), 0, 1e4, 0, &t, &evb),
      2);
  double tw = march(&es, oct_v(200, 0, 10), oct_v(1, 0, 0), 200, 0.01);
  ck_assert_msg(fabs(t - tw) < 0.02 + 2 * (eps_k * t + eps_min),
                "wall at %.4f, march %.4f", t, tw);
  ck_assert(fabs(t - 97.0) < 0.1);
  ck_assert(weight_bounds > 0);
  /* without it, tolerance steps from t = 0 (growing by 1e-4 a step) give
  ** up before the wall (OC_TRACE_MAX_STEPS) */
  ck_assert_int_eq(
      oc_etrace(&tn, oct_v(200, 0, 10), oct_v(1, 0, 0), 0, 1e4, 0, &t, &evn),
      0);
  ck_assert_msg(evb < 100 && evn >= 16384,
                "with the bound %g calls, "
                "without %g",
                evb, evn);
  /* a view over the first disc, through the hole to the second */
  oc_render_params rp =
      view(oct_v(-250, -60, 45), oct_v(600, 0, 20), HOLE_W, HOLE_H);
  int n = rp.width * rp.height, hits = 0, differ = 0;
  evb = evn = 0;
  for (int j = 0; j < rp.height; j++)
    for (int i = 0; i < rp.width; i++) {
      oc_vec3 d = pixel_ray(&rp, i, j), o = rp.camera.eye;
      double t0, t1;
      int h0 = oc_etrace(&tb, o, d, 0, 1e5, 0, &t0, &evb);
      int h1 = oc_etrace(&tn, o, d, 0, 1e5, 0, &t1, &evn);
      double tref = march(&es, o, d, 1400, 0.05);
      if ((h0 != 0) != isfinite(tref) || (h0 != 0) != (h1 != 0)) {
        differ++;
        continue;
      }
      if (!h0) continue;
      hits++;
      double e = eps_k * tref + eps_min;
      ck_assert_msg(fabs(t0 - tref) <= 0.05 + 4 * e,
                    "pixel %d %d: %.6f, march %.6f", i, j, t0, tref);
      ck_assert_msg(fabs(t0 - t1) <= 4 * e,
                    "pixel %d %d: %.6f, without the bound %.6f", i, j, t0, t1);
    }
  ck_assert_msg(hits > n / 3, "only %d of %d rays hit", hits, n);
  ck_assert_msg(differ <= n / 50, "%d of %d rays disagree", differ, n);
  /* (16 x 12: 3437 calls against 73710) */
  ck_assert_msg(evb * 5 < evn, "with the bound %g calls, without %g", evb, evn);
  src.release(src.ud);
  for (int i = 3; i >= 0; i--)
    oc_enode_release(k[i]);
}
END_TEST

/* ---- beams ------------------------------------------------------------- */

/* The beam through pixels [i0, i1) x [j0, j1) of rp, as render.c makes
** it (written independently of lib/). */
static oc_ebeam pixel_beam(const oc_render_params *rp, int i0, int j0, int i1,
                           int j1) {
  oc_ebeam b;
  oc_vec3 w = oct_sub(rp->camera.target, rp->camera.eye);
  b.w = oct_mul(w, 1 / oct_len(w));
  oc_vec3 r = oct_cross(b.w, rp->camera.up);
  b.r = oct_mul(r, 1 / oct_len(r));
  b.v = oct_cross(b.r, b.w);
  b.o = rp->camera.eye;
  double th = tan(rp->camera.fov * PI / 360),
         a = (double)rp->width / rp->height;
  b.x0 = ((double)i0 / rp->width * 2 - 1) * th * a;
  b.x1 = ((double)i1 / rp->width * 2 - 1) * th * a;
  b.y0 = (1 - (double)j1 / rp->height * 2) * th;
  b.y1 = (1 - (double)j0 / rp->height * 2) * th;
  return b;
}

/* Every ray of a beam, its corners and a grid of rays inside, meets the
** surface (by the dense march) no nearer than the depth the beam proves
** free; the beams go most of the way to the surface; a beam that sees
** only sky proves every ray free. Returns the beams that stopped short. */
static void beams_against_march(const oc_esurface *es,
                                const oc_render_params *rp, int bs, double ds) {
  oc_etracer tr;
  oc_etracer_init(&tr, es, OC_TRACE_SEGMENT, 1e-4, 1e-6);
  int beams = 0, far = 0, sky = 0;
  for (int j0 = 0; j0 < rp->height; j0 += bs)
    for (int i0 = 0; i0 < rp->width; i0 += bs) {
      oc_ebeam b = pixel_beam(rp, i0, j0, i0 + bs, j0 + bs);
      double nb = 0,
             d = oc_etrace_beam(&tr, &b, 0, INFINITY, &nb, NULL, NULL, NULL);
      double tmin = INFINITY;
      for (int v = 0; v <= 4; v++)
        for (int u = 0; u <= 4; u++) {
          double x = b.x0 + (b.x1 - b.x0) * u / 4;
          double y = b.y0 + (b.y1 - b.y0) * v / 4;
          oc_vec3 D = oct_add(b.w, oct_add(oct_mul(b.r, x), oct_mul(b.v, y)));
          double len = oct_len(D);
          double tref = march(es, b.o, oct_mul(D, 1 / len), 5000, ds);
          ck_assert_msg(tref >= d * len - ds,
                        "beam at %d %d: free to %g, a ray meets the surface "
                        "at %g",
                        i0, j0, d * len, tref);
          tmin = fmin(tmin, tref);
        }
      beams++;
      if (!isfinite(tmin)) {
        sky += d == INFINITY;
        continue;
      }
      ck_assert(nb > 0);
      far += d >= 0.5 * tmin;
    }
  ck_assert_msg(far + sky >= beams / 2, "%d of %d beams went half way", far,
                beams);
  ck_assert_msg(sky > 0, "no beam sees only sky");
}

START_TEST(beams_conservative) {
  oc_heightfield *hf = fbm_grid();
  oc_elevation src;
  oc_error e;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_esurface es = {&src, NULL, NULL, 0.5, NULL};
  oc_render_params rp =
      view(oct_v(-150, -250, 450), oct_v(600, 500, 300), 64, 40);
  beams_against_march(&es, &rp, 8, 0.05);
  src.release(src.ud);
  oc_heightfield_release(hf);
  /* the analytic source, and the same with a hole */
  oc_elevation w = wave_source();
  oc_esurface ws = {&w, NULL, NULL, 0.5, NULL};
  rp = view(oct_v(-600, -700, 300), oct_v(100, 100, 200), 48, 32);
  beams_against_march(&ws, &rp, 4, 0.05);
  ws.weight = half;
  beams_against_march(&ws, &rp, 16, 0.05);
}
END_TEST

/* A thin spike on hills: a base disc wide enough that alpha >= 1/2 on the
** whole domain (no holes), noise of amplitude amp, and a spike 120 m tall
** and 8 m in radius added at (sx, sy) (f_A + alpha_B f_B); with bump, a
** second one 100 m tall and 5 m in radius at (bx, by). *made receives
** the nodes to release (NULL-terminated, released in reverse). */
static oc_enode *spike_tree(double sx, double sy, double amp,
                            const double *bump, oc_enode *made[8]) {
  oc_error err;
  oc_enode_disc_params bp = {
      0, 0, 4000, 0, {OC_ENOISE_PLAIN, amp, 150, 4, 0, 0, 7}};
  oc_enode_disc_params sp = {
      sx, sy, 8, 120, {OC_ENOISE_PLAIN, 0, 10, 1, 0, 0, 1}};
  oc_enode_add_params ap = {0, 0, 0, 0, 0, 0, 0, 0};
  int n = 0;
  oc_enode *t = made[n++] = oc_enode_disc(&bp, &err);
  oc_enode *k = made[n++] = oc_enode_disc(&sp, &err);
  t = made[n++] = oc_enode_add(t, k, &ap, &err);
  if (bump) {
    oc_enode_disc_params bb = {
        bump[0], bump[1], 5, 100, {OC_ENOISE_PLAIN, 0, 10, 1, 0, 0, 1}};
    k = made[n++] = oc_enode_disc(&bb, &err);
    t = made[n++] = oc_enode_add(t, k, &ap, &err);
  }
  made[n] = NULL;
  for (int i = 0; i < n; i++)
    ck_assert_ptr_nonnull(made[i]);
  return t;
}

/* The surface of tree on dom (its holes where alpha < 1/2). */
static oc_esurface tree_surface(oc_enode *tree, const double dom[4],
                                oc_elevation *src) {
  oc_error err;
  ck_assert_int_eq(oc_enode_elevation(tree, dom, src, &err), OC_OK);
  return (oc_esurface){src, tree_weight, tree, 0.5, NULL};
}

static void release_made(oc_enode **made) {
  int n = 0;
  while (made[n])
    n++;
  while (n > 0)
    oc_enode_release(made[--n]);
}

/* The beam on models must prove every ray of the beam free, not its axis
** alone: a wide beam looking down onto flat ground whose axis passes far
** from a thin spike that its corner ray meets (a bump beside the beam
** stops its elevation ranges early, so its models carry it on). The
** depth it proves free stays before the spike; a beam proving its axis
** alone, without the margin for its width, strides on past the spike
** (its axis meets the ground at depth 400). A part of the beam at that
** corner, and the corner ray, go on from the model the beam ended on
** (their first step takes it without a call) and still meet the spike. */
START_TEST(beam_margin_spike) {
  oc_enode *made[8];
  const double bump[2] = {60, 40};
  const double dom[4] = {-100, -300, 700, 300};
  oc_elevation src;
  oc_esurface es =
      tree_surface(spike_tree(150, 60, 0.2, bump, made), dom, &src);
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, 1e-4, 1e-6);
  /* looking along +x from 30 m up: r = -y, v = +z */
  oc_ebeam b;
  b.o = oct_v(0, 0, 30), b.w = oct_v(1, 0, 0);
  b.r = oct_v(0, -1, 0), b.v = oct_v(0, 0, 1);
  b.x0 = -0.4, b.x1 = 0.4, b.y0 = -0.1, b.y1 = -0.05;
  double nb = 0, ne = 0, next = 0;
  oc_emodel m = {0};
  double d = oc_etrace_beam(&tr, &b, 0, INFINITY, &nb, &ne, &next, &m);
  ck_assert(ne > 0 && next > 0 && m.ok);
  /* the corner ray (x0, y0) = (-0.4, -0.1) passes over the spike's
  ** centre at depth 150, 15 m up: it meets the spike first */
  oc_vec3 D = oct_v(1, 0.4, -0.1);
  double len = oct_len(D);
  double tc = march(&es, b.o, oct_mul(D, 1 / len), 500, 0.01);
  ck_assert_msg(tc < 150 * len, "the corner ray meets the spike at %g", tc);
  ck_assert_msg(d * len <= tc, "beam free to %g, its corner ray hits at %g",
                d * len, tc);
  /* the corner's part and ray from the beam's model */
  oc_ebeam part = b;
  part.x1 = -0.35, part.y1 = -0.09;
  oc_emodel pm = m;
  double pnext = next, pe = 0, pb = 0;
  double dp = oc_etrace_beam(&tr, &part, d, INFINITY, &pb, &pe, &pnext, &pm);
  /* near the surface, its one range query fails, and it turns to models
  ** (not halving its pieces down to its width: a query each) */
  ck_assert_msg(pb == 1 && pe > 0, "part: %g range queries, %g calls", pb, pe);
  ck_assert_msg(dp >= d && dp * len <= tc,
                "part free from %g to %g, its corner ray hits at %g", d * len,
                dp * len, tc);
  double t, ev = 0, ev0 = 0, t0;
  oc_vec3 u = oct_mul(D, 1 / len), n;
  ck_assert_int_eq(oc_etrace_hit(&tr, b.o, u, d * len * (1 - 1e-12), 1e5, 0,
                                 next * len, &m, &t, &n, &ev),
                   1);
  ck_assert_msg(fabs(t - tc) <= 0.01 + 4 * (1e-4 * tc + 1e-6),
                "the corner ray from the model hits at %g, the march at %g", t,
                tc);
  /* the same hit without the model */
  ck_assert_int_eq(oc_etrace_hit(&tr, b.o, u, d * len * (1 - 1e-12), 1e5, 0,
                                 next * len, NULL, &t0, &n, &ev0),
                   1);
  ck_assert_msg(fabs(t - t0) <= 4 * (1e-4 * tc + 1e-6), "%g and %g", t, t0);
  src.release(src.ud);
  release_made(made);
}
END_TEST

/* Whole renders through the blocks' beams (on models) against every ray
** traced alone from the eye: the same pixels hit and the same depths
** within the tolerance, on a thin spike seen against hills far behind
** (its silhouette between widely differing depths inside blocks), and
** the evals channel counting the beams' calls (fractions of them), the
** same bytes on one thread and two. */
#ifdef __SANITIZE_ADDRESS__
#define SPIKE_W 48
#define SPIKE_H 32
#else
#define SPIKE_W 96
#define SPIKE_H 64
#endif

START_TEST(tiles_see_thin_spike) {
  oc_enode *made[8];
  const double dom[4] = {-900, -900, 900, 900};
  oc_elevation src;
  oc_esurface es = tree_surface(spike_tree(0, 0, 12, NULL, made), dom, &src);
  oc_error err;
  oc_render_params rp =
      view(oct_v(-300, -20, 45), oct_v(0, 0, 40), SPIKE_W, SPIKE_H);
  omp_set_num_threads(1);
  oc_image *g1 = oc_render_surface_geometry(&es, &rp, &err);
  omp_set_num_threads(2);
  oc_image *g = oc_render_surface_geometry(&es, &rp, &err);
  ck_assert_msg(g && g1, "%s", err.msg);
  const float *px = oc_image_cdata(g);
  /* the blocks and their shares are the same on any thread count */
  ck_assert(memcmp(px, oc_image_cdata(g1),
                   (size_t)rp.width * rp.height * OC_RG_COUNT * sizeof *px) ==
            0);
  oc_image_free(g1);
  double pixel = 2 * tan(rp.camera.fov * PI / 360) / rp.height;
  double eps_k = 0.25 * pixel, eps_min = 1e-7 * oct_len(oct_v(300, 20, 5));
  oc_etracer tr;
  oc_etracer_init(&tr, &es, OC_TRACE_SEGMENT, eps_k, eps_min);
  int spike = 0, far = 0, hits = 0, frac = 0, grazing = 0;
  double alone = 0, tiled = 0;
  for (int j = 0; j < rp.height; j++)
    for (int i = 0; i < rp.width; i++) {
      const float *q = px + ((size_t)j * rp.width + i) * OC_RG_COUNT;
      oc_vec3 d = pixel_ray(&rp, i, j);
      double t, ev = 0;
      oc_vec3 nm;
      int h = oc_etrace_hit(&tr, rp.camera.eye, d, 0, 1e5, 0, 0, NULL, &t, &nm,
                            &ev);
      alone += ev; /* normals included */
      tiled += q[OC_RG_EVALS];
      frac += q[OC_RG_EVALS] != floorf(q[OC_RG_EVALS]);
      double tt = q[OC_RG_HIT] > 0 ? q[OC_RG_Z] : INFINITY;
      if (!h) t = INFINITY;
      double near = fmin(t, tt), e = eps_k * near + eps_min;
      if (tt != t && !(fabs(tt - t) <= 4 * e)) {
        /* the two differ only where the nearer hit is a crest the ray
        ** crosses within the tolerance (a step of either may pass over
        ** it): the dense march meets it there and leaves it so soon */
        double tm = march(&es, rp.camera.eye, d, 2 * near, 0.02);
        ck_assert_msg(fabs(tm - near) <= 0.02 + 4 * e,
                      "pixel %d %d: tiled %g, alone %g, march %g", i, j, tt, t,
                      tm);
        double out = tm;
        while (out < tm + 4 * e) {
          oc_vec3 p = oct_add(rp.camera.eye, oct_mul(d, out));
          if (p.z > src.height(src.ud, p.x, p.y, NULL)) break;
          out += 0.01;
        }
        ck_assert_msg(out < tm + 4 * e,
                      "pixel %d %d: tiled %g, alone %g, not a crest", i, j, tt,
                      t);
        grazing++;
        continue;
      }
      if (!h) continue;
      hits++;
      oc_vec3 p = oct_add(rp.camera.eye, oct_mul(d, t));
      spike += hypot(p.x, p.y) < 8 && p.z > 20;
      far += t > 600;
    }
  /* the spike is a few pixels wide, the hills behind it far off */
  ck_assert_msg(spike >= SPIKE_H / 16, "%d pixels on the spike", spike);
  ck_assert_msg(far >= 8, "%d pixels far behind", far);
  ck_assert(hits > rp.width * rp.height / 3);
  ck_assert_msg(grazing <= rp.width * rp.height / 100, "%d rays differ",
                grazing);
  /* the beams' calls are shared by their pixels, and save calls */
  ck_assert(frac > 0);
  ck_assert_msg(tiled < alone, "tiled %g calls, alone %g", tiled, alone);
  oc_image_free(g);
  src.release(src.ud);
  release_made(made);
}
END_TEST

/* ---- whole renders ----------------------------------------------------- */

START_TEST(render_heightfield) {
  oc_heightfield *hf = fbm_grid();
  oc_elevation src;
  oc_error e;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_render_params rp =
      view(oct_v(-150, -250, 450), oct_v(600, 500, 20), 64, 40);
  oc_render_stats st[2];
  oc_image *img[2];
  for (int k = 0; k < 2; k++) {
    omp_set_num_threads(k + 1);
    img[k] = oc_render_elevation(&src, &rp, &st[k], &e);
    ck_assert_msg(img[k], "%s", e.msg);
  }
  omp_set_num_threads(2);
  ck_assert_int_eq(oc_image_channels(img[0]), 12);
  size_t n = (size_t)64 * 40 * 12;
  ck_assert(memcmp(oc_image_cdata(img[0]), oc_image_cdata(img[1]),
                   n * sizeof(float)) == 0);
  ck_assert(memcmp(&st[0], &st[1], sizeof st[0]) == 0);
  ck_assert_int_eq(st[0].pixels, 64 * 40);
  ck_assert(st[0].hits > 64 * 40 / 3);
  ck_assert(st[0].calls_per_pixel > 1 && st[0].calls_per_pixel < 100);
  ck_assert(st[0].calls_total > st[0].calls); /* shadows and AO */
  /* hits: P on the surface, N the height's normal, Z the distance */
  const float *px = oc_image_cdata(img[0]);
  double tot = 0;
  int hits = 0;
  for (int k = 0; k < 64 * 40; k++) {
    const float *q = px + (size_t)k * 12;
    tot += q[11];
    if (!isfinite(q[4])) continue;
    hits++;
    if (q[7] < 1e-3) continue; /* a side of the block */
    double g[2], z = oc_heightfield_height(hf, q[8], q[9], g);
    double l = sqrt(1 + g[0] * g[0] + g[1] * g[1]);
    /* located to OC_ETRACE_REFINE_STOP of the tolerance along the ray,
    ** where h changes at most 1 + |grad f| a unit (and float P) */
    double loc = OC_ETRACE_REFINE_STOP * 0.25 * 2 * tan(25 * PI / 180) / 40 *
                 q[4] * (1 + l);
    ck_assert_msg(fabs(q[10] - z) < loc + 1e-3, "P.z %g, height %g", q[10], z);
    ck_assert(fabs(q[7] - 1 / l) < 1e-3);
    oc_vec3 d = oct_sub(oct_v(q[8], q[9], q[10]), rp.camera.eye);
    ck_assert(fabs(oct_len(d) - q[4]) < 1e-2);
  }
  ck_assert_int_eq(hits, st[0].hits);
  ck_assert(fabs(tot - st[0].calls_total) < 1e-6 * tot);
  /* the sphere tracer draws the same picture at a greater cost */
  rp.tracer = OC_TRACE_SPHERE;
  oc_render_stats ss;
  oc_image *sph = oc_render_elevation(&src, &rp, &ss, &e);
  ck_assert_msg(sph, "%s", e.msg);
  /* (a ray grazing a ridge within the tolerance may differ) */
  ck_assert(llabs(ss.hits - st[0].hits) <= 2);
  ck_assert_msg(ss.calls > 1.5 * st[0].calls, "sphere %g, accelerated %g",
                ss.calls, st[0].calls);
  /* depths within 4 tolerances (a pixel is 2 tan(25 deg) / 40 rad), but
  ** for the rays that graze a ridge thinner than the tolerance (metres
  ** at this coarse size), which either tracer may step over */
  const float *sp = oc_image_cdata(sph);
  double tolk = 4 * 0.25 * 2 * tan(25 * PI / 180) / 40;
  int off = 0;
  for (int k = 0; k < 64 * 40; k++)
    if (isfinite(px[k * 12 + 4]) && isfinite(sp[k * 12 + 4]))
      off += fabs(sp[k * 12 + 4] - px[k * 12 + 4]) > tolk * px[k * 12 + 4];
  ck_assert_msg(off <= st[0].hits / 100, "%d pixels differ in depth", off);
  oc_image_free(sph);
  /* the two phases give the same image */
  rp.tracer = OC_TRACE_SEGMENT;
  oc_image *geo = oc_render_elevation_geometry(&src, &rp, &e);
  ck_assert_msg(geo, "%s", e.msg);
  oc_image *two = oc_render_elevation_shade(&src, &rp, geo, NULL, &e);
  ck_assert_msg(two, "%s", e.msg);
  ck_assert(memcmp(oc_image_cdata(two), px, n * sizeof(float)) == 0);
  oc_image_free(two);
  oc_image_free(geo);
  for (int k = 0; k < 2; k++)
    oc_image_free(img[k]);
  src.release(src.ud);
  oc_heightfield_release(hf);
}
END_TEST

static int stop_now(void *ud, double done) {
  (void)done;
  ++*(int *)ud;
  return 1;
}

START_TEST(cancelled) {
  oc_elevation src = wave_source();
  oc_render_params rp = view(oct_v(-600, -700, 300), oct_v(0, 0, 0), 64, 64);
  int calls = 0;
  rp.progress.fn = stop_now;
  rp.progress.ud = &calls;
  oc_error e;
  ck_assert_ptr_null(oc_render_elevation(&src, &rp, NULL, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  ck_assert(calls >= 1);
}
END_TEST

START_TEST(bad_sources) {
  oc_render_params rp = view(oct_v(-600, -700, 300), oct_v(0, 0, 0), 8, 8);
  oc_error e;
  ck_assert_ptr_null(oc_render_elevation(NULL, &rp, NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  oc_elevation src = wave_source();
  src.x1 = src.x0;
  ck_assert_ptr_null(oc_render_elevation(&src, &rp, NULL, &e));
  ck_assert(strstr(e.msg, "domain"));
  src = wave_source();
  src.slope = NULL;
  ck_assert_ptr_null(oc_render_elevation(&src, &rp, NULL, &e));
  ck_assert(strstr(e.msg, "slope"));
  src = wave_source();
  rp.camera.fov = 0;
  ck_assert_ptr_null(oc_render_elevation(&src, &rp, NULL, &e));
  ck_assert(strstr(e.msg, "'camera.fov'"));
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("etrace");
  TCase *t = tcase_create("tracing");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, heightfield_against_march);
  tcase_add_test(t, analytic_against_march);
  tcase_add_test(t, tree_models_against_march);
  tcase_add_test(t, hits_located);
  tcase_add_test(t, model_hit_normals);
  tcase_add_test(t, relaxed_steps_take_the_tolerance);
  tcase_add_test(t, models_ask_boxes_only_when_poor);
  tcase_add_test(t, beam_steps_relaxed);
  tcase_add_test(t, weight_makes_holes);
  tcase_add_test(t, holes_crossed_on_weight_bound);
  tcase_add_test(t, beams_conservative);
  tcase_add_test(t, beam_margin_spike);
  tcase_add_test(t, tiles_see_thin_spike);
  suite_add_tcase(s, t);
  t = tcase_create("rendering");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, render_heightfield);
  tcase_add_test(t, cancelled);
  tcase_add_test(t, bad_sources);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
