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

static const oc_kind_def erosion_kind;

oc_node *oc_erosion(oc_node *terrain, oc_node *geology, oc_node *control,
                    double depth, oc_error *err) {
  if (!terrain || !geology) {
    oc_seterr(err, OC_EINVAL, "erosion needs a terrain and a geology node");
    return NULL;
  }
  if (!oc_check_positive(depth, "depth", err)) return NULL;
  oc_node *kids[3] = {terrain, geology, control};
  double par[2] = {depth, control ? 1 : 0};
  return oc_kind_node(&erosion_kind, kids, control ? 3 : 2, par, 2, NULL, err);
}

static int erosion_compile(oc_kcompile *c, oc_error *err) {
  const oc_kinfo *f = &c->kid[0], *rho = &c->kid[1];
  double depth = c->node_par[OC_GP_DEPTH];
  (void)err;
  c->par[OC_GP_DEPTH] = depth;
  c->par[OC_GP_HASCTL] = c->node_par[OC_GP_HASCTL];
  c->npar = 2;
  double lctl = c->nkids > 2 ? c->kid[2].lip : 0;
  c->info.box = f->box;
  c->info.lo = fmin(f->lo, 0);
  c->info.hi = f->hi;
  /* max(h, m) is max(L_h, L_m)-Lipschitz; L_m = L_f <= L_h, and
  ** |grad (f_D (1 - rho^))| <= depth (L_control + L_rho) */
  c->info.lip = f->lip + depth * (lctl + rho->lip);
  return OC_OK;
}

/* clamp(v, 0, 1), zeroing the gradient where the clamp is active; NaN
** stays NaN. */
static double unit_clamp(double v, oc_vec3 *g) {
  if ((v > 0 && v < 1) || v != v) return v;
  if (g) *g = oc_v3(0, 0, 0);
  return v >= 1 ? 1 : 0;
}

static double erosion_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const double *par = k->par;
  double f = oc_child_eval(k, 0, p, g);
  /* no rock, nothing to erode (and the cheap common case: air) */
  if (!(f > 0)) return f;
  oc_vec3 gw = oc_v3(0, 0, 0), gr = oc_v3(0, 0, 0);
  double w = 1;
  if (par[OC_GP_HASCTL] != 0) {
    w = unit_clamp(oc_child_eval(k, 2, p, g ? &gw : NULL), g ? &gw : NULL);
    if (w == 0) return f;
  }
  double rho =
      unit_clamp(oc_child_eval(k, 1, p, g ? &gr : NULL), g ? &gr : NULL);
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

/* f~ = f wherever f_D = 0 (outside the control's support) or f = 0
** (outside the terrain's). */
static int erosion_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  oc_aabb b = oc_child_box(k, 0);
  if (k->par[OC_GP_HASCTL] != 0) { /* (as is: an empty x or y range too) */
    oc_aabb c = oc_child_box(k, 2);
    b.lo = oc_vmax(b.lo, c.lo);
    b.hi = oc_vmin(b.hi, c.hi);
  }
  if (b.lo.z <= b.hi.z && b.lo.x <= f->x1 && b.hi.x >= f->x0 &&
      b.lo.y <= f->y1 && b.hi.y >= f->y0) {
    if (isinf(b.lo.z) || isinf(b.hi.z)) {
      oc_col_whole(q);
      return 0;
    }
    oc_col_add(q, b.lo.z, b.hi.z);
  }
  oc_child_spans(k, 0, f, q);
  return 0;
}

static double erosion_lip_in(const oc_kctx *k, const oc_aabb *b) {
  /* where f <= 0 the erosion is f itself: 0 where f's support misses the
  ** box (as between islands under one erosion) */
  if (oc_child_zero_in(k, 0, b)) return 0;
  /* L_f, plus depth (L_control + L_rho) where f_D may be non-zero */
  double L = oc_child_lipschitz_in(k, 0, b);
  int hasctl = k->par[OC_GP_HASCTL] != 0;
  if (hasctl) {
    oc_aabb c = oc_child_box(k, 2);
    if (!(c.lo.x <= b->hi.x && c.hi.x >= b->lo.x && c.lo.y <= b->hi.y &&
          c.hi.y >= b->lo.y && c.lo.z <= b->hi.z && c.hi.z >= b->lo.z))
      return L;
  }
  double e = oc_child_lipschitz_in(k, 1, b);
  if (hasctl) e += oc_child_lipschitz_in(k, 2, b);
  return fmin(L + k->par[OC_GP_DEPTH] * e, k->lip);
}

static const oc_kind_def erosion_kind = {
    .name = "erosion",
    .compile = erosion_compile,
    .eval = erosion_eval,
    .lipschitz_in = erosion_lip_in,
    .column = erosion_column,
};
