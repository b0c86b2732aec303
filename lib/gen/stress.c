/*
** stress.c — the shared step of shallow erosion (Paris et al. 2019, section
** 6.1):
** candidate columns by Poisson sampling, rays marched to the current
** surface, stress and resistance at the samples, and negative point
** primitives with energy -strength e(rho, sigma). See erode.h.
*/
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/checked.h"
#include "core/error.h"
#include "core/rng.h"
#include "gen/erode.h"

/* Candidates are processed in blocks: between blocks the calling thread
** reports progress, inside a block both cores march rays. A block holds at
** most BLOCK candidates and about BLOCK_EVALS field evaluations, so that
** long rays (a large footprint) still poll for cancellation often. */
#define BLOCK 4096
#define BLOCK_EVALS (1 << 22)
/* Bisection steps once a ray has entered the solid. */
#define BISECT 14

/* ---- candidate columns ------------------------------------------------- */

typedef struct keeper {
  int (*keep)(void *, double, double);
  void *ud;
} keeper;

static double keep_density(void *ud, double x, double y) {
  const keeper *k = ud;
  return k->keep(k->ud, x, y) ? 1.0 : 0.0;
}

/* Accepted columns hashed by their cell of side `spacing`, to drop the
** columns of later tiles too close to them. */
typedef struct colhash {
  int64_t *slot; /* column index, or -1 */
  size_t mask;
  double x0, y0, inv;
} colhash;

static size_t cell_hash(const colhash *H, int64_t ci, int64_t cj) {
  return (size_t)oc_hash2((uint64_t)ci, (uint64_t)cj) & H->mask;
}

static int too_close(const colhash *H, const double *xy, double x, double y,
                     double r2) {
  int64_t ci = (int64_t)floor((x - H->x0) * H->inv);
  int64_t cj = (int64_t)floor((y - H->y0) * H->inv);
  for (int64_t dj = -1; dj <= 1; dj++)
    for (int64_t di = -1; di <= 1; di++) {
      for (size_t h = cell_hash(H, ci + di, cj + dj); H->slot[h] >= 0;
           h = (h + 1) & H->mask) {
        const double *q = xy + 2 * H->slot[h];
        double dx = q[0] - x, dy = q[1] - y;
        if (dx * dx + dy * dy < r2) return 1;
      }
    }
  return 0;
}

static void hash_add(colhash *H, const double *xy, int64_t k) {
  int64_t ci = (int64_t)floor((xy[2 * k] - H->x0) * H->inv);
  int64_t cj = (int64_t)floor((xy[2 * k + 1] - H->y0) * H->inv);
  size_t h = cell_hash(H, ci, cj);
  while (H->slot[h] >= 0)
    h = (h + 1) & H->mask;
  H->slot[h] = k;
}

double *oc_erode_columns(const oc_heightfield *hf, const unsigned char *mask,
                         double spacing, uint64_t seed,
                         int (*keep)(void *, double, double), void *ud,
                         oc_progress pr, double at, size_t *n, oc_error *err) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double x0, y0, c = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  double w = c * (nx - 1), h = c * (ny - 1);
  double side = 16 * spacing > 4 * c ? 16 * spacing : 4 * c;
  /* A tile wider than the footprint is the footprint: a huge spacing must
  ** neither make the tile count 0 nor the tile boxes infinite. */
  double ext = (w > h ? w : h) + c;
  if (!(side <= ext)) side = ext;
  int tx, ty;
  size_t ntile;
  if (!oc_double_to_int(fmax(1, ceil(w / side)), 1, INT_MAX, &tx) ||
      !oc_double_to_int(fmax(1, ceil(h / side)), 1, INT_MAX, &ty) ||
      !oc_mul_size((size_t)tx, (size_t)ty, &ntile) || ntile > 100000000) {
    oc_seterr(err, OC_ENOMEM, "'spacing' %g is too small for the extent",
              spacing);
    return NULL;
  }
  unsigned char *act = calloc(ntile, 1);
  int *list = malloc(ntile * sizeof *list);
  oc_samples **got = calloc(ntile, sizeof *got);
  double *xy = NULL;
  colhash H = {NULL, 0, x0, y0, 1 / spacing};
  int nact = 0, failed = 0;
  oc_error ferr = {OC_OK, ""};
  if (!act || !list || !got) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %d x %d tiles", tx, ty);
    goto done;
  }
  /* A masked sample marks the tiles within one cell of it. */
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      if (!mask[(size_t)j * nx + i]) continue;
      for (int dj = -1; dj <= 1; dj += 2)
        for (int di = -1; di <= 1; di += 2) {
          int a = (int)floor((i + di) * c / side);
          int b = (int)floor((j + dj) * c / side);
          a = a < 0 ? 0 : a >= tx ? tx - 1 : a;
          b = b < 0 ? 0 : b >= ty ? ty - 1 : b;
          act[(size_t)b * tx + a] = 1;
        }
    }
  for (int t = 0; t < tx * ty; t++)
    if (act[t]) list[nact++] = t;
  /* The same bound as the sampler's, over all the tiles at once. */
  double q = side / spacing + 1; /* as a ratio: spacing^2 may overflow */
  double bound = nact * q * q / 0.785398;
  if (!(bound <= OC_POISSON_MAX)) {
    oc_seterr(err, OC_ENOMEM,
              "'spacing' %g is too small: up to %.3g columns could fit "
              "(at most %d million)",
              spacing, bound, OC_POISSON_MAX / 1000000);
    goto done;
  }
  keeper K = {keep, ud};
  int stop = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < nact; k++) {
    int t = list[k], a = t % tx, b = t / tx, halt;
#pragma omp atomic read
    halt = stop;
    if (halt) continue;
    oc_poisson_params pp;
    memset(&pp, 0, sizeof pp);
    double bx1 = x0 + (a + 1) * side, by1 = y0 + (b + 1) * side;
    pp.box = (oc_aabb){
        {x0 + a * side, y0 + b * side, 0},
        {bx1 < x0 + w ? bx1 : x0 + w, by1 < y0 + h ? by1 : y0 + h, 0}};
    pp.radius = spacing;
    pp.seed = oc_hash2(seed, (uint64_t)t);
    pp.density = keep_density;
    pp.density_ud = &K;
    oc_error e = {OC_OK, ""};
    got[t] = oc_poisson2d(&pp, &e);
    if (!got[t]) {
#pragma omp critical(oc_erode_columns)
      if (!failed++) ferr = e;
    }
    /* only the calling thread talks to the caller */
    if (pr.fn && omp_get_thread_num() == 0 && pr.fn(pr.ud, at)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (stop) {
    oc_seterr(err, OC_ECANCEL, "erosion cancelled");
    goto done;
  }
  if (failed) {
    oc_seterr(err, ferr.code, "%s", ferr.msg);
    goto done;
  }
  size_t total = 0, cap = 16;
  for (int k = 0; k < nact; k++)
    total += oc_samples_count(got[list[k]]);
  while (cap < 2 * total)
    cap *= 2;
  xy = malloc((total ? total : 1) * 2 * sizeof *xy);
  H.slot = malloc(cap * sizeof *H.slot);
  if (!xy || !H.slot) {
    free(xy);
    xy = NULL;
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu columns", total);
    goto done;
  }
  memset(H.slot, 0xff, cap * sizeof *H.slot);
  H.mask = cap - 1;
  size_t m = 0;
  for (int k = 0; k < nact; k++) {
    const oc_samples *s = got[list[k]];
    const double *p = oc_samples_data(s);
    for (size_t i = 0; i < oc_samples_count(s); i++) {
      if (too_close(&H, xy, p[2 * i], p[2 * i + 1], spacing * spacing))
        continue;
      xy[2 * m] = p[2 * i];
      xy[2 * m + 1] = p[2 * i + 1];
      hash_add(&H, xy, (int64_t)m);
      m++;
    }
  }
  *n = m;
done:
  if (got)
    for (int t = 0; t < tx * ty; t++)
      oc_samples_free(got[t]);
  free(got);
  free(act);
  free(list);
  free(H.slot);
  return xy;
}

/* ---- accessibility at a sample ----------------------------------------- */

/* Rays leave from 1.5 cells back along the candidate's ray, out of the
** rock: on a steep face the heightfield right at the sample stands at
** the cliff top and would block every ray. */
static double access_at(const oc_erode_params *ep, const oc_erode_cand *cd,
                        oc_vec3 s, uint64_t key) {
  const oc_heightfield *hf = ep->alpha;
  double c = oc_heightfield_cell(hf), x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  double x1 = x0 + c * (oc_heightfield_nx(hf) - 1);
  double y1 = y0 + c * (oc_heightfield_ny(hf) - 1);
  oc_rng r = oc_rng_stream(ep->seed ^ 0xacce55, key);
  double turn = 6.28318530717958648 * oc_rng_uniform(&r), dt = 0.5 * c;
  s.x -= 1.5 * c * cd->ux;
  s.y -= 1.5 * c * cd->uy;
  int open = 0, n = ep->rays;
  for (int k = 0; k < n; k++) {
    /* Fibonacci lattice, uniform in solid angle: cos theta uniform. */
    double cz = 1 - (k + 0.5) / n, sz = sqrt(1 - cz * cz);
    double phi = turn + k * 2.39996322972865332;
    double dx = sz * cos(phi), dy = sz * sin(phi);
    int blocked = 0;
    /* steps grow with the distance: far terrain blocks only when high */
    for (double t = dt; t <= ep->reach && !blocked;
         t += dt > 0.25 * t ? dt : 0.25 * t) {
      double x = s.x + t * dx, y = s.y + t * dy;
      /* a step that no longer moves the point ends the ray (tiny cells) */
      if (!(t > 0) || (x == s.x && y == s.y && t > dt)) break;
      if (x < x0 || x > x1 || y < y0 || y > y1) break;
      blocked = oc_heightfield_height(hf, x, y, NULL) > s.z + t * cz;
    }
    open += !blocked;
  }
  return (double)open / n;
}

/* ---- one ray --------------------------------------------------------- */

/* The first point of the ray a + t u, t in [0, len], where f > T, refined
** by bisection; 0 when the ray starts inside or never enters. */
static int march(const oc_program *prog, double T, oc_vec3 a, double ux,
                 double uy, double len, double step, oc_vec3 *s) {
  if (!(oc_program_eval(prog, a) <= T)) return 0;
  double t0 = 0;
  int nstep = (int)ceil(len / step);
  for (int k = 1; k <= nstep; k++) {
    double t1 = k == nstep ? len : k * step;
    oc_vec3 p = {a.x + t1 * ux, a.y + t1 * uy, a.z};
    if (oc_program_eval(prog, p) > T) {
      for (int b = 0; b < BISECT; b++) {
        double tm = 0.5 * (t0 + t1);
        oc_vec3 q = {a.x + tm * ux, a.y + tm * uy, a.z};
        if (oc_program_eval(prog, q) > T)
          t1 = tm;
        else
          t0 = tm;
      }
      *s = (oc_vec3){a.x + t1 * ux, a.y + t1 * uy, a.z};
      return 1;
    }
    t0 = t1;
  }
  return 0;
}

/* The sample of candidate i at `step` on the current tree, with its
** effect; e = NaN when the ray finds no surface. */
static void sample_one(const oc_erode_params *ep, const oc_program *tree,
                       const oc_program *geo, const oc_erode_cand *c, size_t i,
                       int step, oc_vec3 *s, double *e, double *alpha) {
  oc_rng r = oc_rng_stream(ep->seed, oc_hash2((uint64_t)step, i));
  double z = c->zlo < c->zhi ? oc_rng_range(&r, c->zlo, c->zhi) : c->zlo;
  *e = NAN;
  if (c->ux == 0 && c->uy == 0) {
    *s = (oc_vec3){c->x, c->y, z};
  } else {
    double back = fmin(c->back, ep->span), fwd = fmin(c->fwd, ep->span);
    oc_vec3 a = {c->x - back * c->ux, c->y - back * c->uy, z};
    if (!march(tree, ep->threshold, a, c->ux, c->uy, back + fwd, ep->step, s))
      return;
  }
  double sigma = c->stress;
  if (ep->range > 0)
    sigma *= oc_erode_falloff(fabs(s->z - ep->sea_level) / ep->range);
  /* The column's exposure, measured where its ray first met the coast and
  ** kept: from inside a cave the heightfield would see only the cliff
  ** above and stop the cave from deepening. */
  if (ep->alpha) {
    if (isnan(*alpha)) *alpha = access_at(ep, c, *s, i);
    sigma *= *alpha;
  }
  sigma = sigma < 0 ? 0 : sigma > 1 ? 1 : sigma;
  double rho = ep->rho;
  if (geo) rho = oc_program_eval(geo, *s);
  rho = rho < 0 ? 0 : rho > 1 ? 1 : rho;
  if (isnan(rho)) rho = 1;
  *e = oc_erode_effect(rho, sigma, ep->beta);
}

/* ---- the steps ----------------------------------------------------------- */

typedef struct prims {
  oc_node **v; /* v[0] is the base */
  size_t n, cap;
} prims;

static void prims_free(prims *P) {
  for (size_t k = 0; k < P->n; k++)
    oc_node_release(P->v[k]);
  free(P->v);
}

static int prims_push(prims *P, oc_node *nd, oc_error *err) {
  if (P->n == P->cap) {
    size_t cap = P->cap ? 2 * P->cap : 1024;
    oc_node **v = realloc(P->v, cap * sizeof *v);
    if (!v) return oc_seterr(err, OC_ENOMEM, "out of memory for primitives");
    P->v = v;
    P->cap = cap;
  }
  P->v[P->n++] = nd;
  return OC_OK;
}

oc_node *oc_erode_run(const oc_erode_params *ep, const oc_erode_cand *cand,
                      size_t n, oc_gen_sea_stats *st, oc_error *err) {
  /* each column makes at most one primitive per step */
  double most = (double)n * ep->steps;
  if (most > OC_ERODE_MAX_PRIMITIVES) {
    oc_seterr(err, OC_ENOMEM,
              "%zu columns over %d 'steps' could make %.3g primitives (at "
              "most %d million): use a larger 'spacing' or fewer 'steps'",
              n, ep->steps, most, OC_ERODE_MAX_PRIMITIVES / 1000000);
    return NULL;
  }
  prims P = {NULL, 0, 0};
  oc_program *geo = NULL, *tree = NULL;
  oc_node *out = NULL;
  oc_vec3 *s = malloc((n ? n : 1) * sizeof *s);
  double *e = malloc((n ? n : 1) * sizeof *e);
  double *alpha = malloc((n ? n : 1) * sizeof *alpha);
  size_t found = 0;
  oc_compile_options co = {ep->threshold, 0};
  if (!s || !e || !alpha) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu samples", n);
    goto done;
  }
  for (size_t i = 0; i < n; i++)
    alpha[i] = NAN;
  oc_node_retain(ep->base);
  if (prims_push(&P, ep->base, err)) {
    oc_node_release(ep->base);
    goto done;
  }
  if (ep->geology && !(geo = oc_compile(ep->geology, NULL, err))) goto done;
  /* evaluations per candidate, at most: the ray both ways, bisection */
  double evals = 2 * ep->span / ep->step + BISECT + 2;
  size_t block = BLOCK;
  if (evals * BLOCK > BLOCK_EVALS)
    block = evals * 16 > BLOCK_EVALS ? 16 : (size_t)(BLOCK_EVALS / evals);
  for (int step = 0; step < ep->steps; step++) {
    oc_node *cur = oc_blend(P.v, P.n, err);
    if (!cur) goto done;
    tree = oc_compile(cur, &co, err);
    oc_node_release(cur);
    if (!tree) goto done;
    for (size_t b0 = 0; b0 < n; b0 += block) {
      long long b1 = (long long)(b0 + block < n ? b0 + block : n);
#pragma omp parallel for schedule(dynamic, 64)
      for (long long i = (long long)b0; i < b1; i++)
        sample_one(ep, tree, geo, &cand[i], (size_t)i, step, &s[i], &e[i],
                   &alpha[i]);
      double f = (step + (double)b1 / (double)n) / ep->steps;
      if (ep->progress.fn &&
          ep->progress.fn(ep->progress.ud, ep->pbase + ep->pspan * f)) {
        oc_seterr(err, OC_ECANCEL, "erosion cancelled");
        goto done;
      }
    }
    oc_program_free(tree);
    tree = NULL;
    for (size_t i = 0; i < n; i++) {
      if (isnan(e[i])) continue;
      found++;
      if (e[i] < ep->cutoff || e[i] <= 0) continue;
      oc_node *pt = oc_point(s[i], ep->radius, -ep->strength * e[i], err);
      if (!pt) goto done;
      if (prims_push(&P, pt, err)) {
        oc_node_release(pt);
        goto done;
      }
    }
  }
  if (ep->omit_base && P.n == 1)
    oc_seterr(err, OC_EINVAL,
              "nothing was carved (no sample reached 'cutoff'), and "
              "without the terrain there is nothing to return");
  else if (ep->omit_base)
    out = oc_blend(P.v + 1, P.n - 1, err);
  else
    out = oc_blend(P.v, P.n, err);
  if (out && st) {
    st->columns = n;
    st->samples = found;
    st->primitives = P.n - 1;
  }
done:
  oc_program_free(tree);
  oc_program_free(geo);
  prims_free(&P);
  free(s);
  free(e);
  free(alpha);
  return out;
}

/* ---- shared set-up ------------------------------------------------------- */

oc_node *oc_erode_base(oc_heightfield *hf, oc_node *terrain, oc_error *err) {
  if (terrain) {
    oc_node_retain(terrain);
    return terrain;
  }
  return oc_heightfield_terrain(hf, NULL, err);
}

void oc_gen_erode_defaults(oc_gen_erode_params *e) {
  memset(e, 0, sizeof *e);
  e->beta = 0.2;
  e->cutoff = 0.05;
}

void oc_erode_shared(oc_erode_params *ep, oc_node *base,
                     const oc_heightfield *hf, const oc_gen_erode_params *c) {
  memset(ep, 0, sizeof *ep);
  ep->base = base;
  ep->omit_base = c->no_terrain;
  ep->geology = c->geology;
  ep->rho = 0.5;
  ep->threshold = c->threshold > 0 ? c->threshold : OC_DEFAULT_THRESHOLD;
  ep->radius = c->radius;
  ep->strength = c->strength;
  ep->beta = c->beta;
  ep->cutoff = c->cutoff;
  double cell = oc_heightfield_cell(hf);
  ep->step = fmax(0.5 * fmin(cell, c->radius), cell / 32);
  ep->span = cell * (hypot(oc_heightfield_nx(hf), oc_heightfield_ny(hf)) + 1);
  ep->steps = c->steps;
  ep->seed = c->seed;
  ep->progress = c->progress;
}

int oc_erode_check(const oc_gen_erode_params *c, oc_error *err) {
  double radius = c->radius, spacing = c->spacing, beta = c->beta;
  double strength = c->strength, cutoff = c->cutoff, threshold = c->threshold;
  int steps = c->steps;
  char b[OC_NUMSTR];
  if (!(radius > 0 && isfinite(radius)))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %s)",
                     oc_numstr(radius, b));
  if (!(spacing > 0 && isfinite(spacing)))
    return oc_seterr(err, OC_EINVAL, "'spacing' must be > 0 (got %s)",
                     oc_numstr(spacing, b));
  if (!(beta >= 0 && beta <= 1))
    return oc_seterr(err, OC_EINVAL, "'beta' must be in [0, 1] (got %s)",
                     oc_numstr(beta, b));
  if (!(strength > 0 && isfinite(strength)))
    return oc_seterr(err, OC_EINVAL, "'strength' must be > 0 (got %s)",
                     oc_numstr(strength, b));
  if (!(cutoff >= 0 && isfinite(cutoff)))
    return oc_seterr(err, OC_EINVAL, "'cutoff' must be >= 0 (got %s)",
                     oc_numstr(cutoff, b));
  if (steps < 1 || steps > 64)
    return oc_seterr(err, OC_EINVAL, "'steps' must be in 1..64 (got %d)",
                     steps);
  if (!(threshold >= 0 && isfinite(threshold)))
    return oc_seterr(err, OC_EINVAL, "'threshold' must be > 0 (got %s)",
                     oc_numstr(threshold, b));
  return OC_OK;
}
