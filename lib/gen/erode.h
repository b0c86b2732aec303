/*
** erode.h — shallow procedural erosion shared by the sea and river
** generators (Paris et al. 2019, section 6.1): the effect function e(rho,
** sigma),
** and the step that turns candidate rays into negative point primitives
** on the current surface (stress.c).
**
** A candidate is a column (x, y) with a height interval and a horizontal
** direction u pointing into the rock. At each step a height z is drawn in
** the interval (keyed by seed, step and candidate index), and the ray
** (x, y, z) + t u, t in [-back, fwd], is marched on the tree built so far
** (terrain plus the primitives of earlier steps) until it enters the
** solid: that point is the step's sample. Since each step marches the
** updated tree, a step bites further where the previous ones carved, so
** soft rock is hollowed into overhangs, caves and arches.
*/
#ifndef OC_GEN_ERODE_H
#define OC_GEN_ERODE_H

#include <stddef.h>
#include <stdint.h>

#include "outcrop.h"

/* e(rho, sigma) = sigma (1 - rho)(1 - beta) + sigma beta: no erosion
** without stress, e(1, 1) = beta on the hardest rock. */
static inline double oc_erode_effect(double rho, double sigma, double beta) {
  return sigma * (1 - rho) * (1 - beta) + sigma * beta;
}

/* Wyvill's falloff (1 - x^2)^3 on [0, 1), 0 beyond. */
static inline double oc_erode_falloff(double x) {
  if (!(x < 1)) return 0;
  double a = 1 - x * x;
  return a * a * a;
}

typedef struct oc_erode_cand {
  double x, y;
  double zlo, zhi;  /* the height is drawn uniformly in [zlo, zhi] */
  double ux, uy;    /* unit, into the rock; (0, 0): the sample is (x, y, z)
                    ** itself, no marching (river beds) */
  double back, fwd; /* the ray runs from -back to +fwd along u */
  double stress;    /* the part of sigma that depends on the column only */
} oc_erode_cand;

typedef struct oc_erode_params {
  oc_node *base;           /* the terrain the rays march */
  int omit_base;           /* 1: the result holds the primitives alone */
  oc_node *geology;        /* resistance, clamped to [0, 1]; or NULL */
  double rho;              /* the resistance when geology is NULL */
  double threshold;        /* T of the surface */
  double sea_level, range; /* range > 0: sigma *= g(|z - sea_level| / range) */
  /* or NULL: sigma *= the accessibility of the sample (Miller 1994): the
  ** fraction of `rays` directions over the upper hemisphere (a Fibonacci
  ** lattice turned by a per-sample angle) along which the heightfield
  ** does not rise above the ray within `reach`, marched from the sample
  ** itself, so that a point on a vertical cliff face sees about half. */
  const oc_heightfield *alpha;
  int rays;
  double reach;
  double radius;   /* of the point primitives */
  double strength; /* energy = -strength e */
  double beta;
  double cutoff; /* samples with e < cutoff make no primitive */
  double step;   /* marching step along rays */
  double span;   /* rays are cut to this each way (the footprint's diagonal
                 ** plus a cell): depth and radius lengthen them no more */
  int steps;     /* >= 1 */
  uint64_t seed;
  oc_progress progress;
  double pbase, pspan; /* this work's share of the caller's progress */
} oc_erode_params;

/* Runs the steps; returns the blend of base and every primitive made (base
** first, then the primitives in step and candidate order; without base
** when omit_base, and then NULL with OC_EINVAL when nothing was carved),
** or NULL with err. st (or NULL) gets the candidates, the rays that found
** the surface and the primitives made. */
oc_node *oc_erode_run(const oc_erode_params *ep, const oc_erode_cand *cand,
                      size_t n, oc_gen_sea_stats *st, oc_error *err);

/* Fills *ep from the generators' shared parameters c (outcrop.h), the
** rest zero: the primitives alone when c->no_terrain, resistance 0.5
** without geology, the default threshold for 0, a marching step of half
** the smaller of hf's cell and the radius (but at least 1/32 cell: a
** tinier radius only makes the march longer) and rays cut to hf's
** extent. */
void oc_erode_shared(oc_erode_params *ep, oc_node *base,
                     const oc_heightfield *hf, const oc_gen_erode_params *c);

/* Candidate columns: maximal Poisson disk sets of radius `spacing` on
** square tiles of the heightfield's extent, only on the tiles that hold a
** grid sample with mask != 0 (nx ny bytes) or neighbour one, thinned to
** the columns where keep(ud, x, y) != 0 (called from several threads).
** Tiles are sampled in parallel and merged in tile order, a column closer
** than `spacing` to one of an earlier tile being dropped, so the set is
** still `spacing` apart (slightly sparser along tile seams) and does not
** depend on the thread count. Polls pr between tiles, reporting the
** fraction `at`. Returns the positions (2 doubles each) in a new array
** (free()), the count in *n; NULL with err (OC_ECANCEL when cancelled). */
double *oc_erode_columns(const oc_heightfield *hf, const unsigned char *mask,
                         double spacing, uint64_t seed,
                         int (*keep)(void *, double, double), void *ud,
                         oc_progress pr, double at, size_t *n, oc_error *err);

/* A new reference to `terrain`, or when it is NULL to the default terrain
** node of the heightfield (oc_heightfield_terrain); NULL with err. */
oc_node *oc_erode_base(oc_heightfield *hf, oc_node *terrain, oc_error *err);

/* Checks the parameters both generators share (radius and spacing once
** their defaults are applied), naming the field. */
int oc_erode_check(const oc_gen_erode_params *c, oc_error *err);

#endif
