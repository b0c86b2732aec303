/*
** write_ply.c — binary little-endian PLY: float positions and normals,
** uchar colours when the mesh has them, triangles as uchar-counted lists
** of uint indices. An empty mesh gives a valid file with zero elements.
**
** Colours are linear in the engine; the bytes are their sRGB encoding,
** which is how viewers read PLY colours. Metadata follows the first
** comment as "comment key=value" lines.
*/
#include <stdio.h>

#include "core/srgb.h"
#include "mesh/write.h"

#define FIRST_LINES                                                            \
  "ply\n"                                                                      \
  "format binary_little_endian 1.0\n"                                          \
  "comment written by outcrop " OC_VERSION "\n"

static void header(const oc_mesh *m, char *buf, size_t size) {
  snprintf(buf, size,
           "element vertex %zu\n"
           "property float x\n"
           "property float y\n"
           "property float z\n"
           "property float nx\n"
           "property float ny\n"
           "property float nz\n"
           "%s"
           "element face %zu\n"
           "property list uchar uint vertex_indices\n"
           "end_header\n",
           m->nv,
           m->col ? "property uchar red\n"
                    "property uchar green\n"
                    "property uchar blue\n"
                  : "",
           m->nt);
}

int oc_mesh_write_ply(const oc_mesh *m, oc_atomic *a, oc_error *err) {
  /* write failures are reported by the commit */
  unsigned char buf[OC_WRITE_CHUNK];
  oc_atomic_write(a, FIRST_LINES, sizeof FIRST_LINES - 1);
  int rc = oc_mesh_write_meta_lines(m, a, "comment ", err);
  if (rc) return rc;
  header(m, (char *)buf, sizeof buf);
  oc_atomic_write(a, buf, strlen((char *)buf));

  const size_t vsize = m->col ? 27 : 24;
  unsigned char *p = buf;
  for (size_t i = 0; i < m->nv; i++) {
    if ((size_t)(p - buf) + vsize > sizeof buf) {
      if (oc_atomic_write(a, buf, (size_t)(p - buf))) return OC_OK;
      p = buf;
    }
    for (int c = 0; c < 3; c++)
      p = oc_put_f32(p, m->pos[3 * i + c]);
    for (int c = 0; c < 3; c++)
      p = oc_put_f32(p, m->nrm[3 * i + c]);
    if (m->col)
      for (int c = 0; c < 3; c++)
        *p++ = oc_srgb_byte(m->col[3 * i + c]);
  }
  for (size_t t = 0; t < m->nt; t++) {
    if ((size_t)(p - buf) + 13 > sizeof buf) {
      if (oc_atomic_write(a, buf, (size_t)(p - buf))) return OC_OK;
      p = buf;
    }
    *p++ = 3;
    for (int c = 0; c < 3; c++)
      p = oc_put_u32(p, m->tri[3 * t + c]);
  }
  oc_atomic_write(a, buf, (size_t)(p - buf));
  return OC_OK;
}
