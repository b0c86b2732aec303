/*
** test_defaults.c — the defaults and compositions the front ends take from
** the lib (so that C callers get the Lua API's): render framing, the
** polygonize box and cell, the slice window and palettes, a grid's
** resample grid, crop range and sum, its default terrain, sea level and
** mask image, the shared erosion parameters, transform composition and
** the message number format.
*/
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "ocheck.h"
#include "outcrop.h"

#define PI 3.14159265358979323846

static oc_program *point_at(oc_vec3 c, double r) {
  oc_error e = {0};
  return oct_compile(OCT_OK(oc_point(c, r, 1, &e)), 0, 0);
}

static oc_program *plane_prog(void) {
  oc_error e = {0};
  return oct_compile(OCT_OK(oc_plane(oct_v(0, 0, 0), oct_v(0, 0, 1), 1, 1, &e)),
                     0, 0);
}

static void assert_msg(const oc_error *e, const char *word) {
  ck_assert_int_eq(e->code, OC_EINVAL);
  ck_assert_msg(strstr(e->msg, word) != NULL, "message '%s' lacks '%s'", e->msg,
                word);
}

/* A grid nx x ny of cell c at (x0, y0) whose sample k is z0 + k * dz. */
static oc_heightfield *ramp(int nx, int ny, double c, double x0, double y0,
                            double z0, double dz) {
  oc_error e = {0};
  oc_heightfield *hf = oc_heightfield_new(nx, ny, c, x0, y0, NULL, &e);
  ck_assert_msg(hf != NULL, "%s", e.msg);
  float *z = oc_heightfield_samples_mut(hf);
  for (int k = 0; k < nx * ny; k++)
    z[k] = (float)(z0 + k * dz);
  return hf;
}

/* ---- render framing ------------------------------------------------------ */

START_TEST(render_framing) {
  oc_program *pr = point_at(oct_v(10, 20, 5), 2);
  oc_aabb b = oc_program_bounds(pr);
  oc_render_params rp;
  oc_error e = {0};
  oc_render_defaults(&rp);
  ck_assert_double_eq(rp.camera.fov, 40);
  ck_assert_double_eq(rp.camera.up.z, 1);
  ck_assert_int_eq(oc_render_default_camera(pr, &rp, 0, 0, &e), OC_OK);
  oc_vec3 t = rp.camera.target, eye = rp.camera.eye;
  ck_assert_double_eq_tol(t.x, (b.lo.x + b.hi.x) / 2, 1e-12);
  ck_assert_double_eq_tol(t.y, (b.lo.y + b.hi.y) / 2, 1e-12);
  ck_assert_double_eq_tol(t.z, (b.lo.z + b.hi.z) / 2, 1e-12);
  /* From the south-west (x and y smaller), 30 degrees up. */
  oc_vec3 d = oct_sub(eye, t);
  double len = oct_len(d);
  ck_assert(d.x < 0 && d.y < 0);
  ck_assert_double_eq_tol(d.x, d.y, 1e-9 * len);
  ck_assert_double_eq_tol(asin(d.z / len) * 180 / PI, 30, 1e-9);
  /* Every corner of the bounds in view, and the eye outside them. */
  oc_vec3 fw = oct_mul(d, -1 / len);
  oc_vec3 rt = oct_cross(fw, rp.camera.up);
  rt = oct_mul(rt, 1 / oct_len(rt));
  oc_vec3 up = oct_cross(rt, fw);
  double tv = tan(rp.camera.fov * PI / 360), th = tv * 640 / 360;
  double worst = 0;
  for (int c = 0; c < 8; c++) {
    oc_vec3 q = oct_v(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y,
                      c & 4 ? b.hi.z : b.lo.z);
    oc_vec3 v = oct_sub(q, eye);
    double z = oct_dot(v, fw);
    ck_assert(z > 0);
    worst = fmax(worst, fmax(fabs(oct_dot(v, rt)) / (th * z),
                             fabs(oct_dot(v, up)) / (tv * z)));
  }
  ck_assert(worst <= 1);
  ck_assert(worst > 0.5); /* framed, not lost in the distance */
  ck_assert(!oct_box_contains(b, eye));

  /* A given eye is kept; a given target too. */
  oc_render_defaults(&rp);
  rp.camera.eye = oct_v(1, 2, 3);
  ck_assert_int_eq(oc_render_default_camera(pr, &rp, 1, 0, &e), OC_OK);
  ck_assert_double_eq(rp.camera.eye.x, 1);
  ck_assert_double_eq_tol(rp.camera.target.x, t.x, 1e-12);
  oc_render_defaults(&rp);
  rp.camera.target = oct_v(7, 8, 9);
  ck_assert_int_eq(oc_render_default_camera(pr, &rp, 0, 1, &e), OC_OK);
  ck_assert_double_eq(rp.camera.target.x, 7);
  oc_vec3 d2 = oct_sub(rp.camera.eye, rp.camera.target);
  ck_assert(d2.x < 0 && d2.y < 0 && d2.z > 0);

  /* Refusals: an up along the view, infinite bounds. */
  oc_render_defaults(&rp);
  rp.camera.up = fw;
  ck_assert_int_eq(oc_render_default_camera(pr, &rp, 0, 0, &e), OC_EINVAL);
  assert_msg(&e, "'camera.up' is parallel to the default view direction");
  oc_program *pl = plane_prog();
  oc_render_defaults(&rp);
  ck_assert_int_eq(oc_render_default_camera(pl, &rp, 0, 0, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "the node's bounds are infinite: give 'camera' = "
                          "{eye =, target =}");
  ck_assert_int_eq(oc_render_default_camera(pl, &rp, 1, 1, &e), OC_OK);
  /* The checks oc_render makes, before any work; fov as framing says it. */
  oc_render_defaults(&rp);
  rp.camera.eye = oct_v(0, -20, 0);
  ck_assert_int_eq(oc_render_check(pr, &rp, &e), OC_OK);
  rp.camera.fov = 180;
  ck_assert_int_eq(oc_render_check(pr, &rp, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "'camera.fov' must be in (0, 179] degrees (got "
                          "180.0)");
  ck_assert_int_eq(oc_render_default_camera(pr, &rp, 0, 0, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "'camera.fov' must be in (0, 179] degrees (got "
                          "180.0)");
  rp.camera.fov = 40;
  rp.sun_intensity = -2;
  ck_assert_int_eq(oc_render_check(pr, &rp, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "'sun.intensity' must be finite and >= 0 (got "
                          "-2.0)");
  rp.sun_intensity = 1;
  rp.sun_direction = oct_v(0, 0, 0);
  ck_assert_int_eq(oc_render_check(pr, &rp, &e), OC_EINVAL);
  assert_msg(&e, "'sun.direction'");
  oc_program_free(pl);
  oc_program_free(pr);
}
END_TEST

/* ---- polygonize ---------------------------------------------------------- */

START_TEST(polygonize_defaults) {
  oc_program *pr = point_at(oct_v(0, 0, 0), 2);
  oc_aabb b;
  oc_error e = {0};
  ck_assert_int_eq(oc_polygonize_default_box(pr, &b, &e), OC_OK);
  oc_aabb pb = oc_program_bounds(pr);
  ck_assert_double_eq(b.lo.x, pb.lo.x);
  ck_assert_double_eq(b.hi.z, pb.hi.z);
  ck_assert_double_eq_tol(oc_polygonize_default_cell(b),
                          (pb.hi.x - pb.lo.x) / 64, 1e-15);
  ck_assert_double_eq(
      oc_polygonize_default_cell((oc_aabb){{0, 0, 0}, {1, 6.4, 3}}), 0.1);

  /* cell 0 and no resolution: the default cell, the same mesh. */
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = b;
  oc_mesh *m0 = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m0 != NULL, "%s", e.msg);
  pp.cell = oc_polygonize_default_cell(b);
  oc_mesh *m1 = oc_polygonize(pr, &pp, &e);
  ck_assert_msg(m1 != NULL, "%s", e.msg);
  size_t nv = oc_mesh_vertex_count(m0);
  ck_assert_uint_gt(nv, 100);
  ck_assert_uint_eq(nv, oc_mesh_vertex_count(m1));
  ck_assert_uint_eq(oc_mesh_triangle_count(m0), oc_mesh_triangle_count(m1));
  ck_assert(memcmp(oc_mesh_positions(m0), oc_mesh_positions(m1),
                   nv * 3 * sizeof(float)) == 0);
  oc_mesh_free(m0);
  oc_mesh_free(m1);

  oc_program *pl = plane_prog();
  b = (oc_aabb){{1, 2, 3}, {4, 5, 6}};
  ck_assert_int_eq(oc_polygonize_default_box(pl, &b, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "the node's bounds are infinite: give 'box' = "
                          "{x0, y0, z0, x1, y1, z1}");
  ck_assert_double_eq(b.lo.x, 1); /* unchanged */
  oc_program_free(pl);
  oc_program_free(pr);
}
END_TEST

/* ---- slices and palettes ------------------------------------------------- */

START_TEST(slice_window_and_palette) {
  oc_program *pr = point_at(oct_v(1, 2, 3), 2);
  oc_aabb b = oc_program_bounds(pr);
  oc_slice_params sp = {OC_PLANE_XZ, 2, 0, 0, 0, 0, 16, 8};
  oc_error e = {0};
  ck_assert_int_eq(oc_slice_default_window(pr, &sp, &e), OC_OK);
  ck_assert_double_eq(sp.u0, b.lo.x);
  ck_assert_double_eq(sp.v0, b.lo.z);
  ck_assert_double_eq(sp.u1, b.hi.x);
  ck_assert_double_eq(sp.v1, b.hi.z);
  sp.plane = OC_PLANE_YZ;
  ck_assert_int_eq(oc_slice_default_window(pr, &sp, &e), OC_OK);
  ck_assert_double_eq(sp.u0, b.lo.y);
  ck_assert_double_eq(sp.v1, b.hi.z);

  int n = 0;
  const double *st = oc_palette_strata(&n);
  ck_assert_int_eq(n, 5);
  ck_assert_int_eq(oc_palette_check(st, n, &e), OC_OK);
  ck_assert_double_eq(st[4 * 4 + 1], 0.30);
  const double *rs = oc_palette_resistance(&n);
  ck_assert_int_eq(n, 4);
  ck_assert_int_eq(oc_palette_check(rs, n, &e), OC_OK);
  ck_assert(rs[1] < rs[4 * 3 + 1]); /* soft is dark, hard pale */

  oc_image *img = oc_slice(pr, &sp, &e);
  ck_assert_msg(img != NULL, "%s", e.msg);
  ck_assert_int_eq(oc_slice_apply_palette(img, rs, n, &e), OC_OK);
  const float *px = oc_image_cdata(img);
  for (int i = 0; i < 16 * 8; i++) {
    double rgb[3];
    oc_palette_eval(rs, n, px[5 * i + 4], rgb);
    ck_assert_float_eq(px[5 * i], (float)rgb[0]);
    ck_assert_float_eq(px[5 * i + 2], (float)rgb[2]);
    ck_assert_float_eq(px[5 * i + 3], 1);
  }
  static const double bad[] = {1, 0, 0, 0, 0, 1, 1, 1};
  ck_assert_int_eq(oc_slice_apply_palette(img, bad, 2, &e), OC_EINVAL);
  assert_msg(&e, "'stops'");
  oc_image_free(img);
  img = oc_image_new(4, 4, 3, &e);
  ck_assert_int_eq(oc_slice_apply_palette(img, rs, n, &e), OC_EINVAL);
  assert_msg(&e, "slice");
  oc_image_free(img);

  oc_program *pl = plane_prog();
  ck_assert_int_eq(oc_slice_default_window(pl, &sp, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "the node's bounds are infinite: give 'box' = "
                          "{u0, v0, u1, v1}");
  oc_program_free(pl);
  oc_program_free(pr);
}
END_TEST

/* ---- heightfields -------------------------------------------------------- */

START_TEST(resample_grid_crop_sum) {
  oc_heightfield *hf = ramp(101, 51, 1, 5, -3, 0, 1); /* 100 x 50 m */
  oc_heightfield_grid g;
  oc_error e = {0};
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0.1, 0, 0, &g, &e), OC_OK);
  ck_assert_int_eq(g.nx, 1001); /* 100 / 0.1 with the slack */
  ck_assert_int_eq(g.ny, 501);
  ck_assert_double_eq(g.cell, 0.1);
  ck_assert_double_eq(g.x0, 5);
  ck_assert_double_eq(g.y0, -3);
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 3, 0, 0, &g, &e), OC_OK);
  ck_assert_int_eq(g.nx, 34);
  ck_assert_int_eq(g.ny, 17);
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0, 201, 101, &g, &e),
                   OC_OK);
  ck_assert_double_eq(g.cell, 0.5);
  ck_assert_int_eq(g.nx, 201);

  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0, 0, 0, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "give either 'cell' or 'size' = {nx, ny}");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 1, 10, 10, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "give either 'cell' or 'size' = {nx, ny}");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0, 11, 11, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'size' {11, 11} needs cells of 10.0 along x but "
                          "5.0 along y (cells are square): keep the grid's "
                          "proportions or give 'cell'");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 60, 0, 0, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'cell' 60.0 is larger than the grid (100.0 x "
                          "50.0): it would leave fewer than 2 samples per "
                          "side");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0.001, 0, 0, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'cell' 0.001 gives 100001 x 50001 samples (at "
                          "most 65535 per side)");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, 0.004, 0, 0, &g, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'cell' 0.004 gives 25001 x 12501 samples, over "
                          "the limit of 268435456");
  ck_assert_int_eq(oc_heightfield_resample_grid(hf, -1, 0, 0, &g, &e),
                   OC_EINVAL);
  assert_msg(&e, "'cell'");

  int ij[4];
  ck_assert_int_eq(oc_heightfield_crop_range(hf, 7.5, -3, 10, 0.5, ij, &e),
                   OC_OK);
  ck_assert_int_eq(ij[0], 3); /* x = 8 */
  ck_assert_int_eq(ij[1], 0);
  ck_assert_int_eq(ij[2], 5); /* x = 10, on the edge: kept */
  ck_assert_int_eq(ij[3], 3);
  oc_heightfield *c = oc_heightfield_crop_box(hf, 7.5, -3, 10, 0.5, &e);
  ck_assert_msg(c != NULL, "%s", e.msg);
  ck_assert_int_eq(oc_heightfield_nx(c), 3);
  ck_assert_int_eq(oc_heightfield_ny(c), 4);
  ck_assert_float_eq(oc_heightfield_samples(c)[0], 3);
  /* sum of 101 j + i over i = 3..5, j = 0..3 */
  ck_assert_double_eq(oc_heightfield_sum(c), 12 * 4 + 3 * 101 * 6);
  oc_heightfield_release(c);
  ck_assert_int_eq(oc_heightfield_crop_range(hf, 7.2, 0, 7.8, 4, ij, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'box' holds fewer than 2 x 2 samples of the grid");
  ck_assert_int_eq(oc_heightfield_crop_range(hf, 8, 0, 7, 4, ij, &e),
                   OC_EINVAL);
  ck_assert_str_eq(e.msg, "'box' = {x0, y0, x1, y1} needs x0 < x1 and y0 < y1");
  double n = 101.0 * 51;
  ck_assert_double_eq(oc_heightfield_sum(hf), n * (n - 1) / 2);
  ck_assert_double_eq(oc_heightfield_sum(NULL), 0);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(terrain_sea_level_mask) {
  oc_error e = {0};
  oc_heightfield *hf = ramp(21, 11, 2, 0, 0, -5, 0.1);
  oc_terrain_params tp;
  oc_terrain_defaults(hf, &tp);
  ck_assert_double_eq(tp.falloff, 8);
  ck_assert_double_eq(tp.transition, 1);
  ck_assert(tp.mask == NULL && tp.invert == 0 && tp.thickness == 0);
  ck_assert_int_eq(tp.edges, OC_TERRAIN_EDGES_DEFAULT);

  /* The default terrain is the terrain of the default parameters. */
  oc_node *a = oc_heightfield_terrain(hf, NULL, &e);
  ck_assert_msg(a != NULL, "%s", e.msg);
  oc_node *b = oc_heightfield_terrain(hf, &tp, &e);
  ck_assert_msg(b != NULL, "%s", e.msg);
  oc_program *pa = oct_compile(a, 0, 0), *pb = oct_compile(b, 0, 0);
  for (int k = 0; k < 50; k++) {
    oc_vec3 p = oct_v(0.8 * k, 0.4 * k, -6 + 0.3 * k);
    ck_assert_double_eq(oc_program_eval(pa, p), oc_program_eval(pb, p));
  }
  /* the surface is the grid's: z = h at a sample */
  double h = -5 + 0.1 * (3 * 21 + 4); /* sample (4, 3) at (8, 6) */
  ck_assert_double_eq_tol(oc_program_eval(pa, oct_v(8, 6, h)), 0.5, 1e-6);
  oc_program_free(pa);
  oc_program_free(pb);

  /* Sea level: 0 when spanned, else a quarter up the relief. */
  ck_assert_double_eq(oc_heightfield_sea_level(hf), 0); /* -5 .. 18 */
  oc_heightfield *up = ramp(11, 11, 1, 0, 0, 10, 1);    /* 10 .. 130 */
  ck_assert_double_eq(oc_heightfield_sea_level(up), 40);
  oc_heightfield_release(up);

  /* A mask from an image: stretched over hf, divided by its brightest. */
  const char *dir = oct_tmpdir("defaults");
  oc_image *img = oc_image_new(6, 4, 1, &e);
  float *px = oc_image_data(img);
  for (int k = 0; k < 24; k++)
    px[k] = k < 12 ? 0.2f : 0.4f;
  const char *path = oct_in_dir(dir, "mask.tif");
  int rc = oc_image_write(img, path, 16, &e);
  ck_assert_msg(rc == OC_OK, "%s", e.msg);
  oc_heightfield *m = oc_heightfield_load_mask(path, hf, &e);
  ck_assert_msg(m != NULL, "%s", e.msg);
  ck_assert_int_eq(oc_heightfield_nx(m), 6);
  ck_assert_int_eq(oc_heightfield_ny(m), 4);
  ck_assert_double_eq_tol(oc_heightfield_cell(m), 40.0 / 5, 1e-12);
  double lo, hi;
  oc_heightfield_minmax(m, &lo, &hi);
  ck_assert_double_eq_tol(hi, 1, 1e-6);
  ck_assert_double_eq_tol(lo, 0.5, 1e-3);
  oc_heightfield_release(m);
  for (int k = 0; k < 24; k++)
    px[k] = 0;
  path = oct_in_dir(dir, "black.tif");
  ck_assert_int_eq(oc_image_write(img, path, 16, &e), OC_OK);
  ck_assert(oc_heightfield_load_mask(path, hf, &e) == NULL);
  char want[600];
  snprintf(want, sizeof want, "'mask' image '%s' is black: nothing is inside",
           path);
  ck_assert_str_eq(e.msg, want);
  ck_assert(oc_heightfield_load_mask(oct_in_dir(dir, "none.png"), hf, &e) ==
            NULL);
  ck_assert(strncmp(e.msg, "'mask': ", 8) == 0);
  oc_image_free(img);
  oct_rm_tree(dir);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- generators ---------------------------------------------------------- */

START_TEST(erosion_shared_defaults) {
  oc_gen_erode_params c;
  oc_gen_erode_defaults(&c);
  ck_assert_double_eq(c.beta, 0.2);
  ck_assert_double_eq(c.cutoff, 0.05);
  ck_assert(c.heightfield == NULL && c.radius == 0 && c.steps == 0);
  oc_gen_sea_params s;
  oc_gen_sea_defaults(&s);
  ck_assert_double_eq(s.erode.beta, 0.2);
  ck_assert_double_eq(s.erode.strength, 4);
  ck_assert_int_eq(s.erode.steps, 3);
  ck_assert(isnan(s.sea_level));
  ck_assert_double_eq(s.range, 8);
  ck_assert_int_eq(s.rays, 16);
  oc_gen_river_params r;
  oc_gen_river_defaults(&r);
  ck_assert_double_eq(r.erode.cutoff, 0.05);
  ck_assert_double_eq(r.erode.strength, 2);
  ck_assert_int_eq(r.erode.steps, 2);
  ck_assert_int_eq(r.banks, 3);
  oc_gen_sea_params bad;
  oc_gen_sea_defaults(&bad);
  oc_error e0 = {0};
  oc_heightfield *h0 = ramp(8, 8, 1, 0, 0, -1, 0.1);
  bad.erode.heightfield = h0;
  bad.erode.beta = 2;
  ck_assert(oc_generate_sea(&bad, NULL, &e0) == NULL);
  ck_assert_str_eq(e0.msg, "'beta' must be in [0, 1] (got 2.0)");
  bad.erode.beta = 0.2;
  bad.erode.cutoff = -0.5;
  ck_assert(oc_generate_sea(&bad, NULL, &e0) == NULL);
  ck_assert_str_eq(e0.msg, "'cutoff' must be >= 0 (got -0.5)");
  oc_heightfield_release(h0);

  /* The default sea level is oc_heightfield_sea_level's: the same node. */
  oc_heightfield *hf = ramp(24, 24, 1, 0, 0, 10, 0.05); /* 10 .. 38.75 */
  oc_gen_sea_stats st1, st2;
  oc_error e = {0};
  s.erode.heightfield = hf;
  s.erode.seed = 5;
  s.range = 3;
  s.erode.steps = 1;
  s.rays = 0;
  oc_node *n1 = oc_generate_sea(&s, &st1, &e);
  ck_assert_msg(n1 != NULL, "%s", e.msg);
  s.sea_level = oc_heightfield_sea_level(hf);
  oc_node *n2 = oc_generate_sea(&s, &st2, &e);
  ck_assert_msg(n2 != NULL, "%s", e.msg);
  ck_assert_uint_gt(st1.primitives, 0);
  ck_assert_uint_eq(st1.primitives, st2.primitives);
  ck_assert_uint_eq(st1.samples, st2.samples);
  oc_program *p1 = oct_compile(n1, 0, 0), *p2 = oct_compile(n2, 0, 0);
  for (int k = 0; k < 40; k++) {
    oc_vec3 p = oct_v(0.5 * k, 0.55 * k, 10 + 0.4 * k);
    ck_assert_double_eq(oc_program_eval(p1, p), oc_program_eval(p2, p));
  }
  oc_program_free(p1);
  oc_program_free(p2);
  oc_heightfield_release(hf);
}
END_TEST

/* ---- transforms ---------------------------------------------------------- */

static void apply(const double m[12], oc_vec3 p, double out[3]) {
  for (int i = 0; i < 3; i++)
    out[i] =
        m[4 * i] * p.x + m[4 * i + 1] * p.y + m[4 * i + 2] * p.z + m[4 * i + 3];
}

START_TEST(transform_composition) {
  double m[12], r[12], q[3];
  oc_error e = {0};
  /* 90 degrees about z: x goes to y. */
  ck_assert_int_eq(oc_xform_axis_angle(oct_v(0, 0, 5), 90, r, &e), OC_OK);
  apply(r, oct_v(1, 0, 0), q);
  ck_assert_double_eq_tol(q[0], 0, 1e-15);
  ck_assert_double_eq_tol(q[1], 1, 1e-15);
  /* Euler {90, 0, 90}: about x first (y to z), then about z. */
  ck_assert_int_eq(oc_xform_euler(oct_v(90, 0, 90), r, &e), OC_OK);
  apply(r, oct_v(0, 1, 0), q); /* y -> z -> z */
  ck_assert_double_eq_tol(q[2], 1, 1e-15);
  apply(r, oct_v(1, 0, 0), q); /* x -> x -> y */
  ck_assert_double_eq_tol(q[1], 1, 1e-15);
  /* Euler about one axis equals the axis-angle rotation, to the bit. */
  double a[12];
  oc_xform_euler(oct_v(0, 33, 0), r, &e);
  oc_xform_axis_angle(oct_v(0, 1, 0), 33, a, &e);
  ck_assert(memcmp(r, a, sizeof r) == 0);
  /* T R S */
  oc_xform_axis_angle(oct_v(0, 0, 1), 90, r, &e);
  ck_assert_int_eq(oc_xform_compose(oct_v(10, 0, 0), r, oct_v(2, 3, 4), m, &e),
                   OC_OK);
  apply(m, oct_v(1, 1, 1), q); /* scaled (2, 3, 4), turned (-3, 2, 4) */
  ck_assert_double_eq_tol(q[0], 7, 1e-14);
  ck_assert_double_eq_tol(q[1], 2, 1e-14);
  ck_assert_double_eq_tol(q[2], 4, 1e-14);
  oc_xform_mul(m, m, a); /* in place is allowed */
  oc_xform_mul(m, m, m);
  ck_assert(memcmp(m, a, sizeof a) == 0);
  ck_assert_int_eq(
      oc_xform_compose(oct_v(0, 0, 0), NULL, oct_v(1, 1, 1), m, &e), OC_OK);
  oc_xform_identity(a);
  ck_assert(memcmp(m, a, sizeof a) == 0);

  ck_assert_int_eq(oc_xform_axis_angle(oct_v(0, 0, 0), 10, r, &e), OC_EINVAL);
  ck_assert_str_eq(e.msg, "'rotate.axis' must be a non-zero vector");
  ck_assert_int_eq(
      oc_xform_compose(oct_v(0, 0, 0), NULL, oct_v(1, 0, 2.5), m, &e),
      OC_EINVAL);
  ck_assert_str_eq(e.msg,
                   "'scale' factors must be non-zero (got {1.0, 0.0, 2.5})");
  ck_assert_int_eq(oc_xform_euler(oct_v(NAN, 0, 0), r, &e), OC_EINVAL);
  assert_msg(&e, "'rotate'");
}
END_TEST

START_TEST(number_format) {
  char b[OC_NUMSTR];
  ck_assert_str_eq(oc_numstr(2, b), "2.0");
  ck_assert_str_eq(oc_numstr(-3, b), "-3.0");
  ck_assert_str_eq(oc_numstr(0.25, b), "0.25");
  ck_assert_str_eq(oc_numstr(1e20, b), "1e+20");
  ck_assert_str_eq(oc_numstr(0.1 + 0.2, b), "0.3");
  ck_assert_str_eq(oc_numstr(INFINITY, b), "inf");
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("defaults");
  TCase *t = tcase_create("defaults");
  tcase_set_timeout(t, 60);
  tcase_add_test(t, render_framing);
  tcase_add_test(t, polygonize_defaults);
  tcase_add_test(t, slice_window_and_palette);
  tcase_add_test(t, resample_grid_crop_sum);
  tcase_add_test(t, terrain_sea_level_mask);
  tcase_add_test(t, erosion_shared_defaults);
  tcase_add_test(t, transform_composition);
  tcase_add_test(t, number_format);
  suite_add_tcase(s, t);
  return s;
}

int main(void) {
  return oct_run(suite());
}
