/*
** triplanar.h — texturing by material (Peytavie et al. 2009, section 6)
** (internal to lib/render): a procedural texture projected along the
** three axes and blended by |n_i|^8, and colours blended by weights (the
** visible material ratios around a point), for renders and mesh vertex
** colours alike.
*/
#ifndef OC_TRIPLANAR_H
#define OC_TRIPLANAR_H

#include <stdint.h>

#include "outcrop.h"

/* The triplanar texture at p (unit normal n) in [0, 1], for a texture
** period of 1 / s metres; `seed` picks the texture (0: the renderer's
** default one). NaN where n is 0. */
double oc_triplanar(oc_vec3 p, oc_vec3 n, double s, uint64_t seed);

/* The multiplier a texture value t gives a colour: 1 + amp (0.35 + 0.65
** (1 - |n_z|)) 2 (t - 0.5), at least 0 (stronger on steep faces). */
double oc_triplanar_gain(double t, double amp, double nz);

/* The blended albedo at p: sum w_i c_i k_i / sum w_i over the n weight
** programs (w_i = max(f_i(p), 0)), k_i the gain of texture i + 1 (amp,
** period 1 / s); c_0 where every weight is 0. *evals counts the field
** evaluations. */
void oc_blend_albedo(const oc_program *const *f, const double *col, int n,
                     double amp, double s, oc_vec3 p, oc_vec3 nrm,
                     double rgb[3], double *evals);

/* Checks a blend (messages name the Lua fields). */
int oc_blend_check(const oc_program *const *f, const double *col, int n,
                   oc_error *err);

#endif
