/*
** sweep.c — the sweeping tool (Peytavie et al. 2009, section 4.2, figures
** 11 and 12): a branching graph of paths whose nodes carry cross-section
** profiles (closed piecewise cubic curves, non-convex allowed) sweeps a
** volume V that is carved out of the bedrock by difference.
**
** Each profile is the closed Catmull-Rom spline through its control
** points (u across the path, to the right of travel; v along the path's
** up vector), resampled into NP points by arc length from its first
** control point, so two profiles interpolate point by point along an
** arc. The up vector is the surface normal at a node for cracks (the
** graph projected on the top of the solid) and the vertical for tunnels,
** made orthogonal to the arc. An arc's end alone is cut square; two ends
** meeting are mitred (the plane halfway between the arcs, so a bend has
** neither gap nor overlap); at a branching node (three or more ends) the
** profile turns about the up vector past the ends (u becomes the signed
** distance from the node's axis), closing the joint.
**
** The difference is taken on the layers themselves: bedrock inside V
** becomes air, other materials stay (loose material falls to the floor
** of its new gap with the canonical sorting), the stacks are rebuilt from
** the crossings of V's boundary along their axes (sculpt.c's rebuilding,
** sampling every cell / 4) and stabilised around the edit.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "layers/layers.h"

#define NP 96  /* resampled profile points */
#define SUB 16 /* spline samples per control span before resampling */

typedef struct sarc {
  oc_vec3 a, b, t;       /* ends and unit tangent */
  oc_vec3 ma, mb;        /* end planes' normals (along t), where not capped */
  int cap[2];            /* 1: the profile turns about up past that end */
  oc_vec3 na, nb;        /* up vectors at the ends (unit, orthogonal to t) */
  double len, reach;     /* length; largest profile radius */
  const double *pa, *pb; /* resampled profiles at the ends (NP u, v pairs) */
  double lo[3], hi[3];   /* bounding box of the swept volume */
} sarc;

typedef struct swctx {
  const sarc *arc;
  size_t narc;
  int *list; /* arcs that can reach the current column */
  int nlist;
} swctx;

static oc_vec3 v3(double x, double y, double z) {
  return (oc_vec3){x, y, z};
}
static oc_vec3 sub(oc_vec3 a, oc_vec3 b) {
  return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static double dot(oc_vec3 a, oc_vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
static oc_vec3 cross(oc_vec3 a, oc_vec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
            a.x * b.y - a.y * b.x);
}
static oc_vec3 unit(oc_vec3 a) {
  double l = sqrt(dot(a, a));
  return l > 0 ? v3(a.x / l, a.y / l, a.z / l) : v3(0, 0, 1);
}

/* up made orthogonal to the unit tangent t (another axis when parallel). */
static oc_vec3 ortho(oc_vec3 up, oc_vec3 t) {
  oc_vec3 n = sub(up, v3(t.x * dot(up, t), t.y * dot(up, t), t.z * dot(up, t)));
  if (dot(n, n) < 1e-12)
    return ortho(fabs(t.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0), t);
  return unit(n);
}

/* The closed Catmull-Rom spline through the n points uv resampled into
** NP points by arc length (out: NP u, v pairs). */
static void resample(const double *uv, size_t n, double *out, double *scratch) {
  size_t m = n * SUB;
  double *pts = scratch, *acc = scratch + 2 * (m + 1); /* 3 (m + 1) */
  for (size_t k = 0; k < n; k++) {
    const double *p0 = uv + 2 * ((k + n - 1) % n), *p1 = uv + 2 * k,
                 *p2 = uv + 2 * ((k + 1) % n), *p3 = uv + 2 * ((k + 2) % n);
    for (int q = 0; q < SUB; q++) {
      double s = (double)q / SUB, s2 = s * s, s3 = s2 * s;
      for (int c = 0; c < 2; c++)
        pts[2 * (k * SUB + q) + c] =
            0.5 * (2 * p1[c] + (p2[c] - p0[c]) * s +
                   (2 * p0[c] - 5 * p1[c] + 4 * p2[c] - p3[c]) * s2 +
                   (3 * p1[c] - p0[c] - 3 * p2[c] + p3[c]) * s3);
    }
  }
  pts[2 * m] = pts[0];
  pts[2 * m + 1] = pts[1];
  acc[0] = 0;
  for (size_t k = 1; k <= m; k++)
    acc[k] = acc[k - 1] + hypot(pts[2 * k] - pts[2 * k - 2],
                                pts[2 * k + 1] - pts[2 * k - 1]);
  size_t k = 0;
  for (int q = 0; q < NP; q++) {
    double at = acc[m] * q / NP;
    while (k + 1 < m && acc[k + 1] <= at)
      k++;
    double span = acc[k + 1] - acc[k], w = span > 0 ? (at - acc[k]) / span : 0;
    out[2 * q] = pts[2 * k] + w * (pts[2 * k + 2] - pts[2 * k]);
    out[2 * q + 1] = pts[2 * k + 1] + w * (pts[2 * k + 3] - pts[2 * k + 1]);
  }
}

/* (u, v) inside the profile pa + s (pb - pa) (even-odd rule). */
static int in_profile(const double *pa, const double *pb, double s, double u,
                      double v) {
  int in = 0;
  double ju = pa[2 * (NP - 1)] + s * (pb[2 * (NP - 1)] - pa[2 * (NP - 1)]);
  double jv = pa[2 * NP - 1] + s * (pb[2 * NP - 1] - pa[2 * NP - 1]);
  for (int q = 0; q < NP; q++) {
    double iu = pa[2 * q] + s * (pb[2 * q] - pa[2 * q]);
    double iv = pa[2 * q + 1] + s * (pb[2 * q + 1] - pa[2 * q + 1]);
    if ((iv > v) != (jv > v) && u < (ju - iu) * (v - iv) / (jv - iv) + iu)
      in = !in;
    ju = iu;
    jv = iv;
  }
  return in;
}

/* p inside the volume swept along arc c. */
static int in_arc(const sarc *c, oc_vec3 p) {
  oc_vec3 d = sub(p, c->a);
  double w = dot(d, c->t), s = c->len > 0 ? w / c->len : 0;
  s = s < 0 ? 0 : s > 1 ? 1 : s;
  oc_vec3 q = v3(c->a.x + s * (c->b.x - c->a.x), c->a.y + s * (c->b.y - c->a.y),
                 c->a.z + s * (c->b.z - c->a.z));
  /* flat or mitred ends: nothing past their planes */
  if (!c->cap[0] && dot(sub(p, c->a), c->ma) < 0) return 0;
  if (!c->cap[1] && dot(sub(p, c->b), c->mb) > 0) return 0;
  d = sub(p, q);
  if (dot(d, d) > c->reach * c->reach) return 0;
  oc_vec3 n = ortho(v3(c->na.x + s * (c->nb.x - c->na.x),
                       c->na.y + s * (c->nb.y - c->na.y),
                       c->na.z + s * (c->nb.z - c->na.z)),
                    c->t);
  oc_vec3 r = cross(c->t, n);
  double u = dot(d, r), v = dot(d, n), along = dot(d, c->t);
  /* past a capped end: the profile turned about the up vector */
  if ((s == 0 && c->cap[0]) || (s == 1 && c->cap[1]))
    u = copysign(sqrt(u * u + along * along), u);
  return in_profile(c->pa, c->pb, s, u, v);
}

/* The arcs whose box holds the column, and their z range. */
static int sweep_window(void *ctx, double px, double py, double *z0,
                        double *z1) {
  swctx *x = ctx;
  *z0 = INFINITY;
  *z1 = -INFINITY;
  x->nlist = 0;
  for (size_t e = 0; e < x->narc; e++) {
    const sarc *c = &x->arc[e];
    if (px >= c->lo[0] && px <= c->hi[0] && py >= c->lo[1] && py <= c->hi[1]) {
      x->list[x->nlist++] = (int)e;
      *z0 = fmin(*z0, c->lo[2]);
      *z1 = fmax(*z1, c->hi[2]);
    }
  }
  return x->nlist > 0;
}

static int sweep_after(const void *ctx, double px, double py, double z,
                       int m0) {
  const swctx *x = ctx;
  if (m0 != OC_MAT_BEDROCK) return m0;
  for (int k = 0; k < x->nlist; k++)
    if (in_arc(&x->arc[x->list[k]], v3(px, py, z))) return OC_MAT_AIR;
  return m0;
}

/* The top of the solid (bedrock, sand, rocks) of stack k. */
static double solid_top(const oc_stacks *s, size_t k) {
  double z = s->zbase, top = s->zbase;
  for (size_t l = oc_soff(s, k), lend = l + oc_scount(s, k); l < lend; l++) {
    z += oc_lay_t(s->lay[l]);
    if (oc_lay_m(s->lay[l]) >= OC_MAT_SAND) top = z;
  }
  return top;
}

/* The top of the solid at (x, y), bilinear between stack centres. */
static double surface_at(const oc_stacks *s, double x, double y) {
  double fx = (x - s->x0) / s->cell, fy = (y - s->y0) / s->cell;
  fx = fmin(fmax(fx, 0), s->nx - 1);
  fy = fmin(fmax(fy, 0), s->ny - 1);
  int i = (int)fmin(floor(fx), s->nx - 2 < 0 ? 0 : s->nx - 2);
  int j = (int)fmin(floor(fy), s->ny - 2 < 0 ? 0 : s->ny - 2);
  int i1 = i + 1 < s->nx ? i + 1 : i, j1 = j + 1 < s->ny ? j + 1 : j;
  double wx = fx - i, wy = fy - j;
  double h00 = solid_top(s, (size_t)j * s->nx + i),
         h10 = solid_top(s, (size_t)j * s->nx + i1),
         h01 = solid_top(s, (size_t)j1 * s->nx + i),
         h11 = solid_top(s, (size_t)j1 * s->nx + i1);
  return (1 - wy) * ((1 - wx) * h00 + wx * h10) +
         wy * ((1 - wx) * h01 + wx * h11);
}

static int check(const oc_stacks *s, const oc_sweep_params *p, oc_error *err) {
  if (p->npoints < 2 || p->npoints > OC_SWEEP_MAX_POINTS)
    return oc_seterr(err, OC_EINVAL,
                     "'path' must have 2 .. %d points (got %zu)",
                     OC_SWEEP_MAX_POINTS, p->npoints);
  if (p->nedges < 1 || p->nedges > OC_SWEEP_MAX_POINTS)
    return oc_seterr(err, OC_EINVAL, "'path' must have 1 .. %d arcs (got %zu)",
                     OC_SWEEP_MAX_POINTS, p->nedges);
  if (p->nprofiles < 1 || p->nprofiles > OC_SWEEP_MAX_POINTS)
    return oc_seterr(err, OC_EINVAL, "'profiles' must hold 1 .. %d curves",
                     OC_SWEEP_MAX_POINTS);
  for (size_t k = 0; k < p->npoints; k++) {
    oc_vec3 q = p->points[k];
    if (!isfinite(q.x) || !isfinite(q.y) || (p->tunnel && !isfinite(q.z)))
      return oc_seterr(err, OC_EINVAL, "'path' point %zu must be finite",
                       k + 1);
    if (p->point_profile[k] < 0 || (size_t)p->point_profile[k] >= p->nprofiles)
      return oc_seterr(err, OC_EINVAL,
                       "'profile' of path point %zu must be 1 .. %zu (got %d)",
                       k + 1, p->nprofiles, p->point_profile[k] + 1);
  }
  for (size_t e = 0; e < p->nedges; e++) {
    int a = p->edges[2 * e], b = p->edges[2 * e + 1];
    if (a < 0 || b < 0 || (size_t)a >= p->npoints || (size_t)b >= p->npoints ||
        a == b)
      return oc_seterr(err, OC_EINVAL,
                       "'path' arc %zu must join two different points", e + 1);
  }
  for (size_t k = 0; k < p->nprofiles; k++) {
    size_t n = p->profile_off[k + 1] - p->profile_off[k];
    if (n < 3 || n > 1024)
      return oc_seterr(err, OC_EINVAL,
                       "'profiles[%zu]' must have 3 .. 1024 points (got %zu)",
                       k + 1, n);
    for (size_t q = 2 * p->profile_off[k]; q < 2 * p->profile_off[k + 1]; q++)
      if (!isfinite(p->profile_uv[q]))
        return oc_seterr(err, OC_EINVAL, "'profiles[%zu]' must be finite",
                         k + 1);
  }
  (void)s;
  return OC_OK;
}

/* The arcs, their profiles resampled (prof: NP pairs per profile). */
static void make_arcs(const oc_stacks *s, const oc_sweep_params *p,
                      const double *prof, const double *reach, oc_vec3 *pts,
                      oc_vec3 *up, sarc *arc) {
  for (size_t k = 0; k < p->npoints; k++) {
    pts[k] = p->points[k];
    up[k] = v3(0, 0, 1);
    if (p->tunnel) continue;
    double x = pts[k].x, y = pts[k].y, h = s->cell;
    pts[k].z = surface_at(s, x, y);
    /* the surface normal of the solid's top (central differences) */
    double gx = (surface_at(s, x + h, y) - surface_at(s, x - h, y)) / (2 * h);
    double gy = (surface_at(s, x, y + h) - surface_at(s, x, y - h)) / (2 * h);
    up[k] = unit(v3(-gx, -gy, 1));
  }
  for (size_t e = 0; e < p->nedges; e++) {
    int a = p->edges[2 * e], b = p->edges[2 * e + 1];
    sarc *c = &arc[e];
    c->a = pts[a];
    c->b = pts[b];
    oc_vec3 d = sub(c->b, c->a);
    c->len = sqrt(dot(d, d));
    c->t = c->len > 0 ? unit(d) : v3(1, 0, 0);
    c->na = ortho(up[a], c->t);
    c->nb = ortho(up[b], c->t);
    c->pa = prof + 2 * NP * p->point_profile[a];
    c->pb = prof + 2 * NP * p->point_profile[b];
    c->reach = fmax(reach[p->point_profile[a]], reach[p->point_profile[b]]);
    c->lo[0] = fmin(c->a.x, c->b.x) - c->reach;
    c->lo[1] = fmin(c->a.y, c->b.y) - c->reach;
    c->lo[2] = fmin(c->a.z, c->b.z) - c->reach;
    c->hi[0] = fmax(c->a.x, c->b.x) + c->reach;
    c->hi[1] = fmax(c->a.y, c->b.y) + c->reach;
    c->hi[2] = fmax(c->a.z, c->b.z) + c->reach;
  }
}

/* The arcs' ends grouped by position (the points' given coordinates,
** before any projection): an end alone is flat (cut square to its arc),
** two ends meeting are mitred (the plane halfway between the two arcs),
** three or more are capped (the profile turned about the up vector, so
** the branches' joint is closed). */
typedef struct jend {
  oc_vec3 p;
  int arc, end;
} jend;

static int cmp_end(const void *x, const void *y) {
  const jend *a = x, *b = y;
  if (a->p.x != b->p.x) return a->p.x < b->p.x ? -1 : 1;
  if (a->p.y != b->p.y) return a->p.y < b->p.y ? -1 : 1;
  if (a->p.z != b->p.z) return a->p.z < b->p.z ? -1 : 1;
  return a->arc != b->arc ? (a->arc < b->arc ? -1 : 1) : a->end - b->end;
}

/* Direction of arc c travelled away from its end `end`. */
static oc_vec3 away(const sarc *c, int end) {
  return end ? v3(-c->t.x, -c->t.y, -c->t.z) : c->t;
}

static int joints(const oc_sweep_params *p, sarc *arc) {
  size_t ne = p->nedges;
  jend *e = malloc(2 * ne * sizeof *e);
  if (!e) return 1;
  for (size_t k = 0; k < 2 * ne; k++) {
    oc_vec3 q = p->points[p->edges[k]];
    if (!p->tunnel) q.z = 0; /* cracks: z is not given */
    e[k] = (jend){q, (int)(k / 2), (int)(k % 2)};
  }
  qsort(e, 2 * ne, sizeof *e, cmp_end);
  for (size_t a = 0, b; a < 2 * ne; a = b) {
    for (b = a + 1; b < 2 * ne && e[b].p.x == e[a].p.x &&
                    e[b].p.y == e[a].p.y && e[b].p.z == e[a].p.z;
         b++)
      ;
    for (size_t k = a; k < b; k++) {
      sarc *c = &arc[e[k].arc];
      int end = e[k].end;
      oc_vec3 m = c->t; /* flat */
      int cap = b - a > 2;
      if (b - a == 2) { /* mitred: the plane between the two arcs */
        const jend *o = &e[k == a ? a + 1 : a];
        oc_vec3 h = sub(away(&arc[o->arc], o->end), away(c, end));
        if (dot(h, h) < 1e-12)
          cap = 1; /* a U-turn */
        else
          m = unit(end ? h : v3(-h.x, -h.y, -h.z));
      }
      c->cap[end] = cap;
      if (end)
        c->mb = m;
      else
        c->ma = m;
    }
  }
  free(e);
  return 0;
}

int oc_stacks_sweep(oc_stacks *s, const oc_sweep_params *p, double *changed,
                    oc_stabilize_result *res, oc_error *err) {
  if (changed) *changed = 0;
  if (res) *res = (oc_stabilize_result){0, 1, 0};
  if (check(s, p, err)) return OC_EINVAL;
  oc_stabilize_params sp;
  if (oc_layers_tool_stab(s, p->stab, p->stabilize, &sp, err)) return OC_EINVAL;
  size_t np = p->npoints, ne = p->nedges, nprof = p->nprofiles;
  double *prof = malloc((2 * NP + 1) * nprof * sizeof *prof);
  oc_vec3 *pts = malloc(2 * np * sizeof *pts);
  sarc *arc = malloc(ne * sizeof *arc);
  int *list = malloc(ne * sizeof *list);
  if (!prof || !pts || !arc || !list) {
    free(prof);
    free(pts);
    free(arc);
    free(list);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  double *reach = prof + 2 * NP * nprof;
  double *scratch = malloc(3 * (1024 * SUB + 1) * sizeof *scratch);
  if (!scratch) {
    free(prof);
    free(pts);
    free(arc);
    free(list);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  for (size_t k = 0; k < nprof; k++) {
    size_t o = p->profile_off[k], n = p->profile_off[k + 1] - o;
    resample(p->profile_uv + 2 * o, n, prof + 2 * NP * k, scratch);
    reach[k] = 0;
    for (int q = 0; q < NP; q++)
      reach[k] = fmax(reach[k], hypot(prof[2 * NP * k + 2 * q],
                                      prof[2 * NP * k + 2 * q + 1]));
    reach[k] *= 1.0 + 1e-9;
  }
  free(scratch);
  make_arcs(s, p, prof, reach, pts, pts + np, arc);
  if (joints(p, arc)) {
    free(prof);
    free(pts);
    free(arc);
    free(list);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  /* the stacks the volume can reach, as a window grid of their own */
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (size_t e = 0; e < ne; e++)
    for (int c = 0; c < 2; c++) {
      lo[c] = fmin(lo[c], arc[e].lo[c]);
      hi[c] = fmax(hi[c], arc[e].hi[c]);
    }
  double c = s->cell;
  int i0 = oc_sindex(ceil((lo[0] - s->x0) / c), 0, s->nx);
  int i1 = oc_sindex(floor((hi[0] - s->x0) / c), -1, s->nx - 1);
  int j0 = oc_sindex(ceil((lo[1] - s->y0) / c), 0, s->ny);
  int j1 = oc_sindex(floor((hi[1] - s->y0) / c), -1, s->ny - 1);
  int rc = OC_OK;
  oc_stacks *w = NULL;
  double before = 0, after = 0;
  if (i0 > i1 || j0 > j1) goto done;
  w = oc_stacks_window(s, i0, j0, i1, j1, err);
  if (!w) {
    rc = OC_ENOMEM;
    goto done;
  }
  before = oc_stacks_volume(w, OC_MAT_BEDROCK);
  swctx x = {arc, ne, list, 0};
  oc_layers_edit ed = {sweep_window, sweep_after, &x, c / 4};
  rc = oc_layers_rebuild_grid(w, &ed, err);
  after = oc_stacks_volume(w, OC_MAT_BEDROCK);
  if (rc == OC_OK) rc = oc_stacks_splice(s, w, i0, j0, err);
done:
  oc_stacks_free(w);
  free(prof);
  free(pts);
  free(arc);
  free(list);
  if (rc) return rc;
  if (changed) *changed = after - before;
  if (!p->stabilize || i0 > i1 || j0 > j1) return OC_OK;
  sp.region[0] = i0;
  sp.region[1] = j0;
  sp.region[2] = i1;
  sp.region[3] = j1;
  return oc_layers_stabilize_local(s, &sp, res, err);
}
