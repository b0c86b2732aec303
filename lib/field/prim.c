/*
** prim.c — primitive constructors and the distance functions behind them.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "field/node.h"
#include "field/prim.h"

#define MAX_CURVE_POINTS 1000000

static void put(double *par, int at, oc_vec3 v) {
  par[at] = v.x;
  par[at + 1] = v.y;
  par[at + 2] = v.z;
}
static oc_vec3 get(const double *par, int at) {
  return oc_v3(par[at], par[at + 1], par[at + 2]);
}

static oc_node *dist_prim(oc_kind k, double R, const char *rname, double E,
                          oc_error *err) {
  if (!oc_check_positive(R, rname, err) || !oc_check_finite(E, "energy", err))
    return NULL;
  oc_node *n = oc_node_alloc(k, NULL, 0, err);
  if (n) {
    n->par[OC_P_E] = E;
    n->par[OC_P_R] = R;
  }
  return n;
}

oc_node *oc_point(oc_vec3 c, double radius, double energy, oc_error *err) {
  if (!oc_check_vec(c, "center", err)) return NULL;
  oc_node *n = dist_prim(OC_K_POINT, radius, "radius", energy, err);
  if (n) put(n->par, OC_P_C, c);
  return n;
}

oc_node *oc_sphere(oc_vec3 c, double radius, double falloff, double energy,
                   oc_error *err) {
  if (!oc_check_vec(c, "center", err) ||
      !oc_check_positive(radius, "radius", err))
    return NULL;
  oc_node *n = dist_prim(OC_K_SPHERE, falloff, "falloff", energy, err);
  if (n) {
    put(n->par, OC_P_C, c);
    n->par[OC_P_RAD] = radius;
  }
  return n;
}

oc_node *oc_box(oc_vec3 lo, oc_vec3 hi, double falloff, double energy,
                oc_error *err) {
  if (!oc_check_vec(lo, "min", err) || !oc_check_vec(hi, "max", err))
    return NULL;
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) {
    oc_seterr(err, OC_EINVAL, "'min' must be <= 'max' on every axis");
    return NULL;
  }
  oc_node *n = dist_prim(OC_K_BOX, falloff, "falloff", energy, err);
  if (n) {
    put(n->par, OC_P_LO, lo);
    put(n->par, OC_P_HI, hi);
  }
  return n;
}

oc_node *oc_segment(oc_vec3 a, oc_vec3 b, double radius, double energy,
                    oc_error *err) {
  if (!oc_check_vec(a, "a", err) || !oc_check_vec(b, "b", err)) return NULL;
  oc_node *n = dist_prim(OC_K_SEGMENT, radius, "radius", energy, err);
  if (n) {
    put(n->par, OC_P_A, a);
    put(n->par, OC_P_B, b);
  }
  return n;
}

oc_node *oc_cone(oc_vec3 base, oc_vec3 apex, double radius, double falloff,
                 double energy, oc_error *err) {
  if (!oc_check_vec(base, "base", err) || !oc_check_vec(apex, "apex", err) ||
      !oc_check_positive(radius, "radius", err))
    return NULL;
  oc_vec3 ax = oc_sub(apex, base);
  if (!(oc_len(ax) > 0)) {
    oc_seterr(err, OC_EINVAL, "'apex' must differ from 'base'");
    return NULL;
  }
  oc_node *n = dist_prim(OC_K_CONE, falloff, "falloff", energy, err);
  if (n) {
    put(n->par, OC_P_A, base);
    put(n->par, OC_P_B, apex);
    n->par[OC_P_CONE_R] = radius;
  }
  return n;
}

oc_node *oc_plane(oc_vec3 origin, oc_vec3 normal, double falloff, double energy,
                  oc_error *err) {
  if (!oc_check_vec(origin, "origin", err) ||
      !oc_check_vec(normal, "normal", err))
    return NULL;
  double l = oc_len(normal);
  if (!(l > 0) || !isfinite(l)) {
    oc_seterr(err, OC_EINVAL, "'normal' must be a non-zero vector");
    return NULL;
  }
  oc_node *n = dist_prim(OC_K_PLANE, falloff, "falloff", energy, err);
  if (n) {
    put(n->par, OC_P_O, origin);
    put(n->par, OC_P_N, oc_mul(normal, 1.0 / l));
  }
  return n;
}

oc_node *oc_turbulence(const oc_noise *noise, oc_error *err) {
  if (!oc_check_noise(noise, err)) return NULL;
  oc_node *n = oc_node_alloc(OC_K_TURB, NULL, 0, err);
  if (n) n->noise = *noise;
  return n;
}

/* ---- curves --------------------------------------------------------- */

static oc_vec3 bezier(const oc_vec3 *c, double t) {
  double u = 1 - t;
  double b0 = u * u * u, b1 = 3 * u * u * t, b2 = 3 * u * t * t, b3 = t * t * t;
  return oc_v3(b0 * c[0].x + b1 * c[1].x + b2 * c[2].x + b3 * c[3].x,
               b0 * c[0].y + b1 * c[1].y + b2 * c[2].y + b3 * c[3].y,
               b0 * c[0].z + b1 * c[1].z + b2 * c[2].z + b3 * c[3].z);
}

/* Uniform steps per cubic piece so that the chord error stays below tol:
** the error of linear interpolation over a step h is at most h^2/8 max|B''|
** and |B''| <= 6 max(|P0 - 2P1 + P2|, |P1 - 2P2 + P3|). */
static size_t bezier_steps(const oc_vec3 *c, double tol) {
  double m1 = oc_len(oc_add(oc_sub(c[0], oc_mul(c[1], 2)), c[2]));
  double m2 = oc_len(oc_add(oc_sub(c[1], oc_mul(c[2], 2)), c[3]));
  double m = 6 * fmax(m1, m2);
  double n = ceil(sqrt(m / (8 * tol)));
  if (!(n >= 1)) n = 1;
  if (n > 4096) n = 4096;
  return (size_t)n;
}

oc_node *oc_curve(const oc_vec3 *pts, size_t n, int bz, double radius,
                  double energy, oc_error *err) {
  if (!pts || n < 2) {
    oc_seterr(err, OC_EINVAL, "'points' needs at least 2 points (got %zu)", n);
    return NULL;
  }
  if (bz && (n < 4 || (n - 1) % 3 != 0)) {
    oc_seterr(err, OC_EINVAL,
              "'points' of a Bezier curve must number 3k+1 (4, 7, 10, ...; "
              "got %zu)",
              n);
    return NULL;
  }
  if (n > MAX_CURVE_POINTS) {
    oc_seterr(err, OC_EINVAL, "'points' has more than %d points",
              MAX_CURVE_POINTS);
    return NULL;
  }
  for (size_t i = 0; i < n; i++)
    if (!oc_vfinite(pts[i])) {
      oc_seterr(err, OC_EINVAL,
                "'points' has a non-finite coordinate (point %zu)", i + 1);
      return NULL;
    }
  oc_node *node = dist_prim(OC_K_CURVE, radius, "radius", energy, err);
  if (!node) return NULL;
  size_t total = n;
  if (bz) {
    total = 1;
    for (size_t i = 0; i + 3 < n; i += 3) {
      total += bezier_steps(pts + i, 1e-4 * radius);
      if (total > MAX_CURVE_POINTS) {
        oc_node_release(node);
        oc_seterr(err, OC_EINVAL, "Bezier curve too long to flatten");
        return NULL;
      }
    }
  }
  node->pts = malloc(total * sizeof *node->pts);
  if (!node->pts) {
    oc_node_release(node);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  if (!bz) {
    memcpy(node->pts, pts, n * sizeof *pts);
  } else {
    size_t k = 0;
    node->pts[k++] = pts[0];
    for (size_t i = 0; i + 3 < n; i += 3) {
      size_t steps = bezier_steps(pts + i, 1e-4 * radius);
      for (size_t s = 1; s <= steps; s++)
        node->pts[k++] =
            s == steps ? pts[i + 3] : bezier(pts + i, (double)s / steps);
    }
  }
  node->npts = total;
  return node;
}

/* ---- packing for programs ------------------------------------------ */

/* A curve's segments are grouped in chunks of CHUNK with a bounding box
** each, stored after the points, so a query skips whole chunks farther
** than the best distance found so far. */
#define CHUNK 8

static size_t nchunks(size_t npts) {
  return npts > 1 ? (npts - 2) / CHUNK + 1 : 0;
}

const double *oc_prim_curve_boxes(const double *par, size_t *n) {
  size_t np = (size_t)par[2];
  *n = nchunks(np);
  return par + 3 + 3 * np;
}

size_t oc_prim_npar(const oc_node *n) {
  return n->kind == OC_K_CURVE ? 3 + 3 * n->npts + 6 * nchunks(n->npts) : 9;
}

void oc_prim_pack(const oc_node *n, double *out) {
  if (n->kind == OC_K_CURVE) {
    out[0] = n->par[OC_P_E];
    out[1] = n->par[OC_P_R];
    out[2] = (double)n->npts;
    for (size_t i = 0; i < n->npts; i++)
      put(out, 3 + 3 * (int)i, n->pts[i]);
    double *box = out + 3 + 3 * n->npts;
    for (size_t c = 0; c < nchunks(n->npts); c++, box += 6) {
      oc_vec3 lo = n->pts[c * CHUNK], hi = lo;
      for (size_t i = c * CHUNK + 1; i <= (c + 1) * CHUNK && i < n->npts; i++) {
        lo = oc_vmin(lo, n->pts[i]);
        hi = oc_vmax(hi, n->pts[i]);
      }
      put(box, 0, lo);
      put(box, 3, hi);
    }
  } else {
    memcpy(out, n->par, 9 * sizeof *out);
  }
}

/* ---- distances ------------------------------------------------------ */

static double seg_project(oc_vec3 a, oc_vec3 b, oc_vec3 p, oc_vec3 *s) {
  oc_vec3 ab = oc_sub(b, a), ap = oc_sub(p, a);
  double l2 = oc_dot(ab, ab);
  double t = l2 > 0 ? oc_dot(ap, ab) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  *s = oc_add(a, oc_mul(ab, t));
  return oc_len(oc_sub(p, *s));
}

/* The unit direction of segment ab when the closest point of p lies
** inside it (where it slides along the segment as p moves), else 0. */
static oc_vec3 seg_tangent(oc_vec3 a, oc_vec3 b, oc_vec3 p) {
  oc_vec3 ab = oc_sub(b, a);
  double l2 = oc_dot(ab, ab), t = l2 > 0 ? oc_dot(oc_sub(p, a), ab) / l2 : 0;
  return t > 0 && t < 1 ? oc_mul(ab, 1 / sqrt(l2)) : oc_v3(0, 0, 0);
}

/* The closest point of a curve's polyline, skipping the chunks whose box
** is farther than the best distance so far; *seg (when not NULL) gets the
** index of its segment, or SIZE_MAX. */
static double curve_project(const double *par, oc_vec3 p, oc_vec3 *s,
                            double cutoff, size_t *seg) {
  size_t n = (size_t)par[2];
  if (seg) *seg = SIZE_MAX;
  if (n == 1) {
    *s = get(par, 3);
    return oc_len(oc_sub(p, *s));
  }
  const double *box = par + 3 + 3 * n;
  double best = cutoff, best2 = cutoff * cutoff;
  *s = p;
  for (size_t c = 0; c < nchunks(n); c++, box += 6) {
    /* squared distance from p to the chunk's box (plain comparisons:
    ** fmax is a library call at -O2) */
    double dx = p.x < box[0] ? box[0] - p.x : p.x > box[3] ? p.x - box[3] : 0;
    double dy = p.y < box[1] ? box[1] - p.y : p.y > box[4] ? p.y - box[4] : 0;
    double dz = p.z < box[2] ? box[2] - p.z : p.z > box[5] ? p.z - box[5] : 0;
    if (dx * dx + dy * dy + dz * dz >= best2) continue;
    size_t end = (c + 1) * CHUNK < n - 1 ? (c + 1) * CHUNK : n - 1;
    for (size_t i = c * CHUNK; i < end; i++) {
      const double *v = par + 3 + 3 * i;
      oc_vec3 q;
      double d = seg_project(get(v, 0), get(v, 3), p, &q);
      if (d < best) {
        best = d;
        best2 = d * d;
        *s = q;
        if (seg) *seg = i;
      }
    }
  }
  return best;
}

/* Closest point on 2D segment (ax, ay)-(bx, by) to (x, y). */
static double seg2(double ax, double ay, double bx, double by, double x,
                   double y, double *sx, double *sy) {
  double dx = bx - ax, dy = by - ay;
  double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((x - ax) * dx + (y - ay) * dy) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  *sx = ax + t * dx;
  *sy = ay + t * dy;
  return hypot(x - *sx, y - *sy);
}

/* The cone's cross-section in (radial x >= 0, axial y) coordinates is the
** triangle (0,0) (r,0) (0,h); outside it the closest point lies on the base
** edge or the slant edge. */
static double cone_project(const double *par, oc_vec3 p, oc_vec3 *s) {
  oc_vec3 B = get(par, OC_P_A), A = get(par, OC_P_B);
  double r = par[OC_P_CONE_R];
  oc_vec3 ax = oc_sub(A, B);
  double h = oc_len(ax);
  ax = oc_mul(ax, 1.0 / h);
  oc_vec3 bp = oc_sub(p, B);
  double y = oc_dot(bp, ax);
  oc_vec3 q = oc_sub(bp, oc_mul(ax, y));
  double x = oc_len(q);
  if (y >= 0 && x * h + y * r <= r * h) {
    *s = p;
    return 0;
  }
  double x1, y1, x2, y2;
  double d1 = seg2(0, 0, r, 0, x, y, &x1, &y1);
  double d2 = seg2(r, 0, 0, h, x, y, &x2, &y2);
  if (d2 < d1) {
    d1 = d2;
    x1 = x2;
    y1 = y2;
  }
  oc_vec3 radial = x > 0 ? oc_mul(q, 1.0 / x) : oc_v3(0, 0, 0);
  *s = oc_add(B, oc_add(oc_mul(ax, y1), oc_mul(radial, x1)));
  return d1;
}

double oc_prim_project(oc_kind kind, const double *par, oc_vec3 p, oc_vec3 *s,
                       double cutoff) {
  switch (kind) {
  case OC_K_POINT:
    *s = get(par, OC_P_C);
    return oc_len(oc_sub(p, *s));
  case OC_K_SPHERE: {
    oc_vec3 c = get(par, OC_P_C), cp = oc_sub(p, c);
    double l = oc_len(cp), r = par[OC_P_RAD];
    if (l <= r) {
      *s = p;
      return 0;
    }
    *s = oc_add(c, oc_mul(cp, r / l));
    return l - r;
  }
  case OC_K_BOX: {
    oc_vec3 lo = get(par, OC_P_LO), hi = get(par, OC_P_HI);
    *s = oc_vmin(oc_vmax(p, lo), hi);
    return oc_len(oc_sub(p, *s));
  }
  case OC_K_SEGMENT:
    return seg_project(get(par, OC_P_A), get(par, OC_P_B), p, s);
  case OC_K_CURVE:
    return curve_project(par, p, s, cutoff, NULL);
  case OC_K_CONE:
    return cone_project(par, p, s);
  case OC_K_PLANE: {
    oc_vec3 o = get(par, OC_P_O), nrm = get(par, OC_P_N);
    double d = oc_dot(oc_sub(p, o), nrm);
    if (d <= 0) {
      *s = p;
      return 0;
    }
    *s = oc_sub(p, oc_mul(nrm, d));
    return d;
  }
  default:
    *s = p;
    return INFINITY;
  }
}

static void set_outer(double J[9], oc_vec3 a, double k) {
  const double v[3] = {a.x, a.y, a.z};
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++)
      J[3 * r + c] = k * v[r] * v[c];
}

static void set_diag(double J[9], double x, double y, double z) {
  for (int k = 0; k < 9; k++)
    J[k] = 0;
  J[0] = x, J[4] = y, J[8] = z;
}

int oc_prim_project_jac(oc_kind kind, const double *par, oc_vec3 p, oc_vec3 *s,
                        double cutoff, double *d, double J[9]) {
  switch (kind) {
  case OC_K_POINT:
    *d = oc_prim_project(kind, par, p, s, cutoff);
    set_diag(J, 0, 0, 0);
    return 1;
  case OC_K_SEGMENT: {
    oc_vec3 a = get(par, OC_P_A), b = get(par, OC_P_B);
    *d = seg_project(a, b, p, s);
    set_outer(J, seg_tangent(a, b, p), 1); /* 0 at an end: s stays */
    return 1;
  }
  case OC_K_CURVE: {
    size_t i;
    *d = curve_project(par, p, s, cutoff, &i);
    oc_vec3 t = oc_v3(0, 0, 0);
    if (i != SIZE_MAX)
      t = seg_tangent(get(par, 3 + 3 * (int)i), get(par, 6 + 3 * (int)i), p);
    set_outer(J, t, 1);
    return 1;
  }
  case OC_K_SPHERE: {
    *d = oc_prim_project(kind, par, p, s, cutoff);
    oc_vec3 cp = oc_sub(p, get(par, OC_P_C));
    double l = oc_len(cp);
    if (!(*d > 0)) {
      set_diag(J, 1, 1, 1);
      return 1;
    }
    /* s = c + r u: dS = (r / l) (I - u u^T) */
    oc_vec3 u = oc_mul(cp, 1 / l);
    double k = par[OC_P_RAD] / l;
    set_outer(J, u, -k);
    J[0] += k, J[4] += k, J[8] += k;
    return 1;
  }
  case OC_K_BOX: {
    *d = oc_prim_project(kind, par, p, s, cutoff);
    oc_vec3 lo = get(par, OC_P_LO), hi = get(par, OC_P_HI);
    set_diag(J, p.x > lo.x && p.x<hi.x, p.y> lo.y && p.y<hi.y, p.z> lo.z &&
                    p.z < hi.z);
    return 1;
  }
  default:
    return 0;
  }
}

oc_aabb oc_prim_skeleton_box(oc_kind kind, const double *par) {
  oc_aabb b = oc_aabb_empty();
  switch (kind) {
  case OC_K_POINT:
    b.lo = b.hi = get(par, OC_P_C);
    break;
  case OC_K_SPHERE: {
    double r = par[OC_P_RAD];
    b.lo = oc_sub(get(par, OC_P_C), oc_v3(r, r, r));
    b.hi = oc_add(get(par, OC_P_C), oc_v3(r, r, r));
    break;
  }
  case OC_K_BOX:
    b.lo = get(par, OC_P_LO);
    b.hi = get(par, OC_P_HI);
    break;
  case OC_K_SEGMENT:
    b.lo = oc_vmin(get(par, OC_P_A), get(par, OC_P_B));
    b.hi = oc_vmax(get(par, OC_P_A), get(par, OC_P_B));
    break;
  case OC_K_CURVE: {
    size_t n = (size_t)par[2];
    for (size_t i = 0; i < n; i++) {
      oc_vec3 v = get(par, 3 + 3 * (int)i);
      b.lo = oc_vmin(b.lo, v);
      b.hi = oc_vmax(b.hi, v);
    }
    break;
  }
  case OC_K_CONE: {
    /* base disc: extent along axis i is r sqrt(1 - a_i^2) */
    oc_vec3 B = get(par, OC_P_A), A = get(par, OC_P_B);
    oc_vec3 ax = oc_sub(A, B);
    ax = oc_mul(ax, 1.0 / oc_len(ax));
    double r = par[OC_P_CONE_R];
    oc_vec3 e = oc_v3(r * sqrt(fmax(0, 1 - ax.x * ax.x)),
                      r * sqrt(fmax(0, 1 - ax.y * ax.y)),
                      r * sqrt(fmax(0, 1 - ax.z * ax.z)));
    b.lo = oc_vmin(oc_sub(B, e), A);
    b.hi = oc_vmax(oc_add(B, e), A);
    break;
  }
  case OC_K_PLANE: {
    b = oc_aabb_all();
    oc_vec3 o = get(par, OC_P_O), n = get(par, OC_P_N);
    /* only an axis-aligned half-space is bounded (on one side) */
    double c[3] = {n.x, n.y, n.z}, oo[3] = {o.x, o.y, o.z};
    for (int i = 0; i < 3; i++) {
      int j = (i + 1) % 3, k = (i + 2) % 3;
      if (c[j] == 0 && c[k] == 0) {
        double *lo = &b.lo.x, *hi = &b.hi.x;
        if (c[i] > 0)
          hi[i] = oo[i];
        else
          lo[i] = oo[i];
      }
    }
    break;
  }
  default:
    b = oc_aabb_all();
  }
  return b;
}
