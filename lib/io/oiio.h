/*
** oiio.h — the C interface of the OpenImageIO bridge
** (bindings/oiio/oiio.cpp, the project's only C++).
**
** The bridge knows file formats; it does not know about temporary names,
** quantization or which channels a format keeps: lib/io decides those and
** hands the bridge a ready buffer. No C++ exception crosses this
** interface: every failure comes back as a status and a message.
*/
#ifndef OC_OIIO_H
#define OC_OIIO_H

#include <stddef.h>

#include "outcrop.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Storage type of the samples in the file. */
typedef enum oc_oiio_type {
  OC_OIIO_U8,   /* pixels are uint8_t */
  OC_OIIO_U16,  /* pixels are uint16_t */
  OC_OIIO_HALF, /* pixels are float, stored as half */
  OC_OIIO_F32   /* pixels are float */
} oc_oiio_type;

typedef struct oc_oiio_out {
  const char *format; /* OpenImageIO format: "png", "jpeg", "tiff", "openexr" */
  int width, height, channels;
  oc_oiio_type type;
  const void *pixels; /* interleaved, row 0 at the top, tightly packed */
  int alpha;          /* index of an unassociated alpha channel, or -1 */
  const char *const *channel_names; /* `channels` names */
  const char *const *meta;          /* key0, value0, key1, value1, ... */
  size_t nmeta;                     /* number of (key, value) pairs */
} oc_oiio_out;

/* Receives a whole encoded file; returns OC_OK or an error code with the
** reason in `why`. */
typedef int (*oc_oiio_sink)(void *ud, const void *bytes, size_t n, char *why,
                            size_t whysize);

/* Encodes `im` in memory and hands the bytes to `sink` (the bridge never
** writes a file). Every metadata pair becomes a string attribute; where
** the format has no free text fields (TIFF, JPEG) the keys it cannot
** hold become "key=value" lines of the ImageDescription, each value
** quoted by oc_meta_quote (io/metatext.h) so that no value can forge a
** line. No timestamp is added, so equal inputs give equal bytes. Returns
** what `sink` returned, or OC_EIO with the reason in `why`. */
int oc_oiio_encode(const oc_oiio_out *im, oc_oiio_sink sink, void *ud,
                   char *why, size_t whysize);

/* Encodes `im` and writes it atomically (io/atomic.h) as `name` relative
** to `dirfd` (AT_FDCWD: the current folder). OC_OK, or OC_EIO with a
** message naming `name` ("cannot write 'x.png': No space left on
** device"), and then neither the file nor a temporary exists. Defined in
** io/image_write.c. */
int oc_oiio_write_at(int dirfd, const char *name, const oc_oiio_out *im,
                     oc_error *err);

/* Reads the first subimage of `path` (opened with oc_infile_open: a
** regular file, the reader chosen by its signature) into a new float
** image owned by the caller (oc_image_free). Integer samples map to [0, 1];
*alpha is left as
** stored (never premultiplied). Channel names are copied, and every file
** attribute that oc_image_set_meta accepts becomes metadata (numbers as
** text); so do the "key=value" lines of a TIFF or JPEG description.
** NULL on failure with `err` set: OC_EIO naming the path, or the
** error of oc_image_new for images too large. */
oc_image *oc_oiio_read(const char *path, oc_error *err);

/* (oc_image_meta_count, _key, _value and _get are in outcrop.h.) */

#ifdef __cplusplus
}
#endif
#endif
