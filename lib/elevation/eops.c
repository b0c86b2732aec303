/*
** eops.c — the operators of elevation trees (Génevaux et al. 2015, section
** 5 and the appendix): blend, replace, add, affine transforms and warps,
** with their values, gradients and bounds (whole plane and in a box).
**
** The appendix's bounds, corrected, with w = clamp(alpha_B, 0, 1):
**  blend    lambda <= max lambda_i + Lambda D / max(inf sum alpha, T),
**           D the width of the children's range of f, Lambda =
**           max(lambda_alpha) for two children, the smaller of the sum and
**           (n - 1) times the largest for n; where sum alpha may be < T,
**           also at most max lambda_i + sum lambda_alpha_i sup|f_i| / T;
**  replace  lambda <= max(lambda_A, lambda_B) + lambda_alphaB sup|f_A - f_B|;
**  add      lambda <= lambda_A + lambda_w sup|f_B| + sup w lambda_B, w the
**           clamped weight times the altitude and slope weights (their
**           Lipschitz bounds added: each factor lies in [0, 1]);
**  warp     lambda_A (1 + lambda_delta);
**  transform |vscale| lambda_A / scale.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "core/error.h"
#include "core/noise.h"
#include "core/rng.h"
#include "elevation/enode.h"
#include "elevation/etaylor.h"

#define T OC_ENODE_T
#define DEG (3.14159265358979323846 / 180)

/* par slots */
enum {
  /* add, with an altitude weight: below_z, fade (add_below) */
  P_BZ = 0,
  P_FADE = 1,
  /* add, with a slope weight: its angle and fade (add_slope) */
  P_SLOPE = 0,
  P_SFADE = 1,
  /* transform: the first row (cos, sin) / scale of the inverse rotation
  ** and scaling Minv = R^T / scale (its second row is (-sin, cos) /
  ** scale), translation, vscale, voffset, scale and angle; p' = Minv (p
  ** - t) */
  P_MI = 0,
  P_TX = 2,
  P_TY = 3,
  P_VS = 4,
  P_VO = 5,
  P_SCALE = 6,
  P_ANGLE = 7,
  /* warp: largest displacement per axis, delta's Lipschitz bound, the
  ** noise's amplitude, wavelength and seed (its bits) */
  P_WMAX = 0,
  P_WLIP = 1,
  P_WAMP = 2,
  P_WWL = 3,
  P_WSEED = 4
};

/* A transform's Minv, row-major. */
static void minv(const oc_enode *n, double m[4]) {
  const double *q = OC_EUN(n)->par + P_MI;
  m[0] = q[0];
  m[1] = q[1];
  m[2] = -q[1];
  m[3] = q[0];
}

static oc_erect rect_union(oc_erect a, oc_erect b) {
  oc_erect r = {fmin(a.x0, b.x0), fmin(a.y0, b.y0), fmax(a.x1, b.x1),
                fmax(a.y1, b.y1)};
  return r;
}

/* Stores the bound and box of a blend or a binary operator, derived from
** its children's kb and kbox, rounded outward. */
static void store_derived(oc_enode *n, const oc_ebound *kb,
                          const oc_erect *kbox) {
  oc_ebound g;
  oc_erect box;
  oc_eop_derive(n, kb, kbox, &g, &box);
  if (n->kind == OC_E_BLEND) {
    oc_ebound_round(&g, &((oc_eblend *)n)->glob);
    oc_erect_round(&box, &((oc_eblend *)n)->box);
  } else {
    oc_ebound_round(&g, &((oc_ebin *)n)->glob);
    oc_erect_round(&box, &((oc_ebin *)n)->box);
  }
}

static double clamp01(double v, int *inside) {
  *inside = v > 0 && v < 1;
  return v <= 0 ? 0 : v >= 1 ? 1 : v; /* (NaN stays NaN) */
}

/* ---- blend ------------------------------------------------------------ */

/* The grid of a blend (enode.h), after the children: its scales, then
** the masks of its columns and of its rows. */
typedef struct grid_head {
  double sx, sy; /* G / the box's sides: cells a unit */
} grid_head;

static const grid_head *grid_of(const oc_eblend *bl) {
  return (const grid_head *)(const void *)(bl->kids + bl->nkids);
}
static const uint64_t *grid_masks(const oc_eblend *bl) {
  return (const uint64_t *)(const void *)(grid_of(bl) + 1);
}

/* The cell of v on an axis from lo, s = G / (hi - lo) cells a unit: a
** monotone function of v (rounded subtraction and product, truncation,
** clamps), so a child's box and a query's region that share a point
** share a cell of both their ranges. NaN gives 0 (its box tests fail). */
static int grid_cell(double v, double lo, double s, int G) {
  double t = (v - lo) * s;
  if (!(t >= 0)) return 0;
  return t >= G ? G - 1 : (int)t;
}

/* The cells [i0, i1] x [j0, j1] of blend bl's grid (G a side) that
** [x0, x1] x [y0, y1] meets: the same arithmetic for the children's
** boxes when the grid is built and for the queries, so that they agree
** (the scales stored: no division a query). */
static void grid_range(const oc_eblend *bl, int G, double x0, double y0,
                       double x1, double y1, int r[4]) {
  double bx = bl->box.x0, by = bl->box.y0;
  const grid_head *gh = grid_of(bl);
  r[0] = grid_cell(x0, bx, gh->sx, G), r[1] = grid_cell(x1, bx, gh->sx, G);
  r[2] = grid_cell(y0, by, gh->sy, G), r[3] = grid_cell(y1, by, gh->sy, G);
}

/* The children a query over [x0, x1] x [y0, y1] may meet: those of the
** cells that region meets (all when the blend has no grid), as W words
** of 64 bits visited in order:
**   for (int w = 0; w < it.W; w++)
**     for (uint64_t m = kid_word(&it, w); m; m &= m - 1)
**       ... bl->kids[KID_INDEX(w, m)] ...
** A child's cells are a rectangle, as the region's: they share a cell
** exactly when their columns and their rows overlap, so the masks of the
** region's columns ORed, ANDed with those of its rows ORed, are the
** children of its cells (G + G words where a G x G grid of masks had G^2). */
typedef struct kid_iter {
  uint64_t m[OC_EGRID_WORDS]; /* (with a grid) */
  size_t n;
  int W, grid;
} kid_iter;

static void kids_in(const oc_eblend *bl, double x0, double y0, double x1,
                    double y1, kid_iter *it) {
  int G = bl->h.octaves;
  size_t n = bl->nkids;
  it->n = n, it->W = (int)((n + 63) / 64), it->grid = G != 0;
  if (!G) return;
  int r[4];
  grid_range(bl, G, x0, y0, x1, y1, r);
  int i0 = r[0], i1 = r[1], j0 = r[2], j1 = r[3];
  const uint64_t *col = grid_masks(bl), *row = col + (size_t)G * it->W;
  if (n <= 64) { /* (one word a column: the common case) */
    uint64_t c = 0, w = 0;
    for (int i = i0; i <= i1; i++)
      c |= col[i];
    for (int j = j0; j <= j1; j++)
      w |= row[j];
    it->m[0] = c & w;
    return;
  }
  int W = it->W;
  uint64_t c[OC_EGRID_WORDS] = {0}, w[OC_EGRID_WORDS] = {0};
  for (int i = i0; i <= i1; i++)
    for (int k = 0; k < W; k++)
      c[k] |= col[(size_t)i * W + k];
  for (int j = j0; j <= j1; j++)
    for (int k = 0; k < W; k++)
      w[k] |= row[(size_t)j * W + k];
  for (int k = 0; k < OC_EGRID_WORDS; k++)
    it->m[k] = c[k] & w[k];
}

static inline uint64_t kid_word(const kid_iter *it, int w) {
  if (it->grid) return it->m[w];
  size_t left = it->n - 64 * (size_t)w;
  return left >= 64 ? ~(uint64_t)0 : ((uint64_t)1 << left) - 1;
}
#define KID_INDEX(w, m) (64 * (size_t)(w) + (size_t)__builtin_ctzll(m))

/* The next child of it (cursor: word w, mask mk) whose box meets r; NULL
** when none is left. */
static inline const oc_enode *next_meeting(const oc_eblend *bl,
                                           const kid_iter *it,
                                           const oc_erect *r, int *w,
                                           uint64_t *mk) {
  for (;;) {
    while (!*mk) {
      if (++*w >= it->W) return NULL;
      *mk = kid_word(it, *w);
    }
    const oc_enode *k = bl->kids[KID_INDEX(*w, *mk)];
    *mk &= *mk - 1;
    if (oc_enode_meets(k, r)) return k;
  }
}

/* At most this many children of a blend meet the disc (else fallback). */
#define TAY_KIDS 64

/* oc_edisc_meets(k, b) without branches; k goes to *kk (kept where it
** meets b: the caller's count then grows by 1). */
static inline int disc_meets(const oc_enode *k, const oc_erect *b,
                             const oc_enode **kk) {
  const double *p = OC_EDISC(k)->par;
  *kk = k;
#ifdef __SSE2__
  /* the x and y tests in the two lanes of one register: the same
  ** differences, sums and comparisons, 17 instructions a child where the
  ** scalar tests took 25 (taylor a call, CPU time on one thread, best of
  ** 5 interleaved runs of a replay of bench_elev -q's queries: fig3
  ** 0.425 -> 0.414 us, fig1 0.712 -> 0.704, fig21 0.532 -> 0.523) */
  __m128d c = _mm_loadu_pd(p), r = _mm_set1_pd(p[2]);
  __m128d lo = _mm_setr_pd(b->x0, b->y0), hi = _mm_setr_pd(b->x1, b->y1);
  __m128d m = _mm_and_pd(_mm_cmple_pd(_mm_sub_pd(c, r), hi),
                         _mm_cmpge_pd(_mm_add_pd(c, r), lo));
  return _mm_movemask_pd(m) == 3;
#else
  return (p[0] - p[2] <= b->x1) & (p[0] + p[2] >= b->x0) &
         (p[1] - p[2] <= b->y1) & (p[1] + p[2] >= b->y0);
#endif
}

/* The children of a blend of discs alone (OC_EF_DISCS, at most TAY_KIDS
** of them) whose box meets the ball b, in order, into kk. Their boxes
** are tested without branches (oc_edisc_meets' comparisons): which ones
** a ball meets is a coin toss for a branch predictor. */
static int discs_meeting(const oc_eblend *bl, const oc_erect *b,
                         const oc_enode **kk) {
  kid_iter it;
  kids_in(bl, b->x0, b->y0, b->x1, b->y1, &it);
  int nk = 0, w = 0;
  if (!it.grid) { /* (every child, in order) */
    for (uint32_t i = 0; i < bl->nkids; i++)
      nk += disc_meets(bl->kids[i], b, &kk[nk]);
    return nk;
  }
  for (uint64_t mk = kid_word(&it, 0); w < it.W;
       mk = ++w < it.W ? kid_word(&it, w) : 0)
    for (; mk; mk &= mk - 1)
      nk += disc_meets(bl->kids[KID_INDEX(w, mk)], b, &kk[nk]);
  return nk;
}

/* Whether blend bl's children meeting b go through discs_meeting. */
static inline int discs_only(const oc_eblend *bl) {
  return bl->h.flags & OC_EF_DISCS && bl->nkids <= TAY_KIDS;
}

/* The children of blend bl whose box meets the ball b, in order, into kk
** (up to TAY_KIDS; -1 beyond), and whether they are all discs. */
static int kids_meeting(const oc_eblend *bl, const oc_erect *b,
                        const oc_enode **kk, int *discs) {
  *discs = 1;
  if (discs_only(bl)) return discs_meeting(bl, b, kk);
  kid_iter it;
  kids_in(bl, b->x0, b->y0, b->x1, b->y1, &it);
  int nk = 0, w = 0;
  uint64_t mk = kid_word(&it, 0);
  const oc_enode *k;
  while ((k = next_meeting(bl, &it, b, &w, &mk))) {
    if (nk == TAY_KIDS) return -1;
    kk[nk++] = k;
    *discs = *discs && k->kind == OC_E_DISC;
  }
  return nk;
}

/* Cells a side for n children (0: no grid): the most with 8
** oc_eblend_grid_words(n, G) <= 6 n, 6 bytes a child at most, so that
** the Table 1 scenes stay within the paper's bytes (bench_elev --bytes);
** blends below 24 children (fig3's 18) test their children's boxes as
** fast as a grid's cells. */
static int grid_side(size_t n) {
  size_t W = (n + 63) / 64;
  if (n < OC_EGRID_MIN || W > OC_EGRID_WORDS) return 0;
  int G = 1;
  while (8 * oc_eblend_grid_words(n, G + 1) <= 6 * n)
    G++;
  return G;
}

/* Fills blend e's grid from its children's boxes kbox (its box stored):
** its scales, then each child's bit in the columns and rows its box
** meets. */
static void grid_build(oc_eblend *bl, const oc_erect *kbox) {
  int G = bl->h.octaves, W = (int)((bl->nkids + 63) / 64);
  grid_head *gh = (grid_head *)(uintptr_t)grid_of(bl);
  double bx = bl->box.x0, by = bl->box.y0;
  gh->sx = G / ((double)bl->box.x1 - bx);
  gh->sy = G / ((double)bl->box.y1 - by);
  uint64_t *col = (uint64_t *)(uintptr_t)grid_masks(bl),
           *row = col + (size_t)G * W;
  for (size_t k = 0; k < bl->nkids; k++) {
    const oc_erect *b = &kbox[k];
    uint64_t bit = (uint64_t)1 << (k % 64);
    int r[4];
    grid_range(bl, G, b->x0, b->y0, b->x1, b->y1, r);
    for (int i = r[0]; i <= r[1]; i++)
      col[(size_t)i * W + k / 64] |= bit;
    for (int j = r[2]; j <= r[3]; j++)
      row[(size_t)j * W + k / 64] |= bit;
  }
}

static void blend_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                     int want, oc_enode_sample *s) {
  int grad = want & OC_EV_GRAD, only = want & OC_EV_ALPHA;
  double N = 0, S = 0, nx = 0, ny = 0, sx = 0, sy = 0;
  const oc_eblend *bl = OC_EBLEND(n);
  kid_iter it;
  kids_in(bl, x, y, x, y, &it);
  for (int w = 0; w < it.W; w++)
    for (uint64_t mk = kid_word(&it, w); mk; mk &= mk - 1) {
      const oc_enode *k = bl->kids[KID_INDEX(w, mk)];
      if (!oc_enode_holds(k, x, y))
        continue; /* alpha = 0 there: no contribution */
      oc_enode_sample c;
      oc_enode_ev(k, x, y, ft, grad | OC_EV_LAZY | only, &c);
      if (only) {
        S += c.a;
        continue;
      }
      if (c.a == 0) continue;
      N += c.a * c.f;
      S += c.a;
      if (grad) {
        nx += c.ax * c.f + c.a * c.fx;
        ny += c.ay * c.f + c.a * c.fy;
        sx += c.ax;
        sy += c.ay;
      }
    }
  s->a = S;
  s->ax = sx;
  s->ay = sy;
  if (only) return;
  if (x != x || y != y) { /* NaN fails every box test */
    s->f = s->a = NAN;
    s->fx = s->fy = s->ax = s->ay = NAN;
    return;
  }
  if (S >= T) {
    s->f = N / S;
    s->fx = (nx - s->f * sx) / S;
    s->fy = (ny - s->f * sy) / S;
  } else {
    s->f = N / T;
    s->fx = nx / T;
    s->fy = ny / T;
  }
  if (!grad) s->fx = s->fy = s->ax = s->ay = 0;
}

/* Combines the children's bounds (those whose box meets the region; the
** others have alpha = 0 there). Where sum alpha >= T, f is a convex
** combination: its slope is at most max lambda_i + Lambda D / inf S, D
** the width of the children's range; where sum alpha < T, f = sum
** alpha_i f_i / T: at most max lambda_i + sum lambda_alpha_i sup|f_i| / T. */
static void blend_combine(const oc_ebound *kb, size_t n, int plane,
                          oc_ebound *o) {
  if (n == 0) {
    *o = (oc_ebound){0, 0, 0, 0, 0, 0};
    return;
  }
  double flo = INFINITY, fhi = -INFINITY, slo = 0, shi = 0, lmax = 0;
  double lasum = 0, lamax = 0, M = 0;
  for (size_t i = 0; i < n; i++) {
    flo = oc_fmin(flo, kb[i].flo);
    fhi = oc_fmax(fhi, kb[i].fhi);
    slo += plane ? 0 : kb[i].alo; /* (the plane: some point is outside) */
    shi += kb[i].ahi;
    lmax = oc_fmax(lmax, kb[i].lf);
    lasum += kb[i].la;
    lamax = oc_fmax(lamax, kb[i].la);
    M += kb[i].la * oc_fmax(fabs(kb[i].flo), fabs(kb[i].fhi));
  }
  double lam = oc_fmin(lasum, (double)(n - 1) * lamax);
  /* sum |grad alpha_i| |f_i - f| with f in [flo, fhi]: each child's own
  ** distance to that range is often far below its width */
  double dev = 0;
  for (size_t i = 0; i < n; i++)
    dev += kb[i].la * oc_fmax(kb[i].fhi - flo, fhi - kb[i].flo);
  o->lf = lmax + oc_fmin(lam * (fhi - flo), dev) / oc_fmax(slo, T);
  if (slo < T) { /* f fades towards 0 where sum alpha < T */
    o->lf = oc_fmax(o->lf, lmax + M / T);
    flo = oc_fmin(flo, 0);
    fhi = oc_fmax(fhi, 0);
  }
  o->flo = flo;
  o->fhi = fhi;
  o->alo = slo;
  o->ahi = shi;
  o->la = lasum;
}

#define KB_STACK 64 /* (3 kB: blends of up to 64 children allocate nothing) */

static void blend_bound_in(const oc_enode *n, const oc_erect *b,
                           const oc_efootb *fb, oc_ebound *o) {
  const oc_eblend *bl = OC_EBLEND(n);
  oc_ebound stack[KB_STACK], *kb = stack;
  if (bl->nkids > KB_STACK && !(kb = malloc(bl->nkids * sizeof *kb))) {
    oc_enode_glob(n, o); /* (conservative: the whole plane's) */
    return;
  }
  size_t m = 0;
  /* alpha = 0 on the whole box: neither a child's f nor its weight's
  ** slope counts there */
  if (discs_only(bl)) {
    const oc_enode *kk[TAY_KIDS];
    int nk = discs_meeting(bl, b, kk);
    for (int i = 0; i < nk; i++) {
      oc_enode_bnd(kk[i], b, fb, &kb[m]);
      m += kb[m].ahi > 0;
    }
  } else {
    kid_iter it;
    kids_in(bl, b->x0, b->y0, b->x1, b->y1, &it);
    const oc_enode *k;
    int w = 0;
    uint64_t mk = kid_word(&it, 0);
    while ((k = next_meeting(bl, &it, b, &w, &mk))) {
      oc_enode_bnd(k, b, fb, &kb[m]);
      m += kb[m].ahi > 0;
    }
  }
  blend_combine(kb, m, 0, o);
  if (kb != stack) free(kb);
}

oc_enode *oc_enode_blend(oc_enode *const *kids, size_t n, oc_error *err) {
  if (!kids || n == 0) {
    oc_seterr(err, OC_EINVAL, "blend needs at least one elevation node");
    return NULL;
  }
  for (size_t i = 0; i < n; i++)
    if (!kids[i]) {
      oc_seterr(err, OC_EINVAL, "blend: child %zu is NULL", i + 1);
      return NULL;
    }
  if (n > UINT32_MAX || n > (SIZE_MAX - sizeof(oc_eblend)) / sizeof *kids) {
    oc_seterr(err, OC_EINVAL, "blend: too many children (%zu)", n);
    return NULL;
  }
  oc_ebound *kb = malloc(n * sizeof *kb);
  oc_erect *kbox = malloc(n * sizeof *kbox);
  oc_enode *e = NULL;
  if (!kb || !kbox) {
    oc_seterr(err, OC_ENOMEM, "out of memory (%zu children)", n);
    goto done;
  }
  /* the grid: over a box of positive finite sides (the box as
  ** store_derived rounds it) */
  oc_erect u = oc_enode_box(kids[0]);
  oc_erectf uf;
  for (size_t i = 0; i < n; i++) {
    kbox[i] = oc_enode_box(kids[i]);
    u = rect_union(u, kbox[i]);
  }
  oc_erect_round(&u, &uf);
  int G = grid_side(n);
  if (!(isfinite(uf.x0) && isfinite(uf.x1) && isfinite(uf.y0) &&
        isfinite(uf.y1) && uf.x1 > uf.x0 && uf.y1 > uf.y0))
    G = 0;
  e = oc_enode_alloc(OC_E_BLEND,
                     offsetof(oc_eblend, kids) + n * sizeof *kids +
                         oc_eblend_grid_words(n, G) * sizeof(uint64_t),
                     kids, n, err);
  if (!e) goto done;
  for (size_t i = 0; i < n; i++)
    oc_enode_glob(kids[i], &kb[i]);
  store_derived(e, kb, kbox);
  e->octaves = (uint8_t)G;
  int discs = 1;
  for (size_t i = 0; i < n; i++)
    discs = discs && kids[i]->kind == OC_E_DISC;
  e->flags |= discs ? OC_EF_DISCS : 0;
  if (G) grid_build((oc_eblend *)e, kbox);
done:
  free(kb);
  free(kbox);
  return e;
}

/* ---- replace ---------------------------------------------------------- */

static void replace_ev(const oc_enode *n, double x, double y,
                       const oc_efoot *ft, int want, oc_enode_sample *s) {
  int grad = want & OC_EV_GRAD, in;
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  oc_enode_sample a, b;
  int lerp = (n->flags & OC_EF_LERP) != 0;
  if (want & OC_EV_ALPHA) { /* alpha_A, or lerped with B's */
    oc_enode_ev(A, x, y, ft, OC_EV_ALPHA, &a);
    s->a = a.a;
    if (lerp) {
      b.a = 0;
      if (oc_enode_holds(B, x, y)) oc_enode_ev(B, x, y, ft, OC_EV_ALPHA, &b);
      double w = clamp01(b.a, &in);
      s->a = (1 - w) * a.a + w * w;
    }
    return;
  }
  b.a = b.f = b.fx = b.fy = b.ax = b.ay = 0;
  if (oc_enode_holds(B, x, y)) oc_enode_ev(B, x, y, ft, grad | OC_EV_LAZY, &b);
  double w = clamp01(b.a, &in);
  /* A's f is not needed where B replaces it wholly, nor, for a lazy
  ** caller, where A's weight (the node's, unless lerped) is 0 */
  int alazy = w >= 1 || (!lerp && (want & OC_EV_LAZY));
  oc_enode_ev(A, x, y, ft, grad | (alazy ? OC_EV_LAZY : 0), &a);
  if (w >= 1) {
    /* f = f_B; a.f may be unset only where alpha_A = 0, where the lazy
    ** caller does not read it either */
    a.f = a.fx = a.fy = 0;
  }
  if (want & OC_EV_LAZY && a.a == 0 && !lerp) {
    *s = a;
    s->f = s->fx = s->fy = 0;
    return;
  }
  double wx = grad && in ? b.ax : 0, wy = grad && in ? b.ay : 0;
  s->f = (1 - w) * a.f + w * b.f;
  s->fx = (1 - w) * a.fx + w * b.fx + wx * (b.f - a.f);
  s->fy = (1 - w) * a.fy + w * b.fy + wy * (b.f - a.f);
  if (lerp) {
    s->a = (1 - w) * a.a + w * w;
    s->ax = (1 - w) * a.ax - wx * a.a + 2 * w * wx;
    s->ay = (1 - w) * a.ay - wy * a.a + 2 * w * wy;
  } else {
    s->a = a.a;
    s->ax = a.ax;
    s->ay = a.ay;
  }
  if (!grad) s->fx = s->fy = s->ax = s->ay = 0;
}

/* Bounds from A's and B's over one region. */
static void replace_combine(const oc_enode *n, const oc_ebound *A,
                            const oc_ebound *B, int bmeets, oc_ebound *o) {
  int lerp = (n->flags & OC_EF_LERP) != 0;
  double wlo = bmeets ? oc_fmin(oc_fmax(B->alo, 0), 1) : 0;
  double whi = bmeets ? oc_fmin(oc_fmax(B->ahi, 0), 1) : 0;
  double law = bmeets ? B->la : 0;
  *o = *A;
  if (whi > 0) {
    o->flo = oc_fmin(A->flo, B->flo);
    o->fhi = oc_fmax(A->fhi, B->fhi);
    o->lf =
        oc_fmax(A->lf, B->lf) + law * oc_fmax(A->fhi - B->flo, B->fhi - A->flo);
  }
  if (lerp) {
    /* (1 - w) a + w^2 on [wlo, whi] x [alo, ahi]: convex in w */
    double v = oc_fmin(oc_fmax(A->alo / 2, wlo), whi);
    o->alo = oc_fmax(0, (1 - v) * A->alo + v * v);
    o->ahi =
        oc_fmax((1 - wlo) * A->ahi + wlo * wlo, (1 - whi) * A->ahi + whi * whi);
    o->la = A->la + law * (A->ahi + 2 * whi);
  }
}

static oc_enode *binary(oc_ekind kind, oc_enode *a, oc_enode *b, size_t size,
                        oc_error *err) {
  if (!a || !b) {
    oc_seterr(err, OC_EINVAL, "%s needs two elevation nodes",
              kind == OC_E_REPLACE ? "replace" : "add");
    return NULL;
  }
  oc_enode *k[2] = {a, b};
  return oc_enode_alloc(kind, size, k, 2, err);
}

/* Stores a binary operator's bound and box from its children's. */
static void store_binary(oc_enode *n, const oc_enode *a, const oc_enode *b) {
  oc_ebound kb[2];
  oc_erect kbox[2] = {oc_enode_box(a), oc_enode_box(b)};
  oc_enode_glob(a, &kb[0]);
  oc_enode_glob(b, &kb[1]);
  store_derived(n, kb, kbox);
}

oc_enode *oc_enode_replace(oc_enode *a, oc_enode *b, int lerp, oc_error *err) {
  oc_enode *n = binary(OC_E_REPLACE, a, b, offsetof(oc_ebin, par), err);
  if (!n) return NULL;
  n->flags |= lerp ? OC_EF_LERP : 0;
  store_binary(n, a, b);
  return n;
}

/* ---- add -------------------------------------------------------------- */

/* The altitude weight: 1 below below_z - fade, 0 above below_z, the C1
** smoothstep between; its derivative in *d. */
static double below_w(const double *par, double z, double *d) {
  double t = (par[P_BZ] - z) / par[P_FADE];
  if (t <= 0 || t >= 1) {
    *d = 0;
    return t >= 1 ? 1 : 0;
  }
  *d = -6 * t * (1 - t) / par[P_FADE];
  return t * t * (3 - 2 * t);
}

/* The altitude weight W(t), t = (below_z - f_A) / fade, over a region
** where f_A lies in [A->flo, A->fhi]: t in [tlo, thi] (padded for the
** rounding of t), W nondecreasing in t, so W <= W(thi), the return value;
** and |dW/df_A| = 6 t (1 - t) / fade, largest at t = 1/2, so at most its
** value at the point of [tlo, thi] nearest 1/2 (0 where the interval
** misses (0, 1)), in *dw. With w = c W (c = clamp(alpha_B) <= chi),
** |grad w| <= |grad c| W + c |dW/df_A| |grad f_A| <= lambda_c W(thi) +
** chi *dw lambda_A: the 1.5 / fade lambda_A of the whole plane, times the
** weight of B and the altitude weight's slope where f_A can be. */
static double below_w_hi(double bz, double fade, const oc_ebound *A,
                         double *dw) {
  double pad =
      1e-9 * (1 + (fabs(bz) + fmax(fabs(A->flo), fabs(A->fhi))) / fade);
  double a = fmax((bz - A->fhi) / fade - pad, 0);
  double b = fmin((bz - A->flo) / fade + pad, 1);
  double d = 0;
  if (a <= b) { /* (else t stays out of (0, 1): W is constant) */
    double t = b < 0.5 ? b : a > 0.5 ? a : 0.5;
    d = 6 * t * (1 - t) / fade * (1 + 1e-12);
  }
  *dw = d;
  if (!(b < 1)) return 1;
  return b <= 0 ? 0 : fmin(1, b * b * (3 - 2 * b) * (1 + 1e-12));
}

/* An add's parameters (enode.h): the altitude weight's, and the slope
** weight's after them, with its step. */
static const double *add_below(const oc_enode *n) {
  return OC_EBIN(n)->par;
}
static const double *add_slope(const oc_enode *n) {
  return OC_EBIN(n)->par + (n->flags & OC_EF_BELOW ? 2 : 0);
}
static double add_step(const oc_enode *n) {
  const double *q = add_slope(n) + 2;
  if (!(n->flags & OC_EF_STEPF)) return *q;
  float f;
  memcpy(&f, q, sizeof f);
  return f;
}

/* The slope weight (Génevaux et al. 2015, section 5: an add weighted by
** the slope of A). A's slope is measured by central differences of f_A
** over the step h,
**
**   D = (f_A(p + h e_x) - f_A(p - h e_x), f_A(p + h e_y) - f_A(p - h e_y))
**       / (2 h),   theta = atan |D|,
**
** and the weight is 1 where theta <= theta0, 0 where theta >= theta0 +
** phi, 1 - smoothstep((theta - theta0) / phi) between. Measured so, the
** weight is a C1 function of the values of f_A at four points, whose
** exact gradient needs only the gradients of f_A there (no second
** derivatives), and whose slope is bounded by A's own bounds: each
** component of D is lambda_A / h Lipschitz (lambda_A over the box grown by
** h), so |D| is sqrt(2) lambda_A / h Lipschitz, and |dW/d|D|| <= 1.5 / phi
** cos^2 theta0 (the smoothstep's slope 1.5 / phi times atan' = 1 / (1 +
** |D|^2), which is below cos^2 theta0 wherever the weight is not 1). As h
** goes to 0, theta is the slope angle of A. The gradient of W in *wx,
** *wy (want: OC_EV_GRAD or 0). */
static double slope_w(const oc_enode *n, const oc_enode *A, double x, double y,
                      const oc_efoot *ft, int want, double *wx, double *wy) {
  const double *par = add_slope(n);
  double h = add_step(n);
  oc_enode_sample e, w, no, so;
  /* every f is needed, also where alpha_A = 0: no OC_EV_LAZY; the
  ** footprint is p's, so each term is a function of p whose gradient the
  ** child includes */
  oc_enode_ev(A, x + h, y, ft, want, &e);
  oc_enode_ev(A, x - h, y, ft, want, &w);
  oc_enode_ev(A, x, y + h, ft, want, &no);
  oc_enode_ev(A, x, y - h, ft, want, &so);
  double dx = (e.f - w.f) / (2 * h), dy = (no.f - so.f) / (2 * h);
  double s2 = dx * dx + dy * dy, s = sqrt(s2);
  double t = (atan(s) - par[P_SLOPE]) / par[P_SFADE];
  *wx = *wy = 0;
  if (!(t > 0)) return t == t ? 1 : NAN;
  if (t >= 1) return 0;
  if (want & OC_EV_GRAD) {
    /* dW/ds / s, then grad s = (dx grad dx + dy grad dy) / s */
    double k = -6 * t * (1 - t) / par[P_SFADE] / (1 + s2) / s;
    double i2h = 1 / (2 * h);
    double xx = (e.fx - w.fx) * i2h, xy = (e.fy - w.fy) * i2h;
    double yx = (no.fx - so.fx) * i2h, yy = (no.fy - so.fy) * i2h;
    *wx = k * (dx * xx + dy * yx);
    *wy = k * (dx * xy + dy * yy);
  }
  return 1 - t * t * (3 - 2 * t);
}

static void add_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                   int want, oc_enode_sample *s) {
  int grad = want & OC_EV_GRAD, in;
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  oc_enode_sample a, b;
  int sumw = (n->flags & OC_EF_SUMW) != 0;
  if (want & OC_EV_ALPHA) { /* alpha_A, or plus w_B^2 */
    oc_enode_ev(A, x, y, ft, OC_EV_ALPHA, &a);
    s->a = a.a;
    if (sumw) {
      b.a = 0;
      if (oc_enode_holds(B, x, y)) oc_enode_ev(B, x, y, ft, OC_EV_ALPHA, &b);
      double c = clamp01(b.a, &in);
      s->a += c * c;
    }
    return;
  }
  /* alpha_A + w^2 may be > 0 where alpha_A = 0: then f_A is needed */
  oc_enode_ev(A, x, y, ft, sumw ? grad : want, &a);
  if (want & OC_EV_LAZY && a.a == 0 && !sumw) {
    *s = a;
    return;
  }
  b.a = b.f = b.fx = b.fy = b.ax = b.ay = 0;
  if (oc_enode_holds(B, x, y)) oc_enode_ev(B, x, y, ft, grad | OC_EV_LAZY, &b);
  double c = clamp01(b.a, &in), cx = grad && in ? b.ax : 0,
         cy = grad && in ? b.ay : 0;
  double w = c, wx = cx, wy = cy;
  if (n->flags & OC_EF_BELOW) {
    double dW, W = below_w(add_below(n), a.f, &dW);
    w = c * W;
    wx = cx * W + c * dW * a.fx;
    wy = cy * W + c * dW * a.fy;
  }
  /* where w = 0 its gradient is 0 too (c and the altitude weight reach
  ** 0 with slope 0): the slope weight is not needed there */
  if ((n->flags & OC_EF_SLOPE) && w != 0) {
    double Sx, Sy, S = slope_w(n, A, x, y, ft, grad, &Sx, &Sy);
    wx = wx * S + w * Sx;
    wy = wy * S + w * Sy;
    w *= S;
  }
  s->f = a.f + w * b.f;
  s->fx = a.fx + wx * b.f + w * b.fx;
  s->fy = a.fy + wy * b.f + w * b.fy;
  s->a = sumw ? a.a + c * c : a.a;
  s->ax = sumw ? a.ax + 2 * c * cx : a.ax;
  s->ay = sumw ? a.ay + 2 * c * cy : a.ay;
  if (!grad) s->fx = s->fy = s->ax = s->ay = 0;
}

/* lah: A's Lipschitz bound over the region grown by the slope step (for
** the slope weight; unused without it). */
static void add_combine(const oc_enode *n, const oc_ebound *A,
                        const oc_ebound *B, int bmeets, double lah,
                        oc_ebound *o) {
  double clo = bmeets ? oc_fmin(oc_fmax(B->alo, 0), 1) : 0;
  double chi = bmeets ? oc_fmin(oc_fmax(B->ahi, 0), 1) : 0;
  double lc = bmeets ? B->la : 0;
  *o = *A;
  /* the altitude weight is 0 on the region where f_A >= below_z, 1
  ** where f_A <= below_z - fade (with a hair for the rounding of t) */
  const double *par = add_below(n), *sp = add_slope(n);
  int below = (n->flags & OC_EF_BELOW) != 0;
  double bz = below ? par[P_BZ] : 0, fade = below ? par[P_FADE] : 1;
  double fchi = chi;
  if (below && A->flo >= bz) fchi = 0;
  if (below && A->fhi < bz - fade * (1 + 1e-9) - 1e-9 * fabs(bz)) below = 0;
  /* the slope weight is 1 on the region where |D| <= sqrt(2) lah stays
  ** below tan theta0 (with a hair for the rounding of D and atan) */
  int slope = (n->flags & OC_EF_SLOPE) != 0;
  double h = slope ? add_step(n) : 0, th0 = slope ? sp[P_SLOPE] : 0;
  slope = slope && !(sqrt(2.0) * lah * (1 + 1e-9) < tan(th0) * (1 - 1e-9));
  if (fchi > 0) {
    double wlo = clo, whi = fchi, lw = lc;
    if (below) {
      wlo = 0; /* the altitude weight may be 0 */
      double dw, Whi = below_w_hi(bz, fade, A, &dw);
      lw = lc * Whi + chi * dw * A->lf;
    }
    if (slope) {
      /* |D| <= sqrt(2) lah keeps t below tmax, where the smoothstep's
      ** slope 6 t (1 - t) is at most its value at tmax if tmax < 1/2 */
      double c0 = cos(th0), phi = sp[P_SFADE];
      double tmax = (atan(sqrt(2.0) * lah) - th0) / phi * (1 + 1e-9) + 1e-9;
      tmax = oc_fmax(tmax, 0);
      double ss = tmax < 0.5 ? 6 * tmax * (1 - tmax) : 1.5;
      wlo = 0;
      lw += ss * c0 * c0 / phi * sqrt(2.0) * lah / h * (1 + 1e-9);
    }
    /* w f_B with w in [wlo, whi] */
    double p[4] = {wlo * B->flo, wlo * B->fhi, whi * B->flo, whi * B->fhi};
    double plo = oc_fmin(oc_fmin(p[0], p[1]), oc_fmin(p[2], p[3]));
    double phi = oc_fmax(oc_fmax(p[0], p[1]), oc_fmax(p[2], p[3]));
    o->flo = A->flo + plo;
    o->fhi = A->fhi + phi;
    o->lf = A->lf + lw * oc_fmax(fabs(B->flo), fabs(B->fhi)) + whi * B->lf;
  }
  if (n->flags & OC_EF_SUMW) {
    o->alo = A->alo + clo * clo;
    o->ahi = A->ahi + chi * chi;
    o->la = A->la + 2 * chi * lc;
  }
}

/* Replace and add in box b: A's and (where its box meets b) B's bounds,
** combined by the operator. */
typedef void (*combine_fn)(const oc_enode *n, const oc_ebound *A,
                           const oc_ebound *B, int bmeets, oc_ebound *o);
static void binary_bound_in(const oc_enode *n, const oc_erect *b,
                            const oc_efootb *fb, combine_fn combine,
                            oc_ebound *o) {
  oc_ebound A, B;
  const oc_ebin *bn = OC_EBIN(n);
  oc_enode_bnd(bn->kids[0], b, fb, &A);
  int meets = oc_enode_meets(bn->kids[1], b);
  if (meets) oc_enode_bnd(bn->kids[1], b, fb, &B);
  combine(n, &A, &B, meets, o);
}

/* Add in box b: as binary_bound_in, with A's slope over b grown by the
** slope weight's step where that weight counts. */
static void add_bound_in(const oc_enode *n, const oc_erect *b,
                         const oc_efootb *fb, oc_ebound *o) {
  oc_ebound A, B, G;
  const oc_ebin *bn = OC_EBIN(n);
  oc_enode_bnd(bn->kids[0], b, fb, &A);
  int meets = oc_enode_meets(bn->kids[1], b);
  if (meets) oc_enode_bnd(bn->kids[1], b, fb, &B);
  double lah = 0;
  /* A's slope over the stencil's reach, where the slope weight counts */
  if ((n->flags & OC_EF_SLOPE) && meets && B.ahi > 0 &&
      !(n->flags & OC_EF_BELOW && A.flo >= add_below(n)[P_BZ])) {
    double h = add_step(n);
    oc_erect g = {b->x0 - h, b->y0 - h, b->x1 + h, b->y1 + h};
    oc_enode_bnd(bn->kids[0], &g, fb, &G);
    lah = G.lf;
  }
  add_combine(n, &A, &B, meets, lah, o);
}

oc_enode *oc_enode_add(oc_enode *a, oc_enode *b, const oc_enode_add_params *p,
                       oc_error *err) {
  oc_enode_add_params d = {0, 0, 0, 0, 0, 0, 0, 0};
  if (!p) p = &d;
  double step = p->slope_step == 0 ? 5 : p->slope_step;
  if (p->slope) {
    if (!(p->slope_deg >= 0 && p->slope_deg < 90)) {
      oc_seterr(err, OC_EINVAL,
                "'slope' must be an angle in degrees in [0, 90) (got %g)",
                p->slope_deg);
      return NULL;
    }
    if (!(isfinite(p->slope_fade) && p->slope_fade > 0)) {
      oc_seterr(err, OC_EINVAL,
                "'slope_fade' must be a positive angle in degrees (got %g)",
                p->slope_fade);
      return NULL;
    }
    if (!(isfinite(step) && step > 0)) {
      oc_seterr(err, OC_EINVAL,
                "'slope_step' must be a positive number (got %g)",
                p->slope_step);
      return NULL;
    }
  }
  if (p->below) {
    if (!isfinite(p->below_z)) {
      oc_seterr(err, OC_EINVAL, "'below' must be a finite number (got %g)",
                p->below_z);
      return NULL;
    }
    if (!(isfinite(p->fade) && p->fade > 0)) {
      oc_seterr(err, OC_EINVAL, "'fade' must be a positive number (got %g)",
                p->fade);
      return NULL;
    }
  }
  int flags = (p->sum_weight ? OC_EF_SUMW : 0) | (p->below ? OC_EF_BELOW : 0) |
              (p->slope ? OC_EF_SLOPE : 0) |
              (p->slope && (double)(float)step == step ? OC_EF_STEPF : 0);
  oc_enode *n = binary(OC_E_ADD, a, b, oc_eadd_size(flags), err);
  if (!n) return NULL;
  n->flags |= (uint8_t)flags;
  double *par = ((oc_ebin *)n)->par;
  if (p->below) par[P_BZ] = p->below_z, par[P_FADE] = p->fade;
  if (p->slope) {
    double *sp = par + (p->below ? 2 : 0);
    sp[P_SLOPE] = p->slope_deg * DEG;
    sp[P_SFADE] = p->slope_fade * DEG;
    if (flags & OC_EF_STEPF) {
      float f = (float)step;
      memcpy(sp + 2, &f, sizeof f);
    } else {
      sp[2] = step;
    }
  }
  store_binary(n, a, b);
  return n;
}

/* ---- affine transforms ------------------------------------------------ */

/* The footprint in the child's units: foot(M p' + t) / s, whose
** gradient in p' is R^T grad foot = s Minv grad foot (m = Minv); NULL
** stays NULL. */
static const oc_efoot *xform_foot(const oc_enode *n, const double m[4],
                                  const oc_efoot *ft, oc_efoot *cf) {
  if (!ft) return NULL;
  double sc = OC_EUN(n)->par[P_SCALE];
  cf->v = ft->v * (1 / sc);
  cf->gx = sc * (m[0] * ft->gx + m[1] * ft->gy);
  cf->gy = sc * (m[2] * ft->gx + m[3] * ft->gy);
  return cf;
}

/* Footprints over a region, in the child's units: a similarity keeps the
** footprint's Lipschitz bound, in any units. */
static const oc_efootb *xform_footb(const oc_enode *n, const oc_efootb *fb,
                                    oc_efootb *cf) {
  if (!fb) return NULL;
  double is = 1 / OC_EUN(n)->par[P_SCALE];
  *cf = (oc_efootb){fb->lo * is, fb->hi * is, fb->k};
  return cf;
}

static void xform_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                     int want, oc_enode_sample *s) {
  const double *par = OC_EUN(n)->par;
  double m[4];
  minv(n, m);
  double u = x - par[P_TX], v = y - par[P_TY];
  oc_enode_sample c;
  oc_efoot cf;
  const oc_efoot *cft = xform_foot(n, m, ft, &cf);
  oc_enode_ev(OC_EUN(n)->kid, m[0] * u + m[1] * v, m[2] * u + m[3] * v, cft,
              want, &c);
  double vs = par[P_VS];
  s->a = c.a;
  if (want & OC_EV_ALPHA) return;
  if (want & OC_EV_LAZY && c.a == 0)
    s->f = 0;
  else
    s->f = vs * c.f + par[P_VO];
  /* grad = Minv^T grad_child */
  s->fx = vs * (m[0] * c.fx + m[2] * c.fy);
  s->fy = vs * (m[1] * c.fx + m[3] * c.fy);
  s->ax = m[0] * c.ax + m[2] * c.ay;
  s->ay = m[1] * c.ax + m[3] * c.ay;
}

/* The box of the image of rectangle r under p -> M p + t (fwd) or
** Minv (p - t) (inverse). */
static oc_erect map_rect(const oc_enode *n, const oc_erect *r, int inverse) {
  double xs[2] = {r->x0, r->x1}, ys[2] = {r->y0, r->y1};
  oc_erect o = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  const double *par = OC_EUN(n)->par;
  double mi[4];
  minv(n, mi);
  double s = par[P_SCALE];
  /* M = s^2 Minv^T for a similarity: Minv = R^T / s, M = s R */
  double m[4] = {mi[0] * s * s, mi[2] * s * s, mi[1] * s * s, mi[3] * s * s};
  for (int a = 0; a < 2; a++)
    for (int b = 0; b < 2; b++) {
      double u, v;
      if (inverse) {
        double px = xs[a] - par[P_TX], py = ys[b] - par[P_TY];
        u = mi[0] * px + mi[1] * py;
        v = mi[2] * px + mi[3] * py;
      } else {
        u = m[0] * xs[a] + m[1] * ys[b] + par[P_TX];
        v = m[2] * xs[a] + m[3] * ys[b] + par[P_TY];
      }
      o.x0 = fmin(o.x0, u);
      o.x1 = fmax(o.x1, u);
      o.y0 = fmin(o.y0, v);
      o.y1 = fmax(o.y1, v);
    }
  /* rounding of the map: a relative hair */
  double pad = 1e-12 * (fabs(o.x0) + fabs(o.x1) + fabs(o.y0) + fabs(o.y1));
  o.x0 -= pad, o.y0 -= pad, o.x1 += pad, o.y1 += pad;
  return o;
}

static void xform_map_bound(const oc_enode *n, const oc_ebound *c,
                            oc_ebound *o) {
  const double *par = OC_EUN(n)->par;
  double vs = par[P_VS], vo = par[P_VO], is = 1 / par[P_SCALE];
  double a = vs * c->flo + vo, b = vs * c->fhi + vo;
  *o = *c;
  o->flo = fmin(a, b);
  o->fhi = fmax(a, b);
  o->lf = fabs(vs) * c->lf * is;
  o->la = c->la * is;
}

static void xform_bound_in(const oc_enode *n, const oc_erect *b,
                           const oc_efootb *fb, oc_ebound *o) {
  oc_erect r = map_rect(n, b, 1);
  oc_ebound c;
  oc_efootb cf;
  oc_enode_bnd(OC_EUN(n)->kid, &r, xform_footb(n, fb, &cf), &c);
  xform_map_bound(n, &c, o);
}

oc_enode *oc_enode_transform(oc_enode *e, const oc_enode_xform *x,
                             oc_error *err) {
  if (!e || !x) {
    oc_seterr(err, OC_EINVAL, "transform needs an elevation node");
    return NULL;
  }
  double s = x->scale == 0 ? 1 : x->scale, vs = x->vscale == 0 ? 1 : x->vscale;
  if (!isfinite(x->tx) || !isfinite(x->ty)) {
    oc_seterr(err, OC_EINVAL, "'translate' must have finite coordinates");
    return NULL;
  }
  if (!isfinite(x->angle)) {
    oc_seterr(err, OC_EINVAL, "'rotate' must be a finite number (got %g)",
              x->angle);
    return NULL;
  }
  if (!(isfinite(s) && s > 0 && isfinite(1 / s))) {
    oc_seterr(err, OC_EINVAL, "'scale' must be a positive number (got %g)",
              x->scale);
    return NULL;
  }
  if (!(isfinite(vs) && isfinite(x->voffset))) {
    oc_seterr(err, OC_EINVAL,
              "'vscale' and 'voffset' must be finite numbers (got %g, %g)",
              x->vscale, x->voffset);
    return NULL;
  }
  /* concatenate with a transform below: p = s R p' + t, p' = s' R' p'' +
  ** t', so p = s s' R R' p'' + (s R t' + t) */
  double ang = x->angle, tx = x->tx, ty = x->ty, vo = x->voffset;
  oc_enode *child = e;
  if (e->kind == OC_E_XFORM) {
    const double *ep = OC_EUN(e)->par;
    double s2 = ep[P_SCALE];
    double c1 = cos(ang * DEG), s1 = sin(ang * DEG);
    double t2x = ep[P_TX], t2y = ep[P_TY];
    tx += s * (c1 * t2x - s1 * t2y);
    ty += s * (s1 * t2x + c1 * t2y);
    vo += vs * ep[P_VO];
    vs *= ep[P_VS];
    s *= s2;
    ang += ep[P_ANGLE];
    child = OC_EUN(e)->kid;
  }
  if (!(isfinite(s) && s > 0 && isfinite(1 / s) && isfinite(tx) &&
        isfinite(ty) && isfinite(vs) && vs != 0 && isfinite(vo))) {
    oc_seterr(err, OC_EINVAL, "transform: the composed transform overflows");
    return NULL;
  }
  oc_enode *n = oc_enode_alloc(
      OC_E_XFORM, offsetof(oc_eun, par) + OC_EXFORM_NPAR * sizeof(double),
      &child, 1, err);
  if (!n) return NULL;
  double th = ang * DEG, c = cos(th), sn = sin(th);
  double *par = ((oc_eun *)n)->par;
  /* Minv = R^T / s: its first row (its second is minv's) */
  par[P_MI + 0] = c / s;
  par[P_MI + 1] = sn / s;
  par[P_TX] = tx;
  par[P_TY] = ty;
  par[P_VS] = vs;
  par[P_VO] = vo;
  par[P_SCALE] = s;
  par[P_ANGLE] = ang;
  oc_erect cbox = oc_enode_box(child), box = map_rect(n, &cbox, 0);
  oc_erect_round(&box, &((oc_eun *)n)->box);
  return n;
}

/* ---- warp ------------------------------------------------------------- */

/* delta(p) = A sum_k 2^-k (eta_1, eta_2)(2^k p / wl); with jac, its
** Jacobian rows. */
static void warp_delta(const oc_enode *n, double x, double y, double d[2],
                       double jac[4]) {
  const double *par = OC_EUN(n)->par;
  double a = par[P_WAMP], s = 1 / par[P_WWL];
  uint64_t nzseed;
  memcpy(&nzseed, &par[P_WSEED], sizeof nzseed);
  d[0] = d[1] = 0;
  if (jac) jac[0] = jac[1] = jac[2] = jac[3] = 0;
  for (int k = 0; k < n->octaves; k++) {
    for (int c = 0; c < 2; c++) {
      double g[2];
      uint64_t seed =
          oc_mix64(nzseed + 0x9e3779b97f4a7c15ull * (uint64_t)(2 * k + c + 1));
      d[c] += a * oc_eta(seed, x * s, y * s, jac ? g : NULL);
      if (jac) {
        jac[2 * c] += a * s * g[0];
        jac[2 * c + 1] += a * s * g[1];
      }
    }
    a *= 0.5;
    s *= 2;
  }
}

static void warp_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                    int want, oc_enode_sample *s) {
  int grad = want & OC_EV_GRAD;
  double d[2], J[4];
  warp_delta(n, x, y, d, grad ? J : NULL);
  oc_enode_sample c;
  /* the footprint is a function of p: in q = p + delta(p) its gradient
  ** is (I + J)^-T grad foot (I + J is invertible: |J| < 1) */
  oc_efoot cf, *cft = NULL;
  if (ft) {
    cf = (oc_efoot){ft->v, 0, 0};
    if (grad) {
      double a = 1 + J[0], b = J[1], c2 = J[2], e = 1 + J[3];
      double det = a * e - b * c2;
      cf.gx = (e * ft->gx - c2 * ft->gy) / det;
      cf.gy = (-b * ft->gx + a * ft->gy) / det;
    }
    cft = &cf;
  }
  oc_enode_ev(OC_EUN(n)->kid, x + d[0], y + d[1], cft, want, &c);
  *s = c;
  if (!grad) return;
  /* grad = (I + J)^T grad_child */
  s->fx = c.fx + J[0] * c.fx + J[2] * c.fy;
  s->fy = c.fy + J[1] * c.fx + J[3] * c.fy;
  s->ax = c.ax + J[0] * c.ax + J[2] * c.ay;
  s->ay = c.ay + J[1] * c.ax + J[3] * c.ay;
}

static void warp_bound_in(const oc_enode *n, const oc_erect *b,
                          const oc_efootb *fb, oc_ebound *o) {
  double m = OC_EUN(n)->par[P_WMAX], l = OC_EUN(n)->par[P_WLIP];
  oc_erect r = {b->x0 - m, b->y0 - m, b->x1 + m, b->y1 + m};
  /* the inverse of p -> p + delta(p) is 1 / (1 - l) Lipschitz */
  oc_efootb cf, *cfb = NULL;
  if (fb) {
    cf = (oc_efootb){fb->lo, fb->hi, fb->k / (1 - l)};
    cfb = &cf;
  }
  oc_enode_bnd(OC_EUN(n)->kid, &r, cfb, o);
  o->lf *= 1 + l;
  o->la *= 1 + l;
}

oc_enode *oc_enode_warp(oc_enode *e, const oc_enode_warp_params *p,
                        oc_error *err) {
  if (!e || !p) {
    oc_seterr(err, OC_EINVAL, "warp needs an elevation node");
    return NULL;
  }
  if (!(isfinite(p->amplitude) && p->amplitude >= 0)) {
    oc_seterr(err, OC_EINVAL,
              "'amplitude' must be a finite number >= 0 (got %g)",
              p->amplitude);
    return NULL;
  }
  if (!(isfinite(p->wavelength) && p->wavelength > 0)) {
    oc_seterr(err, OC_EINVAL, "'wavelength' must be a positive number (got %g)",
              p->wavelength);
    return NULL;
  }
  if (p->octaves < 1 || p->octaves > 16) {
    oc_seterr(err, OC_EINVAL, "'octaves' must be an integer in 1..16 (got %d)",
              p->octaves);
    return NULL;
  }
  /* each component's gradient is at most A lambda_eta / wl per octave
  ** (2^-k A times 2^k / wl); the Jacobian's norm at most sqrt(2) times */
  double lip = sqrt(2.0) * p->amplitude * 2 * oc_noise3_lipschitz * p->octaves /
               p->wavelength;
  double maxd = p->amplitude * (2 - ldexp(1.0, 1 - p->octaves));
  if (!(lip < 1)) {
    oc_seterr(err, OC_EINVAL,
              "warp: its Lipschitz bound %g is not below 1, so it may fold "
              "the plane (not a bijection): lower 'amplitude' below %g or "
              "raise 'wavelength'",
              lip, p->amplitude / lip);
    return NULL;
  }
  oc_enode *n = oc_enode_alloc(
      OC_E_WARP, offsetof(oc_eun, par) + OC_EWARP_NPAR * sizeof(double), &e, 1,
      err);
  if (!n) return NULL;
  double *par = ((oc_eun *)n)->par;
  n->octaves = (uint8_t)p->octaves;
  par[P_WMAX] = maxd;
  par[P_WLIP] = lip;
  par[P_WAMP] = p->amplitude;
  par[P_WWL] = p->wavelength;
  memcpy(&par[P_WSEED], &p->seed, sizeof p->seed);
  oc_ebound g;
  oc_erect cbox = oc_enode_box(e), box;
  oc_enode_glob(e, &g);
  oc_eop_derive(n, &g, &cbox, &g, &box);
  oc_erect_round(&box, &((oc_eun *)n)->box);
  return n;
}

/* ---- bounds over the plane ------------------------------------------- */

void oc_eop_derive(const oc_enode *n, const oc_ebound *kb, const oc_erect *kbox,
                   oc_ebound *glob, oc_erect *box) {
  switch (n->kind) {
  case OC_E_BLEND: {
    size_t nk = OC_EBLEND(n)->nkids;
    *box = kbox[0];
    for (size_t i = 0; i < nk; i++)
      *box = rect_union(*box, kbox[i]);
    /* over the whole plane, some points are outside every support */
    blend_combine(kb, nk, 1, glob);
    return;
  }
  case OC_E_REPLACE:
  case OC_E_ADD: {
    /* alpha may be > 0 where B alone is, with the summed or lerped
    ** weight */
    int both =
        (n->flags & (n->kind == OC_E_REPLACE ? OC_EF_LERP : OC_EF_SUMW)) != 0;
    *box = both ? rect_union(kbox[0], kbox[1]) : kbox[0];
    oc_ebound B = kb[1];
    B.alo = 0;
    if (n->kind == OC_E_REPLACE)
      replace_combine(n, &kb[0], &B, 1, glob);
    else /* (A's slope over the plane for the slope weight's) */
      add_combine(n, &kb[0], &B, 1, kb[0].lf, glob);
    return;
  }
  case OC_E_XFORM:
    *box = map_rect(n, &kbox[0], 0);
    xform_map_bound(n, &kb[0], glob);
    return;
  default: { /* warp */
    double maxd = OC_EUN(n)->par[P_WMAX], lip = OC_EUN(n)->par[P_WLIP];
    *box = (oc_erect){kbox[0].x0 - maxd, kbox[0].y0 - maxd, kbox[0].x1 + maxd,
                      kbox[0].y1 + maxd};
    *glob = kb[0];
    glob->lf *= 1 + lip;
    glob->la *= 1 + lip;
  }
  }
}

/* ---- rows (oc_enode_ev_row) -------------------------------------------- */

/* blend_ev without gradients, a row at a time: each child on the span of
** the row its box holds, the sums taken child by child as there. */
static void blend_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                         int want, double *f, double *a) {
  int only = want & OC_EV_ALPHA;
  double N[OC_EROW], S[OC_EROW], kf[OC_EROW], ka[OC_EROW];
  const oc_eblend *bl = OC_EBLEND(n);
  for (int m = 0; m < cnt; m++)
    N[m] = S[m] = 0;
  kid_iter it;
  kids_in(bl, x[0], y, x[cnt > 0 ? cnt - 1 : 0], y, &it);
  for (int w = 0; cnt > 0 && w < it.W; w++)
    for (uint64_t mk = kid_word(&it, w); mk; mk &= mk - 1) {
      const oc_enode *k = bl->kids[KID_INDEX(w, mk)];
      int i0, i1;
      oc_enode_row_span(k, x, y, cnt, &i0, &i1);
      if (i0 >= i1) continue;
      oc_enode_ev_row(k, x + i0, y, i1 - i0, OC_EV_LAZY | only, kf + i0,
                      ka + i0);
      for (int m = i0; m < i1; m++) {
        if (only) {
          S[m] += ka[m];
          continue;
        }
        if (ka[m] == 0) continue;
        N[m] += ka[m] * kf[m];
        S[m] += ka[m];
      }
    }
  for (int m = 0; m < cnt; m++) {
    a[m] = S[m];
    if (!only) f[m] = S[m] >= T ? N[m] / S[m] : N[m] / T;
  }
}

/* replace_ev without gradients, a row at a time. A is evaluated lazily
** only where the point would be (its f is not read where w >= 1). */
static void replace_ev_row(const oc_enode *n, const double *x, double y,
                           int cnt, int want, double *f, double *a) {
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  int lerp = (n->flags & OC_EF_LERP) != 0, in, i0, i1;
  double bf[OC_EROW], ba[OC_EROW], af[OC_EROW];
  int only = want & OC_EV_ALPHA;
  for (int m = 0; m < cnt; m++)
    ba[m] = bf[m] = 0;
  oc_enode_row_span(B, x, y, cnt, &i0, &i1);
  if (only) {
    oc_enode_ev_row(A, x, y, cnt, OC_EV_ALPHA, NULL, a);
    if (!lerp) return;
    if (i0 < i1)
      oc_enode_ev_row(B, x + i0, y, i1 - i0, OC_EV_ALPHA, NULL, ba + i0);
    for (int m = 0; m < cnt; m++) {
      double w = clamp01(ba[m], &in);
      a[m] = (1 - w) * a[m] + w * w;
    }
    return;
  }
  if (i0 < i1)
    oc_enode_ev_row(B, x + i0, y, i1 - i0, OC_EV_LAZY, bf + i0, ba + i0);
  int lazy = want & OC_EV_LAZY && !lerp;
  oc_enode_ev_row(A, x, y, cnt, lazy ? OC_EV_LAZY : 0, af, a);
  for (int m = 0; m < cnt; m++) {
    double w = clamp01(ba[m], &in), fa = w >= 1 ? 0 : af[m];
    if (lazy && a[m] == 0) {
      f[m] = 0;
      continue;
    }
    f[m] = (1 - w) * fa + w * bf[m];
    if (lerp) a[m] = (1 - w) * a[m] + w * w;
  }
}

int oc_eop_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                  int want, double *f, double *a) {
  if (n->kind == OC_E_BLEND)
    blend_ev_row(n, x, y, cnt, want, f, a);
  else if (n->kind == OC_E_REPLACE)
    replace_ev_row(n, x, y, cnt, want, f, a);
  else
    return 0;
  return 1;
}

/* ---- first-order models (etaylor.h) ------------------------------------
** Each returns 0 when it has no rule there (the caller then falls back to
** the node's box bound, oc_enode_taylor_flat). The values are computed as
** the evaluators compute them (the same bits). */

/* A blend's model being summed child by child (blend_taylor): N, sum a_k
** F_k + f_k A_k, S, the remainders' sum, and per child its f_k (or, out,
** the range of f_k) and alpha_k's remainder. */
typedef struct blendsum {
  double N, Nx, Ny, rest[3];
  oc_etay S;
  int m;
  double fk[TAY_KIDS], fhi[TAY_KIDS], ea[TAY_KIDS][3];
  unsigned char out[TAY_KIDS];
} blendsum;

/* No child summed yet (the arrays are filled as children come). */
static inline void blendsum_zero(blendsum *q) {
  q->N = q->Nx = q->Ny = q->rest[0] = q->rest[1] = q->rest[2] = 0;
  q->S = oc_etay_const(0);
  q->m = 0;
}

/* Adds child k, its models c (alpha_k(p) != 0 or its gradient not 0),
** to q; S too unless the caller summed it. */
static inline void blend_add(blendsum *q, const oc_enode *k,
                             const oc_etaylor *c, double x, double y, double R,
                             int add_s) {
  int m = q->m;
  if (oc_enode_holds(k, x, y) && c->a.v != 0)
    q->N += c->a.v * c->f.v; /* (ev) */
  q->Nx += c->a.v * c->f.gx + c->f.v * c->a.gx;
  q->Ny += c->a.v * c->f.gy + c->f.v * c->a.gy;
  if (add_s) oc_etay_add(&q->S, &c->a);
  double pa[3] = {c->a.e0, oc_etay_gnorm(&c->a) + c->a.e1, c->a.e2};
  double pf[3] = {c->f.e0, oc_etay_gnorm(&c->f) + c->f.e1, c->f.e2}, r[3];
  oc_etay_polymul(pa, pf, R, r);
  double ak = fabs(c->a.v);
  q->rest[0] += ak * c->f.e0 + r[0];
  q->rest[1] += ak * c->f.e1 + r[1];
  q->rest[2] += ak * c->f.e2 + r[2];
  q->fk[m] = c->f.v, q->out[m] = 0;
  q->ea[m][0] = c->a.e0, q->ea[m][1] = c->a.e1, q->ea[m][2] = c->a.e2;
  q->m = m + 1;
}

/* Adds child k whose alpha_k(p) = 0 (so grad alpha_k(p) = 0: alpha_k >= 0
** is C1), its model a not constant: alpha_k' (f_k' - f) is at most
** E_ak(r) sup|f_k - f|, f_k's range from its bound over the plane (no
** noise evaluated). */
static inline void blend_add_out(blendsum *q, const oc_enode *k,
                                 const oc_etay *a, int add_s) {
  int m = q->m;
  oc_ebound g;
  oc_enode_glob(k, &g);
  q->fk[m] = g.flo, q->fhi[m] = g.fhi, q->out[m] = 1;
  if (add_s) oc_etay_add(&q->S, a);
  q->ea[m][0] = a->e0, q->ea[m][1] = a->e1, q->ea[m][2] = a->e2;
  q->m = m + 1;
}

/* blend, f = N / S where S = sum alpha_k >= T on the whole disc: with
** f the value at p, N' - f S' = sum alpha_k' (f_k' - f) and, writing each
** child's alpha_k' = a_k + A_k.d + x_k, f_k' = f_k + F_k.d + y_k, this is
** (sum a_k F_k + (f_k - f) A_k).d + Q = S G.d + Q with G the linear part
** below and |Q| <= sum a_k E_fk + |f_k - f| E_ak + (|A_k| r + E_ak)(|F_k|
** r + E_fk) (sum a_k (f_k - f) = 0). Then f' - f - G.d = (S G.d + Q) / S'
** - G.d = (Q - G.d (S' - S)) / S', at most (Q + |G| r (|A_S| r + E_S)) /
** inf S'. Where S <= T on the whole disc f = N / T, N the sum of the
** products alpha_k f_k (product rule, etaylor.h). */
static int blend_taylor(const oc_enode *n, double x, double y, double R,
                        const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  const oc_eblend *bl = OC_EBLEND(n);
  oc_erect ball = {x - R, y - R, x + R, y + R};
  blendsum q;
  blendsum_zero(&q);
  /* the children meeting the disc (alpha_k = 0 on it for the others) */
  const oc_enode *kk[TAY_KIDS];
  int discs, nk = kids_meeting(bl, &ball, kk, &discs);
  double gS = -1; /* |grad S| once known */
  int general = !(nk >= 0 && discs);
  if (!general) {
    /* discs: their weights' models first (no noise), so that a sum
    ** crossing T (no rule: the caller's fallback) costs no noise model;
    ** those that are 0 on the whole disc dropped. Then the others' f
    ** models, in the same order: S is the sum of the same models in the
    ** same order as the general rule's below. (Under a view too: 4.5 %
    ** of fig21's LoD blends cross T, after 4.6 % of its disc models. A
    ** disc without an LoD model there, the footprint reaching 0, sends
    ** the blend to the general rule, which has its fallback.) */
    oc_etay ka[TAY_KIDS];
    const oc_enode *kd[TAY_KIDS]; /* (kk kept for the general rule) */
    int na = 0;
    for (int i = 0; i < nk; i++) {
      oc_edisc_taylor_alpha(kk[i], x, y, R, &ka[na]);
      if (ka[na].v == 0 && oc_etay_is_const(&ka[na])) continue;
      oc_etay_add(&q.S, &ka[na]);
      kd[na++] = kk[i];
    }
    gS = oc_etay_gnorm(&q.S); /* (S is final: the same bits below) */
    double dev = gS * R + oc_etay_rem(&q.S, R); /* (oc_etay_dev) */
    if (!(q.S.v - dev >= T) && !(q.S.v + dev <= T)) return 0; /* (below) */
    for (int i = 0; i < na; i++) {
      oc_etaylor c;
      c.a = ka[i];
      if (c.a.v == 0 && c.a.gx == 0 && c.a.gy == 0) {
        blend_add_out(&q, kd[i], &c.a, 0);
        continue;
      }
      if (!tf) {
        oc_edisc_taylor_f(kd[i], x, y, R, &c.f);
      } else if (!oc_edisc_taylor_f_view(kd[i], x, y, R, tf, &c.f)) {
        general = 1;
        break;
      }
      blend_add(&q, kd[i], &c, x, y, R, 0);
    }
    if (general) { /* (afresh) */
      blendsum_zero(&q);
      gS = -1;
    }
  }
  if (general) {
    /* (beyond TAY_KIDS, nk < 0: the children again, one by one) */
    kid_iter it;
    int w = 0;
    uint64_t mk = 0;
    if (nk < 0) {
      kids_in(bl, ball.x0, ball.y0, ball.x1, ball.y1, &it);
      mk = kid_word(&it, 0);
    }
    for (int i = 0;; i++) {
      const oc_enode *k = nk >= 0 ? (i < nk ? kk[i] : NULL)
                                  : next_meeting(bl, &it, &ball, &w, &mk);
      if (!k) break;
      if (q.m == TAY_KIDS || oc_eop_taylor_partial(k)) return 0;
      oc_etaylor c;
      /* alpha_k's model first where it is cheap (no noise) */
      int have = oc_enode_taylor_alpha(k, x, y, R, &c.a, boxes);
      if (have && c.a.v == 0 && c.a.gx == 0 && c.a.gy == 0) {
        if (!oc_etay_is_const(&c.a)) blend_add_out(&q, k, &c.a, 1);
        continue;
      }
      /* a disc's f model alone (its alpha's model: c.a) */
      if (!(have && k->kind == OC_E_DISC &&
            oc_edisc_taylor_f_view(k, x, y, R, tf, &c.f)))
        oc_enode_taylor_view(k, x, y, R, tf, &c, boxes);
      if (c.a.v == 0 && oc_etay_is_const(&c.a)) continue;
      blend_add(&q, k, &c, x, y, R, 1);
    }
  }
  oc_etay S = q.S;
  int m = q.m;
  o->a = S;
  if (m == 0) {
    o->f = oc_etay_const(0);
    return 1;
  }
  if (gS < 0) gS = oc_etay_gnorm(&S);
  double dev = gS * R + oc_etay_rem(&S, R), Slo = S.v - dev; /* (dev) */
  int conv = Slo >= T; /* else S <= T on the whole disc, or no rule */
  if (!conv && !(S.v + dev <= T)) return 0; /* max(S, T) has a kink */
  double f = conv ? q.N / S.v : 0, Q[3] = {q.rest[0], q.rest[1], q.rest[2]};
  for (int j = 0; j < m; j++) {
    /* |f_k - f| (|f_k| where S <= T), or its bound for an outer child */
    double d =
        q.out[j] ? oc_fmax(q.fhi[j] - f, f - q.fk[j]) : fabs(q.fk[j] - f);
    if (q.out[j] && !conv) d = oc_fmax(fabs(q.fk[j]), fabs(q.fhi[j]));
    Q[0] += d * q.ea[j][0], Q[1] += d * q.ea[j][1], Q[2] += d * q.ea[j][2];
  }
  if (!conv) {
    o->f = (oc_etay){q.N / T, q.Nx / T, q.Ny / T, Q[0] / T, Q[1] / T, Q[2] / T};
    return 1;
  }
  double gx = (q.Nx - f * S.gx) / S.v, gy = (q.Ny - f * S.gy) / S.v;
  double g = sqrt(gx * gx + gy * gy);
  /* r (|A_S| r + E_S(r)), truncated at R */
  double P1 = S.e0, P2 = gS + S.e1 + R * S.e2;
  o->f = (oc_etay){
      f, gx, gy, Q[0] / Slo, (Q[1] + g * P1) / Slo, (Q[2] + g * P2) / Slo};
  return 1;
}

/* The flat model (no linear part) of psi = w (f_B - c) for a child B
** whose f bounds hold only where its weight is > 0 (oc_eop_taylor_partial), w =
** clamp(alpha_B), from B's bound Bb on the disc's box: psi is continuous,
** 0 where w = 0, and where w > 0 its gradient is at most lambda_w sup|f_B
** - c| + sup w lambda_B; so psi is Lipschitz with that on every segment
** (on each stretch where w > 0, by the mean value theorem, its ends being
** the segment's or points where psi = 0), and its values lie in the hull
** of 0 and [0, w_hi] [flo - c, fhi - c]. pv: psi at p. */
static oc_etay psi_flat(const oc_ebound *Bb, double c, double pv, double R) {
  double whi = oc_fmin(oc_fmax(Bb->ahi, 0), 1);
  double dlo = Bb->flo - c, dhi = Bb->fhi - c;
  double lip = Bb->la * oc_fmax(fabs(dlo), fabs(dhi)) + whi * Bb->lf;
  double lo = oc_fmin(0, whi * dlo), hi = oc_fmax(0, whi * dhi);
  return oc_etay_flat(pv, lip * (1 + 1e-12), oc_fmax(hi - pv, pv - lo), R);
}

/* w = clamp(alpha_B)'s model and, for a partial B, B's bound on the
** disc's box. 0: w = 0 on the whole disc. */
static int weight_taylor(const oc_enode *B, double x, double y, double R,
                         const oc_etfoot *tf, oc_etaylor *b, oc_etay *w,
                         oc_ebound *Bb, int *boxes) {
  oc_erect ball = {x - R, y - R, x + R, y + R};
  if (!oc_enode_meets(B, &ball)) return 0;
  if (oc_eop_taylor_partial(B)) {
    oc_enode_sample s;
    if (B->kind == OC_E_CURVE) {
      /* (its box bound and sample from one closest-point search; a
      ** curve has no level of detail: no footprints) */
      if (!oc_ecurve_weight_in(B, x, y, &ball, Bb, &s, boxes)) return 0;
    } else {
      oc_enode_bnd(B, &ball, tf ? &tf->b : NULL, Bb);
      (*boxes)++;
      if (!(Bb->ahi > 0)) return 0;
      /* (lazy: f may be 0 where alpha_B = 0, where w = 0 and psi = 0) */
      oc_enode_ev(B, x, y, tf ? &tf->p : NULL, OC_EV_LAZY, &s);
    }
    b->f = oc_etay_const(s.f);
    b->a = oc_etay_flat(s.a, Bb->la, oc_fmax(Bb->ahi - s.a, s.a - Bb->alo), R);
  } else if (B->kind == OC_E_DISC && !tf) {
    /* (a disc's weight first: no noise where w = 0 on the whole disc) */
    oc_edisc_taylor_alpha(B, x, y, R, &b->a);
    *w = oc_etay_clamp01(&b->a, R);
    if (w->v == 0 && oc_etay_is_const(w)) return 0;
    oc_edisc_taylor_f(B, x, y, R, &b->f);
    return 1;
  } else {
    oc_enode_taylor_view(B, x, y, R, tf, b, boxes);
  }
  *w = oc_etay_clamp01(&b->a, R);
  return !(w->v == 0 && oc_etay_is_const(w));
}

/* replace, f = f_A + w (f_B - f_A): the product rule on w and f_B - f_A;
** for a partial B, f = f_A + psi - w (f_A - c) with c = f_A(p) (psi_flat,
** and the product rule on w and f_A - c, whose value is 0). The lerped
** weight (1 - w) alpha_A + w^2 = alpha_A + w (w - alpha_A), by the
** product rule. */
static int replace_taylor(const oc_enode *n, double x, double y, double R,
                          const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  if (oc_eop_taylor_partial(A)) return 0;
  oc_etaylor a, b;
  oc_etay w;
  oc_ebound Bb;
  oc_enode_taylor_view(A, x, y, R, tf, &a, boxes);
  *o = a;
  if (!weight_taylor(B, x, y, R, tf, &b, &w, &Bb, boxes)) return 1;
  double fv = (1 - w.v) * a.f.v + w.v * b.f.v;
  if (oc_eop_taylor_partial(B)) {
    oc_etay psi = psi_flat(&Bb, a.f.v, w.v * (b.f.v - a.f.v), R);
    oc_etay d = a.f;
    d.v = 0;
    oc_etay wd = oc_etay_mul(&w, &d, R);
    wd = oc_etay_scale(&wd, -1);
    oc_etay_add(&o->f, &psi);
    oc_etay_add(&o->f, &wd);
  } else {
    oc_etay d = oc_etay_scale(&a.f, -1);
    oc_etay_add(&d, &b.f);
    oc_etay wd = oc_etay_mul(&w, &d, R);
    oc_etay_add(&o->f, &wd);
  }
  o->f.v = fv;
  if (n->flags & OC_EF_LERP) {
    oc_etay d = oc_etay_scale(&a.a, -1);
    oc_etay_add(&d, &w);
    oc_etay wd = oc_etay_mul(&w, &d, R);
    oc_etay_add(&o->a, &wd);
    o->a.v = (1 - w.v) * a.a.v + w.v * w.v;
  }
  return 1;
}

/* add, f = f_A + w f_B, w = clamp(alpha_B) times the altitude weight
** W(f_A) when there is one: W is C1 in f_A with |W''| <= 6 / fade^2
** (the smoothstep's second derivative 6 - 12 t over fade^2), so the
** composition rule holds, and W is constant where f_A's range on the
** disc keeps t out of (0, 1). alpha_A + w_B^2 by the product rule. A slope
** weight, or a partial child, has no rule. */
static int add_taylor(const oc_enode *n, double x, double y, double R,
                      const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  if (n->flags & OC_EF_SLOPE || oc_eop_taylor_partial(A) ||
      oc_eop_taylor_partial(B))
    return 0;
  oc_etaylor a, b;
  oc_etay c;
  oc_ebound Bb;
  oc_enode_taylor_view(A, x, y, R, tf, &a, boxes);
  *o = a;
  if (!weight_taylor(B, x, y, R, tf, &b, &c, &Bb, boxes)) return 1;
  oc_etay w = c;
  if (n->flags & OC_EF_BELOW) {
    const double *par = add_below(n);
    double bz = par[P_BZ], fade = par[P_FADE], dW;
    double W = below_w(par, a.f.v, &dW), dev = oc_etay_dev(&a.f, R);
    oc_etay Wm;
    if (a.f.v - dev >= bz)
      Wm = oc_etay_const(0);
    else if (a.f.v + dev < bz - fade * (1 + 1e-9) - 1e-9 * fabs(bz))
      Wm = oc_etay_const(1);
    else
      Wm = oc_etay_compose(&a.f, W, dW, 6 / (fade * fade) * (1 + 1e-9), R);
    Wm.v = W;
    w = oc_etay_mul(&c, &Wm, R);
    w.v = c.v * W;
  }
  oc_etay wf = oc_etay_mul(&w, &b.f, R);
  oc_etay_add(&o->f, &wf);
  o->f.v = a.f.v + w.v * b.f.v;
  if (n->flags & OC_EF_SUMW) {
    oc_etay cc = oc_etay_mul(&c, &c, R);
    oc_etay_add(&o->a, &cc);
    o->a.v = a.a.v + c.v * c.v;
  }
  return 1;
}

/* transform: the child's model at p' = Minv (p - t) for R / scale (|Minv
** d| = |d| / scale): f = vs f_c + vo, its linear part vs Minv^T F_c, its
** remainder |vs| E_c(r / scale). Under a view, with the footprints in
** the child's units (as evaluation and bounds map them). */
static int xform_taylor(const oc_enode *n, double x, double y, double R,
                        const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  const double *par = OC_EUN(n)->par;
  double m[4];
  minv(n, m);
  double u = x - par[P_TX], v = y - par[P_TY], is = 1 / par[P_SCALE];
  oc_etaylor c;
  oc_etfoot cf;
  double Rc = R * is * (1 + 1e-12);
  if (tf) {
    xform_foot(n, m, &tf->p, &cf.p);
    xform_footb(n, &tf->b, &cf.b);
    oc_etfoot_scaled(tf, R, par[P_SCALE], Rc, &cf);
  }
  oc_enode_taylor_view(OC_EUN(n)->kid, m[0] * u + m[1] * v, m[2] * u + m[3] * v,
                       Rc, tf ? &cf : NULL, &c, boxes);
  double vs = par[P_VS], k = fabs(vs), is2 = is * is;
  o->f = (oc_etay){vs * c.f.v + par[P_VO],
                   vs * (m[0] * c.f.gx + m[2] * c.f.gy),
                   vs * (m[1] * c.f.gx + m[3] * c.f.gy),
                   k * c.f.e0,
                   k * c.f.e1 * is,
                   k * c.f.e2 * is2};
  o->a = (oc_etay){c.a.v,
                   m[0] * c.a.gx + m[2] * c.a.gy,
                   m[1] * c.a.gx + m[3] * c.a.gy,
                   c.a.e0,
                   c.a.e1 * is,
                   c.a.e2 * is2};
  return 1;
}

/* alpha's model alone (no f, no noise): a blend's the sum of its
** children's, a transform's mapped, a replace's or add's A's (the lerped
** and summed weights have none: 0). */
int oc_eop_taylor_alpha(const oc_enode *n, double x, double y, double R,
                        oc_etay *a, int *boxes) {
  switch (n->kind) {
  case OC_E_BLEND: {
    const oc_eblend *bl = OC_EBLEND(n);
    oc_erect ball = {x - R, y - R, x + R, y + R};
    *a = oc_etay_const(0);
    kid_iter it;
    kids_in(bl, ball.x0, ball.y0, ball.x1, ball.y1, &it);
    const oc_enode *k;
    int w = 0;
    uint64_t mk = kid_word(&it, 0);
    while ((k = next_meeting(bl, &it, &ball, &w, &mk))) {
      oc_etay c;
      if (!oc_enode_taylor_alpha(k, x, y, R, &c, boxes)) return 0;
      oc_etay_add(a, &c);
    }
    return 1;
  }
  case OC_E_REPLACE:
    if (n->flags & OC_EF_LERP) return 0;
    return oc_enode_taylor_alpha(OC_EBIN(n)->kids[0], x, y, R, a, boxes);
  case OC_E_ADD:
    if (n->flags & OC_EF_SUMW) return 0;
    return oc_enode_taylor_alpha(OC_EBIN(n)->kids[0], x, y, R, a, boxes);
  case OC_E_XFORM: {
    const double *par = OC_EUN(n)->par;
    double m[4];
    minv(n, m);
    double u = x - par[P_TX], v = y - par[P_TY], is = 1 / par[P_SCALE];
    oc_etay c;
    if (!oc_enode_taylor_alpha(OC_EUN(n)->kid, m[0] * u + m[1] * v,
                               m[2] * u + m[3] * v, R * is * (1 + 1e-12), &c,
                               boxes))
      return 0;
    *a = (oc_etay){c.v,
                   m[0] * c.gx + m[2] * c.gy,
                   m[1] * c.gx + m[3] * c.gy,
                   c.e0,
                   c.e1 * is,
                   c.e2 * is * is};
    return 1;
  }
  default:
    return 0;
  }
}

int oc_eop_taylor(const oc_enode *n, double x, double y, double R,
                  const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  switch (n->kind) {
  case OC_E_BLEND:
    return blend_taylor(n, x, y, R, tf, o, boxes);
  case OC_E_REPLACE:
    return replace_taylor(n, x, y, R, tf, o, boxes);
  case OC_E_ADD:
    return add_taylor(n, x, y, R, tf, o, boxes);
  case OC_E_XFORM:
    return xform_taylor(n, x, y, R, tf, o, boxes);
  default:
    return 0; /* warp */
  }
}

/* ---- dispatch --------------------------------------------------------- */

void oc_eop_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
               int want, oc_enode_sample *s) {
  switch (n->kind) {
  case OC_E_BLEND:
    blend_ev(n, x, y, ft, want, s);
    return;
  case OC_E_REPLACE:
    replace_ev(n, x, y, ft, want, s);
    return;
  case OC_E_ADD:
    add_ev(n, x, y, ft, want, s);
    return;
  case OC_E_XFORM:
    xform_ev(n, x, y, ft, want, s);
    return;
  default:
    warp_ev(n, x, y, ft, want, s);
    return;
  }
}

void oc_eop_bound_in(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                     oc_ebound *o) {
  switch (n->kind) {
  case OC_E_BLEND:
    blend_bound_in(n, b, fb, o);
    return;
  case OC_E_REPLACE:
    binary_bound_in(n, b, fb, replace_combine, o);
    return;
  case OC_E_ADD:
    add_bound_in(n, b, fb, o);
    return;
  case OC_E_XFORM:
    xform_bound_in(n, b, fb, o);
    return;
  default:
    warp_bound_in(n, b, fb, o);
    return;
  }
}
