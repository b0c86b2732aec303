/*
** curve.c — piecewise planar curves with elevation (see curve.h): checked
** construction, the arc-length tables, the box tree of the closest-point
** query, frames, curvature and turning bounds, flattening.
*/
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/bezier.h"
#include "core/checked.h"
#include "core/curve.h"
#include "core/error.h"
#include "core/fround.h"
#include "core/vec.h"

/* Storage (what oc_curve_bytes counts): the points; per piece its start's
** arc length (s[n], the length) and, where it has any, the inner knots
** of its arc-length table; a box tree. A Catmull-Rom curve
** (oc_curve_catmull) keeps its through-points alone and derives each
** piece's inner control points as it reads the piece (the same
** arithmetic that built them, so the same bits); other curves keep their
** control points, each shared end once. The curvature bound, the
** largest turn and the box are computed when asked (builders ask once). */

/* A piece as read (piece_at): its control points, degree and index. */
typedef struct piece {
  oc_vec3 p[4];
  int deg;
  size_t i;
} piece;

/* Box tree node, floats rounded outward: a balanced tree over the pieces
** laid out in preorder, so the node covering pieces [lo, hi) with mid = lo
** + (hi - lo) / 2 has its left child next and its right child 2 (mid -
** lo) nodes after it; a leaf (hi - lo = 1) holds the control points' box
** of piece lo. */
typedef struct fbox {
  float x0, y0, x1, y1;
} fbox;

/* A piece while the curve is built. */
typedef struct rawpiece {
  int deg;
  oc_vec3 p[4];
  double scale;
} rawpiece;

/* One block: this header, then the box tree (2 n - 1 boxes: first, so
** the tree walks find it at once), s (n + 1 doubles: the arc length at
** each piece's start, s[n] the length), the inner knots' arc lengths (nk
** doubles, from their piece's start), the points (control points with
** shared ends once, or a Catmull-Rom spline's through-points), the inner
** knots' first index per piece (n + 1, when nk > 0), mixed degrees' first
** point per piece (n + 1) and the knots' parameters (nk floats: dyadic,
** so exact). (Boxes are 16 bytes: the doubles after them stay aligned.) */
struct oc_pcurve {
  uint32_t n, npts, nk;
  uint8_t deg;     /* every piece's degree, or 0 (mixed: off) */
  uint8_t catmull; /* pts are through-points of a Catmull-Rom spline */
  uint8_t closed;
  fbox bvh[];
};

static double *c_s(const oc_pcurve *c) {
  return (double *)(c->bvh + 2 * (size_t)c->n - 1);
}
static double *c_ts(const oc_pcurve *c) {
  return c_s(c) + c->n + 1;
}
static oc_vec3 *c_pts(const oc_pcurve *c) {
  return (oc_vec3 *)(c_ts(c) + c->nk);
}
static size_t c_ntab(const oc_pcurve *c) {
  return c->nk ? c->n + 1 : 0;
}
static size_t c_noff(const oc_pcurve *c) {
  return c->deg || c->catmull ? 0 : c->n + 1;
}
static uint32_t *c_tab(const oc_pcurve *c) {
  return (uint32_t *)(c_pts(c) + c->npts);
}
static uint32_t *c_off(const oc_pcurve *c) {
  return c_tab(c) + c_ntab(c);
}
static float *c_tt(const oc_pcurve *c) {
  return (float *)(c_off(c) + c_noff(c));
}

static size_t curve_bytes(size_t n, size_t npts, size_t nk, size_t noff) {
  return sizeof(oc_pcurve) + (n + 1 + nk) * sizeof(double) +
         npts * sizeof(oc_vec3) +
         ((nk ? n + 1 : 0) + noff + nk) * sizeof(uint32_t) +
         (2 * n - 1) * sizeof(fbox);
}

/* Piece i of a Catmull-Rom spline through P[0 .. m-1] as a cubic Bézier;
** the ends reflect their neighbour. */
static void catmull_piece(const oc_vec3 *P, size_t m, size_t i, oc_vec3 *q) {
  oc_vec3 a = i > 0 ? P[i - 1] : oc_sub(oc_mul(P[0], 2), P[1]);
  oc_vec3 e = i + 2 < m ? P[i + 2] : oc_sub(oc_mul(P[m - 1], 2), P[m - 2]);
  q[0] = P[i];
  q[1] = oc_add(P[i], oc_mul(oc_sub(P[i + 1], a), 1.0 / 6));
  q[2] = oc_sub(P[i + 1], oc_mul(oc_sub(e, P[i]), 1.0 / 6));
  q[3] = P[i + 1];
}

static void piece_at(const oc_pcurve *c, size_t i, piece *pc) {
  pc->i = i;
  if (c->catmull) {
    pc->deg = 3;
    catmull_piece(c_pts(c), c->npts, i, pc->p);
    return;
  }
  const oc_vec3 *pts = c_pts(c);
  size_t o = c->deg ? i * c->deg : c_off(c)[i];
  pc->deg = c->deg ? c->deg : (int)(c_off(c)[i + 1] - o);
  for (int k = 0; k <= pc->deg; k++)
    pc->p[k] = pts[o + (size_t)k];
}

static double piece_len(const oc_pcurve *c, size_t i) {
  return c_s(c)[i + 1] - c_s(c)[i];
}

/* Inner knots of piece i: how many, and the first's index. */
static size_t ninner(const oc_pcurve *c, size_t i) {
  return c->nk ? c_tab(c)[i + 1] - c_tab(c)[i] : 0;
}

/* ---- construction ------------------------------------------------------ */

static double poly_len_xy(const oc_vec3 *p, int n) {
  double l = 0;
  for (int i = 0; i < n; i++)
    l += hypot(p[i + 1].x - p[i].x, p[i + 1].y - p[i].y);
  return l;
}

typedef struct knots {
  double *t, *s;
  size_t n, cap;
} knots;

static int knots_push(knots *k, double t, double s) {
  if (k->n >= UINT32_MAX - 1) return 0; /* (tab's range) */
  if (k->n == k->cap) {
    size_t cap = k->cap ? 2 * k->cap : 64, bytes;
    if (!oc_mul_size(cap, sizeof(double), &bytes)) return 0;
    double *nt = realloc(k->t, bytes);
    if (!nt) return 0;
    k->t = nt;
    double *ns = realloc(k->s, bytes);
    if (!ns) return 0;
    k->s = ns;
    k->cap = cap;
  }
  k->t[k->n] = t, k->s[k->n] = s, k->n++;
  return 1;
}

/* Tabulates the arc length of a Bézier piece: [0, 1] is split until the
** 8-point rule on a span agrees with the rule on its halves to 1e-14 of
** the piece's scale (a span then carries ~1e-16 of error, well inside the
** documented 1e-9); depth is capped at 24 (cusps, where the speed has a
** kink), so the knots are dyadic and exact in floats. The knots between
** spans are appended in order (the ends, (0, 0) and (1, length), are not
** stored: knot_t, knot_s); most pieces of a smooth spline are one span.
** The piece's length is returned. */
static int tabulate(const rawpiece *pc, knots *k, double *len) {
  struct {
    double a, b;
    int depth;
  } st[32];
  int top = 0;
  double s = 0, tol = 1e-14 * pc->scale;
  st[top].a = 0, st[top].b = 1, st[top].depth = 0, top++;
  while (top > 0) {
    double a = st[top - 1].a, b = st[top - 1].b, m = 0.5 * (a + b);
    int depth = st[top - 1].depth;
    top--;
    double whole = oc_bez_arclen(pc->p, pc->deg, a, b);
    double halves = oc_bez_arclen(pc->p, pc->deg, a, m) +
                    oc_bez_arclen(pc->p, pc->deg, m, b);
    if (depth >= 24 || fabs(whole - halves) <= tol) {
      s += halves;
      if (top > 0 && !knots_push(k, b, s)) return 0; /* (the last: b = 1) */
      continue;
    }
    st[top].a = m, st[top].b = b, st[top].depth = depth + 1, top++;
    st[top].a = a, st[top].b = m, st[top].depth = depth + 1, top++;
  }
  *len = s;
  return 1;
}

/* The xy length of a piece's control polygon, only where it decides: v >
** 1e-12 of it (the L1 length bounds it above, so most calls need no
** hypot). */
static int above_scale(const piece *pc, double v) {
  double l1 = 0;
  for (int i = 0; i < pc->deg; i++)
    l1 += fabs(pc->p[i + 1].x - pc->p[i].x) + fabs(pc->p[i + 1].y - pc->p[i].y);
  if (v > 1e-12 * l1) return 1;
  return v > 1e-12 * poly_len_xy(pc->p, pc->deg);
}

/* Unit direction of travel of one piece at t (xy); where the derivative
** vanishes at an end, the direction to the nearest distinct control
** point, which is the limit of the tangent. */
static void piece_dir(const piece *pc, double t, double *tx, double *ty) {
  oc_vec3 d = {0, 0, 0};
  oc_bez_d1_xy(pc->p, pc->deg, t, &d.x, &d.y);
  double v = hypot(d.x, d.y);
  if (!above_scale(pc, v)) {
    int n = pc->deg;
    if (t < 0.5) {
      int k = 1;
      while (k < n && pc->p[k].x == pc->p[0].x && pc->p[k].y == pc->p[0].y)
        k++;
      d = oc_sub(pc->p[k], pc->p[0]);
    } else {
      int k = n - 1;
      while (k > 0 && pc->p[k].x == pc->p[n].x && pc->p[k].y == pc->p[n].y)
        k--;
      d = oc_sub(pc->p[n], pc->p[k]);
    }
    v = hypot(d.x, d.y);
  }
  *tx = d.x / v, *ty = d.y / v;
}

/* Tight xy and z extent of a piece: its ends and the interior zeros of
** each coordinate's derivative (a polynomial of degree <= 2). */
static void piece_box(const piece *pc, oc_aabb *box) {
  double ts[8];
  int nt = 0, n = pc->deg;
  ts[nt++] = 0, ts[nt++] = 1;
  for (int ax = 0; ax < 3 && n > 1; ax++) {
    double h[3];
    for (int i = 0; i < n; i++) {
      const double *a = &pc->p[i].x, *b = &pc->p[i + 1].x;
      h[i] = b[ax] - a[ax];
    }
    if (n == 2) {
      if (h[0] != h[1]) ts[nt++] = h[0] / (h[0] - h[1]);
      continue;
    }
    /* h0 (1-t)^2 + 2 h1 t (1-t) + h2 t^2 = A t^2 + B t + C */
    double A = h[0] - 2 * h[1] + h[2], B = 2 * (h[1] - h[0]), C = h[0];
    if (A == 0) {
      if (B != 0) ts[nt++] = -C / B;
      continue;
    }
    double disc = B * B - 4 * A * C;
    if (disc < 0) continue;
    double q = -0.5 * (B + copysign(sqrt(disc), B));
    ts[nt++] = q / A;
    if (q != 0) ts[nt++] = C / q;
  }
  for (int i = 0; i < nt; i++)
    if (ts[i] >= 0 && ts[i] <= 1) {
      oc_vec3 q = oc_bez_eval(pc->p, n, ts[i]);
      box->lo = oc_vmin(box->lo, q);
      box->hi = oc_vmax(box->hi, q);
    }
}

static void build_bvh(oc_pcurve *c, size_t lo, size_t hi, size_t i) {
  fbox *bvh = c->bvh, *b = &bvh[i];
  if (hi - lo == 1) {
    piece pc;
    piece_at(c, lo, &pc);
    double x0 = pc.p[0].x, x1 = x0, y0 = pc.p[0].y, y1 = y0;
    for (int k = 1; k <= pc.deg; k++) {
      x0 = fmin(x0, pc.p[k].x), x1 = fmax(x1, pc.p[k].x);
      y0 = fmin(y0, pc.p[k].y), y1 = fmax(y1, pc.p[k].y);
    }
    b->x0 = oc_float_down(x0), b->y0 = oc_float_down(y0);
    b->x1 = oc_float_up(x1), b->y1 = oc_float_up(y1);
    return;
  }
  size_t mid = lo + (hi - lo) / 2, l = i + 1, r = i + 2 * (mid - lo);
  build_bvh(c, lo, mid, l);
  build_bvh(c, mid, hi, r);
  b->x0 = fminf(bvh[l].x0, bvh[r].x0);
  b->y0 = fminf(bvh[l].y0, bvh[r].y0);
  b->x1 = fmaxf(bvh[l].x1, bvh[r].x1);
  b->y1 = fmaxf(bvh[l].y1, bvh[r].y1);
}

static double turn_at(const piece *a, const piece *b) {
  double ax, ay, bx, by;
  piece_dir(a, 1, &ax, &ay);
  piece_dir(b, 0, &bx, &by);
  return atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
}

static int same_point(oc_vec3 a, oc_vec3 b, double tol) {
  return fabs(a.x - b.x) <= tol && fabs(a.y - b.y) <= tol &&
         fabs(a.z - b.z) <= tol;
}

static int same_vec(oc_vec3 a, oc_vec3 b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

/* The checked pieces, snapped, without those of no length, and whether
** the curve closes: NULL (err set) when refused. */
static rawpiece *raw_pieces(const oc_curve_piece *pieces, size_t n,
                            size_t *nout, int *closed, oc_error *err) {
  if (n == 0 || !pieces) {
    oc_seterr(err, OC_EINVAL, "'pieces' must hold at least one piece");
    return NULL;
  }
  double scale = 1;
  for (size_t i = 0; i < n; i++) {
    int deg = pieces[i].degree;
    if (deg < 1 || deg > 3) {
      oc_seterr(err, OC_EINVAL, "piece %zu: degree must be 1, 2 or 3 (got %d)",
                i, deg);
      return NULL;
    }
    for (int k = 0; k <= deg; k++) {
      oc_vec3 q = pieces[i].p[k];
      if (!oc_vfinite(q)) {
        oc_seterr(err, OC_EINVAL, "piece %zu: control point %d is not finite",
                  i, k);
        return NULL;
      }
      scale = fmax(scale, fmax(fabs(q.x), fmax(fabs(q.y), fabs(q.z))));
    }
  }
  double jtol = 1e-9 * scale;
  for (size_t i = 1; i < n; i++) {
    oc_vec3 e = pieces[i - 1].p[pieces[i - 1].degree], s = pieces[i].p[0];
    if (!same_point(e, s, jtol)) {
      oc_seterr(err, OC_EINVAL,
                "piece %zu does not start where piece %zu ends (gap %g)", i,
                i - 1, oc_len(oc_sub(s, e)));
      return NULL;
    }
  }
  rawpiece *raw = NULL;
  size_t bytes, nraw = 0;
  if (n >= UINT32_MAX / 4 || !oc_mul_size(n, sizeof *raw, &bytes) ||
      !(raw = malloc(bytes))) {
    oc_seterr(err, OC_ENOMEM, "out of memory for a curve of %zu pieces", n);
    return NULL;
  }
  oc_vec3 last = pieces[0].p[0];
  for (size_t i = 0; i < n; i++) {
    rawpiece pc = {0};
    pc.deg = pieces[i].degree;
    memcpy(pc.p, pieces[i].p, sizeof pc.p);
    pc.p[0] = last; /* snap to the previous end */
    pc.scale = poly_len_xy(pc.p, pc.deg);
    last = pc.p[pc.deg];
    if (!(pc.scale <= 1e300)) {
      /* (the derivatives would overflow, and the arc length's subdivision
      ** then never meets its tolerance) */
      free(raw);
      oc_seterr(err, OC_EINVAL,
                "piece %zu is too long (control polygon %g in xy, at most "
                "1e300)",
                i, pc.scale);
      return NULL;
    }
    if (pc.scale == 0) {
      /* (all its points are then the previous end: dropping it leaves the
      ** next piece starting where the one before ends) */
      for (int k = 1; k <= pc.deg; k++)
        if (pc.p[k].z != pc.p[0].z) {
          free(raw);
          oc_seterr(err, OC_EINVAL,
                    "piece %zu has no length in xy but its z changes", i);
          return NULL;
        }
      continue;
    }
    raw[nraw++] = pc;
  }
  if (nraw == 0) {
    free(raw);
    oc_seterr(err, OC_EINVAL,
              "the curve has no length (every piece is a point in xy)");
    return NULL;
  }
  rawpiece *rfirst = &raw[0], *rend = &raw[nraw - 1];
  *closed = 0;
  if (same_point(rend->p[rend->deg], rfirst->p[0], jtol) &&
      (nraw > 1 || rend->deg > 1)) {
    *closed = 1;
    rend->p[rend->deg] = rfirst->p[0];
  }
  *nout = nraw;
  return raw;
}

/* The curve on raw pieces; with through (m points), a Catmull-Rom spline
** whose pieces raw are (then only the points are kept). raw is freed. */
static oc_pcurve *build(rawpiece *raw, size_t nraw, int closed,
                        const oc_vec3 *through, size_t m, oc_error *err) {
  /* the tables first (their size is known after) */
  knots k = {0};
  double *len = malloc(nraw * sizeof *len);
  uint32_t *kfirst = malloc(nraw * sizeof *kfirst);
  if (!len || !kfirst) goto nomem;
  for (size_t i = 0; i < nraw; i++) {
    kfirst[i] = (uint32_t)k.n;
    if (raw[i].deg == 1)
      len[i] = raw[i].scale;
    else if (!tabulate(&raw[i], &k, &len[i]))
      goto nomem;
  }
  int mixed = 0;
  size_t npts = through ? m : 1;
  for (size_t i = 0; i < nraw; i++) {
    mixed |= raw[i].deg != raw[0].deg;
    if (!through) npts += (size_t)raw[i].deg;
  }
  size_t nk = k.n, noff = mixed && !through ? nraw + 1 : 0;
  oc_pcurve *c = malloc(curve_bytes(nraw, npts, nk, noff));
  if (!c) goto nomem;
  c->n = (uint32_t)nraw, c->npts = (uint32_t)npts, c->nk = (uint32_t)nk;
  c->deg = (uint8_t)(through ? 3 : mixed ? 0 : raw[0].deg);
  c->catmull = through != NULL;
  c->closed = (uint8_t)closed;
  oc_vec3 *pts = c_pts(c);
  if (through) {
    memcpy(pts, through, m * sizeof *through);
  } else {
    uint32_t *off = noff ? c_off(c) : NULL;
    size_t o = 0;
    pts[0] = raw[0].p[0];
    for (size_t i = 0; i < nraw; i++) {
      if (off) off[i] = (uint32_t)o;
      for (int q = 1; q <= raw[i].deg; q++)
        pts[o + (size_t)q] = raw[i].p[q];
      o += (size_t)raw[i].deg;
    }
    if (off) off[nraw] = (uint32_t)o;
  }
  double s = 0;
  for (size_t i = 0; i < nraw; i++) {
    c_s(c)[i] = s;
    s += len[i];
    if (nk) c_tab(c)[i] = kfirst[i];
  }
  c_s(c)[nraw] = s;
  if (nk) c_tab(c)[nraw] = (uint32_t)nk;
  for (size_t j = 0; j < nk; j++) /* (dyadic parameters: exact floats) */
    c_tt(c)[j] = (float)k.t[j], c_ts(c)[j] = k.s[j];
  build_bvh(c, 0, nraw, 0);
  free(k.t), free(k.s), free(len), free(kfirst), free(raw);
  return c;
nomem:
  free(k.t), free(k.s), free(len), free(kfirst), free(raw);
  oc_seterr(err, OC_ENOMEM, "out of memory for a curve of %zu pieces", nraw);
  return NULL;
}

oc_pcurve *oc_curve_new(const oc_curve_piece *pieces, size_t n, oc_error *err) {
  size_t nraw;
  int closed;
  rawpiece *raw = raw_pieces(pieces, n, &nraw, &closed, err);
  return raw ? build(raw, nraw, closed, NULL, 0, err) : NULL;
}

oc_pcurve *oc_curve_from_points(const oc_vec3 *pts, size_t n, int degree,
                                oc_error *err) {
  if (degree < 1 || degree > 3) {
    oc_seterr(err, OC_EINVAL, "'degree' must be 1, 2 or 3 (got %d)", degree);
    return NULL;
  }
  if (n < 2 || (n - 1) % (size_t)degree != 0) {
    oc_seterr(err, OC_EINVAL,
              "'points' must number %d m + 1 with m >= 1 (got %zu)", degree, n);
    return NULL;
  }
  size_t m = (n - 1) / degree, bytes;
  oc_curve_piece *pcs;
  if (!oc_mul_size(m, sizeof *pcs, &bytes) || !(pcs = malloc(bytes))) {
    oc_seterr(err, OC_ENOMEM, "out of memory for a curve of %zu pieces", m);
    return NULL;
  }
  for (size_t i = 0; i < m; i++) {
    pcs[i].degree = degree;
    for (int k = 0; k <= degree; k++)
      pcs[i].p[k] = pts[i * degree + k];
  }
  oc_pcurve *c = oc_curve_new(pcs, m, err);
  free(pcs);
  return c;
}

oc_pcurve *oc_curve_catmull(const oc_vec3 *pts, size_t n, oc_error *err) {
  if (n < 2 || !pts) {
    oc_seterr(err, OC_EINVAL, "'points' must hold at least 2 points (got %zu)",
              n);
    return NULL;
  }
  size_t bytes;
  oc_curve_piece *pcs;
  if (!oc_mul_size(n - 1, sizeof *pcs, &bytes) || !(pcs = malloc(bytes))) {
    oc_seterr(err, OC_ENOMEM, "out of memory (%zu points)", n);
    return NULL;
  }
  for (size_t i = 0; i + 1 < n; i++) {
    pcs[i].degree = 3;
    catmull_piece(pts, n, i, pcs[i].p);
  }
  size_t nraw;
  int closed;
  rawpiece *raw = raw_pieces(pcs, n - 1, &nraw, &closed, err);
  free(pcs);
  if (!raw) return NULL;
  /* the points alone when the pieces are exactly those they give (none
  ** dropped, no end snapped) */
  int derived = nraw == n - 1;
  for (size_t i = 0; derived && i < nraw; i++) {
    oc_vec3 q[4];
    catmull_piece(pts, n, i, q);
    for (int k = 0; k < 4; k++)
      derived &= same_vec(q[k], raw[i].p[k]);
  }
  return build(raw, nraw, closed, derived ? pts : NULL, n, err);
}

void oc_curve_free(oc_pcurve *c) {
  free(c); /* (one block) */
}

size_t oc_curve_bytes(const oc_pcurve *c) {
  return curve_bytes(c->n, c->npts, c->nk, c_noff(c));
}

size_t oc_curve_npieces(const oc_pcurve *c) {
  return c->n;
}
int oc_curve_closed(const oc_pcurve *c) {
  return c->closed;
}
double oc_curve_length(const oc_pcurve *c) {
  return c_s(c)[c->n];
}
double oc_curve_kappa_max(const oc_pcurve *c) {
  double k = 0, s = c_s(c)[c->n];
  for (size_t i = 0; i < c->n; i++) {
    piece pc;
    piece_at(c, i, &pc);
    k = fmax(k, oc_bez_kappa_bound(pc.p, pc.deg, 1e-2, 1e-9 / s));
  }
  return k;
}
double oc_curve_max_turn(const oc_pcurve *c) {
  double turn = 0;
  piece a, b, first;
  piece_at(c, 0, &first);
  a = first;
  for (size_t i = 1; i < c->n; i++) {
    piece_at(c, i, &b);
    turn = fmax(turn, turn_at(&a, &b));
    a = b;
  }
  if (c->closed) turn = fmax(turn, turn_at(&a, &first));
  return turn;
}

double oc_curve_grade_max(const oc_pcurve *c) {
  double g = 0;
  for (size_t i = 0; i < c->n; i++) {
    piece pc;
    piece_at(c, i, &pc);
    g = fmax(g, oc_bez_grade_bound(pc.p, pc.deg));
  }
  return g;
}

double oc_curve_curvature_at(const oc_pcurve *c, const oc_curve_point *pt) {
  piece pc;
  piece_at(c, pt->piece, &pc);
  return pc.deg < 2 ? 0 : oc_bez_curvature(pc.p, pc.deg, pt->t);
}

double oc_curve_grade_at(const oc_pcurve *c, const oc_curve_point *pt) {
  piece pc;
  piece_at(c, pt->piece, &pc);
  oc_vec3 d = oc_bez_d1(pc.p, pc.deg, pt->t);
  double v = hypot(d.x, d.y);
  return v > 0 ? d.z / v : 0;
}

oc_aabb oc_curve_bounds(const oc_pcurve *c, double r) {
  oc_aabb b = oc_aabb_empty();
  for (size_t i = 0; i < c->n; i++) {
    piece pc;
    piece_at(c, i, &pc);
    piece_box(&pc, &b);
  }
  b.lo.x -= r, b.lo.y -= r, b.hi.x += r, b.hi.y += r;
  return b;
}

/* ---- arc length <-> parameter ------------------------------------------ */

/* Knot j (0 .. ninner + 1) of a Bézier piece: its parameter and its arc
** length (the ends are 0 and 0, 1 and the piece's length). */
static double knot_t(const oc_pcurve *c, const piece *pc, size_t j) {
  return j == 0                 ? 0
         : j > ninner(c, pc->i) ? 1
                                : c_tt(c)[c_tab(c)[pc->i] + j - 1];
}
static double knot_s(const oc_pcurve *c, const piece *pc, size_t j) {
  return j == 0                 ? 0
         : j > ninner(c, pc->i) ? piece_len(c, pc->i)
                                : c_ts(c)[c_tab(c)[pc->i] + j - 1];
}

/* The knot span k of a Bézier piece with knot k <= t < knot k + 1. */
static size_t span_of_t(const oc_pcurve *c, const piece *pc, double t) {
  size_t lo = 0, hi = ninner(c, pc->i) + 1;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (knot_t(c, pc, m) <= t)
      lo = m;
    else
      hi = m;
  }
  return lo;
}

/* Arc length from the start of the piece to t. */
static double s_of_t(const oc_pcurve *c, const piece *pc, double t) {
  if (t >= 1) return piece_len(c, pc->i);
  if (t <= 0) return 0;
  if (pc->deg == 1) return t * piece_len(c, pc->i);
  size_t k = span_of_t(c, pc, t);
  return knot_s(c, pc, k) + oc_bez_arclen(pc->p, pc->deg, knot_t(c, pc, k), t);
}

/* The parameter at arc length sl from the start of the piece: Newton on
** the tabulated span, safeguarded by bisection (the speed may vanish). */
static double t_of_s(const oc_pcurve *c, const piece *pc, double sl) {
  double len = piece_len(c, pc->i);
  if (sl <= 0) return 0;
  if (sl >= len) return 1;
  if (pc->deg == 1) return sl / len;
  size_t lo = 0, hi = ninner(c, pc->i) + 1;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (knot_s(c, pc, m) <= sl)
      lo = m;
    else
      hi = m;
  }
  double a = knot_t(c, pc, lo), b = knot_t(c, pc, lo + 1);
  double s0 = knot_s(c, pc, lo), ds = knot_s(c, pc, lo + 1) - s0;
  double t = ds > 0 ? a + (b - a) * (sl - s0) / ds : a;
  for (int it = 0; it < 60; it++) {
    double g = s0 + oc_bez_arclen(pc->p, pc->deg, knot_t(c, pc, lo), t) - sl;
    if (g == 0) break;
    if (g < 0)
      a = t;
    else
      b = t;
    oc_vec3 d = oc_bez_d1(pc->p, pc->deg, t);
    double v = hypot(d.x, d.y), tn = v > 0 ? t - g / v : 0.5 * (a + b);
    if (!(tn > a && tn < b)) tn = 0.5 * (a + b);
    if (fabs(tn - t) <= 1e-16 || b - a <= 1e-16) {
      t = tn;
      break;
    }
    t = tn;
  }
  return t;
}

/* The tangent at (piece pc, t); at a join, the bisector of both sides. */
static void tangent(const oc_pcurve *c, const piece *pc, double t, double *tx,
                    double *ty) {
  size_t i = pc->i, o;
  piece_dir(pc, t, tx, ty);
  if (t <= 0 && (i > 0 || c->closed))
    o = i > 0 ? i - 1 : c->n - 1;
  else if (t >= 1 && (i + 1 < c->n || c->closed))
    o = i + 1 < c->n ? i + 1 : 0;
  else
    return;
  piece other;
  piece_at(c, o, &other);
  double ox, oy;
  piece_dir(&other, t <= 0 ? 1 : 0, &ox, &oy);
  double sx = *tx + ox, sy = *ty + oy, v = hypot(sx, sy);
  if (v > 1e-12) *tx = sx / v, *ty = sy / v;
}

/* (with_s 0: out->s is NaN, oc_curve_s_at) */
static void fill(const oc_pcurve *c, const piece *pc, double t, int with_s,
                 oc_curve_point *out) {
  size_t i = pc->i;
  out->piece = i;
  out->t = t;
  out->s = with_s ? c_s(c)[i] + s_of_t(c, pc, t) : NAN;
  out->q = t >= 1 ? pc->p[pc->deg] : oc_bez_eval(pc->p, pc->deg, t);
  tangent(c, pc, t, &out->tx, &out->ty);
  out->nx = -out->ty, out->ny = out->tx;
  out->d = 0;
  out->end = 0;
  if (!c->closed) {
    if (i == 0 && t <= 0) out->end = -1;
    if (i + 1 == c->n && t >= 1) out->end = 1;
  }
}

int oc_curve_at(const oc_pcurve *c, double s, oc_curve_point *out) {
  if (isnan(s)) return 0;
  double length = c_s(c)[c->n];
  s = s < 0 ? 0 : s > length ? length : s;
  size_t lo = 0, hi = c->n;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (c_s(c)[m] <= s)
      lo = m;
    else
      hi = m;
  }
  piece pc;
  piece_at(c, lo, &pc);
  fill(c, &pc, t_of_s(c, &pc, s - c_s(c)[lo]), 1, out);
  out->end = 0;
  return 1;
}

/* ---- closest point --------------------------------------------------- */

/* The larger of a and b, a single maxsd (no NaN here: the queries check
** theirs, the boxes are finite). */
static inline double max2(double a, double b) {
  return a > b ? a : b;
}

/* (squared: the sign of a zero, the only bits max2 may choose otherwise
** than oc_fmax, squares away) */
static inline double box_d2(const fbox *b, double x, double y) {
  double dx = max2(max2(b->x0 - x, x - b->x1), 0);
  double dy = max2(max2(b->y0 - y, y - b->y1), 0);
  return dx * dx + dy * dy;
}

int oc_curve_far_from_segment(const oc_pcurve *c, double xa, double ya,
                              double xb, double yb, double r) {
  if (!(r >= 0 && r < INFINITY)) return 0;
  for (size_t i = 0; i < c->n; i++) {
    piece pc;
    piece_at(c, i, &pc);
    if (!oc_bez_far(pc.p, pc.deg, xa, ya, xb, yb, r)) return 0;
  }
  return 1;
}

/* nextafter(v, INFINITY) for v >= 0 (finite or not), inline: the next
** double up, by its bits. */
static inline double next_up(double v) {
  if (!(v < INFINITY)) return v;
  uint64_t u;
  memcpy(&u, &v, sizeof u);
  u = v == 0 ? 1 : u + 1;
  memcpy(&v, &u, sizeof v);
  return v;
}

/* A pending node of the box tree: its index and its pieces [lo, hi);
** and with its box's squared distance to the query. */
typedef struct pending {
  uint32_t node, lo, hi;
} pending;
typedef struct pending_d {
  pending p;
  double d2;
} pending_d;

double oc_curve_s_at(const oc_pcurve *c, const oc_curve_point *pt) {
  piece pc;
  piece_at(c, pt->piece, &pc);
  return c_s(c)[pt->piece] + s_of_t(c, &pc, pt->t);
}

/* The closest piece and parameter within r, and its squared distance
** *d2: 0 when none is within r. */
static int search(const oc_pcurve *c, double x, double y, double r, piece *bp,
                  double *bt, double *d2) {
  if (!(r >= 0) || isnan(x) || isnan(y)) return 0;
  double lim = next_up(r * r), best = lim;
  piece pc;
  int found = 0;
  const fbox *bvh = c->bvh;
  /* (each entry keeps its box's distance, computed once: best only
  ** falls, so a box dropped when pushed would be when popped) */
  pending_d st[128];
  int top = 0;
  st[top++] = (pending_d){{0, 0, c->n}, box_d2(&bvh[0], x, y)};
  while (top > 0) {
    pending_d e = st[--top];
    if (e.d2 >= best) continue;
    if (e.p.hi - e.p.lo == 1) {
      piece_at(c, e.p.lo, &pc);
      /* (oc_bez_closest first tests whether the piece is out of reach) */
      double t, d = oc_bez_closest(pc.p, pc.deg, x, y, best, &t);
      if (d < best) best = d, *bp = pc, *bt = t, found = 1;
      continue;
    }
    uint32_t mid = e.p.lo + (e.p.hi - e.p.lo) / 2;
    pending_d l = {{e.p.node + 1, e.p.lo, mid}, 0},
              rr = {{e.p.node + 2 * (mid - e.p.lo), mid, e.p.hi}, 0};
    l.d2 = box_d2(&bvh[l.p.node], x, y), rr.d2 = box_d2(&bvh[rr.p.node], x, y);
    /* nearer child on top; the tree is balanced, so 2 log2 n entries */
    pending_d *near = l.d2 <= rr.d2 ? &l : &rr, *far = near == &l ? &rr : &l;
    if (far->d2 < best) st[top++] = *far;
    if (near->d2 < best) st[top++] = *near;
  }
  *d2 = best;
  return found;
}

/* out from the search's piece, parameter and squared distance. */
static void answer(const oc_pcurve *c, const piece *bp, double bt, double d2,
                   double x, double y, int with_s, oc_curve_point *out) {
  fill(c, bp, bt, with_s, out);
  double cr = out->tx * (y - out->q.y) - out->ty * (x - out->q.x);
  double dist = sqrt(d2);
  out->d = cr < 0 ? -dist : dist;
}

static int closest(const oc_pcurve *c, double x, double y, double r, int with_s,
                   oc_curve_point *out) {
  piece bp;
  double bt = 0, d2;
  if (!search(c, x, y, r, &bp, &bt, &d2)) return 0;
  answer(c, &bp, bt, d2, x, y, with_s, out);
  return 1;
}

int oc_curve_closest_within(const oc_pcurve *c, double x, double y, double rin,
                            double r, oc_curve_point *out, double *d2) {
  piece bp;
  double bt = 0;
  if (!search(c, x, y, r, &bp, &bt, d2)) return 0;
  /* (a search with rin keeps the boxes and pieces nearer than its limit,
  ** which hold the minimum when it is below that limit: the same piece
  ** and parameter) */
  if (!(*d2 < next_up(rin * rin))) return 1;
  answer(c, &bp, bt, *d2, x, y, 0, out);
  return 2;
}

int oc_curve_closest(const oc_pcurve *c, double x, double y, double r,
                     oc_curve_point *out) {
  return closest(c, x, y, r, 1, out);
}

int oc_curve_closest_t(const oc_pcurve *c, double x, double y, double r,
                       oc_curve_point *out) {
  return closest(c, x, y, r, 0, out);
}

/* The pieces whose boxes come within sqrt(lim) of (x, y), in the box
** tree's depth-first order: walk_next gives them one at a time (a
** search may stop at the first that answers it). */
typedef struct near_walk {
  const fbox *bvh;
  double x, y, lim;
  pending st[128];
  int top;
} near_walk;

static void walk_start(near_walk *w, const oc_pcurve *c, double x, double y,
                       double lim) {
  w->bvh = c->bvh, w->x = x, w->y = y, w->lim = lim;
  w->top = 0;
  w->st[w->top++] = (pending){0, 0, c->n};
}

static int walk_next(near_walk *w, uint32_t *leaf) {
  while (w->top > 0) {
    pending e = w->st[--w->top];
    if (box_d2(&w->bvh[e.node], w->x, w->y) >= w->lim) continue;
    if (e.hi - e.lo > 1) {
      uint32_t mid = e.lo + (e.hi - e.lo) / 2;
      w->st[w->top++] = (pending){e.node + 2 * (mid - e.lo), mid, e.hi};
      w->st[w->top++] = (pending){e.node + 1, e.lo, mid};
      continue;
    }
    *leaf = e.lo;
    return 1;
  }
  return 0;
}

int oc_curve_within(const oc_pcurve *c, double x, double y, double r) {
  if (!(r >= 0) || isnan(x) || isnan(y)) return 0;
  double lim = next_up(r * r);
  near_walk w;
  uint32_t i;
  walk_start(&w, c, x, y, lim);
  while (walk_next(&w, &i)) {
    piece pc;
    piece_at(c, i, &pc);
    /* the ends lie on the curve: no root finding when one is near */
    for (int k = 0; k <= pc.deg; k += pc.deg) {
      double dx = pc.p[k].x - x, dy = pc.p[k].y - y;
      if (dx * dx + dy * dy < lim) return 1;
    }
    /* and its middle and quarters (on fig3's and fig22's traces, these
    ** answer 53 % of what would be root findings, and the chord's frame
    ** 75 % of the rest) */
    static const double at[3] = {0.5, 0.25, 0.75};
    for (int k = 0; pc.deg > 1 && k < 3; k++) {
      double mx, my;
      oc_bez_xy(pc.p, pc.deg, at[k], &mx, &my);
      double dx = mx - x, dy = my - y;
      if (dx * dx + dy * dy < lim) return 1;
    }
    double t; /* (out of reach: one test, oc_bez_closest's) */
    if (oc_bez_closest(pc.p, pc.deg, x, y, lim, &t) < lim) return 1;
  }
  return 0;
}

int oc_curve_z_near(const oc_pcurve *c, double x, double y, double r,
                    double *zlo, double *zhi) {
  if (!(r >= 0) || isnan(x) || isnan(y)) return 0;
  double lim = next_up(r * r), lo = INFINITY, hi = -INFINITY;
  near_walk w;
  uint32_t i;
  int got = 0;
  walk_start(&w, c, x, y, lim);
  while (walk_next(&w, &i)) {
    piece pc;
    piece_at(c, i, &pc);
    for (int k = 0; k <= pc.deg; k++)
      lo = fmin(lo, pc.p[k].z), hi = fmax(hi, pc.p[k].z);
    got = 1;
  }
  if (!got) return 0;
  /* (de Casteljau's convex combinations round within a few ulps of the
  ** hull) */
  double m = 1e-12 * fmax(fabs(lo), fabs(hi));
  *zlo = lo - m, *zhi = hi + m;
  return 1;
}

/* ---- flattening ------------------------------------------------------- */

typedef struct flat_ctx {
  const oc_pcurve *c;
  piece pc;
  oc_curve_vertex *out;
  size_t cap, k;
} flat_ctx;

static void flat_emit(void *ud, double t) {
  flat_ctx *f = ud;
  if (f->out && f->k < f->cap) {
    const piece *pc = &f->pc;
    oc_vec3 q = t >= 1 ? pc->p[pc->deg] : oc_bez_eval(pc->p, pc->deg, t);
    oc_curve_vertex v = {q.x, q.y, q.z, c_s(f->c)[pc->i] + s_of_t(f->c, pc, t)};
    f->out[f->k] = v;
  }
  f->k++;
}

int oc_curve_flatten(const oc_pcurve *c, double tol, oc_curve_vertex *out,
                     size_t cap, size_t *count, oc_error *err) {
  double length = c_s(c)[c->n];
  if (!(tol >= 1e-9 * length) || !isfinite(tol))
    return oc_seterr(err, OC_EINVAL,
                     "'tolerance' must be finite and >= %g (1e-9 of the "
                     "curve's length; got %g)",
                     1e-9 * length, tol);
  flat_ctx f = {c, {{{0, 0, 0}}, 0, 0}, out, cap, 0};
  piece_at(c, 0, &f.pc);
  flat_emit(&f, 0);
  for (size_t i = 0; i < c->n; i++) {
    piece_at(c, i, &f.pc);
    oc_bez_flatten(f.pc.p, f.pc.deg, tol, flat_emit, &f);
  }
  *count = f.k;
  return OC_OK;
}
