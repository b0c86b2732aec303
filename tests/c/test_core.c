/*
** test_core.c — the small containers of lib/core: growable arrays
** (grow.h), the pointer map (pmap.h) and interval sets (spanset.h).
*/
#include <stdint.h>
#include <stdlib.h>

#include "core/grow.h"
#include "core/pmap.h"
#include "core/spanset.h"
#include "ocheck.h"

/* Capacities double from the first one; contents survive; an overflowing
** size is refused with the array left as it was. */
START_TEST(grow_doubles_and_refuses_overflow) {
  int *a = NULL;
  size_t n = 0, cap = 0;
  for (int i = 0; i < 1000; i++) {
    ck_assert(OC_GROW(a, n, cap, 1));
    a[n++] = i;
  }
  ck_assert_uint_eq(cap, 1024); /* 16, 32, ..., 1024 */
  for (int i = 0; i < 1000; i++)
    ck_assert_int_eq(a[i], i);
  ck_assert(OC_GROW(a, n, cap, 24)); /* fits: no growth */
  ck_assert_uint_eq(cap, 1024);
  ck_assert(!OC_GROW(a, n, cap, SIZE_MAX - 10));
  ck_assert_int_eq(oc_grow(&a, &cap, SIZE_MAX / 2, sizeof *a, 16), -1);
  ck_assert_uint_eq(cap, 1024);
  ck_assert_int_eq(a[999], 999);
  size_t c2 = 0;
  double *d = NULL;
  ck_assert_int_eq(oc_grow(&d, &c2, 65, sizeof *d, 64), 0);
  ck_assert_uint_eq(c2, 128);
  free(d);
  free(a);
}
END_TEST

/* Every key keeps its value across the map's growth; absent keys are
** absent. */
START_TEST(pmap_maps_pointers) {
  enum { N = 5000 };
  char *keys = malloc(N);
  ck_assert(keys != NULL);
  oc_pmap m = {0};
  ck_assert(oc_pmap_slot(&m, keys, 0) == NULL); /* empty */
  for (uint32_t i = 0; i < N; i++) {
    uint32_t *s = oc_pmap_slot(&m, keys + i, 1);
    ck_assert(s != NULL);
    *s = 3 * i;
  }
  ck_assert_uint_eq(m.n, N);
  ck_assert(m.cap >= 2 * m.n);
  for (uint32_t i = 0; i < N; i++) {
    uint32_t *s = oc_pmap_slot(&m, keys + i, 0);
    ck_assert(s != NULL);
    ck_assert_uint_eq(*s, 3 * i);
  }
  int other;
  ck_assert(oc_pmap_slot(&m, &other, 0) == NULL);
  /* creating an existing key finds it */
  ck_assert_uint_eq(*oc_pmap_slot(&m, keys + 7, 1), 21);
  ck_assert_uint_eq(m.n, N);
  oc_pmap_free(&m);
  ck_assert(m.cap == 0 && m.n == 0 && m.key == NULL);
  free(keys);
}
END_TEST

/* Adding keeps the set sorted and disjoint; past the capacity and in
** oc_spanset_reduce, the closest neighbours merge first. */
START_TEST(spanset_merges_closest_gaps) {
  oc_zspan s[4];
  int n = 0;
  oc_spanset_add(s, &n, 4, 10, 11);
  oc_spanset_add(s, &n, 4, 0, 1);
  oc_spanset_add(s, &n, 4, 5, 6);
  oc_spanset_add(s, &n, 4, 0.5, 2); /* overlaps [0, 1] */
  oc_spanset_add(s, &n, 4, NAN, 3); /* ignored */
  ck_assert_int_eq(n, 3);
  ck_assert(s[0].lo == 0 && s[0].hi == 2);
  ck_assert(s[1].lo == 5 && s[1].hi == 6);
  ck_assert(s[2].lo == 10 && s[2].hi == 11);
  oc_spanset_add(s, &n, 4, 20, 21);
  oc_spanset_add(s, &n, 4, 30, 31); /* full: gaps 3, 4, 9, 9 -> [0, 6] */
  ck_assert_int_eq(n, 4);
  ck_assert(s[0].lo == 0 && s[0].hi == 6);
  ck_assert(s[3].lo == 30 && s[3].hi == 31);
  oc_spanset_reduce(s, &n, 2); /* gaps 4, 9, 9: the leftmost 9 on a tie */
  ck_assert_int_eq(n, 2);
  ck_assert(s[0].lo == 0 && s[0].hi == 21);
  ck_assert(s[1].lo == 30 && s[1].hi == 31);
  oc_zspan one[1];
  int m = 0;
  oc_spanset_add(one, &m, 1, 0, 1);
  oc_spanset_add(one, &m, 1, 5, 6); /* capacity 1: the hull */
  ck_assert_int_eq(m, 1);
  ck_assert(one[0].lo == 0 && one[0].hi == 6);
}
END_TEST

int main(void) {
  Suite *s = suite_create("core");
  TCase *tc = tcase_create("core");
  tcase_add_test(tc, grow_doubles_and_refuses_overflow);
  tcase_add_test(tc, pmap_maps_pointers);
  tcase_add_test(tc, spanset_merges_closest_gaps);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
