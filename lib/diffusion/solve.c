/*
** solve.c — the multigrid solve of one map (Hnaidi et al. 2010, section
** 5.2, after Orzan et al. 2008). The paper's schedule: a coarse-to-fine
** cascade with 5 (l - i) Jacobi sweeps at level i of l (0 the coarsest),
** each level starting from the bilinear prolongation of the one below.
**
** The converged mode (a tolerance given) starts from that cascade, then
** runs V-cycles on the finest grid while each removes at least 30 % of
** its largest update, then BiCGSTAB preconditioned by V-cycles, until
** that update is below the tolerance. (The elevation's operator is not
** symmetric, with its upwind gradient terms; the Krylov iteration
** removes the few modes V-cycles leave. Its dot products are row sums
** added in row order, so the result does not depend on the thread
** count.)
**
** V-cycle: on the finest grid 2 red-black Gauss-Seidel sweeps of the
** relaxation (jacobi.c; the same for any thread count), the residual
** r = M x + c - x summed over each coarse sample's children, the coarse
** correction solved from 0 with the Galerkin operators of galerkin.c
** (at each coarser level 2 Gauss-Seidel sweeps, the residual summed
** again, the next correction prolonged and added, 2 sweeps; 100 sweeps
** on the coarsest grid), prolonged bilinearly and added with the step
** that minimises the residual (the whole of it as BiCGSTAB's
** preconditioner, which must be a fixed linear map); 2 sweeps.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define PRE 2
#define POST 2
#define COARSE_SWEEPS 100
#define STALL 0.7 /* V-cycles removing less: BiCGSTAB takes over */

typedef struct vctx {
  oc_dpyramid *py;
  const oc_dgalerkin *gal; /* the coarse levels' operators */
  const oc_dop *op;        /* the problem (level 0) */
  oc_dop hom;              /* its correction equation (levels >= 1) */
  /* per level: correction and right-hand side (levels >= 1), residual;
  ** the finest grid's prolonged correction and its image by the
  ** operator (c, ac: level 0 only) */
  float **e, **b, **r, **c, **ac;
  double *rows; /* per-row partial sums of the finest grid's height */
  int linear;   /* as BiCGSTAB's preconditioner: the whole correction
                ** (a fixed linear map: the Krylov iteration needs one) */
} vctx;

/* n red-black Gauss-Seidel sweeps of x; returns the last update. */
static double smooth(const oc_dop *op, const oc_dlevel *lv, float *x,
                     const float *rhs, int n) {
  double big = 0;
  for (int it = 0; it < n; it++)
    big = oc_dgauss_seidel(op, lv, x, rhs);
  return big;
}

/* The residual of x at level lv into r: one sweep's update, 0 where
** constrained. */
static void residual(const oc_dop *op, const oc_dlevel *lv, const float *x,
                     const float *rhs, float *r) {
  oc_dresidual(op, lv, x, rhs, r);
}

/* The step t minimising |r - t A c| (A c = c - M c, homogeneous), by
** sums over rows added in row order (the same for any thread count). */
static double step(const vctx *v, const oc_dlevel *lv, const float *r,
                   const float *c, float *ac) {
  oc_djacobi(&v->hom, lv, c, ac, NULL);
  int ny = lv->ny;
  size_t nx = (size_t)lv->nx;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (int j = 0; j < ny; j++) {
    double ra = 0, aa = 0;
    for (size_t i = 0; i < nx; i++) {
      size_t k = (size_t)j * nx + i;
      double a = (double)c[k] - ac[k];
      ra += r[k] * a;
      aa += a * a;
    }
    v->rows[2 * j] = ra;
    v->rows[2 * j + 1] = aa;
  }
  double ra = 0, aa = 0;
  for (int j = 0; j < ny; j++)
    ra += v->rows[2 * j], aa += v->rows[2 * j + 1];
  return aa > 0 ? ra / aa : 0;
}

/* The prolongation of level k + 1's correction into c (0 where fixed). */
static void prolong_correction(const vctx *v, int k, float *c) {
  const oc_dlevel *lv = &v->py->lv[k];
  memset(c, 0, (size_t)lv->nx * (size_t)lv->ny * sizeof *c);
  oc_dprolong(&v->hom, &v->py->lv[k + 1], v->e[k + 1], lv, c, 0);
}

/* One V-cycle of the correction equation A_k x = b at level k >= 1,
** with the Galerkin operators. */
static void gcycle(const vctx *v, int k, float *x, const float *b) {
  oc_dpyramid *py = v->py;
  const oc_dlevel *lv = &py->lv[k];
  if (k == py->nlevels - 1) {
    oc_dgalerkin_smooth(v->gal, lv, k, x, b, COARSE_SWEEPS);
    return;
  }
  oc_dgalerkin_smooth(v->gal, lv, k, x, b, PRE);
  oc_dgalerkin_residual(v->gal, lv, k, x, b, v->r[k]);
  const oc_dlevel *lc = &py->lv[k + 1];
  oc_dgalerkin_restrict(lv, v->r[k], lc, v->b[k + 1]);
  memset(v->e[k + 1], 0, (size_t)lc->nx * (size_t)lc->ny * sizeof(float));
  gcycle(v, k + 1, v->e[k + 1], v->b[k + 1]);
  oc_dgalerkin_prolong(v->gal, k, lc, v->e[k + 1], lv, x);
  oc_dgalerkin_smooth(v->gal, lv, k, x, b, POST);
}

/* One V-cycle on the finest grid's x (rhs NULL: the problem itself, else
** the correction equation A x = rhs). The coarse correction is added
** with the step that minimises the residual, or whole as BiCGSTAB's
** preconditioner (a fixed linear map). */
static double vcycle(const vctx *v, float *x, const float *rhs) {
  oc_dpyramid *py = v->py;
  const oc_dop *op = rhs ? &v->hom : v->op;
  const oc_dlevel *lv = &py->lv[0];
  if (py->nlevels == 1) return smooth(op, lv, x, rhs, COARSE_SWEEPS);
  smooth(op, lv, x, rhs, PRE);
  residual(op, lv, x, rhs, v->r[0]);
  const oc_dlevel *lc = &py->lv[1];
  oc_dgalerkin_restrict(lv, v->r[0], lc, v->b[1]);
  memset(v->e[1], 0, (size_t)lc->nx * (size_t)lc->ny * sizeof(float));
  gcycle(v, 1, v->e[1], v->b[1]);
  prolong_correction(v, 0, v->c[0]);
  double t = v->linear ? 1 : step(v, lv, v->r[0], v->c[0], v->ac[0]);
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
  const float *c = v->c[0];
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (size_t q = 0; q < ns; q++)
    x[q] = (float)(x[q] + t * c[q]);
  return smooth(op, lv, x, rhs, POST);
}

static int report(const oc_dsolve *s, double f) {
  return s->progress.fn && s->progress.fn(s->progress.ud, s->lo + s->span * f);
}

/* The smallest and largest constrained value of the finest grid. */
static void fixed_range(const oc_dpyramid *py, const oc_dop *op, double *lo,
                        double *hi) {
  const oc_dlevel *lv = &py->lv[0];
  const float *x = lv->map[op->map];
  double a = INFINITY, b = -INFINITY;
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
#pragma omp parallel for schedule(static) reduction(min : a) reduction(max : b)
  for (size_t k = 0; k < ns; k++)
    if (oc_dfixed(op, lv, k)) {
      if (x[k] < a) a = x[k];
      if (x[k] > b) b = x[k];
    }
  *lo = a, *hi = b;
}

/* Ordered dot product of two finest-level vectors (row sums in order). */
static double dot(const vctx *v, const float *a, const float *b) {
  const oc_dlevel *lv = &v->py->lv[0];
  size_t nx = (size_t)lv->nx;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (int j = 0; j < lv->ny; j++) {
    double d = 0;
    for (size_t i = 0; i < nx; i++)
      d += (double)a[(size_t)j * nx + i] * b[(size_t)j * nx + i];
    v->rows[j] = d;
  }
  double d = 0;
  for (int j = 0; j < lv->ny; j++)
    d += v->rows[j];
  return d;
}

/* y = A x = x - M x (homogeneous; 0 where constrained), finest level. */
static void apply(const vctx *v, const float *x, float *y) {
  const oc_dlevel *lv = &v->py->lv[0];
  oc_djacobi(&v->hom, lv, x, y, NULL);
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
  for (size_t q = 0; q < ns; q++)
    y[q] = oc_dfixed(&v->hom, lv, q) ? 0 : x[q] - y[q];
}

/* z = one V-cycle on A z = q from 0. */
static void precond(const vctx *v, const float *q, float *z) {
  const oc_dlevel *lv = &v->py->lv[0];
  memset(z, 0, (size_t)lv->nx * (size_t)lv->ny * sizeof *z);
  vcycle(v, z, q);
}

static double maxabs(const oc_dlevel *lv, const float *r) {
  double m = 0;
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
#pragma omp parallel for schedule(static) reduction(max : m) if (OC_DPAR(lv))
  for (size_t q = 0; q < ns; q++)
    if (fabs(r[q]) > m) m = fabs(r[q]);
  return m;
}

/* BiCGSTAB (van der Vorst 1992) on A x = b, right-preconditioned by one
** V-cycle; the true residual is recomputed after every iteration (one
** sweep), so rounding cannot make it drift; restarts on breakdown. */
static int krylov(const vctx *v, const oc_dsolve *s, double tol, double *res,
                  int *cycles, oc_error *err) {
  const oc_dlevel *lv = &v->py->lv[0];
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
  float *x = lv->map[v->op->map];
  float *w = malloc(8 * ns * sizeof *w);
  if (!w) return oc_seterr(err, OC_ENOMEM, "out of memory");
  float *r = w, *r0 = w + ns, *p = w + 2 * ns, *vv = w + 3 * ns,
        *ph = w + 4 * ns, *sv = w + 5 * ns, *sh = w + 6 * ns, *t = w + 7 * ns;
  residual(v->op, lv, x, NULL, r);
  memcpy(r0, r, ns * sizeof *r);
  memset(p, 0, ns * sizeof *p);
  memset(vv, 0, ns * sizeof *vv);
  double rho = 1, alpha = 1, omega = 1;
  int c = *cycles, rc = OC_OK;
  while (*res > tol && c < OC_DIFFUSION_MAX_CYCLES) {
    double rn = dot(v, r0, r);
    if (rn == 0 || omega == 0) { /* breakdown: restart */
      memcpy(r0, r, ns * sizeof *r);
      memset(p, 0, ns * sizeof *p);
      memset(vv, 0, ns * sizeof *vv);
      rho = alpha = omega = 1;
      rn = dot(v, r0, r);
      if (rn == 0) break;
    }
    double beta = (rn / rho) * (alpha / omega);
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
    for (size_t q = 0; q < ns; q++)
      p[q] = (float)(r[q] + beta * (p[q] - omega * vv[q]));
    precond(v, p, ph);
    apply(v, ph, vv);
    double d = dot(v, r0, vv);
    if (d == 0) break;
    alpha = rn / d;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
    for (size_t q = 0; q < ns; q++)
      sv[q] = (float)(r[q] - alpha * vv[q]);
    precond(v, sv, sh);
    apply(v, sh, t);
    double tt = dot(v, t, t);
    omega = tt > 0 ? dot(v, t, sv) / tt : 0;
#pragma omp parallel for schedule(static) if (OC_DPAR(lv))
    for (size_t q = 0; q < ns; q++)
      x[q] = (float)(x[q] + alpha * ph[q] + omega * sh[q]);
    residual(v->op, lv, x, NULL, r); /* the true residual, no drift */
    rho = rn;
    *res = maxabs(lv, r);
    c++;
    if (s->residual) s->residual[c] = *res;
    if (report(s, 0.5 + 0.5 * c / OC_DIFFUSION_MAX_CYCLES)) {
      rc = oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
      break;
    }
  }
  *cycles = c;
  free(w);
  return rc;
}

/* At least floats floats of w (the old contents lost), or NULL (ENOMEM). */
static void *dwork_get(oc_dwork *w, size_t floats) {
  if (w->cap < floats) {
    free(w->f);
    w->f = malloc(floats * sizeof(float));
    w->cap = w->f ? floats : 0;
  }
  return w->f;
}

static int vcycles(oc_dpyramid *py, const oc_dop *op, const oc_dsolve *s,
                   double first, oc_error *err) {
  int L = py->nlevels, rc = OC_OK;
  oc_dgalerkin own = {0};
  vctx v = {
      py, s->gal ? s->gal : &own, op, *op, NULL, NULL, NULL, NULL, NULL, NULL,
      0};
  v.hom.hom = 1;
  /* the buffers in one block, kept across solves when s->work is given
  ** (memory touched for the first time costs a page fault) */
  oc_dwork mine = {0}, *w = s->work ? s->work : &mine;
  size_t need = 2 * (size_t)py->lv[0].ny * sizeof(double) /
                sizeof(float); /* the rows' sums */
  for (int k = 0; k < L; k++)
    need += 3 * (size_t)py->lv[k].nx * (size_t)py->lv[k].ny;
  float *all[5 * 32] = {NULL};
  float *at = dwork_get(w, need);
  if (!at) rc = oc_seterr(err, OC_ENOMEM, "out of memory");
  v.e = all, v.b = all + L, v.r = all + 2 * L, v.c = all + 3 * L,
  v.ac = all + 4 * L;
  if (at) {
    v.rows = (double *)(void *)at; /* (the block is malloc'd: aligned) */
    at += 2 * (size_t)py->lv[0].ny * sizeof(double) / sizeof(float);
    for (int k = 0; k < L; k++) {
      size_t ns = (size_t)py->lv[k].nx * (size_t)py->lv[k].ny;
      for (int q = 0; q < 5; q++)
        if (k > 0 ? q <= 2 : q >= 2)
          all[(size_t)q * (size_t)L + (size_t)k] = at, at += ns;
    }
  }
  double lo, hi;
  fixed_range(py, op, &lo, &hi);
  double scale = fmax(hi - lo, fmax(fabs(lo), fabs(hi)));
  double tol = s->tolerance * fmax(scale, 1e-6);
  if (!rc && !s->gal) rc = oc_dgalerkin_build(&own, py, &v.hom, err);
  double res = first;
  if (s->residual) s->residual[0] = res;
  int c = 0;
  /* V-cycles while each removes most of the largest update, then the
  ** Krylov iteration for the modes they leave */
  while (!rc && res > tol && c < OC_DIFFUSION_MAX_CYCLES) {
    double prev = res;
    res = vcycle(&v, py->lv[0].map[op->map], NULL);
    c++;
    if (s->residual) s->residual[c] = res;
    if (report(s, 0.5 + 0.5 * c / OC_DIFFUSION_MAX_CYCLES))
      rc = oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
    if (res > STALL * prev) break;
  }
  v.linear = 1;
  if (!rc && res > tol && c < OC_DIFFUSION_MAX_CYCLES)
    rc = krylov(&v, s, tol, &res, &c, err);
  if (s->cycles) *s->cycles = c;
  free(mine.f);
  oc_dgalerkin_free(&own);
  return rc;
}

int oc_dsolve_map(oc_dpyramid *py, const oc_dop *op, const oc_dsolve *s,
                  oc_error *err) {
  int L = py->nlevels;
  /* the coarsest grid starts at the mean of its constrained values */
  const oc_dlevel *top = &py->lv[L - 1];
  float *xt = top->map[op->map];
  size_t nt = (size_t)top->nx * (size_t)top->ny, nf = 0;
  double sum = 0;
  for (size_t k = 0; k < nt; k++)
    if (oc_dfixed(op, top, k)) sum += xt[k], nf++;
  for (size_t k = 0; k < nt; k++)
    if (!oc_dfixed(op, top, k)) xt[k] = nf ? (float)(sum / nf) : 0;
  double total = 0, done = 0, last = 0;
  for (int k = 0; k < L; k++)
    total += 5.0 * (k + 1) * py->lv[k].nx * py->lv[k].ny;
  double part = s->tolerance > 0 ? 0.5 : 1;
  for (int k = L - 1; k >= 0; k--) {
    oc_dlevel *lv = &py->lv[k];
    if (k < L - 1)
      oc_dprolong(op, &py->lv[k + 1], py->lv[k + 1].map[op->map], lv,
                  lv->map[op->map], 0);
    last = oc_djacobi_n(op, lv, lv->map[op->map], py->scratch, 5 * (k + 1));
    done += 5.0 * (k + 1) * lv->nx * lv->ny;
    if (report(s, part * done / total))
      return oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
  }
  if (s->tolerance > 0) return vcycles(py, op, s, last, err);
  if (s->residual) s->residual[0] = last;
  if (s->cycles) *s->cycles = 0;
  return OC_OK;
}
