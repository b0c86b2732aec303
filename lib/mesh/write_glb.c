/*
** write_glb.c — glTF 2.0 binary (.glb): one scene, one node, one mesh of
** one indexed triangle primitive; POSITION (with its required min/max),
** NORMAL and, when set, COLOR_0 as float VEC3; UNSIGNED_INT indices. One
** buffer in the BIN chunk, one bufferView per array, all 4-byte aligned.
**
** A mesh without triangles gives a valid file whose one scene is empty:
** no node, mesh or buffer (glTF forbids accessors and buffers of length
** 0, and validators flag empty nodes).
**
** GLB stores lengths in 32 bits: a mesh whose file would pass 4 GiB is
** refused before anything is written.
*/
#include <stdarg.h>
#include <stdio.h>

#include "core/error.h"
#include "mesh/write.h"

#define GLB_MAGIC 0x46546C67u /* "glTF" */
#define CHUNK_JSON 0x4E4F534Au
#define CHUNK_BIN 0x004E4942u
#define JSON_MAX 4096 /* the JSON below stays far under this */

/* Size of the BIN chunk's data: positions, normals, colours, indices. */
static uint64_t bin_size(const oc_mesh *m) {
  if (m->nt == 0) return 0;
  return (uint64_t)m->nv * (m->col ? 36 : 24) + (uint64_t)m->nt * 12;
}

int oc_mesh_glb_fits(const oc_mesh *m, const char *path, oc_error *err) {
  uint64_t total = 12 + 8 + JSON_MAX + 8 + bin_size(m);
  if (m->nt > UINT32_MAX / 3 || total > UINT32_MAX)
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': a mesh of %zu vertices and %zu "
                     "triangles needs more than the 4 GiB a GLB file can "
                     "hold (write .ply instead)",
                     path, m->nv, m->nt);
  return OC_OK;
}

typedef struct text {
  char buf[JSON_MAX];
  size_t n;
} text;

static void add(text *t, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int k = vsnprintf(t->buf + t->n, sizeof t->buf - t->n, fmt, ap);
  va_end(ap);
  if (k > 0) t->n += (size_t)k;
  if (t->n >= sizeof t->buf) t->n = sizeof t->buf; /* marks overflow */
}

static void bounds(const oc_mesh *m, float lo[3], float hi[3]) {
  for (int c = 0; c < 3; c++)
    lo[c] = hi[c] = m->pos[c];
  for (size_t i = 1; i < m->nv; i++)
    for (int c = 0; c < 3; c++) {
      float v = m->pos[3 * i + c];
      if (v < lo[c]) lo[c] = v;
      if (v > hi[c]) hi[c] = v;
    }
}

/* The JSON chunk's text. Members in a fixed order and numbers as %.9g, so
** equal meshes give equal bytes; a float printed so reads back as the
** same float, which is how glTF compares min/max with the data. */
static void json(const oc_mesh *m, text *t) {
  t->n = 0;
  add(t, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"outcrop " OC_VERSION
         "\"},\"scene\":0");
  if (m->nt == 0) {
    add(t, ",\"scenes\":[{}]}");
    return;
  }
  size_t nv = m->nv, vbytes = 12 * nv;
  int ncol = m->col ? 1 : 0;
  float lo[3], hi[3];
  bounds(m, lo, hi);
  add(t, ",\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":"
         "\"outcrop\"}]");
  add(t, ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,"
         "\"NORMAL\":1");
  if (ncol) add(t, ",\"COLOR_0\":2");
  add(t, "},\"indices\":%d,\"mode\":4}]}]", 2 + ncol);
  add(t,
      ",\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
      "\"count\":%zu,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],"
      "\"max\":[%.9g,%.9g,%.9g]}",
      nv, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  for (int k = 1; k <= 1 + ncol; k++)
    add(t,
        ",{\"bufferView\":%d,\"componentType\":5126,\"count\":%zu,"
        "\"type\":\"VEC3\"}",
        k, nv);
  add(t,
      ",{\"bufferView\":%d,\"componentType\":5125,\"count\":%zu,"
      "\"type\":\"SCALAR\"}]",
      2 + ncol, 3 * m->nt);
  add(t, ",\"bufferViews\":[");
  for (int k = 0; k < 2 + ncol; k++)
    add(t,
        "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,"
        "\"target\":34962}",
        k ? "," : "", k * vbytes, vbytes);
  add(t,
      ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,"
      "\"target\":34963}]",
      (2 + ncol) * vbytes, 12 * m->nt);
  add(t, ",\"buffers\":[{\"byteLength\":%llu}]}",
      (unsigned long long)bin_size(m));
}

/* Colours are clamped to [0, 1] (NaN to 0) as the PLY writer does. */
static float unit(float c) {
  return c > 0.0f ? (c < 1.0f ? c : 1.0f) : 0.0f;
}

/* Writes `count` floats, encoded little-endian a chunk at a time. */
static int floats(oc_atomic *a, const float *v, size_t count, int colour,
                  unsigned char *buf) {
  size_t per = OC_WRITE_CHUNK / 4;
  for (size_t i = 0; i < count; i += per) {
    size_t n = count - i < per ? count - i : per;
    unsigned char *p = buf;
    for (size_t j = 0; j < n; j++)
      p = oc_put_f32(p, colour ? unit(v[i + j]) : v[i + j]);
    if (oc_atomic_write(a, buf, 4 * n)) return -1;
  }
  return 0;
}

static int uints(oc_atomic *a, const uint32_t *v, size_t count,
                 unsigned char *buf) {
  size_t per = OC_WRITE_CHUNK / 4;
  for (size_t i = 0; i < count; i += per) {
    size_t n = count - i < per ? count - i : per;
    unsigned char *p = buf;
    for (size_t j = 0; j < n; j++)
      p = oc_put_u32(p, v[i + j]);
    if (oc_atomic_write(a, buf, 4 * n)) return -1;
  }
  return 0;
}

int oc_mesh_write_glb(const oc_mesh *m, oc_atomic *a, oc_error *err) {
  text t;
  json(m, &t);
  if (t.n >= sizeof t.buf - 4) /* cannot happen: the JSON is bounded */
    return oc_seterr(err, OC_EINVAL, "cannot write '%s': glTF JSON too long",
                     a->path);
  while (t.n % 4)
    t.buf[t.n++] = ' '; /* the padding glTF asks for */
  uint32_t bin = (uint32_t)bin_size(m);
  uint32_t total = 12 + 8 + (uint32_t)t.n + (bin ? 8 + bin : 0);

  unsigned char buf[OC_WRITE_CHUNK], *p = buf;
  p = oc_put_u32(p, GLB_MAGIC);
  p = oc_put_u32(p, 2);
  p = oc_put_u32(p, total);
  p = oc_put_u32(p, (uint32_t)t.n);
  p = oc_put_u32(p, CHUNK_JSON);
  oc_atomic_write(a, buf, (size_t)(p - buf));
  oc_atomic_write(a, t.buf, t.n);
  if (!bin) return OC_OK;
  /* Every array is a multiple of 4 bytes: no padding inside or after. */
  p = oc_put_u32(buf, bin);
  p = oc_put_u32(p, CHUNK_BIN);
  oc_atomic_write(a, buf, (size_t)(p - buf));
  if (floats(a, m->pos, 3 * m->nv, 0, buf) ||
      floats(a, m->nrm, 3 * m->nv, 0, buf) ||
      (m->col && floats(a, m->col, 3 * m->nv, 1, buf)))
    return OC_OK;
  uints(a, m->tri, 3 * m->nt, buf);
  return OC_OK;
}
