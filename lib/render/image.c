/*
** image.c — float image buffers: pixels, channel names, metadata.
**
** Pixels are interleaved floats, row 0 at the top. Sizes are checked
** before anything is allocated, so an absurd resolution coming from a
** script is an error message, never an exhausted machine.
*/
#define _DEFAULT_SOURCE /* madvise */
#include <ctype.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>

#include "core/error.h"
#include "core/kvlist.h"
#include "io/oiio.h"
#include "outcrop.h"

#define MAX_SIDE 65535
#define MAX_CHANNELS 64
#define MAX_BYTES (4096ull << 20) /* 4 GiB of pixels */
#define NAME_SIZE 64              /* channel names: up to 63 characters */
#define MAX_KEY 79                /* PNG's limit for text chunk keywords */
#define MAX_VALUE 65535
#define MAX_META 1024

/* Pixels of an image this large go on huge pages where the system has
** them (2 MiB, asked for): a render writes its images' pixels once each,
** and the first write to every 4 KiB page faulted. Measured (a 1920 x
** 1080 x 9 geometry image, 75 MB, written once): 200 to 270 ms of CPU on
** 4 KiB pages, 14 to 60 ms on huge ones (the faults of bench_elev fig3's
** geometry 18329 to 455). */
#define HUGE_BYTES (4u << 20)
#define HUGE_PAGE ((uintptr_t)2 << 20)

static void advise_huge(void *p, size_t bytes) {
#ifdef MADV_HUGEPAGE
  uintptr_t a = ((uintptr_t)p + HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
  uintptr_t b = ((uintptr_t)p + bytes) & ~(HUGE_PAGE - 1);
  if (bytes >= HUGE_BYTES && b > a) madvise((void *)a, b - a, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

struct oc_image {
  int width, height, channels;
  float *data;
  char (*names)[NAME_SIZE];
  oc_kvlist meta;
};

oc_image *oc_image_new(int width, int height, int channels, oc_error *err) {
  if (width < 1 || width > MAX_SIDE) {
    oc_seterr(err, OC_EINVAL, "'width' must be in 1..%d (got %d)", MAX_SIDE,
              width);
    return NULL;
  }
  if (height < 1 || height > MAX_SIDE) {
    oc_seterr(err, OC_EINVAL, "'height' must be in 1..%d (got %d)", MAX_SIDE,
              height);
    return NULL;
  }
  if (channels < 1 || channels > MAX_CHANNELS) {
    oc_seterr(err, OC_EINVAL, "'channels' must be in 1..%d (got %d)",
              MAX_CHANNELS, channels);
    return NULL;
  }
  /* Cannot overflow: 65535^2 * 64 * 4 < 2^41. */
  unsigned long long n = (unsigned long long)width * height * channels;
  unsigned long long bytes = n * sizeof(float);
  if (bytes > MAX_BYTES || bytes > (unsigned long long)SIZE_MAX) {
    oc_seterr(err, OC_ENOMEM,
              "image of %d x %d x %d floats needs %llu MiB, over the %llu MiB "
              "limit",
              width, height, channels, (bytes + (1u << 20) - 1) >> 20,
              MAX_BYTES >> 20);
    return NULL;
  }
  oc_image *img = calloc(1, sizeof *img);
  if (img) {
    img->data = calloc((size_t)n, sizeof(float));
    if (img->data) advise_huge(img->data, (size_t)bytes);
    img->names = calloc((size_t)channels, sizeof *img->names);
  }
  if (!img || !img->data || !img->names) {
    oc_image_free(img);
    oc_seterr(err, OC_ENOMEM,
              "out of memory for an image of %d x %d x %d floats", width,
              height, channels);
    return NULL;
  }
  img->width = width;
  img->height = height;
  img->channels = channels;
  static const char *const rgba[] = {"R", "G", "B", "A"};
  for (int c = 0; c < channels; c++) {
    if (c < 4)
      strcpy(img->names[c], rgba[c]);
    else
      snprintf(img->names[c], NAME_SIZE, "c%d", c);
  }
  return img;
}

void oc_image_free(oc_image *img) {
  if (!img) return;
  oc_kvlist_free(&img->meta);
  free(img->names);
  free(img->data);
  free(img);
}

int oc_image_width(const oc_image *img) {
  return img->width;
}
int oc_image_height(const oc_image *img) {
  return img->height;
}
int oc_image_channels(const oc_image *img) {
  return img->channels;
}
float *oc_image_data(oc_image *img) {
  return img->data;
}
const float *oc_image_cdata(const oc_image *img) {
  return img->data;
}

/* Names go into file headers (EXR channel lists), so they stay printable
** and free of spaces. Uniqueness is checked when writing an EXR: checking
** here would forbid renaming two channels into each other's names. */
int oc_image_set_channel_name(oc_image *img, int channel, const char *name,
                              oc_error *err) {
  if (!img) return oc_seterr(err, OC_EINVAL, "'image' is NULL");
  if (channel < 0 || channel >= img->channels)
    return oc_seterr(err, OC_EINVAL, "'channel' must be in 0..%d (got %d)",
                     img->channels - 1, channel);
  if (!name) return oc_seterr(err, OC_EINVAL, "'name' is NULL");
  size_t len = strlen(name);
  if (len == 0 || len >= NAME_SIZE)
    return oc_seterr(err, OC_EINVAL,
                     "'name' must have 1..%d characters (got %zu)",
                     NAME_SIZE - 1, len);
  for (size_t i = 0; i < len; i++) {
    unsigned char ch = (unsigned char)name[i];
    if (ch <= ' ' || ch > '~')
      return oc_seterr(
          err, OC_EINVAL,
          "'name' must be printable ASCII without spaces (got '%s')", name);
  }
  memcpy(img->names[channel], name, len + 1);
  return OC_OK;
}

const char *oc_image_channel_name(const oc_image *img, int channel) {
  if (!img || channel < 0 || channel >= img->channels) return NULL;
  return img->names[channel];
}

/* Attribute names that OpenImageIO's writers read as instructions
** (compression, orientation, colour space ...) rather than as text: a
** provenance key must never change how a file is encoded. */
static int reserved_key(const char *key) {
  static const char *const ns[] = {"oiio", "tiff",      "openexr", "png",
                                   "jpeg", "exif",      "gps",     "iptc",
                                   "xmp",  "photoshop", "smpte"};
  static const char *const plain[] = {
      "compression",   "planarconfig",   "Orientation",    "ICCProfile",
      "XResolution",   "YResolution",    "ResolutionUnit", "PixelAspectRatio",
      "textureformat", "wrapmodes",      "fovcot",         "worldtocamera",
      "worldtoscreen", "FramesPerSecond"};
  const char *colon = strchr(key, ':');
  for (size_t i = 0; i < sizeof ns / sizeof *ns; i++) {
    size_t n = strlen(ns[i]);
    if (colon && (size_t)(colon - key) == n && strncasecmp(key, ns[i], n) == 0)
      return 1;
  }
  for (size_t i = 0; i < sizeof plain / sizeof *plain; i++)
    if (strcasecmp(key, plain[i]) == 0) return 1;
  return 0;
}

static int check_key(const char *key, oc_error *err) {
  size_t len = strlen(key);
  if (len == 0 || len > MAX_KEY)
    return oc_seterr(err, OC_EINVAL,
                     "'key' must have 1..%d characters (got %zu)", MAX_KEY,
                     len);
  if (!isalpha((unsigned char)key[0]))
    return oc_seterr(err, OC_EINVAL,
                     "'key' must start with a letter (got '%s')", key);
  for (size_t i = 0; i < len; i++) {
    unsigned char ch = (unsigned char)key[i];
    if (!isalnum(ch) && ch != '_' && ch != '.' && ch != ':' && ch != '-')
      return oc_seterr(err, OC_EINVAL,
                       "'key' may hold only letters, digits, '_', '.', ':' and "
                       "'-' (got '%s')",
                       key);
  }
  if (reserved_key(key))
    return oc_seterr(err, OC_EINVAL,
                     "'key' '%s' is reserved: image writers read it as an "
                     "encoding setting",
                     key);
  return OC_OK;
}

/* Keys compare without case because OpenImageIO's attribute lists do:
** "Scene" and "scene" would land on the same attribute in the file. */
int oc_image_set_meta(oc_image *img, const char *key, const char *value,
                      oc_error *err) {
  if (!img) return oc_seterr(err, OC_EINVAL, "'image' is NULL");
  if (!key) return oc_seterr(err, OC_EINVAL, "'key' is NULL");
  if (!value) return oc_seterr(err, OC_EINVAL, "'value' is NULL");
  int rc = check_key(key, err);
  if (rc) return rc;
  size_t vlen = strlen(value);
  if (vlen > MAX_VALUE)
    return oc_seterr(err, OC_EINVAL,
                     "'value' of '%s' is too long (%zu > %d bytes)", key, vlen,
                     MAX_VALUE);
  return oc_kvlist_set(&img->meta, key, value, 1, MAX_META, err);
}

size_t oc_image_meta_count(const oc_image *img) {
  return img->meta.n;
}

const char *oc_image_meta_key(const oc_image *img, size_t i) {
  return i < img->meta.n ? img->meta.v[i].key : NULL;
}

const char *oc_image_meta_value(const oc_image *img, size_t i) {
  return i < img->meta.n ? img->meta.v[i].value : NULL;
}

const char *oc_image_meta_get(const oc_image *img, const char *key) {
  return oc_kvlist_get(&img->meta, key, 1);
}
