/*
** node.c — node allocation, reference counting and operator constructors.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "field/node.h"

#define OC_KIND_NAME(id, name, flags) name,
#define OC_KIND_FLAGS(id, name, flags) flags,
static const char *const kind_names[OC_K_COUNT] = {OC_CORE_KINDS(OC_KIND_NAME)};
static const unsigned char kind_flags[OC_K_COUNT] = {
    OC_CORE_KINDS(OC_KIND_FLAGS)};
#undef OC_KIND_NAME
#undef OC_KIND_FLAGS

_Static_assert(OC_NPAR >= OC_KIND_NODE_MAXPAR,
               "a node's par holds an extension node's parameters");

const char *oc_kind_name(oc_kind kind) {
  return (unsigned)kind < OC_K_COUNT ? kind_names[kind] : "?";
}
unsigned oc_kind_flags(oc_kind kind) {
  return (unsigned)kind < OC_K_COUNT ? kind_flags[kind] : 0;
}
int oc_node_is_prim(const oc_node *n) {
  unsigned f = n->kind == OC_K_EXT ? n->def->flags : kind_flags[n->kind];
  return (f & OC_KF_PRIM) != 0;
}

oc_node *oc_node_alloc(oc_kind kind, oc_node *const *kids, size_t nkids,
                       oc_error *err) {
  oc_node *n = calloc(1, sizeof *n);
  if (!n) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  n->refs = 1;
  n->kind = kind;
  if (nkids <= 2) {
    n->kids = n->inl;
  } else {
    if (nkids > SIZE_MAX / sizeof *n->kids ||
        !(n->kids = malloc(nkids * sizeof *n->kids))) {
      free(n);
      oc_seterr(err, OC_ENOMEM, "out of memory (%zu children)", nkids);
      return NULL;
    }
  }
  n->nkids = nkids;
  for (size_t i = 0; i < nkids; i++) {
    n->kids[i] = kids ? kids[i] : NULL;
    if (n->kids[i]) oc_node_retain(n->kids[i]);
  }
  return n;
}

void oc_node_retain(oc_node *node) {
  if (node) node->refs++;
}

static void free_one(oc_node *n) {
  if (n->kids != n->inl) free(n->kids);
  free(n->pts);
  if (n->def && n->def->release) n->def->release(n->data);
  free(n);
}

/* Deep trees (a + b + c + ... from Lua is a left-deep chain) would overflow
** the C stack if freed recursively: nodes whose count drops to zero go on
** an explicit heap stack instead. */
void oc_node_release(oc_node *node) {
  if (!node || --node->refs > 0) return;
  oc_node **stack = NULL;
  size_t top = 0, cap = 0;
  oc_node *cur = node;
  for (;;) {
    for (size_t i = 0; i < cur->nkids; i++) {
      oc_node *k = cur->kids[i];
      if (!k || --k->refs > 0) continue;
      if (top == cap) {
        size_t nc = cap ? 2 * cap : 64;
        oc_node **ns = realloc(stack, nc * sizeof *ns);
        if (!ns) { /* no memory for the stack: recurse for this one */
          k->refs = 1;
          oc_node_release(k);
          continue;
        }
        stack = ns;
        cap = nc;
      }
      stack[top++] = k;
    }
    free_one(cur);
    if (top == 0) break;
    cur = stack[--top];
  }
  free(stack);
}

const char *oc_node_kind(const oc_node *node) {
  if (!node) return "?";
  return node->kind == OC_K_EXT ? node->def->name : oc_kind_name(node->kind);
}

oc_node *oc_kind_node(const oc_kind_def *def, oc_node *const *kids,
                      size_t nkids, const double *npar, size_t nnpar,
                      void *data, oc_error *err) {
  oc_node *n = NULL;
  if (nnpar > OC_KIND_NODE_MAXPAR)
    oc_seterr(err, OC_EINVAL, "%s: %zu parameters, more than %d", def->name,
              nnpar, OC_KIND_NODE_MAXPAR);
  else
    n = oc_node_alloc(OC_K_EXT, kids, nkids, err);
  if (!n) {
    if (def->release) def->release(data);
    return NULL;
  }
  n->def = def;
  n->data = data;
  n->nnpar = nnpar;
  if (nnpar) memcpy(n->par, npar, nnpar * sizeof *npar);
  return n;
}
const oc_kind_def *oc_node_def(const oc_node *n) {
  return n->kind == OC_K_EXT ? n->def : NULL;
}
const void *oc_node_data(const oc_node *n) {
  return n->kind == OC_K_EXT ? n->data : NULL;
}
size_t oc_node_child_count(const oc_node *node) {
  return node ? node->nkids : 0;
}
oc_node *oc_node_child(const oc_node *node, size_t i) {
  return node && i < node->nkids ? node->kids[i] : NULL;
}

/* ---- checks --------------------------------------------------------- */

int oc_check_finite(double v, const char *what, oc_error *err) {
  if (isfinite(v)) return 1;
  oc_seterr(err, OC_EINVAL, "'%s' must be a finite number (got %g)", what, v);
  return 0;
}
int oc_check_positive(double v, const char *what, oc_error *err) {
  if (isfinite(v) && v > 0) return 1;
  oc_seterr(err, OC_EINVAL, "'%s' must be a positive number (got %g)", what, v);
  return 0;
}
int oc_check_vec(oc_vec3 v, const char *what, oc_error *err) {
  if (oc_vfinite(v)) return 1;
  oc_seterr(err, OC_EINVAL, "'%s' must have finite coordinates", what);
  return 0;
}
int oc_check_noise(const oc_noise *n, oc_error *err) {
  if (!n) {
    oc_seterr(err, OC_EINVAL, "noise parameters missing");
    return 0;
  }
  if (!oc_check_positive(n->wavelength, "wavelength", err) ||
      !oc_check_finite(n->amplitude, "amplitude", err) ||
      !oc_check_finite(n->offset, "offset", err))
    return 0;
  if (n->octaves < 1 || n->octaves > 16) {
    oc_seterr(err, OC_EINVAL, "'octaves' must be an integer in 1..16 (got %d)",
              n->octaves);
    return 0;
  }
  return 1;
}

/* ---- operators ------------------------------------------------------ */

static int check_kids(oc_node *const *kids, size_t n, oc_error *err) {
  if (n == 0 || !kids) {
    oc_seterr(err, OC_EINVAL, "at least one child node is needed");
    return 0;
  }
  for (size_t i = 0; i < n; i++)
    if (!kids[i]) {
      oc_seterr(err, OC_EINVAL, "child %zu is NULL", i + 1);
      return 0;
    }
  return 1;
}

static oc_node *nary(oc_kind k, oc_node *const *kids, size_t n, oc_error *err) {
  if (!check_kids(kids, n, err)) return NULL;
  return oc_node_alloc(k, kids, n, err);
}
oc_node *oc_blend(oc_node *const *kids, size_t n, oc_error *err) {
  return nary(OC_K_BLEND, kids, n, err);
}
oc_node *oc_union(oc_node *const *kids, size_t n, oc_error *err) {
  return nary(OC_K_UNION, kids, n, err);
}
oc_node *oc_intersection(oc_node *const *kids, size_t n, oc_error *err) {
  return nary(OC_K_INTER, kids, n, err);
}

oc_node *oc_difference(oc_node *a, oc_node *b, oc_error *err) {
  oc_node *k[2] = {a, b};
  return nary(OC_K_DIFF, k, 2, err);
}

static oc_node *smooth(oc_kind kind, oc_node *a, oc_node *b, double r,
                       oc_error *err) {
  oc_node *k[2] = {a, b};
  if (!check_kids(k, 2, err) || !oc_check_positive(r, "radius", err))
    return NULL;
  oc_node *n = oc_node_alloc(kind, k, 2, err);
  if (n) n->par[OC_P_SRAD] = r;
  return n;
}
oc_node *oc_smooth_union(oc_node *a, oc_node *b, double r, oc_error *err) {
  return smooth(OC_K_SUNION, a, b, r, err);
}
oc_node *oc_smooth_intersection(oc_node *a, oc_node *b, double r,
                                oc_error *err) {
  return smooth(OC_K_SINTER, a, b, r, err);
}

oc_node *oc_scale_field(oc_node *a, double factor, oc_error *err) {
  if (!check_kids(&a, 1, err) || !oc_check_finite(factor, "factor", err))
    return NULL;
  oc_node *n = oc_node_alloc(OC_K_SCALE, &a, 1, err);
  if (n) n->par[OC_P_FACTOR] = factor;
  return n;
}

oc_node *oc_warp(oc_node *child, const oc_noise *noise, oc_node *control,
                 oc_error *err) {
  if (!check_kids(&child, 1, err) || !oc_check_noise(noise, err)) return NULL;
  oc_node *k[2] = {child, control};
  oc_node *n = oc_node_alloc(OC_K_WARP, k, control ? 2 : 1, err);
  if (n) n->noise = *noise;
  return n;
}

/* Inverse of a 3x4 affine map (rows: [M | t]); 0 when singular. */
static int affine_inverse(const double m[12], double inv[12]) {
  double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8],
         h = m[9], i = m[10];
  double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
  double det = a * A + b * B + c * C;
  double scale = fabs(a) + fabs(b) + fabs(c) + fabs(d) + fabs(e) + fabs(f) +
                 fabs(g) + fabs(h) + fabs(i);
  if (!isfinite(det) || fabs(det) <= 1e-12 * scale * scale * scale) return 0;
  double r = 1.0 / det;
  double R[9] = {A * r, -(b * i - c * h) * r, (b * f - c * e) * r,
                 B * r, (a * i - c * g) * r,  -(a * f - c * d) * r,
                 C * r, -(a * h - b * g) * r, (a * e - b * d) * r};
  for (int row = 0; row < 3; row++) {
    inv[row * 4 + 0] = R[row * 3 + 0];
    inv[row * 4 + 1] = R[row * 3 + 1];
    inv[row * 4 + 2] = R[row * 3 + 2];
    inv[row * 4 + 3] = -(R[row * 3 + 0] * m[3] + R[row * 3 + 1] * m[7] +
                         R[row * 3 + 2] * m[11]);
  }
  return 1;
}

oc_node *oc_transform(oc_node *child, const double m[12], oc_error *err) {
  if (!check_kids(&child, 1, err)) return NULL;
  double inv[12];
  for (int i = 0; i < 12; i++)
    if (!m || !isfinite(m[i])) {
      oc_seterr(err, OC_EINVAL, "transform matrix must be finite");
      return NULL;
    }
  if (!affine_inverse(m, inv)) {
    oc_seterr(err, OC_EINVAL,
              "transform is not invertible (a 'scale' of 0, or too small or "
              "too large)");
    return NULL;
  }
  oc_node *n = oc_node_alloc(OC_K_XFORM, &child, 1, err);
  if (n) {
    memcpy(n->par + OC_P_FWD, m, 12 * sizeof *m);
    memcpy(n->par + OC_P_INV, inv, 12 * sizeof *inv);
  }
  return n;
}

oc_node *oc_perturb(oc_node *prim, const oc_noise *noise, oc_error *err) {
  if (!check_kids(&prim, 1, err) || !oc_check_noise(noise, err)) return NULL;
  if (!OC_KIND_IS_DIST(prim->kind) || prim->kind == OC_K_PLANE) {
    oc_seterr(
        err, OC_EINVAL,
        "the node to perturb must be a point, sphere, box, segment, curve "
        "or cone primitive (got %s)",
        oc_node_kind(prim));
    return NULL;
  }
  double R = prim->par[OC_P_R];
  double tmax = 2.0 - ldexp(1.0, 1 - noise->octaves);
  if (noise->amplitude < 0 && -noise->amplitude * tmax >= 0.999 * R) {
    oc_seterr(err, OC_EINVAL,
              "'amplitude' %g would shrink the radius %g to zero or less",
              noise->amplitude, R);
    return NULL;
  }
  oc_node *n = oc_node_alloc(OC_K_PERTURB, &prim, 1, err);
  if (n) n->noise = *noise;
  return n;
}
