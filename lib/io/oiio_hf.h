/*
** oiio_hf.h — exact reads for heightfields through OpenImageIO
** (bindings/oiio/oiio_hf.cpp): the first channel of an image file as the
** values stored, integer counts not normalized. oc_oiio_read (io/oiio.h)
** maps integers to [0, 1], which cannot give 16-bit counts back exactly
** for every scale.
*/
#ifndef OC_OIIO_HF_H
#define OC_OIIO_HF_H

#include <stddef.h>

#include "outcrop.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct oc_oiio_raw {
  /* Called for each file attribute (numbers and arrays as text), before
  ** `begin`. */
  void (*attr)(void *ud, const char *key, const char *value);
  /* Called once with the image's size, its channel count and the sample
  ** type of the first channel ("uint8", "uint16", "half", "float", ...).
  ** Returns where the samples go: width x height floats, row 0 (the top)
  ** first; or NULL with `err` set to stop. */
  float *(*begin)(void *ud, int width, int height, int channels,
                  const char *type, oc_error *err);
  void *ud;
  /* Polled between strips of rows; non-zero stops with OC_ECANCEL. */
  oc_progress progress;
} oc_oiio_raw;

/* Reads the first channel of the first subimage of `path`, opened with
** oc_infile_open (io/infile.h): a regular file, the reader chosen by its
** signature. Integer samples
** become their counts (uint16 65535 is 65535.0f; 32-bit integers are
** rounded to float), half and float samples are copied exactly, doubles
** rounded to float. Returns OC_OK, or an error code with `err`: OC_EIO
** naming the path for unreadable or corrupt files, or what `begin` set. */
int oc_oiio_read_raw(const char *path, const oc_oiio_raw *r, oc_error *err);

#ifdef __cplusplus
}
#endif
#endif
