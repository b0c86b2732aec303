/*
** components.c — connected components of a mesh (union-find over the
** triangles' edges) and the removal of the small ones.
**
** Components are numbered in order of their lowest vertex index, which
** depends on the arrays alone: the same mesh gives the same numbering
** and, after a removal, the same bytes, whatever the thread count.
*/
#include <stdint.h>
#include <stdlib.h>

#include "core/checked.h"
#include "core/error.h"
#include "mesh/mesh.h"

/* The root of v, halving the path on the way (amortized near-constant). */
static uint32_t find(uint32_t *up, uint32_t v) {
  while (up[v] != v) {
    up[v] = up[up[v]];
    v = up[v];
  }
  return v;
}

/* The lower root becomes the parent, so a root is its component's lowest
** vertex. */
static void join(uint32_t *up, uint32_t a, uint32_t b) {
  a = find(up, a), b = find(up, b);
  if (a < b)
    up[b] = a;
  else if (b < a)
    up[a] = b;
}

/* label[v] = the component number of vertex v (0, 1, ... in order of
** lowest vertex); returns the number of components, or -1 with err. */
static int label(const oc_mesh *m, uint32_t **labels, size_t *ncomp,
                 oc_error *err) {
  size_t bytes;
  *labels = NULL;
  *ncomp = 0;
  if (m->nv == 0) return OC_OK;
  if (!oc_mul_size(m->nv, sizeof(uint32_t), &bytes))
    return oc_seterr(err, OC_ENOMEM, "mesh too large to label (%zu vertices)",
                     m->nv);
  uint32_t *up = malloc(bytes);
  if (!up)
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory labelling the components of %zu vertices",
                     m->nv);
  for (size_t v = 0; v < m->nv; v++)
    up[v] = (uint32_t)v;
  for (size_t t = 0; t < m->nt; t++) {
    const uint32_t *k = m->tri + 3 * t;
    join(up, k[0], k[1]);
    join(up, k[1], k[2]);
  }
  /* Every vertex straight to its root first; then, roots being lowest
  ** vertices, a vertex's root is numbered before the vertex is met, so
  ** one pass in index order numbers them all. (The passes must not mix:
  ** find() would walk through entries already turned into numbers.) */
  for (size_t v = 0; v < m->nv; v++)
    up[v] = find(up, (uint32_t)v);
  size_t n = 0;
  for (size_t v = 0; v < m->nv; v++)
    up[v] = up[v] == v ? (uint32_t)n++ : up[up[v]];
  *labels = up;
  *ncomp = n;
  return OC_OK;
}

int oc_mesh_components(const oc_mesh *mesh, size_t **sizes, size_t *count,
                       oc_error *err) {
  if (!mesh || !sizes || !count)
    return oc_seterr(err, OC_EINVAL, "'mesh', 'sizes' and 'count' are needed");
  *sizes = NULL;
  *count = 0;
  uint32_t *lab;
  size_t n;
  int rc = label(mesh, &lab, &n, err);
  if (rc || n == 0) return rc;
  size_t *sz = calloc(n, sizeof *sz); /* n <= nv: the product fits */
  if (!sz) {
    free(lab);
    return oc_seterr(err, OC_ENOMEM, "out of memory for %zu components", n);
  }
  for (size_t v = 0; v < mesh->nv; v++)
    sz[lab[v]]++;
  free(lab);
  *sizes = sz;
  *count = n;
  return OC_OK;
}

int oc_mesh_drop_components(oc_mesh *mesh, size_t min_vertices, oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  if (min_vertices <= 1 || mesh->nv == 0) return OC_OK;
  uint32_t *lab;
  size_t n, *sz;
  int rc = label(mesh, &lab, &n, err);
  if (rc) return rc;
  sz = calloc(n, sizeof *sz);
  if (!sz) {
    free(lab);
    return oc_seterr(err, OC_ENOMEM, "out of memory for %zu components", n);
  }
  for (size_t v = 0; v < mesh->nv; v++)
    sz[lab[v]]++;
  /* lab becomes the new index of each kept vertex; kept vertices and
  ** triangles stay in their order, moved down in place. */
  size_t nv = 0, nt = 0;
  for (size_t v = 0; v < mesh->nv; v++) {
    int keep = sz[lab[v]] >= min_vertices;
    lab[v] = keep ? (uint32_t)nv : UINT32_MAX;
    if (!keep) continue;
    for (int c = 0; c < 3; c++) {
      mesh->pos[3 * nv + c] = mesh->pos[3 * v + c];
      mesh->nrm[3 * nv + c] = mesh->nrm[3 * v + c];
      if (mesh->col) mesh->col[3 * nv + c] = mesh->col[3 * v + c];
    }
    nv++;
  }
  for (size_t t = 0; t < mesh->nt; t++) {
    const uint32_t *k = mesh->tri + 3 * t;
    /* A triangle's vertices share a component: one test decides. */
    if (lab[k[0]] == UINT32_MAX) continue;
    uint32_t a = lab[k[0]], b = lab[k[1]], c = lab[k[2]];
    mesh->tri[3 * nt] = a, mesh->tri[3 * nt + 1] = b, mesh->tri[3 * nt + 2] = c;
    nt++;
  }
  free(sz);
  free(lab);
  /* The arrays keep their capacity; only the counts shrink. */
  mesh->nv = nv;
  mesh->nt = nt;
  return OC_OK;
}
