/*
** shade.c — light at a surface point: the sun (Lambert, hidden by shadow
** rays traced like primary rays), light from the sky (hemispherical,
** dimmed by ambient occlusion), and distance fog; and the colour of rays
** that miss. All radiometry is in linear RGB.
*/
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "render/shade.h"

#define AO_SAMPLES OC_AO_SAMPLES

/* ---- secondary rays under a level of detail ------------------------------
** A level-of-detail source (oc_enode_elevation_view) keeps the detail a
** pixel shows where a primary ray meets it. Secondary rays need less
** (ray cones, Amanatides 1984; ray differentials, Igehy 1999): a shadow
** ray leaves the hit with the pixel's footprint F = pixel z and widens
** by the sun's angular radius (at least a pixel's angle), so detail
** finer than F + cone t at t along it changes the shadow by less than
** its penumbra's blur; an AO sample at distance d along the normal
** stands for the heights within about d of it. Both query coarser levels
** of the source (oc_elevation's coarser), made once per image: level j
** drops the detail finer than lev0 2^j, and a query asking for a
** footprint m takes the level of m rounded down (at most twice the
** detail asked; none below lev0). Sources without levels (grids, exact
** trees) are traced as they are: exact renders do not change. The
** levels are made before the tiles and only read by them (every
** thread the same levels: the image does not depend on threads). */
#define NLEV 24
/* lev0 is a pixel's footprint at 1/LEV_SPAN of the domain's diagonal:
** nearer hits (smaller footprints) start on the source itself */
#define LEV_SPAN 1024.0
/* An AO sample at distance d asks for the footprint AO_FOOT d. */
#define AO_FOOT 2.0
/* A shadow ray's footprint at t is SHADOW_FOOT F + cone t, F = pixel z
** the pixel's at the hit; its pieces span LEV_PIECE levels; its march
** starts on models from a candidate step of START_STEP F (first piece)
** or START_PIECE of the piece (the others). Measured on bench_elev_lod at
** 480 x 270 (callgrind, instructions of the shading phase; 15.0 10^9
** without levels, 0.4 10^9 without shadows and AO): with shadows, no AO,
** 11.1 10^9 without levels, SHADOW_FOOT 1, 2, 4 with START_STEP 8 (4)
** 6.6, 5.8, 8.2 (7.4, 5.9, 5.2), pieces of one level 1.2 times the CPU
** of two; with AO, no shadows, 4.3 10^9 without levels, AO_FOOT 0.5, 1,
** 2 2.9, 2.6, 2.1 (mean colour change 0.0001, 0.0003, 0.0007). */
#define SHADOW_FOOT 4.0
#define LEV_PIECE 2
#define START_STEP 4.0
#define START_PIECE 0.25

/* The level for footprint m: floor(log2(m / lev0)), at most the last; -1
** below lev0 (the source itself). */
static int level_of(const oc_shader *sh, double m) {
  if (!(m >= sh->lev0)) return -1;
  int e;
  frexp(m / sh->lev0, &e); /* m / lev0 in [2^(e - 1), 2^e) */
  return e - 1 < sh->nlev ? e - 1 : sh->nlev - 1;
}

int oc_shader_lod(oc_shader *sh, oc_error *err) {
  const oc_render_params *rp = sh->rp;
  const oc_esurface *es = sh->es;
  sh->lev = NULL;
  sh->nlev = 0;
  sh->pixel = oc_render_pixel_angle(rp);
  sh->cone = fmax(rp->sun_radius, sh->pixel);
  for (int k = 0; k < AO_SAMPLES; k++)
    sh->ao_src[k] = es ? es->src : NULL;
  if (!es || !es->src->coarser || !(rp->shadows || rp->ao)) return OC_OK;
  const oc_elevation *s = es->src;
  sh->lev0 = sh->pixel * hypot(s->x1 - s->x0, s->y1 - s->y0) / LEV_SPAN;
  if (!(sh->lev0 > 0) || !isfinite(ldexp(sh->lev0, NLEV))) return OC_OK;
  for (int k = 0; k < 3; k++)
    sh->lo[k] = sh->etracer.lo[k], sh->hi[k] = sh->etracer.hi[k];
  sh->lev = calloc(NLEV, sizeof *sh->lev);
  if (!sh->lev)
    return oc_seterr(err, OC_ENOMEM, "out of memory for the shading's levels");
  for (int j = 0; j < NLEV; j++) {
    oc_shade_level *l = &sh->lev[j];
    int rc = s->coarser(s->ud, ldexp(sh->lev0, j), &l->src, err);
    if (rc) {
      oc_shader_release(sh);
      return rc;
    }
    sh->nlev = j + 1;
    if (!rp->shadows) continue; /* (AO asks the sources alone) */
    l->es = *es;
    l->es.src = &l->src;
    l->es.weight_bound = NULL; /* (the full detail's weight's) */
    if (es->wud == s->ud) l->es.wud = l->src.ud; /* the source's own weight */
    const oc_etracer *et = &sh->etracer;
    oc_etracer_init(&l->tr, &l->es, et->mode, et->eps_k, et->eps_min);
    l->tr.refine = 0;
    for (int k = 0; k < 3; k++) {
      sh->lo[k] = fmin(sh->lo[k], l->tr.lo[k]);
      sh->hi[k] = fmax(sh->hi[k], l->tr.hi[k]);
    }
  }
  for (int k = 0; k < AO_SAMPLES; k++) {
    double d = (k + 1) * sh->ao_step; /* (as eocclusion's) */
    int j = level_of(sh, AO_FOOT * d);
    if (j >= 0) sh->ao_src[k] = &sh->lev[j].src;
  }
  return OC_OK;
}

void oc_shader_release(oc_shader *sh) {
  for (int j = 0; j < sh->nlev; j++)
    if (sh->lev[j].src.release) sh->lev[j].src.release(sh->lev[j].src.ud);
  free(sh->lev);
  sh->lev = NULL;
  sh->nlev = 0;
}

/* A shadow ray from o (off along it, hit at distance z) under a level of
** detail: in pieces, each on the level of the footprint F + cone t at its
** start, to where that footprint has grown by LEV_PIECE levels (each
** piece a march of its own: fewer, longer pieces restart less often).
** The first piece's level may lie above o (its detail below the pixel's
** is gone): where its first sample is under that level, o is lifted to
** off above it and the piece traced again (a pixel shows no shadow of
** detail it cannot show). A march on models starts from a candidate step
** of START_STEP footprints (its first piece) or START_PIECE of its piece
** (the others). Returns 1 when lit. */
static int lod_shadow(const oc_shader *sh, oc_vec3 o, double off, double z,
                      double *evals) {
  double F = SHADOW_FOOT * sh->pixel * z, t = off, th;
  int j = level_of(sh, F + sh->cone * off), lifted = j < 0;
  double t0 = t, far = sh->far; /* (to where it leaves the levels' box) */
  if (!oc_etrace_clip(sh->lo, sh->hi, o, sh->sun, &t0, &far)) return 1;
  while (t < far) {
    const oc_etracer *tr = j < 0 ? &sh->etracer : &sh->lev[j].tr;
    double t1 = far;
    if (j + LEV_PIECE < sh->nlev)
      t1 = fmin(t1, (ldexp(sh->lev0, j + LEV_PIECE) - F) / sh->cone);
    double step = t == off ? START_STEP * F : START_PIECE * (t1 - t);
    int hit =
        oc_etrace_hit(tr, o, sh->sun, t, t1, z, step, NULL, &th, NULL, evals);
    if (hit == 2 && th <= t && !lifted) {
      const oc_elevation *s = tr->s->src;
      double h = o.z - s->height(s->ud, o.x, o.y, NULL);
      *evals += 1;
      lifted = 1;
      if (h < off) {
        o.z += off - h;
        continue;
      }
    }
    if (hit) return 0;
    t = t1;
    j += LEV_PIECE;
  }
  return 1;
}

/* Ambient occlusion of an elevation surface from heights along the
** normal: leaving the surface along n, the height above it grows at
** least as fast as the distance on open ground (sqrt(1 + |grad f|^2)
** times on a plane); where it falls short, higher ground is near. The
** shortfall, relative to the distance, is the occlusion. */
static double eocclusion(const oc_shader *sh, oc_vec3 p, oc_vec3 n,
                         double *evals) {
  double occ = 0, w = 0.5;
  for (int k = 1; k <= AO_SAMPLES; k++, w *= 0.5) {
    double d = k * sh->ao_step;
    const oc_elevation *src = sh->ao_src[k - 1];
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
    if (sh->nlev) return lod_shadow(sh, o, off, z, evals);
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
