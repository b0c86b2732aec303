/*
** analysis.c — helpers the terrain analysis files share: the neighbour
** tables and the making of result grids.
*/
#include "terrain/analysis.h"

const int oc_hf_di[8] = {1, 1, 0, -1, -1, -1, 0, 1};
const int oc_hf_dj[8] = {0, 1, 1, 1, 0, -1, -1, -1};
const double oc_hf_dist[8] = {
    1, 1.41421356237309504880, 1, 1.41421356237309504880,
    1, 1.41421356237309504880, 1, 1.41421356237309504880};

oc_heightfield *oc_hf_like(const oc_heightfield *hf, oc_error *err) {
  double x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  /* calloc'd by the grid constructor; the caller overwrites every sample */
  return oc_heightfield_new(oc_heightfield_nx(hf), oc_heightfield_ny(hf),
                            oc_heightfield_cell(hf), x0, y0, NULL, err);
}
