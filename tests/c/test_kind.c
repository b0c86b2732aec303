/*
** test_kind.c — the extension-kind seam (lib/field/kind.h), from the side
** of a family: two kinds written here, outside lib/field, as a new family
** would write them. A "bump" primitive (data owned by the node, no
** analytic gradient, every optional hook left NULL) and a "twice"
** operator (f = 2 f_child, reaching its child only through oc_child_*).
** Checked: names, stats, values, finite-difference gradients, compiled
** bounds, the documented defaults of the NULL hooks, the child helpers,
** the walk over a program's data and the release of the data.
*/
#include <stdlib.h>
#include <string.h>

#include "field/kind.h"
#include "ocheck.h"

/* ---- a primitive: E (1 - |p - c|^2 / R^2) inside the ball ---------------- */

typedef struct bump {
  oc_vec3 c;
  double R, E;
} bump;

static int released; /* test-local count of releases */

static void bump_release(void *data) {
  released++;
  free(data);
}

static int bump_compile(oc_kcompile *c, oc_error *err) {
  const bump *b = c->data;
  (void)err;
  c->info.box.lo = oct_sub(b->c, oct_v(b->R, b->R, b->R));
  c->info.box.hi = oct_add(b->c, oct_v(b->R, b->R, b->R));
  c->info.lo = 0;
  c->info.hi = b->E;
  c->info.lip = 2 * b->E / b->R;
  c->par[0] = c->T; /* a T-dependent parameter, as a terrain's sigma */
  c->npar = 1;
  return OC_OK;
}

static double bump_value(const bump *b, oc_vec3 p) {
  oc_vec3 d = oct_sub(p, b->c);
  double q = oct_dot(d, d) / (b->R * b->R);
  return q < 1 ? b->E * (1 - q) : 0;
}

static double bump_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  if (g) return oc_kind_fd_gradient(k, p, 1e-5, g);
  return bump_value(k->data, p);
}

static const oc_kind_def bump_kind = {
    .name = "bump",
    .flags = OC_KF_PRIM,
    .compile = bump_compile,
    .eval = bump_eval,
    .release = bump_release,
};

static oc_node *new_bump(oc_vec3 c, double R, double E) {
  bump *b = malloc(sizeof *b);
  ck_assert_ptr_nonnull(b);
  *b = (bump){c, R, E};
  oc_error err;
  return OCT_OK(oc_kind_node(&bump_kind, NULL, 0, NULL, 0, b, &err));
}

/* ---- an operator: 2 f_child ---------------------------------------------- */

static int twice_compile(oc_kcompile *c, oc_error *err) {
  (void)err;
  c->info = c->kid[0];
  c->info.lo *= 2;
  c->info.hi *= 2;
  c->info.lip *= 2;
  return OC_OK;
}
static double twice_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  double v = oc_child_eval(k, 0, p, g);
  if (g) *g = oct_mul(*g, 2);
  return 2 * v;
}
static double twice_lip_in(const oc_kctx *k, const oc_aabb *b) {
  return 2 * oc_child_lipschitz_in(k, 0, b);
}
static int twice_zero_in(const oc_kctx *k, const oc_aabb *b) {
  return oc_child_zero_in(k, 0, b);
}
static int twice_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  oc_child_spans(k, 0, f, q);
  return 0;
}
static const oc_kind_def twice_kind = {
    .name = "twice",
    .compile = twice_compile,
    .eval = twice_eval,
    .lipschitz_in = twice_lip_in,
    .zero_in = twice_zero_in,
    .column = twice_column,
};

/* ---- tests ----------------------------------------------------------- */

START_TEST(primitive_kind) {
  released = 0;
  oc_node *n = new_bump(oct_v(1, 2, 3), 2, 1.5);
  ck_assert_str_eq(oc_node_kind(n), "bump");
  oc_program *P = oct_compile(n, 0.4, 0);
  oc_program_stats st;
  oc_program_get_stats(P, &st);
  ck_assert_uint_eq(st.nodes, 1);
  ck_assert_uint_eq(st.primitives, 1);
  oc_aabb b = oc_program_bounds(P);
  ck_assert(b.lo.x == -1 && b.hi.z == 5);
  ck_assert(oc_program_lipschitz(P) == 1.5);
  /* values, and the finite-difference gradient against the formula
  ** grad = -2 E (p - c) / R^2 */
  oct_rng r = oct_rng_new(7);
  for (int i = 0; i < 200; i++) {
    oc_vec3 p = oct_in_box(&r, oct_v(-0.5, 0.5, 1.5), oct_v(2.5, 3.5, 4.5));
    oc_vec3 d = oct_sub(p, oct_v(1, 2, 3)), g;
    double q = oct_dot(d, d) / 4;
    double want = q < 1 ? 1.5 * (1 - q) : 0;
    ck_assert_double_eq_tol(oc_program_eval(P, p), want, 1e-15);
    double v = oc_program_gradient(P, p, &g);
    ck_assert_double_eq_tol(v, want, 1e-15);
    if (q < 0.95) {
      oc_vec3 w = oct_mul(d, -2 * 1.5 / 4);
      ck_assert_double_le(oct_len(oct_sub(g, w)), 1e-8);
    }
  }
  /* NULL lipschitz_in: the global bound where the box meets the
  ** support, 0 where it does not */
  oc_aabb near = {oct_v(0, 1, 2), oct_v(1, 2, 3)};
  oc_aabb far = {oct_v(10, 10, 10), oct_v(11, 11, 11)};
  ck_assert(oc_program_lipschitz_in(P, near) == 1.5);
  ck_assert(oc_program_lipschitz_in(P, far) == 0);
  /* NULL column: the support box's z-range over a footprint meeting it */
  oc_zspan s[4];
  int ns = oc_program_column_spans(P, 0.5, 1.5, 0.7, 1.7, s, 4);
  ck_assert_int_eq(ns, 1);
  ck_assert(s[0].lo <= 1 && s[0].hi >= 5 && s[0].hi < 5.001);
  ck_assert_int_eq(oc_program_column_spans(P, 8, 8, 9, 9, s, 4), 0);
  ck_assert_int_eq(released, 0); /* the program holds the node */
  oc_program_free(P);            /* (oct_compile dropped ours) */
  ck_assert_int_eq(released, 1);
}
END_TEST

START_TEST(operator_kind) {
  released = 0;
  oc_error err;
  oc_node *a = new_bump(oct_v(0, 0, 0), 1, 1);
  oc_node *b = new_bump(oct_v(5, 0, 0), 1, 1);
  oc_node *kids[2] = {a, b};
  oc_node *u = OCT_OK(oc_blend(kids, 2, &err));
  oc_node *t = OCT_OK(oc_kind_node(&twice_kind, &u, 1, NULL, 0, NULL, &err));
  oc_node_release(a);
  oc_node_release(b);
  oc_node_release(u);
  ck_assert_str_eq(oc_node_kind(t), "twice");
  oc_program *P = oct_compile(t, 0, 0);
  oc_program_stats st;
  oc_program_get_stats(P, &st);
  ck_assert_uint_eq(st.primitives, 2);
  ck_assert_uint_eq(st.nodes, 4);
  ck_assert_double_eq_tol(oc_program_eval(P, oct_v(0.5, 0, 0)), 1.5, 1e-15);
  ck_assert_double_eq_tol(oc_program_eval(P, oct_v(5, 0.5, 0)), 1.5, 1e-15);
  oc_vec3 g;
  oc_program_gradient(P, oct_v(0.5, 0, 0), &g);
  ck_assert_double_eq_tol(g.x, -2, 1e-8); /* 2 * (-2 x) */
  /* child helpers: local bound from the bump that the box meets */
  oc_aabb near_a = {oct_v(-0.5, -0.5, -0.5), oct_v(0.5, 0.5, 0.5)};
  oc_aabb between = {oct_v(2, -0.5, -0.5), oct_v(3, 0.5, 0.5)};
  ck_assert(oc_program_lipschitz_in(P, near_a) == 4);
  ck_assert(oc_program_lipschitz_in(P, between) == 0);
  /* column spans through the child: the bump's z-range, none between */
  oc_zspan s[4];
  ck_assert_int_eq(oc_program_column_spans(P, -0.1, -0.1, 0.1, 0.1, s, 4), 1);
  ck_assert(s[0].lo <= -1 && s[0].hi >= 1 && s[0].hi < 1.001);
  ck_assert_int_eq(oc_program_column_spans(P, 2, -0.1, 3, 0.1, s, 4), 0);
  oc_program_free(P); /* and t with it: oct_compile dropped ours */
  ck_assert_int_eq(released, 2);
}
END_TEST

START_TEST(kind_data_walk) {
  released = 0;
  oc_error err;
  oc_node *a = new_bump(oct_v(0, 0, 0), 1, 1);
  oc_node *b = new_bump(oct_v(3, 0, 0), 1, 2);
  oc_node *kids[3] = {a, b, a}; /* a shared: one op */
  oc_node *u = OCT_OK(oc_union(kids, 3, &err));
  oc_program *P = oct_compile(u, 0, 0);
  size_t it = 0, n = 0;
  double esum = 0;
  for (const bump *d; (d = oc_program_kind_data(P, &bump_kind, &it));) {
    n++;
    esum += d->E;
  }
  ck_assert_uint_eq(n, 2);
  ck_assert(esum == 3);
  it = 0;
  ck_assert_ptr_null(oc_program_kind_data(P, &twice_kind, &it));
  oc_program_free(P);
  ck_assert_int_eq(released, 0);
  oc_node_release(a);
  oc_node_release(b);
  ck_assert_int_eq(released, 2);
}
END_TEST

/* The node owns its data from the call on: a refused node frees it. */
START_TEST(refused_node_releases_data) {
  released = 0;
  oc_error err;
  double par[OC_KIND_NODE_MAXPAR + 1] = {0};
  bump *b = malloc(sizeof *b);
  ck_assert_ptr_nonnull(b);
  oc_node *n =
      oc_kind_node(&bump_kind, NULL, 0, par, OC_KIND_NODE_MAXPAR + 1, b, &err);
  ck_assert_ptr_null(n);
  ck_assert_int_eq(err.code, OC_EINVAL);
  ck_assert_ptr_nonnull(strstr(err.msg, "bump"));
  ck_assert_int_eq(released, 1);
}
END_TEST

int main(void) {
  Suite *s = suite_create("kind");
  TCase *tc = tcase_create("kind");
  tcase_add_test(tc, primitive_kind);
  tcase_add_test(tc, operator_kind);
  tcase_add_test(tc, kind_data_walk);
  tcase_add_test(tc, refused_node_releases_data);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
