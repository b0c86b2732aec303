/*
** sea.c — sea erosion (Paris et al. 2019, section 6.1, figure 11): sea cliffs,
** overhangs, sea caves and arches carved by negative point primitives
** around sea level, deepest where the rock is soft.
**
** Candidate columns are Poisson disk samples of the footprint kept where
** the heightfield lies in the band [sea_level - range, sea_level + range]
** (beaches, gentle slopes: the ray is cast at z = h) or above it within
** `reach` of the band (steep cliffs, whose faces a footprint sampling
** barely sees: the ray is cast at a height drawn in the band, from the
** sea side). The rays run landward and stop where they enter the current
** tree, so later steps find the surface the earlier ones carved.
*/
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "gen/erode.h"

void oc_gen_sea_defaults(oc_gen_sea_params *p) {
  memset(p, 0, sizeof *p);
  oc_gen_erode_defaults(&p->erode);
  p->erode.strength = 4;
  p->erode.steps = 3;
  p->sea_level = NAN; /* follows the grid (oc_heightfield_sea_level) */
  p->range = 8;
  p->rays = 16;
}

typedef struct coast {
  const oc_heightfield *hf, *dist; /* dist: to the band, or NULL */
  double lo, hi, reach;
} coast;

static int keep_column(void *ud, double x, double y) {
  const coast *C = ud;
  double h = oc_heightfield_height(C->hf, x, y, NULL);
  if (h < C->lo) return 0;
  if (h <= C->hi) return 1;
  return C->dist && oc_heightfield_height(C->dist, x, y, NULL) <= C->reach;
}

/* Grid samples that are candidates themselves, so that the sampler visits
** only the tiles near the coast. */
static unsigned char *coast_mask(const coast *C, oc_error *err) {
  int nx = oc_heightfield_nx(C->hf), ny = oc_heightfield_ny(C->hf);
  const float *z = oc_heightfield_samples(C->hf);
  const float *d = C->dist ? oc_heightfield_samples(C->dist) : NULL;
  unsigned char *m = malloc((size_t)nx * ny);
  if (!m) {
    oc_seterr(err, OC_ENOMEM, "out of memory for the coast mask");
    return NULL;
  }
  for (size_t k = 0; k < (size_t)nx * ny; k++)
    m[k] = z[k] >= C->lo && (z[k] <= C->hi || (d && d[k] <= C->reach));
  return m;
}

/* The candidate of column (x, y); 0 when it has no landward direction. */
static int make_cand(const coast *C, const oc_gen_sea_params *p, double cell,
                     double x, double y, oc_erode_cand *c) {
  double g[2], h = oc_heightfield_height(C->hf, x, y, g);
  double fwd = p->erode.steps * p->erode.radius + cell;
  c->x = x;
  c->y = y;
  c->stress = 1;
  if (h <= C->hi) { /* in the band: the surface is at z = h */
    double len = hypot(g[0], g[1]);
    c->zlo = c->zhi = h;
    c->ux = c->uy = 0;
    if (len > 1e-9) {
      c->ux = g[0] / len;
      c->uy = g[1] / len;
    }
    c->back = p->erode.radius + cell;
    c->fwd = fwd;
    return 1;
  }
  double d = oc_heightfield_height(C->dist, x, y, g);
  double len = hypot(g[0], g[1]);
  if (!(len > 1e-9)) return 0;
  c->ux = g[0] / len;
  c->uy = g[1] / len;
  c->zlo = C->lo;
  c->zhi = C->hi;
  c->back = (d > 0 ? d : 0) + 2 * (p->erode.radius + cell);
  c->fwd = fwd;
  return 1;
}

static int check(const oc_gen_sea_params *p, oc_gen_sea_params *q,
                 oc_error *err) {
  *q = *p;
  if (!p->erode.heightfield)
    return oc_seterr(err, OC_EINVAL, "'heightfield' is required");
  if (isnan(q->sea_level))
    q->sea_level = oc_heightfield_sea_level(p->erode.heightfield);
  if (!isfinite(q->sea_level))
    return oc_seterr(err, OC_EINVAL, "'sea_level' must be finite (got %g)",
                     q->sea_level);
  if (!(p->range > 0 && isfinite(p->range)))
    return oc_seterr(err, OC_EINVAL, "'range' must be > 0 (got %g)", p->range);
  if (q->erode.radius == 0) q->erode.radius = q->range;
  if (q->erode.spacing == 0) q->erode.spacing = q->erode.radius / 2;
  if (q->reach == 0) q->reach = fmin(2 * q->erode.radius, DBL_MAX);
  if (oc_erode_check(&q->erode, err)) return err ? err->code : OC_EINVAL;
  if (!(q->reach > 0 && isfinite(q->reach)))
    return oc_seterr(err, OC_EINVAL, "'reach' must be > 0 (got %g)", q->reach);
  if (p->rays < 0 || p->rays > 4096)
    return oc_seterr(err, OC_EINVAL, "'rays' must be in 0..4096 (got %d)",
                     p->rays);
  return OC_OK;
}

oc_node *oc_generate_sea(const oc_gen_sea_params *pin, oc_gen_sea_stats *st,
                         oc_error *err) {
  oc_gen_sea_params p;
  if (check(pin, &p, err)) return NULL;
  oc_heightfield *hf = p.erode.heightfield, *dist = NULL;
  unsigned char *mask = NULL;
  double cell = oc_heightfield_cell(hf), *xy = NULL;
  oc_erode_cand *cand = NULL;
  oc_node *base = NULL, *out = NULL;
  size_t ncol = 0, nc = 0;
  coast C = {hf, NULL, p.sea_level - p.range, p.sea_level + p.range, p.reach};
  oc_error e2 = {OC_OK, ""};

  if (!(base = oc_erode_base(hf, p.erode.terrain, err))) return NULL;
  /* No sample at or below the band: no cliff to reach, only the band. */
  dist = oc_heightfield_distance_to_level(hf, C.hi, &e2);
  if (!dist && e2.code != OC_EINVAL) {
    oc_seterr(err, e2.code, "%s", e2.msg);
    goto done;
  }
  C.dist = dist;
  if (!(mask = coast_mask(&C, err))) goto done;
  xy = oc_erode_columns(hf, mask, p.erode.spacing, p.erode.seed, keep_column,
                        &C, p.erode.progress, 0.05, &ncol, err);
  if (!xy) goto done;
  if (p.erode.progress.fn && p.erode.progress.fn(p.erode.progress.ud, 0.1)) {
    oc_seterr(err, OC_ECANCEL, "sea erosion cancelled");
    goto done;
  }
  cand = malloc((ncol ? ncol : 1) * sizeof *cand);
  if (!cand) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu columns", ncol);
    goto done;
  }
  for (size_t i = 0; i < ncol; i++)
    nc += make_cand(&C, &p, cell, xy[2 * i], xy[2 * i + 1], &cand[nc]);

  oc_erode_params ep;
  oc_erode_shared(&ep, base, hf, &p.erode);
  ep.sea_level = p.sea_level;
  ep.range = p.range;
  ep.alpha = p.rays > 0 ? hf : NULL;
  ep.rays = p.rays;
  ep.reach = 8 * p.erode.radius;
  ep.pbase = 0.1;
  ep.pspan = 0.9;
  out = oc_erode_run(&ep, cand, nc, st, err);
done:
  oc_node_release(base);
  oc_heightfield_release(dist);
  free(mask);
  free(xy);
  free(cand);
  return out;
}
