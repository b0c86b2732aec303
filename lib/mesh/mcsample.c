/*
** mcsample.c — the samples of a slab: which ones its cubes need, per
** sample column (the union of the k-ranges of the four cube columns
** around it), and their values. A sample in a gap between spans, where
** the field is constant along the column, takes the value of one sample
** of that gap, evaluated once. Padding samples are -INFINITY (outside)
** for closed meshes; open meshes evaluate them on the box faces.
*/
#include <math.h>

#include "mesh/mcwork.h"

int oc_mc_sample_ranges(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
                        const oc_mc_rlist *cubes, size_t *total) {
  int nx = g->n[0];
  size_t ncol = (size_t)(jb - ja + 1) * (size_t)(nx + 2);
  if (oc_mc_grow(&w->srat, &w->capsrat, ncol + 1, sizeof *w->srat)) return -1;
  w->nsr = 0;
  w->srat[0] = 0;
  size_t c = 0, off = 0;
  for (int j = ja; j <= jb; j++) {
    for (int i = -1; i <= nx; i++, c++) {
      size_t nt = 0;
      for (int q = 0; q < 4; q++) {
        int ci = i - 1 + (q & 1), cj = j - 1 + (q >> 1);
        if (ci < -1 || ci > nx - 1 || cj < ja || cj > jb - 1) continue;
        size_t cc = (size_t)(cj - ja) * (nx + 1) + (size_t)(ci + 1);
        size_t a = cubes->at[cc], e = cubes->at[cc + 1];
        if (oc_mc_grow(&w->tmp, &w->capt, nt + (e - a), sizeof *w->tmp))
          return -1;
        for (size_t r = a; r < e; r++) {
          w->tmp[nt].lo = cubes->r[r].lo;
          w->tmp[nt].hi = cubes->r[r].hi + 1;
          nt++;
        }
      }
      oc_mc_sort_ranges(w->tmp, nt);
      for (size_t t = 0; t < nt; t++) {
        oc_mc_srange *last = w->nsr > w->srat[c] ? &w->sr[w->nsr - 1] : NULL;
        if (last && w->tmp[t].lo <= last->hi + 1) {
          if (w->tmp[t].hi > last->hi) {
            off += (size_t)(w->tmp[t].hi - last->hi);
            last->hi = w->tmp[t].hi;
          }
          continue;
        }
        if (oc_mc_grow(&w->sr, &w->capsr, w->nsr + 1, sizeof *w->sr)) return -1;
        oc_mc_srange *s = &w->sr[w->nsr++];
        s->lo = w->tmp[t].lo;
        s->hi = w->tmp[t].hi;
        s->off = (ptrdiff_t)off - s->lo;
        off += (size_t)(s->hi - s->lo + 1);
      }
      w->srat[c + 1] = w->nsr;
    }
  }
  *total = off;
  return 0;
}

/* Values of the samples of one real column; the samples of a gap share
** the value of the gap's sample next to the span above it (or below it,
** for the top gap). */
static void eval_column(const oc_mcgrid *g, int i, int j, const oc_mc_srange *s,
                        size_t ns, const oc_mc_irange *var, size_t nvar,
                        double *val, size_t *calls) {
  int nz = g->n[2];
  double x = oc_mc_coord(g, 0, i), y = oc_mc_coord(g, 1, j);
  size_t v = 0;
  long gap = -1; /* the gap whose value is cached */
  double gapval = 0;
  for (size_t r = 0; r < ns; r++) {
    for (int32_t k = s[r].lo; k <= s[r].hi; k++) {
      double *out = &val[s[r].off + k];
      if (!g->open && (k < 0 || k >= nz)) {
        *out = -INFINITY;
        continue;
      }
      if (g->full) {
        *out = oc_program_eval(g->prog, (oc_vec3){x, y, oc_mc_coord(g, 2, k)});
        (*calls)++;
        continue;
      }
      while (v < nvar && var[v].hi < k)
        v++;
      if (v < nvar && var[v].lo <= k) {
        *out = oc_program_eval(g->prog, (oc_vec3){x, y, oc_mc_coord(g, 2, k)});
        (*calls)++;
        continue;
      }
      if (gap != (long)v) {
        /* gap v lies between var[v - 1] and var[v]; its sample next to a
        ** span is the one the dilated band needs anyway (a column without
        ** spans is one gap: its bottom sample stands for it) */
        int32_t k0 = v < nvar ? var[v].lo - 1 : v ? var[v - 1].hi + 1 : 0;
        gapval =
            oc_program_eval(g->prog, (oc_vec3){x, y, oc_mc_coord(g, 2, k0)});
        (*calls)++;
        gap = (long)v;
      }
      *out = gapval;
    }
  }
}

void oc_mc_samples(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w,
                   size_t *calls) {
  int nx = g->n[0], ny = g->n[1];
  size_t c = 0;
  for (int j = ja; j <= jb; j++) {
    for (int i = -1; i <= nx; i++, c++) {
      size_t ns = w->srat[c + 1] - w->srat[c];
      const oc_mc_srange *s = ns ? w->sr + w->srat[c] : NULL; /* no NULL + 0 */
      if (!g->open && (i < 0 || i >= nx || j < 0 || j >= ny)) {
        for (size_t r = 0; r < ns; r++)
          for (int32_t k = s[r].lo; k <= s[r].hi; k++)
            w->val[s[r].off + k] = -INFINITY;
        continue;
      }
      if (g->direct && w->dsurf[c]) {
        oc_mc_direct_column(g, i, j, c, s, ns, w);
        continue;
      }
      /* the spans of cube column (i, j) cover sample column (i, j); those
      ** of the last cube column and row also cover the padding beyond */
      int ci = i < nx ? i : nx - 1, cj = j < ny ? j : ny - 1;
      size_t cc = (size_t)(cj - ja) * (nx + 1) + (size_t)(ci + 1);
      size_t nvar = g->full ? 0 : w->var.at[cc + 1] - w->var.at[cc];
      const oc_mc_irange *var = nvar ? w->var.r + w->var.at[cc] : NULL;
      eval_column(g, i, j, s, ns, var, nvar, w->val, calls);
    }
  }
}
