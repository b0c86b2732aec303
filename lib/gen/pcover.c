/*
** pcover.c — is a box covered by disks (balls) of radius r?
**
** A point is covered when its nearest sample is within r. Inside the
** box, the points whose nearest sample is s_i form a convex polytope (the
** box cut by the bisectors of s_i and the others), on which the distance
** to s_i is convex: it peaks at a vertex. So the distance to the nearest
** sample peaks over the box at a vertex of the box cut by the Voronoi
** diagram, a point equidistant from s + 1 samples lying on d - s faces of
** the box. The test visits every such point, and the box is covered when
** none is open; points that are not true vertices are still points of
** the box, so visiting them does no harm. Samples that cannot matter are
** dropped first: those farther than r from the box, and those another
** sample is nearer to everywhere in the box; what remains is a handful,
** fewer as the boxes get smaller.
*/
#include <math.h>

#include "gen/poisson.h"

#define MAXNB (OC_PREACH * OC_PREACH * OC_PREACH)

typedef struct cover {
  int d, m;
  double e[3]; /* half sides; the box is centred */
  double t[OC_PCOVER_MAX][3], tn2[OC_PCOVER_MAX]; /* samples, |t|^2 */
  double rc2, eps, tiny; /* slack of "inside", smallest pivot */
} cover;

/* Solves the s x s system m y = v (s <= 3) by Gaussian elimination with
** partial pivoting; returns 0 when it is (nearly) singular. */
static int solve(int s, double m[3][3], double v[3], double y[3], double tiny) {
  for (int c = 0; c < s; c++) {
    int p = c;
    for (int r = c + 1; r < s; r++)
      if (fabs(m[r][c]) > fabs(m[p][c])) p = r;
    if (!(fabs(m[p][c]) > tiny)) return 0;
    if (p != c) {
      for (int k = 0; k < s; k++) {
        double t = m[c][k];
        m[c][k] = m[p][k], m[p][k] = t;
      }
      double t = v[c];
      v[c] = v[p], v[p] = t;
    }
    for (int r = c + 1; r < s; r++) {
      double f = m[r][c] / m[c][c];
      for (int k = c; k < s; k++)
        m[r][k] -= f * m[c][k];
      v[r] -= f * v[c];
    }
  }
  for (int c = s - 1; c >= 0; c--) {
    double t = v[c];
    for (int k = c + 1; k < s; k++)
      t -= m[c][k] * y[k];
    y[c] = t / m[c][c];
  }
  return 1;
}

/* Is x (inside the box, give or take eps) farther than rc from every
** sample? Sample `first` is tried first: x is equidistant from it and a
** few others, and most often it settles the question. */
static int open_at(const cover *C, const double *x, int first) {
  const double *t0 = C->t[first];
  double d2 = 0;
  for (int k = 0; k < C->d; k++)
    if (fabs(x[k]) > C->e[k] + C->eps) return 0;
  for (int k = 0; k < C->d; k++)
    d2 += (x[k] - t0[k]) * (x[k] - t0[k]);
  if (d2 <= C->rc2) return 0;
  for (int i = 0; i < C->m; i++) {
    d2 = 0;
    for (int k = 0; k < C->d; k++)
      d2 += (x[k] - C->t[i][k]) * (x[k] - C->t[i][k]);
    if (d2 <= C->rc2) return 0;
  }
  return 1;
}

/* The points equidistant from the s + 1 samples in `set` (their first
** sample's bisectors with the others) that lie on the box's faces of the
** other d - s axes: is one of them open? */
static int open_on(const cover *C, const int *set, int s) {
  int d = C->d;
  const double *t0 = C->t[set[0]];
  double a[3][3], b[3];
  for (int r = 0; r < s; r++) {
    const double *tj = C->t[set[r + 1]];
    for (int k = 0; k < d; k++)
      a[r][k] = 2 * (tj[k] - t0[k]);
    b[r] = C->tn2[set[r + 1]] - C->tn2[set[0]];
  }
  for (unsigned fix = 0; fix < (1u << d); fix++) {
    static const int bits[8] = {0, 1, 1, 2, 1, 2, 2, 3};
    if (bits[fix] != d - s) continue;
    int freeax[3], nf = 0;
    for (int k = 0; k < d; k++)
      if (!(fix & (1u << k))) freeax[nf++] = k;
    for (unsigned sg = 0; sg < (1u << d); sg++) {
      if (sg & ~fix) continue; /* signs only on the fixed axes */
      double x[3] = {0, 0, 0}, m[3][3], v[3], y[3];
      for (int k = 0; k < d; k++)
        if (fix & (1u << k)) x[k] = (sg & (1u << k)) ? C->e[k] : -C->e[k];
      for (int r = 0; r < s; r++) {
        v[r] = b[r];
        for (int k = 0; k < d; k++)
          if (fix & (1u << k)) v[r] -= a[r][k] * x[k];
        for (int c = 0; c < s; c++)
          m[r][c] = a[r][freeax[c]];
      }
      if (s > 0 && !solve(s, m, v, y, C->tiny)) continue;
      for (int c = 0; c < s; c++)
        x[freeax[c]] = y[c];
      if (open_at(C, x, set[0])) return 1;
    }
  }
  return 0;
}

/* Coverage of the box [lo, hi] by the n samples nb (absolute
** coordinates); boxes that more than `max` samples matter to are split,
** `depth` more times at most. */
static int cover_box(int d, double r, const double *lo, const double *hi,
                     const double *nb, int n, int max, int depth) {
  double ctr[3] = {0, 0, 0}, rc = r * (1 + OC_PCOVER_TOL), r2 = r * r;
  cover C;
  C.d = d;
  C.rc2 = rc * rc;
  C.eps = 1e-13 * r;
  C.tiny = 1e-12 * r;
  for (int k = 0; k < d; k++) {
    ctr[k] = 0.5 * (lo[k] + hi[k]);
    C.e[k] = 0.5 * (hi[k] - lo[k]);
  }
  /* Positions relative to the centre of the samples that reach into the
  ** box; a sample whose disk holds the whole box settles it. */
  double t[MAXNB][3], tn2[MAXNB];
  int src[MAXNB], m = 0;
  for (int j = 0; j < n && j < MAXNB; j++) {
    const double *s = nb + (size_t)d * (size_t)j;
    double dmax2 = 0, dmin2 = 0, n2 = 0;
    for (int k = 0; k < d; k++) {
      double u = s[k] - ctr[k], au = fabs(u), v = au - C.e[k];
      t[m][k] = u;
      n2 += u * u;
      dmax2 += (au + C.e[k]) * (au + C.e[k]);
      if (v > 0) dmin2 += v * v;
    }
    if (dmax2 <= C.rc2) return 1;
    if (dmin2 < r2) src[m] = j, tn2[m++] = n2;
  }
  if (m == 0) return 0;
  /* Drop the samples another one is nearer to throughout the box: for x
  ** in the box, |x - ti|^2 - |x - tj|^2 = -2 x.(ti - tj) + |ti|^2 - |tj|^2,
  ** largest at a corner. Nearness is transitive, so dropping in any order
  ** keeps the nearest sample of every point. */
  int keep[MAXNB], nk = 0;
  for (int j = 0; j < m; j++) {
    int dominated = 0;
    for (int i = 0; i < m && !dominated; i++) {
      if (i == j) continue;
      double q = tn2[i] - tn2[j];
      for (int k = 0; k < d; k++)
        q += 2 * C.e[k] * fabs(t[i][k] - t[j][k]);
      dominated = q < 0;
    }
    if (!dominated) keep[nk++] = j;
  }
  /* One sample nearest everywhere, and its disk does not hold the box. */
  if (nk == 1) return 0;
  if (nk > max) {
    /* Split: each part meets fewer of these samples. */
    double sub[MAXNB * 3], clo[3], chi[3];
    if (depth == 0) return 0;
    for (int j = 0; j < nk; j++)
      for (int k = 0; k < d; k++)
        sub[d * j + k] = nb[(size_t)d * (size_t)src[keep[j]] + (size_t)k];
    for (unsigned b = 0; b < (1u << d); b++) {
      for (int k = 0; k < d; k++) {
        clo[k] = (b >> k) & 1 ? ctr[k] : lo[k];
        chi[k] = (b >> k) & 1 ? hi[k] : ctr[k];
      }
      if (!cover_box(d, r, clo, chi, sub, nk, max, depth - 1)) return 0;
    }
    return 1;
  }
  C.m = nk;
  for (int j = 0; j < nk; j++) {
    for (int k = 0; k < 3; k++)
      C.t[j][k] = k < d ? t[keep[j]][k] : 0;
    C.tn2[j] = tn2[keep[j]];
  }
  /* The farthest point from the samples is a vertex of the box cut by
  ** their Voronoi diagram: equidistant from s + 1 samples and on d - s
  ** faces of the box. */
  int set[4] = {0, 0, 0, 0};
  if (open_on(&C, set, 0)) return 0;
  for (set[0] = 0; set[0] < C.m; set[0]++)
    for (set[1] = set[0] + 1; set[1] < C.m; set[1]++) {
      if (open_on(&C, set, 1)) return 0;
      for (set[2] = set[1] + 1; set[2] < C.m; set[2]++) {
        if (open_on(&C, set, 2)) return 0;
        if (d < 3) continue;
        for (set[3] = set[2] + 1; set[3] < C.m; set[3]++)
          if (open_on(&C, set, 3)) return 0;
      }
    }
  return 1;
}

int oc_pcover(int d, double r, const double *lo, const double *hi,
              const double *nb, int n, int max, int depth) {
  if (max > OC_PCOVER_MAX) max = OC_PCOVER_MAX;
  return cover_box(d, r, lo, hi, nb, n, max, depth);
}
