/*
** authored.c — blocks placed by the user inside a fracture tile (Paris et
** al. 2020, section 4.1 and figure 6: "user-defined fractures and blocks").
**
** An authored block is the convex hull of given points, or the
** intersection of given half-spaces (bounded: the normals must surround
** the origin; its vertices are the feasible intersections of three
** planes). It is moved by a multiple of s so that its centroid lies in
** the tile, like a cluster, and must be less than s - 2 k r across (it
** must not meet its own periodic images). Then, with its periodic images:
**  - the tile's points inside it, or less than r / 2 outside its faces,
**    are removed (the half gap leaves a joint like the others);
**  - edges of the neighbour graph whose segment crosses it are cut, so no
**    cluster grows through it;
**  - a generated block whose hull still reaches into it (a cluster grown
**    around it) is cut back by the face of the authored block that
**    leaves the most of it;
**  - it becomes a block of the tile itself, after the generated ones.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "core/error.h"

#define MAX_AUTHORED 1000
#define MAX_POINTS 100000
#define MAX_PLANES 64

/* Corners of the three planes i, j, k of pl (unit normals) inside all. */
static int corner(const double *pl, size_t n, size_t i, size_t j, size_t k,
                  double *x) {
  const double *a = pl + 4 * i, *b = pl + 4 * j, *c = pl + 4 * k;
  /* x = -(d_a (b x c) + d_b (c x a) + d_c (a x b)) / (a . (b x c)) */
  double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2],
                  b[0] * c[1] - b[1] * c[0]};
  double ca[3] = {c[1] * a[2] - c[2] * a[1], c[2] * a[0] - c[0] * a[2],
                  c[0] * a[1] - c[1] * a[0]};
  double ab[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                  a[0] * b[1] - a[1] * b[0]};
  double det = a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2];
  if (fabs(det) < 1e-9) return 0;
  for (int q = 0; q < 3; q++)
    x[q] = -(a[3] * bc[q] + b[3] * ca[q] + c[3] * ab[q]) / det;
  double scale = 1 + fabs(x[0]) + fabs(x[1]) + fabs(x[2]);
  for (size_t m = 0; m < n; m++) {
    const double *h = pl + 4 * m;
    if (h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + h[3] > 1e-9 * scale) return 0;
  }
  return 1;
}

/* The shape's points: given, or the corners of its planes (bounded when
** the origin is inside the hull of the normals). A new array in *out. */
static int shape_points(const oc_block_shape *sh, size_t i, double **out,
                        size_t *n, oc_error *err) {
  *out = NULL;
  *n = 0;
  if (sh->npoints) {
    if (sh->npoints < 4 || sh->npoints > MAX_POINTS || !sh->points)
      return oc_seterr(err, OC_EINVAL,
                       "'blocks[%zu].points' must hold 4 .. %d points (got "
                       "%zu)",
                       i + 1, MAX_POINTS, sh->npoints);
    for (size_t k = 0; k < 3 * sh->npoints; k++)
      if (!isfinite(sh->points[k]))
        return oc_seterr(err, OC_EINVAL,
                         "'blocks[%zu].points[%zu]' must be finite", i + 1,
                         k / 3 + 1);
    *out = malloc(3 * sh->npoints * sizeof **out);
    if (!*out) return oc_seterr(err, OC_ENOMEM, "out of memory");
    memcpy(*out, sh->points, 3 * sh->npoints * sizeof **out);
    *n = sh->npoints;
    return 0;
  }
  size_t np = sh->nplanes;
  if (np < 4 || np > MAX_PLANES || !sh->planes)
    return oc_seterr(err, OC_EINVAL,
                     "'blocks[%zu]' needs 'points' (4 or more) or 'planes' "
                     "(4 .. %d, got %zu)",
                     i + 1, MAX_PLANES, np);
  double pl[4 * MAX_PLANES], nrm[3 * MAX_PLANES];
  for (size_t k = 0; k < np; k++) {
    const double *h = sh->planes + 4 * k;
    double l = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    if (!(l > 1e-12) || !isfinite(l) || !isfinite(h[3]))
      return oc_seterr(err, OC_EINVAL,
                       "'blocks[%zu].planes[%zu]' must be finite with a "
                       "non-zero normal",
                       i + 1, k + 1);
    for (int q = 0; q < 4; q++)
      pl[4 * k + q] = h[q] / l;
    for (int q = 0; q < 3; q++)
      nrm[3 * k + q] = pl[4 * k + q];
  }
  /* bounded: the origin strictly inside the hull of the unit normals */
  oc_bblock nb = {0};
  int h = oc_bhull_points(nrm, np, &nb);
  int bounded = h == 0;
  for (size_t k = 0; bounded && k < nb.nplane; k++)
    bounded = nb.plane[4 * k + 3] < -1e-9;
  oc_bblock_free(&nb);
  if (h == OC_ENOMEM) return oc_seterr(err, OC_ENOMEM, "out of memory");
  if (!bounded)
    return oc_seterr(err, OC_EINVAL,
                     "'blocks[%zu].planes' do not bound a block (their "
                     "normals must point all round)",
                     i + 1);
  size_t cap = 64;
  double *x = malloc(3 * cap * sizeof *x);
  if (!x) return oc_seterr(err, OC_ENOMEM, "out of memory");
  for (size_t a = 0; a < np; a++)
    for (size_t b = a + 1; b < np; b++)
      for (size_t c = b + 1; c < np; c++) {
        if (*n == cap) {
          double *y = realloc(x, 6 * cap * sizeof *x);
          if (!y) {
            free(x);
            return oc_seterr(err, OC_ENOMEM, "out of memory");
          }
          x = y;
          cap *= 2;
        }
        if (corner(pl, np, a, b, c, x + 3 * *n)) ++*n;
      }
  *out = x;
  return 0;
}

static void shift_block(oc_bblock *b, const double *sh) {
  for (size_t v = 0; v < b->nvert; v++)
    for (int a = 0; a < 3; a++)
      b->vert[3 * v + a] += sh[a];
  for (size_t k = 0; k < b->nplane; k++) {
    double *h = b->plane + 4 * k;
    h[3] -= h[0] * sh[0] + h[1] * sh[1] + h[2] * sh[2];
  }
}

int oc_bauthored_make(oc_btile *t, oc_error *err) {
  const oc_btile_params *pp = &t->pp;
  double s = pp->size, most = s - 2 * pp->neighbour * pp->radius;
  if (!pp->nblocks) return 0;
  if (!pp->blocks || pp->nblocks > MAX_AUTHORED)
    return oc_seterr(err, OC_EINVAL, "'blocks': 1 .. %d authored blocks",
                     MAX_AUTHORED);
  t->auth = calloc(pp->nblocks, sizeof *t->auth);
  if (!t->auth) return oc_seterr(err, OC_ENOMEM, "out of memory");
  for (size_t i = 0; i < pp->nblocks; i++) {
    double *x;
    size_t n;
    if (shape_points(&pp->blocks[i], i, &x, &n, err)) return OC_EINVAL;
    oc_bblock *b = &t->auth[t->nauth];
    int h = oc_bhull_points(x, n, b);
    free(x);
    if (h == OC_ENOMEM) return oc_seterr(err, OC_ENOMEM, "out of memory");
    t->nauth++;
    if (h)
      return oc_seterr(err, OC_EINVAL, "'blocks[%zu]' is flat (no volume)",
                       i + 1);
    oc_bblock_measure(b);
    double ext[3] = {b->box.hi.x - b->box.lo.x, b->box.hi.y - b->box.lo.y,
                     b->box.hi.z - b->box.lo.z};
    if (!(ext[0] < most && ext[1] < most && ext[2] < most))
      return oc_seterr(err, OC_EINVAL,
                       "'blocks[%zu]' is %g x %g x %g: it must be less than "
                       "size - 2 neighbour radius = %g across",
                       i + 1, ext[0], ext[1], ext[2], most);
    double g[3] = {0, 0, 0}, sh[3];
    for (size_t v = 0; v < b->nvert; v++)
      for (int a = 0; a < 3; a++)
        g[a] += b->vert[3 * v + a] / (double)b->nvert;
    for (int a = 0; a < 3; a++) {
      sh[a] = -s * floor(g[a] / s);
      g[a] += sh[a];
    }
    shift_block(b, sh);
    oc_bblock_measure(b);
    b->centroid = (oc_vec3){g[0], g[1], g[2]};
    b->npts = 0;
  }
  return 0;
}

/* The largest h(p - sh) over b's planes (<= 0 inside). */
static double depth(const oc_bblock *b, const double *p, const double *sh) {
  double m = -INFINITY;
  for (size_t k = 0; k < b->nplane; k++) {
    const double *h = b->plane + 4 * k;
    m = fmax(m, h[0] * (p[0] - sh[0]) + h[1] * (p[1] - sh[1]) +
                    h[2] * (p[2] - sh[2]) + h[3]);
  }
  return m;
}

static void image(int k, double s, double *sh) {
  sh[0] = (k % 3 - 1) * s;
  sh[1] = (k / 3 % 3 - 1) * s;
  sh[2] = (k / 9 - 1) * s;
}

/* Does the box of b, shifted by sh and grown by g, hold p? */
static int near_box(const oc_bblock *b, const double *sh, double g,
                    const double *p) {
  return p[0] >= b->box.lo.x + sh[0] - g && p[0] <= b->box.hi.x + sh[0] + g &&
         p[1] >= b->box.lo.y + sh[1] - g && p[1] <= b->box.hi.y + sh[1] + g &&
         p[2] >= b->box.lo.z + sh[2] - g && p[2] <= b->box.hi.z + sh[2] + g;
}

void oc_bauthored_points(oc_btile *t) {
  double s = t->pp.size, gap = 0.5 * t->pp.radius;
  size_t m = 0;
  for (size_t i = 0; i < t->np; i++) {
    const double *p = t->pts + 3 * i;
    int out = 1;
    for (size_t a = 0; a < t->nauth && out; a++)
      for (int k = 0; k < 27 && out; k++) {
        double sh[3];
        image(k, s, sh);
        if (near_box(&t->auth[a], sh, gap, p))
          out = depth(&t->auth[a], p, sh) >= gap;
      }
    if (out) {
      memmove(t->pts + 3 * m, p, 3 * sizeof *p);
      m++;
    }
  }
  t->np = m;
}

/* Does segment [p, q] meet the hull of b shifted by sh? (Clips the
** parameter interval by each half-space.) */
static int crosses(const oc_bblock *b, const double *sh, const double *p,
                   const double *q) {
  double t0 = 0, t1 = 1;
  for (size_t k = 0; k < b->nplane && t0 <= t1; k++) {
    const double *h = b->plane + 4 * k;
    double a = h[0] * (p[0] - sh[0]) + h[1] * (p[1] - sh[1]) +
               h[2] * (p[2] - sh[2]) + h[3];
    double d =
        h[0] * (q[0] - p[0]) + h[1] * (q[1] - p[1]) + h[2] * (q[2] - p[2]);
    /* a + t d <= 0 */
    if (d == 0) {
      if (a > 0) return 0;
    } else if (d > 0) {
      t1 = fmin(t1, -a / d);
    } else {
      t0 = fmax(t0, -a / d);
    }
  }
  return t0 <= t1;
}

void oc_bauthored_cut(oc_btile *t) {
  oc_bgraph *g = &t->g;
  double s = t->pp.size, reach = t->pp.neighbour * t->pp.radius;
  for (size_t e = 0; e < g->ne; e++) {
    if (g->cut[e]) continue;
    const double *p = t->pts + 3 * (size_t)g->a[e];
    double q[3] = {p[0] + g->v[3 * e], p[1] + g->v[3 * e + 1],
                   p[2] + g->v[3 * e + 2]};
    for (size_t a = 0; a < t->nauth && !g->cut[e]; a++)
      for (int k = 0; k < 27 && !g->cut[e]; k++) {
        double sh[3];
        image(k, s, sh);
        if (near_box(&t->auth[a], sh, reach, p) &&
            crosses(&t->auth[a], sh, p, q))
          g->cut[e] = 1;
      }
  }
}

/* The least h(v) over B's vertices for A's plane k shifted by sh. */
static double least(const oc_bblock *A, size_t k, const double *sh,
                    const oc_bblock *B) {
  const double *h = A->plane + 4 * k;
  double o = h[3] - (h[0] * sh[0] + h[1] * sh[1] + h[2] * sh[2]), m = INFINITY;
  for (size_t v = 0; v < B->nvert; v++) {
    const double *x = B->vert + 3 * v;
    m = fmin(m, h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + o);
  }
  return m;
}

static int boxes_meet(const oc_aabb *a, const oc_aabb *b, const double *sh) {
  return a->lo.x <= b->hi.x + sh[0] && b->lo.x + sh[0] <= a->hi.x &&
         a->lo.y <= b->hi.y + sh[1] && b->lo.y + sh[1] <= a->hi.y &&
         a->lo.z <= b->hi.z + sh[2] && b->lo.z + sh[2] <= a->hi.z;
}

/* Cuts generated block B back from authored block A's image at sh. */
static int cut_back(oc_bblock *B, const oc_bblock *A, const double *sh) {
  double best = -INFINITY;
  size_t bk = 0;
  for (size_t k = 0; k < A->nplane; k++) {
    double m = least(A, k, sh, B);
    if (m > best) best = m, bk = k;
  }
  if (best >= 0) return 0; /* a face of A separates them */
  double nsh[3] = {-sh[0], -sh[1], -sh[2]};
  for (size_t k = 0; k < B->nplane; k++)
    if (least(B, k, nsh, A) >= 0) return 0; /* a face of B does */
  double *p = realloc(B->plane, 4 * (B->nplane + 1) * sizeof *p);
  if (!p) return OC_ENOMEM;
  B->plane = p;
  const double *h = A->plane + 4 * bk;
  double *c = p + 4 * B->nplane++;
  c[0] = -h[0], c[1] = -h[1], c[2] = -h[2];
  c[3] = -(h[3] - (h[0] * sh[0] + h[1] * sh[1] + h[2] * sh[2]));
  return 0;
}

int oc_bauthored_finish(oc_btile *t, oc_error *err) {
  double s = t->pp.size;
  if (!t->nauth) return 0;
  for (size_t i = 0; i < t->nb; i++)
    for (size_t a = 0; a < t->nauth; a++)
      for (int k = 0; k < 27; k++) {
        double sh[3];
        image(k, s, sh);
        if (boxes_meet(&t->block[i].box, &t->auth[a].box, sh) &&
            cut_back(&t->block[i], &t->auth[a], sh))
          return oc_seterr(err, OC_ENOMEM, "out of memory for block cuts");
      }
  /* t->block holds ncl entries, nb of them blocks: make room after them */
  oc_bblock *nbk = realloc(t->block, (t->ncl + t->nauth) * sizeof *t->block);
  if (!nbk) return oc_seterr(err, OC_ENOMEM, "out of memory for blocks");
  t->block = nbk;
  memmove(t->block + t->nb + t->nauth, t->block + t->nb,
          (t->ncl - t->nb) * sizeof *t->block);
  for (size_t a = 0; a < t->nauth; a++) {
    t->block[t->nb + a] = t->auth[a];
    memset(&t->auth[a], 0, sizeof t->auth[a]);
  }
  t->nb += t->nauth;
  t->ncl += t->nauth;
  return 0;
}
