/*
** geology.h — the node kinds of resistance trees and the erosion node
** (internal): strata, clamp, taper, fault (geology.c) and erosion
** (erosion.c). docs/fields.md, "Geology", has the formulas.
**
** compile.c, eval.c and query.c hand these kinds to the functions below;
** the functions reach the children through callbacks, so the evaluator's
** and the queries' recursion stay where they are.
*/
#ifndef OC_GEOLOGY_H
#define OC_GEOLOGY_H

#include "field/node.h"
#include "field/program.h"

#define OC_KIND_IS_GEO(k)                                                      \
  ((k) == OC_K_STRATA || (k) == OC_K_CLAMP || (k) == OC_K_TAPER ||             \
   (k) == OC_K_FAULT || (k) == OC_K_EROSION)

/* Strata sample the 3D turbulence on the vertical line (X, Y, z / wl),
** away from the lattice's axes, where simplex noise is more regular. */
#define OC_STRATA_X 0.318309886
#define OC_STRATA_Y 0.587785252

/* Parameter slots, in the node and (same order) in the compiled op. */
enum {
  /* strata: the noise, packed as 6 doubles */
  OC_GP_NOISE = 0,
  /* clamp */
  OC_GP_LO = 0,
  OC_GP_HI = 1,
  /* taper: origin, unit axis, unit `along`, from, to, factor, height */
  OC_GP_TO = 0,
  OC_GP_TA = 3,
  OC_GP_TB = 6,
  OC_GP_U0 = 9,
  OC_GP_U1 = 10,
  OC_GP_K = 11,
  OC_GP_H = 12,
  /* fault: offset, domain kind, then box lo and hi or half-space origin
  ** and unit normal */
  OC_GP_OFF = 0,
  OC_GP_DOM = 3,
  OC_GP_DA = 4,
  OC_GP_DB = 7,
  /* erosion: depth, and 1 when a control node is given */
  OC_GP_DEPTH = 0,
  OC_GP_HASCTL = 1,
  OC_GP_COUNT = 13
};

/* What compile.c knows of a compiled child. */
typedef struct oc_geo_info {
  oc_aabb box;   /* support */
  double lo, hi; /* value range */
  double lip;    /* Lipschitz bound */
} oc_geo_info;

/* Fills par (OC_GP_COUNT doubles at most) and *out for node n, whose
** children compiled to kids[0 .. n->nkids - 1]; returns the number of
** parameters. */
size_t oc_geo_compile(const oc_node *n, double T, const oc_geo_info *kids,
                      double *par, oc_geo_info *out);
size_t oc_erosion_compile(const oc_node *n, const oc_geo_info *kids,
                          double *par, oc_geo_info *out);

/* Evaluates child `op` at p, with the gradient when g is not NULL. */
typedef double (*oc_geo_kid_fn)(const oc_program *P, uint32_t op, oc_vec3 p,
                                oc_vec3 *g);

/* Value of a geology op (and gradient when g is not NULL). */
double oc_geo_eval(const oc_program *P, const oc_op *o, oc_vec3 p, oc_vec3 *g,
                   oc_geo_kid_fn kid);
double oc_erosion_eval(const oc_program *P, const oc_op *o, oc_vec3 p,
                       oc_vec3 *g, oc_geo_kid_fn kid);

/* Column spans of a geology op over the footprint: returns -1 when the
** whole column varies; otherwise 1 with a z-range [*zlo, *zhi] the op adds
** to the spans of its first child (which the caller adds), or 0 when it
** adds nothing. */
int oc_geo_column(const oc_program *P, const oc_op *o, double x0, double y0,
                  double x1, double y1, double *zlo, double *zhi);

/* Local Lipschitz bound in box b; `lip` gives a child's bound in a box. */
typedef double (*oc_geo_lip_fn)(const oc_program *P, uint32_t op,
                                const oc_aabb *b, void *ud);
double oc_geo_lipschitz_in(const oc_program *P, const oc_op *o,
                           const oc_aabb *b, oc_geo_lip_fn lip, void *ud);

#endif
