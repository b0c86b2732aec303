/*
** node.h — the immutable, reference-counted nodes of a construction tree
** (internal). Nodes only hold validated parameters; everything that depends
** on the threshold T or on the whole tree (bounds, value ranges, Lipschitz
** bounds, acceleration structures) is computed by compile.c.
*/
#ifndef OC_NODE_H
#define OC_NODE_H

#include "field/kind.h"

/* The core kinds, in one list: enum constant, name (what oc_node_kind
** answers) and flags. Every other kind is an extension (kind.h). */
#define OC_KF_DIST 8u /* E g(d / R), d the distance to a skeleton or solid */
#define OC_CORE_KINDS(X)                                                       \
  /* primitives */                                                             \
  X(POINT, "point", OC_KF_PRIM | OC_KF_DIST)                                   \
  X(SPHERE, "sphere", OC_KF_PRIM | OC_KF_DIST)                                 \
  X(BOX, "box", OC_KF_PRIM | OC_KF_DIST)                                       \
  X(SEGMENT, "segment", OC_KF_PRIM | OC_KF_DIST)                               \
  X(CURVE, "curve", OC_KF_PRIM | OC_KF_DIST)                                   \
  X(CONE, "cone", OC_KF_PRIM | OC_KF_DIST)                                     \
  X(PLANE, "plane", OC_KF_PRIM | OC_KF_DIST | OC_KF_HFLIKE)                    \
  X(TURB, "turbulence", OC_KF_PRIM) /* offset + A t(p / wavelength) */         \
  /* operators */                                                              \
  X(BLEND, "blend", 0)                                                         \
  X(UNION, "union", 0)                                                         \
  X(INTER, "intersection", 0)                                                  \
  X(DIFF, "difference", 0)                                                     \
  X(SUNION, "smooth_union", 0)                                                 \
  X(SINTER, "smooth_intersection", 0)                                          \
  X(SCALE, "scale", 0)                                                         \
  X(WARP, "warp", 0)                                                           \
  X(XFORM, "transform", 0)                                                     \
  X(PERTURB, "perturb", 0)                                                     \
  /* every kind of kind.h: the node's table answers */                         \
  X(EXT, "extension", 0)

typedef enum oc_kind {
#define OC_KIND_ENUM(id, name, flags) OC_K_##id,
  OC_CORE_KINDS(OC_KIND_ENUM)
#undef OC_KIND_ENUM
      OC_K_COUNT
} oc_kind;

/* OC_KF_* flags of a core kind (kind.h, and OC_KF_DIST above). */
unsigned oc_kind_flags(oc_kind kind);
#define OC_KIND_IS_DIST(k) ((oc_kind_flags(k) & OC_KF_DIST) != 0)

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
  const oc_kind_def *def; /* OC_K_EXT: the kind's table, and its data */
  void *data;             /* (owned: def->release frees it) */
  size_t nnpar;           /* OC_K_EXT: parameters given in par */
};

/* Allocates a node with refs = 1 and room for nkids children (retained
** from kids when not NULL). */
oc_node *oc_node_alloc(oc_kind kind, oc_node *const *kids, size_t nkids,
                       oc_error *err);
const char *oc_kind_name(oc_kind kind);
/* 1 when n counts as a primitive in program stats. */
int oc_node_is_prim(const oc_node *n);

#endif
