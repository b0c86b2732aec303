/*
** mesh.h — the triangle mesh behind oc_mesh (internal).
**
** Flat arrays, as the writers want them: positions and unit normals, three
** floats per vertex; optional colours, three floats per vertex in [0, 1];
** triangles as three vertex indices, counter-clockwise seen from outside;
** metadata (provenance) as key/value strings, in the order first set.
*/
#ifndef OC_MESH_H
#define OC_MESH_H

#include "core/kvlist.h"
#include "outcrop.h"

struct oc_mesh {
  float *pos;
  float *nrm;
  float *col; /* NULL until colours are set */
  size_t nv;
  uint32_t *tri;
  size_t nt;
  oc_mesh_stats stats;
  oc_kvlist meta;
};

/* An empty mesh with room for exactly nv vertices and nt triangles (both
** may be 0); fails cleanly with OC_ENOMEM. */
oc_mesh *oc_mesh_alloc(size_t nv, size_t nt, oc_error *err);

#endif
