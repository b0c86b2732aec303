/*
** elevation_tree.c — elevation sources other than grids (elevation trees,
** Génevaux et al. 2015) as terrains and as grids: the default terrain
** parameters of a source, the terrain node of a tree, the default grid
** over a source's domain and the sampling of a source into a grid.
**
** Sampling calls height_weight (or height) once per sample, f and alpha
** coming from one traversal of the tree (or height_weight_row, the same
** values a row at a time); each sample depends on its
** position alone, so rows run on all cores and the grid is the same to
** the byte for any thread count.
*/
#include <float.h>
#include <math.h>
#include <string.h>

#include "core/error.h"
#include "outcrop.h"
#include "terrain/analysis.h"

/* The default falloff, as a fraction of the domain's longer side: enough
** bedrock under the lowest point (X_HALF R, 9 m for 2 km) without the
** prism's slow fade costing the tracer steps. */
#define FALLOFF_FRACTION 0.01
/* Samples along the longer side of a default grid. */
#define DEFAULT_SAMPLES 513
#define MAX_SIDE 65535

void oc_terrain_defaults_source(const oc_elevation *src,
                                oc_terrain_params *tp) {
  memset(tp, 0, sizeof *tp);
  tp->falloff =
      src ? FALLOFF_FRACTION * fmax(src->x1 - src->x0, src->y1 - src->y0) : 0;
  tp->transition = 1;
}

oc_node *oc_enode_terrain(oc_enode *e, const double *domain,
                          const oc_terrain_params *tp, oc_error *err) {
  if (!e) {
    oc_seterr(err, OC_EINVAL, "the elevation tree is NULL");
    return NULL;
  }
  oc_elevation src;
  if (oc_enode_elevation(e, domain, &src, err) != OC_OK) return NULL;
  oc_terrain_params d;
  if (!tp) {
    oc_terrain_defaults_source(&src, &d);
    tp = &d;
  }
  oc_node *t = oc_terrain(&src, tp, err);
  src.release(src.ud); /* the node holds its own reference */
  return t;
}

int oc_elevation_grid(const oc_elevation *src, int nx, int ny, double cell,
                      const double *origin, oc_heightfield_grid *g,
                      oc_error *err) {
  if (!src)
    return oc_seterr(err, OC_EINVAL, "no elevation source for the grid");
  double x0 = origin ? origin[0] : src->x0, y0 = origin ? origin[1] : src->y0;
  double w = src->x1 - x0, h = src->y1 - y0;
  if (!(isfinite(x0) && isfinite(y0)))
    return oc_seterr(err, OC_EINVAL, "'origin' must be finite");
  if (!(cell == 0 || (cell > 0 && isfinite(cell))))
    return oc_seterr(err, OC_EINVAL, "'cell' must be a number > 0 (got %g)",
                     cell);
  if ((nx != 0 || ny != 0) &&
      (nx < 2 || ny < 2 || nx > MAX_SIDE || ny > MAX_SIDE))
    return oc_seterr(err, OC_EINVAL,
                     "'size' must be {nx, ny} with integers in 2..%d (got "
                     "{%d, %d})",
                     MAX_SIDE, nx, ny);
  if ((!nx || !cell) && !(w > 0 && h > 0))
    return oc_seterr(err, OC_EINVAL,
                     "'origin' {%g, %g} lies beyond the domain's far corner "
                     "{%g, %g}: give 'size' and 'cell'",
                     x0, y0, src->x1, src->y1);
  if (!nx && !cell) cell = fmax(w, h) / (DEFAULT_SAMPLES - 1);
  if (!cell) {
    /* the smallest cell with which nx x ny samples cover the domain */
    cell = fmax(w / (nx - 1), h / (ny - 1));
  } else if (!nx) {
    /* (less a rounding, so that a cell dividing the domain does not add
    ** a sample past it) */
    double a = ceil(w / cell * (1 - 1e-12)) + 1;
    double b = ceil(h / cell * (1 - 1e-12)) + 1;
    if (!(a <= MAX_SIDE && b <= MAX_SIDE))
      return oc_seterr(err, OC_EINVAL,
                       "'cell' %g gives %.0f x %.0f samples over the "
                       "domain, more than %d a side: give a larger 'cell' or "
                       "a 'size'",
                       cell, a, b, MAX_SIDE);
    nx = a < 2 ? 2 : (int)a;
    ny = b < 2 ? 2 : (int)b;
  }
  g->nx = nx, g->ny = ny, g->cell = cell, g->x0 = x0, g->y0 = y0;
  return OC_OK;
}

/* ---- sampling ---------------------------------------------------------- */

typedef struct sample_ctx {
  const oc_elevation *src;
  double x0, y0, cell;
  int holes; /* samples where alpha < 1/2 get hole */
  float hole;
} sample_ctx;

/* Samples along a row at a time, from the source's rows when it has them
** (the same values as its points). */
#define ROW_CHUNK 256

static void sample_row(const void *ctx, oc_heightfield *out, int j) {
  const sample_ctx *c = ctx;
  const oc_elevation *s = c->src;
  int nx = oc_heightfield_nx(out);
  float *row = oc_heightfield_samples_mut(out) + (size_t)j * (size_t)nx;
  double y = c->y0 + j * c->cell;
  double xs[ROW_CHUNK], fs[ROW_CHUNK], as[ROW_CHUNK];
  for (int i0 = 0; i0 < nx; i0 += ROW_CHUNK) {
    int n = nx - i0 < ROW_CHUNK ? nx - i0 : ROW_CHUNK;
    for (int i = 0; i < n; i++) {
      double x = c->x0 + (i0 + i) * c->cell;
      xs[i] = x;
      as[i] = 1;
      if (s->height_weight_row) continue;
      if (s->height_weight)
        fs[i] = s->height_weight(s->ud, x, y, NULL, &as[i], NULL);
      else
        fs[i] = s->height(s->ud, x, y, NULL);
    }
    if (s->height_weight_row) s->height_weight_row(s->ud, xs, y, n, fs, as);
    for (int i = 0; i < n; i++)
      row[i0 + i] =
          c->holes && !(as[i] >= 0.5) ? c->hole : oc_heightfield_float(fs[i]);
  }
}

oc_heightfield *oc_heightfield_from_elevation(const oc_elevation *src,
                                              const oc_heightfield_grid *g,
                                              int holes, double hole,
                                              oc_progress progress,
                                              oc_error *err) {
  if (!src || !src->height || !g) {
    oc_seterr(err, OC_EINVAL, "no elevation source or grid to sample");
    return NULL;
  }
  if (holes && !(isfinite(hole) && fabs(hole) <= FLT_MAX)) {
    oc_seterr(err, OC_EINVAL, "'holes' must be a finite float (got %g)", hole);
    return NULL;
  }
  oc_heightfield *out =
      oc_heightfield_new(g->nx, g->ny, g->cell, g->x0, g->y0, NULL, err);
  if (!out) return NULL;
  sample_ctx c = {src, g->x0, g->y0, g->cell, holes != 0, (float)hole};
  if (oc_heightfield_each_row(out, sample_row, &c, progress, "sampling", err) !=
      OC_OK) {
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}
