/*
** test_layers.c — material stacks (Peytavie et al. 2009): the canonical
** form (merge, sort between bedrock layers), packed sizes, conversions,
** the convolution surface against a direct computation of V_M (value,
** gradient, Lipschitz bound, support, column spans), from_program then
** field reproducing a sphere within a cell, stabilisation (volume
** conserved, every slope under the angle of repose, identical for 1 and 2
** threads), deposit, and parameter errors.
*/
#include <omp.h>
#include <string.h>

#include "layers/layers.h"
#include "ocheck.h"

#define T 0.5

static oc_stacks *grid(int nx, int ny, double cell, double zbase) {
  oc_error err;
  oc_stacks *s = oc_stacks_new(nx, ny, cell, 0, 0, zbase, &err);
  ck_assert_msg(s != NULL, "%s", err.msg);
  return s;
}

static void set(oc_stacks *s, int i, int j, const uint8_t *m, const double *t,
                size_t n) {
  oc_error err;
  ck_assert_msg(oc_stacks_set(s, i, j, m, t, n, &err) == OC_OK, "%s", err.msg);
}

START_TEST(canonical_form) {
  oc_stacks *s = grid(3, 2, 1, 0);
  /* sand, air, bedrock, air, water, sand, rocks, sand, bedrock, bedrock,
  ** air, sand, air */
  uint8_t m[] = {OC_MAT_SAND,    OC_MAT_AIR,     OC_MAT_BEDROCK, OC_MAT_AIR,
                 OC_MAT_WATER,   OC_MAT_SAND,    OC_MAT_ROCKS,   OC_MAT_SAND,
                 OC_MAT_BEDROCK, OC_MAT_BEDROCK, OC_MAT_AIR,     OC_MAT_SAND,
                 OC_MAT_AIR};
  double t[] = {1, 2, 3, 4, 0.5, 1, 2, 0.25, 5, 1, 7, 0.5, 3};
  set(s, 1, 1, m, t, 13);
  uint8_t gm[16];
  double gt[16];
  size_t n = oc_stacks_get(s, 1, 1, gm, gt, 16);
  /* gap 0: sand 1, air 2 | bedrock 3 | sand 1.25, rocks 2, water 0.5,
  ** air 4 | bedrock 6 | sand 0.5 (air on top dropped) */
  uint8_t em[] = {OC_MAT_SAND, OC_MAT_AIR,     OC_MAT_BEDROCK,
                  OC_MAT_SAND, OC_MAT_ROCKS,   OC_MAT_WATER,
                  OC_MAT_AIR,  OC_MAT_BEDROCK, OC_MAT_SAND};
  double et[] = {1, 2, 3, 1.25, 2, 0.5, 4, 6, 0.5};
  ck_assert_uint_eq(n, 9);
  for (size_t l = 0; l < n; l++) {
    ck_assert_int_eq(gm[l], em[l]);
    ck_assert_double_eq(gt[l], et[l]);
  }
  oc_stacks_stats st;
  oc_stacks_get_stats(s, &st);
  ck_assert_uint_eq(st.stacks, 6);
  ck_assert_uint_eq(st.layers, 9);
  ck_assert_uint_eq(st.bytes, sizeof(oc_stacks) + 6 + 4 + 9 * 4);
  ck_assert_double_eq(oc_stacks_volume(s, OC_MAT_SAND), 2.75);
  ck_assert_double_eq(oc_stacks_volume(s, OC_MAT_BEDROCK), 9);
  /* the top of sand: 1 + 2 + 3 + 7.75 + 6 + 0.5 */
  oc_error err;
  oc_heightfield *hf = oc_stacks_heightfield(s, OC_MAT_SAND, &err);
  ck_assert_ptr_nonnull(hf);
  ck_assert_float_eq(oc_heightfield_samples(hf)[4], 20.25f);
  ck_assert_float_eq(oc_heightfield_samples(hf)[0], 0.0f); /* none: base */
  oc_heightfield_release(hf);
  /* replacing keeps the others */
  uint8_t b = OC_MAT_BEDROCK;
  double h = 2;
  set(s, 0, 0, &b, &h, 1);
  ck_assert_uint_eq(oc_stacks_get(s, 1, 1, NULL, NULL, 0), 9);
  ck_assert_uint_eq(oc_stacks_get(s, 0, 0, gm, gt, 16), 1);
  ck_assert_double_eq(gt[0], 2);
  oc_stacks_free(s);
}
END_TEST

START_TEST(from_heightfield_volumes) {
  oc_error err;
  float z[12];
  double sum = 0;
  for (int k = 0; k < 12; k++)
    sum += (z[k] = (float)(3 + (k * 7) % 5));
  oc_heightfield *hf = oc_heightfield_new(4, 3, 2, 10, 20, z, &err);
  oc_stacks_hf_params p = {NAN, 0.5};
  oc_stacks *s = oc_stacks_from_heightfield(hf, &p, &err);
  ck_assert_ptr_nonnull(s);
  ck_assert_double_eq(oc_stacks_base(s), 2); /* lowest sample 3, minus 1 */
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_BEDROCK),
                          (sum - 12 * 2) * 4, 1e-9);
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_SAND), 12 * 0.5 * 4, 1e-9);
  oc_heightfield *top = oc_stacks_heightfield(s, OC_MAT_BEDROCK, &err);
  for (int k = 0; k < 12; k++)
    ck_assert_float_eq(oc_heightfield_samples(top)[k], z[k]);
  oc_heightfield_release(top);
  p.sand = -1;
  ck_assert_ptr_null(oc_stacks_from_heightfield(hf, &p, &err));
  ck_assert(strstr(err.msg, "'sand'"));
  oc_heightfield_release(hf);
  oc_stacks_free(s);
}
END_TEST

/* ---- the convolution surface ---------------------------------------------
 */

/* V_M by direct summation over every stack: the reference. */
static double ref_field(const oc_stacks *s, unsigned mask, double sg,
                        oc_vec3 p) {
  double V = 0, c = oc_stacks_cell(s), x0, y0;
  oc_stacks_origin(s, &x0, &y0);
  for (int j = 0; j < oc_stacks_ny(s); j++)
    for (int i = 0; i < oc_stacks_nx(s); i++) {
      double ax = x0 + (i - 0.5) * c, ay = y0 + (j - 0.5) * c;
      double wx = fmin(p.x + sg, ax + c) - fmax(p.x - sg, ax);
      double wy = fmin(p.y + sg, ay + c) - fmax(p.y - sg, ay);
      if (wx <= 0 || wy <= 0) continue;
      uint8_t m[64];
      double t[64], z = oc_stacks_base(s), len = 0;
      size_t n = oc_stacks_get(s, i, j, m, t, 64);
      for (size_t l = 0; l < n; l++) {
        if (mask & 1u << m[l]) {
          double w = fmin(p.z + sg, z + t[l]) - fmax(p.z - sg, z);
          if (w > 0) len += w;
        }
        z += t[l];
      }
      V += wx * wy * len;
    }
  return 2 * T * V / (8 * sg * sg * sg);
}

/* A 6 x 5 grid of cell 2 with bedrock, caves and sand of varied heights. */
static oc_stacks *scene(void) {
  oc_stacks *s = grid(6, 5, 2, -3);
  oct_rng r = oct_rng_new(5);
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 6; i++) {
      uint8_t m[] = {OC_MAT_BEDROCK, OC_MAT_AIR, OC_MAT_BEDROCK, OC_MAT_SAND};
      double t[] = {oct_unif(&r, 1, 4),
                    (i + j) % 3 == 0 ? 0 : oct_unif(&r, 1, 3),
                    oct_unif(&r, 0, 3), oct_unif(&r, 0, 1.5)};
      set(s, i, j, m, t, 4);
    }
  return s;
}

START_TEST(field_matches_direct_volume) {
  oc_stacks *s = scene();
  oc_error err;
  oct_rng r = oct_rng_new(9);
  const unsigned masks[2] = {1u << OC_MAT_BEDROCK,
                             1u << OC_MAT_BEDROCK | 1u << OC_MAT_SAND};
  const double sigmas[2] = {2, 0.7};
  for (int a = 0; a < 2; a++) {
    oc_program *pr = oct_compile(
        OCT_OK(oc_stacks_field(s, masks[a], sigmas[a], &err)), T, 0);
    oc_vec3 lo = oct_v(-4, -4, -6), hi = oct_v(13, 11, 14);
    int inside = 0;
    for (int k = 0; k < 3000; k++) {
      oc_vec3 p = oct_in_box(&r, lo, hi);
      double f = oc_program_eval(pr, p);
      ck_assert_double_eq_tol(f, ref_field(s, masks[a], sigmas[a], p), 1e-12);
      inside += f > T;
      if (k < 500) oct_check_grad(pr, p, 1e-6, 1e-5);
    }
    ck_assert_msg(inside > 100 && inside < 2700, "inside %d", inside);
    ck_assert_double_eq_tol(oc_program_lipschitz(pr), sqrt(3) * T / sigmas[a],
                            1e-6);
    oct_check_lipschitz(pr, lo, hi, 3000, &r);
    ck_assert(oct_check_bounds(pr, lo, hi, 3000, &r) > 100);
    /* column spans: f is the same at any two points of a footprint at
    ** heights between two spans */
    for (int k = 0; k < 300; k++) {
      double x = oct_unif(&r, -3, 12), y = oct_unif(&r, -3, 10);
      double w = oct_unif(&r, 0, 3);
      oc_zspan sp[32];
      int n = oc_program_column_spans(pr, x, y, x + w, y + w, sp, 32);
      ck_assert(n >= 0);
      for (int q = 0; q + 1 < n; q++) {
        double z1 = oct_unif(&r, sp[q].hi, sp[q + 1].lo);
        double z2 = oct_unif(&r, sp[q].hi, sp[q + 1].lo);
        double f1 = oc_program_eval(pr, oct_v(x + oct_unif(&r, 0, w), y, z1));
        double f2 = oc_program_eval(pr, oct_v(x, y + oct_unif(&r, 0, w), z2));
        ck_assert_double_eq_tol(f1, f2, 1e-12);
      }
      double zb = oct_unif(&r, -20, n ? sp[0].lo : 20);
      ck_assert_double_eq(oc_program_eval(pr, oct_v(x + w / 2, y, zb)), 0);
    }
    oc_program_free(pr);
  }
  oc_stacks_free(s);
}
END_TEST

/* A flat slab: the surface where the cube is half full, f linear in z. */
START_TEST(field_flat_slab) {
  oc_stacks *s = grid(9, 9, 1, 0);
  uint8_t m = OC_MAT_BEDROCK;
  double t = 10;
  for (int j = 0; j < 9; j++)
    for (int i = 0; i < 9; i++)
      set(s, i, j, &m, &t, 1);
  oc_error err;
  oc_program *pr = oct_compile(
      OCT_OK(oc_stacks_field(s, 1u << OC_MAT_BEDROCK, NAN, &err)), T, 0);
  for (double z = 8.1; z <= 12; z += 0.25) {
    oc_vec3 g;
    double f = oc_program_gradient(pr, oct_v(4.3, 3.9, z), &g);
    double want = 2 * T * fmin(fmax((10 - (z - 1)) / 2, 0), 1);
    ck_assert_double_eq_tol(f, want, 1e-12);
    ck_assert_double_eq_tol(g.z, z > 9 && z < 11 ? -T : 0, 1e-12);
    ck_assert_double_eq(g.x, 0);
  }
  ck_assert_double_eq_tol(oc_program_eval(pr, oct_v(2, 2, 10)), T, 1e-12);
  oc_program_free(pr);
  OCT_EINVAL(oc_stacks_field(s, 1u << OC_MAT_BEDROCK, 0, &err), err, "sigma");
  OCT_EINVAL(oc_stacks_field(s, 1u << OC_MAT_BEDROCK, -1, &err), err, "sigma");
  OCT_EINVAL(oc_stacks_field(s, 1u << OC_MAT_AIR, 1, &err), err, "materials");
  OCT_EINVAL(oc_stacks_field(s, 0, 1, &err), err, "materials");
  oc_stacks_free(s);
}
END_TEST

/* A box with a spherical cave: air layers; the field of the stacks puts
** its surface within a cell of the node's. */
START_TEST(from_program_reproduces_surface) {
  oc_error err;
  double R = 6, F = 2, rs = R + 0.45420201894740647 * F; /* f = T there */
  oc_node *box =
      OCT_OK(oc_box(oct_v(-12, -12, -12), oct_v(12, 12, 12), 1, 1, &err));
  oc_node *ball = OCT_OK(oc_sphere(oct_v(0, 0, 0), R, F, 1, &err));
  oc_node *cave = OCT_OK(oc_difference(box, ball, &err));
  oc_node_release(box);
  oc_node_release(ball);
  oc_program *src = oct_compile(cave, T, 0);
  double cell = 0.5;
  oc_stacks_node_params np = {
      {{-11, -11, -11}, {11, 11, 11}}, cell, 0, OC_MAT_BEDROCK, {NULL, NULL}};
  oc_stacks *s = oc_stacks_from_program(src, &np, &err);
  ck_assert_msg(s != NULL, "%s", err.msg);
  ck_assert_int_eq(oc_stacks_nx(s), 45);
  /* through the centre: bedrock, air (the cave), bedrock */
  uint8_t m[8];
  double t[8];
  ck_assert_uint_eq(oc_stacks_get(s, 22, 22, m, t, 8), 3);
  ck_assert_int_eq(m[1], OC_MAT_AIR);
  ck_assert_double_eq_tol(t[1], 2 * rs, 1e-5);
  ck_assert_double_eq_tol(t[0], 11 - rs, 1e-5);
  oc_program *pr = oct_compile(
      OCT_OK(oc_stacks_field(s, 1u << OC_MAT_BEDROCK, NAN, &err)), T, 0);
  oct_rng r = oct_rng_new(3);
  for (int k = 0; k < 300; k++) {
    oc_vec3 d = oct_dir(&r);
    /* the layer field along the ray from the centre crosses T within a
    ** cell of the cave's radius */
    double a = rs - 2 * cell, b = rs + 2 * cell;
    ck_assert(oc_program_eval(pr, oct_mul(d, a)) < T);
    ck_assert(oc_program_eval(pr, oct_mul(d, b)) > T);
    for (int it = 0; it < 50; it++) {
      double c = 0.5 * (a + b);
      if (oc_program_eval(pr, oct_mul(d, c)) > T)
        b = c;
      else
        a = c;
    }
    ck_assert_msg(fabs(a - rs) <= cell, "radius %g vs %g", a, rs);
  }
  /* and a mesh of it, like any node: the column spans skip no surface
  ** (the same mesh as the full grid's) */
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{-13, -13, -13}, {13, 13, 13}};
  pp.cell = 0.8;
  oc_mesh *a = oc_polygonize(pr, &pp, &err);
  ck_assert_msg(a != NULL, "%s", err.msg);
  pp.full_grid = 1;
  oc_mesh *b = oc_polygonize(pr, &pp, &err);
  ck_assert_uint_gt(oc_mesh_triangle_count(a), 1000);
  ck_assert_uint_eq(oc_mesh_triangle_count(a), oc_mesh_triangle_count(b));
  ck_assert_uint_eq(oc_mesh_vertex_count(a), oc_mesh_vertex_count(b));
  const float *v = oc_mesh_positions(a);
  for (size_t k = 0; k < oc_mesh_vertex_count(a); k += 7)
    ck_assert_double_eq_tol(
        oc_program_eval(pr, oct_v(v[3 * k], v[3 * k + 1], v[3 * k + 2])), T,
        1e-3);
  oc_mesh_stats ma, mb;
  oc_mesh_get_stats(a, &ma);
  oc_mesh_get_stats(b, &mb);
  ck_assert_uint_lt(ma.field_calls, mb.field_calls);
  oc_mesh_free(a);
  oc_mesh_free(b);
  oc_program_free(pr);
  oc_program_free(src);
  oc_stacks_free(s);
}
END_TEST

/* ---- stabilisation --------------------------------------------------------
 */

/* The top of the solid of each stack's last segment. */
static void tops(const oc_stacks *s, double *h) {
  oc_lseg seg[64];
  for (int k = 0; k < oc_stacks_nx(s) * oc_stacks_ny(s); k++) {
    size_t n = oc_layers_segments(s, (size_t)k, seg);
    h[k] = seg[n - 1].floor + seg[n - 1].a[0] + seg[n - 1].a[1];
  }
}

static oc_stacks *sand_pile(int n, double peak) {
  oc_stacks *s = grid(n, n, 1, 0);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      double dx = i - n / 2, dy = j - n / 3;
      uint8_t m[] = {OC_MAT_BEDROCK, OC_MAT_SAND};
      double t[] = {5 + 0.1 * i, fmax(0, peak - sqrt(dx * dx + dy * dy))};
      set(s, i, j, m, t, 2);
    }
  return s;
}

START_TEST(stabilize_conserves_and_rests) {
  oc_error err;
  oc_stacks *s = sand_pile(40, 12);
  double v0 = oc_stacks_volume(s, OC_MAT_SAND);
  double b0 = oc_stacks_volume(s, OC_MAT_BEDROCK);
  oc_stabilize_params p;
  oc_stabilize_defaults(s, &p);
  oc_stabilize_result res;
  ck_assert_msg(oc_stacks_stabilize(s, &p, &res, &err) == OC_OK, "%s", err.msg);
  ck_assert(res.converged);
  ck_assert(res.iterations > 10);
  ck_assert(res.moved > 0.05 * v0);
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_SAND), v0, 1e-6 * v0);
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_BEDROCK), b0, 1e-6 * b0);
  /* every slope from a stack with sand under the angle of repose (plus
  ** what the tolerance leaves) */
  double h[1600], ta = tan(32 * 3.14159265358979323846 / 180);
  tops(s, h);
  int steep = 0;
  for (int j = 0; j < 40; j++)
    for (int i = 0; i < 40; i++) {
      uint8_t m[4];
      size_t n = oc_stacks_get(s, i, j, m, NULL, 4);
      if (m[n - 1] != OC_MAT_SAND) continue;
      for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
          int a = i + di, b = j + dj;
          if ((!di && !dj) || a < 0 || b < 0 || a >= 40 || b >= 40) continue;
          double lim = (di && dj ? sqrt(2) : 1) * ta;
          double d = h[j * 40 + i] - h[b * 40 + a];
          ck_assert_msg(d <= lim + 8 * p.tolerance / p.rate,
                        "slope %g > %g at %d %d", d, lim, i, j);
          steep += d > 0.9 * lim;
        }
    }
  ck_assert(steep > 50); /* a pile at rest, not flattened */
  oc_stacks_free(s);
}
END_TEST

static void same_stacks(const oc_stacks *a, const oc_stacks *b) {
  oc_stacks_stats sa, sb;
  oc_stacks_get_stats(a, &sa);
  oc_stacks_get_stats(b, &sb);
  ck_assert_uint_eq(sa.layers, sb.layers);
  for (size_t k = 0; k <= sa.stacks; k++)
    ck_assert_uint_eq(oc_soff(a, k), oc_soff(b, k));
  ck_assert(memcmp(a->lay, b->lay, sa.layers * sizeof *a->lay) == 0);
}

START_TEST(deposit_and_threads) {
  oc_error err;
  oc_stacks *s[2];
  double added[2];
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t + 1);
    s[t] = sand_pile(48, 4);
    double v0 = oc_stacks_volume(s[t], OC_MAT_SAND);
    double r0 = oc_stacks_volume(s[t], OC_MAT_ROCKS);
    oc_deposit_params dp = {30, 20, 8, 6, OC_MAT_SAND, 1, NULL};
    oc_stabilize_result res;
    ck_assert_msg(oc_stacks_deposit(s[t], &dp, &added[t], &res, &err) == OC_OK,
                  "%s", err.msg);
    ck_assert(res.converged && res.moved > 0);
    ck_assert_double_eq_tol(oc_stacks_volume(s[t], OC_MAT_SAND), v0 + added[t],
                            1e-6 * (v0 + added[t]));
    dp.material = OC_MAT_ROCKS;
    dp.amount = 3;
    double ar;
    ck_assert(oc_stacks_deposit(s[t], &dp, &ar, &res, &err) == OC_OK);
    ck_assert(ar > 0);
    ck_assert_double_eq_tol(oc_stacks_volume(s[t], OC_MAT_ROCKS), r0 + ar,
                            1e-6 * ar);
  }
  omp_set_num_threads(2);
  /* A g(r / R) summed over the stacks within R */
  double want = 0;
  for (int j = 0; j < 48; j++)
    for (int i = 0; i < 48; i++) {
      double r = sqrt((i - 30.0) * (i - 30.0) + (j - 20.0) * (j - 20.0)) / 8;
      want += 6 * oct_g(r);
    }
  ck_assert_double_eq_tol(added[0], want, 1e-9 * want);
  ck_assert_double_eq(added[0], added[1]);
  same_stacks(s[0], s[1]);
  oc_stacks_free(s[0]);
  oc_stacks_free(s[1]);
}
END_TEST

START_TEST(parameter_errors) {
  oc_error err;
  oc_stacks *s = grid(4, 4, 1, 0);
  uint8_t m[] = {OC_MAT_BEDROCK, 9};
  double t[] = {-1, 1};
  ck_assert_int_eq(oc_stacks_set(s, 0, 0, m, t, 1, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'thickness'"));
  t[0] = 1;
  ck_assert_int_eq(oc_stacks_set(s, 0, 0, m, t, 2, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'material'"));
  ck_assert_int_eq(oc_stacks_set(s, 4, 0, m, t, 1, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'i'"));
  ck_assert_ptr_null(oc_stacks_new(0, 3, 1, 0, 0, 0, &err));
  ck_assert(strstr(err.msg, "'size'"));
  ck_assert_ptr_null(oc_stacks_new(3, 3, -1, 0, 0, 0, &err));
  ck_assert(strstr(err.msg, "'cell'"));
  oc_stabilize_params p;
  oc_stabilize_defaults(s, &p);
  p.angle[OC_MAT_SAND] = 90;
  ck_assert_int_eq(oc_stacks_stabilize(s, &p, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'angle.sand'"));
  oc_stabilize_defaults(s, &p);
  p.rate = 0.9;
  ck_assert_int_eq(oc_stacks_stabilize(s, &p, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'rate'"));
  oc_deposit_params dp = {1, 1, 0, 1, OC_MAT_SAND, 1, NULL};
  ck_assert_int_eq(oc_stacks_deposit(s, &dp, NULL, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'radius'"));
  dp.radius = 1;
  dp.material = OC_MAT_BEDROCK;
  ck_assert_int_eq(oc_stacks_deposit(s, &dp, NULL, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'material'"));
  ck_assert_int_eq(oc_material_parse("sand"), OC_MAT_SAND);
  ck_assert_int_eq(oc_material_parse("lava"), -1);
  ck_assert_str_eq(oc_material_name(OC_MAT_BEDROCK), "bedrock");
  oc_stacks_free(s);
}
END_TEST

START_TEST(erode_modes) {
  oc_error err;
  oc_stacks *s = grid(10, 10, 1, 0);
  uint8_t m[] = {OC_MAT_BEDROCK, OC_MAT_AIR, OC_MAT_BEDROCK, OC_MAT_SAND};
  double t[] = {5, 3, 1, 0.5};
  ck_assert(oc_stacks_fill(s, m, t, 4, &err) == OC_OK);
  double tot0 = oc_stacks_volume(s, OC_MAT_BEDROCK) +
                oc_stacks_volume(s, OC_MAT_SAND) +
                oc_stacks_volume(s, OC_MAT_ROCKS);
  /* the roofs of the 3 x 2 stacks in the region collapse onto the floor */
  oc_stacks_erode_params ep = {
      2, 3, 4, 4.5, 0.25, 2, OC_STACKS_ERODE_COLLAPSE, 0, NULL};
  double v;
  ck_assert(oc_stacks_erode(s, &ep, &v, NULL, &err) == OC_OK);
  ck_assert_double_eq(v, 6);
  uint8_t gm[8];
  double gt[8];
  ck_assert_uint_eq(oc_stacks_get(s, 3, 4, gm, gt, 8), 3);
  ck_assert_int_eq(gm[0], OC_MAT_BEDROCK);
  ck_assert_double_eq(gt[0], 5);
  ck_assert_int_eq(gm[1], OC_MAT_SAND);
  ck_assert_double_eq(gt[1], 0.75);
  ck_assert_int_eq(gm[2], OC_MAT_ROCKS);
  ck_assert_double_eq(gt[2], 0.75);
  ck_assert_uint_eq(oc_stacks_get(s, 3, 5, NULL, NULL, 0), 4); /* outside */
  ck_assert_double_eq(oc_stacks_volume(s, OC_MAT_ROCKS), 6 * 0.75);
  /* a roof thicker than depth stays */
  ep.x0 = 6, ep.x1 = 8, ep.depth = 0.5;
  ck_assert(oc_stacks_erode(s, &ep, &v, NULL, &err) == OC_OK);
  ck_assert_double_eq(v, 0);
  /* the surface, stabilised: volume conserved */
  ep = (oc_stacks_erode_params){0, 0,   9, 9, 0.5, 0.4, OC_STACKS_ERODE_SURFACE,
                                1, NULL};
  oc_stabilize_result res;
  ck_assert(oc_stacks_erode(s, &ep, &v, &res, &err) == OC_OK);
  ck_assert_double_eq_tol(v, 100 * 0.4, 1e-9);
  double tot1 = oc_stacks_volume(s, OC_MAT_BEDROCK) +
                oc_stacks_volume(s, OC_MAT_SAND) +
                oc_stacks_volume(s, OC_MAT_ROCKS);
  ck_assert_double_eq_tol(tot1, tot0, 1e-6 * tot0); /* floats */
  ck_assert(res.converged && res.moved > 0);
  ep.ratio = 2;
  ck_assert_int_eq(oc_stacks_erode(s, &ep, &v, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'ratio'"));
  oc_stacks_free(s);
}
END_TEST

/* Sculpting a flat slab: adding raises the top around the centre and
** adds bedrock there only; carving the same place removes it. */
START_TEST(sculpt_add_carve) {
  oc_error err;
  oc_stacks *s = grid(24, 24, 0.5, 0);
  uint8_t m = OC_MAT_BEDROCK;
  double t = 10;
  ck_assert(oc_stacks_fill(s, &m, &t, 1, &err) == OC_OK);
  double v0 = oc_stacks_volume(s, OC_MAT_BEDROCK);
  oc_sculpt_params sp = {{6, 6, 10}, 3, 2, NAN, 0, 0, 0, NULL};
  double dv;
  ck_assert_msg(oc_stacks_sculpt(s, &sp, &dv, NULL, &err) == OC_OK, "%s",
                err.msg);
  ck_assert(dv > 1);
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_BEDROCK), v0 + dv, 1e-9);
  /* the top at the centre: where T(1 - (z - 10)) + 4T K = T, K over the
  ** distance to c' = (6, 6, 8.5) (f of the slab, sigma = 0.5: linear
  ** over 9.5 .. 10.5, then 0) */
  oc_heightfield *hf = oc_stacks_heightfield(s, OC_MAT_BEDROCK, &err);
  double top = oc_heightfield_samples(hf)[12 * 24 + 12];
  double a = 10, b = 13;
  for (int it = 0; it < 60; it++) {
    double z = 0.5 * (a + b), q = (z - 8.5) * (z - 8.5) / 9;
    double K = q < 1 ? (1 - q) * (1 - q) : 0;
    double f = 2 * T * fmin(fmax((10.5 - z) / 1, 0), 1) + 4 * T * K;
    if (f > T)
      a = z;
    else
      b = z;
  }
  ck_assert_double_eq_tol(top, a, 1e-4);
  ck_assert_float_eq(oc_heightfield_samples(hf)[0], 10); /* far: as before */
  oc_heightfield_release(hf);
  sp.carve = 1;
  sp.center.z = top;
  ck_assert(oc_stacks_sculpt(s, &sp, &dv, NULL, &err) == OC_OK);
  ck_assert(dv < -1);
  sp.radius = 0;
  ck_assert_int_eq(oc_stacks_sculpt(s, &sp, &dv, NULL, &err), OC_EINVAL);
  ck_assert(strstr(err.msg, "'radius'"));
  oc_stacks_free(s);
}
END_TEST

/* A deposit stabilised in a window around it (grown while material
** reaches its border) gives the stacks the whole grid's stabilisation
** gives. */
START_TEST(local_equals_whole) {
  oc_error err;
  oc_stacks *s[2];
  for (int k = 0; k < 2; k++) {
    s[k] = grid(90, 80, 1, 0);
    uint8_t m = OC_MAT_BEDROCK;
    double t = 3;
    ck_assert(oc_stacks_fill(s[k], &m, &t, 1, &err) == OC_OK);
    oc_deposit_params dp = {40, 35, 3, 200, OC_MAT_SAND, k == 0, NULL};
    double added;
    oc_stabilize_result res;
    ck_assert(oc_stacks_deposit(s[k], &dp, &added, &res, &err) == OC_OK);
    if (k == 1) {
      ck_assert(oc_stacks_stabilize(s[k], NULL, &res, &err) == OC_OK);
      ck_assert(res.converged);
    }
  }
  /* the pile spread past the first window (8 stacks around 7 x 7) */
  uint8_t mm[4];
  ck_assert_uint_eq(oc_stacks_get(s[0], 40 - 13, 35, mm, NULL, 4), 2);
  same_stacks(s[0], s[1]);
  oc_stacks_free(s[0]);
  oc_stacks_free(s[1]);
}
END_TEST

/* Passes over large boxes run on both threads: the same stacks as on
** one. */
START_TEST(large_grid_threads) {
  oc_error err;
  oc_stacks *s[2];
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t + 1);
    s[t] = sand_pile(300, 6);
    for (int k = 0; k < 4; k++) { /* piles far apart: a box of 90 000 */
      oc_deposit_params dp = {
          20 + 260 * (k & 1), 20 + 260 * (k >> 1), 6, 5, OC_MAT_SAND, 0, NULL};
      ck_assert(oc_stacks_deposit(s[t], &dp, NULL, NULL, &err) == OC_OK);
    }
    oc_stabilize_result res;
    ck_assert(oc_stacks_stabilize(s[t], NULL, &res, &err) == OC_OK);
    ck_assert(res.converged && res.moved > 0);
  }
  omp_set_num_threads(2);
  same_stacks(s[0], s[1]);
  oc_stacks_free(s[0]);
  oc_stacks_free(s[1]);
}
END_TEST

/* The coarse levels move material several stacks at once, but only down
** a slope: a pile against a thin, tall bedrock wall stays on its side
** (a stride of 8 from a 12 m pile would otherwise clear the wall). */
START_TEST(strides_do_not_jump_walls) {
  oc_error err;
  oc_stacks *s = grid(120, 40, 1, 0);
  uint8_t m = OC_MAT_BEDROCK;
  double t = 5, wall = 45;
  ck_assert(oc_stacks_fill(s, &m, &t, 1, &err) == OC_OK);
  for (int j = 0; j < 40; j++)
    set(s, 62, j, &m, &wall, 1);
  oc_deposit_params dp = {46, 20, 15, 30, OC_MAT_SAND, 1, NULL};
  double added;
  oc_stabilize_result res;
  ck_assert(oc_stacks_deposit(s, &dp, &added, &res, &err) == OC_OK);
  ck_assert(res.converged && res.moved > 0);
  ck_assert_double_eq_tol(oc_stacks_volume(s, OC_MAT_SAND), added,
                          1e-6 * added);
  double beyond = 0, near = 0;
  for (int j = 0; j < 40; j++)
    for (int i = 0; i < 120; i++) {
      uint8_t mm[4];
      double th[4];
      size_t n = oc_stacks_get(s, i, j, mm, th, 4);
      if (n > 1 && mm[n - 1] == OC_MAT_SAND) {
        if (i > 62) beyond += th[n - 1];
        if (i == 61) near += th[n - 1];
      }
    }
  ck_assert(beyond == 0);
  ck_assert(near > 1); /* the pile reached the wall */
  oc_stacks_free(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("layers");
  TCase *tc = tcase_create("layers");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, canonical_form);
  tcase_add_test(tc, from_heightfield_volumes);
  tcase_add_test(tc, field_matches_direct_volume);
  tcase_add_test(tc, field_flat_slab);
  tcase_add_test(tc, from_program_reproduces_surface);
  tcase_add_test(tc, stabilize_conserves_and_rests);
  tcase_add_test(tc, strides_do_not_jump_walls);
  tcase_add_test(tc, deposit_and_threads);
  tcase_add_test(tc, local_equals_whole);
  tcase_add_test(tc, large_grid_threads);
  tcase_add_test(tc, erode_modes);
  tcase_add_test(tc, sculpt_add_carve);
  tcase_add_test(tc, parameter_errors);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
