/*
** test_elevation_memory.c — the storage of elevation-tree nodes
** (enode.h): each kind's bytes (at most 100 a node, a blend's children
** and an add's slope weight aside), statistics that count the data of curves,
*lakes and images (a
** grid shared by two images once), and the float boxes and bounds rounded
** outward: on random trees every stored bound contains the one
** construction in doubles gives (oc_enode_exact), within float rounding,
** and what scripts see (e:bounds(), e:lipschitz()) is that exact one.
*/
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/curve.h"
#include "elevation/enode.h"
#include "ocheck.h"

/* e, which must have been made (else err's message fails the test) */
static oc_enode *made(oc_enode *e, const oc_error *err) {
  ck_assert_msg(e != NULL, "%s", err->msg);
  return e;
}
#define EOK(expr) made((expr), &err)

static oc_enode *disc(double cx, double cy, double r, double h,
                      oc_enoise_kind kind, double gain, uint64_t seed) {
  oc_error err;
  oc_enode_disc_params p = {
      cx, cy, r, h, {kind, 0.3 * fabs(h) + 1, r / 2, 5, gain, 0, seed}};
  return EOK(oc_enode_disc(&p, &err));
}

static size_t bytes_of(const oc_enode *e) {
  oc_error err;
  oc_enode_stats st;
  ck_assert_int_eq(oc_enode_get_stats(e, &st, &err), OC_OK);
  return st.bytes;
}

static oc_enode *river(int npts, double len) {
  oc_error err;
  oc_vec3 pts[64];
  for (int i = 0; i < npts; i++) {
    double t = (double)i / (npts - 1);
    pts[i] = (oc_vec3){len * (t - 0.5), 0.1 * len * sin(6 * t), 30 - 10 * t};
  }
  oc_enode_river_params p = {
      pts, (size_t)npts, OC_ECURVE_CATMULL, OC_RIVER_STREAM, 0, 0, 0};
  return EOK(oc_enode_river(&p, &err));
}

static oc_heightfield *grid(int n) {
  oc_error err;
  float *z = malloc((size_t)n * n * sizeof *z);
  for (int i = 0; i < n * n; i++)
    z[i] = (float)(10 * sin(0.3 * (i % n)) * cos(0.2 * (i / n)));
  oc_heightfield *hf = oc_heightfield_new(n, n, 1, 0, 0, z, &err);
  free(z);
  ck_assert_msg(hf != NULL, "%s", err.msg);
  return hf;
}

static oc_enode *image(oc_heightfield *hf, double x0) {
  oc_error err;
  oc_enode_image_params p = {0};
  p.heightfield = hf;
  double q[8] = {x0, 0, x0 + 100, 0, x0 + 100, 80, x0, 80};
  for (int k = 0; k < 8; k++)
    p.quad[k] = q[k];
  return EOK(oc_enode_image(&p, &err));
}

/* An image of hf along a winding curve through pts (5 points), 30 wide. */
static const oc_vec3 WIND[5] = {
    {0, 0, 0}, {100, 40, 0}, {200, -20, 0}, {300, 30, 0}, {400, 0, 0}};
static oc_enode *image_along(oc_heightfield *hf) {
  oc_error err;
  oc_enode_image_params p = {0};
  p.heightfield = hf;
  p.curve = WIND, p.ncurve = 5, p.spline = OC_ECURVE_CATMULL, p.width = 30;
  return EOK(oc_enode_image(&p, &err));
}

/* The bytes an image along WIND (width 30) holds for its curve: the
** skeleton, its flattening within eimage.c's tolerance and the chords'
** box tree (a power of two of leaves, twice as many boxes of 4 doubles). */
static size_t wind_curve_bytes(void) {
  oc_error err;
  oc_pcurve *c = oc_ecurve_skeleton(WIND, 5, OC_ECURVE_CATMULL, &err);
  ck_assert_msg(c != NULL, "%s", err.msg);
  double L = oc_curve_length(c), tol = fmax(fmin(15, L) / 16, 2e-9 * L);
  size_t nv, m;
  ck_assert_int_eq(oc_curve_flatten(c, tol, NULL, 0, &nv, &err), OC_OK);
  for (m = 1; m < nv - 1; m *= 2)
    ;
  size_t b = oc_curve_bytes(c) + nv * sizeof(oc_curve_vertex) +
             2 * m * 4 * sizeof(double);
  oc_curve_free(c);
  return b;
}

START_TEST(bytes_per_kind) {
  oc_error err;
  oc_enode *plain = disc(0, 0, 100, 10, OC_ENOISE_NONE, 0, 1);
  oc_enode *noisy = disc(10, 0, 100, 10, OC_ENOISE_RIDGED, 0, 2);
  oc_enode *fl = disc(0, 10, 100, 10, OC_ENOISE_PLAIN, 0.375, 3);
  oc_enode *odd = disc(0, 10, 100, 10, OC_ENOISE_PLAIN, 0.45, 3);
  oc_enode *riv = river(8, 400);
  double radii[5] = {50, 60, 55, 70, 65};
  oc_enode_lake_params lp = {0, 0, radii, 5, NULL, 0, 20, NULL, 0, 0, 0, 0};
  oc_enode *lake = EOK(oc_enode_lake(&lp, &err));
  oc_heightfield *hf = grid(33);
  oc_enode *img = image(hf, 0), *img2 = image(hf, 200);
  oc_enode *k2[2] = {plain, noisy};
  oc_enode *bl = EOK(oc_enode_blend(k2, 2, &err));
  oc_enode *rep = EOK(oc_enode_replace(plain, noisy, 0, &err));
  oc_enode *lerp = EOK(oc_enode_replace(plain, noisy, 1, &err));
  oc_enode_add_params ap = {1, 1, 40, 5, 0, 0, 0, 0};
  oc_enode_add_params as = {0, 1, 40, 5, 1, 20, 10, 3};
  oc_enode *add = EOK(oc_enode_add(plain, noisy, NULL, &err));
  oc_enode *addb = EOK(oc_enode_add(plain, noisy, &ap, &err));
  oc_enode *adds = EOK(oc_enode_add(plain, noisy, &as, &err));
  oc_enode_add_params as1 = {1, 0, 0, 0, 1, 12, 10, 0.1},
                      asum = {1, 0, 0, 0, 0, 0, 0, 0};
  oc_enode *adds1 = EOK(oc_enode_add(noisy, plain, &as1, &err));
  as1.below = 1, as1.below_z = 1e6, as1.fade = 5; /* (a weight of 1) */
  oc_enode *adds2 = EOK(oc_enode_add(noisy, plain, &as1, &err));
  oc_enode *addsum = EOK(oc_enode_add(noisy, plain, &asum, &err));
  oc_enode_xform xf = {3, 4, 30, 2, 1.5, 2};
  oc_enode *moved = EOK(oc_enode_transform(noisy, &xf, &err));
  oc_enode_warp_params wp = {2, 200, 3, 9};
  oc_enode *warp = EOK(oc_enode_warp(noisy, &wp, &err));
  oc_enode_lod_params lo = {50, 0, 1};
  oc_enode *lod = EOK(oc_enode_lod(plain, noisy, &lo, &err));
  /* every kind at 100 bytes or less, the exact layouts of enode.h */
  struct {
    oc_enode *e;
    size_t bytes;
  } want[] = {{plain, 40}, {noisy, 80}, {fl, 88},    {odd, 96},   {riv, 96},
              {lake, 96},  {img, 96},   {bl, 72},    {rep, 64},   {lerp, 64},
              {add, 64},   {addb, 80},  {adds, 100}, {adds1, 88}, {moved, 96},
              {warp, 72},  {lod, 88}};
  for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
    ck_assert_msg(oc_enode_size(want[i].e) == want[i].bytes,
                  "%s (%zu): %zu bytes, want %zu", oc_enode_kind(want[i].e), i,
                  oc_enode_size(want[i].e), want[i].bytes);
    ck_assert_uint_le(oc_enode_size(want[i].e), 100);
  }
  /* a replace keeps its weight in a flag; an add its weights' flags, the
  ** altitude weight's two parameters and the slope weight's three (the
  ** step a float when it is one exactly, as 3 is; 0.1 is not, and with
  ** both weights that add is the one node over 100 bytes); counted in
  ** the statistics, and each add evaluates as its parameters say */
  ck_assert_uint_eq(oc_enode_size(adds2), 64 + 2 * 8 + 3 * 8);
  ck_assert_uint_eq(bytes_of(adds),
                    oc_enode_size(adds) + bytes_of(plain) + bytes_of(noisy));
  ck_assert_uint_eq(bytes_of(addb), 80 + bytes_of(plain) + bytes_of(noisy));
  int differ = 0, sloped = 0;
  for (int i = 0; i < 400; i++) {
    double x = -60 + (i % 20) * 6, y = -60 + (i / 20) * 6;
    oc_enode_sample s1, s2, s0;
    oc_enode_eval(adds1, x, y, &s1);
    oc_enode_eval(adds2, x, y, &s2);
    oc_enode_eval(addsum, x, y, &s0);
    differ += s1.f != s2.f || s1.a != s2.a || s1.fx != s2.fx || s1.fy != s2.fy;
    sloped += s1.f != s0.f; /* where the slope weight lets noisy in */
  }
  ck_assert_int_eq(differ, 0);
  ck_assert_int_gt(sloped, 20);
  /* a blend: 56 bytes and 8 a child */
  oc_enode *k5[5] = {plain, noisy, odd, rep, add};
  oc_enode *b5 = EOK(oc_enode_blend(k5, 5, &err));
  ck_assert_uint_eq(oc_enode_size(b5), 56 + 5 * 8);
  /* the data counts: a river's skeleton grows with its points, an image
  ** holds its grid (33 x 33 floats) and its pyramid (12 bytes a cell) */
  oc_enode *riv2 = river(16, 400);
  ck_assert_uint_gt(bytes_of(riv), oc_enode_size(riv) + 8 * 24);
  ck_assert_uint_gt(bytes_of(riv2), bytes_of(riv) + 8 * 24);
  size_t gb = 33 * 33 * sizeof(float);
  ck_assert_uint_ge(bytes_of(img), 96 + gb + 32 * 32 * 12);
  ck_assert_uint_gt(bytes_of(lake), 96 + 5 * 16);
  /* an image along a curve: the quad's bytes and its curve's */
  oc_enode *imgc = image_along(hf);
  ck_assert_uint_eq(oc_enode_size(imgc), 96);
  ck_assert_uint_eq(bytes_of(imgc), bytes_of(img) + wind_curve_bytes());
  ck_assert_uint_gt(wind_curve_bytes(), 4 * 250);
  /* two images on one grid: the grid once; a DAG's shared node once */
  oc_enode *ki[3] = {img, img2, img};
  oc_enode *bi = EOK(oc_enode_blend(ki, 3, &err));
  ck_assert_uint_eq(bytes_of(bi),
                    oc_enode_size(bi) + bytes_of(img) + bytes_of(img2) - gb);
  /* the nodes alone, and a river's data: its record (with its profiles'
  ** range of heights) and its profile's place (80), the profile's 6 knots
  *(doubles: the stream's depth 0.8 is
  ** no float; 8 + 96) and the skeleton (572: 8 points kept, control
  ** points derived); a profile the same as the one before is stored once,
  ** and knots that are floats exactly take 4 bytes each */
  oc_enode_stats st;
  ck_assert_int_eq(oc_enode_get_stats(riv, &st, &err), OC_OK);
  ck_assert_uint_eq(st.node_bytes, 96);
  ck_assert_uint_eq(st.bytes, 96 + 80 + 104 + 572);
  ck_assert_int_eq(oc_enode_get_stats(bi, &st, &err), OC_OK);
  ck_assert_uint_eq(st.node_bytes, oc_enode_size(bi) + oc_enode_size(img) +
                                       oc_enode_size(img2));
  oc_vec3 pts[8];
  for (int i = 0; i < 8; i++)
    pts[i] = (oc_vec3){50.0 * i, 20 * sin(i), 5};
  double kx[6] = {-30, -10, -5, 5, 10, 30}, kv[6] = {0, -1, -2, -2, -1, 0};
  double kx3[6] = {-30, -10, -5, 5, 10, 30.1};
  oc_enode_profile pr[3] = {{0, kx, kv, 6}, {0.5, kx, kv, 6}, {1, kx3, kv, 6}};
  oc_enode_curve_params cp = {pts, 8, OC_ECURVE_CATMULL, 40, 5, pr, 2};
  oc_enode *one = EOK(oc_enode_curve(&cp, &err));
  cp.nprofiles = 1;
  oc_enode *single = EOK(oc_enode_curve(&cp, &err));
  cp.nprofiles = 3;
  oc_enode *three = EOK(oc_enode_curve(&cp, &err));
  /* (16 bytes a profile's place and arc length; 30.1 is no float: 8 + 96) */
  ck_assert_uint_eq(bytes_of(one), bytes_of(single) + 16);
  ck_assert_uint_eq(bytes_of(three), bytes_of(single) + 32 + 8 + 96);
  oc_pcurve *sk = oc_ecurve_skeleton(pts, 8, OC_ECURVE_CATMULL, &err);
  ck_assert_msg(sk != NULL, "%s", err.msg);
  ck_assert_uint_eq(bytes_of(single), 96 + 80 + 8 + 48 + oc_curve_bytes(sk));
  oc_curve_free(sk);
  oc_enode_release(one);
  oc_enode_release(single);
  oc_enode_release(three);
  oc_enode *all[] = {fl,  plain, noisy, odd, riv,  lake,  img,   img2,
                     bl,  rep,   lerp,  add, addb, adds,  moved, warp,
                     lod, b5,    riv2,  bi,  imgc, adds1, adds2, addsum};
  for (size_t i = 0; i < sizeof all / sizeof *all; i++)
    oc_enode_release(all[i]);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(floats_round_outward) {
  uint64_t s = 12345;
  for (int i = 0; i < 100000; i++) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    double m = (double)(s >> 11) / 9007199254740992.0 - 0.5;
    double v = ldexp(m, (int)(s % 200) - 100);
    float d = oc_efloat_down(v), u = oc_efloat_up(v);
    ck_assert((double)d <= v && (double)u >= v);
    /* the nearest floats on their side */
    ck_assert((double)nextafterf(d, INFINITY) > v || (double)d == v);
    ck_assert((double)nextafterf(u, -INFINITY) < v || (double)u == v);
  }
  ck_assert(oc_efloat_down(1e300) <= 1e300 && oc_efloat_up(1e300) == INFINITY);
  ck_assert(oc_efloat_up(-1e300) >= -1e300 &&
            oc_efloat_down(-1e300) == -INFINITY);
}
END_TEST

/* ---- random trees ------------------------------------------------------ */

static uint64_t rng = 99;
static double urand(double a, double b) {
  rng = rng * 6364136223846793005ull + 1442695040888963407ull;
  return a + (b - a) * (double)(rng >> 11) / 9007199254740992.0;
}

/* Stored (possibly float) bound and box against the exact ones: contained,
** and no looser than float rounding through depth levels allows. */
static void check_contains(const oc_enode *e) {
  oc_ebound g, x;
  oc_erect gb = oc_enode_box(e), xb;
  oc_enode_glob(e, &g);
  oc_enode_exact(e, &x, &xb);
  const char *k = oc_enode_kind(e);
  ck_assert_msg(g.flo <= x.flo && g.fhi >= x.fhi,
                "%s: f [%.17g, %.17g] vs %.17g %.17g", k, g.flo, g.fhi, x.flo,
                x.fhi);
  ck_assert_msg(g.alo <= x.alo && g.ahi >= x.ahi, "%s: alpha", k);
  ck_assert_msg(g.lf >= x.lf && g.la >= x.la, "%s: Lipschitz %.17g vs %.17g", k,
                g.lf, x.lf);
  ck_assert_msg(gb.x0 <= xb.x0 && gb.y0 <= xb.y0 && gb.x1 >= xb.x1 &&
                    gb.y1 >= xb.y1,
                "%s: box", k);
  /* and close: a relative 1e-5 (float rounding, compounded) */
  double sf = 1e-5 * (1 + fabs(x.flo) + fabs(x.fhi));
  ck_assert_msg(x.flo - g.flo <= sf && g.fhi - x.fhi <= sf, "%s: f loose", k);
  /* (the slope terms of replace and add hold differences of f: their
  ** rounding is relative to f's size) */
  ck_assert_msg(g.lf - x.lf <=
                    1e-5 * (x.lf + 0.1 * (1 + fabs(x.flo) + fabs(x.fhi))),
                "%s: lf loose %.17g vs %.17g", k, g.lf, x.lf);
  double sb = 1e-5 * (fabs(xb.x0) + fabs(xb.x1) + fabs(xb.y0) + fabs(xb.y1));
  ck_assert_msg(xb.x0 - gb.x0 <= sb && gb.x1 - xb.x1 <= sb, "%s: box loose", k);
}

static oc_enode *random_node(oc_enode **pool, int n, int *is_new) {
  oc_error err;
  int op = n < 4 ? 0 : (int)urand(0, 8);
  *is_new = 1;
  oc_enode *a = pool[(int)urand(0, n)], *b = pool[(int)urand(0, n)];
  switch (op) {
  case 0: {
    oc_enoise_kind k = (oc_enoise_kind)(int)urand(0, 4);
    return disc(urand(-1000, 1000) + 0.1, urand(-1000, 1000), urand(50, 700),
                urand(-50, 300), k, urand(0, 1) < 0.5 ? 0 : urand(0.3, 0.7),
                (uint64_t)urand(0, 1e9));
  }
  case 1: {
    oc_enode *k[4];
    int m = 2 + (int)urand(0, 3);
    for (int i = 0; i < m; i++)
      k[i] = pool[(int)urand(0, n)];
    return EOK(oc_enode_blend(k, (size_t)m, &err));
  }
  case 2:
    return EOK(oc_enode_replace(a, b, urand(0, 1) < 0.5, &err));
  case 3: {
    /* half of them with a slope weight (their bounds take A's slope) */
    oc_enode_add_params p = {
        urand(0, 1) < 0.5, urand(0, 1) < 0.5, urand(0, 200), urand(1, 50),
        urand(0, 1) < 0.5, urand(0, 60),      urand(1, 20),  urand(0.5, 20)};
    return EOK(oc_enode_add(a, b, &p, &err));
  }
  case 4: {
    oc_enode_xform x = {urand(-500, 500), urand(-500, 500), urand(0, 360),
                        urand(0.3, 3),    urand(-2, 2),     urand(-20, 20)};
    if (x.vscale == 0) x.vscale = 1;
    return EOK(oc_enode_transform(a, &x, &err));
  }
  case 5: {
    oc_enode_warp_params w = {urand(0, 5), urand(300, 900),
                              1 + (int)urand(0, 3), (uint64_t)urand(0, 1e9)};
    return EOK(oc_enode_warp(a, &w, &err));
  }
  case 6: {
    oc_enode_lod_params l = {urand(10, 500), urand(0, 0.4), urand(0.5, 1)};
    return EOK(oc_enode_lod(a, b, &l, &err));
  }
  default:
    *is_new = 0;
    return pool[(int)urand(0, n)];
  }
}

START_TEST(rounded_bounds_contain_exact) {
  for (int tree = 0; tree < 40; tree++) {
    oc_enode *pool[80];
    int n = 0;
    while (n < 80) {
      int fresh;
      oc_enode *e = random_node(pool, n, &fresh);
      if (!fresh) continue;
      check_contains(e);
      pool[n++] = e;
    }
    for (int i = 0; i < n; i++)
      oc_enode_release(pool[i]);
  }
}
END_TEST

START_TEST(scripts_see_exact_bounds) {
  oc_error err;
  /* 0.1 - 250 and friends are not floats: the float box is wider, the
  ** box that e:bounds() gives is the double one */
  oc_enode *a = disc(0.1, 0.3, 250, 10, OC_ENOISE_NONE, 0, 1);
  oc_enode *b = disc(300.7, -0.9, 100.3, 20, OC_ENOISE_NONE, 0, 1);
  oc_enode *k[2] = {a, b};
  oc_enode *e = EOK(oc_enode_blend(k, 2, &err));
  double box[4], lo, hi;
  oc_enode_get_bounds(e, box, &lo, &hi);
  ck_assert(box[0] == 0.1 - 250 && box[1] == 0.3 - 250 &&
            box[2] == 300.7 + 100.3 && box[3] == 0.3 + 250);
  ck_assert(lo == 0 && hi == 20);
  oc_erect fb = oc_enode_box(e);
  ck_assert(fb.x0 < box[0] && fb.y0 < box[1] && fb.x1 == 401 && box[2] == 401 &&
            fb.y1 > box[3]);
  /* (401 is a float) */ /* rounded outward */
  /* the Lipschitz bound: blend_combine's in doubles of the discs' */
  oc_ebound ga, gb, x;
  oc_erect xb;
  oc_enode_glob(a, &ga);
  oc_enode_glob(b, &gb);
  oc_enode_exact(e, &x, &xb);
  ck_assert(oc_enode_lipschitz(e) == x.lf);
  ck_assert(x.lf > 0 && (double)oc_efloat_up(x.lf) >= x.lf);
  oc_enode_release(a);
  oc_enode_release(b);
  oc_enode_release(e);
}
END_TEST

int main(void) {
  Suite *s = suite_create("elevation_memory");
  TCase *tc = tcase_create("memory");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, bytes_per_kind);
  tcase_add_test(tc, floats_round_outward);
  tcase_add_test(tc, rounded_bounds_contain_exact);
  tcase_add_test(tc, scripts_see_exact_bounds);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
