/*
** params.c — the renderer's parameters: their defaults and their checks.
** Messages name each parameter as the Lua table field that sets it, so a
** script sees which of its fields is wrong.
*/
#include <math.h>

#include "core/error.h"
#include "core/vec.h"
#include "render/etrace.h"
#include "render/render.h"
#include "render/triplanar.h"

void oc_render_defaults(oc_render_params *rp) {
  static const oc_render_params d = {
      .camera = {{0, -100, 50}, {0, 0, 0}, {0, 0, 1}, 40},
      .width = 640,
      .height = 360,
      .sun_direction = {-0.5, -0.4, 0.77},
      .sun_color = {1, 0.95, 0.86},
      .sun_intensity = 2.2,
      .sun_radius = 0.00465, /* the sun's, seen from the Earth */
      .sky = {0.45, 0.6, 0.85},
      .shadows = 1,
      .ao = 1,
      .fog_color = {0.45, 0.6, 0.85},
      .background = {0, 0, 0, 0},
      .texture = 0.3,
      .rules = {.rock_slope = 38, .snow_slope = 45},
      .aov = 1,
  };
  *rp = d;
}

static int finite3(oc_vec3 v) {
  return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static int color_ok(const double *c, int n, double hi) {
  for (int k = 0; k < n; k++)
    if (!(c[k] >= 0 && c[k] <= hi)) return 0;
  return 1;
}

static int check_camera(const oc_camera *c, oc_error *err) {
  if (!finite3(c->eye))
    return oc_seterr(err, OC_EINVAL, "'camera.eye' must be finite");
  if (!finite3(c->target))
    return oc_seterr(err, OC_EINVAL, "'camera.target' must be finite");
  if (!finite3(c->up))
    return oc_seterr(err, OC_EINVAL, "'camera.up' must be finite");
  oc_vec3 w = oc_sub(c->target, c->eye);
  double lw = oc_len(w);
  if (!(lw > 0) || !isfinite(lw))
    return oc_seterr(err, OC_EINVAL,
                     "'camera.target' must differ from 'camera.eye' (and "
                     "their distance be finite)");
  double lu = oc_len(c->up);
  if (!(lu > 0) || oc_len(oc_cross(w, c->up)) <= 1e-9 * lw * lu)
    return oc_seterr(err, OC_EINVAL,
                     "'camera.up' must be non-zero and not parallel to the "
                     "view direction");
  char b[OC_NUMSTR];
  if (!(c->fov > 0 && c->fov <= 179))
    return oc_seterr(err, OC_EINVAL,
                     "'camera.fov' must be in (0, 179] degrees (got %s)",
                     oc_numstr(c->fov, b));
  return OC_OK;
}

/* Checks what tracing needs, whatever is traced. */
static int check_trace(const oc_render_params *rp, oc_error *err) {
  if (!rp) return oc_seterr(err, OC_EINVAL, "render parameters are NULL");
  if (rp->width < 1 || rp->width > OC_RENDER_MAX_SIDE)
    return oc_seterr(err, OC_EINVAL, "'size' width must be in 1..%d (got %d)",
                     OC_RENDER_MAX_SIDE, rp->width);
  if (rp->height < 1 || rp->height > OC_RENDER_MAX_SIDE)
    return oc_seterr(err, OC_EINVAL, "'size' height must be in 1..%d (got %d)",
                     OC_RENDER_MAX_SIDE, rp->height);
  long long px = (long long)rp->width * rp->height;
  if (px > OC_RENDER_MAX_PIXELS)
    return oc_seterr(
        err, OC_ENOMEM,
        "'size' %d x %d is %lld pixels, over the limit of %lld "
        "(%d MiB of buffers)",
        rp->width, rp->height, px, (long long)OC_RENDER_MAX_PIXELS,
        (int)(OC_RENDER_MAX_PIXELS * 4 * (OC_RG_COUNT + 12) >> 20));
  int rc = check_camera(&rp->camera, err);
  if (rc) return rc;
  if (!isfinite(rp->threshold))
    return oc_seterr(err, OC_EINVAL, "'threshold' must be finite (got %g)",
                     rp->threshold);
  if (!(rp->max_distance >= 0) || isinf(rp->max_distance))
    return oc_seterr(err, OC_EINVAL,
                     "'max_distance' must be finite and >= 0 (got %g)",
                     rp->max_distance);
  if (rp->tracer != OC_TRACE_SEGMENT && rp->tracer != OC_TRACE_SPHERE)
    return oc_seterr(err, OC_EINVAL,
                     "'tracer' must be \"segment\" or "
                     "\"sphere\"");
  return OC_OK;
}

int oc_render_check_geometry(const oc_program *prog, const oc_render_params *rp,
                             oc_error *err) {
  if (!prog) return oc_seterr(err, OC_EINVAL, "'program' is NULL");
  return check_trace(rp, err);
}

int oc_render_check_surface(const oc_esurface *es, const oc_render_params *rp,
                            oc_error *err) {
  const oc_elevation *src = es ? es->src : NULL;
  if (!src) return oc_seterr(err, OC_EINVAL, "'source' is NULL");
  if (!src->height || !src->range || !src->slope)
    return oc_seterr(err, OC_EINVAL,
                     "the elevation source lacks its height, range or slope "
                     "function");
  if (!(isfinite(src->x0) && isfinite(src->x1) && isfinite(src->y0) &&
        isfinite(src->y1) && src->x0 < src->x1 && src->y0 < src->y1))
    return oc_seterr(err, OC_EINVAL,
                     "the elevation source's domain must be finite and not "
                     "empty (got [%g, %g] x [%g, %g])",
                     src->x0, src->x1, src->y0, src->y1);
  if (es->weight && !isfinite(es->T))
    return oc_seterr(err, OC_EINVAL,
                     "'threshold' of the weight must be finite (got %g)",
                     es->T);
  return check_trace(rp, err);
}

static int check_rules(const oc_render_rules *r, oc_error *err) {
  /* NaN: that level is derived from the visible altitudes */
  if (r->levels && (isinf(r->sea_level) || isinf(r->snow_line)))
    return oc_seterr(err, OC_EINVAL,
                     "'sea_level' and 'snow_line' must be finite or NaN (got "
                     "%g, %g)",
                     r->sea_level, r->snow_line);
  if (!(r->beach >= 0) || isinf(r->beach))
    return oc_seterr(err, OC_EINVAL, "'beach' must be finite and >= 0 (got %g)",
                     r->beach);
  if (!(r->rock_slope >= 0 && r->rock_slope <= 90))
    return oc_seterr(err, OC_EINVAL,
                     "'rock_slope' must be in [0, 90] degrees (got %g)",
                     r->rock_slope);
  if (!(r->snow_slope >= 0 && r->snow_slope <= 90))
    return oc_seterr(err, OC_EINVAL,
                     "'snow_slope' must be in [0, 90] degrees (got %g)",
                     r->snow_slope);
  return OC_OK;
}

static int check_stops(const double *st, int n, oc_error *err) {
  if (!st || n < 1 || n > OC_RENDER_MAX_STOPS)
    return oc_seterr(err, OC_EINVAL, "'palette' must have 1..%d stops (got %d)",
                     OC_RENDER_MAX_STOPS, st ? n : 0);
  for (int i = 0; i < n; i++) {
    const double *s = st + 4 * i;
    if (!isfinite(s[0]))
      return oc_seterr(err, OC_EINVAL,
                       "'palette' stop %d: value must be finite (got %g)",
                       i + 1, s[0]);
    if (i && !(s[0] >= s[-4]))
      return oc_seterr(err, OC_EINVAL,
                       "'palette' stop %d: values must ascend (%g after %g)",
                       i + 1, s[0], s[-4]);
    if (!color_ok(s + 1, 3, 1))
      return oc_seterr(err, OC_EINVAL,
                       "'palette' stop %d: colour components must be in "
                       "[0, 1]",
                       i + 1);
  }
  return OC_OK;
}

/* Checks what shading needs. */
int oc_render_check_shade(const oc_render_params *rp, oc_error *err) {
  oc_vec3 s = rp->sun_direction;
  if (!finite3(s) || !(oc_len(s) > 0))
    return oc_seterr(err, OC_EINVAL,
                     "'sun.direction' must be a finite non-zero vector");
  if (!color_ok(rp->sun_color, 3, 1e6))
    return oc_seterr(err, OC_EINVAL,
                     "'sun.color' components must be finite and >= 0");
  char b[OC_NUMSTR];
  if (!(rp->sun_intensity >= 0) || isinf(rp->sun_intensity))
    return oc_seterr(err, OC_EINVAL,
                     "'sun.intensity' must be finite and >= 0 (got %s)",
                     oc_numstr(rp->sun_intensity, b));
  if (!(rp->sun_radius >= 0 && rp->sun_radius <= 0.1))
    return oc_seterr(err, OC_EINVAL,
                     "'sun.radius' must be in [0, 0.1] radians (got %s)",
                     oc_numstr(rp->sun_radius, b));
  if (!color_ok(rp->sky, 3, 1e6))
    return oc_seterr(err, OC_EINVAL,
                     "'sky' components must be finite and >= 0");
  if (!color_ok(rp->fog_color, 3, 1e6))
    return oc_seterr(err, OC_EINVAL,
                     "'fog_color' components must be finite and >= 0");
  if (!(rp->fog_density >= 0) || isinf(rp->fog_density))
    return oc_seterr(err, OC_EINVAL,
                     "'fog' density must be finite and >= 0 (got %g)",
                     rp->fog_density);
  if (rp->has_background && !color_ok(rp->background, 4, 1e6))
    return oc_seterr(err, OC_EINVAL,
                     "'background' components must be finite and >= 0");
  if (!(rp->ao_distance >= 0) || isinf(rp->ao_distance))
    return oc_seterr(err, OC_EINVAL,
                     "'ao_distance' must be finite and >= 0 (got %g)",
                     rp->ao_distance);
  if (!(rp->texture >= 0 && rp->texture <= 1))
    return oc_seterr(err, OC_EINVAL, "'texture' must be in [0, 1] (got %g)",
                     rp->texture);
  if (!(rp->texture_scale >= 0) || isinf(rp->texture_scale))
    return oc_seterr(err, OC_EINVAL,
                     "'texture_scale' must be finite and >= 0 (got %g)",
                     rp->texture_scale);
  if (!(rp->exposure >= -OC_RENDER_MAX_EV && rp->exposure <= OC_RENDER_MAX_EV))
    return oc_seterr(err, OC_EINVAL,
                     "'exposure' must be in [%d, %d] stops (got %g)",
                     -OC_RENDER_MAX_EV, OC_RENDER_MAX_EV, rp->exposure);
  if (rp->tone != OC_TONE_CLAMP && rp->tone != OC_TONE_FILMIC)
    return oc_seterr(err, OC_EINVAL,
                     "'tone' must be \"clamp\" or \"filmic\" (got %d)",
                     (int)rp->tone);
  if (rp->color == OC_COLOR_RULES) return check_rules(&rp->rules, err);
  if (rp->color == OC_COLOR_FIELD) {
    if (!rp->color_field)
      return oc_seterr(err, OC_EINVAL, "'color' field program is NULL");
    return check_stops(rp->stops, rp->nstops, err);
  }
  if (rp->color == OC_COLOR_BLEND)
    return oc_blend_check(rp->blend_fields, rp->blend_colors, rp->nblend, err);
  return oc_seterr(err, OC_EINVAL, "'color' source is unknown (%d)",
                   (int)rp->color);
}

int oc_render_check(const oc_program *prog, const oc_render_params *rp,
                    oc_error *err) {
  int rc = oc_render_check_geometry(prog, rp, err);
  return rc ? rc : oc_render_check_shade(rp, err);
}
