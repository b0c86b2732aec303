/*
** mcwork.h — the scratch state of the slab mesher and its steps
** (internal): per-column k-ranges of the band, the sample store, and the
** functions of each step (see mcslab.c for the whole).
*/
#ifndef OC_MCWORK_H
#define OC_MCWORK_H

#include <stddef.h>
#include <stdint.h>

#include "core/grow.h"
#include "mesh/mcgrid.h"

typedef struct oc_mc_irange {
  int32_t lo, hi; /* inclusive */
} oc_mc_irange;

typedef struct oc_mc_srange {
  int32_t lo, hi; /* samples lo .. hi of the column */
  ptrdiff_t off;  /* sample k is at val[off + k] */
} oc_mc_srange;

/* A list of ranges per column, in compressed row form. */
typedef struct oc_mc_rlist {
  oc_mc_irange *r;
  size_t n, cap;
  size_t *at; /* column c has r[at[c] .. at[c + 1]) */
  size_t capat;
} oc_mc_rlist;

struct oc_mcwork {
  /* cube ranges before and after culling, varying sample ranges (from
  ** the spans), culled k-ranges per block column */
  oc_mc_rlist cube, kept, var, cull;
  oc_mc_srange *sr;
  size_t nsr, capsr;
  size_t *srat, capsrat;
  double *val;
  uint32_t *slot; /* 3 per sample: vertex on its +x, +y, +z edge */
  size_t capval, capslot;
  oc_mc_irange *tmp;
  size_t capt;
  uint32_t *flat;
  size_t nflat, capflat;
  /* direct extraction, per sample column of the slab (rows ja .. jb,
  ** i = -1 .. nx, as srat): the surface governing it alone or NULL, and
  ** its elevation and gradient there (3 doubles) */
  const struct oc_hfsurf **dsurf;
  double *delev;
  size_t capdsurf, capdelev;
  /* the surface whose elevation delev holds, per sample column (NULL:
  ** none yet), and per block of the slab's cube columns the direct
  ** surface governing the block's whole footprint alone, or NULL */
  const struct oc_hfsurf **esurf, **bsurf;
  size_t capesurf, capbsurf;
  int ja;                  /* first row of the slab being meshed */
  size_t last_nv, last_nt; /* output sizes of the previous slab */
};

/* Grows *pp (an array of elem-byte items, capacity *cap) to hold need
** items, doubling from 64; 0 or -1 when out of memory. Inline: the mesher
** asks at every vertex and cell, and nearly always there is room. */
static inline int oc_mc_grow(void *pp, size_t *cap, size_t need, size_t elem) {
  return need <= *cap ? 0 : oc_grow(pp, cap, need, elem, 64);
}

/* Starts a list of ncol columns (ranges are then added column by column,
** at[c + 1] set by the caller after column c). */
int oc_mc_rlist_columns(oc_mc_rlist *l, size_t ncol);
/* Appends [lo, hi] to the column whose ranges start at `first`, merging
** with the last range when they touch (ranges must come sorted by lo). */
int oc_mc_rlist_add(oc_mc_rlist *l, size_t first, int32_t lo, int32_t hi);
/* Sorts ranges by lo (short lists). */
void oc_mc_sort_ranges(oc_mc_irange *t, size_t n);

/* Step 1: cube ranges of cube rows ja .. jb - 1 into w->cube, varying
** sample ranges of rows ja .. jr into w->var (mcband.c). */
int oc_mc_band(const oc_mcgrid *g, int ja, int jb, int jr, oc_mcwork *w);
/* Step 2: w->kept = w->cube minus the blocks Lipschitz-proven uniform;
** counts the field calls made (mcband.c). */
int oc_mc_cull(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w, size_t *calls);
/* Step 3: the sample ranges the cubes need (*total samples), then their
** values (mcsample.c). */
int oc_mc_sample_ranges(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
                        const oc_mc_rlist *cubes, size_t *total);
void oc_mc_samples(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
                   size_t *calls);

/* Direct elevation extraction (mcdirect.c). The value of every sample of
** the direct sample column c = (i, j), from the elevation there (which it
** stores in w->delev). */
void oc_mc_direct_column(const oc_mcgrid *g, int i, int j, size_t c,
                         const oc_mc_srange *s, size_t ns, oc_mcwork *w);
/* Elevation and gradient (3 doubles) of surface hs at sample column
** (i, j) of the slab (rows ja .. jb), computed once per slab. */
const double *oc_mc_elevation(const oc_mcgrid *g, oc_mcwork *w,
                              const struct oc_hfsurf *hs, int i, int j);
/* Places the vertex of a crossing edge from the elevation when the edge
** lies in direct columns (one, or two under the same surface): 1 done, 0
** when the caller must find the root on the field. */
int oc_mc_direct_vertex(const oc_mcgrid *g, const oc_mcwork *w, const int s[3],
                        int axis, float pos[3], float nrm[3]);

#endif
