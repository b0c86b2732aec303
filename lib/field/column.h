/*
** column.h — what the mesher learns about a column besides its z-spans
** (internal): whether a single heightfield-like op, a terrain or a plane,
** governs the column's footprint alone, and that op's surface as an
** elevation, for direct elevation extraction (Paris et al. 2019, section 7).
*/
#ifndef OC_COLUMN_H
#define OC_COLUMN_H

#include <stdint.h>

#include "field/program.h"

/* oc_program_column_spans, and in *hf the op that alone makes the field
** over the footprint (every other op is 0 there, and it is reached
** through blends and unions only, so f is its value), when that op is
** heightfield-like in all the footprint; OC_NONE otherwise. */
int oc_program_column_query(const oc_program *P, double x0, double y0,
                            double x1, double y1, oc_zspan *out, int max,
                            uint32_t *hf);
/* The same, and in zout (*nz of them, at most max; -1 with the whole
** column) the z-spans outside which the field is constant along every
** column of the footprint: those are the samples a column must evaluate
** one by one. A subset of the spans' union: near a terrain's walls the
** field varies across the footprint at every z, but along a column only
** near the floor and the surface. */
int oc_program_column_query_z(const oc_program *P, double x0, double y0,
                              double x1, double y1, oc_zspan *out, int max,
                              uint32_t *hf, oc_zspan *zout, int *nz);

/* The surface f = T of such an op, for one threshold T. */
typedef struct oc_hfsurf {
  uint32_t op;
  int kind;
  const double *par;
  const struct oc_tdata *t;
  double up;  /* 1: inside below the surface; -1: above */
  double cap; /* terrain: z of the prism's flat cap (bottom, or top) */
  double ds;  /* plane: distance along the normal of the surface */
} oc_hfsurf;

/* Fills s for op at threshold T; 0 when that op has no such surface at T
** (a terrain compiled for another T, a plane whose energy is <= T). */
int oc_hfsurf_init(oc_hfsurf *s, const oc_program *P, uint32_t op, double T);
/* The elevation e(x, y) of the surface, and its gradient in grad. */
double oc_hfsurf_height(const oc_hfsurf *s, double x, double y, double grad[2]);
/* The field at height z in a column whose surface is at e. */
double oc_hfsurf_value(const oc_hfsurf *s, double e, double z);
/* The z-spans (at most 2, sorted, written to out; returns the count)
** holding every point of the surface over the footprint [x0, x1] x
** [y0, y1]: the range of the elevation there, and a terrain's flat cap. */
int oc_hfsurf_level_spans(const oc_hfsurf *s, double x0, double y0, double x1,
                          double y1, oc_zspan out[2]);
/* The same for a column, or a group of columns, whose elevations range
** over [lo, hi]. */
int oc_hfsurf_elev_spans(const oc_hfsurf *s, double lo, double hi,
                         oc_zspan out[2]);
/* The crossing of f = T between za < zb in a column whose surface is at
** e, given that f - T changes sign there: e, or a terrain's flat cap
** (*cap set to 1 then: its normal is vertical). */
double oc_hfsurf_vertical(const oc_hfsurf *s, double e, double za, double zb,
                          int *cap);

#endif
