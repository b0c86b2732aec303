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
#include "core/fround.h"
#include "core/grow.h"
#include "core/pmap.h"
#include "elevation/enode.h"

static const char *const kind_names[OC_E_COUNT] = {
    "disc",      "curve", "blend", "replace", "add",
    "transform", "warp",  "lake",  "image",   "lod"};

size_t oc_enode_size(const oc_enode *n) {
  switch (n->kind) {
  case OC_E_DISC:
    return oc_edisc_size(n->nzkind, n->flags);
  case OC_E_CURVE:
  case OC_E_LAKE:
  case OC_E_IMAGE:
    return sizeof(oc_eprim);
  case OC_E_BLEND:
    return offsetof(oc_eblend, kids) +
           OC_EBLEND(n)->nkids * sizeof(oc_enode *) +
           oc_eblend_grid_words(OC_EBLEND(n)->nkids, n->octaves) *
               sizeof(uint64_t);
  case OC_E_REPLACE:
    return offsetof(oc_ebin, par);
  case OC_E_ADD:
    return oc_eadd_size(n->flags);
  case OC_E_LOD:
    return offsetof(oc_ebin, par) + OC_ELOD_NPAR * sizeof(double);
  case OC_E_XFORM:
    return offsetof(oc_eun, par) + OC_EXFORM_NPAR * sizeof(double);
  case OC_E_WARP:
    return offsetof(oc_eun, par) + OC_EWARP_NPAR * sizeof(double);
  default:
    return sizeof(oc_enode);
  }
}

oc_enode *oc_enode_alloc(oc_ekind kind, size_t size, oc_enode *const *kids,
                         size_t nkids, oc_error *err) {
  oc_enode *n = size >= sizeof(oc_enode) ? calloc(1, size) : NULL;
  if (!n) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  n->refs = 1;
  n->kind = (uint8_t)kind;
  if (kind == OC_E_BLEND) ((oc_eblend *)n)->nkids = (uint32_t)nkids;
  oc_enode **k = (oc_enode **)oc_enode_kids(n);
  for (size_t i = 0; i < nkids; i++) {
    k[i] = kids[i];
    oc_enode_retain(kids[i]);
  }
  /* (a transform's, warp's, replace's or add's A is its first child) */
  int partial = OC_EPRIM_KIND(kind) != 0;
  if (kind == OC_E_XFORM || kind == OC_E_WARP || kind == OC_E_REPLACE ||
      kind == OC_E_ADD || kind == OC_E_LOD)
    partial = nkids > 0 && kids[0]->flags & OC_EF_PARTIAL;
  if (kind == OC_E_LOD && nkids > 1)
    partial = partial || kids[1]->flags & OC_EF_PARTIAL;
  n->flags = partial ? OC_EF_PARTIAL : 0;
  return n;
}

/* ---- floats rounded outward ------------------------------------------- */

float oc_efloat_down(double v) {
  return oc_float_down(v);
}

float oc_efloat_up(double v) {
  return oc_float_up(v);
}

void oc_erect_round(const oc_erect *r, oc_erectf *o) {
  o->x0 = oc_efloat_down(r->x0);
  o->y0 = oc_efloat_down(r->y0);
  o->x1 = oc_efloat_up(r->x1);
  o->y1 = oc_efloat_up(r->y1);
}

void oc_ebound_round(const oc_ebound *b, oc_eboundf *o) {
  o->flo = oc_efloat_down(b->flo);
  o->fhi = oc_efloat_up(b->fhi);
  o->alo = oc_efloat_down(b->alo);
  o->ahi = oc_efloat_up(b->ahi);
  o->lf = oc_efloat_up(b->lf);
  o->la = oc_efloat_up(b->la);
}

void oc_ebound_widen(const oc_eboundf *f, oc_ebound *o) {
  *o = (oc_ebound){f->flo, f->fhi, f->alo, f->ahi, f->lf, f->la};
}

/* ---- whole-plane bounds ----------------------------------------------- */

void oc_enode_glob(const oc_enode *n, oc_ebound *o) {
  switch (n->kind) {
  case OC_E_DISC:
    oc_edisc_glob(n, o);
    return;
  case OC_E_CURVE:
  case OC_E_LAKE:
  case OC_E_IMAGE:
    *o = OC_EPRIM(n)->glob;
    return;
  case OC_E_BLEND:
    oc_ebound_widen(&OC_EBLEND(n)->glob, o);
    return;
  case OC_E_XFORM:
  case OC_E_WARP: {
    oc_ebound c;
    oc_erect cb = oc_enode_box(OC_EUN(n)->kid), box;
    oc_enode_glob(OC_EUN(n)->kid, &c);
    oc_eop_derive(n, &c, &cb, o, &box);
    return;
  }
  default:
    oc_ebound_widen(&OC_EBIN(n)->glob, o);
  }
}

/* The children's exact bounds, then the node's from them. Recursive (as
** evaluation is) with a small frame: more children than STACK take the
** heap, and without memory the stored (wider) bounds answer. */
void oc_enode_exact(const oc_enode *n, oc_ebound *glob, oc_erect *box) {
  enum { STACK = 4 };
  size_t nk = oc_enode_nkids(n);
  oc_ebound kbs[STACK], *kb = kbs;
  oc_erect kboxs[STACK], *kbox = kboxs;
  void *heap = NULL;
  if (nk > STACK) { /* both arrays in one block (doubles throughout) */
    heap = malloc(nk * (sizeof *kb + sizeof *kbox));
    kb = heap;
    kbox = heap ? (oc_erect *)(void *)(kb + nk) : NULL;
  }
  if (nk == 0 || !kb) {
    oc_enode_glob(n, glob);
    *box = oc_enode_box(n);
    return;
  }
  oc_enode *const *k = oc_enode_kids(n);
  for (size_t i = 0; i < nk; i++)
    oc_enode_exact(k[i], &kb[i], &kbox[i]);
  if (n->kind == OC_E_LOD)
    oc_elod_derive(n, kb, kbox, glob, box);
  else
    oc_eop_derive(n, kb, kbox, glob, box);
  free(heap);
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
    size_t nk = oc_enode_nkids(cur);
    oc_enode *const *kids = oc_enode_kids(cur);
    for (size_t i = 0; i < nk; i++) {
      oc_enode *k = kids[i];
      if (--k->refs > 0) continue;
      if (!OC_GROW(stack, top, cap, 1)) { /* no memory: recurse for it */
        k->refs = 1;
        oc_enode_release(k);
        continue;
      }
      stack[top++] = k;
    }
    if (cur->kind == OC_E_CURVE) oc_ecurve_free(OC_EPRIM(cur)->data);
    if (cur->kind == OC_E_LAKE) oc_elake_free(OC_EPRIM(cur)->data);
    if (cur->kind == OC_E_IMAGE) oc_eimage_free(OC_EPRIM(cur)->data);
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

void oc_enode_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                     int want, double *f, double *a) {
  if (n->kind == OC_E_DISC) {
    oc_edisc_ev_row(n, x, y, cnt, want, f, a);
    return;
  }
  if (n->kind == OC_E_CURVE) {
    oc_ecurve_ev_row(n, x, y, cnt, want, f, a);
    return;
  }
  if (oc_eop_ev_row(n, x, y, cnt, want, f, a)) return;
  for (int m = 0; m < cnt; m++) {
    oc_enode_sample s;
    oc_enode_ev(n, x[m], y, NULL, want, &s);
    a[m] = s.a;
    if (!(want & OC_EV_ALPHA)) f[m] = s.f;
  }
}

void oc_enode_row_span(const oc_enode *k, const double *x, double y, int cnt,
                       int *i0, int *i1) {
  oc_erect b = oc_enode_box(k); /* (the doubles oc_enode_holds compares) */
  int m = 0;
  if (y >= b.y0 && y <= b.y1) {
    while (m < cnt && !(x[m] >= b.x0))
      m++;
    *i0 = m;
    while (m < cnt && x[m] <= b.x1)
      m++;
    *i1 = m;
    return;
  }
  *i0 = *i1 = 0;
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

/* The box [x - R, x + R] x [y - R, y + R] holds the disc: on it f moves
** from its value at p by at most lf r and stays in [flo, fhi], so either
** bounds |f(q) - f(p)| with no linear part (etaylor.h, oc_etay_flat); the
** same for alpha. Under a view the box bound takes the footprints of the
** disc, tf->b: a bound under footprints in [lo, hi] holds at every point
** of the box whose footprint is in there (ranges and slopes are bounded
** point by point), and those of the disc are. */
void oc_enode_taylor_flat(const oc_enode *n, double x, double y, double R,
                          const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  oc_enode_sample s;
  oc_ebound b;
  oc_erect r = {x - R, y - R, x + R, y + R};
  oc_enode_ev(n, x, y, tf ? &tf->p : NULL, 0, &s);
  oc_enode_bnd(n, &r, tf ? &tf->b : NULL, &b);
  (*boxes)++;
  o->f = oc_etay_flat(s.f, b.lf, fmax(b.fhi - s.f, s.f - b.flo), R);
  o->a = oc_etay_flat(s.a, b.la, fmax(b.ahi - s.a, s.a - b.alo), R);
}

int oc_enode_taylor_alpha(const oc_enode *n, double x, double y, double R,
                          oc_etay *a, int *boxes) {
  if (n->kind == OC_E_DISC) {
    oc_edisc_taylor_alpha(n, x, y, R, a);
    return 1;
  }
  if (n->kind == OC_E_LOD || OC_EPRIM_KIND(n->kind)) return 0;
  return oc_eop_taylor_alpha(n, x, y, R, a, boxes);
}

void oc_enode_taylor_view(const oc_enode *n, double x, double y, double R,
                          const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  if (n->kind == OC_E_DISC) {
    if (!tf) {
      oc_edisc_taylor(n, x, y, R, o);
      return;
    }
    if (oc_edisc_taylor_lod(n, x, y, R, tf, o)) return;
  } else if (n->kind == OC_E_LOD) {
    if (oc_elod_taylor(n, x, y, R, tf, o, boxes)) return;
  } else if (!OC_EPRIM_KIND(n->kind) && oc_eop_taylor(n, x, y, R, tf, o, boxes))
    return;
  oc_enode_taylor_flat(n, x, y, R, tf, o, boxes);
}

void oc_enode_taylor(const oc_enode *n, double x, double y, double R,
                     oc_etaylor *o, int *boxes) {
  oc_enode_taylor_view(n, x, y, R, NULL, o, boxes);
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
  oc_ebound g;
  oc_erect b;
  oc_enode_exact(e, &g, &b);
  if (box) {
    box[0] = b.x0;
    box[1] = b.y0;
    box[2] = b.x1;
    box[3] = b.y1;
  }
  if (flo) *flo = g.flo;
  if (fhi) *fhi = g.fhi;
}

double oc_enode_lipschitz(const oc_enode *e) {
  oc_ebound g;
  oc_erect b;
  oc_enode_exact(e, &g, &b);
  return g.lf;
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
    st->node_bytes += oc_enode_size(x);
    size_t db = 0;
    if (x->kind == OC_E_CURVE) db = oc_ecurve_bytes(OC_EPRIM(x)->data);
    if (x->kind == OC_E_LAKE) db = oc_elake_bytes(OC_EPRIM(x)->data);
    if (x->kind == OC_E_IMAGE && oc_eimage_bytes(OC_EPRIM(x)->data, &seen, &db))
      goto nomem;
    st->bytes += db;
    size_t nk = oc_enode_nkids(x);
    for (size_t i = 0; i < nk; i++) {
      const oc_enode *k = oc_enode_kid(x, i);
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
  oc_ebound g;
  oc_erect whole; /* (as built in doubles) */
  oc_enode_exact(e, &g, &whole);
  terrain_cells(e, v, whole, 7, &acc);
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

/* Rows of height_weight (oc_elevation.height_weight_row), OC_EROW
** samples at a time. */
static void src_height_weight_row(void *ud, const double *x, double y, int n,
                                  double *h, double *alpha) {
  for (int m = 0; m < n; m += OC_EROW)
    oc_enode_ev_row(ud, x + m, y, n - m < OC_EROW ? n - m : OC_EROW, 0, h + m,
                    alpha + m);
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

/* oc_elevation.taylor: the tree's model of f, padded for rounding (the
** evaluators' sums err by a few ulps of their terms; a relative hair of
** the value and of the coefficients covers that). */
double oc_enode_taylor_src(const oc_enode *n, double x, double y, double R,
                           const oc_etfoot *tf, double g[2], double e[3],
                           int *boxes) {
  oc_etaylor m;
  int nb = 0;
  oc_enode_taylor_view(n, x, y, R, tf, &m, &nb);
  if (boxes) *boxes += nb;
  g[0] = m.f.gx, g[1] = m.f.gy;
  e[0] = m.f.e0 * (1 + 1e-9) + 1e-11 * (1 + fabs(m.f.v));
  e[1] = m.f.e1 * (1 + 1e-9) + 1e-12 * (fabs(m.f.gx) + fabs(m.f.gy));
  e[2] = m.f.e2 * (1 + 1e-9);
  return m.f.v;
}

static double src_taylor(void *ud, double x, double y, double R, double g[2],
                         double e[3], int *boxes) {
  return oc_enode_taylor_src(ud, x, y, R, NULL, g, e, boxes);
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
  src->taylor = src_taylor;
  src->retain = src_retain;
  src->release = src_release;
  src->height_weight = src_height_weight; /* Omega_T: where alpha >= 1/2 */
  src->height_weight_row = src_height_weight_row;
  src->weight_range = src_weight_range;
  src->ud = e;
  src->x0 = d[0];
  src->y0 = d[1];
  src->x1 = d[2];
  src->y1 = d[3];
  oc_enode_retain(e);
  return OC_OK;
}
