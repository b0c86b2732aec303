/*
** sinks.c — oc_heightfield_sinks: the pits of a grid, interior samples strictly
** lower than all eight neighbours.
**
** Border samples are never pits: water can leave the grid there, which is
** also where depression filling lets it out. A depression with a flat
** bottom of two or more equal samples has no sample strictly lower than
** all its neighbours and is not reported (compare the grid with its
** filled version to find every depression).
*/
#include <stdlib.h>

#include "core/error.h"
#include "terrain/analysis.h"

static int is_pit(const float *z, int nx, int i, int j) {
  const float *c = z + (size_t)j * (size_t)nx + (size_t)i;
  for (int k = 0; k < 8; k++)
    if (!(c[0] <
          c[oc_heightfield_dj[k] * (ptrdiff_t)nx + oc_heightfield_di[k]]))
      return 0;
  return 1;
}

int oc_heightfield_sinks(const oc_heightfield *hf, oc_vec3 **out, size_t *n,
                         oc_error *err) {
  if (!out || !n) return oc_seterr(err, OC_EINVAL, "sinks needs out and n");
  *out = NULL;
  *n = 0;
  if (!hf) return oc_seterr(err, OC_EINVAL, "sinks needs a heightfield");
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  const float *z = oc_heightfield_samples(hf);
  double cell = oc_heightfield_cell(hf), x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  size_t count = 0;
  for (int j = 1; j < ny - 1; j++)
    for (int i = 1; i < nx - 1; i++)
      count += (size_t)is_pit(z, nx, i, j);
  if (count == 0) return OC_OK;
  oc_vec3 *p = malloc(count * sizeof *p);
  if (!p)
    return oc_seterr(err, OC_ENOMEM, "out of memory for %zu sinks", count);
  size_t m = 0;
  for (int j = 1; j < ny - 1; j++)
    for (int i = 1; i < nx - 1; i++)
      if (is_pit(z, nx, i, j))
        p[m++] = (oc_vec3){x0 + i * cell, y0 + j * cell,
                           z[(size_t)j * (size_t)nx + (size_t)i]};
  *out = p;
  *n = m;
  return OC_OK;
}
