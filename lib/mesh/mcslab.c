/*
** mcslab.c — marching cubes over one slab of cube rows, restricted to the
** surface band.
**
** The steps: the band (mcband.c: cube ranges from the column spans, then
** Lipschitz culling), the samples (mcsample.c), then the cubes, here: the
** case from the 8 samples, triangles from the table (mctable.c); each
** crossing edge gets one vertex (mcvertex.c), found through a slot on its
** lower sample, so the cubes sharing an edge share the vertex.
**
** Memory is proportional to the band within the slab, never to the box.
** Nothing depends on the thread running it: a slab's output is a function
** of the grid and its rows only.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "mesh/mctable.h"
#include "mesh/mcwork.h"

typedef struct cubecol {
  ptrdiff_t off[4]; /* corner column q = x + 2y: sample k at off[q] + k */
} cubecol;

static int add_vertex(oc_mcout *o, oc_mcwork *w, const float p[3],
                      const float n[3], int flat, uint32_t *index) {
  if (o->nv >= OC_MC_NONE - 1) return -1;
  if (o->nv == o->capv) {
    size_t cap = o->capv, c2 = o->capv;
    if (oc_mc_grow(&o->pos, &cap, o->nv + 1, 3 * sizeof(float)) ||
        oc_mc_grow(&o->nrm, &c2, o->nv + 1, 3 * sizeof(float)))
      return -1;
    o->capv = cap;
  }
  memcpy(o->pos + 3 * o->nv, p, 3 * sizeof(float));
  memcpy(o->nrm + 3 * o->nv, n, 3 * sizeof(float));
  *index = (uint32_t)o->nv;
  if (flat) {
    if (oc_mc_grow(&w->flat, &w->capflat, w->nflat + 1, sizeof *w->flat))
      return -1;
    w->flat[w->nflat++] = *index;
  }
  o->nv++;
  return 0;
}

/* The vertex of edge e of cube (i, j, k), made on first use. */
static int edge_vertex(const oc_mcgrid *g, oc_mcwork *w, oc_mcout *o,
                       const cubecol *cc, int i, int j, int k, int e,
                       uint32_t *out) {
  int c = oc_mc_edge_lo[e], axis = e / 4;
  int q = c & 3, kk = k + (c >> 2);
  size_t at = (size_t)(cc->off[q] + kk);
  uint32_t *slot = &w->slot[3 * at + (size_t)axis];
  if (*slot == OC_MC_NONE) {
    int c2 = c | (1 << axis);
    double va = w->val[at], vb = w->val[cc->off[c2 & 3] + k + (c2 >> 2)];
    int s[3] = {i + (c & 1), j + ((c >> 1) & 1), kk};
    float p[3], n[3];
    int flat = 0;
    if (!g->direct || !oc_mc_direct_vertex(g, w, s, axis, p, n))
      o->calls += (size_t)oc_mc_vertex(g, s, axis, va, vb, p, n, &flat);
    if (add_vertex(o, w, p, n, flat, slot)) return -1;
  }
  *out = *slot;
  return 0;
}

static int emit(const oc_mcgrid *g, oc_mcwork *w, oc_mcout *o,
                const oc_mctable *tb, const cubecol *cc, int i, int j, int k,
                int m) {
  const uint8_t *t = tb->tri[m];
  for (int n = 0; n < tb->ntri[m]; n++, t += 3) {
    uint32_t v[3];
    for (int a = 0; a < 3; a++)
      if (edge_vertex(g, w, o, cc, i, j, k, t[a], &v[a])) return -1;
    if (oc_mc_grow(&o->tri, &o->capt, o->nt + 1, 3 * sizeof(uint32_t)))
      return -1;
    memcpy(o->tri + 3 * o->nt, v, sizeof v);
    o->nt++;
  }
  return 0;
}

static ptrdiff_t find_off(const oc_mcwork *w, size_t col, int32_t a,
                          int32_t b) {
  for (size_t r = w->srat[col]; r < w->srat[col + 1]; r++)
    if (w->sr[r].lo <= a && w->sr[r].hi >= b) return w->sr[r].off;
  return PTRDIFF_MIN; /* cannot happen: the ranges were built to cover */
}

static int march(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
                 const oc_mc_rlist *cubes, oc_mcout *o) {
  const oc_mctable *tb = oc_mctable_get();
  int nx = g->n[0];
  const double T = g->T;
  const double *val = w->val;
  size_t c = 0;
  for (int j = ja; j < jb; j++) {
    for (int i = -1; i < nx; i++, c++) {
      for (size_t r = cubes->at[c]; r < cubes->at[c + 1]; r++) {
        int32_t a = cubes->r[r].lo, b = cubes->r[r].hi;
        cubecol cc;
        for (int q = 0; q < 4; q++) {
          size_t col = (size_t)(j - ja + (q >> 1)) * (size_t)(nx + 2) +
                       (size_t)(i + 1 + (q & 1));
          cc.off[q] = find_off(w, col, a, b + 1);
          if (cc.off[q] == PTRDIFF_MIN) return -1;
        }
        o->cells += (size_t)(b - a + 1);
        int lo = (val[cc.off[0] + a] > T) | (val[cc.off[1] + a] > T) << 1 |
                 (val[cc.off[2] + a] > T) << 2 | (val[cc.off[3] + a] > T) << 3;
        for (int32_t k = a; k <= b; k++) {
          int hi = (val[cc.off[0] + k + 1] > T) |
                   (val[cc.off[1] + k + 1] > T) << 1 |
                   (val[cc.off[2] + k + 1] > T) << 2 |
                   (val[cc.off[3] + k + 1] > T) << 3;
          int m = lo | hi << 4;
          if (m != 0 && m != 255 && emit(g, w, o, tb, &cc, i, j, k, m))
            return -1;
          lo = hi;
        }
      }
    }
  }
  return 0;
}

/* ---- 5. shared rows and flat normals ------------------------------------- */

/* Appends the vertices on the x- and z-edges of sample row j, keyed by
** edge, sorted. */
static int row_keys(const oc_mcgrid *g, int ja, int j, const oc_mcwork *w,
                    oc_mcout *o) {
  int nx = g->n[0], nz = g->n[2];
  for (int i = -1; i <= nx; i++) {
    size_t col = (size_t)(j - ja) * (size_t)(nx + 2) + (size_t)(i + 1);
    for (size_t r = w->srat[col]; r < w->srat[col + 1]; r++) {
      const oc_mc_srange *s = &w->sr[r];
      for (int32_t k = s->lo; k <= s->hi; k++) {
        for (int a = 0; a < 3; a += 2) {
          uint32_t v = w->slot[3 * (size_t)(s->off + k) + (size_t)a];
          if (v == OC_MC_NONE) continue;
          if (o->nk == o->capk) {
            size_t c1 = o->capk, c2 = o->capk;
            if (oc_mc_grow(&o->key, &c1, o->nk + 1, sizeof *o->key) ||
                oc_mc_grow(&o->kidx, &c2, o->nk + 1, sizeof *o->kidx))
              return -1;
            o->capk = c1;
          }
          o->key[o->nk] =
              (((uint64_t)(i + 1) * (uint64_t)(nz + 2) + (uint64_t)(k + 1))
               << 1) |
              (uint64_t)(a == 2);
          o->kidx[o->nk++] = v;
        }
      }
    }
  }
  return 0;
}

/* Vertices where the gradient vanished take their triangles' mean normal
** (area-weighted); without triangles they keep the provisional one. */
static int flat_normals(oc_mcout *o, oc_mcwork *w) {
  if (!w->nflat) return 0;
  double *acc = calloc(o->nv * 3, sizeof *acc);
  if (!acc) return -1;
  for (size_t t = 0; t < o->nt; t++) {
    const uint32_t *v = o->tri + 3 * t;
    const float *a = o->pos + 3 * v[0], *b = o->pos + 3 * v[1],
                *c = o->pos + 3 * v[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double x[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * x[2] - u[2] * x[1], u[2] * x[0] - u[0] * x[2],
                   u[0] * x[1] - u[1] * x[0]};
    for (int k = 0; k < 3; k++)
      for (int d = 0; d < 3; d++)
        acc[3 * v[k] + d] += n[d];
  }
  for (size_t f = 0; f < w->nflat; f++) {
    double *n = acc + 3 * w->flat[f];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(l > 0 && isfinite(l))) continue;
    for (int d = 0; d < 3; d++)
      o->nrm[3 * w->flat[f] + d] = (float)(n[d] / l);
  }
  free(acc);
  return 0;
}

/* ---- the slab ---------------------------------------------------------- */

static size_t band_cubes(const oc_mc_rlist *l) {
  size_t n = 0;
  for (size_t r = 0; r < l->n; r++)
    n += (size_t)(l->r[r].hi - l->r[r].lo + 1);
  return n;
}

static int too_thick(oc_error *err, size_t n, int ja, int jb,
                     const oc_mcgrid *g) {
  return oc_seterr(err, OC_ENOMEM,
                   "the surface band needs %zu samples in a slab of %d rows "
                   "(at most %zu): use a larger 'cell' or a smaller 'box'",
                   n, jb - ja, g->max_samples);
}

static int nomem(oc_error *err) {
  return oc_seterr(err, OC_ENOMEM, "out of memory while meshing");
}

/* Sizes the output like the previous slab's, so it rarely grows (a
** recycled output may be large enough already). */
static int presize(oc_mcout *o, const oc_mcwork *w) {
  size_t v = w->last_nv + w->last_nv / 4, t = w->last_nt + w->last_nt / 4;
  if (v > o->capv) {
    size_t c1 = o->capv, c2 = o->capv;
    if (oc_mc_grow(&o->pos, &c1, v, 3 * sizeof(float)) ||
        oc_mc_grow(&o->nrm, &c2, v, 3 * sizeof(float)))
      return -1;
    o->capv = c1;
  }
  if (t && oc_mc_grow(&o->tri, &o->capt, t, 3 * sizeof(uint32_t))) return -1;
  return 0;
}

int oc_mc_slab(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w, oc_mcout *o,
               oc_error *err) {
  int ny = g->n[1];
  int jr = jb <= ny - 1 ? jb : ny - 1; /* last row with spans */
  w->cube.n = 0;
  w->nflat = 0;
  w->ja = ja;
  if (oc_mc_band(g, ja, jb, jr, w)) return nomem(err);
  /* a band this thick (noise, whole columns) would not fit anyway, and
  ** culling it would take long: refuse it first */
  if (w->cube.n && band_cubes(&w->cube) > 2 * g->max_samples)
    return too_thick(err, band_cubes(&w->cube), ja, jb, g);
  const oc_mc_rlist *cubes = &w->cube;
  if (!g->full) {
    if (oc_mc_cull(g, ja, jb, w, &o->calls)) return nomem(err);
    cubes = &w->kept;
  }
  size_t total;
  if (oc_mc_sample_ranges(g, ja, jb, w, cubes, &total)) return nomem(err);
  if (total > g->max_samples) return too_thick(err, total, ja, jb, g);
  if (oc_mc_grow(&w->val, &w->capval, total, sizeof *w->val) ||
      oc_mc_grow(&w->slot, &w->capslot, 3 * total, sizeof *w->slot) ||
      presize(o, w))
    return nomem(err);
  if (total) memset(w->slot, 0xff, total * 3 * sizeof *w->slot);
  oc_mc_samples(g, ja, jb, w, &o->calls);
  if (march(g, ja, jb, w, cubes, o) || flat_normals(o, w) ||
      row_keys(g, ja, ja, w, o))
    return nomem(err);
  o->nb = o->nk;
  if (row_keys(g, ja, jb, w, o)) return nomem(err);
  w->last_nv = o->nv;
  w->last_nt = o->nt;
  return 0;
}
