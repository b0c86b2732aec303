/*
** write.h — what the mesh writers share (internal to lib/mesh).
**
** oc_mesh_write (write.c) checks the mesh, opens the atomic output and
** switches to the C locale; each format's writer then only encodes. The
** writers report encoding problems through err; failed writes on the
** stream are found by oc_atomic_commit.
*/
#ifndef OC_MESH_WRITE_H
#define OC_MESH_WRITE_H

#include <stdint.h>
#include <string.h>

#include "io/atomic.h"
#include "mesh/mesh.h"

/* Bytes encoded at a time before they go to the stream. */
#define OC_WRITE_CHUNK 65536

int oc_mesh_write_ply(const oc_mesh *m, oc_atomic *a, oc_error *err);
int oc_mesh_write_obj(const oc_mesh *m, oc_atomic *a, oc_error *err);
int oc_mesh_write_glb(const oc_mesh *m, oc_atomic *a, oc_error *err);
/* OC_EINVAL when the mesh cannot be held by a GLB file (32-bit sizes);
** called before anything is created, and before the arrays are read. */
int oc_mesh_glb_fits(const oc_mesh *m, const char *path, oc_error *err);

/* Writes one "<prefix>key=value\n" line per metadata pair of m, values
** quoted by oc_meta_quote (io/metatext.h) so that no value holds a line
** break: PLY ("comment ") and OBJ ("# ") share it. OC_ENOMEM with err
** when a value cannot be quoted; write failures are left to the commit. */
int oc_mesh_write_meta_lines(const oc_mesh *m, oc_atomic *a, const char *prefix,
                             oc_error *err);

/* Little-endian encoding, whatever the host's byte order. */
static inline unsigned char *oc_put_u32(unsigned char *p, uint32_t v) {
  p[0] = (unsigned char)v;
  p[1] = (unsigned char)(v >> 8);
  p[2] = (unsigned char)(v >> 16);
  p[3] = (unsigned char)(v >> 24);
  return p + 4;
}

static inline unsigned char *oc_put_f32(unsigned char *p, float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return oc_put_u32(p, u);
}

#endif
