/*
** bvhwalk.h — the one depth-first walk over a group's BVH (internal),
** shared by evaluation (eval.c), the local queries (query.c, raybound.c)
** and the compiler's blend Lipschitz bound (compile.c).
**
** One walk, OC_BVH_FOREACH, written once: it takes the test "may this
** node's subtree matter to the query?" and runs a leaf visit. Evaluation
** uses the macro itself; the queries use oc_bvh_walk, the same walk with
** the test and the visit as static functions.
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

/* Runs the statements after `full` for each leaf nd, depth first and
** left child first, whose every node on the path from the root passes
** MEETS(node) (a function or function-like macro). A `break` in them ends
** the walk; `full` (an int lvalue) is set to 1 when the stack filled and
** a subtree was left out. A macro so that evaluation's loop is exactly
** the hand-written one: its accumulators stay in registers. */
#define OC_BVH_FOREACH(nodes, root, nd, MEETS, full, ...)                      \
  do {                                                                         \
    uint32_t oc_st_[OC_BVH_STACK];                                             \
    int oc_sp_ = 0;                                                            \
    /* misses cost no stack traffic: the stack only holds nodes that meet */   \
    if (MEETS(&(nodes)[root])) oc_st_[oc_sp_++] = (root);                      \
    while (oc_sp_) {                                                           \
      const oc_bvhnode *nd = &(nodes)[oc_st_[--oc_sp_]];                       \
      if (nd->count) {                                                         \
        __VA_ARGS__                                                            \
        continue;                                                              \
      }                                                                        \
      const oc_bvhnode *oc_l_ = &(nodes)[nd->first];                           \
      int oc_hr_ = MEETS(oc_l_ + 1), oc_hl_ = MEETS(oc_l_);                    \
      if (oc_sp_ + 2 > OC_BVH_STACK) {                                         \
        (full) = 1;                                                            \
        break;                                                                 \
      }                                                                        \
      if (oc_hr_) oc_st_[oc_sp_++] = nd->first + 1;                            \
      if (oc_hl_) oc_st_[oc_sp_++] = nd->first;                                \
    }                                                                          \
  } while (0)

typedef int (*oc_bvh_meets_fn)(const oc_bvhnode *nd, void *q);
typedef int (*oc_bvh_leaf_fn)(const oc_bvhnode *nd, void *q);

/* The same walk for the queries, through two small static functions:
** meets(node, q), and leaf(node, q) which returns nonzero to end the walk.
** Forced inline, the calls through the pointers become direct calls to
** known functions, which the compiler inlines in turn. */
static inline __attribute__((always_inline)) int
oc_bvh_walk(const oc_bvhnode *nodes, uint32_t root, oc_bvh_meets_fn meets,
            oc_bvh_leaf_fn leaf, void *q) {
  int full = 0, stopped = 0;
#define OC_MEETS_Q_(x) meets(x, q)
  OC_BVH_FOREACH(nodes, root, nd, OC_MEETS_Q_, full, {
    if (leaf(nd, q)) {
      stopped = 1;
      break;
    }
  });
#undef OC_MEETS_Q_
  return stopped ? OC_WALK_STOPPED : full ? OC_WALK_FULL : OC_WALK_DONE;
}

#endif
