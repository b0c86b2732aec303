/*
** erode.c — the erosion tool (Peytavie et al. 2009, section 4): bedrock
** turned into sand and rocks by the ratio rho, volume conserved, either
** at the surface (the top of each stack's highest bedrock) or by the
** collapse of thin roofs over caves, whose debris the canonical sorting
** drops to the floor below; then stabilisation from the region.
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "layers/layers.h"

/* Turns bedrock layer l of stack k's decoded layers into debris: d of
** its thickness, from its top. */
static void debris(oc_layer *l, size_t *n, size_t at, double d, double rho) {
  for (size_t q = *n; q > at + 1; q--)
    l[q + 1] = l[q - 1];
  l[at].t -= d;
  l[at + 1] = (oc_layer){rho * d, OC_MAT_SAND};
  l[at + 2] = (oc_layer){(1 - rho) * d, OC_MAT_ROCKS};
  *n += 2;
}

int oc_stacks_erode(oc_stacks *s, const oc_stacks_erode_params *p,
                    double *eroded, oc_stabilize_result *res, oc_error *err) {
  if (eroded) *eroded = 0;
  if (res) *res = (oc_stabilize_result){0, 1, 0};
  if (!isfinite(p->x0) || !isfinite(p->y0) || !isfinite(p->x1) ||
      !isfinite(p->y1) || !(p->x0 <= p->x1 && p->y0 <= p->y1))
    return oc_seterr(err, OC_EINVAL,
                     "'region' must be {x0, y0, x1, y1} with x0 <= x1 and "
                     "y0 <= y1");
  if (!(p->ratio >= 0 && p->ratio <= 1))
    return oc_seterr(err, OC_EINVAL, "'ratio' must be in [0, 1] (got %g)",
                     p->ratio);
  if (!(p->depth > 0) || isnan(p->depth))
    return oc_seterr(err, OC_EINVAL, "'depth' must be > 0 (got %g)", p->depth);
  if (p->mode != OC_STACKS_ERODE_SURFACE && p->mode != OC_STACKS_ERODE_COLLAPSE)
    return oc_seterr(err, OC_EINVAL, "'mode' must be surface or collapse");
  oc_stabilize_params sp;
  if (oc_layers_tool_stab(s, p->stab, p->stabilize, &sp, err)) return OC_EINVAL;
  double c = s->cell;
  double i0 = fmax(ceil((p->x0 - s->x0) / c), 0);
  double i1 = fmin(floor((p->x1 - s->x0) / c), s->nx - 1);
  double j0 = fmax(ceil((p->y0 - s->y0) / c), 0);
  double j1 = fmin(floor((p->y1 - s->y0) / c), s->ny - 1);
  if (i0 > i1 || j0 > j1) return OC_OK;
  oc_stacks *w = oc_stacks_window(s, (int)i0, (int)j0, (int)i1, (int)j1, err);
  if (!w) return OC_ENOMEM;
  size_t ns = (size_t)w->nx * w->ny, most = 0;
  for (size_t k = 0; k < ns; k++)
    if (oc_scount(w, k) > most) most = oc_scount(w, k);
  /* each bedrock layer may gain 2 debris layers */
  oc_layer *l = malloc((3 * most + 3) * 2 * sizeof *l);
  oc_stacks_builder b;
  int rc = l ? oc_builder_init(&b, ns, oc_soff(w, ns) + ns, err)
             : oc_seterr(err, OC_ENOMEM, "out of memory");
  double vol = 0;
  for (size_t k = 0; k < ns && rc == OC_OK; k++) {
    oc_layer *out = l + 3 * most + 3;
    size_t n = 0;
    for (size_t q = oc_soff(w, k), qend = q + oc_scount(w, k); q < qend; q++)
      l[n++] = (oc_layer){oc_lay_t(w->lay[q]), oc_lay_m(w->lay[q])};
    if (p->mode == OC_STACKS_ERODE_SURFACE) {
      for (size_t q = n; q-- > 0;)
        if (l[q].m == OC_MAT_BEDROCK) {
          double d = fmin(p->depth, l[q].t);
          debris(l, &n, q, d, p->ratio);
          vol += d;
          break;
        }
    } else {
      for (size_t q = n; q-- > 1;)
        if (l[q].m == OC_MAT_BEDROCK && l[q - 1].m == OC_MAT_AIR &&
            l[q].t <= p->depth) {
          vol += l[q].t;
          debris(l, &n, q, l[q].t, p->ratio);
        }
    }
    rc = oc_builder_push(&b, out, oc_layers_canon(l, n, out), err);
  }
  if (rc == OC_OK)
    oc_builder_commit(&b, w);
  else if (l)
    oc_builder_free(&b);
  free(l);
  if (rc == OC_OK) rc = oc_stacks_splice(s, w, (int)i0, (int)j0, err);
  oc_stacks_free(w);
  if (rc) return rc;
  if (eroded) *eroded = vol * c * c;
  if (!p->stabilize || vol == 0) return OC_OK;
  sp.region[0] = (int)i0;
  sp.region[1] = (int)j0;
  sp.region[2] = (int)i1;
  sp.region[3] = (int)j1;
  return oc_layers_stabilize_local(s, &sp, res, err);
}
