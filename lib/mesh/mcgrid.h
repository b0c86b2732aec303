/*
** mcgrid.h — the sampling grid of the polygonizer and the slab interface
** (internal).
**
** Samples sit at cell centres: sample i on axis a is at
** lo[a] + (i + 0.5) h[a], i = 0 .. n[a] - 1, and a padding layer at i = -1
** and i = n[a] lies on the box faces. For closed meshes the padding is
** outside by definition (the outside of the box is empty), so the surface
** is capped where a solid meets the box: a crossing between a real sample
** and a padding one lies exactly on the box face. For open meshes the
** padding samples take the field's values on the faces, so the surface
** runs right up to the box and stops there (terrain tiles that abut). A
** "cube" of marching cubes joins samples i .. i + 1 on each axis,
** i = -1 .. n - 1.
**
** The grid is split into slabs of cube rows along y, meshed independently
** (in parallel) and merged in order; see polygonize.c.
*/
#ifndef OC_MCGRID_H
#define OC_MCGRID_H

#include <stddef.h>
#include <stdint.h>

#include "outcrop.h"

#define OC_MC_NONE UINT32_MAX
/* Cubes per side of a Lipschitz culling block; slabs are whole blocks. */
#define OC_MC_BLOCK 4

typedef struct oc_mcgrid {
  const oc_program *prog;
  double lo[3], hi[3]; /* the box */
  double h[3];         /* sample spacing */
  int n[3];            /* real samples per axis */
  double tmin[3];      /* vertices keep this fraction of an edge from its
                       ** samples: distinct even in single precision */
  double T;
  int steps;          /* root-finding iterations per edge (at most) */
  double newton_tol;  /* and the step, in edges, below which they stop */
  int open;           /* padding samples on the faces, no caps */
  int full;           /* ignore surface bounds */
  size_t max_samples; /* per-slab sample budget (memory guard) */
  /* the surfaces of the heightfield-like ops at T, sorted by op: they
  ** narrow the band to the surface in the columns they govern alone
  ** (mcband.c), and give direct elevation extraction (mcdirect.c) */
  const struct oc_hfsurf *surf;
  size_t nsurf;
  int direct; /* direct extraction: on, and some surface allows it */
} oc_mcgrid;

/* Coordinate of sample i on axis a; padding indices (and beyond) map to
** the box faces. Every user goes through this, so two slabs computing the
** same edge agree to the bit. */
static inline double oc_mc_coord(const oc_mcgrid *g, int a, int i) {
  if (i < 0) return g->lo[a];
  if (i >= g->n[a]) return g->hi[a];
  return g->lo[a] + ((double)i + 0.5) * g->h[a];
}

/* What a slab produces: its vertices (positions and unit normals), its
** triangles (indices local to the slab), and the vertices on the x- and
** z-edges of its first and last sample rows, which the neighbouring slabs
** share, as sorted edge keys (the same edge has the same key in both
** slabs) with local indices: [0, nb) for the first row, [nb, nk) for the
** last. */
typedef struct oc_mcout {
  float *pos, *nrm;
  size_t nv, capv;
  uint32_t *tri;
  size_t nt, capt;
  uint64_t *key;
  uint32_t *kidx;
  size_t nk, capk, nb;
  size_t calls, cells;
} oc_mcout;

typedef struct oc_mcwork oc_mcwork; /* per-thread scratch, reused */

oc_mcwork *oc_mcwork_new(void);
void oc_mcwork_free(oc_mcwork *w);
void oc_mcout_clear(oc_mcout *out);
/* Empties out but keeps its arrays, for another slab. */
void oc_mcout_reset(oc_mcout *out);

/* Meshes the cube rows ja .. jb - 1 (ja >= -1, jb <= n[1]) into *out,
** whose counts must be 0 (its arrays may be those of an earlier slab,
** reused). Returns OC_OK, or OC_ENOMEM with err filled (out
** is then to be cleared by the caller). */
int oc_mc_slab(const oc_mcgrid *g, int ja, int jb, oc_mcwork *w, oc_mcout *out,
               oc_error *err);

/* Places the vertex of the crossing edge from sample s = (i, j, k) to its
** neighbour along `axis`, given the two sample values (exactly one > T;
** padding samples are recognised by their index). Writes the position
** and the unit outward normal and returns the number of field calls
** made. *flat is set when the gradient vanished there: the normal is then
** a provisional one along the edge, for the caller to replace by the
** average of the vertex's triangles. */
int oc_mc_vertex(const oc_mcgrid *g, const int s[3], int axis, double va,
                 double vb, float pos[3], float nrm[3], int *flat);

/* The surface of the heightfield-like op `op` (OC_MC_NONE for any other
** op or when direct extraction is off), or NULL (mcdirect.c). */
const struct oc_hfsurf *oc_mc_surface(const oc_mcgrid *g, uint32_t op);
/* Whether direct extraction applies to the columns s governs. */
int oc_mc_direct_kind(const struct oc_hfsurf *s);
/* Collects g->surf for the program and threshold of g (and g->direct,
** when `direct` asks for it); g->surf is NULL
** afterwards when there is none. Returns 0, or -1 out of memory. Free
** with oc_mc_surfaces_free. */
int oc_mc_surfaces(oc_mcgrid *g, int direct);
void oc_mc_surfaces_free(oc_mcgrid *g);

/* An estimate of the triangles the mesh of g will have, from a few
** thousand field values (mcproject.c); low rather than high. A grid too
** small to ever exceed `limit` is not probed: the result is then its
** bound (at most limit). */
double oc_mc_project_triangles(const oc_mcgrid *g, double limit);

#endif
