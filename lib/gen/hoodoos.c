/*
** hoodoos.c — the hoodoo generator (Paris et al. 2019, section 6.3): placement
** probability from slope, drainage and a mask, Poisson disk axioms, one
** grammar derivation per axiom (gen/grammar.c) on both cores, and the
** symbols' solids blended with the terrain.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "gen/hoodoos.h"

#define PI 3.14159265358979323846
#define CHUNK 1024 /* axioms derived between two progress reports */

void oc_gen_hoodoos_defaults(oc_gen_hoodoos_params *p, oc_heightfield *hf) {
  double c = hf ? oc_heightfield_cell(hf) : 1;
  memset(p, 0, sizeof *p);
  p->heightfield = hf;
  p->radius = 5 * c;
  p->height_lo = 4 * c;
  p->height_hi = 10 * c;
  p->width = 0.3 * p->radius;
  p->margin = 4 * c;
  p->max_depth = 6;
  p->p_block = 0.5;
  p->p_cone = 0.5;
  p->shrink = 0.85;
  p->tilt = 0.1;
  p->roughness = 0.3;
  p->probability = 1;
  p->slope = 0.6;
  p->slope_spread = 0.4;
  p->drainage = 20 * c * c;
}

static int in01(double v) {
  return v >= 0 && v <= 1;
}

static int check(const oc_gen_hoodoos_params *p, oc_error *err) {
  if (p->heightfield == NULL)
    return oc_seterr(err, OC_EINVAL, "'heightfield' is required");
  if (!(p->radius > 0 && isfinite(p->radius)))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)",
                     p->radius);
  if (!(p->height_lo > 0 && p->height_lo <= p->height_hi &&
        isfinite(p->height_hi)))
    return oc_seterr(err, OC_EINVAL,
                     "'height' must be {lo, hi} with 0 < lo <= hi (got {%g, "
                     "%g})",
                     p->height_lo, p->height_hi);
  if (!(p->width > 0 && isfinite(p->width)))
    return oc_seterr(err, OC_EINVAL, "'width' must be > 0 (got %g)", p->width);
  /* Symbols beyond the footprint's size (or, shrunk, below a millionth of
  ** it) only make transforms that cannot be inverted in double. */
  const oc_heightfield *hf = p->heightfield;
  double ext = oc_heightfield_cell(hf) *
               fmax(oc_heightfield_nx(hf), oc_heightfield_ny(hf));
  if (!(p->width >= 1e-6 * ext && p->width <= ext))
    return oc_seterr(err, OC_EINVAL,
                     "'width' must be in [%g, %g] (a millionth of the "
                     "heightfield's width, to its width; got %g)",
                     1e-6 * ext, ext, p->width);
  if (!(p->height_lo >= 1e-6 * ext && p->height_hi <= 100 * ext))
    return oc_seterr(err, OC_EINVAL,
                     "'height' must be in [%g, %g] (a millionth of the "
                     "heightfield's width, to 100 times it; got {%g, %g})",
                     1e-6 * ext, 100 * ext, p->height_lo, p->height_hi);
  if (!(p->margin >= 0 && isfinite(p->margin)))
    return oc_seterr(err, OC_EINVAL, "'margin' must be >= 0 (got %g)",
                     p->margin);
  if (p->max_depth < 2 || p->max_depth > OC_HOODOO_MAX_DEPTH)
    return oc_seterr(err, OC_EINVAL, "'max_depth' must be in 2..%d (got %d)",
                     OC_HOODOO_MAX_DEPTH, p->max_depth);
  if (!in01(p->p_block))
    return oc_seterr(err, OC_EINVAL, "'p_block' must be in [0, 1] (got %g)",
                     p->p_block);
  if (!in01(p->p_cone))
    return oc_seterr(err, OC_EINVAL, "'p_cone' must be in [0, 1] (got %g)",
                     p->p_cone);
  if (!(p->shrink >= 0.1 && p->shrink <= 1))
    return oc_seterr(err, OC_EINVAL, "'shrink' must be in [0.1, 1] (got %g)",
                     p->shrink);
  if (!(p->tilt >= 0 && p->tilt <= 0.5))
    return oc_seterr(err, OC_EINVAL,
                     "'tilt' must be in [0, 0.5] radians (got %g)", p->tilt);
  if (!in01(p->roughness))
    return oc_seterr(err, OC_EINVAL, "'roughness' must be in [0, 1] (got %g)",
                     p->roughness);
  if (!in01(p->probability))
    return oc_seterr(err, OC_EINVAL, "'probability' must be in [0, 1] (got %g)",
                     p->probability);
  if (!(p->slope >= 0 && isfinite(p->slope)))
    return oc_seterr(err, OC_EINVAL, "'slope' must be >= 0 (got %g)", p->slope);
  if (!(p->slope_spread > 0 && isfinite(p->slope_spread)))
    return oc_seterr(err, OC_EINVAL, "'slope_spread' must be > 0 (got %g)",
                     p->slope_spread);
  if (!(p->drainage > 0 && isfinite(p->drainage)))
    return oc_seterr(err, OC_EINVAL, "'drainage' must be > 0 (got %g)",
                     p->drainage);
  if (!(p->threshold >= 0 && isfinite(p->threshold)))
    return oc_seterr(err, OC_EINVAL, "'threshold' must be > 0 (got %g)",
                     p->threshold);
  return OC_OK;
}

/* ---- placement ----------------------------------------------------------- */

typedef struct placement {
  const oc_gen_hoodoos_params *p;
  oc_heightfield *slope, *drainage;
  int bad_mask;  /* the mask function returned something out of range */
  double got;    /* what it returned */
  double gx, gy; /* where */
} placement;

static double clamp01(double v) {
  return v < 0 ? 0 : v > 1 ? 1 : v;
}

static double probability(void *ud, double x, double y) {
  placement *P = ud;
  const oc_gen_hoodoos_params *p = P->p;
  double m = 1;
  if (p->mask) m = clamp01(oc_heightfield_height(p->mask, x, y, NULL));
  if (p->mask_fn && m > 0) {
    double v = p->mask_fn(p->mask_ud, x, y);
    if (!in01(v)) {
      P->bad_mask = 1;
      P->got = v;
      P->gx = x;
      P->gy = y;
      return NAN;
    }
    m *= v;
  }
  if (m <= 0) return 0;
  double s = oc_heightfield_height(P->slope, x, y, NULL);
  double a = oc_heightfield_height(P->drainage, x, y, NULL);
  double ws = (s - p->slope) / p->slope_spread;
  double v = p->probability * exp(-ws * ws) / (1 + fmax(a, 0) / p->drainage);
  return clamp01(v * m);
}

/* Scales oc_progress into [base, base + span] of the caller's. */
typedef struct phase {
  oc_progress to;
  double base, span;
} phase;

static int phase_fn(void *ud, double f) {
  const phase *ph = ud;
  return ph->to.fn(ph->to.ud, ph->base + ph->span * f);
}

static oc_progress sub(phase *ph, oc_progress to, double base, double span) {
  ph->to = to;
  ph->base = base;
  ph->span = span;
  oc_progress r = {to.fn ? phase_fn : NULL, ph};
  return r;
}

static oc_samples *place(const oc_gen_hoodoos_params *p, oc_error *err) {
  oc_heightfield *hf = p->heightfield;
  double c = oc_heightfield_cell(hf), x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  double x1 = x0 + c * (oc_heightfield_nx(hf) - 1);
  double y1 = y0 + c * (oc_heightfield_ny(hf) - 1);
  oc_poisson_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box.lo = (oc_vec3){x0 + p->margin, y0 + p->margin, 0};
  pp.box.hi = (oc_vec3){x1 - p->margin, y1 - p->margin, 0};
  if (!(pp.box.lo.x < pp.box.hi.x && pp.box.lo.y < pp.box.hi.y)) {
    oc_seterr(err, OC_EINVAL,
              "'margin' %g leaves no room on the heightfield (%g x %g)",
              p->margin, x1 - x0, y1 - y0);
    return NULL;
  }
  placement P = {p, NULL, NULL, 0, 0, 0, 0};
  phase ph;
  oc_heightfield_flow_params fp = {0};
  fp.progress = sub(&ph, p->progress, 0.05, 0.35);
  P.slope = oc_heightfield_slope(hf, err);
  if (P.slope) P.drainage = oc_heightfield_drainage(hf, &fp, err);
  oc_samples *s = NULL;
  if (P.drainage) {
    pp.radius = p->radius;
    pp.seed = p->seed;
    pp.density = probability;
    pp.density_ud = &P;
    phase ph2;
    pp.progress = sub(&ph2, p->progress, 0.4, 0.3);
    s = oc_poisson2d(&pp, err);
    if (s == NULL && P.bad_mask)
      oc_seterr(err, OC_EINVAL,
                "'mask' must give a number in [0, 1] (got %g at x = %g, "
                "y = %g)",
                P.got, P.gx, P.gy);
  }
  oc_heightfield_release(P.slope);
  oc_heightfield_release(P.drainage);
  return s;
}

/* ---- derivation ---------------------------------------------------------- */

/* Size of the first symbol for a full derivation rising `rise`. */
static double first_size(double rise, double shrink, int depth) {
  if (shrink >= 1) return rise / depth;
  return rise * (1 - shrink) / (1 - pow(shrink, depth));
}

static void derive_one(const oc_gen_hoodoos_params *p,
                       const oc_hoodoo_grammar *g, const double *xy, uint32_t i,
                       oc_hoodoo_symbol *out, int *count) {
  oc_rng rng = oc_rng_stream(oc_hash2(p->seed, 0x686f6f646f6fULL), i);
  double grad[2];
  double z = oc_heightfield_height(p->heightfield, xy[0], xy[1], grad);
  double H = oc_rng_range(&rng, p->height_lo, p->height_hi);
  double s0 = first_size(H, p->shrink, p->max_depth);
  /* Sunk so that the base's footprint is under the ground even downhill,
  ** but never by more than half the base symbol: its top stays out. */
  double depth = 0.15 * H + hypot(grad[0], grad[1]) * 1.5 * p->width;
  if (depth > 0.5 * s0) depth = 0.5 * s0;
  double s = first_size(H + depth, p->shrink, p->max_depth);
  oc_vec3 base = {xy[0], xy[1], z - depth};
  *count = oc_hoodoo_derive(g, base, s, i, &rng, out);
}

int oc_hoodoo_symbols(const oc_gen_hoodoos_params *p, oc_hoodoo_symbol **out,
                      size_t *n, oc_gen_hoodoos_stats *st, oc_error *err) {
  double t0 = omp_get_wtime();
  *out = NULL;
  *n = 0;
  if (st) memset(st, 0, sizeof *st);
  int rc = check(p, err);
  if (rc) return rc;
  oc_program *geo = NULL;
  if (p->geology) {
    geo = oc_compile(p->geology, NULL, err);
    if (!geo) return err ? err->code : OC_EINVAL;
  }
  oc_samples *ax = place(p, err);
  if (!ax) {
    oc_program_free(geo);
    return err ? err->code : OC_EINVAL;
  }
  size_t na = oc_samples_count(ax), D = (size_t)p->max_depth;
  const double *xy = oc_samples_data(ax);
  oc_hoodoo_symbol *sym = NULL;
  int *cnt = NULL;
  if (na > OC_HOODOO_MAX_SYMBOLS / D) {
    rc = oc_seterr(err, OC_ENOMEM,
                   "%zu hoodoos of up to %zu symbols exceed %d symbols: "
                   "raise 'radius' or lower 'max_depth'",
                   na, D, OC_HOODOO_MAX_SYMBOLS);
    goto done;
  }
  if (na > 0) {
    sym = malloc(na * D * sizeof *sym);
    cnt = malloc(na * sizeof *cnt);
    if (!sym || !cnt) {
      rc = oc_seterr(err, OC_ENOMEM, "out of memory for %zu hoodoos", na);
      goto done;
    }
  }
  oc_hoodoo_grammar g = {p->max_depth, p->p_block, p->p_cone, p->shrink,
                         p->width,     p->tilt,    geo};
  for (size_t b = 0; b < na; b += CHUNK) {
    long e = (long)(b + CHUNK < na ? b + CHUNK : na);
#pragma omp parallel for schedule(dynamic, 16)
    for (long i = (long)b; i < e; i++)
      derive_one(p, &g, xy + 2 * i, (uint32_t)i, sym + (size_t)i * D, &cnt[i]);
    if (p->progress.fn &&
        p->progress.fn(p->progress.ud, 0.7 + 0.3 * (double)e / (double)na)) {
      rc = oc_seterr(err, OC_ECANCEL, "hoodoo generation cancelled");
      goto done;
    }
  }
  size_t m = 0;
  for (size_t i = 0; i < na; i++) {
    memmove(sym + m, sym + i * D, (size_t)cnt[i] * sizeof *sym);
    m += (size_t)cnt[i];
  }
  if (st) {
    st->hoodoos = na;
    st->primitives = m;
    for (size_t k = 0; k < m; k++) {
      st->blocks += sym[k].kind == OC_HOODOO_BLOCK;
      st->cones += sym[k].kind == OC_HOODOO_CONE;
      st->boxes += sym[k].kind == OC_HOODOO_BOX;
    }
  }
  if (m == 0) {
    free(sym);
    sym = NULL;
  } else {
    oc_hoodoo_symbol *shrunk = realloc(sym, m * sizeof *sym);
    if (shrunk) sym = shrunk;
  }
  *out = sym;
  *n = m;
  sym = NULL;
done:
  free(sym);
  free(cnt);
  oc_samples_free(ax);
  oc_program_free(geo);
  if (st) st->seconds = omp_get_wtime() - t0;
  return rc;
}

/* ---- solids -------------------------------------------------------------- */

/* M = translate(base) rotate(tilt about a horizontal axis) rotate(turn
** about z) scale(sx, sy, sz), 3 x 4 row-major. */
static void frame(const oc_hoodoo_symbol *s, double sx, double sy, double sz,
                  double m[12]) {
  double ct = cos(s->turn), st = sin(s->turn);
  double ux = cos(s->tilt_dir), uy = sin(s->tilt_dir);
  double c = cos(s->tilt), sn = sin(s->tilt), k = 1 - c;
  /* Rodrigues for the unit axis (ux, uy, 0) */
  double R[3][3] = {{c + ux * ux * k, ux * uy * k, uy * sn},
                    {ux * uy * k, c + uy * uy * k, -ux * sn},
                    {-uy * sn, ux * sn, c}};
  double Z[3][3] = {{ct, -st, 0}, {st, ct, 0}, {0, 0, 1}};
  double S[3] = {sx, sy, sz};
  const double t[3] = {s->base.x, s->base.y, s->base.z};
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) {
      double v = 0;
      for (int l = 0; l < 3; l++)
        v += R[i][l] * Z[l][j];
      m[4 * i + j] = v * S[j];
    }
    m[4 * i + 3] = t[i];
  }
}

/* Each solid is built in a unit frame, its surface (energy 2T, so where
** g = 1/2, at 0.4542 falloffs from the solid) at distance about 1, then
** scaled to the symbol. */
oc_node *oc_hoodoo_symbol_node(const oc_hoodoo_symbol *s, double roughness,
                               double threshold, oc_error *err) {
  double E = 2 * (threshold > 0 ? threshold : OC_DEFAULT_THRESHOLD);
  double w = s->width, a = s->aspect, R;
  oc_node *prim;
  double m[12];
  switch (s->kind) {
  case OC_HOODOO_BLOCK:
    R = 0.6;
    prim = oc_sphere((oc_vec3){0, 0, 1}, 1 - 0.4542 * R, R, E, err);
    frame(s, w * a, w / a, 0.5 * s->size, m);
    break;
  case OC_HOODOO_CONE:
    R = 0.3;
    prim = oc_cone((oc_vec3){0, 0, 0}, (oc_vec3){0, 0, 1}, 1, R, E, err);
    frame(s, w * a, w / a, s->size, m);
    break;
  case OC_HOODOO_BOX:
    R = 0.3;
    prim = oc_box((oc_vec3){-1, -1, 0}, (oc_vec3){1, 1, 1}, R, E, err);
    frame(s, 1.3 * w * a, 1.3 * w / a, 0.3 * s->size, m);
    break;
  default:
    oc_seterr(err, OC_EINVAL, "unknown hoodoo symbol '%c'", s->kind);
    return NULL;
  }
  if (!prim) return NULL;
  if (roughness > 0) {
    oc_noise nz = {0.7, roughness * R, 0, 3, s->noise};
    oc_node *q = oc_perturb(prim, &nz, err);
    oc_node_release(prim);
    if (!q) return NULL;
    prim = q;
  }
  oc_node *x = oc_transform(prim, m, err);
  oc_node_release(prim);
  return x;
}

oc_node *oc_generate_hoodoos(const oc_gen_hoodoos_params *p,
                             oc_gen_hoodoos_stats *st, oc_error *err) {
  oc_hoodoo_symbol *sym;
  size_t n;
  oc_gen_hoodoos_stats local;
  if (!st) st = &local;
  if (oc_hoodoo_symbols(p, &sym, &n, st, err)) return NULL;
  double t0 = omp_get_wtime();
  /* the default terrain, the one outcrop.generate.hoodoos blends with */
  oc_node *terrain = p->terrain, *own = NULL;
  if (!terrain && !p->no_terrain &&
      !(terrain = own = oc_heightfield_terrain(p->heightfield, NULL, err))) {
    free(sym);
    return NULL;
  }
  size_t nk = n + (terrain != NULL), k = 0;
  if (nk == 0) {
    oc_seterr(err, OC_EINVAL,
              "no hoodoo was placed and no 'terrain' was given (raise "
              "'probability', or check 'mask')");
    free(sym);
    return NULL;
  }
  oc_node **kids = malloc(nk * sizeof *kids);
  oc_node *r = NULL;
  if (!kids) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu hoodoo symbols", n);
    free(sym);
    oc_node_release(own);
    return NULL;
  }
  if (terrain) {
    oc_node_retain(terrain);
    kids[k++] = terrain;
  }
  for (size_t i = 0; i < n; i++) {
    oc_node *x =
        oc_hoodoo_symbol_node(&sym[i], p->roughness, p->threshold, err);
    if (!x) goto done;
    kids[k++] = x;
  }
  r = oc_blend(kids, k, err);
done:
  for (size_t i = 0; i < k; i++)
    oc_node_release(kids[i]);
  free(kids);
  free(sym);
  oc_node_release(own);
  st->seconds += omp_get_wtime() - t0;
  return r;
}
