/*
** fround.h — doubles stored as floats rounded outward: the nearest float
** on a given side, for boxes and bounds kept in floats that must stay
** conservative (never tighter than the doubles they round).
*/
#ifndef OC_FROUND_H
#define OC_FROUND_H

#include <math.h>

/* The largest float <= v (-INFINITY below the float range). */
static inline float oc_float_down(double v) {
  float f = (float)v;
  return (double)f > v ? nextafterf(f, -INFINITY) : f;
}

/* The smallest float >= v (INFINITY above the float range). */
static inline float oc_float_up(double v) {
  float f = (float)v;
  return (double)f < v ? nextafterf(f, INFINITY) : f;
}

#endif
