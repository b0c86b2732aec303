/*
** canon.c — the canonical form of a material stack (Peytavie et al. 2009,
** section 3.4, figure 6) and its segment view.
**
** Canonical: no empty layer; adjacent layers of one material merged;
** within each gap between bedrock layers (and below the first, above the
** last) the loose materials sorted upwards sand, rocks, water, air (the
** paper: sand, rocks, air; water just below air is outcrop's choice, so
** that sand and rocks settle under lakes); no air on top (implicit).
** So a stack is bedrock layers with, in each gap, at most one layer of
** each loose material: the segments the stabilisation and the tools edit.
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "layers/layers.h"

/* Gap order: sand, rocks, water, air. */
static const int GAP_MAT[4] = {OC_MAT_SAND, OC_MAT_ROCKS, OC_MAT_WATER,
                               OC_MAT_AIR};

static int gap_index(int m) {
  switch (m) {
  case OC_MAT_SAND:
    return 0;
  case OC_MAT_ROCKS:
    return 1;
  case OC_MAT_WATER:
    return 2;
  default:
    return 3;
  }
}

int oc_seg_index(int m) {
  int g = gap_index(m);
  return m == OC_MAT_BEDROCK || g == 3 ? -1 : g;
}

/* Emits the gap's loose layers in order (air only when `air`). */
static size_t flush(double g[4], int air, oc_layer *out, size_t k) {
  for (int q = 0; q < (air ? 4 : 3); q++)
    if (g[q] > 0) out[k++] = (oc_layer){g[q], GAP_MAT[q]};
  g[0] = g[1] = g[2] = g[3] = 0;
  return k;
}

size_t oc_layers_canon(const oc_layer *in, size_t n, oc_layer *out) {
  double g[4] = {0, 0, 0, 0};
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    if (!(in[i].t > 0)) continue;
    if (in[i].m != OC_MAT_BEDROCK) {
      g[gap_index(in[i].m)] += in[i].t;
      continue;
    }
    k = flush(g, 1, out, k);
    if (k > 0 && out[k - 1].m == OC_MAT_BEDROCK)
      out[k - 1].t += in[i].t;
    else
      out[k++] = in[i];
  }
  return flush(g, 0, out, k);
}

size_t oc_layers_segments(const oc_stacks *s, size_t k, oc_lseg *out) {
  size_t n = 0;
  double z = s->zbase;
  oc_lseg *c = &out[0];
  *c = (oc_lseg){z, 0, 0, {0, 0, 0}};
  for (size_t l = oc_soff(s, k), lend = l + oc_scount(s, k); l < lend; l++) {
    double t = oc_lay_t(s->lay[l]);
    int m = oc_lay_m(s->lay[l]);
    if (m == OC_MAT_BEDROCK) {
      c->cap = z - c->floor;
      z += t;
      c = &out[++n];
      *c = (oc_lseg){z, 0, t, {0, 0, 0}};
      continue;
    }
    int q = oc_seg_index(m);
    if (q >= 0) c->a[q] += t;
    z += t;
  }
  c->cap = INFINITY;
  return n + 1;
}

size_t oc_layers_from_segments(const oc_lseg *seg, size_t nseg, oc_layer *out) {
  size_t k = 0;
  for (size_t i = 0; i < nseg; i++) {
    const oc_lseg *c = &seg[i];
    if (i > 0 && c->bed > 0) {
      if (k > 0 && out[k - 1].m == OC_MAT_BEDROCK)
        out[k - 1].t += c->bed;
      else
        out[k++] = (oc_layer){c->bed, OC_MAT_BEDROCK};
    }
    double used = 0;
    for (int q = 0; q < OC_SEG_N; q++)
      if (c->a[q] > 0) {
        out[k++] = (oc_layer){c->a[q], GAP_MAT[q]};
        used += c->a[q];
      }
    /* (air thinner than rounding would be a spurious layer) */
    if (i + 1 < nseg && c->cap - used > 1e-12 * (fabs(c->floor) + c->cap))
      out[k++] = (oc_layer){c->cap - used, OC_MAT_AIR};
  }
  return k;
}

/* ---- every stack ----------------------------------------------------------
 */

int oc_layers_decode_all(const oc_stacks *s, oc_lseg **seg, size_t **soff,
                         oc_error *err) {
  size_t ns = (size_t)s->nx * s->ny;
  size_t *o = malloc((ns + 1) * sizeof *o);
  if (!o) return oc_seterr(err, OC_ENOMEM, "out of memory");
  o[0] = 0;
  for (size_t k = 0; k < ns; k++) {
    size_t nb = 0;
    for (size_t l = oc_soff(s, k), lend = l + oc_scount(s, k); l < lend; l++)
      nb += oc_lay_m(s->lay[l]) == OC_MAT_BEDROCK;
    o[k + 1] = o[k] + nb + 1;
  }
  oc_lseg *g = malloc(o[ns] * sizeof *g);
  if (!g) {
    free(o);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
#pragma omp parallel for schedule(static)
  for (long k = 0; k < (long)ns; k++)
    oc_layers_segments(s, (size_t)k, g + o[k]);
  *seg = g;
  *soff = o;
  return OC_OK;
}

int oc_layers_encode_all(oc_stacks *s, const oc_lseg *seg, const size_t *soff,
                         oc_error *err) {
  size_t ns = (size_t)s->nx * s->ny, most = 0;
  for (size_t k = 0; k < ns; k++)
    if (soff[k + 1] - soff[k] > most) most = soff[k + 1] - soff[k];
  oc_layer *buf = malloc(10 * most * sizeof *buf);
  oc_stacks_builder b;
  if (!buf || oc_builder_init(&b, ns, oc_soff(s, ns) + ns / 4, err)) {
    free(buf);
    return buf ? OC_ENOMEM : oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  for (size_t k = 0; k < ns; k++) {
    size_t n =
        oc_layers_from_segments(seg + soff[k], soff[k + 1] - soff[k], buf);
    size_t m = oc_layers_canon(buf, n, buf + 5 * most);
    if (oc_builder_push(&b, buf + 5 * most, m, err)) {
      oc_builder_free(&b);
      free(buf);
      return OC_ENOMEM;
    }
  }
  oc_builder_commit(&b, s);
  free(buf);
  return OC_OK;
}
