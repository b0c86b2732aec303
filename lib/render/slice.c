/*
** slice.c — oc_slice: the field sampled on an axis-aligned plane, as a
** colour map with the surface f = T drawn in black, plus the raw values;
** the default window (the program's bounds) and recolouring through a
** palette.
**
** Two passes over rows: the field first (stored in the image's "field"
** channel), then colours, which need each pixel's four neighbours. Each
** pixel depends only on its own position, so the result is the same for
** any thread count and schedule. Sizes are capped as the renderer's
** (OC_RENDER_MAX_PIXELS): 2^25 pixels of 5 floats are 640 MiB already.
*/
#include <math.h>

#include "core/error.h"
#include "outcrop.h"
#include "render/render.h"

#define MAX_SIDE OC_RENDER_MAX_SIDE
#define NCH 5 /* R, G, B, A, field */
#define FIELD 4

static int check(const oc_program *prog, const oc_slice_params *sp,
                 oc_error *err) {
  if (!prog) return oc_seterr(err, OC_EINVAL, "'program' is NULL");
  if (!sp) return oc_seterr(err, OC_EINVAL, "slice parameters are NULL");
  if (sp->plane != OC_PLANE_XY && sp->plane != OC_PLANE_XZ &&
      sp->plane != OC_PLANE_YZ)
    return oc_seterr(err, OC_EINVAL,
                     "'plane' must be \"xy\", \"xz\" or \"yz\"");
  if (sp->width < 1 || sp->width > MAX_SIDE)
    return oc_seterr(err, OC_EINVAL, "'width' must be in 1..%d (got %d)",
                     MAX_SIDE, sp->width);
  if (sp->height < 1 || sp->height > MAX_SIDE)
    return oc_seterr(err, OC_EINVAL, "'height' must be in 1..%d (got %d)",
                     MAX_SIDE, sp->height);
  long long px = (long long)sp->width * sp->height;
  if (px > OC_RENDER_MAX_PIXELS)
    return oc_seterr(err, OC_ENOMEM,
                     "'size' %d x %d is %lld pixels, over the limit of %lld "
                     "(%lld MiB of %d float channels)",
                     sp->width, sp->height, px, (long long)OC_RENDER_MAX_PIXELS,
                     OC_RENDER_MAX_PIXELS * NCH * 4 >> 20, NCH);
  if (!isfinite(sp->at))
    return oc_seterr(err, OC_EINVAL, "'at' must be finite (got %g)", sp->at);
  /* The spans must be finite too, or pixel centres would be inf or NaN. */
  if (!isfinite(sp->u0) || !isfinite(sp->u1) || !(sp->u0 < sp->u1) ||
      !isfinite(sp->u1 - sp->u0))
    return oc_seterr(err, OC_EINVAL,
                     "'u0' and 'u1' must be finite with u0 < u1 (got %g, %g)",
                     sp->u0, sp->u1);
  if (!isfinite(sp->v0) || !isfinite(sp->v1) || !(sp->v0 < sp->v1) ||
      !isfinite(sp->v1 - sp->v0))
    return oc_seterr(err, OC_EINVAL,
                     "'v0' and 'v1' must be finite with v0 < v1 (got %g, %g)",
                     sp->v0, sp->v1);
  return OC_OK;
}

static oc_vec3 plane_point(oc_plane_axis plane, double u, double v, double at) {
  oc_vec3 p;
  switch (plane) {
  case OC_PLANE_XZ:
    p.x = u, p.y = at, p.z = v;
    break;
  case OC_PLANE_YZ:
    p.x = at, p.y = u, p.z = v;
    break;
  default:
    p.x = u, p.y = v, p.z = at;
    break;
  }
  return p;
}

static void mix(float *rgb, const float a[3], const float b[3], double t) {
  for (int c = 0; c < 3; c++)
    rgb[c] = (float)(a[c] + (b[c] - a[c]) * t);
}

/* The diverging map. Warm inside (tan at T to dark brown at 2T and
** above), cool outside (pale to mid blue over (0, T)), near-white where
** f is exactly 0 so that the edge of every support shows, purple for
** carving (negative) values, growing darker down to -T. */
static void colour(float f, double T, float *rgb) {
  static const float tan_[3] = {0.87f, 0.75f, 0.55f};
  static const float brown[3] = {0.33f, 0.19f, 0.07f};
  static const float pale[3] = {0.80f, 0.88f, 0.97f};
  static const float blue[3] = {0.35f, 0.55f, 0.85f};
  static const float white[3] = {0.97f, 0.97f, 0.95f};
  static const float lilac[3] = {0.80f, 0.70f, 0.90f};
  static const float purple[3] = {0.35f, 0.10f, 0.50f};
  static const float nan_[3] = {0.0f, 1.0f, 0.0f};
  double unit = T > 0 ? T : 1.0;
  if (isnan(f))
    mix(rgb, nan_, nan_, 0);
  else if (f > T)
    mix(rgb, tan_, brown, fmin((f - T) / unit, 1.0));
  else if (f > 0)
    mix(rgb, pale, blue, fmin(f / unit, 1.0));
  else if (f == 0)
    mix(rgb, white, white, 0);
  else
    mix(rgb, lilac, purple, fmin(-f / unit, 1.0));
}

/* A pixel is on the iso-line when a 4-neighbour lies on the other side of
** T and this pixel is at least as close to T: one pixel of the two that
** straddle the surface, so the line is about one pixel wide. */
static int on_line(const float *img, int w, int h, int i, int j, double T) {
  static const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
  float f = img[((size_t)j * w + i) * NCH + FIELD];
  if (isnan(f)) return 0;
  int in = f > T;
  for (int k = 0; k < 4; k++) {
    int ni = i + di[k], nj = j + dj[k];
    if (ni < 0 || ni >= w || nj < 0 || nj >= h) continue;
    float g = img[((size_t)nj * w + ni) * NCH + FIELD];
    if (isnan(g) || (g > T) == in) continue;
    if (fabs(f - T) <= fabs(g - T)) return 1;
  }
  return 0;
}

oc_image *oc_slice(const oc_program *prog, const oc_slice_params *sp,
                   oc_error *err) {
  if (check(prog, sp, err)) return NULL;
  oc_image *img = oc_image_new(sp->width, sp->height, NCH, err);
  if (!img) return NULL;
  oc_image_set_channel_name(img, FIELD, "field", NULL);
  float *px = oc_image_data(img);
  const int w = sp->width, h = sp->height;
  const double du = (sp->u1 - sp->u0) / w, dv = (sp->v1 - sp->v0) / h;
  const double T = oc_program_threshold(prog);

#pragma omp parallel for schedule(dynamic)
  for (int j = 0; j < h; j++) {
    double v = sp->v1 - (j + 0.5) * dv;
    for (int i = 0; i < w; i++) {
      double u = sp->u0 + (i + 0.5) * du;
      oc_vec3 p = plane_point(sp->plane, u, v, sp->at);
      px[((size_t)j * w + i) * NCH + FIELD] = (float)oc_program_eval(prog, p);
    }
  }

#pragma omp parallel for schedule(dynamic)
  for (int j = 0; j < h; j++) {
    for (int i = 0; i < w; i++) {
      float *q = px + ((size_t)j * w + i) * NCH;
      if (on_line(px, w, h, i, j, T))
        q[0] = q[1] = q[2] = 0.0f;
      else
        colour(q[FIELD], T, q);
      q[3] = 1.0f;
    }
  }
  return img;
}

int oc_slice_default_window(const oc_program *prog, oc_slice_params *sp,
                            oc_error *err) {
  if (!prog) return oc_seterr(err, OC_EINVAL, "'program' is NULL");
  if (!sp) return oc_seterr(err, OC_EINVAL, "slice parameters are NULL");
  oc_aabb b = oc_program_bounds(prog);
  double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  int u = sp->plane == OC_PLANE_YZ ? 1 : 0;
  int v = sp->plane == OC_PLANE_XY ? 1 : 2;
  if (!(isfinite(lo[u]) && isfinite(lo[v]) && isfinite(hi[u]) &&
        isfinite(hi[v])))
    return oc_seterr(err, OC_EINVAL,
                     "the node's bounds are infinite: give 'box' = "
                     "{u0, v0, u1, v1}");
  sp->u0 = lo[u], sp->v0 = lo[v], sp->u1 = hi[u], sp->v1 = hi[v];
  return OC_OK;
}

int oc_slice_apply_palette(oc_image *img, const double *stops, int n,
                           oc_error *err) {
  if (!img) return oc_seterr(err, OC_EINVAL, "'image' is NULL");
  if (oc_image_channels(img) != NCH)
    return oc_seterr(err, OC_EINVAL,
                     "'image' must be a slice (%d channels, got %d)", NCH,
                     oc_image_channels(img));
  int rc = oc_palette_check(stops, n, err);
  if (rc) return rc;
  float *px = oc_image_data(img);
  size_t npx = (size_t)oc_image_width(img) * (size_t)oc_image_height(img);
  for (size_t i = 0; i < npx; i++) {
    float *q = px + i * NCH;
    double rgb[3];
    oc_palette_eval(stops, n, q[FIELD], rgb);
    q[0] = (float)rgb[0], q[1] = (float)rgb[1], q[2] = (float)rgb[2];
    q[3] = 1;
  }
  return OC_OK;
}
