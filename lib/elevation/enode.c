/*
** enode.c — elevation-tree nodes: allocation, reference counting,
** evaluation and bounds dispatch, statistics, and the elevation source
** through which a tree is a terrain like a grid (oc_terrain, heightfield
** sampling, rendering).
*/
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/grow.h"
#include "core/pmap.h"
#include "elevation/enode.h"

static const char *const kind_names[OC_E_COUNT] = {
    "disc", "curve", "blend", "replace", "add", "transform", "warp",
    "lake", "image", "lod"};

/* 1 + the parameters each kind stores (disc.c, ecurve.c, eops.c); 0, a
** kind not listed: OC_ENODE_NPAR. */
static const unsigned char par_counts[OC_E_COUNT] = {
    [OC_E_DISC] = 1 + 4,    [OC_E_CURVE] = 1 + 2, [OC_E_BLEND] = 1 + 0,
    [OC_E_REPLACE] = 1 + 1, [OC_E_ADD] = 1 + 7,   [OC_E_XFORM] = 1 + 11,
    [OC_E_WARP] = 1 + 2,    [OC_E_LOD] = 1 + 3};

static size_t par_count(oc_ekind kind) {
  unsigned c = (unsigned)kind < OC_E_COUNT ? par_counts[kind] : 0;
  return c ? c - 1 : OC_ENODE_NPAR;
}

size_t oc_enode_size(const oc_enode *n) {
  return offsetof(oc_enode, par) + par_count(n->kind) * sizeof(double) +
         (n->kids != n->inl ? n->nkids * sizeof *n->kids : 0);
}

oc_enode *oc_enode_alloc(oc_ekind kind, oc_enode *const *kids, size_t nkids,
                         oc_error *err) {
  oc_enode *n =
      calloc(1, offsetof(oc_enode, par) + par_count(kind) * sizeof(double));
  if (!n) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  n->refs = 1;
  n->kind = kind;
  if (nkids <= 2) {
    n->kids = n->inl;
  } else if (nkids > SIZE_MAX / sizeof *n->kids ||
             !(n->kids = malloc(nkids * sizeof *n->kids))) {
    free(n);
    oc_seterr(err, OC_ENOMEM, "out of memory (%zu children)", nkids);
    return NULL;
  }
  n->nkids = nkids;
  for (size_t i = 0; i < nkids; i++) {
    n->kids[i] = kids[i];
    oc_enode_retain(kids[i]);
  }
  return n;
}

void oc_enode_retain(oc_enode *e) {
  if (e) e->refs++;
}

/* Iterative, so that deep chains do not overflow the C stack. */
void oc_enode_release(oc_enode *e) {
  if (!e || --e->refs > 0) return;
  oc_enode **stack = NULL;
  size_t top = 0, cap = 0;
  for (oc_enode *cur = e;;) {
    for (size_t i = 0; i < cur->nkids; i++) {
      oc_enode *k = cur->kids[i];
      if (--k->refs > 0) continue;
      if (!OC_GROW(stack, top, cap, 1)) { /* no memory: recurse for it */
        k->refs = 1;
        oc_enode_release(k);
        continue;
      }
      stack[top++] = k;
    }
    if (cur->kids != cur->inl) free(cur->kids);
    if (cur->kind == OC_E_CURVE) oc_ecurve_free(cur->data);
    if (cur->kind == OC_E_LAKE) oc_elake_free(cur->data);
    if (cur->kind == OC_E_IMAGE) oc_eimage_free(cur->data);
    free(cur);
    if (!top) break;
    cur = stack[--top];
  }
  free(stack);
}

const char *oc_enode_kind(const oc_enode *e) {
  return e && (unsigned)e->kind < OC_E_COUNT ? kind_names[e->kind] : "?";
}

void oc_enode_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s) {
  if (n->kind == OC_E_DISC)
    oc_edisc_ev(n, x, y, ft, want, s);
  else if (n->kind == OC_E_CURVE)
    oc_ecurve_ev(n, x, y, ft, want, s);
  else if (n->kind == OC_E_LAKE)
    oc_elake_ev(n, x, y, ft, want, s);
  else if (n->kind == OC_E_IMAGE)
    oc_eimage_ev(n, x, y, ft, want, s);
  else if (n->kind == OC_E_LOD)
    oc_elod_ev(n, x, y, ft, want, s);
  else
    oc_eop_ev(n, x, y, ft, want, s);
}

void oc_enode_bnd(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                  oc_ebound *o) {
  if (n->kind == OC_E_DISC)
    oc_edisc_bound_in(n, b, fb, o);
  else if (n->kind == OC_E_CURVE)
    oc_ecurve_bound_in(n, b, fb, o);
  else if (n->kind == OC_E_LAKE)
    oc_elake_bound_in(n, b, fb, o);
  else if (n->kind == OC_E_IMAGE)
    oc_eimage_bound_in(n, b, fb, o);
  else if (n->kind == OC_E_LOD)
    oc_elod_bound_in(n, b, fb, o);
  else
    oc_eop_bound_in(n, b, fb, o);
}

/* ---- public queries --------------------------------------------------- */

void oc_enode_eval(const oc_enode *e, double x, double y, oc_enode_sample *s) {
  if (!isfinite(x) || !isfinite(y)) {
    s->f = s->a = s->fx = s->fy = s->ax = s->ay = NAN;
    return;
  }
  oc_enode_ev(e, x, y, NULL, OC_EV_GRAD, s);
}

double oc_enode_weight(const oc_enode *e, double x, double y) {
  if (!isfinite(x) || !isfinite(y)) return NAN;
  oc_enode_sample s;
  oc_enode_ev(e, x, y, NULL, OC_EV_ALPHA, &s);
  return s.a;
}

void oc_enode_get_bounds(const oc_enode *e, double box[4], double *flo,
                         double *fhi) {
  if (box) {
    box[0] = e->box.x0;
    box[1] = e->box.y0;
    box[2] = e->box.x1;
    box[3] = e->box.y1;
  }
  if (flo) *flo = e->glob.flo;
  if (fhi) *fhi = e->glob.fhi;
}

double oc_enode_lipschitz(const oc_enode *e) {
  return e->glob.lf;
}

void oc_enode_bound_in(const oc_enode *e, double x0, double y0, double x1,
                       double y1, oc_enode_bound *b) {
  oc_erect r = {x0, y0, x1, y1};
  if (!(x0 <= x1 && y0 <= y1)) { /* empty (or NaN): nothing there */
    *b = (oc_enode_bound){0, 0, 0, 0, 0, 0};
    b->flo = INFINITY, b->fhi = -INFINITY;
    return;
  }
  oc_enode_bnd(e, &r, NULL, b);
}

int oc_enode_get_stats(const oc_enode *e, oc_enode_stats *st, oc_error *err) {
  oc_pmap seen = {0};
  const oc_enode **stack = NULL;
  size_t n = 0, cap = 0;
  int rc = OC_OK;
  memset(st, 0, sizeof *st);
  if (!oc_pmap_slot(&seen, e, 1) || !OC_GROW(stack, n, cap, 1)) goto nomem;
  stack[n++] = e;
  while (n) {
    const oc_enode *x = stack[--n];
    st->nodes++;
    st->primitives += x->kind == OC_E_DISC || x->kind == OC_E_CURVE ||
                      x->kind == OC_E_LAKE || x->kind == OC_E_IMAGE;
    st->bytes += oc_enode_size(x);
    for (size_t i = 0; i < x->nkids; i++) {
      const oc_enode *k = x->kids[i];
      if (oc_pmap_slot(&seen, k, 0)) continue;
      if (!oc_pmap_slot(&seen, k, 1) || !OC_GROW(stack, n, cap, 1)) goto nomem;
      stack[n++] = k;
    }
  }
  goto done;
nomem:
  rc = oc_seterr(err, OC_ENOMEM, "out of memory while counting the tree");
done:
  oc_pmap_free(&seen);
  free(stack);
  return rc;
}

/* ---- where the terrain is --------------------------------------------- */

/* Grows *acc by the parts of r where alpha may reach T, splitting r in four
** down to depth 0. */
static void terrain_cells(const oc_enode *e, const oc_eview *v, oc_erect r,
                          int depth, oc_erect *acc) {
  oc_ebound b;
  oc_efootb fb;
  if (v) oc_eview_footb(v, &r, &fb);
  oc_enode_bnd(e, &r, v ? &fb : NULL, &b);
  if (!(b.ahi >= OC_ENODE_T)) return;
  if (depth == 0 || b.alo >= OC_ENODE_T) {
    acc->x0 = fmin(acc->x0, r.x0);
    acc->y0 = fmin(acc->y0, r.y0);
    acc->x1 = fmax(acc->x1, r.x1);
    acc->y1 = fmax(acc->y1, r.y1);
    return;
  }
  double mx = (r.x0 + r.x1) / 2, my = (r.y0 + r.y1) / 2;
  oc_erect q[4] = {{r.x0, r.y0, mx, my},
                   {mx, r.y0, r.x1, my},
                   {r.x0, my, mx, r.y1},
                   {mx, my, r.x1, r.y1}};
  for (int k = 0; k < 4; k++)
    terrain_cells(e, v, q[k], depth - 1, acc);
}

int oc_enode_terrain_box_in(const oc_enode *e, const oc_eview *v,
                            double box[4]) {
  oc_erect acc = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  terrain_cells(e, v, e->box, 7, &acc);
  if (!(acc.x0 < acc.x1 && acc.y0 < acc.y1)) return 0;
  box[0] = acc.x0, box[1] = acc.y0, box[2] = acc.x1, box[3] = acc.y1;
  return 1;
}

int oc_enode_terrain_box(const oc_enode *e, double box[4]) {
  return oc_enode_terrain_box_in(e, NULL, box);
}

/* ---- the elevation source --------------------------------------------- */

static double src_height(void *ud, double x, double y, double grad[2]) {
  oc_enode_sample s;
  oc_enode_ev(ud, x, y, NULL, grad ? OC_EV_GRAD : 0, &s);
  if (grad) {
    grad[0] = s.fx;
    grad[1] = s.fy;
  }
  return s.f;
}

static void src_range(void *ud, double x0, double y0, double x1, double y1,
                      double *lo, double *hi) {
  oc_ebound b;
  oc_erect r = {x0, y0, x1, y1};
  oc_enode_bnd(ud, &r, NULL, &b);
  *lo = b.flo;
  *hi = b.fhi;
}

static double src_slope(void *ud, double x0, double y0, double x1, double y1) {
  oc_ebound b;
  oc_erect r = {x0, y0, x1, y1};
  oc_enode_bnd(ud, &r, NULL, &b);
  return b.lf;
}

static double src_height_weight(void *ud, double x, double y, double grad[2],
                                double *alpha, double agrad[2]) {
  oc_enode_sample s;
  oc_enode_ev(ud, x, y, NULL, grad || agrad ? OC_EV_GRAD : 0, &s);
  if (grad) grad[0] = s.fx, grad[1] = s.fy;
  if (agrad) agrad[0] = s.ax, agrad[1] = s.ay;
  *alpha = s.a;
  return s.f;
}

static void src_weight_range(void *ud, double x0, double y0, double x1,
                             double y1, double *alo, double *ahi,
                             double *alip) {
  oc_ebound b;
  oc_erect r = {x0, y0, x1, y1};
  oc_enode_bnd(ud, &r, NULL, &b);
  *alo = b.alo;
  *ahi = b.ahi;
  *alip = b.la;
}

static void src_bound(void *ud, double x0, double y0, double x1, double y1,
                      double *lo, double *hi, double *slope) {
  oc_ebound b;
  oc_erect r = {x0, y0, x1, y1};
  oc_enode_bnd(ud, &r, NULL, &b);
  *lo = b.flo;
  *hi = b.fhi;
  *slope = b.lf;
}

static void src_retain(void *ud) {
  oc_enode_retain(ud);
}
static void src_release(void *ud) {
  oc_enode_release(ud);
}

int oc_enode_domain(const oc_enode *e, const oc_eview *v, const double *domain,
                    double d[4], oc_error *err) {
  if (domain)
    memcpy(d, domain, 4 * sizeof *d);
  else if (!oc_enode_terrain_box_in(e, v, d))
    return oc_seterr(err, OC_EINVAL,
                     "the tree has no terrain (its weight never reaches "
                     "1/2): add a base primitive that covers the scene");
  if (!(isfinite(d[0]) && isfinite(d[1]) && isfinite(d[2]) && isfinite(d[3]) &&
        d[0] < d[2] && d[1] < d[3]))
    return oc_seterr(err, OC_EINVAL,
                     "the elevation domain [%g, %g] x [%g, %g] must be "
                     "finite and not empty",
                     d[0], d[2], d[1], d[3]);
  return OC_OK;
}

int oc_enode_elevation(oc_enode *e, const double *domain, oc_elevation *src,
                       oc_error *err) {
  double d[4];
  int rc = oc_enode_domain(e, NULL, domain, d, err);
  if (rc) return rc;
  memset(src, 0, sizeof *src);
  src->height = src_height;
  src->range = src_range;
  src->slope = src_slope;
  src->bound = src_bound;
  src->retain = src_retain;
  src->release = src_release;
  src->height_weight = src_height_weight; /* Omega_T: where alpha >= 1/2 */
  src->weight_range = src_weight_range;
  src->ud = e;
  src->x0 = d[0];
  src->y0 = d[1];
  src->x1 = d[2];
  src->y1 = d[3];
  oc_enode_retain(e);
  return OC_OK;
}
