/*
** oiio_host.cpp — the entry of liboutcrop_oiio.so (io/oiio_glue.h): it
** keeps the host's table and gives the bridge the lib/ functions it calls
** by name (images, metadata text) as forwarders to that table, so the
** bridge's sources read as if linked into lib/.
**
** The object's version script exports oc_oiio_glue_open only; these
** names stay private to it.
*/
#include "io/oiio_glue.h"
#include "io/metatext.h"
#include "oiio_util.hpp"

/* Set once, by oc_oiio_glue_open under the loader's pthread_once, before
** any bridge function can run; read-only afterwards. */
static const oc_oiio_host *host;

extern "C" {

oc_image *oc_image_new(int width, int height, int channels, oc_error *err) {
  return host->image_new(width, height, channels, err);
}

void oc_image_free(oc_image *img) {
  host->image_free(img);
}

float *oc_image_data(oc_image *img) {
  return host->image_data(img);
}

int oc_image_set_channel_name(oc_image *img, int channel, const char *name,
                              oc_error *err) {
  return host->image_set_channel_name(img, channel, name, err);
}

int oc_image_set_meta(oc_image *img, const char *key, const char *value,
                      oc_error *err) {
  return host->image_set_meta(img, key, value, err);
}

size_t oc_meta_quoted_size(const char *value) {
  return host->meta_quoted_size(value);
}

size_t oc_meta_quote(const char *value, char *out) {
  return host->meta_quote(value, out);
}

int oc_meta_unfold(const char *text,
                   void (*take)(void *ud, const char *key, const char *value),
                   void *ud) {
  return host->meta_unfold(text, take, ud);
}

__attribute__((visibility("default"))) const oc_oiio_glue *
oc_oiio_glue_open(const oc_oiio_host *h, int abi) {
  static const oc_oiio_glue glue = {oc_glue_encode, oc_glue_read,
                                    oc_glue_read_raw};
  if (abi != OC_OIIO_GLUE_ABI || !h) return nullptr;
  host = h;
  return &glue;
}
}
