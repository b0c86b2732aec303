/*
** erosion.c — the erosion node of Paris et al. 2019, section 6: a terrain's
** field
** lowered where the rock is soft, f~ = f - f_D (1 - rho), over the region
** a control field selects; stratified cliffs and overhangs without any
** primitive.
**
** Two choices the paper leaves open (docs/fields.md, "Erosion"): f_D is
** depth * clamp(control, 0, 1), and the result is floored at min(f, 0),
** so that erosion never makes negative (carving) values where there was
** no rock, and the node's support stays the terrain's.
*/
#include <math.h>

#include "core/error.h"
#include "core/vec.h"
#include "geology/geology.h"

oc_node *oc_erosion(oc_node *terrain, oc_node *geology, oc_node *control,
                    double depth, oc_error *err) {
  if (!terrain || !geology) {
    oc_seterr(err, OC_EINVAL, "erosion needs a terrain and a geology node");
    return NULL;
  }
  if (!oc_check_positive(depth, "depth", err)) return NULL;
  oc_node *kids[3] = {terrain, geology, control};
  oc_node *n = oc_node_alloc(OC_K_EROSION, kids, control ? 3 : 2, err);
  if (n) {
    n->par[OC_GP_DEPTH] = depth;
    n->par[OC_GP_HASCTL] = control ? 1 : 0;
  }
  return n;
}

size_t oc_erosion_compile(const oc_node *n, const oc_geo_info *kids,
                          double *par, oc_geo_info *out) {
  const oc_geo_info *f = &kids[0], *rho = &kids[1];
  double depth = n->par[OC_GP_DEPTH];
  par[OC_GP_DEPTH] = depth;
  par[OC_GP_HASCTL] = n->par[OC_GP_HASCTL];
  double lctl = n->nkids > 2 ? kids[2].lip : 0;
  out->box = f->box;
  out->lo = fmin(f->lo, 0);
  out->hi = f->hi;
  /* max(h, m) is max(L_h, L_m)-Lipschitz; L_m = L_f <= L_h, and
  ** |grad (f_D (1 - rho^))| <= depth (L_control + L_rho) */
  out->lip = f->lip + depth * (lctl + rho->lip);
  return 2;
}

/* clamp(v, 0, 1), zeroing the gradient where the clamp is active; NaN
** stays NaN. */
static double unit_clamp(double v, oc_vec3 *g) {
  if ((v > 0 && v < 1) || v != v) return v;
  if (g) *g = oc_v3(0, 0, 0);
  return v >= 1 ? 1 : 0;
}

double oc_erosion_eval(const oc_program *P, const oc_op *o, oc_vec3 p,
                       oc_vec3 *g, oc_geo_kid_fn kid) {
  const double *par = P->par + o->par;
  const uint32_t *k = P->kids + o->kid;
  double f = kid(P, k[0], p, g);
  /* no rock, nothing to erode (and the cheap common case: air) */
  if (!(f > 0)) return f;
  oc_vec3 gw = oc_v3(0, 0, 0), gr = oc_v3(0, 0, 0);
  double w = 1;
  if (par[OC_GP_HASCTL] != 0) {
    w = unit_clamp(kid(P, k[2], p, g ? &gw : NULL), g ? &gw : NULL);
    if (w == 0) return f;
  }
  double rho = unit_clamp(kid(P, k[1], p, g ? &gr : NULL), g ? &gr : NULL);
  double depth = par[OC_GP_DEPTH];
  double h = f - depth * w * (1 - rho);
  if (h != h) return h; /* NaN from the geology or control */
  if (h <= 0) {
    if (g) *g = oc_v3(0, 0, 0);
    return 0;
  }
  if (g) {
    /* grad h = grad f - depth ((1 - rho) grad w - w grad rho) */
    oc_vec3 d = oc_sub(oc_mul(gw, 1 - rho), oc_mul(gr, w));
    *g = oc_sub(*g, oc_mul(d, depth));
  }
  return h;
}
