/*
** mcdirect.c — direct elevation extraction (Paris et al. 2019, section 7): in
** the
** sample columns that one heightfield-like op (a terrain, a plane)
** governs alone, the samples come from one elevation e(x, y) per column
** and the vertices straight from the elevation, with no field call.
**
** Which sample columns are direct is decided per column from its own
** footprint (the column query of its cube column, which covers the four
** edges leaving it), so two slabs sharing a row decide alike, and an edge
** is placed one way whichever cube asks for it:
**  - a vertical edge of a direct column: at z = e (or on a terrain's flat
**    prism cap), no root finding;
**  - a horizontal edge between two direct columns under the same surface:
**    where e - z is 0, e interpolated along the edge by the cubic Hermite
**    of the two columns' elevations and slopes (the paper interpolates
**    linearly; the slopes come free with the elevations and bring the
**    error from O(cell^2) to O(cell^4)); then Newton steps on the
**    elevation itself along the edge (usually one or two lookups of e,
**    cheaper than one field call), whose last lookup gives the normal
**    (interpolated gradients are poor on rough grids);
**  - any other edge: root finding on the field (mcvertex.c), so direct
**    columns join normally meshed ones without a seam.
** Marching cubes stays closed and manifold whatever the sample values, so
** none of this touches the topology; vertices keep the same distance from
** the samples as root-found ones.
*/
#include <math.h>
#include <stdlib.h>

#include "field/hfsurf.h"
#include "field/query.h"
#include "mesh/mcwork.h"

/* Elevation lookups per horizontal vertex, at most, and the step (in
** edges) below which they stop. */
#define NEWTON_STEPS 6
#define NEWTON_TOL 1e-5

/* Kinds flagged OC_KF_DIRECT only (terrains): a plane costs a dot
** product to evaluate, and its root is found in one Newton step, so planes
** keep the root-found vertices (and meshes made before terrains existed
** stay the same). */
int oc_mc_direct_kind(const oc_hfsurf *s) {
  return s->direct;
}

int oc_mc_surfaces(oc_mcgrid *g, int direct) {
  const oc_program *P = g->prog;
  size_t n = 0;
  g->surf = NULL;
  g->nsurf = 0;
  g->direct = 0;
  for (uint32_t i = 0; i < P->nops; i++)
    n += oc_hfsurf_candidate(P, i);
  if (!n) return 0;
  oc_hfsurf *s = malloc(n * sizeof *s);
  if (!s) return -1;
  size_t k = 0;
  for (uint32_t i = 0; i < P->nops; i++)
    if (oc_hfsurf_candidate(P, i) && oc_hfsurf_init(&s[k], P, i, g->T)) {
      g->direct += direct && s[k].direct;
      k++;
    }
  if (!k) {
    free(s);
    return 0;
  }
  g->surf = s;
  g->nsurf = k;
  return 0;
}

void oc_mc_surfaces_free(oc_mcgrid *g) {
  free((void *)g->surf);
  g->surf = NULL;
  g->nsurf = 0;
  g->direct = 0;
}

const oc_hfsurf *oc_mc_surface(const oc_mcgrid *g, uint32_t op) {
  size_t a = 0, b = g->nsurf; /* sorted by op: they were made in order */
  while (a < b) {
    size_t m = a + (b - a) / 2;
    if (g->surf[m].op < op)
      a = m + 1;
    else
      b = m;
  }
  return a < g->nsurf && g->surf[a].op == op ? &g->surf[a] : NULL;
}

const double *oc_mc_elevation(const oc_mcgrid *g, oc_mcwork *w,
                              const oc_hfsurf *hs, int i, int j) {
  size_t c = (size_t)(j - w->ja) * ((size_t)g->n[0] + 2) + (size_t)(i + 1);
  double *el = w->delev + 3 * c;
  if (w->esurf[c] != hs) {
    el[0] = oc_hfsurf_height(hs, oc_mc_coord(g, 0, i), oc_mc_coord(g, 1, j),
                             el + 1);
    w->esurf[c] = hs;
  }
  return el;
}

void oc_mc_direct_column(const oc_mcgrid *g, int i, int j, size_t c,
                         const oc_mc_srange *s, size_t ns, oc_mcwork *w) {
  const oc_hfsurf *hs = w->dsurf[c];
  double e = oc_mc_elevation(g, w, hs, i, j)[0];
  int nz = g->n[2];
  for (size_t r = 0; r < ns; r++)
    for (int32_t k = s[r].lo; k <= s[r].hi; k++)
      w->val[s[r].off + k] = !g->open && (k < 0 || k >= nz)
                                 ? -INFINITY
                                 : oc_hfsurf_value(hs, e, oc_mc_coord(g, 2, k));
}

/* Root in (0, 1) of the cubic Hermite p with p(0) = a, p(1) = b (of
** opposite signs), p'(0) = ma, p'(1) = mb; *dp gets p' there. Newton from
** the linear guess, kept in a shrinking bracket (bisection when it
** leaves it). */
static double hermite_root(double a, double b, double ma, double mb,
                           double *dp) {
  /* p(t) = a + ma t + c2 t^2 + c3 t^3 */
  double c2 = 3 * (b - a) - 2 * ma - mb, c3 = 2 * (a - b) + ma + mb;
  double lo = 0, hi = 1, t = a / (a - b);
  int lo_neg = a < 0;
  for (int it = 0; it < 12; it++) {
    double p = a + t * (ma + t * (c2 + t * c3));
    double d = ma + t * (2 * c2 + 3 * t * c3);
    if (p == 0) break;
    if ((p < 0) == lo_neg)
      lo = t;
    else
      hi = t;
    double tn = t - p / d;
    if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    int done = fabs(tn - t) < 1e-10;
    t = tn;
    if (done) break;
  }
  *dp = ma + t * (2 * c2 + 3 * t * c3);
  return t;
}

/* Outward unit normal of the surface z = e with gradient (gx, gy). */
static void surface_normal(const oc_hfsurf *hs, double gx, double gy,
                           float nrm[3]) {
  double l = sqrt(gx * gx + gy * gy + 1);
  nrm[0] = (float)(-hs->up * gx / l);
  nrm[1] = (float)(-hs->up * gy / l);
  nrm[2] = (float)(hs->up / l);
}

int oc_mc_direct_vertex(const oc_mcgrid *g, const oc_mcwork *w, const int s[3],
                        int axis, float pos[3], float nrm[3]) {
  if (!g->open && (s[axis] < 0 || s[axis] + 1 >= g->n[axis]))
    return 0; /* a cap on the box: mcvertex.c */
  if (s[0] < 0 || s[1] < 0 || s[0] >= g->n[0] || s[1] >= g->n[1]) return 0;
  size_t stride = (size_t)g->n[0] + 2;
  size_t c = (size_t)(s[1] - w->ja) * stride + (size_t)(s[0] + 1);
  const oc_hfsurf *hs = w->dsurf[c];
  if (!hs) return 0;
  const double *ea = w->delev + 3 * c;
  double lo = oc_mc_coord(g, axis, s[axis]);
  double hi = oc_mc_coord(g, axis, s[axis] + 1);
  double t, gx, gy;
  int cap = 0;
  if (axis == 2) {
    double z = oc_hfsurf_vertical(hs, ea[0], lo, hi, &cap);
    t = (z - lo) / (hi - lo);
    gx = ea[1];
    gy = ea[2];
  } else {
    if (s[axis] + 1 >= g->n[axis]) return 0;
    size_t cb = c + (axis == 0 ? 1 : stride);
    if (w->dsurf[cb] != hs) return 0;
    const double *eb = w->delev + 3 * cb;
    double z = oc_mc_coord(g, 2, s[2]);
    double da = ea[0] - z, db = eb[0] - z;
    if (!((da > 0 && db < 0) || (da < 0 && db > 0))) return 0;
    double len = hi - lo, dp, gr[2];
    t = hermite_root(da, db, ea[1 + axis] * len, eb[1 + axis] * len, &dp);
    double tl = 0, th = 1; /* bracket: e - z has the sign of da at tl */
    int done = 0;
    for (int it = 0; it < NEWTON_STEPS && !done; it++) {
      double x = axis == 0 ? lo + t * len : oc_mc_coord(g, 0, s[0]);
      double y = axis == 1 ? lo + t * len : oc_mc_coord(g, 1, s[1]);
      double r = oc_hfsurf_height(hs, x, y, gr) - z;
      if (r == 0) {
        done = 1;
        break;
      }
      if ((r > 0) == (da > 0))
        tl = t;
      else
        th = t;
      double tn = t - r / (gr[axis] * len);
      if (!(tn > tl && tn < th)) tn = 0.5 * (tl + th);
      done = fabs(tn - t) < NEWTON_TOL;
      t = tn;
    }
    if (!done) return 0; /* rare: the field's root finder will do */
    gx = gr[0];
    gy = gr[1];
  }
  t = fmin(fmax(t, g->tmin[axis]), 1 - g->tmin[axis]); /* NaN: tmin */
  for (int a = 0; a < 3; a++)
    pos[a] = (float)oc_mc_coord(g, a, s[a]);
  pos[axis] = (float)(lo + t * (hi - lo));
  if (cap) {
    nrm[0] = nrm[1] = 0;
    nrm[2] = (float)-hs->up;
  } else {
    surface_normal(hs, gx, gy, nrm);
  }
  return 1;
}
