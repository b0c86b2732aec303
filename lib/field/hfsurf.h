/*
** hfsurf.h — the surface of a heightfield-like op (a plane, or an
** extension kind flagged OC_KF_HFLIKE such as a terrain) as an elevation,
** for direct elevation extraction (Paris et al. 2019, section 7)
** (internal). Which op governs a column alone is what the column query
** of query.h tells.
*/
#ifndef OC_HFSURF_H
#define OC_HFSURF_H

#include <stdint.h>

#include "field/program.h"

/* The surface f = T of such an op, for one threshold T. */
typedef struct oc_hfsurf {
  uint32_t op;
  int ext;    /* 1: an extension kind's surface (ks, k); 0: a plane's */
  int direct; /* the mesher extracts it directly (OC_KF_DIRECT) */
  const double *par;
  oc_ksurf ks;
  oc_kctx k;  /* what ks.value takes */
  double up;  /* 1: inside below the surface; -1: above */
  double cap; /* z of a flat cap (a terrain's prism bottom or top), or NAN */
  double ds;  /* plane: distance along the normal of the surface */
} oc_hfsurf;

/* 1 when op may have such a surface: a plane, or a kind flagged
** OC_KF_HFLIKE. */
int oc_hfsurf_candidate(const oc_program *P, uint32_t op);
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
