/*
** kind.c — the parts of the extension-kind seam (kind.h) that need no
** evaluator or query recursion: finite-difference gradients, children's
** boxes, and the walk over a program's ops of one kind. The node
** constructor is in node.c, the child queries beside the recursion they
** enter (eval.c, query.c).
*/
#include "core/vec.h"
#include "field/kind.h"
#include "field/program.h"

double oc_fd_gradient(double (*f)(const void *a, const void *b, oc_vec3 p),
                      const void *a, const void *b, oc_vec3 p, double h,
                      oc_vec3 *g) {
  double v = f(a, b, p);
  double gx =
      f(a, b, oc_v3(p.x + h, p.y, p.z)) - f(a, b, oc_v3(p.x - h, p.y, p.z));
  double gy =
      f(a, b, oc_v3(p.x, p.y + h, p.z)) - f(a, b, oc_v3(p.x, p.y - h, p.z));
  double gz =
      f(a, b, oc_v3(p.x, p.y, p.z + h)) - f(a, b, oc_v3(p.x, p.y, p.z - h));
  *g = oc_mul(oc_v3(gx, gy, gz), 0.5 / h);
  return v;
}

static double kind_value(const void *k, const void *def, oc_vec3 p) {
  return ((const oc_kind_def *)def)->eval(k, p, NULL);
}

double oc_kind_fd_gradient(const oc_kctx *k, oc_vec3 p, double h, oc_vec3 *g) {
  const oc_program *P = k->P_;
  const oc_kind_def *def = P->ext[P->ops[k->op_].ext].def;
  return oc_fd_gradient(kind_value, k, def, p, h, g);
}

oc_aabb oc_child_box(const oc_kctx *k, size_t i) {
  const oc_program *P = k->P_;
  const oc_op *c = &P->ops[P->kids[P->ops[k->op_].kid + i]];
  oc_aabb b = {oc_v3(c->lo[0], c->lo[1], c->lo[2]),
               oc_v3(c->hi[0], c->hi[1], c->hi[2])};
  return b;
}

const void *oc_program_kind_data(const struct oc_program *P,
                                 const oc_kind_def *def, size_t *it) {
  while (*it < P->next) {
    const oc_pext *x = &P->ext[(*it)++];
    if (x->def == def) return x->data;
  }
  return NULL;
}
