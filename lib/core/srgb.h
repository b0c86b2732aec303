/*
** srgb.h — the sRGB transfer function (IEC 61966-2-1), shared by every
** writer that turns linear values into display-referred integers (image
** files of renders, PLY vertex colours), so that they all encode alike.
*/
#ifndef OC_SRGB_H
#define OC_SRGB_H

#include <math.h>

/* The sRGB encoding of a linear value in [0, 1]. */
static inline double oc_srgb_encode(double x) {
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
}

/* Its inverse: the linear value of an sRGB-encoded value in [0, 1]. */
static inline double oc_srgb_decode(double s) {
  return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

/* A linear value as an 8-bit sRGB byte: clamped to [0, 1] (NaN to 0),
** encoded, rounded half up. */
static inline unsigned char oc_srgb_byte(double x) {
  double v = x > 0 ? (x < 1 ? x : 1) : 0;
  return (unsigned char)(oc_srgb_encode(v) * 255.0 + 0.5);
}

#endif
