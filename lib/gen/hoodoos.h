/*
** hoodoos.h — the open parameterized grammar of the hoodoo generator
** (Paris et al. 2019, figure 20), shared by gen/grammar.c, gen/hoodoos.c and
** the
** tests.
*/
#ifndef OC_GEN_HOODOOS_H
#define OC_GEN_HOODOOS_H

#include "core/rng.h"
#include "outcrop.h"

typedef struct oc_hoodoo_grammar {
  int max_depth;             /* 2 .. OC_HOODOO_MAX_DEPTH */
  double p_block, p_cone;    /* base production probabilities */
  double shrink;             /* lambda: size ratio of successive symbols */
  double width;              /* half-width of the base symbol */
  double tilt;               /* largest tilt, radians */
  const oc_program *geology; /* rho, clamped to [0, 1]; NULL: 0.5 */
} oc_hoodoo_grammar;

/* Derives one hoodoo from the axiom A(base, size): writes its symbols
** (at most g->max_depth) to out and returns their count. All draws come
** from rng, so the result is a function of its state. Thread-safe. */
int oc_hoodoo_derive(const oc_hoodoo_grammar *g, oc_vec3 base, double size,
                     uint32_t hoodoo, oc_rng *rng, oc_hoodoo_symbol *out);

#endif
