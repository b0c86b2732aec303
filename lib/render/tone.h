/*
** tone.h — the renderer's tone curves (internal): how a linear colour
** value becomes a display value in [0, 1] before the sRGB encoding of an
** integer file (io/image_write.c). A render records a curve other than
** the default clamp as its metadata key OC_TONE_KEY.
*/
#ifndef OC_TONE_H
#define OC_TONE_H

#include "outcrop.h"

#define OC_TONE_KEY "outcrop:tone"

/* The ACES filmic fit of Narkowicz (2015):
**   f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to
**   [0, 1];
** 0 for x <= 0 and NaN. */
double oc_tone_filmic(double x);

/* x through `tone`: OC_TONE_CLAMP clamps to [0, 1] (NaN to 0). */
double oc_tone_apply(oc_render_tone tone, double x);

/* The name of a curve ("clamp", "filmic"), and back: the curve of
** metadata value `name`, OC_TONE_CLAMP for NULL or an unknown name. */
const char *oc_tone_name(oc_render_tone tone);
oc_render_tone oc_tone_from_name(const char *name);

#endif
