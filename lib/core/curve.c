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
#include "core/vec.h"

/* A piece's control points are deg + 1 consecutive points of the curve's
** pts, its first the previous piece's last (so each is stored once). */
typedef struct piece {
  const oc_vec3 *p;   /* in pts */
  double s0, len;     /* arc length at the start, and of the piece */
  double scale;       /* xy length of the control polygon */
  uint32_t tab, ntab; /* Bézier: ntab spans, their inner knots at tt/ts[tab] */
  int deg;
} piece;

/* Box tree node: a leaf (right = 0) holds piece `piece`; else its left
** child follows it and `right` is the index of the right child. */
typedef struct bnode {
  double x0, y0, x1, y1;
  uint32_t right, piece;
} bnode;

/* A piece while the curve is built. */
typedef struct rawpiece {
  int deg;
  oc_vec3 p[4];
  double scale;
} rawpiece;

struct oc_pcurve {
  size_t n;
  piece *pc;
  oc_vec3 *pts; /* the pieces' control points, shared ends once */
  size_t npts;
  double *tt, *ts; /* knots: parameter and arc length from the piece start */
  size_t nknots;
  bnode *bvh;
  double length, kappa, turn;
  int closed;
  oc_aabb box;
};

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
  if (k->n >= UINT32_MAX) return 0; /* (piece.tab's range) */
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

/* a, of n items of size or more, cut to n (kept as it is if realloc
** fails or n is 0). */
static void *shrink(void *a, size_t n, size_t size) {
  void *b = n ? realloc(a, n * size) : NULL;
  return b ? b : a;
}

/* Tabulates the arc length of a Bézier piece: [0, 1] is split until the
** 8-point rule on a span agrees with the rule on its halves to 1e-14 of
** the piece's scale (a span then carries ~1e-16 of error, well inside the
** documented 1e-9); depth is capped at 24 (cusps, where the speed has a
** kink). The knots between spans are appended in order (the ends, (0, 0)
** and (1, length), are not stored: knot_t, knot_s); the piece's length is
** returned. */
static int tabulate(piece *pc, knots *k, double *len) {
  struct {
    double a, b;
    int depth;
  } st[32];
  int top = 0;
  double s = 0, tol = 1e-14 * pc->scale;
  uint32_t spans = 0;
  pc->tab = (uint32_t)k->n;
  st[top].a = 0, st[top].b = 1, st[top].depth = 0, top++;
  while (top > 0) {
    double a = st[top - 1].a, b = st[top - 1].b, m = 0.5 * (a + b);
    int depth = st[top - 1].depth;
    top--;
    double whole = oc_bez_arclen(pc->p, pc->deg, a, b);
    double halves = oc_bez_arclen(pc->p, pc->deg, a, m) +
                    oc_bez_arclen(pc->p, pc->deg, m, b);
    if (depth >= 24 || (depth >= 2 && fabs(whole - halves) <= tol)) {
      s += halves;
      spans++;
      if (top > 0 && !knots_push(k, b, s)) return 0; /* (the last: b = 1) */
      continue;
    }
    st[top].a = m, st[top].b = b, st[top].depth = depth + 1, top++;
    st[top].a = a, st[top].b = m, st[top].depth = depth + 1, top++;
  }
  pc->ntab = spans;
  *len = s;
  return 1;
}

/* Unit direction of travel of one piece at t (xy); where the derivative
** vanishes at an end, the direction to the nearest distinct control
** point, which is the limit of the tangent. */
static void piece_dir(const piece *pc, double t, double *tx, double *ty) {
  oc_vec3 d = oc_bez_d1(pc->p, pc->deg, t);
  double v = hypot(d.x, d.y);
  if (!(v > 1e-12 * pc->scale)) {
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

static size_t build_bvh(oc_pcurve *c, size_t lo, size_t hi, size_t *next) {
  size_t i = (*next)++;
  bnode *b = &c->bvh[i];
  b->right = 0, b->piece = (uint32_t)lo;
  if (hi - lo == 1) {
    const piece *pc = &c->pc[lo];
    b->x0 = b->x1 = pc->p[0].x, b->y0 = b->y1 = pc->p[0].y;
    for (int k = 1; k <= pc->deg; k++) {
      b->x0 = fmin(b->x0, pc->p[k].x), b->x1 = fmax(b->x1, pc->p[k].x);
      b->y0 = fmin(b->y0, pc->p[k].y), b->y1 = fmax(b->y1, pc->p[k].y);
    }
    return i;
  }
  size_t mid = lo + (hi - lo) / 2;
  size_t l = build_bvh(c, lo, mid, next), r = build_bvh(c, mid, hi, next);
  b = &c->bvh[i];
  b->right = (uint32_t)r;
  b->x0 = fmin(c->bvh[l].x0, c->bvh[r].x0);
  b->y0 = fmin(c->bvh[l].y0, c->bvh[r].y0);
  b->x1 = fmax(c->bvh[l].x1, c->bvh[r].x1);
  b->y1 = fmax(c->bvh[l].y1, c->bvh[r].y1);
  return i;
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

oc_pcurve *oc_curve_new(const oc_curve_piece *pieces, size_t n, oc_error *err) {
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
  oc_pcurve *c = calloc(1, sizeof *c);
  rawpiece *raw = NULL;
  size_t bytes, nraw = 0;
  if (!c || !oc_mul_size(n, sizeof *raw, &bytes) || !(raw = malloc(bytes))) {
    free(c);
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
      oc_curve_free(c);
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
          oc_curve_free(c);
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
    oc_curve_free(c);
    oc_seterr(err, OC_EINVAL,
              "the curve has no length (every piece is a point in xy)");
    return NULL;
  }
  rawpiece *rfirst = &raw[0], *rend = &raw[nraw - 1];
  if (same_point(rend->p[rend->deg], rfirst->p[0], jtol) &&
      (nraw > 1 || rend->deg > 1)) {
    c->closed = 1;
    rend->p[rend->deg] = rfirst->p[0];
  }
  /* the points, each shared end once, and the pieces on them */
  c->npts = 1;
  for (size_t i = 0; i < nraw; i++)
    c->npts += (size_t)raw[i].deg;
  if (!(c->pc = malloc(nraw * sizeof *c->pc)) ||
      !(c->pts = malloc(c->npts * sizeof *c->pts))) {
    free(raw);
    oc_curve_free(c);
    oc_seterr(err, OC_ENOMEM, "out of memory for a curve of %zu pieces", n);
    return NULL;
  }
  size_t at = 0;
  c->pts[0] = raw[0].p[0];
  for (size_t i = 0; i < nraw; i++) {
    piece *pc = &c->pc[i];
    memset(pc, 0, sizeof *pc);
    pc->deg = raw[i].deg;
    pc->scale = raw[i].scale;
    pc->p = &c->pts[at];
    for (int k = 1; k <= pc->deg; k++)
      c->pts[at + (size_t)k] = raw[i].p[k];
    at += (size_t)pc->deg;
  }
  c->n = nraw;
  free(raw);
  piece *first = &c->pc[0], *end = &c->pc[c->n - 1];

  knots k = {0};
  double s = 0;
  c->kappa = 0;
  c->box = oc_aabb_empty();
  for (size_t i = 0; i < c->n; i++) {
    piece *pc = &c->pc[i];
    double len;
    if (pc->deg == 1) {
      len = pc->scale;
    } else if (!tabulate(pc, &k, &len)) {
      free(k.t), free(k.s);
      oc_curve_free(c);
      oc_seterr(err, OC_ENOMEM, "out of memory for a curve's arc lengths");
      return NULL;
    }
    pc->s0 = s, pc->len = len;
    s += len;
    piece_box(pc, &c->box);
  }
  /* the tables' spare capacity, given back */
  c->tt = shrink(k.t, k.n, sizeof *k.t);
  c->ts = shrink(k.s, k.n, sizeof *k.s);
  c->nknots = k.n;
  c->length = s;
  for (size_t i = 0; i < c->n; i++)
    c->kappa = fmax(
        c->kappa, oc_bez_kappa_bound(c->pc[i].p, c->pc[i].deg, 1e-2, 1e-9 / s));
  for (size_t i = 1; i < c->n; i++)
    c->turn = fmax(c->turn, turn_at(&c->pc[i - 1], &c->pc[i]));
  if (c->closed) c->turn = fmax(c->turn, turn_at(end, first));

  if (!oc_mul_size(2 * c->n - 1, sizeof(bnode), &bytes) ||
      !(c->bvh = malloc(bytes))) {
    oc_curve_free(c);
    oc_seterr(err, OC_ENOMEM, "out of memory for a curve of %zu pieces", n);
    return NULL;
  }
  size_t next = 0;
  build_bvh(c, 0, c->n, &next);
  return c;
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

void oc_curve_free(oc_pcurve *c) {
  if (!c) return;
  free(c->pc);
  free(c->pts);
  free(c->tt);
  free(c->ts);
  free(c->bvh);
  free(c);
}

size_t oc_curve_bytes(const oc_pcurve *c) {
  return sizeof *c + c->n * sizeof *c->pc + c->npts * sizeof *c->pts +
         c->nknots * (sizeof *c->tt + sizeof *c->ts) +
         (2 * c->n - 1) * sizeof *c->bvh;
}

size_t oc_curve_npieces(const oc_pcurve *c) {
  return c->n;
}
int oc_curve_closed(const oc_pcurve *c) {
  return c->closed;
}
double oc_curve_length(const oc_pcurve *c) {
  return c->length;
}
double oc_curve_kappa_max(const oc_pcurve *c) {
  return c->kappa;
}
double oc_curve_max_turn(const oc_pcurve *c) {
  return c->turn;
}

double oc_curve_grade_max(const oc_pcurve *c) {
  double g = 0;
  for (size_t i = 0; i < c->n; i++)
    g = fmax(g, oc_bez_grade_bound(c->pc[i].p, c->pc[i].deg));
  return g;
}

double oc_curve_curvature_at(const oc_pcurve *c, const oc_curve_point *pt) {
  const piece *pc = &c->pc[pt->piece];
  return pc->deg < 2 ? 0 : oc_bez_curvature(pc->p, pc->deg, pt->t);
}

double oc_curve_grade_at(const oc_pcurve *c, const oc_curve_point *pt) {
  const piece *pc = &c->pc[pt->piece];
  oc_vec3 d = oc_bez_d1(pc->p, pc->deg, pt->t);
  double v = hypot(d.x, d.y);
  return v > 0 ? d.z / v : 0;
}

oc_aabb oc_curve_bounds(const oc_pcurve *c, double r) {
  oc_aabb b = c->box;
  b.lo.x -= r, b.lo.y -= r, b.hi.x += r, b.hi.y += r;
  return b;
}

/* ---- arc length <-> parameter ------------------------------------------ */

/* Knot j (0 .. ntab) of a Bézier piece: its parameter and its arc
** length (the ends are 0 and 0, 1 and the piece's length). */
static double knot_t(const oc_pcurve *c, const piece *pc, size_t j) {
  return j == 0 ? 0 : j == pc->ntab ? 1 : c->tt[pc->tab + j - 1];
}
static double knot_s(const oc_pcurve *c, const piece *pc, size_t j) {
  return j == 0 ? 0 : j == pc->ntab ? pc->len : c->ts[pc->tab + j - 1];
}

/* The knot span k of a Bézier piece with knot k <= t < knot k + 1. */
static size_t span_of_t(const oc_pcurve *c, const piece *pc, double t) {
  size_t lo = 0, hi = pc->ntab;
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
  if (t >= 1) return pc->len;
  if (t <= 0) return 0;
  if (pc->deg == 1) return t * pc->len;
  size_t k = span_of_t(c, pc, t);
  return knot_s(c, pc, k) + oc_bez_arclen(pc->p, pc->deg, knot_t(c, pc, k), t);
}

/* The parameter at arc length sl from the start of the piece: Newton on
** the tabulated span, safeguarded by bisection (the speed may vanish). */
static double t_of_s(const oc_pcurve *c, const piece *pc, double sl) {
  if (sl <= 0) return 0;
  if (sl >= pc->len) return 1;
  if (pc->deg == 1) return sl / pc->len;
  size_t lo = 0, hi = pc->ntab;
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

/* The tangent at (piece i, t); at a join, the bisector of both sides. */
static void tangent(const oc_pcurve *c, size_t i, double t, double *tx,
                    double *ty) {
  piece_dir(&c->pc[i], t, tx, ty);
  const piece *other = NULL;
  if (t <= 0 && (i > 0 || c->closed)) other = &c->pc[i > 0 ? i - 1 : c->n - 1];
  if (t >= 1 && (i + 1 < c->n || c->closed))
    other = &c->pc[i + 1 < c->n ? i + 1 : 0];
  if (!other) return;
  double ox, oy;
  piece_dir(other, t <= 0 ? 1 : 0, &ox, &oy);
  double sx = *tx + ox, sy = *ty + oy, v = hypot(sx, sy);
  if (v > 1e-12) *tx = sx / v, *ty = sy / v;
}

static void fill(const oc_pcurve *c, size_t i, double t, oc_curve_point *out) {
  const piece *pc = &c->pc[i];
  out->piece = i;
  out->t = t;
  out->s = pc->s0 + s_of_t(c, pc, t);
  out->q = t >= 1 ? pc->p[pc->deg] : oc_bez_eval(pc->p, pc->deg, t);
  tangent(c, i, t, &out->tx, &out->ty);
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
  s = s < 0 ? 0 : s > c->length ? c->length : s;
  size_t lo = 0, hi = c->n;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2;
    if (c->pc[m].s0 <= s)
      lo = m;
    else
      hi = m;
  }
  const piece *pc = &c->pc[lo];
  fill(c, lo, t_of_s(c, pc, s - pc->s0), out);
  out->end = 0;
  return 1;
}

/* ---- closest point --------------------------------------------------- */

static double box_d2(const bnode *b, double x, double y) {
  double dx = fmax(0, fmax(b->x0 - x, x - b->x1));
  double dy = fmax(0, fmax(b->y0 - y, y - b->y1));
  return dx * dx + dy * dy;
}

/* The distance from (a, c) to the box [alo, ahi] x [clo, chi]. */
static double box_dist(double a, double c, const double b[4]) {
  double da = fmax(fmax(b[0] - a, a - b[1]), 0);
  double dc = fmax(fmax(b[2] - c, c - b[3]), 0);
  return hypot(da, dc);
}

/* The distance from (a, c) to the segment (a1, c1) (a2, c2). */
static double seg_dist(double a, double c, double a1, double c1, double a2,
                       double c2) {
  double da = a2 - a1, dc = c2 - c1, l2 = da * da + dc * dc;
  double t = l2 > 0 ? ((a - a1) * da + (c - c1) * dc) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return hypot(a - a1 - t * da, c - c1 - t * dc);
}

/* The distance from a segment to a box (both convex): 0 where they meet,
** else the least of its ends' distances to the box and the box corners'
** to it. Whether they meet: the segment clipped to the box's slabs. */
static double seg_box_dist(double a1, double c1, double a2, double c2,
                           const double b[4]) {
  double t0 = 0, t1 = 1, d[2] = {a2 - a1, c2 - c1}, o[2] = {a1, c1};
  int meets = 1;
  for (int k = 0; k < 2 && meets; k++) {
    double lo = b[2 * k], hi = b[2 * k + 1];
    if (d[k] == 0) {
      meets = o[k] >= lo && o[k] <= hi;
      continue;
    }
    double u = (lo - o[k]) / d[k], v = (hi - o[k]) / d[k];
    if (u > v) {
      double w = u;
      u = v, v = w;
    }
    t0 = fmax(t0, u), t1 = fmin(t1, v);
    meets = t0 <= t1;
  }
  if (meets) return 0;
  double m = fmin(box_dist(a1, c1, b), box_dist(a2, c2, b));
  for (int i = 0; i < 4; i++)
    m = fmin(m, seg_dist(b[i & 1], b[2 + (i >> 1)], a1, c1, a2, c2));
  return m;
}

int oc_curve_far_from_segment(const oc_pcurve *c, double xa, double ya,
                              double xb, double yb, double r) {
  if (!(r >= 0 && r < INFINITY)) return 0;
  double M = fmax(fmax(fabs(xa), fabs(ya)), fmax(fabs(xb), fabs(yb)));
  for (size_t i = 0; i < c->n; i++) {
    const piece *pc = &c->pc[i];
    const oc_vec3 *p = pc->p;
    int n = pc->deg;
    double ux = p[n].x - p[0].x, uy = p[n].y - p[0].y, l = hypot(ux, uy);
    if (l > 0)
      ux /= l, uy /= l;
    else
      ux = 1, uy = 0;
    double b[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY}, Mp = M;
    for (int k = 0; k <= n; k++) {
      double a = p[k].x * ux + p[k].y * uy, cc = p[k].y * ux - p[k].x * uy;
      b[0] = fmin(b[0], a), b[1] = fmax(b[1], a);
      b[2] = fmin(b[2], cc), b[3] = fmax(b[3], cc);
      Mp = fmax(Mp, fmax(fabs(p[k].x), fabs(p[k].y)));
    }
    double D = seg_box_dist(xa * ux + ya * uy, ya * ux - xa * uy,
                            xb * ux + yb * uy, yb * ux - xb * uy, b);
    if (!(D - 1e-9 * Mp > r * (1 + 1e-9))) return 0;
  }
  return 1;
}

/* Whether the piece is at least sqrt(lim) from (x, y): the control points'
** box in the frame of the chord p[0] p[deg] (the piece lies in their hull,
** so in that box) is that far. */
static int far_in_frame(const piece *pc, double x, double y, double lim) {
  double ux = pc->p[pc->deg].x - pc->p[0].x, uy = pc->p[pc->deg].y - pc->p[0].y;
  double l = sqrt(ux * ux + uy * uy);
  if (!(l > 0)) return 0;
  ux /= l, uy /= l;
  double a0 = INFINITY, a1 = -INFINITY, b0 = INFINITY, b1 = -INFINITY;
  for (int k = 0; k <= pc->deg; k++) {
    double dx = pc->p[k].x - pc->p[0].x, dy = pc->p[k].y - pc->p[0].y;
    double a = dx * ux + dy * uy, b = dy * ux - dx * uy;
    a0 = a < a0 ? a : a0, a1 = a > a1 ? a : a1;
    b0 = b < b0 ? b : b0, b1 = b > b1 ? b : b1;
  }
  double dx = x - pc->p[0].x, dy = y - pc->p[0].y;
  double a = dx * ux + dy * uy, b = dy * ux - dx * uy;
  double ea = a < a0 ? a0 - a : a > a1 ? a - a1 : 0;
  double eb = b < b0 ? b0 - b : b > b1 ? b - b1 : 0;
  /* a hair for the rounding of the frame (and of the differences of
  ** coordinates far from the origin) */
  double d2 = ea * ea + eb * eb,
         pad =
             1e-9 * (l + fabs(a) + fabs(b)) +
             1e-14 * (fabs(x) + fabs(y) + fabs(pc->p[0].x) + fabs(pc->p[0].y));
  return d2 > lim + 2 * pad * sqrt(lim) + pad * pad;
}

int oc_curve_closest(const oc_pcurve *c, double x, double y, double r,
                     oc_curve_point *out) {
  if (!(r >= 0) || isnan(x) || isnan(y)) return 0;
  double lim = nextafter(r * r, INFINITY), best = lim, bt = 0;
  size_t bp = 0;
  int found = 0;
  size_t st[128];
  int top = 0;
  st[top++] = 0;
  while (top > 0) {
    const bnode *b = &c->bvh[st[--top]];
    if (box_d2(b, x, y) >= best) continue;
    if (!b->right) {
      const piece *pc = &c->pc[b->piece];
      if (far_in_frame(pc, x, y, best)) continue; /* (cannot beat best) */
      double t, d2 = oc_bez_closest(pc->p, pc->deg, x, y, best, &t);
      if (d2 < best) best = d2, bp = b->piece, bt = t, found = 1;
      continue;
    }
    size_t l = (size_t)(b - c->bvh) + 1, rr = b->right;
    double dl = box_d2(&c->bvh[l], x, y), dr = box_d2(&c->bvh[rr], x, y);
    /* nearer child on top; the tree is balanced, so 2 log2 n entries */
    if (dl <= dr) {
      st[top++] = rr;
      st[top++] = l;
    } else {
      st[top++] = l;
      st[top++] = rr;
    }
  }
  if (!found) return 0;
  fill(c, bp, bt, out);
  double cr = out->tx * (y - out->q.y) - out->ty * (x - out->q.x);
  double dist = sqrt(best);
  out->d = cr < 0 ? -dist : dist;
  return 1;
}

int oc_curve_within(const oc_pcurve *c, double x, double y, double r) {
  if (!(r >= 0) || isnan(x) || isnan(y)) return 0;
  double lim = nextafter(r * r, INFINITY);
  size_t st[128];
  int top = 0;
  st[top++] = 0;
  while (top > 0) {
    const bnode *b = &c->bvh[st[--top]];
    if (box_d2(b, x, y) >= lim) continue;
    if (b->right) {
      st[top++] = b->right;
      st[top++] = (size_t)(b - c->bvh) + 1;
      continue;
    }
    const piece *pc = &c->pc[b->piece];
    /* the ends lie on the curve: no root finding when one is near */
    for (int k = 0; k <= pc->deg; k += pc->deg) {
      double dx = pc->p[k].x - x, dy = pc->p[k].y - y;
      if (dx * dx + dy * dy < lim) return 1;
    }
    /* and its middle and quarters (on fig3's and fig22's traces, these
    ** answer 53 % of what would be root findings, and the chord's frame
    ** 75 % of the rest) */
    static const double at[3] = {0.5, 0.25, 0.75};
    for (int k = 0; pc->deg > 1 && k < 3; k++) {
      oc_vec3 m = oc_bez_eval(pc->p, pc->deg, at[k]);
      double dx = m.x - x, dy = m.y - y;
      if (dx * dx + dy * dy < lim) return 1;
    }
    if (far_in_frame(pc, x, y, lim)) continue;
    double t;
    if (oc_bez_closest(pc->p, pc->deg, x, y, lim, &t) < lim) return 1;
  }
  return 0;
}

/* ---- flattening ------------------------------------------------------- */

typedef struct flat_ctx {
  const oc_pcurve *c;
  const piece *pc;
  oc_curve_vertex *out;
  size_t cap, k;
} flat_ctx;

static void flat_emit(void *ud, double t) {
  flat_ctx *f = ud;
  if (f->out && f->k < f->cap) {
    oc_vec3 q =
        t >= 1 ? f->pc->p[f->pc->deg] : oc_bez_eval(f->pc->p, f->pc->deg, t);
    oc_curve_vertex v = {q.x, q.y, q.z, f->pc->s0 + s_of_t(f->c, f->pc, t)};
    f->out[f->k] = v;
  }
  f->k++;
}

int oc_curve_flatten(const oc_pcurve *c, double tol, oc_curve_vertex *out,
                     size_t cap, size_t *count, oc_error *err) {
  if (!(tol >= 1e-9 * c->length) || !isfinite(tol))
    return oc_seterr(err, OC_EINVAL,
                     "'tolerance' must be finite and >= %g (1e-9 of the "
                     "curve's length; got %g)",
                     1e-9 * c->length, tol);
  flat_ctx f = {c, c->pc, out, cap, 0};
  flat_emit(&f, 0);
  for (size_t i = 0; i < c->n; i++) {
    f.pc = &c->pc[i];
    oc_bez_flatten(f.pc->p, f.pc->deg, tol, flat_emit, &f);
  }
  *count = f.k;
  return OC_OK;
}
