/*
** write_ply.c — binary little-endian PLY: float positions and normals,
** uchar colours when the mesh has them, triangles as uchar-counted lists
** of uint indices. An empty mesh gives a valid file with zero elements.
*/
#include <stdio.h>

#include "mesh/write.h"

/* Round to nearest from [0, 1]; anything else (NaN too) is clamped. */
static unsigned char quantize(float c) {
  return c > 0.0f ? (c < 1.0f ? (unsigned char)(c * 255.0 + 0.5) : 255) : 0;
}

static void header(const oc_mesh *m, char *buf, size_t size) {
  snprintf(buf, size,
           "ply\n"
           "format binary_little_endian 1.0\n"
           "comment written by outcrop " OC_VERSION "\n"
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
  (void)err; /* write failures are reported by the commit */
  unsigned char buf[OC_WRITE_CHUNK];
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
        *p++ = quantize(m->col[3 * i + c]);
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
