/*
** oiio_glue.h — the seam between lib/io and liboutcrop_oiio.so, the
** shared object that holds the OpenImageIO bridge (io/oiio.cpp,
** io/oiio_hf.cpp) and is loaded on the first image read or write
** (io/oiio_load.c), so that a script that never touches an image does
** not pay for OpenImageIO's ~260 libraries at start-up.
**
** The object is opened RTLD_LOCAL from a host that may not export its
** symbols (the interpreter, the Lua module loaded by lua5.4), so it calls
** nothing of lib/ by name: what it needs that allocates or builds images
** comes in a table of the host's functions (so that the interpreter's
** --max-memory accounting sees those allocations as before), and it
** exports one function returning its own table. The error and infile
** helpers, which allocate nothing, are linked into it privately.
*/
#ifndef OC_OIIO_GLUE_H
#define OC_OIIO_GLUE_H

#include <stddef.h>

#include "io/oiio.h"
#include "io/oiio_hf.h"
#include "outcrop.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped whenever either table changes: a stale object is refused. */
#define OC_OIIO_GLUE_ABI 1
#define OC_OIIO_GLUE_FILE "liboutcrop_oiio.so"
#define OC_OIIO_GLUE_ENTRY "oc_oiio_glue_open"

/* The host's functions, called by the bridge under the names of lib/
** (io/oiio_host.cpp forwards them). */
typedef struct oc_oiio_host {
  oc_image *(*image_new)(int width, int height, int channels, oc_error *err);
  void (*image_free)(oc_image *img);
  float *(*image_data)(oc_image *img);
  int (*image_set_channel_name)(oc_image *img, int channel, const char *name,
                                oc_error *err);
  int (*image_set_meta)(oc_image *img, const char *key, const char *value,
                        oc_error *err);
  size_t (*meta_quoted_size)(const char *value);
  size_t (*meta_quote)(const char *value, char *out);
  int (*meta_unfold)(const char *text,
                     void (*take)(void *ud, const char *key, const char *value),
                     void *ud);
} oc_oiio_host;

/* The bridge's entry points, as io/oiio.h and io/oiio_hf.h describe them. */
typedef struct oc_oiio_glue {
  int (*encode)(const oc_oiio_out *im, oc_oiio_sink sink, void *ud, char *why,
                size_t whysize);
  oc_image *(*read)(const char *path, oc_error *err);
  int (*read_raw)(const char *path, const oc_oiio_raw *r, oc_error *err);
} oc_oiio_glue;

/* The object's one exported function (OC_OIIO_GLUE_ENTRY): keeps `host`
** (which must outlive the process's use of images) and returns the
** bridge's table, or NULL when `abi` is not OC_OIIO_GLUE_ABI. Called once. */
typedef const oc_oiio_glue *(*oc_oiio_glue_open_fn)(const oc_oiio_host *host,
                                                    int abi);

#ifdef __cplusplus
}
#endif
#endif
