/*
** curve.h — a piecewise planar curve carrying an elevation: line segments,
** quadratic and cubic Bézier pieces with control points (x, y, z). The
** skeleton of the curve primitives of elevation trees (Génevaux et al.
** 2015, f = q_z + c(d)) and of the feature curves of diffusion (Hnaidi et
** al. 2010): one implementation of arc length, closest point, frames,
** curvature bound and flattening.
**
** Geometry is planar: arc length s, distances, tangents and curvature are
** in xy; z is carried along each piece's parameter (q_z of the closest
** point). A built curve is immutable; every query below is read-only,
** allocates nothing and may run from any number of threads at once.
*/
#ifndef OC_CURVE_H
#define OC_CURVE_H

#include <stddef.h>

#include "outcrop.h"

/* (oc_curve is taken by the 3D curve primitive of outcrop.h, hence the
** type's name; the functions are oc_curve_*.) */
typedef struct oc_pcurve oc_pcurve;

/* One piece: degree 1 (segment p[0] p[1]), 2 or 3 (Bézier p[0..degree]). */
typedef struct oc_curve_piece {
  int degree;
  oc_vec3 p[4];
} oc_curve_piece;

/* A point of the curve, as answered by oc_curve_at and oc_curve_closest. */
typedef struct oc_curve_point {
  double s;      /* arc length from the start, in [0, length] */
  oc_vec3 q;     /* the point on the curve (x, y) and the skeleton z there */
  double tx, ty; /* unit tangent (direction of travel) */
  double nx, ny; /* unit left normal (-ty, tx) */
  double d;      /* closest only: signed xy distance, > 0 on the left */
  size_t piece;  /* index among the kept pieces, and parameter in it */
  double t;
  int end; /* closest only: -1 / +1 when q is the start / end of an
           ** open curve (then the sign of d is the side of the end
           ** tangent's line), else 0 */
} oc_curve_point;

/* Builds a curve from n pieces (copied). Checked: degree 1..3, finite
** coordinates, each piece starting where the previous one ends (within
** 1e-9 of the coordinates' scale; the start is then snapped to that end),
** at least one piece with non-zero xy length. Pieces of zero xy length
** are dropped (refused if their z changes: a vertical step has no closest
** point). The curve is closed when its last end meets its first start.
** Errors name the piece index (from 0). The caller frees the result with
** oc_curve_free; NULL (err set) on failure. */
oc_pcurve *oc_curve_new(const oc_curve_piece *pieces, size_t n, oc_error *err);

/* A spline through shared points: with degree k, n = k m + 1 points make
** m pieces (point k i is where piece i starts). Same checks; the count is
** named 'points'. */
oc_pcurve *oc_curve_from_points(const oc_vec3 *pts, size_t n, int degree,
                                oc_error *err);

/* The uniform Catmull-Rom spline through n >= 2 points, as cubic pieces
** (piece i from pts[i] to pts[i + 1], its inner control points pts[i] +
** (pts[i + 1] - pts[i - 1]) / 6 and pts[i + 1] - (pts[i + 2] - pts[i]) /
** 6, the ends reflecting their neighbour). Same checks as oc_curve_new
** (errors name 'points' for the count). The curve keeps its points alone
** and derives the control points as it reads a piece (unless a piece was
** dropped or an end snapped: then it keeps them as oc_curve_new does). */
oc_pcurve *oc_curve_catmull(const oc_vec3 *pts, size_t n, oc_error *err);

void oc_curve_free(oc_pcurve *c);

size_t oc_curve_npieces(const oc_pcurve *c); /* pieces kept */
/* The memory it holds: its points, an arc length per piece, the inner
** knots of pieces whose arc length one 8-point rule does not give to
** 1e-14, a box tree of floats (2 pieces - 1 boxes of 16 bytes). */
size_t oc_curve_bytes(const oc_pcurve *c);
int oc_curve_closed(const oc_pcurve *c);
/* Total xy arc length. Each Bézier piece's arc length is tabulated at
** build (adaptive Gauss–Legendre); the length and every s below are
** accurate to about 1e-13 relative (documented bound: 1e-9). */
double oc_curve_length(const oc_pcurve *c);

/* The point, unit tangent and left normal at arc length s (clamped to
** [0, length]); at a join the tangent is the bisector of the two pieces'
** tangents. Returns 0 (out untouched) when s is NaN. */
int oc_curve_at(const oc_pcurve *c, double s, oc_curve_point *out);

/* 1 when every point of the segment (xa, ya) (xb, yb) is provably farther
** than r from the curve in xy, so that oc_curve_closest(c, x, y, r, ...)
** returns 0 at each of them; 0 when that is not shown. Each piece passes
** oc_bez_far (its control points boxed in the frame of its chord, tight
** for a diagonal piece; the segment's distance to that box taken exactly,
** less a margin for rounding): the test oc_curve_closest runs per piece. */
int oc_curve_far_from_segment(const oc_pcurve *c, double xa, double ya,
                              double xb, double yb, double r);

/* The closest point of the curve to (x, y) in xy, if it lies within r
** (r may be INFINITY): returns 1 and fills out (s, q, tangent, normal,
** signed d), else 0. The global minimum: pieces are pruned through a box
** tree over their control-polygon boxes (a far query costs one box test),
** segments are exact to rounding, Bézier pieces isolate every stationary
** point of the distance (bezier.h). */
int oc_curve_closest(const oc_pcurve *c, double x, double y, double r,
                     oc_curve_point *out);
/* The same point without its arc length (out->s is NaN: computing it is
** a third of a query), for callers that may not need it; oc_curve_s_at
** then gives the bits oc_curve_closest puts in out->s. */
int oc_curve_closest_t(const oc_pcurve *c, double x, double y, double r,
                       oc_curve_point *out);
double oc_curve_s_at(const oc_pcurve *c, const oc_curve_point *pt);
/* Two radii rin <= r in one search: 0 when no point of the curve lies
** within r of (x, y); 1 when one does but none within rin (out
** untouched); 2 when one lies within rin, out then holding the bits
** oc_curve_closest_t(c, x, y, rin, out) gives. *d2 (when not 0): the
** squared distance of the closest point found. For a caller that asks
** both whether the curve comes near a box and its closest point near
** the box's centre (ecurve.c: an elevation curve's weight in a replace). */
int oc_curve_closest_within(const oc_pcurve *c, double x, double y, double rin,
                            double r, oc_curve_point *out, double *d2);

/* Whether some point of the curve lies within r of (x, y) in xy: what
** oc_curve_closest returns, without finding the closest point (the
** first piece within r answers; a piece whose end, middle or quarter
** point is within r needs no root finding). */
int oc_curve_within(const oc_pcurve *c, double x, double y, double r);

/* The elevations of the curve's points within r of (x, y) in xy lie in
** [*zlo, *zhi]: the range of the control points' z of the pieces whose
** boxes come within r (a Bézier piece lies in its control points' hull),
** widened by a relative 1e-12 for the evaluation's roundings. Returns 0
** (zlo, zhi untouched) when no piece's box comes within r. */
int oc_curve_z_near(const oc_pcurve *c, double x, double y, double r,
                    double *zlo, double *zhi);

/* An upper bound of the planar curvature |kappa| inside the pieces,
** rigorous up to rounding and within about 1 % of the true maximum
** (bezier.h); 0 for a polyline, INFINITY where a Bézier piece's
** derivative vanishes: a cusp, or an end control point doubled (p[1] =
** p[0]), whose curvature is generally unbounded near that end.
** Joins are not included: see oc_curve_max_turn. Computed when asked
** (a branch and bound over the pieces: callers ask once). */
double oc_curve_kappa_max(const oc_pcurve *c);

/* The largest angle (radians, in [0, pi]) between the tangents meeting at
** a join (and at the closing point of a closed curve): 0 for a G1 curve.
** A corner has infinite curvature, so a profile of half-width w is safe
** (w kappa_max < 1) only on a curve without corners. Computed when asked. */
double oc_curve_max_turn(const oc_pcurve *c);

/* An upper bound of the grade |dz/ds| along the whole curve (rigorous up
** to rounding; oc_bez_grade_bound per piece). */
double oc_curve_grade_max(const oc_pcurve *c);
/* At a point answered by oc_curve_at or oc_curve_closest: the signed
** planar curvature (> 0 turning left; 0 at the ends of pieces' joins
** treated as the piece's own) and the grade dz/ds. */
double oc_curve_curvature_at(const oc_pcurve *c, const oc_curve_point *pt);
double oc_curve_grade_at(const oc_pcurve *c, const oc_curve_point *pt);

/* The tight box of the curve (x, y and z) with x and y grown by r >= 0
** (computed when asked, O(pieces)). */
oc_aabb oc_curve_bounds(const oc_pcurve *c, double r);

/* A vertex of a flattened curve: the point and its arc length. */
typedef struct oc_curve_vertex {
  double x, y, z, s;
} oc_curve_vertex;

/* Flattens the curve to a polyline whose vertices lie on the curve and
** such that every point of the curve is within tol (xy) of the polyline;
** z and s are the curve's at the vertices (segments keep their two ends).
** Writes at most cap vertices into out (which may be NULL to count) and
** sets *count to the number the whole polyline needs (first and last
** vertices included; a closed curve repeats its start at the end). tol
** must be finite and >= 1e-9 of the curve's length (so counts stay
** bounded). Returns 0 or an error code. */
int oc_curve_flatten(const oc_pcurve *c, double tol, oc_curve_vertex *out,
                     size_t cap, size_t *count, oc_error *err);

#endif
