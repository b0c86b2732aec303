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

#include <stddef.h>
#include <stdint.h>

#include "outcrop.h"

/* A provable bound on |grad n| (not an estimate). */
extern const double oc_noise3_lipschitz;
/* A provable bound on the Hessian of n on any coordinate plane (the
** operator norm of each principal 2 x 2 block of its Hessian): on such a
** plane the gradient's part in it changes by at most this much per unit
** of distance (elevation discs sample the plane z = 0). */
extern const double oc_noise3_hessian;
/* The two as constant expressions, the same doubles (noise.c defines
** them so), for hot code that then folds its products of them at compile
** time instead of loading and scaling them on every call: the proved
** bounds of the raw sum, its gradient and Hessian (noise.c), and the
** scale n = 1/2 + raw / (2 RAW_MAX). */
#define OC_NOISE3_RAW_MAX 0.013008
#define OC_NOISE3_RAW_GRAD_MAX 0.0908
#define OC_NOISE3_RAW_HESS_MAX 0.64
#define OC_NOISE3_LIPSCHITZ (0.5 * OC_NOISE3_RAW_GRAD_MAX / OC_NOISE3_RAW_MAX)
#define OC_NOISE3_HESSIAN (0.5 * OC_NOISE3_RAW_HESS_MAX / OC_NOISE3_RAW_MAX)

/* n(p) in [0, 1]; stores the gradient in *grad when grad != NULL. */
double oc_noise3(uint64_t seed, oc_vec3 p, oc_vec3 *grad);

/* n(x[m], y[m], 0) for m < n, in out: oc_noise3's values bit for bit,
** the lattice corners' hashes shared by consecutive points in one cell
** (a row of nearby points: sampling elevation trees). */
void oc_noise3_z0_row(uint64_t seed, const double *x, const double *y, size_t n,
                      double *out);

/* n(x[m], y[m], 0) under seeds[m] for m < n, in val, with the x and y
** parts of the gradient in gx and gy when both are not NULL: oc_noise3's
** values and gradients bit for bit (the z part is not computed). Points
** go several at a time through the same operations, lane by lane (the
** octaves of an elevation disc's noise sum: one call per point and sum):
** eight under AVX-512 where the processor has it, else two. */
void oc_noise3_z0_multi(const uint64_t *seeds, const double *x, const double *y,
                        size_t n, double *val, double *gx, double *gy);

/* The paths of oc_noise3_z0_multi: AUTO picks the fastest this processor
** runs (the choice it makes on every call); the others force one, for
** tests and benchmarks. Every path gives the same bits. */
typedef enum oc_noise_isa {
  OC_NOISE_ISA_AUTO,
  OC_NOISE_ISA_SSE2,  /* two lanes, portable (GCC vector extensions) */
  OC_NOISE_ISA_AVX512 /* eight lanes, x86-64 with AVX-512 F and DQ */
} oc_noise_isa;

/* 1 when this processor runs the path isa (AUTO and SSE2: always). */
int oc_noise_isa_supported(oc_noise_isa isa);

/* oc_noise3_z0_multi through the path isa; returns 0, or -1 (and does
** nothing) when this processor lacks it. */
int oc_noise3_z0_multi_isa(oc_noise_isa isa, const uint64_t *seeds,
                           const double *x, const double *y, size_t n,
                           double *val, double *gx, double *gy);

/* The seed of octave i (from 0) of a sum of noise octaves seeded by seed:
** oc_mix64(seed + 0x9e3779b97f4a7c15 (i + 1)) (elevation discs). */
uint64_t oc_noise_octave_seed(uint64_t seed, int i);

/* The most octaves oc_noise3_z0_octaves takes. */
#define OC_NOISE_MAXOCT 16

/* The octaves m < n (n <= OC_NOISE_MAXOCT) of a sum at one point (u, v):
** oc_noise3_z0_multi of the seeds oc_noise_octave_seed(seed, m) and the
** points (s[m] u, s[m] v), bit for bit (an elevation disc's noise, its
** frequencies in s), the seeds made in the vector lanes under AVX-512.
** val, gx and gy (when not NULL) have room for OC_NOISE_MAXOCT values:
** those past n may be overwritten (whole vectors are stored, which the
** caller's loads of single values then read straight from the store). */
void oc_noise3_z0_octaves(uint64_t seed, const double *s, double u, double v,
                          size_t n, double *val, double *gx, double *gy);
/* The same through the path isa; returns 0, or -1 (and does nothing)
** when this processor lacks it or n > OC_NOISE_MAXOCT. */
int oc_noise3_z0_octaves_isa(oc_noise_isa isa, uint64_t seed, const double *s,
                             double u, double v, size_t n, double *val,
                             double *gx, double *gy);

/* oc_noise3_z0_octaves of the frequencies s[m] = f 2^m (f doubled m
** times: a disc's octaves at the default lacunarity), bit for bit, the
** frequencies made in the vector lanes under AVX-512 rather than in a
** loop by the caller. */
void oc_noise3_z0_octaves2(uint64_t seed, double f, double u, double v,
                           size_t n, double *val, double *gx, double *gy);
/* The same through the path isa; returns 0, or -1 (and does nothing)
** when this processor lacks it or n > OC_NOISE_MAXOCT. */
int oc_noise3_z0_octaves2_isa(oc_noise_isa isa, uint64_t seed, double f,
                              double u, double v, size_t n, double *val,
                              double *gx, double *gy);

/* t(p); gradient when grad != NULL. octaves >= 1. */
double oc_turb3(uint64_t seed, int octaves, oc_vec3 p, oc_vec3 *grad);
/* Upper bound of t: sum 2^-k = 2 - 2^(1-octaves); t >= 0. */
double oc_turb3_max(int octaves);
/* Lipschitz bound of t: octaves * oc_noise3_lipschitz. */
double oc_turb3_lipschitz(int octaves);

/* Noise parameters as a compiled program stores them: wavelength,
** amplitude, offset, octaves, and the seed as two 32-bit halves (so it
** survives a double). Turbulence, warp and perturb ops (lib/field) and
** strata (lib/geology) read them back with oc_noise_unpack. */
#define OC_NOISE_NPAR 6

static inline void oc_noise_pack(const oc_noise *nz,
                                 double out[OC_NOISE_NPAR]) {
  out[0] = nz->wavelength;
  out[1] = nz->amplitude;
  out[2] = nz->offset;
  out[3] = (double)nz->octaves;
  out[4] = (double)(nz->seed >> 32);
  out[5] = (double)(nz->seed & 0xffffffffu);
}

static inline oc_noise oc_noise_unpack(const double *par) {
  oc_noise nz = {par[0], par[1], par[2], (int)par[3],
                 ((uint64_t)par[4] << 32) | (uint64_t)par[5]};
  return nz;
}

#endif
