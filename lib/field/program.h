/*
** program.h — the compiled, read-only evaluation program (internal).
**
** A program is a flat array of ops; an op refers to its children by index.
** Blend and union ops hold their bounded children as "entries" under a
** bounding volume hierarchy; plain point primitives are stored inline in
** their entry (single precision) so that a blend of many points costs a
** few dozen bytes per point and no indirection.
*/
#ifndef OC_PROGRAM_H
#define OC_PROGRAM_H

#include <stdint.h>

#include "field/node.h"

#define OC_NONE UINT32_MAX

/* A child of a blend/union under its BVH. ref == OC_NONE: an inline point
** primitive e * g(|p - c|^2 * ir2); otherwise the op index of the child. */
typedef struct oc_ent {
  float c[3];
  float ir2;
  float e;
  uint32_t ref;
} oc_ent;

/* count == 0: interior node, children at first and first + 1;
** otherwise a leaf over entries [first, first + count). */
typedef struct oc_bvhnode {
  float lo[3], hi[3];
  uint32_t first, count;
} oc_bvhnode;

typedef struct oc_op {
  uint8_t kind;  /* oc_kind */
  uint8_t sub;   /* perturb: the primitive's kind */
  uint8_t nobvh; /* groups: evaluate every entry (brute force) */
  uint32_t par;  /* first parameter in prog->par */
  uint32_t kid;  /* first child in prog->kids */
  uint32_t nkid; /* groups: unbounded children, always evaluated */
  union {
    uint32_t ent; /* groups: first entry */
    uint32_t ext; /* OC_K_EXT: its index in prog->ext */
  };
  uint32_t nent;
  uint32_t bvh;       /* groups: BVH root, or OC_NONE */
  uint32_t ntotal;    /* groups: number of children in all */
  float lo[3], hi[3]; /* support box, rounded outwards */
  double lip;         /* global Lipschitz bound of this op */
} oc_op;

/* An extension op's kind (kind.h) and its node's data. */
typedef struct oc_pext {
  const oc_kind_def *def;
  const void *data;
  /* the context of eval, filled once compilation is over (depth 0): the
  ** hot path hands it over as it is instead of building one a call */
  oc_kctx ev;
} oc_pext;

struct oc_program {
  oc_op *ops;
  uint32_t nops, root;
  double *par;
  size_t npar;
  uint32_t *kids;
  size_t nkids;
  oc_ent *ent;
  size_t nent;
  oc_bvhnode *bvh;
  size_t nbvh;
  oc_pext *ext; /* the extension ops' tables and data (op.ext indexes
                ** it; the data is owned by the retained nodes) */
  size_t next;
  double T;
  oc_aabb bounds;
  double lip;
  /* ops whose field jumps across a surface (an open terrain's sides, the
  ** `jump` of kind.h):
  ** their lip, and so P->lip, hold only off the jump, where
  ** oc_op_lipschitz_in and oc_ray_dbound answer INFINITY instead */
  uint32_t njump;
  oc_program_stats stats;
  oc_node *node; /* retained source */
};

/* BVH construction over n boxes; fills nodes (capacity 2n) and the entry
** order perm (n), and tells the tree's depth in levels (a lone leaf is
** 1; see bvhwalk.h for its bound). Returns the node count. Leaves hold
** <= OC_BVH_LEAF. */
#define OC_BVH_LEAF 8
size_t oc_bvh_build(const oc_aabb *boxes, size_t n, oc_bvhnode *nodes,
                    uint32_t *perm, int *levels);

/* The local Lipschitz bound of op `op` inside box b (query.c): what
** oc_program_lipschitz_in answers for the root. */
double oc_op_lipschitz_in(const oc_program *P, uint32_t op, const oc_aabb *b);
/* 1 when op is 0 all over box b, as far as supports tell (query.c). */
int oc_op_zero_in(const oc_program *P, uint32_t op, const oc_aabb *b);
/* The largest distance from its skeleton at which a perturb op is non-zero
** (eval.c). */
double oc_perturb_reach(const oc_op *o, const double *par);

/* f(p) and, in *g, its gradient by central differences of step h, for
** f(a, b, .) (kinds without an analytic gradient). */
double oc_fd_gradient(double (*f)(const void *a, const void *b, oc_vec3 p),
                      const void *a, const void *b, oc_vec3 p, double h,
                      oc_vec3 *g);

/* Float box rounded outwards so that it contains the double box. */
void oc_box_to_float(oc_aabb b, float lo[3], float hi[3]);

#endif
