/*
** shade.h — per-pixel colour and light of the renderer (internal):
** albedo sources (rules, field palette), the triplanar variation, and
** the lighting (sun with shadow rays, sky, ambient occlusion, fog).
*/
#ifndef OC_SHADE_H
#define OC_SHADE_H

#include "outcrop.h"
#include "render/etrace.h"
#include "render/trace.h"

/* Everything shading needs, resolved once per image. */
typedef struct oc_shader {
  const oc_render_params *rp;
  const oc_program *prog; /* a field, or NULL and */
  const oc_esurface *es;  /* an elevation surface */
  oc_tracer tracer;       /* shadow rays of a field */
  oc_etracer etracer;     /* of an elevation surface */
  double T;
  oc_vec3 sun;      /* unit, towards the sun */
  double sea, snow; /* resolved rule levels */
  double beach;     /* resolved sand band */
  double ao_step;   /* metres between AO samples */
  double tex_scale; /* metres per texture period */
  double far;       /* shadow rays end there */
} oc_shader;

/* Albedo by the rules or the field palette at p with unit normal n, the
** triplanar variation not included; *evals counts field evaluations. */
void oc_albedo(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double rgb[3],
               double *evals);

/* Multiplies rgb by the triplanar texture variation at p (Peytavie et al. 2009
** section 6): three planar projections of a procedural texture blended
** by |n_i|^8, stronger on steep faces. */
void oc_texture(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double rgb[3]);

/* Linear radiance of a hit at distance z (p, n) with the given albedo. */
void oc_light(const oc_shader *sh, oc_vec3 p, oc_vec3 n, double z,
              const double albedo[3], double rgb[3], double *evals);

/* Colour of a ray that hit nothing: the background or the sky. */
void oc_sky(const oc_shader *sh, oc_vec3 u, double rgba[4]);

#endif
