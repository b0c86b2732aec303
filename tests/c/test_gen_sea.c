/*
** test_gen_sea.c — sea and river erosion (Paris et al. 2019, section 6.1): the
** effect function against its formula, determinism by seed and thread
** count, carving confined to the sea band and to the riverbed's reach,
** soft rock and later steps biting deeper, counts against the compiled
** tree, and parameter errors.
*/
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "gen/erode.h"
#include "ocheck.h"

#define NX 121
#define NY 81

static double smooth(double t) {
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return t * t * (3 - 2 * t);
}

/* A straight coast: sea floor at -12, a cliff around y = 40, plateau 40. */
static oc_heightfield *cliff(void) {
  oc_error err;
  oc_heightfield *hf = oc_heightfield_new(NX, NY, 1, 0, 0, NULL, &err);
  ck_assert_ptr_nonnull(hf);
  float *z = oc_heightfield_samples_mut(hf);
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++)
      z[j * NX + i] = (float)(-12 + 52 * smooth((j - 37) / 6.0));
  return hf;
}

static oc_gen_sea_params sea_params(oc_heightfield *hf, uint64_t seed) {
  oc_gen_sea_params p;
  oc_gen_sea_defaults(&p);
  p.erode.heightfield = hf;
  p.erode.seed = seed;
  p.range = 4;
  p.erode.radius = 3;
  p.erode.spacing = 1.5;
  p.erode.steps = 2;
  p.erode.strength = 4;
  return p;
}

static oc_program *sea_prog(const oc_gen_sea_params *p, oc_gen_sea_stats *st) {
  oc_error err;
  oc_node *n = oc_generate_sea(p, st, &err);
  if (!n) ck_abort_msg("oc_generate_sea: %s", err.msg);
  return oct_compile(n, 0, 0);
}

static oc_program *terrain_prog(oc_heightfield *hf) {
  oc_error err;
  return oct_compile(OCT_OK(oc_erode_base(hf, NULL, &err)), 0, 0);
}

/* Points inside the original rock (f > T) that the erosion opened. */
static int carved(const oc_program *t, const oc_program *e, double x0,
                  double x1, double z0, double z1) {
  int n = 0;
  for (double x = x0; x < x1; x += 0.5)
    for (double y = 20; y < 60; y += 0.5)
      for (double z = z0; z <= z1; z += 0.5) {
        oc_vec3 p = {x, y, z};
        n += oc_program_eval(t, p) > 0.5 && oc_program_eval(e, p) <= 0.5;
      }
  return n;
}

START_TEST(effect_formula) {
  for (double r = 0; r <= 1; r += 0.125)
    for (double s = 0; s <= 1; s += 0.125)
      for (double b = 0; b <= 1; b += 0.25) {
        double e = oc_erode_effect(r, s, b);
        ck_assert_double_eq_tol(e, s * ((1 - r) * (1 - b) + b), 1e-15);
        ck_assert(e >= 0 && e <= s + 1e-15);
      }
  ck_assert(oc_erode_effect(0.3, 0, 0.4) == 0);   /* no stress, no erosion */
  ck_assert(oc_erode_effect(1, 1, 0.35) == 0.35); /* e(1, 1) = beta */
  ck_assert(oc_erode_effect(0, 1, 0.35) == 1);
  ck_assert(oc_erode_falloff(0) == 1 && oc_erode_falloff(1) == 0);
  ck_assert_double_eq_tol(oc_erode_falloff(0.5), 0.421875, 1e-15);
}
END_TEST

START_TEST(sea_deterministic) {
  oc_heightfield *hf = cliff();
  oc_gen_sea_params p = sea_params(hf, 7);
  oc_gen_sea_stats s1, s2, s3;
  omp_set_num_threads(1);
  oc_program *a = sea_prog(&p, &s1);
  omp_set_num_threads(2);
  oc_program *b = sea_prog(&p, &s2);
  p.erode.seed = 8;
  oc_program *c = sea_prog(&p, &s3);
  ck_assert_uint_eq(s1.primitives, s2.primitives);
  ck_assert_uint_eq(s1.samples, s2.samples);
  ck_assert(s1.primitives > 50);
  oct_rng r = oct_rng_new(3);
  int differ = 0;
  for (int i = 0; i < 20000; i++) {
    oc_vec3 q = oct_in_box(&r, oct_v(0, 25, -6), oct_v(120, 55, 6));
    double fa = oc_program_eval(a, q);
    ck_assert(fa == oc_program_eval(b, q)); /* byte-identical */
    differ += fa != oc_program_eval(c, q);
  }
  ck_assert(differ > 100); /* another seed, other primitives */
  oc_program_free(a);
  oc_program_free(b);
  oc_program_free(c);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(sea_carves_near_sea_level_only) {
  oc_heightfield *hf = cliff();
  for (int k = 0; k < 2; k++) {
    oc_gen_sea_params p = sea_params(hf, 11);
    p.sea_level = k ? 6 : 0;
    oc_gen_sea_stats st;
    oc_program *e = sea_prog(&p, &st), *t = terrain_prog(hf);
    double band = p.range + p.erode.radius;
    oct_rng r = oct_rng_new(5);
    int near = 0, removed = 0;
    for (int i = 0; i < 40000; i++) {
      oc_vec3 q = oct_in_box(&r, oct_v(0, 0, -14), oct_v(120, 80, 42));
      double fe = oc_program_eval(e, q), ft = oc_program_eval(t, q);
      ck_assert(fe <= ft); /* negative primitives only remove */
      if (fabs(q.z - p.sea_level) > band + 1e-9)
        ck_assert_double_eq_tol(fe, ft, 1e-12);
      else if (ft > 0.5 && fe <= 0.5)
        near++;
      removed += fe < ft;
    }
    ck_assert(near > 20); /* and it does carve in the band */
    ck_assert(removed > near);
    /* counts: the terrain plus one point per primitive */
    oc_program_stats ps;
    oc_program_get_stats(e, &ps);
    ck_assert_uint_eq(ps.primitives, st.primitives + 1);
    ck_assert(st.samples >= st.primitives && st.columns > 0);
    oc_program_free(e);
    oc_program_free(t);
  }
  oc_heightfield_release(hf);
}
END_TEST

/* Soft rock (x < 60) against hard (x >= 60); one step against three. */
START_TEST(sea_soft_rock_and_steps) {
  oc_error err;
  oc_heightfield *hf = cliff();
  oc_node *geo =
      OCT_OK(oc_box(oct_v(60, -1e3, -1e3), oct_v(1e3, 1e3, 1e3), 0.5, 1, &err));
  oc_gen_sea_params p = sea_params(hf, 3);
  p.erode.geology = geo;
  p.erode.steps = 1;
  oc_gen_sea_stats st;
  oc_program *t = terrain_prog(hf), *e1 = sea_prog(&p, &st);
  p.erode.steps = 3;
  oc_program *e3 = sea_prog(&p, &st);
  int soft1 = carved(t, e1, 4, 56, -4, 4),
      hard1 = carved(t, e1, 64, 116, -4, 4);
  int soft3 = carved(t, e3, 4, 56, -4, 4),
      hard3 = carved(t, e3, 64, 116, -4, 4);
  ck_assert_msg(soft1 > 2 * hard1 + 10, "soft %d hard %d", soft1, hard1);
  ck_assert_msg(soft3 > soft1 + soft1 / 2, "3 steps %d, 1 step %d", soft3,
                soft1);
  ck_assert(hard3 >= hard1);
  oc_program_free(t);
  oc_program_free(e1);
  oc_program_free(e3);
  oc_node_release(geo);
  oc_heightfield_release(hf);
}
END_TEST

/* A plane tilted down to -y with a V channel along x = 60. */
static oc_heightfield *valley(void) {
  oc_error err;
  oc_heightfield *hf = oc_heightfield_new(NX, NY, 1, 0, 0, NULL, &err);
  ck_assert_ptr_nonnull(hf);
  float *z = oc_heightfield_samples_mut(hf);
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++)
      z[j * NX + i] = (float)(0.3 * j + 0.1 * fabs(i - 60.0));
  return hf;
}

static int cmpf(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

START_TEST(river_follows_stream_power) {
  oc_error err;
  oc_heightfield *hf = valley();
  oc_heightfield *pw = oc_heightfield_stream_power(hf, NULL, &err);
  ck_assert_ptr_nonnull(pw);
  /* the bed: the 95th percentile of the stream power, as documented */
  float *v = malloc(NX * NY * sizeof *v);
  memcpy(v, oc_heightfield_samples(pw), NX * NY * sizeof *v);
  qsort(v, NX * NY, sizeof *v, cmpf);
  double thr = v[(size_t)(0.95 * (NX * NY - 1))];
  free(v);
  /* the bed cells, for distances to them */
  double *bx = malloc(NX * NY * sizeof *bx), *by = malloc(NX * NY * sizeof *by);
  int nb = 0, channel = 0;
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++)
      if (oc_heightfield_samples(pw)[j * NX + i] >= thr) {
        bx[nb] = i;
        by[nb++] = j;
        channel += i == 60;
      }
  ck_assert(nb > 0 && nb < NX * NY / 10);
  ck_assert(channel > 20); /* the V channel holds high stream power */
  oc_gen_river_params p;
  oc_gen_river_defaults(&p);
  p.erode.heightfield = hf;
  p.erode.seed = 4;
  p.erode.radius = 2;
  oc_gen_sea_stats st, st2;
  omp_set_num_threads(1);
  oc_node *n = oc_generate_river(&p, &st, &err);
  if (!n) ck_abort_msg("%s", err.msg);
  oc_program *e = oct_compile(n, 0, 0), *t = terrain_prog(hf);
  omp_set_num_threads(2);
  oc_program *e2 = oct_compile(OCT_OK(oc_generate_river(&p, &st2, &err)), 0, 0);
  ck_assert_uint_eq(st.primitives, st2.primitives);
  /* columns reach banks cells past the bed (rounded to the nearest
  ** sample), rays go up to steps R + cell further, spheres R around */
  double reach =
      p.banks + 0.75 + p.erode.steps * p.erode.radius + 1 + p.erode.radius;
  oct_rng r = oct_rng_new(9);
  int bed = 0, far = 0;
  for (int i = 0; i < 40000; i++) {
    oc_vec3 q = oct_in_box(&r, oct_v(0, 0, -5), oct_v(120, 80, 35));
    double fe = oc_program_eval(e, q), ft = oc_program_eval(t, q);
    ck_assert(fe == oc_program_eval(e2, q));
    ck_assert(fe <= ft);
    double d2 = INFINITY;
    for (int k = 0; k < nb; k++)
      d2 = fmin(d2,
                (q.x - bx[k]) * (q.x - bx[k]) + (q.y - by[k]) * (q.y - by[k]));
    if (d2 > reach * reach) {
      ck_assert_double_eq_tol(fe, ft, 1e-12);
      far++;
    }
    bed += d2 < 1 && ft > 0.5 && fe <= 0.5;
  }
  ck_assert(far > 10000); /* the test saw the untouched land */
  ck_assert(bed > 20);    /* the bed itself is carved */
  oc_program_stats ps;
  oc_program_get_stats(e, &ps);
  ck_assert_uint_eq(ps.primitives, st.primitives + 1);
  oc_program_free(e);
  oc_program_free(e2);
  oc_program_free(t);
  free(bx);
  free(by);
  oc_heightfield_release(pw);
  oc_heightfield_release(hf);
}
END_TEST

START_TEST(parameter_errors) {
  oc_error err;
  oc_heightfield *hf = cliff();
  oc_gen_sea_params p = sea_params(hf, 1), q;
  oc_gen_sea_stats st;
  q = p;
  q.erode.heightfield = NULL;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "heightfield");
  q = p;
  q.range = 0;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "range");
  q = p;
  q.sea_level = INFINITY; /* NaN is the default, not an error */
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "sea_level");
  q = p;
  q.erode.beta = 1.5;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "beta");
  q = p;
  q.erode.steps = 0;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "steps");
  q = p;
  q.erode.radius = -1;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "radius");
  q = p;
  q.rays = -2;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "rays");
  q = p;
  q.erode.cutoff = NAN;
  OCT_EINVAL(oc_generate_sea(&q, &st, &err), err, "cutoff");
  q = p;
  q.erode.spacing = 1e-6; /* would need billions of columns */
  ck_assert_ptr_null(oc_generate_sea(&q, &st, &err));
  ck_assert_int_eq(err.code, OC_ENOMEM);
  ck_assert_ptr_nonnull(strstr(err.msg, "'spacing'"));

  oc_gen_river_params r, s;
  oc_gen_river_defaults(&r);
  r.erode.heightfield = hf;
  s = r;
  s.erode.heightfield = NULL;
  OCT_EINVAL(oc_generate_river(&s, &st, &err), err, "heightfield");
  s = r;
  s.banks = -1;
  OCT_EINVAL(oc_generate_river(&s, &st, &err), err, "banks");
  s = r;
  s.power = NAN;
  OCT_EINVAL(oc_generate_river(&s, &st, &err), err, "power");
  s = r;
  s.depth = -3;
  OCT_EINVAL(oc_generate_river(&s, &st, &err), err, "depth");
  s = r;
  s.erode.strength = 0;
  s.erode.radius = 1;
  OCT_EINVAL(oc_generate_river(&s, &st, &err), err, "strength");
  oc_heightfield_release(hf);
}
END_TEST

/* no_terrain: the primitives alone, whose sum with the terrain is the
** full result. */
START_TEST(primitives_alone) {
  oc_error err;
  oc_heightfield *hf = cliff();
  oc_gen_sea_params p = sea_params(hf, 21);
  oc_gen_sea_stats s1, s2;
  oc_program *full = sea_prog(&p, &s1), *t = terrain_prog(hf);
  p.erode.no_terrain = 1;
  oc_node *n = oc_generate_sea(&p, &s2, &err);
  ck_assert_ptr_nonnull(n);
  ck_assert_uint_eq(oc_node_child_count(n), s2.primitives);
  ck_assert_uint_eq(s1.primitives, s2.primitives);
  oc_program *alone = oct_compile(n, 0, 0);
  oct_rng r = oct_rng_new(8);
  for (int i = 0; i < 5000; i++) {
    oc_vec3 q = oct_in_box(&r, oct_v(0, 25, -8), oct_v(120, 55, 8));
    double fa = oc_program_eval(alone, q);
    ck_assert(fa <= 0);
    ck_assert_double_eq_tol(fa + oc_program_eval(t, q),
                            oc_program_eval(full, q), 1e-12);
  }
  /* nothing reaches an impossible cutoff: an error, not an empty blend */
  p.erode.cutoff = 2;
  OCT_EINVAL(oc_generate_sea(&p, &s2, &err), err, "cutoff");
  oc_program_free(full);
  oc_program_free(alone);
  oc_program_free(t);
  oc_heightfield_release(hf);
}
END_TEST

/* Cancelling through the progress callback: NULL with OC_ECANCEL. */
static int cancel_at(void *ud, double f) {
  (void)ud;
  return f > 0.3;
}

START_TEST(cancel) {
  oc_error err;
  oc_heightfield *hf = cliff();
  oc_gen_sea_params p = sea_params(hf, 1);
  p.erode.progress = (oc_progress){cancel_at, NULL};
  ck_assert_ptr_null(oc_generate_sea(&p, NULL, &err));
  ck_assert_int_eq(err.code, OC_ECANCEL);
  oc_heightfield_release(hf);
}
END_TEST

int main(void) {
  Suite *s = suite_create("gen_sea");
  TCase *tc = tcase_create("gen_sea");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, effect_formula);
  tcase_add_test(tc, sea_deterministic);
  tcase_add_test(tc, sea_carves_near_sea_level_only);
  tcase_add_test(tc, sea_soft_rock_and_steps);
  tcase_add_test(tc, river_follows_stream_power);
  tcase_add_test(tc, parameter_errors);
  tcase_add_test(tc, primitives_alone);
  tcase_add_test(tc, cancel);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
