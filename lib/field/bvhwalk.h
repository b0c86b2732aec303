/*
** bvhwalk.h — the one depth-first walk over a group's BVH (internal),
** shared by evaluation (eval.c), the local queries (query.c, raybound.c)
** and the compiler's blend Lipschitz bound (compile.c).
**
** The walk is a static inline function taking two small static
** functions: `meets` (may this node's subtree matter to the query?) and
** `leaf` (visit one leaf's entries). Forced inline, the calls through
** the two pointers become direct calls to known functions, which the
** compiler inlines in turn: evaluation's hot loop is the hand-written one.
*/
#ifndef OC_BVHWALK_H
#define OC_BVHWALK_H

#include "field/program.h"

/* Depth of the fixed stack of a walk.
**
** A child is tested before it is pushed, so when a node at depth d (the
** root at 0) is expanded the stack holds at most one pending right
** sibling per depth 1..d, and then its two children: d + 2 slots. An
** interior node is at most at depth levels - 2, so a tree of at most
** OC_BVH_STACK levels never fills the stack.
**
** bvh.c's median split puts half the leaves (rounded down to a whole
** leaf) on each side, so a tree over n entries has
** ceil(log2(ceil(n / OC_BVH_LEAF))) + 1 levels: at most 30 for the 2^32
** entries a uint32_t index allows. compile.c measures every tree it
** builds and refuses one deeper than OC_BVH_STACK (it cannot happen), so
** evaluation, which has no bound to fall back to, never meets a full
** stack; the queries still fall back to their global bound if it does
** (tests/c/test_query.c builds such a tree by hand). */
#define OC_BVH_STACK 64

/* What oc_bvh_walk returns. */
#define OC_WALK_DONE 0    /* every leaf that meets the query was visited */
#define OC_WALK_STOPPED 1 /* a leaf visit asked to stop */
#define OC_WALK_FULL                                                           \
  2 /* the stack filled: a subtree was left out, the                           \
    ** caller answers its conservative bound */

typedef int (*oc_bvh_meets_fn)(const oc_bvhnode *nd, void *q);
typedef int (*oc_bvh_leaf_fn)(const oc_bvhnode *nd, void *q);

/* Visits, depth first and left child first, the leaves of the tree at
** nodes[root] whose every node on the path from the root passes
** meets(node, q); leaf(node, q) returns nonzero to end the walk. */
static inline __attribute__((always_inline)) int
oc_bvh_walk(const oc_bvhnode *nodes, uint32_t root, oc_bvh_meets_fn meets,
            oc_bvh_leaf_fn leaf, void *q) {
  uint32_t stack[OC_BVH_STACK];
  int sp = 0;
  /* misses cost no stack traffic: the stack only holds nodes that meet */
  if (meets(&nodes[root], q)) stack[sp++] = root;
  while (sp) {
    const oc_bvhnode *nd = &nodes[stack[--sp]];
    if (nd->count) {
      if (leaf(nd, q)) return OC_WALK_STOPPED;
      continue;
    }
    const oc_bvhnode *l = &nodes[nd->first];
    int hr = meets(l + 1, q), hl = meets(l, q);
    if (sp + 2 > OC_BVH_STACK) return OC_WALK_FULL;
    if (hr) stack[sp++] = nd->first + 1;
    if (hl) stack[sp++] = nd->first;
  }
  return OC_WALK_DONE;
}

#endif
