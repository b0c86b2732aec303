/*
** test_meshio.c — meshes and their files: the oc_mesh container, colours
** (given, or from a field through a palette), the PLY / OBJ / GLB writers
** read back by the tests' own reader (meshread.c) and checked for exact
** values, structure and topology; atomic writes and their failures; the
** reader's own checks on meshes built by hand to be wrong in one way each.
*/
#include <check.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/atomic.h"
#include "mesh/mesh.h"
#include "meshread.h"
#include "ocheck.h"
#include "octmpfs.h"
#include "outcrop.h"

/* ---- folders ------------------------------------------------------------ */

static char dir[64];

static void mkdir_tmp(void) {
  strcpy(dir, oct_tmpdir("meshio"));
}

static void teardown(void) {
  oct_rm_tree(dir);
}

/* ---- meshes built by hand ----------------------------------------------- */

/* A mesh with these positions and triangles; normals are the normalized
** area-weighted sums of the triangle normals (so they agree with the
** winding), or +z where that sum vanishes. */
static oc_mesh *build(const float *pos, size_t nv, const uint32_t *tri,
                      size_t nt) {
  oc_error e = {0};
  oc_mesh *m = oc_mesh_alloc(nv, nt, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  memcpy(m->pos, pos, 3 * nv * sizeof *pos);
  if (nt) memcpy(m->tri, tri, 3 * nt * sizeof *tri);
  double *acc = calloc(3 * nv + 1, sizeof *acc);
  for (size_t t = 0; t < nt; t++) {
    const float *a = pos + 3 * tri[3 * t], *b = pos + 3 * tri[3 * t + 1],
                *c = pos + 3 * tri[3 * t + 2];
    oc_vec3 u = oct_v(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    oc_vec3 v = oct_v(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    oc_vec3 n = oct_cross(u, v);
    for (int k = 0; k < 3; k++) {
      double *s = acc + 3 * tri[3 * t + k];
      s[0] += n.x, s[1] += n.y, s[2] += n.z;
    }
  }
  for (size_t i = 0; i < nv; i++) {
    double *s = acc + 3 * i;
    double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int c = 0; c < 3; c++)
      m->nrm[3 * i + c] = l > 0 ? (float)(s[c] / l) : (c == 2 ? 1.0f : 0.0f);
  }
  free(acc);
  return m;
}

static const float tetra_pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t tetra_tri[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

static oc_mesh *tetra(void) {
  return build(tetra_pos, 4, tetra_tri, 4);
}

/* [-1, 1]^3; vertex i has x = bit 0, y = bit 1, z = bit 2. */
static float cube_pos[24];
static const uint32_t cube_tri[36] = {
    0, 2, 3, 0, 3, 1, /* z- */ 4, 5, 7, 4, 7, 6, /* z+ */
    0, 1, 5, 0, 5, 4, /* y- */ 2, 6, 7, 2, 7, 3, /* y+ */
    0, 4, 6, 0, 6, 2, /* x- */ 1, 3, 7, 1, 7, 5  /* x+ */
};

static oc_mesh *cube_with(const uint32_t *tri) {
  for (int i = 0; i < 8; i++)
    for (int c = 0; c < 3; c++)
      cube_pos[3 * i + c] = (i >> c & 1) ? 1 : -1;
  return build(cube_pos, 8, tri, 12);
}

static oc_mesh *cube(void) {
  return cube_with(cube_tri);
}

/* Positions over a wide range of magnitudes and signs (-0, subnormals,
** near FLT_MAX), in triangles that touch every vertex, and colours. */
static oc_mesh *awkward(size_t nv, uint64_t seed) {
  oct_rng r = oct_rng_new(seed);
  oc_error e = {0};
  oc_mesh *m = oc_mesh_alloc(nv, nv, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  for (size_t i = 0; i < 3 * nv; i++) {
    double mag = pow(10.0, oct_unif(&r, -40, 38));
    float v = (float)(oct_unif(&r, -1, 1) * mag);
    m->pos[i] = i % 97 == 5 ? -0.0f : i % 89 == 7 ? 1e-45f : v;
    m->nrm[i] = (float)oct_unif(&r, -1, 1);
  }
  m->pos[0] = 3.4e38f;
  m->pos[1] = 0.1f;
  m->pos[2] = -1234.5678f;
  for (size_t t = 0; t < nv; t++)
    for (int k = 0; k < 3; k++)
      m->tri[3 * t + k] = (uint32_t)((t + k) % nv);
  return m;
}

static void write_ok(const oc_mesh *m, const char *path) {
  oc_error e = {0};
  int rc = oc_mesh_write(m, path, &e);
  ck_assert_msg(rc == OC_OK, "writing %s: %d %s", path, rc, e.msg);
}

static double srgb_decode(double s) {
  return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

/* The file as written, in the file's own axes (glTF: +Y up). */
static mr_mesh *read_raw(const char *path) {
  char why[300];
  mr_mesh *m = mr_read(path, why, sizeof why);
  ck_assert_msg(m != NULL, "reading back: %s", why);
  return m;
}

/* The file in engine axes: a GLB's Y-up axes turned back to Z-up, so
** that every format compares with the mesh bit for bit. */
static mr_mesh *read_ok(const char *path) {
  mr_mesh *m = read_raw(path);
  if (m->format == MR_GLB) mr_gltf_to_engine(m);
  return m;
}

static mr_report report_of(const char *path) {
  mr_mesh *m = read_ok(path);
  mr_report r;
  mr_check(m, &r);
  mr_free(m);
  return r;
}

static const char *const exts[3] = {".ply", ".obj", ".glb"};

static int bits_equal(float a, float b) {
  return memcmp(&a, &b, 4) == 0;
}

/* Positions, normals and triangles of `back` equal those of `m` (floats
** bit for bit: %.9g in OBJ reads back to the same float too). */
static void same_geometry(const oc_mesh *m, const mr_mesh *back,
                          const char *what) {
  ck_assert_msg(back->nv == m->nv && back->nt == m->nt,
                "%s: %zu/%zu vertices, %zu/%zu triangles", what, back->nv,
                m->nv, back->nt, m->nt);
  ck_assert_msg(back->nrm != NULL || m->nv == 0, "%s: no normals", what);
  for (size_t i = 0; i < 3 * m->nv; i++) {
    ck_assert_msg(bits_equal(back->pos[i], m->pos[i]),
                  "%s: position %zu is %.9g, wrote %.9g", what, i, back->pos[i],
                  m->pos[i]);
    ck_assert_msg(bits_equal(back->nrm[i], m->nrm[i]),
                  "%s: normal %zu is %.9g, wrote %.9g", what, i, back->nrm[i],
                  m->nrm[i]);
  }
  for (size_t i = 0; i < 3 * m->nt; i++)
    ck_assert_msg(back->tri[i] == m->tri[i], "%s: index %zu is %u, wrote %u",
                  what, i, back->tri[i], m->tri[i]);
}

/* ---- the container ------------------------------------------------------ */

START_TEST(alloc_and_accessors) {
  oc_error e = {0};
  oc_mesh *m = oc_mesh_alloc(5, 7, &e);
  ck_assert_ptr_nonnull(m);
  ck_assert_uint_eq(oc_mesh_vertex_count(m), 5);
  ck_assert_uint_eq(oc_mesh_triangle_count(m), 7);
  ck_assert_ptr_eq(oc_mesh_positions(m), m->pos);
  ck_assert_ptr_eq(oc_mesh_normals(m), m->nrm);
  ck_assert_ptr_eq(oc_mesh_indices(m), m->tri);
  ck_assert_ptr_null(oc_mesh_colors(m));
  /* The arrays are as large as promised (ASan would object otherwise). */
  memset(m->pos, 0, 15 * sizeof(float));
  memset(m->nrm, 0, 15 * sizeof(float));
  memset(m->tri, 0, 21 * sizeof(uint32_t));
  m->stats.field_calls = 123;
  m->stats.cells_visited = 45;
  m->stats.seconds = 0.5;
  oc_mesh_stats st;
  oc_mesh_get_stats(m, &st);
  ck_assert_uint_eq(st.vertices, 5);
  ck_assert_uint_eq(st.triangles, 7);
  ck_assert_uint_eq(st.field_calls, 123);
  ck_assert_uint_eq(st.cells_visited, 45);
  ck_assert_double_eq(st.seconds, 0.5);
  oc_mesh_free(m);
  oc_mesh_free(NULL);

  m = oc_mesh_alloc(0, 0, &e);
  ck_assert_ptr_nonnull(m);
  ck_assert_uint_eq(oc_mesh_vertex_count(m), 0);
  ck_assert_uint_eq(oc_mesh_triangle_count(m), 0);
  oc_mesh_free(m);

  /* Too many vertices for 32-bit indices, and sizes that overflow. */
  e.code = OC_OK;
  ck_assert_ptr_null(oc_mesh_alloc((size_t)UINT32_MAX + 5, 1, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  ck_assert_msg(strstr(e.msg, "32-bit"), "%s", e.msg);
  e.code = OC_OK;
  ck_assert_ptr_null(oc_mesh_alloc(3, SIZE_MAX / 4, &e));
  ck_assert_int_eq(e.code, OC_ENOMEM);
  ck_assert_ptr_null(oc_mesh_alloc(3, SIZE_MAX / 4, NULL));
}
END_TEST

START_TEST(set_colors) {
  oc_mesh *m = tetra();
  oc_error e = {0};
  float rgb[12] = {0, 0.5f, 1, -0.5f, 1.5f, 0.25f, 1, 1, 1, 0.2f, 0.4f, 0.6f};
  rgb[5] = NAN;
  ck_assert_int_eq(oc_mesh_set_colors(m, rgb, &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'colors'") && strstr(e.msg, "vertex 1"), "%s",
                e.msg);
  ck_assert_ptr_null(oc_mesh_colors(m)); /* nothing set on failure */
  rgb[5] = 0.25f;
  ck_assert_int_eq(oc_mesh_set_colors(m, rgb, &e), OC_OK);
  rgb[0] = 0.75f; /* the mesh holds a copy */
  const float *c = oc_mesh_colors(m);
  ck_assert_ptr_nonnull(c);
  const float want[12] = {0, 0.5f, 1, 0, 1, 0.25f, 1, 1, 1, 0.2f, 0.4f, 0.6f};
  for (int i = 0; i < 12; i++)
    ck_assert_float_eq(c[i], want[i]);
  /* Setting again reuses the array. */
  ck_assert_int_eq(oc_mesh_set_colors(m, want, &e), OC_OK);
  ck_assert_ptr_eq(oc_mesh_colors(m), c);
  ck_assert_int_eq(oc_mesh_set_colors(NULL, rgb, &e), OC_EINVAL);
  ck_assert_int_eq(oc_mesh_set_colors(m, NULL, &e), OC_EINVAL);
  oc_mesh_free(m);
}
END_TEST

/* A point primitive at the origin: f = g(|p|), g Wyvill's falloff. */
static oc_program *point_field(void) {
  oc_error e = {0};
  oc_node *n = oc_point(oct_v(0, 0, 0), 1.0, 1.0, &e);
  ck_assert_msg(n != NULL, "%s", e.msg);
  return oct_compile(n, 0, 0);
}

START_TEST(color_by_field) {
  oc_program *pr = point_field();
  /* Vertices at distances 0, 0.25, 0.5, 0.75 and 2 along x. */
  float pos[15] = {0};
  const double d[5] = {0, 0.25, 0.5, 0.75, 2};
  for (int i = 0; i < 5; i++)
    pos[3 * i] = (float)d[i];
  uint32_t tri[3] = {0, 1, 2};
  oc_mesh *m = build(pos, 5, tri, 1);
  oc_error e = {0};
  const double stops[8] = {0, 0, 0, 0, 1, 1, 0.5, 0.25};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, stops, 2, &e), OC_OK);
  const float *c = oc_mesh_colors(m);
  for (int i = 0; i < 5; i++) {
    double f = oct_g(d[i]);
    const double rgb[3] = {f, 0.5 * f, 0.25 * f};
    for (int k = 0; k < 3; k++)
      ck_assert_msg(fabs(c[3 * i + k] - rgb[k]) < 1e-6,
                    "vertex %d channel %d: %.9g, want %.9g", i, k, c[3 * i + k],
                    rgb[k]);
  }
  /* Clamped beyond the end stops, linear between. */
  const double mid[8] = {0.2, 1, 0, 0, 0.8, 0, 0, 1};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, mid, 2, &e), OC_OK);
  for (int i = 0; i < 5; i++) {
    double t = fmin(fmax((oct_g(d[i]) - 0.2) / 0.6, 0), 1);
    ck_assert_msg(fabs(c[3 * i] - (1 - t)) < 1e-6 && c[3 * i + 1] == 0 &&
                      fabs(c[3 * i + 2] - t) < 1e-6,
                  "vertex %d: %g %g %g, t=%g", i, c[3 * i], c[3 * i + 1],
                  c[3 * i + 2], t);
  }
  ck_assert_float_eq(c[0], 0.0f); /* f = 1 > 0.8: the last stop */
  ck_assert_float_eq(c[2], 1.0f);
  ck_assert_float_eq(c[12], 1.0f); /* f = 0 < 0.2: the first stop */
  /* One stop: a constant colour. Two stops at one value: a step. */
  const double one[4] = {0.5, 0.1, 0.2, 0.3};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, one, 1, &e), OC_OK);
  for (int i = 0; i < 5; i++)
    ck_assert_float_eq(c[3 * i + 1], 0.2f);
  const double step[8] = {0.5, 0, 0, 0, 0.5, 1, 1, 1};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, step, 2, &e), OC_OK);
  for (int i = 0; i < 5; i++)
    ck_assert_float_eq(c[3 * i], oct_g(d[i]) >= 0.5 ? 1.0f : 0.0f);
  /* A step inside the palette, hit exactly: f = 1 at the centre, f = 0 at
  ** distance 2; from a repeated value on, the later stop's colour. */
  const double mid_step[16] = {-1, 0.1, 0.1, 0.1, 0, 0.2, 0.2, 0.2,
                               0,  0.3, 0.3, 0.3, 1, 0.4, 0.4, 0.4};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, mid_step, 4, &e), OC_OK);
  ck_assert_float_eq(c[12], 0.3f); /* f = 0: the third stop, not the second */
  ck_assert_float_eq(c[0], 0.4f);
  const double top_step[16] = {0, 0.1, 0.1, 0.1, 1, 0.2, 0.2, 0.2,
                               1, 0.3, 0.3, 0.3, 2, 0.4, 0.4, 0.4};
  ck_assert_int_eq(oc_mesh_color_by_field(m, pr, top_step, 4, &e), OC_OK);
  ck_assert_float_eq(c[0], 0.3f);  /* f = 1 */
  ck_assert_float_eq(c[12], 0.1f); /* f = 0 */

  /* Bad palettes name 'stops'; the colours are left as they were. */
  const double unsorted[8] = {1, 0, 0, 0, 0, 1, 1, 1};
  const double bright[4] = {0, 0, 2, 0};
  const double nan_value[4] = {NAN, 0, 0, 0};
  struct {
    const double *s;
    int n;
  } bad[] = {{stops, 0}, {NULL, 2}, {unsorted, 2}, {bright, 1}, {nan_value, 1}};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    e.code = OC_OK;
    ck_assert_int_eq(oc_mesh_color_by_field(m, pr, bad[i].s, bad[i].n, &e),
                     OC_EINVAL);
    ck_assert_msg(strstr(e.msg, "'stops'"), "%zu: %s", i, e.msg);
  }
  ck_assert_float_eq(c[0], 0.3f);
  ck_assert_int_eq(oc_mesh_color_by_field(m, NULL, stops, 2, &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'field'"), "%s", e.msg);
  ck_assert_int_eq(oc_mesh_color_by_field(NULL, pr, stops, 2, &e), OC_EINVAL);
  oc_mesh_free(m);
  oc_program_free(pr);
}
END_TEST

START_TEST(color_by_field_deterministic) {
  oc_program *pr = point_field();
  enum { NV = 20000 };
  oc_mesh *a = oc_mesh_alloc(NV, 0, NULL), *b = oc_mesh_alloc(NV, 0, NULL);
  oct_rng r = oct_rng_new(7);
  for (int i = 0; i < 3 * NV; i++)
    a->pos[i] = b->pos[i] = (float)oct_unif(&r, -1.2, 1.2);
  const double stops[12] = {0, 0, 0, 1, 0.5, 1, 0, 0, 1, 1, 1, 1};
  int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  ck_assert_int_eq(oc_mesh_color_by_field(a, pr, stops, 3, NULL), OC_OK);
  omp_set_num_threads(2);
  ck_assert_int_eq(oc_mesh_color_by_field(b, pr, stops, 3, NULL), OC_OK);
  omp_set_num_threads(threads);
  ck_assert_int_eq(memcmp(a->col, b->col, 3 * NV * sizeof(float)), 0);
  /* And right: the reference palette evaluated here. */
  for (int i = 0; i < NV; i++) {
    const float *p = a->pos + 3 * i;
    double f = oct_g(
        sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]));
    double want[3] = {f < 0.5 ? 2 * f : 1, f < 0.5 ? 0 : 2 * (f - 0.5),
                      f < 0.5 ? 1 - 2 * f : 2 * (f - 0.5)};
    for (int k = 0; k < 3; k++)
      ck_assert_msg(fabs(a->col[3 * i + k] - want[k]) < 1e-5,
                    "vertex %d: f=%g channel %d = %g, want %g", i, f, k,
                    a->col[3 * i + k], want[k]);
  }
  oc_mesh_free(a);
  oc_mesh_free(b);
  oc_program_free(pr);
}
END_TEST

/* ---- round trips -------------------------------------------------------- */

START_TEST(round_trip_exact) {
  oc_mesh *m = awkward(500, 3);
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "awkward%s", exts[k]);
    write_ok(m, oct_in_dir(dir, name));
    mr_mesh *back = read_ok(oct_in_dir(dir, name));
    same_geometry(m, back, name);
    ck_assert_msg(strstr(back->generator, "outcrop " OC_VERSION), "%s: '%s'",
                  name, back->generator);
    ck_assert_ptr_null(back->col);
    mr_free(back);
  }
  oc_mesh_free(m);
}
END_TEST

START_TEST(ply_layout) {
  oc_mesh *m = tetra();
  write_ok(m, oct_in_dir(dir, "t.ply"));
  size_t len;
  unsigned char *d = mr_slurp(oct_in_dir(dir, "t.ply"), &len);
  ck_assert_ptr_nonnull(d);
  const char *want = "ply\nformat binary_little_endian 1.0\ncomment written by "
                     "outcrop " OC_VERSION
                     "\nelement vertex 4\nproperty float x\nproperty float y\n"
                     "property float z\nproperty float nx\nproperty float ny\n"
                     "property float nz\nelement face 4\n"
                     "property list uchar uint vertex_indices\nend_header\n";
  size_t hl = strlen(want);
  ck_assert_msg(len > hl && memcmp(d, want, hl) == 0, "header:\n%.*s",
                (int)(len < 400 ? len : 400), d);
  ck_assert_uint_eq(len, hl + 4 * 24 + 4 * 13);
  /* Explicit little-endian: vertex 1's x = 1.0f = 00 00 80 3f. */
  const unsigned char one[4] = {0x00, 0x00, 0x80, 0x3f};
  ck_assert_int_eq(memcmp(d + hl + 24, one, 4), 0);
  /* The first face: count 3, then 0, 2, 1 as uint32 LE. */
  const unsigned char *f = d + hl + 4 * 24;
  const unsigned char face[13] = {3, 0, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0};
  ck_assert_int_eq(memcmp(f, face, 13), 0);
  free(d);
  oc_mesh_free(m);
}
END_TEST

START_TEST(ply_colors) {
  oc_mesh *m = cube();
  /* Values at and around the rounding points of the 8-bit quantization. */
  float rgb[24] = {
      0,          1,           0.5f,        -1,           2,      1.0f / 255,
      0.5f / 255, 0.49f / 255, 0.51f / 255, 127.5f / 255, 0.999f, 0.001f,
      0.2f,       0.4f,        0.6f,        0.8f,         0.3f,   0.7f,
      0.9f,       0.1f,        0.05f,       0.95f,        0.33f,  0.66f};
  ck_assert_int_eq(oc_mesh_set_colors(m, rgb, NULL), OC_OK);
  write_ok(m, oct_in_dir(dir, "c.ply"));
  write_ok(m, oct_in_dir(dir, "c.glb"));
  mr_mesh *back = read_ok(oct_in_dir(dir, "c.ply"));
  same_geometry(m, back, "c.ply");
  ck_assert_ptr_nonnull(back->col);
  /* Bytes are the sRGB encoding of the linear colours, rounded half up. */
  for (int i = 0; i < 24; i++) {
    double v = fmin(fmax(rgb[i], 0), 1);
    double e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
    long want = lround(floor(e * 255 + 0.5));
    long got = lround(back->col[i] * 255);
    ck_assert_msg(got == want, "colour %d (%.9g): %ld, want %ld", i, rgb[i],
                  got, want);
  }
  ck_assert_float_eq(back->col[2] * 255, 188); /* linear 0.5: sRGB 0.735 */
  ck_assert_float_eq(back->col[5] * 255, 13);  /* 1/255: sRGB 0.0497 */
  mr_free(back);
  /* GLB keeps the float colours (clamped). */
  back = read_ok(oct_in_dir(dir, "c.glb"));
  ck_assert_ptr_nonnull(back->col);
  for (int i = 0; i < 24; i++)
    ck_assert_float_eq(back->col[i], oc_mesh_colors(m)[i]);
  mr_free(back);
  /* OBJ has no colours. */
  write_ok(m, oct_in_dir(dir, "c.obj"));
  back = read_ok(oct_in_dir(dir, "c.obj"));
  ck_assert_ptr_null(back->col);
  mr_free(back);
  oc_mesh_free(m);
}
END_TEST

START_TEST(obj_text) {
  oc_mesh *m = tetra();
  m->pos[3] = 0.1f;
  write_ok(m, oct_in_dir(dir, "t.obj"));
  size_t len;
  char *d = (char *)mr_slurp(oct_in_dir(dir, "t.obj"), &len);
  ck_assert_ptr_nonnull(d);
  d = realloc(d, len + 1);
  d[len] = '\0';
  ck_assert_msg(strncmp(d, "# written by outcrop " OC_VERSION "\n", 22) == 0,
                "%s", d);
  ck_assert_msg(strstr(d, "\nv 0.100000001 0 0\n"), "%s", d);
  ck_assert_msg(strstr(d, "\nf 1//1 3//3 2//2\n"), "%s", d);
  ck_assert_msg(strstr(d, "\nf 2//2 3//3 4//4\n"), "%s", d);
  ck_assert_msg(d[len - 1] == '\n', "no final newline");
  free(d);
  oc_mesh_free(m);
}
END_TEST

/* ---- GLB structure ------------------------------------------------------ */

static long long jnum(const mr_json *v) {
  ck_assert_msg(v && v->type == MR_JNUMBER, "number expected");
  return (long long)v->number;
}

START_TEST(glb_structure) {
  for (int colours = 0; colours < 2; colours++) {
    oc_mesh *m = awkward(301, 11);
    if (colours) {
      float *rgb = malloc(3 * 301 * sizeof *rgb);
      for (int i = 0; i < 3 * 301; i++)
        rgb[i] = (float)(i % 7) / 6;
      oc_mesh_set_colors(m, rgb, NULL);
      free(rgb);
    }
    write_ok(m, oct_in_dir(dir, "s.glb"));
    mr_mesh *back =
        read_ok(oct_in_dir(dir, "s.glb")); /* validates the structure */
    same_geometry(m, back, "s.glb");
    const mr_json *g = back->gltf;
    ck_assert_str_eq(
        mr_json_str(mr_json_get(mr_json_get(g, "asset"), "version")), "2.0");
    ck_assert_str_eq(back->generator, "outcrop " OC_VERSION);
    /* File = header + JSON chunk + BIN chunk, every length consistent. */
    size_t len;
    unsigned char *d = mr_slurp(oct_in_dir(dir, "s.glb"), &len);
    ck_assert_uint_eq(len, 12 + 8 + back->json_length + 8 + back->bin_length);
    ck_assert_uint_eq(back->json_length % 4, 0);
    ck_assert_uint_eq(back->bin_length, 301 * (colours ? 36 : 24) + 301 * 12);
    ck_assert_int_eq(memcmp(d + 20 + back->json_length + 4, "BIN\0", 4), 0);
    free(d);
    ck_assert_int_eq(jnum(mr_json_get(mr_json_at(mr_json_get(g, "buffers"), 0),
                                      "byteLength")),
                     (long long)back->bin_length);
    /* Accessors: kinds, counts, min/max of POSITION equal to the data. */
    const mr_json *accs = mr_json_get(g, "accessors");
    ck_assert_uint_eq(accs->n, 3 + (size_t)colours);
    const mr_json *prim = mr_json_at(
        mr_json_get(mr_json_at(mr_json_get(g, "meshes"), 0), "primitives"), 0);
    ck_assert_int_eq(jnum(mr_json_get(prim, "mode")), 4);
    const mr_json *attrs = mr_json_get(prim, "attributes");
    ck_assert_uint_eq(attrs->n, 2 + (size_t)colours);
    const mr_json *pa =
        mr_json_at(accs, (size_t)jnum(mr_json_get(attrs, "POSITION")));
    ck_assert_int_eq(jnum(mr_json_get(pa, "componentType")), 5126);
    ck_assert_str_eq(mr_json_str(mr_json_get(pa, "type")), "VEC3");
    ck_assert_int_eq(jnum(mr_json_get(pa, "count")), 301);
    /* in glTF axes: X = x, Y = z, Z = -y */
    for (int c = 0; c < 3; c++) {
      int ec = c == 0 ? 0 : c == 1 ? 2 : 1;
      float sg = c == 2 ? -1.0f : 1.0f;
      float lo = sg * m->pos[ec], hi = sg * m->pos[ec];
      for (int i = 1; i < 301; i++) {
        lo = fminf(lo, sg * m->pos[3 * i + ec]);
        hi = fmaxf(hi, sg * m->pos[3 * i + ec]);
      }
      ck_assert_float_eq((float)mr_json_at(mr_json_get(pa, "min"), c)->number,
                         lo);
      ck_assert_float_eq((float)mr_json_at(mr_json_get(pa, "max"), c)->number,
                         hi);
    }
    const mr_json *ia =
        mr_json_at(accs, (size_t)jnum(mr_json_get(prim, "indices")));
    ck_assert_int_eq(jnum(mr_json_get(ia, "componentType")), 5125);
    ck_assert_int_eq(jnum(mr_json_get(ia, "count")), 3 * 301);
    /* Every bufferView 4-aligned, vertex data targeted as such. */
    const mr_json *views = mr_json_get(g, "bufferViews");
    ck_assert_uint_eq(views->n, 3 + (size_t)colours);
    for (size_t i = 0; i < views->n; i++) {
      const mr_json *v = mr_json_at(views, i);
      ck_assert_int_eq(jnum(mr_json_get(v, "byteOffset")) % 4, 0);
      ck_assert_int_eq(jnum(mr_json_get(v, "target")),
                       i + 1 < views->n ? 34962 : 34963);
    }
    ck_assert_int_eq(
        jnum(mr_json_get(mr_json_at(mr_json_get(g, "nodes"), 0), "mesh")), 0);
    mr_free(back);
    oc_mesh_free(m);
  }
}
END_TEST

/* Rewrites the first occurrence of `from` in the file by `to` (same
** length, so the chunk lengths stay right). */
static void patch(const char *path, const char *from, const char *to) {
  size_t len;
  unsigned char *d = mr_slurp(path, &len);
  ck_assert_ptr_nonnull(d);
  size_t n = strlen(from);
  ck_assert_uint_eq(n, strlen(to));
  unsigned char *at = NULL;
  for (size_t i = 0; i + n <= len && !at; i++)
    if (memcmp(d + i, from, n) == 0) at = d + i;
  ck_assert_msg(at != NULL, "'%s' not in %s", from, path);
  memcpy(at, to, n);
  FILE *f = fopen(path, "wb");
  ck_assert_uint_eq(fwrite(d, 1, len, f), len);
  fclose(f);
  free(d);
}

static void read_fails(const char *path, const char *reason) {
  char why[300] = "";
  mr_mesh *m = mr_read(path, why, sizeof why);
  if (m) mr_free(m);
  ck_assert_msg(m == NULL, "%s read although %s", path, reason);
  ck_assert_msg(strstr(why, reason), "%s: '%s' does not say '%s'", path, why,
                reason);
}

/* The reader's GLB checks do fail on broken files (else the structure
** test above could not fail). */
START_TEST(reader_rejects_broken_glb) {
  oc_mesh *m = cube();
  const char *p = oct_in_dir(dir, "b.glb");
  struct {
    const char *from, *to, *reason;
  } cases[] = {
      {"\"count\":8,", "\"count\":9,", "overrun"},
      {"\"min\":[-1,", "\"min\":[-2,", "min[0]"},
      {"\"byteOffset\":96", "\"byteOffset\":98", "aligned"},
      {"{\"byteLength\":336}]", "{\"byteLength\":340}]", "buffer of"},
      {"\"target\":34963", "\"target\":34962", "target"},
      {"\"mode\":4", "\"mode\":1", "TRIANGLES"},
      {"\"version\":\"2.0\"", "\"version\":\"1.0\"", "version"},
      {"\"POSITION\":0,", "\"POSITION\":0]", "JSON"},
      {"glTF", "glTf", "magic"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    write_ok(m, p);
    mr_free(read_ok(p));
    patch(p, cases[i].from, cases[i].to);
    read_fails(p, cases[i].reason);
  }
  /* A truncated file. */
  write_ok(m, p);
  ck_assert_int_eq(truncate(p, 200), 0);
  read_fails(p, "length");
  oc_mesh_free(m);
}
END_TEST

START_TEST(reader_rejects_broken_ply_obj) {
  oc_mesh *m = cube();
  const char *p = oct_in_dir(dir, "b.ply"), *o = oct_in_dir(dir, "b.obj");
  write_ok(m, p);
  struct stat st;
  ck_assert_int_eq(stat(p, &st), 0);
  ck_assert_int_eq(truncate(p, st.st_size - 1), 0);
  read_fails(p, "truncated");
  write_ok(m, p);
  patch(p, "binary_little_endian", "binary_big_endian\n\n\n");
  read_fails(p, "format");
  write_ok(m, o);
  patch(o, "f 1//1 3//3 4//4", "f 1//1 3//3 9//9");
  read_fails(o, "corner");
  write_ok(m, o);
  patch(o, "f 1//1 3//3 4//4", "f 1//1 3//2 4//4");
  read_fails(o, "normal");
  oc_mesh_free(m);
}
END_TEST

START_TEST(json_parser) {
  char why[200];
  const char *ok =
      " {\"a\": [1, -2.5e3, 0.125, true, false, null, \"x\\\"\\u00e9\\ud83d"
      "\\ude00\\n\"], \"b\": {}, \"c\": [] , \"d\": -0} ";
  mr_json *v = mr_json_parse(ok, strlen(ok), why, sizeof why);
  ck_assert_msg(v != NULL, "%s", why);
  const mr_json *a = mr_json_get(v, "a");
  ck_assert_uint_eq(a->n, 7);
  ck_assert_double_eq(mr_json_at(a, 1)->number, -2500);
  ck_assert_double_eq(mr_json_at(a, 2)->number, 0.125);
  ck_assert_int_eq(mr_json_at(a, 3)->type, MR_JTRUE);
  ck_assert_int_eq(mr_json_at(a, 4)->type, MR_JFALSE);
  ck_assert_int_eq(mr_json_at(a, 5)->type, MR_JNULL);
  ck_assert_str_eq(mr_json_str(mr_json_at(a, 6)),
                   "x\"\xc3\xa9\xf0\x9f\x98\x80\n");
  ck_assert_int_eq(mr_json_get(v, "b")->type, MR_JOBJECT);
  ck_assert_uint_eq(mr_json_get(v, "c")->n, 0);
  ck_assert_ptr_null(mr_json_get(v, "e"));
  ck_assert_ptr_null(mr_json_at(a, 7));
  mr_json_free(v);
  const char *bad[] = {"",
                       "{",
                       "[1,]",
                       "{\"a\":1,}",
                       "01",
                       "1.",
                       "-",
                       "\"\\x\"",
                       "{\"a\" 1}",
                       "[1] [2]",
                       "tru",
                       "{\"a\":1,\"a\":2}",
                       "\"\\ud800\"",
                       "\"a\nb\"",
                       "{1:2}",
                       "[.5]"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    why[0] = '\0';
    v = mr_json_parse(bad[i], strlen(bad[i]), why, sizeof why);
    ck_assert_msg(v == NULL, "accepted '%s'", bad[i]);
    ck_assert_msg(strstr(why, "JSON"), "'%s': no reason", bad[i]);
  }
  /* Nesting is bounded, not recursion without end. */
  char deep[400];
  memset(deep, '[', 200);
  memset(deep + 200, ']', 200);
  ck_assert_ptr_null(mr_json_parse(deep, 400, why, sizeof why));
  ck_assert_msg(strstr(why, "deep"), "%s", why);
}
END_TEST

/* ---- the reader's checks on meshes wrong in one way each ----------------- */

static mr_report check_all(const oc_mesh *m, const char *base) {
  mr_report r[3];
  for (int k = 0; k < 3; k++) {
    char name[64];
    snprintf(name, sizeof name, "%s%s", base, exts[k]);
    write_ok(m, oct_in_dir(dir, name));
    r[k] = report_of(oct_in_dir(dir, name));
    if (k) { /* the three files tell the same story */
      ck_assert_msg(r[k].edges == r[0].edges &&
                        r[k].boundary_edges == r[0].boundary_edges &&
                        r[k].misoriented_edges == r[0].misoriented_edges &&
                        r[k].euler == r[0].euler &&
                        r[k].volume == r[0].volume &&
                        r[k].duplicate_vertices == r[0].duplicate_vertices,
                    "%s: %s differs from %s", base, exts[k], exts[0]);
    }
  }
  return r[0];
}

START_TEST(check_closed_shapes) {
  char buf[400];
  oc_mesh *m = cube();
  mr_report r = check_all(m, "cube");
  ck_assert_msg(r.closed && r.consistent && r.outward, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_int_eq(r.euler, 2);
  ck_assert_uint_eq(r.edges, 18);
  ck_assert_uint_eq(r.components, 1);
  ck_assert_double_eq(r.volume, 8.0);
  ck_assert_double_eq(r.area, 24.0);
  ck_assert_uint_eq(r.duplicate_vertices, 0);
  ck_assert_uint_eq(r.degenerate_triangles, 0);
  ck_assert_uint_eq(r.normals_against, 0);
  ck_assert_double_lt(r.normal_length_error, 1e-6);
  for (int c = 0; c < 3; c++) {
    ck_assert_double_eq(r.lo[c], -1);
    ck_assert_double_eq(r.hi[c], 1);
  }
  oc_mesh_free(m);

  m = tetra();
  r = check_all(m, "tetra");
  ck_assert_msg(r.closed && r.consistent && r.outward && r.euler == 2, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_double_eq_tol(r.volume, 1.0 / 6, 1e-15);
  oc_mesh_free(m);

  /* Turned inside out: still closed and consistent, but inward. */
  uint32_t inv[36];
  for (int t = 0; t < 12; t++) {
    inv[3 * t] = cube_tri[3 * t];
    inv[3 * t + 1] = cube_tri[3 * t + 2];
    inv[3 * t + 2] = cube_tri[3 * t + 1];
  }
  m = cube_with(inv);
  for (int i = 0; i < 24; i++)
    m->nrm[i] = -m->nrm[i]; /* stay outward */
  r = check_all(m, "inverted");
  ck_assert_msg(r.closed && r.consistent && !r.outward, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_double_eq(r.volume, -8.0);
  ck_assert_uint_eq(r.normals_against, 8);
  oc_mesh_free(m);
}
END_TEST

START_TEST(check_defects) {
  char buf[400];
  /* An open square: four boundary edges, Euler 1. */
  const float sq[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const uint32_t sqt[6] = {0, 1, 2, 0, 2, 3};
  oc_mesh *m = build(sq, 4, sqt, 2);
  mr_report r = check_all(m, "square");
  ck_assert_msg(!r.closed && r.consistent && !r.outward, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_uint_eq(r.boundary_edges, 4);
  ck_assert_uint_eq(r.edges, 5);
  ck_assert_int_eq(r.euler, 1);
  ck_assert_double_eq(r.area, 1.0);
  oc_mesh_free(m);

  /* One cube triangle flipped: closed, but three edges run the same way
  ** in both their triangles. */
  uint32_t fl[36];
  memcpy(fl, cube_tri, sizeof fl);
  fl[1] = cube_tri[2];
  fl[2] = cube_tri[1];
  m = cube_with(fl);
  r = check_all(m, "flipped");
  ck_assert_msg(r.closed && !r.consistent && !r.outward, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_uint_eq(r.misoriented_edges, 3);
  oc_mesh_free(m);

  /* A tetrahedron whose last face uses a copy of vertex 3: a duplicate
  ** vertex, and the mesh is no longer closed. */
  float dp[15];
  memcpy(dp, tetra_pos, sizeof tetra_pos);
  memcpy(dp + 12, tetra_pos + 9, 3 * sizeof(float));
  const uint32_t dt[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 4};
  m = build(dp, 5, dt, 4);
  r = check_all(m, "dup");
  ck_assert_msg(r.duplicate_vertices == 1 && !r.closed, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_uint_eq(r.boundary_edges, 4);
  oc_mesh_free(m);

  /* Degenerate triangles: a zero-area sliver on an edge's midpoint and a
  ** repeated index. */
  float gp[15];
  memcpy(gp, tetra_pos, sizeof tetra_pos);
  gp[12] = 0.5f, gp[13] = 0, gp[14] = 0;
  const uint32_t gt[18] = {0, 2, 1, 0, 1, 3, 0, 3, 2,
                           1, 2, 3, 0, 4, 1, 2, 2, 3};
  m = build(gp, 5, gt, 6);
  r = check_all(m, "degenerate");
  ck_assert_msg(r.degenerate_triangles == 2, "%s",
                mr_report_str(&r, buf, sizeof buf));
  ck_assert_uint_eq(r.duplicate_vertices, 0);
  oc_mesh_free(m);

  /* Two separate tetrahedra: two components, Euler 4. A non-manifold
  ** edge: three triangles on one edge. */
  float two[24];
  memcpy(two, tetra_pos, sizeof tetra_pos);
  for (int i = 0; i < 12; i++)
    two[12 + i] = tetra_pos[i] + 5;
  uint32_t tt[24];
  for (int i = 0; i < 12; i++) {
    tt[i] = tetra_tri[i];
    tt[12 + i] = tetra_tri[i] + 4;
  }
  m = build(two, 8, tt, 8);
  r = check_all(m, "two");
  ck_assert_msg(r.closed && r.outward && r.components == 2 && r.euler == 4,
                "%s", mr_report_str(&r, buf, sizeof buf));
  ck_assert_double_eq_tol(r.volume, 2.0 / 6, 1e-12);
  oc_mesh_free(m);
  const float fan[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
  const uint32_t ft[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  m = build(fan, 5, ft, 3);
  r = check_all(m, "fan");
  ck_assert_msg(r.nonmanifold_edges == 1 && !r.closed && !r.consistent, "%s",
                mr_report_str(&r, buf, sizeof buf));
  oc_mesh_free(m);
}
END_TEST

/* ---- empty meshes, limits and refusals ---------------------------------- */

START_TEST(empty_meshes) {
  oc_mesh *m = oc_mesh_alloc(0, 0, NULL);
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "empty%s", exts[k]);
    write_ok(m, oct_in_dir(dir, name));
    mr_mesh *back = read_ok(oct_in_dir(dir, name));
    ck_assert_uint_eq(back->nv, 0);
    ck_assert_uint_eq(back->nt, 0);
    if (k == 2) { /* one empty scene; no node, buffer or mesh */
      ck_assert_ptr_null(mr_json_get(back->gltf, "meshes"));
      ck_assert_ptr_null(mr_json_get(back->gltf, "nodes"));
      ck_assert_ptr_null(mr_json_get(back->gltf, "buffers"));
      ck_assert_uint_eq(mr_json_get(back->gltf, "scenes")->n, 1);
      ck_assert_uint_eq(back->bin_length, 0);
    }
    mr_free(back);
  }
  oc_mesh_free(m);
  /* Vertices without triangles: PLY and OBJ keep them, GLB has nothing to
  ** draw and writes the empty scene. */
  m = build(tetra_pos, 4, NULL, 0);
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "points%s", exts[k]);
    write_ok(m, oct_in_dir(dir, name));
    mr_mesh *back = read_ok(oct_in_dir(dir, name));
    ck_assert_uint_eq(back->nv, k == 2 ? 0 : 4);
    ck_assert_uint_eq(back->nt, 0);
    mr_free(back);
  }
  oc_mesh_free(m);
}
END_TEST

START_TEST(glb_size_limit) {
  /* Counts as a huge mesh would have; the limit is checked before any
  ** array is read (they are NULL here) and before any file exists. */
  struct oc_mesh huge = {0};
  huge.nv = 150000000;
  huge.nt = 300000000;
  oc_error e = {0};
  ck_assert_int_eq(oc_mesh_write(&huge, oct_in_dir(dir, "huge.glb"), &e),
                   OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "4 GiB") && strstr(e.msg, "huge.glb"), "%s",
                e.msg);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);
}
END_TEST

START_TEST(refused_meshes) {
  oc_error e = {0};
  oc_mesh *m = tetra();
  m->tri[5] = 4; /* past the vertices */
  ck_assert_int_eq(oc_mesh_write(m, oct_in_dir(dir, "x.ply"), &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "triangle 1") && strstr(e.msg, "x.ply"), "%s",
                e.msg);
  m->tri[5] = 3;
  m->pos[4] = NAN;
  ck_assert_int_eq(oc_mesh_write(m, oct_in_dir(dir, "x.glb"), &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "vertex 1"), "%s", e.msg);
  m->pos[4] = 0;
  m->nrm[0] = INFINITY;
  ck_assert_int_eq(oc_mesh_write(m, oct_in_dir(dir, "x.obj"), &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "normal"), "%s", e.msg);
  ck_assert_int_eq(oc_mesh_write(NULL, oct_in_dir(dir, "x.obj"), &e),
                   OC_EINVAL);
  ck_assert_int_eq(oc_mesh_write(m, NULL, &e), OC_EINVAL);
  ck_assert_int_eq(oc_mesh_write(m, "", &e), OC_EINVAL);
  ck_assert_msg(strstr(e.msg, "'path'"), "%s", e.msg);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);
  oc_mesh_free(m);
}
END_TEST

START_TEST(extensions) {
  oc_mesh *m = tetra();
  const char *bad[] = {"a.stl",     "noext", "a.ply.bak",
                       "sub.ply/x", ".ply",  "a.gltf"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    oc_error e = {0};
    const char *p = oct_in_dir(dir, bad[i]);
    ck_assert_int_eq(oc_mesh_write(m, p, &e), OC_EINVAL);
    ck_assert_msg(strstr(e.msg, p) && strstr(e.msg, ".ply") &&
                      strstr(e.msg, ".obj") && strstr(e.msg, ".glb"),
                  "%s", e.msg);
  }
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);
  /* Any case picks the format. */
  const char *good[] = {"A.PLY", "b.Obj", "c.gLB"};
  for (int i = 0; i < 3; i++) {
    write_ok(m, oct_in_dir(dir, good[i]));
    mr_mesh *back = read_ok(oct_in_dir(dir, good[i]));
    ck_assert_int_eq(back->format, i == 0 ? MR_PLY : i == 1 ? MR_OBJ : MR_GLB);
    same_geometry(m, back, good[i]);
    mr_free(back);
  }
  char names[256];
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 3, "%s", names);
  oc_mesh_free(m);
}
END_TEST

/* ---- determinism and atomicity ------------------------------------------ */

START_TEST(repeat_writes_identical) {
  for (int k = 0; k < 3; k++) {
    char a[32], b[32], c[32];
    snprintf(a, sizeof a, "r1%s", exts[k]);
    snprintf(b, sizeof b, "r2%s", exts[k]);
    snprintf(c, sizeof c, "r3%s", exts[k]);
    oc_mesh *m1 = awkward(1000, 5), *m2 = awkward(1000, 5);
    write_ok(m1, oct_in_dir(dir, a));
    write_ok(m2, oct_in_dir(dir, b));
    ck_assert_msg(mr_same_bytes(oct_in_dir(dir, a), oct_in_dir(dir, b)),
                  "%s differs", exts[k]);
    /* A different mesh does give a different file. */
    m2->pos[3 * 999] = nextafterf(m2->pos[3 * 999], INFINITY);
    write_ok(m2, oct_in_dir(dir, c));
    ck_assert_msg(!mr_same_bytes(oct_in_dir(dir, a), oct_in_dir(dir, c)),
                  "%s same", exts[k]);
    oc_mesh_free(m1);
    oc_mesh_free(m2);
  }
}
END_TEST

START_TEST(unwritable_paths) {
  oc_mesh *m = cube();
  oc_error e = {0};
  for (int k = 0; k < 3; k++) {
    char name[64], want[400];
    /* A missing folder: the message names the path and the reason. */
    snprintf(name, sizeof name, "missing/y%s", exts[k]);
    const char *p = oct_in_dir(dir, name);
    ck_assert_int_eq(oc_mesh_write(m, p, &e), OC_EIO);
    snprintf(want, sizeof want, "cannot write '%s': No such file or directory",
             p);
    ck_assert_str_eq(e.msg, want);
    ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 0);

    /* The final name is a folder: the temporary file was written, the
    ** rename fails, and the temporary file must be gone. */
    snprintf(name, sizeof name, "taken%s", exts[k]);
    ck_assert_int_eq(mkdir(oct_in_dir(dir, name), 0777), 0);
    ck_assert_int_eq(oc_mesh_write(m, oct_in_dir(dir, name), &e), OC_EIO);
    ck_assert_msg(strstr(e.msg, "cannot write '") && strstr(e.msg, name), "%s",
                  e.msg);
    char names[256];
    ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 1,
                  "left behind: %s", names);
    ck_assert_int_eq(oct_count_entries(oct_in_dir(dir, name), NULL, 0), 0);
    rmdir(oct_in_dir(dir, name));
  }
  /* A read-only folder (root ignores permissions, so only as a user). */
  if (geteuid() != 0) {
    ck_assert_int_eq(mkdir(oct_in_dir(dir, "ro"), 0555), 0);
    ck_assert_int_eq(oc_mesh_write(m, oct_in_dir(dir, "ro/z.ply"), &e), OC_EIO);
    ck_assert_msg(strstr(e.msg, "Permission denied"), "%s", e.msg);
    chmod(oct_in_dir(dir, "ro"), 0755);
  }
  oc_mesh_free(m);
}
END_TEST

/* The disk fills up mid-write (a file size limit stands in for a full
** disk: writes fail the same way, with EFBIG instead of ENOSPC). The old
** file must survive untouched and nothing else may be left. */
START_TEST(write_fails_midway) {
  oc_mesh *small = cube(), *big = awkward(20000, 9);
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "full%s", exts[k]);
    const char *p = oct_in_dir(dir, name);
    write_ok(small, p);
    struct rlimit old, lim;
    ck_assert_int_eq(getrlimit(RLIMIT_FSIZE, &old), 0);
    lim = old;
    lim.rlim_cur = 100000; /* the big mesh needs more in every format */
    void (*prev)(int) = signal(SIGXFSZ, SIG_IGN);
    ck_assert_int_eq(setrlimit(RLIMIT_FSIZE, &lim), 0);
    oc_error e = {0};
    int rc = oc_mesh_write(big, p, &e);
    ck_assert_int_eq(setrlimit(RLIMIT_FSIZE, &old), 0);
    signal(SIGXFSZ, prev);
    ck_assert_int_eq(rc, OC_EIO);
    char want[400];
    snprintf(want, sizeof want, "cannot write '%s': %s", p, strerror(EFBIG));
    ck_assert_str_eq(e.msg, want);
    char names[256];
    ck_assert_msg(oct_count_entries(dir, names, sizeof names) == k + 1,
                  "left behind: %s", names);
    mr_mesh *back = read_ok(p);
    same_geometry(small, back, name);
    mr_free(back);
  }
  oc_mesh_free(small);
  oc_mesh_free(big);
}
END_TEST

/* A full disk: every format reports it with the reason and leaves neither
** the file nor its temporary; a mesh that fits is still written. */
START_TEST(disk_full) {
  const char *fs = oct_tmpfs(64 * 1024, "meshio disk_full");
  if (!fs) return;
  oc_mesh *small = cube(), *big = awkward(20000, 9);
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "full%s", exts[k]);
    const char *p = oct_in_dir(fs, name);
    oc_error e = {0};
    oct_assert_full(oc_mesh_write(big, p, &e), e.msg, p, fs);
    write_ok(small, p);
    mr_mesh *back = read_ok(p);
    same_geometry(small, back, name);
    mr_free(back);
    ck_assert_int_eq(unlink(p), 0);
  }
  oc_mesh_free(small);
  oc_mesh_free(big);
  oct_tmpfs_done(fs);
}
END_TEST

/* Two threads writing the same name at once: temporary names never clash
** and the reader always finds one whole file. */
START_TEST(concurrent_writes) {
  oc_mesh *m[2] = {cube(), awkward(3000, 2)};
  const char *p = oct_in_dir(dir, "race.glb");
  int failures = 0;
#pragma omp parallel num_threads(2) reduction(+ : failures)
  {
    int t = omp_get_thread_num();
    for (int i = 0; i < 20; i++) {
      oc_error e = {0};
      if (oc_mesh_write(m[t], p, &e) != OC_OK) failures++;
    }
  }
  ck_assert_int_eq(failures, 0);
  char names[256];
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 1, "%s", names);
  mr_mesh *back = read_ok(p);
  same_geometry(back->nv == 8 ? m[0] : m[1], back, "race.glb");
  mr_free(back);
  oc_mesh_free(m[0]);
  oc_mesh_free(m[1]);
}
END_TEST

/* The helper itself: commit, abort, relative names. */
START_TEST(atomic_helper) {
  oc_error e = {0};
  oc_atomic a;
  const char *p = oct_in_dir(dir, "h.txt");
  /* Through the stream, then commit. */
  ck_assert_int_eq(oc_atomic_begin(&a, p, &e), OC_OK);
  /* anonymous until the commit (O_TMPFILE), or hidden next to p */
  ck_assert_msg(!a.tmp ||
                    (strstr(a.tmp, "/.h.txt.tmp-") && strstr(a.tmp, ".txt")),
                "%s", a.tmp);
  ck_assert_int_eq(access(p, F_OK), -1); /* not there before commit */
  ck_assert_int_eq(oc_atomic_write(&a, "hello ", 6), 0);
  fputs("world", a.fp);
  ck_assert_int_eq(oc_atomic_commit(&a, &e), OC_OK);
  size_t len;
  char *d = (char *)mr_slurp(p, &len);
  ck_assert_uint_eq(len, 11);
  ck_assert_int_eq(memcmp(d, "hello world", 11), 0);
  free(d);
  /* Abort: the old file stays, the temporary one goes. */
  ck_assert_int_eq(oc_atomic_begin(&a, p, &e), OC_OK);
  oc_atomic_write(&a, "x", 1);
  oc_atomic_abort(&a);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 1);
  d = (char *)mr_slurp(p, &len);
  ck_assert_uint_eq(len, 11);
  free(d);
  /* Relative names put the temporary file in the current folder. */
  char cwd[512];
  ck_assert_ptr_nonnull(getcwd(cwd, sizeof cwd));
  ck_assert_int_eq(chdir(dir), 0);
  ck_assert_int_eq(oc_atomic_begin(&a, "rel", &e), OC_OK);
  ck_assert_msg(!a.tmp || strncmp(a.tmp, ".rel.tmp-", 9) == 0, "%s", a.tmp);
  ck_assert_int_eq(oc_atomic_commit(&a, &e), OC_OK);
  ck_assert_int_eq(chdir(cwd), 0);
  ck_assert_int_eq(access(oct_in_dir(dir, "rel"), F_OK), 0);
  ck_assert_int_eq(oct_count_entries(dir, NULL, 0), 2);
}
END_TEST

/* A process killed in the middle of a write (a second Ctrl-C, SIGKILL)
** leaves neither the file nor a temporary: the temporary is anonymous
** until the commit. */
START_TEST(killed_while_writing) {
  int ready[2];
  ck_assert_int_eq(pipe(ready), 0);
  pid_t pid = fork();
  ck_assert_int_ge(pid, 0);
  if (pid == 0) {
    oc_error e = {0};
    oc_atomic a;
    if (oc_atomic_begin(&a, oct_in_dir(dir, "k.ply"), &e) != OC_OK) _exit(1);
    oc_atomic_write(&a, "partial", 7);
    fflush(a.fp);
    if (write(ready[1], "x", 1) != 1) _exit(1);
    for (;;)
      pause();
  }
  char c;
  ck_assert_int_eq(read(ready[0], &c, 1), 1);
  char names[256];
  int during = oct_count_entries(dir, names, sizeof names);
  ck_assert_int_eq(kill(pid, SIGKILL), 0);
  ck_assert_int_eq(waitpid(pid, NULL, 0), pid);
  close(ready[0]);
  close(ready[1]);
  ck_assert_msg(during == 0, "visible while writing: %s", names);
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 0, "left: %s",
                names);
}
END_TEST

/* ---- polygonized shapes, checked through the files ---------------------- */

#define PI 3.14159265358979323846

/* Polygonizes `n` (the reference is consumed) over `box` at `cell`,
** writes the mesh in every format, reads each file back and checks that
** the three agree; returns the report and the mesh (caller frees). */
static mr_report mesh_files(oc_node *n, oc_aabb box, double cell, int open,
                            const char *base, oc_mesh **out) {
  oc_program *pr = oct_compile(n, 0, 0);
  oc_polygonize_params pp = {0};
  pp.box = box;
  pp.cell = cell;
  pp.open = open;
  oc_error e = {0};
  oc_mesh *m = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m != NULL, "%s: %s", base, e.msg);
  oc_program_free(pr);
  mr_report r = check_all(m, base);
  for (int k = 0; k < 3; k++) { /* what was read is what was meshed */
    char name[64];
    snprintf(name, sizeof name, "%s%s", base, exts[k]);
    mr_mesh *back = read_ok(oct_in_dir(dir, name));
    same_geometry(m, back, name);
    mr_free(back);
  }
  if (out)
    *out = m;
  else
    oc_mesh_free(m);
  return r;
}

static oc_aabb cube_box(double h) {
  oc_aabb b = {oct_v(-h, -h, -h), oct_v(h, h, h)};
  return b;
}

/* Closed, manifold, consistently and outward oriented, with normals from
** the gradient that agree with the winding, no duplicate vertex and no
** degenerate triangle. */
static void assert_solid(const mr_report *r, long euler, const char *what) {
  char buf[512];
  mr_report_str(r, buf, sizeof buf);
  ck_assert_msg(r->triangles > 100, "%s: %s", what, buf);
  ck_assert_msg(r->closed && r->consistent && r->outward, "%s: %s", what, buf);
  ck_assert_msg(r->euler == euler, "%s: Euler %ld, want %ld: %s", what,
                r->euler, euler, buf);
  ck_assert_msg(r->duplicate_vertices == 0 && r->degenerate_triangles == 0,
                "%s: %s", what, buf);
  ck_assert_msg(r->referenced == r->vertices, "%s: unused vertices: %s", what,
                buf);
  ck_assert_msg(r->normals_against == 0 && r->normal_length_error < 1e-5,
                "%s: normals: %s", what, buf);
}

START_TEST(polygonized_point_sphere) {
  const double R = 1.0, T = OC_DEFAULT_THRESHOLD;
  oc_node *n = OCT_OK(oc_point(oct_v(0.1, -0.2, 0.3), R, 1.0, NULL));
  oc_aabb box = {oct_v(-1.1, -1.3, -0.9), oct_v(1.2, 1.0, 1.4)};
  mr_report r = mesh_files(n, box, R / 20, 0, "psphere", NULL);
  assert_solid(&r, 2, "point sphere");
  ck_assert_uint_eq(r.components, 1);
  /* The iso-surface g(d / R) = T is a sphere of radius R ginv(T). */
  double rho = R * oct_ginv(T), want = 4.0 / 3.0 * PI * rho * rho * rho;
  ck_assert_msg(fabs(r.volume - want) <= 0.01 * want,
                "volume %.6g, analytic %.6g (%.3f %%)", r.volume, want,
                100 * (r.volume - want) / want);
  for (int c = 0; c < 3; c++) {
    double ctr = c == 0 ? 0.1 : c == 1 ? -0.2 : 0.3;
    ck_assert_double_le(fabs(r.lo[c] - (ctr - rho)), R / 20);
    ck_assert_double_le(fabs(r.hi[c] - (ctr + rho)), R / 20);
  }
}
END_TEST

START_TEST(polygonized_box) {
  /* A rounded box: the solid [lo, hi] grown by rho = R ginv(T). */
  const double R = 0.5;
  oc_node *n =
      OCT_OK(oc_box(oct_v(-1, -0.5, -0.25), oct_v(1, 0.5, 0.25), R, 1, NULL));
  mr_report r = mesh_files(n, cube_box(1.6), 0.04, 0, "box", NULL);
  assert_solid(&r, 2, "box");
  double rho = R * oct_ginv(OC_DEFAULT_THRESHOLD), a = 2, b = 1, c = 0.5;
  double want = a * b * c + 2 * (a * b + b * c + c * a) * rho +
                PI * (a + b + c) * rho * rho + 4.0 / 3.0 * PI * rho * rho * rho;
  ck_assert_msg(fabs(r.volume - want) <= 0.01 * want,
                "volume %.6g, analytic %.6g", r.volume, want);
}
END_TEST

START_TEST(polygonized_ring) {
  /* A closed polyline (16-gon of radius 2) thickened: a torus. */
  oc_vec3 pts[17];
  for (int i = 0; i <= 16; i++) {
    double t = 2 * PI * (i % 16) / 16;
    pts[i] = oct_v(2 * cos(t), 2 * sin(t), 0);
  }
  oc_node *n = OCT_OK(oc_curve(pts, 17, 0, 0.6, 1, NULL));
  oc_aabb box = {oct_v(-3, -3, -1), oct_v(3, 3, 1)};
  mr_report r = mesh_files(n, box, 0.05, 0, "ring", NULL);
  assert_solid(&r, 0, "ring");
  ck_assert_uint_eq(r.components, 1);
}
END_TEST

START_TEST(polygonized_half_space) {
  /* The half-space below z = rho, cut and capped by the box: a slab. */
  const double R = 1;
  oc_node *n = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), R, 1, NULL));
  oc_aabb box = {oct_v(-1, -1.5, -1), oct_v(1, 1.5, 1.25)};
  oc_mesh *m;
  mr_report r = mesh_files(n, box, 0.1, 0, "halfspace", &m);
  assert_solid(&r, 2, "capped half-space");
  double rho = R * oct_ginv(OC_DEFAULT_THRESHOLD);
  double want = 2 * 3 * (rho + 1);
  /* The flat top is exact; marching cubes bevels the box's edges where
  ** the caps meet (by up to half a cell), which costs ~0.3 % here. */
  ck_assert_msg(fabs(r.volume - want) <= 0.01 * want, "volume %.9g, exact %.9g",
                r.volume, want);
  ck_assert_double_le(fabs(r.hi[2] - rho), 1e-5);
  oc_mesh_free(m);
  /* open: the cap faces on the box go, the surface stays consistent. */
  n = OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), R, 1, NULL));
  r = mesh_files(n, box, 0.1, 1, "terrain", NULL);
  char buf[512];
  ck_assert_msg(!r.closed && r.consistent && r.boundary_edges > 0 &&
                    r.euler == 1,
                "open half-space: %s", mr_report_str(&r, buf, sizeof buf));
  /* The bevel along the box's edges stays: a skirt less than a cell deep
  ** (0.1 / 0.0978 here) hangs from the flat surface at the border. */
  ck_assert_double_le(fabs(r.hi[2] - rho), 1e-5);
  ck_assert_double_ge(r.lo[2], rho - 0.1);
}
END_TEST

START_TEST(polygonized_sphere_crossing_box) {
  oc_node *n = OCT_OK(oc_sphere(oct_v(1, 0.2, 0), 1, 0.5, 1, NULL));
  mr_report r = mesh_files(n, cube_box(1.2), 0.05, 0, "crossing", NULL);
  assert_solid(&r, 2, "sphere crossing the box");
  ck_assert_double_eq_tol(r.hi[0], 1.2, 1e-6); /* capped on the face */
}
END_TEST

START_TEST(polygonized_threads_identical) {
  oc_vec3 pts[5] = {oct_v(-1, 0, 0), oct_v(0, 1, 0.3), oct_v(1, 0, 0),
                    oct_v(0, -1, -0.3), oct_v(-1, 0, 0)};
  int threads = omp_get_max_threads();
  for (int t = 1; t <= 2; t++) {
    oc_node *n = OCT_OK(oc_curve(pts, 5, 0, 0.4, 1, NULL));
    omp_set_num_threads(t);
    oc_mesh *m;
    mesh_files(n, cube_box(1.6), 0.03, 0, t == 1 ? "t1" : "t2", &m);
    oc_mesh_free(m);
  }
  omp_set_num_threads(threads);
  for (int k = 0; k < 3; k++) {
    char a[16], b[16];
    snprintf(a, sizeof a, "t1%s", exts[k]);
    snprintf(b, sizeof b, "t2%s", exts[k]);
    ck_assert_msg(mr_same_bytes(oct_in_dir(dir, a), oct_in_dir(dir, b)),
                  "%s differ", exts[k]);
  }
}
END_TEST

/* ---- axes, colour space, components, metadata (issue 12) --------------- */

/* A heightfield terrain (a hill over 6 x 8 units, about 1.5 high) written
** as GLB stands on +Y: the engine's z extent is glTF Y, engine y is -Z,
** and the triangles still wind counter-clockwise seen from outside. */
START_TEST(glb_terrain_is_y_up) {
  enum { NX = 25, NY = 33 };
  float z[NX * NY];
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++) {
      double x = i * 0.25 - 3, y = j * 0.25 - 4;
      z[j * NX + i] = (float)(1.0 + 0.8 * exp(-(x * x + y * y) / 4));
    }
  oc_error e = {0};
  oc_heightfield *hf = oc_heightfield_new(NX, NY, 0.25, -3, -4, z, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  oc_elevation src;
  ck_assert_int_eq(oc_heightfield_elevation(hf, &src, &e), OC_OK);
  oc_terrain_params tp = {0};
  tp.falloff = 0.5;
  tp.transition = 0.2;
  oc_node *n = oc_terrain(&src, &tp, &e);
  src.release(src.ud);
  oc_heightfield_release(hf);
  ck_assert_msg(n != NULL, "%s", e.msg);
  oc_program *pr = oct_compile(n, 0, 0);
  oc_polygonize_params pp = {0};
  pp.box = (oc_aabb){oct_v(-3, -4, 0), oct_v(3, 4, 2.5)};
  pp.cell = 0.1;
  oc_mesh *m = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  oc_program_free(pr);
  write_ok(m, oct_in_dir(dir, "hill.glb"));
  mr_mesh *g = read_raw(oct_in_dir(dir, "hill.glb"));
  const mr_json *accs = mr_json_get(g->gltf, "accessors");
  const mr_json *pa = mr_json_at(accs, 0);
  double lo[3], hi[3], elo[3], ehi[3];
  for (int c = 0; c < 3; c++) {
    lo[c] = mr_json_at(mr_json_get(pa, "min"), c)->number;
    hi[c] = mr_json_at(mr_json_get(pa, "max"), c)->number;
    elo[c] = ehi[c] = m->pos[c];
    for (size_t i = 1; i < m->nv; i++) {
      elo[c] = fmin(elo[c], m->pos[3 * i + c]);
      ehi[c] = fmax(ehi[c], m->pos[3 * i + c]);
    }
  }
  /* glTF X = x, Y = z, Z = -y (float values, compared exactly). */
  ck_assert_double_eq((float)lo[0], (float)elo[0]);
  ck_assert_double_eq((float)hi[0], (float)ehi[0]);
  ck_assert_double_eq((float)lo[1], (float)elo[2]);
  ck_assert_double_eq((float)hi[1], (float)ehi[2]);
  ck_assert_double_eq((float)lo[2], (float)-ehi[1]);
  ck_assert_double_eq((float)hi[2], (float)-elo[1]);
  /* The height runs along glTF Y: 0 .. 1.8, narrower than X (6), Z (8). */
  ck_assert_double_le(hi[1] - lo[1], 2.0);
  ck_assert_double_ge(hi[2] - lo[2], 7);
  ck_assert_double_ge(hi[0] - lo[0], 5);
  /* Read in its own axes the file is a closed, outward solid whose
  ** normals agree with the winding; the hill top's normal points +Y. */
  mr_report r;
  char buf[512];
  mr_check(g, &r);
  ck_assert_msg(r.closed && r.consistent && r.outward && r.volume > 0 &&
                    r.normals_against * 100 < r.referenced,
                "%s", mr_report_str(&r, buf, sizeof buf));
  size_t top = 0;
  for (size_t i = 1; i < g->nv; i++)
    if (g->pos[3 * i + 1] > g->pos[3 * top + 1]) top = i;
  ck_assert_double_gt(g->nrm[3 * top + 1], 0.9);
  mr_free(g);
  oc_mesh_free(m);
}
END_TEST

/* One colour space: PLY bytes decoded from sRGB equal GLB's linear
** floats within the 8-bit step; the GLB's material shows them. */
START_TEST(colors_agree_ply_glb) {
  oc_mesh *m = awkward(256, 5);
  float *rgb = malloc(3 * 256 * sizeof *rgb);
  for (int i = 0; i < 3 * 256; i++)
    rgb[i] = (float)((i * 37) % 256) / 255.0f;
  rgb[0] = 0.5f, rgb[1] = 0.002f, rgb[2] = 1;
  ck_assert_int_eq(oc_mesh_set_colors(m, rgb, NULL), OC_OK);
  free(rgb);
  write_ok(m, oct_in_dir(dir, "c.ply"));
  write_ok(m, oct_in_dir(dir, "c.glb"));
  mr_mesh *p = read_ok(oct_in_dir(dir, "c.ply"));
  mr_mesh *g = read_ok(oct_in_dir(dir, "c.glb"));
  ck_assert_ptr_nonnull(p->col);
  ck_assert_ptr_nonnull(g->col);
  double worst = 0;
  for (int i = 0; i < 3 * 256; i++) {
    double lin = srgb_decode(p->col[i]); /* p->col = byte / 255 */
    worst = fmax(worst, fabs(lin - g->col[i]));
    /* Half an 8-bit step in sRGB, through the decoding's slope (<= 2.3). */
    ck_assert_msg(fabs(lin - g->col[i]) <= 2.3 * 0.5 / 255 + 1e-6,
                  "colour %d: PLY %g (linear %g), GLB %g", i, p->col[i] * 255,
                  lin, g->col[i]);
  }
  ck_assert_double_gt(worst, 0); /* 8-bit, so not all exact */
  /* Without the sRGB encoding, linear 0.5 would read back as 0.5 and
  ** decode to 0.214. */
  ck_assert_double_eq_tol(srgb_decode(p->col[0]), 0.5, 0.005);
  const mr_json *prim = mr_json_at(
      mr_json_get(mr_json_at(mr_json_get(g->gltf, "meshes"), 0), "primitives"),
      0);
  const mr_json *mat = mr_json_at(mr_json_get(g->gltf, "materials"),
                                  (size_t)jnum(mr_json_get(prim, "material")));
  const mr_json *pbr = mr_json_get(mat, "pbrMetallicRoughness");
  ck_assert_ptr_nonnull(pbr);
  for (int c = 0; c < 4; c++)
    ck_assert_double_eq(
        mr_json_at(mr_json_get(pbr, "baseColorFactor"), (size_t)c)->number, 1);
  ck_assert_double_eq(mr_json_get(pbr, "metallicFactor")->number, 0);
  ck_assert_double_eq_tol(mr_json_get(pbr, "roughnessFactor")->number, 0.9,
                          1e-9);
  mr_free(p);
  mr_free(g);
  oc_mesh_free(m);
}
END_TEST

/* Two separate spheres, 1 and 0.5 in radius: two components, numbered
** by lowest vertex, whose counts add up; a threshold between them keeps
** the big one only, closed, with the same bytes for 1 and 2 threads. */
static oc_mesh *two_spheres(size_t min_component) {
  oc_node *a = OCT_OK(oc_point(oct_v(-1.5, 0, 0), 1.0, 1.0, NULL));
  oc_node *b = OCT_OK(oc_point(oct_v(1.5, 0, 0), 0.5, 1.0, NULL));
  oc_node *kids[2] = {a, b};
  oc_node *u = OCT_OK(oc_union(kids, 2, NULL));
  oc_node_release(a);
  oc_node_release(b);
  oc_program *pr = oct_compile(u, 0, 0);
  oc_polygonize_params pp = {0};
  pp.box = (oc_aabb){oct_v(-2.6, -1.1, -1.1), oct_v(2.6, 1.1, 1.1)};
  pp.cell = 0.05;
  pp.min_component = min_component;
  oc_error e = {0};
  oc_mesh *m = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  oc_program_free(pr);
  return m;
}

START_TEST(components_two_spheres) {
  oc_mesh *m = two_spheres(0);
  size_t *sz, n;
  oc_error e = {0};
  ck_assert_int_eq(oc_mesh_components(m, &sz, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 2);
  ck_assert_uint_eq(sz[0] + sz[1], m->nv);
  size_t big = sz[0] > sz[1] ? sz[0] : sz[1];
  size_t small = sz[0] > sz[1] ? sz[1] : sz[0];
  /* Areas scale as R^2: the small sphere has about a quarter of the
  ** vertices. */
  ck_assert_msg(small * 3 < big && small * 6 > big, "%zu, %zu", big, small);
  /* Vertex 0's sphere is component 0. */
  ck_assert_uint_eq(sz[0], m->pos[0] < 0 ? big : small);
  /* A ground truth independent of the union-find: count vertices by x. */
  size_t left = 0;
  for (size_t i = 0; i < m->nv; i++)
    left += m->pos[3 * i] < 0;
  ck_assert_uint_eq(left, big);
  free(sz);
  oc_mesh_free(m);

  /* min_component between the two keeps only the big sphere. */
  m = two_spheres(small + 1);
  ck_assert_uint_eq(m->nv, big);
  for (size_t i = 0; i < m->nv; i++)
    ck_assert_float_lt(m->pos[3 * i], 0);
  ck_assert_int_eq(oc_mesh_components(m, &sz, &n, &e), OC_OK);
  ck_assert_uint_eq(n, 1);
  ck_assert_uint_eq(sz[0], big);
  free(sz);
  write_ok(m, oct_in_dir(dir, "big.ply"));
  mr_report r = report_of(oct_in_dir(dir, "big.ply"));
  assert_solid(&r, 2, "the big sphere alone");
  oc_mesh_free(m);
  /* 0, 1 and small keep both. */
  for (size_t k = 0; k <= 2; k++) {
    m = two_spheres(k == 2 ? small : k);
    ck_assert_uint_eq(m->nv, big + small);
    oc_mesh_free(m);
  }
  /* Above both: nothing left, still a valid (empty) mesh. */
  m = two_spheres(big + 1);
  ck_assert_uint_eq(m->nv, 0);
  ck_assert_uint_eq(m->nt, 0);
  write_ok(m, oct_in_dir(dir, "none.glb"));
  oc_mesh_free(m);

  /* The same bytes for 1 and 2 threads. */
  int threads = omp_get_max_threads();
  for (int t = 1; t <= 2; t++) {
    omp_set_num_threads(t);
    m = two_spheres(small + 1);
    write_ok(m, oct_in_dir(dir, t == 1 ? "c1.ply" : "c2.ply"));
    oc_mesh_free(m);
  }
  omp_set_num_threads(threads);
  ck_assert(
      mr_same_bytes(oct_in_dir(dir, "c1.ply"), oct_in_dir(dir, "c2.ply")));
}
END_TEST

/* Components of a hand-made mesh: order by lowest vertex, unused
** vertices alone, colours moved with their vertices. */
START_TEST(components_order) {
  /* Tetra A on vertices 1, 3, 5, 7; tetra B on 0, 2, 4, 6; 8 unused. */
  float pos[27];
  for (int i = 0; i < 27; i++)
    pos[i] = (float)i;
  const uint32_t tri[24] = {1, 3, 5, 1, 5, 7, 1, 7, 3, 3, 7, 5,
                            0, 2, 4, 0, 4, 6, 0, 6, 2, 2, 6, 4};
  oc_mesh *m = build(pos, 9, tri, 8);
  size_t *sz, n;
  ck_assert_int_eq(oc_mesh_components(m, &sz, &n, NULL), OC_OK);
  ck_assert_uint_eq(n, 3);
  ck_assert_uint_eq(sz[0], 4); /* vertex 0's */
  ck_assert_uint_eq(sz[1], 4); /* vertex 1's */
  ck_assert_uint_eq(sz[2], 1); /* vertex 8 */
  free(sz);
  float rgb[27];
  for (int i = 0; i < 27; i++)
    rgb[i] = (float)i / 32;
  oc_mesh_set_colors(m, rgb, NULL);
  ck_assert_int_eq(oc_mesh_drop_components(m, 2, NULL), OC_OK);
  ck_assert_uint_eq(m->nv, 8);
  ck_assert_uint_eq(m->nt, 8);
  for (size_t i = 0; i < 24; i++) {
    ck_assert_float_eq(m->pos[i], (float)i);
    ck_assert_float_eq(m->col[i], (float)i / 32);
    ck_assert_uint_eq(m->tri[i], tri[i]);
  }
  ck_assert_int_eq(oc_mesh_components(m, &sz, &n, NULL), OC_OK);
  ck_assert_uint_eq(n, 2);
  free(sz);
  oc_mesh_free(m);
  /* An empty mesh has no component. */
  m = oc_mesh_alloc(0, 0, NULL);
  ck_assert_int_eq(oc_mesh_components(m, &sz, &n, NULL), OC_OK);
  ck_assert_uint_eq(n, 0);
  ck_assert_ptr_null(sz);
  oc_mesh_free(m);
}
END_TEST

/* The text of a PLY's header or an OBJ's leading comments. */
static char *slurp_text(const char *path) {
  size_t len;
  char *d = (char *)mr_slurp(path, &len);
  ck_assert_ptr_nonnull(d);
  d = realloc(d, len + 1);
  d[len] = '\0';
  return d;
}

/* Metadata with quotes, newlines, a tab, a control byte, UTF-8 and a
** byte that is not UTF-8: the GLB's JSON parses, is UTF-8, and gives the
** value back (the bad byte as U+FFFD); PLY and OBJ comments hold one line
** per pair that cannot forge another. */
START_TEST(meta_in_every_format) {
  const char *nasty = "a \"quoted\" \\ path\nend\tx\001 caf\xc3\xa9 \xff!";
  const char *forge = "1\noutcrop:seed=99";
  oc_mesh *m = tetra();
  oc_error e = {0};
  ck_assert_int_eq(oc_mesh_set_meta(m, "outcrop:scene", "old", &e), OC_OK);
  ck_assert_int_eq(oc_mesh_set_meta(m, "outcrop:scene", nasty, &e), OC_OK);
  ck_assert_int_eq(oc_mesh_set_meta(m, "outcrop:seed", forge, &e), OC_OK);
  ck_assert_int_eq(oc_mesh_set_meta(m, "Software", "outcrop " OC_VERSION, &e),
                   OC_OK);
  ck_assert_uint_eq(oc_mesh_meta_count(m), 3);
  ck_assert_int_eq(oc_mesh_set_meta(m, "bad key", "v", &e), OC_EINVAL);
  ck_assert_int_eq(oc_mesh_set_meta(m, "a\nb", "v", &e), OC_EINVAL);
  ck_assert_int_eq(oc_mesh_set_meta(m, "", "v", &e), OC_EINVAL);
  ck_assert_int_eq(oc_mesh_set_meta(m, "k", NULL, &e), OC_EINVAL);
  ck_assert_uint_eq(oc_mesh_meta_count(m), 3);

  write_ok(m, oct_in_dir(dir, "p.glb"));
  mr_mesh *g = read_raw(oct_in_dir(dir, "p.glb")); /* the JSON parses */
  const mr_json *x = mr_json_get(mr_json_get(g->gltf, "asset"), "extras");
  ck_assert_ptr_nonnull(x);
  ck_assert_uint_eq(x->n, 3);
  ck_assert_str_eq(
      mr_json_str(mr_json_get(x, "outcrop:scene")),
      "a \"quoted\" \\ path\nend\tx\001 caf\xc3\xa9 \xef\xbf\xbd!");
  ck_assert_str_eq(mr_json_str(mr_json_get(x, "outcrop:seed")), forge);
  ck_assert_str_eq(mr_json_str(mr_json_get(x, "Software")),
                   "outcrop " OC_VERSION);
  mr_free(g);
  /* The JSON chunk is valid UTF-8. */
  size_t len;
  unsigned char *d = mr_slurp(oct_in_dir(dir, "p.glb"), &len);
  size_t jl = d[12] | d[13] << 8 | d[14] << 16 | (size_t)d[15] << 24;
  for (size_t i = 20; i < 20 + jl;) {
    unsigned c = d[i];
    size_t k = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : 4;
    ck_assert_msg(c < 0x80 || (c >= 0xC2 && c <= 0xF4), "byte %zu: %02x", i, c);
    for (size_t j = 1; j < k; j++)
      ck_assert_msg((d[i + j] & 0xC0) == 0x80, "byte %zu", i + j);
    i += k;
  }
  free(d);

  const char *want[2] = {"comment ", "# "};
  const char *names[2] = {"p.ply", "p.obj"};
  for (int f = 0; f < 2; f++) {
    write_ok(m, oct_in_dir(dir, names[f]));
    char *t = slurp_text(oct_in_dir(dir, names[f]));
    char line[256];
    snprintf(line, sizeof line,
             "\n%soutcrop:scene=\"a \\\"quoted\\\" \\\\ path\\nend\\tx\\001 "
             "caf\xc3\xa9 \xff!\"\n",
             want[f]);
    ck_assert_msg(strstr(t, line), "%s: no line %s in\n%.600s", names[f], line,
                  t);
    snprintf(line, sizeof line, "\n%soutcrop:seed=\"1\\noutcrop:seed=99\"\n",
             want[f]);
    ck_assert_msg(strstr(t, line), "%s: %.600s", names[f], t);
    ck_assert_ptr_null(strstr(t, "\noutcrop:seed=99"));
    free(t);
    mr_mesh *b = read_ok(oct_in_dir(dir, names[f]));
    same_geometry(m, b, names[f]);
    ck_assert_str_eq(b->generator, "written by outcrop " OC_VERSION);
    mr_free(b);
  }
  /* A value of 65535 bytes (the limit) of quotes still writes, in every
  ** format. */
  char *big = malloc(65536);
  memset(big, '"', 65535);
  big[65535] = '\0';
  ck_assert_int_eq(oc_mesh_set_meta(m, "outcrop:params", big, &e), OC_OK);
  big[0] = 'x';
  for (int k = 0; k < 3; k++) {
    char name[16];
    snprintf(name, sizeof name, "big%s", exts[k]);
    write_ok(m, oct_in_dir(dir, name));
    mr_mesh *b = read_raw(oct_in_dir(dir, name));
    if (k == 2)
      ck_assert_uint_eq(
          strlen(mr_json_str(
              mr_json_get(mr_json_get(mr_json_get(b->gltf, "asset"), "extras"),
                          "outcrop:params"))),
          65535);
    mr_free(b);
  }
  free(big);
  oc_mesh_free(m);
}
END_TEST

/* ---- suite -------------------------------------------------------------- */

static Suite *suite(void) {
  Suite *s = suite_create("meshio");
  TCase *t = tcase_create("mesh");
  tcase_add_test(t, alloc_and_accessors);
  tcase_add_test(t, set_colors);
  tcase_add_test(t, color_by_field);
  tcase_add_test(t, color_by_field_deterministic);
  tcase_add_test(t, json_parser);
  suite_add_tcase(s, t);
  t = tcase_create("files");
  tcase_add_checked_fixture(t, mkdir_tmp, teardown);
  tcase_set_timeout(t, 60);
  tcase_add_test(t, round_trip_exact);
  tcase_add_test(t, ply_layout);
  tcase_add_test(t, ply_colors);
  tcase_add_test(t, obj_text);
  tcase_add_test(t, glb_structure);
  tcase_add_test(t, reader_rejects_broken_glb);
  tcase_add_test(t, reader_rejects_broken_ply_obj);
  tcase_add_test(t, check_closed_shapes);
  tcase_add_test(t, check_defects);
  tcase_add_test(t, empty_meshes);
  tcase_add_test(t, glb_size_limit);
  tcase_add_test(t, refused_meshes);
  tcase_add_test(t, extensions);
  tcase_add_test(t, repeat_writes_identical);
  tcase_add_test(t, unwritable_paths);
  tcase_add_test(t, write_fails_midway);
  tcase_add_test(t, disk_full);
  tcase_add_test(t, concurrent_writes);
  tcase_add_test(t, atomic_helper);
  tcase_add_test(t, killed_while_writing);
  suite_add_tcase(s, t);
  t = tcase_create("polygonized");
  tcase_add_checked_fixture(t, mkdir_tmp, teardown);
  tcase_set_timeout(t, 120);
  tcase_add_test(t, polygonized_point_sphere);
  tcase_add_test(t, polygonized_box);
  tcase_add_test(t, polygonized_ring);
  tcase_add_test(t, polygonized_half_space);
  tcase_add_test(t, polygonized_sphere_crossing_box);
  tcase_add_test(t, polygonized_threads_identical);
  tcase_add_test(t, glb_terrain_is_y_up);
  tcase_add_test(t, colors_agree_ply_glb);
  tcase_add_test(t, components_two_spheres);
  tcase_add_test(t, components_order);
  tcase_add_test(t, meta_in_every_format);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
