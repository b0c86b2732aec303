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
/* (oc_render_check_surface, oc_render_check_shade and the surface
** renders are public: outcrop.h.) */

#endif
