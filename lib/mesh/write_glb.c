/*
** write_glb.c — glTF 2.0 binary (.glb): one scene, one node, one mesh of
** one indexed triangle primitive; POSITION (with its required min/max),
** NORMAL and, when set, COLOR_0 as float VEC3; UNSIGNED_INT indices. One
** buffer in the BIN chunk, one bufferView per array, all 4-byte aligned.
**
** glTF is +Y up (glTF 2.0 section 3.4) and the engine is Z-up: engine
** (x, y, z) is written as (x, z, -y), positions and normals alike. That
** is a rotation (determinant +1), so the triangles' winding, and with it
** the outward orientation, is unchanged.
**
** Colours are linear, as COLOR_0 is; the primitive uses one material,
** white, dielectric and rough, so that viewers show the vertex colours
** (COLOR_0 multiplies the base colour). The mesh's metadata goes into
** asset.extras as string members under their own keys.
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
#include <stdlib.h>

#include "core/error.h"
#include "mesh/write.h"

#define GLB_MAGIC 0x46546C67u /* "glTF" */
#define CHUNK_JSON 0x4E4F534Au
#define CHUNK_BIN 0x004E4942u
#define JSON_MAX 4096 /* the JSON apart from the metadata stays under this */

/* Size of the BIN chunk's data: positions, normals, colours, indices. */
static uint64_t bin_size(const oc_mesh *m) {
  if (m->nt == 0) return 0;
  return (uint64_t)m->nv * (m->col ? 36 : 24) + (uint64_t)m->nt * 12;
}

/* At most 6 bytes of JSON per byte of a key or value (\u00XX), plus
** quotes and separators. */
static uint64_t meta_size(const oc_mesh *m) {
  uint64_t n = 16;
  for (size_t i = 0; i < m->meta.n; i++)
    n += 6 * ((uint64_t)strlen(m->meta.v[i].key) + strlen(m->meta.v[i].value)) + 8;
  return n;
}

int oc_mesh_glb_fits(const oc_mesh *m, const char *path, oc_error *err) {
  uint64_t total = 12 + 8 + JSON_MAX + meta_size(m) + 8 + bin_size(m);
  if (m->nt > UINT32_MAX / 3 || total > UINT32_MAX)
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': a mesh of %zu vertices and %zu "
                     "triangles needs more than the 4 GiB a GLB file can "
                     "hold (write .ply instead)",
                     path, m->nv, m->nt);
  return OC_OK;
}

/* The JSON text, in a buffer sized before it is built (see meta_size). */
typedef struct text {
  char *buf;
  size_t n, cap;
} text;

static void add(text *t, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int k = vsnprintf(t->buf + t->n, t->cap - t->n, fmt, ap);
  va_end(ap);
  if (k > 0) t->n += (size_t)k;
  if (t->n >= t->cap) t->n = t->cap; /* marks overflow */
}

static void addc(text *t, char c) {
  if (t->n < t->cap) t->buf[t->n++] = c;
}

/* Length of the well-formed UTF-8 sequence at s (1..4), or 0 when the
** bytes there are not one (overlong forms, surrogates and code points
** past U+10FFFF included). */
static int utf8_len(const unsigned char *s) {
  unsigned c = s[0];
  int n = c < 0x80                 ? 1
          : c >= 0xC2 && c <= 0xDF ? 2
          : c >= 0xE0 && c <= 0xEF ? 3
          : c >= 0xF0 && c <= 0xF4 ? 4
                                   : 0;
  for (int i = 1; i < n; i++)
    if ((s[i] & 0xC0) != 0x80) return 0; /* also stops at the NUL */
  if (n == 3 && ((c == 0xE0 && s[1] < 0xA0) || (c == 0xED && s[1] > 0x9F)))
    return 0;
  if (n == 4 && ((c == 0xF0 && s[1] < 0x90) || (c == 0xF4 && s[1] > 0x8F)))
    return 0;
  return n;
}

/* s as a JSON string: quote, backslash and control characters escaped,
** well-formed UTF-8 as it is, and each byte of anything else as U+FFFD
** (JSON text, and so glTF, must be UTF-8). */
static void add_string(text *t, const char *str) {
  const unsigned char *s = (const unsigned char *)str;
  addc(t, '"');
  while (*s) {
    unsigned c = *s;
    int n = utf8_len(s);
    if (c == '"' || c == '\\') {
      addc(t, '\\');
      addc(t, (char)c);
    } else if (c == '\n') {
      add(t, "\\n");
    } else if (c == '\t') {
      add(t, "\\t");
    } else if (c == '\r') {
      add(t, "\\r");
    } else if (c < 0x20) {
      add(t, "\\u%04x", c);
    } else if (n == 0) {
      add(t, "\\ufffd");
      n = 1;
    } else {
      for (int i = 0; i < n; i++)
        addc(t, (char)s[i]);
    }
    s += n ? n : 1;
  }
  addc(t, '"');
}

/* Engine axes to glTF axes: (x, y, z) -> (x, z, -y). */
static void to_gltf(const float *v, float out[3]) {
  out[0] = v[0];
  out[1] = v[2];
  out[2] = -v[1];
}

/* Bounds in glTF axes. */
static void bounds(const oc_mesh *m, float lo[3], float hi[3]) {
  float g[3];
  to_gltf(m->pos, g);
  for (int c = 0; c < 3; c++)
    lo[c] = hi[c] = g[c];
  for (size_t i = 1; i < m->nv; i++) {
    to_gltf(m->pos + 3 * i, g);
    for (int c = 0; c < 3; c++) {
      if (g[c] < lo[c]) lo[c] = g[c];
      if (g[c] > hi[c]) hi[c] = g[c];
    }
  }
}

/* The JSON chunk's text. Members in a fixed order and numbers as %.9g, so
** equal meshes give equal bytes; a float printed so reads back as the
** same float, which is how glTF compares min/max with the data. */
static void json(const oc_mesh *m, text *t) {
  t->n = 0;
  add(t, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"outcrop " OC_VERSION
         "\"");
  if (m->meta.n) {
    add(t, ",\"extras\":{");
    for (size_t i = 0; i < m->meta.n; i++) {
      if (i) addc(t, ',');
      add_string(t, m->meta.v[i].key);
      addc(t, ':');
      add_string(t, m->meta.v[i].value);
    }
    addc(t, '}');
  }
  add(t, "},\"scene\":0");
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
  add(t, "},\"indices\":%d,\"material\":0,\"mode\":4}]}]", 2 + ncol);
  add(t, ",\"materials\":[{\"name\":\"outcrop vertex colours\","
         "\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],"
         "\"metallicFactor\":0,\"roughnessFactor\":0.9}}]");
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

/* Writes the nv vectors of v (3 floats each), encoded little-endian a
** chunk at a time: colours clamped to [0, 1] (NaN to 0) as the PLY writer
** does, positions and normals turned to glTF axes. */
static int vectors(oc_atomic *a, const float *v, size_t nv, int colour,
                   unsigned char *buf) {
  size_t per = OC_WRITE_CHUNK / 12;
  for (size_t i = 0; i < nv; i += per) {
    size_t n = nv - i < per ? nv - i : per;
    unsigned char *p = buf;
    for (size_t j = 0; j < n; j++) {
      const float *x = v + 3 * (i + j);
      float g[3];
      if (colour)
        for (int c = 0; c < 3; c++)
          g[c] = unit(x[c]);
      else
        to_gltf(x, g);
      for (int c = 0; c < 3; c++)
        p = oc_put_f32(p, g[c]);
    }
    if (oc_atomic_write(a, buf, 12 * n)) return -1;
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
  t.cap = (size_t)(JSON_MAX + meta_size(m)); /* fits() bounded it */
  t.buf = malloc(t.cap);
  if (!t.buf)
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory",
                     a->path);
  json(m, &t);
  if (t.n >= t.cap - 4) { /* cannot happen: the JSON is bounded */
    free(t.buf);
    return oc_seterr(err, OC_EINVAL, "cannot write '%s': glTF JSON too long",
                     a->path);
  }
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
  free(t.buf);
  if (!bin) return OC_OK;
  /* Every array is a multiple of 4 bytes: no padding inside or after. */
  p = oc_put_u32(buf, bin);
  p = oc_put_u32(p, CHUNK_BIN);
  oc_atomic_write(a, buf, (size_t)(p - buf));
  if (vectors(a, m->pos, m->nv, 0, buf) || vectors(a, m->nrm, m->nv, 0, buf) ||
      (m->col && vectors(a, m->col, m->nv, 1, buf)))
    return OC_OK;
  uints(a, m->tri, 3 * m->nt, buf);
  return OC_OK;
}
