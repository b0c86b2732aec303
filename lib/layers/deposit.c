/*
** deposit.c — the deposit tool (Peytavie et al. 2009, section 4): sand,
** rocks or water A g(|p - c| / R) thick (g the engine's falloff
** (1 - x^2)^3) on top of every stack within R of c, then, by default,
** stabilisation started from that region.
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/falloff.h"
#include "layers/layers.h"

int oc_stacks_deposit(oc_stacks *s, const oc_deposit_params *p, double *added,
                      oc_stabilize_result *res, oc_error *err) {
  if (added) *added = 0;
  if (res) *res = (oc_stabilize_result){0, 1, 0};
  if (!isfinite(p->cx) || !isfinite(p->cy))
    return oc_seterr(err, OC_EINVAL, "'center' must be finite");
  if (!(p->radius > 0) || !isfinite(p->radius))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)",
                     p->radius);
  if (!(p->amount >= 0) || !isfinite(p->amount))
    return oc_seterr(err, OC_EINVAL, "'amount' must be >= 0 (got %g)",
                     p->amount);
  int q = oc_seg_index(p->material);
  if (q < 0)
    return oc_seterr(
        err, OC_EINVAL, "'material' must be sand, rocks or water (got %s)",
        oc_material_name(p->material) ? oc_material_name(p->material)
                                      : "an unknown material");
  oc_stabilize_params sp;
  if (oc_layers_tool_stab(s, p->stab, p->stabilize, &sp, err)) return OC_EINVAL;
  /* the stacks whose centres may lie within R */
  double c = s->cell;
  double fi0 = ceil((p->cx - p->radius - s->x0) / c);
  double fi1 = floor((p->cx + p->radius - s->x0) / c);
  double fj0 = ceil((p->cy - p->radius - s->y0) / c);
  double fj1 = floor((p->cy + p->radius - s->y0) / c);
  fi0 = fmax(fi0, 0), fj0 = fmax(fj0, 0);
  fi1 = fmin(fi1, s->nx - 1), fj1 = fmin(fj1, s->ny - 1);
  if (fi0 > fi1 || fj0 > fj1 || p->amount == 0) return OC_OK;
  /* the stacks of the footprint, edited as a grid of their own */
  int i0 = (int)fi0, j0 = (int)fj0, i1 = (int)fi1, j1 = (int)fj1;
  oc_stacks *w = oc_stacks_window(s, i0, j0, i1, j1, err);
  if (!w) return OC_ENOMEM;
  oc_lseg *seg;
  size_t *soff;
  int rc = oc_layers_decode_all(w, &seg, &soff, err);
  double vol = 0;
  if (!rc) {
    for (int j = j0; j <= j1; j++)
      for (int i = i0; i <= i1; i++) {
        double dx = s->x0 + i * c - p->cx, dy = s->y0 + j * c - p->cy;
        double t = p->amount * oc_falloff(sqrt(dx * dx + dy * dy) / p->radius);
        if (!(t > 0)) continue;
        size_t k = (size_t)(j - j0) * w->nx + (i - i0);
        seg[soff[k + 1] - 1].a[q] += t; /* the top segment: the sky's */
        vol += t;
      }
    rc = oc_layers_encode_all(w, seg, soff, err);
    free(seg);
    free(soff);
  }
  if (!rc) rc = oc_stacks_splice(s, w, i0, j0, err);
  oc_stacks_free(w);
  if (!rc && p->stabilize) {
    sp.region[0] = i0;
    sp.region[1] = j0;
    sp.region[2] = i1;
    sp.region[3] = j1;
    rc = oc_layers_stabilize_local(s, &sp, res, err);
  }
  if (!rc && added) *added = vol * c * c;
  return rc;
}
