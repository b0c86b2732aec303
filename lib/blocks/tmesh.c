/*
** tmesh.c — a tile's blocks as meshes, one per block, for engines that
** instance meshes (Paris et al. 2020, section 4): each block's field
** polygonized over its support at the place of its centroid's cell, so a
** copy of the mesh moved by s (i, j, k) is the block in cell (i, j, k).
** The solid f > T lies strictly inside the support, so each mesh is
** closed; the field is a rounded convex hull, so the mesh is convex up to
** the polygonizer's error.
*/
#include <math.h>

#include "blocks/btile.h"
#include "core/error.h"

oc_mesh *oc_btile_mesh(const oc_btile *t, size_t i, double cell, double T,
                       oc_progress progress, oc_error *err) {
  if (!t || i >= t->nb) {
    oc_seterr(err, OC_EINVAL, "block %zu out of range (the tile has %zu)",
              i + 1, t ? t->nb : 0);
    return NULL;
  }
  if (!(cell > 0) || !isfinite(cell)) {
    oc_seterr(err, OC_EINVAL, "'cell' must be > 0 (got %g)", cell);
    return NULL;
  }
  oc_node *n = oc_bblock_node(&t->block[i], t->pp.rounding, t->pp.width, err);
  if (!n) return NULL;
  oc_compile_options co = {T, 0};
  oc_program *pr = oc_compile(n, &co, err);
  oc_node_release(n);
  if (!pr) return NULL;
  oc_polygonize_params pp = {0};
  pp.box = oc_program_bounds(pr);
  pp.cell = cell;
  pp.progress = progress;
  oc_mesh *m = oc_polygonize(pr, &pp, err);
  oc_program_free(pr);
  return m;
}
