/*
** shade.c — light at a surface point: the sun (Lambert, hidden by shadow
** rays traced like primary rays), light from the sky (hemispherical,
** dimmed by ambient occlusion), and distance fog; and the colour of rays
** that miss. All radiometry is in linear RGB.
*/
#include <math.h>

#include "render/shade.h"

#define AO_SAMPLES 5

/* Ambient occlusion of an elevation surface from heights along the
** normal: leaving the surface along n, the height above it grows at
** least as fast as the distance on open ground (sqrt(1 + |grad f|^2)
** times on a plane); where it falls short, higher ground is near. The
** shortfall, relative to the distance, is the occlusion. */
static double eocclusion(const oc_shader *sh, oc_vec3 p, oc_vec3 n,
                         double *evals) {
  const oc_elevation *src = sh->es->src;
  double occ = 0, w = 0.5;
  for (int k = 1; k <= AO_SAMPLES; k++, w *= 0.5) {
    double d = k * sh->ao_step;
    oc_vec3 q = {p.x + d * n.x, p.y + d * n.y, p.z + d * n.z};
    double h = q.z - src->height(src->ud, q.x, q.y, NULL);
    *evals += 1;
    if (!isfinite(h)) return 1;
    double lack = 1 - h / d;
    occ += w * (lack < 0 ? 0 : lack > 1 ? 1 : lack);
  }
  double a = 1 - 1.5 * occ;
  return a < 0 ? 0 : a;
}

/* Ambient occlusion from field samples along the normal. Leaving a free
** surface, the field only falls (and, with compact support, soon stays
** at 0); wherever it rises again on the way out, another surface is
** near: the rise, in units of T, is the occlusion. (Comparing with the
** distance (T - f) / |grad f| a linear field would give instead darkens
** every surface whose field saturates within the sampled distance.)
** Closer samples weigh more. */
static double occlusion(const oc_shader *sh, oc_vec3 p, oc_vec3 n,
                        double *evals) {
  if (sh->es) return eocclusion(sh, p, n, evals);
  double low = oc_program_eval(sh->prog, p);
  *evals += 1;
  if (!isfinite(low)) return 1;
  double occ = 0, w = 0.5, T = fabs(sh->T) > 0 ? fabs(sh->T) : 1;
  for (int k = 1; k <= AO_SAMPLES; k++, w *= 0.5) {
    double h = k * sh->ao_step;
    oc_vec3 q = {p.x + h * n.x, p.y + h * n.y, p.z + h * n.z};
    double f = oc_program_eval(sh->prog, q);
    *evals += 1;
    double rise = (f - low) / T;
    occ += w * (rise < 0 ? 0 : rise > 1 ? 1 : rise);
    if (f < low) low = f;
  }
  double a = 1 - 1.5 * occ;
  return a < 0 ? 0 : a;
}

static double shadow(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double z,
                     double *evals) {
  if (sh->es) {
    const oc_etracer *et = &sh->etracer;
    double off = 4 * (et->eps_k * z + et->eps_min), t;
    oc_vec3 o = {p.x + off * n.x, p.y + off * n.y, p.z + off * n.z};
    return oc_etrace(et, o, sh->sun, off, sh->far, z, &t, evals) ? 0 : 1;
  }
  const oc_tracer *tr = &sh->tracer;
  /* leave the surface by a few tolerances, or the first step would stop
  ** on it */
  double off = 4 * (tr->eps_k * z + tr->eps_min);
  oc_vec3 o = {p.x + off * n.x, p.y + off * n.y, p.z + off * n.z};
  double t;
  return oc_trace(tr, o, sh->sun, off, sh->far, z, &t, evals) ? 0 : 1;
}

#define GROUND_BOUNCE 0.2

void oc_light(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double z,
              const double albedo[3], double rgb[3], double *evals) {
  const oc_render_params *rp = sh->rp;
  double ndl = n.x * sh->sun.x + n.y * sh->sun.y + n.z * sh->sun.z;
  double sun = 0;
  if (ndl > 0 && rp->sun_intensity > 0) {
    sun = ndl * rp->sun_intensity;
    if (rp->shadows) sun *= shadow(sh, p, n, z, evals);
  }
  /* the sky is above; faces turned down still get the light bounced
  ** off the ground below (a fifth of the sky's), so overhangs and the
  ** undersides of arches and floating islands are not pitch black */
  double sky = 0.5 + 0.5 * n.z + GROUND_BOUNCE * (0.5 - 0.5 * n.z);
  if (rp->ao) sky *= occlusion(sh, p, n, evals);
  double fog = rp->fog_density > 0 ? exp(-rp->fog_density * z) : 1;
  for (int k = 0; k < 3; k++) {
    double c = albedo[k] * (sun * rp->sun_color[k] + sky * rp->sky[k]);
    rgb[k] = c * fog + rp->fog_color[k] * (1 - fog);
  }
}

void oc_sky(const oc_shader *sh, oc_vec3 u, double rgba[4]) {
  const oc_render_params *rp = sh->rp;
  if (rp->has_background) {
    for (int k = 0; k < 4; k++)
      rgba[k] = rp->background[k];
    return;
  }
  /* paler towards the horizon */
  double e = u.z < 0 ? 0 : u.z;
  double w = 1 - e;
  w = w * w * w;
  for (int k = 0; k < 3; k++)
    rgba[k] = rp->sky[k] + (1 - rp->sky[k]) * 0.55 * w;
  rgba[3] = 1;
}
