/*
** eimage.c — the image primitive of elevation trees (Génevaux et al. 2015,
** section 4.2, figure 8): a heightfield, and an optional weight grid,
** mapped on a convex quadrangle P0 P1 P2 P3 (counter-clockwise) by
**
**   p(u, v) = P0 + e u + f v + g u v,  e = P1 - P0, f = P3 - P0,
**                                      g = P0 - P1 + P2 - P3,
**
** inverted for each point (the quadratic of the bilinear map, polished by
** Newton steps). The grid is read through its elevation source
** (oc_heightfield_elevation: the C1 bicubic and its min/max pyramid).
**
**   f = offset + height h(X(u), Y(v)) inside the quad; outside, f at the
**       closest point of the quad (projection on a convex set is
**       1-Lipschitz, so f keeps its bound over the plane);
**   alpha = clamp(w(u, v), 0, 1) prod_k G(d_k / F), d_k the distance to
**       edge k, G(x) = 1 - (1 - x^2)^3 on [0, 1] (C1: 0 with slope 0 on the
**       border, 1 with slope 0 at F inside it).
**
** Bounds. With K = dp/d(X, Y), grad f = height K^-T grad h, and
** |K^-1| <= |K|_F / det K <= sqrt(Lu^2 H^2 + Lv^2 W^2) / det J, W x H the
** grid's extent, Lu and Lv the largest |dp/du|, |dp/dv| (|e + g v|, |f + g
** u|: at the ends of v's and u's ranges) and det J = cross(e, f) +
** u cross(e, g) + v cross(g, f) (affine in u and v: its least at a corner
** of the (u, v) range, > 0 for a strictly convex quad). In a box: the
** points whose projection matters lie in the quad within r of the box (r
** the largest distance of a box corner to the quad); u and v have straight
** level lines, so their extremes over that convex polygon are at its
** vertices; the grid's pyramid gives h's range and slope over the (u, v)
** range mapped to it.
**
** Along a curve (the shared skeleton of core/curve.h: closest point, arc
** length s, curvature), (u, v) = (s / L, (d + w/2) / w), d the signed
** distance, w the width. grad s = t / (1 - kappa d) and grad d = n, so in
** the band |d| <= w/2 (w/2 kappa_max < 1, checked) |grad f| <= height
** |grad h| max(W / (L (1 - kappa_max w/2)), H / w). In a box of centre c
** and half-diagonal rho, every point's closest point of the skeleton lies
** within dist(c) + 2 rho of c, so its s lies in the spans of the
** flattened skeleton (within tol of their chords, a box tree over them)
** that come that close: u's range, and the grid's over it.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/curve.h"
#include "core/error.h"
#include "core/falloff.h"
#include "elevation/enode.h"
#include "terrain/terrain.h"

typedef struct grid {
  oc_elevation src; /* src.ud NULL: none (weight 1) */
  double x0, y0, W, H;
} grid;

/* A box of the chords' tree. */
typedef struct cbox {
  double x0, y0, x1, y1;
} cbox;

typedef struct eimage {
  grid h, w;
  double P[4][2];
  double e[2], f[2], g[2];
  double nrm[4][2], c[4]; /* inward unit normals: d_k = nrm_k . p - c_k */
  double vs, off, F;
  /* along a curve (cv not NULL): its length, half width, curvature
  ** bound, and the flattened skeleton (nfl vertices within tol) with a
  ** box tree over its chords (heap order, leaves from m) */
  oc_pcurve *cv;
  double L, hw, kap, tol;
  oc_curve_vertex *fl;
  size_t nfl, m;
  cbox *tree;
} eimage;

static const eimage *image_of(const oc_enode *n) {
  return OC_EPRIM(n)->data;
}

static double cross(const double a[2], const double b[2]) {
  return a[0] * b[1] - a[1] * b[0];
}

void oc_eimage_free(void *data) {
  eimage *d = data;
  if (!d) return;
  if (d->h.src.release) d->h.src.release(d->h.src.ud);
  if (d->w.src.release) d->w.src.release(d->w.src.ud);
  oc_curve_free(d->cv);
  free(d->fl);
  free(d->tree);
  free(d);
}

/* p(u, v) and its partial derivatives. */
static void bilin(const eimage *d, double u, double v, double p[2],
                  double pu[2], double pv[2]) {
  for (int k = 0; k < 2; k++) {
    p[k] = d->P[0][k] + d->e[k] * u + d->f[k] * v + d->g[k] * u * v;
    pu[k] = d->e[k] + d->g[k] * v;
    pv[k] = d->f[k] + d->g[k] * u;
  }
}

/* (u, v) of a point in the quad (or on its border), clamped to [0, 1]. */
static void inverse(const eimage *d, double x, double y, double *u, double *v) {
  double h[2] = {x - d->P[0][0], y - d->P[0][1]};
  double k2 = cross(d->g, d->f);
  double k1 = cross(d->e, d->f) + cross(h, d->g);
  double k0 = cross(h, d->e);
  double vv;
  if (fabs(k2) <= 1e-12 * fabs(k1)) { /* a parallelogram or trapezium */
    vv = -k0 / k1;
  } else {
    double disc = fmax(k1 * k1 - 4 * k0 * k2, 0);
    double q = -0.5 * (k1 + (k1 < 0 ? -sqrt(disc) : sqrt(disc)));
    double r1 = q / k2, r2 = q != 0 ? k0 / q : r1;
    vv = fabs(r1 - 0.5) <= fabs(r2 - 0.5) ? r1 : r2;
  }
  vv = vv < 0 ? 0 : vv > 1 ? 1 : vv == vv ? vv : 0.5;
  double a[2] = {d->e[0] + d->g[0] * vv, d->e[1] + d->g[1] * vv};
  double b[2] = {h[0] - d->f[0] * vv, h[1] - d->f[1] * vv};
  double uu = (a[0] * b[0] + a[1] * b[1]) / (a[0] * a[0] + a[1] * a[1]);
  uu = uu < 0 ? 0 : uu > 1 ? 1 : uu;
  /* Newton: p(u, v) = (x, y); the Jacobian is invertible on the quad */
  for (int it = 0; it < 3; it++) {
    double p[2], pu[2], pv[2];
    bilin(d, uu, vv, p, pu, pv);
    double rx = x - p[0], ry = y - p[1], det = cross(pu, pv);
    double du = (rx * pv[1] - ry * pv[0]) / det;
    double dv = (pu[0] * ry - pu[1] * rx) / det;
    uu += du;
    vv += dv;
    uu = uu < 0 ? 0 : uu > 1 ? 1 : uu;
    vv = vv < 0 ? 0 : vv > 1 ? 1 : vv;
  }
  *u = uu;
  *v = vv;
}

/* The grid's value at (u, v) and its derivatives in u and v. */
static double grid_at(const grid *G, double u, double v, int grad, double *gu,
                      double *gv) {
  double gr[2] = {0, 0};
  double z = G->src.height(G->src.ud, G->x0 + u * G->W, G->y0 + v * G->H,
                           grad ? gr : NULL);
  *gu = gr[0] * G->W;
  *gv = gr[1] * G->H;
  return z;
}

/* G(x) = 1 - (1 - x^2)^3 on [0, 1], and G'. */
static double ramp(double x, double *dg) {
  if (x <= 0) {
    *dg = 0;
    return 0;
  }
  if (x >= 1) {
    *dg = 0;
    return 1;
  }
  *dg = -oc_falloff_d(x);
  return 1 - oc_falloff(x);
}

/* alpha = clamp(w(u, v), 0, 1) prod_k G(e_k / F), from the four edge
** coordinates e_k (distances inside) and their gradients (ex_k, ey_k),
** with grad u = gu and grad v = gv for the weight grid's chain rule. */
static void edge_alpha(const eimage *d, const double e[4], const double ex[4],
                       const double ey[4], double u, double v,
                       const double gu[2], const double gv[2], int grad,
                       oc_enode_sample *s) {
  double G[4], dG[4], ab = 1;
  for (int k = 0; k < 4; k++) {
    G[k] = ramp(e[k] / d->F, &dG[k]);
    ab *= G[k];
  }
  double w = 1, wx = 0, wy = 0;
  if (ab > 0 && d->w.src.ud) { /* (alpha = 0 whatever w is) */
    double wu, wv;
    w = grid_at(&d->w, u, v, grad, &wu, &wv);
    if (w <= 0) {
      w = 0;
    } else if (w >= 1) {
      w = 1;
    } else {
      wx = wu * gu[0] + wv * gv[0];
      wy = wu * gu[1] + wv * gv[1];
    }
  }
  s->a = w * ab;
  if (grad && s->a != 0) {
    double bx = 0, by = 0;
    for (int k = 0; k < 4; k++) {
      double o = dG[k] / d->F;
      for (int j = 0; j < 4; j++)
        if (j != k) o *= G[j];
      bx += o * ex[k];
      by += o * ey[k];
    }
    s->ax = ab * wx + w * bx;
    s->ay = ab * wy + w * by;
  }
}

/* Along a curve: (u, v) from the closest point, grad u and grad v. */
static void curve_ev(const eimage *d, double x, double y, int want,
                     oc_enode_sample *s) {
  int grad = want & OC_EV_GRAD, lazy = want & (OC_EV_LAZY | OC_EV_ALPHA);
  oc_curve_point pt;
  s->f = s->a = s->ax = s->ay = s->fx = s->fy = 0;
  /* alpha = 0 farther than w/2: a lazy caller needs only the band */
  if (!oc_curve_closest(d->cv, x, y, lazy ? d->hw : INFINITY, &pt)) {
    if (!lazy) s->f = s->a = NAN;
    return;
  }
  /* beyond an end: the offset along the end's normal, s constant */
  double dl = pt.end ? (x - pt.q.x) * pt.nx + (y - pt.q.y) * pt.ny : pt.d;
  double gsx = 0, gsy = 0;
  if (grad && !pt.end) {
    double den = 1 - oc_curve_curvature_at(d->cv, &pt) * dl;
    if (den > 0) {
      gsx = pt.tx / den;
      gsy = pt.ty / den;
    }
  }
  double u = pt.s / d->L, v = (dl + d->hw) / (2 * d->hw);
  int vin = v > 0 && v < 1;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  v = v < 0 ? 0 : v > 1 ? 1 : v;
  double gux = gsx / d->L, guy = gsy / d->L;
  double gvx = vin ? pt.nx / (2 * d->hw) : 0,
         gvy = vin ? pt.ny / (2 * d->hw) : 0;
  /* alpha: the ramps of the four edge coordinates s, L - s, w/2 - d and
  ** w/2 + d (0 at an end, where s is 0 or L) */
  double ec[4] = {pt.s, d->L - pt.s, d->hw - dl, d->hw + dl};
  double egx[4] = {gsx, -gsx, -pt.nx, pt.nx},
         egy[4] = {gsy, -gsy, -pt.ny, pt.ny};
  double gu[2] = {gux, guy}, gv[2] = {gvx, gvy};
  edge_alpha(d, ec, egx, egy, u, v, gu, gv, grad, s);
  if (want & OC_EV_ALPHA || (lazy && s->a == 0)) return;
  double fu, fv;
  s->f = d->off + d->vs * grid_at(&d->h, u, v, grad, &fu, &fv);
  if (grad) {
    s->fx = d->vs * (fu * gux + fv * gvx);
    s->fy = d->vs * (fu * guy + fv * gvy);
  }
}

void oc_eimage_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                  int want, oc_enode_sample *s) {
  if (image_of(n)->cv) {
    curve_ev(image_of(n), x, y, want, s);
    return;
  }
  (void)ft; /* no detail to filter */
  const eimage *d = OC_EPRIM(n)->data;
  int grad = want & OC_EV_GRAD;
  double dk[4];
  int inside = 1;
  for (int k = 0; k < 4; k++) {
    dk[k] = d->nrm[k][0] * x + d->nrm[k][1] * y - d->c[k];
    inside &= dk[k] >= 0;
  }
  s->a = s->ax = s->ay = s->fx = s->fy = 0;
  double u, v, tan[2] = {0, 0}; /* outside: the edge's direction, or 0 */
  if (inside) {
    inverse(d, x, y, &u, &v);
  } else {
    if (want & OC_EV_LAZY) {
      s->f = 0;
      return;
    }
    /* the closest point of the border; (u, v) exact on it */
    double best = INFINITY;
    u = v = 0;
    for (int k = 0; k < 4; k++) {
      const double *A = d->P[k], *B = d->P[(k + 1) & 3];
      double E[2] = {B[0] - A[0], B[1] - A[1]}, L2 = E[0] * E[0] + E[1] * E[1];
      double t = ((x - A[0]) * E[0] + (y - A[1]) * E[1]) / L2;
      int mid = t > 0 && t < 1;
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      double qx = A[0] + t * E[0] - x, qy = A[1] + t * E[1] - y;
      double dd = qx * qx + qy * qy;
      if (dd < best) {
        best = dd;
        double uv[4][2] = {{t, 0}, {1, t}, {1 - t, 1}, {0, 1 - t}};
        u = uv[k][0];
        v = uv[k][1];
        double L = sqrt(L2);
        tan[0] = mid ? E[0] / L : 0;
        tan[1] = mid ? E[1] / L : 0;
      }
    }
  }
  double p[2], pu[2], pv[2], fu, fv;
  bilin(d, u, v, p, pu, pv);
  s->f = d->off + d->vs * grid_at(&d->h, u, v, grad, &fu, &fv);
  /* grad u = (pv.y, -pv.x) / det, grad v = (-pu.y, pu.x) / det */
  double det = cross(pu, pv);
  double gux = pv[1] / det, guy = -pv[0] / det;
  double gvx = -pu[1] / det, gvy = pu[0] / det;
  if (grad) {
    double gx = d->vs * (fu * gux + fv * gvx),
           gy = d->vs * (fu * guy + fv * gvy);
    if (inside) {
      s->fx = gx;
      s->fy = gy;
    } else { /* through the projection: its tangential part */
      double t = gx * tan[0] + gy * tan[1];
      s->fx = t * tan[0];
      s->fy = t * tan[1];
    }
  }
  if (!inside) return;
  /* alpha */
  double ex[4], ey[4], gu[2] = {gux, guy}, gv[2] = {gvx, gvy};
  for (int k = 0; k < 4; k++)
    ex[k] = d->nrm[k][0], ey[k] = d->nrm[k][1];
  edge_alpha(d, dk, ex, ey, u, v, gu, gv, grad, s);
}

/* ---- bounds ------------------------------------------------------------ */

/* The squared distance from (x, y) to the segment A B. */
static double seg_dist2(const double A[2], const double B[2], double x,
                        double y) {
  double E[2] = {B[0] - A[0], B[1] - A[1]}, L2 = E[0] * E[0] + E[1] * E[1];
  double t = L2 > 0 ? ((x - A[0]) * E[0] + (y - A[1]) * E[1]) / L2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  double qx = A[0] + t * E[0] - x, qy = A[1] + t * E[1] - y;
  return qx * qx + qy * qy;
}

static double dist_to_quad(const eimage *d, double x, double y) {
  int inside = 1;
  for (int k = 0; k < 4; k++)
    inside &= d->nrm[k][0] * x + d->nrm[k][1] * y - d->c[k] >= 0;
  if (inside) return 0;
  double best = INFINITY;
  for (int k = 0; k < 4; k++) {
    const double *A = d->P[k], *B = d->P[(k + 1) & 3];
    double E[2] = {B[0] - A[0], B[1] - A[1]};
    double t =
        ((x - A[0]) * E[0] + (y - A[1]) * E[1]) / (E[0] * E[0] + E[1] * E[1]);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    best = fmin(best, hypot(A[0] + t * E[0] - x, A[1] + t * E[1] - y));
  }
  return best;
}

/* The (u, v) range of the quad's part within the rectangle r: the
** rectangle clipped by the quad's four half-planes (Sutherland-Hodgman),
** its vertices inverted. 0 when nothing is left. */
static int uv_range(const eimage *d, const oc_erect *r, double uv[4]) {
  double P[16][2], Q[16][2];
  int n = 4;
  P[0][0] = r->x0, P[0][1] = r->y0;
  P[1][0] = r->x1, P[1][1] = r->y0;
  P[2][0] = r->x1, P[2][1] = r->y1;
  P[3][0] = r->x0, P[3][1] = r->y1;
  for (int k = 0; k < 4 && n > 0; k++) {
    int m = 0;
    for (int i = 0; i < n; i++) {
      const double *A = P[i], *B = P[(i + 1) % n];
      double da = d->nrm[k][0] * A[0] + d->nrm[k][1] * A[1] - d->c[k];
      double db = d->nrm[k][0] * B[0] + d->nrm[k][1] * B[1] - d->c[k];
      if (da >= 0) Q[m][0] = A[0], Q[m][1] = A[1], m++;
      if ((da >= 0) != (db >= 0)) {
        double t = da / (da - db);
        Q[m][0] = A[0] + t * (B[0] - A[0]);
        Q[m][1] = A[1] + t * (B[1] - A[1]);
        m++;
      }
    }
    n = m;
    for (int i = 0; i < n; i++)
      P[i][0] = Q[i][0], P[i][1] = Q[i][1];
  }
  if (n == 0) return 0;
  uv[0] = uv[1] = INFINITY;
  uv[2] = uv[3] = -INFINITY;
  for (int i = 0; i < n; i++) {
    double u, v;
    inverse(d, P[i][0], P[i][1], &u, &v);
    uv[0] = fmin(uv[0], u);
    uv[1] = fmin(uv[1], v);
    uv[2] = fmax(uv[2], u);
    uv[3] = fmax(uv[3], v);
  }
  /* the clipped vertices and their inversion round off */
  double pad = 1e-9;
  uv[0] = fmax(0, uv[0] - pad);
  uv[1] = fmax(0, uv[1] - pad);
  uv[2] = fmin(1, uv[2] + pad);
  uv[3] = fmin(1, uv[3] + pad);
  return 1;
}

/* Range of a grid over the (u, v) rectangle, and its slope bound there in
** the grid's units. */
static double grid_range(const grid *G, const double uv[4], double *lo,
                         double *hi) {
  const oc_elevation *s = &G->src;
  double X0 = G->x0 + uv[0] * G->W, X1 = G->x0 + uv[2] * G->W;
  double Y0 = G->y0 + uv[1] * G->H, Y1 = G->y0 + uv[3] * G->H;
  s->range(s->ud, X0, Y0, X1, Y1, lo, hi);
  return s->slope(s->ud, X0, Y0, X1, Y1);
}

/* The same, the slope as a function of p: through |K^-1|. */
static void grid_bound(const eimage *d, const grid *G, const double uv[4],
                       double *lo, double *hi, double *lip) {
  double gs = grid_range(G, uv, lo, hi);
  double detmin = INFINITY, Lu = 0, Lv = 0;
  for (int c = 0; c < 4; c++) {
    double u = uv[c & 1 ? 2 : 0], v = uv[c & 2 ? 3 : 1];
    double p[2], pu[2], pv[2];
    bilin(d, u, v, p, pu, pv);
    detmin = fmin(detmin, cross(d->e, d->f) + u * cross(d->e, d->g) +
                              v * cross(d->g, d->f));
    Lu = fmax(Lu, hypot(pu[0], pu[1]));
    Lv = fmax(Lv, hypot(pv[0], pv[1]));
  }
  *lip = gs * hypot(Lu * G->H, Lv * G->W) / detmin * (1 + 1e-9);
}

/* The arc lengths [*s0, *s1] of the skeleton's spans whose chord comes
** within r of (x, y): node k of the chords' tree holds chords [i, i +
** len). Spans already inside [*s0, *s1] are skipped. */
static void spans_near(const eimage *d, size_t k, size_t i, size_t len,
                       double x, double y, double r, double *s0, double *s1) {
  size_t nc = d->nfl - 1;
  if (i >= nc) return;
  const cbox *b = &d->tree[k];
  double dx = fmax(fmax(b->x0 - x, x - b->x1), 0);
  double dy = fmax(fmax(b->y0 - y, y - b->y1), 0);
  if (dx * dx + dy * dy > r * r) return;
  size_t j = i + len < nc ? i + len : nc;
  if (d->fl[i].s >= *s0 && d->fl[j].s <= *s1) return;
  if (len == 1) {
    double A[2] = {d->fl[i].x, d->fl[i].y},
           B[2] = {d->fl[i + 1].x, d->fl[i + 1].y};
    if (seg_dist2(A, B, x, y) <= r * r) {
      *s0 = fmin(*s0, d->fl[i].s);
      *s1 = fmax(*s1, d->fl[i + 1].s);
    }
    return;
  }
  spans_near(d, 2 * k, i, len / 2, x, y, r, s0, s1);
  spans_near(d, 2 * k + 1, i + len / 2, len / 2, x, y, r, s0, s1);
}

/* |grad s| in the band, bounded. */
static double band_ds(const eimage *d) {
  return 1 / (1 - d->kap * d->hw);
}

static void curve_bound_in(const eimage *d, const oc_erect *b, oc_ebound *o) {
  double cx = 0.5 * (b->x0 + b->x1), cy = 0.5 * (b->y0 + b->y1);
  double rho = 0.5 * hypot(b->x1 - b->x0, b->y1 - b->y0);
  oc_curve_point pt;
  double dc = INFINITY, s0 = 0, s1 = d->L;
  /* (the closest point alone: its arc length is not read) */
  if (oc_curve_closest_t(d->cv, cx, cy, INFINITY, &pt)) {
    dc = hypot(cx - pt.q.x, cy - pt.q.y);
    /* every point of b has its closest point within dc + 2 rho of c,
    ** within tol of a chord of its span (and a hair for rounding) */
    double r = (dc + 2 * rho) * (1 + 1e-12) + d->tol +
               1e-12 * (d->L + fabs(cx) + fabs(cy));
    s0 = INFINITY, s1 = -INFINITY;
    spans_near(d, 1, 0, d->m, cx, cy, r, &s0, &s1);
    if (!(s0 <= s1)) s0 = 0, s1 = d->L; /* (rounding: all of it) */
  }
  double pad = 1e-9;
  double uv[4] = {fmax(0, s0 / d->L - pad), 0, fmin(1, s1 / d->L + pad), 1};
  double lo, hi, ds = band_ds(d);
  double gs = grid_range(&d->h, uv, &lo, &hi);
  double a = d->off + d->vs * lo, z = d->off + d->vs * hi;
  double m = 1e-12 * (1 + fabs(a) + fabs(z));
  o->flo = fmin(a, z) - m;
  o->fhi = fmax(a, z) + m;
  o->lf = fabs(d->vs) * gs * fmax(d->h.W * ds / d->L, d->h.H / (2 * d->hw)) *
          (1 + 1e-9);
  /* alpha: 0 unless b comes within w/2 of the skeleton (|d| <= dc + rho
  ** on b) */
  o->alo = o->ahi = o->la = 0;
  if (!(dc - rho < d->hw)) return;
  double wlo = 1, whi = 1, lw = 0;
  if (d->w.src.ud) {
    double wg = grid_range(&d->w, uv, &wlo, &whi);
    lw = wg * fmax(d->w.W * ds / d->L, d->w.H / (2 * d->hw));
    whi = fmin(fmax(whi, 0), 1);
  }
  /* the ramps rise with their edge coordinate: s in [s0, s1], L - s in
  ** [L - s1, L - s0], w/2 -+ d in [w/2 - dh, w/2 + dh], dh = min(w/2,
  ** dc + rho) */
  double F = d->F, dh = fmin(d->hw, dc + rho), dg;
  double bhi = ramp(s1 / F, &dg) * ramp((d->L - s0) / F, &dg) *
               ramp((d->hw - fmax(0, dc - rho)) / F, &dg);
  double lb = (oc_falloff_slope_in(s0 / F, s1 / F) +
               oc_falloff_slope_in((d->L - s1) / F, (d->L - s0) / F)) *
                  ds / F +
              2 * oc_falloff_slope_in((d->hw - dh) / F, (d->hw + dh) / F) / F;
  o->ahi = fmin(1, whi * bhi * (1 + 1e-12));
  o->la = (bhi * lw + whi * lb) * (1 + 1e-9);
}

void oc_eimage_bound_in(const oc_enode *n, const oc_erect *b,
                        const oc_efootb *fb, oc_ebound *o) {
  if (image_of(n)->cv) {
    curve_bound_in(image_of(n), b, o);
    return;
  }
  (void)fb;
  const eimage *d = OC_EPRIM(n)->data;
  /* f: over the quad within r of b */
  double r = 0;
  for (int c = 0; c < 4; c++)
    r = fmax(r, dist_to_quad(d, c & 1 ? b->x1 : b->x0, c & 2 ? b->y1 : b->y0));
  r = r * (1 + 1e-9) + 1e-9 * (1 + fabs(b->x1 - b->x0) + fabs(b->y1 - b->y0));
  oc_erect g = {b->x0 - r, b->y0 - r, b->x1 + r, b->y1 + r};
  double uv[4] = {0, 0, 1, 1}, lo, hi, lh;
  if (!uv_range(d, &g, uv)) uv[0] = uv[1] = 0, uv[2] = uv[3] = 1;
  grid_bound(d, &d->h, uv, &lo, &hi, &lh);
  double a = d->off + d->vs * lo, z = d->off + d->vs * hi;
  double m = 1e-12 * (1 + fabs(a) + fabs(z));
  o->flo = fmin(a, z) - m;
  o->fhi = fmax(a, z) + m;
  o->lf = fabs(d->vs) * lh;
  /* alpha: zero unless b meets the quad */
  o->alo = o->ahi = o->la = 0;
  double dl[4], dh[4];
  for (int k = 0; k < 4; k++) {
    double v0 = d->nrm[k][0] * b->x0, v1 = d->nrm[k][0] * b->x1;
    double w0 = d->nrm[k][1] * b->y0, w1 = d->nrm[k][1] * b->y1;
    dl[k] = fmin(v0, v1) + fmin(w0, w1) - d->c[k];
    dh[k] = fmax(v0, v1) + fmax(w0, w1) - d->c[k];
    if (!(dh[k] > 0)) return;
  }
  if (!uv_range(d, b, uv)) return;
  double wlo = 1, whi = 1, lw = 0;
  if (d->w.src.ud) {
    grid_bound(d, &d->w, uv, &wlo, &whi, &lw);
    wlo = fmin(fmax(wlo, 0), 1);
    whi = fmin(fmax(whi, 0), 1);
  }
  double blo = 1, bhi = 1, lb = 0, dg;
  for (int k = 0; k < 4; k++) {
    double sl = dl[k] / d->F, sh = dh[k] / d->F;
    blo *= ramp(sl, &dg);
    bhi *= ramp(sh, &dg);
    lb += oc_falloff_slope_in(sl, sh) / d->F;
  }
  o->alo = fmax(0, wlo * blo * (1 - 1e-12) - 1e-300);
  o->ahi = fmin(1, whi * bhi * (1 + 1e-12));
  o->la = (bhi * lw + whi * lb) * (1 + 1e-9);
}

/* ---- construction ----------------------------------------------------- */

static int take_grid(oc_heightfield *hf, grid *G, oc_error *err) {
  if (oc_heightfield_elevation(hf, &G->src, err)) return err->code;
  G->x0 = G->src.x0;
  G->y0 = G->src.y0;
  G->W = G->src.x1 - G->src.x0;
  G->H = G->src.y1 - G->src.y0;
  return OC_OK;
}

/* The corners of p's quad (or of its segment's rectangle); 0 or an error
** naming the field. */
static int corners(const oc_enode_image_params *p, double P[4][2],
                   oc_error *err) {
  const char *name = p->segment ? "segment" : "quad";
  if (p->segment) {
    for (int k = 0; k < 4; k++)
      if (!isfinite(p->seg[k]))
        return oc_seterr(err, OC_EINVAL,
                         "'segment' must have finite coordinates");
    if (!(isfinite(p->width) && p->width > 0))
      return oc_seterr(err, OC_EINVAL,
                       "'width' must be a positive number (got %g)", p->width);
    double tx = p->seg[2] - p->seg[0], ty = p->seg[3] - p->seg[1];
    double L = hypot(tx, ty);
    if (!(L > 0) || !isfinite(L))
      return oc_seterr(err, OC_EINVAL,
                       "'segment' must join two distinct points");
    double nx = -ty / L * p->width / 2, ny = tx / L * p->width / 2;
    double c[4][2] = {{p->seg[0] - nx, p->seg[1] - ny},
                      {p->seg[2] - nx, p->seg[3] - ny},
                      {p->seg[2] + nx, p->seg[3] + ny},
                      {p->seg[0] + nx, p->seg[1] + ny}};
    for (int k = 0; k < 4; k++)
      P[k][0] = c[k][0], P[k][1] = c[k][1];
  } else {
    for (int k = 0; k < 4; k++) {
      P[k][0] = p->quad[2 * k];
      P[k][1] = p->quad[2 * k + 1];
      if (!isfinite(P[k][0]) || !isfinite(P[k][1]))
        return oc_seterr(err, OC_EINVAL,
                         "'quad[%d]' must have finite coordinates", k + 1);
    }
  }
  int pos = 0, neg = 0;
  for (int k = 0; k < 4; k++) {
    const double *A = P[k], *B = P[(k + 1) & 3], *C = P[(k + 2) & 3];
    double E[2] = {B[0] - A[0], B[1] - A[1]}, F[2] = {C[0] - B[0], C[1] - B[1]};
    double le = hypot(E[0], E[1]), lf = hypot(F[0], F[1]);
    if (!(le > 0 && lf > 0) || !isfinite(le * lf))
      return oc_seterr(err, OC_EINVAL,
                       "'%s' is degenerate (corners %d and %d coincide, or "
                       "are too far apart)",
                       name, k + 1, (k + 1) % 4 + 1);
    double sn = cross(E, F) / (le * lf); /* the sine of the turn at B */
    if (fabs(sn) < 1e-6)
      return oc_seterr(err, OC_EINVAL,
                       "'%s' is degenerate: corners %d, %d and %d are in line",
                       name, k + 1, (k + 1) % 4 + 1, (k + 2) % 4 + 1);
    pos += sn > 0;
    neg += sn < 0;
  }
  if (neg == 4)
    return oc_seterr(err, OC_EINVAL,
                     "'quad' must be counter-clockwise (its corners go "
                     "clockwise: reverse them)");
  if (pos != 4) return oc_seterr(err, OC_EINVAL, "'%s' must be convex", name);
  /* a convex polygon turns once: a self-crossing one turns more */
  double ang = 0;
  for (int k = 0; k < 4; k++) {
    const double *A = P[k], *B = P[(k + 1) & 3], *C = P[(k + 2) & 3];
    double E[2] = {B[0] - A[0], B[1] - A[1]}, F[2] = {C[0] - B[0], C[1] - B[1]};
    ang += atan2(cross(E, F), E[0] * F[0] + E[1] * F[1]);
  }
  if (ang > 7)
    return oc_seterr(err, OC_EINVAL, "'%s' must be convex (it crosses itself)",
                     name);
  return OC_OK;
}

#define MAX_CHORDS ((size_t)1 << 20)

/* The skeleton of an image along a curve, checked, flattened and its
** chords' tree built; its area in *area. 0 or an error naming the field. */
static int along_curve(eimage *d, const oc_enode_image_params *p, double *area,
                       oc_error *err) {
  if (!(isfinite(p->width) && p->width > 0))
    return oc_seterr(err, OC_EINVAL,
                     "'width' must be a positive number (got %g)", p->width);
  if (p->ncurve < 2)
    return oc_seterr(err, OC_EINVAL,
                     "'curve' must hold at least 2 points (got %zu)",
                     p->ncurve);
  if ((unsigned)p->spline > OC_ECURVE_LINEAR)
    return oc_seterr(err, OC_EINVAL, "image: unknown 'spline'");
  if (!(d->cv = oc_ecurve_skeleton(p->curve, p->ncurve, p->spline, err))) {
    char m[sizeof err->msg];
    snprintf(m, sizeof m, "%s", err->msg);
    return oc_seterr(err, err->code, "'curve': %s", m);
  }
  if (oc_curve_closed(d->cv))
    return oc_seterr(err, OC_EINVAL,
                     "'curve' must be open (its ends meet: the grid's x "
                     "would jump there)");
  double turn = oc_curve_max_turn(d->cv);
  if (turn > 1e-6)
    return oc_seterr(err, OC_EINVAL,
                     "'curve' has a corner of %g degrees, where the closest "
                     "point jumps: use spline = \"catmull\" (the default) "
                     "or smooth Bézier joins",
                     turn * 180 / 3.14159265358979323846);
  d->hw = p->width / 2;
  d->kap = oc_curve_kappa_max(d->cv);
  if (!(d->kap * d->hw < 1))
    return oc_seterr(err, OC_EINVAL,
                     "'width' %g: its half is not below the curve's smallest "
                     "radius of curvature %g, so the cross-sections would "
                     "overlap (space the points out or lower 'width')",
                     p->width, 1 / d->kap);
  d->L = oc_curve_length(d->cv);
  d->tol = fmax(fmin(d->hw, d->L) / 16, 2e-9 * d->L);
  size_t nv;
  if (oc_curve_flatten(d->cv, d->tol, NULL, 0, &nv, err)) return err->code;
  if (nv < 2 || nv - 1 > MAX_CHORDS)
    return oc_seterr(err, OC_EINVAL,
                     "'curve': %zu chords to bound it within %g, at most %zu "
                     "(a curve too long for its width)",
                     nv - 1, d->tol, MAX_CHORDS);
  if (!(d->fl = malloc(nv * sizeof *d->fl)))
    return oc_seterr(err, OC_ENOMEM, "out of memory (%zu vertices)", nv);
  if (oc_curve_flatten(d->cv, d->tol, d->fl, nv, &d->nfl, err))
    return err->code;
  size_t nc = d->nfl - 1;
  for (d->m = 1; d->m < nc; d->m *= 2)
    ;
  if (!(d->tree = malloc(2 * d->m * sizeof *d->tree)))
    return oc_seterr(err, OC_ENOMEM, "out of memory (%zu chords)", nc);
  for (size_t i = 0; i < d->m; i++) {
    cbox *b = &d->tree[d->m + i];
    *b = (cbox){INFINITY, INFINITY, -INFINITY, -INFINITY};
    if (i < nc) {
      const oc_curve_vertex *A = &d->fl[i], *B = &d->fl[i + 1];
      *b = (cbox){fmin(A->x, B->x), fmin(A->y, B->y), fmax(A->x, B->x),
                  fmax(A->y, B->y)};
    }
  }
  for (size_t k = d->m - 1; k >= 1; k--) {
    const cbox *l = &d->tree[2 * k], *r = &d->tree[2 * k + 1];
    d->tree[k] = (cbox){fmin(l->x0, r->x0), fmin(l->y0, r->y0),
                        fmax(l->x1, r->x1), fmax(l->y1, r->y1)};
  }
  *area = d->L * p->width;
  return OC_OK;
}

oc_enode *oc_enode_image(const oc_enode_image_params *p, oc_error *err) {
  if (!p || !p->heightfield) {
    oc_seterr(err, OC_EINVAL, "image: no 'heightfield'");
    return NULL;
  }
  double vs = p->height == 0 ? 1 : p->height;
  if (!isfinite(vs)) {
    oc_seterr(err, OC_EINVAL, "'height' must be a finite number (got %g)",
              p->height);
    return NULL;
  }
  if (!isfinite(p->offset)) {
    oc_seterr(err, OC_EINVAL, "'offset' must be a finite number (got %g)",
              p->offset);
    return NULL;
  }
  if (!(isfinite(p->falloff) && p->falloff >= 0)) {
    oc_seterr(err, OC_EINVAL, "'falloff' must be a positive number (got %g)",
              p->falloff);
    return NULL;
  }
  eimage *d = calloc(1, sizeof *d);
  if (!d) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  double area = 0;
  if (p->curve && p->segment) {
    oc_seterr(err, OC_EINVAL, "image: give 'curve' or 'segment', not both");
    goto fail;
  }
  if (p->curve) {
    if (along_curve(d, p, &area, err)) goto fail;
  } else {
    if (corners(p, d->P, err)) goto fail;
    for (int k = 0; k < 2; k++) {
      d->e[k] = d->P[1][k] - d->P[0][k];
      d->f[k] = d->P[3][k] - d->P[0][k];
      d->g[k] = d->P[0][k] - d->P[1][k] + d->P[2][k] - d->P[3][k];
    }
    for (int k = 0; k < 4; k++) {
      const double *A = d->P[k], *B = d->P[(k + 1) & 3];
      double ex = B[0] - A[0], ey = B[1] - A[1], L = hypot(ex, ey);
      d->nrm[k][0] = -ey / L; /* left of a counter-clockwise edge: inward */
      d->nrm[k][1] = ex / L;
      d->c[k] = d->nrm[k][0] * A[0] + d->nrm[k][1] * A[1];
      area += cross(A, B) / 2;
    }
  }
  d->vs = vs;
  d->off = p->offset;
  /* (along a curve, also at most a quarter of the width: the side ramps
  ** reach 1) */
  d->F = p->falloff > 0 ? p->falloff
         : d->cv        ? fmin(sqrt(area) / 10, d->hw / 2)
                        : sqrt(area) / 10;
  if (take_grid(p->heightfield, &d->h, err)) goto fail;
  if (p->weight && take_grid(p->weight, &d->w, err)) goto fail;
  oc_eprim *n =
      (oc_eprim *)oc_enode_alloc(OC_E_IMAGE, sizeof(oc_eprim), NULL, 0, err);
  if (!n) goto fail;
  n->data = d;
  n->box = (oc_erect){INFINITY, INFINITY, -INFINITY, -INFINITY};
  if (d->cv) {
    oc_aabb bx = oc_curve_bounds(d->cv, d->hw);
    n->box = (oc_erect){bx.lo.x, bx.lo.y, bx.hi.x, bx.hi.y};
  }
  for (int k = 0; k < 4 && !d->cv; k++) {
    n->box.x0 = fmin(n->box.x0, d->P[k][0]);
    n->box.y0 = fmin(n->box.y0, d->P[k][1]);
    n->box.x1 = fmax(n->box.x1, d->P[k][0]);
    n->box.y1 = fmax(n->box.y1, d->P[k][1]);
  }
  oc_eimage_bound_in(&n->h, &n->box, NULL, &n->glob);
  n->glob.alo = 0;
  if (!isfinite(n->glob.flo) || !isfinite(n->glob.fhi) ||
      !isfinite(n->glob.lf) || !isfinite(n->glob.la) || !isfinite(d->F) ||
      !(d->F > 0)) {
    oc_seterr(err, OC_EINVAL,
              "image: its elevations or slopes overflow (height %g, offset "
              "%g, falloff %g)",
              vs, p->offset, d->F);
    oc_enode_release(&n->h);
    return NULL;
  }
  return &n->h;
fail:
  oc_eimage_free(d);
  return NULL;
}

int oc_eimage_bytes(const void *data, oc_pmap *seen, size_t *bytes) {
  const eimage *d = data;
  const grid *gs[2] = {&d->h, &d->w};
  *bytes = sizeof *d;
  if (d->cv) /* along a curve: its skeleton, flattening and chords' tree */
    *bytes += oc_curve_bytes(d->cv) + d->nfl * sizeof *d->fl +
              2 * d->m * sizeof *d->tree;
  for (int k = 0; k < 2; k++) {
    if (!gs[k]->src.ud) continue;
    const oc_heightfield *hf;
    size_t hb;
    *bytes += oc_hfsrc_bytes(&gs[k]->src, &hf, &hb);
    if (!hf || oc_pmap_slot(seen, hf, 0)) continue; /* counted */
    if (!oc_pmap_slot(seen, hf, 1)) return OC_ENOMEM;
    *bytes += hb;
  }
  return OC_OK;
}
