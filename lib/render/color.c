/*
** color.c — surface albedo for the renderer: the rule palette (sand,
** grass, rock, snow by altitude and slope), a field (e.g. a geology
** tree's resistance) through a palette of stops, and the triplanar
** texture variation of Peytavie et al. 2009, section 6 that every source
** receives.
*/
#include <math.h>

#include "core/palette.h"
#include "core/noise.h"
#include "render/shade.h"

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
  } else {
    rules(sh, p, n, rgb);
  }
}

/* A 2D texture in [0, 1]: two octaves of simplex noise, stretched along
** u so that steep faces show horizontal bands like strata. */
static double tex2(double u, double v, uint64_t plane) {
  oc_vec3 q = {u * 0.35, v * 2.0, 0.5};
  return oc_turb3(0x7e57u + plane, 3, q, NULL) / oc_turb3_max(3);
}

void oc_texture(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double rgb[3]) {
  double amp = sh->rp->texture;
  if (!(amp > 0)) return;
  double s = 1 / sh->tex_scale;
  double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
  /* weights |n_i|^8, normalised (p = 8 as in the paper) */
  double wx = ax * ax, wy = ay * ay, wz = az * az;
  wx *= wx, wy *= wy, wz *= wz;
  wx *= wx, wy *= wy, wz *= wz;
  double sum = wx + wy + wz;
  if (!(sum > 0)) return;
  /* the projection along x sees (y, z), and so on */
  double t = (wx * tex2(p.y * s, p.z * s, 0) + wy * tex2(p.x * s, p.z * s, 1) +
              wz * tex2(p.x * s, p.y * s, 2)) /
             sum;
  double steep = 0.35 + 0.65 * (1 - az);
  double k = 1 + amp * steep * 2 * (t - 0.5);
  if (k < 0) k = 0;
  for (int c = 0; c < 3; c++)
    rgb[c] *= k;
}
