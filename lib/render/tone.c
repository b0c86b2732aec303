/*
** tone.c — tone curves: linear values to display values in [0, 1]
** (render/tone.h). The filmic curve is applied by the writer, not the
** renderer, so that EXR files keep the linear values.
*/
#include <strings.h>

#include "render/tone.h"

double oc_tone_filmic(double x) {
  if (!(x > 0)) return 0;
  double y = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
  return y < 1 ? y : 1; /* (infinity gives NaN above) */
}

double oc_tone_apply(oc_render_tone tone, double x) {
  if (tone == OC_TONE_FILMIC) return oc_tone_filmic(x);
  return x > 0 ? (x < 1 ? x : 1) : 0;
}

const char *oc_tone_name(oc_render_tone tone) {
  return tone == OC_TONE_FILMIC ? "filmic" : "clamp";
}

oc_render_tone oc_tone_from_name(const char *name) {
  return name && strcasecmp(name, "filmic") == 0 ? OC_TONE_FILMIC
                                                 : OC_TONE_CLAMP;
}
