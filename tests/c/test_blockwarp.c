/*
** test_blockwarp.c — gradient-based warping (Paris et al. 2020, section
** 4.2): the warp's formula against a reference written here, its
** analytic gradient, its stated Lipschitz bound (the formula, and random
** pairs), its support, an image relief displacing a plane by the
** bilinear relief exactly; and the errors naming the parameter.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/noise.h"
#include "ocheck.h"
#include "outcrop.h"

/* a sphere of radius 1 with a 0.5 m falloff, energy 1: f = T = 0.5 about
** 1.2 m from its centre */
static oc_node *ball(void) {
  oc_error e = {0};
  return OCT_OK(oc_sphere(oct_v(0, 0, 0), 1, 0.5, 1, &e));
}

static oc_node *warped(oc_node *child, double amp, double wl, int oct) {
  oc_relief_params rp;
  oc_relief_defaults(&rp);
  rp.amplitude = amp;
  rp.wavelength = wl;
  rp.octaves = oct;
  rp.seed = 5;
  oc_error e = {0};
  return OCT_OK(oc_relief_warp(child, &rp, &e));
}

static oc_btile *small_tile(uint64_t seed) {
  oc_btile_params pp;
  oc_btile_defaults(OC_BLOCKS_EQUIDIMENSIONAL, &pp);
  pp.size = 8;
  pp.radius = 0.5;
  pp.disc_lo = 2;
  pp.disc_hi = 3;
  pp.spacing = 1;
  pp.seed = seed;
  oc_error e = {0};
  oc_btile *t = oc_btile_new(&pp, &e);
  ck_assert_msg(t != NULL, "oc_btile_new: %s", e.msg);
  return t;
}

/* The warp's formula, written again from the paper's definition (with
** the tetrahedral gradient and the fading of relief.c): f(p + u s). */
static double reference(const oc_program *child, double L, oc_vec3 p,
                        double amp, double wl, int oct, uint64_t seed) {
  static const double E[4][3] = {
      {1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
  double h = 4 * amp, G[3] = {0, 0, 0};
  for (int k = 0; k < 4; k++) {
    double f = oc_program_eval(
        child, oct_v(p.x + h * E[k][0], p.y + h * E[k][1], p.z + h * E[k][2]));
    for (int a = 0; a < 3; a++)
      G[a] += E[k][a] * f / (4 * h);
  }
  double n = sqrt(G[0] * G[0] + G[1] * G[1] + G[2] * G[2]);
  double m = fmax(n, L / 2), u[3] = {G[0] / m, G[1] / m, G[2] / m};
  double l1 = fabs(u[0]) + fabs(u[1]) + fabs(u[2]);
  if (l1 == 0) return oc_program_eval(child, p); /* no gradient: no warp */
  double tmax = 2 - pow(2, 1 - oct);
#define D(x, y)                                                                \
  (amp *                                                                       \
   (2 * oc_turb3(seed, oct, oct_v((x) / wl, (y) / wl, 0), NULL) / tmax - 1))
  double s = fabs(u[2]) / l1 * D(p.x, p.y) + fabs(u[1]) / l1 * D(p.x, p.z) +
             fabs(u[0]) / l1 * D(p.y, p.z);
#undef D
  return oc_program_eval(child,
                         oct_v(p.x + u[0] * s, p.y + u[1] * s, p.z + u[2] * s));
}

START_TEST(relief_formula) {
  oc_node *b = ball();
  oc_node_retain(b);
  oc_program *pc = oct_compile(b, 0.5, 0);
  double L = oc_program_lipschitz(pc);
  oc_program *pw = oct_compile(warped(b, 0.08, 0.3, 3), 0.5, 0);
  oc_node_release(b);
  oct_rng r = oct_rng_new(3);
  double moved = 0;
  for (int k = 0; k < 500; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-1.6, -1.6, -1.6), oct_v(1.6, 1.6, 1.6));
    double want = reference(pc, L, p, 0.08, 0.3, 3, 5),
           got = oc_program_eval(pw, p);
    ck_assert_double_eq_tol(got, want, 1e-12);
    moved = fmax(moved, fabs(got - oc_program_eval(pc, p)));
  }
  /* the relief shows: somewhere the field changed by a good part of
  ** A times the slope (about 1.7) */
  ck_assert_double_gt(moved, 0.05);
  oc_program_free(pc);
  oc_program_free(pw);
}
END_TEST

/* amplitude 0: the field itself, bit for bit */
START_TEST(relief_zero_amplitude) {
  oc_node *b = ball();
  oc_node_retain(b);
  oc_program *pc = oct_compile(b, 0.5, 0);
  oc_program *pw = oct_compile(warped(b, 0, 1, 2), 0.5, 0);
  oc_node_release(b);
  oct_rng r = oct_rng_new(4);
  for (int k = 0; k < 300; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-2, -2, -2), oct_v(2, 2, 2));
    ck_assert(oc_program_eval(pw, p) == oc_program_eval(pc, p));
  }
  ck_assert_double_eq(oc_program_lipschitz(pw), oc_program_lipschitz(pc));
  oc_program_free(pc);
  oc_program_free(pw);
}
END_TEST

/* The analytic gradient, the Lipschitz bound (its formula and random
** pairs), the support (the child's grown by A), on a sphere and on a
** block of a tile. */
START_TEST(relief_gradient_lipschitz_support) {
  oc_error e = {0};
  oc_btile *t = small_tile(3);
  oc_node *kids[2] = {ball(), OCT_OK(oc_btile_block(t, 0, &e))};
  oc_btile_free(t);
  for (int i = 0; i < 2; i++) {
    oc_node_retain(kids[i]);
    oc_program *pc = oct_compile(kids[i], 0.5, 0);
    double amp = 0.06, wl = 0.4;
    int oct = 3;
    oc_program *pw = oct_compile(warped(kids[i], amp, wl, oct), 0.5, 0);
    oc_node_release(kids[i]);
    oc_aabb cb = oc_program_bounds(pc), wb = oc_program_bounds(pw);
    ck_assert_double_eq_tol(wb.lo.x, cb.lo.x - amp, 1e-9);
    ck_assert_double_eq_tol(wb.hi.z, cb.hi.z + amp, 1e-9);
    /* the stated bound: L (1 + L_d + 2 (1 + 2 sqrt 3) A / h), h = 4 A */
    double L = oc_program_lipschitz(pc);
    double tmax = oc_turb3_max(oct);
    double Ld = 2 * amp * oc_turb3_lipschitz(oct) / (tmax * wl);
    double want = L * (1 + Ld + 2 * (1 + 2 * sqrt(3)) * amp / (4 * amp));
    ck_assert_double_eq_tol(oc_program_lipschitz(pw), want, 1e-9 * want);
    oct_rng r = oct_rng_new(7 + i);
    double ratio = oct_check_lipschitz(pw, wb.lo, wb.hi, 3000, &r);
    printf("relief_warp %s: L %.3f, bound %.3f, largest seen / bound %.3f\n",
           i ? "block" : "sphere", L, want, ratio);
    ck_assert_double_le(ratio, 1);
    /* the warp steepens the field: pairs beat the child's own bound */
    ck_assert_double_gt(ratio * want, L);
    ck_assert_int_gt(oct_check_bounds(pw, wb.lo, wb.hi, 2000, &r), 0);
    for (int k = 0; k < 300; k++)
      oct_check_grad(pw, oct_in_box(&r, wb.lo, wb.hi), 1e-6, 1e-4);
    oc_program_free(pc);
    oc_program_free(pw);
  }
}
END_TEST

/* An image relief on a horizontal plane: the surface rises by the
** bilinear relief d(x, y) = A (2 v - 1) exactly. */
START_TEST(relief_image_plane) {
  const char *dir = oct_tmpdir("relief");
  char path[256];
  snprintf(path, sizeof path, "%s/r.png", dir);
  /* 4 x 4 grey, values k / 255; image row 0 is the top (v = 3 cells) */
  static const int px[4][4] = {{0, 255, 51, 102},
                               {204, 153, 0, 255},
                               {17, 34, 68, 136},
                               {255, 0, 0, 85}};
  oc_error e = {0};
  oc_image *im = oc_image_new(4, 4, 1, &e);
  ck_assert_ptr_nonnull(im);
  for (int j = 0; j < 4; j++)
    for (int i = 0; i < 4; i++)
      oc_image_data(im)[j * 4 + i] = px[j][i] / 255.0f;
  ck_assert_int_eq(oc_image_write(im, path, 8, &e), OC_OK);
  oc_image_free(im);
  oc_node *plane = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e));
  oc_node_retain(plane);
  oc_program *pc = oct_compile(plane, 0.5, 0);
  oc_relief_params rp;
  oc_relief_defaults(&rp);
  rp.kind = OC_RELIEF_IMAGE;
  rp.path = path;
  rp.wavelength = 2; /* 4 pixels over 2 m: cell 0.5 */
  rp.amplitude = 0.1;
  oc_program *pw = oct_compile(OCT_OK(oc_relief_warp(plane, &rp, &e)), 0.5, 0);
  oc_node_release(plane);
  /* the unwarped surface: f = 0.5 at z0 */
  double lo = -1, hi = 1;
  for (int k = 0; k < 60; k++) {
    double m = 0.5 * (lo + hi);
    *(oc_program_eval(pc, oct_v(0, 0, m)) > 0.5 ? &lo : &hi) = m;
  }
  double z0 = 0.5 * (lo + hi);
  oct_rng r = oct_rng_new(9);
  for (int k = 0; k < 40; k++) {
    double x = oct_unif(&r, -3, 3), y = oct_unif(&r, -3, 3);
    /* bilinear, periodic, sample (i, j) at (0.5 i, 0.5 j), j from the
    ** bottom row */
    double u = x / 0.5, v = y / 0.5, fu = floor(u), fv = floor(v);
    int i0 = (int)(fu - 4 * floor(fu / 4)), j0 = (int)(fv - 4 * floor(fv / 4));
    int i1 = (i0 + 1) % 4, j1 = (j0 + 1) % 4;
#define P(i, j) (px[3 - (j)][(i)] / 255.0)
    double b0 = P(i0, j0) + (u - fu) * (P(i1, j0) - P(i0, j0)),
           b1 = P(i0, j1) + (u - fu) * (P(i1, j1) - P(i0, j1));
#undef P
    double d = 0.1 * (2 * (b0 + (v - fv) * (b1 - b0)) - 1);
    lo = -1, hi = 1;
    for (int it = 0; it < 60; it++) {
      double m = 0.5 * (lo + hi);
      *(oc_program_eval(pw, oct_v(x, y, m)) > 0.5 ? &lo : &hi) = m;
    }
    ck_assert_double_eq_tol(0.5 * (lo + hi), z0 + d, 1e-7);
  }
  /* L_d = 2 A |(m_x, m_y)| / cell: m_x = 1 (0 -> 255), m_y = 1 */
  double L = oc_program_lipschitz(pc);
  double want =
      L * (1 + 2 * 0.1 * sqrt(2) / 0.5 + 2 * (1 + 2 * sqrt(3)) * 0.1 / 0.4);
  ck_assert_double_eq_tol(oc_program_lipschitz(pw), want, 1e-9 * want);
  oc_program_free(pc);
  oc_program_free(pw);
  unlink(path);
  rmdir(dir);
}
END_TEST

START_TEST(relief_errors) {
  oc_node *b = ball();
  oc_relief_params rp;
  oc_error e = {0};
  oc_relief_defaults(&rp);
  rp.amplitude = NAN;
  OCT_EINVAL(oc_relief_warp(b, &rp, &e), e, "amplitude");
  oc_relief_defaults(&rp);
  rp.wavelength = 0;
  OCT_EINVAL(oc_relief_warp(b, &rp, &e), e, "relief.wavelength");
  oc_relief_defaults(&rp);
  rp.octaves = 17;
  OCT_EINVAL(oc_relief_warp(b, &rp, &e), e, "relief.octaves");
  oc_relief_defaults(&rp);
  rp.step = -1;
  OCT_EINVAL(oc_relief_warp(b, &rp, &e), e, "step");
  oc_relief_defaults(&rp);
  rp.kind = OC_RELIEF_IMAGE;
  rp.path = "/nonexistent/relief.png";
  ck_assert_ptr_null(oc_relief_warp(b, &rp, &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_msg(strstr(e.msg, "/nonexistent/relief.png") != NULL, "%s", e.msg);
  oc_node_release(b);
}
END_TEST

/* ---- replication with an inset ------------------------------------------ */

static oc_node *replicated(oc_node *ter, const oc_btile *t, double inset,
                           oc_error *e) {
  oc_replicate_tile rt = {t, 0, 0};
  oc_replicate_params rp;
  oc_replicate_defaults(&rp);
  rp.tiles = &rt;
  rp.ntiles = 1;
  rp.slope = 0.5;
  rp.inset = inset;
  return oc_blocks_replicate(ter, &rp, e);
}

START_TEST(replicate_inset) {
  oc_error e = {0};
  /* a 16 x 16 x 10 m box: its wall x = 0 has its surface (f = T) at
  ** x = -0.454 (falloff 1) */
  oc_node *ter = OCT_OK(oc_box(oct_v(0, 0, 0), oct_v(16, 16, 10), 1, 1, &e));
  oc_btile *t = small_tile(4);
  oc_program *pt = oct_compile(ter, 0.5, 0);
  oc_node_retain(ter);
  oc_program *p0 = oct_compile(OCT_OK(replicated(ter, t, 0, &e)), 0.5, 0);
  oc_program *pi = oct_compile(OCT_OK(replicated(ter, t, 0.3, &e)), 0.5, 0);
  /* the bound: L + inset L lip_b / T, lip_b = 1 (sigma's slope) */
  double L = oc_program_lipschitz(pt);
  ck_assert_double_eq_tol(oc_program_lipschitz(pi), L + 0.3 * L / 0.5, 1e-9);
  /* far from blocks (the top's middle) the terrain as it is */
  for (double z = 9; z < 11.5; z += 0.25)
    ck_assert(oc_program_eval(pi, oct_v(8, 8, z)) ==
              oc_program_eval(pt, oct_v(8, 8, z)));
  oct_rng r = oct_rng_new(5);
  for (int k = 0; k < 2000; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-2, -2, -2), oct_v(18, 18, 12));
    double f = oc_program_eval(pt, p), f0 = oc_program_eval(p0, p),
           fi = oc_program_eval(pi, p);
    ck_assert_double_le(fi, f0);
    /* where a block wins, it wins the same with an inset */
    if (f0 > f) ck_assert(fi == f0);
    if (k < 300) oct_check_grad(pi, p, 1e-6, 1e-5);
  }
  ck_assert_double_le(
      oct_check_lipschitz(pi, oct_v(-2, -2, -2), oct_v(18, 18, 12), 2000, &r),
      1);
  /* the plane x = -0.3 lies inside the wall: without an inset all of it
  ** is solid; with one, the joints between the blocks open */
  int n = 0, open0 = 0, openi = 0;
  for (double y = 1; y < 15; y += 0.1)
    for (double z = 1; z < 9; z += 0.1, n++) {
      open0 += oc_program_eval(p0, oct_v(-0.3, y, z)) < 0.5;
      openi += oc_program_eval(pi, oct_v(-0.3, y, z)) < 0.5;
    }
  printf("replicate inset 0.3: %d of %d points of the wall open (0 without)\n",
         openi, n);
  ck_assert_int_eq(open0, 0);
  ck_assert_int_gt(openi, n / 50);
  ck_assert_int_lt(openi, n / 2);
  /* a negative inset is refused */
  oc_node *bad = replicated(ter, t, -1, &e);
  ck_assert_ptr_null(bad);
  ck_assert_msg(strstr(e.msg, "'inset'") != NULL, "%s", e.msg);
  oc_node_release(ter);
  oc_program_free(pt);
  oc_program_free(p0);
  oc_program_free(pi);
  oc_btile_free(t);
}
END_TEST

/* ---- save and load ------------------------------------------------------ */

static unsigned char *read_all(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  ck_assert_ptr_nonnull(f);
  fseek(f, 0, SEEK_END);
  *n = (size_t)ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *b = malloc(*n);
  ck_assert_uint_eq(fread(b, 1, *n, f), *n);
  fclose(f);
  return b;
}

/* Writes b with bytes [at, at + 8) set to v and the checksum made anew (a
** crafted file), then loads it: NULL, OC_EINVAL, `what` in the message. */
static void crafted(const char *path, const unsigned char *b, size_t n,
                    size_t at, uint64_t v, const char *what) {
  unsigned char *c = malloc(n);
  memcpy(c, b, n);
  for (int i = 0; i < 8; i++)
    c[at + (size_t)i] = (unsigned char)(v >> (8 * i));
  oc_sha256 h;
  oc_sha256_init(&h);
  oc_sha256_update(&h, c, n - OC_SHA256_BYTES);
  oc_sha256_final(&h, c + n - OC_SHA256_BYTES);
  FILE *f = fopen(path, "wb");
  ck_assert_uint_eq(fwrite(c, 1, n, f), n);
  fclose(f);
  free(c);
  oc_error e = {0};
  ck_assert_ptr_null(oc_btile_load(path, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_msg(strstr(e.msg, what) != NULL, "'%s' not in: %s", what, e.msg);
}

static uint64_t bits(double v) {
  uint64_t u;
  memcpy(&u, &v, 8);
  return u;
}

START_TEST(tile_save_load) {
  const char *dir = oct_tmpdir("btile");
  char path[256], bad[256];
  snprintf(path, sizeof path, "%s/t.octile", dir);
  snprintf(bad, sizeof bad, "%s/bad.octile", dir);
  oc_btile_params pp;
  oc_btile_defaults(OC_BLOCKS_POLYHEDRAL, &pp);
  pp.size = 8, pp.radius = 0.5, pp.disc_lo = 2, pp.disc_hi = 3;
  pp.spacing = 1, pp.seed = 6;
  oc_block_disc ud = {{4, 4, 4.1}, {0, 0, 1}, 9};
  pp.discs = &ud, pp.ndiscs = 1;
  oc_error e = {0};
  oc_btile *t = oc_btile_new(&pp, &e);
  ck_assert_msg(t != NULL, "%s", e.msg);
  ck_assert_int_eq(oc_btile_save(t, path, &e), OC_OK);
  oc_btile *l = oc_btile_load(path, &e);
  ck_assert_msg(l != NULL, "%s", e.msg);
  oc_btile_stats a, b;
  oc_btile_stats_get(t, &a);
  oc_btile_stats_get(l, &b);
  ck_assert_uint_eq(a.points, b.points);
  ck_assert_uint_eq(a.fractures, b.fractures);
  ck_assert_uint_eq(a.blocks, b.blocks);
  ck_assert_uint_eq(a.edges, b.edges);
  ck_assert_uint_eq(a.cut, b.cut);
  ck_assert_uint_eq(a.thick, b.thick);
  ck_assert_uint_eq(a.separated, b.separated);
  ck_assert_uint_eq(a.merged, b.merged);
  ck_assert(a.points_per_block == b.points_per_block);
  ck_assert(a.seconds == b.seconds);
  ck_assert_uint_gt(a.cut, 0);
  for (size_t i = 0; i < a.blocks; i++) {
    size_t na, nb;
    const double *pa = oc_btile_planes(t, i, &na),
                 *pb = oc_btile_planes(l, i, &nb);
    ck_assert_uint_eq(na, nb);
    ck_assert_int_eq(memcmp(pa, pb, 4 * na * sizeof *pa), 0);
    pa = oc_btile_vertices(t, i, &na);
    pb = oc_btile_vertices(l, i, &nb);
    ck_assert_uint_eq(na, nb);
    ck_assert_int_eq(memcmp(pa, pb, 3 * na * sizeof *pa), 0);
  }
  /* the loaded tile's field equals the original's, bit for bit */
  oc_program *pa = oct_compile(OCT_OK(oc_btile_node(t, &e)), 0.5, 0),
             *pb = oct_compile(OCT_OK(oc_btile_node(l, &e)), 0.5, 0);
  oct_rng r = oct_rng_new(11);
  for (int k = 0; k < 3000; k++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-1, -1, -1), oct_v(9, 9, 9)), ga, gb;
    ck_assert(oc_program_gradient(pa, p, &ga) ==
              oc_program_gradient(pb, p, &gb));
    ck_assert(ga.x == gb.x && ga.y == gb.y && ga.z == gb.z);
  }
  oc_program_free(pa);
  oc_program_free(pb);
  /* saving the loaded tile gives the same bytes */
  ck_assert_int_eq(oc_btile_save(l, bad, &e), OC_OK);
  size_t n, n2;
  unsigned char *buf = read_all(path, &n), *buf2 = read_all(bad, &n2);
  ck_assert_uint_eq(n, n2);
  ck_assert_int_eq(memcmp(buf, buf2, n), 0);
  free(buf2);
  oc_btile_free(l);
  /* an unwritable path: OC_EIO naming it, nothing left */
  char nodir[300];
  snprintf(nodir, sizeof nodir, "%s/no/t.octile", dir);
  ck_assert_int_eq(oc_btile_save(t, nodir, &e), OC_EIO);
  ck_assert_msg(strstr(e.msg, "t.octile") != NULL, "%s", e.msg);
  /* refused: not a file, not a tile, another version, damaged, crafted */
  ck_assert_ptr_null(oc_btile_load(dir, &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_msg(strstr(e.msg, "not a regular file") != NULL, "%s", e.msg);
  FILE *f = fopen(bad, "wb");
  fwrite(buf, 1, n / 2, f);
  fclose(f);
  ck_assert_ptr_null(oc_btile_load(bad, &e));
  ck_assert_msg(strstr(e.msg, "damaged") != NULL, "%s", e.msg);
  f = fopen(bad, "wb");
  fwrite("P6\n", 1, 3, f);
  fclose(f);
  ck_assert_ptr_null(oc_btile_load(bad, &e));
  ck_assert_msg(strstr(e.msg, "no tile header") != NULL, "%s", e.msg);
  /* offsets: version 8, radius 28, width 84, counts from 108 (points,
  ** discs, blocks, ..., authored at 172), points from 188 */
  crafted(bad, buf, n, 8, 2 | (uint64_t)0 << 32, "version 2");
  crafted(bad, buf, n, 28, bits(NAN), "not finite");
  crafted(bad, buf, n, 84, bits(0), "'width' must be > 0");
  crafted(bad, buf, n, 108, (uint64_t)1 << 40, "counts are out of range");
  crafted(bad, buf, n, 124, a.blocks + 1000, "truncated");
  crafted(bad, buf, n, 172, a.blocks + 1, "counts are out of range");
  size_t b0 = 188 + 24 * a.points + 56 * a.fractures;
  crafted(bad, buf, n, b0, (uint64_t)1 << 62, "a block's counts");
  crafted(bad, buf, n, b0 + 24 + 80, bits(2.0), "unit normal");
  crafted(bad, buf, n, 188, bits(-3.0), "a point lies outside");
  free(buf);
  oc_btile_free(t);
  unlink(path);
  unlink(bad);
  rmdir(dir);
}
END_TEST

/* ---- meshes ------------------------------------------------------------- */

/* 1 when every directed edge (a, b) of the mesh has its (b, a): closed
** and consistently oriented. */
static int closed(const oc_mesh *m) {
  size_t nt = oc_mesh_triangle_count(m);
  const uint32_t *ix = oc_mesh_indices(m);
  uint64_t fw = 0, bw = 0;
  for (size_t k = 0; k < nt; k++)
    for (int j = 0; j < 3; j++) {
      uint64_t a = ix[3 * k + j], b = ix[3 * k + (j + 1) % 3];
      fw += (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xC2B2AE3D27D4EB4Full);
      bw += (b * 0x9E3779B97F4A7C15ull) ^ (a * 0xC2B2AE3D27D4EB4Full);
    }
  return fw == bw;
}

/* A mesh per block: closed, convex (midpoints of vertex pairs inside up to
** the polygonizer's error), within the block's support, at the place of
** the block's hull. */
START_TEST(tile_meshes_closed_convex) {
  oc_btile *t = small_tile(8);
  oc_error e = {0};
  for (size_t i = 0; i < 5; i++) {
    oc_mesh *m = oc_btile_mesh(t, i, 0.1, 0.5, (oc_progress){0}, &e);
    ck_assert_msg(m != NULL, "%s", e.msg);
    size_t nv = oc_mesh_vertex_count(m);
    const float *x = oc_mesh_positions(m);
    ck_assert_uint_gt(oc_mesh_triangle_count(m), 100);
    ck_assert_msg(closed(m), "block %zu: mesh not closed", i);
    oc_program *pr = oct_compile(OCT_OK(oc_btile_block(t, i, &e)), 0.5, 0);
    oc_aabb b = oc_program_bounds(pr);
    oct_rng r = oct_rng_new(i);
    double worst = 0;
    for (int k = 0; k < 5000; k++) {
      size_t a = (size_t)oct_unif(&r, 0, (double)nv) % nv,
             c = (size_t)oct_unif(&r, 0, (double)nv) % nv;
      oc_vec3 p = oct_v(0.5 * (x[3 * a] + x[3 * c]),
                        0.5 * (x[3 * a + 1] + x[3 * c + 1]),
                        0.5 * (x[3 * a + 2] + x[3 * c + 2]));
      worst = fmax(worst, 0.5 - oc_program_eval(pr, p));
    }
    ck_assert_double_le(worst, 0.01);
    for (size_t k = 0; k < nv; k++) {
      ck_assert(x[3 * k] > b.lo.x && x[3 * k] < b.hi.x);
      ck_assert(x[3 * k + 2] > b.lo.z && x[3 * k + 2] < b.hi.z);
    }
    oc_mesh_free(m);
    oc_program_free(pr);
  }
  ck_assert_ptr_null(oc_btile_mesh(t, 100000, 0.1, 0.5, (oc_progress){0}, &e));
  ck_assert_ptr_null(oc_btile_mesh(t, 0, 0, 0.5, (oc_progress){0}, &e));
  ck_assert_msg(strstr(e.msg, "'cell'") != NULL, "%s", e.msg);
  oc_btile_free(t);
}
END_TEST

/* ---- seamless replication ----------------------------------------------- */

static oc_mesh *mesh_box(const oc_program *pr, double y0, double y1) {
  oc_polygonize_params pp = {0};
  pp.box = (oc_aabb){{-3, y0, 4}, {0, y1, 12}};
  pp.cell = 0.125;
  pp.open = 1;
  oc_error e = {0};
  oc_mesh *m = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  return m;
}

static int cmp3(const void *a, const void *b) {
  const float *p = a, *q = b;
  for (int i = 0; i < 3; i++)
    if (p[i] != q[i]) return p[i] < q[i] ? -1 : 1;
  return 0;
}

/* The vertices of m on the plane y = w, sorted; their count in *n. */
static float *seam(const oc_mesh *m, float w, size_t *n) {
  size_t nv = oc_mesh_vertex_count(m);
  const float *x = oc_mesh_positions(m);
  float *s = malloc(3 * (nv ? nv : 1) * sizeof *s);
  *n = 0;
  for (size_t k = 0; k < nv; k++)
    if (x[3 * k + 1] == w) memcpy(s + 3 * (*n)++, x + 3 * k, 3 * sizeof *s);
  qsort(s, *n, 3 * sizeof *s, cmp3);
  return s;
}

/* Blocks replicated on a long wall (8 m tiles; the wall's surface at
** x = -1.35 with a falloff of 3 m): the meshes of two boxes
** meeting on the tile border y = 24 share their seam vertices, blocks
** straddle that border (seam vertices stand out of the wall), and the
** blocks repeat with the tile: the box across the next border, y = 32,
** is the same mesh moved by 8 m. */
START_TEST(replicate_seamless) {
  oc_error e = {0};
  oc_node *ter = OCT_OK(oc_box(oct_v(0, 0, 0), oct_v(16, 48, 16), 3, 1, &e));
  oc_btile *t = small_tile(4);
  oc_program *pr = oct_compile(OCT_OK(replicated(ter, t, 0, &e)), 0.5, 0);
  oc_node_release(ter);
  oc_mesh *a = mesh_box(pr, 20, 24), *b = mesh_box(pr, 24, 28);
  size_t na, nb;
  float *sa = seam(a, 24, &na), *sb = seam(b, 24, &nb);
  size_t out = 0;
  for (size_t k = 0; k < na; k++)
    out += sa[3 * k] < -1.6f;
  printf("replicate seam y = 24: %zu vertices (%zu on blocks standing out "
         "of the wall)\n",
         na, out);
  ck_assert_uint_gt(na, 50);
  ck_assert_uint_gt(out, 8);
  /* the field is continuous across the border (blocks are not cut by it) */
  double L = oc_program_lipschitz(pr), jump = 0;
  for (double x = -3; x <= 0; x += 0.05)
    for (double z = 4; z <= 12; z += 0.05)
      jump = fmax(jump, fabs(oc_program_eval(pr, oct_v(x, 24 - 1e-6, z)) -
                             oc_program_eval(pr, oct_v(x, 24 + 1e-6, z))));
  ck_assert_double_le(jump, 2e-6 * L + 1e-12);
  ck_assert_uint_eq(na, nb);
  ck_assert_int_eq(memcmp(sa, sb, 3 * na * sizeof *sa), 0);
  free(sa);
  free(sb);
  /* periodic: the box across y = 32 is box a moved by 8 m */
  oc_mesh *c = mesh_box(pr, 28, 32);
  ck_assert_uint_eq(oc_mesh_vertex_count(a), oc_mesh_vertex_count(c));
  ck_assert_uint_eq(oc_mesh_triangle_count(a), oc_mesh_triangle_count(c));
  const float *xa = oc_mesh_positions(a), *xc = oc_mesh_positions(c);
  double worst = 0;
  for (size_t k = 0; k < oc_mesh_vertex_count(a); k++)
    worst = fmax(worst, fabs(xa[3 * k] - xc[3 * k]) +
                            fabs(xa[3 * k + 1] + 8 - xc[3 * k + 1]) +
                            fabs(xa[3 * k + 2] - xc[3 * k + 2]));
  ck_assert_double_le(worst, 1e-4);
  ck_assert_int_eq(memcmp(oc_mesh_indices(a), oc_mesh_indices(c),
                          3 * oc_mesh_triangle_count(a) * sizeof(uint32_t)),
                   0);
  oc_mesh_free(a);
  oc_mesh_free(b);
  oc_mesh_free(c);
  oc_program_free(pr);
  oc_btile_free(t);
}
END_TEST

int main(void) {
  Suite *s = suite_create("blockwarp");
  TCase *tc = tcase_create("relief");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, relief_formula);
  tcase_add_test(tc, relief_zero_amplitude);
  tcase_add_test(tc, relief_gradient_lipschitz_support);
  tcase_add_test(tc, relief_image_plane);
  tcase_add_test(tc, relief_errors);
  tcase_add_test(tc, replicate_inset);
  tcase_add_test(tc, tile_save_load);
  tcase_add_test(tc, tile_meshes_closed_convex);
  tcase_add_test(tc, replicate_seamless);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
