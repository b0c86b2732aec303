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

/* Heights an elevation surface's ambient occlusion samples. */
#define OC_AO_SAMPLES 5

/* A coarser level of a level-of-detail source (oc_elevation's coarser)
** with its surface and its shadow rays' tracer. */
typedef struct oc_shade_level {
  oc_elevation src;
  oc_esurface es;
  oc_etracer tr;
} oc_shade_level;

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
  /* Secondary rays of a level-of-detail source (oc_shader_lod): level j
  ** drops the detail finer than lev0 2^j; none when nlev is 0. */
  oc_shade_level *lev;
  int nlev;
  double lev0;
  double lo[3], hi[3]; /* the box of every level's tracer */
  double pixel;        /* a pixel's angle (oc_render_pixel_angle) */
  double cone;         /* a shadow ray's footprint widens by cone a metre */
  /* the source each AO sample of an elevation surface queries */
  const oc_elevation *ao_src[OC_AO_SAMPLES];
} oc_shader;

/* Makes the coarser levels of sh's source for its shadow rays and AO
** (none for fields and sources without levels), once sh's other fields
** are set; oc_shader_release frees them (and may be called after a
** failure). OC_OK, or an error code with err. */
int oc_shader_lod(oc_shader *sh, oc_error *err);
void oc_shader_release(oc_shader *sh);

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
