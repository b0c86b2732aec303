/*
** block.c — the block node kind (Paris et al. 2020, section 4.2): the
** smooth intersection of a convex hull's half-spaces, in metres, made a
** field of the engine's convention.
**
** Distance: h_k(p) = n_k . p + o_k (negative inside), folded in the hull's
** facet order: d = h_1, then d <- max(d, h_k) + R c^3 / 6 with
** c = max(1 - |d - h_k| / R, 0). (The paper prints "- R c^3 / 6", which
** rounds the hull's edges outwards into a fillet of the wrong side; "+"
** cuts them round.) A plane with h_k <= d - R changes nothing and is
** skipped at no cost. The gradient of one step is the weighted sum
** (1 - c^2/2) grad(larger) + (c^2/2) grad(smaller): weights >= 0 summing
** to 1, so |grad d| <= 1 and d is 1-Lipschitz. R is the tile's rounding
** but at most half the block's thickness, so a thin block keeps its
** surface and its gradient vanishes only at its middle, deep inside.
**
** Field: f = sigma(-d), sigma the cubic of the terrain primitive (Paris
** et al. 2019, section 5.1): sigma(0) = T, sigma(v) = 2T for v >= W, 0 for
** v <= -W, slope 1 at 0 (W <= 3T). So f = T on the rounded hull, f > T
** inside, and f = 0 where d >= W. d is then raised to the largest signed
** distance to the faces of the hull's box (a plain max, which changes
** nothing inside the rounded hull): f = 0 outside the box grown by W (the
** support), also near sharp corners, where the planes' distances fall
** short of the true distance. Lipschitz bound: sigma's largest slope.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "core/sigma.h"
#include "core/error.h"
#include "field/kind.h"

struct oc_bfield {
  size_t n;
  double R, W;
  oc_aabb box; /* of the hull */
  double pl[]; /* 4 per plane */
};
typedef oc_bfield bdata;

enum {
  P_DS = OC_SIG_DS,
  P_N = OC_SIG_N
}; /* the compiled op holds sigma's parameters */

/* ---- the distance -------------------------------------------------------- */

double oc_bfield_dist(const oc_bfield *b, oc_vec3 p, oc_vec3 *g) {
  const double *h = b->pl;
  double R = b->R;
  double d = h[0] * p.x + h[1] * p.y + h[2] * p.z + h[3];
  oc_vec3 gd = {h[0], h[1], h[2]};
  for (size_t k = 1; k < b->n; k++) {
    h = b->pl + 4 * k;
    double e = h[0] * p.x + h[1] * p.y + h[2] * p.z + h[3];
    double diff = d - e;
    if (diff >= R) continue; /* cannot matter */
    if (diff <= -R) {
      d = e;
      gd = (oc_vec3){h[0], h[1], h[2]};
      continue;
    }
    double c = 1 - fabs(diff) / R, w = 0.5 * c * c;
    /* weights of the larger and the smaller */
    double wd = diff >= 0 ? 1 - w : w, we = 1 - wd;
    d = fmax(d, e) + R * c * c * c / 6;
    gd = (oc_vec3){wd * gd.x + we * h[0], wd * gd.y + we * h[1],
                   wd * gd.z + we * h[2]};
  }
  /* the box's faces, by a plain max: inside the rounded hull none of them
  ** is above d (a ray along an axis leaves the hull through a face before
  ** it leaves the box), so the block is unchanged; outside, they make
  ** d >= W beyond the box grown by W (the support), which the hull's
  ** planes alone do not near sharp corners */
  const oc_aabb *x = &b->box;
  double e[6] = {p.x - x->hi.x, x->lo.x - p.x, p.y - x->hi.y,
                 x->lo.y - p.y, p.z - x->hi.z, x->lo.z - p.z};
  for (int a = 0; a < 6; a++)
    if (e[a] > d) {
      d = e[a];
      double s = a & 1 ? -1 : 1;
      gd =
          (oc_vec3){a / 2 == 0 ? s : 0, a / 2 == 1 ? s : 0, a / 2 == 2 ? s : 0};
    }
  if (g) *g = gd;
  return d;
}

/* ---- the kind --------------------------------------------------------------
 */

static int block_compile(oc_kcompile *c, oc_error *err) {
  const bdata *b = c->data;
  (void)err;
  oc_sigma_params(c->T, b->W, c->par);
  c->npar = P_N;
  c->info.lo = 0;
  c->info.hi = 2 * c->T;
  c->info.lip = c->par[P_DS];
  c->info.box = oc_bfield_support(b);
  return OC_OK;
}

static double block_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  return oc_bfield_eval(k->data, k->par, p, g);
}

/* 0 all over the box when some plane is W or more away over all of it. */
static int block_zero_in(const oc_kctx *k, const oc_aabb *box) {
  const bdata *b = k->data;
  double cx = 0.5 * (box->lo.x + box->hi.x), cy = 0.5 * (box->lo.y + box->hi.y),
         cz = 0.5 * (box->lo.z + box->hi.z);
  double ex = 0.5 * (box->hi.x - box->lo.x), ey = 0.5 * (box->hi.y - box->lo.y),
         ez = 0.5 * (box->hi.z - box->lo.z);
  for (size_t i = 0; i < b->n; i++) {
    const double *h = b->pl + 4 * i;
    double lo = h[0] * cx + h[1] * cy + h[2] * cz + h[3] -
                (fabs(h[0]) * ex + fabs(h[1]) * ey + fabs(h[2]) * ez);
    if (lo >= b->W) return 1;
  }
  return 0;
}

static void block_release(void *data) {
  free(data);
}

static const oc_kind_def block_kind = {
    .name = "block",
    .flags = OC_KF_PRIM,
    .compile = block_compile,
    .eval = block_eval,
    .zero_in = block_zero_in,
    .release = block_release,
};

oc_bfield *oc_bfield_new(const oc_bblock *src, double R, double W) {
  bdata *b = malloc(sizeof *b + 4 * src->nplane * sizeof(double));
  if (!b) return NULL;
  b->n = src->nplane;
  b->R = fmin(R, 0.5 * src->thickness);
  b->W = W;
  b->box = src->box;
  memcpy(b->pl, src->plane, 4 * src->nplane * sizeof(double));
  return b;
}

oc_aabb oc_bfield_support(const oc_bfield *b) {
  double W = b->W;
  return (oc_aabb){{b->box.lo.x - W, b->box.lo.y - W, b->box.lo.z - W},
                   {b->box.hi.x + W, b->box.hi.y + W, b->box.hi.z + W}};
}

size_t oc_bfield_bytes(const oc_bfield *b) {
  return sizeof *b + 4 * b->n * sizeof(double);
}

double oc_bfield_width(const oc_bfield *b) {
  return b->W;
}

double oc_bfield_eval(const oc_bfield *b, const double *sp, oc_vec3 p,
                      oc_vec3 *g) {
  oc_vec3 gd;
  double ds, d = oc_bfield_dist(b, p, g ? &gd : NULL);
  double f = oc_sigma(sp, -d, &ds);
  if (g) *g = (oc_vec3){-ds * gd.x, -ds * gd.y, -ds * gd.z};
  return f;
}

void oc_bfield_sigma(double T, double W, double sp[OC_BSIGMA_N]) {
  oc_sigma_params(T, W, sp);
}

oc_node *oc_bblock_node(const oc_bblock *src, double R, double W,
                        oc_error *err) {
  bdata *b = oc_bfield_new(src, R, W);
  if (!b) {
    oc_seterr(err, OC_ENOMEM, "out of memory for a block");
    return NULL;
  }
  return oc_kind_node(&block_kind, NULL, 0, NULL, 0, b, err);
}
