/*
** diffuse.c — oc_diffusion (Hnaidi et al. 2010, figure 2): checks, the
** constraint maps (raster.c), their restriction to every level
** (pyramid.c), the diffusions in the paper's order — the gradient (norm
** and direction n first, n re-normalised after, so that conflicting
** gradients are filled), then the elevation guided by it, then amplitude
** and roughness — and the final sum of the smooth map and the noise
** detail. Each step is parallel and the same to the byte for any thread
** count; progress is reported between sweeps and may cancel.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"
#include "terrain/analysis.h"

#define MAX_CURVES 65534
#define COHERENT 0.5

static int check(const oc_diffusion_params *p, oc_error *err) {
  char b[OC_NUMSTR];
  if (!p) return oc_seterr(err, OC_EINVAL, "diffusion: no parameters");
  const oc_heightfield_grid *g = &p->grid;
  if (g->nx < 2 || g->ny < 2 || g->nx > 65535 || g->ny > 65535 ||
      (unsigned long long)g->nx * (unsigned long long)g->ny >
          OC_DIFFUSION_MAX_SAMPLES)
    return oc_seterr(err, OC_EINVAL,
                     "'size' must be {nx, ny} in 2..65535 with nx ny <= %llu "
                     "(got %d x %d)",
                     OC_DIFFUSION_MAX_SAMPLES, g->nx, g->ny);
  if (!(g->cell > 0 && isfinite(g->cell)))
    return oc_seterr(err, OC_EINVAL, "'cell' must be > 0 (got %s)",
                     oc_numstr(g->cell, b));
  if (!isfinite(g->x0) || !isfinite(g->y0))
    return oc_seterr(err, OC_EINVAL, "'origin' must be finite");
  if (!p->curves || p->ncurves < 1 || p->ncurves > MAX_CURVES)
    return oc_seterr(err, OC_EINVAL,
                     "'curves' must hold 1 to %d feature curves (got %zu)",
                     MAX_CURVES, p->curves ? p->ncurves : 0);
  int strict = 0;
  for (size_t i = 0; i < p->ncurves; i++) {
    if (!p->curves[i])
      return oc_seterr(err, OC_EINVAL, "'curves[%zu]' is NULL", i + 1);
    strict |= (oc_fcurve_has(p->curves[i]) & OC_FC_HEIGHT) != 0;
  }
  if (!strict)
    return oc_seterr(err, OC_EINVAL,
                     "'curves': no strict elevation anywhere (give some "
                     "constraint point a 'height')");
  if (p->scheme != OC_DIFFUSION_UPWIND && p->scheme != OC_DIFFUSION_PAPER)
    return oc_seterr(err, OC_EINVAL,
                     "'scheme' must be \"upwind\" or \"paper\"");
  if (!(p->tolerance >= 0 && p->tolerance < 1))
    return oc_seterr(err, OC_EINVAL,
                     "'converged' tolerance must be in (0, 1) (got %s)",
                     oc_numstr(p->tolerance, b));
  if (!(p->wavelength >= 0 && isfinite(p->wavelength)))
    return oc_seterr(err, OC_EINVAL, "'noise.wavelength' must be > 0 (got %s)",
                     oc_numstr(p->wavelength, b));
  if (p->octaves < 0 || p->octaves > 16)
    return oc_seterr(err, OC_EINVAL,
                     "'noise.octaves' must be in 1..16 (got %d)", p->octaves);
  if (!(p->ratio == 0 || (p->ratio > 1 && p->ratio <= 16)))
    return oc_seterr(err, OC_EINVAL,
                     "'noise.ratio' must be in (1, 16] (got %s)",
                     oc_numstr(p->ratio, b));
  return OC_OK;
}

static oc_heightfield *grid_of(const oc_diffusion_params *p, const float *z,
                               oc_error *err) {
  const oc_heightfield_grid *g = &p->grid;
  return oc_heightfield_new(g->nx, g->ny, g->cell, g->x0, g->y0, z, err);
}

/* The converged mode's state kept across the maps' solves: the coarse
** operators (built once for the three gradient maps, once for the
** elevation, once for amplitude and roughness, in the same memory) and
** the V-cycles' buffers. */
typedef struct conv {
  oc_dgalerkin gal;
  oc_dwork work;
} conv;

/* Frees c's operators and buffers (c then as new). */
static void conv_free(conv *c) {
  oc_dgalerkin_free(&c->gal);
  free(c->work.f);
  c->work = (oc_dwork){0};
}

/* With tolerance > 0 the coarse operators of (kind, mask) into c->gal. */
static int operators(conv *c, oc_dpyramid *py, const oc_diffusion_params *p,
                     oc_dkind kind, uint8_t mask, oc_error *err) {
  oc_dop hom = {kind, MAP_H, mask, p->scheme == OC_DIFFUSION_PAPER, 1};
  return p->tolerance > 0 ? oc_dgalerkin_build(&c->gal, py, &hom, err) : OC_OK;
}

static int solve(oc_dpyramid *py, const oc_diffusion_params *p, oc_dkind kind,
                 int map, uint8_t mask, conv *c, double lo, double span,
                 oc_diffusion_result *out, oc_error *err) {
  oc_dop op = {kind, map, mask, p->scheme == OC_DIFFUSION_PAPER, 0};
  oc_dsolve s = {p->progress, lo,   span,    p->tolerance,
                 NULL,        NULL, &c->gal, &c->work};
  if (kind == DK_GUIDED) {
    s.residual = out->residual;
    s.cycles = &out->cycles;
  }
  return oc_dsolve_map(py, &op, &s, err);
}

int oc_diffusion(const oc_diffusion_params *p, oc_diffusion_result *out,
                 oc_error *err) {
  if (!out) return oc_seterr(err, OC_EINVAL, "diffusion: no result");
  memset(out, 0, sizeof *out);
  int rc = check(p, err);
  if (rc) return rc;
  const oc_heightfield_grid *g = &p->grid;
  /* the output grid (zero) is the finest level's elevation: the noise
  ** detail is added to it in place at the end */
  out->height = grid_of(p, NULL, err);
  if (!out->height) return err ? err->code : OC_ENOMEM;
  oc_dpyramid py;
  conv cv = {{0}, {0}};
  rc = oc_dpyramid_init(&py, g->nx, g->ny, g->cell,
                        oc_heightfield_samples_mut(out->height), err);
  if (rc) {
    oc_diffusion_result_clear(out);
    return rc;
  }
  oc_draster_stats st;
  rc = oc_draster(&py, g->x0, g->y0, p->curves, p->ncurves, p->progress, 0.05,
                  &st, err);
  if (rc) goto done;
  out->strict = st.strict, out->slope = st.slope, out->conflict = st.conflict;
  out->levels = py.nlevels;
  if (!st.strict) {
    rc = oc_seterr(err, OC_EINVAL,
                   "'curves': no strict elevation inside the grid (the "
                   "curves with a 'height' lie outside it)");
    goto done;
  }
  if (p->progress.fn && p->progress.fn(p->progress.ud, 0.05)) {
    rc = oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
    goto done;
  }
  oc_dpyramid_grow(&py);
  oc_dpyramid_restrict(&py);
  /* the elevation reads the guide on slope samples (constrained: their
  ** values stay) and on conflicts: without conflicts nothing to fill */
  if (st.conflict) {
    static const int maps[3] = {MAP_GX, MAP_GY, MAP_GD};
    rc = operators(&cv, &py, p, DK_LAPLACE, DF_SLOPE, err);
    for (int q = 0; q < 3 && !rc; q++)
      rc = solve(&py, p, DK_LAPLACE, maps[q], DF_SLOPE, &cv, 0.05 + 0.1 * q,
                 0.1, out, err);
    if (rc) goto done;
  }
  /* n back to unit length after its diffusion (when there was one).
  ** Where the diffused n is shorter than COHERENT (directions that met
  ** from opposite sides and cancel: the sources and sinks of the filled
  ** field) it is dropped, so that the elevation follows Laplace there:
  ** the upwind equations of two samples each upwind of the other
  ** contradict each other and would stall the solver. Only on the finest
  ** grid: the coarse grids keep every direction, which their corrections
  ** need (measured: dropping there too stalls the V-cycles). */
  for (int k = 0; k < py.nlevels; k++)
    oc_dguide_prepare(&py.lv[k], p->scheme == OC_DIFFUSION_PAPER,
                      !st.conflict ? -1
                      : k          ? 1e-6
                                   : COHERENT);
  rc = operators(&cv, &py, p, DK_GUIDED, DF_H, err);
  if (!rc) rc = solve(&py, p, DK_GUIDED, MAP_H, DF_H, &cv, 0.35, 0.3, out, err);
  if (!rc && st.strict_noise)
    rc = operators(&cv, &py, p, DK_LAPLACE, DF_NOISE, err);
  if (!rc && st.strict_noise)
    rc = solve(&py, p, DK_LAPLACE, MAP_A, DF_NOISE, &cv, 0.65, 0.075, out, err);
  if (!rc && st.strict_noise)
    rc =
        solve(&py, p, DK_LAPLACE, MAP_R, DF_NOISE, &cv, 0.725, 0.075, out, err);
  conv_free(&cv);
  if (rc) goto done;
  oc_dpyramid_shrink(&py); /* the finest grid's maps are all that is left */
  const oc_dlevel *lv = &py.lv[0];
  oc_ddetail dd = {g->x0,
                   g->y0,
                   g->cell,
                   p->wavelength > 0 ? p->wavelength
                                     : fmax(g->nx, g->ny) * g->cell / 8,
                   p->ratio > 0 ? p->ratio : 2,
                   p->octaves ? p->octaves : 4,
                   p->seed};
  float *detail = NULL; /* (without strict noise A stayed 0) */
  if (p->maps) {
    out->smooth = grid_of(p, lv->map[MAP_H], err);
    out->amplitude = out->smooth ? grid_of(p, lv->map[MAP_A], err) : NULL;
    out->roughness = out->amplitude ? grid_of(p, lv->map[MAP_R], err) : NULL;
    out->gradient = out->roughness ? grid_of(p, lv->map[MAP_GD], err) : NULL;
    out->detail = out->gradient ? grid_of(p, NULL, err) : NULL;
    if (!out->detail) {
      rc = err ? err->code : OC_ENOMEM;
      goto done;
    }
    detail = oc_heightfield_samples_mut(out->detail);
  }
  rc = oc_ddetail_grid(&dd, lv, oc_heightfield_samples_mut(out->height), detail,
                       p->progress, 0.8, 0.2, err);
done:
  conv_free(&cv);
  oc_dpyramid_free(&py);
  if (rc) oc_diffusion_result_clear(out);
  return rc;
}

void oc_diffusion_result_clear(oc_diffusion_result *r) {
  if (!r) return;
  oc_heightfield *g[6] = {r->height,    r->smooth,    r->detail,
                          r->amplitude, r->roughness, r->gradient};
  for (int k = 0; k < 6; k++)
    oc_heightfield_release(g[k]);
  r->height = r->smooth = r->detail = r->amplitude = r->roughness =
      r->gradient = NULL;
}
