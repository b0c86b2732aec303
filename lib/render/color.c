/*
** color.c — surface albedo for the renderer: the rule palette (sand,
** grass, rock, snow by altitude and slope), a field (e.g. a geology
** tree's resistance) through a palette of stops, colours blended by
** weights (materials, triplanar.c), and the triplanar texture variation
** of Peytavie et al. 2009, section 6 that every other source receives.
*/
#include <math.h>

#include "core/palette.h"
#include "render/shade.h"
#include "render/triplanar.h"

/* Linear-RGB albedos (measured-ish reflectances of dry materials). */
static const double ROCK[3] = {0.22, 0.18, 0.15};
static const double GRASS[3] = {0.10, 0.17, 0.05};
static const double SNOW[3] = {0.80, 0.82, 0.86};
static const double SAND[3] = {0.50, 0.42, 0.28};

#define RULE_BLEND 4.0 /* degrees over which slope rules fade */

static double smooth(double a, double b, double x) {
  if (x <= a) return 0;
  if (x >= b) return 1;
  double u = (x - a) / (b - a);
  return u * u * (3 - 2 * u);
}

static void mix(double c[3], const double d[3], double w) {
  for (int k = 0; k < 3; k++)
    c[k] += (d[k] - c[k]) * w;
}

static void rules(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double c[3]) {
  const oc_render_rules *ru = &sh->rp->rules;
  double nz = n.z > 1 ? 1 : n.z < -1 ? -1 : n.z;
  double slope = acos(nz) * (180 / 3.14159265358979323846);
  double rock =
      smooth(ru->rock_slope - RULE_BLEND, ru->rock_slope + RULE_BLEND, slope);
  for (int k = 0; k < 3; k++)
    c[k] = GRASS[k];
  double band = sh->beach > 0 ? sh->beach : 1e-9;
  double sand =
      1 - smooth(sh->sea + sh->beach, sh->sea + sh->beach + band, p.z);
  mix(c, SAND, sand);
  mix(c, ROCK, rock);
  double snow = smooth(sh->snow, sh->snow + 2 * band, p.z) *
                (1 - smooth(ru->snow_slope - RULE_BLEND,
                            ru->snow_slope + RULE_BLEND, slope));
  mix(c, SNOW, snow);
}

void oc_albedo(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double rgb[3],
               double *evals) {
  const oc_render_params *rp = sh->rp;
  if (rp->color == OC_COLOR_FIELD) {
    double v = oc_program_eval(rp->color_field, p);
    *evals += 1;
    oc_palette_eval(rp->stops, rp->nstops, v, rgb);
  } else if (rp->color == OC_COLOR_BLEND) {
    oc_blend_albedo(rp->blend_fields, rp->blend_colors, rp->nblend, rp->texture,
                    1 / sh->tex_scale, p, n, rgb, evals);
  } else {
    rules(sh, p, n, rgb);
  }
}

void oc_texture(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double rgb[3]) {
  double amp = sh->rp->texture;
  if (!(amp > 0) || sh->rp->color == OC_COLOR_BLEND) return;
  double t = oc_triplanar(p, n, 1 / sh->tex_scale, 0);
  if (t != t) return;
  double k = oc_triplanar_gain(t, amp, n.z);
  for (int c = 0; c < 3; c++)
    rgb[c] *= k;
}
