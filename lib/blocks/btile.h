/*
** btile.h — internals of the block family (Paris et al. 2020, section 4),
** shared by its files: a fracture tile (tile.c) is made from periodic
** Poisson points, a neighbour graph (graph.c), fracture discs (discs.c),
** clusters (cluster.c) and their convex hulls (hull.c); each hull becomes
** a block node (block.c).
**
** Coordinates: the tile is the cube [0, s)^3 of a 3-torus. Points are
** stored in it; a cluster's points are unwrapped to contiguous
** coordinates (each one a periodic image of a stored point) and the
** cluster is then shifted so that its centroid lies in the tile.
*/
#ifndef OC_BTILE_H
#define OC_BTILE_H

#include <stddef.h>
#include <stdint.h>

#include "outcrop.h"

/* A fracture disc: centre c, unit normal n, radius r. */
typedef struct oc_bdisc {
  oc_vec3 c, n;
  double r;
} oc_bdisc;

/* A fracture disc's radius is at most this many tile sizes: a larger one
** cuts the periodic tile over and over (its images grow as the cube of
** radius / size) and tells nothing more. */
#define OC_BTILE_MAX_DISC_SIZES 16.0

/* A periodic image of a disc (its centre shifted by a multiple of s) with
** the box around it. */
typedef struct oc_bimage {
  oc_vec3 c, n;
  double r2;
  oc_aabb box;
} oc_bimage;

/* The neighbour graph: edge e joins points a[e] < b[e]; the image of b
** nearest to a is at p[a] + v[e]. adj lists, for each point i,
** the edges at it: adj[start[i] .. start[i + 1]). */
typedef struct oc_bgraph {
  size_t ne;
  uint32_t *a, *b;
  float *v; /* 3 per edge */
  unsigned char *cut;
  size_t *start;
  uint32_t *adj;
} oc_bgraph;

/* One block: its hull planes n . p + off <= 0 (4 doubles each), the hull
** vertices (3 doubles each), the cluster's points, centroid and box. */
typedef struct oc_bblock {
  size_t nplane, nvert, npts;
  double *plane, *vert;
  oc_vec3 centroid;
  oc_aabb box; /* of the hull */
  double thickness;
} oc_bblock;

struct oc_btile {
  oc_btile_params pp;
  size_t np;
  double *pts; /* 3 per point, in [0, s)^3 */
  size_t nd;
  oc_bdisc *disc;
  oc_bgraph g;
  size_t ncl;      /* clusters */
  uint32_t *label; /* cluster of each point */
  double *unwrap;  /* each point's unwrapped position (3 per point) */
  size_t nb;       /* blocks (clusters with a hull) */
  oc_bblock *block;
  size_t thick;  /* degenerate clusters made thick polygons or points */
  size_t ncut;   /* pairs of blocks cut apart (separate.c) */
  size_t merged; /* small clusters merged into a neighbour (merge.c) */
  size_t nauth;  /* authored blocks (authored.c), the last nauth of block */
  oc_bblock *auth;
  size_t gcut; /* a loaded tile's cut edges (tio.c): its g holds only
               ** the count of edges, g.ne, and no arrays */
  double seconds;
};

/* The checks of oc_btile_new: 0, or OC_EINVAL with err naming the
** parameter (tile.c). */
int oc_btile_check(const oc_btile_params *pp, oc_error *err);

/* Fills t->disc with the type's discs then the user's (discs.c). */
int oc_bdiscs_make(oc_btile *t, oc_error *err);
/* The images of the discs whose boxes meet the box `in`; a new array
** in *out (caller frees), its count in *n. */
int oc_bdiscs_images(const oc_btile *t, oc_aabb in, oc_bimage **out, size_t *n,
                     oc_error *err);
/* 1 when segment [p, q] crosses the image's disc. */
int oc_bimage_cuts(const oc_bimage *d, const double *p, const double *q);
/* The same with p's and q's signed distances a, b to the plane known
** (inline: clustering calls it tens of millions of times per tile). */
static inline int oc_bimage_cuts_at(const oc_bimage *d, const double *p,
                                    const double *q, double a, double b) {
  if ((a > 0 && b > 0) || (a < 0 && b < 0) || a == b) return 0;
  double w = a / (a - b);
  double x = p[0] + w * (q[0] - p[0]) - d->c.x,
         y = p[1] + w * (q[1] - p[1]) - d->c.y,
         z = p[2] + w * (q[2] - p[2]) - d->c.z;
  return x * x + y * y + z * z <= d->r2;
}

/* Builds t->g (edges shorter than neighbour * radius, periodic) and marks
** the edges the discs cut (graph.c). */
int oc_bgraph_make(oc_btile *t, oc_error *err);
void oc_bgraph_free(oc_bgraph *g);

/* Greedy clusters with the mutual-visibility check, unwrapped (cluster.c):
** fills t->ncl, t->label, t->unwrap. */
int oc_bclusters_make(oc_btile *t, oc_error *err);

/* Merges the smallest clusters into neighbours and moves each centroid
** into the tile (merge.c); renumbers t->label, updates t->ncl. */
int oc_bclusters_merge(oc_btile *t, oc_error *err);

/* Convex hulls of the clusters (hull.c): fills t->block, t->nb. */
int oc_bhulls_make(oc_btile *t, oc_error *err);
void oc_bblock_free(oc_bblock *b);
/* One block from the hull of n points (3 doubles each): planes, vertices,
** box, thickness, centroid the points' mean. OC_EINVAL when qhull finds
** them flat (or n < 4), OC_ENOMEM; b is then empty. */
int oc_bblock_hull(double *xyz, size_t n, oc_bblock *b, oc_error *err);

/* qhull of the n points xyz into b's planes and vertices (hull.c): 0,
** 1 when qhull failed (fewer than 4 points, flat), OC_ENOMEM. */
int oc_bhull_points(double *xyz, size_t n, oc_bblock *b);
/* b's box and thickness from its vertices and planes. */
void oc_bblock_measure(oc_bblock *b);

/* Authored blocks (authored.c): their hulls into t->auth (before the
** points), the tile points inside them removed, the graph's edges
** across them cut, and at the end generated blocks cut back by their
** faces and the authored blocks appended to t->block. */
int oc_bauthored_make(oc_btile *t, oc_error *err);
void oc_bauthored_points(oc_btile *t);
void oc_bauthored_cut(oc_btile *t);
int oc_bauthored_finish(oc_btile *t, oc_error *err);

/* Cuts overlapping blocks apart with a plane each (separate.c). */
int oc_bblocks_separate(oc_btile *t, oc_error *err);

/* A block's field (block.c): its planes, rounding min(R, thickness / 2)
** and width W, malloc'ed (free with free). */
typedef struct oc_bfield oc_bfield;
oc_bfield *oc_bfield_new(const oc_bblock *b, double R, double W);
/* The hull's box grown by W (f = 0 outside), and W. */
oc_aabb oc_bfield_support(const oc_bfield *b);
double oc_bfield_width(const oc_bfield *b);
/* Bytes the field holds. */
size_t oc_bfield_bytes(const oc_bfield *b);
/* The rounded distance d (<= 0 inside) and its gradient. */
double oc_bfield_dist(const oc_bfield *b, oc_vec3 p, oc_vec3 *g);
/* sigma's constants for threshold T and width W, then f = sigma(-d). */
#define OC_BSIGMA_N 4
void oc_bfield_sigma(double T, double W, double sp[OC_BSIGMA_N]);
double oc_bfield_eval(const oc_bfield *b, const double *sp, oc_vec3 p,
                      oc_vec3 *g);

/* The block node of hull planes (block.c): rounding R, width W. */
oc_node *oc_bblock_node(const oc_bblock *b, double R, double W, oc_error *err);

#endif
