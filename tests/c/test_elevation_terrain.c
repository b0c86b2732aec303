/*
** test_elevation_terrain.c — elevation trees (Génevaux et al. 2015) as
** terrains and grids: the implicitized tree's surface is z = f on Omega_T
** and nothing is solid off it, its gradient and Lipschitz bounds hold,
** the mesh is closed and manifold with its top vertices at f (direct
** extraction, far fewer field calls than root finding), sampling into a
** grid gives f exactly (as floats) and the same bytes on any thread
** count, and bad input is refused with the field named.
*/
#include <float.h>
#include <omp.h>
#include <string.h>

#include "meshread.h"
#include "ocheck.h"

static oc_enode *eok_(oc_enode *e, const oc_error *err, const char *what,
                      int line) {
  ck_assert_msg(e != NULL, "line %d: %s failed: %s", line, what, err->msg);
  return e;
}
#define EOK(expr) eok_((expr), &err, #expr, __LINE__)

/* Two noisy hills 800 m apart, a gap between them where alpha < 1/2
** (two Wyvill weights of 0.17), and a river replaced across the west
** one. */
static oc_enode *two_hills(void) {
  oc_error err;
  oc_enode_disc_params a = {
      -400, 0, 600, 100, {OC_ENOISE_PLAIN, 30, 200, 4, 0, 0, 7}};
  oc_enode_disc_params b = {
      400, 0, 600, 220, {OC_ENOISE_RIDGED, 60, 250, 4, 0, 0, 9}};
  oc_enode *k[2] = {EOK(oc_enode_disc(&a, &err)), EOK(oc_enode_disc(&b, &err))};
  oc_enode *land = EOK(oc_enode_blend(k, 2, &err));
  oc_vec3 pts[3] = {{-400, -300, 90}, {-420, 0, 92}, {-380, 300, 95}};
  oc_enode_river_params rp = {pts, 3, OC_ECURVE_CATMULL, OC_RIVER_RIVER, 0,
                              0,   0};
  oc_enode *river = EOK(oc_enode_river(&rp, &err));
  oc_enode *scene = EOK(oc_enode_replace(land, river, 0, &err));
  oc_enode_release(k[0]);
  oc_enode_release(k[1]);
  oc_enode_release(land);
  oc_enode_release(river);
  return scene;
}

static oc_program *tree_program(oc_enode *e, const oc_terrain_params *tp) {
  oc_error err;
  oc_node *t = oc_enode_terrain(e, NULL, tp, &err);
  ck_assert_msg(t != NULL, "oc_enode_terrain: %s", err.msg);
  return oct_compile(t, 0, 0);
}

/* ---- the surface --------------------------------------------------------- */

START_TEST(surface_is_f_on_omega_t) {
  oc_enode *e = two_hills();
  oc_program *pr = tree_program(e, NULL);
  double box[4];
  ck_assert(oc_enode_terrain_box(e, box));
  oct_rng r = oct_rng_new(14);
  int on = 0, off = 0;
  for (int k = 0; k < 4000; k++) {
    double x = oct_unif(&r, box[0], box[2]), y = oct_unif(&r, box[1], box[3]);
    oc_enode_sample s;
    oc_enode_eval(e, x, y, &s);
    if (s.a > 0.5 + 1e-9) {
      /* sigma(0) = T: the field is T on z = f, inside just below, outside
      ** just above (by a hundredth of the transition) */
      double fz = oc_program_eval(pr, oct_v(x, y, s.f));
      ck_assert_msg(fabs(fz - 0.5) < 1e-9, "f at z = h: %.12g at (%g, %g)", fz,
                    x, y);
      ck_assert(oc_program_eval(pr, oct_v(x, y, s.f - 0.01)) > 0.5);
      ck_assert(oc_program_eval(pr, oct_v(x, y, s.f + 0.01)) < 0.5);
      on++;
    } else if (s.a < 0.5) {
      /* off Omega_T nothing is solid: f <= f_W < T at every z */
      for (double z = -200; z <= 400; z += 7.3) {
        double v = oc_program_eval(pr, oct_v(x, y, z));
        ck_assert_msg(v < 0.5,
                      "solid off Omega_T: f = %g at (%g, %g, %g), "
                      "alpha %g",
                      v, x, y, z, s.a);
        /* f_W = 2T clamp(1/2 + 4 (alpha - 1/2), 0, 1) */
        ck_assert(v <= fmax(0.5 + 4 * (s.a - 0.5), 0) + 1e-12);
        if (s.a <= 0.375) ck_assert(v == 0);
      }
      off++;
    }
  }
  ck_assert_int_gt(on, 1000);
  ck_assert_int_gt(off, 300); /* the gap and the corners */
  oc_program_free(pr);
  oc_enode_release(e);
}
END_TEST

START_TEST(gradient_and_lipschitz) {
  oc_enode *e = two_hills();
  oc_program *pr = tree_program(e, NULL);
  oc_aabb b = oc_program_bounds(pr);
  oct_rng r = oct_rng_new(5);
  /* analytic gradients (f_T, f_P and the weight term) against central
  ** differences, away from the kinks of min() */
  int checked = 0;
  for (int k = 0; k < 3000 && checked < 300; k++) {
    oc_vec3 p = oct_in_box(&r, b.lo, b.hi);
    double f = oc_program_eval(pr, p);
    if (f <= 1e-3 || f >= 1 - 1e-3) continue;
    oc_vec3 g, fd = oct_fd_grad(pr, p, 1e-4);
    oc_program_gradient(pr, p, &g);
    /* skip where a central difference straddles a kink of min() */
    oc_vec3 fd2 = oct_fd_grad(pr, p, 5e-5);
    if (oct_len(oct_sub(fd, fd2)) > 1e-4 * (1 + oct_len(fd))) continue;
    ck_assert_msg(oct_len(oct_sub(g, fd)) <= 1e-3 * (1 + oct_len(fd)),
                  "grad (%g %g %g) vs fd (%g %g %g) at (%g %g %g)", g.x, g.y,
                  g.z, fd.x, fd.y, fd.z, p.x, p.y, p.z);
    checked++;
  }
  ck_assert_int_gt(checked, 100);
  double worst = oct_check_lipschitz(pr, b.lo, b.hi, 20000, &r);
  ck_assert(worst <= 1);
  /* local bounds in random boxes hold on random pairs in them */
  for (int k = 0; k < 200; k++) {
    oc_vec3 c = oct_in_box(&r, b.lo, b.hi);
    double s = oct_unif(&r, 1, 150);
    oc_aabb q = {oct_sub(c, oct_v(s, s, s / 4)),
                 oct_add(c, oct_v(s, s, s / 4))};
    double L = oc_program_lipschitz_in(pr, q);
    if (isinf(L)) continue; /* across the open sides */
    for (int m = 0; m < 50; m++) {
      oc_vec3 p1 = oct_in_box(&r, q.lo, q.hi), p2 = oct_in_box(&r, q.lo, q.hi);
      double d = fabs(oc_program_eval(pr, p1) - oc_program_eval(pr, p2));
      ck_assert_msg(d <= L * oct_len(oct_sub(p1, p2)) * (1 + 1e-9) + 1e-12,
                    "box bound %g broken: %g over %g", L, d,
                    oct_len(oct_sub(p1, p2)));
    }
  }
  oc_program_free(pr);
  oc_enode_release(e);
}
END_TEST

/* ---- meshes ------------------------------------------------------------- */

static oc_mesh *mesh(const oc_program *pr, double cell, int no_direct) {
  oc_polygonize_params pp;
  memset(&pp, 0, sizeof pp);
  oc_error err;
  ck_assert_int_eq(oc_polygonize_default_box(pr, &pp.box, &err), OC_OK);
  pp.cell = cell;
  pp.no_direct = no_direct;
  oc_mesh *m = oc_polygonize(pr, &pp, &err);
  ck_assert_msg(m != NULL, "%s", err.msg);
  return m;
}

START_TEST(polygonize_direct) {
  oc_enode *e = two_hills();
  oc_program *pr = tree_program(e, NULL);
  oc_mesh *m = mesh(pr, 8, 0), *ref = mesh(pr, 8, 1);
  oc_mesh_stats sd, sr;
  oc_mesh_get_stats(m, &sd);
  oc_mesh_get_stats(ref, &sr);
  /* direct extraction: most of the surface without a field call */
  ck_assert_msg(2 * sd.field_calls < sr.field_calls,
                "direct %zu field calls, root finding %zu", sd.field_calls,
                sr.field_calls);
  const char *dir = oct_tmpdir("eterrain");
  const char *path = oct_in_dir(dir, "tree.ply");
  oc_error err;
  ck_assert_int_eq(oc_mesh_write(m, path, &err), OC_OK);
  char why[256], buf[512];
  mr_mesh *mm = mr_read(path, why, sizeof why);
  ck_assert_msg(mm != NULL, "%s", why);
  mr_report rep;
  mr_check(mm, &rep);
  mr_report_str(&rep, buf, sizeof buf);
  ck_assert_msg(rep.closed && rep.outward && rep.consistent &&
                    rep.nonmanifold_edges == 0 && rep.degenerate_triangles == 0,
                "%s", buf);
  mr_free(mm);
  oct_rm_tree(dir);
  /* top vertices (normal pointing up, inside Omega_T) lie on z = f:
  ** those of direct columns to the float rounding of ~300 m and the
  ** Newton steps' 1e-5 of an edge; the few root-found on the field
  ** (where Newton meets a ridge's crease, next to the walls) to the
  ** root finder's accuracy */
  const float *p = oc_mesh_positions(m), *n = oc_mesh_normals(m);
  size_t nv = oc_mesh_vertex_count(m), top = 0, loose = 0;
  double worst = 0;
  for (size_t v = 0; v < nv; v++) {
    oc_enode_sample s;
    oc_enode_eval(e, p[3 * v], p[3 * v + 1], &s);
    if (n[3 * v + 2] < 0.3 || s.a < 0.55) continue;
    double d = fabs(p[3 * v + 2] - s.f);
    worst = fmax(worst, d);
    loose += d > 2e-4;
    top++;
  }
  ck_assert_uint_gt(top, nv / 3);
  ck_assert_msg(loose * 100 < top, "%zu of %zu top vertices off f", loose, top);
  ck_assert_msg(worst < 8.0 / 200, "top vertex %g from f", worst);
  oc_mesh_free(m);
  oc_mesh_free(ref);
  oc_program_free(pr);
  oc_enode_release(e);
}
END_TEST

/* ---- sampling ----------------------------------------------------------- */

static oc_heightfield *sample(oc_enode *e, const oc_heightfield_grid *g,
                              int holes, double hv) {
  oc_error err;
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(e, NULL, &src, &err), OC_OK);
  oc_heightfield *hf = oc_heightfield_from_elevation(
      &src, g, holes, hv, (oc_progress){NULL, NULL}, &err);
  ck_assert_msg(hf != NULL, "%s", err.msg);
  src.release(src.ud);
  return hf;
}

START_TEST(heightfield_exact_and_deterministic) {
  oc_enode *e = two_hills();
  oc_error err;
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(e, NULL, &src, &err), OC_OK);
  oc_heightfield_grid g;
  ck_assert_int_eq(oc_elevation_grid(&src, 0, 0, 0, NULL, &g, &err), OC_OK);
  /* the default grid: 513 samples along the longer side, covering the
  ** terrain box */
  ck_assert_int_eq(g.nx > g.ny ? g.nx : g.ny, 513);
  ck_assert(g.x0 == src.x0 && g.y0 == src.y0);
  ck_assert(g.x0 + (g.nx - 1) * g.cell >= src.x1 - 1e-9 * g.cell);
  ck_assert(g.y0 + (g.ny - 1) * g.cell >= src.y1 - 1e-9 * g.cell);
  ck_assert(g.y0 + (g.ny - 2) * g.cell < src.y1);
  oc_heightfield_grid c = {0};
  ck_assert_int_eq(oc_elevation_grid(&src, 0, 0, 10, NULL, &c, &err), OC_OK);
  ck_assert_int_eq(c.nx, (int)ceil((src.x1 - src.x0) / 10) + 1);
  ck_assert_int_eq(oc_elevation_grid(&src, 11, 21, 0, NULL, &c, &err), OC_OK);
  ck_assert(c.cell == fmax((src.x1 - src.x0) / 10, (src.y1 - src.y0) / 20));
  src.release(src.ud);

  omp_set_num_threads(1);
  oc_heightfield *h1 = sample(e, &g, 0, 0);
  omp_set_num_threads(2);
  oc_heightfield *h2 = sample(e, &g, 0, 0);
  size_t n = (size_t)g.nx * g.ny;
  ck_assert(memcmp(oc_heightfield_samples(h1), oc_heightfield_samples(h2),
                   n * sizeof(float)) == 0);
  oc_heightfield *hh = sample(e, &g, 1, -1000);
  const float *z = oc_heightfield_samples(h2), *zh = oc_heightfield_samples(hh);
  size_t holes = 0;
  for (int j = 0; j < g.ny; j++)
    for (int i = 0; i < g.nx; i++) {
      oc_enode_sample s;
      oc_enode_eval(e, g.x0 + i * g.cell, g.y0 + j * g.cell, &s);
      size_t q = (size_t)j * g.nx + i;
      ck_assert_msg(z[q] == (float)s.f, "sample (%d, %d): %.9g, f %.9g", i, j,
                    z[q], s.f);
      ck_assert(zh[q] == (s.a >= 0.5 ? (float)s.f : -1000.0f));
      holes += s.a < 0.5;
    }
  ck_assert_uint_gt(holes, n / 10);
  oc_heightfield_release(h1);
  oc_heightfield_release(h2);
  oc_heightfield_release(hh);
  oc_enode_release(e);
}
END_TEST

/* ---- bad input ---------------------------------------------------------- */

static void einval(int rc, const oc_error *err, const char *name) {
  ck_assert_int_eq(rc, OC_EINVAL);
  ck_assert_msg(strstr(err->msg, name) != NULL, "'%s' not named in: %s", name,
                err->msg);
}

START_TEST(bad_input) {
  oc_enode *e = two_hills();
  oc_error err;
  double dom[4] = {0, 0, 0, 10};
  ck_assert(oc_enode_terrain(e, dom, NULL, &err) == NULL);
  einval(err.code, &err, "domain");
  dom[2] = NAN;
  ck_assert(oc_enode_terrain(e, dom, NULL, &err) == NULL);
  einval(err.code, &err, "domain");
  oc_terrain_params tp;
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(e, NULL, &src, &err), OC_OK);
  oc_terrain_defaults_source(&src, &tp);
  ck_assert(tp.falloff == 0.01 * fmax(src.x1 - src.x0, src.y1 - src.y0));
  tp.falloff = -1;
  OCT_EINVAL(oc_enode_terrain(e, NULL, &tp, &err), err, "falloff");
  /* half a weight is refused */
  oc_elevation half = src;
  half.weight_range = NULL;
  oc_terrain_defaults_source(&src, &tp);
  ck_assert(oc_terrain(&half, &tp, &err) == NULL);
  einval(err.code, &err, "weight_range");
  oc_heightfield_grid g;
  einval(oc_elevation_grid(&src, 1, 5, 0, NULL, &g, &err), &err, "size");
  einval(oc_elevation_grid(&src, 0, 0, -2, NULL, &g, &err), &err, "cell");
  einval(oc_elevation_grid(&src, 0, 0, 1e-6, NULL, &g, &err), &err, "cell");
  double far[2] = {1e6, 1e6};
  einval(oc_elevation_grid(&src, 0, 0, 0, far, &g, &err), &err, "origin");
  ck_assert_int_eq(oc_elevation_grid(&src, 4, 4, 1, NULL, &g, &err), OC_OK);
  ck_assert(oc_heightfield_from_elevation(
                &src, &g, 1, NAN, (oc_progress){NULL, NULL}, &err) == NULL);
  einval(err.code, &err, "holes");
  src.release(src.ud);
  oc_enode_release(e);
}
END_TEST

static int stop_now(void *ud, double f) {
  (void)ud, (void)f;
  return 1;
}

START_TEST(sampling_cancels) {
  oc_enode *e = two_hills();
  oc_error err;
  oc_elevation src;
  ck_assert_int_eq(oc_enode_elevation(e, NULL, &src, &err), OC_OK);
  oc_heightfield_grid g = {64, 64, 10, -500, -500};
  ck_assert(oc_heightfield_from_elevation(
                &src, &g, 0, 0, (oc_progress){stop_now, NULL}, &err) == NULL);
  ck_assert_int_eq(err.code, OC_ECANCEL);
  src.release(src.ud);
  oc_enode_release(e);
}
END_TEST

int main(void) {
  Suite *s = suite_create("elevation_terrain");
  TCase *tc = tcase_create("elevation_terrain");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, surface_is_f_on_omega_t);
  tcase_add_test(tc, gradient_and_lipschitz);
  tcase_add_test(tc, polygonize_direct);
  tcase_add_test(tc, heightfield_exact_and_deterministic);
  tcase_add_test(tc, bad_input);
  tcase_add_test(tc, sampling_cancels);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
