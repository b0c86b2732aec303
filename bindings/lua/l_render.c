/*
** l_render.c — outcrop.render(node, {...}): an image of the surface f = T
** traced by lib/render, with every option checked before any work; and
** outcrop.render(heightfield, {...}), the surface z = h(x, y) traced
** directly (lib/render/etrace.c), with the same options, returning the
** image and the height calls made ({pixels =, hits =, calls =,
** calls_per_pixel =, calls_total =, calls_total_per_pixel =}). For an
** elevation surface `threshold` is the T of its weight (no surface where
** the weight is below it); a heightfield has none, so it is unused there.
**
** Defaults (the lib's, oc_render_defaults, except where said): 640 x 360;
** camera framed by oc_render_default_camera (oc_render_frame_box for an
** elevation surface: a heightfield's extent x its elevation range),
** looking at the centre of the bounds from the south-west, 30 degrees up,
** just far enough for the corners of the bounds to fit the view (an error
** when the bounds are infinite and camera.eye or camera.target is
** missing), up = {0, 0, 1}, fov = 40 degrees (vertical);
** sun, sky, shadows, AO and texture as the lib; no fog; the sky behind
** the surface; threshold = outcrop.threshold; rule colours by altitude
** and slope; the AOV channels (Z, N, P, evals) after R, G, B, A unless
** aov = false; exposure 0 stops; tone "clamp" (the look of renders made
** before the option existed), or "filmic".
**
** `color` selects the albedo: nil (rules, tuned by `rules = {...}`), a
** node mapped through `palette` (the lib's oc_palette_strata by default,
** strata colours for resistances in [0, 1]), {field = node, palette = ...} as
*polygonize
** takes it, {blend = {{node, {r, g, b}}, ...}} (colours blended by the
** nodes' values, each with its own triplanar texture: texturing by
** material, e.g. stacks:colors()), or a function (x, y, z, nx, ny, nz) ->
** r, g, b called once
** per pixel that hits the surface, row by row from the top left, between
** the lib's two passes (geometry, then shading). Colours are linear RGB.
*/
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "l_blend.h"
#include "l_elevation.h"
#include "l_field.h"
#include "l_heightfield.h"
#include "l_image.h"
#include "l_progress.h"
#include "l_render.h"

#define FNAME "outcrop.render"
#define MAX_SIDE 16384
#define MAX_EV 20.0 /* exposure, stops either way (lib/render/render.h) */
/* Fog given as a distance: the transmittance there is exp(-3), 5 %. */
#define FOG_DISTANCE_FACTOR 3.0

static const char *const rgb_names[3] = {"r", "g", "b"};

/* Raises for a failed lib call: "interrupted" (as polygonize) when it was
** cancelled, else the lib's message. */
static int render_error(lua_State *L, oclua_progress *pl, const oc_error *err) {
  oclua_progress_end(pl);
  if (err->code == OC_ECANCEL) return luaL_error(L, "interrupted");
  return oclua_liberror(L, FNAME, err);
}

/* ---- small readers ---------------------------------------------------- */

/* Reads field `name` of f as {r, g, b} (or, when `alpha`, also
** {r, g, b, a}): linear colours, components finite and >= 0, alpha in
** [0, 1]. Returns the count read, 0 when absent. */
static int read_rgb(const oclua_fields *f, const char *name, double *out,
                    int alpha) {
  lua_State *L = f->L;
  const char *what =
      alpha ? "must be {r, g, b} or {r, g, b, a}" : "must be {r, g, b}";
  int t = oclua_field_push(f, name);
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return 0;
  }
  size_t n = t == LUA_TTABLE ? lua_rawlen(L, -1) : 0;
  if (n != 3 && !(alpha && n == 4)) oclua_field_error(f, name, -1, what);
  for (size_t i = 0; i < n; i++) {
    int ti = lua_geti(L, -1, (lua_Integer)i + 1);
    double x = lua_tonumber(L, -1);
    if (!(ti == LUA_TNUMBER && isfinite(x) && x >= 0 && (x <= 1 || i < 3)))
      oclua_error(L, f->fname, "'%s%s' %s with components %s (item %d is %s)",
                  f->prefix, name, what,
                  alpha ? "finite and >= 0, alpha <= 1" : "finite and >= 0",
                  (int)i + 1, oclua_got(L, -1));
    out[i] = x;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return (int)n;
}

static double read_range(const oclua_fields *f, const char *name, double lo,
                         double hi, double def) {
  lua_State *L = f->L;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  double x = lua_tonumber(L, -1);
  if (lua_type(L, -1) != LUA_TNUMBER || !(x >= lo && x <= hi)) {
    const char *what =
        lua_pushfstring(L, "must be a number in [%f, %f]", lo, hi);
    oclua_field_error(f, name, -2, what);
  }
  lua_pop(L, 1);
  return x;
}

/* Opens the sub-table `name` of f (pushed on the stack) into sub;
** returns 0 (nothing pushed) when the field is absent. */
static int open_sub(const oclua_fields *f, const char *name, oclua_fields *sub,
                    const char *const *known) {
  lua_State *L = f->L;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return 0;
  }
  const char *prefix = lua_pushfstring(L, "%s%s.", f->prefix, name);
  lua_insert(L, -2); /* the prefix string stays alive below the table */
  oclua_fields_open(sub, L, -1, f->fname, prefix, known, 0);
  return 1;
}

static void close_sub(lua_State *L) {
  lua_pop(L, 2);
}

/* ---- fields ------------------------------------------------------------ */

static void read_size(const oclua_fields *f, oc_render_params *rp) {
  lua_State *L = f->L;
  double size[2];
  if (!oclua_field_numbers(f, "size", 2, size, "must be {width, height}"))
    return;
  for (int k = 0; k < 2; k++)
    if (size[k] != floor(size[k]) || size[k] < 1 || size[k] > MAX_SIDE) {
      if (size[k] == floor(size[k]) && fabs(size[k]) < 1e18)
        lua_pushinteger(L, (lua_Integer)size[k]);
      else
        lua_pushnumber(L, size[k]);
      oclua_error(L, f->fname,
                  "'size' must be {width, height} with integers in "
                  "1..%d (got %s)",
                  MAX_SIDE, oclua_got(L, -1));
    }
  rp->width = (int)size[0];
  rp->height = (int)size[1];
}

typedef struct camera_in {
  int has_eye, has_target;
} camera_in;

static void read_camera(const oclua_fields *f, oc_render_params *rp,
                        camera_in *ci) {
  static const char *const known[] = {"eye", "target", "up", "fov", NULL};
  oclua_fields c;
  ci->has_eye = ci->has_target = 0;
  if (!open_sub(f, "camera", &c, known)) return;
  ci->has_eye = oclua_field_optvec(&c, "eye", &rp->camera.eye);
  ci->has_target = oclua_field_optvec(&c, "target", &rp->camera.target);
  oclua_field_optvec(&c, "up", &rp->camera.up);
  /* (the range is the lib's to check: oc_render_default_camera) */
  rp->camera.fov =
      oclua_field_optnumber(&c, "fov", OCLUA_POSITIVE, rp->camera.fov);
  close_sub(f->L);
}

static void read_sun(const oclua_fields *f, oc_render_params *rp) {
  static const char *const known[] = {"direction", "color", "intensity",
                                      "radius", NULL};
  oclua_fields s;
  oc_vec3 d;
  if (!open_sub(f, "sun", &s, known)) return;
  /* a zero direction and a negative intensity are the lib's to refuse
  ** (oc_render_check) */
  if (oclua_field_optvec(&s, "direction", &d)) rp->sun_direction = d;
  read_rgb(&s, "color", rp->sun_color, 0);
  rp->sun_intensity =
      oclua_field_optnumber(&s, "intensity", OCLUA_FINITE, rp->sun_intensity);
  /* (its range is the lib's to check) */
  rp->sun_radius =
      oclua_field_optnumber(&s, "radius", OCLUA_FINITE, rp->sun_radius);
  close_sub(f->L);
}

/* fog = density (per metre) or {density = | distance =, color =}. */
static void read_fog(const oclua_fields *f, oc_render_params *rp) {
  static const char *const known[] = {"density", "distance", "color", NULL};
  lua_State *L = f->L;
  oclua_fields g;
  int t = oclua_field_push(f, "fog");
  lua_pop(L, 1);
  if (t == LUA_TNIL) return;
  if (t == LUA_TNUMBER) {
    rp->fog_density = read_range(f, "fog", 0, HUGE_VAL, 0);
    return;
  }
  if (t != LUA_TTABLE) {
    oclua_field_push(f, "fog");
    oclua_field_error(f, "fog", -1,
                      "must be a density per metre or {density = or "
                      "distance =, color =}");
  }
  open_sub(f, "fog", &g, known);
  double density = read_range(&g, "density", 0, HUGE_VAL, -1);
  double distance = oclua_field_optnumber(&g, "distance", OCLUA_POSITIVE, 0);
  if (density >= 0 && distance > 0)
    oclua_error(L, f->fname, "give either 'fog.density' or 'fog.distance'");
  if (density < 0 && distance == 0)
    oclua_field_missing(&g, "density",
                        "or 'fog.distance': how thick the fog is");
  rp->fog_density = distance > 0 ? FOG_DISTANCE_FACTOR / distance : density;
  read_rgb(&g, "color", rp->fog_color, 0);
  close_sub(L);
}

static void read_rules(const oclua_fields *f, oc_render_params *rp) {
  static const char *const known[] = {"sea_level",  "snow_line",  "beach",
                                      "rock_slope", "snow_slope", NULL};
  lua_State *L = f->L;
  oclua_fields r;
  if (!open_sub(f, "rules", &r, known)) return;
  oc_render_rules *ru = &rp->rules;
  int sea = oclua_field_push(&r, "sea_level") != LUA_TNIL;
  int snow = oclua_field_push(&r, "snow_line") != LUA_TNIL;
  lua_pop(L, 2);
  /* a level not given follows the visible altitudes (NaN for the engine) */
  if (sea || snow) {
    ru->levels = 1;
    ru->sea_level = ru->snow_line = NAN;
  }
  if (sea) ru->sea_level = oclua_field_number(&r, "sea_level", OCLUA_FINITE);
  if (snow) ru->snow_line = oclua_field_number(&r, "snow_line", OCLUA_FINITE);
  if (sea && snow) {
    if (!(ru->sea_level < ru->snow_line))
      oclua_error(L, f->fname,
                  "'rules.sea_level' must be below 'rules.snow_line' "
                  "(got %f and %f)",
                  ru->sea_level, ru->snow_line);
  }
  ru->beach = read_range(&r, "beach", 0, HUGE_VAL, ru->beach);
  ru->rock_slope = read_range(&r, "rock_slope", 0, 90, ru->rock_slope);
  ru->snow_slope = read_range(&r, "snow_slope", 0, 90, ru->snow_slope);
  close_sub(L);
}

enum { SRC_RULES, SRC_FIELD, SRC_FUNCTION, SRC_BLEND };

/* What `color` asked for; the node or function stays on the stack at idx
** (and the stops in a userdata) until the image is made. */
typedef struct source {
  int kind;
  int idx;
} source;

static void read_color(const oclua_fields *f, oc_render_params *rp,
                       source *src) {
  static const char *const known[] = {"field", "palette", "blend", NULL};
  lua_State *L = f->L;
  int t = oclua_field_push(f, "color");
  int has_palette = oclua_field_push(f, "palette") != LUA_TNIL;
  int has_rules = oclua_field_push(f, "rules") != LUA_TNIL;
  lua_pop(L, 2);
  src->kind = SRC_RULES;
  src->idx = lua_gettop(L);
  rp->color = OC_COLOR_RULES;
  if (has_rules && t != LUA_TNIL)
    oclua_error(L, f->fname,
                "'rules' tune the default colours: it cannot go with "
                "'color'");
  if (has_palette && t != LUA_TUSERDATA)
    oclua_error(L, f->fname,
                "'palette' maps a 'color' node: give 'color' = node "
                "with it");
  if (t == LUA_TNIL) {
    read_rules(f, rp);
    return;
  }
  if (t == LUA_TFUNCTION) {
    src->kind = SRC_FUNCTION;
    return;
  }
  if (t == LUA_TUSERDATA && oclua_testnode(L, -1)) {
    src->kind = SRC_FIELD;
    rp->color = OC_COLOR_FIELD;
    if (has_palette) {
      oclua_field_push(f, "palette");
      rp->stops =
          oclua_read_palette(L, lua_gettop(L), FNAME, "palette", &rp->nstops);
    }
    return;
  }
  if (t == LUA_TTABLE) { /* {field =, palette =}, as polygonize's colors */
    oclua_fields c;
    oclua_fields_open(&c, L, -1, f->fname, "color.", known, 0);
    if (oclua_field_push(&c, "blend") != LUA_TNIL) { /* by material */
      src->kind = SRC_BLEND;
      src->idx = lua_gettop(L);
      rp->color = OC_COLOR_BLEND;
      rp->nblend = oclua_read_blend(L, src->idx, FNAME, "color.blend",
                                    &rp->blend_colors);
      if (oclua_field_push(&c, "field") != LUA_TNIL ||
          oclua_field_push(&c, "palette") != LUA_TNIL)
        oclua_error(L, f->fname,
                    "'color.blend' cannot go with 'field' or 'palette'");
      lua_pop(L, 2);
      return;
    }
    lua_pop(L, 1);
    if (oclua_field_push(&c, "field") == LUA_TNIL)
      oclua_field_missing(&c, "field", "an outcrop node");
    if (oclua_testnode(L, -1) == NULL)
      oclua_field_error(&c, "field", -1, "must be an outcrop node");
    src->kind = SRC_FIELD;
    src->idx = lua_gettop(L);
    rp->color = OC_COLOR_FIELD;
    if (oclua_field_push(&c, "palette") != LUA_TNIL)
      rp->stops = oclua_read_palette(L, lua_gettop(L), FNAME, "color.palette",
                                     &rp->nstops);
    return;
  }
  oclua_field_error(f, "color", -1,
                    "must be an outcrop node, a function (x, y, z, nx, ny, "
                    "nz) -> r, g, b, or {field = node, palette = ...}");
}

/* ---- the colour function ----------------------------------------------- */

/* Calls the function at fn for every hit pixel of the geometry image g
** (row by row, from the top left), gathering albedos in a Lua-owned
** buffer that it pushes and returns. */
static const float *albedo_by_function(lua_State *L, int fn, const oc_image *g,
                                       oclua_progress *pl) {
  size_t w = (size_t)oc_image_width(g), h = (size_t)oc_image_height(g);
  const float *px = oc_image_cdata(g);
  float *rgb = lua_newuserdatauv(L, w * h * 3 * sizeof *rgb, 0);
  luaL_checkstack(L, 8, NULL);
  for (size_t i = 0; i < w * h; i++) {
    const float *p = px + i * OC_RG_COUNT;
    /* (Ctrl-C in the function is the interpreter's hook's to catch.) */
    if (i % w == 0) oclua_progress_report(pl, (double)i / (double)(w * h));
    float *out = rgb + 3 * i;
    if (!(p[OC_RG_HIT] > 0.5f)) {
      out[0] = out[1] = out[2] = 0;
      continue;
    }
    lua_pushvalue(L, fn);
    for (int k = 0; k < 3; k++)
      lua_pushnumber(L, p[OC_RG_PX + k]);
    for (int k = 0; k < 3; k++)
      lua_pushnumber(L, p[OC_RG_NX + k]);
    lua_call(L, 6, 3);
    for (int k = 0; k < 3; k++) {
      int idx = k - 3;
      double x = lua_tonumber(L, idx);
      if (lua_type(L, idx) != LUA_TNUMBER || !(x >= 0 && x <= 1))
        oclua_error(L, FNAME,
                    "the color function must return r, g, b in [0, 1] "
                    "(got %s = %s at pixel %I, %I)",
                    rgb_names[k], oclua_got(L, idx), (LUAI_UACINT)(i % w + 1),
                    (LUAI_UACINT)(i / w + 1));
      out[k] = (float)x;
    }
    lua_pop(L, 3);
  }
  return rgb;
}

typedef struct albedo_call {
  const oc_image *g;
  oclua_progress *pl;
  const float *rgb;
} albedo_call;

/* albedo_by_function under lua_pcall: the function at 1, the call's
** description at 2. */
static int protected_albedo(lua_State *L) {
  albedo_call *ac = lua_touserdata(L, 2);
  ac->rgb = albedo_by_function(L, 1, ac->g, ac->pl);
  return 1;
}

/* Runs the colour function over every hit pixel of g and pushes the
** albedo buffer. With a progress line on the terminal the calls are
** protected, so that an error (or Ctrl-C) clears the line before the
** message is printed; the error then goes on from here, its message
** still naming the line of the function that failed. */
static const float *run_colour_function(lua_State *L, int fn, const oc_image *g,
                                        oclua_progress *pl) {
  if (!pl->tty) return albedo_by_function(L, fn, g, pl);
  albedo_call ac = {g, pl, NULL};
  lua_pushcfunction(L, protected_albedo);
  lua_pushvalue(L, fn);
  lua_pushlightuserdata(L, &ac);
  if (lua_pcall(L, 2, 1, 0) != LUA_OK) {
    oclua_progress_end(pl);
    lua_error(L);
  }
  return ac.rgb;
}

/* ---- elevation surfaces ---------------------------------------------- */

#define SURFACE_MT "outcrop.render.surface"

/* An elevation surface made for one render, released by the collector
** (so that an error anywhere after it leaks nothing). */
typedef struct lsurface {
  oc_elevation src;
  int has_src;
  oc_esurface es;
} lsurface;

static int surface_gc(lua_State *L) {
  lsurface *s = lua_touserdata(L, 1);
  if (s->has_src && s->src.release) s->src.release(s->src.ud);
  s->has_src = 0;
  return 0;
}

/* Whether the value at idx is traced as an elevation surface: pins it
** (a guard slot the caller keeps) before any option is read, so no
** metamethod of the options can close it. */
static int pin_surface(lua_State *L, int idx) {
  if (oclua_testenode(L, idx)) return 1; /* immutable: on the stack */
  if (!oclua_isheightfield(L, idx)) return 0;
  oclua_pinheightfield(L, idx, FNAME);
  return 1;
}

/* The elevation surface of the (pinned) value at idx: its source and,
** for sources that have holes, their weight with threshold T. Pushes the
** userdata that owns it. This is where every kind of elevation value
** turns into an oc_esurface: heightfields now (no holes); the elevation
** trees of issue 14 will set es.weight and es.wud to their alpha (no
** terrain where alpha < T, the trees' Omega_T). */
static double tree_weight(void *wud, double x, double y) {
  return oc_enode_weight(wud, x, y);
}

static const oc_esurface *surface_at(lua_State *L, int idx, double T) {
  oc_enode *tree = oclua_testenode(L, idx);
  oc_heightfield *hf = tree ? NULL : oclua_checkheightfield(L, idx, FNAME);
  lsurface *s = lua_newuserdatauv(L, sizeof *s, 0);
  memset(s, 0, sizeof *s);
  if (luaL_newmetatable(L, SURFACE_MT)) {
    lua_pushcfunction(L, surface_gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_setmetatable(L, -2);
  oc_error err = {OC_OK, ""};
  if ((tree ? oclua_toelevation(L, idx, NULL, &s->src, &err)
            : oc_heightfield_elevation(hf, &s->src, &err)) != OC_OK)
    oclua_liberror(L, FNAME, &err);
  s->has_src = 1;
  s->es.src = &s->src;
  /* a tree's terrain is where its weight reaches 1/2 (Omega_T) */
  s->es.weight = tree ? tree_weight : NULL;
  s->es.weight_bound = tree ? s->src.weight_range : NULL; /* (holes) */
  s->es.wud = tree;
  s->es.T = tree ? OC_ENODE_T : T;
  return &s->es;
}

/* The level of detail of a tree's render: lod = true (c = 1) | false |
** {c = > 0}; 0 when off. */
static double read_lod(const oclua_fields *f, int tree) {
  static const char *const known[] = {"c", NULL};
  lua_State *L = f->L;
  int t = oclua_field_push(f, "lod");
  double c = 0;
  if (t == LUA_TBOOLEAN) {
    c = lua_toboolean(L, -1) ? 1 : 0;
  } else if (t == LUA_TTABLE) {
    oclua_fields g;
    oclua_fields_open(&g, L, lua_gettop(L), f->fname, "lod.", known, 0);
    c = oclua_field_optnumber(&g, "c", OCLUA_POSITIVE, 1);
  } else if (t != LUA_TNIL) {
    oclua_field_error(f, "lod", -1, "must be true, false or {c =}");
  }
  lua_pop(L, 1);
  if (c > 0 && !tree)
    oclua_error(L, f->fname,
                "'lod' applies to elevation trees only (argument #1 is not "
                "one)");
  return c;
}

/* Under lod, the surface becomes the tree seen from the camera: the
** source's footprint k = c times the pixel's angle (oc_render_pixel_angle),
** its weight the tree's under the same view. */
static void surface_lod(lua_State *L, int idx, const oc_esurface *es,
                        const oc_render_params *rp, double c) {
  lsurface *s = (lsurface *)(void *)((char *)es - offsetof(lsurface, es));
  oc_enode_view v = {{rp->camera.eye.x, rp->camera.eye.y, rp->camera.eye.z},
                     c * oc_render_pixel_angle(rp)};
  oc_elevation src;
  oc_error err = {OC_OK, ""};
  if (oc_enode_elevation_view(oclua_testenode(L, idx), NULL, &v, &src, &err))
    oclua_liberror(L, FNAME, &err);
  if (s->src.release) s->src.release(s->src.ud);
  s->src = src;
  s->es.weight = oc_enode_view_weight;
  s->es.weight_bound = oc_enode_view_weight_bound; /* (holes) */
  s->es.wud = src.ud;
}

/* The box the default camera frames: the domain x the elevation range. */
static oc_aabb surface_bounds(const oc_esurface *es) {
  const oc_elevation *e = es->src;
  double lo, hi;
  e->range(e->ud, e->x0, e->y0, e->x1, e->y1, &lo, &hi);
  oc_aabb b = {{e->x0, e->y0, lo}, {e->x1, e->y1, hi}};
  return b;
}

static void set_number(lua_State *L, const char *k, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, k);
}

/* Pushes the statistics table; calls_total only when counted. */
static void push_stats(lua_State *L, const oc_render_stats *st, int total) {
  lua_createtable(L, 0, 6);
  lua_pushinteger(L, (lua_Integer)st->pixels);
  lua_setfield(L, -2, "pixels");
  lua_pushinteger(L, (lua_Integer)st->hits);
  lua_setfield(L, -2, "hits");
  set_number(L, "calls", st->calls);
  set_number(L, "calls_per_pixel", st->calls_per_pixel);
  if (!total) return;
  set_number(L, "calls_total", st->calls_total);
  set_number(L, "calls_total_per_pixel", st->calls_total_per_pixel);
}

/* The statistics of a render in two phases: from the geometry image, and
** the shading's from the final image's "evals" channel when it has one. */
static int stats_of(const oc_image *geo, const oc_image *img,
                    oc_render_stats *st) {
  size_t npx = (size_t)oc_image_width(geo) * oc_image_height(geo);
  const float *g = oc_image_cdata(geo), *q = oc_image_cdata(img);
  int nch = oc_image_channels(img), total = nch > 4;
  memset(st, 0, sizeof *st);
  st->pixels = (long long)npx;
  for (size_t k = 0; k < npx; k++) {
    st->hits += g[k * OC_RG_COUNT + OC_RG_HIT] > 0;
    st->calls += g[k * OC_RG_COUNT + OC_RG_EVALS];
    if (total) st->calls_total += q[k * nch + nch - 1];
  }
  st->calls_per_pixel = st->calls / (double)npx;
  st->calls_total_per_pixel = st->calls_total / (double)npx;
  return total;
}

/* ---- outcrop.render -------------------------------------------------- */

static int l_render(lua_State *L) {
  static const char *const known[] = {
      "camera",      "size",          "sun",
      "sky",         "shadows",       "ao",
      "ao_distance", "fog",           "color",
      "palette",     "rules",         "background",
      "texture",     "texture_scale", "aov",
      "threshold",   "max_distance",  "tracer",
      "exposure",    "tone",          "lod",
      NULL};
  static const char *const tracers[] = {"segment", "sphere", NULL};
  static const char *const tones[] = {"clamp", "filmic", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_render_params rp;
  oclua_progress pl;
  camera_in ci;
  source src;
  double bg[4] = {0, 0, 0, 1};
  oclua_checkargs(L, 2, FNAME,
                  "(node, heightfield or elevation tree, {camera =, size =, "
                  "sun =, sky =, "
                  "shadows =, ao =, fog =, color =, background =, aov =, "
                  "...})");
  int tree = oclua_testenode(L, 1) != NULL;
  if (!tree && !oclua_isheightfield(L, 1) && !oclua_testnode(L, 1))
    oclua_error(L, FNAME,
                "argument #1 must be an outcrop node or a heightfield (or an "
                "elevation tree) (got %s)",
                oclua_got(L, 1));
  if (!tree && !oclua_isheightfield(L, 1))
    oclua_checknode(L, 1, FNAME, "argument #1");
  lua_settop(L, 2);
  if (lua_isnil(L, 2)) {
    lua_newtable(L);
    lua_replace(L, 2);
  }
  int elev = pin_surface(L, 1);
  oclua_fields_open(&f, L, 2, FNAME, NULL, known, 0);
  oc_render_defaults(&rp);
  read_size(&f, &rp);
  read_camera(&f, &rp, &ci);
  read_sun(&f, &rp);
  int has_sky = read_rgb(&f, "sky", rp.sky, 0);
  if (has_sky) memcpy(rp.fog_color, rp.sky, sizeof rp.sky);
  rp.shadows = oclua_field_optbool(&f, "shadows", rp.shadows);
  rp.ao = oclua_field_optbool(&f, "ao", rp.ao);
  rp.ao_distance =
      oclua_field_optnumber(&f, "ao_distance", OCLUA_POSITIVE, rp.ao_distance);
  read_fog(&f, &rp);
  int nbg = read_rgb(&f, "background", bg, 1);
  if (nbg) {
    rp.has_background = 1;
    memcpy(rp.background, bg, sizeof bg);
  }
  rp.texture = read_range(&f, "texture", 0, 1, rp.texture);
  rp.texture_scale = oclua_field_optnumber(&f, "texture_scale", OCLUA_POSITIVE,
                                           rp.texture_scale);
  rp.aov = oclua_field_optbool(&f, "aov", rp.aov);
  rp.exposure = read_range(&f, "exposure", -MAX_EV, MAX_EV, rp.exposure);
  rp.tone = oclua_field_optoption(&f, "tone", tones, 0) == 1 ? OC_TONE_FILMIC
                                                             : OC_TONE_CLAMP;
  double t = oclua_field_optnumber(&f, "threshold", OCLUA_POSITIVE, 0);
  if (t == 0) t = oclua_threshold(L, FNAME);
  rp.threshold = t;
  rp.max_distance =
      oclua_field_optnumber(&f, "max_distance", OCLUA_POSITIVE, 0);
  rp.tracer = oclua_field_optoption(&f, "tracer", tracers, 0) == 1
                  ? OC_TRACE_SPHERE
                  : OC_TRACE_SEGMENT;
  read_color(&f, &rp, &src);
  double lod = read_lod(&f, tree);
  if (src.kind == SRC_FIELD && rp.stops == NULL)
    rp.stops = oc_palette_strata(&rp.nstops);

  const oc_program *prog = NULL;
  const oc_esurface *es = NULL;
  if (elev) {
    es = surface_at(L, 1, t);
    if (oc_render_frame_box(surface_bounds(es), &rp, ci.has_eye, ci.has_target,
                            &err))
      oclua_liberror(L, FNAME, &err);
  } else {
    prog = oclua_program_at(L, 1, FNAME, t);
    if (oc_render_default_camera(prog, &rp, ci.has_eye, ci.has_target, &err))
      oclua_liberror(L, FNAME, &err);
  }
  /* The colour node is compiled at the render's threshold: were it the
  ** main node itself, another threshold would replace (and free) the
  ** program in use. Everything is checked before any work (a colour
  ** function runs between the lib's passes). */
  if (src.kind == SRC_FIELD)
    rp.color_field = oclua_program_at(L, src.idx, FNAME, t);
  if (src.kind == SRC_BLEND)
    rp.blend_fields = oclua_blend_programs(L, src.idx, rp.nblend, FNAME, t);
  if (prog ? oc_render_check(prog, &rp, &err)
           : oc_render_check_surface(es, &rp, &err) ||
                 oc_render_check_shade(&rp, &err))
    oclua_liberror(L, FNAME, &err);
  /* (after the checks: the camera is known and valid) */
  if (lod > 0) surface_lod(L, 1, es, &rp, lod);
  memset(&rp.progress, 0, sizeof rp.progress);
  rp.progress = oclua_progress_start(L, &pl, FNAME);
  char warning[300] = "";
  rp.warning = warning;
  rp.warning_size = sizeof warning;

  if (src.kind != SRC_FUNCTION) {
    oclua_image *u = oclua_newimage(L);
    oc_render_stats st;
    u->img =
        es ? oc_render_surface(es, &rp, &st, &err) : oc_render(prog, &rp, &err);
    if (u->img == NULL) render_error(L, &pl, &err);
    oclua_progress_end(&pl);
    if (warning[0]) oclua_warn(L, FNAME, "%s", warning);
    if (!es) return 1;
    push_stats(L, &st, 1);
    return 2;
  }

  /* A Lua function colours the pixels, serially, between the two passes;
  ** every buffer is a userdata, so an error in it leaks nothing. */
  oclua_image *g = oclua_newimage(L);
  pl.span = 0.2;
  g->img = es ? oc_render_surface_geometry(es, &rp, &err)
              : oc_render_geometry(prog, &rp, &err);
  if (g->img == NULL) render_error(L, &pl, &err);
  pl.base = 0.2, pl.span = 0.6;
  const float *albedo = run_colour_function(L, src.idx, g->img, &pl);
  pl.base = 0.8, pl.span = 0.2;
  /* The function may have queried the node at another threshold, which
  ** recompiles it: fetch the program again. */
  if (!es) prog = oclua_program_at(L, 1, FNAME, t);
  oclua_image *u = oclua_newimage(L);
  u->img = es ? oc_render_surface_shade(es, &rp, g->img, albedo, &err)
              : oc_render_shade(prog, &rp, g->img, albedo, &err);
  if (u->img == NULL) render_error(L, &pl, &err);
  oclua_progress_end(&pl);
  oc_render_stats st;
  int total = es ? stats_of(g->img, u->img, &st) : 0;
  oc_image_free(g->img); /* big: not left to the collector */
  g->img = NULL;
  if (warning[0]) oclua_warn(L, FNAME, "%s", warning);
  if (!es) return 1;
  push_stats(L, &st, total);
  return 2;
}

static const luaL_Reg render_funcs[] = {{"render", l_render}, {NULL, NULL}};

void oclua_open_render(lua_State *L) {
  luaL_setfuncs(L, render_funcs, 0);
}
