/*
** hf_defaults.c — the defaults the front ends derive from a heightfield,
** kept here so that a C program gets the ones a script gets: the terrain
** parameters and node of a grid (outcrop.terrain without options, and the
** terrain the generators march when given none), the sea level of the sea
** generator, and a mask grid made from a grey image.
*/
#include <string.h>

#include "core/error.h"
#include "outcrop.h"

void oc_terrain_defaults(const oc_heightfield *hf, oc_terrain_params *tp) {
  memset(tp, 0, sizeof *tp);
  tp->falloff = hf ? 4 * oc_heightfield_cell(hf) : 0;
  tp->transition = 1;
}

oc_node *oc_heightfield_terrain(oc_heightfield *hf, const oc_terrain_params *tp,
                                oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "the heightfield is NULL");
    return NULL;
  }
  oc_terrain_params d;
  if (!tp) {
    oc_terrain_defaults(hf, &d);
    tp = &d;
  }
  oc_elevation src;
  if (oc_heightfield_elevation(hf, &src, err) != OC_OK) return NULL;
  oc_node *t = oc_terrain(&src, tp, err);
  src.release(src.ud); /* the node holds its own reference */
  return t;
}

/* A grid that spans 0 meets the sea there; one wholly above or below it
** gets a band a quarter of the way up its relief, so that every grid has
** a coast. */
double oc_heightfield_sea_level(const oc_heightfield *hf) {
  double lo, hi;
  if (!hf) return 0;
  oc_heightfield_minmax(hf, &lo, &hi);
  return lo < 0 && hi > 0 ? 0 : lo + 0.25 * (hi - lo);
}

oc_heightfield *oc_heightfield_load_mask(const char *path,
                                         const oc_heightfield *hf,
                                         oc_error *err) {
  oc_error e = {OC_OK, ""};
  if (!path || !hf) {
    oc_seterr(err, OC_EINVAL, "'mask' needs a path and a heightfield");
    return NULL;
  }
  oc_heightfield *m = oc_heightfield_load(path, NULL, &e);
  if (!m) {
    oc_seterr(err, e.code, "'mask': %s", e.msg);
    return NULL;
  }
  int nx = oc_heightfield_nx(m), ny = oc_heightfield_ny(m);
  double lo, hi, x0, y0;
  oc_heightfield_minmax(m, &lo, &hi);
  oc_heightfield_origin(hf, &x0, &y0);
  double cell =
      oc_heightfield_cell(hf) * (oc_heightfield_nx(hf) - 1) / (double)(nx - 1);
  oc_heightfield *s = NULL;
  if (hi > 0) s = oc_heightfield_new(nx, ny, cell, x0, y0, NULL, &e);
  if (s) {
    const float *a = oc_heightfield_samples(m);
    float *b = oc_heightfield_samples_mut(s);
    for (size_t k = 0; k < (size_t)nx * (size_t)ny; k++)
      b[k] = (float)(a[k] / hi);
  }
  oc_heightfield_release(m);
  if (!s && hi > 0)
    oc_seterr(err, e.code, "'mask': %s", e.msg);
  else if (!s)
    oc_seterr(err, OC_EINVAL, "'mask' image '%s' is black: nothing is inside",
              path);
  return s;
}
