/*
** hfsurf.c — the surface of a heightfield-like op as an elevation: what
** direct elevation extraction reads instead of evaluating the program.
**
** Extension kinds (a terrain) describe theirs through their surface hook
** (kind.h): for a terrain, f = min(sigma(+-(h - z)), f_P(z)) where the
** mesher uses it, so the surface is z = h (sigma(0) = T) plus the prism's
** flat cap. Plane:
** f = E g(max(0, d) / R), d = (p - o).n, so f = T at d = R x*,
** g(x*) = T / E, which is the elevation e(x, y) = oz + (R x* - nx (x - ox)
** - ny (y - oy)) / nz, and d = R x* + nz (z - e) along the column.
*/
#include <math.h>

#include "core/falloff.h"
#include "field/hfsurf.h"

int oc_hfsurf_candidate(const oc_program *P, uint32_t op) {
  const oc_op *o = &P->ops[op];
  if (o->kind == OC_K_EXT)
    return (P->ext[o->ext].def->flags & OC_KF_HFLIKE) != 0;
  return (oc_kind_flags((oc_kind)o->kind) & OC_KF_HFLIKE) != 0;
}

int oc_hfsurf_init(oc_hfsurf *s, const oc_program *P, uint32_t op, double T) {
  const oc_op *o = &P->ops[op];
  s->op = op;
  s->par = P->par + o->par;
  s->ext = 0;
  s->direct = 0;
  s->cap = NAN;
  if (o->kind == OC_K_EXT) {
    const oc_pext *x = &P->ext[o->ext];
    if (!(x->def->flags & OC_KF_HFLIKE) || !x->def->surface) return 0;
    s->ext = 1;
    s->direct = (x->def->flags & OC_KF_DIRECT) != 0;
    s->k = (oc_kctx){s->par, x->data, P->T, o->lip, P, op, 0};
    if (!x->def->surface(&s->k, T, &s->ks)) return 0;
    s->up = s->ks.up;
    s->cap = s->ks.cap;
    return 1;
  }
  if (o->kind != OC_K_PLANE) return 0;
  double E = s->par[OC_P_E], R = s->par[OC_P_R], nz = s->par[OC_P_N + 2];
  if (!(T > 0 && T < E) || fabs(nz) < 1e-6) return 0;
  s->ds = R * sqrt(1 - cbrt(T / E));
  s->up = nz > 0 ? 1 : -1;
  return 1;
}

double oc_hfsurf_height(const oc_hfsurf *s, double x, double y,
                        double grad[2]) {
  if (s->ext) return s->ks.height(s->ks.ud, x, y, grad);
  const double *p = s->par;
  double nx = p[OC_P_N], ny = p[OC_P_N + 1], nz = p[OC_P_N + 2];
  if (grad) {
    grad[0] = -nx / nz;
    grad[1] = -ny / nz;
  }
  return p[OC_P_O + 2] +
         (s->ds - nx * (x - p[OC_P_O]) - ny * (y - p[OC_P_O + 1])) / nz;
}

double oc_hfsurf_value(const oc_hfsurf *s, double e, double z) {
  if (s->ext) return s->ks.value(&s->k, e, z);
  const double *p = s->par;
  double d = s->ds + p[OC_P_N + 2] * (z - e);
  return p[OC_P_E] * oc_falloff(fmax(0, d) / p[OC_P_R]);
}

double oc_hfsurf_vertical(const oc_hfsurf *s, double e, double za, double zb,
                          int *cap) {
  *cap = 0;
  if (e >= za && e <= zb) return e;
  if (s->cap >= za && s->cap <= zb) { /* (false for NAN) */
    *cap = 1;
    return s->cap;
  }
  return e < za ? za : zb; /* rounding: the nearer end */
}

int oc_hfsurf_level_spans(const oc_hfsurf *s, double x0, double y0, double x1,
                          double y1, oc_zspan out[2]) {
  double lo, hi;
  if (s->ext) {
    s->ks.range(s->ks.ud, x0, y0, x1, y1, &lo, &hi);
  } else { /* a plane: its elevation is affine, extreme at the corners */
    double e[4] = {
        oc_hfsurf_height(s, x0, y0, NULL), oc_hfsurf_height(s, x1, y0, NULL),
        oc_hfsurf_height(s, x0, y1, NULL), oc_hfsurf_height(s, x1, y1, NULL)};
    lo = hi = e[0];
    for (int k = 1; k < 4; k++) {
      lo = fmin(lo, e[k]);
      hi = fmax(hi, e[k]);
    }
  }
  return oc_hfsurf_elev_spans(s, lo, hi, out);
}

int oc_hfsurf_elev_spans(const oc_hfsurf *s, double lo, double hi,
                         oc_zspan out[2]) {
  /* rounding of the elevation and of the range: far below a cell */
  double m = 1e-9 * (fabs(lo) + fabs(hi) + 1);
  oc_zspan a = {lo - m, hi + m};
  if (isnan(s->cap)) {
    out[0] = a;
    return 1;
  }
  oc_zspan c = {s->cap - m - 1e-9 * fabs(s->cap),
                s->cap + m + 1e-9 * fabs(s->cap)};
  if (c.hi < a.lo) {
    out[0] = c, out[1] = a;
    return 2;
  }
  if (c.lo > a.hi) {
    out[0] = a, out[1] = c;
    return 2;
  }
  out[0] = (oc_zspan){fmin(a.lo, c.lo), fmax(a.hi, c.hi)};
  return 1;
}
