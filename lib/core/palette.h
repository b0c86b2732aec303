/*
** palette.h — colour maps: stops (value, r, g, b) sorted by value, linear
** between neighbours, the end colours beyond them. Meshes, renders and
** heightfield images all colour values through these.
*/
#ifndef OC_PALETTE_H
#define OC_PALETTE_H

#include "outcrop.h"

/* OC_OK when n >= 1 stops have finite, ascending values and colour
** components in [0, 1]; else OC_EINVAL naming 'stops'. */
int oc_palette_check(const double *stops, int n, oc_error *err);

/* The colour of v. Where stops share a value the colour steps (the later
** stop wins from that value on). NaN takes the first stop's colour. */
void oc_palette_eval(const double *stops, int n, double v, double rgb[3]);

#endif
