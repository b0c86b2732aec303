/*
** test_terrain.c — the terrain node (heightfield implicitization, Paris et al.
** 2019
** section 5.1) and direct elevation extraction in the mesher (section 7).
**
** Checked against formulas written here, not borrowed from lib/: sigma's
** profile, the crossing of f = T on random columns against an independent
** Catmull-Rom interpolation of the grid, inversion, masks, analytic
** gradients against central differences, global and local Lipschitz
** bounds on point pairs, support inside the bounds, the heightfield
** source's ranges and slopes (exact for planar grids), column spans
** (covering, and tight), and meshes of DEMs: closed and manifold from the
** written file, the same for 1, 2 and 3 threads and with or without
** surface bounds, seamless next to sculpted features, fewer field calls
** with direct extraction, vertices on the elevation.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshread.h"
#include "ocheck.h"
#include "terrain/terrain.h"
#include "outcrop.h"

/* ---- grids and an independent interpolation ------------------------------ */

/* A smooth landscape with some bumps and noise: z(i, j) of an nx x ny grid. */
static oc_heightfield *grid(int nx, int ny, double cell, double x0, double y0,
                            double amp, uint64_t seed) {
  oct_rng r = oct_rng_new(seed);
  float *z = malloc((size_t)nx * ny * sizeof *z);
  double a = oct_unif(&r, 0, 6), b = oct_unif(&r, 0, 6);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      z[(size_t)j * nx + i] =
          (float)(amp * (sin(0.21 * i + a) * cos(0.17 * j + b) +
                         0.4 * sin(0.05 * (i + 2 * j))) +
                  0.05 * amp * oct_unif(&r, -1, 1));
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(nx, ny, cell, x0, y0, z, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  free(z);
  return hf;
}

static double cr1(double p0, double p1, double p2, double p3, double t) {
  return 0.5 *
         (2 * p1 + (p2 - p0) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t +
          (3 * p1 - p0 - 3 * p2 + p3) * t * t * t);
}

/* Catmull-Rom through the samples, indices clamped at the borders. */
static double ref_height(const oc_heightfield *hf, double x, double y) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double x0, y0, c = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  const float *z = oc_heightfield_samples(hf);
  double u = (x - x0) / c, v = (y - y0) / c;
  int i = (int)floor(u), j = (int)floor(v);
  if (i > nx - 2) i = nx - 2;
  if (j > ny - 2) j = ny - 2;
  double row[4];
  for (int b = 0; b < 4; b++) {
    int jj = j - 1 + b < 0 ? 0 : j - 1 + b > ny - 1 ? ny - 1 : j - 1 + b;
    double p[4];
    for (int a = 0; a < 4; a++) {
      int ii = i - 1 + a < 0 ? 0 : i - 1 + a > nx - 1 ? nx - 1 : i - 1 + a;
      p[a] = z[(size_t)jj * nx + ii];
    }
    row[b] = cr1(p[0], p[1], p[2], p[3], u - i);
  }
  return cr1(row[0], row[1], row[2], row[3], v - j);
}

static oc_node *terrain_e(oc_heightfield *hf, double R, double W, int invert,
                          double thick, const oc_heightfield *mask, int edges) {
  oc_error e;
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {R, W, invert, thick, mask, edges};
  oc_node *n = oc_terrain(&src, &tp, &e);
  src.release(src.ud);
  ck_assert_msg(n != NULL, "oc_terrain: %s", e.msg);
  return n;
}

/* The paper's slab: most tests here check its prism. */
static oc_node *terrain_thick(oc_heightfield *hf, double R, double W,
                              int invert, double thick,
                              const oc_heightfield *mask) {
  return terrain_e(hf, R, W, invert, thick, mask,
                   mask ? OC_TERRAIN_EDGES_DEFAULT : OC_TERRAIN_SLAB);
}

static oc_node *terrain_of(oc_heightfield *hf, double R, double W, int invert,
                           const oc_heightfield *mask) {
  return terrain_thick(hf, R, W, invert, 0, mask);
}

/* z in [lo, hi] where f crosses T, f > T at lo and f < T at hi. */
static double crossing(const oc_program *pr, double x, double y, double lo,
                       double hi) {
  double T = oc_program_threshold(pr);
  double flo = oc_program_eval(pr, oct_v(x, y, lo));
  double fhi = oc_program_eval(pr, oct_v(x, y, hi));
  ck_assert_msg((flo > T) != (fhi > T), "no crossing at %g %g: %g %g", x, y,
                flo, fhi);
  int lo_in = flo > T;
  for (int it = 0; it < 80; it++) {
    double m = 0.5 * (lo + hi);
    if ((oc_program_eval(pr, oct_v(x, y, m)) > T) == lo_in)
      lo = m;
    else
      hi = m;
  }
  return 0.5 * (lo + hi);
}

/* ---- sigma ------------------------------------------------------------- */

/* The paper's cubic: T + x + (3T - 2W)/W^2 x^2 + (W - 2T)/W^3 x^3 on
** [0, W], odd around (0, T). */
static double paper_sigma(double x, double T, double W) {
  if (x >= W) return 2 * T;
  if (x <= -W) return 0;
  double a = fabs(x);
  double s = a + (3 * T - 2 * W) / (W * W) * a * a +
             (W - 2 * T) / (W * W * W) * a * a * a;
  return x >= 0 ? T + s : T - s;
}

START_TEST(sigma_profile) {
  const double T = 0.5, h0 = 2.25;
  float z[40 * 40];
  for (int k = 0; k < 1600; k++)
    z[k] = (float)h0;
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(40, 40, 1, 0, 0, z, &e);
  static const double Ws[] = {0.3, 0.5, 1.0, 1.5, 4.0};
  for (int w = 0; w < 5; w++) {
    double W = Ws[w];
    for (int inv = 0; inv < 2; inv++) {
      /* a thick prism: f = sigma over the whole window */
      oc_program *pr =
          oct_compile(terrain_thick(hf, 5, W, inv, 10, NULL), T, 0);
      double prev = 0;
      for (int k = -200; k <= 200; k++) {
        double v = 1.2 * W * k / 200; /* h - z */
        double f = oc_program_eval(pr, oct_v(20.3, 19.6, h0 - v));
        ck_assert(f >= 0 && f <= 2 * T);
        if (W <= 3 * T) {
          double ref = paper_sigma(inv ? -v : v, T, W);
          ck_assert_msg(fabs(f - ref) < 1e-12, "W %g v %g: %.15g vs %.15g", W,
                        v, f, ref);
        }
        /* monotone: f grows with v = h - z (falls when inverted) */
        if (k > -200) ck_assert(inv ? f <= prev + 1e-15 : f >= prev - 1e-15);
        prev = f;
        if (k % 17 == 0)
          oct_check_grad(pr, oct_v(20.3, 19.6, h0 - v), 1e-6, 1e-7);
      }
      /* sigma(0) = T exactly at the surface, sigma'(0) = 1 when W <= 3T */
      ck_assert(fabs(oc_program_eval(pr, oct_v(20.3, 19.6, h0)) - T) < 1e-12);
      oc_vec3 g;
      oc_program_gradient(pr, oct_v(20.3, 19.6, h0), &g);
      double slope = W <= 3 * T ? 1 : 3 * T / W;
      ck_assert(fabs(fabs(g.z) - slope) < 1e-9);
      oc_program_free(pr);
    }
  }
  oc_heightfield_release(hf);
}
END_TEST

/* ---- the surface embeds the heightfield -----------------------------------
 */

START_TEST(embeds_heightfield) {
  oc_heightfield *hf = grid(65, 49, 2, -10, 5, 12, 1);
  const double R = 6, W = 1, c = 2;
  for (int inv = 0; inv < 2; inv++) {
    oc_program *pr = oct_compile(terrain_of(hf, R, W, inv, NULL), 0, 0);
    oc_aabb b = oc_program_bounds(pr);
    oct_rng r = oct_rng_new(7 + inv);
    double worst = 0;
    for (int n = 0; n < 400; n++) {
      double x = oct_unif(&r, -10 + R, -10 + 64 * c - R);
      double y = oct_unif(&r, 5 + R, 5 + 48 * c - R);
      double h = ref_height(hf, x, y);
      ck_assert(fabs(h - oc_heightfield_height(hf, x, y, NULL)) < 1e-9);
      /* one crossing between the prism's floor and the top of the support
      ** (or the reverse when inverted) */
      double z = inv ? crossing(pr, x, y, b.hi.z - R + 0.05, b.lo.z)
                     : crossing(pr, x, y, b.lo.z + R - 0.05, b.hi.z);
      worst = fmax(worst, fabs(z - h));
      /* inside below (above when inverted) */
      double up = oc_program_eval(pr, oct_v(x, y, h + 0.3));
      double dn = oc_program_eval(pr, oct_v(x, y, h - 0.3));
      ck_assert(inv ? up > 0.5 && dn < 0.5 : up < 0.5 && dn > 0.5);
    }
    ck_assert_msg(worst <= 1e-3 * c, "crossing %g from h", worst);
    oc_program_free(pr);
  }
  oc_heightfield_release(hf);
}
END_TEST

/* ---- gradients, Lipschitz bounds, support ------------------------------ */

static oc_heightfield *disc_mask(int n, double cell, double x0, double y0,
                                 double cx, double cy, double rad) {
  float *m = malloc((size_t)n * n * sizeof *m);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++)
      m[(size_t)j * n + i] =
          hypot(x0 + i * cell - cx, y0 + j * cell - cy) < rad ? 1.0f : 0.0f;
  oc_error e;
  oc_heightfield *hf = oc_heightfield_new(n, n, cell, x0, y0, m, &e);
  free(m);
  return hf;
}

START_TEST(gradient_lipschitz_support) {
  oc_heightfield *hf = grid(41, 37, 1.5, 3, -2, 6, 2);
  oc_heightfield *mask = disc_mask(50, 1.25, 2, -3, 33, 25, 22);
  for (int variant = 0; variant < 4; variant++) {
    int inv = variant & 1, masked = variant >> 1;
    oc_program *pr = oct_compile(terrain_of(hf, 4.5, variant == 3 ? 2.5 : 0.8,
                                            inv, masked ? mask : NULL),
                                 0, 0);
    oc_aabb b = oc_program_bounds(pr);
    ck_assert(isfinite(b.lo.x + b.lo.y + b.lo.z + b.hi.x + b.hi.y + b.hi.z));
    oc_vec3 lo = oct_v(b.lo.x - 3, b.lo.y - 3, b.lo.z - 3);
    oc_vec3 hi = oct_v(b.hi.x + 3, b.hi.y + 3, b.hi.z + 3);
    oct_rng r = oct_rng_new(30 + variant);
    for (int n = 0; n < 3000; n++) {
      oc_vec3 p = oct_in_box(&r, lo, hi);
      oct_check_grad(pr, p, 1e-6, 1e-6);
    }
    double worst = oct_check_lipschitz(pr, lo, hi, 20000, &r);
    ck_assert(worst <= 1);
    ck_assert(worst > 0.05); /* the bound is not absurdly loose */
    /* local bounds on random boxes */
    for (int n = 0; n < 300; n++) {
      oc_vec3 c = oct_in_box(&r, lo, hi);
      double s = oct_unif(&r, 0.2, 6);
      oc_aabb box = {c, oct_add(c, oct_v(s, s * 0.7, s * 0.5))};
      double L = oc_program_lipschitz_in(pr, box);
      ck_assert(L <= oc_program_lipschitz(pr) * (1 + 1e-12));
      for (int k = 0; k < 40; k++) {
        oc_vec3 p = oct_in_box(&r, box.lo, box.hi),
                q = oct_in_box(&r, box.lo, box.hi);
        double df = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q));
        ck_assert_msg(df <= L * oct_len(oct_sub(p, q)) * (1 + 1e-9) + 1e-15,
                      "local bound %g broken: %g over %g", L, df,
                      oct_len(oct_sub(p, q)));
      }
    }
    ck_assert_int_gt(oct_check_bounds(pr, lo, hi, 20000, &r), 100);
    oc_program_free(pr);
  }
  oc_heightfield_release(mask);
  oc_heightfield_release(hf);
}
END_TEST

/* The mask's distance range over a footprint: exact over few nodes, and
** from the min/max pyramid over many, always a superset of the nodes'
** range (lo below their minimum, hi above their maximum). */
START_TEST(mask_range_pyramid) {
  oc_heightfield *mask = disc_mask(203, 0.5, -3, 2, 45, 50, 38);
  oc_tdata *t = calloc(1, sizeof *t);
  t->R = 4;
  t->src.x0 = t->src.y0 = -1e9;
  t->src.x1 = t->src.y1 = 1e9;
  oc_error e;
  ck_assert_int_eq(oc_terrain_mask(t, mask, &e), OC_OK);
  ck_assert_int_ge(t->mlev, 7);
  oct_rng r = oct_rng_new(31);
  int exact = 0, coarse = 0;
  for (int k = 0; k < 3000; k++) {
    double w = k % 3 ? oct_unif(&r, 0, 3) : oct_unif(&r, 3, 90);
    double x0 = oct_unif(&r, -3, 98 - w), y0 = oct_unif(&r, 2, 103 - w);
    double x1 = x0 + w, y1 = y0 + oct_unif(&r, 0, w);
    double lo, hi;
    oc_terrain_mask_range(t, x0, y0, x1, y1, &lo, &hi);
    /* the nodes of the footprint, as the query takes them */
    int i0 = (int)((x0 + 3) / 0.5), i1 = (int)ceil((x1 + 3) / 0.5);
    int j0 = (int)((y0 - 2) / 0.5), j1 = (int)ceil((y1 - 2) / 0.5);
    double a = INFINITY, b = 0;
    for (int j = j0; j <= j1 && j < 203; j++)
      for (int i = i0; i <= i1 && i < 203; i++) {
        a = fmin(a, t->dist[(size_t)j * 203 + i]);
        b = fmax(b, t->dist[(size_t)j * 203 + i]);
      }
    ck_assert_msg(lo <= a && hi >= b, "range [%g, %g] misses [%g, %g]", lo, hi,
                  a, b);
    if ((i1 - i0 + 1) * (j1 - j0 + 1) <= 64) {
      ck_assert(lo == a && hi == b);
      exact++;
    } else {
      coarse++;
    }
    /* and the interpolated distance anywhere inside lies in it */
    for (int q = 0; q < 4; q++) {
      double d = oc_terrain_mask_dist(t, oct_unif(&r, x0, x1),
                                      oct_unif(&r, y0, y1), NULL);
      ck_assert(d >= lo - 1e-6 && d <= hi + 1e-6);
    }
  }
  ck_assert(exact > 500 && coarse > 500);
  oc_tdata_free(t);
  oc_heightfield_release(mask);
}
END_TEST

START_TEST(mask_shapes_domain) {
  oc_heightfield *hf = grid(61, 61, 1, 0, 0, 4, 3);
  oc_heightfield *mask = disc_mask(61, 1, 0, 0, 30, 30, 15);
  const double R = 3;
  oc_program *pr = oct_compile(terrain_of(hf, R, 1, 0, mask), 0, 0);
  oc_aabb b = oc_program_bounds(pr);
  ck_assert(b.lo.x >= 13 && b.hi.x <= 47 && b.lo.y >= 13 && b.hi.y <= 47);
  oct_rng r = oct_rng_new(5);
  for (int n = 0; n < 500; n++) {
    double a = oct_unif(&r, 0, 2 * 3.14159265), d = oct_unif(&r, 0, 22);
    double x = 30 + d * cos(a), y = 30 + d * sin(a);
    double h = ref_height(hf, x, y);
    if (d < 15 - R - 2) { /* the surface is the heightfield */
      ck_assert(oc_program_eval(pr, oct_v(x, y, h - 0.01)) > 0.5);
      ck_assert(oc_program_eval(pr, oct_v(x, y, h + 0.01)) < 0.5);
      double z = crossing(pr, x, y, h - 0.5, h + 0.5);
      ck_assert(fabs(z - h) < 1e-6);
    } else if (d > 16.5) { /* outside the mask: nothing */
      for (int k = -10; k <= 10; k++)
        ck_assert(oc_program_eval(pr, oct_v(x, y, h + k)) == 0);
    }
  }
  oc_program_free(pr);
  /* a mask with nothing inside, or a falloff eating it all */
  oc_heightfield *tiny = disc_mask(61, 1, 0, 0, 30, 30, 2.5);
  oc_elevation src;
  oc_error e;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {R, 1, 0, 0, tiny, 0};
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "falloff");
  oc_heightfield *none = disc_mask(61, 1, 100, 100, 0, 0, 1);
  tp.mask = none;
  ck_assert(oc_terrain(&src, &tp, &e) == NULL);
  ck_assert(strstr(e.msg, "'mask'") != NULL);
  src.release(src.ud);
  oc_heightfield_release(none);
  oc_heightfield_release(tiny);
  oc_heightfield_release(mask);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- the heightfield source, column spans -------------------------------- */

START_TEST(source_ranges_and_slopes) {
  oc_error e;
  oct_rng r = oct_rng_new(9);
  /* planar grid: ranges are exact (the hull of a linear patch) */
  float z[30 * 20];
  for (int j = 0; j < 20; j++)
    for (int i = 0; i < 30; i++)
      z[j * 30 + i] = (float)(0.25 * i - 0.5 * j + 3);
  oc_heightfield *plane = oc_heightfield_new(30, 20, 2, 0, 0, z, &e);
  oc_heightfield *bumpy = grid(70, 53, 0.5, -4, 1, 8, 4);
  oc_elevation sp, sb;
  int tight = 0;
  ck_assert_int_eq(oc_heightfield_elevation(plane, &sp, &e), OC_OK);
  ck_assert_int_eq(oc_heightfield_elevation(bumpy, &sb, &e), OC_OK);
  for (int n = 0; n < 500; n++) {
    /* inside: the border cells clamp their samples (not planar there) */
    double w = oct_unif(&r, 0, 1.9), h = oct_unif(&r, 0, 1.9);
    double x0 = oct_unif(&r, 4, 54 - w), y0 = oct_unif(&r, 4, 34 - h);
    double lo, hi;
    sp.range(sp.ud, x0, y0, x0 + w, y0 + h, &lo, &hi);
    /* the plane's range over the cells the footprint meets, exactly */
    int i0 = (int)floor(x0 / 2), i1 = (int)floor((x0 + w) / 2) + 1;
    int j0 = (int)floor(y0 / 2), j1 = (int)floor((y0 + h) / 2) + 1;
    double elo = 0.25 * i0 - 0.5 * j1 + 3, ehi = 0.25 * i1 - 0.5 * j0 + 3;
    ck_assert_msg(fabs(lo - elo) < 1e-9 && fabs(hi - ehi) < 1e-9,
                  "planar range %g %g, expected %g %g", lo, hi, elo, ehi);
    ck_assert(fabs(sp.slope(sp.ud, x0, y0, x0 + w, y0 + h) -
                   hypot(0.125, 0.25)) < 1e-6);
    /* bumpy: every value inside, every gradient below the slope bound */
    w = oct_unif(&r, 0, 8), h = oct_unif(&r, 0, 6);
    double bx0 = oct_unif(&r, -6, 36), by0 = oct_unif(&r, -1, 28);
    sb.range(sb.ud, bx0, by0, bx0 + w, by0 + h, &lo, &hi);
    double G = sb.slope(sb.ud, bx0, by0, bx0 + w, by0 + h), smin = INFINITY,
           smax = -INFINITY;
    for (int k = 0; k < 60; k++) {
      double x = bx0 + oct_unif(&r, 0, w), y = by0 + oct_unif(&r, 0, h), g[2];
      double v = sb.height(sb.ud, x, y, g);
      ck_assert(v >= lo && v <= hi);
      ck_assert(hypot(g[0], g[1]) <= G);
      smin = fmin(smin, v);
      smax = fmax(smax, v);
    }
    /* and, for footprints within 4 x 4 cells, within the overshoot bound
    ** of the samples the cells depend on */
    if (w < 1.5 && h < 1.5) {
      const float *zs = oc_heightfield_samples(bumpy);
      int ci0 = (int)floor((bx0 + 4) / 0.5),
          ci1 = (int)floor((bx0 + w + 4) / 0.5);
      int cj0 = (int)floor((by0 - 1) / 0.5),
          cj1 = (int)floor((by0 + h - 1) / 0.5);
      ci0 = ci0 < 0 ? 0 : ci0 > 68 ? 68 : ci0;
      ci1 = ci1 < 0 ? 0 : ci1 > 68 ? 68 : ci1;
      cj0 = cj0 < 0 ? 0 : cj0 > 51 ? 51 : cj0;
      cj1 = cj1 < 0 ? 0 : cj1 > 51 ? 51 : cj1;
      double plo = INFINITY, phi = -INFINITY;
      for (int j = cj0 - 1; j <= cj1 + 2; j++)
        for (int i = ci0 - 1; i <= ci1 + 2; i++) {
          int ii = i < 0    ? 0
                   : i > 69 ? 69
                            : i,
              jj = j < 0    ? 0
                   : j > 52 ? 52
                            : j;
          plo = fmin(plo, zs[jj * 70 + ii]);
          phi = fmax(phi, zs[jj * 70 + ii]);
        }
      double over = OC_HEIGHTFIELD_OVERSHOOT * (phi - plo) + 1e-6;
      ck_assert_msg(lo >= plo - over && hi <= phi + over,
                    "range %g .. %g for samples %g .. %g", lo, hi, plo, phi);
      tight++;
    }
  }
  ck_assert_int_gt(tight, 20);
  sp.release(sp.ud);
  sb.release(sb.ud);
  oc_heightfield_release(plane);
  oc_heightfield_release(bumpy);
}
END_TEST

START_TEST(column_spans_cover_and_tight) {
  oc_heightfield *hf = grid(81, 81, 1, 0, 0, 5, 6);
  const double R = 4, W = 0.75;
  oc_program *pr = oct_compile(terrain_of(hf, R, W, 0, NULL), 0, 0);
  oct_rng r = oct_rng_new(11);
  double zlo = oc_program_bounds(pr).lo.z + R;
  int tight = 0;
  for (int n = 0; n < 300; n++) {
    double x0 = oct_unif(&r, -2, 80), y0 = oct_unif(&r, -2, 80);
    double s = oct_unif(&r, 0.5, 3);
    oc_zspan sp[16];
    int ns = oc_program_column_spans(pr, x0, y0, x0 + s, y0 + s, sp, 16);
    ck_assert_int_ge(ns, 0);
    /* between spans f does not vary over the footprint */
    for (int g = 0; g <= ns; g++) {
      double zl = g ? sp[g - 1].hi : -40, zh = g < ns ? sp[g].lo : 40;
      if (!(zl < zh)) continue;
      double f0 = NAN;
      for (int k = 0; k < 40; k++) {
        oc_vec3 p = oct_v(x0 + oct_unif(&r, 0, s), y0 + oct_unif(&r, 0, s),
                          oct_unif(&r, zl, zh));
        double f = oc_program_eval(pr, p);
        if (k == 0) f0 = f;
        ck_assert_msg(f == f0, "f varies in a gap: %g vs %g", f, f0);
      }
    }
    /* inside the prism the surface's span is the local relief + 2W */
    if (x0 > R && y0 > R && x0 + s < 80 - R && y0 + s < 80 - R) {
      /* the relief on the footprint, and on the cells it meets */
      double smin = INFINITY, smax = -INFINITY, cmin = INFINITY,
             cmax = -INFINITY, cx0 = floor(x0), cy0 = floor(y0);
      double cs = fmax(floor(x0 + s) + 1 - cx0, floor(y0 + s) + 1 - cy0);
      for (int a = 0; a <= 30; a++)
        for (int b = 0; b <= 30; b++) {
          double h = ref_height(hf, x0 + s * a / 30, y0 + s * b / 30);
          smin = fmin(smin, h);
          smax = fmax(smax, h);
          h = ref_height(hf, cx0 + cs * a / 30, cy0 + cs * b / 30);
          cmin = fmin(cmin, h);
          cmax = fmax(cmax, h);
        }
      int k = 0;
      while (k < ns && sp[k].hi < smin)
        k++;
      ck_assert(k < ns && sp[k].lo <= smin - W && sp[k].hi >= smax + W);
      double width = sp[k].hi - sp[k].lo;
      /* unless merged with the floor's span (near the lowest point) */
      if (sp[k].lo > zlo) {
        ck_assert_msg(width <= (cmax - cmin) + 2 * W + 0.25,
                      "span %g wide for a relief of %g (%g on the cells)",
                      width, smax - smin, cmax - cmin);
        tight++;
      }
    }
  }
  ck_assert_int_gt(tight, 50);
  oc_program_free(pr);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- meshes -------------------------------------------------------------- */

static oc_mesh *polygonize(const oc_program *pr, oc_aabb box, double cell,
                           int full, int no_direct, int open) {
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = box;
  pp.cell = cell;
  pp.full_grid = full;
  pp.no_direct = no_direct;
  pp.open = open;
  oc_error e;
  oc_mesh *m = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  return m;
}

static void check_file(const oc_mesh *m, const char *dir, int closed,
                       long euler) {
  oc_error e;
  const char *path = oct_in_dir(dir, "dem.ply");
  ck_assert_int_eq(oc_mesh_write(m, path, &e), OC_OK);
  char why[256], buf[512];
  mr_mesh *mm = mr_read(path, why, sizeof why);
  ck_assert_msg(mm != NULL, "%s", why);
  mr_report rep;
  mr_check(mm, &rep);
  mr_report_str(&rep, buf, sizeof buf);
  ck_assert_msg(rep.duplicate_vertices == 0 && rep.degenerate_triangles == 0 &&
                    rep.nonmanifold_edges == 0 && rep.consistent,
                "%s", buf);
  if (closed) {
    ck_assert_msg(rep.closed && rep.outward, "%s", buf);
    ck_assert_msg(rep.euler == euler, "%s", buf);
  } else {
    ck_assert_msg(rep.boundary_edges > 0, "%s", buf);
  }
  ck_assert_msg(rep.normals_against * 100 < rep.referenced, "%s", buf);
  mr_free(mm);
}

static int same_mesh(const oc_mesh *a, const oc_mesh *b) {
  size_t nv = oc_mesh_vertex_count(a), nt = oc_mesh_triangle_count(a);
  return nv == oc_mesh_vertex_count(b) && nt == oc_mesh_triangle_count(b) &&
         !memcmp(oc_mesh_positions(a), oc_mesh_positions(b),
                 3 * nv * sizeof(float)) &&
         !memcmp(oc_mesh_normals(a), oc_mesh_normals(b),
                 3 * nv * sizeof(float)) &&
         !memcmp(oc_mesh_indices(a), oc_mesh_indices(b),
                 3 * nt * sizeof(uint32_t));
}

typedef struct tri9 {
  float v[9];
} tri9;
static int cmp3(const float *a, const float *b) {
  for (int i = 0; i < 3; i++)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}
static int cmp9(const void *x, const void *y) {
  const float *a = x, *b = y;
  for (int i = 0; i < 9; i++)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}
/* The same triangles, whatever the vertex order. */
static int same_triangles(const oc_mesh *a, const oc_mesh *b) {
  size_t n = oc_mesh_triangle_count(a);
  if (n != oc_mesh_triangle_count(b)) return 0;
  tri9 *t[2];
  const oc_mesh *m[2] = {a, b};
  for (int w = 0; w < 2; w++) {
    const float *P = oc_mesh_positions(m[w]);
    const uint32_t *I = oc_mesh_indices(m[w]);
    t[w] = malloc((n ? n : 1) * sizeof(tri9));
    for (size_t i = 0; i < n; i++) {
      int s = 0;
      for (int k = 1; k < 3; k++)
        if (cmp3(P + 3 * I[3 * i + k], P + 3 * I[3 * i + s]) < 0) s = k;
      for (int k = 0; k < 3; k++)
        memcpy(t[w][i].v + 3 * k, P + 3 * I[3 * i + (s + k) % 3],
               3 * sizeof(float));
    }
    qsort(t[w], n, sizeof(tri9), cmp9);
  }
  int same = !memcmp(t[0], t[1], n * sizeof(tri9));
  free(t[0]);
  free(t[1]);
  return same;
}

/* Meshed with surface bounds (and direct extraction), the file checked
** (closed with that Euler characteristic, or open), and the same
** triangles as on the full grid. */
static void check_bounded(const oc_program *pr, oc_aabb box, double cell,
                          int open, const char *dir, long euler) {
  oc_mesh *m = polygonize(pr, box, cell, 0, 0, open);
  check_file(m, dir, !open, euler);
  oc_mesh *mf = polygonize(pr, box, cell, 1, 0, open);
  ck_assert(same_triangles(m, mf));
  oc_mesh_free(m);
  oc_mesh_free(mf);
}

START_TEST(dem_meshed_closed) {
  oc_heightfield *hf = grid(97, 81, 1, 0, 0, 6, 8);
  const double R = 5;
  oc_program *pr = oct_compile(terrain_of(hf, R, 1, 0, NULL), 0, 0);
  oc_aabb b = oc_program_bounds(pr);
  oc_aabb box = {oct_v(-1, -1, b.lo.z - 1), oct_v(97, 81, b.hi.z + 1)};
  const char *dir = oct_tmpdir("terrain");
  int nt0 = omp_get_max_threads();
  omp_set_num_threads(1);
  oc_mesh *m1 = polygonize(pr, box, 0.7, 0, 0, 0);
  omp_set_num_threads(2);
  oc_mesh *m2 = polygonize(pr, box, 0.7, 0, 0, 0);
  omp_set_num_threads(3);
  oc_mesh *m3 = polygonize(pr, box, 0.7, 0, 0, 0);
  omp_set_num_threads(nt0);
  ck_assert(same_mesh(m1, m2) && same_mesh(m1, m3));
  check_file(m1, dir, 1, 2); /* a slab: a topological sphere */
  /* surface bounds change nothing but the work */
  oc_mesh *mf = polygonize(pr, box, 0.7, 1, 0, 0);
  ck_assert(same_triangles(m1, mf));
  /* root finding everywhere: the same topology, more field calls */
  oc_mesh *mr = polygonize(pr, box, 0.7, 0, 1, 0);
  check_file(mr, dir, 1, 2);
  oc_mesh_stats sd, sr;
  oc_mesh_get_stats(m1, &sd);
  oc_mesh_get_stats(mr, &sr);
  ck_assert_msg(sd.field_calls * 2 < sr.field_calls,
                "direct %zu calls, root finding %zu", sd.field_calls,
                sr.field_calls);
  /* vertices of the top inside the prism lie on the elevation (vertical
  ** edges: z = h; horizontal ones: Newton on h from the Hermite guess; a
  ** few fall back to the field's root finder, good to ~1e-3 of a cell),
  ** with the elevation's normal */
  const float *P = oc_mesh_positions(m1), *N = oc_mesh_normals(m1);
  size_t top = 0;
  double worst = 0;
  for (size_t v = 0; v < oc_mesh_vertex_count(m1); v++) {
    double x = P[3 * v], y = P[3 * v + 1], z = P[3 * v + 2];
    if (x < R + 1 || y < R + 1 || x > 96 - R - 1 || y > 80 - R - 1) continue;
    if (N[3 * v + 2] < 0.2) continue; /* the bottom */
    double h = ref_height(hf, x, y);
    worst = fmax(worst, fabs(z - h));
    if (fabs(z - h) > 1e-3)
      fprintf(stderr, "OUT %g %g %g h %g n %g %g %g\n", x, y, z, h, N[3 * v],
              N[3 * v + 1], N[3 * v + 2]);
    top++;
    /* the normal is the elevation's */
    double gx = (ref_height(hf, x + 1e-4, y) - ref_height(hf, x - 1e-4, y)) /
                2e-4,
           gy = (ref_height(hf, x, y + 1e-4) - ref_height(hf, x, y - 1e-4)) /
                2e-4;
    double l = sqrt(gx * gx + gy * gy + 1);
    double dot = (-gx * N[3 * v] - gy * N[3 * v + 1] + N[3 * v + 2]) / l;
    ck_assert_msg(dot > 0.9999, "normal off by %g rad at %g %g %g",
                  acos(fmin(dot, 1)), x, y, z);
  }
  ck_assert(top > 5000);
  ck_assert_msg(worst < 2e-3, "vertex %g from the elevation", worst);
  /* every vertex, the prism's flat bottom and walls included, is on the
  ** surface: |f - T| / |grad f| a small fraction of a cell, but for a few
  ** root-found ones at the kink where the top meets a wall */
  double T = oc_program_threshold(pr), off = 0;
  size_t noff = 0, nv = oc_mesh_vertex_count(m1);
  for (size_t v = 0; v < nv; v++) {
    oc_vec3 g, p = oct_v(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
    if (p.x <= box.lo.x || p.x >= box.hi.x || p.y <= box.lo.y ||
        p.y >= box.hi.y || p.z <= box.lo.z || p.z >= box.hi.z)
      continue; /* a cap on the box */
    double f = oc_program_gradient(pr, p, &g), l = oct_len(g);
    if (!(l > 1e-3)) continue;
    off = fmax(off, fabs(f - T) / l);
    noff += fabs(f - T) / l > 2e-3;
  }
  ck_assert_msg(noff * 1000 < nv && off < 0.02 * 0.7,
                "%zu vertices off the surface, by up to %g", noff, off);
  /* open: the surface reaches the box and stops there */
  oc_aabb inner = {oct_v(10, 10, b.lo.z - 1), oct_v(80, 70, b.hi.z + 1)};
  check_bounded(pr, inner, 0.7, 1, dir, 0);
  oc_mesh_free(m1);
  oc_mesh_free(m2);
  oc_mesh_free(m3);
  oc_mesh_free(mf);
  oc_mesh_free(mr);
  oc_program_free(pr);
  oc_heightfield_release(hf);
  oct_rm_tree(dir);
}
END_TEST

/* ---- open edges ---------------------------------------------------------- */

/* Open edges: the surface is the grid's over its whole footprint, border
** samples included, f = 0 just off it; bounds hold inside, local bounds
** across a side are infinite (the jump), spans cover; heightfield.from on
** the same grid gives the samples back; the mesh is closed and manifold,
** its walls on the grid's sides, the same for any thread count. */
START_TEST(open_edges) {
  oc_error e;
  oc_heightfield *hf = grid(61, 49, 1.5, 3, -2, 6, 21);
  double x1 = 3 + 60 * 1.5, y1 = -2 + 48 * 1.5;
  for (int inv = 0; inv < 2; inv++) {
    oc_program *pr = oct_compile(
        terrain_e(hf, 4.5, 0.8, inv, 0, NULL, OC_TERRAIN_EDGES_DEFAULT), 0, 0);
    double T = oc_program_threshold(pr);
    oc_aabb b = oc_program_bounds(pr);
    ck_assert(b.lo.x == 3 && b.lo.y == -2 && b.hi.x == x1 && b.hi.y == y1);
    /* on the border samples f = T at z = h; just off them f = 0 */
    for (int k = 0; k < 4; k++) {
      double x = k == 0 ? 3 : k == 1 ? x1 : 3 + 17 * 1.5;
      double y = k == 2 ? -2 : k == 3 ? y1 : -2 + 9 * 1.5;
      double h = ref_height(hf, x, y), sgn = inv ? -1 : 1;
      ck_assert(fabs(oc_program_eval(pr, oct_v(x, y, h)) - T) < 1e-9);
      ck_assert(oc_program_eval(pr, oct_v(x, y, h - sgn * 0.3)) > T);
      double dx = k == 0 ? -1e-9 : k == 1 ? 1e-9 : 0;
      double dy = k == 2 ? -1e-9 : k == 3 ? 1e-9 : 0;
      ck_assert(oc_program_eval(pr, oct_v(x + dx, y + dy, h - sgn * 0.3)) == 0);
    }
    /* inside: gradients, the global bound, local bounds */
    oc_vec3 lo = oct_v(b.lo.x, b.lo.y, b.lo.z - 3);
    oc_vec3 hi = oct_v(b.hi.x, b.hi.y, b.hi.z + 3);
    oct_rng r = oct_rng_new(70 + inv);
    for (int n = 0; n < 2000; n++)
      oct_check_grad(pr,
                     oct_in_box(&r, oct_add(lo, oct_v(1e-4, 1e-4, 0)),
                                oct_sub(hi, oct_v(1e-4, 1e-4, 0))),
                     1e-6, 1e-6);
    /* its pairs may reach a little beyond the box */
    double worst =
        oct_check_lipschitz(pr, oct_add(lo, oct_v(0.5, 0.5, 0)),
                            oct_sub(hi, oct_v(0.5, 0.5, 0)), 20000, &r);
    ck_assert(worst <= 1 && worst > 0.05);
    int across = 0;
    for (int n = 0; n < 400; n++) {
      oc_vec3 c = oct_in_box(&r, oct_sub(lo, oct_v(4, 4, 0)), hi);
      double sz = oct_unif(&r, 0.2, 6);
      oc_aabb box = {c, oct_add(c, oct_v(sz, sz * 0.7, sz * 0.5))};
      double L = oc_program_lipschitz_in(pr, box);
      int cross = (box.lo.x < b.lo.x && box.hi.x >= b.lo.x) ||
                  (box.lo.x <= x1 && box.hi.x > x1) ||
                  (box.lo.y < b.lo.y && box.hi.y >= b.lo.y) ||
                  (box.lo.y <= y1 && box.hi.y > y1);
      /* across a side, finite only where f is 0 on both (over the
      ** elevations, below the floor): the pairs check that */
      if (cross && isinf(L)) {
        across++;
        continue;
      }
      for (int k = 0; k < 40; k++) {
        oc_vec3 p = oct_in_box(&r, box.lo, box.hi),
                q = oct_in_box(&r, box.lo, box.hi);
        double df = fabs(oc_program_eval(pr, p) - oc_program_eval(pr, q));
        ck_assert_msg(df <= L * oct_len(oct_sub(p, q)) * (1 + 1e-9) + 1e-15,
                      "local bound %g broken: %g over %g", L, df,
                      oct_len(oct_sub(p, q)));
      }
    }
    ck_assert_int_gt(across, 20);
    ck_assert_int_gt(oct_check_bounds(pr, oct_sub(lo, oct_v(3, 3, 0)),
                                      oct_add(hi, oct_v(3, 3, 0)), 20000, &r),
                     100);
    /* spans: f does not vary over the footprint between them, also on
    ** footprints across a side */
    for (int n = 0; n < 300; n++) {
      double fx = oct_unif(&r, 0, 97), fy = oct_unif(&r, -5, 72);
      double sz = oct_unif(&r, 0.5, 3);
      oc_zspan sp[16];
      int ns = oc_program_column_spans(pr, fx, fy, fx + sz, fy + sz, sp, 16);
      ck_assert_int_ge(ns, 0);
      for (int g = 0; g <= ns; g++) {
        double zl = g ? sp[g - 1].hi : -40, zh = g < ns ? sp[g].lo : 40;
        if (!(zl < zh)) continue;
        double f0 = NAN;
        for (int k = 0; k < 40; k++) {
          double f = oc_program_eval(pr, oct_v(fx + oct_unif(&r, 0, sz),
                                               fy + oct_unif(&r, 0, sz),
                                               oct_unif(&r, zl, zh)));
          if (k == 0) f0 = f;
          ck_assert_msg(f == f0, "f varies in a gap: %g vs %g", f, f0);
        }
      }
    }
    /* the grid back from the terrain, border samples included */
    if (!inv) {
      oc_heightfield_grid g = {61, 49, 1.5, 3, -2};
      oc_heightfield *back = oc_heightfield_from_program(
          pr, &g, b.lo.z, b.hi.z, 0, (oc_progress){0}, &e);
      ck_assert_msg(back != NULL, "%s", e.msg);
      const float *za = oc_heightfield_samples(hf),
                  *zb = oc_heightfield_samples(back);
      double off = 0;
      for (size_t k = 0; k < 61 * 49; k++)
        off = fmax(off, fabs(za[k] - zb[k]));
      ck_assert_msg(off < 1e-5, "the grid back is %g off", off);
      oc_heightfield_release(back);
    }
    /* meshes: walls on the sides (box = the bounds: caps; a wider box:
    ** root finding across the jump) */
    const char *dir = oct_tmpdir("open");
    oc_aabb wide = {oct_v(b.lo.x - 2, b.lo.y - 2, b.lo.z - 1),
                    oct_v(b.hi.x + 2, b.hi.y + 2, b.hi.z + 1)};
    for (int wb = 0; wb < 2; wb++) {
      oc_aabb box = wb ? wide : b;
      int nt0 = omp_get_max_threads();
      omp_set_num_threads(1);
      oc_mesh *m1 = polygonize(pr, box, 0.7, 0, 0, 0);
      omp_set_num_threads(2);
      oc_mesh *m2 = polygonize(pr, box, 0.7, 0, 0, 0);
      omp_set_num_threads(nt0);
      ck_assert(same_mesh(m1, m2));
      check_file(m1, dir, 1, 2);
      oc_mesh *mf = polygonize(pr, box, 0.7, 1, 0, 0);
      ck_assert(same_triangles(m1, mf));
      /* the walls reach the grid's sides, and the top the elevation
      ** up to the last half cell before them */
      const float *P = oc_mesh_positions(m1);
      double xmin = INFINITY, xmax = -INFINITY, worst = 0;
      size_t top = 0;
      for (size_t v = 0; v < oc_mesh_vertex_count(m1); v++) {
        double x = P[3 * v], y = P[3 * v + 1], z = P[3 * v + 2];
        xmin = fmin(xmin, x);
        xmax = fmax(xmax, x);
        if (x < 3 + 0.4 || x > x1 - 0.4 || y < -2 + 0.4 || y > y1 - 0.4)
          continue;
        double h = ref_height(hf, x, y);
        if (fabs(z - h) < 0.5) {
          worst = fmax(worst, fabs(z - h));
          top++;
        }
      }
      ck_assert_msg(fabs(xmin - 3) < 1e-4 && fabs(xmax - x1) < 1e-4,
                    "walls at x = %g and %g, not 3 and %g", xmin, xmax, x1);
      ck_assert(top > 3000);
      ck_assert_msg(worst < 2e-3, "vertex %g from the elevation", worst);
      oc_mesh_free(m1);
      oc_mesh_free(m2);
      oc_mesh_free(mf);
    }
    oct_rm_tree(dir);
    oc_program_free(pr);
  }
  /* 'open' with a mask is refused; an unknown mode too */
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {4, 1, 0, 0, hf, OC_TERRAIN_OPEN};
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "edges");
  tp.mask = NULL;
  tp.edges = 7;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "edges");
  /* open edges take any falloff (the slab needs 2R < the width) */
  tp.edges = OC_TERRAIN_OPEN;
  tp.falloff = 500;
  oc_node_release(OCT_OK(oc_terrain(&src, &tp, &e)));
  src.release(src.ud);
  oc_heightfield_release(hf);
}
END_TEST

/* A solid thinner than a cell meshes to nothing, and says why. */
START_TEST(thin_terrain_warns) {
  oc_error e;
  float z[16 * 16] = {0};
  oc_heightfield *hf = oc_heightfield_new(16, 16, 1, 0, 0, z, &e);
  for (int pass = 0; pass < 2; pass++) {
    oc_program *pr = oct_compile(
        terrain_e(hf, pass ? 4 : 0.01, 1, 0, 0, NULL, OC_TERRAIN_OPEN), 0, 0);
    char warn[300] = "x";
    oc_polygonize_params pp;
    memset(&pp, 0, sizeof pp);
    pp.box = (oc_aabb){oct_v(-1, -1, -2), oct_v(16, 16, 2)};
    pp.cell = 0.5;
    pp.warning = warn;
    pp.warning_size = sizeof warn;
    oc_mesh *m = oc_polygonize(pr, &pp, &e);
    ck_assert_msg(m != NULL, "%s", e.msg);
    if (pass == 0) {
      ck_assert_int_eq(oc_mesh_triangle_count(m), 0);
      ck_assert_msg(strstr(warn, "falloff") && strstr(warn, "thickness"),
                    "warning: '%s'", warn);
    } else {
      ck_assert(oc_mesh_triangle_count(m) > 0);
      ck_assert_str_eq(warn, "");
    }
    oc_mesh_free(m);
    oc_program_free(pr);
  }
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(sculpted_terrain_seamless) {
  /* direct columns next to root-found ones: carved caves, a rock, an arch
  ** on an implicitized DEM; floating islands from a terrain and an
  ** inverted one */
  oc_error e;
  oc_heightfield *hf = grid(81, 81, 1, 0, 0, 3, 12);
  oc_node *k[5];
  k[0] = terrain_of(hf, 5, 1, 0, NULL);
  double h = ref_height(hf, 30, 30);
  k[1] = OCT_OK(oc_point(oct_v(30, 30, h), 5, -1.5, &e));
  k[2] = OCT_OK(oc_sphere(oct_v(55, 40, ref_height(hf, 55, 40)), 3, 2, 1, &e));
  double ha = ref_height(hf, 40, 60), hb = ref_height(hf, 55, 60);
  oc_vec3 sp[4] = {
      {40, 60, ha - 2}, {40, 60, ha + 12}, {55, 60, hb + 12}, {55, 60, hb - 2}};
  k[3] = OCT_OK(oc_curve(sp, 4, 1, 2.5, 1, &e));
  (void)sp;
  oc_node *scene = OCT_OK(oc_blend(k, 4, &e));
  for (int i = 0; i < 4; i++)
    oc_node_release(k[i]);
  oc_program *pr = oct_compile(scene, 0, 0);
  oc_aabb box = {oct_v(-1, -1, -15), oct_v(81, 81, 20)};
  const char *dir = oct_tmpdir("terrain2");
  oc_mesh *m1 = polygonize(pr, box, 0.6, 0, 0, 0);
  omp_set_num_threads(1);
  oc_mesh *ms = polygonize(pr, box, 0.6, 0, 0, 0);
  omp_set_num_threads(2);
  ck_assert(same_mesh(m1, ms));
  oc_mesh *mf = polygonize(pr, box, 0.6, 1, 0, 0);
  ck_assert(same_triangles(m1, mf));
  check_file(m1, dir, 1, 0); /* the arch makes a handle: genus 1 */
  oc_mesh_free(m1);
  oc_mesh_free(ms);
  oc_mesh_free(mf);
  oc_program_free(pr);
  /* a round island cut by a mask: direct blocks inside the disc, the
  ** mask's walls root-found; the same with or without bounds, closed */
  oc_heightfield *disc = disc_mask(81, 1, 0, 0, 40, 40, 30);
  pr = oct_compile(terrain_of(hf, 3, 1, 0, disc), 0, 0);
  check_bounded(pr, box, 0.6, 0, dir, 2);
  oc_program_free(pr);
  oc_heightfield_release(disc);
  /* floating island: below h, above h2 = -h / 2 - 8 (inverted) */
  oc_heightfield *flip = grid(81, 81, 1, 0, 0, 3, 12);
  float *z = oc_heightfield_samples_mut(flip);
  const float *z0 = oc_heightfield_samples(hf);
  for (int q = 0; q < 81 * 81; q++)
    z[q] = -0.5f * z0[q] - 8;
  oc_node *top = terrain_of(hf, 8, 1, 0, NULL);
  oc_node *bot = terrain_thick(flip, 8, 1, 1, 30, NULL);
  oc_node *kids[2] = {top, bot};
  oc_node *isl = OCT_OK(oc_intersection(kids, 2, &e));
  oc_node_release(top);
  oc_node_release(bot);
  pr = oct_compile(isl, 0, 0);
  double h1 = ref_height(hf, 40, 40), h2 = ref_height(flip, 40, 40);
  ck_assert(oc_program_eval(pr, oct_v(40, 40, h1 - 0.1)) > 0.5);
  ck_assert(oc_program_eval(pr, oct_v(40, 40, h1 + 0.1)) < 0.5);
  ck_assert(oc_program_eval(pr, oct_v(40, 40, h2 + 0.1)) > 0.5);
  ck_assert(oc_program_eval(pr, oct_v(40, 40, h2 - 0.1)) < 0.5);
  check_bounded(pr, box, 0.6, 0, dir, 2);
  oc_program_free(pr);
  oc_heightfield_release(flip);
  oc_heightfield_release(hf);
  oct_rm_tree(dir);
}
END_TEST

/* ---- errors ----------------------------------------------------------------
 */

START_TEST(bad_input) {
  oc_heightfield *hf = grid(20, 30, 1, 0, 0, 2, 1);
  oc_elevation src;
  oc_error e;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {2, 1, 0, 0, NULL, OC_TERRAIN_SLAB};
  tp.thickness = -1;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "thickness");
  tp.thickness = NAN;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "thickness");
  tp.thickness = 0;
  tp.falloff = -1;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "falloff");
  tp.falloff = NAN;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "falloff");
  tp.falloff = 9.6; /* the domain is 19 m wide */
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "falloff");
  tp.falloff = 2;
  tp.transition = -0.5;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "transition");
  tp.transition = INFINITY;
  OCT_EINVAL(oc_terrain(&src, &tp, &e), e, "transition");
  ck_assert(oc_terrain(NULL, &tp, &e) == NULL && e.code == OC_EINVAL);
  ck_assert(oc_terrain(&src, NULL, &e) == NULL && e.code == OC_EINVAL);
  oc_elevation bad = src;
  bad.x1 = bad.x0;
  ck_assert(oc_terrain(&bad, &tp, &e) == NULL && e.code == OC_EINVAL);
  bad = src;
  bad.range = NULL;
  ck_assert(oc_terrain(&bad, &tp, &e) == NULL && e.code == OC_EINVAL);
  /* NaN in, NaN out */
  tp.transition = 1;
  oc_program *pr = oct_compile(OCT_OK(oc_terrain(&src, &tp, &e)), 0, 0);
  ck_assert(isnan(oc_program_eval(pr, oct_v(NAN, 3, 1))));
  oc_program_free(pr);
  src.release(src.ud);
  /* the node keeps the grid alive after every other reference is gone */
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_node *n = OCT_OK(oc_terrain(&src, &tp, &e));
  src.release(src.ud);
  double h = ref_height(hf, 9, 9);
  oc_heightfield_release(hf);
  pr = oct_compile(n, 0, 0);
  ck_assert(fabs(crossing(pr, 9, 9, h - 1, h + 1) - h) < 1e-9);
  oc_program_free(pr);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("terrain");
  TCase *t = tcase_create("field");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, sigma_profile);
  tcase_add_test(t, embeds_heightfield);
  tcase_add_test(t, gradient_lipschitz_support);
  tcase_add_test(t, mask_shapes_domain);
  tcase_add_test(t, mask_range_pyramid);
  tcase_add_test(t, source_ranges_and_slopes);
  tcase_add_test(t, column_spans_cover_and_tight);
  tcase_add_test(t, bad_input);
  suite_add_tcase(s, t);
  t = tcase_create("mesh");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, dem_meshed_closed);
  tcase_add_test(t, sculpted_terrain_seamless);
  tcase_add_test(t, open_edges);
  tcase_add_test(t, thin_terrain_warns);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
