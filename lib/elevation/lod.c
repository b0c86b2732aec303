/*
** lod.c — level of detail for elevation trees (Génevaux et al. 2015,
** section 6): views and their pixel footprints, the octave filter kappa,
** the lod operator that blends a coarse tree into a detailed one, and the
** elevation source of a tree seen from a camera.
**
** The footprint is a function of the point p alone, foot(p) = k sqrt(|p -
** e_xy|^2 + dz^2), not of the ray that reaches p, so the tree under a view
** is one 2D terrain that primary and shadow rays alike see; foot is C1
** and k-Lipschitz, so kappa(p) = b(clamp(log2(w / foot(p)), 0, 1)) is C1
** with |grad kappa| <= max b' k / (ln 2 foot), and every bound of the
** tree can include it (the accelerated tracer stays exact for it).
**
** The lod bound (the appendix, corrected): with t = clamp((kappa - k0) /
** (k1 - k0)), f = (1 - t) f_A + t f_B,
**   lambda <= max(lambda_A, lambda_B) + lambda_kappa sup|f_A - f_B| / (k1 -
*k0).
*/
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "core/error.h"
#include "elevation/enode.h"

#define LN2 0.69314718055994530942
/* par slots: wavelength, k0, k1 */
enum { P_W = 0, P_K0 = 1, P_K1 = 2 };

/* ---- views ------------------------------------------------------------- */

/* (inline in this file's per-query paths: vsrc_taylor's footprint, box
** footprints and prep are one sequence, no calls or reloads) */
static inline void view_foot(const oc_eview *v, double x, double y,
                             oc_efoot *ft) {
  double u = x - v->ex, w = y - v->ey;
  double r = sqrt(u * u + w * w + v->dz * v->dz);
  ft->v = v->k * r;
  if (r > 0) {
    ft->gx = v->k * u / r;
    ft->gy = v->k * w / r;
  } else {
    ft->gx = ft->gy = 0;
  }
}

static inline void view_footb(const oc_eview *v, const oc_erect *b,
                              oc_efootb *fb) {
  double dx = oc_fmax(oc_fmax(b->x0 - v->ex, v->ex - b->x1), 0);
  double dy = oc_fmax(oc_fmax(b->y0 - v->ey, v->ey - b->y1), 0);
  double fx = oc_fmax(fabs(b->x0 - v->ex), fabs(b->x1 - v->ex));
  double fy = oc_fmax(fabs(b->y0 - v->ey), fabs(b->y1 - v->ey));
  double z2 = v->dz * v->dz;
  /* rounding: a relative hair each way */
  fb->lo = v->k * sqrt(dx * dx + dy * dy + z2) * (1 - 1e-12);
  fb->hi = v->k * sqrt(fx * fx + fy * fy + z2) * (1 + 1e-12);
  fb->k = v->k;
}

void oc_eview_foot(const oc_eview *v, double x, double y, oc_efoot *ft) {
  view_foot(v, x, y, ft);
}

void oc_eview_footb(const oc_eview *v, const oc_erect *b, oc_efootb *fb) {
  view_footb(v, b, fb);
}

void oc_elod_kappa_bound_t(double w, double tmin, double tmax,
                           const oc_efootb *fb, double *lo, double *hi,
                           double *lip) {
  /* on the ramp foot lies in (w / 2, w): |grad t| <= k / (ln 2 foot)
  ** (max b' times that, as (max b' k) / (ln 2 foot)) */
  oc_elod_kappa_bound_c(tmin, tmax, 1, lo, hi, lip);
  if (*lip != 0) *lip = *lip * fb->k / (LN2 * oc_fmax(fb->lo, w / 2));
}

void oc_elod_kappa_bound(double w, const oc_efootb *fb, double *lo, double *hi,
                         double *lip) {
  if (!fb || !(fb->hi > 0)) {
    *lo = *hi = 1;
    *lip = 0;
    return;
  }
  /* t = log2(w / foot), padded against the evaluators' rounding */
  double tmin = log2(w / fb->hi) - 1e-12;
  double tmax = fb->lo > 0 ? log2(w / fb->lo) + 1e-12 : INFINITY;
  oc_elod_kappa_bound_t(w, tmin, tmax, fb, lo, hi, lip);
}

/* ---- the lod operator -------------------------------------------------- */

/* kappa at the footprint ft and, when g, its gradient */
static double kappa_at(double w, const oc_efoot *ft, double g[2]) {
  double db, t = log2(w / ft->v);
  double k = oc_elod_b(t, &db);
  if (g) {
    double c = -db / (ft->v * LN2);
    g[0] = c * ft->gx;
    g[1] = c * ft->gy;
  }
  return k;
}

void oc_elod_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                int want, oc_enode_sample *s) {
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  const double *p = OC_EBIN(n)->par;
  int grad = want & OC_EV_GRAD;
  if (!ft || !(ft->v > 0)) { /* full detail: kappa = 1, t = 1 */
    oc_enode_ev(B, x, y, ft, want, s);
    return;
  }
  double gk[2] = {0, 0};
  double kap = kappa_at(p[P_W], ft, grad ? gk : NULL);
  double t = (kap - p[P_K0]) / (p[P_K1] - p[P_K0]);
  if (t >= 1) {
    oc_enode_ev(B, x, y, ft, want, s);
    return;
  }
  if (t <= 0) {
    oc_enode_ev(A, x, y, ft, want, s);
    return;
  }
  /* both: neither may leave f unset where its own weight is 0 (alpha
  ** alone: no f) */
  int only = want & OC_EV_ALPHA;
  oc_enode_sample a, b;
  oc_enode_ev(A, x, y, ft, grad | only, &a);
  oc_enode_ev(B, x, y, ft, grad | only, &b);
  s->a = (1 - t) * a.a + t * b.a;
  if (only) return;
  s->f = (1 - t) * a.f + t * b.f;
  if (!grad) {
    s->fx = s->fy = s->ax = s->ay = 0;
    return;
  }
  double c = 1 / (p[P_K1] - p[P_K0]), tx = c * gk[0], ty = c * gk[1];
  s->fx = (1 - t) * a.fx + t * b.fx + tx * (b.f - a.f);
  s->fy = (1 - t) * a.fy + t * b.fy + ty * (b.f - a.f);
  s->ax = (1 - t) * a.ax + t * b.ax + tx * (b.a - a.a);
  s->ay = (1 - t) * a.ay + t * b.ay + ty * (b.a - a.a);
}

/* A's and B's bounds over one region, t in [tlo, thi] with Lipschitz
** bound lt. */
static void lod_combine(const oc_ebound *A, const oc_ebound *B, double lt,
                        oc_ebound *o) {
  o->flo = oc_fmin(A->flo, B->flo);
  o->fhi = oc_fmax(A->fhi, B->fhi);
  o->alo = oc_fmin(A->alo, B->alo);
  o->ahi = oc_fmax(A->ahi, B->ahi);
  o->lf =
      oc_fmax(A->lf, B->lf) + lt * oc_fmax(A->fhi - B->flo, B->fhi - A->flo);
  o->la =
      oc_fmax(A->la, B->la) + lt * oc_fmax(A->ahi - B->alo, B->ahi - A->alo);
}

void oc_elod_bound_in(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                      oc_ebound *o) {
  const double *p = OC_EBIN(n)->par;
  oc_enode *const *k = OC_EBIN(n)->kids;
  double klo, khi, lk;
  oc_elod_kappa_bound(p[P_W], fb, &klo, &khi, &lk);
  double c = 1 / (p[P_K1] - p[P_K0]);
  double tlo = (klo - p[P_K0]) * c, thi = (khi - p[P_K0]) * c;
  if (tlo >= 1) {
    oc_enode_bnd(k[1], b, fb, o);
    return;
  }
  if (thi <= 0) {
    oc_enode_bnd(k[0], b, fb, o);
    return;
  }
  oc_ebound A, B;
  oc_enode_bnd(k[0], b, fb, &A);
  oc_enode_bnd(k[1], b, fb, &B);
  lod_combine(&A, &B, lk * c, o);
}

oc_enode *oc_enode_lod(oc_enode *a, oc_enode *b, const oc_enode_lod_params *p,
                       oc_error *err) {
  if (!a || !b || !p) {
    oc_seterr(err, OC_EINVAL, "lod needs two elevation nodes and parameters");
    return NULL;
  }
  double k0 = p->k0, k1 = p->k1;
  if (k0 == 0 && k1 == 0) k1 = 1;
  if (!(isfinite(p->wavelength) && p->wavelength > 0)) {
    oc_seterr(err, OC_EINVAL, "'wavelength' must be a positive number (got %g)",
              p->wavelength);
    return NULL;
  }
  if (!(k0 >= 0 && k0 < k1 && k1 <= 1)) {
    oc_seterr(err, OC_EINVAL,
              "'k0' and 'k1' must satisfy 0 <= k0 < k1 <= 1 (got %g, %g)", k0,
              k1);
    return NULL;
  }
  oc_enode *k[2] = {a, b};
  oc_enode *n = oc_enode_alloc(
      OC_E_LOD, offsetof(oc_ebin, par) + OC_ELOD_NPAR * sizeof(double), k, 2,
      err);
  if (!n) return NULL;
  oc_ebin *bn = (oc_ebin *)n;
  bn->par[P_W] = p->wavelength;
  bn->par[P_K0] = k0;
  bn->par[P_K1] = k1;
  oc_ebound kb[2], g;
  oc_erect kbox[2] = {oc_enode_box(a), oc_enode_box(b)}, box;
  oc_enode_glob(a, &kb[0]);
  oc_enode_glob(b, &kb[1]);
  oc_elod_derive(n, kb, kbox, &g, &box);
  oc_ebound_round(&g, &bn->glob);
  oc_erect_round(&box, &bn->box);
  return n;
}

void oc_elod_derive(const oc_enode *n, const oc_ebound *kb,
                    const oc_erect *kbox, oc_ebound *glob, oc_erect *box) {
  (void)n;
  const oc_erect *a = &kbox[0], *b = &kbox[1];
  /* under a view alpha may come from a: its box too */
  *box = (oc_erect){oc_fmin(a->x0, b->x0), oc_fmin(a->y0, b->y0),
                    oc_fmax(a->x1, b->x1), oc_fmax(a->y1, b->y1)};
  /* without a view the node is b (its slopes), with the ranges of both so
  ** that those of any view lie inside */
  *glob = kb[1];
  glob->flo = oc_fmin(kb[0].flo, kb[1].flo);
  glob->fhi = oc_fmax(kb[0].fhi, kb[1].fhi);
  glob->alo = oc_fmin(kb[0].alo, kb[1].alo);
  glob->ahi = oc_fmax(kb[0].ahi, kb[1].ahi);
}

/* ---- first-order models under a view (etaylor.h) -----------------------
** tau(q) = log2(w / foot(q)) feeds kappa and the discs' octave filters.
** In world units foot = k rho, rho = |(q - e_xy, dz)|, so ln foot = ln k
** + ln rho, whose Hessian is I / rho^2 - 2 x x^T / rho^4 (x = q - e_xy):
** its eigenvalues 1 / rho^2 (across x) and (dz^2 - |x|^2) / rho^4 (along
** x) lie in [-1 / rho^2, 1 / rho^2], so |Hess ln foot| <= 1 / rho^2 =
** k^2 / foot^2. A transform's child sees foot(M q' + t) / s (M = s Rot):
** the Hessian of its log is s^2 Rot^T (Hess ln foot) Rot, at most s^2 k^2
** / foot^2 = k^2 / foot_c^2 with the same k in its units (xform_footb
** keeps k). A warp's child has no rule (its box bound). So on the disc
** |q - p| <= R, where foot >= fmin = max(fb.lo, foot(p) - k R) (foot is
** k-Lipschitz), |Hess tau| <= k^2 / (ln 2 fmin^2) and Taylor with the
** integral remainder gives
**   |tau(q) - tau(p) - grad tau(p).d| <= k^2 r^2 / (2 ln 2 fmin^2),
** grad tau = -grad foot / (ln 2 foot); tau lies in [log2(w / fmax),
** log2(w / fmin)] there, fmax = min(fb.hi, foot(p) + k R) (bounded
** without logarithms: oc_elod_tau_taylor).
** The filter b(t) = 1 - (1 - t^2)^3 on [0, 1] (0 below, 1 above) is C1
** (b' = 6 t (1 - t^2)^2 vanishes at both ends) with b'' = 6 (1 - t^2)
** (1 - 5 t^2) on (0, 1) and 0 outside, so b(t(q)) composes by the
** chain rule of etaylor.h (oc_etay_compose) with M the largest |b''| on
** t's range (oc_elod_bpp_max, enode.h): |b''| falls from 6 at 0 to 0
** at 1 / sqrt 5, then rises to 4.8 at sqrt(3/5) and falls to 0 at 1. */

static inline __attribute__((always_inline)) void tfoot_prep(oc_etfoot *tf,
                                                             double R) {
  const oc_efoot *ft = &tf->p;
  double k = tf->b.k, kr = k * R * (1 + 1e-12), v = ft->v;
  double flo = oc_fmax(tf->b.lo, v - kr), fhi = oc_fmin(tf->b.hi, v + kr);
  tf->R = R;
  tf->tc = -1 / (v * LN2); /* (as the discs' evaluation) */
  /* tau's range without a log2 each: log2(w / fhi) = tau(p) - log2(fhi /
  ** foot(p)) and ln(1 + x) <= x, so log2(fhi / foot(p)) <= (fhi - v) / (v
  ** ln 2) = (fhi - v) |tc|; log2(w / flo) = tau(p) - log2(flo / foot(p))
  ** and -ln y <= 1 / y - 1, so log2(v / fl) <= (v - fl) / (fl ln 2), fl =
  ** min(flo, v). Two divisions where five were (the quotients by ln 2
  ** and by v are tc's and q's products: within 3 ulps, padded 1e-15).
  ** (perf of fig21's LoD primary rays: the prep 2.6 % before, 2.3 %
  ** after; most of it waits on the footprint's square root) */
  tf->dlo = (oc_fmax(fhi, v) - v) * -tf->tc * (1 + 1e-15);
  tf->curved = flo > 0;
  if (tf->curved) {
    double fl = oc_fmin(flo, v), q = 1 / (fl * LN2);
    tf->dhi = (v - fl) * q * (1 + 1e-15);
    /* k^2 / (2 ln 2 fl^2) = k^2 ln 2 q^2 / 2 */
    tf->e2 = 0.5 * k * k * (LN2 * q * q) * (1 + 1e-12);
  } else {
    tf->dhi = INFINITY;
    tf->e2 = 0;
  }
  double gx = tf->tc * ft->gx, gy = tf->tc * ft->gy; /* (tau's linear part) */
  tf->tg = sqrt(gx * gx + gy * gy);
  tf->lf = oc_log2_any(v);
}

void oc_etfoot_prep(oc_etfoot *tf, double R) {
  tfoot_prep(tf, R);
}

/* A similarity's child (eops.c, xform_taylor): its footprint is foot / s
** and its disc of radius Rc = R / s (1 + 1e-12) is the parent's disc of
** radius R (to the map's rounding), so tau's parts follow from the
** parent's, tf prepared for R: tc and lf as evaluation makes them (the
** models' values and linear parts: the same bits as oc_etfoot_prep), tg
** times s (|grad foot_c| = |grad foot|), dlo and dhi unchanged and e2
** times s^2 (ratios of footprints and k / foot scale so), padded for the
** radius' hair (the direct prep's k Rc (1 + 1e-12) is k R (1 + 2e-12) /
** s: flo moves by 1e-12 k R / s, 1e-12 ln 2 dhi of itself, so dlo by
** 1e-12 of itself, dhi by 1e-12 (1 + ln 2 dhi) and e2 by 2e-12 ln 2 dhi;
** padded twice that, and rounding). Where the footprint may come near 0
** on the disc (dhi > 2^20), the direct prep. A division, a square root
** and the footprint's range's arithmetic fewer per instance: the
** transforms' preps were a third of oc_etfoot_prep's calls in
** bench_elev_lod's fig21; oc_etfoot_scaled takes 0.35-0.64 % of its LoD
** primary rays (perf), where the transforms' preps took about 0.85 %. */
void oc_etfoot_scaled(const oc_etfoot *tf, double R, double s, double Rc,
                      oc_etfoot *cf) {
  oc_etfoot own;
  tf = oc_etfoot_for(tf, R, &own); /* (the same bits however tf came) */
  if (!tf->curved || !(tf->dhi <= 0x1p20)) {
    oc_etfoot_prep(cf, Rc);
    return;
  }
  double v = cf->p.v;
  cf->R = Rc;
  cf->tc = -1 / (v * LN2);
  cf->lf = oc_log2_any(v);
  cf->curved = 1;
  double h = 2e-12 * (1 + tf->dhi);
  cf->dlo = tf->dlo * (1 + 2e-12) + 1e-15;
  cf->dhi = tf->dhi * (1 + h) + 1e-15;
  cf->e2 = tf->e2 * (s * s) * (1 + 1.5 * h);
  cf->tg = tf->tg * s * (1 + 1e-14);
}

int oc_elod_tau_taylor(double w, const oc_etfoot *tf, double R, oc_etay *m,
                       double *lo, double *hi) {
  oc_etfoot own;
  tf = oc_etfoot_for(tf, R, &own);
  return oc_elod_tau_taylor_v(log2(w / tf->p.v), tf, m, lo, hi);
}

oc_etay oc_elod_b_taylor(const oc_etay *t, double lo, double hi, double R) {
  double db, bv = oc_elod_b(t->v, &db);
  return oc_elod_b_taylor_at(t, bv, db, lo, hi, R);
}

/* g + t (h - g) for models g, h of the two children and t's: the
** product rule (etaylor.h) on t and h - g. The value is left to the
** caller. */
static oc_etay lerp_taylor(const oc_etay *g, const oc_etay *h, const oc_etay *t,
                           double R) {
  oc_etay d = oc_etay_scale(g, -1), o = *g;
  oc_etay_add(&d, h);
  oc_etay td = oc_etay_mul(t, &d, R);
  oc_etay_add(&o, &td);
  return o;
}

/* The lod operator, f = (1 - t) f_A + t f_B with t = clamp((kappa - k0)
** / (k1 - k0)), kappa = b(tau) (the model above), and alpha the same:
** where t's range on the disc is 1 (0) only B's (A's) model is made;
** else t's model is kappa's scaled, clamped where its range leaves [0,
** 1] (etaylor.h, oc_etay_clamp01), and f and alpha lerp by the product
** rule. Children whose f model holds only where their weight is > 0
** (oc_eop_taylor_partial) have no rule; nor has full detail (tf NULL:
** the node is B there, but the exact renders keep the box bound they
** had). */
int oc_elod_taylor(const oc_enode *n, double x, double y, double R,
                   const oc_etfoot *tf, oc_etaylor *o, int *boxes) {
  const oc_enode *A = OC_EBIN(n)->kids[0], *B = OC_EBIN(n)->kids[1];
  const double *p = OC_EBIN(n)->par;
  if (!tf) return 0;
  oc_etay tau;
  double tlo, thi, d, c = 1 / (p[P_K1] - p[P_K0]);
  int curved = oc_elod_tau_taylor(p[P_W], tf, R, &tau, &tlo, &thi);
  double lo = (oc_elod_b(tlo, &d) - p[P_K0]) * c;
  double hi = (oc_elod_b(thi, &d) - p[P_K0]) * c;
  if (lo >= 1 || hi <= 0) {
    oc_enode_taylor_view(lo >= 1 ? B : A, x, y, R, tf, o, boxes);
    return 1;
  }
  if (!curved || oc_eop_taylor_partial(A) || oc_eop_taylor_partial(B)) return 0;
  oc_etay kap = oc_elod_b_taylor(&tau, tlo, thi, R);
  double t = (kap.v - p[P_K0]) / (p[P_K1] - p[P_K0]); /* (as oc_elod_ev) */
  oc_etay tm = oc_etay_scale(&kap, c);
  tm.v = t;
  if (lo < 0 || hi > 1) tm = oc_etay_clamp01(&tm, R);
  oc_etaylor a, b;
  oc_enode_taylor_view(A, x, y, R, tf, &a, boxes);
  oc_enode_taylor_view(B, x, y, R, tf, &b, boxes);
  o->f = lerp_taylor(&a.f, &b.f, &tm, R);
  o->a = lerp_taylor(&a.a, &b.a, &tm, R);
  /* the values as evaluation gives them: one child's alone at either end */
  o->f.v = t >= 1 ? b.f.v : t <= 0 ? a.f.v : (1 - t) * a.f.v + t * b.f.v;
  o->a.v = t >= 1 ? b.a.v : t <= 0 ? a.a.v : (1 - t) * a.a.v + t * b.a.v;
  return 1;
}

/* ---- queries and the elevation source under a view --------------------- */

static int make_view(const oc_enode *e, const oc_enode_view *v, oc_eview *o,
                     oc_error *err) {
  if (!(isfinite(v->eye[0]) && isfinite(v->eye[1]) && isfinite(v->eye[2])))
    return oc_seterr(err, OC_EINVAL, "'eye' must have finite coordinates");
  if (!(isfinite(v->k) && v->k >= 0))
    return oc_seterr(err, OC_EINVAL,
                     "'k' must be a finite number >= 0 (got %g)", v->k);
  o->ex = v->eye[0];
  o->ey = v->eye[1];
  oc_ebound g;
  oc_erect box;
  oc_enode_exact(e, &g, &box); /* (as built in doubles) */
  o->dz = fabs(v->eye[2] - (g.flo + g.fhi) / 2);
  o->k = v->k;
  if (!isfinite(o->dz))
    return oc_seterr(err, OC_EINVAL, "'eye' is too far from the terrain");
  return OC_OK;
}

int oc_enode_eval_view(const oc_enode *e, double x, double y,
                       const oc_enode_view *v, oc_enode_sample *s,
                       oc_error *err) {
  oc_eview w;
  if (!v) {
    oc_enode_eval(e, x, y, s);
    return OC_OK;
  }
  int rc = make_view(e, v, &w, err);
  if (rc) return rc;
  if (!isfinite(x) || !isfinite(y)) {
    s->f = s->a = s->fx = s->fy = s->ax = s->ay = NAN;
    return OC_OK;
  }
  oc_efoot ft;
  oc_eview_foot(&w, x, y, &ft);
  oc_enode_ev(e, x, y, &ft, OC_EV_GRAD, s);
  return OC_OK;
}

/* What a view source holds: the tree (retained), the view and the
** domain. */
typedef struct vsrc {
  int refs;
  oc_enode *e;
  oc_eview v;
  double d[4];
} vsrc;

static double vsrc_height(void *ud, double x, double y, double grad[2]) {
  const vsrc *q = ud;
  oc_enode_sample s;
  oc_efoot ft;
  view_foot(&q->v, x, y, &ft);
  oc_enode_ev(q->e, x, y, &ft, grad ? OC_EV_GRAD : 0, &s);
  if (grad) {
    grad[0] = s.fx;
    grad[1] = s.fy;
  }
  return s.f;
}

static void vsrc_bound(const vsrc *q, double x0, double y0, double x1,
                       double y1, oc_ebound *b) {
  oc_erect r = {x0, y0, x1, y1};
  oc_efootb fb;
  view_footb(&q->v, &r, &fb);
  oc_enode_bnd(q->e, &r, &fb, b);
}

static void vsrc_range(void *ud, double x0, double y0, double x1, double y1,
                       double *lo, double *hi) {
  oc_ebound b;
  vsrc_bound(ud, x0, y0, x1, y1, &b);
  *lo = b.flo;
  *hi = b.fhi;
}

static double vsrc_slope(void *ud, double x0, double y0, double x1, double y1) {
  oc_ebound b;
  vsrc_bound(ud, x0, y0, x1, y1, &b);
  return b.lf;
}

/* Both at once, from one traversal (the tracer asks for both on every
** segment). */
static void vsrc_both(void *ud, double x0, double y0, double x1, double y1,
                      double *lo, double *hi, double *slope) {
  oc_ebound b;
  vsrc_bound(ud, x0, y0, x1, y1, &b);
  *lo = b.flo;
  *hi = b.fhi;
  *slope = b.lf;
}

/* The tree's model under the view: the footprint at p and over the
** disc's box (the full-detail model where the view's k is 0). */
static double vsrc_taylor(void *ud, double x, double y, double R, double g[2],
                          double e[3], int *boxes) {
  const vsrc *q = ud;
  oc_etfoot tf;
  oc_erect r = {x - R, y - R, x + R, y + R};
  view_foot(&q->v, x, y, &tf.p);
  view_footb(&q->v, &r, &tf.b);
  if (tf.p.v > 0) tfoot_prep(&tf, R);
  return oc_enode_taylor_src(q->e, x, y, R, tf.p.v > 0 ? &tf : NULL, g, e,
                             boxes);
}

static void vsrc_retain(void *ud) {
  ((vsrc *)ud)->refs++;
}

static void vsrc_release(void *ud) {
  vsrc *q = ud;
  if (--q->refs > 0) return;
  oc_enode_release(q->e);
  free(q);
}

/* alpha alone (OC_EV_ALPHA, as oc_enode_weight: the same bits as
** alpha's in a full evaluation, no noise sum; with OC_EV_LAZY it summed
** the noise of every disc with a weight, 3.7 % of bench_elev_lod's LoD
** primary rays' instructions at 240 x 135) */
double oc_enode_view_weight(void *ud, double x, double y) {
  const vsrc *q = ud;
  if (!isfinite(x) || !isfinite(y)) return NAN;
  oc_enode_sample s;
  oc_efoot ft;
  view_foot(&q->v, x, y, &ft);
  oc_enode_ev(q->e, x, y, &ft, OC_EV_ALPHA, &s);
  return s.a;
}

void oc_enode_view_weight_bound(void *ud, double x0, double y0, double x1,
                                double y1, double *lo, double *hi,
                                double *lip) {
  oc_ebound b;
  vsrc_bound(ud, x0, y0, x1, y1, &b);
  *lo = b.alo;
  *hi = b.ahi;
  *lip = b.la;
}

static int vsrc_coarser(void *ud, double m, oc_elevation *out, oc_error *err);

/* The source of tree e under view w on domain d. */
static int vsrc_new(oc_enode *e, const oc_eview *w, const double d[4],
                    oc_elevation *src, oc_error *err) {
  vsrc *q = malloc(sizeof *q);
  if (!q) return oc_seterr(err, OC_ENOMEM, "out of memory");
  q->refs = 1;
  q->e = e;
  q->v = *w;
  for (int k = 0; k < 4; k++)
    q->d[k] = d[k];
  oc_enode_retain(e);
  *src = (oc_elevation){.height = vsrc_height,
                        .range = vsrc_range,
                        .slope = vsrc_slope,
                        .bound = vsrc_both,
                        .taylor = vsrc_taylor,
                        .retain = vsrc_retain,
                        .release = vsrc_release,
                        .coarser = vsrc_coarser,
                        .ud = q,
                        .x0 = d[0],
                        .y0 = d[1],
                        .x1 = d[2],
                        .y1 = d[3]};
  return OC_OK;
}

/* A coarser level: foot(p) = k sqrt(|p - e_xy|^2 + dz^2) becomes
** sqrt(foot(p)^2 + m^2) = k sqrt(|p - e_xy|^2 + dz^2 + (m / k)^2), the
** same view with dz raised to hypot(dz, m / k): a footprint of the same
** form, C1 and k-Lipschitz with the Hessian bound above, so every bound
** and model of this file holds for it unchanged. (k = 0, full detail,
** has no such form: the level is the source itself.) */
static int vsrc_coarser(void *ud, double m, oc_elevation *out, oc_error *err) {
  const vsrc *q = ud;
  if (!(m >= 0) || isinf(m))
    return oc_seterr(err, OC_EINVAL,
                     "a coarser level's footprint must be finite and >= 0 "
                     "(got %g)",
                     m);
  oc_eview w = q->v;
  if (w.k > 0 && m > 0) w.dz = hypot(w.dz, m / w.k);
  if (!isfinite(w.dz))
    return oc_seterr(err, OC_EINVAL,
                     "a coarser level's footprint %g is too large for the "
                     "view's k %g",
                     m, w.k);
  return vsrc_new(q->e, &w, q->d, out, err);
}

int oc_enode_elevation_view(oc_enode *e, const double *domain,
                            const oc_enode_view *v, oc_elevation *src,
                            oc_error *err) {
  oc_eview w;
  double d[4];
  if (!v) return oc_seterr(err, OC_EINVAL, "lod: no view");
  int rc = make_view(e, v, &w, err);
  if (!rc) rc = oc_enode_domain(e, &w, domain, d, err);
  if (rc) return rc;
  return vsrc_new(e, &w, d, src, err);
}
