/*
** test_polygonize.c — oc_polygonize on the in-memory mesh: closed,
** manifold, consistently and outwardly oriented, no duplicate vertices nor
** degenerate triangles; Euler characteristics (sphere, ring, box, capped
** half-space, sphere crossing the box, open surface); the volume of a
** point primitive's iso-surface; vertices on the surface and normals along
** the gradient; every case of the table, alone and in random patterns;
** surface bounds against the full grid; byte-identical output for 1 and 2
** threads; parameter checks, absurd sizes and cancellation.
**
** The mesh checks below are written from the mesh arrays alone, not from
** the mesher's internals.
*/
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ocheck.h"
#include "outcrop.h"

#define PI 3.14159265358979323846

/* ---- building and meshing ---------------------------------------------- */

static oc_aabb box3(double x0, double y0, double z0, double x1, double y1,
                    double z1) {
  oc_aabb b = {{x0, y0, z0}, {x1, y1, z1}};
  return b;
}

static oc_polygonize_params params(oc_aabb box, double cell) {
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = box;
  pp.cell = cell;
  return pp;
}

static oc_mesh *mesh_ok(const oc_program *pr, const oc_polygonize_params *pp) {
  oc_error e = {0};
  oc_mesh *m = oc_polygonize(pr, pp, &e);
  ck_assert_msg(m != NULL, "oc_polygonize: %s", e.msg);
  return m;
}

static oc_program *point_prog(oc_vec3 c, double R, double E) {
  oc_error e;
  return oct_compile(OCT_OK(oc_point(c, R, E, &e)), 0, 0);
}

/* Radius of the iso-surface E g(r / R) = T of a point primitive. */
static double iso_radius(double R, double E, double T) {
  return R * sqrt(1 - cbrt(T / E));
}

/* ---- mesh checks --------------------------------------------------------- */

typedef struct edge {
  uint32_t a, b; /* a < b */
  int dir;       /* +1: a -> b in its triangle, -1: b -> a */
} edge;

static int cmp_edge(const void *x, const void *y) {
  const edge *p = x, *q = y;
  if (p->a != q->a) return p->a < q->a ? -1 : 1;
  if (p->b != q->b) return p->b < q->b ? -1 : 1;
  return p->dir - q->dir;
}

static int cmp_pos(const void *x, const void *y) {
  const float *p = x, *q = y;
  for (int k = 0; k < 3; k++)
    if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
  return 0;
}

static int on_box_face(oc_aabb b, const float *p) {
  const double lo[3] = {b.lo.x, b.lo.y, b.lo.z},
               hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  for (int a = 0; a < 3; a++)
    if (p[a] == (float)lo[a] || p[a] == (float)hi[a]) return 1;
  return 0;
}

typedef struct meshinfo {
  size_t nv, nt, ne, boundary;
  long euler;
  double volume; /* signed, from the orientation */
} meshinfo;

/* Asserts the structural properties; `closed` demands every edge shared
** by exactly two triangles, otherwise edges used once must join vertices
** on the box's faces. Also: indices in range, no unused vertex, no
** duplicate position, no zero-area triangle, finite unit normals. */
static meshinfo check_mesh(const oc_mesh *m, int closed, oc_aabb box) {
  meshinfo in = {0};
  size_t nv = oc_mesh_vertex_count(m), nt = oc_mesh_triangle_count(m);
  const float *P = oc_mesh_positions(m), *N = oc_mesh_normals(m);
  const uint32_t *I = oc_mesh_indices(m);
  in.nv = nv;
  in.nt = nt;
  ck_assert_msg(nt > 0, "empty mesh");
  /* duplicates */
  float *sp = malloc(nv * 3 * sizeof *sp);
  memcpy(sp, P, nv * 3 * sizeof *sp);
  qsort(sp, nv, 3 * sizeof *sp, cmp_pos);
  for (size_t v = 1; v < nv; v++)
    ck_assert_msg(cmp_pos(sp + 3 * (v - 1), sp + 3 * v) != 0,
                  "duplicate vertex at %g %g %g", sp[3 * v], sp[3 * v + 1],
                  sp[3 * v + 2]);
  free(sp);
  for (size_t v = 0; v < nv; v++) {
    double l = 0;
    for (int k = 0; k < 3; k++) {
      ck_assert(isfinite(P[3 * v + k]) && isfinite(N[3 * v + k]));
      l += (double)N[3 * v + k] * N[3 * v + k];
    }
    ck_assert_msg(fabs(l - 1) < 1e-5, "normal of length %g", sqrt(l));
  }
  /* triangles: range, area, volume, edges */
  char *used = calloc(nv, 1);
  edge *E = malloc(3 * nt * sizeof *E);
  double cx = 0.5 * (box.lo.x + box.hi.x), cy = 0.5 * (box.lo.y + box.hi.y),
         cz = 0.5 * (box.lo.z + box.hi.z);
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *v = I + 3 * t;
    for (int k = 0; k < 3; k++) {
      ck_assert_uint_lt(v[k], nv);
      used[v[k]] = 1;
    }
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; k++) {
      a[k] = P[3 * v[0] + k];
      b[k] = P[3 * v[1] + k];
      c[k] = P[3 * v[2] + k];
    }
    a[0] -= cx, b[0] -= cx, c[0] -= cx;
    a[1] -= cy, b[1] -= cy, c[1] -= cy;
    a[2] -= cz, b[2] -= cz, c[2] -= cz;
    oc_vec3 A = oct_v(a[0], a[1], a[2]), Bv = oct_v(b[0], b[1], b[2]),
            C = oct_v(c[0], c[1], c[2]);
    oc_vec3 n = oct_cross(oct_sub(Bv, A), oct_sub(C, A));
    ck_assert_msg(oct_len(n) > 0, "degenerate triangle %zu", t);
    in.volume += oct_dot(A, oct_cross(Bv, C)) / 6;
    for (int k = 0; k < 3; k++) {
      uint32_t p = v[k], q = v[(k + 1) % 3];
      ck_assert_msg(p != q, "triangle %zu repeats a vertex", t);
      E[3 * t + k].a = p < q ? p : q;
      E[3 * t + k].b = p < q ? q : p;
      E[3 * t + k].dir = p < q ? 1 : -1;
    }
  }
  for (size_t v = 0; v < nv; v++)
    ck_assert_msg(used[v], "vertex %zu unused", v);
  free(used);
  qsort(E, 3 * nt, sizeof *E, cmp_edge);
  for (size_t i = 0; i < 3 * nt;) {
    size_t j = i;
    while (j < 3 * nt && E[j].a == E[i].a && E[j].b == E[i].b)
      j++;
    in.ne++;
    if (j - i == 1) {
      in.boundary++;
      ck_assert_msg(!closed, "edge %u-%u used once (crack)", E[i].a, E[i].b);
      ck_assert_msg(on_box_face(box, P + 3 * E[i].a) &&
                        on_box_face(box, P + 3 * E[i].b),
                    "open edge %u-%u off the box faces", E[i].a, E[i].b);
    } else {
      ck_assert_msg(j - i == 2, "edge %u-%u shared by %zu triangles", E[i].a,
                    E[i].b, j - i);
      ck_assert_msg(E[i].dir != E[i + 1].dir,
                    "edge %u-%u has the same direction in both triangles",
                    E[i].a, E[i].b);
    }
    i = j;
  }
  free(E);
  in.euler = (long)nv - (long)in.ne + (long)nt;
  return in;
}

/* The fraction of triangles whose face normal agrees with the mean of
** their vertices' normals (gradient normals point the same way as the
** orientation where the surface is smooth). Triangles touching the box
** faces are left out: the caps have the faces' normals, and the
** half-cell skirt between the surface and a face may fold. */
static double normal_agreement(const oc_mesh *m, oc_aabb box) {
  const float *P = oc_mesh_positions(m), *N = oc_mesh_normals(m);
  const uint32_t *I = oc_mesh_indices(m);
  size_t nt = oc_mesh_triangle_count(m), good = 0, seen = 0;
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *v = I + 3 * t;
    oc_vec3 a = oct_v(P[3 * v[0]], P[3 * v[0] + 1], P[3 * v[0] + 2]);
    oc_vec3 b = oct_v(P[3 * v[1]], P[3 * v[1] + 1], P[3 * v[1] + 2]);
    oc_vec3 c = oct_v(P[3 * v[2]], P[3 * v[2] + 1], P[3 * v[2] + 2]);
    oc_vec3 f = oct_cross(oct_sub(b, a), oct_sub(c, a));
    oc_vec3 s = oct_v(0, 0, 0);
    for (int k = 0; k < 3; k++)
      s = oct_add(s, oct_v(N[3 * v[k]], N[3 * v[k] + 1], N[3 * v[k] + 2]));
    if (on_box_face(box, P + 3 * v[0]) || on_box_face(box, P + 3 * v[1]) ||
        on_box_face(box, P + 3 * v[2]))
      continue;
    seen++;
    good += oct_dot(f, s) > 0;
  }
  ck_assert(seen > 0);
  return (double)good / (double)seen;
}

static void expect_fail(const oc_program *pr, const oc_polygonize_params *pp,
                        oc_status code, const char *word);

/* ---- shapes ------------------------------------------------------------ */

START_TEST(sphere_closed_volume) {
  /* cell = R / 20: the enclosed volume within 1 % of the iso-sphere's */
  const double R = 2, E = 1, T = 0.5;
  oc_vec3 c = oct_v(0.3, -0.2, 0.1);
  oc_program *pr = point_prog(c, R, E);
  oc_aabb box = box3(-2.5, -2.5, -2.5, 2.5, 2.5, 2.5);
  oc_polygonize_params pp = params(box, R / 20);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  double r = iso_radius(R, E, T), want = 4.0 / 3.0 * PI * r * r * r;
  ck_assert_msg(fabs(in.volume - want) < 0.01 * want,
                "volume %g, iso-sphere %g", in.volume, want);
  ck_assert_msg(in.volume > 0.99 * want, "orientation: volume %g", in.volume);
  /* vertices on the sphere (root finding), normals radial and outward */
  const float *P = oc_mesh_positions(m), *N = oc_mesh_normals(m);
  double worst = 0, worstn = 0;
  for (size_t v = 0; v < in.nv; v++) {
    oc_vec3 p = oct_v(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
    oc_vec3 d = oct_sub(p, c);
    worst = fmax(worst, fabs(oct_len(d) - r));
    oc_vec3 u = oct_mul(d, 1 / oct_len(d));
    worstn = fmax(worstn,
                  1 - oct_dot(u, oct_v(N[3 * v], N[3 * v + 1], N[3 * v + 2])));
    ck_assert(fabs(oc_program_eval(pr, p) - T) < 1e-5);
  }
  ck_assert_msg(worst < 1e-5, "vertex %g off the iso-sphere", worst);
  ck_assert_msg(worstn < 1e-6, "normal off the radial direction (%g)", worstn);
  ck_assert(normal_agreement(m, box) == 1.0);
  /* more steps: closer still (within float rounding) */
  oc_polygonize_params p20 = pp;
  p20.steps = 20;
  oc_mesh *m20 = mesh_ok(pr, &p20);
  ck_assert_uint_eq(oc_mesh_vertex_count(m20), in.nv);
  const float *P20 = oc_mesh_positions(m20);
  double worst20 = 0;
  for (size_t v = 0; v < in.nv; v++) {
    oc_vec3 d = oct_sub(oct_v(P20[3 * v], P20[3 * v + 1], P20[3 * v + 2]), c);
    worst20 = fmax(worst20, fabs(oct_len(d) - r));
  }
  ck_assert_msg(worst20 < 5e-7, "20 steps: %g off", worst20);
  oc_mesh_free(m20);
  oc_mesh_stats st;
  oc_mesh_get_stats(m, &st);
  ck_assert_uint_eq(st.vertices, in.nv);
  ck_assert_uint_eq(st.triangles, in.nt);
  ck_assert_uint_gt(st.field_calls, in.nv);
  ck_assert_uint_gt(st.cells_visited, 0);
  ck_assert(st.seconds > 0 && st.seconds < 60);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(ring_euler_zero) {
  /* a closed polyline circle: a torus */
  oc_error e;
  enum { K = 48 };
  oc_vec3 pts[K + 1];
  for (int k = 0; k <= K; k++) {
    double a = 2 * PI * (k % K) / K;
    pts[k] = oct_v(3 * cos(a), 3 * sin(a), 0.2);
  }
  oc_program *pr =
      oct_compile(OCT_OK(oc_curve(pts, K + 1, 0, 1.2, 1, &e)), 0, 0);
  oc_aabb box = box3(-4.5, -4.5, -1.5, 4.5, 4.5, 1.5);
  oc_polygonize_params pp = params(box, 0.1);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 0);
  ck_assert(in.volume > 0);
  ck_assert(normal_agreement(m, box) == 1.0);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(box_euler_two) {
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_box(oct_v(-1, -0.5, -0.7), oct_v(1.2, 0.8, 0.6), 0.5, 1, &e)),
      0, 0);
  oc_aabb box = box3(-2, -2, -2, 2, 2, 2);
  oc_polygonize_params pp = params(box, 0.09);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  /* the iso-surface is the box grown by d (Steiner's formula) */
  double d = 0.5 * sqrt(1 - cbrt(0.5)), a = 2.2, b = 1.3, c = 1.3;
  double want = a * b * c + 2 * d * (a * b + b * c + a * c) +
                PI * d * d * (a + b + c) + 4.0 / 3.0 * PI * d * d * d;
  ck_assert_msg(fabs(in.volume - want) < 0.01 * want, "volume %g, want %g",
                in.volume, want);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(capped_half_space) {
  /* everything below z ~ 0.45 is inside: the box caps it into a slab */
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e)), 0, 0);
  oc_aabb box = box3(-2, -1.5, -2, 2, 1.5, 2);
  oc_polygonize_params pp = params(box, 0.1);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  double zs = sqrt(1 - cbrt(0.5)); /* the surface */
  double want = 4 * 3 * (zs + 2);
  /* the caps are on the faces, so only the edge chamfers are missing */
  ck_assert_msg(in.volume < want && in.volume > 0.99 * want,
                "volume %g, slab %g", in.volume, want);
  /* every vertex is on the surface or on a face of the box */
  const float *P = oc_mesh_positions(m);
  for (size_t v = 0; v < in.nv; v++)
    ck_assert(on_box_face(box, P + 3 * v) || fabs(P[3 * v + 2] - zs) < 1e-5);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

/* A transition far narrower than a cell (a tilted plane of falloff
** 0.03 meshed at cell 0.4): the field is flat at both samples of most
** crossing edges, so Newton has nothing to go on and the fallbacks need
** more than the default step budget; every vertex must still end on the
** surface. */
START_TEST(narrow_transition_vertices) {
  oc_error e;
  oc_vec3 n = oct_v(0.3, 0.2, 1);
  n = oct_mul(n, 1 / oct_len(n));
  const double R = 0.03;
  oc_program *pr =
      oct_compile(OCT_OK(oc_plane(oct_v(0, 0, 0), n, R, 1, &e)), 0, 0);
  oc_aabb box = box3(-3, -3, -2, 3, 3, 2);
  oc_polygonize_params pp = params(box, 0.4);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  double ds = iso_radius(R, 1, 0.5), worst = 0;
  const float *P = oc_mesh_positions(m);
  for (size_t v = 0; v < in.nv; v++) {
    if (on_box_face(box, P + 3 * v)) continue;
    double d = P[3 * v] * n.x + P[3 * v + 1] * n.y + P[3 * v + 2] * n.z;
    worst = fmax(worst, fabs(d - ds));
  }
  ck_assert_msg(worst < 1e-3 * 0.4, "a vertex %g from the surface", worst);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(sphere_crossing_box) {
  const double R = 1.5;
  oc_program *pr = point_prog(oct_v(1.9, 0.1, -0.05), R, 1);
  oc_aabb box = box3(-2, -2, -2, 2, 2, 2);
  oc_polygonize_params pp = params(box, 0.1);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  /* a cap on x = 2: vertices there */
  const float *P = oc_mesh_positions(m);
  size_t oncap = 0;
  for (size_t v = 0; v < in.nv; v++)
    oncap += P[3 * v] == 2.0f;
  ck_assert_uint_gt(oncap, 20);
  /* the face is 0.1 from the centre: the sphere loses the cap of height
  ** r - 0.1 beyond it */
  double r = iso_radius(R, 1, 0.5), a = r - 0.1;
  double want = 4.0 / 3.0 * PI * r * r * r - PI * a * a * (3 * r - a) / 3;
  ck_assert_msg(fabs(in.volume - want) < 0.03 * want, "volume %g, want %g",
                in.volume, want);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(open_surface) {
  /* a tilted ground: open=1 leaves a disc (Euler 1) whose boundary lies on
  ** the box faces */
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 0.1), oct_v(0.2, -0.1, 1), 1.5, 1, &e)), 0,
      0);
  oc_aabb box = box3(-2, -2, -2, 2, 2, 2);
  oc_polygonize_params pp = params(box, 0.125);
  pp.open = 1;
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 0, box);
  ck_assert_int_eq(in.euler, 1);
  ck_assert_uint_ge(in.boundary, 4 * 32);
  ck_assert(normal_agreement(m, box) == 1.0);
  /* nothing of the caps: no vertex below the surface band */
  const float *P = oc_mesh_positions(m);
  for (size_t v = 0; v < in.nv; v++)
    ck_assert(P[3 * v + 2] > -1.5);
  /* the surface reaches the box faces: its footprint is the whole square */
  double area = 0, xmin = 1e9, xmax = -1e9;
  const uint32_t *I = oc_mesh_indices(m);
  for (size_t t = 0; t < in.nt; t++) {
    const float *a = P + 3 * I[3 * t], *b = P + 3 * I[3 * t + 1],
                *c = P + 3 * I[3 * t + 2];
    area += 0.5 *
            fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
  }
  for (size_t v = 0; v < in.nv; v++) {
    xmin = fmin(xmin, P[3 * v]);
    xmax = fmax(xmax, P[3 * v]);
  }
  ck_assert_double_eq_tol(area, 16.0, 1e-4);
  ck_assert(xmin == -2.0 && xmax == 2.0);
  /* the same surface closed has more triangles (the caps) */
  pp.open = 0;
  oc_mesh *mc = mesh_ok(pr, &pp);
  meshinfo ic = check_mesh(mc, 1, box);
  ck_assert_int_eq(ic.euler, 2);
  ck_assert_uint_gt(ic.nt, in.nt + 2 * 32 * 32);
  oc_mesh_free(m);
  oc_mesh_free(mc);
  oc_program_free(pr);
}
END_TEST

/* ---- the case table --------------------------------------------------------
 */

/* Inside exactly at the chosen sample centres: a point of radius 0.9 cell
** on each, so no other sample and no other edge feels it. */
static oc_program *pattern_prog(const unsigned char *in, int n, double h) {
  oc_error e;
  oc_node **k = malloc((size_t)(n * n * n + 1) * sizeof *k);
  size_t nk = 0;
  for (int z = 0; z < n; z++)
    for (int y = 0; y < n; y++)
      for (int x = 0; x < n; x++)
        if (in[(z * n + y) * n + x])
          k[nk++] = OCT_OK(
              oc_point(oct_v((x + 0.5) * h, (y + 0.5) * h, (z + 0.5) * h),
                       0.9 * h, 1, &e));
  if (!nk) k[nk++] = OCT_OK(oc_point(oct_v(-10, -10, -10), 1, 1, &e));
  oc_node *b = OCT_OK(oc_blend(k, nk, &e));
  for (size_t i = 0; i < nk; i++)
    oc_node_release(k[i]);
  free(k);
  return oct_compile(b, 0, 0);
}

START_TEST(every_case_alone) {
  /* 2 x 2 x 2 samples: one cube with the case's corners, padded */
  for (int m = 1; m < 256; m++) {
    unsigned char in[8];
    for (int c = 0; c < 8; c++)
      in[c] = (m >> c) & 1;
    oc_program *pr = pattern_prog(in, 2, 1.0);
    oc_aabb box = box3(0, 0, 0, 2, 2, 2);
    oc_polygonize_params pp = params(box, 1.0);
    oc_mesh *msh = mesh_ok(pr, &pp);
    meshinfo info = check_mesh(msh, 1, box);
    ck_assert_msg(info.volume > 0, "case %d: volume %g", m, info.volume);
    oc_mesh_free(msh);
    oc_program_free(pr);
  }
}
END_TEST

START_TEST(random_patterns) {
  /* ambiguous faces between cubes in every arrangement: no cracks */
  oct_rng r = oct_rng_new(3);
  enum { N = 7 };
  for (int trial = 0; trial < 24; trial++) {
    unsigned char in[N * N * N];
    double p = oct_unif(&r, 0.2, 0.8);
    for (int i = 0; i < N * N * N; i++)
      in[i] = oct_unif(&r, 0, 1) < p;
    oc_program *pr = pattern_prog(in, N, 0.5);
    oc_aabb box = box3(0, 0, 0, N * 0.5, N * 0.5, N * 0.5);
    oc_polygonize_params pp = params(box, 0.5);
    oc_mesh *msh = mesh_ok(pr, &pp);
    meshinfo info = check_mesh(msh, 1, box);
    ck_assert(info.volume > 0);
    /* the volume grows with the inside samples: each contributes a blob */
    oc_mesh_free(msh);
    oc_program_free(pr);
  }
}
END_TEST

/* ---- surface bounds, threads ----------------------------------------------
 */

static oc_program *terrain(int n) {
  oct_rng r = oct_rng_new(11);
  oc_error e;
  oc_node **k = malloc((size_t)(n + 2) * sizeof *k);
  size_t nk = 0;
  k[nk++] = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0.05, 0.02, 1), 2, 1, &e));
  for (int i = 0; i < n; i++) {
    oc_vec3 c =
        oct_v(oct_unif(&r, 0, 40), oct_unif(&r, 0, 40), oct_unif(&r, -2, 2));
    if (i % 2)
      k[nk++] = OCT_OK(oc_sphere(c, oct_unif(&r, 0.5, 2), 1.5, -1.5, &e));
    else
      k[nk++] = OCT_OK(oc_point(c, oct_unif(&r, 1.5, 3), 1.3, &e));
  }
  oc_vec3 spine[4] = {{14, 20, -1}, {14, 20, 9}, {26, 20, 9}, {26, 20, -1}};
  k[nk++] = OCT_OK(oc_curve(spine, 4, 1, 2.5, 1, &e));
  oc_node *b = OCT_OK(oc_blend(k, nk, &e));
  for (size_t i = 0; i < nk; i++)
    oc_node_release(k[i]);
  free(k);
  return oct_compile(b, 0, 0);
}

typedef struct tri9 {
  float v[9];
} tri9;

static int cmp9(const void *x, const void *y) {
  const float *a = x, *b = y;
  for (int i = 0; i < 9; i++)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}

/* Triangles by position, each rotated to start at its smallest vertex
** (which keeps its orientation), sorted. */
static tri9 *canonical(const oc_mesh *m) {
  size_t n = oc_mesh_triangle_count(m);
  const float *P = oc_mesh_positions(m);
  const uint32_t *I = oc_mesh_indices(m);
  tri9 *t = malloc(n * sizeof *t);
  for (size_t i = 0; i < n; i++) {
    int s = 0;
    for (int k = 1; k < 3; k++)
      if (cmp_pos(P + 3 * I[3 * i + k], P + 3 * I[3 * i + s]) < 0) s = k;
    for (int k = 0; k < 3; k++)
      memcpy(t[i].v + 3 * k, P + 3 * I[3 * i + (s + k) % 3], 3 * sizeof(float));
  }
  qsort(t, n, sizeof *t, cmp9);
  return t;
}

START_TEST(bounds_match_full_grid) {
  oc_program *pr = terrain(20);
  oc_aabb box = box3(0, 0, -12, 40, 40, 16);
  for (int open = 0; open < 2; open++) {
    oc_polygonize_params pp = params(box, 0.4);
    pp.open = open;
    oc_mesh *mb = mesh_ok(pr, &pp);
    pp.full_grid = 1;
    oc_mesh *mf = mesh_ok(pr, &pp);
    meshinfo ib = check_mesh(mb, !open, box);
    if (!open) ck_assert(ib.volume > 0);
    ck_assert_uint_eq(oc_mesh_triangle_count(mb), oc_mesh_triangle_count(mf));
    ck_assert_uint_eq(oc_mesh_vertex_count(mb), oc_mesh_vertex_count(mf));
    tri9 *tb = canonical(mb), *tf = canonical(mf);
    ck_assert(!memcmp(tb, tf, oc_mesh_triangle_count(mb) * sizeof *tb));
    free(tb);
    free(tf);
    oc_mesh_stats sb, sf;
    oc_mesh_get_stats(mb, &sb);
    oc_mesh_get_stats(mf, &sf);
    /* the band is a small part of the box */
    ck_assert_uint_lt(4 * sb.field_calls, sf.field_calls);
    ck_assert_uint_lt(4 * sb.cells_visited, sf.cells_visited);
    ck_assert_uint_eq(sf.cells_visited, 101u * 101u * 71u);
    oc_mesh_free(mb);
    oc_mesh_free(mf);
  }
  oc_program_free(pr);
}
END_TEST

static int same_mesh(const oc_mesh *a, const oc_mesh *b) {
  size_t nv = oc_mesh_vertex_count(a), nt = oc_mesh_triangle_count(a);
  return nv == oc_mesh_vertex_count(b) && nt == oc_mesh_triangle_count(b) &&
         !memcmp(oc_mesh_positions(a), oc_mesh_positions(b),
                 3 * nv * sizeof(float)) &&
         !memcmp(oc_mesh_normals(a), oc_mesh_normals(b),
                 3 * nv * sizeof(float)) &&
         !memcmp(oc_mesh_indices(a), oc_mesh_indices(b),
                 3 * nt * sizeof(uint32_t));
}

START_TEST(thin_span_between_samples) {
  /* a tilted half-space whose field varies over a slab thinner than a
  ** cell (falloff 0.3, cell 1), often between two sample layers: the
  ** gap below it (inside) and the gap above it (outside) must not merge
  ** into one constant (regression: coarse cells on thin terrains) */
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 4.9), oct_v(0.05, 0.02, 1), 0.3, 1, &e)), 0,
      0);
  oc_aabb box = box3(0, 0, 0, 24, 24, 10);
  oc_polygonize_params pp = params(box, 1);
  oc_mesh *mb = mesh_ok(pr, &pp);
  pp.full_grid = 1;
  oc_mesh *mf = mesh_ok(pr, &pp);
  meshinfo ib = check_mesh(mb, 1, box);
  ck_assert_int_eq(ib.euler, 2);
  tri9 *tb = canonical(mb), *tf = canonical(mf);
  ck_assert_uint_eq(oc_mesh_triangle_count(mb), oc_mesh_triangle_count(mf));
  ck_assert(!memcmp(tb, tf, oc_mesh_triangle_count(mb) * sizeof *tb));
  free(tb);
  free(tf);
  oc_mesh_free(mb);
  oc_mesh_free(mf);
  oc_program_free(pr);
}
END_TEST

START_TEST(tiny_grids) {
  /* 1 to 9 cells per axis, slabs of every size, a surface crossing the
  ** box or not: closed, and the same with and without bounds */
  oc_error e;
  oc_node *k[2] = {
      OCT_OK(oc_point(oct_v(0.7, 0.4, 0.3), 0.9, 1, &e)),
      OCT_OK(oc_plane(oct_v(0, 0, -0.2), oct_v(0.1, 0.3, 1), 0.5, 1, &e))};
  oc_program *pr = oct_compile(OCT_OK(oc_blend(k, 2, &e)), 0, 0);
  oc_node_release(k[0]);
  oc_node_release(k[1]);
  static const int ns[] = {1, 2, 3, 5, 9};
  oc_aabb box = box3(-0.3, -0.6, -0.9, 1.1, 1.3, 0.8);
  for (int a = 0; a < 5; a++)
    for (int b = 0; b < 5; b++)
      for (int c = 0; c < 5; c++) {
        oc_polygonize_params pp = params(box, 0);
        pp.nx = ns[a], pp.ny = ns[b], pp.nz = ns[c];
        oc_mesh *mb = mesh_ok(pr, &pp);
        pp.full_grid = 1;
        oc_mesh *mf = mesh_ok(pr, &pp);
        size_t nt = oc_mesh_triangle_count(mb);
        ck_assert_uint_eq(nt, oc_mesh_triangle_count(mf));
        if (nt) {
          meshinfo in = check_mesh(mb, 1, box);
          ck_assert(in.volume > 0);
          tri9 *tb = canonical(mb), *tf = canonical(mf);
          ck_assert(!memcmp(tb, tf, nt * sizeof *tb));
          free(tb);
          free(tf);
        }
        oc_mesh_free(mb);
        oc_mesh_free(mf);
      }
  oc_program_free(pr);
}
END_TEST

START_TEST(threads_byte_identical) {
  oc_program *pr = terrain(60);
  oc_aabb box = box3(0, 0, -12, 40, 40, 16);
  oc_polygonize_params pp = params(box, 0.3);
  int nt0 = omp_get_max_threads();
  omp_set_num_threads(1);
  oc_mesh *m1 = mesh_ok(pr, &pp);
  omp_set_num_threads(2);
  oc_mesh *m2 = mesh_ok(pr, &pp);
  omp_set_num_threads(3);
  oc_mesh *m3 = mesh_ok(pr, &pp);
  omp_set_num_threads(nt0);
  ck_assert(same_mesh(m1, m2));
  ck_assert(same_mesh(m1, m3));
  oc_mesh_stats s1, s2;
  oc_mesh_get_stats(m1, &s1);
  oc_mesh_get_stats(m2, &s2);
  ck_assert_uint_eq(s1.field_calls, s2.field_calls);
  ck_assert_uint_eq(s1.cells_visited, s2.cells_visited);
  check_mesh(m1, 1, box);
  oc_mesh_free(m1);
  oc_mesh_free(m2);
  oc_mesh_free(m3);
  oc_program_free(pr);
}
END_TEST

START_TEST(resolution_and_threshold) {
  /* nx, ny, nz instead of cell; an explicit threshold moves the surface */
  const double R = 1;
  oc_program *pr = point_prog(oct_v(0, 0, 0), R, 1);
  oc_aabb box = box3(-1, -1, -1, 1, 1, 1);
  oc_polygonize_params pp = params(box, 0);
  pp.nx = 40, pp.ny = 30, pp.nz = 50;
  pp.threshold = 0.2;
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  double r = iso_radius(R, 1, 0.2);
  const float *P = oc_mesh_positions(m);
  for (size_t v = 0; v < in.nv; v++) {
    double l =
        sqrt((double)P[3 * v] * P[3 * v] + (double)P[3 * v + 1] * P[3 * v + 1] +
             (double)P[3 * v + 2] * P[3 * v + 2]);
    ck_assert_msg(fabs(l - r) < 1e-5, "vertex at %g from the centre, %g", l, r);
  }
  /* one root-finding step is coarser, but still on the edge and closed */
  pp.steps = 1;
  oc_mesh *m1 = mesh_ok(pr, &pp);
  meshinfo i1 = check_mesh(m1, 1, box);
  ck_assert_int_eq(i1.euler, 2);
  oc_mesh_free(m1);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(flat_gradient_normals) {
  /* a volumetric sphere whose falloff (0.03) is far thinner than a cell:
  ** with one root-finding step, vertices often end where the gradient
  ** vanishes (core or outside the shell); those vertices take their triangles'
  *normal, which must
  ** still point outwards (check_mesh asserts finite unit normals) */
  oc_error e;
  oc_vec3 c = oct_v(0.05, 0.1, 0.2);
  oc_program *pr = oct_compile(OCT_OK(oc_sphere(c, 1.2, 0.03, 1, &e)), 0, 0);
  oc_aabb box = box3(-2, -2, -2, 2, 2, 2);
  oc_polygonize_params pp = params(box, 0.1);
  pp.steps = 1;
  oc_mesh *m = mesh_ok(pr, &pp);
  check_mesh(m, 1, box);
  const float *P = oc_mesh_positions(m), *N = oc_mesh_normals(m);
  size_t n = 0;
  for (size_t v = 0; v < oc_mesh_vertex_count(m); v++) {
    oc_vec3 p = oct_v(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
    oc_vec3 nn = oct_v(N[3 * v], N[3 * v + 1], N[3 * v + 2]);
    ck_assert(oct_dot(nn, oct_sub(p, c)) > 0.5 * oct_len(oct_sub(p, c)));
    oc_vec3 g;
    oc_program_gradient(pr, p, &g);
    n += oct_len(g) == 0;
  }
  ck_assert_uint_gt(n, 10);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(samples_exactly_at_threshold) {
  /* f == T counts as outside: a surface through a whole layer of samples
  ** still gives a clean closed mesh */
  oc_error e;
  oc_program *pr = oct_compile(
      OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e)), 0, 0);
  oc_aabb box = box3(0, 0, 0, 1, 1, 1);
  oc_polygonize_params pp = params(box, 0.1);
  pp.threshold = oc_program_eval(pr, oct_v(0.55, 0.45, 0.45));
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  /* the top is just under the layer at z = 0.45 */
  const float *P = oc_mesh_positions(m);
  float top = 0;
  for (size_t v = 0; v < in.nv; v++)
    top = fmaxf(top, P[3 * v + 2]);
  ck_assert(top < 0.45f && top > 0.449f);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(cavity_negative_threshold) {
  /* T < 0: empty space (f = 0) is inside, a carving point makes a cavity.
  ** Most columns have no span at all yet are solid: capped all round. */
  const double R = 1;
  oc_vec3 c = oct_v(0.3, 0.1, -0.2);
  oc_program *pr = point_prog(c, R, -1);
  oc_aabb box = box3(-1.5, -2, -1.2, 1.5, 2, 1.2);
  oc_polygonize_params pp = params(box, 0.05);
  pp.threshold = -0.5;
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 4); /* the box's surface and the cavity's */
  double r = iso_radius(R, 1, 0.5);
  double want = 3 * 4 * 2.4 - 4.0 / 3.0 * PI * r * r * r;
  ck_assert_msg(fabs(in.volume - want) < 0.01 * want, "volume %g, want %g",
                in.volume, want);
  oc_polygonize_params pf = pp;
  pf.full_grid = 1;
  oc_mesh *mf = mesh_ok(pr, &pf);
  tri9 *tb = canonical(m), *tf = canonical(mf);
  ck_assert_uint_eq(oc_mesh_triangle_count(m), oc_mesh_triangle_count(mf));
  ck_assert(!memcmp(tb, tf, in.nt * sizeof *tb));
  free(tb);
  free(tf);
  oc_mesh_free(mf);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(far_from_origin) {
  /* cells of a few hundred float ulps: vertices still distinct, no
  ** triangle degenerate once rounded to float */
  const double X = 2000;
  oc_program *pr = point_prog(oct_v(X + 0.013, -X + 0.021, X + 0.017), 0.2, 1);
  oc_aabb box = box3(X - 0.2, -X - 0.2, X - 0.2, X + 0.2, -X + 0.2, X + 0.2);
  oc_polygonize_params pp = params(box, 0.01);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  oc_mesh_free(m);
  /* finer than the coordinates can hold: refused */
  pp.cell = 1e-4;
  expect_fail(pr, &pp, OC_EINVAL, "'cell'");
  oc_program_free(pr);
}
END_TEST

START_TEST(wide_grid_streams) {
  /* 4000 x 4000 columns, 1000 cells tall: 1.6e10 cells, far more than
  ** memory if the grid were stored; only the band around the small
  ** sphere is. */
  oc_program *pr = point_prog(oct_v(1000.2, 1000.1, 10.05), 4, 1);
  oc_aabb box = box3(0, 0, 0, 2000, 2000, 500);
  oc_polygonize_params pp = params(box, 0.5);
  oc_mesh *m = mesh_ok(pr, &pp);
  meshinfo in = check_mesh(m, 1, box);
  ck_assert_int_eq(in.euler, 2);
  oc_mesh_stats st;
  oc_mesh_get_stats(m, &st);
  ck_assert_uint_lt(st.field_calls, 20000000u);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

/* ---- errors and cancellation ----------------------------------------------
 */

static void expect_fail(const oc_program *pr, const oc_polygonize_params *pp,
                        oc_status code, const char *word) {
  oc_error e = {0};
  oc_mesh *m = oc_polygonize(pr, pp, &e);
  ck_assert_msg(m == NULL, "expected a failure naming %s", word);
  ck_assert_int_eq(e.code, code);
  ck_assert_msg(strstr(e.msg, word) != NULL, "message '%s' lacks '%s'", e.msg,
                word);
}

START_TEST(bad_params) {
  oc_program *pr = point_prog(oct_v(0, 0, 0), 1, 1);
  oc_aabb box = box3(-1, -1, -1, 1, 1, 1);
  oc_polygonize_params pp = params(box, -0.1);
  expect_fail(pr, &pp, OC_EINVAL, "'cell'");
  pp.cell = NAN;
  expect_fail(pr, &pp, OC_EINVAL, "'cell'");
  pp.cell = 1e-9; /* 2e9 cells per axis */
  expect_fail(pr, &pp, OC_EINVAL, "'cell'");
  pp = params(box, 0);
  pp.nx = 4; /* some but not all given */
  expect_fail(pr, &pp, OC_EINVAL, "'resolution'");
  pp.nx = pp.ny = 10, pp.nz = (1 << 20) + 1;
  expect_fail(pr, &pp, OC_EINVAL, "'resolution'");
  pp = params(box3(-1, -1, -1, 1, -1, 1), 0.1);
  expect_fail(pr, &pp, OC_EINVAL, "'box'");
  pp = params(box3(-1, -1, -INFINITY, 1, 1, 1), 0.1);
  expect_fail(pr, &pp, OC_EINVAL, "'box'");
  pp = params(box3(-1, -1, -1, 1, NAN, 1), 0.1);
  expect_fail(pr, &pp, OC_EINVAL, "'box'");
  pp = params(box, 0.1);
  pp.steps = -1;
  expect_fail(pr, &pp, OC_EINVAL, "'steps'");
  pp.steps = 1000;
  expect_fail(pr, &pp, OC_EINVAL, "'steps'");
  pp.steps = 0;
  pp.threshold = INFINITY;
  expect_fail(pr, &pp, OC_EINVAL, "'threshold'");
  oc_error e = {0};
  ck_assert(oc_polygonize(NULL, &pp, &e) == NULL);
  ck_assert_int_eq(e.code, OC_EINVAL);
  ck_assert(oc_polygonize(pr, NULL, &e) == NULL);
  oc_program_free(pr);
}
END_TEST

START_TEST(absurd_sizes) {
  oc_program *pr = point_prog(oct_v(0, 0, 0), 1, 1);
  /* 2^60 cells */
  oc_polygonize_params pp = params(box3(-1, -1, -1, 1, 1, 1), 0);
  pp.nx = pp.ny = pp.nz = 1 << 20;
  expect_fail(pr, &pp, OC_ENOMEM, "too large");
  /* a whole-column slab of the full grid would not fit */
  pp.nx = pp.nz = 1 << 16;
  pp.ny = 8;
  pp.full_grid = 1;
  expect_fail(pr, &pp, OC_ENOMEM, "'full_grid'");
  /* an unbounded field (noise) has no surface bounds: a tall wide grid
  ** must be refused cleanly, not crash */
  oc_noise nz = {2, 1, 0, 2, 9};
  oc_error e;
  oc_program *tu = oct_compile(OCT_OK(oc_turbulence(&nz, &e)), 0.75, 0);
  pp = params(box3(0, 0, 0, 1, 1, 1), 0);
  pp.nx = pp.nz = 1 << 14;
  pp.ny = 4;
  expect_fail(tu, &pp, OC_ENOMEM, "'cell'");
  oc_program_free(tu);
  oc_program_free(pr);
}
END_TEST

typedef struct progress_log {
  int calls;
  int cancel; /* 1: at the first report, 2: at the final one (1.0) */
  double last;
  int monotone;
} progress_log;

static int on_progress(void *ud, double f) {
  progress_log *l = ud;
  if (f < l->last || f < 0 || f > 1) l->monotone = 0;
  l->last = f;
  l->calls++;
  return l->cancel == 1 || (l->cancel == 2 && f == 1.0);
}

START_TEST(progress_and_cancel) {
  oc_program *pr = terrain(20);
  oc_aabb box = box3(0, 0, -8, 40, 40, 8);
  oc_polygonize_params pp = params(box, 0.5);
  progress_log log = {0, 0, 0, 1};
  pp.progress.fn = on_progress;
  pp.progress.ud = &log;
  /* one thread: a report per slab (how many the calling thread gets with
  ** more depends on scheduling), then 1.0 */
  int nt0 = omp_get_max_threads();
  omp_set_num_threads(1);
  oc_mesh *m1 = mesh_ok(pr, &pp);
  omp_set_num_threads(nt0);
  ck_assert_int_gt(log.calls, 4);
  ck_assert(log.monotone);
  ck_assert(log.last == 1.0);
  log = (progress_log){0, 0, 0, 1};
  oc_mesh *m = mesh_ok(pr, &pp);
  ck_assert_int_ge(log.calls, 1);
  ck_assert(log.monotone);
  ck_assert(log.last == 1.0);
  ck_assert(same_mesh(m, m1));
  oc_mesh_free(m1);
  /* progress does not change the output */
  oc_polygonize_params p0 = params(box, 0.5);
  oc_mesh *m0 = mesh_ok(pr, &p0);
  ck_assert(same_mesh(m, m0));
  oc_mesh_free(m);
  oc_mesh_free(m0);
  /* cancelled at the first report, and at the very end */
  for (int at = 1; at <= 2; at++) {
    progress_log c = {0, at, 0, 1};
    pp.progress.ud = &c;
    oc_error e = {0};
    ck_assert(oc_polygonize(pr, &pp, &e) == NULL);
    ck_assert_int_eq(e.code, OC_ECANCEL);
  }
  oc_program_free(pr);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("polygonize");
  TCase *t = tcase_create("shapes");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, sphere_closed_volume);
  tcase_add_test(t, ring_euler_zero);
  tcase_add_test(t, box_euler_two);
  tcase_add_test(t, capped_half_space);
  tcase_add_test(t, narrow_transition_vertices);
  tcase_add_test(t, sphere_crossing_box);
  tcase_add_test(t, open_surface);
  tcase_add_test(t, resolution_and_threshold);
  tcase_add_test(t, flat_gradient_normals);
  tcase_add_test(t, samples_exactly_at_threshold);
  suite_add_tcase(s, t);
  t = tcase_create("table");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, every_case_alone);
  tcase_add_test(t, random_patterns);
  suite_add_tcase(s, t);
  t = tcase_create("bounds");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, bounds_match_full_grid);
  tcase_add_test(t, threads_byte_identical);
  tcase_add_test(t, thin_span_between_samples);
  tcase_add_test(t, tiny_grids);
  tcase_add_test(t, wide_grid_streams);
  tcase_add_test(t, far_from_origin);
  tcase_add_test(t, cavity_negative_threshold);
  suite_add_tcase(s, t);
  t = tcase_create("errors");
  tcase_set_timeout(t, 120);
  tcase_add_test(t, bad_params);
  tcase_add_test(t, absurd_sizes);
  tcase_add_test(t, progress_and_cancel);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
