/*
** l_provenance.h — the provenance every image written from Lua carries:
** scene file, --set parameters, seed and outcrop version, stored as image
** metadata (PNG text chunks, EXR string attributes, TIFF and JPEG
** ImageDescription lines).
*/
#ifndef L_PROVENANCE_H
#define L_PROVENANCE_H

#include "l_util.h"

/* Metadata keys, written in this order. */
#define OCLUA_META_SOFTWARE "Software"       /* "outcrop 0.1.0" */
#define OCLUA_META_VERSION "outcrop:version" /* OC_VERSION */
#define OCLUA_META_SCENE "outcrop:scene"     /* see below */
#define OCLUA_META_SEED "outcrop:seed"       /* decimal integer */
#define OCLUA_META_PARAMS "outcrop:params"   /* see below */

/* Sets the provenance keys on img (replacing earlier values, so stamping
** twice is harmless). Call it just before writing any image.
**
** scene: registry OCLUA_SCENE as the interpreter got it ("-" for standard
**   input); under stock lua5.4, the file of the nearest calling chunk, or
**   "(none)" when there is none.
** params: the --set parameters sorted by name, "name=value" separated by
**   single spaces; a pair holding a space, a quote, a backslash or a
**   non-printable byte is written in double quotes with \" \\ \n \t \r
**   and \ddd escapes. "(none)" when there are none.
** seed: the scene seed (registry OCLUA_SEED, default 1).
**
** Raises only when memory runs out. */
void oclua_stamp_provenance(lua_State *L, oc_image *img);

/* The same provenance for writers that take key/value pairs rather than
** an oc_image (e.g. oc_hf_save_params.meta): pushes the values on the
** stack (pop OCLUA_PROVENANCE_PAIRS values once the write is done: the
** strings live there) and stores key0, value0, key1, ... in kv. */
#define OCLUA_PROVENANCE_PAIRS 5
void oclua_push_provenance(lua_State *L,
                           const char *kv[2 * OCLUA_PROVENANCE_PAIRS]);

#endif
