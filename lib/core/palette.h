/*
** palette.h — colour maps: stops (value, r, g, b) sorted by value, linear
** between neighbours, the end colours beyond them. Meshes, renders and
** heightfield images all colour values through these.
*/
#ifndef OC_PALETTE_H
#define OC_PALETTE_H

#include "outcrop.h"

/* oc_palette_check, oc_palette_eval and the built-in palettes are
** declared in outcrop.h. */

#endif
