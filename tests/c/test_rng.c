/*
** test_rng.c — counter-based random streams (lib/core/rng.h): range and
** moments of the uniforms, reproducibility, independence of keyed and split
** streams, avalanche of the mixer.
*/
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

#define NDRAW 1000000

static int popcount64(uint64_t x) {
  int n = 0;
  for (; x; x &= x - 1)
    n++;
  return n;
}

/* Pearson correlation of the first n uniforms of two streams. */
static double stream_corr(oc_rng a, oc_rng b, int n) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < n; i++) {
    double x = oc_rng_uniform(&a), y = oc_rng_uniform(&b);
    sa += x, sb += y, saa += x * x, sbb += y * y, sab += x * y;
  }
  double ma = sa / n, mb = sb / n;
  double cov = sab / n - ma * mb;
  return cov / sqrt((saa / n - ma * ma) * (sbb / n - mb * mb));
}

START_TEST(uniform_range_and_moments) {
  oc_rng r = oc_rng_stream(12345, 67);
  double sum = 0, sum2 = 0, lo = 1, hi = 0;
  int hist[100] = {0}, outside = 0;
  for (int i = 0; i < NDRAW; i++) {
    double u = oc_rng_uniform(&r);
    outside += !(u >= 0.0 && u < 1.0);
    sum += u, sum2 += u * u;
    if (u < lo) lo = u;
    if (u > hi) hi = u;
    if (u >= 0.0 && u < 1.0) hist[(int)(u * 100)]++;
  }
  ck_assert_int_eq(outside, 0);
  double mean = sum / NDRAW, var = sum2 / NDRAW - mean * mean;
  printf("rng: mean %.6f (1/2) variance %.6f (1/12 = %.6f) range [%g, %g]\n",
         mean, var, 1.0 / 12, lo, hi);
  /* Standard errors: 2.9e-4 for the mean, 7.5e-5 for the variance. */
  ck_assert_double_eq_tol(mean, 0.5, 0.0015);
  ck_assert_double_eq_tol(var, 1.0 / 12, 0.0005);
  ck_assert(lo < 1e-4 && hi > 1 - 1e-4);
  /* Chi-square over 100 bins: 99 degrees of freedom, mean 99, sd 14. */
  double chi2 = 0, e = NDRAW / 100.0;
  for (int b = 0; b < 100; b++)
    chi2 += (hist[b] - e) * (hist[b] - e) / e;
  printf("rng: chi2 over 100 bins %.1f\n", chi2);
  ck_assert(chi2 < 170);
}
END_TEST

START_TEST(uniform_has_53_bits) {
  /* Every one of the 53 mantissa bits must vary: a stuck bit would mean a
  ** coarser grid of values than documented. */
  oc_rng r = oc_rng_stream(1, 2);
  uint64_t seen_one = 0, seen_zero = 0;
  for (int i = 0; i < 10000; i++) {
    uint64_t m = (uint64_t)(oc_rng_uniform(&r) * 0x1p53);
    seen_one |= m, seen_zero |= ~m;
  }
  uint64_t mask = (1ull << 53) - 1;
  ck_assert_uint_eq(seen_one & mask, mask);
  ck_assert_uint_eq(seen_zero & mask, mask);
}
END_TEST

START_TEST(next_bits_balanced) {
  oc_rng r = oc_rng_stream(99, 0);
  int ones[64] = {0};
  const int n = 200000;
  for (int i = 0; i < n; i++) {
    uint64_t x = oc_rng_next(&r);
    for (int b = 0; b < 64; b++)
      ones[b] += (int)((x >> b) & 1);
  }
  /* sd of the count is sqrt(n)/2 = 224; 6 sd. */
  for (int b = 0; b < 64; b++)
    ck_assert_int_lt(abs(ones[b] - n / 2), 1350);
}
END_TEST

START_TEST(range_respects_bounds) {
  oc_rng r = oc_rng_stream(5, 5);
  int outside = 0;
  for (int i = 0; i < 100000; i++) {
    double x = oc_rng_range(&r, -3.0, 7.5);
    outside += !(x >= -3.0 && x < 7.5);
  }
  ck_assert_int_eq(outside, 0);
}
END_TEST

START_TEST(same_key_reproduces) {
  oc_rng a = oc_rng_stream(42, 7), b = oc_rng_stream(42, 7);
  int differ = 0;
  for (int i = 0; i < 10000; i++) {
    double x = oc_rng_uniform(&a), y = oc_rng_uniform(&b);
    differ += memcmp(&x, &y, sizeof x) != 0;
  }
  ck_assert_int_eq(differ, 0);
  /* The value is a function of the counter alone, not of the draws done
  ** before: jumping the counter gives the same value. */
  oc_rng c = oc_rng_stream(42, 7);
  c.counter = 9999;
  oc_rng d = oc_rng_stream(42, 7);
  for (int i = 0; i < 9999; i++)
    oc_rng_next(&d);
  ck_assert_uint_eq(oc_rng_next(&c), oc_rng_next(&d));
}
END_TEST

START_TEST(different_keys_differ) {
  /* First outputs of 2000 keyed streams, and of 2000 seeds: all distinct. */
  enum { N = 2000 };
  static uint64_t first[2 * N];
  for (int k = 0; k < N; k++) {
    oc_rng r = oc_rng_stream(3, (uint64_t)k);
    first[k] = oc_rng_next(&r);
    oc_rng s = oc_rng_stream((uint64_t)k + N, 3); /* (3, 3) only once */
    first[N + k] = oc_rng_next(&s);
  }
  int equal = 0;
  for (int i = 0; i < 2 * N; i++)
    for (int j = i + 1; j < 2 * N; j++)
      equal += first[i] == first[j];
  ck_assert_int_eq(equal, 0);
  /* Neighbouring keys and seeds give uncorrelated streams. */
  double c1 = stream_corr(oc_rng_stream(3, 0), oc_rng_stream(3, 1), 100000);
  double c2 = stream_corr(oc_rng_stream(0, 3), oc_rng_stream(1, 3), 100000);
  double c3 = stream_corr(oc_rng_stream(3, 5), oc_rng_stream(5, 3), 100000);
  printf(
      "rng: correlation of neighbouring keys %.4f, seeds %.4f, swapped %.4f\n",
      c1, c2, c3);
  /* sd of a correlation estimate over 1e5 pairs: 0.0032. */
  ck_assert(fabs(c1) < 0.015 && fabs(c2) < 0.015 && fabs(c3) < 0.015);
}
END_TEST

START_TEST(split_streams_differ) {
  oc_rng parent = oc_rng_stream(8, 8);
  oc_rng saved = parent;
  oc_rng c0 = oc_rng_split(&parent, 0), c1 = oc_rng_split(&parent, 1);
  /* Splitting does not disturb the parent. */
  ck_assert_uint_eq(parent.key, saved.key);
  ck_assert_uint_eq(parent.counter, saved.counter);
  /* Children differ from the parent, from each other, and from the plain
  ** stream with the same key. */
  ck_assert(c0.key != parent.key && c1.key != parent.key && c0.key != c1.key);
  oc_rng plain = oc_rng_stream(8, 0);
  ck_assert(c0.key != plain.key);
  oc_rng p = parent, a = c0, b = c1;
  int same_pa = 0, same_ab = 0;
  for (int i = 0; i < 10000; i++) {
    uint64_t x = oc_rng_next(&p), y = oc_rng_next(&a), z = oc_rng_next(&b);
    same_pa += x == y, same_ab += y == z;
  }
  ck_assert_int_eq(same_pa, 0);
  ck_assert_int_eq(same_ab, 0);
  ck_assert(fabs(stream_corr(parent, c0, 100000)) < 0.015);
  ck_assert(fabs(stream_corr(c0, c1, 100000)) < 0.015);
  /* Splitting is deterministic, also after the parent has advanced. */
  oc_rng again = oc_rng_split(&saved, 1);
  ck_assert_uint_eq(again.key, c1.key);
  oc_rng_next(&saved);
  ck_assert_uint_eq(oc_rng_split(&saved, 1).key, c1.key);
}
END_TEST

START_TEST(mix_avalanche) {
  /* Flipping one input bit flips half of the output bits on average: the
  ** property the noise relies on to turn corner coordinates into gradients. */
  oc_rng r = oc_rng_stream(0, 0);
  double total = 0;
  int n = 0;
  for (int b = 0; b < 64; b++) {
    int sum = 0;
    for (int i = 0; i < 2000; i++) {
      uint64_t x = oc_rng_next(&r);
      sum += popcount64(oc_mix64(x) ^ oc_mix64(x ^ (1ull << b)));
    }
    double m = sum / 2000.0;
    total += m, n++;
    /* sd of the mean: 4 / sqrt(2000) = 0.09. */
    ck_assert(fabs(m - 32) < 0.6);
  }
  ck_assert_double_eq_tol(total / n, 32, 0.1);
  /* oc_hash2 is asymmetric: (a, b) and (b, a) differ. */
  ck_assert(oc_hash2(1, 2) != oc_hash2(2, 1));
  ck_assert(oc_hash2(0, 0) != oc_hash2(0, 1));
}
END_TEST

int main(void) {
  /* Line buffering: a failing test's child would lose its report. */
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("rng");
  TCase *tc = tcase_create("streams");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, uniform_range_and_moments);
  tcase_add_test(tc, uniform_has_53_bits);
  tcase_add_test(tc, next_bits_balanced);
  tcase_add_test(tc, range_respects_bounds);
  tcase_add_test(tc, same_key_reproduces);
  tcase_add_test(tc, different_keys_differ);
  tcase_add_test(tc, split_streams_differ);
  tcase_add_test(tc, mix_avalanche);
  suite_add_tcase(s, tc);
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed ? 1 : 0;
}
