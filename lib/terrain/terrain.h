/*
** terrain.h — the terrain primitive: an elevation source implicitized as
** min(f_T, f_P) (Paris et al. 2019, section 5.1), its value, gradient, support,
** Lipschitz bounds and column spans (internal; docs/fields.md has the
** formulas).
**
** The threshold T enters sigma, so a compiled terrain op carries
** OC_TPAR_N doubles (oc_terrain_sigma) next to a pointer to the node's
** oc_tdata, which holds everything independent of T.
*/
#ifndef OC_TERRAIN_H
#define OC_TERRAIN_H

#include "outcrop.h"

#define OC_TMASK_LEVELS 32

typedef struct oc_tdata {
  oc_elevation src; /* retained */
  double R, W;      /* prism falloff, half-width of sigma */
  int invert;
  int open;        /* open edges: f = 0 off the domain, no horizontal falloff */
  double zlo, zhi; /* the prism's z-range: range of h */
  double ix0, iy0, ix1, iy1; /* no mask: Omega shrunk by R (open: Omega) */
  double sx0, sy0, sx1, sy1; /* where f_P may be > 0 */
  double slope;              /* bound of |grad h| over the domain */
  double wlip;               /* weighted sources: alpha's Lipschitz bound */
  float *dist;               /* mask: distance to Omega shrunk by R */
  int mnx, mny;              /* mask grid */
  double mcell, mx0, my0;
  /* min/max pyramid of dist: level k (1 .. mlev) holds, for blocks of
  ** 2^k x 2^k nodes, (min, max) pairs at mpyr + moff[k], mw[k] per row */
  float *mpyr;
  int mlev, mw[OC_TMASK_LEVELS], mh[OC_TMASK_LEVELS];
  size_t moff[OC_TMASK_LEVELS];
} oc_tdata;

/* par of a terrain op: T, W, k = sigma'(0) W / T, and max sigma'. */
enum { OC_TPAR_T, OC_TPAR_W, OC_TPAR_K, OC_TPAR_DS, OC_TPAR_N };

void oc_tdata_free(oc_tdata *t);
void oc_terrain_sigma(double T, double W, double par[OC_TPAR_N]);

oc_aabb oc_terrain_box(const oc_tdata *t);
double oc_terrain_lipschitz(const oc_tdata *t, const double *par);
double oc_terrain_lipschitz_in(const oc_tdata *t, const double *par,
                               const oc_aabb *b);
/* Adds the z-spans where the terrain may vary over the footprint (zvar =
** 0), or only those where it may vary along z, column by column (zvar =
** 1: near the prism's walls f_P changes across the footprint at every
** z, but along a column only near its floor and top); returns 1 when the
** footprint lies where f_P depends on z alone (inside Omega shrunk by
** R), so that f = min(sigma(v), f_P(z)) along every column of it: the
** case of direct elevation extraction. */
int oc_terrain_spans(const oc_tdata *t, const double *par, double x0, double y0,
                     double x1, double y1, int zvar,
                     void (*add)(void *, double, double), void *S);

/* Along a column of that case, with elevation h there: the field at z,
** and the z of the prism's cap (the bottom, or the top when inverted). */
double oc_terrain_column_value(const oc_tdata *t, const double *par, double h,
                               double z);
double oc_terrain_cap_z(const oc_tdata *t);

/* When a terrain of P has a solid thinner than `size` (a small falloff
** and no thickness), so that samples `size` apart may all miss it (the
** mesher's cells, the renderer's ray steps), a sentence saying so in buf
** and 1; else 0. `what` names the size ("the cell"). The mesher and the
** renderer call it once their result came out empty. */
int oc_terrain_thin_reason(const struct oc_program *P, double size,
                           const char *what, char *buf, size_t n);

/* terrain_mask.c: the distance grid of a mask, and its queries. */
int oc_terrain_mask(oc_tdata *t, const oc_heightfield *mask, oc_error *err);
double oc_terrain_mask_dist(const oc_tdata *t, double x, double y,
                            double grad[2]);
/* Smallest and largest distance the interpolant takes on the footprint
** (conservative: from the nodes of the cells it meets). */
void oc_terrain_mask_range(const oc_tdata *t, double x0, double y0, double x1,
                           double y1, double *lo, double *hi);

/* The bytes of a heightfield's elevation source (oc_heightfield_elevation,
** elevation_hf.c): its own (the pyramid) returned, and in *hf and
** *hf_bytes the heightfield it reads and that grid's bytes, which every
** holder of the heightfield shares. 0 and NULL for another source. */
size_t oc_hfsrc_bytes(const oc_elevation *src, const oc_heightfield **hf,
                      size_t *hf_bytes);

#endif
