/*
** framing.c — oc_render_default_camera: the view a render takes when the
** caller gives no camera, looking at the centre of the program's bounds
** from the south-west, 30 degrees up, just far enough for the corners of
** the bounds to fit the view. Front ends call it so that every one of them
** frames a scene the same way.
*/
#include <math.h>

#include "core/error.h"
#include "outcrop.h"

/* From the south-west, 30 degrees above the horizon. */
#define VIEW_AZIMUTH (-135.0)
#define VIEW_ELEVATION 30.0
#define PI 3.14159265358979323846

int oc_render_default_camera(const oc_program *prog, oc_render_params *rp,
                             int has_eye, int has_target, oc_error *err) {
  if (!prog) return oc_seterr(err, OC_EINVAL, "'program' is NULL");
  return oc_render_frame_box(oc_program_bounds(prog), rp, has_eye, has_target,
                             err);
}

int oc_render_frame_box(oc_aabb b, oc_render_params *rp, int has_eye,
                        int has_target, oc_error *err) {
  if (!rp) return oc_seterr(err, OC_EINVAL, "render parameters are NULL");
  if (has_eye && has_target) return OC_OK;
  double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  for (int k = 0; k < 3; k++) {
    if (lo[k] > hi[k])
      return oc_seterr(err, OC_EINVAL,
                       "the node's bounds are empty (its field is 0 "
                       "everywhere): give 'camera' = {eye =, target =}");
    if (!isfinite(lo[k]) || !isfinite(hi[k]))
      return oc_seterr(err, OC_EINVAL,
                       "the node's bounds are infinite: give 'camera' = "
                       "{eye =, target =}");
  }
  char f[OC_NUMSTR];
  if (!(rp->camera.fov > 0 && rp->camera.fov <= 179))
    return oc_seterr(err, OC_EINVAL,
                     "'camera.fov' must be in (0, 179] degrees (got %s)",
                     oc_numstr(rp->camera.fov, f));
  if (rp->width < 1 || rp->height < 1)
    return oc_seterr(err, OC_EINVAL,
                     "'size' must be at least 1 x 1 (got %d x %d)", rp->width,
                     rp->height);
  double c[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
  if (!has_target) rp->camera.target = (oc_vec3){c[0], c[1], c[2]};
  if (has_eye) return OC_OK;
  /* Viewing direction (from the eye to the target) and the camera's
  ** right and up vectors; an up along the view cannot frame. */
  double az = VIEW_AZIMUTH * PI / 180, el = VIEW_ELEVATION * PI / 180;
  double fw[3] = {-cos(el) * cos(az), -cos(el) * sin(az), -sin(el)};
  oc_vec3 u = rp->camera.up;
  double rt[3] = {fw[1] * u.z - fw[2] * u.y, fw[2] * u.x - fw[0] * u.z,
                  fw[0] * u.y - fw[1] * u.x};
  double n = sqrt(rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]);
  if (!(n > 1e-9 * sqrt(u.x * u.x + u.y * u.y + u.z * u.z)))
    return oc_seterr(err, OC_EINVAL,
                     "'camera.up' is parallel to the default view direction: "
                     "give 'camera.eye'");
  for (int k = 0; k < 3; k++)
    rt[k] /= n;
  double up[3] = {rt[1] * fw[2] - rt[2] * fw[1], rt[2] * fw[0] - rt[0] * fw[2],
                  rt[0] * fw[1] - rt[1] * fw[0]};
  double tv = tan(rp->camera.fov * PI / 360);
  double th = tv * (double)rp->width / (double)rp->height;
  double t[3] = {rp->camera.target.x, rp->camera.target.y, rp->camera.target.z};
  double dist = 0, radius = 0;
  for (int corner = 0; corner < 8; corner++) {
    double q[3], x = 0, y = 0, z = 0;
    for (int k = 0; k < 3; k++) {
      q[k] = ((corner >> k) & 1 ? hi[k] : lo[k]) - t[k];
      x += q[k] * rt[k], y += q[k] * up[k], z += q[k] * fw[k];
    }
    /* The corner is in view when |x| <= th (dist + z), |y| <= tv (dist + z). */
    dist = fmax(dist, fmax(fabs(x) / th, fabs(y) / tv) - z);
    radius = fmax(radius, sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]));
  }
  /* A small margin, and never inside the bounds' sphere. */
  dist = fmax(1.04 * dist, 1.01 * radius);
  if (!(dist > 0)) dist = 1;
  rp->camera.eye =
      (oc_vec3){t[0] - dist * fw[0], t[1] - dist * fw[1], t[2] - dist * fw[2]};
  return OC_OK;
}
