/*
** test_image.c — image buffers and oc_image_write: size limits, channel
** names, metadata, round trips through every format (read back with the
** bridge's reader), atomic writes and byte-identical repeats.
*/
#include <check.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
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
  strcpy(dir, oct_tmpdir("image"));
}

static void teardown(void) {
  oct_rm_tree(dir);
}

/* A test pattern with values below 0, above 1 and in between, and a NaN. */
static oc_image *pattern(int w, int h, int nc) {
  oc_error e = {0};
  oc_image *img = oc_image_new(w, h, nc, &e);
  ck_assert_msg(img != NULL, "%s", e.msg);
  float *px = oc_image_data(img);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++)
      for (int c = 0; c < nc; c++)
        px[((size_t)j * w + i) * nc + c] =
            (float)(-0.25 + 1.5 * ((i * 7 + j * 13 + c * 5) % 41) / 40.0);
  px[1] = NAN;
  return img;
}

static double quant(float x, double levels) {
  double v = isnan(x) ? 0.0 : fmin(fmax(x, 0.0), 1.0);
  return floor(v * levels + 0.5) / levels;
}

static void write_ok(const oc_image *img, const char *path, int bits) {
  oc_error e = {0};
  int rc = oc_image_write(img, path, bits, &e);
  ck_assert_msg(rc == OC_OK, "writing %s (bits %d): %d %s", path, bits, rc,
                e.msg);
}

static oc_image *read_ok(const char *path) {
  oc_error e = {0};
  oc_image *img = oc_oiio_read(path, &e);
  ck_assert_msg(img != NULL, "reading %s: %s", path, e.msg);
  return img;
}

/* Channel index by name in `img`, or -1. */
static int channel(const oc_image *img, const char *name) {
  for (int c = 0; c < oc_image_channels(img); c++)
    if (!strcmp(oc_image_channel_name(img, c), name)) return c;
  return -1;
}

/* Reads `path` back and compares its `nc` channels with the first `nc` of
** `img` quantized to `levels` (0: exact floats; -1: half precision). */
static void check_round_trip(const oc_image *img, const char *path, int nc,
                             double levels) {
  oc_image *back = read_ok(path);
  int w = oc_image_width(img), h = oc_image_height(img);
  int snc = oc_image_channels(img);
  ck_assert_int_eq(oc_image_width(back), w);
  ck_assert_int_eq(oc_image_height(back), h);
  ck_assert_int_eq(oc_image_channels(back), nc);
  const float *a = oc_image_cdata(img), *b = oc_image_cdata(back);
  for (size_t p = 0; p < (size_t)w * h; p++)
    for (int c = 0; c < nc; c++) {
      float x = a[p * snc + c], y = b[p * nc + c];
      double want, tol;
      if (levels > 0) {
        want = quant(x, levels);
        tol = 1e-6;
      } else if (levels == 0) {
        want = x;
        tol = 0;
      } else {
        want = x;
        tol = fabs(x) * (1.0 / 1024); /* half: 10-bit mantissa */
      }
      if (isnan(want)) {
        ck_assert_msg(isnan(y), "%s: pixel %zu ch %d: %g, want NaN", path, p, c,
                      y);
        continue;
      }
      ck_assert_msg(fabs(y - want) <= tol,
                    "%s: pixel %zu channel %d: read %.9g, wrote %.9g, want "
                    "%.9g",
                    path, p, c, y, x, want);
    }
  oc_image_free(back);
}

static int same_bytes(const char *p, const char *q) {
  FILE *a = fopen(p, "rb"), *b = fopen(q, "rb");
  ck_assert_ptr_nonnull(a);
  ck_assert_ptr_nonnull(b);
  int same = 1, ca, cb;
  do {
    ca = getc(a);
    cb = getc(b);
    if (ca != cb) same = 0;
  } while (same && ca != EOF);
  fclose(a);
  fclose(b);
  return same;
}

/* Output of `oiiotool --info -v path`. */
static void oiiotool_info(const char *path, char *out, size_t size) {
  char cmd[600];
  snprintf(cmd, sizeof cmd, "oiiotool --info -v '%s' 2>&1", path);
  FILE *f = popen(cmd, "r");
  ck_assert_ptr_nonnull(f);
  size_t n = fread(out, 1, size - 1, f);
  out[n] = '\0';
  int st = pclose(f);
  ck_assert_msg(st == 0, "oiiotool failed (%d): %s", st, out);
}

/* ---- buffers ------------------------------------------------------------ */

START_TEST(new_and_free) {
  oc_error e = {0};
  oc_image *img = oc_image_new(7, 3, 6, &e);
  ck_assert_ptr_nonnull(img);
  ck_assert_int_eq(oc_image_width(img), 7);
  ck_assert_int_eq(oc_image_height(img), 3);
  ck_assert_int_eq(oc_image_channels(img), 6);
  ck_assert_ptr_eq(oc_image_data(img), oc_image_cdata(img));
  for (int i = 0; i < 7 * 3 * 6; i++)
    ck_assert_float_eq(oc_image_cdata(img)[i], 0.0f);
  static const char *const want[] = {"R", "G", "B", "A", "c4", "c5"};
  for (int c = 0; c < 6; c++)
    ck_assert_str_eq(oc_image_channel_name(img, c), want[c]);
  ck_assert_ptr_null(oc_image_channel_name(img, 6));
  ck_assert_ptr_null(oc_image_channel_name(img, -1));
  /* The whole buffer is writable (ASan checks the bounds). */
  oc_image_data(img)[7 * 3 * 6 - 1] = 1.0f;
  oc_image_free(img);
  oc_image_free(NULL);
  oc_image *one = oc_image_new(1, 1, 1, &e);
  ck_assert_ptr_nonnull(one);
  ck_assert_str_eq(oc_image_channel_name(one, 0), "R");
  oc_image_free(one);
}
END_TEST

/* The kB of huge pages in the mapping of /proc/self/smaps holding p; -1
** when the system has no transparent huge pages to give (or no smaps). */
static long huge_kb_at(const void *p) {
  FILE *t = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
  char mode[128] = "";
  if (!t) return -1;
  if (!fgets(mode, sizeof mode, t)) mode[0] = '\0';
  fclose(t);
  if (strstr(mode, "[never]") || !strstr(mode, "[")) return -1;
  FILE *f = fopen("/proc/self/smaps", "r");
  if (!f) return -1;
  char line[512];
  int in = 0;
  long kb = -1;
  unsigned long a = (unsigned long)p;
  while (fgets(line, sizeof line, f)) {
    unsigned long lo, hi;
    if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2)
      in = a >= lo && a < hi;
    else if (in && sscanf(line, "AnonHugePages: %ld kB", &kb) == 1)
      break;
  }
  fclose(f);
  return kb;
}

/* A large image's pixels are asked for on huge pages (image.c
** HUGE_BYTES): written once over, they are, where the system gives
** them; and zeroed as any image's. */
START_TEST(large_on_huge_pages) {
  oc_image *img = oc_image_new(1024, 1024, 4, NULL); /* 16 MiB */
  ck_assert_ptr_nonnull(img);
  float *d = oc_image_data(img);
  for (size_t k = 0; k < (size_t)1024 * 1024 * 4; k += 1024) {
    ck_assert_float_eq(d[k], 0.0f);
    d[k] = 1.0f;
  }
  long kb = huge_kb_at(d + 2 * 1024 * 1024);
  if (kb >= 0) ck_assert_msg(kb >= 2048, "%ld kB on huge pages", kb);
  oc_image_free(img);
}
END_TEST

static void new_einval(int w, int h, int c, const char *param) {
  oc_error e = {0};
  oc_image *img = oc_image_new(w, h, c, &e);
  ck_assert_msg(img == NULL, "%d x %d x %d accepted", w, h, c);
  ck_assert_int_eq(e.code, OC_EINVAL);
  char q[32];
  snprintf(q, sizeof q, "'%s'", param);
  ck_assert_msg(strstr(e.msg, q) != NULL, "message '%s' lacks %s", e.msg, q);
}

START_TEST(size_limits) {
  new_einval(0, 1, 1, "width");
  new_einval(-5, 1, 1, "width");
  new_einval(65536, 1, 1, "width");
  new_einval(1, 0, 1, "height");
  new_einval(1, 65536, 1, "height");
  new_einval(1, 1, 0, "channels");
  new_einval(1, 1, 65, "channels");
  new_einval(1, 1, -1, "channels");
  oc_image *img = oc_image_new(65535, 1, 64, NULL); /* 16 MiB: fine */
  ck_assert_ptr_nonnull(img);
  oc_image_free(img);
}
END_TEST

START_TEST(absurd_sizes) {
  oc_error e = {0};
  /* 65535^2 x 64 floats: about a terabyte. */
  ck_assert_ptr_null(oc_image_new(65535, 65535, 64, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  unsigned long long mib =
      (65535ull * 65535ull * 64ull * 4ull + (1ull << 20) - 1) >> 20;
  char want[160];
  snprintf(want, sizeof want,
           "image of 65535 x 65535 x 64 floats needs %llu MiB, over the "
           "4096 MiB limit",
           mib);
  ck_assert_str_eq(e.msg, want);
  /* Just over 4 GiB. */
  e.code = OC_OK;
  ck_assert_ptr_null(oc_image_new(32768, 32769, 1, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  ck_assert_msg(strstr(e.msg, "needs 4097 MiB") != NULL, "%s", e.msg);
  /* A NULL err is allowed. */
  ck_assert_ptr_null(oc_image_new(65535, 65535, 4, NULL));
}
END_TEST

START_TEST(channel_names) {
  oc_error e = {0};
  oc_image *img = oc_image_new(2, 2, 5, NULL);
  ck_assert_int_eq(oc_image_set_channel_name(img, 4, "field", &e), OC_OK);
  ck_assert_str_eq(oc_image_channel_name(img, 4), "field");
  ck_assert_int_eq(oc_image_set_channel_name(img, 0, "height.z", &e), OC_OK);
  ck_assert_str_eq(oc_image_channel_name(img, 0), "height.z");
  char longest[64];
  memset(longest, 'x', 63);
  longest[63] = '\0';
  ck_assert_int_eq(oc_image_set_channel_name(img, 1, longest, &e), OC_OK);
  ck_assert_str_eq(oc_image_channel_name(img, 1), longest);

  char toolong[65];
  memset(toolong, 'x', 64);
  toolong[64] = '\0';
  const char *bad[] = {"", "a b", "tab\t", toolong, "\xc3\xa9t\xc3\xa9"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    e.code = OC_OK;
    ck_assert_int_eq(oc_image_set_channel_name(img, 2, bad[i], &e), OC_EINVAL);
    ck_assert_int_eq(e.code, OC_EINVAL);
    ck_assert_msg(strstr(e.msg, "'name'"), "%s", e.msg);
    ck_assert_str_eq(oc_image_channel_name(img, 2), "B");
  }
  ck_assert_int_eq(oc_image_set_channel_name(img, 5, "Z", &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'channel'"), "%s", e.msg);
  ck_assert_int_eq(oc_image_set_channel_name(img, -1, "Z", &e), OC_EINVAL);
  ck_assert_int_eq(oc_image_set_channel_name(img, 0, NULL, &e), OC_EINVAL);
  oc_image_free(img);
}
END_TEST

START_TEST(metadata) {
  oc_error e = {0};
  oc_image *img = oc_image_new(1, 1, 1, NULL);
  ck_assert_int_eq(oc_image_meta_count(img), 0);
  ck_assert_int_eq(oc_image_set_meta(img, "outcrop:seed", "42", &e), OC_OK);
  ck_assert_int_eq(oc_image_set_meta(img, "Software", "outcrop", &e), OC_OK);
  ck_assert_int_eq(oc_image_set_meta(img, "scene", "", &e), OC_OK);
  ck_assert_int_eq(oc_image_meta_count(img), 3);
  /* Same key without regard to case: replaced, not added. */
  ck_assert_int_eq(oc_image_set_meta(img, "OUTCROP:SEED", "7", &e), OC_OK);
  ck_assert_int_eq(oc_image_meta_count(img), 3);
  ck_assert_str_eq(oc_image_meta_get(img, "outcrop:seed"), "7");
  ck_assert_str_eq(oc_image_meta_key(img, 0), "outcrop:seed");
  ck_assert_str_eq(oc_image_meta_value(img, 1), "outcrop");
  ck_assert_ptr_null(oc_image_meta_key(img, 3));
  ck_assert_ptr_null(oc_image_meta_get(img, "missing"));

  const char *bad[] = {"",
                       "1abc",
                       "a b",
                       "compression",
                       "oiio:ColorSpace",
                       "tiff:Compression",
                       "Orientation",
                       "ExIf:Foo",
                       "with\"quote"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    e.code = OC_OK;
    ck_assert_msg(oc_image_set_meta(img, bad[i], "v", &e) == OC_EINVAL,
                  "key '%s' accepted", bad[i]);
    ck_assert_msg(strstr(e.msg, "'key'"), "%s", e.msg);
  }
  char key[81];
  memset(key, 'k', 80);
  key[80] = '\0';
  ck_assert_int_eq(oc_image_set_meta(img, key, "v", &e), OC_EINVAL);
  key[79] = '\0';
  ck_assert_int_eq(oc_image_set_meta(img, key, "v", &e), OC_OK);
  ck_assert_int_eq(oc_image_set_meta(img, "k", NULL, &e), OC_EINVAL);
  ck_assert_int_eq(oc_image_meta_count(img), 4);
  oc_image_free(img);
}
END_TEST

/* ---- formats ------------------------------------------------------------ */

START_TEST(png_round_trip) {
  oc_image *img = pattern(13, 9, 4);
  /* Round to nearest, not truncation: 0.999 is 255, 0.003 is 1. */
  float *px = oc_image_data(img);
  px[4] = 0.999f;
  px[5] = 0.003f;
  px[6] = 1.5f;
  px[7] = 0.25f; /* alpha below 1: colours must not be premultiplied */
  write_ok(img, oct_in_dir(dir, "a8.png"), 8);
  write_ok(img, oct_in_dir(dir, "a0.png"), 0);
  write_ok(img, oct_in_dir(dir, "a16.png"), 16);
  check_round_trip(img, oct_in_dir(dir, "a8.png"), 4, 255);
  check_round_trip(img, oct_in_dir(dir, "a0.png"), 4, 255);
  check_round_trip(img, oct_in_dir(dir, "a16.png"), 4, 65535);
  oc_image *back = read_ok(oct_in_dir(dir, "a8.png"));
  ck_assert_float_eq(oc_image_cdata(back)[4], 1.0f);
  ck_assert_float_eq_tol(oc_image_cdata(back)[5], 1.0f / 255, 1e-7);
  oc_image_free(back);
  oc_image_free(img);

  /* Grey, grey + alpha, RGB, and only the first four of six channels. */
  int ncs[] = {1, 2, 3, 6}, want[] = {1, 2, 3, 4};
  for (int k = 0; k < 4; k++) {
    img = pattern(5, 4, ncs[k]);
    char name[32];
    snprintf(name, sizeof name, "c%d.PNG", ncs[k]);
    write_ok(img, oct_in_dir(dir, name), 16);
    check_round_trip(img, oct_in_dir(dir, name), want[k], 65535);
    oc_image_free(img);
  }
}
END_TEST

START_TEST(jpeg_round_trip) {
  /* JPEG is lossy: a smooth image comes back close, not equal. */
  oc_image *img = oc_image_new(32, 16, 5, NULL);
  float *px = oc_image_data(img);
  for (int j = 0; j < 16; j++)
    for (int i = 0; i < 32; i++)
      for (int c = 0; c < 5; c++)
        px[(j * 32 + i) * 5 + c] = (float)(0.2 + 0.6 * (i + j + 4 * c) / 56.0);
  write_ok(img, oct_in_dir(dir, "a.jpg"), 0);
  write_ok(img, oct_in_dir(dir, "b.JPEG"), 8);
  oc_image *back = read_ok(oct_in_dir(dir, "a.jpg"));
  ck_assert_int_eq(oc_image_channels(back), 3);
  double worst = 0;
  for (int p = 0; p < 32 * 16; p++)
    for (int c = 0; c < 3; c++)
      worst =
          fmax(worst, fabs(oc_image_cdata(back)[p * 3 + c] - px[p * 5 + c]));
  ck_assert_msg(worst < 0.03, "JPEG error %g", worst);
  oc_image_free(back);
  oc_error e = {0};
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "c.jpg"), 16, &e),
                   OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'bits'") && strstr(e.msg, "JPEG"), "%s", e.msg);
  oc_image_free(img);

  img = pattern(8, 8, 1);
  write_ok(img, oct_in_dir(dir, "grey.jpg"), 8);
  back = read_ok(oct_in_dir(dir, "grey.jpg"));
  ck_assert_int_eq(oc_image_channels(back), 1);
  oc_image_free(back);
  oc_image_free(img);
}
END_TEST

START_TEST(tiff_round_trip) {
  oc_image *img = pattern(11, 7, 5);
  write_ok(img, oct_in_dir(dir, "a8.tif"), 8);
  write_ok(img, oct_in_dir(dir, "a16.tiff"), 16);
  write_ok(img, oct_in_dir(dir, "a0.TIF"), 0);
  write_ok(img, oct_in_dir(dir, "a32.tif"), 32);
  check_round_trip(img, oct_in_dir(dir, "a8.tif"), 4, 255);
  check_round_trip(img, oct_in_dir(dir, "a16.tiff"), 4, 65535);
  check_round_trip(img, oct_in_dir(dir, "a0.TIF"), 4,
                   65535); /* default: 16 bits */
  check_round_trip(img, oct_in_dir(dir, "a32.tif"), 4, 0); /* floats: exact */
  oc_image_free(img);
  for (int nc = 1; nc <= 3; nc++) {
    img = pattern(3, 3, nc);
    char name[32];
    snprintf(name, sizeof name, "c%d.tif", nc);
    write_ok(img, oct_in_dir(dir, name), 8);
    check_round_trip(img, oct_in_dir(dir, name), nc, 255);
    oc_image_free(img);
  }
}
END_TEST

START_TEST(exr_round_trip) {
  oc_image *img = pattern(9, 6, 6);
  oc_image_set_channel_name(img, 4, "field", NULL);
  float *px = oc_image_data(img);
  px[3] = 1234.5f; /* EXR keeps values outside [0, 1] */
  write_ok(img, oct_in_dir(dir, "h.exr"), 0);
  write_ok(img, oct_in_dir(dir, "f.EXR"), 32);
  write_ok(img, oct_in_dir(dir, "h16.exr"), 16);
  for (int k = 0; k < 3; k++) {
    const char *name = k == 0 ? "h.exr" : k == 1 ? "f.EXR" : "h16.exr";
    oc_image *back = read_ok(oct_in_dir(dir, name));
    ck_assert_int_eq(oc_image_channels(back), 6);
    /* Every channel under its name, wherever the file puts it. */
    for (int c = 0; c < 6; c++) {
      const char *cn = oc_image_channel_name(img, c);
      int bc = channel(back, cn);
      ck_assert_msg(bc >= 0, "%s: channel '%s' missing", name, cn);
      for (int p = 0; p < 9 * 6; p++) {
        float x = px[p * 6 + c], y = oc_image_cdata(back)[p * 6 + bc];
        if (isnan(x)) {
          ck_assert(isnan(y));
          continue;
        }
        double tol = k == 1 ? 0 : fabs(x) / 1024;
        ck_assert_msg(fabs(y - x) <= tol, "%s ch %s: %g vs %g", name, cn, y, x);
      }
    }
    oc_image_free(back);
  }
  oc_error e = {0};
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "b.exr"), 8, &e),
                   OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'bits'"), "%s", e.msg);
  /* EXR channel names must be unique. */
  oc_image_set_channel_name(img, 5, "field", NULL);
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "dup.exr"), 0, &e),
                   OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'field'"), "%s", e.msg);
  ck_assert_int_eq(access(oct_in_dir(dir, "dup.exr"), F_OK), -1);
  /* Other formats do not carry names, so duplicates do not matter. */
  write_ok(img, oct_in_dir(dir, "dup.png"), 8);
  oc_image_free(img);
}
END_TEST

START_TEST(metadata_in_files) {
  oc_image *img = pattern(4, 4, 4);
  oc_image_set_meta(img, "outcrop:seed", "42", NULL);
  oc_image_set_meta(img, "outcrop:script", "examples/demo.lua", NULL);
  oc_image_set_meta(img, "Software", "outcrop " OC_VERSION, NULL);
  const char *files[] = {"m.png", "m.tif", "m.exr"};
  for (int k = 0; k < 3; k++) {
    write_ok(img, oct_in_dir(dir, files[k]), 0);
    oc_image *back = read_ok(oct_in_dir(dir, files[k]));
    const char *sw = oc_image_meta_get(back, "Software");
    ck_assert_msg(sw && !strcmp(sw, "outcrop " OC_VERSION), "%s: Software %s",
                  files[k], sw ? sw : "(none)");
    char info[8192];
    oiiotool_info(oct_in_dir(dir, files[k]), info, sizeof info);
    if (k == 1) {
      /* TIFF has no free text fields: the keys go to ImageDescription. */
      const char *d = oc_image_meta_get(back, "ImageDescription");
      ck_assert_msg(d && strstr(d, "outcrop:seed=42") &&
                        strstr(d, "outcrop:script=examples/demo.lua"),
                    "ImageDescription: %s", d ? d : "(none)");
      ck_assert_msg(strstr(info, "outcrop:seed=42"), "%s", info);
    } else {
      const char *s = oc_image_meta_get(back, "outcrop:seed");
      ck_assert_msg(s && !strcmp(s, "42"), "%s: seed %s", files[k],
                    s ? s : "(none)");
      s = oc_image_meta_get(back, "outcrop:script");
      ck_assert_msg(s && !strcmp(s, "examples/demo.lua"), "%s", files[k]);
      ck_assert_msg(strstr(info, "outcrop:seed: \"42\""), "%s", info);
    }
    ck_assert_msg(strstr(info, "Software: \"outcrop " OC_VERSION "\""), "%s",
                  info);
    /* No timestamp sneaks in. */
    ck_assert_msg(!strstr(info, "DateTime: \"2"), "%s", info);
    oc_image_free(back);
  }
  oc_image_free(img);
}
END_TEST

START_TEST(repeat_writes_identical) {
  oc_image *img = pattern(20, 10, 5);
  oc_image_set_meta(img, "outcrop:seed", "1", NULL);
  const char *names[] = {"r.png",  "r16.png", "r.jpg", "r.tif",
                         "r8.tif", "r32.tif", "r.exr", "r32.exr"};
  int bits[] = {8, 16, 8, 0, 8, 32, 0, 32};
  for (int k = 0; k < 8; k++)
    write_ok(img, oct_in_dir(dir, names[k]), bits[k]);
  /* Timestamps have one-second resolution: cross a second boundary. */
  struct timespec pause = {1, 100000000};
  nanosleep(&pause, NULL);
  for (int k = 0; k < 8; k++) {
    char again[64];
    snprintf(again, sizeof again, "again-%s", names[k]);
    write_ok(img, oct_in_dir(dir, again), bits[k]);
    ck_assert_msg(same_bytes(oct_in_dir(dir, names[k]), oct_in_dir(dir, again)),
                  "%s differs between two writes", names[k]);
  }
  oc_image_free(img);
}
END_TEST

/* ---- failures ----------------------------------------------------------- */

START_TEST(unknown_extension) {
  oc_image *img = pattern(2, 2, 3);
  const char *bad[] = {"x.bmp", "noext", "x.png.gz", ".png", "x."};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    oc_error e = {0};
    ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, bad[i]), 0, &e),
                     OC_EINVAL);
    ck_assert_int_eq(e.code, OC_EINVAL);
    ck_assert_msg(strstr(e.msg, bad[i]) && strstr(e.msg, ".png") &&
                      strstr(e.msg, ".jpg") && strstr(e.msg, ".tif") &&
                      strstr(e.msg, ".exr"),
                  "%s", e.msg);
  }
  oc_error e = {0};
  ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "x.png"), 32, &e),
                   OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'bits'") && strstr(e.msg, "8 or 16"), "%s",
                e.msg);
  ck_assert_int_eq(oc_image_write(img, "", 0, &e), OC_EINVAL);
  ck_assert_int_eq(oc_image_write(img, NULL, 0, &e), OC_EINVAL);
  ck_assert_int_eq(oc_image_write(NULL, oct_in_dir(dir, "y.png"), 0, &e),
                   OC_EINVAL);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);
  oc_image_free(img);
}
END_TEST

START_TEST(unwritable_paths) {
  oc_image *img = pattern(4, 4, 4);
  oc_error e = {0};
  /* Missing folder: the message names the path and the reason. */
  const char *p = oct_in_dir(dir, "missing/y.png");
  ck_assert_int_eq(oc_image_write(img, p, 0, &e), OC_EIO);
  char want[300];
  snprintf(want, sizeof want, "cannot write '%s': No such file or directory",
           p);
  ck_assert_str_eq(e.msg, want);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);

  /* The final name is a folder: the temporary file is written, the rename
  ** fails, and the temporary file must be gone. */
  ck_assert_int_eq(mkdir(oct_in_dir(dir, "taken.exr"), 0777), 0);
  for (int k = 0; k < 2; k++) {
    const char *name = k ? "taken.exr" : "taken.exr/";
    e.code = OC_OK;
    int rc = oc_image_write(img, oct_in_dir(dir, name), 0, &e);
    ck_assert_int_ne(rc, OC_OK);
    if (k) {
      ck_assert_int_eq(rc, OC_EIO);
      ck_assert_msg(strstr(e.msg, "cannot write '") && strstr(e.msg, name),
                    "%s", e.msg);
    }
    char names[256];
    int n = oct_count_entries(dir, names, sizeof names);
    ck_assert_msg(n == 1, "left behind: %s", names);
    ck_assert_int_eq(oct_count_entries(oct_in_dir(dir, "taken.exr"), NULL, 0),
                     0);
  }

  /* A read-only folder (root ignores permissions, so only as a user). */
  if (geteuid() != 0) {
    ck_assert_int_eq(mkdir(oct_in_dir(dir, "ro"), 0555), 0);
    ck_assert_int_eq(oc_image_write(img, oct_in_dir(dir, "ro/z.tif"), 0, &e),
                     OC_EIO);
    ck_assert_msg(strstr(e.msg, "Permission denied"), "%s", e.msg);
    chmod(oct_in_dir(dir, "ro"), 0755);
  }
  oc_image_free(img);
}
END_TEST

START_TEST(overwrite_is_atomic) {
  oc_image *a = pattern(6, 6, 3), *b = oc_image_new(6, 6, 3, NULL);
  const char *p = oct_in_dir(dir, "o.png");
  write_ok(a, p, 8);
  write_ok(b, p, 8); /* replaces: all zero now */
  oc_image *back = read_ok(p);
  for (int i = 0; i < 6 * 6 * 3; i++)
    ck_assert_float_eq(oc_image_cdata(back)[i], 0.0f);
  oc_image_free(back);
  char names[256];
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 1, "%s", names);
  /* A failed write leaves the previous file as it was. */
  oc_error e = {0};
  ck_assert_int_eq(oc_image_write(a, p, 12, &e), OC_EINVAL);
  back = read_ok(p);
  ck_assert_float_eq(oc_image_cdata(back)[0], 0.0f);
  oc_image_free(back);
  /* Relative paths: the temporary file goes to the same (current) folder. */
  char cwd[512];
  ck_assert_ptr_nonnull(getcwd(cwd, sizeof cwd));
  ck_assert_int_eq(chdir(dir), 0);
  write_ok(a, "rel.tif", 8);
  ck_assert_int_eq(chdir(cwd), 0);
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 2, "%s", names);
  check_round_trip(a, oct_in_dir(dir, "rel.tif"), 3, 255);
  oc_image_free(a);
  oc_image_free(b);
}
END_TEST

START_TEST(read_errors) {
  oc_error e = {0};
  ck_assert_ptr_null(oc_oiio_read(oct_in_dir(dir, "nothing.png"), &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_msg(strstr(e.msg, "cannot read '") && strstr(e.msg, "nothing.png"),
                "%s", e.msg);
  FILE *f = fopen(oct_in_dir(dir, "junk.png"), "wb");
  fputs("this is not a PNG file at all", f);
  fclose(f);
  ck_assert_ptr_null(oc_oiio_read(oct_in_dir(dir, "junk.png"), &e));
  ck_assert_int_eq(e.code, OC_EIO);
  ck_assert_msg(strstr(e.msg, "unrecognised image format"), "%s", e.msg);
  /* not a regular file: refused at once, never probed by every reader */
  ck_assert_ptr_null(oc_oiio_read("/dev/zero", &e));
  ck_assert_msg(strstr(e.msg, "not a regular file"), "%s", e.msg);
}
END_TEST

/* Values with line breaks cannot forge a line of a TIFF or JPEG
** description: they come back whole, and the seed read back is the real
** one. In PNG a free description is text, never parsed into keys. */
START_TEST(metadata_cannot_forge_lines) {
  const char *forged = "scene.lua\noutcrop:seed=99";
  const char *tricky = "\"q\" \\ tab\t\x01 end";
  oc_image *img = pattern(4, 4, 3);
  oc_image_set_meta(img, "outcrop:seed", "42", NULL);
  oc_image_set_meta(img, "outcrop:scene", forged, NULL);
  oc_image_set_meta(img, "outcrop:params", tricky, NULL);
  oc_image_set_meta(img, "ImageDescription", "x\noutcrop:seed=7", NULL);
  const char *files[] = {"f.tif", "f.jpg", "f.png"};
  for (int k = 0; k < 3; k++) {
    write_ok(img, oct_in_dir(dir, files[k]), 8);
    oc_image *back = read_ok(oct_in_dir(dir, files[k]));
    const char *seed = oc_image_meta_get(back, "outcrop:seed");
    const char *scene = oc_image_meta_get(back, "outcrop:scene");
    const char *params = oc_image_meta_get(back, "outcrop:params");
    const char *d = oc_image_meta_get(back, "ImageDescription");
    ck_assert_msg(seed && strcmp(seed, "42") == 0, "%s: seed %s", files[k],
                  seed ? seed : "(none)");
    ck_assert_msg(scene && strcmp(scene, forged) == 0, "%s: scene %s", files[k],
                  scene ? scene : "(none)");
    ck_assert_msg(params && strcmp(params, tricky) == 0, "%s: params %s",
                  files[k], params ? params : "(none)");
    ck_assert_msg(d && strcmp(d, "x\noutcrop:seed=7") == 0,
                  "%s: description %s", files[k], d ? d : "(none)");
    oc_image_free(back);
  }
  oc_image_free(img);
}
END_TEST

/* libjpeg exits the process on an image wider or taller than 65500: such
** a write is refused before the encoder runs, and nothing is left. */
START_TEST(jpeg_size_limit) {
  oc_error e = {0};
  oc_image *img = oc_image_new(65501, 2, 3, &e);
  ck_assert_ptr_nonnull(img);
  const char *p = oct_in_dir(dir, "wide.jpg");
  ck_assert_int_eq(oc_image_write(img, p, 0, &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "65500") && strstr(e.msg, "65501 x 2"), "%s",
                e.msg);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);
  oc_image_free(img);
  img = oc_image_new(2, 65501, 1, &e);
  ck_assert_int_eq(oc_image_write(img, p, 0, &e), OC_EINVAL);
  oc_image_free(img);
  img = pattern(65500, 1, 3); /* the largest that JPEG holds */
  write_ok(img, p, 0);
  oc_image_free(img);
}
END_TEST

/* A full disk: every format reports it, and leaves neither the file nor
** its temporary; once there is room, the same folder takes a small file.
** (The PNG writer used to report success and rename a truncated file into
** place, and libjpeg to exit the process.) */
START_TEST(disk_full) {
  const char *fs = oct_tmpfs(64 * 1024, "image disk_full");
  if (!fs) return;
  oct_rng r = oct_rng_new(11);
  oc_error e = {0};
  oc_image *big = oc_image_new(512, 512, 4, &e), *small = pattern(4, 4, 4);
  ck_assert_ptr_nonnull(big);
  float *px = oc_image_data(big);
  for (size_t i = 0; i < 512 * 512 * 4; i++) /* noise: no compression */
    px[i] = (float)oct_unif(&r, 0, 1);
  oc_image_set_meta(big, "outcrop:seed", "1", NULL);
  const char *files[] = {"f.png", "f.tif", "f.jpg", "f.exr"};
  for (int k = 0; k < 4; k++) {
    const char *p = oct_in_dir(fs, files[k]);
    int rc = oc_image_write(big, p, 0, &e);
    oct_assert_full(rc, e.msg, p, fs);
    write_ok(small, p, 0);
    oc_image *back = read_ok(p);
    ck_assert_int_eq(oc_image_width(back), 4);
    oc_image_free(back);
    ck_assert_int_eq(unlink(p), 0);
  }
  oc_image_free(big);
  oc_image_free(small);
  oct_tmpfs_done(fs);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("image");
  TCase *t = tcase_create("buffers");
  tcase_add_test(t, new_and_free);
  tcase_add_test(t, large_on_huge_pages);
  tcase_add_test(t, size_limits);
  tcase_add_test(t, absurd_sizes);
  tcase_add_test(t, channel_names);
  tcase_add_test(t, metadata);
  suite_add_tcase(s, t);
  t = tcase_create("files");
  tcase_add_checked_fixture(t, mkdir_tmp, teardown);
  tcase_add_test(t, png_round_trip);
  tcase_add_test(t, jpeg_round_trip);
  tcase_add_test(t, tiff_round_trip);
  tcase_add_test(t, exr_round_trip);
  tcase_add_test(t, metadata_in_files);
  tcase_add_test(t, repeat_writes_identical);
  tcase_add_test(t, unknown_extension);
  tcase_add_test(t, unwritable_paths);
  tcase_add_test(t, overwrite_is_atomic);
  tcase_add_test(t, read_errors);
  tcase_add_test(t, metadata_cannot_forge_lines);
  tcase_add_test(t, jpeg_size_limit);
  tcase_add_test(t, disk_full);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
