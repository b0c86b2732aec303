/*
** raster.c — the constraint maps of the finest grid (Hnaidi et al. 2010,
** section 4.1). Each curve is flattened (core/curve.h) within a quarter
** cell; each segment paints the quadrangles on both sides of it, reaching
** r (strict elevation, amplitude and roughness, uniform across) and then
** a on the left or b on the right (the slope: tan theta at the inner
** edge, 0 at the far end); the convex side of a join is closed by the
** round wedge between the two quadrangles. Strict bands are at least
** the half-extent of a cell across the curve (conservative), so cells the
** curve crosses always get h, even when r is below a cell.
**
** Overlaps: strict values are averaged; a cell reached by the slopes of
** two different curves is a conflict, left empty (its gradient is filled
** by the Laplace diffusion, figure 9). The guide direction n is the
** outward normal and the stored value the drop per metre along it; on a
** curve without strict elevation both are inverted (n inward), as the
** paper does so that the gradient propagates from the surroundings.
**
** Rows are split in blocks painted in parallel; every block visits the
** items (segments, wedges) in the same order, so each cell sums its
** contributions in that order whatever the thread count.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define BLOCK 8
#define CONFLICT_OWNER 0xffffu

typedef struct ritem {
  uint32_t curve;
  int wedge;
  double vx, vy, tx, ty, len; /* segment: start, unit direction, length */
  double t2x, t2y;            /* wedge: next direction (tx, ty the previous) */
  double s0, s1;              /* arc length at the ends (wedge: s0) */
  double e0, e1;              /* conservative extension of the ends */
  int convex_left;            /* wedge: the convex side is the left */
  double ylo, yhi;
  /* the linear attributes at the ends (slope angles in degrees), and
  ** whether no knot of theirs lies inside (then they are linear along
  ** the item and interpolated; else looked up per sample) */
  double a0[FA_COUNT], a1[FA_COUNT];
  int linear;
  double w;            /* the farthest a cell it paints lies from it */
  double tan_l, tan_r; /* linear, the same angle at both ends: its tan */
  int same_l, same_r;
} ritem;

typedef struct rcurve {
  const oc_fcurve *fc;
  double reach; /* the farthest a painted cell lies from the curve */
} rcurve;

typedef struct rctx {
  const oc_dlevel *lv;
  double x0, y0;
  const rcurve *cv;
  const ritem *it;
  size_t nit;
  float *h, *gx, *gy, *gd, *A, *R;
  uint16_t *hc, *nc, *gc, *owner;
} rctx;

#define DEG (3.14159265358979323846 / 180)

/* Attribute q of item it's curve fc at the fraction f of the item
** (normalised arc length u): interpolated between the item's ends when
** it is linear there (the slope angles then in degrees), else looked up
** (the angles as tan). */
static inline double attr(const oc_fcurve *fc, const ritem *it, int q, double f,
                          double u) {
  if (it->linear) return it->a0[q] + f * (it->a1[q] - it->a0[q]);
  double v[FA_COUNT];
  oc_fcurve_attrs(fc, u, 1u << q, v);
  return v[q];
}

/* The contributions of item it's curve to cell k at the fraction f of
** the item (arc length s), distance dist on the left (or right) side,
** outward normal (nox, noy); no slope when !slopes (conservative cells
** beyond an end). Each attribute is looked up only where it is used
** (most cells lie in a slope band and need 3 of them). */
static inline __attribute__((always_inline)) void
deposit(const rctx *rc, size_t k, const ritem *it, double f, double s,
        double dist, int left, double nox, double noy, int slopes) {
  uint32_t ci = it->curve;
  const oc_fcurve *fc = rc->cv[ci].fc;
  unsigned has = fc->has;
  double u = !it->linear && fc->length > 0 ? s / fc->length : 0;
  double r = attr(fc, it, FA_RADIUS, f, u);
  double half = 0.5 * rc->lv->cell * (fabs(nox) + fabs(noy));
  double ws = r > half ? r : half; /* (fmax: a call; neither is NaN) */
  if (dist <= ws && (has & (OC_FC_HEIGHT | OC_FC_NOISE))) {
    if (it->linear) u = fc->length > 0 ? s / fc->length : 0;
    if (has & OC_FC_HEIGHT) {
      double a[FA_COUNT];
      oc_fcurve_attrs(fc, u, 1u << FA_HEIGHT, a);
      rc->h[k] += (float)a[FA_HEIGHT];
      if (rc->hc[k] < 0xffffu) rc->hc[k]++;
    }
    if (has & OC_FC_NOISE) {
      rc->A[k] += (float)attr(fc, it, FA_AMP, f, u);
      rc->R[k] += (float)attr(fc, it, FA_ROUGH, f, u);
      if (rc->nc[k] < 0xffffu) rc->nc[k]++;
    }
  }
  if (!slopes || !(has & OC_FC_SLOPE) || !(dist > r)) return;
  double ext = attr(fc, it, left ? FA_EXTA : FA_EXTB, f, u);
  if (!(ext > 0 && dist <= r + ext)) return;
  uint16_t me = (uint16_t)(ci + 1);
  if (rc->owner[k] == CONFLICT_OWNER) return;
  if (rc->owner[k] && rc->owner[k] != me) {
    rc->owner[k] = CONFLICT_OWNER;
    return;
  }
  rc->owner[k] = me;
  double tn;
  if (it->linear && (left ? it->same_l : it->same_r))
    tn = left ? it->tan_l : it->tan_r; /* (a0 + f 0 = a0: the same tan) */
  else {
    tn = attr(fc, it, left ? FA_LEFT : FA_RIGHT, f, u);
    if (it->linear) tn = tan(tn * DEG);
  }
  double val = tn * (1 - (dist - r) / ext);
  double sg = (has & OC_FC_HEIGHT) ? 1 : -1;
  rc->gx[k] += (float)(sg * nox);
  rc->gy[k] += (float)(sg * noy);
  rc->gd[k] += (float)(sg * val);
  if (rc->gc[k] < 0xffffu) rc->gc[k]++;
}

/* x in [lo, hi] where lo <= a x + b <= hi' (updates *xlo, *xhi); 0 when
** empty. */
static int clip(double a, double b, double lo, double hi, double *xlo,
                double *xhi) {
  if (fabs(a) < 1e-12) return b >= lo && b <= hi;
  double u = (lo - b) / a, v = (hi - b) / a;
  if (u > v) {
    double t = u;
    u = v;
    v = t;
  }
  if (u > *xlo) *xlo = u;
  if (v < *xhi) *xhi = v;
  return *xlo <= *xhi;
}

static void paint_row(const rctx *rc, const ritem *it, int j) {
  const oc_dlevel *lv = rc->lv;
  double cell = lv->cell, y = rc->y0 + j * cell;
  double w = it->w;
  double xlo = -INFINITY, xhi = INFINITY;
  if (it->wedge) {
    double dy = y - it->vy;
    if (fabs(dy) > w) return;
    double hw = sqrt(w * w - dy * dy);
    xlo = it->vx - hw, xhi = it->vx + hw;
    /* the sector between the two directions: along the previous one > 0,
    ** along the next < 0 (each a half-plane, so an interval of the row;
    ** widened by a cell, the test below stays exact) */
    if (!clip(it->tx, -it->vx * it->tx + dy * it->ty, 0, INFINITY, &xlo,
              &xhi) ||
        !clip(it->t2x, -it->vx * it->t2x + dy * it->t2y, -INFINITY, 0, &xlo,
              &xhi)) {
      if (!(xlo <= xhi + 2 * cell)) return;
    }
    xlo -= cell, xhi += cell;
  } else {
    /* along = (x - vx) tx + (y - vy) ty, across = -(x - vx) ty + (y - vy) tx */
    double dy = y - it->vy;
    if (!clip(it->tx, -it->vx * it->tx + dy * it->ty, -it->e0, it->len + it->e1,
              &xlo, &xhi) ||
        !clip(-it->ty, it->vx * it->ty + dy * it->tx, -w, w, &xlo, &xhi))
      return;
  }
  double fi0 = ceil((xlo - rc->x0) / cell - 1e-9),
         fi1 = floor((xhi - rc->x0) / cell + 1e-9);
  if (fi0 < 0) fi0 = 0;
  if (fi1 > lv->nx - 1) fi1 = lv->nx - 1;
  size_t row = (size_t)j * (size_t)lv->nx;
  for (int i = (int)fi0; i <= (int)fi1; i++) {
    double dx = rc->x0 + i * cell - it->vx, dy = y - it->vy;
    if (it->wedge) {
      if (!(dx * it->tx + dy * it->ty > 0 && dx * it->t2x + dy * it->t2y < 0))
        continue;
      double d = sqrt(dx * dx + dy * dy);
      if (d > w || d == 0) continue;
      deposit(rc, row + (size_t)i, it, 0, it->s0, d, it->convex_left, dx / d,
              dy / d, 1);
      continue;
    }
    double along = dx * it->tx + dy * it->ty;
    double across = -dx * it->ty + dy * it->tx;
    if (along < -it->e0 || along > it->len + it->e1 || fabs(across) > w)
      continue;
    double f = along <= 0 ? 0 : along >= it->len ? 1 : along / it->len;
    double s = it->s0 + f * (it->s1 - it->s0);
    int left = across >= 0;
    double nox = left ? -it->ty : it->ty, noy = left ? it->tx : -it->tx;
    /* beyond an end of the curve (conservative cells): strict values only */
    deposit(rc, row + (size_t)i, it, f, s, fabs(across), left, nox, noy,
            along >= 0 && along <= it->len);
  }
}

static double attr_max(const oc_fattr *t) {
  double m = 0;
  for (size_t i = 0; i < t->n; i++)
    m = fmax(m, t->v[i]);
  return m;
}

/* The linear attributes of item it at its ends (arc lengths s0, s1), and
** whether they are linear along it: no knot strictly between; then its
** reach (the curve's otherwise: at most reach) from the largest radius
** and extent at its ends (an attribute linear along the item lies
** between its end values, to a rounding: the margin) or the
** conservative half-extent of a cell, and the tan of a slope angle the
** same at both ends. */
static void item_attrs(const oc_fcurve *fc, ritem *it, double s0, double s1,
                       double cell, double reach) {
  double u0 = fc->length > 0 ? s0 / fc->length : 0,
         u1 = fc->length > 0 ? s1 / fc->length : 0;
  it->linear = 1;
  for (int q = FA_RADIUS; q < FA_COUNT; q++) {
    const oc_fattr *t = &fc->attr[q];
    it->a0[q] = t->n ? oc_linear_eval(t->u, t->v, t->n, u0) : 0;
    it->a1[q] = t->n ? oc_linear_eval(t->u, t->v, t->n, u1) : 0;
    for (size_t i = 0; i < t->n; i++)
      if (t->u[i] > u0 && t->u[i] < u1) it->linear = 0;
  }
  it->w = reach;
  it->same_l = it->same_r = 0;
  if (!it->linear) return;
  double r = fmax(it->a0[FA_RADIUS], it->a1[FA_RADIUS]);
  double e = fmax(fmax(it->a0[FA_EXTA], it->a1[FA_EXTA]),
                  fmax(it->a0[FA_EXTB], it->a1[FA_EXTB]));
  double w = fmax(r + fmax(e, 0), cell);
  it->w = fmin(reach, w + 1e-6 * w);
  it->same_l = it->a0[FA_LEFT] == it->a1[FA_LEFT];
  it->same_r = it->a0[FA_RIGHT] == it->a1[FA_RIGHT];
  it->tan_l = tan(it->a0[FA_LEFT] * DEG);
  it->tan_r = tan(it->a0[FA_RIGHT] * DEG);
}

/* Appends the items of one curve (segments, then the wedge after each
** join) to *it. */
static int curve_items(const oc_fcurve *fc, uint32_t ci, double cell,
                       double reach, ritem **it, size_t *n, size_t *cap,
                       oc_error *err) {
  double tol = fmax(0.25 * cell, 1e-6 * fc->length);
  size_t nv = 0;
  int rc = oc_curve_flatten(fc->c, tol, NULL, 0, &nv, err);
  if (rc) return rc;
  oc_curve_vertex *v = malloc(nv * sizeof *v);
  if (!v) return oc_seterr(err, OC_ENOMEM, "out of memory (curve %u)", ci + 1);
  rc = oc_curve_flatten(fc->c, tol, v, nv, &nv, err);
  if (rc) {
    free(v);
    return rc;
  }
  int closed = oc_curve_closed(fc->c);
  if (*n + 2 * nv + 1 > *cap) {
    size_t nc = 2 * (*cap + 2 * nv + 1);
    ritem *t = realloc(*it, nc * sizeof *t);
    if (!t) {
      free(v);
      return oc_seterr(err, OC_ENOMEM, "out of memory (curve %u)", ci + 1);
    }
    *it = t;
    *cap = nc;
  }
  double ptx = 0, pty = 0, ftx = 0, fty = 0;
  int have_prev = 0;
  for (size_t k = 0; k + 1 < nv; k++) {
    double dx = v[k + 1].x - v[k].x, dy = v[k + 1].y - v[k].y;
    double len = sqrt(dx * dx + dy * dy);
    if (!(len > 0)) continue;
    ritem s = {0};
    s.curve = ci;
    s.vx = v[k].x, s.vy = v[k].y, s.tx = dx / len, s.ty = dy / len;
    s.len = len, s.s0 = v[k].s, s.s1 = v[k + 1].s;
    item_attrs(fc, &s, s.s0, s.s1, cell, reach);
    double half = 0.5 * cell * (fabs(s.tx) + fabs(s.ty));
    s.e0 = (k == 0 && !closed) ? half : 0;
    s.e1 = (k + 2 == nv && !closed) ? half : 0;
    double e = fmax(s.e0, s.e1) + s.w;
    s.ylo = fmin(v[k].y, v[k + 1].y) - e, s.yhi = fmax(v[k].y, v[k + 1].y) + e;
    if (have_prev) {
      double cr = ptx * s.ty - pty * s.tx;
      if (fabs(cr) > 1e-12) {
        ritem w = {0};
        w.curve = ci, w.wedge = 1, w.vx = v[k].x, w.vy = v[k].y;
        w.tx = ptx, w.ty = pty, w.t2x = s.tx, w.t2y = s.ty, w.s0 = v[k].s;
        item_attrs(fc, &w, w.s0, w.s0, cell, reach);
        w.convex_left = cr < 0;
        w.ylo = v[k].y - w.w, w.yhi = v[k].y + w.w;
        (*it)[(*n)++] = w;
      }
    }
    (*it)[(*n)++] = s;
    if (!have_prev) ftx = s.tx, fty = s.ty;
    ptx = s.tx, pty = s.ty, have_prev = 1;
  }
  /* a closed curve's last join, where it started */
  double cr = ptx * fty - pty * ftx;
  if (closed && have_prev && fabs(cr) > 1e-12) {
    ritem w = {0};
    w.curve = ci, w.wedge = 1, w.vx = v[0].x, w.vy = v[0].y;
    w.tx = ptx, w.ty = pty, w.t2x = ftx, w.t2y = fty, w.s0 = v[0].s;
    item_attrs(fc, &w, w.s0, w.s0, cell, reach);
    w.convex_left = cr < 0;
    w.ylo = v[0].y - w.w, w.yhi = v[0].y + w.w;
    (*it)[(*n)++] = w;
  }
  free(v);
  return OC_OK;
}

static void normalise(const rctx *rc, size_t k, uint8_t *flags) {
  uint8_t f = 0;
  if (rc->hc[k]) {
    rc->h[k] /= rc->hc[k];
    f |= DF_H;
  }
  if (rc->nc[k]) {
    rc->A[k] /= rc->nc[k];
    rc->R[k] /= rc->nc[k];
    f |= DF_NOISE;
  }
  int conflict = rc->owner[k] == CONFLICT_OWNER;
  if (!conflict && rc->gc[k]) { /* (the norm only where slopes were) */
    double gx = rc->gx[k], gy = rc->gy[k], g = sqrt(gx * gx + gy * gy);
    if (g > 1e-6) {
      rc->gx[k] = (float)(gx / g);
      rc->gy[k] = (float)(gy / g);
      rc->gd[k] /= rc->gc[k];
      f |= DF_SLOPE;
    } else {
      conflict = 1;
    }
  }
  if (conflict) {
    f |= DF_CONFLICT;
    rc->gx[k] = rc->gy[k] = rc->gd[k] = 0;
  }
  flags[k] = f;
}

int oc_draster(oc_dpyramid *py, double x0, double y0, oc_fcurve *const *curves,
               size_t ncurves, oc_progress pr, double span,
               oc_draster_stats *st, oc_error *err) {
  oc_dlevel *lv = &py->lv[0];
  size_t ns = (size_t)lv->nx * (size_t)lv->ny;
  rcurve *cv = malloc((ncurves ? ncurves : 1) * sizeof *cv);
  uint16_t *cnt = oc_dpyramid_counters(py);
  ritem *it = NULL;
  size_t nit = 0, cap = 0;
  int rc = OC_OK;
  if (!cv) {
    rc = oc_seterr(err, OC_ENOMEM, "out of memory (%zu samples)", ns);
    goto done;
  }
  for (size_t c = 0; c < ncurves; c++) {
    const oc_fcurve *fc = curves[c];
    cv[c].fc = fc;
    cv[c].reach =
        attr_max(&fc->attr[FA_RADIUS]) +
        fmax(attr_max(&fc->attr[FA_EXTA]), attr_max(&fc->attr[FA_EXTB])) +
        lv->cell;
    rc = curve_items(fc, (uint32_t)c, lv->cell, cv[c].reach, &it, &nit, &cap,
                     err);
    if (rc) goto done;
  }
  rctx x = {lv,
            x0,
            y0,
            cv,
            it,
            nit,
            lv->map[MAP_H],
            lv->map[MAP_GX],
            lv->map[MAP_GY],
            lv->map[MAP_GD],
            lv->map[MAP_A],
            lv->map[MAP_R],
            cnt,
            cnt + ns,
            cnt + 2 * ns,
            cnt + 3 * ns};
  int nb = (lv->ny + BLOCK - 1) / BLOCK, stop = 0, done = 0;
  size_t nx = (size_t)lv->nx, ss = 0, sl = 0, sc = 0, sn = 0;
  float *maps[MAP_COUNT] = {x.h, x.gx, x.gy, x.gd, x.A, x.R};
  /* each block of rows zeroes its maps and counters (written first:
  ** fresh memory read first faults twice, for the zero page and again
  ** for the copy), paints the items that reach it, then normalises its
  ** rows while they are in cache */
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : ss, sl, sc, sn)
  for (int b = 0; b < nb; b++) {
    int halt;
#pragma omp atomic read
    halt = stop;
    if (halt) continue;
    int j0 = b * BLOCK, j1 = j0 + BLOCK < lv->ny ? j0 + BLOCK : lv->ny;
    size_t k0 = (size_t)j0 * nx, nk = (size_t)(j1 - j0) * nx;
    for (int m = 0; m < MAP_COUNT; m++)
      memset(maps[m] + k0, 0, nk * sizeof(float));
    for (int m = 0; m < 4; m++)
      memset(cnt + (size_t)m * ns + k0, 0, nk * sizeof *cnt);
    double ylo = y0 + j0 * lv->cell, yhi = y0 + (j1 - 1) * lv->cell;
    for (size_t t = 0; t < nit; t++) {
      if (it[t].yhi < ylo || it[t].ylo > yhi) continue;
      for (int j = j0; j < j1; j++)
        paint_row(&x, &it[t], j);
    }
    for (size_t k = k0; k < k0 + nk; k++) {
      normalise(&x, k, lv->flags);
      ss += (lv->flags[k] & DF_H) != 0;
      sl += (lv->flags[k] & DF_SLOPE) != 0;
      sc += (lv->flags[k] & DF_CONFLICT) != 0;
      sn += (lv->flags[k] & DF_NOISE) != 0;
    }
    int d;
#pragma omp atomic capture
    d = ++done;
    /* only the calling thread talks to the callback */
    if (pr.fn && omp_get_thread_num() == 0 && pr.fn(pr.ud, span * d / nb)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (stop) {
    rc = oc_seterr(err, OC_ECANCEL, "diffusion cancelled");
    goto done;
  }
  st->strict = ss, st->slope = sl, st->conflict = sc, st->strict_noise = sn;
done:
  free(it);
  free(cv);
  return rc;
}
