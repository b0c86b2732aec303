/*
** poisson.c — oc_poisson2d and oc_poisson3d: checks the request, lays out
** the grid, runs the phases over the tiles in parallel, then collects
** (and in 2D thins) the samples in cell order.
**
** Phases: a few rounds of dart throwing, each visiting the 2^d parity
** classes of tiles in turn, so that all tiles fill at the same pace (as
** one dart thrower over the whole box would) and no tile border shows;
** then one gap-filling pass per class, which leaves the tiles maximal. A
** tile's work depends on its random stream, keyed by (seed, tile, round),
** and on the samples within reach, which no other tile of its class can
** change: the result is the same to the bit for any thread count.
*/
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/checked.h"
#include "core/error.h"
#include "gen/poisson.h"

/* Rounds of darts before gap filling, and darts per cell in each. */
#define DART_ROUNDS 3
#define DARTS_PER_CELL 0.7
#define PI 3.14159265358979323846
#define TILE_2D 16
#define TILE_3D 8
/* Samples the exact coverage test takes on (pcover.c), and how many times
** it may split a box that more samples matter to. Its cost grows as the
** 3rd power of the samples in 2D, the 4th in 3D, where splitting (or
** leaving the box to the next level) is cheaper. */
#define COVER_MAX_2D 8
#define COVER_MAX_3D 2
#define COVER_DEPTH 2
/* Sides of the box below this fraction of a cell are refused. */
#define THIN 1e-3
/* Key of the thinning stream, distinct from any tile's. */
#define THIN_KEY 0x7468696e6e696e67ull

struct oc_samples {
  int dim;
  size_t n;
  double *xyz;
};

/* Upper bound on the count: disks of radius r/2 around the samples are
** disjoint and lie in the box grown by r/2. */
static double count_bound(int d, const double *len, double r) {
  double v = 1;
  for (int a = 0; a < d; a++)
    v *= (len[a] + r) / r;
  return d == 2 ? v / (PI / 4) : v / (PI / 6);
}

/* Periodic mode: a square or cube of side len split into n cells of side
** h = len / n <= r / sqrt(d) exactly, n a multiple of two tiles (or at
** most one tile), so parity classes stay apart across the wrap. */
static int periodic_cells(oc_pgrid *g, int d, const double *len,
                          oc_error *err) {
  for (int a = 1; a < d; a++)
    if (len[a] != len[0])
      return oc_seterr(err, OC_EINVAL,
                       "'box' must be a %s when periodic (sides %g %g %g)",
                       d == 2 ? "square" : "cube", len[0], len[1], len[2]);
  if (!(len[0] > 2 * g->r))
    return oc_seterr(err, OC_EINVAL,
                     "'radius' %g must be less than half the side %g of a "
                     "periodic box",
                     g->r, len[0]);
  double n = ceil(len[0] / g->h);
  for (;; n++) {
    if (n > g->tile) n = ceil(n / (2 * g->tile)) * (2 * g->tile);
    double h = len[0] / n;
    if (h * h * d <= g->r2) {
      g->h = h;
      break;
    }
  }
  g->periodic = 1;
  g->len = len[0];
  return 0;
}

static ptrdiff_t offset(const oc_pgrid *g, int x, int y, int z) {
  return (ptrdiff_t)g->d *
         (((ptrdiff_t)z * g->n[1] + (ptrdiff_t)y) * g->n[0] + (ptrdiff_t)x);
}

/* Lists the offsets within reach by their least gap (in cells), nearest
** first (equal gaps keep their order), and in their order. */
static void near_order(oc_pgrid *g) {
  g->nreach = 0;
  for (int z = 0; z < OC_PREACH; z++)
    for (int y = 0; y < OC_PREACH; y++)
      for (int x = 0; x < OC_PREACH; x++)
        if (g->reach[z][y][x])
          g->reachoff[g->nreach++] = offset(g, x - 2, y - 2, z - 2);
  g->nnear = 0;
  for (int gap = 0; gap <= 3 * 2 * 2; gap++)
    for (int z = 0; z < OC_PREACH; z++)
      for (int y = 0; y < OC_PREACH; y++)
        for (int x = 0; x < OC_PREACH; x++) {
          int o[3] = {x - 2, y - 2, z - 2}, q = 0;
          for (int a = 0; a < 3; a++) {
            int gp = abs(o[a]) > 1 ? abs(o[a]) - 1 : 0;
            q += gp * gp;
          }
          if (q != gap || !g->reach[z][y][x]) continue;
          for (int a = 0; a < 3; a++)
            g->near[g->nnear][a] = (signed char)o[a];
          g->nearoff[g->nnear++] = offset(g, o[0], o[1], o[2]);
        }
}

static int setup(const oc_poisson_params *pp, int d, oc_pgrid *g,
                 oc_error *err) {
  const char *fname = d == 2 ? "poisson2d" : "poisson3d";
  if (!pp) return oc_seterr(err, OC_EINVAL, "%s needs params", fname);
  const double lo[3] = {pp->box.lo.x, pp->box.lo.y, d == 3 ? pp->box.lo.z : 0};
  const double hi[3] = {pp->box.hi.x, pp->box.hi.y, d == 3 ? pp->box.hi.z : 0};
  double len[3] = {0, 0, 0}, big = 0, r = pp->radius;
  for (int a = 0; a < d; a++) {
    len[a] = hi[a] - lo[a];
    if (!isfinite(lo[a]) || !isfinite(hi[a]) || !(lo[a] < hi[a]) ||
        !isfinite(len[a]))
      return d == 2 ? oc_seterr(err, OC_EINVAL,
                                "'box' must be finite with x0 < x1 and y0 < "
                                "y1 (got %g %g %g %g)",
                                lo[0], lo[1], hi[0], hi[1])
                    : oc_seterr(err, OC_EINVAL,
                                "'box' must be finite with x0 < x1, y0 < y1 "
                                "and z0 < z1 (got %g %g %g %g %g %g)",
                                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    big = fmax(big, fmax(fabs(lo[a]), fabs(hi[a])));
  }
  if (!(r > 0) || !isfinite(r))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)", r);
  if (r < 1e-9 * big)
    return oc_seterr(err, OC_EINVAL,
                     "'radius' %g is too small for 'box' coordinates up to %g "
                     "(double precision; move the box nearer the origin)",
                     r, big);
  double bound = count_bound(d, len, r);
  if (!(bound <= OC_POISSON_MAX))
    return oc_seterr(err, OC_ENOMEM,
                     "'radius' %g is too small for the box: up to %.3g "
                     "samples could fit (at most %d million; a maximal set "
                     "holds about %s of that bound)",
                     r, bound, OC_POISSON_MAX / 1000000,
                     d == 2 ? "55 %" : "38 %");
  if (pp->density && d != 2)
    return oc_seterr(err, OC_EINVAL, "'density' is for 2D sampling only");
  memset(g, 0, sizeof *g);
  g->d = d;
  g->r = r;
  g->r2 = r * r;
  g->h = r / sqrt((double)d);
  while (g->h * g->h * d > g->r2)
    g->h = nextafter(g->h, 0);
  /* A box within one cell is that cell: darts thrown at a cell far larger
  ** than the box (radius 1e308) would never land in it. */
  double longest = fmax(len[0], fmax(len[1], len[2]));
  if (g->h > longest) g->h = longest;
  /* Gap filling splits the boxes of a cell until they are as thin as the
  ** box: 2^(d-1) more at each level, too many below THIN of a cell. */
  for (int a = 0; a < d; a++)
    if (len[a] < THIN * g->h)
      return oc_seterr(err, OC_EINVAL,
                       "'box' is %g along %c, too thin for 'radius' %g "
                       "(at least %g)",
                       len[a], "xyz"[a], r, THIN * g -> h);
  g->tile = d == 2 ? TILE_2D : TILE_3D;
  g->seed = pp->seed;
  g->cover_max = d == 2 ? COVER_MAX_2D : COVER_MAX_3D;
  g->cover_depth = COVER_DEPTH;
  if (pp->periodic && periodic_cells(g, d, len, err)) return OC_EINVAL;
  size_t n[3], bytes;
  for (int a = 0; a < 3; a++) {
    g->lo[a] = lo[a];
    g->hi[a] = hi[a];
    /* n <= 2 bound^(1/d) + 2 fits, but checked all the same */
    double na = g->periodic ? round(len[a] / g->h) : ceil(len[a] / g->h);
    if (!oc_double_to_int(a < d ? fmax(1, na) : 1, 1, INT_MAX - g->tile,
                          &g->n[a]))
      return oc_seterr(err, OC_ENOMEM, "'radius' %g is too small for the box",
                       r);
    g->nt[a] = (g->n[a] + g->tile - 1) / g->tile;
    n[a] = (size_t)g->n[a];
  }
  if (!oc_prod_size(n, 3, &g->ncell) ||
      !oc_mul_size(g->ncell, (size_t)d * sizeof *g->pos, &bytes))
    return oc_seterr(err, OC_ENOMEM, "'radius' %g is too small for the box", r);
  for (int z = 0; z < OC_PREACH; z++)
    for (int y = 0; y < OC_PREACH; y++)
      for (int x = 0; x < OC_PREACH; x++) {
        int o[3] = {x - 2, y - 2, z - 2};
        double gap2 = 0;
        for (int a = 0; a < 3; a++) {
          double gp = (abs(o[a]) > 1 ? abs(o[a]) - 1 : 0) * g->h;
          gap2 += gp * gp;
        }
        g->reach[z][y][x] = (d == 3 || o[2] == 0) && gap2 < g->r2;
      }
  near_order(g);
  g->pos = malloc(bytes);
  if (!g->pos)
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory for a grid of %zu cells (%zu MiB)",
                     g->ncell, bytes >> 20);
  const double nan = NAN;
  const long long nc = (long long)g->ncell * d;
#pragma omp parallel for schedule(static)
  for (long long c = 0; c < nc; c++)
    g->pos[c] = nan;
  return 0;
}

/* Tiles of parity class `cls` (bit a: odd index on axis a). */
static size_t class_size(const oc_pgrid *g, unsigned cls) {
  size_t n = 1;
  for (int a = 0; a < 3; a++) {
    int b = (cls >> a) & 1;
    n *= (size_t)((g->nt[a] - b + 1) / 2);
  }
  return n;
}

static void class_tile(const oc_pgrid *g, unsigned cls, size_t q, int t[3]) {
  for (int a = 0; a < 3; a++) {
    int b = (cls >> a) & 1;
    size_t m = (size_t)((g->nt[a] - b + 1) / 2);
    t[a] = b + 2 * (int)(q % m);
    q /= m;
  }
}

static oc_rng tile_stream(const oc_pgrid *g, const int t[3], int round) {
  uint64_t id = ((uint64_t)t[2] * (uint64_t)g->nt[1] + (uint64_t)t[1]) *
                    (uint64_t)g->nt[0] +
                (uint64_t)t[0];
  return oc_rng_stream(g->seed, id * 64 + (uint64_t)round);
}

/* Runs every phase; returns 0, OC_ENOMEM or OC_ECANCEL. */
static int run_phases(oc_pgrid *g, const oc_progress *cb, oc_error *err) {
  int ncls = 1 << g->d, nphase = (DART_ROUNDS + 1) * ncls;
  int nthr = omp_get_max_threads();
  oc_pwork *work = calloc((size_t)nthr, sizeof *work);
  if (!work) return oc_seterr(err, OC_ENOMEM, "out of memory");
  size_t per_tile =
      (size_t)g->tile * (size_t)g->tile * (g->d == 3 ? g->tile : 1);
  size_t throws = (size_t)ceil(DARTS_PER_CELL * (double)per_tile);
  /* work done so far, in tiles (each tile counts once per phase) */
  size_t ntiles = (size_t)g->nt[0] * (size_t)g->nt[1] * (size_t)g->nt[2];
  double total = (double)ntiles * (DART_ROUNDS + 1);
  size_t done = 0;
  int stop = 0, cancelled = 0, nomem = 0;
  for (int ph = 0; ph < nphase && !stop; ph++) {
    int round = ph / ncls;
    unsigned cls = (unsigned)(ph % ncls);
    long long n = (long long)class_size(g, cls);
#pragma omp parallel for schedule(dynamic, 1)
    for (long long q = 0; q < n; q++) {
      int halt, t[3];
#pragma omp atomic read
      halt = stop;
      if (halt) continue;
      class_tile(g, cls, (size_t)q, t);
      oc_rng rng = tile_stream(g, t, round);
      if (round < DART_ROUNDS) {
        oc_ptile_darts(g, t, &rng, throws);
      } else if (oc_ptile_fill(g, t, &rng, &work[omp_get_thread_num()])) {
#pragma omp atomic write
        nomem = 1;
#pragma omp atomic write
        stop = 1;
      }
      size_t dn;
#pragma omp atomic capture
      dn = ++done;
      /* only the calling thread talks to the caller */
      if (cb->fn && omp_get_thread_num() == 0 &&
          cb->fn(cb->ud, 0.99 * (double)dn / total)) {
#pragma omp atomic write
        cancelled = 1;
#pragma omp atomic write
        stop = 1;
      }
    }
  }
  for (int i = 0; i < nthr; i++)
    oc_pwork_free(&work[i]);
  free(work);
  if (nomem)
    return oc_seterr(err, OC_ENOMEM, "out of memory while filling gaps");
  if (cancelled) return oc_seterr(err, OC_ECANCEL, "sampling cancelled");
  return 0;
}

/* Collects the samples in cell order, keeping each with the density's
** probability (2D). */
static oc_samples *collect(const oc_pgrid *g, const oc_poisson_params *pp,
                           oc_error *err) {
  int d = g->d;
  size_t n = 0;
  for (size_t c = 0; c < g->ncell; c++)
    n += !isnan(g->pos[(size_t)d * c]);
  oc_samples *s = malloc(sizeof *s);
  double *xyz = malloc((n ? n : 1) * (size_t)d * sizeof *xyz);
  if (!s || !xyz) {
    free(s);
    free(xyz);
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu samples", n);
    return NULL;
  }
  s->dim = d;
  s->xyz = xyz;
  s->n = 0;
  uint64_t thin = oc_hash2(g->seed, THIN_KEY);
  for (size_t c = 0; c < g->ncell; c++) {
    const double *p = g->pos + (size_t)d * c;
    if (isnan(p[0])) continue;
    if (pp->density) {
      double pr = pp->density(pp->density_ud, p[0], p[1]);
      if (!(pr >= 0 && pr <= 1)) {
        oc_seterr(err, OC_EINVAL,
                  "'density' must be a probability in [0, 1] (got %g at "
                  "%g, %g)",
                  pr, p[0], p[1]);
        oc_samples_free(s);
        return NULL;
      }
      oc_rng u = oc_rng_stream(thin, c);
      if (!(oc_rng_uniform(&u) < pr)) continue;
    }
    memcpy(xyz + (size_t)d * s->n++, p, (size_t)d * sizeof *p);
  }
  return s;
}

static oc_samples *poisson(const oc_poisson_params *pp, int d, oc_error *err) {
  oc_pgrid g;
  if (setup(pp, d, &g, err)) return NULL;
  oc_samples *s = NULL;
  if (!run_phases(&g, &pp->progress, err)) {
    s = collect(&g, pp, err);
    if (s && pp->progress.fn && pp->progress.fn(pp->progress.ud, 1.0)) {
      oc_samples_free(s);
      s = NULL;
      oc_seterr(err, OC_ECANCEL, "sampling cancelled");
    }
  }
  free(g.pos);
  return s;
}

oc_samples *oc_poisson2d(const oc_poisson_params *pp, oc_error *err) {
  return poisson(pp, 2, err);
}

oc_samples *oc_poisson3d(const oc_poisson_params *pp, oc_error *err) {
  return poisson(pp, 3, err);
}

void oc_samples_free(oc_samples *s) {
  if (!s) return;
  free(s->xyz);
  free(s);
}

size_t oc_samples_count(const oc_samples *s) {
  return s->n;
}
int oc_samples_dim(const oc_samples *s) {
  return s->dim;
}
const double *oc_samples_data(const oc_samples *s) {
  return s->xyz;
}
