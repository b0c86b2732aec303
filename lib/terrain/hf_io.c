/*
** hf_io.c — heightfields to and from image files: oc_heightfield_load and
** oc_heightfield_save.
**
** Files hold one channel, north up (the top row is the grid's last row).
** Integer files hold counts q with elevation = q scale + offset; the
** cell, origin, scale and offset travel as metadata written with 17
** significant digits, so that a saved grid loads back to exactly the
** quantized elevations and a float file to exactly its floats.
*/
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/palette.h"
#include "io/atomic.h"
#include "io/metatext.h"
#include "io/oiio.h"
#include "io/oiio_hf.h"
#include "outcrop.h"

/* The metadata keys, in the order of the load parameters they fill. */
enum { M_CELL, M_X0, M_Y0, M_SCALE, M_OFFSET, NKEYS };
static const char *const keys[NKEYS] = {"outcrop:cell", "outcrop:x0",
                                        "outcrop:y0", "outcrop:scale",
                                        "outcrop:offset"};

/* ---- loading ----------------------------------------------------------- */

typedef struct loader {
  const char *path;
  oc_heightfield_load_params p; /* what the caller gave */
  /* values found in the file: [0] as attributes of their own, [1] as
  ** lines of the ImageDescription (TIFF), used only when [0] lacks them */
  double meta[2][NKEYS];
  int found[2][NKEYS];
  int memory_failed; /* the description could not be parsed */
  oc_heightfield *hf;
} loader;

/* A whole string holding one finite number. */
static int parse_number(const char *s, double *out) {
  char *end;
  double v = strtod(s, &end);
  while (*end == ' ' || *end == '\t')
    end++;
  if (end == s || *end != '\0' || !isfinite(v)) return 0;
  *out = v;
  return 1;
}

static void take(loader *ld, int from, const char *key, const char *value) {
  for (int k = 0; k < NKEYS; k++)
    if (strcasecmp(key, keys[k]) == 0) {
      double v;
      if (parse_number(value, &v)) {
        ld->meta[from][k] = v;
        ld->found[from][k] = 1;
      }
    }
}

static void take_line(void *ud, const char *key, const char *value) {
  take(ud, 1, key, value);
}

/* TIFF keeps keys it has no tag for as "key=value" lines of its
** ImageDescription, values quoted (see io/metatext.h); other formats keep
** them as attributes of their own. */
static void on_attr(void *ud, const char *key, const char *value) {
  loader *ld = ud;
  if (strcasecmp(key, "ImageDescription") != 0)
    take(ld, 0, key, value);
  else if (oc_meta_unfold(value, take_line, ld) != 0)
    ld->memory_failed = 1;
}

static double pick(const loader *ld, unsigned bit, double given, int k,
                   double def) {
  if (ld->p.given & bit) return given;
  for (int from = 0; from < 2; from++)
    if (ld->found[from][k]) return ld->meta[from][k];
  return def;
}

static float *on_begin(void *ud, int w, int h, int channels, const char *type,
                       oc_error *err) {
  loader *ld = ud;
  (void)channels, (void)type;
  if (ld->memory_failed) {
    oc_seterr(err, OC_ENOMEM, "cannot load '%s': out of memory", ld->path);
    return NULL;
  }
  if (w < 2 || h < 2) {
    oc_seterr(err, OC_EINVAL,
              "cannot load '%s': it is %d x %d pixels, a heightfield needs "
              "at least 2 x 2",
              ld->path, w, h);
    return NULL;
  }
  double cell = pick(ld, OC_HEIGHTFIELD_GIVE_CELL, ld->p.cell, M_CELL, 1);
  double x0 = pick(ld, OC_HEIGHTFIELD_GIVE_ORIGIN, ld->p.x0, M_X0, 0);
  double y0 = pick(ld, OC_HEIGHTFIELD_GIVE_ORIGIN, ld->p.y0, M_Y0, 0);
  oc_error e = {OC_OK, ""};
  ld->hf = oc_heightfield_new(w, h, cell, x0, y0, NULL, &e);
  if (!ld->hf) {
    oc_seterr(err, e.code, "cannot load '%s': %s", ld->path, e.msg);
    return NULL;
  }
  return oc_heightfield_samples_mut(ld->hf);
}

/* Turns the image rows (top first, raw values) into grid rows (j = 0 at
** the bottom, elevations). */
static int finish_load(loader *ld, oc_error *err) {
  oc_heightfield *hf = ld->hf;
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  float *z = oc_heightfield_samples_mut(hf);
  for (int a = 0, b = ny - 1; a < b; a++, b--) {
    float *ra = z + (size_t)a * nx, *rb = z + (size_t)b * nx;
    for (int i = 0; i < nx; i++) {
      float t = ra[i];
      ra[i] = rb[i];
      rb[i] = t;
    }
  }
  double scale = pick(ld, OC_HEIGHTFIELD_GIVE_SCALE, ld->p.scale, M_SCALE, 1);
  double offset =
      pick(ld, OC_HEIGHTFIELD_GIVE_OFFSET, ld->p.offset, M_OFFSET, 0);
  if (!isfinite(scale) || !isfinite(offset))
    return oc_seterr(err, OC_EINVAL,
                     "cannot load '%s': 'scale' and 'offset' must be finite",
                     ld->path);
  /* scale 1 and offset 0 copy the values as they are, -0.0 included. */
  int identity = scale == 1 && offset == 0;
  size_t n = (size_t)nx * (size_t)ny;
  for (size_t k = 0; k < n; k++) {
    float v = identity ? z[k] : (float)(z[k] * scale + offset);
    if (!isfinite(v))
      return oc_seterr(err, OC_EINVAL,
                       "cannot load '%s': the elevation of sample (%zu, %zu) "
                       "is not finite (%g)",
                       ld->path, k % (size_t)nx, k / (size_t)nx, (double)v);
    z[k] = v;
  }
  return OC_OK;
}

oc_heightfield *oc_heightfield_load(const char *path,
                                    const oc_heightfield_load_params *p,
                                    oc_error *err) {
  if (!path || !*path) {
    oc_seterr(err, OC_EINVAL, "'path' must be a non-empty file name");
    return NULL;
  }
  loader ld;
  memset(&ld, 0, sizeof ld);
  ld.path = path;
  if (p) ld.p = *p;
  if ((ld.p.given & OC_HEIGHTFIELD_GIVE_CELL) &&
      (!(ld.p.cell > 0) || !isfinite(ld.p.cell))) {
    oc_seterr(err, OC_EINVAL, "'cell' must be > 0 (got %g)", ld.p.cell);
    return NULL;
  }
  oc_oiio_raw r = {on_attr, on_begin, &ld, ld.p.progress};
  int rc = oc_oiio_read_raw(path, &r, err);
  if (rc == OC_OK) rc = finish_load(&ld, err);
  if (rc != OC_OK) {
    oc_heightfield_release(ld.hf);
    return NULL;
  }
  return ld.hf;
}

/* ---- RAW ----------------------------------------------------------------- */

oc_heightfield *oc_heightfield_load_raw(const char *path, int nx, int ny,
                                        const oc_heightfield_load_params *p,
                                        oc_error *err) {
  oc_heightfield_load_params d = {0, 1, 1, 0, 0, 0, {NULL, NULL}};
  if (!p) p = &d;
  if (!path || !*path) {
    oc_seterr(err, OC_EINVAL, "'path' must be a non-empty file name");
    return NULL;
  }
  double cell = p->given & OC_HEIGHTFIELD_GIVE_CELL ? p->cell : 1;
  double scale = p->given & OC_HEIGHTFIELD_GIVE_SCALE ? p->scale : 1;
  double offset = p->given & OC_HEIGHTFIELD_GIVE_OFFSET ? p->offset : 0;
  double x0 = p->given & OC_HEIGHTFIELD_GIVE_ORIGIN ? p->x0 : 0;
  double y0 = p->given & OC_HEIGHTFIELD_GIVE_ORIGIN ? p->y0 : 0;
  if (!isfinite(scale) || !isfinite(offset)) {
    oc_seterr(err, OC_EINVAL,
              "cannot load '%s': 'scale' and 'offset' must be finite", path);
    return NULL;
  }
  if ((nx != 0 || ny != 0) && (nx < 2 || ny < 2)) {
    oc_seterr(err, OC_EINVAL,
              "cannot load '%s': 'size' must be at least 2 x 2 (got %d x %d)",
              path, nx, ny);
    return NULL;
  }
  /* only a regular file: a FIFO or a device must not block or stream */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  struct stat st;
  if (fd < 0 || fstat(fd, &st) != 0) {
    oc_seterr(err, OC_EIO, "cannot load '%s': %s", path, strerror(errno));
    if (fd >= 0) close(fd);
    return NULL;
  }
  if (!S_ISREG(st.st_mode)) {
    close(fd);
    oc_seterr(err, OC_EIO, "cannot load '%s': not a regular file", path);
    return NULL;
  }
  unsigned long long bytes = (unsigned long long)st.st_size;
  if (nx == 0) {
    /* square: 2 n^2 bytes */
    unsigned long long n = bytes / 2, s = (unsigned long long)sqrt((double)n);
    while (s * s > n)
      s--;
    while ((s + 1) * (s + 1) <= n)
      s++;
    if (bytes % 2 || s * s != n || s < 2 || s > 65535) {
      close(fd);
      oc_seterr(err, OC_EINVAL,
                "cannot load '%s': %llu bytes are not a square grid of "
                "16-bit samples: give 'size' = {nx, ny}",
                path, bytes);
      return NULL;
    }
    nx = ny = (int)s;
  }
  if (bytes != 2ull * (unsigned long long)nx * (unsigned long long)ny) {
    close(fd);
    oc_seterr(err, OC_EINVAL,
              "cannot load '%s': it has %llu bytes, %d x %d 16-bit samples "
              "need %llu",
              path, bytes, nx, ny,
              2ull * (unsigned long long)nx * (unsigned long long)ny);
    return NULL;
  }
  oc_error e = {OC_OK, ""};
  oc_heightfield *hf = oc_heightfield_new(nx, ny, cell, x0, y0, NULL, &e);
  if (!hf) {
    close(fd);
    oc_seterr(err, e.code, "cannot load '%s': %s", path, e.msg);
    return NULL;
  }
  float *z = oc_heightfield_samples_mut(hf);
  unsigned char buf[8192];
  size_t k = 0, n = (size_t)nx * (size_t)ny;
  int bad = 0;
  while (k < n && !bad) {
    size_t want = (n - k) * 2 < sizeof buf ? (n - k) * 2 : sizeof buf;
    ssize_t got = read(fd, buf, want);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0 || got % 2) {
      /* a file that shrank, or an odd read: refuse rather than guess */
      bad = 1;
      break;
    }
    for (ssize_t b = 0; b < got; b += 2) {
      size_t r = k / (size_t)nx, i = k % (size_t)nx;
      /* image order: the first row is the grid's last (north up) */
      size_t at = ((size_t)ny - 1 - r) * (size_t)nx + i;
      double q = buf[b] | (unsigned)buf[b + 1] << 8;
      z[at] = (float)(q * scale + offset);
      if (!isfinite(z[at])) bad = 2;
      k++;
    }
    if (p->progress.fn && p->progress.fn(p->progress.ud, (double)k / n)) {
      close(fd);
      oc_heightfield_release(hf);
      oc_seterr(err, OC_ECANCEL, "loading '%s' cancelled", path);
      return NULL;
    }
  }
  close(fd);
  if (bad) {
    oc_heightfield_release(hf);
    if (bad == 2)
      oc_seterr(err, OC_EINVAL,
                "cannot load '%s': 'scale' %g and 'offset' %g give "
                "elevations beyond float range",
                path, scale, offset);
    else
      oc_seterr(err, OC_EIO, "cannot load '%s': short read", path);
    return NULL;
  }
  return hf;
}

/* ---- saving ------------------------------------------------------------ */

typedef enum kind { PNG, TIFF, EXR, RAW } kind;

static const struct {
  const char *ext;
  kind kind;
} extensions[] = {{".png", PNG}, {".tif", TIFF}, {".tiff", TIFF},
                  {".exr", EXR}, {".r16", RAW},  {".raw", RAW}};

static const char *const oiio_names[] = {"png", "tiff", "openexr", "raw"};

static int file_kind(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = strrchr(base, '.');
  if (!dot || dot == base) return -1;
  for (size_t i = 0; i < sizeof extensions / sizeof *extensions; i++)
    if (strcasecmp(dot, extensions[i].ext) == 0) return (int)extensions[i].kind;
  return -1;
}

/* Sample type for `bits`, or -1 when the format cannot hold it. */
static int sample_type(kind k, int bits) {
  switch (k) {
  case PNG:
    return bits == 0 || bits == 16 ? OC_OIIO_U16 : bits == 8 ? OC_OIIO_U8 : -1;
  case TIFF:
    return bits == 0 || bits == 32 ? OC_OIIO_F32
           : bits == 16            ? OC_OIIO_U16
                                   : -1;
  case EXR:
    return bits == 0 || bits == 32 ? OC_OIIO_F32
           : bits == 16            ? OC_OIIO_HALF
                                   : -1;
  case RAW:
    return bits == 0 || bits == 16 ? OC_OIIO_U16 : -1;
  }
  return -1;
}

static const char *const bits_allowed[] = {"8 or 16", "16 or 32",
                                           "16 (half) or 32 (float)", "16"};

/* The counts of an integer file, in image order (top row first). */
static void *quantize(const oc_heightfield *hf, int type, double scale,
                      double offset, int fixed, const char *path,
                      oc_error *err) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  const float *z = oc_heightfield_samples(hf);
  double qmax = type == OC_OIIO_U8 ? 255 : 65535;
  size_t size = type == OC_OIIO_U8 ? 1 : 2;
  unsigned char *buf = malloc((size_t)nx * (size_t)ny * size);
  if (!buf) {
    oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
    return NULL;
  }
  for (int r = 0; r < ny; r++) {
    const float *row = z + (size_t)(ny - 1 - r) * (size_t)nx;
    for (int i = 0; i < nx; i++) {
      double q = floor((row[i] - offset) / scale + 0.5);
      if (!(q >= 0 && q <= qmax)) {
        if (fixed) {
          oc_seterr(err, OC_EINVAL,
                    "cannot write '%s': elevation %g at sample (%d, %d) is "
                    "outside [offset, offset + %.0f scale] = [%g, %g]",
                    path, (double)row[i], i, ny - 1 - r, qmax, offset,
                    offset + qmax * scale);
          free(buf);
          return NULL;
        }
        q = q < 0 ? 0 : qmax; /* fitted: a rounding step outside at most */
      }
      size_t k = (size_t)r * (size_t)nx + (size_t)i;
      if (size == 1)
        buf[k] = (unsigned char)q;
      else
        ((uint16_t *)buf)[k] = (uint16_t)q;
    }
  }
  return buf;
}

/* The floats in image order. */
static float *flipped(const oc_heightfield *hf, const char *path,
                      oc_error *err) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  float *buf = malloc((size_t)nx * (size_t)ny * sizeof *buf);
  if (!buf) {
    oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
    return NULL;
  }
  for (int r = 0; r < ny; r++)
    memcpy(buf + (size_t)r * nx,
           oc_heightfield_samples(hf) + (size_t)(ny - 1 - r) * nx,
           (size_t)nx * sizeof *buf);
  return buf;
}

static int is_ours(const char *key) {
  for (int k = 0; k < NKEYS; k++)
    if (strcasecmp(key, keys[k]) == 0) return 1;
  return 0;
}

/* The colour picture of the grid through a palette: 8-bit RGB, north up,
** with the caller's metadata only (it is no heightfield file). */
static int save_colors(const oc_heightfield *hf, int dir, const char *path,
                       int k, const oc_heightfield_save_params *p,
                       oc_error *err) {
  if (k != PNG && k != TIFF)
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': a palette picture must be .png or "
                     ".tif",
                     path);
  int rc = oc_palette_check(p->stops, p->nstops, err);
  if (rc != OC_OK) return rc;
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  unsigned char *px = malloc((size_t)nx * (size_t)ny * 3);
  if (!px)
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  const float *z = oc_heightfield_samples(hf);
  for (int r = 0; r < ny; r++)
    for (int i = 0; i < nx; i++) {
      double rgb[3];
      oc_palette_eval(p->stops, p->nstops,
                      z[(size_t)(ny - 1 - r) * (size_t)nx + (size_t)i], rgb);
      unsigned char *o = px + 3 * ((size_t)r * (size_t)nx + (size_t)i);
      for (int c = 0; c < 3; c++)
        o[c] = (unsigned char)lround(rgb[c] * 255);
    }
  const char *names[3] = {"R", "G", "B"};
  oc_oiio_out out = {
      .format = oiio_names[k],
      .width = nx,
      .height = ny,
      .channels = 3,
      .type = OC_OIIO_U8,
      .pixels = px,
      .alpha = -1,
      .channel_names = names,
      .meta = p->meta,
      .nmeta = p->nmeta,
  };
  rc = oc_oiio_write_at(dir, path, &out, err);
  free(px);
  return rc;
}

/* RAW: the counts as little-endian uint16, image order, no header (the
** layout of Unity's and Unreal's .r16 / .raw heightmaps). */
static int write_raw(const uint16_t *q, size_t n, int dir, const char *path,
                     oc_error *err) {
  oc_atomic a;
  int rc = oc_atomic_begin_at(&a, dir, path, err);
  if (rc != OC_OK) return rc;
  unsigned char buf[8192];
  size_t used = 0;
  for (size_t k = 0; k < n; k++) {
    buf[used++] = (unsigned char)(q[k] & 0xff);
    buf[used++] = (unsigned char)(q[k] >> 8);
    if (used == sizeof buf || k + 1 == n) {
      oc_atomic_write(&a, buf, used);
      used = 0;
    }
  }
  return oc_atomic_commit(&a, err);
}

int oc_heightfield_save(const oc_heightfield *hf, const char *path,
                        const oc_heightfield_save_params *p, double used[2],
                        oc_error *err) {
  return oc_heightfield_save_at(hf, AT_FDCWD, path, p, used, err);
}

int oc_heightfield_save_at(const oc_heightfield *hf, int dir, const char *path,
                           const oc_heightfield_save_params *p, double used[2],
                           oc_error *err) {
  static const oc_heightfield_save_params defaults = {0,    0, 1,    0,
                                                      NULL, 0, NULL, 0};
  if (!hf) return oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
  if (!path || !*path)
    return oc_seterr(err, OC_EINVAL, "'path' must be a non-empty file name");
  if (!p) p = &defaults;
  int k = file_kind(path);
  if (k < 0)
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': unknown heightfield format (use "
                     ".png, .tif, .tiff, .exr, .r16 or .raw)",
                     path);
  if (p->nstops > 0) {
    int rc = save_colors(hf, dir, path, k, p, err);
    if (rc == OC_OK && used) used[0] = 1, used[1] = 0;
    return rc;
  }
  int type = sample_type((kind)k, p->bits);
  if (type < 0)
    return oc_seterr(err, OC_EINVAL, "'bits' must be %s for %s (got %d)",
                     bits_allowed[k], oiio_names[k], p->bits);
  int integer = type == OC_OIIO_U8 || type == OC_OIIO_U16;
  double scale = 1, offset = 0;
  if (p->fixed) {
    if (!integer)
      return oc_seterr(err, OC_EINVAL,
                       "'scale' and 'offset' apply to 8- and 16-bit files "
                       "only (floats are stored as they are)");
    if (!(p->scale > 0) || !isfinite(p->scale))
      return oc_seterr(err, OC_EINVAL, "'scale' must be > 0 (got %g)",
                       p->scale);
    if (!isfinite(p->offset))
      return oc_seterr(err, OC_EINVAL, "'offset' must be finite (got %g)",
                       p->offset);
    scale = p->scale;
    offset = p->offset;
  } else if (integer) {
    double lo, hi;
    oc_heightfield_minmax(hf, &lo, &hi);
    offset = lo;
    scale = (hi - lo) / (type == OC_OIIO_U8 ? 255.0 : 65535.0);
    if (!(scale > 0) || !isfinite(scale)) scale = 1;
  }

  void *px = integer ? quantize(hf, type, scale, offset, p->fixed, path, err)
                     : (void *)flipped(hf, path, err);
  if (!px) return err ? err->code : OC_ENOMEM;
  if (k == RAW) {
    int rc = write_raw(
        px, (size_t)oc_heightfield_nx(hf) * (size_t)oc_heightfield_ny(hf), dir,
        path, err);
    free(px);
    if (rc == OC_OK && used) used[0] = scale, used[1] = offset;
    return rc;
  }

  double x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  double vals[NKEYS] = {oc_heightfield_cell(hf), x0, y0, scale, offset};
  char text[NKEYS][32];
  size_t nmeta = NKEYS;
  const char **meta = malloc((2 * (NKEYS + p->nmeta)) * sizeof *meta);
  if (!meta) {
    free(px);
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  }
  for (int m = 0; m < NKEYS; m++) {
    snprintf(text[m], sizeof text[m], "%.17g", vals[m]);
    meta[2 * m] = keys[m];
    meta[2 * m + 1] = text[m];
  }
  for (size_t m = 0; m < p->nmeta; m++) {
    const char *key = p->meta[2 * m], *value = p->meta[2 * m + 1];
    if (!key || !value || is_ours(key)) continue;
    meta[2 * nmeta] = key;
    meta[2 * nmeta + 1] = value;
    nmeta++;
  }
  const char *names[1] = {"Y"};
  oc_oiio_out out = {
      .format = oiio_names[k],
      .width = oc_heightfield_nx(hf),
      .height = oc_heightfield_ny(hf),
      .channels = 1,
      .type = (oc_oiio_type)type,
      .pixels = px,
      .alpha = -1,
      .channel_names = names,
      .meta = meta,
      .nmeta = nmeta,
  };
  int rc = oc_oiio_write_at(dir, path, &out, err);
  free(meta);
  free(px);
  if (rc == OC_OK && used) {
    used[0] = scale;
    used[1] = offset;
  }
  return rc;
}
