/*
** stabilize.c — stabilisation by the angle of repose (Peytavie et al.
** 2009, section 3.4): sand, then rocks (bottom-up), move from each stack
** to its 8 neighbours while the slope between them exceeds the material's
** angle of repose.
**
** For material m in a segment (the gap above a bedrock layer) of stack c,
** h is the top of m there (floor + sand, + rocks for rocks). Toward
** neighbour i, h_i is the top of the solid (floor + sand + rocks) of the
** neighbour's segment holding elevation h (none when h is inside the
** neighbour's bedrock); dh_i = h - h_i (the material goes downhill: the
** paper's extracted text prints hi - h), the excess dh~_i = dh_i - t_i
** when positive, t_i = s tan(alpha) for the 4 sides and s sqrt(2)
** tan(alpha) for the diagonals. The stack gives A = min(m present, rate
** max dh~_i), shared in proportion to dh~_i (the paper's a dh~_i /
** sum dh~_i), each share capped by an eighth of the air of the receiving
** segment (so 8 givers cannot overfill it). Repeated until no transfer
** exceeds the tolerance.
**
** Double-buffered and gathered: pass 1 computes, from the old state, each
** giver's factor A / sum dh~_i and its loss; pass 2 recomputes each
** share from the same old state at the receiver and sums its gains in a
** fixed order; only then is the state replaced. Every value is written by
** one thread from old values alone, so the result does not depend on the
** thread count, and every share is subtracted and added once: volume is
** conserved to rounding. Only stacks near the last changes are visited:
** the givers' box grown by 2 (the first pass: the region given).
**
** Multiresolution: the same passes run first with a stride k (8, 4 or 2),
** then with its halves down to 1, between a stack and its 8 neighbours k
** stacks away, with the
** thresholds k t_i and tolerance k times the given one. A coarse pass moves
** material k stacks at once, so a pile spreads over L stacks in about
** L / k passes instead of the L^2 / rate of a diffusion; the next finer
** level starts from every stack the coarser one changed, and the last
** (k = 1) alone decides the rest state, so every slope ends below the angle
** of repose as without the coarse levels. A stride only follows a slope
** down: each stack between holds elevation h in a segment whose solid top
** lies between the receiver's and h, so material never jumps over a wall,
** a bump or a gap. The first stride is the largest power of 2 up to 8
** with 8 k at most the extent of the box of the stacks that give at a
** first pass with k = 1: a coarse level leaves each of its k^2 sub-lattices a
*pile
** of its own, which the finer levels cannot gather back, so a small pile
** (a 75 m^3 one at cells of 0.5 m) spreads one or two strides wider than
** with k = 1 alone; it is then left to k = 1. The box depends on the
** material to move, not on the grid or the region given, so a window
** gives the stacks the whole grid gives. A 10^5 m^3 deposit on 1000 x 750
** stacks: 99 passes (first stride 8) instead of 5037.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "layers/layers.h"

static const int DX[8] = {1, -1, 0, 0, 1, 1, -1, -1};
static const int DY[8] = {0, 0, 1, -1, 1, -1, 1, -1};

typedef struct work {
  int nx, ny, q; /* q: OC_SEG_SAND or OC_SEG_ROCKS */
  int k;         /* stride: neighbours k stacks away */
  const oc_lseg *seg;
  const size_t *soff;
  double thr[2]; /* sides, diagonals */
  double rate;
  double *kf, *loss, *nxt; /* per segment */
} work;

static double src_h(const oc_lseg *c, int q) {
  return c->floor + c->a[OC_SEG_SAND] + (q == OC_SEG_ROCKS ? c->a[q] : 0);
}

static double solid_top(const oc_lseg *c) {
  return c->floor + c->a[OC_SEG_SAND] + c->a[OC_SEG_ROCKS];
}

static double air(const oc_lseg *c) {
  return c->cap - c->a[0] - c->a[1] - c->a[2];
}

/* The segment of stack n holding elevation h, or -1 (inside bedrock, or
** below the base). */
static long seg_at(const work *w, size_t n, double h) {
  size_t lo = w->soff[n], hi = w->soff[n + 1];
  while (lo < hi) {
    size_t m = (lo + hi) / 2;
    if (w->seg[m].floor <= h)
      lo = m + 1;
    else
      hi = m;
  }
  if (lo == w->soff[n]) return -1;
  const oc_lseg *c = &w->seg[lo - 1];
  return h < c->floor + c->cap ? (long)(lo - 1) : -1;
}

/* The excess dh~ of giver segment g of stack (i, j) toward direction d,
** its receiving segment in *t; 0 when nothing moves that way. */
static double excess(const work *w, int i, int j, size_t g, int d, long *t) {
  int k = w->k, ni = i + k * DX[d], nj = j + k * DY[d];
  if (ni < 0 || nj < 0 || ni >= w->nx || nj >= w->ny) return 0;
  double h = src_h(&w->seg[g], w->q);
  long r = seg_at(w, (size_t)nj * w->nx + ni, h);
  if (r < 0) return 0;
  double hr = solid_top(&w->seg[r]);
  double ex = h - hr - w->thr[d >= 4];
  if (!(ex > 0)) return 0;
  /* a stride over k stacks only down a slope: each stack between holds
  ** elevation h in a segment whose solid top lies in [hr, h] (no jump over
  ** a wall, a bump or a gap) */
  for (int m = 1; m < k; m++) {
    long b = seg_at(w, (size_t)(j + m * DY[d]) * w->nx + (i + m * DX[d]), h);
    if (b < 0) return 0;
    double hb = solid_top(&w->seg[b]);
    if (!(hb >= hr && hb <= h)) return 0;
  }
  *t = r;
  return ex;
}

static double share(const work *w, size_t g, double ex, long t) {
  double dz = w->kf[g] * ex, cap = air(&w->seg[t]) / 8;
  return dz < cap ? dz : cap;
}

typedef struct box {
  int i0, j0, i1, j1; /* inclusive; empty when i0 > i1 */
} box;

/* Passes over fewer stacks run on one thread: a pass over a pile's box
** (~10^4 stacks, ~1 ms) costs less than waking and joining the other
** thread on a loaded machine, where the wait is a scheduler's time
** slice. */
#define PAR_MIN 65536

static double area(box b) {
  return b.i0 > b.i1 || b.j0 > b.j1
             ? 0
             : (double)(b.i1 - b.i0 + 1) * (b.j1 - b.j0 + 1);
}

static box grow(box b, int by, int nx, int ny) {
  if (b.i0 > b.i1) return b;
  b.i0 = b.i0 - by < 0 ? 0 : b.i0 - by;
  b.j0 = b.j0 - by < 0 ? 0 : b.j0 - by;
  b.i1 = b.i1 + by >= nx ? nx - 1 : b.i1 + by;
  b.j1 = b.j1 + by >= ny ? ny - 1 : b.j1 + by;
  return b;
}

/* Pass 1 over the stacks of b: factors and losses; the box of givers in
** *giv, the largest share in *big, the row-ordered sum of losses in *sum. */
static void pass1(work *w, box b, box *giv, double *big, double *sum) {
  int nrow = b.j1 - b.j0 + 1;
  box *rb = malloc((size_t)(nrow > 0 ? nrow : 1) * sizeof *rb);
  double *rbig = calloc((size_t)(nrow > 0 ? nrow : 1), sizeof *rbig);
  double *rsum = calloc((size_t)(nrow > 0 ? nrow : 1), sizeof *rsum);
  *giv = (box){1, 1, 0, 0};
  *big = 0;
  *sum = 0;
  if (!rb || !rbig || !rsum) { /* (checked by the caller's allocation) */
    free(rb);
    free(rbig);
    free(rsum);
    *big = INFINITY;
    return;
  }
#pragma omp parallel for schedule(dynamic, 4) if (area(b) >= PAR_MIN)
  for (int j = b.j0; j <= b.j1; j++) {
    box r = {1, j, 0, j};
    double mx = 0, sm = 0;
    for (int i = b.i0; i <= b.i1; i++) {
      size_t k = (size_t)j * w->nx + i;
      for (size_t g = w->soff[k]; g < w->soff[k + 1]; g++) {
        w->kf[g] = w->loss[g] = 0;
        double amt = w->seg[g].a[w->q];
        if (!(amt > 0)) continue;
        double ex[8], tot = 0, top = 0;
        long t[8];
        for (int d = 0; d < 8; d++) {
          ex[d] = excess(w, i, j, g, d, &t[d]);
          tot += ex[d];
          top = fmax(top, ex[d]);
        }
        if (!(tot > 0)) continue;
        double A = fmin(amt, w->rate * top);
        w->kf[g] = A / tot;
        double loss = 0;
        for (int d = 0; d < 8; d++)
          if (ex[d] > 0) {
            double dz = share(w, g, ex[d], t[d]);
            loss += dz;
            mx = fmax(mx, dz);
          }
        w->loss[g] = loss;
        if (loss > 0) {
          sm += loss;
          if (r.i0 > r.i1) r.i0 = r.i1 = i;
          r.i1 = i;
        }
      }
    }
    rb[j - b.j0] = r;
    rbig[j - b.j0] = mx;
    rsum[j - b.j0] = sm;
  }
  for (int r = 0; r < nrow; r++) {
    *big = fmax(*big, rbig[r]);
    *sum += rsum[r];
    box x = rb[r];
    if (x.i0 > x.i1) continue;
    if (giv->i0 > giv->i1)
      *giv = x;
    else {
      giv->i0 = x.i0 < giv->i0 ? x.i0 : giv->i0;
      giv->i1 = x.i1 > giv->i1 ? x.i1 : giv->i1;
      giv->j1 = x.j1;
    }
  }
  free(rb);
  free(rbig);
  free(rsum);
}

/* Pass 2 over the stacks of b: the new amounts into nxt. */
static void pass2(work *w, box b) {
#pragma omp parallel for schedule(dynamic, 4) if (area(b) >= PAR_MIN)
  for (int j = b.j0; j <= b.j1; j++)
    for (int i = b.i0; i <= b.i1; i++) {
      size_t k = (size_t)j * w->nx + i;
      for (size_t g = w->soff[k]; g < w->soff[k + 1]; g++)
        w->nxt[g] = w->seg[g].a[w->q] - w->loss[g];
      for (int d = 0; d < 8; d++) {
        int ni = i - w->k * DX[d], nj = j - w->k * DY[d]; /* gives toward d */
        if (ni < 0 || nj < 0 || ni >= w->nx || nj >= w->ny) continue;
        size_t n = (size_t)nj * w->nx + ni;
        for (size_t g = w->soff[n]; g < w->soff[n + 1]; g++) {
          if (!(w->kf[g] > 0)) continue;
          long t;
          double ex = excess(w, ni, nj, g, d, &t);
          if (ex > 0) w->nxt[t] += share(w, g, ex, t);
        }
      }
    }
}

/* The coarsest stride, and the extent of the givers (in strides) below
** which a stride is not used (see the top of the file). */
#define STRIDE_TOP OC_LAYERS_STRIDE_MAX
#define STRIDE_SPAN 8

static box box_union(box a, box b) {
  if (a.i0 > a.i1) return b;
  if (b.i0 > b.i1) return a;
  return (box){a.i0 < b.i0 ? a.i0 : b.i0, a.j0 < b.j0 ? a.j0 : b.j0,
               a.i1 > b.i1 ? a.i1 : b.i1, a.j1 > b.j1 ? a.j1 : b.j1};
}

int oc_layers_stabilize_segs(oc_stacks *s, oc_lseg *seg, const size_t *soff,
                             const oc_stabilize_params *p,
                             oc_stabilize_result *res, oc_error *err) {
  static const int MATS[2] = {OC_MAT_SAND, OC_MAT_ROCKS};
  size_t ns = (size_t)s->nx * s->ny, nseg = soff[ns];
  oc_stabilize_result r = {0, 1, 0};
  work w = {s->nx, s->ny, 0, 1, seg, soff, {0, 0}, p->rate, NULL, NULL, NULL};
  w.kf = calloc(3 * nseg, sizeof *w.kf);
  if (!w.kf) return oc_seterr(err, OC_ENOMEM, "out of memory");
  w.loss = w.kf + nseg;
  w.nxt = w.loss + nseg;
  box all = {0, 0, s->nx - 1, s->ny - 1}, start = all;
  if (p->region[2] >= p->region[0]) {
    start = (box){p->region[0], p->region[1], p->region[2], p->region[3]};
    start.i0 = start.i0 < 0 ? 0 : start.i0;
    start.j0 = start.j0 < 0 ? 0 : start.j0;
    start.i1 = start.i1 >= s->nx ? s->nx - 1 : start.i1;
    start.j1 = start.j1 >= s->ny ? s->ny - 1 : start.j1;
  }
  for (int mi = 0; mi < 2; mi++) {
    int m = MATS[mi];
    double ta = tan(p->angle[m] * (3.14159265358979323846 / 180));
    w.q = oc_seg_index(m);
    long it = 0;
    int done = 0, top = 1;
    { /* the coarsest stride, from the extent of the first givers */
      box giv;
      double big, sum;
      w.k = 1;
      w.thr[0] = s->cell * ta;
      w.thr[1] = s->cell * sqrt(2.0) * ta;
      pass1(&w, start, &giv, &big, &sum);
      if (isinf(big)) {
        free(w.kf);
        return oc_seterr(err, OC_ENOMEM, "out of memory");
      }
      int ext = giv.i0 > giv.i1                     ? 0
                : giv.i1 - giv.i0 > giv.j1 - giv.j0 ? giv.i1 - giv.i0 + 1
                                                    : giv.j1 - giv.j0 + 1;
      while (2 * top <= STRIDE_TOP && 2 * top * STRIDE_SPAN <= ext)
        top *= 2;
    }
    for (w.k = top; w.k >= 1; w.k /= 2) {
      w.thr[0] = w.k * s->cell * ta;
      w.thr[1] = w.k * s->cell * sqrt(2.0) * ta;
      double tol = w.k * p->tolerance;
      memset(w.kf, 0, 2 * nseg * sizeof *w.kf);
      box b = start;
      done = 0;
      while (it < p->iterations && b.i0 <= b.i1 && b.j0 <= b.j1) {
        box giv;
        double big, sum;
        pass1(&w, b, &giv, &big, &sum);
        if (isinf(big)) {
          free(w.kf);
          return oc_seterr(err, OC_ENOMEM, "out of memory");
        }
        if (!(big > tol)) {
          done = 1;
          break;
        }
        box c = grow(giv, w.k, s->nx, s->ny);
        pass2(&w, c);
        for (int j = c.j0; j <= c.j1; j++)
          for (int i = c.i0; i <= c.i1; i++) {
            size_t k = (size_t)j * s->nx + i;
            for (size_t g = soff[k]; g < soff[k + 1]; g++)
              seg[g].a[w.q] = w.nxt[g];
          }
        /* factors and losses are 0 outside the givers (which pass 1 of the
        ** next box covers), so pass 2 reads none stale */
        for (int j = giv.j0; j <= giv.j1; j++)
          for (size_t g = soff[(size_t)j * s->nx + giv.i0];
               g < soff[(size_t)j * s->nx + giv.i1 + 1]; g++)
            w.kf[g] = w.loss[g] = 0;
        r.moved += sum * s->cell * s->cell;
        b = grow(c, w.k, s->nx, s->ny);
        /* the next level starts from every stack this one changed */
        if (w.k > 1) start = box_union(start, b);
        it++;
      }
      if (b.i0 > b.i1) done = 1;
    }
    r.iterations += it;
    r.converged &= done;
  }
  free(w.kf);
  if (res) *res = r;
  return OC_OK;
}

void oc_stabilize_defaults(const oc_stacks *s, oc_stabilize_params *p) {
  memset(p, 0, sizeof *p);
  p->angle[OC_MAT_SAND] = 32;
  p->angle[OC_MAT_ROCKS] = 42;
  p->rate = 0.25;
  p->tolerance = 1e-3 * (s ? s->cell : 1);
  p->iterations = 100000;
  p->region[0] = 0;
  p->region[2] = -1;
}

int oc_layers_check_stabilize(const oc_stabilize_params *p, oc_error *err) {
  static const char *const name[2] = {"angle.sand", "angle.rocks"};
  for (int k = 0; k < 2; k++) {
    double a = p->angle[k == 0 ? OC_MAT_SAND : OC_MAT_ROCKS];
    if (!(a > 0 && a < 90))
      return oc_seterr(err, OC_EINVAL,
                       "'%s' must be an angle in (0, 90) degrees (got %g)",
                       name[k], a);
  }
  if (!(p->rate > 0 && p->rate <= 0.5))
    return oc_seterr(err, OC_EINVAL, "'rate' must be in (0, 0.5] (got %g)",
                     p->rate);
  if (!(p->tolerance > 0) || !isfinite(p->tolerance))
    return oc_seterr(err, OC_EINVAL, "'tolerance' must be > 0 (got %g)",
                     p->tolerance);
  if (p->iterations < 1)
    return oc_seterr(err, OC_EINVAL, "'iterations' must be >= 1 (got %ld)",
                     p->iterations);
  return OC_OK;
}

int oc_layers_tool_stab(const oc_stacks *s, const oc_stabilize_params *given,
                        int stabilize, oc_stabilize_params *p, oc_error *err) {
  if (given)
    *p = *given;
  else
    oc_stabilize_defaults(s, p);
  return stabilize ? oc_layers_check_stabilize(p, err) : OC_OK;
}

int oc_stacks_stabilize(oc_stacks *s, const oc_stabilize_params *p,
                        oc_stabilize_result *res, oc_error *err) {
  oc_stabilize_params d;
  if (!p) {
    oc_stabilize_defaults(s, &d);
    p = &d;
  }
  if (oc_layers_check_stabilize(p, err)) return OC_EINVAL;
  oc_lseg *seg;
  size_t *soff;
  int rc = oc_layers_decode_all(s, &seg, &soff, err);
  if (rc) return rc;
  rc = oc_layers_stabilize_segs(s, seg, soff, p, res, err);
  if (!rc) rc = oc_layers_encode_all(s, seg, soff, err);
  free(seg);
  free(soff);
  return rc;
}
