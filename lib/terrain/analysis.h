/*
** analysis.h — what the terrain analysis files share: the 8-neighbourhood
** in a fixed order (the order every sum over neighbours runs in, which is
** part of what makes results byte-identical), a progress relay that maps
** the fraction of one phase into the whole call, and the result grid.
*/
#ifndef OC_TERRAIN_ANALYSIS_H
#define OC_TERRAIN_ANALYSIS_H

#include <float.h>
#include <stddef.h>

#include "outcrop.h"

/* Neighbour k of sample (i, j) is (i + oc_heightfield_di[k], j +
** oc_heightfield_dj[k]);
** even k are the four axis neighbours, odd k the diagonals. */
extern const int oc_heightfield_di[8], oc_heightfield_dj[8];
/* Distance to neighbour k in cells. */
extern const double oc_heightfield_dist[8];

/* A phase of a longer call: reports lo + span * f through the caller's
** callback. Returns non-zero when the caller asks to stop. */
typedef struct oc_heightfield_phase {
  oc_progress cb;
  double lo, span;
} oc_heightfield_phase;

static inline int oc_heightfield_report(const oc_heightfield_phase *ph,
                                        double f) {
  return ph->cb.fn && ph->cb.fn(ph->cb.ud, ph->lo + ph->span * f);
}

/* A new grid with the geometry of hf (samples at 0, for the caller to
** write before it shares the grid). */
oc_heightfield *oc_heightfield_like(const oc_heightfield *hf, oc_error *err);

/* Fills one row j of the grid being made. */
typedef void (*oc_heightfield_row_fn)(const void *ctx, oc_heightfield *out,
                                      int j);

/* Runs fn over every row of `out` on all cores. Only the calling thread
** talks to the progress callback; a non-zero answer stops the remaining
** rows and the work ends with OC_ECANCEL ("<what> cancelled"). */
int oc_heightfield_each_row(oc_heightfield *out, oc_heightfield_row_fn fn,
                            const void *ctx, oc_progress pr, const char *what,
                            oc_error *err);

/* A finite float for a double result (slopes of absurd grids overflow). */
static inline float oc_heightfield_float(double v) {
  return v > FLT_MAX ? FLT_MAX : v < -FLT_MAX ? -FLT_MAX : (float)v;
}

/* Priority-Flood+epsilon into z (nx ny samples, modified in place). */
int oc_heightfield_fill_samples(float *z, int nx, int ny,
                                const oc_heightfield_phase *ph, oc_error *err);
/* |grad z| by central differences (one-sided on the border) into out. */
void oc_heightfield_slope_samples(const float *z, int nx, int ny, double cell,
                                  float *out);

#endif
