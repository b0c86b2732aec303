/*
** kind.h — the seam through which a family of nodes outside lib/field
** (terrain, geology, and every family to come) plugs into construction,
** compilation, evaluation and the local queries (internal). It is the only
** lib/field header a family includes; lib/field names no family.
**
** A family describes each of its kinds with a static, constant table of
** query functions, in the manner of an SQLite virtual-table module: a NULL
** entry means the default documented beside it. Its nodes are "extension"
** nodes: lib/field stores the table and the node's data, compiles them to
** one op of kind OC_K_EXT, and sends every query on that op through the
** table. Hooks are called concurrently from many threads on one compiled
** program: they allocate nothing, keep no per-thread state and take no
** locks; the data is read-only once the node exists.
**
** The core kinds (primitives, blend, union and the operators) stay in
** lib/field's own switch statements, whose hot paths the seam does not
** touch.
*/
#ifndef OC_KIND_H
#define OC_KIND_H

#include <stddef.h>
#include <stdint.h>

#include "outcrop.h"

/* ---- flags ------------------------------------------------------------ */

#define OC_KF_PRIM 1u /* a primitive: counted as one in program stats */
#define OC_KF_HFLIKE                                                           \
  2u /* may govern a column alone as an elevation: its                         \
     ** column hook may answer 1, and its surface hook                         \
     ** describes that elevation */
#define OC_KF_DIRECT                                                           \
  4u /* the mesher extracts its surface directly, with                         \
     ** no field calls (Paris et al. 2019, section 7) */

/* Parameters a node of an extension kind may be given, and that its op
** may hold once compiled. */
#define OC_KIND_NODE_MAXPAR 24
#define OC_KIND_MAXPAR 32

/* ---- compilation ------------------------------------------------------ */

/* What compilation knows of a compiled node. */
typedef struct oc_kinfo {
  oc_aabb box;   /* support: f is exactly 0 outside */
  double lo, hi; /* range of f */
  double lip;    /* global Lipschitz bound (off jumps, see `jump`) */
} oc_kinfo;

typedef struct oc_kcompile {
  /* in */
  const void *data;       /* the node's data */
  const double *node_par; /* the node's parameters (as given at creation) */
  size_t node_npar;       /* their count */
  double T;               /* the threshold compiled for */
  size_t nkids;           /* the node's children, compiled first: */
  const oc_kinfo *kid;    /* what is known of each */
  /* out */
  double par[OC_KIND_MAXPAR]; /* what eval and the queries read as k->par */
  size_t npar;
  oc_kinfo info;
  int jump; /* 1: f jumps across a surface, where the Lipschitz bounds hold
            ** only off the jump (lipschitz_in answers INFINITY near it) */
} oc_kcompile;

/* ---- the context of a query ------------------------------------------- */

/* Given to every query hook: the compiled op's parameters, the node's
** data, and the fields after them, which only lib/field reads (the
** child helpers below use them). */
typedef struct oc_kctx {
  const double *par; /* the op's compiled parameters */
  const void *data;  /* the node's data */
  double T;          /* the program's threshold */
  double lip;        /* the op's global Lipschitz bound */
  const struct oc_program *P_;
  uint32_t op_;
  int depth_;
} oc_kctx;

/* A column footprint [x0, x1] x [y0, y1], and the z-spans a column query
** gathers (opaque: filled through the oc_col_* functions). */
typedef struct oc_foot {
  double x0, y0, x1, y1;
} oc_foot;
typedef struct oc_colq oc_colq;

/* The surface f = T of a heightfield-like kind as an elevation e(x, y),
** for direct extraction. */
typedef struct oc_ksurf {
  double (*height)(void *ud, double x, double y, double grad[2]);
  void (*range)(void *ud, double x0, double y0, double x1, double y1,
                double *lo, double *hi);
  void *ud; /* for height and range */
  /* the field at height z in a column whose surface is at e */
  double (*value)(const oc_kctx *k, double e, double z);
  double up;  /* 1: inside below the surface; -1: above */
  double cap; /* z of a flat cap the surface also has (a terrain's prism
              ** bottom or top), or NAN */
} oc_ksurf;

/* ---- the table -------------------------------------------------------- */

typedef struct oc_kind_def {
  const char *name; /* what oc_node_kind answers */
  unsigned flags;   /* OC_KF_* */
  /* Fills c->par, c->npar, c->info (and c->jump). NULL: no parameters,
  ** support and range unbounded, Lipschitz bound infinite. Returns OC_OK,
  ** or an error code with err. */
  int (*compile)(oc_kcompile *c, oc_error *err);
  /* f(p), and its gradient in *g when g is not NULL. Required. A kind
  ** without an analytic gradient calls oc_kind_fd_gradient. */
  double (*eval)(const oc_kctx *k, oc_vec3 p, oc_vec3 *g);
  /* A Lipschitz bound of f inside box b (which meets the op's support).
  ** NULL: k->lip. */
  double (*lipschitz_in)(const oc_kctx *k, const oc_aabb *b);
  /* 1 when f is 0 all over box b (which meets the support). NULL: 0,
  ** "cannot tell". */
  int (*zero_in)(const oc_kctx *k, const oc_aabb *b);
  /* Adds to q the z-spans where f may vary over the footprint f (which
  ** meets the support; f is constant along a column outside them),
  ** through oc_col_* and
  ** oc_child_spans. Returns 1 when the op is heightfield-like over all of
  ** the footprint (OC_KF_HFLIKE kinds only), else 0. NULL: the z-range of
  ** the support box (the whole column when it is unbounded). */
  int (*column)(const oc_kctx *k, const oc_foot *f, oc_colq *q);
  /* Fills s for threshold T; 0 when the op has no such surface at T.
  ** Required with OC_KF_HFLIKE. */
  int (*surface)(const oc_kctx *k, double T, oc_ksurf *s);
  /* Frees the node's data. NULL: the data is not owned. */
  void (*release)(void *data);
} oc_kind_def;

/* ---- construction ----------------------------------------------------- */

/* A new node of kind def (refs = 1) over kids (retained; none NULL), with
** a copy of npar (at most OC_KIND_NODE_MAXPAR doubles; npar may be NULL with
** nnpar 0) and data, which the node owns from here on, also on failure
** (def->release frees it then). */
oc_node *oc_kind_node(const oc_kind_def *def, oc_node *const *kids,
                      size_t nkids, const double *npar, size_t nnpar,
                      void *data, oc_error *err);
/* The table and the data of a node; NULL for a core kind. */
const oc_kind_def *oc_node_def(const oc_node *n);
const void *oc_node_data(const oc_node *n);

/* Parameter checks shared by constructors; they fill err and return 0 on
** failure. `what` is the parameter name as Lua spells it. */
int oc_check_positive(double v, const char *what, oc_error *err);
int oc_check_finite(double v, const char *what, oc_error *err);
int oc_check_vec(oc_vec3 v, const char *what, oc_error *err);
int oc_check_noise(const oc_noise *n, oc_error *err);

/* ---- children (operator-like kinds) ----------------------------------- */

/* Child i of the op: its value (and gradient when g), its local
** Lipschitz bound in b, whether it is 0 all over b, its support box
** (a float box, widened to double), and its column spans over f, added
** to q (as a child of an operator: never heightfield-like for q). */
double oc_child_eval(const oc_kctx *k, size_t i, oc_vec3 p, oc_vec3 *g);
double oc_child_lipschitz_in(const oc_kctx *k, size_t i, const oc_aabb *b);
int oc_child_zero_in(const oc_kctx *k, size_t i, const oc_aabb *b);
oc_aabb oc_child_box(const oc_kctx *k, size_t i);
void oc_child_spans(const oc_kctx *k, size_t i, const oc_foot *f, oc_colq *q);

/* The gradient of the op by central differences of step h (for kinds
** without an analytic one): k's eval is called with g = NULL. Returns
** f(p), the gradient in *g. */
double oc_kind_fd_gradient(const oc_kctx *k, oc_vec3 p, double h, oc_vec3 *g);

/* ---- column spans ----------------------------------------------------- */

/* f may vary in [lo, hi] over the footprint, along columns too. */
void oc_col_add(void *q, double lo, double hi);
/* f may vary in [lo, hi] across the footprint, but along each column only
** within the spans given by oc_col_add_z (a terrain's walls). */
void oc_col_add_xy(void *q, double lo, double hi);
void oc_col_add_z(void *q, double lo, double hi);
/* 1 when the query wants the oc_col_add_z spans (else they are ignored
** and need not be computed). */
int oc_col_wants_z(const oc_colq *q);
/* f may vary along the whole column. */
void oc_col_whole(oc_colq *q);

/* ---- programs --------------------------------------------------------- */

/* Iterates over the data of the ops of kind def in P: start with *it = 0;
** NULL at the end. */
const void *oc_program_kind_data(const struct oc_program *P,
                                 const oc_kind_def *def, size_t *it);

#endif
