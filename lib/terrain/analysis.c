/*
** analysis.c — helpers the terrain analysis files share: the neighbour
** tables and the making of result grids, row by row on all cores.
*/
#include <omp.h>

#include "core/error.h"
#include "terrain/analysis.h"

const int oc_heightfield_di[8] = {1, 1, 0, -1, -1, -1, 0, 1};
const int oc_heightfield_dj[8] = {0, 1, 1, 1, 0, -1, -1, -1};
const double oc_heightfield_dist[8] = {
    1, 1.41421356237309504880, 1, 1.41421356237309504880,
    1, 1.41421356237309504880, 1, 1.41421356237309504880};

oc_heightfield *oc_heightfield_like(const oc_heightfield *hf, oc_error *err) {
  double x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  /* calloc'd by the grid constructor; the caller overwrites every sample */
  return oc_heightfield_new(oc_heightfield_nx(hf), oc_heightfield_ny(hf),
                            oc_heightfield_cell(hf), x0, y0, NULL, err);
}

int oc_heightfield_each_row(oc_heightfield *out, oc_heightfield_row_fn fn,
                            const void *ctx, oc_progress pr, const char *what,
                            oc_error *err) {
  int ny = oc_heightfield_ny(out), stop = 0, done = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (int j = 0; j < ny; j++) {
    int halt;
#pragma omp atomic read
    halt = stop;
    if (halt) continue;
    fn(ctx, out, j);
    int d;
#pragma omp atomic capture
    d = ++done;
    if (pr.fn && omp_get_thread_num() == 0 && pr.fn(pr.ud, 0.99 * d / ny)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (stop || (pr.fn && pr.fn(pr.ud, 1.0)))
    return oc_seterr(err, OC_ECANCEL, "%s cancelled", what);
  return OC_OK;
}
