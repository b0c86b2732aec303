/*
** relief.c — gradient-based warping (Paris et al. 2020, section 4.2,
** figures 9, 10 and 12), a node kind over any field:
**
**   f_w(p) = f(w(p)),  w(p) = p + u(p) s(p),
**   s(p) = a_xy d(p.x, p.y) + a_xz d(p.x, p.z) + a_yz d(p.y, p.z),
**   a_xy = |u.z| / |u|_1, a_xz = |u.y| / |u|_1, a_yz = |u.x| / |u|_1,
**
** the paper's weights |g . z|, |g . y|, |g . x| normalised to sum 1, d a
** relief R^2 -> [-A, A] in metres (turbulence or an image, taken at world
** coordinates) and u the direction of the unwarped field's gradient. d > 0
** moves the surface outwards (f grows inward).
**
** u is made so that f_w has a Lipschitz bound that follows from the
** child's alone (no curvature of f is known here): the gradient is the
** tetrahedral difference G(p) = sum_k e_k f(p + h e_k) / (4 h), e_k the
** corners (1, -1, -1), (-1, -1, 1), (-1, 1, -1), (1, 1, 1) (exact for a
** linear f), and u = G / max(|G|, eps) with eps = L / 2, L the child's
** Lipschitz bound: the unit gradient where f is at least half as steep as
** it can be, fading to 0 where the gradient vanishes (the middle of a
** block, the centre of a sphere), where a unit gradient would flip and
** make f_w jump.
**
** Lipschitz bound. |sum_k e_k c_k| <= 4 max |c_k|, so G is (L / h)-
** Lipschitz and u, a radial projection onto the ball of radius eps
** divided by eps, is (L / (h eps))-Lipschitz. With |u| <= 1 and the
** weights summing to 1: |s| <= A; d/du (u s) = s I + u (grad_u s)^T,
** grad_u s = sign(u_j) (d_j - s) / |u|_1 so |u| |grad_u s| <= 2 sqrt(3) A;
** and the relief's part is at most L_d (each projection is 1-Lipschitz).
** Hence |grad (w - id)| <= L_d + (1 + 2 sqrt 3) A L / (h eps), and
**
**   Lip(f_w) <= L (1 + L_d + (1 + 2 sqrt 3) A L / (h eps))
**            = L (1 + L_d + 2 (1 + 2 sqrt 3) A / h)    (eps = L / 2),
**
** L_d = 2 A Lip(t) / (t_max wavelength) for turbulence, 2 A |(m_x, m_y)| /
** cell for an image (m the largest difference of neighbouring pixels:
** bilinear interpolation). The default step h = 4 A keeps the last term
** at 2.23. lipschitz_in uses the child's bounds in the box grown by A
** (where f is read) and by sqrt(3) h (where G reads it).
**
** Support: |w(p) - p| <= A, so f_w = 0 outside the child's box grown by
** A. The gradient is analytic: grad f_w = (I + J)^T grad f(w(p)), J the
** Jacobian of u s, from the child's gradients at the four samples.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/vec.h"
#include "field/kind.h"
#include "io/oiio.h"

/* 1 + 2 sqrt(3) */
#define KU 4.4641016151377544
/* images at most this many pixels a side */
#define IMG_MAX 16384

typedef struct rwdata {
  int kind;  /* OC_RELIEF_* */
  double a;  /* A: d in [-A, A] */
  double h;  /* the gradient's step */
  double Ld; /* Lipschitz bound of d */
  /* turbulence */
  uint64_t seed;
  int octaves;
  double wl, tmax;
  /* image: w x ht samples in [0, 1], row 0 at v = 0, periodic */
  int w, ht;
  double cell;
  float px[];
} rwdata;

static const oc_vec3 E[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};

void oc_relief_defaults(oc_relief_params *rp) {
  memset(rp, 0, sizeof *rp);
  rp->kind = OC_RELIEF_TURBULENCE;
  rp->wavelength = 1;
  rp->octaves = 4;
  rp->seed = 1;
}

/* ---- the relief ---------------------------------------------------------- */

/* d(x, y) in [-A, A], its gradient in du, dv. */
static double relief(const rwdata *r, double x, double y, double *du,
                     double *dv) {
  if (r->kind == OC_RELIEF_TURBULENCE) {
    oc_vec3 gr;
    double t = oc_turb3(r->seed, r->octaves, oc_v3(x / r->wl, y / r->wl, 0),
                        du ? &gr : NULL);
    double k = 2 * r->a / r->tmax;
    if (du) {
      *du = k * gr.x / r->wl;
      *dv = k * gr.y / r->wl;
    }
    return k * t - r->a;
  }
  /* bilinear, periodic; sample (i, j) at (i cell, j cell) */
  double u = x / r->cell, v = y / r->cell;
  double fu = floor(u), fv = floor(v);
  double tu = u - fu, tv = v - fv;
  double iu = fu - r->w * floor(fu / r->w), iv = fv - r->ht * floor(fv / r->ht);
  int i0 = (int)iu, j0 = (int)iv;
  if (i0 < 0 || i0 >= r->w) i0 = 0; /* (rounding at huge coordinates) */
  if (j0 < 0 || j0 >= r->ht) j0 = 0;
  int i1 = i0 + 1 == r->w ? 0 : i0 + 1, j1 = j0 + 1 == r->ht ? 0 : j0 + 1;
  const float *row0 = r->px + (size_t)j0 * r->w,
              *row1 = r->px + (size_t)j1 * r->w;
  double p00 = row0[i0], p10 = row0[i1], p01 = row1[i0], p11 = row1[i1];
  double b0 = p00 + tu * (p10 - p00), b1 = p01 + tu * (p11 - p01);
  double val = b0 + tv * (b1 - b0);
  double k = 2 * r->a;
  if (du) {
    *du = k * ((1 - tv) * (p10 - p00) + tv * (p11 - p01)) / r->cell;
    *dv = k * (b1 - b0) / r->cell;
  }
  return k * val - r->a;
}

/* ---- the kind ------------------------------------------------------------ */

enum { P_EPS, P_N };

static oc_aabb grow(oc_aabb b, double m) {
  return (oc_aabb){{b.lo.x - m, b.lo.y - m, b.lo.z - m},
                   {b.hi.x + m, b.hi.y + m, b.hi.z + m}};
}

/* The bound of the header for child bounds Lq (where f is read) and Lg
** (where G reads it). */
static double bound(const rwdata *r, double eps, double Lq, double Lg) {
  if (Lq == 0) return 0;
  return Lq * (1 + r->Ld + KU * fabs(r->a) * Lg / (r->h * eps));
}

static int rw_compile(oc_kcompile *c, oc_error *err) {
  const rwdata *r = c->data;
  (void)err;
  const oc_kinfo *k = &c->kid[0];
  double L = k->lip;
  double eps = isfinite(L) && L > 0 ? L / 2 : 0.5;
  c->par[P_EPS] = eps;
  c->npar = P_N;
  c->info.lo = k->lo;
  c->info.hi = k->hi;
  c->info.box = grow(k->box, fabs(r->a));
  c->info.lip = isfinite(L) ? bound(r, eps, L, L) : INFINITY;
  return OC_OK;
}

static double rw_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const rwdata *r = k->data;
  double h = r->h, eps = k->par[P_EPS];
  double fk[4];
  oc_vec3 ck[4];
  oc_vec3 G = {0, 0, 0};
  for (int i = 0; i < 4; i++) {
    oc_vec3 q = oc_add(p, oc_mul(E[i], h));
    fk[i] = oc_child_eval(k, 0, q, g ? &ck[i] : NULL);
    G = oc_add(G, oc_mul(E[i], fk[i]));
  }
  G = oc_mul(G, 1 / (4 * h));
  double n = oc_len(G), m = fmax(n, eps);
  oc_vec3 u = oc_mul(G, 1 / m);
  double l1 = fabs(u.x) + fabs(u.y) + fabs(u.z);
  if (!(l1 > 0)) return oc_child_eval(k, 0, p, g);
  double dxy_u, dxy_v, dxz_u, dxz_v, dyz_u, dyz_v;
  double dxy = relief(r, p.x, p.y, g ? &dxy_u : NULL, &dxy_v),
         dxz = relief(r, p.x, p.z, g ? &dxz_u : NULL, &dxz_v),
         dyz = relief(r, p.y, p.z, g ? &dyz_u : NULL, &dyz_v);
  double axy = fabs(u.z) / l1, axz = fabs(u.y) / l1, ayz = fabs(u.x) / l1;
  double s = axy * dxy + axz * dxz + ayz * dyz;
  oc_vec3 q = oc_add(p, oc_mul(u, s));
  if (!g) return oc_child_eval(k, 0, q, NULL);
  oc_vec3 gq;
  double v = oc_child_eval(k, 0, q, &gq);
  /* J_G[i][j] = sum_k e_k[i] c_k[j] / (4 h) */
  double JG[3][3] = {{0}}, Ju[3][3];
  for (int i = 0; i < 4; i++) {
    const double e[3] = {E[i].x, E[i].y, E[i].z},
                 c[3] = {ck[i].x, ck[i].y, ck[i].z};
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        JG[a][b] += e[a] * c[b];
  }
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++)
      JG[a][b] /= 4 * h;
  if (n > eps) {
    /* (I - gh gh^T) J_G / n */
    const double gh[3] = {G.x / n, G.y / n, G.z / n};
    double t[3];
    for (int b = 0; b < 3; b++)
      t[b] = gh[0] * JG[0][b] + gh[1] * JG[1][b] + gh[2] * JG[2][b];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        Ju[a][b] = (JG[a][b] - gh[a] * t[b]) / n;
  } else {
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        Ju[a][b] = JG[a][b] / eps;
  }
  /* grad s: the reliefs' part, then the weights' (through u) */
  const double uu[3] = {u.x, u.y, u.z};
  double gs[3] = {axy * dxy_u + axz * dxz_u, axy * dxy_v + ayz * dyz_u,
                  axz * dxz_v + ayz * dyz_v};
  /* d s / d u_j = sign(u_j) (d_(j) - s) / |u|_1, d_(x) = d_yz ... */
  const double dj[3] = {dyz, dxz, dxy};
  double ds[3];
  for (int j = 0; j < 3; j++)
    ds[j] = (uu[j] > 0 ? 1 : uu[j] < 0 ? -1 : 0) * (dj[j] - s) / l1;
  for (int b = 0; b < 3; b++)
    gs[b] += ds[0] * Ju[0][b] + ds[1] * Ju[1][b] + ds[2] * Ju[2][b];
  /* grad f_w = gq + grad s (u . gq) + s Ju^T gq */
  const double gg[3] = {gq.x, gq.y, gq.z};
  double ug = oc_dot(u, gq), out[3];
  for (int b = 0; b < 3; b++)
    out[b] = gg[b] + gs[b] * ug +
             s * (Ju[0][b] * gg[0] + Ju[1][b] * gg[1] + Ju[2][b] * gg[2]);
  *g = oc_v3(out[0], out[1], out[2]);
  return v;
}

static double rw_lipschitz_in(const oc_kctx *k, const oc_aabb *b) {
  const rwdata *r = k->data;
  oc_aabb bq = grow(*b, fabs(r->a)), bg = grow(*b, sqrt(3) * r->h);
  double Lq = oc_child_lipschitz_in(k, 0, &bq);
  if (Lq == 0) return 0;
  double Lg = oc_child_lipschitz_in(k, 0, &bg);
  double v = bound(r, k->par[P_EPS], Lq, Lg);
  return isfinite(v) ? fmin(v, k->lip) : k->lip;
}

static int rw_zero_in(const oc_kctx *k, const oc_aabb *b) {
  const rwdata *r = k->data;
  oc_aabb g = grow(*b, fabs(r->a));
  return oc_child_zero_in(k, 0, &g);
}

static void rw_release(void *data) {
  free(data);
}

static const oc_kind_def relief_kind = {
    .name = "relief_warp",
    .compile = rw_compile,
    .eval = rw_eval,
    .lipschitz_in = rw_lipschitz_in,
    .zero_in = rw_zero_in,
    .release = rw_release,
};

/* ---- construction -------------------------------------------------------- */

/* The image at rp->path as w x ht samples of its first channel (row 0 at
** v = 0: the image's bottom row), clamped to [0, 1], and L_d. */
static rwdata *load_image(const oc_relief_params *rp, oc_error *err) {
  oc_image *im = oc_oiio_read(rp->path, err);
  if (!im) return NULL;
  int w = oc_image_width(im), ht = oc_image_height(im),
      ch = oc_image_channels(im);
  rwdata *r = NULL;
  if (w < 2 || ht < 2 || w > IMG_MAX || ht > IMG_MAX) {
    oc_seterr(err, OC_EINVAL,
              "'relief.path': the image '%s' must be 2 .. %d pixels a side "
              "(got %d x %d)",
              rp->path, IMG_MAX, w, ht);
    goto done;
  }
  r = malloc(sizeof *r + (size_t)w * (size_t)ht * sizeof(float));
  if (!r) {
    oc_seterr(err, OC_ENOMEM, "out of memory for the relief image");
    goto done;
  }
  const float *src = oc_image_cdata(im);
  for (int j = 0; j < ht; j++)
    for (int i = 0; i < w; i++) {
      float v = src[((size_t)(ht - 1 - j) * w + i) * ch];
      if (!isfinite(v)) {
        oc_seterr(err, OC_EINVAL,
                  "'relief.path': the image '%s' has a non-finite sample at "
                  "(%d, %d)",
                  rp->path, i, ht - 1 - j);
        free(r);
        r = NULL;
        goto done;
      }
      r->px[(size_t)j * w + i] = v < 0 ? 0 : v > 1 ? 1 : v;
    }
  r->w = w;
  r->ht = ht;
  double mx = 0, my = 0;
  for (int j = 0; j < ht; j++)
    for (int i = 0; i < w; i++) {
      double v = r->px[(size_t)j * w + i];
      mx = fmax(mx, fabs(r->px[(size_t)j * w + (i + 1) % w] - v));
      my = fmax(my, fabs(r->px[(size_t)((j + 1) % ht) * w + i] - v));
    }
  r->cell = rp->wavelength / w;
  r->Ld = 2 * fabs(rp->amplitude) * sqrt(mx * mx + my * my) / r->cell;
done:
  oc_image_free(im);
  return r;
}

oc_node *oc_relief_warp(oc_node *child, const oc_relief_params *rp,
                        oc_error *err) {
  if (!child || !rp) {
    oc_seterr(err, OC_EINVAL, "relief_warp needs a node and params");
    return NULL;
  }
  if (!oc_check_finite(rp->amplitude, "amplitude", err) ||
      !oc_check_positive(rp->wavelength, "relief.wavelength", err))
    return NULL;
  if (!(rp->step >= 0) || !isfinite(rp->step)) {
    oc_seterr(err, OC_EINVAL, "'step' must be >= 0 (got %g)", rp->step);
    return NULL;
  }
  rwdata *r;
  if (rp->kind == OC_RELIEF_TURBULENCE) {
    if (rp->octaves < 1 || rp->octaves > 16) {
      oc_seterr(err, OC_EINVAL, "'relief.octaves' must be in 1 .. 16 (got %d)",
                rp->octaves);
      return NULL;
    }
    r = calloc(1, sizeof *r);
    if (!r) {
      oc_seterr(err, OC_ENOMEM, "out of memory");
      return NULL;
    }
    r->seed = rp->seed;
    r->octaves = rp->octaves;
    r->wl = rp->wavelength;
    r->tmax = oc_turb3_max(rp->octaves);
    r->Ld = 2 * fabs(rp->amplitude) * oc_turb3_lipschitz(rp->octaves) /
            (r->tmax * r->wl);
  } else if (rp->kind == OC_RELIEF_IMAGE) {
    if (!rp->path) {
      oc_seterr(err, OC_EINVAL, "'relief.path' missing");
      return NULL;
    }
    if (!(r = load_image(rp, err))) return NULL;
  } else {
    oc_seterr(err, OC_EINVAL, "'relief.kind' %d is not a relief",
              (int)rp->kind);
    return NULL;
  }
  r->kind = rp->kind;
  r->a = rp->amplitude;
  r->h = rp->step > 0              ? rp->step
         : fabs(rp->amplitude) > 0 ? 4 * fabs(rp->amplitude)
                                   : 0.01;
  return oc_kind_node(&relief_kind, &child, 1, NULL, 0, r, err);
}
