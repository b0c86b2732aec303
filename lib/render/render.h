/*
** render.h — limits and parameter checks shared by the renderer's files,
** and the elevation renders with holes (internal).
*/
#ifndef OC_RENDER_H
#define OC_RENDER_H

#include "outcrop.h"

#define OC_RENDER_MAX_SIDE 16384
#define OC_RENDER_MAX_PIXELS (1ll << 25) /* 8K UHD fits */
#define OC_RENDER_MAX_STOPS 256
#define OC_RENDER_MAX_EV 20 /* exposure range, stops either way */

int oc_render_check_geometry(const oc_program *prog, const oc_render_params *rp,
                             oc_error *err);
/* The same for an elevation surface (etrace.h): a usable source. */
struct oc_esurface;
int oc_render_check_surface(const struct oc_esurface *es,
                            const oc_render_params *rp, oc_error *err);
int oc_render_check_shade(const oc_render_params *rp, oc_error *err);

/* oc_render_elevation and its two phases for a surface with holes (the
** weight of an oc_esurface); the public functions pass none. */
oc_image *oc_render_surface(const struct oc_esurface *es,
                            const oc_render_params *rp, oc_render_stats *st,
                            oc_error *err);
oc_image *oc_render_surface_geometry(const struct oc_esurface *es,
                                     const oc_render_params *rp, oc_error *err);
oc_image *oc_render_surface_shade(const struct oc_esurface *es,
                                  const oc_render_params *rp,
                                  const oc_image *geometry, const float *albedo,
                                  oc_error *err);

#endif
