/*
** write_obj.c — Wavefront OBJ: "v", "vn" and "f a//a b//b c//c" lines
** (1-based; normal i belongs to vertex i). Numbers are %.9g, enough for
** every float to read back to the same float. Colours are not written:
** OBJ has no standard place for them. An empty mesh gives a file with
** only the header comments. Metadata follows them as "# key=value" lines.
*/
#include <stdio.h>

#include "mesh/write.h"

/* Longest line: "vn " and three %.9g numbers ("-1.23456789e-38") with
** separators, or "f " and three "4294967295//4294967295". */
#define LINE 80

/* Text is formatted into a chunk that goes to the stream when full. */
typedef struct chunk {
  oc_atomic *a;
  char buf[OC_WRITE_CHUNK];
  size_t n;
} chunk;

/* Makes room for one more line; -1 once the stream has failed. */
static int room(chunk *c) {
  if (c->n + LINE < sizeof c->buf) return 0;
  int rc = oc_atomic_write(c->a, c->buf, c->n);
  c->n = 0;
  return rc;
}

static int vec3(chunk *c, const char *tag, const float *v) {
  if (room(c)) return -1;
  c->n += (size_t)snprintf(c->buf + c->n, LINE, "%s %.9g %.9g %.9g\n", tag,
                           v[0], v[1], v[2]);
  return 0;
}

int oc_mesh_write_obj(const oc_mesh *m, oc_atomic *a, oc_error *err) {
  /* write failures are reported by the commit */
  chunk c, *ch = &c;
  ch->a = a;
  ch->n = (size_t)snprintf(ch->buf, sizeof ch->buf,
                           "# written by outcrop " OC_VERSION "\n"
                           "# %zu vertices, %zu triangles\n",
                           m->nv, m->nt);
  oc_atomic_write(a, ch->buf, ch->n);
  ch->n = 0;
  int rc = oc_mesh_write_meta_lines(m, a, "# ", err);
  if (rc) return rc;
  for (size_t i = 0; i < m->nv; i++)
    if (vec3(ch, "v", m->pos + 3 * i)) return OC_OK;
  for (size_t i = 0; i < m->nv; i++)
    if (vec3(ch, "vn", m->nrm + 3 * i)) return OC_OK;
  for (size_t t = 0; t < m->nt; t++) {
    if (room(ch)) return OC_OK;
    const uint32_t *v = m->tri + 3 * t;
    unsigned long i = v[0] + 1ul, j = v[1] + 1ul, k = v[2] + 1ul;
    ch->n +=
        (size_t)snprintf(ch->buf + ch->n, LINE,
                         "f %lu//%lu %lu//%lu %lu//%lu\n", i, i, j, j, k, k);
  }
  oc_atomic_write(a, ch->buf, ch->n);
  return OC_OK;
}
