/*
** ptile.c — the work on one tile of the Poisson grid: throwing darts at
** its cells, then filling its gaps for good.
**
** Gap filling follows Ebeida et al. 2012 ("A simple algorithm for maximal
** Poisson-disk sampling in high dimensions"): the tile's empty cells are
** the boxes of level 0; at each level, boxes proven covered are dropped,
** darts are thrown at the remaining ones picked uniformly (all boxes of a
** level have the same size, so the darts stay uniform over the uncovered
** area), and the survivors are split in 2^d. Their test of coverage (a
** box inside one disk) never settles a box straddling the meeting line of
** two disks, so the boxes would multiply forever along it; here the test
** is exact (pcover.c), every box kept holds an uncovered point, and the
** levels end once the voids are filled.
*/
#include <math.h>
#include <stdlib.h>

#include "core/grow.h"
#include "gen/poisson.h"

/* Darts per open box at each level of gap filling. */
#define FILL_DARTS 4.0
/* Splits before giving up on a box (its side is then 2^-48 of a cell's,
** far below any gap a dart could still find). */
#define MAX_LEVEL 48

static size_t pick(oc_rng *rng, size_t n) {
  return (size_t)(((unsigned __int128)oc_rng_next(rng) * n) >> 64);
}

static void cell_coords(const oc_pgrid *g, size_t c, int ijk[3]) {
  size_t nxy = (size_t)g->n[0] * (size_t)g->n[1];
  ijk[2] = (int)(c / nxy);
  c %= nxy;
  ijk[1] = (int)(c / (size_t)g->n[0]);
  ijk[0] = (int)(c % (size_t)g->n[0]);
}

/* Calls body with `s` pointing at each sample of the cells within reach of
** cell (i, j, k). */
#define FOR_NEAR(g, i, j, k, s, body)                                          \
  do {                                                                         \
    int z0_ = (k) > 2 ? -2 : -(k), z1_ = (g)->n[2] - 1 - (k);                  \
    int y0_ = (j) > 2 ? -2 : -(j), y1_ = (g)->n[1] - 1 - (j);                  \
    int x0_ = (i) > 2 ? -2 : -(i), x1_ = (g)->n[0] - 1 - (i);                  \
    if (z1_ > 2) z1_ = 2;                                                      \
    if (y1_ > 2) y1_ = 2;                                                      \
    if (x1_ > 2) x1_ = 2;                                                      \
    for (int dz_ = z0_; dz_ <= z1_; dz_++)                                     \
      for (int dy_ = y0_; dy_ <= y1_; dy_++) {                                 \
        const unsigned char *m_ = (g)->reach[dz_ + 2][dy_ + 2] + 2;            \
        const double *row_ =                                                   \
            (g)->pos +                                                         \
            (size_t)(g)->d * oc_pcell((g), (i), (j) + dy_, (k) + dz_);         \
        for (int dx_ = x0_; dx_ <= x1_; dx_++) {                               \
          const double *s = row_ + (ptrdiff_t)(g)->d * dx_;                    \
          if (!m_[dx_] || isnan(s[0])) continue;                               \
          body;                                                                \
        }                                                                      \
      }                                                                        \
  } while (0)

/* Periodic mode: calls body with `s` pointing at the periodic image (a
** shifted copy in sp_) of each sample of the cells within reach of cell
** (i, j, k), wrapping across the faces of the torus. The wrapped index
** and shift of each offset are worked out once per axis. */
#define FOR_NEAR_PERIODIC(g, i, j, k, s, body)                                 \
  do {                                                                         \
    int zr_ = (g)->d == 3 ? 2 : 0, ix_[3][OC_PREACH];                          \
    double sh_[3][OC_PREACH];                                                  \
    const int c_[3] = {(i), (j), (k)};                                         \
    for (int a_ = 0; a_ < 3; a_++)                                             \
      for (int o_ = -2; o_ <= 2; o_++) {                                       \
        int x_ = c_[a_] + o_, w_ = x_ < 0 ? -1 : x_ >= (g)->n[a_];             \
        ix_[a_][o_ + 2] = x_ - w_ * (g)->n[a_];                                \
        sh_[a_][o_ + 2] = w_ * (g)->len;                                       \
      }                                                                        \
    for (int dz_ = -zr_; dz_ <= zr_; dz_++) {                                  \
      double shz_ = (g)->d == 3 ? sh_[2][dz_ + 2] : 0;                         \
      for (int dy_ = -2; dy_ <= 2; dy_++) {                                    \
        const unsigned char *m_ = (g)->reach[dz_ + 2][dy_ + 2];                \
        const double *row_ =                                                   \
            (g)->pos + (size_t)(g)->d *                                        \
                           oc_pcell((g), 0, ix_[1][dy_ + 2], ix_[2][dz_ + 2]); \
        for (int dx_ = 0; dx_ < OC_PREACH; dx_++) {                            \
          if (!m_[dx_]) continue;                                              \
          const double *q_ = row_ + (size_t)(g)->d * (size_t)ix_[0][dx_];      \
          if (isnan(q_[0])) continue;                                          \
          double sp_[3] = {q_[0] + sh_[0][dx_], q_[1] + sh_[1][dy_ + 2],       \
                           (g)->d == 3 ? q_[2] + shz_ : 0};                    \
          const double *s = sp_;                                               \
          body;                                                                \
        }                                                                      \
      }                                                                        \
    }                                                                          \
  } while (0)

/* Is cell (i, j, k) two cells or more from every face (so that the cells
** within reach are found at fixed offsets, unwrapped)? */
static int inner(const oc_pgrid *g, int i, int j, int k) {
  return i >= 2 && i + 2 < g->n[0] && j >= 2 && j + 2 < g->n[1] &&
         (g->d == 2 || (k >= 2 && k + 2 < g->n[2]));
}

/* Is p, in cell (i, j, k), farther than r from every sample? The cells
** within reach are visited nearest first; the answer does not depend on
** the order. */
static int is_free(const oc_pgrid *g, const double *p, int i, int j, int k) {
  int d = g->d;
  double r2 = g->r2;
  const int c[3] = {i, j, k};
  if (inner(g, i, j, k)) {
    const double *base = g->pos + (size_t)d * oc_pcell(g, i, j, k);
    for (int q = 0; q < g->nnear; q++) {
      const double *s = base + g->nearoff[q];
      if (isnan(s[0])) continue;
      double d2 = 0;
      for (int a = 0; a < d; a++)
        d2 += (s[a] - p[a]) * (s[a] - p[a]);
      if (d2 <= r2) return 0;
    }
    return 1;
  }
  for (int q = 0; q < g->nnear; q++) {
    const signed char *o = g->near[q];
    int x[3], w[3];
    for (int a = 0; a < 3; a++) {
      x[a] = c[a] + o[a];
      w[a] = x[a] < 0 ? -1 : x[a] >= g->n[a];
    }
    if (g->periodic) {
      for (int a = 0; a < 3; a++)
        x[a] -= w[a] * g->n[a];
    } else if (w[0] | w[1] | w[2]) {
      continue;
    }
    const double *s = g->pos + (size_t)d * oc_pcell(g, x[0], x[1], x[2]);
    if (isnan(s[0])) continue;
    double d2 = 0;
    if (g->periodic) {
      /* the periodic image, as FOR_NEAR_PERIODIC has it */
      for (int a = 0; a < d; a++) {
        double sa = s[a] + w[a] * g->len;
        d2 += (sa - p[a]) * (sa - p[a]);
      }
    } else {
      for (int a = 0; a < d; a++)
        d2 += (s[a] - p[a]) * (s[a] - p[a]);
    }
    if (d2 <= r2) return 0;
  }
  return 1;
}

int oc_pgather(const oc_pgrid *g, int i, int j, int k, double *nb) {
  int n = 0, d = g->d;
  if (inner(g, i, j, k)) {
    const double *base = g->pos + (size_t)d * oc_pcell(g, i, j, k);
    for (int q = 0; q < g->nreach; q++) {
      const double *s = base + g->reachoff[q];
      if (isnan(s[0])) continue;
      for (int a = 0; a < d; a++)
        nb[d * n + a] = s[a];
      n++;
    }
    return n;
  }
  if (g->periodic) {
    FOR_NEAR_PERIODIC(g, i, j, k, s, {
      for (int a = 0; a < d; a++)
        nb[d * n + a] = s[a];
      n++;
    });
    return n;
  }
  FOR_NEAR(g, i, j, k, s, {
    for (int a = 0; a < d; a++)
      nb[d * n + a] = s[a];
    n++;
  });
  return n;
}

/* A dart at box `lo` of side `side` in cell c: kept when it is inside the
** box of the grid and free. With `clip`
** (gap filling) the dart is drawn in the part of the box inside the
** domain: a box straddling a face of a domain much thinner than a cell
** would otherwise almost never be hit, and its splits would double at
** every level. (Those boxes get slightly denser darts than others; the
** result stays maximal, and stays the same for any thread count.) */
static void dart(oc_pgrid *g, size_t c, const double *lo, double side, int clip,
                 oc_rng *rng) {
  int d = g->d, ijk[3];
  double p[3];
  double *slot = g->pos + (size_t)d * c;
  for (int a = 0; a < d; a++) {
    double a0 = lo[a], len = side;
    if (clip) { /* fmax and fmin, inline */
      double b = lo[a] + side;
      a0 = lo[a] > g->lo[a] ? lo[a] : g->lo[a];
      len = (b < g->hi[a] ? b : g->hi[a]) - a0;
    }
    p[a] = a0 + len * oc_rng_uniform(rng);
    if (p[a] < g->lo[a] || p[a] > g->hi[a]) return;
    if (g->periodic && p[a] >= g->hi[a]) return; /* [lo, hi) on a torus */
  }
  if (!isnan(slot[0])) return;
  cell_coords(g, c, ijk);
  if (!is_free(g, p, ijk[0], ijk[1], ijk[2])) return;
  for (int a = 0; a < d; a++)
    slot[a] = p[a];
}

static void tile_range(const oc_pgrid *g, const int t[3], int a0[3],
                       int a1[3]) {
  for (int a = 0; a < 3; a++) {
    a0[a] = t[a] * g->tile;
    a1[a] = a0[a] + g->tile < g->n[a] ? a0[a] + g->tile : g->n[a];
  }
}

void oc_ptile_darts(oc_pgrid *g, const int t[3], oc_rng *rng, size_t throws) {
  int a0[3], a1[3], d = g->d;
  tile_range(g, t, a0, a1);
  size_t mx = (size_t)(a1[0] - a0[0]), my = (size_t)(a1[1] - a0[1]);
  size_t m = mx * my * (size_t)(a1[2] - a0[2]);
  for (size_t n = 0; n < throws; n++) {
    size_t q = pick(rng, m);
    int i = a0[0] + (int)(q % mx), j = a0[1] + (int)(q / mx % my),
        k = a0[2] + (int)(q / (mx * my));
    size_t c = oc_pcell(g, i, j, k);
    double lo[3] = {g->lo[0] + i * g->h, g->lo[1] + j * g->h,
                    g->lo[2] + k * g->h};
    if (!isnan(g->pos[(size_t)d * c])) continue;
    dart(g, c, lo, g->h, 0, rng);
  }
}

static int reserve(oc_psub **v, size_t *cap, size_t n) {
  return oc_grow(v, cap, n, sizeof **v, 1024) ? OC_ENOMEM : 0;
}

void oc_pwork_free(oc_pwork *w) {
  free(w->cur);
  free(w->next);
  w->cur = w->next = NULL;
  w->capcur = w->capnext = 0;
}

/* The samples within reach of cell ijk (oc_pgather) less those at r or
** more from it (with a margin far above rounding), which no box of the
** cell can meet: the coverage test would drop them; returns their count. */
static int near_cell(const oc_pgrid *g, const int ijk[3], double *nb) {
  int d = g->d, n = oc_pgather(g, ijk[0], ijk[1], ijk[2], nb), m = 0;
  double lim = g->r2 * (1 + 1e-9);
  for (int q = 0; q < n; q++) {
    const double *s = nb + d * q;
    double d2 = 0;
    for (int a = 0; a < d; a++) {
      double lo = g->lo[a] + ijk[a] * g->h, hi = lo + g->h;
      double v = s[a] < lo ? lo - s[a] : s[a] > hi ? s[a] - hi : 0;
      d2 += v * v;
    }
    if (!(d2 < lim)) continue;
    for (int a = 0; a < d; a++)
      nb[d * m + a] = s[a];
    m++;
  }
  return m;
}

/* Keeps the boxes of w->cur that may hold an uncovered point; returns
** their count. */
static size_t keep_open(const oc_pgrid *g, oc_pwork *w, size_t ncur,
                        double side) {
  int d = g->d, nnb = 0;
  size_t last = (size_t)-1, nkeep = 0;
  for (size_t q = 0; q < ncur; q++) {
    const oc_psub *s = &w->cur[q];
    double lo[3], hi[3];
    int empty = 0;
    if (!isnan(g->pos[(size_t)d * s->cell])) continue;
    for (int a = 0; a < d; a++) {
      lo[a] = s->lo[a] > g->lo[a] ? s->lo[a] : g->lo[a];
      hi[a] = s->lo[a] + side < g->hi[a] ? s->lo[a] + side : g->hi[a];
      empty |= !(lo[a] < hi[a]);
    }
    if (empty) continue;
    if (s->cell != last) {
      int ijk[3];
      cell_coords(g, s->cell, ijk);
      nnb = near_cell(g, ijk, w->nb);
      last = s->cell;
    }
    if (oc_pcover(d, g->r, lo, hi, w->nb, nnb, g->cover_max, g->cover_depth))
      continue;
    w->cur[nkeep++] = *s; /* in place: nkeep <= q */
  }
  return nkeep;
}

int oc_ptile_fill(oc_pgrid *g, const int t[3], oc_rng *rng, oc_pwork *w) {
  int a0[3], a1[3], d = g->d;
  size_t ncur = 0;
  tile_range(g, t, a0, a1);
  size_t m = (size_t)(a1[0] - a0[0]) * (size_t)(a1[1] - a0[1]) *
             (size_t)(a1[2] - a0[2]);
  if (reserve(&w->cur, &w->capcur, m)) return OC_ENOMEM;
  for (int k = a0[2]; k < a1[2]; k++)
    for (int j = a0[1]; j < a1[1]; j++)
      for (int i = a0[0]; i < a1[0]; i++) {
        size_t c = oc_pcell(g, i, j, k);
        if (!isnan(g->pos[(size_t)d * c])) continue;
        oc_psub *s = &w->cur[ncur++];
        s->cell = c;
        s->lo[0] = g->lo[0] + i * g->h;
        s->lo[1] = g->lo[1] + j * g->h;
        s->lo[2] = g->lo[2] + k * g->h;
      }
  double side = g->h;
  for (int level = 0;; level++) {
    ncur = keep_open(g, w, ncur, side);
    if (ncur == 0) break;
    if (level == MAX_LEVEL) {
      w->unresolved += ncur;
      break;
    }
    size_t throws = (size_t)ceil(FILL_DARTS * (double)ncur);
    for (size_t n = 0; n < throws; n++) {
      const oc_psub *s = &w->cur[pick(rng, ncur)];
      dart(g, s->cell, s->lo, side, 1, rng);
    }
    /* split the boxes whose cell is still empty */
    double half = 0.5 * side;
    size_t nn = 0;
    if (reserve(&w->next, &w->capnext, ncur << d)) return OC_ENOMEM;
    for (size_t q = 0; q < ncur; q++) {
      const oc_psub *s = &w->cur[q];
      if (!isnan(g->pos[(size_t)d * s->cell])) continue;
      for (unsigned b = 0; b < (1u << d); b++) {
        oc_psub *c = &w->next[nn++];
        c->cell = s->cell;
        for (int a = 0; a < 3; a++)
          c->lo[a] = s->lo[a] + ((b >> a) & 1 ? half : 0);
      }
    }
    oc_psub *x = w->cur;
    size_t cx = w->capcur;
    w->cur = w->next, w->capcur = w->capnext;
    w->next = x, w->capnext = cx;
    ncur = nn;
    side = half;
  }
  return 0;
}
