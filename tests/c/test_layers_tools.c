/*
** test_layers_tools.c — material-stack tools (Peytavie et al. 2009,
** section 4) beyond test_layers.c: sculpting add then carve returns the
** surface within a cell, from_program's progress and cancellation, and
** the sweep tool (a crack's cross-section equal to its profile, branches,
** tunnels, volume bookkeeping, thread independence, bad input), and mesh
** vertex colours textured by material (oc_mesh_color_by_blend), and the
** visible material ratio (oc_stacks_visible).
*/
#include <omp.h>
#include <string.h>

#include "layers/layers.h"
#include "ocheck.h"

#define T 0.5

static oc_stacks *slab(int n, double cell, double top) {
  oc_error err;
  oc_stacks *s = oc_stacks_new(n, n, cell, 0, 0, 0, &err);
  ck_assert_msg(s != NULL, "%s", err.msg);
  uint8_t m = OC_MAT_BEDROCK;
  ck_assert(oc_stacks_fill(s, &m, &top, 1, &err) == OC_OK);
  return s;
}

/* The top of the bedrock of stack (i, j). */
static double top_of(const oc_stacks *s, int i, int j) {
  uint8_t m[16];
  double t[16], z = oc_stacks_base(s), top = z;
  size_t n = oc_stacks_get(s, i, j, m, t, 16);
  for (size_t l = 0; l < n && l < 16; l++) {
    z += t[l];
    if (m[l] == OC_MAT_BEDROCK) top = z;
  }
  return top;
}

/* A bump added, then carved by the same stroke picked at the bump's top
** (as a user would click it; default delta, so the carving centre sits
** above that top): the slab's top comes back within a cell everywhere
** (measured: 0.12 for cell 0.5), and the bedrock volume within 0.1 m over
** the stroke's disc (the bump held 4.7 m^3). */
START_TEST(sculpt_round_trip) {
  oc_error err;
  double cell = 0.5, R = 3;
  oc_stacks *s = slab(24, cell, 10);
  double v0 = oc_stacks_volume(s, OC_MAT_BEDROCK), add, cut;
  oc_sculpt_params sp = {{6, 6, 10}, R, 2, NAN, 0, 0, 0, NULL};
  ck_assert_msg(oc_stacks_sculpt(s, &sp, &add, NULL, &err) == OC_OK, "%s",
                err.msg);
  double bump = top_of(s, 12, 12);
  ck_assert(bump > 10 + cell); /* a real bump */
  sp.carve = 1;
  sp.center.z = bump;
  ck_assert(oc_stacks_sculpt(s, &sp, &cut, NULL, &err) == OC_OK);
  ck_assert(add > 4 && cut < -2);
  double worst = 0;
  for (int j = 0; j < 24; j++)
    for (int i = 0; i < 24; i++)
      worst = fmax(worst, fabs(top_of(s, i, j) - 10));
  ck_assert_msg(worst <= cell, "top off by %g", worst);
  double v1 = oc_stacks_volume(s, OC_MAT_BEDROCK);
  ck_assert_double_eq_tol(v1, v0 + add + cut, 1e-6);
  ck_assert_msg(fabs(v1 - v0) <= 0.1 * 3.14159265358979 * R * R,
                "volume off by %g", v1 - v0);
  oc_stacks_free(s);
}
END_TEST

typedef struct calls {
  int n, stop_at;
  double last;
  int monotone;
} calls;

static int on_progress(void *ud, double f) {
  calls *c = ud;
  if (f < c->last) c->monotone = 0;
  c->last = f;
  return ++c->n >= c->stop_at;
}

/* from_program reports rows done up to 1, and stops when asked. */
START_TEST(from_program_progress) {
  oc_error err;
  oc_node *ball = OCT_OK(oc_sphere(oct_v(0, 0, 0), 4, 2, 1, &err));
  oc_program *P = oct_compile(ball, T, 0);
  calls c = {0, 1 << 30, 0, 1};
  oc_stacks_node_params np = {
      {{-6, -6, -6}, {6, 6, 6}}, 0.5, 0, OC_MAT_BEDROCK, {on_progress, &c}};
  oc_stacks *s = oc_stacks_from_program(P, &np, &err);
  ck_assert_msg(s != NULL, "%s", err.msg);
  ck_assert_msg(c.n >= 1 && c.monotone, "%d calls", c.n);
  ck_assert_double_eq(c.last, 1);
  oc_stacks_free(s);
  c = (calls){0, 1, 0, 1};
  s = oc_stacks_from_program(P, &np, &err);
  ck_assert(s == NULL);
  ck_assert_int_eq(err.code, OC_ECANCEL);
  oc_program_free(P);
}
END_TEST

/* Fuzz findings (tests/corpus/layers-*): a grid without layers (from a
** node that never reaches T in the box, or new without layers) holds no
** layer array, and sculpting or converting it offset that NULL array; a
** grid far from the tool (origin 1e308) made window bounds beyond int.
** Each is now a no-op that leaves the grid as it was; a sweep whose
** profile is 1e30 m across is refused. */
START_TEST(empty_and_far_grids) {
  oc_error err;
  oc_node *ball = OCT_OK(oc_sphere(oct_v(100, 100, 100), 1, 0.5, 1, &err));
  oc_program *P = oct_compile(ball, T, 0);
  oc_stacks_node_params np = {
      {{-4, -4, -4}, {3, 6, 4}}, 1, 1, OC_MAT_BEDROCK, {NULL, NULL}};
  oc_stacks *air = oc_stacks_from_program(P, &np, &err);
  ck_assert_msg(air != NULL, "%s", err.msg);
  ck_assert_int_eq(oc_stacks_nx(air), 8);
  ck_assert_double_eq(oc_stacks_volume(air, OC_MAT_BEDROCK), 0);
  oc_stacks_free(air);
  oc_program_free(P);
  oc_stacks *s = oc_stacks_new(10, 15, 1, 0, 0, 0, &err);
  ck_assert_msg(s != NULL, "%s", err.msg);
  oc_sculpt_params sp = {{-1, -5, 1}, 2, 1, 8, 1, 0, 0, NULL};
  double dv = -1;
  ck_assert_msg(oc_stacks_sculpt(s, &sp, &dv, NULL, &err) == OC_OK, "%s",
                err.msg);
  ck_assert_double_eq(dv, 0);
  oc_stacks_free(s);
  oc_stacks *far = oc_stacks_new(23, 8, 1, 1e308, -2, 0, &err);
  ck_assert_msg(far != NULL, "%s", err.msg);
  uint8_t m = OC_MAT_BEDROCK;
  double top = 3;
  ck_assert(oc_stacks_fill(far, &m, &top, 1, &err) == OC_OK);
  sp = (oc_sculpt_params){{0, 0, 3}, 2, 1, NAN, 1, 0, 0, NULL};
  ck_assert(oc_stacks_sculpt(far, &sp, &dv, NULL, &err) == OC_OK);
  ck_assert_double_eq(dv, 0);
  double uv[] = {-1, 1, 1, 1, 0, -1};
  size_t off[2] = {0, 3};
  oc_vec3 pts[2] = {{0, -5, 1}, {5, 16, 1}};
  int prof[2] = {0, 0}, edges[2] = {0, 1};
  oc_sweep_params wp = {pts, prof, 2, edges, 1, uv, off, 1, 1, 0, NULL};
  ck_assert_msg(oc_stacks_sweep(far, &wp, &dv, NULL, &err) == OC_OK, "%s",
                err.msg);
  ck_assert_double_eq(dv, 0);
  ck_assert_double_eq(oc_stacks_volume(far, OC_MAT_BEDROCK), 23 * 8 * 3);
  oc_stacks_free(far);
  /* a profile 1e30 m across: refused (it took 1e30 / step samples a
  ** stack, a count beyond long), the grid as it was */
  oc_stacks *g = slab(21, 2, 3);
  double huge[] = {1e30, 0, 1e30, 2, -1, 20};
  oc_vec3 crack[2] = {{4, 0.1, 0}, {-1, 10, 0}};
  oc_sweep_params hp = {crack, prof, 2, edges, 1, huge, off, 1, 0, 0, NULL};
  ck_assert_int_eq(oc_stacks_sweep(g, &hp, &dv, NULL, &err), OC_EINVAL);
  ck_assert_msg(strstr(err.msg, "samples"), "%s", err.msg);
  ck_assert_double_eq(oc_stacks_volume(g, OC_MAT_BEDROCK), 21 * 21 * 3 * 4);
  oc_stacks_free(g);
}
END_TEST

/* ---- sweeping ------------------------------------------------------------ */

/* A closed polyline with control points every `h` along its sides (the
** Catmull-Rom spline through collinear, evenly spaced points is those
** sides, so the profile is the polygon away from its corners). */
static size_t polygon(const double *corner, int n, double h, double *uv) {
  size_t m = 0;
  for (int k = 0; k < n; k++) {
    const double *a = corner + 2 * k, *b = corner + 2 * ((k + 1) % n);
    int steps = (int)round(hypot(b[0] - a[0], b[1] - a[1]) / h);
    for (int q = 0; q < steps; q++) {
      uv[2 * m] = a[0] + (b[0] - a[0]) * q / steps;
      uv[2 * m + 1] = a[1] + (b[1] - a[1]) * q / steps;
      m++;
    }
  }
  return m;
}

/* A bottle-shaped (non-convex) cross-section: a neck |u| < 1 from v = 1
** down to -2 over a chamber |u| < 3 from -2 to -5. */
static size_t bottle(double *uv) {
  static const double c[] = {-1, 1,  1,  1,  1,  -2, 3,  -2,
                             3,  -5, -3, -5, -3, -2, -1, -2};
  return polygon(c, 8, 0.5, uv);
}

/* The layers of stack (i, j) as bottom-up (material, top) pairs. */
static size_t column(const oc_stacks *s, int i, int j, uint8_t *m,
                     double *top) {
  size_t n = oc_stacks_get(s, i, j, m, top, 16);
  double z = oc_stacks_base(s);
  for (size_t l = 0; l < n; l++)
    top[l] = z += top[l];
  return n;
}

/* A crack along x on a flat slab: across it, the stacks hold the profile's
** cross-section (open neck, a chamber under bedrock overhangs, untouched
** beyond), to the bisection's precision away from the profile's corners;
** the volume removed is the profile's area below the surface times the
** length, plus the rounded ends. */
START_TEST(sweep_crack_profile) {
  oc_error err;
  double cell = 0.5;
  oc_stacks *s = slab(41, cell, 10);
  double uv[2 * 128];
  size_t n = bottle(uv), off[2] = {0, n};
  oc_vec3 pts[2] = {{2, 10, 0}, {18, 10, 0}};
  int prof[2] = {0, 0}, edges[2] = {0, 1};
  oc_sweep_params p = {pts, prof, 2, edges, 1, uv, off, 1, 0, 0, NULL};
  double dv;
  ck_assert_msg(oc_stacks_sweep(s, &p, &dv, NULL, &err) == OC_OK, "%s",
                err.msg);
  uint8_t m[16];
  double top[16];
  /* x = 10 (i = 20); right of travel along +x is -y: u = 10 - y */
  for (int j = 10; j <= 30; j++) {
    double u = 10 - j * cell;
    size_t k = column(s, 20, j, m, top);
    if (fabs(u) <= 0.5) { /* the neck and chamber: bedrock up to 5 */
      ck_assert_uint_eq(k, 1);
      ck_assert_double_eq_tol(top[0], 5, 1e-5);
    } else if (fabs(u) >= 1.75 && fabs(u) <= 2.25) { /* under the overhang */
      ck_assert_uint_eq(k, 3);
      ck_assert_int_eq(m[1], OC_MAT_AIR);
      ck_assert_double_eq_tol(top[0], 5, 1e-5);
      ck_assert_double_eq_tol(top[1], 8, 1e-5);
      ck_assert_double_eq_tol(top[2], 10, 1e-6);
    } else if (fabs(u) >= 3.5) {
      ck_assert_uint_eq(k, 1);
      ck_assert_double_eq_tol(top[0], 10, 1e-6);
    }
  }
  /* 22 m^2 below the surface (less the rounded corners) over 16 m, and
  ** the two ends: the half-profile turned through a half turn */
  ck_assert_msg(dv < -0.95 * 22 * 16 && dv > -22 * (16 + 2 * 3), "%g", dv);
  oc_stacks_free(s);
}
END_TEST

/* On a slope the profile hangs along the surface normal: its bottom
** (v = -5) lies 5 / cos(slope) below the surface, measured vertically. */
START_TEST(sweep_crack_follows_surface) {
  oc_error err;
  double cell = 0.5;
  oc_stacks *s = slab(41, cell, 10);
  for (int j = 0; j < 41; j++)
    for (int i = 0; i < 41; i++) {
      uint8_t m = OC_MAT_BEDROCK;
      double t = 10 + 0.2 * i * cell;
      ck_assert(oc_stacks_set(s, i, j, &m, &t, 1, &err) == OC_OK);
    }
  double uv[2 * 128];
  size_t n = bottle(uv), off[2] = {0, n};
  oc_vec3 pts[2] = {{2, 10, 999}, {18, 10, -999}}; /* z ignored */
  int prof[2] = {0, 0}, edges[2] = {0, 1};
  oc_sweep_params p = {pts, prof, 2, edges, 1, uv, off, 1, 0, 0, NULL};
  ck_assert_msg(oc_stacks_sweep(s, &p, NULL, NULL, &err) == OC_OK, "%s",
                err.msg);
  uint8_t m[16];
  double top[16];
  for (int i = 12; i <= 28; i += 4) {
    ck_assert_uint_eq(column(s, i, 20, m, top), 1);
    double want = 10 + 0.2 * i * cell - 5 * sqrt(1 + 0.04);
    ck_assert_msg(fabs(top[0] - want) < 0.01, "i %d: %g vs %g", i, top[0],
                  want);
  }
  oc_stacks_free(s);
}
END_TEST

/* A branching graph: three arcs from a junction, the profile growing
** from a square of half-side 1 at the far end of one arc to half-side 3
** at the junction (so half-side 2 half-way); a tunnel: a round bore with
** the ground above left alone. */
START_TEST(sweep_branches_and_tunnel) {
  oc_error err;
  double cell = 0.5;
  oc_stacks *s = slab(61, cell, 10);
  double uv[2 * 256];
  static const double sq1[] = {-1, 1, 1, 1, 1, -1, -1, -1};
  static const double sq3[] = {-3, 3, 3, 3, 3, -3, -3, -3};
  size_t n1 = polygon(sq1, 4, 0.25, uv);
  size_t n3 = polygon(sq3, 4, 0.25, uv + 2 * n1);
  size_t off[3] = {0, n1, n1 + n3};
  oc_vec3 pts[4] = {{15, 15, 0}, {3, 15, 0}, {27, 15, 0}, {15, 27, 0}};
  int prof[4] = {1, 0, 1, 1}, edges[6] = {0, 1, 0, 2, 0, 3};
  oc_sweep_params p = {pts, prof, 4, edges, 3, uv, off, 2, 0, 0, NULL};
  ck_assert_msg(oc_stacks_sweep(s, &p, NULL, NULL, &err) == OC_OK, "%s",
                err.msg);
  uint8_t m[16];
  double top[16];
  /* half-way along the first arc (x = 9): carved to v = -2 (half-way
  ** between -1 and -3) over |u| < 2, away from the corners (the small
  ** square's rounded corners pair with points 0.75 from the corner) */
  for (int j = 20; j <= 40; j++) {
    double u = 15 - j * cell;
    column(s, 18, j, m, top);
    if (fabs(u) <= 1.25)
      ck_assert_msg(fabs(top[0] - 8) < 1e-5, "u %g: %.9g", u, top[0]);
    else if (fabs(u) >= 2.5)
      ck_assert_double_eq_tol(top[0], 10, 1e-6);
  }
  /* the junction and each branch are carved */
  column(s, 30, 30, m, top);
  ck_assert_double_eq_tol(top[0], 7, 1e-5);
  column(s, 50, 30, m, top);
  ck_assert_double_eq_tol(top[0], 7, 1e-5);
  column(s, 30, 50, m, top);
  ck_assert_double_eq_tol(top[0], 7, 1e-5);
  /* a tunnel at z = 5 through the same slab, round (16 control points on
  ** a circle of radius 2): an air layer of thickness 4 on its axis */
  oc_stacks_free(s);
  s = slab(41, cell, 10);
  double circle[32];
  for (int k = 0; k < 16; k++) {
    circle[2 * k] = 2 * cos(k * 3.14159265358979 / 8);
    circle[2 * k + 1] = 2 * sin(k * 3.14159265358979 / 8);
  }
  size_t offc[2] = {0, 16};
  oc_vec3 tp[2] = {{0, 10, 5}, {20, 10, 5}};
  int tprof[2] = {0, 0};
  oc_sweep_params tpp = {tp, tprof, 2, edges, 1, circle, offc, 1, 1, 0, NULL};
  ck_assert(oc_stacks_sweep(s, &tpp, NULL, NULL, &err) == OC_OK);
  ck_assert_uint_eq(column(s, 20, 20, m, top), 3);
  ck_assert_int_eq(m[1], OC_MAT_AIR);
  ck_assert_double_eq_tol(top[1] - top[0], 4, 0.02);
  ck_assert_double_eq_tol(top[2], 10, 1e-6);
  oc_stacks_free(s);
}
END_TEST

/* Sand over the crack falls in and is stabilised: sand volume conserved,
** the same stacks for 1 and 2 threads; bad input names the field. */
START_TEST(sweep_sand_threads_errors) {
  oc_error err;
  double uv[2 * 128];
  size_t n = bottle(uv), off[2] = {0, n};
  oc_vec3 pts[2] = {{3, 8, 0}, {13, 8, 0}};
  int prof[2] = {0, 0}, edges[2] = {0, 1};
  oc_stacks *s[2];
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t + 1);
    s[t] = slab(33, 0.5, 10);
    uint8_t m[2] = {OC_MAT_BEDROCK, OC_MAT_SAND};
    double th[2] = {10, 0.5};
    ck_assert(oc_stacks_fill(s[t], m, th, 2, &err) == OC_OK);
    double sand = oc_stacks_volume(s[t], OC_MAT_SAND);
    oc_sweep_params p = {pts, prof, 2, edges, 1, uv, off, 1, 0, 1, NULL};
    oc_stabilize_result res;
    ck_assert_msg(oc_stacks_sweep(s[t], &p, NULL, &res, &err) == OC_OK, "%s",
                  err.msg);
    ck_assert(res.moved > 0);
    ck_assert_double_eq_tol(oc_stacks_volume(s[t], OC_MAT_SAND), sand,
                            1e-6 * sand);
  }
  omp_set_num_threads(2);
  for (int j = 0; j < 33; j++)
    for (int i = 0; i < 33; i++) {
      uint8_t ma[16], mb[16];
      double ta[16], tb[16];
      size_t na = oc_stacks_get(s[0], i, j, ma, ta, 16);
      ck_assert_uint_eq(na, oc_stacks_get(s[1], i, j, mb, tb, 16));
      ck_assert(!memcmp(ma, mb, na) && !memcmp(ta, tb, na * sizeof *ta));
    }
  oc_sweep_params p = {pts, prof, 2, edges, 1, uv, off, 1, 0, 0, NULL};
  size_t off2[2] = {0, 2};
  p.profile_off = off2;
  ck_assert_int_eq(oc_stacks_sweep(s[0], &p, NULL, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'profiles[1]'"));
  p.profile_off = off;
  int bad[2] = {1, 1};
  p.edges = bad;
  ck_assert_int_eq(oc_stacks_sweep(s[0], &p, NULL, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "arc 1"));
  p.edges = edges;
  int badp[2] = {0, 1};
  p.point_profile = badp;
  ck_assert_int_eq(oc_stacks_sweep(s[0], &p, NULL, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'profile' of path point 2"));
  oc_stacks_free(s[0]);
  oc_stacks_free(s[1]);
}
END_TEST

/* A right-angle bend: the two arcs are mitred, so the outer corner of the
** bend is carved (no wedge left between square-cut ends) and nothing
** beyond the profile's width is; the path's far ends are cut square. */
START_TEST(sweep_bend_mitred) {
  oc_error err;
  double cell = 0.25;
  oc_stacks *s = slab(81, cell, 10);
  static const double sq[] = {-1, 1, 1, 1, 1, -1, -1, -1};
  double uv[2 * 64];
  size_t n = polygon(sq, 4, 0.25, uv), off[2] = {0, n};
  oc_vec3 pts[3] = {{2, 10, 0}, {10, 10, 0}, {10, 18, 0}};
  int prof[3] = {0, 0, 0}, edges[4] = {0, 1, 1, 2};
  oc_sweep_params p = {pts, prof, 3, edges, 2, uv, off, 1, 0, 0, NULL};
  ck_assert_msg(oc_stacks_sweep(s, &p, NULL, NULL, &err) == OC_OK, "%s",
                err.msg);
  uint8_t m[16];
  double top[16];
  /* (10.75, 9.5): the bend's outer corner (0.25 from the profile's
  ** rounded corner, hence the looser tolerance) */
  column(s, 43, 38, m, top);
  ck_assert_double_eq_tol(top[0], 9, 1e-3);
  column(s, 42, 41, m, top); /* (10.5, 10.25) */
  ck_assert_double_eq_tol(top[0], 9, 1e-5);
  column(s, 45, 35, m, top); /* (11.25, 8.75): beyond the width */
  ck_assert_double_eq_tol(top[0], 10, 1e-6);
  column(s, 6, 40, m, top); /* (1.5, 10): before the square-cut start */
  ck_assert_double_eq_tol(top[0], 10, 1e-6);
  column(s, 9, 40, m, top); /* (2.25, 10): just after it */
  ck_assert_double_eq_tol(top[0], 9, 1e-5);
  oc_stacks_free(s);
}
END_TEST

/* ---- texturing by material ------------------------------------------------
 */

/* Bedrock 5 m thick, under 2 m of sand on the half x < 10: mesh vertex
** colours blended by the two materials' convolution surfaces (sigma 1)
** are the sand's colour on the sand, the bedrock's on the bare rock, a
** mix of both on the step between; the triplanar texture (amplitude 0.3)
** scales each colour by a gain within 1 +- 0.3. */
START_TEST(texture_by_material) {
  oc_error err;
  oc_stacks *s = slab(20, 1, 5);
  uint8_t m[2] = {OC_MAT_BEDROCK, OC_MAT_SAND};
  double t[2] = {5, 2};
  for (int j = 0; j < 20; j++)
    for (int i = 0; i < 10; i++)
      ck_assert(oc_stacks_set(s, i, j, m, t, 2, &err) == OC_OK);
  oc_program *solid =
      oct_compile(OCT_OK(oc_stacks_field(
                      s, 1u << OC_MAT_BEDROCK | 1u << OC_MAT_SAND, NAN, &err)),
                  T, 0);
  const oc_program *w[2] = {
      oct_compile(OCT_OK(oc_stacks_field(s, 1u << OC_MAT_SAND, 1, &err)), T, 0),
      oct_compile(OCT_OK(oc_stacks_field(s, 1u << OC_MAT_BEDROCK, 1, &err)), T,
                  0)};
  const double col[6] = {0.5, 0.42, 0.28, 0.22, 0.18, 0.15};
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{0, 0, 1}, {19, 19, 10}};
  pp.cell = 0.5;
  pp.open = 1;
  oc_mesh *mesh = oc_polygonize(solid, &pp, &err);
  ck_assert_msg(mesh != NULL, "%s", err.msg);
  size_t nv = oc_mesh_vertex_count(mesh);
  const float *P = oc_mesh_positions(mesh);
  for (int pass = 0; pass < 2; pass++) {
    double amp = pass ? 0.3 : 0;
    ck_assert_msg(oc_mesh_color_by_blend(mesh, w, col, 2, amp, 4, &err) ==
                      OC_OK,
                  "%s", err.msg);
    const float *C = oc_mesh_colors(mesh);
    int sand = 0, rock = 0, mixed = 0;
    for (size_t v = 0; v < nv; v++) {
      double x = P[3 * v], y = P[3 * v + 1];
      if (y < 2 || y > 17) continue; /* away from the grid's sides */
      const double *want = x < 7 ? col : x > 12 ? col + 3 : NULL;
      if (want) {
        for (int c = 0; c < 3; c++) {
          double lo = want[c] * (1 - amp) - 1e-6, hi = want[c] * (1 + amp);
          ck_assert_msg(C[3 * v + c] >= lo && C[3 * v + c] <= hi + 1e-6,
                        "vertex at x %g: %g not in [%g, %g]", x, C[3 * v + c],
                        lo, hi);
        }
        if (amp == 0) ck_assert_float_eq_tol(C[3 * v], want[0], 1e-6);
        sand += x < 7;
        rock += x > 12;
      } else if (amp == 0 && C[3 * v] < 0.49 && C[3 * v] > 0.23) {
        mixed++;
      }
    }
    ck_assert(sand > 50 && rock > 50 && (amp > 0 || mixed > 10));
  }
  /* bad input names the field */
  const double bad[6] = {0.5, 0.42, 2, 0.22, 0.18, 0.15};
  ck_assert_int_eq(oc_mesh_color_by_blend(mesh, w, bad, 2, 0, 4, &err),
                   OC_EINVAL);
  ck_assert(strstr(err.msg, "'blend[1]'"));
  ck_assert_int_eq(oc_mesh_color_by_blend(mesh, w, col, 2, 0, 0, &err),
                   OC_EINVAL);
  ck_assert(strstr(err.msg, "'texture_scale'"));
  oc_mesh_free(mesh);
  oc_program_free(solid);
  oc_program_free((oc_program *)w[0]);
  oc_program_free((oc_program *)w[1]);
  oc_stacks_free(s);
}
END_TEST

/* The visible ratio (oc_stacks_visible, sigma 1) on a 6 x 6 grid of
** stacks of bedrock 3, air 2, bedrock 1 (a roof), three rows of them
** then bedrock 3 under water 1: the roof's underside counts (over air),
** water is a gap (the bedrock under it shows), tents halve with half a
** sigma, and the gradient matches central differences. */
START_TEST(visible_ratio) {
  oc_error err;
  oc_stacks *s = slab(6, 1, 3);
  uint8_t m[3] = {OC_MAT_BEDROCK, OC_MAT_AIR, OC_MAT_BEDROCK};
  double t[3] = {3, 2, 1};
  for (int j = 0; j < 6; j++)
    for (int i = 0; i < 6; i++)
      ck_assert(oc_stacks_set(s, i, j, m, t, 3, &err) == OC_OK);
  oc_program *bd =
      oct_compile(OCT_OK(oc_stacks_visible(s, OC_MAT_BEDROCK, 1, &err)), T, 0);
  /* the underside at z 5: S = 1, the box [4, 6] half bedrock */
  ck_assert_double_eq_tol(oc_program_eval(bd, (oc_vec3){2.3, 2.6, 5}),
                          1 + 1e-6 * 0.5, 1e-12);
  /* between the underside 5 and the top 6 both tents count */
  ck_assert_double_eq_tol(oc_program_eval(bd, (oc_vec3){2.3, 2.6, 5.5}),
                          1 + 1e-6 * 0.5, 1e-12);
  ck_assert_double_eq_tol(oc_program_eval(bd, (oc_vec3){2.3, 2.6, 3.5}),
                          0.5 + 1e-6 * 0.25, 1e-12);
  /* a sigma from every boundary, no material in the box */
  ck_assert_double_eq_tol(oc_program_eval(bd, (oc_vec3){2.3, 2.6, 4}), 0,
                          1e-15);
  /* water is a gap: the bedrock top under it is the surface */
  uint8_t mw[2] = {OC_MAT_BEDROCK, OC_MAT_WATER};
  double tw[2] = {3, 1};
  for (int j = 3; j < 6; j++)
    for (int i = 0; i < 6; i++)
      ck_assert(oc_stacks_set(s, i, j, mw, tw, 2, &err) == OC_OK);
  oc_program *bw =
      oct_compile(OCT_OK(oc_stacks_visible(s, OC_MAT_BEDROCK, 1, &err)), T, 0);
  oc_program *ww =
      oct_compile(OCT_OK(oc_stacks_visible(s, OC_MAT_WATER, 1, &err)), T, 0);
  ck_assert_double_eq_tol(oc_program_eval(bw, (oc_vec3){2.3, 4, 3}),
                          1 + 1e-6 * 0.5, 1e-12);
  ck_assert_double_eq_tol(oc_program_eval(ww, (oc_vec3){2.3, 4, 3.5}),
                          0.5 + 1e-6 * 0.5, 1e-12);
  /* the gradient, off the stack boundaries */
  const oc_vec3 ps[3] = {{2.3, 4.2, 3.4}, {1.1, 2.7, 5.3}, {3.6, 4.9, 2.8}};
  for (int k = 0; k < 3; k++) {
    oc_vec3 g, p = ps[k];
    oc_program_gradient(bw, p, &g);
    double h = 1e-6, d[3];
    for (int a = 0; a < 3; a++) {
      oc_vec3 u = p, v = p;
      (&u.x)[a] += h;
      (&v.x)[a] -= h;
      d[a] = (oc_program_eval(bw, u) - oc_program_eval(bw, v)) / (2 * h);
    }
    ck_assert_double_eq_tol(g.x, d[0], 1e-6);
    ck_assert_double_eq_tol(g.y, d[1], 1e-6);
    ck_assert_double_eq_tol(g.z, d[2], 1e-6);
  }
  ck_assert(oc_stacks_visible(s, OC_MAT_AIR, 1, &err) == NULL);
  ck_assert(strstr(err.msg, "'material'"));
  ck_assert(oc_stacks_visible(s, OC_MAT_SAND, -1, &err) == NULL);
  ck_assert(strstr(err.msg, "'sigma'"));
  oc_program_free(bd);
  oc_program_free(bw);
  oc_program_free(ww);
  oc_stacks_free(s);
}
END_TEST

/* ---- storage ---------------------------------------------------------------
 */

/* Offsets are a byte of layer count per stack and one offset per block of
** 16 stacks (1.25 bytes a stack) until a stack holds more than 255 layers:
** then one offset per stack. Both give the same layers back, and a set in
** the middle moves every later stack's offset. */
START_TEST(compact_offsets) {
  oc_error err;
  oc_stacks *s = slab(40, 1, 5); /* 1600 stacks of one layer */
  oc_stacks_stats st;
  oc_stacks_get_stats(s, &st);
  ck_assert_uint_eq(st.bytes,
                    sizeof(oc_stacks) + 1600 + (1600 / 16 + 1) * 4 + 1600 * 4);
  uint8_t m[600];
  double t[600];
  for (int l = 0; l < 600; l++) {
    m[l] = l % 2 ? OC_MAT_AIR : OC_MAT_BEDROCK;
    t[l] = 0.25 + 0.001 * l;
  }
  ck_assert(oc_stacks_set(s, 3, 7, m, t, 5, &err) == OC_OK); /* 5 layers */
  ck_assert_uint_eq(oc_soff(s, 7 * 40 + 4), 7 * 40 + 3 + 5);
  ck_assert_uint_eq(oc_soff(s, 1600), 1604);
  ck_assert(s->off == NULL);
  ck_assert(oc_stacks_set(s, 3, 7, m, t, 599, &err) == OC_OK); /* 599 */
  ck_assert(s->off != NULL);
  oc_stacks_get_stats(s, &st);
  ck_assert_uint_eq(st.layers, 1599 + 599);
  ck_assert_uint_eq(st.bytes, sizeof(oc_stacks) + 1601 * 4 + st.layers * 4);
  uint8_t gm[600];
  double gt[600];
  ck_assert_uint_eq(oc_stacks_get(s, 3, 7, gm, gt, 600), 599);
  ck_assert_int_eq(gm[598], OC_MAT_BEDROCK);
  ck_assert_double_eq_tol(gt[598], 0.25 + 0.598, 1e-6);
  ck_assert_uint_eq(oc_stacks_get(s, 4, 7, gm, gt, 600), 1);
  ck_assert_double_eq(gt[0], 5);
  oc_stacks_free(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("layers_tools");
  TCase *tc = tcase_create("layers_tools");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, sculpt_round_trip);
  tcase_add_test(tc, from_program_progress);
  tcase_add_test(tc, empty_and_far_grids);
  tcase_add_test(tc, sweep_crack_profile);
  tcase_add_test(tc, sweep_crack_follows_surface);
  tcase_add_test(tc, sweep_branches_and_tunnel);
  tcase_add_test(tc, sweep_bend_mitred);
  tcase_add_test(tc, sweep_sand_threads_errors);
  tcase_add_test(tc, texture_by_material);
  tcase_add_test(tc, visible_ratio);
  tcase_add_test(tc, compact_offsets);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
