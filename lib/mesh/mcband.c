/*
** mcband.c — the surface band of a slab: which cubes to visit.
**
** 1. Every cube column asks the program for the z-spans where the field
**    may vary over its footprint grown by one cube (the 1-ring of Paris et al.
** 2019
**    section 7); the cubes meeting a span, grown by one cube in z, are
**    visited; closed meshes add the cap cubes against the bottom and top
**    padding and whole columns along the box's sides (caps). The spans
**    also tell, per column, which samples lie in gaps, where the field is
**    constant.
** 2. The band is cut into blocks of OC_MC_BLOCK^3 cubes; a block whose
**    samples all lie on one side of T, by the field at the centre of their
**    box and the Lipschitz bound inside it, is dropped.
*/
#include <math.h>
#include <string.h>

#include "field/hfsurf.h"
#include "field/query.h"
#include "mesh/mcwork.h"

#define MAXSPANS 16
#define B OC_MC_BLOCK

static int32_t clampi(double v, int32_t lo, int32_t hi) {
  if (!(v >= lo)) return lo; /* NaN too */
  if (v > hi) return hi;
  return (int32_t)v;
}

/* ---- 1. the band ------------------------------------------------------- */

/* Cube and sample k-ranges of the z-span [zl, zh]: the cubes meeting it,
** grown by `grow` cubes (1: Paris et al. 2019's dilation), and the samples in
** it,
** with a margin far above the rounding of this arithmetic (a sample
** outside is in a gap, where the field is exactly constant along the
** column). The
** padding samples of open meshes lie on the faces: they vary when the
** span reaches the face. */
static void span_ranges(const oc_mcgrid *g, double zl, double zh, int grow,
                        oc_mc_irange *c, oc_mc_irange *s) {
  int nz = g->n[2];
  double a = (zl - g->lo[2]) / g->h[2], b = (zh - g->lo[2]) / g->h[2];
  c->lo = clampi(ceil(a - 1.5) - grow, -1, nz - 1);
  c->hi = clampi(floor(b - 0.5) + grow, -1, nz - 1);
  s->lo = clampi(ceil(a - 0.5 - 1e-6), 0, nz - 1);
  s->hi = clampi(floor(b - 0.5 + 1e-6), 0, nz - 1);
  if (g->open && a <= 1e-6) s->lo = -1;
  if (g->open && b >= nz - 1e-6) s->hi = nz;
  /* a span between two samples still separates the gaps below and above
  ** it, whose constant values differ: its sample just above varies */
  if (s->lo > s->hi) s->hi = s->lo;
}

/* Direct blocks: per block of B x B cube columns (aligned as the culling
** blocks), the direct surface that governs the block's whole footprint,
** grown by one cube, alone, or NULL. Rows ja .. jr of the slab; the
** decision depends on the block only, so slabs sharing a sample row agree
** on it. */
static int direct_blocks(const oc_mcgrid *g, int ja, int jr, oc_mcwork *w) {
  int nx = g->n[0], ny = g->n[1];
  int nbu = (nx + 1 + B - 1) / B, bv0 = (ja + 1) / B, bv1 = (jr + 1) / B;
  size_t nb = (size_t)(bv1 - bv0 + 1) * (size_t)nbu;
  if (oc_mc_grow(&w->bsurf, &w->capbsurf, nb, sizeof *w->bsurf)) return -1;
  oc_zspan sp[MAXSPANS];
  size_t q = 0;
  for (int bv = bv0; bv <= bv1; bv++) {
    int j0 = bv * B - 1, j1 = j0 + B - 1 < ny - 1 ? j0 + B - 1 : ny - 1;
    for (int bu = 0; bu < nbu; bu++, q++) {
      int i0 = bu * B - 1, i1 = i0 + B - 1 < nx - 1 ? i0 + B - 1 : nx - 1;
      uint32_t hf = OC_MC_NONE;
      int ns = oc_program_column_query(
          g->prog, oc_mc_coord(g, 0, i0 - 1), oc_mc_coord(g, 1, j0 - 1),
          oc_mc_coord(g, 0, i1 + 2), oc_mc_coord(g, 1, j1 + 2), sp, MAXSPANS,
          &hf);
      const struct oc_hfsurf *hs =
          ns >= 0 && hf != OC_MC_NONE ? oc_mc_surface(g, hf) : NULL;
      w->bsurf[q] = hs && oc_mc_direct_kind(hs) ? hs : NULL;
    }
  }
  return 0;
}

/* Cube ranges of cube column (i, j) inside a direct block: exactly the
** cubes the surface crosses, from the elevations of its four sample
** columns (no dilation: every sample of them is on the surface's side
** given by its elevation, so no other cube holds a crossing); closed
** meshes add the cap cubes that hold one. 1 done, 0 when an elevation is
** not finite, -1 out of memory. */
static int exact_cubes(const oc_mcgrid *g, oc_mcwork *w,
                       const struct oc_hfsurf *hs, int i, int j, size_t fc) {
  int nz = g->n[2];
  double lo = INFINITY, hi = -INFINITY;
  int bottom = 0, top = 0; /* a sample of the bottom/top layer inside */
  double z0 = oc_mc_coord(g, 2, 0), z1 = oc_mc_coord(g, 2, nz - 1);
  for (int q = 0; q < 4; q++) {
    double e = oc_mc_elevation(g, w, hs, i + (q & 1), j + (q >> 1))[0];
    lo = fmin(lo, e);
    hi = fmax(hi, e);
    bottom |= oc_hfsurf_value(hs, e, z0) > g->T;
    top |= oc_hfsurf_value(hs, e, z1) > g->T;
  }
  if (!(isfinite(lo) && isfinite(hi))) return 0;
  oc_zspan sp[2];
  int n = oc_hfsurf_elev_spans(hs, lo, hi, sp);
  /* the cap cubes against the padding (outside) hold a crossing only
  ** where a sample next to it is inside */
  if (!g->open && bottom && oc_mc_rlist_add(&w->cube, fc, -1, -1)) return -1;
  for (int s = 0; s < n; s++) {
    oc_mc_irange cr, sr;
    span_ranges(g, sp[s].lo, sp[s].hi, 0, &cr, &sr);
    if (oc_mc_rlist_add(&w->cube, fc, cr.lo, cr.hi)) return -1;
  }
  if (!g->open && top && oc_mc_rlist_add(&w->cube, fc, nz - 1, nz - 1))
    return -1;
  return 1;
}

/* Cube ranges (rows ja .. jb - 1) and varying sample ranges (rows ja ..
** min(jb, ny - 1)) of every cube column i = -1 .. nx - 1. */
int oc_mc_band(const oc_mcgrid *g, int ja, int jb, int jr, oc_mcwork *w) {
  int nx = g->n[0], ny = g->n[1], nz = g->n[2];
  size_t ncol = (size_t)(jr - ja + 1) * (size_t)(nx + 1);
  if (oc_mc_rlist_columns(&w->cube, ncol) || oc_mc_rlist_columns(&w->var, ncol))
    return -1;
  /* direct sample columns: sample column (i, j) is direct when the
  ** footprint of cube column (i, j), which covers its four edges, is
  ** governed by one heightfield-like op alone (mcdirect.c): its block's
  ** footprint, or else its own */
  size_t nsc = (size_t)(jb - ja + 1) * (size_t)(nx + 2);
  int nbu = (nx + 1 + B - 1) / B, bv0 = (ja + 1) / B;
  if (g->direct) {
    if (oc_mc_grow(&w->dsurf, &w->capdsurf, nsc, sizeof *w->dsurf) ||
        oc_mc_grow(&w->esurf, &w->capesurf, nsc, sizeof *w->esurf) ||
        oc_mc_grow(&w->delev, &w->capdelev, 3 * nsc, sizeof *w->delev) ||
        direct_blocks(g, ja, jr, w))
      return -1;
    for (size_t q = 0; q < nsc; q++)
      w->dsurf[q] = w->esurf[q] = NULL;
  }
  oc_zspan sp[MAXSPANS], zsp[MAXSPANS], lsp[2];
  size_t c = 0;
  for (int j = ja; j <= jr; j++) {
    for (int i = -1; i < nx; i++, c++) {
      size_t fc = w->cube.n, fv = w->var.n;
      int side = i == -1 || i == nx - 1 || j == -1 || j == ny - 1;
      const struct oc_hfsurf *bs =
          g->direct && !side ? w->bsurf[(size_t)((j + 1) / B - bv0) * nbu +
                                        (size_t)((i + 1) / B)]
                             : NULL;
      if (bs) {
        /* a direct block: no column query, and exact cubes (all of the
        ** column when full, or should an elevation not be finite) */
        int rc = 0;
        if (j < jb && (g->full || !(rc = exact_cubes(g, w, bs, i, j, fc))))
          rc = oc_mc_rlist_add(&w->cube, fc, -1, nz - 1) ? -1 : 1;
        if (rc < 0) return -1;
        w->dsurf[(size_t)(j - ja) * (nx + 2) + (size_t)(i + 1)] = bs;
        w->cube.at[c + 1] = w->cube.n;
        w->var.at[c + 1] = w->var.n; /* direct: no varying samples */
        continue;
      }
      int ns = -1;
      uint32_t hf = OC_MC_NONE;
      double fx0 = oc_mc_coord(g, 0, i - 1), fy0 = oc_mc_coord(g, 1, j - 1);
      double fx1 = oc_mc_coord(g, 0, i + 2), fy1 = oc_mc_coord(g, 1, j + 2);
      int nzs = -1;
      if (!g->full || g->direct)
        ns =
            oc_program_column_query_z(g->prog, fx0, fy0, fx1, fy1, sp, MAXSPANS,
                                      g->nsurf ? &hf : NULL, zsp, &nzs);
      if (g->full) ns = nzs = -1;
      const struct oc_hfsurf *hs =
          hf != OC_MC_NONE ? oc_mc_surface(g, hf) : NULL;
      if (g->direct && i >= 0 && j >= 0 && hs && oc_mc_direct_kind(hs))
        w->dsurf[(size_t)(j - ja) * (nx + 2) + (size_t)(i + 1)] = hs;
      /* cubes: where the field may vary, or, in a column one surface
      ** governs alone, only where that surface may be (Paris et al. 2019's
      ** exact
      ** elevation bounds): elsewhere no sample is on the other side */
      const oc_zspan *csp = sp;
      int ncs = ns;
      if (hs && ns >= 0) {
        ncs = oc_hfsurf_level_spans(hs, fx0, fy0, fx1, fy1, lsp);
        csp = lsp;
      }
      int whole = ns < 0 || (side && !g->open);
      if (j < jb) {
        if (whole) {
          if (oc_mc_rlist_add(&w->cube, fc, -1, nz - 1)) return -1;
        } else {
          if (!g->open && oc_mc_rlist_add(&w->cube, fc, -1, -1)) return -1;
          for (int s = 0; s < ncs; s++) {
            oc_mc_irange cr, sr;
            if (!(csp[s].lo <= csp[s].hi)) continue;
            span_ranges(g, csp[s].lo, csp[s].hi, 1, &cr, &sr);
            if (oc_mc_rlist_add(&w->cube, fc, cr.lo, cr.hi)) return -1;
          }
          if (!g->open && oc_mc_rlist_add(&w->cube, fc, nz - 1, nz - 1))
            return -1;
        }
      }
      /* samples evaluated one by one: where the field varies along the
      ** column (the others share their gap's value) */
      if (nzs < 0) {
        if (oc_mc_rlist_add(&w->var, fv, -g->open, nz - 1 + g->open)) return -1;
      } else {
        for (int s = 0; s < nzs; s++) {
          oc_mc_irange cr, sr;
          if (!(zsp[s].lo <= zsp[s].hi)) continue;
          span_ranges(g, zsp[s].lo, zsp[s].hi, 1, &cr, &sr);
          if (oc_mc_rlist_add(&w->var, fv, sr.lo, sr.hi)) return -1;
        }
      }
      w->cube.at[c + 1] = w->cube.n;
      w->var.at[c + 1] = w->var.n;
    }
  }
  return 0;
}

/* ---- 2. Lipschitz culling ---------------------------------------------- */

/* 1 when every sample the block's cubes use is on one side of T. Cubes
** i0 .. i1 (per axis) use samples i0 .. i1 + 1; the padding samples of
** closed meshes are outside, so a block touching them may only be dropped
** when outside; those of open meshes lie on the faces, in the box. */
static int block_uniform(const oc_mcgrid *g, const int c0[3], const int c1[3],
                         size_t *calls) {
  double lo[3], hi[3], r2 = 0;
  int pad = 0;
  oc_vec3 ctr;
  for (int a = 0; a < 3; a++) {
    int s0 = c0[a], s1 = c1[a] + 1;
    if (!g->open && s0 < 0) s0 = 0, pad = 1;
    if (!g->open && s1 > g->n[a] - 1) s1 = g->n[a] - 1, pad = 1;
    lo[a] = oc_mc_coord(g, a, s0);
    hi[a] = oc_mc_coord(g, a, s1);
    r2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
  }
  ctr.x = 0.5 * (lo[0] + hi[0]);
  ctr.y = 0.5 * (lo[1] + hi[1]);
  ctr.z = 0.5 * (lo[2] + hi[2]);
  double fc = oc_program_eval(g->prog, ctr);
  (*calls)++;
  oc_aabb box = {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
  double L = oc_program_lipschitz_in(g->prog, box);
  /* margin for the rounding of the centre and of this product */
  double m = L * 0.5 * sqrt(r2) * (1 + 1e-9) + 1e-12 * (fabs(g->T) + 1);
  if (!(m < INFINITY)) return 0;
  if (g->T - fc > m) return 1;
  if (!pad && fc - g->T > m) return 1;
  return 0;
}

/* Whether sample columns i0 .. i1 of rows j0 .. j1 are all direct. */
static int all_direct(const oc_mcgrid *g, const oc_mcwork *w, int ja, int i0,
                      int i1, int j0, int j1) {
  if (!g->direct) return 0;
  for (int j = j0; j <= j1; j++)
    for (int i = i0; i <= i1; i++)
      if (!w->dsurf[(size_t)(j - ja) * (g->n[0] + 2) + (size_t)(i + 1)])
        return 0;
  return 1;
}

int oc_mc_cull(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
               size_t *calls) {
  int nx = g->n[0], nz = g->n[2];
  int nbu = (nx + 1 + B - 1) / B, nbv = (jb - ja + B - 1) / B;
  if (oc_mc_rlist_columns(&w->cull, (size_t)nbu * nbv)) return -1;
  size_t bc = 0;
  for (int bv = 0; bv < nbv; bv++) {
    int j0 = ja + bv * B, j1 = j0 + B - 1 < jb - 1 ? j0 + B - 1 : jb - 1;
    for (int bu = 0; bu < nbu; bu++, bc++) {
      int i0 = bu * B - 1, i1 = i0 + B - 1 < nx - 1 ? i0 + B - 1 : nx - 1;
      size_t first = w->cull.n;
      /* direct columns cost no field call: culling them would cost more
      ** than it saves */
      if (all_direct(g, w, ja, i0, i1 + 1, j0, j1 + 1)) {
        w->cull.at[bc + 1] = w->cull.n;
        continue;
      }
      /* union of the block column's cube ranges */
      size_t nt = 0;
      for (int j = j0; j <= j1; j++) {
        size_t c = (size_t)(j - ja) * (nx + 1) + (size_t)(i0 + 1);
        size_t a = w->cube.at[c], e = w->cube.at[c + (size_t)(i1 - i0) + 1];
        if (oc_mc_grow(&w->tmp, &w->capt, nt + (e - a), sizeof *w->tmp))
          return -1;
        if (e > a) /* w->tmp may still be NULL */
          memcpy(w->tmp + nt, w->cube.r + a, (e - a) * sizeof *w->tmp);
        nt += e - a;
      }
      oc_mc_sort_ranges(w->tmp, nt);
      int last = -1; /* last block tested */
      for (size_t t = 0; t < nt; t++) {
        int k0 = (w->tmp[t].lo + 1) / B, k1 = (w->tmp[t].hi + 1) / B;
        for (int bk = k0 > last + 1 ? k0 : last + 1; bk <= k1; bk++) {
          int lo[3] = {i0, j0, bk * B - 1};
          int hi[3] = {i1, j1,
                       bk * B + B - 2 < nz - 1 ? bk * B + B - 2 : nz - 1};
          if (block_uniform(g, lo, hi, calls) &&
              oc_mc_rlist_add(&w->cull, first, lo[2], hi[2]))
            return -1;
          last = bk;
        }
      }
      w->cull.at[bc + 1] = w->cull.n;
    }
  }
  /* kept = cube ranges minus the culled blocks */
  size_t ncol = (size_t)(jb - ja) * (size_t)(nx + 1);
  if (oc_mc_rlist_columns(&w->kept, ncol)) return -1;
  size_t c = 0;
  for (int j = ja; j < jb; j++) {
    for (int i = -1; i < nx; i++, c++) {
      size_t b = (size_t)((j - ja) / B) * nbu + (size_t)((i + 1) / B);
      size_t ncu = w->cull.at[b + 1] - w->cull.at[b], u = 0, first = w->kept.n;
      /* NULL + 0 is undefined: with nothing culled the list may be NULL */
      const oc_mc_irange *cu = ncu ? w->cull.r + w->cull.at[b] : NULL;
      for (size_t r = w->cube.at[c]; r < w->cube.at[c + 1]; r++) {
        int32_t lo = w->cube.r[r].lo, hi = w->cube.r[r].hi;
        while (lo <= hi) {
          while (u < ncu && cu[u].hi < lo)
            u++;
          if (u < ncu && cu[u].lo <= lo) { /* lo is culled */
            lo = cu[u].hi + 1;
            continue;
          }
          int32_t e = u < ncu && cu[u].lo <= hi ? cu[u].lo - 1 : hi;
          if (oc_mc_rlist_add(&w->kept, first, lo, e)) return -1;
          lo = e + 1;
        }
      }
      w->kept.at[c + 1] = w->kept.n;
    }
  }
  return 0;
}
