/*
** poisson.h — internals of maximal Poisson disk sampling, shared by
** poisson.c (checks, the phase driver, output and thinning), ptile.c (one
** tile's dart throwing and gap filling) and pcover.c (the exact coverage
** test of a box).
**
** The box is covered by a grid of cells of side h <= r / sqrt(d), so a
** cell holds at most one sample and a sample covers its own cell. Cells
** are grouped in tiles of OC_PTILE^d cells; tiles whose indices have the
** same parities on every axis are at least one tile (>= r) apart, so they
** can be worked on at the same time without touching each other's samples
** or the samples they read. Running the 2^d parity classes one after the
** other makes the result independent of the thread count.
**
** Periodic mode: the box is a torus of side len = n h exactly; cells
** beyond a face wrap to the other side, with their samples shifted by
** +-len (the samples near a cell are then its neighbours' periodic
** images). The tiles per axis are even (or one), so tiles of a parity
** class stay a tile apart across the wrap too.
*/
#ifndef OC_SAMPLE_POISSON_H
#define OC_SAMPLE_POISSON_H

#include <stddef.h>
#include <stdint.h>

#include "core/rng.h"
#include "outcrop.h"

/* Neighbour cells within reach: offsets in -2..2 per axis (h sqrt(d) <= r
** needs at most two cells of margin). */
#define OC_PREACH 5
/* Relative slack of the coverage test: a box counts as covered when every
** point of it is within r (1 + OC_PCOVER_TOL) of a sample. */
#define OC_PCOVER_TOL 1e-10
/* Samples near a box beyond which the exact test says "unknown" (the box is
** then split and tested again: smaller boxes meet fewer disks). */
#define OC_PCOVER_MAX 8

typedef struct oc_pgrid {
  int d;               /* 2 or 3 */
  double r, r2;        /* radius and its square */
  double lo[3], hi[3]; /* the box (z is 0 .. 0 in 2D) */
  double h;            /* cell side */
  int n[3];            /* cells per axis (n[2] = 1 in 2D) */
  size_t ncell;        /* n[0] n[1] n[2] */
  double *pos;         /* d coordinates per cell, NaN when it is empty */
  int tile;            /* cells per tile side */
  int nt[3];           /* tiles per axis */
  uint64_t seed;
  int periodic;    /* the box is a torus (oc_poisson_params.periodic) */
  double len;      /* its side when periodic */
  int cover_max;   /* samples the exact coverage test takes on */
  int cover_depth; /* splits it may make when there are more */
  /* reach[dz][dy][dx] (offset + 2) is 1 when a point of that neighbour
  ** cell may be closer than r to a point of the centre cell */
  unsigned char reach[OC_PREACH][OC_PREACH][OC_PREACH];
  /* the offsets within reach, nearest first (the dart test stops at the
  ** first sample too near, most often in an adjacent cell) */
  signed char near[OC_PREACH * OC_PREACH * OC_PREACH][3];
  int nnear;
  /* in doubles of pos, from a cell at least two cells from every face:
  ** those of near, and of the offsets within reach in the order dz, dy,
  ** dx */
  ptrdiff_t nearoff[OC_PREACH * OC_PREACH * OC_PREACH];
  ptrdiff_t reachoff[OC_PREACH * OC_PREACH * OC_PREACH];
  int nreach;
} oc_pgrid;

static inline size_t oc_pcell(const oc_pgrid *g, int i, int j, int k) {
  return ((size_t)k * (size_t)g->n[1] + (size_t)j) * (size_t)g->n[0] +
         (size_t)i;
}

/* A box still to be filled: a cell or a sub-cell of it; its side is the
** same for all the boxes of a refinement level. */
typedef struct oc_psub {
  size_t cell;
  double lo[3];
} oc_psub;

/* One thread's scratch space, reused from tile to tile. */
typedef struct oc_pwork {
  oc_psub *cur, *next;
  size_t capcur, capnext;
  double nb[OC_PREACH * OC_PREACH * OC_PREACH * 3]; /* a cell's neighbours */
  size_t unresolved; /* boxes still open at the depth limit (expected 0) */
} oc_pwork;

void oc_pwork_free(oc_pwork *w);

/* Throws `throws` darts at cells of tile t picked uniformly (empty or not,
** so that the throws are uniform over the tile's area); keeps those farther
** than r from every sample. */
void oc_ptile_darts(oc_pgrid *g, const int t[3], oc_rng *rng, size_t throws);

/* Fills the tile's gaps until no point of it is farther than r from a
** sample: boxes proven covered are dropped, darts are thrown uniformly at
** the others, which are split in 2^d until none is left. Returns 0 or
** OC_ENOMEM. */
int oc_ptile_fill(oc_pgrid *g, const int t[3], oc_rng *rng, oc_pwork *w);

/* Gathers the samples near cell (i, j, k) (all those within reach, d
** coordinates each) into nb; returns their count. */
int oc_pgather(const oc_pgrid *g, int i, int j, int k, double *nb);

/* Coverage of the box [lo, hi] by the disks (balls) of radius r around
** the n samples nb (d coordinates each), which must include every sample
** closer than r to the box. Returns 1 when the box is covered, 0 when some
** point of it is not or when it cannot tell (more than `max` samples
** matter; smaller boxes meet fewer). Exact up to OC_PCOVER_TOL: it checks
** the vertices of the box cut by the samples' Voronoi diagram. */
int oc_pcover(int d, double r, const double *lo, const double *hi,
              const double *nb, int n, int max, int depth);

#endif
