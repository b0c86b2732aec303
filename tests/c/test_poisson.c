/*
** test_poisson.c — maximal Poisson disk and sphere sampling
** (oc_poisson2d, oc_poisson3d): every pair at least the radius apart;
** maximality (no probe point of the box, random or on a fine lattice
** including the faces, farther than the radius from every sample), with
** a check that the probe does catch a hole; density of maximal sets
** against random sequential adsorption's jamming limit; determinism by
** seed and across thread counts; thinning by density; errors and
** cancellation.
**
** The checks use their own bucket grid of the samples, not the sampler's.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "ocheck.h"
#include "outcrop.h"

/* Jamming limits of random sequential adsorption of disks and spheres
** (coverage 0.5470735 and 0.3841 by disks of diameter r): samples per r^2
** and per r^3 of a maximal set far from the box's faces. */
#define PI 3.14159265358979323846
#define RSA_2D (0.5470735 / (PI / 4))
#define RSA_3D (0.3841 / (PI / 6))

/* ---- running the samplers ----------------------------------------------- */

static oc_poisson_params params(double x0, double y0, double z0, double x1,
                                double y1, double z1, double r, uint64_t seed) {
  oc_poisson_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{x0, y0, z0}, {x1, y1, z1}};
  pp.radius = r;
  pp.seed = seed;
  return pp;
}

static oc_samples *sample_ok(int d, const oc_poisson_params *pp) {
  oc_error e = {0};
  oc_samples *s = d == 2 ? oc_poisson2d(pp, &e) : oc_poisson3d(pp, &e);
  ck_assert_msg(s != NULL, "oc_poisson%dd: %s", d, e.msg);
  ck_assert_int_eq(oc_samples_dim(s), d);
  return s;
}

/* ---- a bucket grid of the samples (cells of side r) -------------------- */

typedef struct buckets {
  int d, n[3];
  double lo[3], r;
  size_t *start, *idx; /* counting sort: samples of cell c are
                       ** idx[start[c] .. start[c + 1]) */
  const double *p;
  size_t np;
} buckets;

static int bucket_of(const buckets *b, const double *x, int c[3]) {
  for (int a = 0; a < 3; a++) {
    c[a] = a < b->d ? (int)floor((x[a] - b->lo[a]) / b->r) : 0;
    if (c[a] < 0) c[a] = 0;
    if (c[a] >= b->n[a]) c[a] = b->n[a] - 1;
  }
  return (c[2] * b->n[1] + c[1]) * b->n[0] + c[0];
}

static buckets make_buckets_of(int d, const double *p, size_t np,
                               const oc_poisson_params *pp) {
  buckets b;
  memset(&b, 0, sizeof b);
  b.d = d;
  b.r = pp->radius;
  b.p = p;
  b.np = np;
  double lo[3] = {pp->box.lo.x, pp->box.lo.y, pp->box.lo.z};
  double hi[3] = {pp->box.hi.x, pp->box.hi.y, pp->box.hi.z};
  size_t nc = 1;
  for (int a = 0; a < 3; a++) {
    b.lo[a] = lo[a];
    b.n[a] = a < b.d ? (int)ceil((hi[a] - lo[a]) / b.r) + 1 : 1;
    nc *= (size_t)b.n[a];
  }
  b.start = calloc(nc + 1, sizeof *b.start);
  b.idx = malloc((b.np ? b.np : 1) * sizeof *b.idx);
  int c[3];
  for (size_t i = 0; i < b.np; i++)
    b.start[bucket_of(&b, b.p + (size_t)b.d * i, c) + 1]++;
  for (size_t k = 0; k < nc; k++)
    b.start[k + 1] += b.start[k];
  size_t *fill = malloc((nc + 1) * sizeof *fill);
  memcpy(fill, b.start, (nc + 1) * sizeof *fill);
  for (size_t i = 0; i < b.np; i++)
    b.idx[fill[bucket_of(&b, b.p + (size_t)b.d * i, c)]++] = i;
  free(fill);
  return b;
}

static buckets make_buckets(const oc_samples *s, const oc_poisson_params *pp) {
  return make_buckets_of(oc_samples_dim(s), oc_samples_data(s),
                         oc_samples_count(s), pp);
}

static void free_buckets(buckets *b) {
  free(b->start);
  free(b->idx);
}

static double dist(int d, const double *a, const double *b) {
  double s = 0;
  for (int k = 0; k < d; k++)
    s += (a[k] - b[k]) * (a[k] - b[k]);
  return sqrt(s);
}

/* Distance from x to the nearest sample other than `skip` (only samples
** within one bucket count; farther ones give r at least). */
static double nearest(const buckets *b, const double *x, size_t skip) {
  int c[3], d = b->d;
  double best = INFINITY;
  bucket_of(b, x, c);
  for (int dz = (d == 3 ? -1 : 0); dz <= (d == 3 ? 1 : 0); dz++)
    for (int dy = -1; dy <= 1; dy++)
      for (int dx = -1; dx <= 1; dx++) {
        int q[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= b->n[0] ||
            q[1] >= b->n[1] || q[2] >= b->n[2])
          continue;
        int k = (q[2] * b->n[1] + q[1]) * b->n[0] + q[0];
        for (size_t t = b->start[k]; t < b->start[k + 1]; t++) {
          if (b->idx[t] == skip) continue;
          double e = dist(d, x, b->p + (size_t)d * b->idx[t]);
          if (e < best) best = e;
        }
      }
  return best;
}

/* Asserts that every sample lies in the box and no two are closer than
** r; returns the smallest distance seen. */
static double check_separation(const oc_samples *s,
                               const oc_poisson_params *pp) {
  buckets b = make_buckets(s, pp);
  int d = b.d;
  double lo[3] = {pp->box.lo.x, pp->box.lo.y, pp->box.lo.z};
  double hi[3] = {pp->box.hi.x, pp->box.hi.y, pp->box.hi.z};
  double worst = INFINITY;
  for (size_t i = 0; i < b.np; i++) {
    const double *x = b.p + (size_t)d * i;
    for (int a = 0; a < d; a++)
      ck_assert_msg(x[a] >= lo[a] && x[a] <= hi[a],
                    "sample %zu outside the box on axis %d: %.17g", i, a, x[a]);
    double e = nearest(&b, x, i);
    if (e < worst) worst = e;
  }
  ck_assert_msg(worst >= pp->radius * (1 - 1e-12),
                "two samples %.17g apart, radius %.17g", worst, pp->radius);
  free_buckets(&b);
  return worst;
}

/* Largest distance from a probe point of the box to its nearest sample
** (probes: `nrand` uniform points plus a lattice of `per_axis` points per
** axis spanning the closed box), counting samples except `skip`; *where
** gets the worst probe. */
static double probe_gap(const buckets *b, const oc_poisson_params *pp,
                        int nrand, int per_axis, size_t skip, double *where) {
  int d = b->d;
  double lo[3] = {pp->box.lo.x, pp->box.lo.y, pp->box.lo.z};
  double hi[3] = {pp->box.hi.x, pp->box.hi.y, pp->box.hi.z};
  double worst = 0;
  oct_rng rng = oct_rng_new(99);
  for (int i = 0; i < nrand; i++) {
    double x[3];
    for (int a = 0; a < d; a++)
      x[a] = oct_unif(&rng, lo[a], hi[a]);
    double e = nearest(b, x, skip);
    if (e > worst) worst = e, memcpy(where, x, sizeof x);
  }
  long total = 1;
  for (int a = 0; a < d; a++)
    total *= per_axis;
  for (long q = 0; q < total; q++) {
    double x[3];
    long u = q;
    for (int a = 0; a < d; a++) {
      x[a] = lo[a] + (hi[a] - lo[a]) * (double)(u % per_axis) / (per_axis - 1);
      u /= per_axis;
    }
    double e = nearest(b, x, skip);
    if (e > worst) worst = e, memcpy(where, x, sizeof x);
  }
  return worst;
}

/* Asserts maximality on the probes; then removes one sample and asserts
** the same probes find the hole it leaves, so the check can fail. */
static void check_maximal(const oc_samples *s, const oc_poisson_params *pp,
                          int nrand, int per_axis) {
  buckets b = make_buckets(s, pp);
  double where[3] = {0, 0, 0}, r = pp->radius;
  double gap = probe_gap(&b, pp, nrand, per_axis, (size_t)-1, where);
  printf("poisson %dd: %zu samples, largest probe gap %.9f r\n", b.d, b.np,
         gap / r);
  ck_assert_msg(gap <= r * (1 + 1e-9),
                "point (%g, %g, %g) is %.12g from every sample (radius %g)",
                where[0], where[1], where[2], gap, r);
  /* a gap left by removing a sample near the middle */
  size_t mid = b.np / 2;
  double hole = probe_gap(&b, pp, nrand, per_axis, mid, where);
  ck_assert_msg(hole > r * 1.01, "the probes missed a hole (gap %g r)",
                hole / r);
  free_buckets(&b);
}

/* Exact maximality in 2D, independent of the sampler's method: a hole in
** the union of the disks inside the box is bounded by arcs, so one of its
** corners is a point where two circles cross, or a circle crosses the
** box's edge, or a corner of the box, that no other disk holds. Returns
** the number of such points. */
static int holes_2d(const double *p, size_t np, const oc_poisson_params *pp) {
  buckets b = make_buckets_of(2, p, np, pp);
  double r = pp->radius, tol = r * 1e-9;
  double lo[2] = {pp->box.lo.x, pp->box.lo.y};
  double hi[2] = {pp->box.hi.x, pp->box.hi.y};
  int holes = 0;
  /* points to test: (x, owner i, owner j) */
  for (size_t i = 0; i < b.np; i++) {
    const double *a = b.p + 2 * i;
    double cand[64][2];
    int nc = 0;
    /* circle i with the box's edges */
    for (int ax = 0; ax < 2; ax++)
      for (int side = 0; side < 2; side++) {
        double c = side ? hi[ax] : lo[ax], u = c - a[ax];
        if (fabs(u) >= r) continue;
        double w = sqrt(r * r - u * u);
        for (int sg = -1; sg <= 1; sg += 2) {
          cand[nc][ax] = c;
          cand[nc][1 - ax] = a[1 - ax] + sg * w;
          nc++;
        }
      }
    /* circle i with circle j, j > i */
    int cb[3];
    bucket_of(&b, a, cb);
    for (int dy = -2; dy <= 2; dy++)
      for (int dx = -2; dx <= 2; dx++) {
        int q0 = cb[0] + dx, q1 = cb[1] + dy;
        if (q0 < 0 || q1 < 0 || q0 >= b.n[0] || q1 >= b.n[1]) continue;
        int k = q1 * b.n[0] + q0;
        for (size_t t = b.start[k]; t < b.start[k + 1]; t++) {
          size_t j = b.idx[t];
          if (j <= i) continue;
          const double *c = b.p + 2 * j;
          double dx2 = c[0] - a[0], dy2 = c[1] - a[1];
          double L = sqrt(dx2 * dx2 + dy2 * dy2);
          if (L >= 2 * r || nc + 2 > 64) continue;
          double hgt = sqrt(r * r - 0.25 * L * L);
          double mx = a[0] + 0.5 * dx2, my = a[1] + 0.5 * dy2;
          for (int sg = -1; sg <= 1; sg += 2) {
            cand[nc][0] = mx - sg * hgt * dy2 / L;
            cand[nc][1] = my + sg * hgt * dx2 / L;
            nc++;
          }
        }
      }
    for (int q = 0; q < nc; q++) {
      double *x = cand[q];
      if (x[0] < lo[0] - tol || x[0] > hi[0] + tol || x[1] < lo[1] - tol ||
          x[1] > hi[1] + tol)
        continue;
      /* held strictly by a disk other than its own two? Its owners are at
      ** distance r, so "nearest < r - tol" finds another one. */
      if (nearest(&b, x, (size_t)-1) < r - tol) continue;
      /* on the boundary of the union: it borders a hole unless the hole
      ** side lies outside the box; probe just around it */
      for (int a8 = 0; a8 < 8; a8++) {
        double ang = a8 * PI / 4, e = 1e-6 * r;
        double y[2] = {x[0] + e * cos(ang), x[1] + e * sin(ang)};
        if (y[0] < lo[0] || y[0] > hi[0] || y[1] < lo[1] || y[1] > hi[1])
          continue;
        if (nearest(&b, y, (size_t)-1) > r * (1 + 1e-9)) {
          holes++;
          break;
        }
      }
    }
  }
  double corner[4][2] = {
      {lo[0], lo[1]}, {hi[0], lo[1]}, {lo[0], hi[1]}, {hi[0], hi[1]}};
  for (int q = 0; q < 4; q++)
    holes += nearest(&b, corner[q], (size_t)-1) > r * (1 + 1e-9);
  free_buckets(&b);
  return holes;
}

START_TEST(exact_maximality_many_seeds) {
  int total2 = 0;
  for (uint64_t seed = 0; seed < 40; seed++) {
    oc_poisson_params pp = params(0.3 * seed, -1, 0, 0.3 * seed + 23.5,
                                  16 + 0.1 * seed, 0, 1, seed);
    oc_samples *s = sample_ok(2, &pp);
    check_separation(s, &pp);
    size_t n = oc_samples_count(s);
    int h = holes_2d(oc_samples_data(s), n, &pp);
    ck_assert_msg(h == 0, "seed %d: %d hole corners", (int)seed, h);
    total2 += (int)n;
    /* the check finds the hole left by removing one sample */
    double *cut = malloc(2 * n * sizeof *cut);
    size_t drop = (seed * 7919) % n;
    memcpy(cut, oc_samples_data(s), 2 * drop * sizeof *cut);
    memcpy(cut + 2 * drop, oc_samples_data(s) + 2 * (drop + 1),
           2 * (n - drop - 1) * sizeof *cut);
    ck_assert_int_gt(holes_2d(cut, n - 1, &pp), 0);
    free(cut);
    oc_samples_free(s);
  }
  for (uint64_t seed = 0; seed < 12; seed++) {
    oc_poisson_params pp = params(0, 0, 0, 5 + 0.25 * seed, 4.5, 4, 1, seed);
    oc_samples *s = sample_ok(3, &pp);
    check_separation(s, &pp);
    buckets b = make_buckets(s, &pp);
    double where[3];
    double gap = probe_gap(&b, &pp, 200000, 40, (size_t)-1, where);
    ck_assert_msg(gap <= 1 + 1e-9, "seed %d: gap %.12g at (%g, %g, %g)",
                  (int)seed, gap, where[0], where[1], where[2]);
    free_buckets(&b);
    oc_samples_free(s);
  }
  printf("poisson: 40 2D sets (%d samples) without a hole\n", total2);
}
END_TEST

/* ---- separation and maximality --------------------------------------- */

START_TEST(separation_and_maximality_2d) {
  oc_poisson_params pp = params(-3.5, 2, 0, 41.25, 30.75, 0, 1.3, 7);
  oc_samples *s = sample_ok(2, &pp);
  double m = check_separation(s, &pp);
  printf("poisson 2d: smallest distance %.12f r\n", m / pp.radius);
  check_maximal(s, &pp, 400000, 1200);
  oc_samples_free(s);
}
END_TEST

START_TEST(separation_and_maximality_3d) {
  oc_poisson_params pp = params(-2, 1, 5, 9.5, 12, 13.25, 1.1, 11);
  oc_samples *s = sample_ok(3, &pp);
  double m = check_separation(s, &pp);
  printf("poisson 3d: smallest distance %.12f r\n", m / pp.radius);
  check_maximal(s, &pp, 400000, 110);
  oc_samples_free(s);
}
END_TEST

/* Boxes thinner than the radius, and one much smaller than it. */
START_TEST(thin_and_tiny_boxes) {
  oc_poisson_params pp = params(0, 0, 0, 50, 0.2, 0, 1, 3);
  oc_samples *s = sample_ok(2, &pp);
  check_separation(s, &pp);
  check_maximal(s, &pp, 20000, 2000);
  /* a strip of width w << r: samples along it at most 2 sqrt(r^2 - w^2)
  ** apart, so at least 50 / 2 of them */
  ck_assert_uint_ge(oc_samples_count(s), 25);
  ck_assert_uint_le(oc_samples_count(s), 51);
  oc_samples_free(s);

  pp = params(0, 0, 0, 0.1, 0.1, 0.1, 5, 3);
  s = sample_ok(3, &pp);
  ck_assert_uint_eq(oc_samples_count(s), 1);
  oc_samples_free(s);

  pp = params(0, 0, 0, 30, 0.5, 0.5, 1, 4);
  s = sample_ok(3, &pp);
  check_separation(s, &pp);
  check_maximal(s, &pp, 20000, 60);
  oc_samples_free(s);
}
END_TEST

/* ---- density of maximal sets ------------------------------------------ */

/* Samples per r^d in the box shrunk by `margin` radii on every side (far
** from the faces, where a maximal set packs denser). */
static double inner_density(const oc_samples *s, const oc_poisson_params *pp,
                            double margin) {
  int d = oc_samples_dim(s);
  double lo[3] = {pp->box.lo.x, pp->box.lo.y, pp->box.lo.z};
  double hi[3] = {pp->box.hi.x, pp->box.hi.y, pp->box.hi.z};
  double r = pp->radius, vol = 1;
  size_t n = 0;
  for (int a = 0; a < d; a++)
    vol *= (hi[a] - lo[a] - 2 * margin * r) / r;
  for (size_t i = 0; i < oc_samples_count(s); i++) {
    const double *x = oc_samples_data(s) + (size_t)d * i;
    int in = 1;
    for (int a = 0; a < d; a++)
      in &= x[a] >= lo[a] + margin * r && x[a] < hi[a] - margin * r;
    n += in;
  }
  return (double)n / vol;
}

START_TEST(density_of_maximal_sets) {
  oc_poisson_params pp = params(0, 0, 0, 300, 300, 0, 1, 5);
  oc_samples *s = sample_ok(2, &pp);
  double rho = inner_density(s, &pp, 3);
  printf("poisson 2d: %.4f samples per r^2 inside (RSA jamming %.4f), "
         "%.4f of area / (pi r^2 / 4) over the whole box\n",
         rho, RSA_2D, oc_samples_count(s) / (300.0 * 300 / (PI / 4)));
  ck_assert_double_le(fabs(rho / RSA_2D - 1), 0.015);
  oc_samples_free(s);

  pp = params(0, 0, 0, 36, 36, 36, 1, 5);
  s = sample_ok(3, &pp);
  rho = inner_density(s, &pp, 3);
  printf("poisson 3d: %.4f samples per r^3 inside (RSA jamming %.4f)\n", rho,
         RSA_3D);
  ck_assert_double_le(fabs(rho / RSA_3D - 1), 0.02);
  oc_samples_free(s);
}
END_TEST

/* ---- determinism --------------------------------------------------------- */

static int same(const oc_samples *a, const oc_samples *b) {
  return oc_samples_count(a) == oc_samples_count(b) &&
         memcmp(oc_samples_data(a), oc_samples_data(b),
                oc_samples_count(a) * (size_t)oc_samples_dim(a) *
                    sizeof(double)) == 0;
}

START_TEST(deterministic_by_seed_and_threads) {
  for (int d = 2; d <= 3; d++) {
    oc_poisson_params pp = d == 2 ? params(0, 0, 0, 120, 90, 0, 1, 42)
                                  : params(0, 0, 0, 14, 12, 10, 1, 42);
    int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    oc_samples *one = sample_ok(d, &pp);
    omp_set_num_threads(2);
    oc_samples *two = sample_ok(d, &pp);
    omp_set_num_threads(3);
    oc_samples *three = sample_ok(d, &pp);
    omp_set_num_threads(saved);
    oc_samples *again = sample_ok(d, &pp);
    ck_assert_msg(same(one, two) && same(one, three) && same(one, again),
                  "%dd: results differ across runs or thread counts", d);
    pp.seed = 43;
    oc_samples *other = sample_ok(d, &pp);
    ck_assert_msg(!same(one, other), "%dd: seeds 42 and 43 agree", d);
    /* both maximal: counts close */
    double ratio = (double)oc_samples_count(other) / oc_samples_count(one);
    ck_assert_double_le(fabs(ratio - 1), 0.05);
    oc_samples_free(one);
    oc_samples_free(two);
    oc_samples_free(three);
    oc_samples_free(again);
    oc_samples_free(other);
  }
}
END_TEST

/* ---- thinning ------------------------------------------------------------ */

typedef struct dens {
  double split, left, right; /* probability left / right of x = split */
  size_t calls;
  double *seen; /* positions of the calls, in order (or NULL) */
} dens;

static double dens_fn(void *ud, double x, double y) {
  dens *D = ud;
  if (D->seen) {
    D->seen[2 * D->calls] = x;
    D->seen[2 * D->calls + 1] = y;
  }
  D->calls++;
  return x < D->split ? D->left : D->right;
}

static size_t count_left(const oc_samples *s, double split) {
  size_t n = 0;
  for (size_t i = 0; i < oc_samples_count(s); i++)
    n += oc_samples_data(s)[2 * i] < split;
  return n;
}

/* Is every point of a among those of b (both in the same cell order)? */
static int subset(const oc_samples *a, const oc_samples *b) {
  size_t j = 0;
  for (size_t i = 0; i < oc_samples_count(a); i++) {
    const double *p = oc_samples_data(a) + 2 * i;
    while (j < oc_samples_count(b) &&
           memcmp(oc_samples_data(b) + 2 * j, p, 2 * sizeof *p) != 0)
      j++;
    if (j == oc_samples_count(b)) return 0;
  }
  return 1;
}

START_TEST(thinning_by_density) {
  oc_poisson_params pp = params(0, 0, 0, 200, 100, 0, 1, 9);
  oc_samples *full = sample_ok(2, &pp);
  size_t n = oc_samples_count(full);

  /* density 1 everywhere: the full set, one call per sample, in order */
  dens D = {100, 1, 1, 0, malloc(2 * n * sizeof(double))};
  pp.density = dens_fn;
  pp.density_ud = &D;
  oc_samples *s = sample_ok(2, &pp);
  ck_assert(same(s, full));
  ck_assert_uint_eq(D.calls, n);
  ck_assert(memcmp(D.seen, oc_samples_data(full), 2 * n * sizeof(double)) == 0);
  oc_samples_free(s);
  free(D.seen);

  /* density 0: nothing */
  D = (dens){100, 0, 0, 0, NULL};
  s = sample_ok(2, &pp);
  ck_assert_uint_eq(oc_samples_count(s), 0);
  oc_samples_free(s);

  /* 1 on the left half, 0.5 on the right: the left half untouched, the
  ** right one binomial(n_right, 1/2) */
  D = (dens){100, 1, 0.5, 0, NULL};
  s = sample_ok(2, &pp);
  size_t nl = count_left(full, 100), nr = n - nl;
  size_t sl = count_left(s, 100), sr = oc_samples_count(s) - sl;
  printf("poisson thinning: right half %zu of %zu kept (p = 0.5)\n", sr, nr);
  ck_assert_uint_eq(sl, nl);
  ck_assert_double_le(fabs((double)sr - 0.5 * nr), 4 * sqrt(0.25 * nr));
  ck_assert(subset(s, full));
  check_separation(s, &pp);

  /* a higher density keeps a superset */
  D = (dens){100, 0.3, 0.3, 0, NULL};
  oc_samples *low = sample_ok(2, &pp);
  D = (dens){100, 0.6, 0.6, 0, NULL};
  oc_samples *high = sample_ok(2, &pp);
  ck_assert(subset(low, high));
  ck_assert_uint_lt(oc_samples_count(low), oc_samples_count(high));
  ck_assert_double_le(fabs((double)oc_samples_count(low) - 0.3 * n),
                      4 * sqrt(0.21 * n));
  oc_samples_free(low);
  oc_samples_free(high);
  oc_samples_free(s);
  oc_samples_free(full);
}
END_TEST

/* ---- errors and cancellation ----------------------------------------------
 */

static double bad_density(void *ud, double x, double y) {
  (void)x, (void)y;
  return *(double *)ud;
}

static void expect_error(int d, const oc_poisson_params *pp, oc_status code,
                         const char *needle) {
  oc_error e = {0};
  oc_samples *s = d == 2 ? oc_poisson2d(pp, &e) : oc_poisson3d(pp, &e);
  ck_assert_ptr_null(s);
  ck_assert_int_eq(e.code, code);
  ck_assert_msg(strstr(e.msg, needle) != NULL, "'%s' not in \"%s\"", needle,
                e.msg);
}

START_TEST(errors) {
  oc_poisson_params pp = params(0, 0, 0, 10, 10, 10, 1, 1);
  oc_poisson_params q = pp;
  q.radius = NAN;
  expect_error(2, &q, OC_EINVAL, "'radius'");
  q.radius = -1;
  expect_error(3, &q, OC_EINVAL, "'radius'");
  q.radius = 0;
  expect_error(2, &q, OC_EINVAL, "'radius'");
  q.radius = INFINITY;
  expect_error(2, &q, OC_EINVAL, "'radius'");
  q = pp;
  q.box.hi.x = INFINITY;
  expect_error(2, &q, OC_EINVAL, "'box'");
  q = pp;
  q.box.hi.y = 0;
  expect_error(2, &q, OC_EINVAL, "'box'");
  q = pp;
  q.box.lo.z = NAN;
  expect_error(3, &q, OC_EINVAL, "'box'");
  oc_samples *s = sample_ok(2, &q); /* 2D ignores z */
  oc_samples_free(s);
  q = pp;
  q.box.lo.x = -1e308, q.box.hi.x = 1e308; /* width overflows */
  expect_error(2, &q, OC_EINVAL, "'box'");
  /* billions of samples: refused before allocating */
  q = pp;
  q.radius = 1e-4;
  expect_error(2, &q, OC_ENOMEM, "50 million");
  q.radius = 0.01;
  expect_error(3, &q, OC_ENOMEM, "'radius'");
  q = pp;
  q.box = (oc_aabb){{1e6, 0, 0}, {1e6 + 1, 1, 1}};
  q.radius = 1e-2;
  oc_samples_free(sample_ok(2, &q));
  q.radius = 1e-4; /* below 1e-9 of the coordinates */
  expect_error(2, &q, OC_EINVAL, "'radius'");
  /* density */
  double v = 1.5;
  q = pp;
  q.density = bad_density;
  q.density_ud = &v;
  expect_error(2, &q, OC_EINVAL, "'density'");
  v = NAN;
  expect_error(2, &q, OC_EINVAL, "'density'");
  v = -0.25;
  expect_error(2, &q, OC_EINVAL, "'density'");
  v = 1;
  expect_error(3, &q, OC_EINVAL, "'density'");
  oc_error e;
  ck_assert_ptr_null(oc_poisson2d(NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
}
END_TEST

typedef struct prog {
  int calls, stop_after;
  double last;
  int decreasing;
} prog;

static int on_progress(void *ud, double f) {
  prog *p = ud;
  if (f < p->last) p->decreasing = 1;
  p->last = f;
  return ++p->calls >= p->stop_after;
}

START_TEST(progress_and_cancel) {
  oc_poisson_params pp = params(0, 0, 0, 300, 300, 0, 1, 1);
  prog p = {0, 1 << 30, 0, 0};
  pp.progress = (oc_progress){on_progress, &p};
  oc_samples *s = sample_ok(2, &pp);
  ck_assert_int_gt(p.calls, 10);
  ck_assert(!p.decreasing);
  ck_assert_double_eq(p.last, 1.0);
  oc_samples_free(s);

  p = (prog){0, 5, 0, 0};
  expect_error(2, &pp, OC_ECANCEL, "cancelled");
  ck_assert_int_eq(p.calls, 5);
}
END_TEST

/* ---- periodic mode ------------------------------------------------------ */

/* Periodic distance in a torus of side len (brute force: small sets). */
static double pdist2(int d, const double *a, const double *b, double len) {
  double s2 = 0;
  for (int k = 0; k < d; k++) {
    double t = fabs(a[k] - b[k]);
    t = fmin(t, len - t);
    s2 += t * t;
  }
  return s2;
}

START_TEST(periodic_torus) {
  for (int d = 2; d <= 3; d++) {
    double len = d == 2 ? 9 : 7.5, r = 0.9;
    oc_poisson_params pp = params(-1, 2, 3, -1 + len, 2 + len, 3 + len, r, 5);
    pp.periodic = 1;
    oc_samples *s = sample_ok(d, &pp);
    size_t n = oc_samples_count(s);
    const double *x = oc_samples_data(s);
    double lo[3] = {-1, 2, 3}, m2 = INFINITY;
    for (size_t i = 0; i < n; i++) {
      for (int k = 0; k < d; k++) {
        ck_assert_double_ge(x[d * i + k], lo[k]);
        ck_assert_double_lt(x[d * i + k], lo[k] + len);
      }
      for (size_t j = 0; j < i; j++)
        m2 = fmin(m2, pdist2(d, x + d * i, x + d * j, len));
    }
    ck_assert_double_ge(sqrt(m2), r);
    /* maximal on the torus: random probes, faces included, are within r
    ** of a sample across the wrap */
    oc_rng u = oc_rng_stream(9, (uint64_t)d);
    for (int t = 0; t < 20000; t++) {
      double p[3], b2 = INFINITY;
      for (int k = 0; k < d; k++)
        p[k] = lo[k] + len * oc_rng_uniform(&u);
      if (t < 200) p[t % d] = lo[t % d]; /* on a face */
      for (size_t i = 0; i < n; i++)
        b2 = fmin(b2, pdist2(d, p, x + d * i, len));
      ck_assert_msg(sqrt(b2) <= r * (1 + 1e-9), "%dd probe %d: hole %g", d, t,
                    sqrt(b2));
    }
    /* the same bytes for any thread count */
    int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    oc_samples *one = sample_ok(d, &pp);
    omp_set_num_threads(saved);
    ck_assert(same(one, s));
    /* as dense as a maximal set: no face effect */
    double per = (double)n / pow(len / r, d);
    printf("poisson %dd periodic: %zu samples, %.3f per r^%d\n", d, n, per, d);
    ck_assert_double_ge(per, 0.9 * (d == 2 ? RSA_2D : RSA_3D));
    oc_samples_free(one);
    oc_samples_free(s);
  }
}
END_TEST

START_TEST(periodic_errors) {
  oc_poisson_params pp = params(0, 0, 0, 10, 10, 9, 1, 1);
  pp.periodic = 1;
  expect_error(3, &pp, OC_EINVAL, "must be a cube");
  pp = params(0, 0, 0, 3, 3, 3, 1.6, 1);
  pp.periodic = 1;
  expect_error(3, &pp, OC_EINVAL, "less than half the side");
}
END_TEST

int main(void) {
  Suite *s = suite_create("poisson");
  TCase *tc = tcase_create("poisson");
  tcase_set_timeout(tc, 300);
  tcase_add_test(tc, separation_and_maximality_2d);
  tcase_add_test(tc, separation_and_maximality_3d);
  tcase_add_test(tc, thin_and_tiny_boxes);
  tcase_add_test(tc, exact_maximality_many_seeds);
  tcase_add_test(tc, density_of_maximal_sets);
  tcase_add_test(tc, deterministic_by_seed_and_threads);
  tcase_add_test(tc, thinning_by_density);
  tcase_add_test(tc, errors);
  tcase_add_test(tc, progress_and_cancel);
  tcase_add_test(tc, periodic_torus);
  tcase_add_test(tc, periodic_errors);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
