/*
** infile.h — opening an image file that may be hostile: only a regular
** file (a FIFO, a device such as /dev/zero or a folder is refused without
** blocking), and its format told by its first bytes (signature), so that
** no reader of another format ever probes it; and the hash of such a
** file, which provenance records.
*/
#ifndef OC_INFILE_H
#define OC_INFILE_H

#include <stdio.h>

#include "outcrop.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Opens `path` for reading. On success *fp is a stream at offset 0 (the
** caller closes it) and *format the OpenImageIO format of its signature:
** "png", "tiff" (little- or big-endian, classic or BigTIFF), "openexr" or
** "jpeg". On failure NULL in *fp and OC_EIO with a message naming the
** path: the open's reason, "not a regular file (a folder)", or
** "unrecognised image format (not PNG, TIFF, EXR or JPEG)". */
int oc_infile_open(const char *path, FILE **fp, const char **format,
                   oc_error *err);

/* oc_infile_sha256, the hash of such a file, is declared in outcrop.h. */

#ifdef __cplusplus
}
#endif
#endif
