/*
** test_diffusion.c — feature curves and multigrid diffusion (Hnaidi et
** al. 2010, lib/diffusion): the attribute interpolants against a natural
** spline written here, strict elevations met on the curves, slopes on
** straight ridges at 0, 30 and 45 degrees (upwind within 2 %, the
** paper's printed form sqrt 2 too steep at 45), crossing curves averaged,
** conflicting gradients filled, the converged mode's residual, the noise
** detail's octave sum, determinism across thread counts, bad input.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diffusion/diffusion.h"
#include "ocheck.h"
#include "outcrop.h"

#define PI 3.14159265358979323846

/* ---- helpers ------------------------------------------------------------ */

static oc_fconstraint height_pt(double u, double h, double r) {
  oc_fconstraint k = {0};
  k.u = u, k.has = OC_FC_HEIGHT | OC_FC_RADIUS, k.height = h, k.radius = r;
  return k;
}

static void add_slope(oc_fconstraint *k, double left, double right, double a,
                      double b) {
  k->has |= OC_FC_SLOPE;
  k->left = left, k->right = right, k->extent_a = a, k->extent_b = b;
}

static oc_fcurve *line(double x0, double y0, double x1, double y1,
                       const oc_fconstraint *k, size_t nk) {
  double xy[4] = {x0, y0, x1, y1};
  oc_fcurve_params p = {xy, 2, 0, k, nk};
  oc_error err;
  oc_fcurve *c = oc_fcurve_new(&p, &err);
  ck_assert_msg(c != NULL, "%s", err.msg);
  return c;
}

static oc_diffusion_params params(int n, oc_fcurve *const *c, size_t nc) {
  oc_diffusion_params p = {0};
  p.grid = (oc_heightfield_grid){n, n, 1, 0, 0};
  p.curves = c;
  p.ncurves = nc;
  p.seed = 7;
  p.maps = 1;
  return p;
}

static void run(const oc_diffusion_params *p, oc_diffusion_result *r) {
  oc_error err;
  int rc = oc_diffusion(p, r, &err);
  ck_assert_msg(rc == OC_OK, "%s", err.msg);
}

static double at(const oc_heightfield *hf, int i, int j) {
  return oc_heightfield_samples(hf)[(size_t)j * oc_heightfield_nx(hf) + i];
}

/* The natural cubic spline through (u, v), independently: the interior
** second derivatives by Gaussian elimination on the full system. */
static double ref_spline(const double *u, const double *v, int n, double t) {
  double M[8] = {0}, A[8][9] = {{0}};
  for (int i = 1; i + 1 < n; i++) {
    double h0 = u[i] - u[i - 1], h1 = u[i + 1] - u[i];
    if (i > 1) A[i][i - 1] = h0;
    A[i][i] = 2 * (h0 + h1);
    if (i + 2 < n) A[i][i + 1] = h1;
    A[i][8] = 6 * ((v[i + 1] - v[i]) / h1 - (v[i] - v[i - 1]) / h0);
  }
  for (int i = 1; i + 1 < n; i++)
    for (int r = i + 1; r + 1 < n; r++) {
      double f = A[r][i] / A[i][i];
      for (int c = i; c < 9; c++)
        A[r][c] -= f * A[i][c];
    }
  for (int i = n - 2; i >= 1; i--) {
    double s = A[i][8];
    for (int c = i + 1; c + 1 < n; c++)
      s -= A[i][c] * M[c];
    M[i] = s / A[i][i];
  }
  int i = 0;
  while (i + 2 < n && t > u[i + 1])
    i++;
  double h = u[i + 1] - u[i], a = (u[i + 1] - t) / h, b = (t - u[i]) / h;
  return a * v[i] + b * v[i + 1] +
         ((a * a * a - a) * M[i] + (b * b * b - b) * M[i + 1]) * h * h / 6;
}

/* ---- the model ---------------------------------------------------------- */

START_TEST(attributes_interpolate) {
  double u[4] = {0, 0.3, 0.7, 1}, h[4] = {10, 40, 25, 5};
  oc_fconstraint k[4];
  for (int i = 0; i < 4; i++)
    k[i] = height_pt(u[i], h[i], i);
  k[1].has = OC_FC_NOISE; /* point 2 gives noise only */
  k[1].amplitude = 4, k[1].roughness = 0.5;
  double hu[3] = {0, 0.7, 1}, hv[3] = {10, 25, 5};
  oc_fcurve *c = line(0, 0, 100, 0, k, 4);
  ck_assert(oc_fcurve_has(c) == (OC_FC_HEIGHT | OC_FC_RADIUS | OC_FC_NOISE));
  for (int s = 0; s <= 50; s++) {
    double t = s / 50.0;
    oc_fcurve_sample o;
    ck_assert_int_eq(oc_fcurve_sample_at(c, t, &o), OC_OK);
    ck_assert_double_eq_tol(o.height, ref_spline(hu, hv, 3, t), 1e-9);
    ck_assert_double_eq_tol(o.x, 100 * t, 1e-9);
    /* radius linear among points 1, 3, 4 (radii 0, 2, 3) */
    double r = t < 0.7 ? 2 * t / 0.7 : 2 + (t - 0.7) / 0.3;
    ck_assert_double_eq_tol(o.radius, r, 1e-9);
    ck_assert_double_eq_tol(o.amplitude, 4, 1e-12); /* one point: constant */
  }
  /* two points: linear */
  oc_fconstraint k2[2] = {height_pt(0, 0, 0), height_pt(1, 10, 0)};
  oc_fcurve *c2 = line(0, 0, 10, 0, k2, 2);
  oc_fcurve_sample o;
  oc_fcurve_sample_at(c2, 0.25, &o);
  ck_assert_double_eq_tol(o.height, 2.5, 1e-12);
  oc_fcurve_release(c);
  oc_fcurve_release(c2);
}
END_TEST

/* ---- strict constraints ---------------------------------------------------
 */

START_TEST(strict_elevations_met) {
  /* a straight curve along row 50: every cell on it holds the spline */
  double hu[3] = {0, 0.5, 1}, hv[3] = {10, 30, 15};
  oc_fconstraint k[3] = {height_pt(0, 10, 0), height_pt(0.5, 30, 0),
                         height_pt(1, 15, 0)};
  oc_fcurve *c[2];
  c[0] = line(10, 50, 90, 50, k, 3);
  /* and a Bézier arc carrying a ramp */
  double xy[8] = {10, 10, 40, 0, 60, 30, 90, 20};
  oc_fconstraint kb[2] = {height_pt(0, 0, 0.5), height_pt(1, 8, 0.5)};
  oc_fcurve_params bp = {xy, 4, 1, kb, 2};
  oc_error err;
  c[1] = oc_fcurve_new(&bp, &err);
  ck_assert_msg(c[1] != NULL, "%s", err.msg);
  oc_diffusion_params p = params(100, c, 2);
  oc_diffusion_result r;
  run(&p, &r);
  for (int i = 10; i <= 90; i++)
    ck_assert_double_eq_tol(at(r.smooth, i, 50),
                            ref_spline(hu, hv, 3, (i - 10) / 80.0), 2e-5);
  /* the arc: the cell under each point holds h there within one cell's
  ** change of h (8 m over the length) */
  double tol = 8 / oc_fcurve_length(c[1]) * 1.5 + 1e-4;
  for (int s = 0; s <= 100; s++) {
    oc_fcurve_sample o;
    oc_fcurve_sample_at(c[1], s / 100.0, &o);
    int i = (int)lround(o.x), j = (int)lround(o.y);
    ck_assert_msg(fabs(at(r.smooth, i, j) - o.height) <= tol,
                  "u %g: %g against %g", s / 100.0, at(r.smooth, i, j),
                  o.height);
  }
  ck_assert(r.strict > 0 && r.slope == 0 && r.conflict == 0);
  /* the detail is zero without noise constraints */
  for (int q = 0; q < 100 * 100; q++)
    ck_assert(oc_heightfield_samples(r.detail)[q] == 0);
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(c[0]);
  oc_fcurve_release(c[1]);
}
END_TEST

START_TEST(crossing_curves_averaged) {
  oc_fconstraint a[2] = {height_pt(0, 10, 0), height_pt(1, 10, 0)};
  oc_fconstraint b[2] = {height_pt(0, 30, 0), height_pt(1, 30, 0)};
  oc_fcurve *c[2] = {line(0, 32, 64, 32, a, 2), line(32, 0, 32, 64, b, 2)};
  oc_diffusion_params p = params(65, c, 2);
  oc_diffusion_result r;
  run(&p, &r);
  ck_assert_double_eq_tol(at(r.smooth, 32, 32), 20, 1e-6);
  ck_assert_double_eq_tol(at(r.smooth, 40, 32), 10, 1e-6);
  ck_assert_double_eq_tol(at(r.smooth, 32, 40), 30, 1e-6);
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(c[0]);
  oc_fcurve_release(c[1]);
}
END_TEST

/* ---- slopes ----------------------------------------------------------- */

/* A straight ridge through the centre of a 161 x 161 grid at `angle`
** degrees, h = 50, r = 2, slopes `theta` both sides over a = b = 60,
** solved to convergence: the drop between 5 and 20 m from the ridge,
** measured on the normal, over the constraint's (the slope fades to 0 at
** the far end: tan theta (x - x^2 / 2a) from the plateau's edge). */
static double slope_ratio(double angle, double theta, oc_diffusion_scheme sc) {
  double c = 80, ca = cos(angle * PI / 180), sa = sin(angle * PI / 180);
  oc_fconstraint k[2] = {height_pt(0, 50, 2), height_pt(1, 50, 2)};
  add_slope(&k[0], theta, theta, 60, 60);
  add_slope(&k[1], theta, theta, 60, 60);
  oc_fcurve *cv =
      line(c - 200 * ca, c - 200 * sa, c + 200 * ca, c + 200 * sa, k, 2);
  oc_diffusion_params p = params(161, &cv, 1);
  p.scheme = sc;
  p.tolerance = 1e-5;
  oc_diffusion_result r;
  run(&p, &r);
  double t = tan(theta * PI / 180), ratio = 0;
  for (int side = -1; side <= 1; side += 2) {
    double nx = -sa * side, ny = ca * side;
    double x1 = 3, x2 = 18; /* from the plateau's edge at r = 2 */
    double h1 = oc_heightfield_height(r.smooth, c + (2 + x1) * nx,
                                      c + (2 + x1) * ny, NULL);
    double h2 = oc_heightfield_height(r.smooth, c + (2 + x2) * nx,
                                      c + (2 + x2) * ny, NULL);
    double want = t * ((x2 - x2 * x2 / 120) - (x1 - x1 * x1 / 120));
    ratio += 0.5 * (h1 - h2) / want;
  }
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(cv);
  return ratio;
}

START_TEST(slopes_on_straight_ridges) {
  double angles[3] = {0, 30, 45};
  for (int a = 0; a < 3; a++) {
    double q = slope_ratio(angles[a], 30, OC_DIFFUSION_UPWIND);
    printf("ridge at %g degrees, slope 30: measured / constraint %.4f\n",
           angles[a], q);
    ck_assert_msg(fabs(q - 1) <= 0.02, "angle %g: ratio %g", angles[a], q);
  }
  double q = slope_ratio(45, 30, OC_DIFFUSION_PAPER);
  printf("paper scheme at 45 degrees: %.4f\n", q);
  ck_assert_msg(q > 1.3 && q < 1.5, "paper scheme at 45: %g", q);
  q = slope_ratio(0, 30, OC_DIFFUSION_PAPER); /* axis-aligned: the same */
  ck_assert_msg(fabs(q - 1) <= 0.02, "paper scheme at 0: %g", q);
}
END_TEST

START_TEST(flat_slope_makes_a_plateau) {
  /* 0 degrees (a hill): the ground stays at h across the slope band */
  oc_fconstraint k[2] = {height_pt(0, 20, 1), height_pt(1, 20, 1)};
  add_slope(&k[0], 0, 0, 20, 20);
  add_slope(&k[1], 0, 0, 20, 20);
  oc_fconstraint lo[2] = {height_pt(0, 0, 0), height_pt(1, 0, 0)};
  oc_fcurve *c[2] = {line(-10, 40, 90, 40, k, 2), line(-10, 5, 90, 5, lo, 2)};
  oc_diffusion_params p = params(81, c, 2);
  p.tolerance = 1e-6;
  oc_diffusion_result r;
  run(&p, &r);
  for (int d = 2; d <= 15; d++)
    ck_assert_msg(fabs(at(r.smooth, 40, 40 + d) - 20) < 0.05 &&
                      fabs(at(r.smooth, 40, 40 - d) - 20) < 0.25,
                  "d %d: %g %g", d, at(r.smooth, 40, 40 + d),
                  at(r.smooth, 40, 40 - d));
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(c[0]);
  oc_fcurve_release(c[1]);
}
END_TEST

START_TEST(closed_curve_corners_alike) {
  /* a square loop, counter-clockwise from (20, 20): the slope outside
  ** rounds every corner the same, the one where the loop closes too */
  oc_fconstraint k[2] = {height_pt(0, 30, 0), height_pt(1, 30, 0)};
  add_slope(&k[0], 20, 30, 8, 10);
  add_slope(&k[1], 20, 30, 8, 10);
  double xy[10] = {20, 20, 60, 20, 60, 60, 20, 60, 20, 20};
  oc_fcurve_params cp = {xy, 5, 0, k, 2};
  oc_error err;
  oc_fcurve *c = oc_fcurve_new(&cp, &err);
  ck_assert_msg(c != NULL, "%s", err.msg);
  oc_diffusion_params p = params(81, &c, 1);
  oc_diffusion_result r;
  run(&p, &r);
  double g0 = at(r.gradient, 16, 16), t = tan(30 * PI / 180);
  /* 4 sqrt 2 m from the corner: tan 30 (1 - 5.66 / 10) */
  ck_assert_double_eq_tol(g0, t * (1 - sqrt(32) / 10), 1e-5);
  ck_assert_double_eq_tol(at(r.gradient, 64, 16), g0, 1e-6);
  ck_assert_double_eq_tol(at(r.gradient, 64, 64), g0, 1e-6);
  ck_assert_double_eq_tol(at(r.gradient, 16, 64), g0, 1e-6);
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(c);
}
END_TEST

START_TEST(conflicting_gradients_filled) {
  /* two ridges crossing at right angles: their flanks meet in the four
  ** quadrants around the crossing, left empty and filled by diffusion */
  oc_fconstraint k[2] = {height_pt(0, 40, 1), height_pt(1, 40, 1)};
  add_slope(&k[0], 30, 30, 25, 25);
  add_slope(&k[1], 30, 30, 25, 25);
  oc_fcurve *c[2] = {line(0, 64, 128, 64, k, 2), line(64, 0, 64, 128, k, 2)};
  oc_diffusion_params p = params(129, c, 2);
  oc_diffusion_result r;
  run(&p, &r);
  ck_assert(r.conflict > 0);
  double t = tan(30 * PI / 180);
  /* (69, 69) lies 5 m from both ridges: a conflict, filled between 0 and
  ** tan theta; heights finite and below the ridges */
  double g = at(r.gradient, 69, 69);
  ck_assert_msg(g > 0.05 * t && g < t, "filled gradient %g", g);
  for (int q = 0; q < 129 * 129; q++) {
    double h = oc_heightfield_samples(r.smooth)[q];
    ck_assert(isfinite(h) && h <= 40 + 1e-4);
  }
  oc_diffusion_result_clear(&r);
  oc_fcurve_release(c[0]);
  oc_fcurve_release(c[1]);
}
END_TEST

/* ---- solver ---------------------------------------------------------------
 */

static oc_fcurve *scene(oc_fcurve **c) {
  oc_fconstraint k[3] = {height_pt(0, 60, 1), height_pt(0.5, 90, 1),
                         height_pt(1, 50, 1)};
  for (int i = 0; i < 3; i++) {
    add_slope(&k[i], 35, 25, 30, 20);
    k[i].has |= OC_FC_NOISE;
    k[i].amplitude = 2 + i, k[i].roughness = 0.3 * i;
  }
  double xy[7 * 2] = {10, 20,  40, 10,  60,  60, 90,
                      50, 120, 40, 100, 100, 60, 110};
  oc_fcurve_params bp = {xy, 7, 1, k, 3};
  oc_error err;
  c[0] = oc_fcurve_new(&bp, &err);
  ck_assert_msg(c[0] != NULL, "%s", err.msg);
  oc_fconstraint v[2] = {height_pt(0, 5, 4), height_pt(1, 20, 2)};
  add_slope(&v[0], -20, -20, 15, 15);
  add_slope(&v[1], -20, -20, 15, 15);
  c[1] = line(5, 120, 125, 90, v, 2);
  oc_fconstraint w[2];
  memset(w, 0, sizeof w);
  w[0].u = 0, w[1].u = 1;
  add_slope(&w[0], -40, -40, 10, 10); /* a crack: no strict elevation */
  add_slope(&w[1], -40, -40, 10, 10);
  c[2] = line(20, 80, 70, 100, w, 2);
  return c[0];
}

START_TEST(converged_mode_converges) {
  oc_fcurve *c[3];
  scene(c);
  oc_diffusion_params p = params(128, c, 3);
  p.tolerance = 1e-5;
  oc_diffusion_result r;
  run(&p, &r);
  ck_assert(r.cycles >= 1 && r.cycles < OC_DIFFUSION_MAX_CYCLES);
  printf("converged in %d iterations: largest update %.3g m after the "
         "cascade, %.3g m at the end\n",
         r.cycles, r.residual[0], r.residual[r.cycles]);
  /* scale: the strict elevations, 5 .. 90 */
  ck_assert(r.residual[r.cycles] <= 1e-5 * 90);
  ck_assert(r.residual[r.cycles - 1] > 1e-5 * 90);
  /* V-cycles, then BiCGSTAB (not monotone), never back to the cascade's */
  for (int k = 1; k <= r.cycles; k++)
    ck_assert_msg(r.residual[k] < r.residual[0], "iteration %d", k);
  ck_assert(r.residual[r.cycles] < 1e-3 * r.residual[0]);
  oc_diffusion_result_clear(&r);
  for (int i = 0; i < 3; i++)
    oc_fcurve_release(c[i]);
}
END_TEST

START_TEST(deterministic_across_threads) {
  /* 280 x 260 samples: the finest grid's loops run in parallel (over
  ** 65 536 samples, OC_DPAR) */
  oc_fcurve *c[3];
  scene(c);
  oc_heightfield *h[3];
  int threads[3] = {1, 2, 3};
  for (int t = 0; t < 3; t++) {
    omp_set_num_threads(threads[t]);
    oc_diffusion_params p = params(97, c, 3);
    p.grid = (oc_heightfield_grid){280, 260, 0.5, 0, 0};
    /* the paper's schedule (tolerance 0) */
    oc_diffusion_result r;
    run(&p, &r);
    h[t] = r.height;
    r.height = NULL;
    oc_diffusion_result_clear(&r);
  }
  size_t n = 280 * 260 * sizeof(float);
  ck_assert(memcmp(oc_heightfield_samples(h[0]), oc_heightfield_samples(h[1]),
                   n) == 0);
  ck_assert(memcmp(oc_heightfield_samples(h[0]), oc_heightfield_samples(h[2]),
                   n) == 0);
  /* converged mode too, 1 against 2 threads */
  oc_heightfield *v[2];
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t + 1);
    oc_diffusion_params p = params(97, c, 3);
    p.grid = (oc_heightfield_grid){280, 260, 0.5, 0, 0};
    p.tolerance = 1e-4;
    oc_diffusion_result r;
    run(&p, &r);
    v[t] = r.height;
    r.height = NULL;
    oc_diffusion_result_clear(&r);
  }
  ck_assert(memcmp(oc_heightfield_samples(v[0]), oc_heightfield_samples(v[1]),
                   n) == 0);
  omp_set_num_threads(2);
  for (int t = 0; t < 3; t++)
    oc_heightfield_release(h[t]);
  oc_heightfield_release(v[0]);
  oc_heightfield_release(v[1]);
  for (int i = 0; i < 3; i++)
    oc_fcurve_release(c[i]);
}
END_TEST

/* The converged mode on a hand-made level 0 (48 x 40, 1 m): strict
** columns at x = 6 (100 m) and x = 41 (20 m) with the slope band of
** the first (n = +x, 30 degrees) beside a conflict region whose filled
** directions turn with y, then Laplace: the result satisfies the fine
** equations, written here from the documented formula (upwind F_G),
** to the tolerance times the constraints' scale (100 m), from a start
** that did not. */
START_TEST(converged_meets_fine_equations) {
  enum { NX = 48, NY = 40 };
  oc_dpyramid py;
  oc_error err;
  ck_assert_int_eq(oc_dpyramid_init(&py, NX, NY, 1, NULL, &err), OC_OK);
  oc_dlevel *lv = &py.lv[0];
  static double nx[NX * NY], ny[NX * NY], g[NX * NY];
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++) {
      size_t k = (size_t)j * NX + (size_t)i;
      uint8_t f = 0;
      double h = 0, a = 0, gx = 0, gy = 0, gd = 0;
      if (i == 6 || i == 41) {
        f = DF_H, h = i == 6 ? 100 : 20;
      } else if (i > 6 && i <= 18) { /* slope band: falls along +x */
        f = DF_SLOPE, gx = 1, gd = tan(30 * PI / 180);
      } else if (i > 18 && i <= 26) { /* conflict: directions turning */
        a = (j - NY / 2) * 0.12;
        f = DF_CONFLICT, gx = cos(a), gy = sin(a), gd = 0.3;
      }
      lv->flags[k] = f;
      lv->map[MAP_H][k] = (float)h;
      lv->map[MAP_GX][k] = (float)gx, lv->map[MAP_GY][k] = (float)gy;
      lv->map[MAP_GD][k] = (float)gd;
      lv->map[MAP_A][k] = lv->map[MAP_R][k] = 0;
      nx[k] = lv->map[MAP_GX][k], ny[k] = lv->map[MAP_GY][k];
      g[k] = lv->map[MAP_GD][k];
    }
  oc_dpyramid_grow(&py);
  oc_dpyramid_restrict(&py);
  for (int k = 0; k < py.nlevels; k++)
    oc_dguide_prepare(&py.lv[k], 0, k ? 1e-6 : 0.5);
  double res[OC_DIFFUSION_MAX_CYCLES + 1];
  int cycles = 0;
  oc_dop op = {DK_GUIDED, MAP_H, DF_H, 0, 0};
  oc_dsolve s = {{0}, 0, 1, 1e-5, res, &cycles, NULL, NULL};
  ck_assert_int_eq(oc_dsolve_map(&py, &op, &s, &err), OC_OK);
  const float *F = lv->map[MAP_H];
  double big = 0;
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++) {
      size_t k = (size_t)j * NX + (size_t)i;
      if (lv->flags[k] & DF_H) continue;
#define AT(ii, jj)                                                             \
  F[(size_t)((jj) < 0     ? 0                                                  \
             : (jj) >= NY ? NY - 1                                             \
                          : (jj)) *                                            \
        NX +                                                                   \
    (size_t)((ii) < 0     ? 0                                                  \
             : (ii) >= NX ? NX - 1                                             \
                          : (ii))]
      double L =
          (AT(i - 1, j) + AT(i + 1, j) + AT(i, j - 1) + AT(i, j + 1)) / 4;
      double v = L;
      double ax = fabs(nx[k]), ay = fabs(ny[k]);
      if ((lv->flags[k] & DF_GUIDE) && ax + ay > 1e-6) {
        int sx = nx[k] < 0 ? -1 : 1, sy = ny[k] < 0 ? -1 : 1;
        double FG =
            (ax * AT(i - sx, j) + ay * AT(i, j - sy) - g[k]) / (ax + ay);
        v = 0.5 * L + 0.5 * FG;
      }
#undef AT
      big = fmax(big, fabs(v - F[k]));
    }
  printf("converged on the fine equations: %d steps, largest update %.3g m "
         "(reported %.3g; %.3g after the cascade)\n",
         cycles, big, res[cycles], res[0]);
  ck_assert(cycles >= 1 && cycles < OC_DIFFUSION_MAX_CYCLES);
  ck_assert(res[0] > 1e-5 * 100);
  ck_assert_msg(big <= 1e-5 * 100 * 1.01, "largest update %g m", big);
  /* the slope band: 30 degrees from the strict column, within 3 % */
  double d = F[(size_t)20 * NX + 8] - F[(size_t)20 * NX + 14];
  ck_assert_msg(fabs(d / 6 / tan(30 * PI / 180) - 1) < 0.03, "slope %g", d / 6);
  oc_dpyramid_free(&py);
}
END_TEST

/* The fused sweeps of the cascade (in place, blocks of 64 rows reading
** their neighbours' rows from copies) give the bytes of separate sweeps,
** for sweep counts below and above the halo of one row and a last block
** shorter than the others. */
START_TEST(fused_sweeps_match) {
  /* two blocks or more and n nx ny >= 262 144 (n >= 2): the fused path */
  enum { NX = 600, NY = 230 };
  size_t ns = (size_t)NX * NY;
  float *m = malloc(MAP_COUNT * ns * sizeof *m), *x = malloc(ns * sizeof *x),
        *y = malloc(ns * sizeof *y), *scr = malloc(ns * sizeof *scr);
  uint8_t *flags = malloc(ns);
  ck_assert(m && x && y && scr && flags);
  oc_dlevel lv = {NX, NY, 2, {NULL}, flags};
  for (int q = 0; q < MAP_COUNT; q++)
    lv.map[q] = m + (size_t)q * ns;
  oct_rng rg = oct_rng_new(5);
  for (size_t k = 0; k < ns; k++) {
    double u = oct_unif(&rg, 0, 1);
    flags[k] = u < 0.1   ? DF_H
               : u < 0.5 ? (uint8_t)(DF_SLOPE | DF_GACT |
                                     (oct_unif(&rg, 0, 1) < 0.5 ? DF_SX : 0) |
                                     (oct_unif(&rg, 0, 1) < 0.5 ? DF_SY : 0))
                         : 0;
    lv.map[MAP_GX][k] = (float)oct_unif(&rg, 0, 0.5);
    lv.map[MAP_GY][k] = (float)oct_unif(&rg, -1, 1);
    x[k] = (float)oct_unif(&rg, -10, 10);
  }
  static const int counts[4] = {1, 2, 6, 15};
  for (int kind = 0; kind < 2; kind++)
    for (int q = 0; q < 4; q++) {
      int n = counts[q];
      oc_dop op = {kind ? DK_GUIDED : DK_LAPLACE, MAP_H, DF_H, 0, 0};
      memcpy(y, x, ns * sizeof *x);
      double b0 = 0;
      for (int it = 0; it < n; it++) {
        b0 = oc_djacobi(&op, &lv, y, scr, NULL);
        memcpy(y, scr, ns * sizeof *y);
      }
      memcpy(lv.map[MAP_H], x, ns * sizeof *x);
      double b1 = oc_djacobi_n(&op, &lv, lv.map[MAP_H], scr, n);
      ck_assert_msg(memcmp(y, lv.map[MAP_H], ns * sizeof *y) == 0,
                    "kind %d, %d sweeps", kind, n);
      ck_assert(b0 == b1 && b0 > 0);
    }
  free(m), free(x), free(y), free(scr), free(flags);
}
END_TEST

/* ---- noise detail -------------------------------------------------------- */

START_TEST(detail_octave_sum) {
  oc_ddetail d = {0, 0, 1, 50, 2, 4, 11};
  double big0 = 0, big1 = 0, var0 = 0, var1 = 0;
  oct_rng rg = oct_rng_new(3);
  for (int s = 0; s < 20000; s++) {
    double x = oct_unif(&rg, -1000, 1000), y = oct_unif(&rg, -1000, 1000);
    double n0 = oc_ddetail_at(&d, x, y, 3, 0),
           n1 = oc_ddetail_at(&d, x, y, 3, 1);
    big0 = fmax(big0, fabs(n0)), big1 = fmax(big1, fabs(n1));
    var0 += n0 * n0, var1 += n1 * n1;
  }
  /* |N| <= A (1 + 1/2 + 1/4 + 1/8) = 1.875 A at R = 0, 4 A at R = 1 */
  ck_assert(big0 <= 1.875 * 3 && big1 <= 4 * 3);
  ck_assert(big0 > 0.5 && var1 > 1.2 * var0);
  /* deterministic by seed, and another seed differs */
  oc_ddetail e = d;
  e.seed = 12;
  ck_assert(oc_ddetail_at(&d, 3.5, 7.25, 1, 0.5) ==
            oc_ddetail_at(&d, 3.5, 7.25, 1, 0.5));
  ck_assert(oc_ddetail_at(&d, 3.5, 7.25, 1, 0.5) !=
            oc_ddetail_at(&e, 3.5, 7.25, 1, 0.5));
  ck_assert(oc_ddetail_at(&d, 3.5, 7.25, 0, 0.5) == 0);
}
END_TEST

/* The grid's detail (lattice octaves interpolated, fine octaves sampled
** directly, octaves under 2 cells dropped) against the exact sum. */
START_TEST(detail_grid_matches_octaves) {
  enum { N = 48 };
  static float maps[MAP_COUNT][N * N], z[N * N], det[N * N];
  static uint8_t flags[N * N];
  oc_dlevel lv = {N, N, 1, {NULL}, flags};
  for (int q = 0; q < MAP_COUNT; q++)
    lv.map[q] = maps[q];
  for (int k = 0; k < N * N; k++)
    maps[MAP_H][k] = 10, maps[MAP_A][k] = 3, maps[MAP_R][k] = 0.5f;
  /* wavelengths 50, 25, 12.5, 6.25 m: lattices of 6.25, 3.125, 1.5625 m,
  ** the last finer than the 1 m cell (direct) */
  oc_ddetail d = {-7.5, 3.25, 1, 50, 2, 4, 11};
  oc_error err;
  ck_assert_int_eq(
      oc_ddetail_grid(&d, &lv, z, det, (oc_progress){0}, 0, 1, &err), OC_OK);
  double big = 0, sum = 0;
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double n = oc_ddetail_at(&d, d.x0 + i, d.y0 + j, 3, 0.5);
      big = fmax(big, fabs(det[j * N + i] - n));
      sum += n * n;
      ck_assert(z[j * N + i] == (float)(10 + det[j * N + i]));
    }
  /* Catmull-Rom at 8 nodes a wavelength: within 0.026 of S per octave,
  ** weights 1 + 0.71 + 0.5 (the last exact), A = 3 */
  ck_assert_msg(big < 3 * 0.026 * 1.71, "lattice detail off by %g", big);
  ck_assert(sqrt(sum / (N * N)) > 0.3);
  /* an octave under 2 cells is dropped: wavelength 3 m keeps 3 m only */
  oc_ddetail e = {0, 0, 1, 3, 2, 2, 11}, e1 = e;
  e1.octaves = 1;
  ck_assert_int_eq(
      oc_ddetail_grid(&e, &lv, z, det, (oc_progress){0}, 0, 1, &err), OC_OK);
  for (int k = 0; k < N * N; k += 97)
    ck_assert(fabs(det[k] - oc_ddetail_at(&e1, k % N, k / N, 3, 0.5)) < 1e-5);
}
END_TEST

/* ---- bad input ----------------------------------------------------------- */

static void expect(int ok, const oc_error *err, const char *name) {
  ck_assert_msg(!ok, "accepted bad '%s'", name);
  ck_assert_int_eq(err->code, OC_EINVAL);
  ck_assert_msg(strstr(err->msg, name) != NULL, "'%s' not in: %s", name,
                err->msg);
}

START_TEST(bad_input_names_the_field) {
  oc_error err;
  double xy[4] = {0, 0, 10, 0};
  oc_fconstraint k[2] = {height_pt(0, 1, 0), height_pt(1, 1, 0)};
  oc_fcurve_params p = {xy, 2, 0, k, 1};
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'constraints'");
  p.nconstraints = 2;
  k[1].u = 1.5;
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'constraints[2].u'");
  k[1].u = 0;
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'constraints[2].u'");
  k[1].u = 1;
  k[0].height = NAN;
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'constraints[1].height'");
  k[0].height = 1;
  add_slope(&k[0], 95, 0, 1, 1);
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'constraints[1].slope.left'");
  add_slope(&k[0], 10, 10, -1, 1);
  expect(oc_fcurve_new(&p, &err) != NULL, &err,
         "'constraints[1].slope.extent[1]'");
  k[0].has = OC_FC_NOISE;
  k[0].amplitude = 1, k[0].roughness = 2;
  expect(oc_fcurve_new(&p, &err) != NULL, &err,
         "'constraints[1].noise.roughness'");
  k[0] = height_pt(0, 1, 0);
  xy[2] = NAN;
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'points[2]'");
  xy[2] = 10;
  p.bezier = 1;
  expect(oc_fcurve_new(&p, &err) != NULL, &err, "'points'");
  p.bezier = 0;
  /* no strict elevation anywhere */
  oc_fconstraint n[2];
  memset(n, 0, sizeof n);
  n[1].u = 1;
  oc_fcurve *c = line(0, 0, 10, 0, n, 2);
  oc_diffusion_params d = params(16, &c, 1);
  oc_diffusion_result r;
  expect(oc_diffusion(&d, &r, &err) == OC_OK, &err, "'curves'");
  oc_fcurve_release(c);
  /* strict elevation outside the grid only */
  c = line(100, 100, 120, 100, k, 2);
  d.curves = &c;
  expect(oc_diffusion(&d, &r, &err) == OC_OK, &err, "'curves'");
  d.grid.nx = 1;
  expect(oc_diffusion(&d, &r, &err) == OC_OK, &err, "'size'");
  d.grid.nx = 16;
  d.grid.cell = NAN;
  expect(oc_diffusion(&d, &r, &err) == OC_OK, &err, "'cell'");
  d.grid.cell = 1;
  d.octaves = 40;
  expect(oc_diffusion(&d, &r, &err) == OC_OK, &err, "'noise.octaves'");
  oc_fcurve_release(c);
}
END_TEST

/* ---- compact encoding ---------------------------------------------------- */

START_TEST(encoding_round_trips) {
  oc_fcurve *c[3];
  scene(c);
  for (int i = 0; i < 3; i++) {
    size_t n = oc_fcurve_encode(c[i], NULL, 0);
    ck_assert(n > 8 && n < 80);
    unsigned char buf[128], buf2[128];
    ck_assert_uint_eq(oc_fcurve_encode(c[i], buf, sizeof buf), n);
    oc_error err;
    oc_fcurve *d = oc_fcurve_decode(buf, n, &err);
    ck_assert_msg(d != NULL, "%s", err.msg);
    /* the quantised curve encodes to the same bytes */
    ck_assert_uint_eq(oc_fcurve_encode(d, buf2, sizeof buf2), n);
    ck_assert(memcmp(buf, buf2, n) == 0);
    ck_assert(oc_fcurve_has(d) == oc_fcurve_has(c[i]));
    for (int q = 0; q <= 20; q++) {
      oc_fcurve_sample a, b;
      oc_fcurve_sample_at(c[i], q / 20.0, &a);
      oc_fcurve_sample_at(d, q / 20.0, &b);
      ck_assert(fabs(a.x - b.x) < 0.1 && fabs(a.y - b.y) < 0.1);
      ck_assert(fabs(a.height - b.height) < 0.1);
      ck_assert(fabs(a.left - b.left) < 0.02 &&
                fabs(a.extent_a - b.extent_a) < 0.05);
      ck_assert(fabs(a.amplitude - b.amplitude) < 0.02 &&
                fabs(a.roughness - b.roughness) < 0.001);
    }
    /* truncated, trailing and foreign bytes are refused */
    ck_assert(oc_fcurve_decode(buf, n - 1, &err) == NULL);
    buf[n] = 0;
    ck_assert(oc_fcurve_decode(buf, n + 1, &err) == NULL);
    ck_assert(oc_fcurve_decode((const unsigned char *)"hello", 5, &err) ==
              NULL);
    oc_fcurve_release(d);
  }
  for (int i = 0; i < 3; i++)
    oc_fcurve_release(c[i]);
  /* version 1 still loads: (0, 0) to (10, 0), heights 5 and radii 1 at
  ** u = 0 and 1, LEB128 varints of 1/16 m */
  static const unsigned char v1[] = {'F', 4,    0, 0,  0xc0, 0x02, 0, 2, 0,
                                     3,   0xa0, 1, 32, 0x80, 0x40, 3, 0, 0};
  oc_error err;
  oc_fcurve *o = oc_fcurve_decode(v1, sizeof v1, &err);
  ck_assert_msg(o != NULL, "%s", err.msg);
  oc_fcurve_sample a;
  oc_fcurve_sample_at(o, 0.5, &a);
  ck_assert(a.x == 5 && a.y == 0 && a.height == 5 && a.radius == 1);
  ck_assert(oc_fcurve_length(o) == 10);
  /* and re-encodes as version 2 (marker bits 111): 101 bits */
  unsigned char b2[16];
  ck_assert_uint_eq(oc_fcurve_encode(o, b2, sizeof b2), 13);
  ck_assert((b2[0] & 0xe0) == 0xe0);
  oc_fcurve_release(o);
}
END_TEST

/* ---- cancellation -------------------------------------------------------- */

static int stop_at_half(void *ud, double f) {
  int *calls = ud;
  ++*calls;
  return f > 0.5;
}

static int stop_at_once(void *ud, double f) {
  (void)f;
  ++*(int *)ud;
  return 1;
}

START_TEST(progress_cancels) {
  oc_fcurve *c[3];
  scene(c);
  int calls = 0;
  oc_diffusion_params p = params(64, c, 3);
  p.progress = (oc_progress){stop_at_half, &calls};
  oc_diffusion_result r;
  oc_error err;
  ck_assert_int_eq(oc_diffusion(&p, &r, &err), OC_ECANCEL);
  ck_assert(calls > 2 && r.height == NULL);
  /* stopped at once: in the rasterisation, the first phase */
  p.progress = (oc_progress){stop_at_once, &calls};
  calls = 0;
  ck_assert_int_eq(oc_diffusion(&p, &r, &err), OC_ECANCEL);
  ck_assert(calls == 1 && r.height == NULL);
  for (int i = 0; i < 3; i++)
    oc_fcurve_release(c[i]);
}
END_TEST

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("diffusion");
  TCase *tc = tcase_create("diffusion");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, attributes_interpolate);
  tcase_add_test(tc, strict_elevations_met);
  tcase_add_test(tc, crossing_curves_averaged);
  tcase_add_test(tc, slopes_on_straight_ridges);
  tcase_add_test(tc, flat_slope_makes_a_plateau);
  tcase_add_test(tc, closed_curve_corners_alike);
  tcase_add_test(tc, conflicting_gradients_filled);
  tcase_add_test(tc, converged_mode_converges);
  tcase_add_test(tc, converged_meets_fine_equations);
  tcase_add_test(tc, deterministic_across_threads);
  tcase_add_test(tc, fused_sweeps_match);
  tcase_add_test(tc, detail_octave_sum);
  tcase_add_test(tc, detail_grid_matches_octaves);
  tcase_add_test(tc, bad_input_names_the_field);
  tcase_add_test(tc, progress_cancels);
  tcase_add_test(tc, encoding_round_trips);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
