/*
** log2.h — a base-2 logarithm made inline, for a noisy disc's wavelength
** under a level-of-detail view (elevation/enode.h, oc_edisc_lw): glibc's
** log2 was called once per disc model, 15-18 of its 130 ns (its call and
** latency ahead of the octave counts it decides), and keeping the value
** in the disc cost 8 bytes each (issue 14's memory contract). The
** footprint's log2, once per model query and per transform under it and
** once per disc evaluation, and the octave spans of the box bounds take
** it too (oc_log2_any): glibc's log2 was 1.2 % of bench_elev_lod's LoD
** primary rays (perf), its CPU 1.5 % lower with this.
**
** w = 2^e m, m in [1, 2): with c = 1 + j / 128 the nearest to m of the
** 129 such (m's first 8 bits rounded) and i ~ 1/c (a table of 129 pairs
** {i, -log2 i}), log2 w = e - log2 i + log2(1 + r), r = m i - 1, |r| <=
** 2^-8 (plus rounding; r = 0 and log2 w = e for powers of two), log2(1 + r)
** by its Taylor polynomial of degree 5 (its remainder below |r|^6 / (6
** ln 2 (1 - |r|)) < 8.7e-16). Within 2e-15 + 2^-52 |log2 w| of log2 w
** for normal w > 0 (test_elevation_lod, log2_inline_accuracy): at most
** 4.3e-15 off log2l's over 2 10^6 wavelengths from 1e-3 to 1e9 (9.2e-16
** where |log2 w| < 1), a thousandth of the LoD filter's 1e-12 pads; not
** libm's bits, only ever compared with itself. No zeros, negatives,
** infinities or NaNs (a wavelength is checked > 0 and finite at
** construction); a subnormal w gets a wrong value (its exponent field 0),
** as wrong as its noise (1 / w overflows).
*/
#ifndef OC_LOG2_H
#define OC_LOG2_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* {i_j, -log2 i_j}, i_j = 1 / (1 + j / 128) rounded (log2.c) */
extern const double oc_log2_tab[129][2];

/* j of w's mantissa m: its first 8 bits rounded to 7 (0 to 128) */
static inline int oc_log2_j(uint64_t u) {
  return (int)((((u >> 44) & 255) + 1) >> 1);
}

static inline double oc_log2(double w) {
  uint64_t u, um;
  memcpy(&u, &w, sizeof u);
  const double *t = oc_log2_tab[oc_log2_j(u)];
  um = (u & 0x000fffffffffffffull) | 0x3ff0000000000000ull; /* m */
  double m, e = (double)(int64_t)(u >> 52) - 1023;
  memcpy(&m, &um, sizeof m);
  double r = m * t[0] - 1, r2 = r * r;
  /* ln(1 + r) / ln 2 = sum (-1)^(k+1) r^k / (k ln 2), in Estrin's order
  ** (the latency of the octave counts waiting on it) */
#define OC_LOG2_K(k) (1 / ((k)*0.69314718055994530942))
  double p = r * ((OC_LOG2_K(1) - OC_LOG2_K(2) * r) +
                  r2 * ((OC_LOG2_K(3) - OC_LOG2_K(4) * r) + r2 * OC_LOG2_K(5)));
#undef OC_LOG2_K
  return (e + t[1]) + p;
}

/* oc_log2 to within log2(1 / (1 - 2^-8)) < 0.00565 (its table's entry
** alone, the polynomial skipped: r's term), for decisions that only
** need to be sure where they are not near a threshold (disc.c's octave
** counts, made exactly near one) without waiting on oc_log2's latency. */
static inline double oc_log2_coarse(double w) {
  uint64_t u;
  memcpy(&u, &w, sizeof u);
  return ((double)(int64_t)(u >> 52) - 1023) + oc_log2_tab[oc_log2_j(u)][1];
}

/* oc_log2 where x is a normal positive finite number, libm's log2 for the
** rest (0, subnormals, infinities: footprints and their ratios are user
** numbers' products, unlike the wavelengths checked at construction). */
static inline double oc_log2_any(double x) {
  return x >= 0x1p-1022 && x <= 0x1.fffffffffffffp+1023 ? oc_log2(x) : log2(x);
}

#endif
