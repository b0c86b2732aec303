/*
** mctable.c — builds the marching cubes case table (see mctable.h).
**
** Rather than a hand-typed table, each case is derived from the rule that
** makes it consistent: on every face of the cube, the crossing edges are
** paired into segments (an ambiguous face separates its inside corners),
** each segment is oriented with the inside on its right seen from outside
** the cube, the segments are chained into closed loops, and each loop is
** triangulated as a fan. The loop orientation then makes every triangle
** counter-clockwise seen from the outside.
*/
#include <pthread.h>
#include <string.h>

#include "mesh/mctable.h"

const uint8_t oc_mc_edge_lo[12] = {0, 2, 4, 6, 0, 1, 4, 5, 0, 1, 2, 3};

static oc_mctable table;
static pthread_once_t once = PTHREAD_ONCE_INIT;

/* The edge joining corners a and b (which differ in one bit). */
static int edge_of(int a, int b) {
  int lo = a < b ? a : b, d = a ^ b;
  int axis = d == 1 ? 0 : d == 2 ? 1 : 2;
  int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  return axis * 4 + ((lo >> u) & 1) + 2 * ((lo >> v) & 1);
}

/* Twice the position of corner c, and of edge e's midpoint. */
static void corner2(int c, int p[3]) {
  for (int a = 0; a < 3; a++)
    p[a] = 2 * ((c >> a) & 1);
}
static void mid2(int e, int p[3]) {
  int lo = oc_mc_edge_lo[e], axis = e / 4;
  corner2(lo, p);
  p[axis] += 1;
}

/* Orients the segment between edges e1 and e2 on the face whose outward
** normal is sgn * axis `fa`, given a reference corner `ref` that lies on
** the inside side when `in` (else on the outside side): stores next[from]
** = to so that the inside lies on the right seen from outside. */
static void orient(int e1, int e2, int ref, int in, int fa, int sgn,
                   int8_t next[12]) {
  int p[3], q[3], r[3];
  mid2(e1, p);
  mid2(e2, q);
  corner2(ref, r);
  int d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  int w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  int c[3] = {d[1] * w[2] - d[2] * w[1], d[2] * w[0] - d[0] * w[2],
              d[0] * w[1] - d[1] * w[0]};
  int side = sgn * c[fa]; /* > 0: ref on the left */
  if ((side < 0) == (in != 0))
    next[e1] = (int8_t)e2;
  else
    next[e2] = (int8_t)e1;
}

static void face_segments(int m, int fa, int s, int8_t next[12]) {
  int u = fa == 0 ? 1 : 0, v = fa == 2 ? 1 : 2;
  static const int cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
  int q[4], in[4], e[4];
  for (int k = 0; k < 4; k++) {
    q[k] = (s << fa) | (cu[k] << u) | (cv[k] << v);
    in[k] = (m >> q[k]) & 1;
  }
  int n = 0, cross[4];
  for (int k = 0; k < 4; k++) {
    e[k] = edge_of(q[k], q[(k + 1) & 3]); /* between corners k and k+1 */
    if (in[k] != in[(k + 1) & 3]) cross[n++] = k;
  }
  int sgn = s ? 1 : -1;
  if (n == 4) { /* ambiguous: cut off each inside corner on its own */
    for (int k = 0; k < 4; k++)
      if (in[k]) orient(e[(k + 3) & 3], e[k], q[k], 1, fa, sgn, next);
  } else if (n == 2) {
    int a = cross[0], b = cross[1];
    if (b - a == 1 || b - a == 3) { /* adjacent edges: cut off their corner */
      int c = b - a == 1 ? b : a;   /* corner shared by edges a and b */
      orient(e[a], e[b], q[c], in[c], fa, sgn, next);
    } else { /* opposite edges: any inside corner is on the inside side */
      int c = in[0] ? 0 : in[1] ? 1 : 2;
      orient(e[a], e[b], q[c], 1, fa, sgn, next);
    }
  }
}

/* 1 when edges a and b lie on a common face of the cube. */
static int share_face(int a, int b) {
  int pa[3], pb[3];
  mid2(a, pa);
  mid2(b, pb);
  for (int k = 0; k < 3; k++)
    if (pa[k] == pb[k] && pa[k] != 1) return 1;
  return 0;
}

/* Triangulates loop[0 .. n) into t, using no diagonal between two edges
** on a common face: the neighbouring cube may join the same two vertices
** too, and the edge would then belong to four triangles. Loop edges
** themselves are the face segments, shared by exactly the two cubes.
** Clips ears, backtracking when a choice leads to a dead end. Returns the
** number of triangles, or -1. */
static int triangulate(const int *loop, int n, uint8_t *t) {
  if (n == 3) {
    for (int k = 0; k < 3; k++)
      t[k] = (uint8_t)loop[k];
    return 1;
  }
  for (int i = 0; i < n; i++) {
    int a = loop[(i + n - 1) % n], b = loop[i], c = loop[(i + 1) % n];
    if (share_face(a, c)) continue;
    int rest[12], m = 0;
    for (int k = 1; k < n; k++) /* keep the loop's order from c */
      rest[m++] = loop[(i + k) % n];
    int r = triangulate(rest, m, t + 3);
    if (r < 0) continue;
    t[0] = (uint8_t)a;
    t[1] = (uint8_t)b;
    t[2] = (uint8_t)c;
    return r + 1;
  }
  return -1;
}

static int build_case(int m) {
  int8_t next[12];
  memset(next, -1, sizeof next);
  for (int fa = 0; fa < 3; fa++)
    for (int s = 0; s < 2; s++)
      face_segments(m, fa, s, next);
  int seen[12] = {0}, nt = 0;
  for (int e0 = 0; e0 < 12; e0++) {
    if (next[e0] < 0 || seen[e0]) continue;
    int loop[12], n = 0;
    for (int e = e0; e >= 0 && !seen[e]; e = next[e]) {
      seen[e] = 1;
      loop[n++] = e;
    }
    int r = triangulate(loop, n, table.tri[m] + 3 * nt);
    if (r < 0 || nt + r > OC_MC_MAXTRI) return -1;
    nt += r;
  }
  table.ntri[m] = (uint8_t)nt;
  return 0;
}

static void build(void) {
  for (int m = 0; m < 256; m++)
    if (build_case(m)) table.ntri[m] = 0; /* never: see test_polygonize */
}

const oc_mctable *oc_mctable_get(void) {
  pthread_once(&once, build);
  return &table;
}
