/*
** node.h — the immutable, reference-counted nodes of a construction tree
** (internal). Nodes only hold validated parameters; everything that depends
** on the threshold T or on the whole tree (bounds, value ranges, Lipschitz
** bounds, acceleration structures) is computed by compile.c.
*/
#ifndef OC_NODE_H
#define OC_NODE_H

#include "outcrop.h"

typedef enum oc_kind {
  /* primitives: f = E g(d / R), d the distance to a skeleton or solid */
  OC_K_POINT,
  OC_K_SPHERE,
  OC_K_BOX,
  OC_K_SEGMENT,
  OC_K_CURVE,
  OC_K_CONE,
  OC_K_PLANE,
  OC_K_TURB,    /* offset + A t(p / wavelength) */
  OC_K_TERRAIN, /* implicitized elevation (terrain.c) */
  /* operators */
  OC_K_BLEND,
  OC_K_UNION,
  OC_K_INTER,
  OC_K_DIFF,
  OC_K_SUNION,
  OC_K_SINTER,
  OC_K_SCALE,
  OC_K_WARP,
  OC_K_XFORM,
  OC_K_PERTURB,
  /* geology and erosion (geology/geology.c, geology/erosion.c) */
  OC_K_STRATA,  /* primitive: offset + A t(p_z / wavelength) / tmax */
  OC_K_CLAMP,   /* clamp(f, lo, hi) */
  OC_K_TAPER,   /* strata compressed along an axis */
  OC_K_FAULT,   /* child translated strictly inside a domain */
  OC_K_EROSION, /* max(f - f_D (1 - rho), min(f, 0)) */
  OC_K_COUNT
} oc_kind;

/* Skeletal/volumetric primitives whose field is E g(d / R). */
#define OC_KIND_IS_DIST(k) ((k) <= OC_K_PLANE)
#define OC_KIND_IS_PRIM(k) ((k) <= OC_K_TERRAIN || (k) == OC_K_STRATA)

/* Parameter slots in oc_node.par, by kind. Every distance primitive has
** E at 0 and R (falloff radius) at 1. */
enum {
  OC_P_E = 0,
  OC_P_R = 1,
  /* point, sphere: centre 2..4, sphere radius 5 */
  OC_P_C = 2,
  OC_P_RAD = 5,
  /* box: lo 2..4, hi 5..7 */
  OC_P_LO = 2,
  OC_P_HI = 5,
  /* segment: a 2..4, b 5..7 ; cone: base 2..4, apex 5..7, base radius 8 */
  OC_P_A = 2,
  OC_P_B = 5,
  OC_P_CONE_R = 8,
  /* plane: origin 2..4, unit normal 5..7 */
  OC_P_O = 2,
  OC_P_N = 5,
  /* smooth operators: radius 0 ; scale: factor 0 */
  OC_P_SRAD = 0,
  OC_P_FACTOR = 0,
  /* transform: forward 3x4 at 0..11, inverse 3x4 at 12..23 */
  OC_P_FWD = 0,
  OC_P_INV = 12,
  OC_NPAR = 24
};

struct oc_node {
  int refs; /* nodes are built from one thread (Lua); not atomic */
  oc_kind kind;
  size_t nkids;
  oc_node **kids; /* retained */
  double par[OC_NPAR];
  oc_noise noise; /* turbulence, warp, perturb */
  oc_vec3 *pts;   /* curve: the polyline (Beziers already flattened) */
  size_t npts;
  oc_node *inl[2]; /* small inline child storage to avoid an allocation */
  struct oc_tdata *terrain; /* terrain: source, prism, mask distances */
};

/* Allocates a node with refs = 1 and room for nkids children (retained
** from kids when not NULL). */
oc_node *oc_node_alloc(oc_kind kind, oc_node *const *kids, size_t nkids,
                       oc_error *err);
const char *oc_kind_name(oc_kind kind);

/* Parameter checks shared by constructors; they fill err and return 0 on
** failure. `what` is the parameter name as Lua spells it. */
int oc_check_positive(double v, const char *what, oc_error *err);
int oc_check_finite(double v, const char *what, oc_error *err);
int oc_check_vec(oc_vec3 v, const char *what, oc_error *err);
int oc_check_noise(const oc_noise *n, oc_error *err);

#endif
