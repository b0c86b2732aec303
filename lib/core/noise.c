/*
** noise.c — 3D simplex noise and turbulence with analytic gradients.
**
** Construction. Skew p by F = 1/3 to find its cell and simplex, unskew by
** G = 1/6 to get the offsets d = p - v to the four corners v. Each corner
** adds w(|d|^2) (g_v . d) with w(s) = (1/2 - s)^4 for s < 1/2, 0 beyond,
** and g_v one of the 12 cube-edge vectors (|g_v| = sqrt 2) chosen by hashing
** (seed, v) with the splitmix mixers of rng.h: no permutation table.
**
** Why r0^2 = 1/2 exactly. In skewed coordinates the star of the vertex 0
** (the union of the simplices around it) is {|x_i| <= 1, |x_i - x_j| <= 1},
** a convex polytope whose 12 facets are the faces opposite 0. Skewing is
** p -> S p with S = I + 11^T/3 symmetric, so the facet a.x = 1 is the
** plane (S a).p = 1 at distance 1/|S a| from the vertex; S e_i =
** e_i + 1/3 (1,1,1) and S (e_i - e_j) = e_i - e_j both have |.|^2 = 2: the
** ball inscribed in the star has radius sqrt(1/2), the kernel's support.
** So a corner outside p's simplex adds exactly nothing (with r0^2 = 0.6 it
** would, hence the classic seams), and n is a sum of C^3 terms (w and its
** first three derivatives vanish at s = 1/2): n is C^1 everywhere and
** sup |grad n| is a Lipschitz constant (mean value theorem).
**
** One corner, with a = 1/2 - r^2, r = |d|:
**   |w (g.d)| <= sqrt2 a^4 r, largest at r^2 = 1/18: 256/19683 = 0.0130061;
**   grad = a^3 (a g - 8 (g.d) d), whose norm is at most
**   sqrt2 a^3 max(a, |1/2 - 9 r^2|) (the component along d carries
**   a - 8r^2, the rest a), largest at r = 0: sqrt2/16 = 0.0884.
** All four by hand: the simplex edges are sqrt3/2 and 1 long, so with the
** distances sorted r0 <= r1 <= r2 <= r3 the triangle inequality gives
** r1 >= sqrt3/4, where both one-corner bounds are already decreasing:
**   |raw| <= 0.0130061 + 3 sqrt2 (5/16)^4 sqrt3/4 = 0.0305,
**   |grad raw| <= sqrt2/16 + 3 sqrt2 (5/16)^3 (19/16) = 0.2422.
** Refined (computer-assisted proof): every simplex is the image of the
** reference one {1 >= x >= y >= z >= 0} by a lattice translation and an
** axis permutation, both isometries after unskewing that permute the 12
** gradients among themselves. An interval branch-and-bound over that
** simplex and all 12^4 gradient assignments (centred-form enclosures,
** margin 1e-12 over the rounding of round-to-nearest interval arithmetic)
** proves |raw| <= RAW_MAX and |grad raw| <= RAW_GRAD_MAX below.
** tests/c/test_noise.c re-runs that proof (in about a second), checks
** that this file computes exactly the analysed sum, and shows points of
** the simplex where some assignment reaches 0.0130071 and 0.0906200: the
** bounds are within 0.01 % and 0.2 % of the true suprema.
**
** The same prover (a third mode, with centred forms from the third
** derivatives of one corner's term) bounds the Hessian of raw on the
** coordinate planes: every principal 2 x 2 block of it has operator norm
** at most RAW_HESS_MAX, within a few per cent of a witness. (Each simplex
** is the reference one moved by a translation and an axis permutation, so
** the Hessian on a coordinate plane is such a block of the reference
** simplex's.) Elevation discs bound their noise in small boxes with it
** (elevation/disc.c).
**
** Scale. n = 1/2 + raw / (2 RAW_MAX) lies in [0, 1] since |raw| <= RAW_MAX
** (and reaches to within 3.3e-5 of either end): no clamp is needed and
** none is applied (a clamp would break the gradient).
** |grad n| <= RAW_GRAD_MAX / (2 RAW_MAX) = 3.4902 = oc_noise3_lipschitz.
**
** Domain. Coordinates up to |p| = 3 * 2^48 (8.4e14) are used as given; in
** skewed space they stay below 2^52, so floor() is exact and fits an
** int64. Larger finite coordinates are reduced modulo 3 * 2^48, which
** maps the skewed lattice onto itself (so the result is still a noise
** value) but leaves seams far beyond any scene. NaN or infinite input
** returns NaN, with a NaN gradient.
*/
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/noise.h"
#include "core/rng.h"

#define F3 (1.0 / 3.0)
#define G3 (1.0 / 6.0)

/* Proved bounds of the raw sum and its gradient (see above). */
#define RAW_MAX OC_NOISE3_RAW_MAX           /* 0.013008 */
#define RAW_GRAD_MAX OC_NOISE3_RAW_GRAD_MAX /* 0.0908 */
#define RAW_HESS_MAX OC_NOISE3_RAW_HESS_MAX /* 0.64 */
#define SCALE (0.5 / RAW_MAX)

/* The step between the octaves' seeds of a sum (oc_noise_octave_seed). */
#define OCTAVE_SEED_STEP 0x9e3779b97f4a7c15ull

/* The lattice period used to reduce huge coordinates (a multiple of 3). */
#define REDUCE_PERIOD (3.0 * 0x1p48)

const double oc_noise3_lipschitz = OC_NOISE3_LIPSCHITZ;
const double oc_noise3_hessian = OC_NOISE3_HESSIAN;

/* Pairs g, -g next to each other: the mean is 1/2 by symmetry. */
static const double grad12[12][3] = {
    {1, 1, 0},  {-1, -1, 0}, {1, -1, 0}, {-1, 1, 0},  {1, 0, 1},  {-1, 0, -1},
    {1, 0, -1}, {-1, 0, 1},  {0, 1, 1},  {0, -1, -1}, {0, 1, -1}, {0, -1, 1}};

/* floor for |x| < 2^52, where the conversion is exact; libm's floor is a
** call on baseline x86-64, and three of them cost more than the hashing. */
static inline int64_t floor_i64(double x) {
  int64_t i = (int64_t)x;
  return i - (x < (double)i);
}

/* One corner's gradient index, a pure function of (key, corner). The inner
** sum is injective on (i, j) within any window narrower than 2^30 cells
** (the shortest kernel vector of (i, j) -> i A + j B mod 2^64 has length
** 2^31.17 for these A, B), the outer mix separates k. A nested mix per
** coordinate cost 15 % more time; a single mix of a sum of three products
** would repeat after about 2^21 cells. */
#define HASH_A 0xd1b54a32d192ed03ull
#define HASH_B 0xaef17502108ef2d9ull
static inline unsigned grad_index(uint64_t ij, uint64_t k) {
  uint64_t h = oc_mix64(oc_mix64(ij) + k);
  return (unsigned)(((h >> 32) * 12) >> 32);
}

static inline unsigned corner_grad(uint64_t key, uint64_t i, uint64_t j,
                                   uint64_t k) {
  return grad_index(key + i * HASH_A + j * HASH_B, k);
}

/* The four corners' corner_grad in a simplex of cell (i, j, k), st its
** steps (i1, j1, k1, i2, j2, k2): the cell's key + i A + j B once, a
** corner stepping along i or j adding A or B (the same sums modulo 2^64;
** six multiplies fewer). */
static inline void simplex_grads(uint64_t key, uint64_t i, uint64_t j,
                                 uint64_t k, const unsigned st[6],
                                 unsigned gi[4]) {
  uint64_t base = key + i * HASH_A + j * HASH_B;
  gi[0] = grad_index(base, k);
  gi[1] = grad_index(base + (HASH_A & -(uint64_t)st[0]) +
                         (HASH_B & -(uint64_t)st[1]),
                     k + st[2]);
  gi[2] = grad_index(base + (HASH_A & -(uint64_t)st[3]) +
                         (HASH_B & -(uint64_t)st[4]),
                     k + st[5]);
  gi[3] = grad_index(base + HASH_A + HASH_B, k + 1);
}

/* Adds one corner's term; d is p minus the corner; the gradient's too
** when wg (a constant once inlined: the value alone skips its sums, with
** the same value bit for bit). */
static inline void corner_add(unsigned gi, double dx, double dy, double dz,
                              double *v, double *g, int wg) {
  double a = 0.5 - (dx * dx + dy * dy + dz * dz);
  /* max(a, 0), exactly, without the branch gcc emits for a ?: (a corner is
  ** out of reach too often for that branch to be predicted). */
  a = 0.5 * (a + fabs(a));
  const double *gr = grad12[gi];
  double t = gr[0] * dx + gr[1] * dy + gr[2] * dz;
  double a2 = a * a, a3 = a2 * a;
  *v += a3 * a * t;
  if (!wg) return;
  double k = 8 * t;
  g[0] += a3 * (a * gr[0] - k * dx);
  g[1] += a3 * (a * gr[1] - k * dy);
  g[2] += a3 * (a * gr[2] - k * dz);
}

static inline int is_huge(oc_vec3 p) {
  return !(fabs(p.x) <= REDUCE_PERIOD && fabs(p.y) <= REDUCE_PERIOD &&
           fabs(p.z) <= REDUCE_PERIOD);
}

/* fmod(x, REDUCE_PERIOD), bit for bit, in constant time: glibc's fmod
** loops over the exponent difference, about a thousand steps at 1e300,
** which made a render of a warped node crawl (a fuzz finding). Past
** 2^101 every double is m 2^e with e >= 49, and
** m 2^e mod 3 2^48 = 2^48 ((m mod 3) (2^(e-48) mod 3) mod 3). */
static double reduce1(double x) {
  if (!(fabs(x) >= 0x1p101)) return fmod(x, REDUCE_PERIOD);
  uint64_t b;
  memcpy(&b, &x, sizeof b);
  int e = (int)((b >> 52) & 0x7ff) - 1075; /* x = m 2^e, normal */
  uint64_t m = (b & ((UINT64_C(1) << 52) - 1)) | (UINT64_C(1) << 52);
  unsigned k = (unsigned)(m % 3) * ((e - 48) % 2 ? 2u : 1u) % 3;
  return copysign(k * 0x1p48, x);
}

/* Huge finite coordinates modulo REDUCE_PERIOD (exact). */
static oc_vec3 reduce(oc_vec3 p) {
  oc_vec3 r = {reduce1(p.x), reduce1(p.y), reduce1(p.z)};
  return r;
}

/* The simplex of a point: its cell (skewed lattice coordinates), the
** second and third corners' steps from it, and the offset to the first
** corner. */
typedef struct simplex {
  uint64_t i, j, k;
  unsigned i1, j1, k1, i2, j2, k2;
  double x0, y0, z0;
} simplex;

/* Locates (x, y, z), a point that is not huge. */
static inline void simplex_locate(double x, double y, double z, simplex *S) {
  /* The cell, and p's offset in it, all in skewed space: fractional parts
  ** are exact there, so large coordinates lose nothing more than the
  ** rounding of x + s itself. */
  double s = (x + y + z) * F3;
  double xs = x + s, ys = y + s, zs = z + s;
  int64_t ci = floor_i64(xs), cj = floor_i64(ys), ck = floor_i64(zs);
  double fx = xs - (double)ci, fy = ys - (double)cj, fz = zs - (double)ck;
  S->i = (uint64_t)ci, S->j = (uint64_t)cj, S->k = (uint64_t)ck;
  double t = (fx + fy + fz) * G3;
  double x0 = fx - t, y0 = fy - t, z0 = fz - t;
  S->x0 = x0, S->y0 = y0, S->z0 = z0;

  /* The simplex: the axes in decreasing order of the offset, the second
  ** and third corners stepping along the first one and the first two.
  ** Computed without branches, which would be mispredicted half the time. */
  unsigned xy = x0 >= y0, xz = x0 >= z0, yz = y0 >= z0;
  S->i1 = xy & xz, S->j1 = (!xy) & yz, S->k1 = (!xz) & (!yz);
  S->i2 = xy | xz, S->j2 = (!xy) | yz, S->k2 = (!xz) | (!yz);
}

/* The raw sum of the four corners' terms, gi their gradient indices; the
** gradient's in g when wg. */
static inline double simplex_sum(const simplex *S, const unsigned gi[4],
                                 double g[3], int wg) {
  double x0 = S->x0, y0 = S->y0, z0 = S->z0, v = 0;
  unsigned i1 = S->i1, j1 = S->j1, k1 = S->k1;
  unsigned i2 = S->i2, j2 = S->j2, k2 = S->k2;
  corner_add(gi[0], x0, y0, z0, &v, g, wg);
  corner_add(gi[1], x0 - i1 + G3, y0 - j1 + G3, z0 - k1 + G3, &v, g, wg);
  corner_add(gi[2], x0 - i2 + 2 * G3, y0 - j2 + 2 * G3, z0 - k2 + 2 * G3, &v, g,
             wg);
  corner_add(gi[3], x0 - 1 + 3 * G3, y0 - 1 + 3 * G3, z0 - 1 + 3 * G3, &v, g,
             wg);
  return v;
}

#define KEY_SALT 0x8a5cd789635d2dffull
static inline uint64_t noise_key(uint64_t seed) {
  return oc_mix64(seed ^ KEY_SALT);
}

/* n(p), with the gradient when wg (then grad is not NULL). */
static inline double noise3(uint64_t seed, oc_vec3 p, oc_vec3 *grad, int wg) {
  if (is_huge(p)) {
    if (!(isfinite(p.x) && isfinite(p.y) && isfinite(p.z))) {
      if (grad) grad->x = grad->y = grad->z = NAN;
      return NAN;
    }
    p = reduce(p);
  }
  simplex S;
  simplex_locate(p.x, p.y, p.z, &S);
  unsigned gi[4], st[6] = {S.i1, S.j1, S.k1, S.i2, S.j2, S.k2};
  simplex_grads(noise_key(seed), S.i, S.j, S.k, st, gi);
  double g[3] = {0, 0, 0}, v = simplex_sum(&S, gi, g, wg);
  if (wg) {
    grad->x = SCALE * g[0];
    grad->y = SCALE * g[1];
    grad->z = SCALE * g[2];
  }
  return 0.5 + SCALE * v;
}

double oc_noise3(uint64_t seed, oc_vec3 p, oc_vec3 *grad) {
  return grad ? noise3(seed, p, grad, 1) : noise3(seed, p, NULL, 0);
}

/* Rows go in blocks of ZB points, in three passes: locating the points in
** the skewed lattice and summing the corners' terms are the same
** arithmetic for every point (vector loops: `omp simd` asks for them, and
** a vector lane rounds as the scalar code does, -ffp-contract=off keeping
** products and sums apart); between them, the simplexes and the corners'
** gradients, hashed once per lattice cell along the row. */
#define ZB 64

/* Cube corner di + 2 dj + 4 dk: (di, dj, dk). */
static const double cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

/* The corners' gradients of the current cell along a row. */
typedef struct row_cache {
  uint64_t key, ci, cj, ck;
  unsigned valid;      /* the cube corners of cell (ci, cj, ck) in cg (0:
                       ** no cell yet) */
  unsigned char cg[8]; /* corner di + 2 dj + 4 dk: its gradient index */
} row_cache;

/* floor(x) for |x| < 2^51 as a double, exactly (= (double)floor_i64(x)):
** x + 1.5 2^52 rounds x to an integer, which the subtraction gives back
** exactly, one less where it rounded up. Baseline x86-64 has no vector
** floor nor int64 conversion; this is two adds and a compare. */
#define FLOOR_C 0x1.8p52
static inline double floor_d(double x) {
  double r = x + FLOOR_C; /* (each sum stored: rounded to a double even */
  r = r - FLOOR_C;        /* where an FPU keeps more bits) */
  return r > x ? r - 1 : r;
}

/* Two points at a time (GCC's vector extensions, which clang shares): the
** same operations as the scalar code, lane by lane. */
typedef double v2d __attribute__((vector_size(16)));
typedef long long v2l __attribute__((vector_size(16)));
static inline v2d floor_v(v2d x) {
  const v2d c = {FLOOR_C, FLOOR_C}, one = {1, 1};
  v2d r = (x + c) - c;
  v2l up = r > x; /* all ones where r rounded up */
  return r - (v2d)((v2l)one & up);
}

/* The offset to the first corner and the cell of (x, y, 0) (not huge): a
** point's simplex_locate, in parts. */
static inline void locate_z0(double px, double py, double *x0, double *y0,
                             double *z0, double *fi, double *fj, double *fk) {
  double pz = 0, s = (px + py + pz) * F3;
  double xs = px + s, ys = py + s, zs = pz + s;
  *fi = floor_d(xs), *fj = floor_d(ys), *fk = floor_d(zs);
  double fx = xs - *fi, fy = ys - *fj, fz = zs - *fk;
  double t = (fx + fy + fz) * G3;
  *x0 = fx - t, *y0 = fy - t, *z0 = fz - t;
}

/* v plus one corner's term, as corner_add adds it (value alone), its
** gradient gr[.][m]. */
static inline double corner_term(long long gi, double dx, double dy, double dz,
                                 double v) {
  double a = 0.5 - (dx * dx + dy * dy + dz * dz);
  a = 0.5 * (a + fabs(a));
  double t = grad12[gi][0] * dx + grad12[gi][1] * dy + grad12[gi][2] * dz;
  double a2 = a * a, a3 = a2 * a;
  return v + a3 * a * t;
}

static void z0_block(row_cache *rc, const double *x, const double *y, size_t n,
                     double *out) {
  double X0[ZB], Y0[ZB], Z0[ZB], FI[ZB], FJ[ZB], FK[ZB];
  long long C1[ZB], C2[ZB]; /* the second and third corners (cube) */
  long long G[4][ZB];       /* the four corners' gradient indices */
  /* (is_huge for z = 0: skewed coordinates then stay below 2^51) */
  size_t m = 0;
  for (; m + 2 <= n; m += 2) {
    const v2d f3 = {F3, F3}, g3 = {G3, G3}, zero = {0, 0};
    v2d px = {x[m], x[m + 1]}, py = {y[m], y[m + 1]}, pz = zero;
    v2d s = (px + py + pz) * f3;
    v2d xs = px + s, ys = py + s, zs = pz + s;
    v2d fi = floor_v(xs), fj = floor_v(ys), fk = floor_v(zs);
    v2d fx = xs - fi, fy = ys - fj, fz = zs - fk;
    v2d t = (fx + fy + fz) * g3;
    v2d x0 = fx - t, y0 = fy - t, z0 = fz - t;
    for (int l = 0; l < 2; l++) {
      X0[m + l] = x0[l], Y0[m + l] = y0[l], Z0[m + l] = z0[l];
      FI[m + l] = fi[l], FJ[m + l] = fj[l], FK[m + l] = fk[l];
    }
  }
  for (; m < n; m++)
    locate_z0(x[m], y[m], &X0[m], &Y0[m], &Z0[m], &FI[m], &FJ[m], &FK[m]);
  for (m = 0; m < n; m++) {
    uint64_t i = (uint64_t)(int64_t)FI[m], j = (uint64_t)(int64_t)FJ[m],
             k = (uint64_t)(int64_t)FK[m];
    double x0 = X0[m], y0 = Y0[m], z0 = Z0[m];
    unsigned xy = x0 >= y0, xz = x0 >= z0, yz = y0 >= z0;
    unsigned i1 = xy & xz, j1 = (!xy) & yz, k1 = (!xz) & (!yz);
    unsigned i2 = xy | xz, j2 = (!xy) | yz, k2 = (!xz) | (!yz);
    if (!rc->valid || i != rc->ci || j != rc->cj || k != rc->ck) {
      /* a new cell: its first and last corners, which every simplex
      ** in it has */
      rc->ci = i, rc->cj = j, rc->ck = k, rc->valid = 0x81;
      rc->cg[0] = (unsigned char)corner_grad(rc->key, i, j, k);
      rc->cg[7] = (unsigned char)corner_grad(rc->key, i + 1, j + 1, k + 1);
    }
    unsigned c[2] = {i1 | j1 << 1 | k1 << 2, i2 | j2 << 1 | k2 << 2};
    for (int q = 0; q < 2; q++) {
      unsigned b = c[q];
      if (!(rc->valid >> b & 1)) {
        rc->cg[b] = (unsigned char)corner_grad(rc->key, i + (b & 1),
                                               j + (b >> 1 & 1), k + (b >> 2));
        rc->valid |= 1u << b;
      }
    }
    C1[m] = c[0], C2[m] = c[1];
    G[0][m] = rc->cg[0], G[1][m] = rc->cg[c[0]];
    G[2][m] = rc->cg[c[1]], G[3][m] = rc->cg[7];
  }
#pragma omp simd
  for (m = 0; m < n; m++) {
    double x0 = X0[m], y0 = Y0[m], z0 = Z0[m], v = 0;
    v = corner_term(G[0][m], x0, y0, z0, v);
    v = corner_term(G[1][m], x0 - cube[C1[m]][0] + G3, y0 - cube[C1[m]][1] + G3,
                    z0 - cube[C1[m]][2] + G3, v);
    v = corner_term(G[2][m], x0 - cube[C2[m]][0] + 2 * G3,
                    y0 - cube[C2[m]][1] + 2 * G3, z0 - cube[C2[m]][2] + 2 * G3,
                    v);
    v = corner_term(G[3][m], x0 - 1 + 3 * G3, y0 - 1 + 3 * G3, z0 - 1 + 3 * G3,
                    v);
    out[m] = 0.5 + SCALE * v;
  }
}

void oc_noise3_z0_row(uint64_t seed, const double *x, const double *y, size_t n,
                      double *out) {
  row_cache rc = {noise_key(seed), 0, 0, 0, 0, {0}};
  for (size_t b = 0; b < n; b += ZB) {
    size_t cnt = n - b < ZB ? n - b : ZB, m = 0;
    while (m < cnt && !is_huge((oc_vec3){x[b + m], y[b + m], 0}))
      m++;
    if (m == cnt) {
      z0_block(&rc, x + b, y + b, cnt, out + b);
      continue;
    }
    for (m = 0; m < cnt; m++) /* (huge or not finite: rare) */
      out[b + m] = noise3(seed, (oc_vec3){x[b + m], y[b + m], 0}, NULL, 0);
  }
}

/* ---- oc_noise3_z0_multi: noise3 on the plane z = 0, several points at a
** time, one per lane of a vector. Each lane does the scalar code's
** operations in its order (simplex_locate with floor_d's floor,
** corner_grad's hashes, corner_add's sums), so every value and gradient
** is noise3's bit for bit; the gradient's z part is not computed.
** Vector-by-scalar operations broadcast the scalar exactly. Two paths:
** two lanes with GCC's vector extensions (SSE2 on every x86-64), the
** hashes lane by lane; eight lanes under AVX-512 (F and DQ: 64-bit
** multiplies, so the hashes too are vector operations), chosen on each
** call where the processor has it (a bit of the processor's features
** that the C library read once at start-up). A count that is not a
** multiple of the lanes fills the last vector with padding lanes whose
** results are dropped; huge coordinates are reduced before (noise3's
** reduce), points that are not finite give NaN as in noise3. (Four lanes
** under AVX2, the two-lane code with 32-byte vectors and the hashes lane
** by lane, measured slower on an AMD EPYC: 35 ns an octave against 30.) */

/* A lane's point as noise3 uses it: huge finite coordinates reduced; 0
** (and the origin) for a point that is not finite. */
static int lane_point_slow(double x, double y, double *px, double *py) {
  *px = *py = 0;
  if (!(isfinite(x) && isfinite(y))) return 0;
  oc_vec3 p = reduce((oc_vec3){x, y, 0});
  *px = p.x, *py = p.y;
  return 1;
}

static inline int lane_point(double x, double y, double *px, double *py) {
  if (is_huge((oc_vec3){x, y, 0})) return lane_point_slow(x, y, px, py);
  *px = x, *py = y;
  return 1;
}

/* One corner's term added to v, its gradient's x and y parts to gx, gy
** when wg; gi the lanes' gradient indices. */
static inline void corner2(const unsigned *gi, v2d dx, v2d dy, v2d dz, v2d *v,
                           v2d *gx, v2d *gy, int wg) {
  v2d a = 0.5 - (dx * dx + dy * dy + dz * dz);
  a = 0.5 * (a + (v2d)((v2l)a & INT64_MAX)); /* max(a, 0) = (a + |a|) / 2 */
  v2d grx, gry, grz;
  for (int l = 0; l < 2; l++) {
    grx[l] = grad12[gi[l]][0];
    gry[l] = grad12[gi[l]][1];
    grz[l] = grad12[gi[l]][2];
  }
  v2d t = grx * dx + gry * dy + grz * dz;
  v2d a2 = a * a, a3 = a2 * a;
  *v += a3 * a * t;
  if (!wg) return;
  v2d k = 8 * t;
  *gx += a3 * (a * grx - k * dx);
  *gy += a3 * (a * gry - k * dy);
}

/* noise3 of (px[l], py[l], 0) under seed[l] for the 2 lanes (no point
** huge), into val, and the gradients' x and y parts into gx, gy when wg. */
static inline void z0_lanes(const uint64_t *seed, v2d px, v2d py, v2d *val,
                            v2d *gx, v2d *gy, int wg) {
  const v2l one = (v2l)((v2d){0} + 1); /* 1.0's bits in every lane */
  v2d zero = {0}, pz = zero, s = (px + py + pz) * F3;
  v2d xs = px + s, ys = py + s, zs = pz + s;
  v2d fi, fj, fk; /* floor_d lane by lane */
  {
    v2d r = (xs + FLOOR_C) - FLOOR_C;
    fi = r - (v2d)(one & (r > xs));
    r = (ys + FLOOR_C) - FLOOR_C;
    fj = r - (v2d)(one & (r > ys));
    r = (zs + FLOOR_C) - FLOOR_C;
    fk = r - (v2d)(one & (r > zs));
  }
  v2d fx = xs - fi, fy = ys - fj, fz = zs - fk;
  v2d t = (fx + fy + fz) * G3;
  v2d x0 = fx - t, y0 = fy - t, z0 = fz - t;
  /* the simplex: simplex_locate's bits as all-ones masks */
  v2l xy = x0 >= y0, xz = x0 >= z0, yz = y0 >= z0;
  v2l i1 = xy & xz, j1 = ~xy & yz, k1 = ~xz & ~yz;
  v2l i2 = xy | xz, j2 = ~xy | yz, k2 = ~xz | ~yz;
  unsigned gi[4][2];
  for (int l = 0; l < 2; l++) {
    unsigned st[6] = {i1[l] & 1, j1[l] & 1, k1[l] & 1,
                      i2[l] & 1, j2[l] & 1, k2[l] & 1};
    unsigned g[4];
    simplex_grads(noise_key(seed[l]), (uint64_t)(int64_t)fi[l],
                  (uint64_t)(int64_t)fj[l], (uint64_t)(int64_t)fk[l], st, g);
    for (int c = 0; c < 4; c++)
      gi[c][l] = g[c];
  }
  v2d v = zero, g0 = zero, g1 = zero;
  corner2(gi[0], x0, y0, z0, &v, &g0, &g1, wg);
  corner2(gi[1], x0 - (v2d)(i1 & one) + G3, y0 - (v2d)(j1 & one) + G3,
          z0 - (v2d)(k1 & one) + G3, &v, &g0, &g1, wg);
  corner2(gi[2], x0 - (v2d)(i2 & one) + 2 * G3, y0 - (v2d)(j2 & one) + 2 * G3,
          z0 - (v2d)(k2 & one) + 2 * G3, &v, &g0, &g1, wg);
  corner2(gi[3], x0 - 1 + 3 * G3, y0 - 1 + 3 * G3, z0 - 1 + 3 * G3, &v, &g0,
          &g1, wg);
  *val = 0.5 + SCALE * v;
  if (wg) *gx = SCALE * g0, *gy = SCALE * g1;
}

/* val, gx, gy at m + l for l < cnt (1 or 2) from v, g0, g1, NaN where the
** point was not finite (fin bit l clear). */
static inline void z0_store2(v2d v, v2d g0, v2d g1, unsigned fin, size_t m,
                             size_t cnt, double *val, double *gx, double *gy,
                             int wg) {
  if (fin != 3) /* (rare) */
    for (int l = 0; l < 2; l++)
      if (!(fin >> l & 1)) v[l] = g0[l] = g1[l] = NAN;
  for (size_t l = 0; l < cnt; l++) {
    val[m + l] = v[l];
    if (wg) gx[m + l] = g0[l], gy[m + l] = g1[l];
  }
}

/* The points m < n two at a time, an odd last one beside a padding lane
** (the origin under seed 0). */
static void z0_multi_sse2(const uint64_t *seeds, const double *x,
                          const double *y, size_t n, double *val, double *gx,
                          double *gy, int wg) {
  v2d v, g0 = {0, 0}, g1 = {0, 0};
  size_t m = 0;
  for (; m + 2 <= n; m += 2) {
    double ax, ay, bx, by;
    unsigned fin = (unsigned)lane_point(x[m], y[m], &ax, &ay) |
                   (unsigned)lane_point(x[m + 1], y[m + 1], &bx, &by) << 1;
    z0_lanes(seeds + m, (v2d){ax, bx}, (v2d){ay, by}, &v, &g0, &g1, wg);
    z0_store2(v, g0, g1, fin, m, 2, val, gx, gy, wg);
  }
  if (m < n) {
    double ax, ay;
    unsigned fin = (unsigned)lane_point(x[m], y[m], &ax, &ay) | 2u;
    uint64_t sd[2] = {seeds[m], 0};
    z0_lanes(sd, (v2d){ax, 0}, (v2d){ay, 0}, &v, &g0, &g1, wg);
    z0_store2(v, g0, g1, fin, m, 1, val, gx, gy, wg);
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define HAVE_AVX512 1
#include <immintrin.h>

/* Functions compiled for AVX-512 F and DQ (and nothing else: no FMA, so
** no contraction even if -ffp-contract allowed it); called only where
** the processor has both. */
#define AVX512 __attribute__((target("avx512f,avx512dq")))
/* (inlined always: wg then is a constant) */
#define AVX512_INLINE AVX512 static inline __attribute__((always_inline))

static int have_avx512(void) {
  return __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512dq");
}

#define SET1Q(c) _mm512_set1_epi64((long long)(c))

/* oc_mix64 in each lane. */
AVX512_INLINE __m512i mix64_8(__m512i z) {
  z = _mm512_add_epi64(z, SET1Q(0x9e3779b97f4a7c15ull));
  z = _mm512_xor_si512(z, _mm512_srli_epi64(z, 30));
  z = _mm512_mullo_epi64(z, SET1Q(0xbf58476d1ce4e5b9ull));
  z = _mm512_xor_si512(z, _mm512_srli_epi64(z, 27));
  z = _mm512_mullo_epi64(z, SET1Q(0x94d049bb133111ebull));
  return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}

/* corner_grad of the lanes: ij = key + i A + j B, the k step added. */
AVX512_INLINE __m512i corner_grad8(__m512i ij, __m512i k) {
  __m512i h = mix64_8(_mm512_add_epi64(mix64_8(ij), k));
  /* ((h >> 32) * 12) >> 32, h >> 32 < 2^32: an unsigned 32 x 32 bit
  ** product */
  h = _mm512_mul_epu32(_mm512_srli_epi64(h, 32), SET1Q(12));
  return _mm512_srli_epi64(h, 32);
}

/* floor_d in each lane: floor (exact) plus 0, which turns floor(-0) = -0
** into floor_d's +0 (floor_d never gives -0) and changes nothing else. */
AVX512_INLINE __m512d floor8(__m512d x) {
  return _mm512_roundscale_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC) +
         0.0;
}

/* One corner's term added to v, its gradient's x and y parts to gx, gy
** when wg (corner_add, lane by lane: __m512d takes GCC's vector
** operators, a scalar operand broadcast); gi the gradient indices. The
** gradients' components are looked up in 16-entry tables (two
** registers) by one permutation each. */
AVX512_INLINE void corner8(__m512i gi, __m512d dx, __m512d dy, __m512d dz,
                           __m512d *v, __m512d *gx, __m512d *gy, int wg) {
  const __m512d x_lo = _mm512_setr_pd(1, -1, 1, -1, 1, -1, 1, -1);
  const __m512d y_lo = _mm512_setr_pd(1, -1, -1, 1, 0, 0, 0, 0);
  const __m512d y_hi = _mm512_setr_pd(1, -1, 1, -1, 0, 0, 0, 0);
  const __m512d z_lo = _mm512_setr_pd(0, 0, 0, 0, 1, -1, -1, 1);
  const __m512d z_hi = _mm512_setr_pd(1, -1, -1, 1, 0, 0, 0, 0);
  __m512d grx = _mm512_permutex2var_pd(x_lo, gi, _mm512_setzero_pd());
  __m512d gry = _mm512_permutex2var_pd(y_lo, gi, y_hi);
  __m512d grz = _mm512_permutex2var_pd(z_lo, gi, z_hi);
  __m512d a = 0.5 - (dx * dx + dy * dy + dz * dz);
  /* corner_add's max(a, 0) = (a + |a|) / 2, the same bits in one
  ** instruction: 2a halved is a; a + |a| is +0 for a <= 0, and so is
  ** vmaxpd's second operand (a is never NaN) */
  a = _mm512_max_pd(a, _mm512_setzero_pd());
  __m512d t = grx * dx + gry * dy + grz * dz;
  __m512d a2 = a * a, a3 = a2 * a;
  *v += a3 * a * t;
  if (!wg) return;
  __m512d k = 8 * t;
  *gx += a3 * (a * grx - k * dx);
  *gy += a3 * (a * gry - k * dy);
}

/* z0_lanes for 8 lanes: noise3 of (px, py, 0) under the seeds sd (no
** point huge). */
AVX512_INLINE void z0_lanes8(__m512i sd, __m512d px, __m512d py, __m512d *val,
                             __m512d *gx, __m512d *gy, int wg) {
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1);
  __m512d pz = zero, s = (px + py + pz) * F3;
  __m512d xs = px + s, ys = py + s, zs = pz + s;
  __m512d fi = floor8(xs), fj = floor8(ys), fk = floor8(zs);
  __m512d fx = xs - fi, fy = ys - fj, fz = zs - fk;
  __m512d t = (fx + fy + fz) * G3;
  __m512d x0 = fx - t, y0 = fy - t, z0 = fz - t;
  /* the simplex: simplex_locate's bits, one per lane */
  __mmask8 xy = _mm512_cmp_pd_mask(x0, y0, _CMP_GE_OQ),
           xz = _mm512_cmp_pd_mask(x0, z0, _CMP_GE_OQ),
           yz = _mm512_cmp_pd_mask(y0, z0, _CMP_GE_OQ);
  __mmask8 i1 = xy & xz, j1 = (__mmask8)(~xy & yz), k1 = (__mmask8)(~xz & ~yz);
  __mmask8 i2 = xy | xz, j2 = (__mmask8)(~xy | yz), k2 = (__mmask8)(~xz | ~yz);
  /* the hashes (corner_grad, i A + j B shared as in simplex_grads) */
  __m512i key = mix64_8(_mm512_xor_si512(sd, SET1Q(KEY_SALT))); /* noise_key */
  __m512i ci = _mm512_cvttpd_epi64(fi), cj = _mm512_cvttpd_epi64(fj),
          ck = _mm512_cvttpd_epi64(fk);
  const __m512i ha = SET1Q(HASH_A), hb = SET1Q(HASH_B), q1 = SET1Q(1);
  __m512i base =
      _mm512_add_epi64(_mm512_add_epi64(key, _mm512_mullo_epi64(ci, ha)),
                       _mm512_mullo_epi64(cj, hb));
  __m512i ij1 = _mm512_mask_add_epi64(base, i1, base, ha);
  __m512i ij2 = _mm512_mask_add_epi64(base, i2, base, ha);
  ij1 = _mm512_mask_add_epi64(ij1, j1, ij1, hb);
  ij2 = _mm512_mask_add_epi64(ij2, j2, ij2, hb);
  __m512i ij3 = _mm512_add_epi64(_mm512_add_epi64(base, ha), hb);
  __m512i gi0 = corner_grad8(base, ck);
  __m512i gi1 = corner_grad8(ij1, _mm512_mask_add_epi64(ck, k1, ck, q1));
  __m512i gi2 = corner_grad8(ij2, _mm512_mask_add_epi64(ck, k2, ck, q1));
  __m512i gi3 = corner_grad8(ij3, _mm512_add_epi64(ck, q1));
  /* the corners' offsets: x0 - i1 + G3 ..., x0 - 1 where i1 is set and
  ** x0 elsewhere (x0 - 0 bit for bit) */
  __m512d v = zero, g0 = zero, g1 = zero;
  corner8(gi0, x0, y0, z0, &v, &g0, &g1, wg);
  corner8(gi1, _mm512_mask_sub_pd(x0, i1, x0, one) + G3,
          _mm512_mask_sub_pd(y0, j1, y0, one) + G3,
          _mm512_mask_sub_pd(z0, k1, z0, one) + G3, &v, &g0, &g1, wg);
  corner8(gi2, _mm512_mask_sub_pd(x0, i2, x0, one) + 2 * G3,
          _mm512_mask_sub_pd(y0, j2, y0, one) + 2 * G3,
          _mm512_mask_sub_pd(z0, k2, z0, one) + 2 * G3, &v, &g0, &g1, wg);
  corner8(gi3, x0 - 1 + 3 * G3, y0 - 1 + 3 * G3, z0 - 1 + 3 * G3, &v, &g0, &g1,
          wg);
  *val = 0.5 + SCALE * v;
  if (wg) *gx = SCALE * g0, *gy = SCALE * g1;
}

/* One vector of z0_multi8: the lanes' seeds sd and points (px, py), those
** outside lanes padding; the results stored at val + m ... for the lanes. */
AVX512_INLINE void z0_vec8(__m512i sd, __m512d px, __m512d py, __mmask8 lanes,
                           size_t m, double *val, double *gx, double *gy,
                           int wg, int whole) {
  const __m512d period = _mm512_set1_pd(REDUCE_PERIOD);
  /* is_huge: not |x| <= P and |y| <= P (NaN too); rare */
  __mmask8 huge =
      (__mmask8) ~(_mm512_cmp_pd_mask(_mm512_abs_pd(px), period, _CMP_LE_OQ) &
                   _mm512_cmp_pd_mask(_mm512_abs_pd(py), period, _CMP_LE_OQ));
  __mmask8 nonfinite = 0;
  if (huge & lanes) {
    double bx[8], by[8];
    _mm512_storeu_pd(bx, px), _mm512_storeu_pd(by, py);
    for (unsigned l = 0; l < 8; l++)
      if ((huge & lanes) >> l & 1 &&
          !lane_point_slow(bx[l], by[l], &bx[l], &by[l]))
        nonfinite |= (__mmask8)(1u << l);
    px = _mm512_loadu_pd(bx), py = _mm512_loadu_pd(by);
  }
  __m512d v, g0 = _mm512_setzero_pd(), g1 = g0;
  z0_lanes8(sd, px, py, &v, &g0, &g1, wg);
  if (nonfinite) {
    const __m512d nan = _mm512_set1_pd(NAN);
    v = _mm512_mask_mov_pd(v, nonfinite, nan);
    g0 = _mm512_mask_mov_pd(g0, nonfinite, nan);
    g1 = _mm512_mask_mov_pd(g1, nonfinite, nan);
  }
  if (whole) { /* (the padding lanes' too: the caller's room) */
    _mm512_storeu_pd(val + m, v);
    if (wg) _mm512_storeu_pd(gx + m, g0), _mm512_storeu_pd(gy + m, g1);
    return;
  }
  _mm512_mask_storeu_pd(val + m, lanes, v);
  if (wg) {
    _mm512_mask_storeu_pd(gx + m, lanes, g0);
    _mm512_mask_storeu_pd(gy + m, lanes, g1);
  }
}

/* The points m < n eight at a time, the last vector's missing points as
** padding lanes (masked loads and stores: nothing past n is touched). */
AVX512_INLINE void z0_multi8(const uint64_t *seeds, const double *x,
                             const double *y, size_t n, double *val, double *gx,
                             double *gy, int wg) {
  for (size_t m = 0; m < n; m += 8) {
    __mmask8 lanes = n - m < 8 ? (__mmask8)((1u << (n - m)) - 1) : 0xff;
    z0_vec8(_mm512_maskz_loadu_epi64(lanes, seeds + m),
            _mm512_maskz_loadu_pd(lanes, x + m),
            _mm512_maskz_loadu_pd(lanes, y + m), lanes, m, val, gx, gy, wg, 0);
  }
}

/* z0_multi8 with and without the gradients, each compiled for itself. */
AVX512 static void z0_multi_avx512_g(const uint64_t *seeds, const double *x,
                                     const double *y, size_t n, double *val,
                                     double *gx, double *gy) {
  z0_multi8(seeds, x, y, n, val, gx, gy, 1);
}

AVX512 static void z0_multi_avx512_v(const uint64_t *seeds, const double *x,
                                     const double *y, size_t n, double *val) {
  z0_multi8(seeds, x, y, n, val, NULL, NULL, 0);
}

/* The octaves m < n of a sum (oc_noise3_z0_octaves) eight at a time: the
** seeds oc_noise_octave_seed(seed, m) (the same sum and mix, lane by
** lane) and the points s[m] (u, v), as products of the lanes' s[m] and
** the broadcast u and v (the scalar products' bits). */
AVX512_INLINE void z0_octaves8(uint64_t seed, const double *s, double f,
                               double u, double v, size_t n, double *val,
                               double *gx, double *gy, int wg) {
  /* s NULL: s[m] = f 2^m, lane l of a vector f 2^m times 2^l (products
  ** by powers of 2, exact: the bits of f doubled m + l times, infinities
  ** alike), the padding lanes 0 */
  const __m512d pow2 = _mm512_setr_pd(1, 2, 4, 8, 16, 32, 64, 128);
  /* (l + 1) OCTAVE_SEED_STEP in lane l, folded at compile time: a
  ** vector's seeds are these plus seed + m STEP (the same sums modulo
  ** 2^64), no 64-bit vector multiply per call */
#define STEPS(l) (long long)((l)*OCTAVE_SEED_STEP)
  const __m512i steps =
      _mm512_setr_epi64(STEPS(1), STEPS(2), STEPS(3), STEPS(4), STEPS(5),
                        STEPS(6), STEPS(7), STEPS(8));
#undef STEPS
  for (size_t m = 0; m < n; m += 8) {
    __mmask8 lanes = n - m < 8 ? (__mmask8)((1u << (n - m)) - 1) : 0xff;
    __m512i sd =
        mix64_8(_mm512_add_epi64(SET1Q(seed + m * OCTAVE_SEED_STEP), steps));
    __m512d sc = s ? _mm512_maskz_loadu_pd(lanes, s + m)
                   : _mm512_maskz_mul_pd(lanes, pow2, _mm512_set1_pd(f));
    f *= 256; /* (the next vector's f 2^m) */
    z0_vec8(sd, sc * u, sc * v, lanes, m, val, gx, gy, wg, 1);
  }
}

AVX512 static void z0_octaves_avx512_g(uint64_t seed, const double *s, double u,
                                       double v, size_t n, double *val,
                                       double *gx, double *gy) {
  z0_octaves8(seed, s, 0, u, v, n, val, gx, gy, 1);
}

AVX512 static void z0_octaves_avx512_v(uint64_t seed, const double *s, double u,
                                       double v, size_t n, double *val) {
  z0_octaves8(seed, s, 0, u, v, n, val, NULL, NULL, 0);
}

/* The same with the frequencies f 2^m (each compiled for itself: no
** loads of s, no test of it). */
AVX512 static void z0_octaves2_avx512_g(uint64_t seed, double f, double u,
                                        double v, size_t n, double *val,
                                        double *gx, double *gy) {
  z0_octaves8(seed, NULL, f, u, v, n, val, gx, gy, 1);
}

AVX512 static void z0_octaves2_avx512_v(uint64_t seed, double f, double u,
                                        double v, size_t n, double *val) {
  z0_octaves8(seed, NULL, f, u, v, n, val, NULL, NULL, 0);
}
#endif

#ifndef HAVE_AVX512
static int have_avx512(void) {
  return 0;
}
#endif

/* The points through AVX-512 when avx (the processor has it), else the
** two-lane path. */
static inline void z0_multi(int avx, const uint64_t *seeds, const double *x,
                            const double *y, size_t n, double *val, double *gx,
                            double *gy) {
  int wg = gx && gy;
#ifdef HAVE_AVX512
  if (avx) {
    if (wg)
      z0_multi_avx512_g(seeds, x, y, n, val, gx, gy);
    else
      z0_multi_avx512_v(seeds, x, y, n, val);
    return;
  }
#else
  (void)avx;
#endif
  if (wg)
    z0_multi_sse2(seeds, x, y, n, val, gx, gy, 1);
  else
    z0_multi_sse2(seeds, x, y, n, val, NULL, NULL, 0);
}

uint64_t oc_noise_octave_seed(uint64_t seed, int i) {
  return oc_mix64(seed + OCTAVE_SEED_STEP * (uint64_t)(i + 1));
}

/* oc_noise3_z0_octaves through AVX-512 when avx, else the two-lane path
** on the seeds and points made here. */
static inline void z0_octaves(int avx, uint64_t seed, const double *s, double u,
                              double v, size_t n, double *val, double *gx,
                              double *gy) {
#ifdef HAVE_AVX512
  if (avx) {
    if (gx && gy)
      z0_octaves_avx512_g(seed, s, u, v, n, val, gx, gy);
    else
      z0_octaves_avx512_v(seed, s, u, v, n, val);
    return;
  }
#else
  (void)avx;
#endif
  uint64_t sd[OC_NOISE_MAXOCT];
  double px[OC_NOISE_MAXOCT], py[OC_NOISE_MAXOCT];
  for (size_t i = 0; i < n; i++) {
    sd[i] = oc_noise_octave_seed(seed, (int)i);
    px[i] = s[i] * u, py[i] = s[i] * v;
  }
  z0_multi(0, sd, px, py, n, val, gx, gy);
}

/* oc_noise3_z0_octaves2: z0_octaves of the frequencies f 2^m, made in
** the lanes under AVX-512, else doubled here as a disc's loop did. */
static inline void z0_octaves2(int avx, uint64_t seed, double f, double u,
                               double v, size_t n, double *val, double *gx,
                               double *gy) {
#ifdef HAVE_AVX512
  if (avx) {
    if (gx && gy)
      z0_octaves2_avx512_g(seed, f, u, v, n, val, gx, gy);
    else
      z0_octaves2_avx512_v(seed, f, u, v, n, val);
    return;
  }
#else
  (void)avx;
#endif
  double s[OC_NOISE_MAXOCT];
  for (size_t i = 0; i < n; i++, f *= 2)
    s[i] = f;
  z0_octaves(0, seed, s, u, v, n, val, gx, gy);
}

int oc_noise_isa_supported(oc_noise_isa isa) {
  switch (isa) {
  case OC_NOISE_ISA_AUTO:
  case OC_NOISE_ISA_SSE2:
    return 1;
  case OC_NOISE_ISA_AVX512:
    return have_avx512();
  }
  return 0;
}

int oc_noise3_z0_multi_isa(oc_noise_isa isa, const uint64_t *seeds,
                           const double *x, const double *y, size_t n,
                           double *val, double *gx, double *gy) {
  if (!oc_noise_isa_supported(isa)) return -1;
  z0_multi(isa == OC_NOISE_ISA_AVX512 ||
               (isa == OC_NOISE_ISA_AUTO && have_avx512()),
           seeds, x, y, n, val, gx, gy);
  return 0;
}

void oc_noise3_z0_multi(const uint64_t *seeds, const double *x, const double *y,
                        size_t n, double *val, double *gx, double *gy) {
  z0_multi(have_avx512(), seeds, x, y, n, val, gx, gy);
}

int oc_noise3_z0_octaves_isa(oc_noise_isa isa, uint64_t seed, const double *s,
                             double u, double v, size_t n, double *val,
                             double *gx, double *gy) {
  if (!oc_noise_isa_supported(isa) || n > OC_NOISE_MAXOCT) return -1;
  z0_octaves(isa == OC_NOISE_ISA_AVX512 ||
                 (isa == OC_NOISE_ISA_AUTO && have_avx512()),
             seed, s, u, v, n, val, gx, gy);
  return 0;
}

void oc_noise3_z0_octaves(uint64_t seed, const double *s, double u, double v,
                          size_t n, double *val, double *gx, double *gy) {
  z0_octaves(have_avx512(), seed, s, u, v, n, val, gx, gy);
}

int oc_noise3_z0_octaves2_isa(oc_noise_isa isa, uint64_t seed, double f,
                              double u, double v, size_t n, double *val,
                              double *gx, double *gy) {
  if (!oc_noise_isa_supported(isa) || n > OC_NOISE_MAXOCT) return -1;
  z0_octaves2(isa == OC_NOISE_ISA_AVX512 ||
                  (isa == OC_NOISE_ISA_AUTO && have_avx512()),
              seed, f, u, v, n, val, gx, gy);
  return 0;
}

void oc_noise3_z0_octaves2(uint64_t seed, double f, double u, double v,
                           size_t n, double *val, double *gx, double *gy) {
  z0_octaves2(have_avx512(), seed, f, u, v, n, val, gx, gy);
}

double oc_turb3(uint64_t seed, int octaves, oc_vec3 p, oc_vec3 *grad) {
  /* Octave k is 2^-k n_k(2^k p): its gradient is grad n_k(2^k p) as the two
  ** powers cancel. Both powers are exact, so the octaves stay exact
  ** rescalings of p. */
  double t = 0, freq = 1, amp = 1;
  oc_vec3 g = {0, 0, 0};
  /* Reducing first gives the same octaves (2^k (p mod P) and 2^k p agree
  ** modulo P) but keeps 2^k p from overflowing. */
  if (is_huge(p) && isfinite(p.x) && isfinite(p.y) && isfinite(p.z))
    p = reduce(p);
  for (int o = 0; o < octaves; o++) {
    oc_vec3 q = {p.x * freq, p.y * freq, p.z * freq}, gk;
    t += amp * oc_noise3(oc_hash2(seed, (uint64_t)o), q, grad ? &gk : NULL);
    if (grad) g.x += gk.x, g.y += gk.y, g.z += gk.z;
    freq *= 2;
    amp *= 0.5;
  }
  if (grad) *grad = g;
  return t;
}

double oc_turb3_max(int octaves) {
  return octaves > 0 ? 2 - ldexp(1, 1 - octaves) : 0;
}

double oc_turb3_lipschitz(int octaves) {
  return octaves > 0 ? octaves * oc_noise3_lipschitz : 0;
}
