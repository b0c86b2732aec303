/*
** render.c — oc_render and its two phases: primary rays into a geometry
** image (hit, distance, normal, position, evaluation count per pixel),
** then colour and light into the final image. The same two phases render
** a 3D field (trace.c) or an elevation surface (etrace.c, oc_render_elevation):
** only the tracer, the normals, the shadow rays and the occlusion differ.
**
** Pixels are independent, and each depends only on its own ray, so the
** image is byte-identical for any thread count: tiles are handed out
** dynamically over both cores, and only their order varies. Nothing is
** allocated per pixel.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "render/etrace.h"
#include "render/render.h"
#include "render/shade.h"
#include "render/tone.h"
#include "render/trace.h"
#include "terrain/terrain.h"

#define TILE 16
/* Beams of elevation surfaces split down to blocks this many pixels a
** side: BEAM_MIN_MODELS for sources with first-order models (the beams go
** on on them), BEAM_MIN for the others (elevation ranges alone); their
** rays begin on the source's models with PIXEL_STEP times the beam's
** last candidate step. Measured on bench_elev -qq fig3 (calls a pixel):
** blocks down to 4, 2 and 1 pixels gave 13.7, 12.9 and 18.8 (rays from
** box steps); PIXEL_STEP 1, 2, 4, 8, 16 gave 12.8, 12.2, 12.1, 12.3,
** 12.9 against 12.7 from box steps. On bench_elev hf (no models) 2
** pixels took 5.0 to 4.5 calls a pixel but 6 % more CPU than 4. */
#define BEAM_MIN 4
#define BEAM_MIN_MODELS 2
#define PIXEL_STEP 4
#define NAOV 8
#define GEOM_SHARE 0.7 /* oc_render's progress: tracing, then shading */
/* Hit tolerance: this fraction of a pixel's angular size. */
#define EPS_PIXEL 0.25

static const char *const geom_names[OC_RG_COUNT] = {
    "hit", "Z", "N.x", "N.y", "N.z", "P.x", "P.y", "P.z", "evals"};
static const char *const aov_names[NAOV] = {"Z",   "N.x", "N.y", "N.z",
                                            "P.x", "P.y", "P.z", "evals"};

typedef struct camera {
  oc_vec3 eye, w, right, up; /* w forward, right x up the image plane */
  double th, aspect;         /* tan(fov / 2), width / height */
  int width, height;
  double scale; /* |target - eye|: the scene's scale for defaults */
} camera;

static void camera_init(camera *c, const oc_render_params *rp) {
  const oc_camera *k = &rp->camera;
  c->eye = k->eye;
  oc_vec3 w = oc_sub(k->target, k->eye);
  c->scale = oc_len(w);
  c->w = oc_mul(w, 1 / c->scale);
  oc_vec3 r = oc_cross(c->w, k->up);
  c->right = oc_mul(r, 1 / oc_len(r));
  c->up = oc_cross(c->right, c->w);
  c->th = tan(k->fov * (3.14159265358979323846 / 360));
  c->width = rp->width;
  c->height = rp->height;
  c->aspect = (double)rp->width / rp->height;
}

/* The direction w + x right + y up through the centre of pixel (i, j),
** row 0 on top: at least 1 long (the frame is orthonormal). */
static oc_vec3 ray_vec(const camera *c, int i, int j) {
  double x = (2 * (i + 0.5) / c->width - 1) * c->th * c->aspect;
  double y = (1 - 2 * (j + 0.5) / c->height) * c->th;
  return oc_add(c->w, oc_add(oc_mul(c->right, x), oc_mul(c->up, y)));
}

/* The unit direction through the centre of pixel (i, j). */
static oc_vec3 ray_dir(const camera *c, int i, int j) {
  oc_vec3 d = ray_vec(c, i, j);
  return oc_mul(d, 1 / oc_len(d));
}

/* The beam of the rays through pixels [i0, i1) x [j0, j1), to their
** edges. */
static void beam_for(const camera *c, int i0, int j0, int i1, int j1,
                     oc_ebeam *b) {
  b->o = c->eye, b->w = c->w, b->r = c->right, b->v = c->up;
  b->x0 = (2.0 * i0 / c->width - 1) * c->th * c->aspect;
  b->x1 = (2.0 * i1 / c->width - 1) * c->th * c->aspect;
  b->y0 = (1 - 2.0 * j1 / c->height) * c->th;
  b->y1 = (1 - 2.0 * j0 / c->height) * c->th;
}

static double resolve_T(const oc_program *prog, const oc_render_params *rp) {
  return rp->threshold != 0 ? rp->threshold : oc_program_threshold(prog);
}

static void tracer_for(oc_tracer *tr, const oc_program *prog,
                       const oc_render_params *rp, const camera *c) {
  double pixel = 2 * c->th / c->height;
  oc_tracer_init(tr, prog, resolve_T(prog, rp), rp->tracer, EPS_PIXEL * pixel,
                 1e-7 * c->scale);
}

/* An elevation surface's tracer, its tolerance as a field's. */
static void etracer_for(oc_etracer *tr, const oc_esurface *es,
                        const oc_render_params *rp, const camera *c) {
  double pixel = 2 * c->th / c->height;
  oc_etracer_init(tr, es, rp->tracer, EPS_PIXEL * pixel, 1e-7 * c->scale);
}

/* Rays end where the scene's box ends, or at max_distance; an unbounded
** scene needs a finite end, or a ray grazing a half-space would march
** for ever. (An elevation surface's box, its domain, is always finite.) */
static double far_for(const oc_program *prog, const oc_render_params *rp,
                      const camera *c) {
  if (rp->max_distance > 0) return rp->max_distance;
  if (!prog) return INFINITY;
  oc_aabb b = oc_program_bounds(prog);
  if (oc_vfinite(b.lo) && oc_vfinite(b.hi)) return INFINITY;
  return 1000 * c->scale;
}

/* ---- tiles ---------------------------------------------------------------
 */

typedef void (*tile_fn)(const void *ctx, int x0, int y0, int x1, int y1);

/* Runs fn over every tile in parallel; progress in [base, base + span]
** from the calling thread only. Returns OC_ECANCEL when cancelled. */
static int run_tiles(int w, int h, tile_fn fn, const void *ctx,
                     const oc_progress *pg, double base, double span) {
  int ntx = (w + TILE - 1) / TILE, nty = (h + TILE - 1) / TILE;
  int n = ntx * nty, stop = 0, done = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < n; k++) {
    int halt;
#pragma omp atomic read
    halt = stop;
    if (halt) continue;
    int x0 = (k % ntx) * TILE, y0 = (k / ntx) * TILE;
    fn(ctx, x0, y0, x0 + TILE < w ? x0 + TILE : w,
       y0 + TILE < h ? y0 + TILE : h);
    int d;
#pragma omp atomic capture
    d = ++done;
    if (pg->fn && omp_get_thread_num() == 0 &&
        pg->fn(pg->ud, base + span * d / n)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (stop || (pg->fn && pg->fn(pg->ud, base + span))) return OC_ECANCEL;
  return OC_OK;
}

/* ---- geometry ------------------------------------------------------------
 */

typedef struct gctx {
  const oc_program *prog; /* a field, or NULL and */
  const oc_esurface *es;  /* an elevation surface */
  camera cam;
  oc_tracer tr;
  oc_etracer etr;
  double far;
  float *px;
} gctx;

/* Pixel (i, j), its ray known free of the surface before depth d (the
** distance along w; INFINITY: a miss); share: the height calls of the
** beams that took it there, its part of them (counted in its evals). */
static void geom_pixel(const gctx *g, int i, int j, double d, double step,
                       const oc_emodel *m, double share, float *out) {
  oc_vec3 D = ray_vec(&g->cam, i, j);
  double len = oc_len(D), t, ev = share;
  oc_vec3 n; /* an elevation surface's hit: its normal from the tracer */
  oc_vec3 u = oc_mul(D, 1 / len);
  memset(out, 0, OC_RG_COUNT * sizeof *out);
  int hit = 0;
  if (d == INFINITY)
    hit = 0;
  else if (g->es)
    hit = oc_etrace_hit(&g->etr, g->cam.eye, u, d * len * (1 - 1e-12), g->far,
                        0, PIXEL_STEP * step * len, m, &t, &n, &ev);
  else
    hit = oc_trace(&g->tr, g->cam.eye, u, 0, g->far, 0, &t, &ev);
  if (!hit) {
    out[OC_RG_Z] = INFINITY;
    out[OC_RG_EVALS] = (float)ev;
    return;
  }
  oc_vec3 p = oc_add(g->cam.eye, oc_mul(u, t));
  if (g->es) {
    if (hit == 2) n = oc_etracer_wall(&g->etr, p, u);
  } else {
    oc_vec3 gr;
    oc_program_gradient(g->prog, p, &gr);
    ev += 1;
    double gl = oc_len(gr);
    n = gl > 0 && isfinite(gl) ? oc_mul(gr, -1 / gl) : oc_mul(u, -1);
  }
  out[OC_RG_HIT] = 1;
  out[OC_RG_Z] = (float)t;
  out[OC_RG_NX] = (float)n.x;
  out[OC_RG_NX + 1] = (float)n.y;
  out[OC_RG_NX + 2] = (float)n.z;
  out[OC_RG_PX] = (float)p.x;
  out[OC_RG_PX + 1] = (float)p.y;
  out[OC_RG_PX + 2] = (float)p.z;
  out[OC_RG_EVALS] = (float)ev;
}

/* The pixels [i0, i1) x [j0, j1), each ray from depth d. */
static void geom_pixels(const gctx *g, int i0, int j0, int i1, int j1, double d,
                        double step, const oc_emodel *m, double share) {
  for (int j = j0; j < j1; j++)
    for (int i = i0; i < i1; i++)
      geom_pixel(g, i, j, d, step, m, share,
                 g->px + ((size_t)j * g->cam.width + i) * OC_RG_COUNT);
}

/* The pixels [i0, i1) x [j0, j1), whose rays are free before depth d:
** the beam of the block takes them as far as it proves them free
** together, then its quarters go on from there, down to BEAM_MIN or
** BEAM_MIN_MODELS pixels a side, and each ray from where its block
** stopped. The blocks are the same for any thread count (tiles split
** alike), so are the images. A beam's height calls (on models) are
** shared equally by its pixels: share is each pixel's part of its
** enclosing beams' calls, so that the evals channel sums to every call
** made; step is the candidate step the enclosing beam ended with (0:
** none). */
static void beam_block(const gctx *g, int i0, int j0, int i1, int j1, double d,
                       double step, oc_emodel m, double share) {
  int w = i1 - i0, h = j1 - j0;
  if (d != INFINITY) {
    oc_ebeam b;
    double calls = 0;
    beam_for(&g->cam, i0, j0, i1, j1, &b);
    d = oc_etrace_beam(&g->etr, &b, d, g->far, NULL, &calls, &step, &m);
    share += calls / ((double)w * h);
  }
  int least = g->es->src->taylor ? BEAM_MIN_MODELS : BEAM_MIN;
  if (d != INFINITY && (w > least || h > least)) {
    int im = w > least ? i0 + w / 2 : i1, jm = h > least ? j0 + h / 2 : j1;
    beam_block(g, i0, j0, im, jm, d, step, m, share);
    if (im < i1) beam_block(g, im, j0, i1, jm, d, step, m, share);
    if (jm < j1) {
      beam_block(g, i0, jm, im, j1, d, step, m, share);
      if (im < i1) beam_block(g, im, jm, i1, j1, d, step, m, share);
    }
    return;
  }
  geom_pixels(g, i0, j0, i1, j1, d, step, &m, share);
}

static void geom_tile(const void *ctx, int x0, int y0, int x1, int y1) {
  const gctx *g = ctx;
  if (g->es && g->etr.mode == OC_TRACE_SEGMENT)
    beam_block(g, x0, y0, x1, y1, 0, 0, (oc_emodel){0}, 0);
  else
    geom_pixels(g, x0, y0, x1, y1, 0, 0, NULL, 0);
}

/* A terrain thinner than the rays' tolerance shows as scattered pixels
** or not at all: its solid lies between two samples of most rays. The
** rays that reached the scene's box (they evaluated the field) sample it
** no finer than the tolerance at the box's nearest point; when none hit
** anything, the tolerance at its far end tells why. The renderer's part
** of oc_terrain_thin_reason, the mesher's being its cell. */
static void thin_reason(const gctx *g, const oc_render_params *rp) {
  size_t npx = (size_t)rp->width * rp->height;
  int entered = 0, hit = 0;
  for (size_t k = 0; k < npx; k++) {
    const float *p = g->px + k * OC_RG_COUNT;
    hit |= p[OC_RG_HIT] > 0;
    entered |= p[OC_RG_EVALS] > 0;
  }
  if (!entered) return;
  oc_aabb b = oc_program_bounds(g->prog);
  oc_vec3 e = g->cam.eye, d;
  if (hit) {
    d = oc_v3(fmax(fmax(b.lo.x - e.x, e.x - b.hi.x), 0),
              fmax(fmax(b.lo.y - e.y, e.y - b.hi.y), 0),
              fmax(fmax(b.lo.z - e.z, e.z - b.hi.z), 0));
  } else {
    d = oc_v3(fmax(fabs(b.lo.x - e.x), fabs(b.hi.x - e.x)),
              fmax(fabs(b.lo.y - e.y), fabs(b.hi.y - e.y)),
              fmax(fabs(b.lo.z - e.z), fabs(b.hi.z - e.z)));
  }
  double t = fmin(oc_len(d), g->far);
  if (!isfinite(t)) return;
  oc_terrain_thin_reason(g->prog, g->tr.eps_k * t + g->tr.eps_min,
                         "the render's hit tolerance", rp->warning,
                         rp->warning_size);
}

/* Checks the scene (a program, or an elevation surface when es) and what
** tracing needs. */
static int check_scene(const oc_program *prog, const oc_esurface *es,
                       const oc_render_params *rp, oc_error *err) {
  return es ? oc_render_check_surface(es, rp, err)
            : oc_render_check_geometry(prog, rp, err);
}

static oc_image *geometry(const oc_program *prog, const oc_esurface *es,
                          const oc_render_params *rp, double base, double span,
                          oc_error *err) {
  if (check_scene(prog, es, rp, err)) return NULL;
  oc_image *img = oc_image_new(rp->width, rp->height, OC_RG_COUNT, err);
  if (!img) return NULL;
  for (int c = 0; c < OC_RG_COUNT; c++)
    oc_image_set_channel_name(img, c, geom_names[c], NULL);
  if (rp->warning && rp->warning_size) rp->warning[0] = '\0';
  gctx g;
  camera_init(&g.cam, rp);
  g.prog = prog;
  g.es = es;
  if (es)
    etracer_for(&g.etr, es, rp, &g.cam);
  else
    tracer_for(&g.tr, prog, rp, &g.cam);
  g.far = far_for(prog, rp, &g.cam);
  g.px = oc_image_data(img);
  if (run_tiles(rp->width, rp->height, geom_tile, &g, &rp->progress, base,
                span)) {
    oc_image_free(img);
    oc_seterr(err, OC_ECANCEL, "rendering cancelled");
    return NULL;
  }
  if (prog && rp->warning && rp->warning_size) thin_reason(&g, rp);
  return img;
}

oc_image *oc_render_geometry(const oc_program *prog, const oc_render_params *rp,
                             oc_error *err) {
  return geometry(prog, NULL, rp, 0, 1, err);
}

/* ---- shading -------------------------------------------------------------
 */

typedef struct sctx {
  oc_shader sh;
  camera cam;
  const float *geo;
  const float *albedo;
  float *px;
  float *evals; /* NULL, or each pixel's evaluations (for the stats) */
  int nch;
  double gain; /* 2^exposure */
} sctx;

static void shade_pixel(const sctx *s, int i, int j) {
  size_t k = (size_t)j * s->cam.width + i;
  const float *g = s->geo + k * OC_RG_COUNT;
  float *out = s->px + k * s->nch;
  double ev = g[OC_RG_EVALS], rgba[4];
  if (g[OC_RG_HIT] > 0) {
    oc_vec3 p = oc_v3(g[OC_RG_PX], g[OC_RG_PX + 1], g[OC_RG_PX + 2]);
    oc_vec3 n = oc_v3(g[OC_RG_NX], g[OC_RG_NX + 1], g[OC_RG_NX + 2]);
    double alb[3];
    if (s->albedo)
      for (int c = 0; c < 3; c++)
        alb[c] = s->albedo[k * 3 + c];
    else
      oc_albedo(&s->sh, p, n, alb, &ev);
    oc_texture(&s->sh, p, n, alb);
    oc_light(&s->sh, p, n, g[OC_RG_Z], alb, rgba, &ev);
    rgba[3] = 1;
  } else {
    oc_sky(&s->sh, ray_dir(&s->cam, i, j), rgba);
  }
  /* (a gain of exactly 1 leaves every value as it was) */
  for (int c = 0; c < 3; c++)
    out[c] = (float)(rgba[c] * s->gain);
  out[3] = (float)rgba[3];
  if (s->nch > 4) {
    memcpy(out + 4, g + OC_RG_Z, 7 * sizeof *out);
    out[11] = (float)ev;
  }
  if (s->evals) s->evals[k] = (float)ev;
}

static void shade_tile(const void *ctx, int x0, int y0, int x1, int y1) {
  for (int j = y0; j < y1; j++)
    for (int i = x0; i < x1; i++)
      shade_pixel(ctx, i, j);
}

/* Rule levels from the altitudes of the visible surface, unless given. */
static void resolve_levels(oc_shader *sh, const oc_render_params *rp,
                           const float *geo, size_t npx) {
  const oc_render_rules *ru = &rp->rules;
  double z0 = INFINITY, z1 = -INFINITY;
  for (size_t k = 0; k < npx; k++) {
    const float *g = geo + k * OC_RG_COUNT;
    if (g[OC_RG_HIT] > 0) {
      z0 = fmin(z0, g[OC_RG_PX + 2]);
      z1 = fmax(z1, g[OC_RG_PX + 2]);
    }
  }
  if (!(z0 <= z1)) z0 = z1 = 0;
  double relief = z1 - z0;
  int sea = ru->levels && !isnan(ru->sea_level);
  int snow = ru->levels && !isnan(ru->snow_line);
  sh->sea = sea ? ru->sea_level : z0 + 0.04 * relief;
  sh->snow = snow ? ru->snow_line : z0 + 0.75 * relief;
  sh->beach = sea || ru->beach > 0 ? ru->beach : 0.015 * relief;
}

static oc_image *shade(const oc_program *prog, const oc_esurface *es,
                       const oc_render_params *rp, const oc_image *geo,
                       const float *albedo, float *evals, double base,
                       double span, oc_error *err) {
  if (check_scene(prog, es, rp, err)) return NULL;
  if (oc_render_check_shade(rp, err)) return NULL;
  if (!geo) {
    oc_seterr(err, OC_EINVAL, "'geometry' is NULL");
    return NULL;
  }
  if (oc_image_channels(geo) != OC_RG_COUNT ||
      oc_image_width(geo) != rp->width || oc_image_height(geo) != rp->height) {
    oc_seterr(err, OC_EINVAL,
              "'geometry' must be a %d x %d image from oc_render_geometry "
              "(got %d x %d x %d)",
              rp->width, rp->height, oc_image_width(geo), oc_image_height(geo),
              oc_image_channels(geo));
    return NULL;
  }
  int nch = rp->aov ? 4 + NAOV : 4;
  oc_image *img = oc_image_new(rp->width, rp->height, nch, err);
  if (!img) return NULL;
  for (int c = 4; c < nch; c++)
    oc_image_set_channel_name(img, c, aov_names[c - 4], NULL);
  /* linear light: the writers encode sRGB for integer formats */
  oc_image_set_meta(img, "outcrop:colorspace", "linear", NULL);
  /* the clamp is the writers' default: only another curve is recorded, so
  ** files of default renders are as they were */
  if (rp->tone != OC_TONE_CLAMP)
    oc_image_set_meta(img, OC_TONE_KEY, oc_tone_name(rp->tone), NULL);
  sctx s;
  camera_init(&s.cam, rp);
  s.geo = oc_image_cdata(geo);
  s.albedo = albedo;
  s.px = oc_image_data(img);
  s.evals = evals;
  s.nch = nch;
  s.gain = exp2(rp->exposure);
  oc_shader *sh = &s.sh;
  sh->rp = rp;
  sh->prog = prog;
  sh->es = es;
  if (es) {
    etracer_for(&sh->etracer, es, rp, &s.cam);
    sh->etracer.refine = 0;
    sh->T = es->T;
  } else {
    tracer_for(&sh->tracer, prog, rp, &s.cam);
    sh->tracer.refine = 0; /* shadow rays need no exact distance */
    sh->T = sh->tracer.T;
  }
  sh->sun = oc_mul(rp->sun_direction, 1 / oc_len(rp->sun_direction));
  sh->far = far_for(prog, rp, &s.cam);
  sh->ao_step = rp->ao_distance > 0 ? rp->ao_distance : s.cam.scale / 150;
  sh->tex_scale = rp->texture_scale > 0 ? rp->texture_scale : s.cam.scale / 12;
  resolve_levels(sh, rp, s.geo, (size_t)rp->width * rp->height);
  if (oc_shader_lod(sh, err)) {
    oc_image_free(img);
    return NULL;
  }
  int stop = run_tiles(rp->width, rp->height, shade_tile, &s, &rp->progress,
                       base, span);
  oc_shader_release(sh);
  if (stop) {
    oc_image_free(img);
    oc_seterr(err, OC_ECANCEL, "rendering cancelled");
    return NULL;
  }
  return img;
}

oc_image *oc_render_shade(const oc_program *prog, const oc_render_params *rp,
                          const oc_image *geometry, const float *albedo,
                          oc_error *err) {
  return shade(prog, NULL, rp, geometry, albedo, NULL, 0, 1, err);
}

oc_image *oc_render(const oc_program *prog, const oc_render_params *rp,
                    oc_error *err) {
  /* checked before any tracing: a bad colour should not cost a render */
  if (oc_render_check_geometry(prog, rp, err) || oc_render_check_shade(rp, err))
    return NULL;
  oc_image *geo = geometry(prog, NULL, rp, 0, GEOM_SHARE, err);
  if (!geo) return NULL;
  oc_image *img =
      shade(prog, NULL, rp, geo, NULL, NULL, GEOM_SHARE, 1 - GEOM_SHARE, err);
  oc_image_free(geo);
  return img;
}

/* ---- elevation surfaces ---------------------------------------------------
 */

oc_image *oc_render_surface_geometry(const oc_esurface *es,
                                     const oc_render_params *rp,
                                     oc_error *err) {
  return geometry(NULL, es, rp, 0, 1, err);
}

oc_image *oc_render_surface_shade(const oc_esurface *es,
                                  const oc_render_params *rp,
                                  const oc_image *geometry, const float *albedo,
                                  oc_error *err) {
  return shade(NULL, es, rp, geometry, albedo, NULL, 0, 1, err);
}

/* Sums the evaluations of the geometry image and the per-pixel totals,
** serially, so that the figures are the same for any thread count. */
static void count(oc_render_stats *st, const oc_image *geo,
                  const float *total) {
  size_t npx = (size_t)oc_image_width(geo) * oc_image_height(geo);
  const float *g = oc_image_cdata(geo);
  memset(st, 0, sizeof *st);
  st->pixels = (long long)npx;
  for (size_t k = 0; k < npx; k++) {
    const float *p = g + k * OC_RG_COUNT;
    st->hits += p[OC_RG_HIT] > 0;
    st->calls += p[OC_RG_EVALS];
    st->calls_total += total[k];
  }
  st->calls_per_pixel = st->calls / (double)npx;
  st->calls_total_per_pixel = st->calls_total / (double)npx;
}

oc_image *oc_render_surface(const oc_esurface *es, const oc_render_params *rp,
                            oc_render_stats *st, oc_error *err) {
  if (oc_render_check_surface(es, rp, err) || oc_render_check_shade(rp, err))
    return NULL;
  oc_image *geo = geometry(NULL, es, rp, 0, GEOM_SHARE, err);
  if (!geo) return NULL;
  float *total = NULL;
  if (st) {
    total = malloc((size_t)rp->width * rp->height * sizeof *total);
    if (!total) {
      oc_image_free(geo);
      oc_seterr(err, OC_ENOMEM, "out of memory for the render's statistics");
      return NULL;
    }
  }
  oc_image *img =
      shade(NULL, es, rp, geo, NULL, total, GEOM_SHARE, 1 - GEOM_SHARE, err);
  if (img && st) count(st, geo, total);
  free(total);
  oc_image_free(geo);
  return img;
}

oc_image *oc_render_elevation(const oc_elevation *src,
                              const oc_render_params *rp, oc_render_stats *st,
                              oc_error *err) {
  oc_esurface es = {src, NULL, NULL, 0.5, NULL};
  return oc_render_surface(&es, rp, st, err);
}

oc_image *oc_render_elevation_geometry(const oc_elevation *src,
                                       const oc_render_params *rp,
                                       oc_error *err) {
  oc_esurface es = {src, NULL, NULL, 0.5, NULL};
  return oc_render_surface_geometry(&es, rp, err);
}

oc_image *oc_render_elevation_shade(const oc_elevation *src,
                                    const oc_render_params *rp,
                                    const oc_image *geometry,
                                    const float *albedo, oc_error *err) {
  oc_esurface es = {src, NULL, NULL, 0.5, NULL};
  return oc_render_surface_shade(&es, rp, geometry, albedo, err);
}

/* The footprint rule of the level of detail (oc_enode_elevation_view)
** uses the tracer's own measure of a pixel. */
double oc_render_pixel_angle(const oc_render_params *rp) {
  double th = tan(rp->camera.fov * (3.14159265358979323846 / 360));
  return 2 * th / rp->height;
}
