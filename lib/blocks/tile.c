/*
** tile.c — a fracture tile (Paris et al. 2020, section 4.1): defaults per
** block type (Table 1), checks of the parameters, the pipeline (periodic
** Poisson points, neighbour graph, discs, cut edges, clusters, hulls),
** statistics, and blocks as nodes.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "core/rng.h"

#define KEY_POINTS 0x706f696e7473ull
/* (s / r)^3 beyond which a tile is refused (about 1.6 million points) */
#define MAX_CELLS 4e6
#define MAX_FRACTURES 100000

static const char *const names[OC_BLOCKS_NTYPES] = {
    "equidimensional", "rhombohedral", "polyhedral",
    "tabular",         "prismatic",    "columnar"};
/* Table 1's #D; the extensions' chosen like them (discs.c) */
static const size_t table_discs[OC_BLOCKS_NTYPES] = {15, 24, 44, 30, 12, 12};

const char *oc_block_type_name(oc_block_type type) {
  return (unsigned)type < OC_BLOCKS_NTYPES ? names[type] : NULL;
}

int oc_block_type_find(const char *name) {
  for (int i = 0; i < OC_BLOCKS_NTYPES; i++)
    if (strcmp(name, names[i]) == 0) return i;
  return -1;
}

void oc_btile_defaults(oc_block_type type, oc_btile_params *pp) {
  memset(pp, 0, sizeof *pp);
  pp->type = type;
  pp->size = 20;
  pp->radius = 0.75;
  pp->neighbour = 2;
  pp->fractures = (unsigned)type < OC_BLOCKS_NTYPES ? table_discs[type] : 0;
  pp->spacing = type == OC_BLOCKS_POLYHEDRAL ? 1
                : type == OC_BLOCKS_COLUMNAR ? 1.5
                                             : 2;
  /* disc radii, tuned to Table 1's #B and #Pi at the defaults (the
  ** paper's "about 5 m" gives equidimensional blocks twice too large) */
  static const double radii[OC_BLOCKS_NTYPES][2] = {
      {7, 11}, {4, 6}, {2.5, 3.5}, {4, 6}, {7, 11}, {10, 14}};
  int ty = (unsigned)type < OC_BLOCKS_NTYPES ? (int)type : 0;
  pp->disc_lo = radii[ty][0];
  pp->disc_hi = radii[ty][1];
  pp->rounding = 0.25;
  pp->width = 0.75;
  pp->seed = 1;
}

static int check(const oc_btile_params *pp, oc_error *err) {
  if ((unsigned)pp->type >= OC_BLOCKS_NTYPES)
    return oc_seterr(err, OC_EINVAL, "'type' %d is not a block type",
                     (int)pp->type);
  if (!(pp->size > 0) || !isfinite(pp->size))
    return oc_seterr(err, OC_EINVAL, "'size' must be > 0 (got %g)", pp->size);
  if (!(pp->neighbour > 1 && pp->neighbour <= 4))
    return oc_seterr(err, OC_EINVAL, "'neighbour' must be in (1, 4] (got %g)",
                     pp->neighbour);
  if (!(pp->radius > 0) || !isfinite(pp->radius))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)",
                     pp->radius);
  if (pp->radius * 3 * pp->neighbour > pp->size)
    return oc_seterr(err, OC_EINVAL,
                     "'radius' %g is too large for a tile of 'size' %g (at "
                     "most size / (3 neighbour) = %g)",
                     pp->radius, pp->size, pp->size / (3 * pp->neighbour));
  double cells = pow(pp->size / pp->radius, 3);
  if (!(cells <= MAX_CELLS))
    return oc_seterr(err, OC_EINVAL,
                     "'radius' %g is too small for a tile of 'size' %g "
                     "((size / radius)^3 at most %g)",
                     pp->radius, pp->size, MAX_CELLS);
  if (pp->fractures < 1 || pp->fractures > MAX_FRACTURES)
    return oc_seterr(err, OC_EINVAL, "'fractures' must be in 1 .. %d (got %zu)",
                     MAX_FRACTURES, pp->fractures);
  if (!(pp->spacing >= 0) || !isfinite(pp->spacing))
    return oc_seterr(err, OC_EINVAL, "'spacing' must be >= 0 (got %g)",
                     pp->spacing);
  if (!(pp->disc_lo > 0 && pp->disc_hi >= pp->disc_lo) ||
      !isfinite(pp->disc_hi))
    return oc_seterr(err, OC_EINVAL,
                     "'disc_radius' must be {lo, hi} with 0 < lo <= hi (got "
                     "%g, %g)",
                     pp->disc_lo, pp->disc_hi);
  if (pp->disc_hi > OC_BTILE_MAX_DISC_SIZES * pp->size)
    return oc_seterr(err, OC_EINVAL,
                     "'disc_radius' %g is too large for a tile of 'size' %g "
                     "(at most %g sizes)",
                     pp->disc_hi, pp->size, OC_BTILE_MAX_DISC_SIZES);
  if (!(pp->rounding >= 0) || !isfinite(pp->rounding))
    return oc_seterr(err, OC_EINVAL, "'rounding' must be >= 0 (got %g)",
                     pp->rounding);
  if (!(pp->width > 0) || !isfinite(pp->width))
    return oc_seterr(err, OC_EINVAL, "'width' must be > 0 (got %g)", pp->width);
  if (pp->ndiscs && !pp->discs)
    return oc_seterr(err, OC_EINVAL, "'discs' missing");
  if (pp->ndiscs > MAX_FRACTURES)
    return oc_seterr(err, OC_EINVAL, "'discs': at most %d", MAX_FRACTURES);
  for (size_t i = 0; i < pp->ndiscs; i++) {
    const oc_block_disc *d = &pp->discs[i];
    oc_vec3 n = d->normal, c = d->center;
    if (!isfinite(c.x) || !isfinite(c.y) || !isfinite(c.z))
      return oc_seterr(err, OC_EINVAL, "'discs[%zu].center' must be finite",
                       i + 1);
    double l = n.x * n.x + n.y * n.y + n.z * n.z;
    if (!(l > 1e-24) || !isfinite(l))
      return oc_seterr(err, OC_EINVAL,
                       "'discs[%zu].normal' must be finite and non-zero (got "
                       "%g %g %g)",
                       i + 1, n.x, n.y, n.z);
    if (!(d->radius > 0) || !isfinite(d->radius))
      return oc_seterr(err, OC_EINVAL,
                       "'discs[%zu].radius' must be > 0 (got %g)", i + 1,
                       d->radius);
    if (d->radius > OC_BTILE_MAX_DISC_SIZES * pp->size)
      return oc_seterr(err, OC_EINVAL,
                       "'discs[%zu].radius' %g is too large for a tile of "
                       "'size' %g (at most %g sizes)",
                       i + 1, d->radius, pp->size, OC_BTILE_MAX_DISC_SIZES);
  }
  return 0;
}

int oc_btile_check(const oc_btile_params *pp, oc_error *err) {
  return check(pp, err);
}

void oc_btile_free(oc_btile *t) {
  if (!t) return;
  free(t->pts);
  free(t->disc);
  oc_bgraph_free(&t->g);
  free(t->label);
  free(t->unwrap);
  for (size_t i = 0; i < t->ncl && t->block; i++)
    oc_bblock_free(&t->block[i]);
  free(t->block);
  for (size_t i = 0; i < t->nauth && t->auth; i++)
    oc_bblock_free(&t->auth[i]);
  free(t->auth);
  free(t);
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int points(oc_btile *t, oc_error *err) {
  oc_poisson_params pp;
  memset(&pp, 0, sizeof pp);
  double s = t->pp.size;
  pp.box = (oc_aabb){{0, 0, 0}, {s, s, s}};
  pp.radius = t->pp.radius;
  pp.seed = oc_hash2(t->pp.seed, KEY_POINTS);
  pp.periodic = 1;
  oc_samples *sm = oc_poisson3d(&pp, err);
  if (!sm) return OC_EINVAL;
  t->np = oc_samples_count(sm);
  t->pts = malloc((t->np ? t->np : 1) * 3 * sizeof *t->pts);
  if (!t->pts) {
    oc_samples_free(sm);
    return oc_seterr(err, OC_ENOMEM, "out of memory for points");
  }
  memcpy(t->pts, oc_samples_data(sm), t->np * 3 * sizeof *t->pts);
  oc_samples_free(sm);
  return 0;
}

oc_btile *oc_btile_new(const oc_btile_params *pp, oc_error *err) {
  if (!pp) {
    oc_seterr(err, OC_EINVAL, "blocks.tile needs params");
    return NULL;
  }
  if (check(pp, err)) return NULL;
  double t0 = now();
  oc_btile *t = calloc(1, sizeof *t);
  if (!t) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  t->pp = *pp;
  int rc = oc_bauthored_make(t, err);
  if (!rc) rc = points(t, err);
  if (!rc) oc_bauthored_points(t);
  if (!rc) rc = oc_bdiscs_make(t, err);
  /* copied into t->disc and t->auth: the caller's may go */
  t->pp.discs = NULL;
  t->pp.blocks = NULL;
  if (!rc) rc = oc_bgraph_make(t, err);
  if (!rc) oc_bauthored_cut(t);
  if (!rc) rc = oc_bclusters_make(t, err);
  if (!rc) rc = oc_bclusters_merge(t, err);
  if (!rc) rc = oc_bhulls_make(t, err);
  if (!rc) rc = oc_bblocks_separate(t, err);
  if (!rc) rc = oc_bauthored_finish(t, err);
  if (rc) {
    oc_btile_free(t);
    return NULL;
  }
  t->seconds = now() - t0;
  return t;
}

void oc_btile_stats_get(const oc_btile *t, oc_btile_stats *st) {
  memset(st, 0, sizeof *st);
  st->points = t->np;
  st->fractures = t->nd;
  st->blocks = t->nb;
  st->edges = t->g.ne;
  for (size_t e = 0; e < t->g.ne && t->g.cut; e++)
    st->cut += t->g.cut[e];
  if (!t->g.cut) st->cut = t->gcut; /* a loaded tile (tio.c) */
  st->thick = t->thick;
  st->separated = t->ncut;
  st->merged = t->merged;
  st->authored = t->nauth;
  size_t in = 0;
  for (size_t i = 0; i < t->nb; i++)
    in += t->block[i].npts;
  st->points_per_block = t->nb ? (double)in / (double)t->nb : 0;
  st->seconds = t->seconds;
}

oc_node *oc_btile_block(const oc_btile *t, size_t i, oc_error *err) {
  if (i >= t->nb) {
    oc_seterr(err, OC_EINVAL, "block %zu out of range (the tile has %zu)",
              i + 1, t->nb);
    return NULL;
  }
  return oc_bblock_node(&t->block[i], t->pp.rounding, t->pp.width, err);
}

oc_node *oc_btile_node(const oc_btile *t, oc_error *err) {
  if (!t->nb) {
    oc_seterr(err, OC_EINVAL, "the tile has no blocks");
    return NULL;
  }
  oc_node **kids = calloc(t->nb, sizeof *kids);
  if (!kids) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  oc_node *u = NULL;
  size_t n = 0;
  for (; n < t->nb; n++)
    if (!(kids[n] = oc_btile_block(t, n, err))) break;
  if (n == t->nb) u = oc_union(kids, n, err);
  for (size_t i = 0; i < n; i++)
    oc_node_release(kids[i]);
  free(kids);
  return u;
}

const double *oc_btile_planes(const oc_btile *t, size_t i, size_t *nplane) {
  if (i >= t->nb) return NULL;
  *nplane = t->block[i].nplane;
  return t->block[i].plane;
}

const double *oc_btile_vertices(const oc_btile *t, size_t i, size_t *nvert) {
  if (i >= t->nb) return NULL;
  *nvert = t->block[i].nvert;
  return t->block[i].vert;
}
