/*
** l_provenance.h — the provenance every image written from Lua carries:
** scene file and its hash, parameters, seed, input files and their hashes,
** and outcrop version, stored as image
** metadata (PNG text chunks, EXR string attributes, TIFF and JPEG
** ImageDescription lines).
*/
#ifndef L_PROVENANCE_H
#define L_PROVENANCE_H

#include "l_util.h"

/* Metadata keys, written in this order. */
#define OCLUA_META_SOFTWARE "Software"                 /* "outcrop 0.1.0" */
#define OCLUA_META_VERSION "outcrop:version"           /* OC_VERSION */
#define OCLUA_META_SCENE "outcrop:scene"               /* see below */
#define OCLUA_META_SCENE_SHA256 "outcrop:scene_sha256" /* see below */
#define OCLUA_META_SEED "outcrop:seed"                 /* decimal integer */
#define OCLUA_META_PARAMS "outcrop:params"             /* see below */
#define OCLUA_META_INPUTS "outcrop:inputs"             /* see below */

/* Sets the provenance keys on img (replacing earlier values, so stamping
** twice is harmless). Call it just before writing any image.
**
** scene: registry OCLUA_SCENE as the interpreter got it ("-" for standard
**   input); under stock lua5.4, the file of the nearest calling chunk, or
**   "(none)" when there is none.
** scene_sha256: the SHA-256 (64 lowercase hex digits) of the scene: of
**   the bytes the interpreter loaded (registry OCLUA_SCENE_SHA256), else
**   of the file named by scene, read when first stamped; "(none)" for
**   "(none)" and "-", "(unreadable)" when the file cannot be read.
** params: every parameter, sorted by name, "name=value" separated by
**   single spaces, the value as --set would spell it: those outcrop.param
**   read, with their configured value or else their default (read
**   without default and not configured: left out), and the configured
**   ones not read; a pair holding a space, a quote, a backslash or a
**   non-printable byte is written in double quotes with \" \\ \n \t \r
**   and \ddd escapes. "(none)" when there are none.
** seed: the scene seed (registry OCLUA_SEED, default 1): the seed of
**   every constructor not given its own.
** inputs: the files the engine's loaders read so far, in read order,
**   "name=sha256" pairs quoted as params; "(none)" when there are none.
** Values beyond 65000 bytes are cut and end with "...".
**
** Stamping notes that an output was written: outcrop.configure may not
** change anything any more. Raises only when memory runs out. */
void oclua_stamp_provenance(lua_State *L, oc_image *img);

/* The same provenance for writers that take key/value pairs rather than
** an oc_image (e.g. oc_heightfield_save_params.meta): pushes the values on the
** stack (pop OCLUA_PROVENANCE_PAIRS values once the write is done: the
** strings live there) and stores key0, value0, key1, ... in kv. */
#define OCLUA_PROVENANCE_PAIRS 7
void oclua_push_provenance(lua_State *L,
                           const char *kv[2 * OCLUA_PROVENANCE_PAIRS]);

#endif
