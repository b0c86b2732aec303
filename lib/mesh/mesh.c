/*
** mesh.c — the oc_mesh container: allocation, accessors, statistics and
** per-vertex colours (given, or from a field through a palette),
** metadata.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/palette.h"
#include "mesh/mesh.h"

/* Array of n groups of three `size`-byte items; NULL when n == 0 (the
** accessors then return NULL, and nothing reads the array). Fails on
** overflow as on exhaustion. */
static void *triples(size_t n, size_t size, int *failed) {
  if (n == 0) return NULL;
  if (n > SIZE_MAX / (3 * size)) {
    *failed = 1;
    return NULL;
  }
  void *p = malloc(n * 3 * size);
  if (!p) *failed = 1;
  return p;
}

oc_mesh *oc_mesh_alloc(size_t nv, size_t nt, oc_error *err) {
  /* Indices are 32-bit, and UINT32_MAX is glTF's primitive restart. */
  if (nv > (size_t)UINT32_MAX - 1) {
    oc_seterr(err, OC_ENOMEM,
              "mesh too large: %zu vertices (at most %lu: indices are "
              "32-bit)",
              nv, (unsigned long)UINT32_MAX - 1);
    return NULL;
  }
  oc_mesh *m = calloc(1, sizeof *m);
  int failed = m == NULL;
  if (m) {
    m->pos = triples(nv, sizeof(float), &failed);
    m->nrm = triples(nv, sizeof(float), &failed);
    m->tri = triples(nt, sizeof(uint32_t), &failed);
    m->nv = nv;
    m->nt = nt;
    m->stats.vertices = nv;
    m->stats.triangles = nt;
  }
  if (failed) {
    oc_mesh_free(m);
    oc_seterr(err, OC_ENOMEM,
              "out of memory for a mesh of %zu vertices and %zu triangles", nv,
              nt);
    return NULL;
  }
  return m;
}

void oc_mesh_free(oc_mesh *mesh) {
  if (!mesh) return;
  free(mesh->pos);
  free(mesh->nrm);
  free(mesh->col);
  free(mesh->tri);
  oc_kvlist_free(&mesh->meta);
  free(mesh);
}

size_t oc_mesh_vertex_count(const oc_mesh *mesh) {
  return mesh->nv;
}
size_t oc_mesh_triangle_count(const oc_mesh *mesh) {
  return mesh->nt;
}
const float *oc_mesh_positions(const oc_mesh *mesh) {
  return mesh->pos;
}
const float *oc_mesh_normals(const oc_mesh *mesh) {
  return mesh->nrm;
}
const float *oc_mesh_colors(const oc_mesh *mesh) {
  return mesh->col;
}
const uint32_t *oc_mesh_indices(const oc_mesh *mesh) {
  return mesh->tri;
}

/* The counts come from the arrays, so they are right even when the
** mesher filled the rest of the statistics before trimming. */
void oc_mesh_get_stats(const oc_mesh *mesh, oc_mesh_stats *st) {
  *st = mesh->stats;
  st->vertices = mesh->nv;
  st->triangles = mesh->nt;
}

/* The colour array, allocated on first use (not attached to the mesh
** here: the caller attaches it only once every value is known good). */
static float *color_array(oc_mesh *mesh, oc_error *err) {
  if (mesh->col) return mesh->col;
  int failed = 0;
  /* At least one triple, so that an empty mesh can have colours set. */
  float *c = triples(mesh->nv ? mesh->nv : 1, sizeof(float), &failed);
  if (failed)
    oc_seterr(err, OC_ENOMEM, "out of memory for the colours of %zu vertices",
              mesh->nv);
  return c;
}

static float clamp01(double x) {
  return x > 0 ? (x < 1 ? (float)x : 1.0f) : 0.0f;
}

/* Values outside [0, 1] are clamped; NaN is refused, since it has no
** colour and would reach the files as garbage. */
int oc_mesh_set_colors(oc_mesh *mesh, const float *rgb, oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  if (!rgb && mesh->nv > 0)
    return oc_seterr(err, OC_EINVAL, "'colors' is NULL");
  for (size_t i = 0; i < 3 * mesh->nv; i++)
    if (isnan(rgb[i]))
      return oc_seterr(err, OC_EINVAL,
                       "'colors' has NaN at vertex %zu, component %zu", i / 3,
                       i % 3);
  float *c = color_array(mesh, err);
  if (!c) return OC_ENOMEM;
  for (size_t i = 0; i < 3 * mesh->nv; i++)
    c[i] = clamp01(rgb[i]);
  mesh->col = c;
  return OC_OK;
}

int oc_mesh_color_by_field(oc_mesh *mesh, const oc_program *field,
                           const double *stops, int n, oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  if (!field) return oc_seterr(err, OC_EINVAL, "'field' is NULL");
  int rc = oc_palette_check(stops, n, err);
  if (rc) return rc;
  float *c = color_array(mesh, err);
  if (!c) return OC_ENOMEM;
  const float *P = mesh->pos;
  ptrdiff_t nv = (ptrdiff_t)mesh->nv;
  /* Each vertex on its own: the result cannot depend on the schedule. */
#pragma omp parallel for schedule(static)
  for (ptrdiff_t i = 0; i < nv; i++) {
    oc_vec3 p = {P[3 * i], P[3 * i + 1], P[3 * i + 2]};
    double rgb[3];
    oc_palette_eval(stops, n, oc_program_eval(field, p), rgb);
    for (int k = 0; k < 3; k++)
      c[3 * i + k] = (float)rgb[k];
  }
  mesh->col = c;
  return OC_OK;
}

/* ---- metadata -------------------------------------------------------- */

#define MAX_META_KEY 64
#define MAX_META_VALUE 65535
#define MAX_META 64

/* Keys go into PLY and OBJ comment lines unquoted and into JSON as
** member names, so they are kept to characters safe in all three. */
static int check_key(const char *key, oc_error *err) {
  size_t len = strlen(key);
  if (len == 0 || len > MAX_META_KEY)
    return oc_seterr(err, OC_EINVAL,
                     "'key' must have 1..%d characters (got %zu)", MAX_META_KEY,
                     len);
  unsigned char c0 = (unsigned char)key[0];
  if (!((c0 >= 'a' && c0 <= 'z') || (c0 >= 'A' && c0 <= 'Z')))
    return oc_seterr(err, OC_EINVAL,
                     "'key' must start with a letter (got '%s')", key);
  for (size_t i = 0; i < len; i++) {
    unsigned char c = (unsigned char)key[i];
    int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
             (c >= '0' && c <= '9') || c == '_' || c == '.' || c == ':' ||
             c == '-';
    if (!ok)
      return oc_seterr(err, OC_EINVAL,
                       "'key' may hold only letters, digits, '_', '.', ':' and "
                       "'-' (got '%s')",
                       key);
  }
  return OC_OK;
}

int oc_mesh_set_meta(oc_mesh *mesh, const char *key, const char *value,
                     oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  if (!key) return oc_seterr(err, OC_EINVAL, "'key' is NULL");
  if (!value) return oc_seterr(err, OC_EINVAL, "'value' is NULL");
  int rc = check_key(key, err);
  if (rc) return rc;
  size_t vlen = strlen(value);
  if (vlen > MAX_META_VALUE)
    return oc_seterr(err, OC_EINVAL,
                     "'value' of '%s' is too long (%zu > %d bytes)", key, vlen,
                     MAX_META_VALUE);
  /* Exact comparison: JSON member names are case-sensitive. */
  return oc_kvlist_set(&mesh->meta, key, value, 0, MAX_META, err);
}

size_t oc_mesh_meta_count(const oc_mesh *mesh) {
  return mesh->meta.n;
}
const char *oc_mesh_meta_key(const oc_mesh *mesh, size_t i) {
  return i < mesh->meta.n ? mesh->meta.v[i].key : NULL;
}
const char *oc_mesh_meta_value(const oc_mesh *mesh, size_t i) {
  return i < mesh->meta.n ? mesh->meta.v[i].value : NULL;
}
