/*
** noise.h — 3D simplex noise and turbulence with analytic gradients and
** Lipschitz bounds (Paris et al. 2019, section 3.3).
**
** n : R^3 -> [0, 1], seeded by hashing lattice corners with the seed (no
** permutation tables, so a seed costs no memory).
** t(p) = sum_{k=0}^{octaves-1} 2^-k n_k(2^k p), each octave with its own
** derived seed so octaves are decorrelated.
*/
#ifndef OC_NOISE_H
#define OC_NOISE_H

#include <stdint.h>

#include "outcrop.h"

/* A provable bound on |grad n| (not an estimate). */
extern const double oc_noise3_lipschitz;

/* n(p) in [0, 1]; stores the gradient in *grad when grad != NULL. */
double oc_noise3(uint64_t seed, oc_vec3 p, oc_vec3 *grad);

/* t(p); gradient when grad != NULL. octaves >= 1. */
double oc_turb3(uint64_t seed, int octaves, oc_vec3 p, oc_vec3 *grad);
/* Upper bound of t: sum 2^-k = 2 - 2^(1-octaves); t >= 0. */
double oc_turb3_max(int octaves);
/* Lipschitz bound of t: octaves * oc_noise3_lipschitz. */
double oc_turb3_lipschitz(int octaves);

#endif
