/*
** mcvertex.c — placing a vertex on a crossing edge of the sampling grid.
**
** The root of f - T along the edge is bracketed by the two samples. The
** first guess interpolates them linearly (no call); each step then
** evaluates value and gradient together (one call), shrinks the bracket,
** and takes a Newton step along the edge, falling back to false position
** and then bisection when Newton leaves the bracket. The gradient of the
** last step gives the normal. `steps` sets the accuracy and the usual
** number of iterations: iteration stops once a Newton step moves the
** vertex by less than tol = 10^(-steps/3) of the edge, after which the
** error is about the square of that (the default 6 stops below 1e-2,
** leaving ~1e-4 of a cell or less, and most vertices cost one or two
** calls; 20 reaches double precision). Past `steps` iterations, it goes
** on only while the bracket is wider than tol^2, which happens where the
** field is flat over most of the edge (a transition narrower than a
** cell), so that no vertex stays far from the surface. The edge parameter is
*finally kept 1e-3 (or a few float ulps,
** far from the origin) away from the samples, so that no vertex coincides
** with a grid point even once rounded to float: distinct edges give
** distinct vertices and no triangle degenerates.
**
** In closed meshes, edges to padding samples are the caps: their vertex is
** exactly on the box face. In open ones the padding samples are real
** values on the faces and their edges are searched like any other.
*/
#include <math.h>

#include "mesh/mcgrid.h"

#define BRACKET_TOL 1e-7
#define MAX_ITERS 64

static void unit_or_flag(const oc_vec3 *gr, float nrm[3], int *flat,
                         double fallback_sign, int axis) {
  double l = sqrt(gr->x * gr->x + gr->y * gr->y + gr->z * gr->z);
  if (l > 0 && isfinite(l)) {
    nrm[0] = (float)(-gr->x / l);
    nrm[1] = (float)(-gr->y / l);
    nrm[2] = (float)(-gr->z / l);
    *flat = 0;
    return;
  }
  nrm[0] = nrm[1] = nrm[2] = 0.0f;
  nrm[axis] = (float)fallback_sign;
  *flat = 1;
}

/* A cap vertex: the edge joins a real sample and a padding one (outside),
** so the crossing is on the box face, where the cap is flat. */
static int cap_vertex(const oc_mcgrid *g, const int s[3], int axis,
                      float pos[3], float nrm[3], int *flat) {
  for (int a = 0; a < 3; a++)
    pos[a] = (float)oc_mc_coord(g, a, s[a] + (a == axis && s[a] >= 0));
  nrm[0] = nrm[1] = nrm[2] = 0.0f;
  nrm[axis] = s[axis] < 0 ? -1.0f : 1.0f;
  *flat = 0;
  return 0;
}

int oc_mc_vertex(const oc_mcgrid *g, const int s[3], int axis, double va,
                 double vb, float pos[3], float nrm[3], int *flat) {
  /* Off the axis both ends share their indices, so only the axis can
  ** reach the padding (an edge between two padding samples never
  ** crosses). */
  if (!g->open && (s[axis] < 0 || s[axis] + 1 >= g->n[axis]))
    return cap_vertex(g, s, axis, pos, nrm, flat);
  double T = g->T;
  double p[3];
  for (int a = 0; a < 3; a++)
    p[a] = oc_mc_coord(g, a, s[a]);
  /* t runs from the outside sample (t = 0) to the inside one (t = 1) */
  int lower_in = va > T;
  double co = lower_in ? oc_mc_coord(g, axis, s[axis] + 1) : p[axis];
  double ci = lower_in ? p[axis] : oc_mc_coord(g, axis, s[axis] + 1);
  double d = ci - co;
  double lo = 0, hi = 1;
  double glo = (lower_in ? vb : va) - T, ghi = (lower_in ? va : vb) - T;
  double t = glo < 0 ? glo / (glo - ghi) : 0;
  oc_vec3 gr = {0, 0, 0};
  int calls = 0, fallbacks = 0;
  const double tol = g->newton_tol;
  /* past the budget, only while the bracket is wider than tol^2: where
  ** the field is flat (a narrow transition in a long edge) Newton has
  ** nothing to go on, and the fallbacks need more steps */
  const double wide = fmax(tol * tol, BRACKET_TOL);
  for (int it = 0; it < g->steps || (it < MAX_ITERS && hi - lo > wide); it++) {
    p[axis] = co + t * d;
    double f = oc_program_gradient(g->prog, (oc_vec3){p[0], p[1], p[2]}, &gr);
    calls++;
    double gt = f - T;
    if (gt == 0) break;
    if (gt > 0) {
      hi = t;
      ghi = gt;
    } else if (gt < 0) {
      lo = t;
      glo = gt;
    } else {
      break; /* NaN: keep the current estimate */
    }
    double dg = (axis == 0 ? gr.x : axis == 1 ? gr.y : gr.z) * d;
    double tn = t - gt / dg;
    int newton = tn > lo && tn < hi;
    if (!newton) {
      fallbacks++;
      tn =
          fallbacks > 1 ? 0.5 * (lo + hi) : (lo * ghi - hi * glo) / (ghi - glo);
      if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    } else {
      fallbacks = 0;
    }
    int done = (newton && fabs(tn - t) < tol) || hi - lo < BRACKET_TOL;
    t = tn;
    if (done) break;
  }
  t = fmin(fmax(t, g->tmin[axis]), 1 - g->tmin[axis]); /* NaN: tmin */
  p[axis] = co + t * d;
  for (int a = 0; a < 3; a++)
    pos[a] = (float)p[a];
  unit_or_flag(&gr, nrm, flat, co > ci ? 1.0 : -1.0, axis);
  return calls;
}
