/*
** mctable.h — the marching cubes case table and the cube's geometry
** (internal).
**
** Corner c of a cube is the sample at offset (c & 1, c >> 1 & 1, c >> 2 & 1);
** case bit c is set when that corner is inside (f > T). Edge e runs along
** axis e / 4 from its lower corner oc_mc_edge_lo[e] to lower corner + the
** axis's unit step.
**
** The table is topologically consistent: an ambiguous face (two diagonal
** inside corners) is always resolved by separating the inside corners, a
** rule that depends on the face alone, so the two cubes sharing a face cut
** it the same way and the surface has no cracks. Triangles are listed
** counter-clockwise seen from outside (from f < T).
*/
#ifndef OC_MCTABLE_H
#define OC_MCTABLE_H

#include <stdint.h>

/* A loop crosses at most 12 edges, so a fan has at most 10 triangles. */
#define OC_MC_MAXTRI 10

typedef struct oc_mctable {
  uint8_t ntri[256];
  uint8_t tri[256][OC_MC_MAXTRI * 3]; /* edge indices, 3 per triangle */
} oc_mctable;

/* The table, built once on first use (thread-safe), then read-only. */
const oc_mctable *oc_mctable_get(void);

/* Lower corner of each edge; the edge's axis is e / 4. */
extern const uint8_t oc_mc_edge_lo[12];

#endif
