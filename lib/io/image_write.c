/*
** image_write.c — oc_image_write: the format from the extension, samples
** converted to what the format stores, encoded in memory by the bridge,
** and an atomic write (io/atomic.h: temporary name in the same folder,
** every write checked, then rename) so that no reader ever sees a partial
** file under the final name; oc_oiio_write_at, which heightfield saves
** share.
*/
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/srgb.h"
#include "io/atomic.h"
#include "io/oiio.h"
#include "outcrop.h"
#include "render/tone.h"

#define SUPPORTED ".png, .jpg, .jpeg, .tif, .tiff or .exr"
#define JPEG_MAX_SIDE 65500

typedef enum kind { PNG, JPEG, TIFF, EXR } kind;

static const struct {
  const char *ext;
  kind kind;
} extensions[] = {{".png", PNG},  {".jpg", JPEG},  {".jpeg", JPEG},
                  {".tif", TIFF}, {".tiff", TIFF}, {".exr", EXR}};

static const char *const oiio_names[] = {"png", "jpeg", "tiff", "openexr"};
static const char *const labels[] = {"PNG", "JPEG", "TIFF", "EXR"};

/* The extension of the last path component, or NULL. */
static const char *extension(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = strrchr(base, '.');
  return dot && dot != base ? dot : NULL;
}

/* Sample type for `bits`, or -1 when the format cannot store it. */
static int sample_type(kind k, int bits) {
  switch (k) {
  case PNG:
    return bits == 0 || bits == 8 ? OC_OIIO_U8 : bits == 16 ? OC_OIIO_U16 : -1;
  case JPEG:
    return bits == 0 || bits == 8 ? OC_OIIO_U8 : -1;
  case TIFF:
    return bits == 8                 ? OC_OIIO_U8
           : bits == 0 || bits == 16 ? OC_OIIO_U16
           : bits == 32              ? OC_OIIO_F32
                                     : -1;
  case EXR:
    return bits == 0 || bits == 16 ? OC_OIIO_HALF
           : bits == 32            ? OC_OIIO_F32
                                   : -1;
  }
  return -1;
}

static const char *const bits_allowed[] = {"8 or 16", "8", "8, 16 or 32",
                                           "16 (half) or 32 (float)"};

/* JPEG holds grey or RGB; the others hold grey, grey+alpha, RGB or RGBA,
** except EXR which holds every channel. */
static int written_channels(kind k, int channels) {
  switch (k) {
  case JPEG:
    return channels >= 3 ? 3 : 1;
  case EXR:
    return channels;
  default:
    return channels > 4 ? 4 : channels;
  }
}

/* Clamp to [0, 1] (NaN to 0) and round to nearest. Values are taken as
** display-referred: no transfer function is applied. */
static double unit(float x) {
  return x > 0.0f ? (x < 1.0f ? x : 1.0) : 0.0;
}

/* ---- linear images (renders) ------------------------------------------
** An image whose metadata says outcrop:colorspace=linear holds linear
** light (the renderer's output). Integer files are display-referred, so
** its colour channels go through the sRGB transfer function there and the
** file is tagged sRGB; float files (EXR, float TIFF) keep linear values
** and are tagged linear. Alpha and any other channel stay as they are.
** A render made with a tone curve other than the clamp (render/tone.h)
** has its colour channels go through that curve before the sRGB
** encoding, in integer files only: float files stay scene-referred.
** The marker itself is written as what the file holds (sRGB in integer
** files): an encoded PNG read back must not pass for linear light, or a
** second write would encode it again. */

#define LINEAR_KEY "outcrop:colorspace"

static int is_linear(const oc_image *img) {
  const char *v = oc_image_meta_get(img, LINEAR_KEY);
  return v && strcasecmp(v, "linear") == 0;
}

/* Number of leading colour channels: grey (+ alpha) or RGB (+ alpha). */
static int colour_channels(int nch) {
  return nch >= 3 ? 3 : 1;
}

/* The buffer handed to the bridge: `img`'s own pixels when they can go
** as they are, else a converted copy of the first `nch` channels. */
static const void *samples(const oc_image *img, int nch, oc_oiio_type t,
                           void **owned) {
  size_t npix = (size_t)oc_image_width(img) * oc_image_height(img);
  int stride = oc_image_channels(img);
  const float *src = oc_image_cdata(img);
  *owned = NULL;
  if ((t == OC_OIIO_HALF || t == OC_OIIO_F32) && nch == stride) return src;
  size_t size = t == OC_OIIO_U8 ? 1 : t == OC_OIIO_U16 ? 2 : sizeof(float);
  void *buf = malloc(npix * nch * size);
  if (!buf) return NULL;
  int ncol = is_linear(img) && (t == OC_OIIO_U8 || t == OC_OIIO_U16)
                 ? colour_channels(nch)
                 : 0;
  oc_render_tone tone =
      ncol ? oc_tone_from_name(oc_image_meta_get(img, OC_TONE_KEY))
           : OC_TONE_CLAMP;
  for (size_t p = 0; p < npix; p++) {
    const float *s = src + p * stride;
    for (int c = 0; c < nch; c++) {
      size_t i = p * nch + c;
      double v = c < ncol && tone != OC_TONE_CLAMP ? oc_tone_apply(tone, s[c])
                                                   : unit(s[c]);
      if (c < ncol) v = oc_srgb_encode(v);
      if (t == OC_OIIO_U8)
        ((uint8_t *)buf)[i] = (uint8_t)(v * 255.0 + 0.5);
      else if (t == OC_OIIO_U16)
        ((uint16_t *)buf)[i] = (uint16_t)(v * 65535.0 + 0.5);
      else
        ((float *)buf)[i] = s[c];
    }
  }
  *owned = buf;
  return buf;
}

static int check_names(const oc_image *img, oc_error *err) {
  int n = oc_image_channels(img);
  for (int a = 0; a < n; a++)
    for (int b = a + 1; b < n; b++)
      if (strcmp(oc_image_channel_name(img, a),
                 oc_image_channel_name(img, b)) == 0)
        return oc_seterr(err, OC_EINVAL,
                         "channels %d and %d are both named '%s'; EXR channel "
                         "names must be unique",
                         a, b, oc_image_channel_name(img, a));
  return OC_OK;
}

/* The sink of oc_oiio_write_at: the encoded file into the atomic output. */
static int to_atomic(void *ud, const void *bytes, size_t n, char *why,
                     size_t whysize) {
  (void)why, (void)whysize; /* a failed write is reported by the commit */
  oc_atomic_write(ud, bytes, n);
  return OC_OK;
}

int oc_oiio_write_at(int dirfd, const char *name, const oc_oiio_out *im,
                     oc_error *err) {
  char why[OC_ERRMSG] = "";
  oc_atomic a;
  int rc = oc_atomic_begin_at(&a, dirfd, name, err);
  if (rc != OC_OK) return rc;
  if (oc_oiio_encode(im, to_atomic, &a, why, sizeof why) != OC_OK) {
    oc_atomic_abort(&a);
    return oc_seterr(err, OC_EIO, "cannot write '%s': %s", name, why);
  }
  return oc_atomic_commit(&a, err);
}

int oc_image_write(const oc_image *img, const char *path, int bits,
                   oc_error *err) {
  return oc_image_write_at(img, AT_FDCWD, path, bits, err);
}

int oc_image_write_at(const oc_image *img, int dirfd, const char *path,
                      int bits, oc_error *err) {
  if (!img) return oc_seterr(err, OC_EINVAL, "'image' is NULL");
  if (!path || !*path)
    return oc_seterr(err, OC_EINVAL, "'path' must be a non-empty file name");
  const char *ext = extension(path);
  int k = -1;
  for (size_t i = 0; ext && i < sizeof extensions / sizeof *extensions; i++)
    if (strcasecmp(ext, extensions[i].ext) == 0) k = (int)extensions[i].kind;
  if (k < 0)
    return oc_seterr(
        err, OC_EINVAL,
        "cannot write '%s': unknown image format (use " SUPPORTED ")", path);
  int t = sample_type((kind)k, bits);
  if (t < 0)
    return oc_seterr(err, OC_EINVAL, "'bits' must be %s for %s (got %d)",
                     bits_allowed[k], labels[k], bits);
  if (k == EXR) {
    int rc = check_names(img, err);
    if (rc) return rc;
  }
  /* libjpeg's limit; past it, its error handler exits the process. */
  if (k == JPEG && (oc_image_width(img) > JPEG_MAX_SIDE ||
                    oc_image_height(img) > JPEG_MAX_SIDE))
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': JPEG holds at most %d pixels per "
                     "side (the image is %d x %d; use .png, .tif or .exr)",
                     path, JPEG_MAX_SIDE, oc_image_width(img),
                     oc_image_height(img));

  int nch = written_channels((kind)k, oc_image_channels(img));
  const char *names[64];
  for (int c = 0; c < nch; c++)
    names[c] = oc_image_channel_name(img, c);
  size_t nmeta = oc_image_meta_count(img);
  /* one more pair: the colour space tag of linear images */
  const char **meta = malloc((2 * nmeta + 2) * sizeof *meta);
  void *owned = NULL;
  const void *px = meta ? samples(img, nch, (oc_oiio_type)t, &owned) : NULL;
  if (!px) {
    free(meta);
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  }
  int integer = t == OC_OIIO_U8 || t == OC_OIIO_U16;
  for (size_t i = 0; i < nmeta; i++) {
    meta[2 * i] = oc_image_meta_key(img, i);
    meta[2 * i + 1] = oc_image_meta_value(img, i);
    if (integer && strcasecmp(meta[2 * i], LINEAR_KEY) == 0 &&
        strcasecmp(meta[2 * i + 1], "linear") == 0)
      meta[2 * i + 1] = "sRGB";
  }
  if (is_linear(img)) {
    meta[2 * nmeta] = "oiio:ColorSpace";
    meta[2 * nmeta + 1] = integer ? "sRGB" : "Linear";
    nmeta++;
  }
  oc_oiio_out out = {
      .format = oiio_names[k],
      .width = oc_image_width(img),
      .height = oc_image_height(img),
      .channels = nch,
      .type = (oc_oiio_type)t,
      .pixels = px,
      .alpha = k != EXR && (nch == 2 || nch == 4) ? nch - 1 : -1,
      .channel_names = names,
      .meta = meta,
      .nmeta = nmeta,
  };

  int rc = oc_oiio_write_at(dirfd, path, &out, err);
  free(owned);
  free(meta);
  return rc;
}
