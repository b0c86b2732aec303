/*
** test_rocks.c — rock piles (Peytavie et al. 2009, section 5): rocks
** inside their Voronoi cells (so no two overlap, also as fields), each
** touching neighbours at contacts, eroded elsewhere; placed only where
** the stacks hold rocks, within the depth below the top; deterministic
** by seed; parameter errors.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "blocks/btile.h"
#include "layers/layers.h"
#include "ocheck.h"

static oc_btile *tile(uint64_t seed) {
  oc_rocks_params rp;
  oc_rocks_defaults(&rp);
  rp.size = 6;
  rp.seed = seed;
  oc_error err;
  oc_btile *t = oc_rocks_tile(&rp, &err);
  ck_assert_msg(t != NULL, "%s", err.msg);
  return t;
}

/* Squared distance from x to the nearest periodic image of site j. */
static double d2(const double *x, const double *p, double s) {
  double m = INFINITY;
  for (int o = 0; o < 27; o++) {
    double q[3] = {p[0] + s * (o % 3 - 1), p[1] + s * (o / 3 % 3 - 1),
                   p[2] + s * (o / 9 - 1)};
    double d[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
    m = fmin(m, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  return m;
}

START_TEST(rocks_in_cells) {
  oc_btile *t = tile(7);
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  ck_assert_uint_eq(st.blocks, t->np);
  ck_assert(st.blocks > 30 && st.blocks < 80);
  double s = t->pp.size, r = t->pp.radius;
  for (size_t i = 0; i < t->nb; i++) {
    const oc_bblock *b = &t->block[i];
    const double *pi = t->pts + 3 * i;
    ck_assert(b->centroid.x == pi[0] && b->centroid.z == pi[2]);
    /* convex: every vertex inside every plane of the hull */
    double out = -INFINITY;
    for (size_t v = 0; v < b->nvert; v++)
      for (size_t k = 0; k < b->nplane; k++) {
        const double *h = b->plane + 4 * k, *x = b->vert + 3 * v;
        out = fmax(out, h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + h[3]);
      }
    ck_assert_msg(out < 1e-9, "rock %zu: a vertex %g outside a plane", i, out);
    size_t touching = 0; /* neighbours some vertex lies on the face with */
    unsigned char *seen = calloc(t->np, 1);
    double reach = 0, nearer = -INFINITY;
    for (size_t v = 0; v < b->nvert; v++) {
      const double *x = b->vert + 3 * v;
      double own = d2(x, pi, s);
      reach = fmax(reach, own);
      for (size_t j = 0; j < t->np; j++) {
        if (j == i) continue;
        double other = d2(x, t->pts + 3 * j, s);
        nearer = fmax(nearer, own - other);
        if (other - own < 1e-6 && !seen[j]) seen[j] = 1, touching++;
      }
    }
    free(seen);
    ck_assert(sqrt(reach) < r); /* within the cell's reach */
    /* in its own cell: no nearer site (so hulls cannot overlap) */
    ck_assert_msg(nearer <= 1e-9,
                  "rock %zu: a vertex nearer another site by %g", i, nearer);
    ck_assert_msg(touching >= 4, "rock %zu touches %zu", i, touching);
    /* eroded: the hull's thickness below the cell's (sites >= r apart, so
    ** every cell holds a ball of radius r / 2 around its site) */
    ck_assert(b->thickness > 0.3 * r && b->thickness < 2 * r);
  }
  /* as fields: no point inside two rocks */
  oc_error err;
  oc_node *u = oc_btile_node(t, &err);
  ck_assert(u != NULL);
  oc_program **pr = calloc(t->nb, sizeof *pr);
  for (size_t i = 0; i < t->nb; i++) {
    oc_node *n = oc_btile_block(t, i, &err);
    pr[i] = oc_compile(n, NULL, &err);
    oc_node_release(n);
  }
  int inside = 0;
  for (int z = 0; z < 12; z++)
    for (int y = 0; y < 12; y++)
      for (int x = 0; x < 12; x++) {
        oc_vec3 p = {0.5 * x + 0.1, 0.5 * y + 0.2, 0.5 * z + 0.3};
        int k = 0;
        for (size_t i = 0; i < t->nb; i++)
          k += oc_program_eval(pr[i], p) > 0.5;
        ck_assert_int_le(k, 1);
        inside += k;
      }
  ck_assert(inside > 12 * 12 * 12 / 4); /* rocks fill much of the tile */
  for (size_t i = 0; i < t->nb; i++)
    oc_program_free(pr[i]);
  free(pr);
  oc_node_release(u);
  oc_btile_free(t);
}
END_TEST

START_TEST(deterministic) {
  oc_btile *a = tile(11), *b = tile(11);
  ck_assert_uint_eq(a->nb, b->nb);
  for (size_t i = 0; i < a->nb; i++) {
    ck_assert_uint_eq(a->block[i].nplane, b->block[i].nplane);
    ck_assert(memcmp(a->block[i].plane, b->block[i].plane,
                     4 * a->block[i].nplane * sizeof(double)) == 0);
  }
  oc_btile_free(a);
  oc_btile_free(b);
}
END_TEST

/* Rocks only where the rocks layer is: on x < 10 a 4 m rocks layer over
** bedrock, elsewhere bedrock alone; instances' sites in that layer and
** within depth of its top. */
START_TEST(placed_in_rock_layer) {
  oc_error err;
  oc_stacks *s = oc_stacks_new(40, 20, 0.5, 0, 0, 0, &err);
  ck_assert(s != NULL);
  for (int j = 0; j < 20; j++)
    for (int i = 0; i < 40; i++) {
      uint8_t m[2] = {OC_MAT_BEDROCK, OC_MAT_ROCKS};
      double th[2] = {2, 4};
      ck_assert(oc_stacks_set(s, i, j, m, th, i < 20 ? 2 : 1, &err) == 0);
    }
  oc_btile *t = tile(3);
  size_t count[2];
  for (int k = 0; k < 2; k++) {
    oc_stacks_rocks_params p = {k ? 1.0 : NAN, 0};
    oc_node *n = oc_stacks_rocks(s, t, NULL, &p, &err);
    ck_assert_msg(n != NULL, "%s", err.msg);
    ck_assert(oc_blocks_instances(n, &count[k]));
    double depth = k ? 1.0 : 2 * oc_rocks_reach(t);
    for (size_t i = 0; i < count[k]; i++) {
      size_t b;
      double off[3];
      ck_assert(oc_blocks_instance(n, i, &b, off));
      oc_vec3 c = t->block[b].centroid;
      double x = c.x + off[0], y = c.y + off[1], z = c.z + off[2];
      ck_assert(x < 9.75 && x >= -0.25 && y >= -0.25 && y < 9.75);
      ck_assert(z >= 2 && z < 6 && 6 - z <= depth);
    }
    size_t b;
    double off[3];
    ck_assert(!oc_blocks_instance(n, count[k], &b, off));
    oc_node_release(n);
  }
  /* 10 x 10 x 4 m of rocks hold ~ 400 / 216 tiles' worth; depth 1 m a
  ** quarter of them */
  ck_assert_msg(count[0] > 40 && count[0] < 150, "%zu %zu", count[0], count[1]);
  ck_assert(count[1] > 5 && count[1] < count[0] / 2);
  oc_btile_free(t);
  oc_stacks_free(s);
}
END_TEST

START_TEST(parameter_errors) {
  oc_error err;
  oc_rocks_params rp;
  oc_rocks_defaults(&rp);
  rp.radius = 0;
  ck_assert(oc_rocks_tile(&rp, &err) == NULL);
  ck_assert(strstr(err.msg, "'radius'"));
  oc_rocks_defaults(&rp);
  rp.size = 5;
  ck_assert(oc_rocks_tile(&rp, &err) == NULL);
  ck_assert(strstr(err.msg, "'size'"));
  oc_rocks_defaults(&rp);
  rp.erosion = 0.5;
  ck_assert(oc_rocks_tile(&rp, &err) == NULL);
  ck_assert(strstr(err.msg, "'erosion'"));
  oc_rocks_defaults(&rp);
  rp.contacts = 0;
  ck_assert(oc_rocks_tile(&rp, &err) == NULL);
  ck_assert(strstr(err.msg, "'contacts'"));
  oc_rocks_defaults(&rp);
  rp.size = 1000;
  ck_assert(oc_rocks_tile(&rp, &err) == NULL);
  ck_assert(strstr(err.msg, "'size' / 'radius'"));
}
END_TEST

int main(void) {
  Suite *s = suite_create("rocks");
  TCase *tc = tcase_create("core");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, rocks_in_cells);
  tcase_add_test(tc, deterministic);
  tcase_add_test(tc, placed_in_rock_layer);
  tcase_add_test(tc, parameter_errors);
  suite_add_tcase(s, tc);
  return oct_run(s);
}
