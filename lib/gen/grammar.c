/*
** grammar.c — derivation of one hoodoo by the open parameterized grammar
** of Paris et al. 2019, figure 20:
**   A(p, s) -> B(p, s)
**   B(p, s) -> b(p, s) B(p + s z, l s)  | b(p, s) C(p + s z, l s)
**   C(p, s) -> c(p, s) B(p + s z, l s)  | c(p, s) | d(p, s)
** "Open": the production chosen and the terminal's width depend on the
** resistance rho read at the symbol's own position, so the shape follows
** the rock as it grows.
*/
#include <math.h>
#include <string.h>

#include "gen/hoodoos.h"

#define PI 3.14159265358979323846

static double clamp01(double v) {
  return v < 0 ? 0 : v > 1 ? 1 : v;
}

static double resistance(const oc_hoodoo_grammar *g, oc_vec3 p) {
  if (g->geology == NULL) return 0.5;
  double r = oc_program_eval(g->geology, p);
  return r == r ? clamp01(r) : 0.5; /* NaN: neutral rock */
}

/* The words are b+ (c b+)* (c | d), of at most max_depth letters: a
** production leading to B needs two more letters (b, then a terminal),
** so near the end of the budget the derivation is steered to C and to
** its terminal productions, renormalized. */
int oc_hoodoo_derive(const oc_hoodoo_grammar *g, oc_vec3 base, double size,
                     uint32_t hoodoo, oc_rng *rng, oc_hoodoo_symbol *out) {
  char nt = 'B'; /* A -> B */
  int k = 0, D = g->max_depth;
  double width = g->width;
  while (nt != 0 && k < D) {
    oc_vec3 mid = {base.x, base.y, base.z + 0.5 * size};
    double rho = resistance(g, mid);
    double u = oc_rng_uniform(rng);
    int room = k + 3 <= D; /* a B may follow this symbol */
    char t, next;
    if (nt == 'B') {
      double pb = clamp01(g->p_block * (0.5 + rho));
      t = 'b';
      next = room && u < pb ? 'B' : 'C';
    } else {
      double pc = clamp01(g->p_cone * (1.5 - rho));
      double w_cb = room ? 0.5 * pc : 0, w_c = 0.5 * pc, w_d = 1 - pc;
      double sum = w_cb + w_c + w_d;
      u *= sum;
      if (sum <= 0 || u >= w_cb + w_c) {
        t = 'd';
        next = 0;
      } else {
        t = 'c';
        next = u < w_cb ? 'B' : 0;
      }
    }
    oc_hoodoo_symbol *s = &out[k];
    memset(s, 0, sizeof *s); /* padding too: results compare bytewise */
    s->kind = t;
    s->hoodoo = hoodoo;
    s->depth = k;
    s->base = base;
    s->size = size;
    s->width = width * (0.5 + rho);
    s->rho = rho;
    s->turn = oc_rng_range(rng, 0, 2 * PI);
    s->tilt = g->tilt * oc_rng_uniform(rng);
    s->tilt_dir = oc_rng_range(rng, 0, 2 * PI);
    s->aspect = exp(oc_rng_range(rng, -log(1.3), log(1.3)));
    s->noise = oc_rng_next(rng);
    k++;
    nt = next;
    base.z += size;
    size *= g->shrink;
    width *= g->shrink;
  }
  return k;
}
