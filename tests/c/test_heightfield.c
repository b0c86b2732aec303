/*
** test_heightfield.c — heightfield grids: the C1 Catmull-Rom interpolant
** and its gradient, files (16-bit PNG, float TIFF and EXR round trips, 8-
** and 16-bit counts, a hand-made float GeoTIFF, metadata, errors), and
** procedural grids (fBm, the surface of a field, resampling, cropping),
** deterministic for any thread count.
*/
#include <check.h>
#include <fcntl.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/oiio.h"
#include "ocheck.h"
#include "octmpfs.h"
#include "outcrop.h"

/* ---- helpers ------------------------------------------------------------ */

static char dir[64];

static void mkdir_tmp(void) {
  strcpy(dir, oct_tmpdir("hf"));
}
static void teardown(void) {
  oct_rm_tree(dir);
}

static oc_heightfield *grid_ok(int nx, int ny, double cell, double x0,
                               double y0, const float *z) {
  oc_error e = {0};
  oc_heightfield *hf = oc_heightfield_new(nx, ny, cell, x0, y0, z, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  return hf;
}

/* Smooth random-looking values: sums of a few random waves. */
static oc_heightfield *wavy(int nx, int ny, double cell, uint64_t seed) {
  oc_heightfield *hf = grid_ok(nx, ny, cell, -3.5, 12.25, NULL);
  oct_rng r = oct_rng_new(seed);
  double a[4][4];
  for (int k = 0; k < 4; k++)
    for (int m = 0; m < 4; m++)
      a[k][m] = oct_unif(&r, -1, 1);
  float *z = oc_heightfield_samples_mut(hf);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      double v = 40;
      for (int k = 0; k < 4; k++)
        v += 10 * a[k][0] *
             sin(a[k][1] * 0.3 * i + a[k][2] * 0.2 * j + 3 * a[k][3]);
      z[(size_t)j * nx + i] = (float)v;
    }
  return hf;
}

static int same_samples(const oc_heightfield *a, const oc_heightfield *b) {
  size_t n = (size_t)oc_heightfield_nx(a) * oc_heightfield_ny(a);
  return oc_heightfield_nx(a) == oc_heightfield_nx(b) &&
         oc_heightfield_ny(a) == oc_heightfield_ny(b) &&
         memcmp(oc_heightfield_samples(a), oc_heightfield_samples(b),
                n * sizeof(float)) == 0;
}

static oc_heightfield *load_ok(const char *path,
                               const oc_heightfield_load_params *p) {
  oc_error e = {0};
  oc_heightfield *hf = oc_heightfield_load(path, p, &e);
  ck_assert_msg(hf != NULL, "loading %s: %s", path, e.msg);
  return hf;
}

static void save_ok(const oc_heightfield *hf, const char *path,
                    const oc_heightfield_save_params *p, double used[2]) {
  oc_error e = {0};
  int rc = oc_heightfield_save(hf, path, p, used, &e);
  ck_assert_msg(rc == OC_OK, "saving %s: %s", path, e.msg);
}

static char *slurp(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  ck_assert_ptr_nonnull(f);
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *buf = malloc((size_t)len + 1);
  ck_assert_int_eq(fread(buf, 1, (size_t)len, f), (size_t)len);
  fclose(f);
  *n = (size_t)len;
  return buf;
}

static int same_file(const char *a, const char *b) {
  size_t na, nb;
  char *pa = slurp(a, &na), *pb = slurp(b, &nb);
  int same = na == nb && memcmp(pa, pb, na) == 0;
  free(pa);
  free(pb);
  return same;
}

static void geometry_is(const oc_heightfield *hf, int nx, int ny, double cell,
                        double x0, double y0) {
  double gx, gy;
  oc_heightfield_origin(hf, &gx, &gy);
  ck_assert_int_eq(oc_heightfield_nx(hf), nx);
  ck_assert_int_eq(oc_heightfield_ny(hf), ny);
  ck_assert(oc_heightfield_cell(hf) == cell);
  ck_assert(gx == x0 && gy == y0);
}

/* ---- the interpolant ------------------------------------------------------
 */

START_TEST(passes_through_samples) {
  oc_heightfield *hf = wavy(23, 17, 0.75, 1);
  const float *z = oc_heightfield_samples(hf);
  for (int j = 0; j < 17; j++)
    for (int i = 0; i < 23; i++) {
      double h =
          oc_heightfield_height(hf, -3.5 + i * 0.75, 12.25 + j * 0.75, NULL);
      ck_assert_msg(fabs(h - z[j * 23 + i]) <= 1e-12 * fabs(h), "(%d %d)", i,
                    j);
    }
  oc_heightfield_release(hf);
}
END_TEST

/* Catmull-Rom reproduces linear functions away from the border (where
** clamped samples bend it). */
START_TEST(reproduces_planes) {
  int nx = 12, ny = 9;
  float z[12 * 9];
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      z[j * nx + i] = (float)(5 + 0.5 * i * 2 - 0.25 * j * 2);
  oc_heightfield *hf = grid_ok(nx, ny, 2, 0, 0, z);
  oct_rng r = oct_rng_new(2);
  for (int k = 0; k < 500; k++) {
    double x = oct_unif(&r, 2, 2 * (nx - 2)), y = oct_unif(&r, 2, 2 * (ny - 2));
    double g[2], h = oc_heightfield_height(hf, x, y, g);
    ck_assert_double_eq_tol(h, 5 + 0.5 * x - 0.25 * y, 1e-12);
    ck_assert_double_eq_tol(g[0], 0.5, 1e-12);
    ck_assert_double_eq_tol(g[1], -0.25, 1e-12);
  }
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(gradient_matches_differences) {
  oc_heightfield *hf = wavy(40, 30, 1.5, 3);
  oct_rng r = oct_rng_new(4);
  double x0 = -3.5, y0 = 12.25, h = 1e-5;
  for (int k = 0; k < 2000; k++) {
    double x = oct_unif(&r, x0, x0 + 39 * 1.5),
           y = oct_unif(&r, y0, y0 + 29 * 1.5);
    /* keep the difference inside one cell: the interpolant is C1 only */
    double fu = fmod((x - x0) / 1.5, 1), fv = fmod((y - y0) / 1.5, 1);
    if (fu < 1e-3 || fu > 1 - 1e-3 || fv < 1e-3 || fv > 1 - 1e-3) continue;
    double g[2];
    oc_heightfield_height(hf, x, y, g);
    double dx = (oc_heightfield_height(hf, x + h, y, NULL) -
                 oc_heightfield_height(hf, x - h, y, NULL)) /
                (2 * h);
    double dy = (oc_heightfield_height(hf, x, y + h, NULL) -
                 oc_heightfield_height(hf, x, y - h, NULL)) /
                (2 * h);
    ck_assert_msg(fabs(g[0] - dx) <= 1e-5 * (1 + fabs(dx)), "%g vs %g", g[0],
                  dx);
    ck_assert_msg(fabs(g[1] - dy) <= 1e-5 * (1 + fabs(dy)), "%g vs %g", g[1],
                  dy);
  }
  oc_heightfield_release(hf);
}
END_TEST

/* C1 across cell boundaries: on either side of a sample line the gradient
** tends to the same limit, which for Catmull-Rom is the central difference
** of the samples, (z[i+1] - z[i-1]) / (2 cell). */
START_TEST(gradient_continuous_across_cells) {
  int nx = 20, ny = 16;
  double c = 1.5, x0 = -3.5, y0 = 12.25, e = 1e-9;
  oc_heightfield *hf = wavy(nx, ny, c, 5);
  const float *z = oc_heightfield_samples(hf);
  oct_rng r = oct_rng_new(6);
  for (int k = 0; k < 300; k++) {
    int i = 1 + (int)oct_unif(&r, 0, nx - 2.0001);
    double y = oct_unif(&r, y0 + c, y0 + (ny - 2) * c);
    double x = x0 + i * c, gl[2], gr[2];
    double hl = oc_heightfield_height(hf, x - e, y, gl);
    double hr = oc_heightfield_height(hf, x + e, y, gr);
    ck_assert_double_eq_tol(hl, hr, 1e-6);
    ck_assert_double_eq_tol(gl[0], gr[0], 1e-6);
    ck_assert_double_eq_tol(gl[1], gr[1], 1e-6);
    /* on a sample row too, the limit is the formula */
    int j = 1 + (int)oct_unif(&r, 0, ny - 2.0001);
    double g[2];
    oc_heightfield_height(hf, x, y0 + j * c, g);
    double cd = (z[j * nx + i + 1] - z[j * nx + i - 1]) / (2 * c);
    double cdy = (z[(j + 1) * nx + i] - z[(j - 1) * nx + i]) / (2 * c);
    ck_assert_double_eq_tol(g[0], cd, 1e-9);
    ck_assert_double_eq_tol(g[1], cdy, 1e-9);
    oc_heightfield_height(hf, x - e, y0 + j * c + e, gl);
    ck_assert_double_eq_tol(gl[0], cd, 1e-6);
    ck_assert_double_eq_tol(gl[1], cdy, 1e-6);
  }
  oc_heightfield_release(hf);
}
END_TEST

/* ---- files -----------------------------------------------------------------
 */

START_TEST(png16_round_trip) {
  oc_heightfield *hf = wavy(61, 47, 2.5, 7);
  const char *a = oct_in_dir(dir, "a.png"), *b = oct_in_dir(dir, "b.png");
  double used[2];
  save_ok(hf, a, NULL, used);
  double lo, hi;
  oc_heightfield_minmax(hf, &lo, &hi);
  ck_assert(used[1] == lo);
  ck_assert(used[0] == (hi - lo) / 65535);

  oc_heightfield *h1 = load_ok(a, NULL); /* cell, origin, scale from file */
  geometry_is(h1, 61, 47, 2.5, -3.5, 12.25);
  const float *z = oc_heightfield_samples(hf), *z1 = oc_heightfield_samples(h1);
  for (int k = 0; k < 61 * 47; k++) {
    double q = floor((z[k] - used[1]) / used[0] + 0.5);
    ck_assert(z1[k] == (float)(q * used[0] + used[1]));
    ck_assert(fabs(z1[k] - z[k]) <= 0.5 * used[0] + 1e-5);
  }
  /* the quantized grid saves to the same file and reloads bit-exactly */
  double used1[2];
  save_ok(h1, b, NULL, used1);
  ck_assert(used1[0] == used[0] && used1[1] == used[1]);
  ck_assert(same_file(a, b));
  oc_heightfield *h2 = load_ok(b, NULL);
  ck_assert(same_samples(h1, h2));
  oc_heightfield_release(hf);
  oc_heightfield_release(h1);
  oc_heightfield_release(h2);
}
END_TEST

/* Elevations on the quantization lattice come back exactly, the extreme
** counts 0 and 65535 included. */
START_TEST(png16_exact_lattice) {
  int nx = 256, ny = 256;
  float *z = malloc(sizeof(float) * nx * ny);
  for (int k = 0; k < nx * ny; k++)
    z[k] = (float)(100 + 0.25 * ((k * 7919) % 65536));
  z[5] = 100;
  z[6] = (float)(100 + 0.25 * 65535);
  oc_heightfield *hf = grid_ok(nx, ny, 1, 0, 0, z);
  const char *p = oct_in_dir(dir, "lattice.png");
  double used[2];
  save_ok(hf, p, NULL, used);
  ck_assert(used[0] == 0.25 && used[1] == 100);
  oc_heightfield *h1 = load_ok(p, NULL);
  ck_assert(same_samples(hf, h1));
  /* fixed scale and offset give the same file */
  oc_heightfield_save_params sp = {16, 1, 0.25, 100, NULL, 0, NULL, 0};
  const char *q = oct_in_dir(dir, "fixed.png");
  save_ok(hf, q, &sp, used);
  ck_assert(same_file(p, q));
  free(z);
  oc_heightfield_release(hf);
  oc_heightfield_release(h1);
}
END_TEST

static void float_round_trip(const char *name) {
  int nx = 37, ny = 29;
  oc_heightfield *hf = wavy(nx, ny, 0.1, 9);
  float *z = oc_heightfield_samples_mut(hf);
  z[0] = -0.0f;
  z[1] = 1e-40f; /* subnormal */
  z[2] = 3.0e38f;
  z[3] = -123456.789f;
  z[4] = 0.1f;
  const char *p = oct_in_dir(dir, name);
  double used[2];
  save_ok(hf, p, NULL, used);
  ck_assert(used[0] == 1 && used[1] == 0);
  oc_heightfield *h1 = load_ok(p, NULL);
  geometry_is(h1, nx, ny, 0.1, -3.5, 12.25);
  ck_assert(same_samples(hf, h1));
  ck_assert(signbit(oc_heightfield_samples(h1)[0]));
  oc_heightfield_release(hf);
  oc_heightfield_release(h1);
}

START_TEST(exr_round_trip) {
  float_round_trip("h.exr");
}
END_TEST

START_TEST(tiff_round_trip) {
  float_round_trip("h.tif");
}
END_TEST

START_TEST(tiff16_and_half) {
  oc_heightfield *hf = wavy(33, 21, 1, 10);
  oc_heightfield_save_params sp = {16, 0, 0, 0, NULL, 0, NULL, 0};
  double used[2];
  save_ok(hf, oct_in_dir(dir, "h16.tif"), &sp, used);
  oc_heightfield *a = load_ok(oct_in_dir(dir, "h16.tif"), NULL);
  save_ok(hf, oct_in_dir(dir, "h16.png"), NULL, NULL);
  oc_heightfield *b = load_ok(oct_in_dir(dir, "h16.png"), NULL);
  ck_assert(same_samples(a, b));
  /* half floats: within half precision (11 bits) of elevations near 40 */
  save_ok(hf, oct_in_dir(dir, "half.exr"), &sp, used);
  oc_heightfield *c = load_ok(oct_in_dir(dir, "half.exr"), NULL);
  const float *z = oc_heightfield_samples(hf), *zc = oc_heightfield_samples(c);
  for (int k = 0; k < 33 * 21; k++)
    ck_assert(fabs(z[k] - zc[k]) <= fabs(z[k]) * 0x1p-11);
  oc_heightfield_release(hf);
  oc_heightfield_release(a);
  oc_heightfield_release(b);
  oc_heightfield_release(c);
}
END_TEST

/* Writes raw counts with the bridge (no quantization of ours involved). */
static void write_counts(const char *path, int w, int h, int bits,
                         const void *px) {
  const char *names[1] = {"Y"};
  oc_oiio_out out = {.format = "png",
                     .width = w,
                     .height = h,
                     .channels = 1,
                     .type = bits == 8 ? OC_OIIO_U8 : OC_OIIO_U16,
                     .pixels = px,
                     .alpha = -1,
                     .channel_names = names,
                     .meta = NULL,
                     .nmeta = 0};
  oc_error e = {OC_OK, ""};
  ck_assert_msg(oc_oiio_write_at(AT_FDCWD, path, &out, &e) == OC_OK, "%s",
                e.msg);
}

/* Raw counts, not normalized; north up: image row r is grid row ny-1-r. */
START_TEST(png8_and_png16_counts) {
  int w = 7, h = 5;
  uint8_t p8[35];
  uint16_t p16[35];
  for (int k = 0; k < w * h; k++) {
    p8[k] = (uint8_t)(k * 37 % 256);
    p16[k] = (uint16_t)(k * 4099 % 65536);
  }
  p8[0] = 255;
  p16[0] = 65535;
  write_counts(oct_in_dir(dir, "c8.png"), w, h, 8, p8);
  write_counts(oct_in_dir(dir, "c16.png"), w, h, 16, p16);
  oc_heightfield_load_params lp = {
      OC_HEIGHTFIELD_GIVE_SCALE | OC_HEIGHTFIELD_GIVE_OFFSET,
      0,
      0.5,
      -10,
      0,
      0,
      {0}};
  oc_heightfield *a = load_ok(oct_in_dir(dir, "c8.png"), &lp);
  oc_heightfield *b = load_ok(oct_in_dir(dir, "c16.png"), NULL);
  geometry_is(a, w, h, 1, 0, 0);
  const float *za = oc_heightfield_samples(a), *zb = oc_heightfield_samples(b);
  for (int r = 0; r < h; r++)
    for (int i = 0; i < w; i++) {
      int j = h - 1 - r;
      ck_assert(za[j * w + i] == p8[r * w + i] * 0.5f - 10);
      ck_assert(zb[j * w + i] == (float)p16[r * w + i]);
    }
  oc_heightfield_release(a);
  oc_heightfield_release(b);
}
END_TEST

/* ---- a hand-made float32 GeoTIFF (read as a plain TIFF) -------------- */

static void put16(unsigned char *b, uint16_t v) {
  b[0] = (unsigned char)v, b[1] = (unsigned char)(v >> 8);
}
static void put32(unsigned char *b, uint32_t v) {
  for (int k = 0; k < 4; k++)
    b[k] = (unsigned char)(v >> (8 * k));
}

/* A strip TIFF, little-endian, one sample per pixel of `bits` bits
** (32: IEEE float, 8: unsigned), with GeoTIFF's pixel scale, tie point and
** key directory tags. `data` may be NULL for a header only file. */
static void write_geotiff(const char *path, uint32_t w, uint32_t h, int bits,
                          const void *data) {
  enum { NE = 13 };
  uint32_t ifd = 8, scale_at = ifd + 2 + NE * 12 + 4, tie_at = scale_at + 24,
           keys_at = tie_at + 48, data_at = keys_at + 16;
  uint64_t nbytes = (uint64_t)w * h * (uint32_t)(bits / 8);
  unsigned char head[512];
  memset(head, 0, sizeof head);
  memcpy(head, "II", 2);
  put16(head + 2, 42);
  put32(head + 4, ifd);
  put16(head + ifd, NE);
  struct {
    uint16_t tag, type;
    uint32_t count, value;
  } e[NE] = {{256, 4, 1, w},
             {257, 4, 1, h},
             {258, 3, 1, (uint32_t)bits},
             {259, 3, 1, 1},
             {262, 3, 1, 1},
             {273, 4, 1, data_at},
             {277, 3, 1, 1},
             {278, 4, 1, h},
             {279, 4, 1, (uint32_t)nbytes},
             {339, 3, 1, bits == 32 ? 3 : 1},
             {33550, 12, 3, scale_at},
             {33922, 12, 6, tie_at},
             {34735, 3, 8, keys_at}};
  for (int k = 0; k < NE; k++) {
    unsigned char *p = head + ifd + 2 + 12 * k;
    put16(p, e[k].tag);
    put16(p + 2, e[k].type);
    put32(p + 4, e[k].count);
    if (e[k].type == 3 && e[k].count == 1)
      put16(p + 8, (uint16_t)e[k].value);
    else
      put32(p + 8, e[k].value);
  }
  double scale[3] = {30, 30, 0}, tie[6] = {0, 0, 0, 500000, 4100000, 0};
  memcpy(head + scale_at, scale, sizeof scale); /* x86: little-endian */
  memcpy(head + tie_at, tie, sizeof tie);
  uint16_t keys[8] = {1, 1, 0, 1, 1024, 0, 1, 1};
  memcpy(head + keys_at, keys, sizeof keys);
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  ck_assert_int_eq(fwrite(head, 1, data_at, f), data_at);
  if (data) ck_assert_int_eq(fwrite(data, 1, (size_t)nbytes, f), nbytes);
  fclose(f);
}

START_TEST(geotiff_float32) {
  uint32_t w = 9, h = 6;
  float px[54];
  for (int k = 0; k < 54; k++)
    px[k] = (float)(1234.5 + 0.001 * k * k - 7 * (k % 5));
  px[3] = -0.0f;
  const char *p = oct_in_dir(dir, "dem.tif");
  write_geotiff(p, w, h, 32, px);
  oc_heightfield_load_params lp = {OC_HEIGHTFIELD_GIVE_CELL |
                                       OC_HEIGHTFIELD_GIVE_ORIGIN,
                                   30,
                                   1,
                                   0,
                                   500015,
                                   3950015,
                                   {0}};
  oc_heightfield *hf = load_ok(p, &lp);
  geometry_is(hf, 9, 6, 30, 500015, 3950015);
  const float *z = oc_heightfield_samples(hf);
  for (uint32_t r = 0; r < h; r++)
    for (uint32_t i = 0; i < w; i++)
      ck_assert(memcmp(&z[(h - 1 - r) * w + i], &px[r * w + i], 4) == 0);
  oc_heightfield_release(hf);
}
END_TEST

/* Given parameters win over the file's metadata, each on its own. */
START_TEST(metadata_and_overrides) {
  oc_heightfield *hf = wavy(10, 8, 2.5, 11);
  const char *p = oct_in_dir(dir, "m.png");
  double used[2];
  save_ok(hf, p, NULL, used);
  oc_heightfield_load_params lp = {
      OC_HEIGHTFIELD_GIVE_CELL, 4, 0, 0, 0, 0, {0}};
  oc_heightfield *a = load_ok(p, &lp);
  geometry_is(a, 10, 8, 4, -3.5, 12.25);
  oc_heightfield_load_params lq = {
      OC_HEIGHTFIELD_GIVE_ORIGIN | OC_HEIGHTFIELD_GIVE_SCALE,
      0,
      2,
      0,
      1,
      2,
      {0}};
  oc_heightfield *b = load_ok(p, &lq);
  geometry_is(b, 10, 8, 2.5, 1, 2);
  double lo, hi;
  oc_heightfield_minmax(b, &lo, &hi);
  ck_assert(lo == (float)used[1]);
  ck_assert(hi == (float)(65535 * 2 + used[1]));
  /* provenance-style pairs land in the file next to ours */
  const char *meta[] = {"outcrop:seed", "42", "outcrop:scale", "999"};
  oc_heightfield_save_params sp = {0, 0, 0, 0, meta, 2, NULL, 0};
  save_ok(hf, oct_in_dir(dir, "n.exr"), &sp, used);
  oc_error e = {0};
  oc_image *img = oc_oiio_read(oct_in_dir(dir, "n.exr"), &e);
  ck_assert_msg(img != NULL, "%s", e.msg);
  ck_assert_str_eq(oc_image_meta_get(img, "outcrop:seed"), "42");
  ck_assert_str_eq(oc_image_meta_get(img, "outcrop:scale"), "1");
  ck_assert_str_eq(oc_image_meta_get(img, "outcrop:cell"), "2.5");
  oc_image_free(img);
  oc_heightfield_release(hf);
  oc_heightfield_release(a);
  oc_heightfield_release(b);
}
END_TEST

START_TEST(repeat_saves_identical) {
  oc_heightfield *hf = wavy(30, 20, 1, 12);
  const char *names[] = {"r.png", "r.tif", "r.exr"};
  for (int k = 0; k < 3; k++) {
    char a[32], b[32];
    snprintf(a, sizeof a, "1%s", names[k]);
    snprintf(b, sizeof b, "2%s", names[k]);
    char pa[256], pb[256];
    strcpy(pa, oct_in_dir(dir, a));
    strcpy(pb, oct_in_dir(dir, b));
    save_ok(hf, pa, NULL, NULL);
    save_ok(hf, pb, NULL, NULL);
    ck_assert_msg(same_file(pa, pb), "%s", names[k]);
  }
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(file_errors) {
  oc_error e = {0};
  oc_heightfield *hf = wavy(4, 4, 1, 13);
  /* missing, corrupt, too small, not finite */
  const char *missing = oct_in_dir(dir, "none.png");
  ck_assert_ptr_null(oc_heightfield_load(missing, NULL, &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_ptr_nonnull(strstr(e.msg, missing));
  const char *junk = oct_in_dir(dir, "junk.png");
  FILE *f = fopen(junk, "wb");
  fputs("\x89PNG\r\n\x1a\nthis is not a png at all", f);
  fclose(f);
  ck_assert_ptr_null(oc_heightfield_load(junk, NULL, &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_ptr_nonnull(strstr(e.msg, junk));
  uint8_t px[3] = {1, 2, 3};
  write_counts(oct_in_dir(dir, "thin.png"), 3, 1, 8, px);
  ck_assert_ptr_null(
      oc_heightfield_load(oct_in_dir(dir, "thin.png"), NULL, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, "2 x 2"));
  oc_heightfield_samples_mut(hf)[5] = 1e30f;
  save_ok(hf, oct_in_dir(dir, "big.exr"), NULL, NULL);
  oc_heightfield_load_params lp = {
      OC_HEIGHTFIELD_GIVE_SCALE, 0, 1e10, 0, 0, 0, {0}};
  ck_assert_ptr_null(oc_heightfield_load(oct_in_dir(dir, "big.exr"), &lp, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, "not finite"));
  lp = (oc_heightfield_load_params){
      OC_HEIGHTFIELD_GIVE_CELL, -1, 0, 0, 0, 0, {0}};
  ck_assert_ptr_null(oc_heightfield_load(oct_in_dir(dir, "big.exr"), &lp, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'cell'"));

  /* absurd sizes: refused from the header, before allocating */
  write_geotiff(oct_in_dir(dir, "huge.tif"), 40000, 40000, 8, NULL);
  ck_assert_ptr_null(
      oc_heightfield_load(oct_in_dir(dir, "huge.tif"), NULL, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  ck_assert_ptr_nonnull(strstr(e.msg, "40000 x 40000"));

  /* saving: formats, bits, fixed ranges, unwritable places */
  ck_assert_int_eq(
      oc_heightfield_save(hf, oct_in_dir(dir, "h.jpg"), NULL, NULL, &e),
      OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, ".png"));
  oc_heightfield_save_params sp = {12, 0, 0, 0, NULL, 0, NULL, 0};
  ck_assert_int_eq(
      oc_heightfield_save(hf, oct_in_dir(dir, "h.png"), &sp, NULL, &e),
      OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, "'bits'"));
  sp = (oc_heightfield_save_params){16,   1, 1,    0,
                                    NULL, 0, NULL, 0}; /* 1e30 does not fit */
  ck_assert_int_eq(
      oc_heightfield_save(hf, oct_in_dir(dir, "h.png"), &sp, NULL, &e),
      OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(e.msg, "outside"));
  sp = (oc_heightfield_save_params){0, 1, 1, 0, NULL, 0, NULL, 0};
  ck_assert_int_eq(
      oc_heightfield_save(hf, oct_in_dir(dir, "h.exr"), &sp, NULL, &e),
      OC_EINVAL);
  ck_assert_int_eq(
      oc_heightfield_save(hf, oct_in_dir(dir, "no/such/h.png"), NULL, NULL, &e),
      OC_EIO);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 4); /* no leftovers */
  oc_heightfield_release(hf);
}
END_TEST

/* A caller's metadata value cannot forge the grid's own keys through a
** line break in a TIFF description. */
START_TEST(metadata_cannot_forge_lines) {
  oc_heightfield *hf = wavy(5, 4, 2.5, 21);
  const char *meta[] = {"note", "a\noutcrop:cell=99\noutcrop:x0=7",
                        "ImageDescription", "outcrop:y0=8"};
  oc_heightfield_save_params sp = {0, 0, 1, 0, meta, 2, NULL, 0};
  const char *p = oct_in_dir(dir, "forge.tif");
  save_ok(hf, p, &sp, NULL);
  oc_heightfield *back = load_ok(p, NULL);
  geometry_is(back, 5, 4, 2.5, -3.5, 12.25);
  ck_assert(same_samples(hf, back));
  oc_heightfield_release(back);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- hostile files ---------------------------------------------------- */

#ifdef __SANITIZE_ADDRESS__
#include <sanitizer/lsan_interface.h>
#define LSAN_OFF() __lsan_disable()
#define LSAN_ON() __lsan_enable()
#else
#define LSAN_OFF() ((void)0)
#define LSAN_ON() ((void)0)
#endif

/* Loading `path` fails with `code` and a message holding `what`. */
static void load_refused(const char *path, int code, const char *what) {
  oc_error e = {0};
  ck_assert_ptr_null(oc_heightfield_load(path, NULL, &e));
  ck_assert_msg((int)e.code == code && strstr(e.msg, what) &&
                    strstr(e.msg, path),
                "%s: %d %s (wanted %d, '%s')", path, e.code, e.msg, code, what);
}

static void write_bytes(const char *path, const void *p, size_t n) {
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  ck_assert_uint_eq(fwrite(p, 1, n, f), n);
  ck_assert_int_eq(fclose(f), 0);
}

/* CRC-32 as PNG chunks carry it (bitwise: a few bytes only). */
static uint32_t crc32_of(const unsigned char *p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++)
      c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xffffffffu;
}

static void be32(unsigned char *b, uint32_t v) {
  b[0] = (unsigned char)(v >> 24), b[1] = (unsigned char)(v >> 16);
  b[2] = (unsigned char)(v >> 8), b[3] = (unsigned char)v;
}

/* A PNG signature, a valid IHDR declaring w x h 16-bit grey and an empty
** IDAT: a header libpng accepts, with no pixels behind it. */
static void write_png_header(const char *path, uint32_t w, uint32_t h) {
  unsigned char b[45] = "\x89PNG\r\n\x1a\n";
  be32(b + 8, 13);
  memcpy(b + 12, "IHDR", 4);
  be32(b + 16, w);
  be32(b + 20, h);
  b[24] = 16, b[25] = 0, b[26] = 0, b[27] = 0, b[28] = 0;
  be32(b + 29, crc32_of(b + 12, 17));
  be32(b + 33, 0);
  memcpy(b + 37, "IDAT", 4);
  be32(b + 41, crc32_of(b + 37, 4));
  write_bytes(path, b, sizeof b);
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cancel_always(void *ud, double fraction) {
  (void)ud, (void)fraction;
  return 1;
}

/* Files that used to hang (/dev/zero: every reader probed the stream),
** block (a FIFO) or take a minute (a big file of zeros) are refused at
** once: only regular files, the reader told by the signature. */
START_TEST(hostile_files) {
  double t0 = now();
  load_refused("/dev/zero", OC_EIO, "not a regular file (a character device)");
  const char *fifo = oct_in_dir(dir, "fifo.png");
  ck_assert_int_eq(mkfifo(fifo, 0600), 0);
  load_refused(fifo, OC_EIO, "not a regular file (a FIFO)");
  load_refused(dir, OC_EIO, "not a regular file (a folder)");
  const char *zeros = oct_in_dir(dir, "zeros.png");
  FILE *f = fopen(zeros, "wb");
  ck_assert_int_eq(ftruncate(fileno(f), 64 << 20), 0);
  fclose(f);
  const char *unknown =
      "unrecognised image format (not PNG, TIFF, EXR or JPEG)";
  load_refused(zeros, OC_EIO, unknown);
  const char *empty = oct_in_dir(dir, "empty.tif");
  write_bytes(empty, "", 0);
  load_refused(empty, OC_EIO, unknown);
  ck_assert_msg(now() - t0 < 2, "refusing took %.1f s", now() - t0);

  /* a valid signature and garbage after it, for every format */
  static const struct {
    const char *name, *bytes;
    size_t n;
  } junk[] = {{"j.png", "\x89PNG\r\n\x1a\ngarbage garbage garbage", 31},
              {"j.tif", "II*\0garbage garbage garbage", 27},
              {"j2.tif", "MM\0*garbage garbage garbage", 27},
              {"j3.tif", "II+\0garbage garbage garbage", 27},
              {"j.exr", "\x76\x2f\x31\x01garbage garbage garbage", 27},
              {"j.jpg", "\xff\xd8\xffgarbage garbage garbage", 26}};
  for (size_t k = 0; k < sizeof junk / sizeof *junk; k++) {
    const char *p = oct_in_dir(dir, junk[k].name);
    write_bytes(p, junk[k].bytes, junk[k].n);
    load_refused(p, OC_EIO, "cannot read");
  }

  /* a truncated PNG */
  oc_heightfield *hf = wavy(64, 64, 1, 8);
  const char *whole = oct_in_dir(dir, "whole.png");
  save_ok(hf, whole, NULL, NULL);
  size_t n;
  char *bytes = slurp(whole, &n);
  const char *cut = oct_in_dir(dir, "cut.png");
  write_bytes(cut, bytes, n / 2);
  free(bytes);
  /* OpenImageIO 2.4's PNG reader leaks its error message here (libpng
  ** longjmps over the std::string): not ours to fix, not to report. */
  LSAN_OFF();
  load_refused(cut, OC_EIO, "cannot read");
  LSAN_ON();

  /* a header declaring 100000 x 100000: refused before allocating */
  const char *huge = oct_in_dir(dir, "huge.png");
  write_png_header(huge, 100000, 100000);
  load_refused(huge, OC_EINVAL, "100000 x 100000");

  /* the reader is chosen by the signature, not the name */
  const char *named = oct_in_dir(dir, "really-a-png.exr");
  ck_assert_int_eq(rename(whole, named), 0);
  oc_heightfield *back = load_ok(named, NULL);
  ck_assert_int_eq(oc_heightfield_nx(back), 64);
  oc_heightfield_release(back);

  /* reading polls for cancellation */
  oc_heightfield_load_params lp = {0};
  lp.progress.fn = cancel_always;
  oc_error e = {0};
  ck_assert_ptr_null(oc_heightfield_load(named, &lp, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  oc_heightfield_release(hf);
}
END_TEST

/* RAW 16-bit: little-endian counts, the grid's last row first, exactly
** the PNG's counts; loads back with the range, a square inferred; a size
** that does not fit, a FIFO and a folder are refused. */
START_TEST(raw16_round_trip) {
  const char *dir = oct_tmpdir("raw");
  oc_heightfield *hf = wavy(37, 23, 2, 9);
  double used[2], upng[2];
  const char *raw = oct_in_dir(dir, "h.r16");
  save_ok(hf, raw, NULL, used);
  char png[4096];
  snprintf(png, sizeof png, "%s", oct_in_dir(dir, "h.png"));
  save_ok(hf, png, NULL, upng);
  ck_assert(used[0] == upng[0] && used[1] == upng[1]);
  size_t n;
  unsigned char *b = (unsigned char *)slurp(raw, &n);
  ck_assert_uint_eq(n, 2 * 37 * 23);
  oc_heightfield *p16 = load_ok(png, NULL);
  double lo, hi;
  oc_heightfield_minmax(hf, &lo, &hi);
  const float *z = oc_heightfield_samples(hf);
  for (int r = 0; r < 23; r++)
    for (int i = 0; i < 37; i++) {
      unsigned q = b[2 * (r * 37 + i)] | (unsigned)b[2 * (r * 37 + i) + 1] << 8;
      double zz = z[(22 - r) * 37 + i];
      ck_assert_uint_eq(q, (unsigned)floor((zz - lo) / used[0] + 0.5));
      /* the PNG holds the same counts: the same elevations once loaded */
      ck_assert(fabs(q * used[0] + used[1] -
                     oc_heightfield_samples(p16)[(22 - r) * 37 + i]) < 1e-3);
    }
  free(b);
  oc_heightfield_load_params lp = {OC_HEIGHTFIELD_GIVE_SCALE |
                                       OC_HEIGHTFIELD_GIVE_OFFSET |
                                       OC_HEIGHTFIELD_GIVE_CELL,
                                   2,
                                   used[0],
                                   used[1],
                                   0,
                                   0,
                                   {NULL, NULL}};
  oc_error e = {0};
  oc_heightfield *back = oc_heightfield_load_raw(raw, 37, 23, &lp, &e);
  ck_assert_msg(back != NULL, "%s", e.msg);
  for (size_t k = 0; k < 37 * 23; k++)
    ck_assert(fabs(oc_heightfield_samples(back)[k] - z[k]) <= used[0]);
  /* saved again with the same range: the same bytes */
  oc_heightfield_save_params fixed = {0, 1, used[0], used[1], NULL, 0, NULL, 0};
  const char *raw2 = oct_in_dir(dir, "again.raw");
  save_ok(back, raw2, &fixed, NULL);
  size_t n1, n2;
  char *b1 = slurp(raw, &n1), *b2 = slurp(raw2, &n2);
  ck_assert(n1 == n2 && !memcmp(b1, b2, n1));
  free(b1);
  free(b2);
  /* errors */
  ck_assert(oc_heightfield_load_raw(raw, 0, 0, NULL, &e) == NULL);
  ck_assert(e.code == OC_EINVAL && strstr(e.msg, "square"));
  ck_assert(oc_heightfield_load_raw(raw, 23, 37 + 1, NULL, &e) == NULL);
  ck_assert(e.code == OC_EINVAL && strstr(e.msg, "bytes"));
  ck_assert(oc_heightfield_load_raw(dir, 0, 0, NULL, &e) == NULL);
  ck_assert(e.code == OC_EIO && strstr(e.msg, "regular"));
  lp.scale = NAN;
  ck_assert(oc_heightfield_load_raw(raw, 37, 23, &lp, &e) == NULL);
  ck_assert(e.code == OC_EINVAL && strstr(e.msg, "scale"));
  oc_heightfield_save_params b8 = {8, 0, 1, 0, NULL, 0, NULL, 0};
  ck_assert_int_eq(oc_heightfield_save(hf, raw2, &b8, NULL, &e), OC_EINVAL);
  ck_assert(strstr(e.msg, "'bits'"));
  /* a square: inferred */
  oc_heightfield *sq = wavy(5, 5, 1, 2);
  save_ok(sq, raw2, NULL, used);
  oc_heightfield *sb = oc_heightfield_load_raw(raw2, 0, 0, NULL, &e);
  ck_assert(sb && oc_heightfield_nx(sb) == 5 && oc_heightfield_ny(sb) == 5);
  oc_heightfield_release(sb);
  oc_heightfield_release(sq);
  oc_heightfield_release(back);
  oc_heightfield_release(p16);
  oc_heightfield_release(hf);
  oct_rm_tree(dir);
}
END_TEST

/* Sums, differences, products, clamp and masks against the formulas;
** mismatched grids, non-finite numbers and overflows refused by name. */
START_TEST(grid_arithmetic) {
  oc_heightfield *a = wavy(9, 7, 1.5, 3), *b = wavy(9, 7, 1.5, 4);
  oc_error e = {0};
  const float *za = oc_heightfield_samples(a), *zb = oc_heightfield_samples(b);
  for (int op = OC_HEIGHTFIELD_ADD; op <= OC_HEIGHTFIELD_MUL; op++) {
    oc_heightfield *c = oc_heightfield_combine(a, b, (oc_heightfield_op)op, &e);
    oc_heightfield *d =
        oc_heightfield_scalar(a, 2.5, (oc_heightfield_op)op, &e);
    ck_assert(c && d);
    for (size_t k = 0; k < 63; k++) {
      double x = za[k], y = zb[k];
      double want[] = {x + y, x - y, y - x, x * y};
      double wk[] = {x + 2.5, x - 2.5, 2.5 - x, x * 2.5};
      ck_assert(oc_heightfield_samples(c)[k] == (float)want[op]);
      ck_assert(oc_heightfield_samples(d)[k] == (float)wk[op]);
    }
    oc_heightfield_release(c);
    oc_heightfield_release(d);
  }
  oc_heightfield *moved = grid_ok(9, 7, 1.5, 0, 0, NULL);
  ck_assert(oc_heightfield_combine(a, moved, OC_HEIGHTFIELD_ADD, &e) == NULL);
  ck_assert(e.code == OC_EINVAL && strstr(e.msg, "grids differ"));
  ck_assert(oc_heightfield_scalar(a, INFINITY, OC_HEIGHTFIELD_MUL, &e) == NULL);
  ck_assert(strstr(e.msg, "finite"));
  ck_assert(oc_heightfield_scalar(a, 1e38, OC_HEIGHTFIELD_MUL, &e) == NULL);
  ck_assert(strstr(e.msg, "sample (1, 1)"));
  oc_heightfield *cl = oc_heightfield_clamp(a, 35, 45, &e);
  for (size_t k = 0; k < 63; k++)
    ck_assert(oc_heightfield_samples(cl)[k] ==
              (float)fmin(fmax(za[k], 35), 45));
  oc_heightfield_release(cl);
  ck_assert(oc_heightfield_clamp(a, 5, 1, &e) == NULL);
  ck_assert(oc_heightfield_clamp(a, NAN, 1, &e) == NULL);
  oc_heightfield_mask_params mp = {1, 1, 38, 44, 0};
  oc_heightfield *m = oc_heightfield_mask(a, &mp, &e);
  for (size_t k = 0; k < 63; k++)
    ck_assert(oc_heightfield_samples(m)[k] == (za[k] >= 38 && za[k] <= 44));
  oc_heightfield_release(m);
  mp.has_below = 0;
  mp.falloff = 4;
  m = oc_heightfield_mask(a, &mp, &e);
  for (size_t k = 0; k < 63; k++)
    ck_assert(fabs(oc_heightfield_samples(m)[k] -
                   fmin(fmax((za[k] - 38) / 4 + 0.5, 0), 1)) < 1e-6);
  oc_heightfield_release(m);
  mp.above = NAN;
  ck_assert(oc_heightfield_mask(a, &mp, &e) == NULL && strstr(e.msg, "above"));
  mp.above = 1;
  mp.falloff = -1;
  ck_assert(oc_heightfield_mask(a, &mp, &e) == NULL &&
            strstr(e.msg, "falloff"));
  mp.has_above = 0;
  ck_assert(oc_heightfield_mask(a, &mp, &e) == NULL);
  oc_heightfield_release(moved);
  oc_heightfield_release(a);
  oc_heightfield_release(b);
}
END_TEST

/* A full disk: every save (and the palette picture) reports it and leaves
** neither the file nor its temporary; a save that fits still works. */
START_TEST(disk_full) {
  const char *fs = oct_tmpfs(64 * 1024, "heightfield disk_full");
  if (!fs) return;
  oc_heightfield *big = grid_ok(400, 400, 1, 0, 0, NULL);
  oct_rng r = oct_rng_new(5);
  float *z = oc_heightfield_samples_mut(big);
  for (size_t i = 0; i < 400 * 400; i++) /* noise: no compression */
    z[i] = (float)oct_unif(&r, 0, 1000);
  oc_heightfield *small = wavy(4, 4, 1, 3);
  const double stops[] = {0, 0, 0, 0, 1000, 1, 1, 1};
  const oc_heightfield_save_params colours = {0, 0, 1, 0, NULL, 0, stops, 2};
  const char *files[] = {"h.png", "h.tif", "h.exr", "c.png", "h.r16"};
  for (int k = 0; k < 5; k++) {
    const char *p = oct_in_dir(fs, files[k]);
    const oc_heightfield_save_params *sp = k == 3 ? &colours : NULL;
    /* 400 x 400 x 2 bytes: over the 64 KiB */
    oc_error e = {0};
    int rc = oc_heightfield_save(big, p, sp, NULL, &e);
    oct_assert_full(rc, e.msg, p, fs);
    save_ok(small, p, sp, NULL);
    if (k == 4) {
      oc_heightfield *back = oc_heightfield_load_raw(p, 0, 0, NULL, &e);
      ck_assert(back && oc_heightfield_nx(back) == 4);
      oc_heightfield_release(back);
    }
    if (k < 3) {
      oc_heightfield *back = load_ok(p, NULL);
      ck_assert_int_eq(oc_heightfield_nx(back), 4);
      oc_heightfield_release(back);
    }
    ck_assert_int_eq(unlink(p), 0);
  }
  oc_heightfield_release(big);
  oc_heightfield_release(small);
  oct_tmpfs_done(fs);
}
END_TEST

/* ---- procedural grids
 * --------------------------------------------------------- */

static int cancel_at_once(void *ud, double fraction) {
  (void)fraction;
  ++*(int *)ud;
  return 1;
}

START_TEST(fbm_is_the_turbulence_node) {
  oc_noise nz = {37.5, 12, -3, 5, 77};
  oc_heightfield_grid g = {48, 40, 1.25, -20, 7};
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, none, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  oc_program *pr = oct_compile(OCT_OK(oc_turbulence(&nz, &e)), 0, 0);
  const float *z = oc_heightfield_samples(hf);
  double lo = INFINITY, hi = -INFINITY;
  for (int j = 0; j < g.ny; j++)
    for (int i = 0; i < g.nx; i++) {
      double f = oc_program_eval(pr, oct_v(-20 + i * 1.25, 7 + j * 1.25, 0));
      ck_assert(z[j * g.nx + i] == (float)f);
      lo = fmin(lo, f), hi = fmax(hi, f);
    }
  /* in [offset, offset + amplitude tmax] and not flat */
  ck_assert(lo >= -3 && hi <= -3 + 12 * (2 - 1.0 / 16));
  ck_assert(hi - lo > 2);
  /* another seed, another grid */
  nz.seed = 78;
  oc_heightfield *other = oc_heightfield_fbm(&g, &nz, none, &e);
  ck_assert(!same_samples(hf, other));
  oc_program_free(pr);
  oc_heightfield_release(hf);
  oc_heightfield_release(other);
}
END_TEST

START_TEST(same_bytes_for_any_thread_count) {
  oc_noise nz = {50, 20, 0, 6, 5};
  oc_heightfield_grid g = {301, 257, 0.5, 0, 0};
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  oc_program *pr =
      oct_compile(OCT_OK(oc_sphere(oct_v(70, 60, 0), 30, 10, 1, &e)), 0, 0);
  oc_heightfield *src = wavy(97, 83, 1.5, 14);
  oc_heightfield_grid up = {300, 250, 0.4, -3, 12},
                      down = {40, 30, 3.7, -3.5, 12.25};
  int nt0 = omp_get_max_threads();
  oc_heightfield *r[3][4];
  for (int t = 0; t < 3; t++) {
    omp_set_num_threads(t + 1);
    r[t][0] = oc_heightfield_fbm(&g, &nz, none, &e);
    r[t][1] = oc_heightfield_from_program(pr, &g, -50, 50, 0, none, &e);
    r[t][2] = oc_heightfield_resample(src, &up, none, &e);
    r[t][3] = oc_heightfield_resample(src, &down, none, &e);
    for (int k = 0; k < 4; k++)
      ck_assert_msg(r[t][k] != NULL, "%s", e.msg);
  }
  omp_set_num_threads(nt0);
  for (int t = 1; t < 3; t++)
    for (int k = 0; k < 4; k++) {
      ck_assert(same_samples(r[0][k], r[t][k]));
      oc_heightfield_release(r[t][k]);
    }
  for (int k = 0; k < 4; k++)
    oc_heightfield_release(r[0][k]);
  oc_heightfield_release(src);
  oc_program_free(pr);
}
END_TEST

START_TEST(cancel_and_bad_parameters) {
  oc_error e = {0};
  int calls = 0;
  oc_progress stop = {cancel_at_once, &calls};
  oc_noise nz = {10, 1, 0, 3, 1};
  oc_heightfield_grid g = {64, 64, 1, 0, 0};
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, stop, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  ck_assert_int_ge(calls, 1);
  oc_progress none = {NULL, NULL};
  nz.wavelength = 0;
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'wavelength'"));
  nz.wavelength = 10;
  nz.amplitude = 1e300;
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'amplitude'"));
  nz.amplitude = 1;
  g.nx = 1;
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'size'"));
  g.nx = 60000, g.ny = 60000; /* 13 GiB: refused before allocating */
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, none, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  g = (oc_heightfield_grid){8, 8, NAN, 0, 0};
  ck_assert_ptr_null(oc_heightfield_fbm(&g, &nz, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'cell'"));
  g.cell = 1;
  oc_program *pr =
      oct_compile(OCT_OK(oc_sphere(oct_v(0, 0, 0), 3, 1, 1, &e)), 0, 0);
  ck_assert_ptr_null(oc_heightfield_from_program(pr, &g, 5, 5, 0, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'zrange'"));
  ck_assert_ptr_null(
      oc_heightfield_from_program(pr, &g, -INFINITY, 5, 0, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "'zrange'"));
  ck_assert_ptr_null(
      oc_heightfield_from_program(pr, &g, 1e12, 1e12 + 1e-4, 0, none, &e));
  ck_assert_ptr_nonnull(strstr(e.msg, "too thin"));
  ck_assert_ptr_null(oc_heightfield_from_program(pr, &g, -5, 5, 0, stop, &e));
  ck_assert_int_eq(e.code, OC_ECANCEL);
  oc_program_free(pr);
}
END_TEST

/* The top of a sphere of radius r and falloff R: f = T at distance
** r + R ginv(T) from the centre. Columns missing it give z0; a zrange
** whose top is inside gives z1. */
START_TEST(surface_of_a_sphere) {
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  double cx = 10, cy = -4, cz = 3, r = 6, R = 4;
  oc_program *pr =
      oct_compile(OCT_OK(oc_sphere(oct_v(cx, cy, cz), r, R, 1, &e)), 0, 0);
  double rad = r + R * oct_ginv(0.5);
  oc_heightfield_grid g = {45, 41, 0.5, cx - 11, cy - 10};
  oc_heightfield *hf =
      oc_heightfield_from_program(pr, &g, -20, 30, 0, none, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  const float *z = oc_heightfield_samples(hf);
  int hits = 0;
  for (int j = 0; j < g.ny; j++)
    for (int i = 0; i < g.nx; i++) {
      double x = g.x0 + i * g.cell, y = g.y0 + j * g.cell;
      double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
      double want = d2 < rad * rad ? cz + sqrt(rad * rad - d2) : -20;
      /* grazing columns: sqrt amplifies the bisection's tolerance */
      double tol = d2 < rad * rad * 0.99 ? 1e-5 : 0.1;
      ck_assert_msg(fabs(z[j * g.nx + i] - want) <= tol, "(%d %d) %g vs %g", i,
                    j, z[j * g.nx + i], want);
      hits += d2 < rad * rad;
    }
  ck_assert_int_gt(hits, 400);
  oc_heightfield_release(hf);
  /* a zrange topping out inside the ball */
  oc_heightfield_grid one = {2, 2, 0.1, cx, cy};
  hf = oc_heightfield_from_program(pr, &one, -20, cz + 1, 0, none, &e);
  ck_assert(oc_heightfield_samples(hf)[0] == (float)(cz + 1));
  oc_heightfield_release(hf);
  oc_program_free(pr);
}
END_TEST

/* A taper of huge factor makes the local Lipschitz bounds useless, so
** every step shrank to (z1 - z0) 1e-5: 1e5 evaluations per sample (12 s
** for this grid, beyond Check's timeout). Past a column's budget the
** steps grow to (z1 - z0) / 1024. */
START_TEST(loose_bounds_budget) {
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  oc_noise nz = {2, 0.5, 0, 3, 1};
  oc_taper_params tp = {.origin = oct_v(0, 0, 0),
                        .axis = oct_v(0, 0, 1),
                        .along = oct_v(1, 0, 0),
                        .from = 0,
                        .to = 5,
                        .factor = 1e12,
                        .height = 10};
  oc_node *st = OCT_OK(oc_strata(&nz, &e));
  oc_node *tn = OCT_OK(oc_taper(st, &tp, &e));
  oc_node_release(st);
  oc_program *pr = oct_compile(tn, 0, 0);
  oc_heightfield_grid g = {24, 24, 1, 0, 0};
  oc_heightfield *hf =
      oc_heightfield_from_program(pr, &g, -20, 20, 0, none, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  /* resistance stays below T = 1/2 in every column: z0 everywhere */
  const float *z = oc_heightfield_samples(hf);
  for (int k = 0; k < g.nx * g.ny; k++)
    ck_assert(z[k] == -20.0f);
  oc_heightfield_release(hf);
  oc_program_free(pr);
}
END_TEST

/* A horizontal plane with falloff: the surface lies at h + R ginv(T) for
** any T, with and without the column spans' help. */
START_TEST(surface_of_a_plane) {
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 2.5), oct_v(0, 0, 1), 3, 1, &e)), 0.3, 0);
  oc_heightfield_grid g = {5, 4, 10, -20, -20};
  oc_heightfield *hf =
      oc_heightfield_from_program(pr, &g, -100, 100, 0.7, none, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  double want = 2.5 + 3 * oct_ginv(0.7);
  for (int k = 0; k < 20; k++)
    ck_assert_double_eq_tol(oc_heightfield_samples(hf)[k], want, 1e-5);
  oc_heightfield_release(hf);
  oc_program_free(pr);
}
END_TEST

START_TEST(resample_and_crop) {
  oc_error e = {0};
  oc_progress none = {NULL, NULL};
  oc_heightfield *hf = wavy(41, 33, 2, 15);
  /* the same grid: identical */
  oc_heightfield_grid same = {41, 33, 2, -3.5, 12.25};
  oc_heightfield *a = oc_heightfield_resample(hf, &same, none, &e);
  ck_assert(same_samples(hf, a));
  oc_heightfield_release(a);
  /* finer: the interpolant at the new samples */
  oc_heightfield_grid fine = {161, 129, 0.5, -3.5, 12.25};
  a = oc_heightfield_resample(hf, &fine, none, &e);
  for (int j = 0; j < 129; j += 7)
    for (int i = 0; i < 161; i += 5)
      ck_assert(oc_heightfield_samples(a)[j * 161 + i] ==
                (float)oc_heightfield_height(hf, -3.5 + i * 0.5,
                                             12.25 + j * 0.5, NULL));
  oc_heightfield_release(a);
  /* coarser: a tent average, which cancels the highest frequency that
  ** point sampling would alias to full amplitude */
  int n = 64;
  float *z = malloc(sizeof(float) * n * n);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++)
      z[j * n + i] = (float)(10 + ((i + j) % 2 ? 1 : -1) + 0.5 * i);
  oc_heightfield *chk = grid_ok(n, n, 1, 0, 0, z);
  oc_heightfield_grid half = {32, 32, 2, 0, 0};
  a = oc_heightfield_resample(chk, &half, none, &e);
  for (int j = 1; j < 31; j++)
    for (int i = 1; i < 31; i++)
      ck_assert_double_eq_tol(oc_heightfield_samples(a)[j * 32 + i],
                              10 + 0.5 * (2 * i), 1e-5);
  oc_heightfield_release(a);
  free(z);
  oc_heightfield_release(chk);

  /* crop: samples and origin */
  oc_heightfield *c = oc_heightfield_crop(hf, 3, 5, 20, 9, &e);
  ck_assert_msg(c != NULL, "%s", e.msg);
  geometry_is(c, 18, 5, 2, -3.5 + 6, 12.25 + 10);
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 18; i++)
      ck_assert(oc_heightfield_samples(c)[j * 18 + i] ==
                oc_heightfield_samples(hf)[(j + 5) * 41 + i + 3]);
  oc_heightfield_release(c);
  ck_assert_ptr_null(oc_heightfield_crop(hf, 3, 5, 3, 9, &e));
  ck_assert_ptr_null(oc_heightfield_crop(hf, 0, 0, 41, 9, &e));
  ck_assert_int_eq(e.code, OC_EINVAL);
  oc_heightfield_release(hf);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("heightfield");
  TCase *t = tcase_create("interpolant");
  tcase_add_test(t, passes_through_samples);
  tcase_add_test(t, reproduces_planes);
  tcase_add_test(t, gradient_matches_differences);
  tcase_add_test(t, gradient_continuous_across_cells);
  suite_add_tcase(s, t);
  t = tcase_create("files");
  tcase_add_checked_fixture(t, mkdir_tmp, teardown);
  tcase_add_test(t, png16_round_trip);
  tcase_add_test(t, png16_exact_lattice);
  tcase_add_test(t, exr_round_trip);
  tcase_add_test(t, tiff_round_trip);
  tcase_add_test(t, tiff16_and_half);
  tcase_add_test(t, png8_and_png16_counts);
  tcase_add_test(t, geotiff_float32);
  tcase_add_test(t, metadata_and_overrides);
  tcase_add_test(t, repeat_saves_identical);
  tcase_add_test(t, file_errors);
  tcase_add_test(t, metadata_cannot_forge_lines);
  tcase_add_test(t, hostile_files);
  tcase_add_test(t, disk_full);
  tcase_add_test(t, raw16_round_trip);
  tcase_add_test(t, grid_arithmetic);
  suite_add_tcase(s, t);
  t = tcase_create("procedural");
  tcase_set_timeout(t, 60);
  tcase_add_test(t, fbm_is_the_turbulence_node);
  tcase_add_test(t, same_bytes_for_any_thread_count);
  tcase_add_test(t, cancel_and_bad_parameters);
  tcase_add_test(t, surface_of_a_sphere);
  tcase_add_test(t, loose_bounds_budget);
  tcase_add_test(t, surface_of_a_plane);
  tcase_add_test(t, resample_and_crop);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
