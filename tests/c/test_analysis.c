/*
** test_analysis.c — terrain analysis (lib/terrain: slope, fill, flow,
** sinks, access, edt) against analytic answers and independent
** references: the fill against a fixed-point relaxation of the spill
** level, drainage conservation and its exact values on a tilted plane,
** ring averages on a cone, sinks of pits and bowls, sky visibility of
** planes and valleys (1, 1 - a / pi, 1 - 2 a / pi), distances against
** brute force; byte-identical results for 1 and 2 threads; parameter
** checks and cancellation.
*/
#include <check.h>
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/noise.h"
#include "ocheck.h"
#include "outcrop.h"

#define PI 3.14159265358979323846

/* ---- grids -------------------------------------------------------------- */

typedef double (*height_fn)(double x, double y, const double *k);

/* A grid sampling fn at x0 + i cell, y0 + j cell. */
static oc_heightfield *grid(int nx, int ny, double cell, double x0, double y0,
                            height_fn fn, const double *k) {
  oc_error e = {0};
  oc_heightfield *hf = oc_heightfield_new(nx, ny, cell, x0, y0, NULL, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  float *z = oc_heightfield_samples_mut(hf);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      z[(size_t)j * nx + i] = (float)fn(x0 + i * cell, y0 + j * cell, k);
  return hf;
}

/* k = {amplitude, wavelength, seed, quantum}: fBm, rounded to multiples
** of `quantum` when > 0 (to make flats and ties). */
static double fbm(double x, double y, const double *k) {
  oc_vec3 p = {x / k[1], y / k[1], 0};
  double h = k[0] * oc_turb3((uint64_t)k[2], 5, p, NULL);
  return k[3] > 0 ? k[3] * floor(h / k[3]) : h;
}

/* k = {cx, cy, height, gradient}: cone z = height + gradient r (a peak when
** gradient < 0, a pit when > 0). */
static double cone(double x, double y, const double *k) {
  return k[2] + k[3] * hypot(x - k[0], y - k[1]);
}

/* k = {a, b}: plane z = a x + b y. */
static double plane(double x, double y, const double *k) {
  return k[0] * x + k[1] * y;
}

/* k = {cx, cy, c}: bowl z = c r^2. */
static double bowl(double x, double y, const double *k) {
  double dx = x - k[0], dy = y - k[1];
  return k[2] * (dx * dx + dy * dy);
}

/* k = {cx, t}: V valley (t > 0) or ridge (t < 0) along y: z = t |x - cx|. */
static double vee(double x, double y, const double *k) {
  (void)y;
  return k[1] * fabs(x - k[0]);
}

/* k = {cx, t, w}: canyon along y with a flat floor of half-width w and
** walls of slope t: z = t max(0, |x - cx| - w). */
static double canyon(double x, double y, const double *k) {
  (void)y;
  return k[1] * fmax(0, fabs(x - k[0]) - k[2]);
}

static oc_heightfield *ok(oc_heightfield *hf, const oc_error *e) {
  ck_assert_msg(hf != NULL, "analysis failed: %s", e->msg);
  return hf;
}

#define AT(hf, i, j)                                                           \
  (oc_heightfield_samples(hf)[(size_t)(j)*oc_heightfield_nx(hf) + (i)])

static int on_border(const oc_heightfield *hf, int i, int j) {
  return i == 0 || j == 0 || i == oc_heightfield_nx(hf) - 1 ||
         j == oc_heightfield_ny(hf) - 1;
}

static const int DI[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int DJ[8] = {0, 1, 1, 1, 0, -1, -1, -1};

static int has_lower(const oc_heightfield *hf, int i, int j) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  for (int k = 0; k < 8; k++) {
    int a = i + DI[k], b = j + DJ[k];
    if (a >= 0 && b >= 0 && a < nx && b < ny && AT(hf, a, b) < AT(hf, i, j))
      return 1;
  }
  return 0;
}

/* Spill level by fixed-point relaxation (Planchon and Darboux without
** epsilon): w = z on the border, else max(z, min of neighbours' w),
** iterated to convergence. Independent of the priority flood. */
static double *spill_levels(const oc_heightfield *hf) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double *w = malloc((size_t)nx * ny * sizeof *w);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      w[(size_t)j * nx + i] = on_border(hf, i, j) ? AT(hf, i, j) : INFINITY;
  for (int changed = 1; changed;) {
    changed = 0;
    for (int j = 1; j < ny - 1; j++)
      for (int i = 1; i < nx - 1; i++) {
        double m = INFINITY;
        for (int k = 0; k < 8; k++)
          m = fmin(m, w[(size_t)(j + DJ[k]) * nx + i + DI[k]]);
        double v = fmax(AT(hf, i, j), m);
        if (v < w[(size_t)j * nx + i]) {
          w[(size_t)j * nx + i] = v;
          changed = 1;
        }
      }
  }
  return w;
}

/* 1 where a strictly descending path leads to the border: built upwards
** in order of elevation. */
static int cmp_elev(const void *a, const void *b) {
  const double *x = a, *y = b;
  return x[0] < y[0] ? -1 : x[0] > y[0];
}

static unsigned char *draining(const oc_heightfield *hf) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  size_t n = (size_t)nx * ny;
  double *order = malloc(n * 2 * sizeof *order);
  unsigned char *d = calloc(n, 1);
  for (size_t c = 0; c < n; c++) {
    order[2 * c] = oc_heightfield_samples(hf)[c];
    order[2 * c + 1] = (double)c;
  }
  qsort(order, n, 2 * sizeof *order, cmp_elev);
  for (size_t t = 0; t < n; t++) {
    size_t c = (size_t)order[2 * t + 1];
    int i = (int)(c % nx), j = (int)(c / nx);
    if (on_border(hf, i, j)) {
      d[c] = 1;
      continue;
    }
    for (int k = 0; k < 8; k++) {
      size_t m = (size_t)(j + DJ[k]) * nx + i + DI[k];
      if (d[m] && AT(hf, i + DI[k], j + DJ[k]) < AT(hf, i, j)) d[c] = 1;
    }
  }
  free(order);
  return d;
}

/* Checks a filled grid g of h: g >= h, every interior sample has a
** strictly lower neighbour (so a strictly descending path from every
** sample ends on the border), g within ulps of the spill level, and g == h
** where h already drained. */
static void check_filled(const oc_heightfield *h, const oc_heightfield *g) {
  int nx = oc_heightfield_nx(h), ny = oc_heightfield_ny(h);
  double *w = spill_levels(h);
  unsigned char *d = draining(h);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      size_t c = (size_t)j * nx + i;
      double zh = AT(h, i, j), zg = AT(g, i, j);
      ck_assert_msg(zg >= zh, "filled below the grid at (%d, %d)", i, j);
      ck_assert_msg(on_border(g, i, j) || has_lower(g, i, j),
                    "interior sample (%d, %d) of the filled grid does not "
                    "drain",
                    i, j);
      /* at most one ulp per sample of the depression above the spill */
      double ulp = nextafterf((float)w[c], INFINITY) - (float)w[c];
      ck_assert_msg(zg >= (float)w[c] && zg <= w[c] + (double)nx * ny * ulp,
                    "(%d, %d): filled %.9g, spill level %.9g", i, j, zg, w[c]);
      if (d[c])
        ck_assert_msg(zg == zh,
                      "(%d, %d) drained already but was raised %.9g -> %.9g", i,
                      j, zh, zg);
      if (d[c]) ck_assert(w[c] == zh); /* the reference agrees */
    }
  free(w);
  free(d);
}

/* ---- slope --------------------------------------------------------------- */

START_TEST(slope_plane_exact) {
  double k[2] = {0.3, -0.4};
  oc_heightfield *h = grid(17, 13, 2.0, -5, 3, plane, k);
  oc_error e = {0};
  oc_heightfield *s = ok(oc_heightfield_slope(h, &e), &e);
  for (int j = 0; j < 13; j++)
    for (int i = 0; i < 17; i++) /* borders included (one-sided) */
      ck_assert_double_eq_tol(AT(s, i, j), 0.5, 1e-5);
  oc_heightfield_release(s);
  oc_heightfield_release(h);
}
END_TEST

START_TEST(slope_cone_constant) {
  /* tan of the angle is 0.7 everywhere but the apex; central differences
  ** on r err by at most (cell / r)^2 relative */
  double k[4] = {0, 0, 50, -0.7}, cell = 1.5;
  oc_heightfield *h = grid(41, 41, cell, -20 * cell, -20 * cell, cone, k);
  oc_error e = {0};
  oc_heightfield *s = ok(oc_heightfield_slope(h, &e), &e);
  int checked = 0;
  for (int j = 1; j < 40; j++)
    for (int i = 1; i < 40; i++) {
      double r = hypot(i - 20, j - 20);
      if (r < 3) continue;
      ck_assert_msg(fabs(AT(s, i, j) - 0.7) <= 0.7 / (r * r) + 1e-5,
                    "slope %g at r = %g cells", AT(s, i, j), r);
      checked++;
    }
  ck_assert_int_gt(checked, 1400);
  /* and agrees with the interpolant's gradient at samples */
  double g[2];
  oc_heightfield_height(h, -20 * cell + 27 * cell, -20 * cell + 31 * cell, g);
  ck_assert_double_eq_tol(AT(s, 27, 31), hypot(g[0], g[1]), 1e-5);
  oc_heightfield_release(s);
  oc_heightfield_release(h);
}
END_TEST

/* ---- filling ------------------------------------------------------------- */

START_TEST(fill_fbm_with_pits) {
  /* fBm, plain and quantized (flats, ties, flat-bottomed pits) */
  for (int q = 0; q < 2; q++) {
    double k[4] = {40, 30, 7 + q, q ? 0.5 : 0};
    oc_heightfield *h = grid(97, 83, 1.0, 0, 0, fbm, k);
    oc_error e = {0};
    oc_heightfield *g = ok(oc_heightfield_fill(h, (oc_progress){0}, &e), &e);
    check_filled(h, g);
    /* fBm of this size has depressions: filling must have raised some */
    size_t raised = 0, n = 97 * 83;
    for (size_t c = 0; c < n; c++)
      raised += oc_heightfield_samples(g)[c] > oc_heightfield_samples(h)[c];
    ck_assert_uint_gt(raised, 10);
    /* filling a filled grid changes nothing */
    oc_heightfield *g2 = ok(oc_heightfield_fill(g, (oc_progress){0}, &e), &e);
    ck_assert(memcmp(oc_heightfield_samples(g), oc_heightfield_samples(g2),
                     n * sizeof(float)) == 0);
    oc_heightfield_release(g2);
    oc_heightfield_release(g);
    oc_heightfield_release(h);
  }
}
END_TEST

START_TEST(fill_bowl_flat_at_rim) {
  /* z = c r^2 centred on a 41 x 41 grid: the rim's lowest samples are the
  ** middles of the sides, at r = 20 cells; below that everything fills to
  ** the rim level plus epsilon gradients */
  double k[3] = {20, 20, 0.01};
  oc_heightfield *h = grid(41, 41, 1.0, 0, 0, bowl, k);
  oc_error e = {0};
  oc_heightfield *g = ok(oc_heightfield_fill(h, (oc_progress){0}, &e), &e);
  check_filled(h, g);
  float rim = (float)(0.01 * 400);
  float ulp = nextafterf(rim, INFINITY) - rim;
  int inside = 0;
  for (int j = 0; j < 41; j++)
    for (int i = 0; i < 41; i++) {
      /* above the rim, and on the border, nothing changes; samples exactly
      ** at the rim level inside are part of the lake's surface */
      if (AT(h, i, j) > rim || on_border(h, i, j)) {
        ck_assert(AT(g, i, j) == AT(h, i, j));
        continue;
      }
      inside++;
      ck_assert_msg(AT(g, i, j) > rim && AT(g, i, j) <= rim + 41 * 41 * ulp,
                    "(%d, %d): %.9g, rim %.9g", i, j, AT(g, i, j), rim);
    }
  ck_assert_int_gt(inside, 1200); /* about pi 20^2 */
  oc_heightfield_release(g);
  oc_heightfield_release(h);
}
END_TEST

START_TEST(fill_pit_chain_exact) {
  /* a 1D channel descending to the border with one hole: the hole fills
  ** to exactly one ulp above the sample it spills over */
  float z[7 * 3];
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 7; i++)
      z[j * 7 + i] = j == 1 ? (float)i : 100;
  z[1 * 7 + 4] = 1; /* hole: lower than its neighbours 3 and 5 */
  oc_error e = {0};
  oc_heightfield *h = oc_heightfield_new(7, 3, 1, 0, 0, z, &e);
  oc_heightfield *g = ok(oc_heightfield_fill(h, (oc_progress){0}, &e), &e);
  ck_assert(AT(g, 4, 1) == nextafterf(3, INFINITY));
  for (int i = 0; i < 7; i++)
    if (i != 4) ck_assert(AT(g, i, 1) == AT(h, i, 1));
  check_filled(h, g);
  oc_heightfield_release(g);
  oc_heightfield_release(h);
}
END_TEST

/* ---- drainage ------------------------------------------------------------ */

/* Sum of the drainage of the samples with no lower neighbour in the
** filled grid; asserts they are border samples, and area >= cell^2. */
static double outflow(const oc_heightfield *filled, const oc_heightfield *a) {
  int nx = oc_heightfield_nx(a), ny = oc_heightfield_ny(a);
  double c2 = oc_heightfield_cell(a) * oc_heightfield_cell(a), sum = 0;
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      ck_assert_msg(AT(a, i, j) >= (float)c2, "area %g < cell^2 at (%d, %d)",
                    AT(a, i, j), i, j);
      if (has_lower(filled, i, j)) continue;
      ck_assert_msg(on_border(filled, i, j), "(%d, %d) keeps its water", i, j);
      sum += AT(a, i, j);
    }
  return sum;
}

START_TEST(drainage_conserves_area) {
  double k[4] = {60, 25, 3, 0};
  const double cell = 2.5;
  oc_heightfield *h = grid(120, 90, cell, 0, 0, fbm, k);
  oc_error e = {0};
  oc_heightfield *g = ok(oc_heightfield_fill(h, (oc_progress){0}, &e), &e);
  oc_heightfield *a = ok(oc_heightfield_drainage(h, NULL, &e), &e);
  double total = 120.0 * 90 * cell * cell;
  ck_assert_double_eq_tol(outflow(g, a) / total, 1, 1e-6);
  /* the largest value is a big share of the total: flow does gather */
  double lo, hi;
  oc_heightfield_minmax(a, &lo, &hi);
  ck_assert_double_eq(lo, cell * cell); /* ridge tops receive nothing */
  ck_assert_double_gt(hi, 0.02 * total);
  /* prefilled on the filled grid gives the same bytes */
  oc_heightfield_flow_params fp = {0, 1, {0}};
  oc_heightfield *a2 = ok(oc_heightfield_drainage(g, &fp, &e), &e);
  ck_assert(memcmp(oc_heightfield_samples(a), oc_heightfield_samples(a2),
                   120 * 90 * sizeof(float)) == 0);
  /* another exponent routes differently but conserves too */
  fp.exponent = 3;
  oc_heightfield *a3 = ok(oc_heightfield_drainage(g, &fp, &e), &e);
  ck_assert_double_eq_tol(outflow(g, a3) / total, 1, 1e-6);
  ck_assert(memcmp(oc_heightfield_samples(a), oc_heightfield_samples(a3),
                   120 * 90 * sizeof(float)) != 0);
  oc_heightfield_release(a3);
  oc_heightfield_release(a2);
  oc_heightfield_release(a);
  oc_heightfield_release(g);
  oc_heightfield_release(h);
}
END_TEST

START_TEST(drainage_tilted_plane_linear) {
  /* z = 0.2 x: everything flows towards x = 0, one column per step; the
  ** flow across column i is the area of columns i..nx-1, and away from the
  ** sides (which the flow reaches at one sample per column at most) each
  ** sample holds (nx - i) cell^2 */
  const int nx = 24, ny = 101;
  const double cell = 3;
  double k[2] = {0.2, 0};
  oc_heightfield *h = grid(nx, ny, cell, 0, 0, plane, k);
  oc_error e = {0};
  oc_heightfield *a = ok(oc_heightfield_drainage(h, NULL, &e), &e);
  oc_heightfield *sp = ok(oc_heightfield_stream_power(h, NULL, &e), &e);
  for (int i = 0; i < nx; i++) {
    double col = 0, want = (nx - i) * cell * cell;
    for (int j = 0; j < ny; j++)
      col += AT(a, i, j);
    ck_assert_double_eq_tol(col / (want * ny), 1, 1e-6);
    for (int j = nx; j < ny - nx; j++) {
      ck_assert_double_eq_tol(AT(a, i, j) / want, 1, 1e-6);
      ck_assert_double_eq_tol(AT(sp, i, j) / (sqrt(want) * 0.2), 1, 1e-5);
    }
  }
  oc_heightfield_release(sp);
  oc_heightfield_release(a);
  oc_heightfield_release(h);
}
END_TEST

START_TEST(drainage_cone_grows_with_r) {
  /* On a peak, divergent flow: a sample at radius r (in cells) drains the
  ** sector of the disc out to its outer edge r + 1/2 whose width is one
  ** cell at r, so A = cell^2 (r + 1/2)^2 / (2 r): proportional to r for
  ** large r. Multiple flow directions on the grid spread a little more
  ** water sideways than the continuous sector (a few per cent). */
  const int n = 121, m = 60;
  const double cell = 2;
  double k[4] = {0, 0, 200, -0.5};
  oc_heightfield *h = grid(n, n, cell, -m * cell, -m * cell, cone, k);
  oc_error e = {0};
  oc_heightfield *a = ok(oc_heightfield_drainage(h, NULL, &e), &e);
  double mean[4];
  for (int q = 0; q < 4; q++) {
    double R = 10 + 14 * q, sum = 0;
    int cnt = 0;
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) {
        double r = hypot(i - m, j - m);
        if (r < R - 0.5 || r >= R + 0.5) continue;
        double sector = cell * cell * (r + 0.5) * (r + 0.5) / (2 * r);
        double v = AT(a, i, j) / sector;
        ck_assert_msg(v >= 1 && v <= 1.07, "r = %g: A / sector = %g", r, v);
        sum += v, cnt++;
      }
    mean[q] = sum / cnt;
  }
  /* the same proportion at every radius */
  for (int q = 1; q < 4; q++)
    ck_assert_double_eq_tol(mean[q] / mean[0], 1, 0.015);
  oc_heightfield_release(a);
  oc_heightfield_release(h);
}
END_TEST

/* ---- sinks --------------------------------------------------------------- */

START_TEST(sinks_of_pits) {
  /* inverted cone: one sink, at the apex */
  double k[4] = {3, -2, 10, 0.4};
  oc_heightfield *h = grid(31, 25, 0.5, 3 - 15 * 0.5, -2 - 12 * 0.5, cone, k);
  oc_error e = {0};
  oc_vec3 *p;
  size_t n;
  ck_assert_int_eq(oc_heightfield_sinks(h, &p, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 1);
  ck_assert_double_eq(p[0].x, 3);
  ck_assert_double_eq(p[0].y, -2);
  ck_assert_double_eq(p[0].z, 10);
  free(p);
  /* its filled version has none */
  oc_heightfield *g = ok(oc_heightfield_fill(h, (oc_progress){0}, &e), &e);
  ck_assert_int_eq(oc_heightfield_sinks(g, &p, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 0);
  ck_assert_ptr_null(p);
  oc_heightfield_release(g);
  oc_heightfield_release(h);

  /* a bowl: one sink at the centre */
  double b[3] = {10, 10, 0.05};
  h = grid(21, 21, 1, 0, 0, bowl, b);
  ck_assert_int_eq(oc_heightfield_sinks(h, &p, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 1);
  ck_assert(p[0].x == 10 && p[0].y == 10 && p[0].z == 0);
  free(p);
  oc_heightfield_release(h);

  /* a plane with holes: a single-sample pit (reported), one on the border
  ** and a flat-bottomed pair (neither reported), in row order */
  double t[2] = {0.01, 0.02};
  h = grid(20, 10, 1, 0, 0, plane, t);
  float *z = oc_heightfield_samples_mut(h);
  z[5 * 20 + 7] = -3;                 /* pit at (7, 5) */
  z[2 * 20 + 15] = -4;                /* pit at (15, 2) */
  z[0 * 20 + 4] = -5;                 /* border */
  z[7 * 20 + 2] = z[7 * 20 + 3] = -6; /* flat bottom */
  ck_assert_int_eq(oc_heightfield_sinks(h, &p, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 2);
  ck_assert(p[0].x == 15 && p[0].y == 2 && p[0].z == -4);
  ck_assert(p[1].x == 7 && p[1].y == 5 && p[1].z == -3);
  free(p);
  oc_heightfield_release(h);
}
END_TEST

/* ---- accessibility ------------------------------------------------------- */

START_TEST(access_flat_plane_is_one) {
  double k[2] = {0, 0};
  oc_heightfield *h = grid(30, 20, 1, 0, 0, plane, k);
  oc_error e = {0};
  oc_heightfield_access_params ap = {128, 20, 5, {0}};
  oc_heightfield *a = ok(oc_heightfield_accessibility(h, &ap, &e), &e);
  double lo, hi;
  oc_heightfield_minmax(a, &lo, &hi);
  ck_assert(lo == 1 && hi == 1);
  oc_heightfield_release(a);
  oc_heightfield_release(h);
}
END_TEST

START_TEST(access_tilted_and_valley) {
  /* uniform over the solid angle of the upper hemisphere: a plane tilted
  ** by a hides a lune of dihedral a (1 - a / pi); a V valley with sides at
  ** a, two (1 - 2 a / pi); a ridge hides nothing */
  const double t = 0.8, a = atan(t);
  double pk[2] = {t, 0}, vk[2] = {20, t}, rk[2] = {20, -t};
  oc_heightfield *p = grid(41, 21, 1, 0, 0, plane, pk);
  oc_heightfield *v = grid(41, 21, 1, 0, 0, vee, vk);
  oc_heightfield *r = grid(41, 21, 1, 0, 0, vee, rk);
  oc_error e = {0};
  oc_heightfield_access_params ap = {2048, 15, 9, {0}};
  oc_heightfield *ap_p = ok(oc_heightfield_accessibility(p, &ap, &e), &e);
  oc_heightfield *ap_v = ok(oc_heightfield_accessibility(v, &ap, &e), &e);
  oc_heightfield *ap_r = ok(oc_heightfield_accessibility(r, &ap, &e), &e);
  for (int j = 5; j <= 15; j += 5) {
    ck_assert_double_eq_tol(AT(ap_p, 20, j), 1 - a / PI, 0.01);
    ck_assert_double_eq_tol(AT(ap_v, 20, j), 1 - 2 * a / PI, 0.01);
    ck_assert(AT(ap_r, 20, j) == 1);
    ck_assert(AT(ap_v, 20, j) < AT(ap_r, 20, j));
  }
  /* `distance` limits the search: from the middle of a canyon floor 16
  ** cells wide the walls are 8 cells away, out of reach of 7-metre rays
  ** and in reach of 40-metre ones */
  double ck[3] = {20, 3, 8};
  oc_heightfield *u = grid(41, 21, 1, 0, 0, canyon, ck);
  ap.distance = 7;
  oc_heightfield *shortr = ok(oc_heightfield_accessibility(u, &ap, &e), &e);
  ap.distance = 40;
  oc_heightfield *longr = ok(oc_heightfield_accessibility(u, &ap, &e), &e);
  ck_assert(AT(shortr, 20, 10) == 1);
  ck_assert_double_lt(AT(longr, 20, 10), 0.9);
  oc_heightfield_release(longr);
  oc_heightfield_release(shortr);
  oc_heightfield_release(u);
  oc_heightfield_release(ap_p);
  oc_heightfield_release(ap_v);
  oc_heightfield_release(ap_r);
  oc_heightfield_release(p);
  oc_heightfield_release(v);
  oc_heightfield_release(r);
}
END_TEST

/* ---- distance to a level ------------------------------------------------- */

START_TEST(distance_exact) {
  /* one wet sample: distances are exactly sqrt(di^2 + dj^2) cell */
  double k[4] = {0, 0, 5, 1};
  oc_heightfield *h = grid(9, 7, 0.5, 0, 0, cone, k); /* min 5 at (0, 0) */
  oc_error e = {0};
  oc_heightfield *d = ok(oc_heightfield_distance_to_level(h, 5, &e), &e);
  for (int j = 0; j < 7; j++)
    for (int i = 0; i < 9; i++)
      ck_assert(AT(d, i, j) == (float)(sqrt((double)(i * i + j * j)) * 0.5));
  oc_heightfield_release(d);
  oc_heightfield_release(h);

  /* random terrain against brute force over every wet sample */
  double f[4] = {30, 12, 4, 0};
  h = grid(53, 41, 1.25, 0, 0, fbm, f);
  double lo, hi;
  oc_heightfield_minmax(h, &lo, &hi);
  double level = lo + 0.3 * (hi - lo);
  d = ok(oc_heightfield_distance_to_level(h, level, &e), &e);
  int wet = 0;
  for (int j = 0; j < 41; j++)
    for (int i = 0; i < 53; i++) {
      long best = -1;
      for (int b = 0; b < 41; b++)
        for (int a = 0; a < 53; a++)
          if (AT(h, a, b) <= level) {
            long d2 = (long)(a - i) * (a - i) + (long)(b - j) * (b - j);
            if (best < 0 || d2 < best) best = d2;
          }
      wet += AT(h, i, j) <= level;
      ck_assert_msg(AT(d, i, j) == (float)(sqrt((double)best) * 1.25),
                    "(%d, %d): %g, brute force %g", i, j, AT(d, i, j),
                    sqrt((double)best) * 1.25);
    }
  ck_assert_int_gt(wet, 20);
  ck_assert_int_lt(wet, 53 * 41 - 20);
  oc_heightfield_release(d);
  oc_heightfield_release(h);
}
END_TEST

/* ---- determinism --------------------------------------------------------- */

typedef oc_heightfield *(*analysis_fn)(const oc_heightfield *hf);

static oc_heightfield *run_slope(const oc_heightfield *h) {
  return oc_heightfield_slope(h, NULL);
}
static oc_heightfield *run_fill(const oc_heightfield *h) {
  return oc_heightfield_fill(h, (oc_progress){0}, NULL);
}
static oc_heightfield *run_drainage(const oc_heightfield *h) {
  return oc_heightfield_drainage(h, NULL, NULL);
}
static oc_heightfield *run_power(const oc_heightfield *h) {
  return oc_heightfield_stream_power(h, NULL, NULL);
}
static oc_heightfield *run_access(const oc_heightfield *h) {
  oc_heightfield_access_params ap = {16, 30, 3, {0}};
  return oc_heightfield_accessibility(h, &ap, NULL);
}
static oc_heightfield *run_distance(const oc_heightfield *h) {
  return oc_heightfield_distance_to_level(h, 20, NULL);
}

START_TEST(same_bytes_any_threads) {
  const analysis_fn fns[] = {run_slope, run_fill,   run_drainage,
                             run_power, run_access, run_distance};
  double k[4] = {50, 40, 11, 0};
  oc_heightfield *h = grid(301, 257, 1, 0, 0, fbm, k);
  size_t bytes = 301 * 257 * sizeof(float);
  int saved = omp_get_max_threads();
  for (size_t f = 0; f < sizeof fns / sizeof *fns; f++) {
    omp_set_num_threads(1);
    oc_heightfield *a = fns[f](h);
    omp_set_num_threads(2);
    oc_heightfield *b = fns[f](h);
    omp_set_num_threads(3);
    oc_heightfield *c = fns[f](h);
    ck_assert(a && b && c);
    ck_assert_msg(memcmp(oc_heightfield_samples(a), oc_heightfield_samples(b),
                         bytes) == 0 &&
                      memcmp(oc_heightfield_samples(a),
                             oc_heightfield_samples(c), bytes) == 0,
                  "analysis %zu differs between thread counts", f);
    oc_heightfield_release(a);
    oc_heightfield_release(b);
    oc_heightfield_release(c);
  }
  omp_set_num_threads(saved);
  oc_heightfield_release(h);
}
END_TEST

/* ---- parameters, errors, cancellation ------------------------------------ */

static void expect_einval(oc_heightfield *r, const oc_error *e,
                          const char *param) {
  ck_assert_ptr_null(r);
  ck_assert_int_eq(e->code, OC_EINVAL);
  char q[64];
  snprintf(q, sizeof q, "'%s'", param);
  ck_assert_msg(strstr(e->msg, q) != NULL, "message \"%s\" lacks %s", e->msg,
                q);
}

START_TEST(bad_parameters) {
  double k[2] = {0.1, 0};
  oc_heightfield *h = grid(10, 10, 1, 0, 0, plane, k);
  oc_error e = {0};
  const double bad_p[] = {-1, 4.5, NAN, INFINITY};
  for (int t = 0; t < 4; t++) {
    oc_heightfield_flow_params fp = {bad_p[t], 0, {0}};
    expect_einval(oc_heightfield_drainage(h, &fp, &e), &e, "exponent");
    expect_einval(oc_heightfield_stream_power(h, &fp, &e), &e, "exponent");
  }
  const int bad_rays[] = {-1, 4097};
  for (int t = 0; t < 2; t++) {
    oc_heightfield_access_params ap = {bad_rays[t], 0, 0, {0}};
    expect_einval(oc_heightfield_accessibility(h, &ap, &e), &e, "rays");
  }
  const double bad_d[] = {-1, NAN, INFINITY};
  for (int t = 0; t < 3; t++) {
    oc_heightfield_access_params ap = {0, bad_d[t], 0, {0}};
    expect_einval(oc_heightfield_accessibility(h, &ap, &e), &e, "distance");
  }
  expect_einval(oc_heightfield_distance_to_level(h, NAN, &e), &e, "z");
  expect_einval(oc_heightfield_distance_to_level(h, -0.5, &e), &e, "z");
  /* NULL grids are refused, not dereferenced */
  ck_assert_ptr_null(oc_heightfield_slope(NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_null(oc_heightfield_fill(NULL, (oc_progress){0}, &e));
  ck_assert_ptr_null(oc_heightfield_drainage(NULL, NULL, &e));
  ck_assert_ptr_null(oc_heightfield_accessibility(NULL, NULL, &e));
  oc_vec3 *p = (oc_vec3 *)&e;
  size_t n = 7;
  ck_assert_int_eq(oc_heightfield_sinks(NULL, &p, &n, &e), OC_EINVAL);
  ck_assert_ptr_null(p);
  ck_assert_uint_eq(n, 0);
  /* defaults: exponent 0 is Freeman's 1.1 */
  oc_heightfield_flow_params d0 = {0, 0, {0}}, d1 = {1.1, 0, {0}};
  oc_heightfield *a = ok(oc_heightfield_drainage(h, &d0, &e), &e);
  oc_heightfield *b = ok(oc_heightfield_drainage(h, &d1, &e), &e);
  ck_assert(memcmp(oc_heightfield_samples(a), oc_heightfield_samples(b),
                   100 * sizeof(float)) == 0);
  oc_heightfield_release(a);
  oc_heightfield_release(b);
  oc_heightfield_release(h);
}
END_TEST

typedef struct counter {
  int calls, stop_at;
  double last;
  int monotone;
} counter;

static int count_progress(void *ud, double f) {
  counter *c = ud;
  if (f < c->last || f < 0 || f > 1) c->monotone = 0;
  c->last = f;
  return ++c->calls >= c->stop_at;
}

START_TEST(progress_and_cancel) {
  double k[4] = {50, 40, 2, 0};
  oc_heightfield *h = grid(400, 300, 1, 0, 0, fbm, k);
  oc_error e = {0};
  /* reported, monotone, ending at 1 */
  counter c = {0, 1 << 30, 0, 1};
  oc_heightfield_flow_params fp = {0, 0, {count_progress, &c}};
  oc_heightfield *s = ok(oc_heightfield_stream_power(h, &fp, &e), &e);
  ck_assert_int_gt(c.calls, 3);
  ck_assert(c.monotone && c.last == 1);
  oc_heightfield_release(s);
  /* cancelled at the first report, in each phase */
  counter c1 = {0, 1, 0, 1};
  ck_assert_ptr_null(
      oc_heightfield_fill(h, (oc_progress){count_progress, &c1}, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  for (int stop = 1; stop <= 4; stop++) {
    counter c2 = {0, stop, 0, 1};
    fp.progress.ud = &c2;
    ck_assert_ptr_null(oc_heightfield_drainage(h, &fp, &e));
    ck_assert_int_eq(e.code, OC_ECANCEL);
  }
  counter c3 = {0, 1, 0, 1};
  oc_heightfield_access_params ap = {4, 5, 1, {count_progress, &c3}};
  ck_assert_ptr_null(oc_heightfield_accessibility(h, &ap, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  oc_heightfield_release(h);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("analysis");
  TCase *t = tcase_create("analytic");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, slope_plane_exact);
  tcase_add_test(t, slope_cone_constant);
  tcase_add_test(t, fill_fbm_with_pits);
  tcase_add_test(t, fill_bowl_flat_at_rim);
  tcase_add_test(t, fill_pit_chain_exact);
  tcase_add_test(t, drainage_conserves_area);
  tcase_add_test(t, drainage_tilted_plane_linear);
  tcase_add_test(t, drainage_cone_grows_with_r);
  tcase_add_test(t, sinks_of_pits);
  tcase_add_test(t, access_flat_plane_is_one);
  tcase_add_test(t, access_tilted_and_valley);
  tcase_add_test(t, distance_exact);
  suite_add_tcase(s, t);
  t = tcase_create("engine");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, same_bytes_any_threads);
  tcase_add_test(t, bad_parameters);
  tcase_add_test(t, progress_and_cancel);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
