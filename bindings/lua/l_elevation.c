/*
** l_elevation.c — elevation trees (Génevaux et al. 2015): the
** outcrop.elevation table and the elevation userdata.
**
**   disc{center = {x, y}, radius =, height = 0, noise = {kind = "plain"|
**        "turbulence"|"ridged", amplitude =, wavelength = radius / 4,
**        octaves = 6, gain = 0.5, lacunarity = 2, seed = scene seed}}
**   blend{e1, e2, ...}
**   replace(a, b [, {weight = "a"|"lerp"}])             weight "a"
**   add(a, b [, {weight = "a"|"sum", below =, fade = 10, slope = degrees,
**        slope_fade = 10, slope_step = 5}])
**   warp(e, {amplitude =, wavelength =, octaves = 3, seed =})
**   transform(e, {translate = {x, y}, rotate = degrees, scale = 1,
**        vscale = 1, voffset = 0})
**   lake{center = {x, y}, radius = r | {r1, r2, ...} | contour = {{x, y},
**        ...}, level = 0, falloff = max r / 2, depth = 5, bank = 2,
**        profile = {{d, v}, ...} | profiles = {{angle =, knots =}, ...}}
**   image{heightfield = hf, weight = hf2, quad = {{x, y} x 4} |
**        segment = {{x0, y0}, {x1, y1}}, width = | curve = {{x, y}, ...},
**        spline = "catmull"|"bezier"|"linear", width =; height = 1,
**        offset = 0, falloff = sqrt(area) / 10 (along a curve, at most a
**        quarter of the width)}
**   lod(a, b, {wavelength =, k0 = 0, k1 = 1})  (b without a view)
**
** Methods: e:eval(x, y [, view]) -> f, alpha; e:gradient(x, y [, view])
** -> df/dx, df/dy, view = {eye = {x, y, z}, k =} (level of detail);
** e:bounds() -> x0, y0, fmin, x1, y1, fmax (the box holding the support
** and the range of f); e:lipschitz(); e:stats() -> {nodes=, primitives=,
** bytes=}; e:kind().
**
** Nodes are immutable and reference counted like 3D nodes: a node keeps
** its children alive, and a call keeps the nodes it uses on its stack
** until the library has retained them.
*/
#include <math.h>
#include <stdio.h>

#include "l_elevation.h"
#include "l_handle.h"
#include "l_heightfield.h"

typedef struct oclua_enode {
  oc_enode *e; /* NULL while a constructor runs, and once collected */
} oclua_enode;

static oclua_enode *newenode(lua_State *L) {
  oclua_enode *u = lua_newuserdatauv(L, sizeof *u, 0);
  u->e = NULL;
  luaL_setmetatable(L, OCLUA_ELEVATION);
  return u;
}

static int setenode(lua_State *L, oclua_enode *u, oc_enode *e,
                    const oc_error *err, const char *fname) {
  if (!e) return oclua_liberror(L, fname, err);
  u->e = e;
  return 1;
}

oc_enode *oclua_testenode(lua_State *L, int idx) {
  oclua_enode *u = luaL_testudata(L, idx, OCLUA_ELEVATION);
  return u ? u->e : NULL;
}

oc_enode *oclua_checkenode(lua_State *L, int idx, const char *fname,
                           const char *what) {
  oc_enode *e = oclua_testenode(L, idx);
  if (!e)
    oclua_error(L, fname, "%s must be an elevation node (got %s)", what,
                oclua_got(L, idx));
  return e;
}

/* (e, [{options}]) or (a, b, [{options}]): the options table opened at
** index opt, or an empty one. */
static void options(lua_State *L, oclua_fields *f, const char *fname, int opt,
                    const char *usage, const char *const *known) {
  oclua_checkargs(L, opt, fname, usage);
  if (lua_isnoneornil(L, opt)) {
    lua_settop(L, opt - 1);
    lua_newtable(L);
  } else if (!lua_istable(L, opt)) {
    oclua_error(L, fname, "argument #%d must be a table %s (got %s)", opt,
                usage, oclua_got(L, opt));
  }
  oclua_fields_open(f, L, opt, fname, NULL, known, 0);
}

/* ---- primitives ------------------------------------------------------- */

static void read_noise(oclua_fields *f, double radius, oc_enode_noise *nz) {
  static const char *const known[] = {"kind",    "amplitude", "wavelength",
                                      "octaves", "gain",      "lacunarity",
                                      "seed",    NULL};
  static const char *const kinds[] = {"plain", "turbulence", "ridged", NULL};
  lua_State *L = f->L;
  nz->kind = OC_ENOISE_NONE;
  if (oclua_field_push(f, "noise") == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  if (!lua_istable(L, -1)) oclua_field_error(f, "noise", -1, "must be a table");
  oclua_fields n;
  oclua_fields_open(&n, L, lua_gettop(L), f->fname, "noise.", known, 0);
  nz->kind = (oc_enoise_kind)(OC_ENOISE_PLAIN +
                              oclua_field_optoption(&n, "kind", kinds, 0));
  nz->amplitude = oclua_field_number(&n, "amplitude", OCLUA_FINITE);
  if (nz->amplitude < 0)
    oclua_error(L, f->fname, "'noise.amplitude' must be >= 0 (got %f)",
                nz->amplitude);
  nz->wavelength =
      oclua_field_optnumber(&n, "wavelength", OCLUA_POSITIVE, radius / 4);
  nz->octaves = (int)oclua_field_optint(&n, "octaves", 1, 16, 6);
  nz->gain = oclua_field_optnumber(&n, "gain", OCLUA_POSITIVE, 0.5);
  nz->lacunarity = oclua_field_optnumber(&n, "lacunarity", OCLUA_POSITIVE, 2);
  nz->seed = oclua_field_seed(&n, "seed");
  lua_pop(L, 1);
}

static int l_disc(lua_State *L) {
  static const char *const known[] = {"center", "radius", "height", "noise",
                                      NULL};
  const char *fname = "outcrop.elevation.disc";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_enode_disc_params p = {0};
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  double c[2];
  if (!oclua_field_numbers(&f, "center", 2, c, "must be {x, y}"))
    oclua_field_missing(&f, "center", "must be {x, y}");
  p.cx = c[0];
  p.cy = c[1];
  p.radius = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  p.height = oclua_field_optnumber(&f, "height", OCLUA_FINITE, 0);
  read_noise(&f, p.radius, &p.noise);
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_disc(&p, &err), &err, fname);
}

/* ---- curves ----------------------------------------------------------- */

#define MAX_POINTS (1 << 20)

/* points = {{x, y, z}, ...}: pushed as a Lua-owned array (no leak on
** error); raw reads, so no metamethod runs. */
static oc_vec3 *read_points(oclua_fields *f, size_t *n) {
  lua_State *L = f->L;
  if (oclua_field_push(f, "points") != LUA_TTABLE)
    oclua_field_error(f, "points", -1, "must be an array of {x, y, z}");
  int t = lua_gettop(L);
  lua_Integer m = (lua_Integer)lua_rawlen(L, t);
  if (m < 2)
    oclua_error(L, f->fname, "'points' must hold at least 2 points (got %I)",
                m);
  if (m > MAX_POINTS)
    oclua_error(L, f->fname, "'points': %I points, at most %d", m, MAX_POINTS);
  oc_vec3 *p = lua_newuserdatauv(L, (size_t)m * sizeof *p, 0);
  for (lua_Integer i = 1; i <= m; i++) {
    lua_rawgeti(L, t, i);
    p[i - 1] = oclua_tovec(L, -1, f->fname, "points", i);
    lua_pop(L, 1);
  }
  *n = (size_t)m;
  return p; /* the table and the array stay on the stack */
}

static oc_ecurve_spline read_spline(oclua_fields *f) {
  static const char *const splines[] = {"catmull", "bezier", "linear", NULL};
  return (oc_ecurve_spline)oclua_field_optoption(f, "spline", splines, 0);
}

/* knots = {{d, v}, ...} at stack index idx into Lua-owned arrays. */
static size_t read_knots(lua_State *L, int idx, const char *fname,
                         const char *label, const double **d,
                         const double **v) {
  if (!lua_istable(L, idx))
    oclua_error(L, fname, "'%s' must be an array of {d, v} (got %s)", label,
                oclua_got(L, idx));
  lua_Integer m = (lua_Integer)lua_rawlen(L, idx);
  if (m < 2)
    oclua_error(L, fname, "'%s' must hold at least 2 knots {d, v} (got %I)",
                label, m);
  if (m > MAX_POINTS)
    oclua_error(L, fname, "'%s': %I knots, at most %d", label, m, MAX_POINTS);
  double *a = lua_newuserdatauv(L, 2 * (size_t)m * sizeof *a, 0);
  for (lua_Integer i = 1; i <= m; i++) {
    lua_rawgeti(L, idx, i);
    int ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 2;
    for (int k = 1; ok && k <= 2; k++) {
      lua_rawgeti(L, -1, k);
      ok = lua_type(L, -1) == LUA_TNUMBER && isfinite(lua_tonumber(L, -1));
      if (ok) a[(k - 1) * m + (i - 1)] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
    if (!ok)
      oclua_error(L, fname, "'%s[%I]' must be {d, v} with finite numbers",
                  label, i);
    lua_pop(L, 1);
  }
  *d = a;
  *v = a + m;
  return (size_t)m;
}

/* The array 'profiles' at the top of the stack, {KEY =, knots = {{d, v},
** ...}} each, KEY a number (finite when `finite`) described by `what`,
** into a Lua-owned array pushed with the knots' arrays (raw reads). */
static oc_enode_profile *read_profiles(lua_State *L, const oclua_fields *f,
                                       const char *key, const char *what,
                                       int finite, size_t *n) {
  const char *fname = f->fname;
  int t = lua_gettop(L);
  if (!lua_istable(L, t)) {
    char msg[64];
    snprintf(msg, sizeof msg, "must be an array of {%s =, knots =}", key);
    oclua_field_error(f, "profiles", t, msg);
  }
  lua_Integer m = (lua_Integer)lua_rawlen(L, t);
  if (m < 1 || m > 4096)
    oclua_error(L, fname, "'profiles' must hold 1 to 4096 profiles (got %I)",
                m);
  luaL_checkstack(L, (int)m + 8, "too many profiles");
  oc_enode_profile *pr = lua_newuserdatauv(L, (size_t)m * sizeof *pr, 0);
  for (lua_Integer i = 1; i <= m; i++) {
    char label[48];
    snprintf(label, sizeof label, "profiles[%lld]", (long long)i);
    if (lua_rawgeti(L, t, i) != LUA_TTABLE)
      oclua_error(L, fname, "'%s' must be {%s =, knots = {{d, v}, ...}}", label,
                  key);
    lua_getfield(L, -1, key);
    if (lua_type(L, -1) != LUA_TNUMBER ||
        (finite && !isfinite(lua_tonumber(L, -1))))
      oclua_error(L, fname, "'%s.%s' must be %s", label, key, what);
    pr[i - 1].at = lua_tonumber(L, -1);
    lua_pop(L, 1);
    lua_getfield(L, -1, "knots");
    snprintf(label, sizeof label, "profiles[%lld].knots", (long long)i);
    pr[i - 1].n =
        read_knots(L, lua_gettop(L), fname, label, &pr[i - 1].d, &pr[i - 1].v);
    lua_replace(L, -3); /* keep the knots' array, drop the tables */
    lua_pop(L, 1);
  }
  *n = (size_t)m;
  return pr;
}

static int l_curve(lua_State *L) {
  static const char *const known[] = {"points",  "radius",   "core", "spline",
                                      "profile", "profiles", NULL};
  const char *fname = "outcrop.elevation.curve";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_enode_curve_params p = {0};
  p.points = read_points(&f, &p.npoints);
  p.spline = read_spline(&f);
  p.radius = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  p.core = oclua_field_optnumber(&f, "core", OCLUA_FINITE, 0);
  int one = oclua_field_push(&f, "profile") != LUA_TNIL;
  int many = oclua_field_push(&f, "profiles") != LUA_TNIL;
  if (one == many)
    oclua_error(L, fname,
                "give either 'profile' = {{d, v}, ...} or "
                "'profiles' = {{at =, knots = {{d, v}, ...}}, ...}");
  oc_enode_profile *pr;
  if (one) {
    pr = lua_newuserdatauv(L, sizeof *pr, 0);
    pr->at = 0;
    pr->n = read_knots(L, lua_gettop(L) - 2, fname, "profile", &pr->d, &pr->v);
    p.nprofiles = 1;
  } else {
    pr = read_profiles(L, &f, "at", "a number in [0, 1]", 0, &p.nprofiles);
  }
  p.profiles = pr;
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_curve(&p, &err), &err, fname);
}

static int l_river(lua_State *L) {
  static const char *const known[] = {"points", "kind",   "width", "depth",
                                      "bank",   "spline", NULL};
  static const char *const kinds[] = {"stream", "river", "meander", "main",
                                      NULL};
  const char *fname = "outcrop.elevation.river";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_enode_river_params p = {0};
  p.points = read_points(&f, &p.npoints);
  p.spline = read_spline(&f);
  p.kind = (oc_river_kind)oclua_field_optoption(&f, "kind", kinds, 1);
  p.width = oclua_field_optnumber(&f, "width", OCLUA_POSITIVE, 0);
  p.depth = oclua_field_optnumber(&f, "depth", OCLUA_POSITIVE, 0);
  p.bank = oclua_field_optnumber(&f, "bank", OCLUA_POSITIVE, 0);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_river(&p, &err), &err, fname);
}

static int l_road(lua_State *L) {
  static const char *const known[] = {"points",     "width",  "shoulder",
                                      "embankment", "spline", NULL};
  const char *fname = "outcrop.elevation.road";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_enode_road_params p = {0};
  p.points = read_points(&f, &p.npoints);
  p.spline = read_spline(&f);
  p.width = oclua_field_optnumber(&f, "width", OCLUA_POSITIVE, 7);
  p.shoulder = oclua_field_optnumber(&f, "shoulder", OCLUA_FINITE, 1.5);
  if (p.shoulder < 0)
    oclua_error(L, fname, "'shoulder' must be >= 0 (got %f)", p.shoulder);
  p.embankment = oclua_field_optnumber(&f, "embankment", OCLUA_POSITIVE, 12);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_road(&p, &err), &err, fname);
}

/* ---- operators -------------------------------------------------------- */

static int l_blend(lua_State *L) {
  const char *fname = "outcrop.elevation.blend";
  oclua_checkargs(L, 1, fname, "{e1, e2, ...}");
  if (!lua_istable(L, 1))
    oclua_error(L, fname, "argument #1 must be a table {e1, e2, ...} (got %s)",
                oclua_got(L, 1));
  lua_Integer n = (lua_Integer)lua_rawlen(L, 1);
  if (n < 1)
    oclua_error(L, fname, "needs at least one elevation node in {e1, e2, ...}");
  if (n > 1 << 24)
    oclua_error(L, fname, "%I elevation nodes: at most %d", n, 1 << 24);
  /* the children stay referenced by the table copy below (no metamethod
  ** runs: raw reads) until the node has retained them */
  lua_createtable(L, (int)n, 0);
  int keep = lua_gettop(L);
  oc_enode **kids = lua_newuserdatauv(L, (size_t)n * sizeof *kids, 0);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, 1, i);
    oc_enode *e = oclua_testenode(L, -1);
    if (!e)
      oclua_error(L, fname, "element %I must be an elevation node (got %s)", i,
                  oclua_got(L, -1));
    kids[i - 1] = e;
    lua_rawseti(L, keep, i);
  }
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_blend(kids, (size_t)n, &err), &err, fname);
}

static int l_replace(lua_State *L) {
  static const char *const known[] = {"weight", NULL};
  static const char *const weights[] = {"a", "lerp", NULL};
  const char *fname = "outcrop.elevation.replace";
  oclua_fields f;
  oc_enode *a = oclua_checkenode(L, 1, fname, "argument #1");
  oc_enode *b = oclua_checkenode(L, 2, fname, "argument #2");
  options(L, &f, fname, 3, "(a, b [, {weight = \"a\"|\"lerp\"}])", known);
  int lerp = oclua_field_optoption(&f, "weight", weights, 0);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_replace(a, b, lerp, &err), &err, fname);
}

static int l_add(lua_State *L) {
  static const char *const known[] = {
      "weight", "below", "fade", "slope", "slope_fade", "slope_step", NULL};
  static const char *const weights[] = {"a", "sum", NULL};
  const char *fname = "outcrop.elevation.add";
  oclua_fields f;
  oc_enode *a = oclua_checkenode(L, 1, fname, "argument #1");
  oc_enode *b = oclua_checkenode(L, 2, fname, "argument #2");
  options(L, &f, fname, 3,
          "(a, b [, {weight = \"a\"|\"sum\", below =, fade =, slope =, "
          "slope_fade =, slope_step =}])",
          known);
  oc_enode_add_params p = {0};
  p.sum_weight = oclua_field_optoption(&f, "weight", weights, 0);
  p.below = oclua_field_push(&f, "below") != LUA_TNIL;
  lua_pop(L, 1);
  if (p.below) p.below_z = oclua_field_number(&f, "below", OCLUA_FINITE);
  p.fade = oclua_field_optnumber(&f, "fade", OCLUA_POSITIVE, 10);
  p.slope = oclua_field_push(&f, "slope") != LUA_TNIL;
  lua_pop(L, 1);
  /* the ranges (slope in [0, 90)) are checked by the library, which names
  ** the field */
  if (p.slope) p.slope_deg = oclua_field_number(&f, "slope", OCLUA_FINITE);
  p.slope_fade = oclua_field_optnumber(&f, "slope_fade", OCLUA_POSITIVE, 10);
  p.slope_step = oclua_field_optnumber(&f, "slope_step", OCLUA_POSITIVE, 5);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_add(a, b, &p, &err), &err, fname);
}

static int l_warp(lua_State *L) {
  static const char *const known[] = {"amplitude", "wavelength", "octaves",
                                      "seed", NULL};
  const char *fname = "outcrop.elevation.warp";
  oclua_fields f;
  oc_enode *e = oclua_checkenode(L, 1, fname, "argument #1");
  options(L, &f, fname, 2, "(e, {amplitude =, wavelength =, octaves =})",
          known);
  oc_enode_warp_params p;
  p.amplitude = oclua_field_number(&f, "amplitude", OCLUA_FINITE);
  if (p.amplitude < 0)
    oclua_error(L, fname, "'amplitude' must be >= 0 (got %f)", p.amplitude);
  p.wavelength = oclua_field_number(&f, "wavelength", OCLUA_POSITIVE);
  p.octaves = (int)oclua_field_optint(&f, "octaves", 1, 16, 3);
  p.seed = oclua_field_seed(&f, "seed");
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_warp(e, &p, &err), &err, fname);
}

static int l_transform(lua_State *L) {
  static const char *const known[] = {"translate", "rotate",  "scale",
                                      "vscale",    "voffset", NULL};
  const char *fname = "outcrop.elevation.transform";
  oclua_fields f;
  oc_enode *e = oclua_checkenode(L, 1, fname, "argument #1");
  options(L, &f, fname, 2,
          "(e, {translate = {x, y}, rotate =, scale =, vscale =, voffset =})",
          known);
  oc_enode_xform x = {0};
  double t[2] = {0, 0};
  oclua_field_numbers(&f, "translate", 2, t, "must be {x, y}");
  x.tx = t[0];
  x.ty = t[1];
  x.angle = oclua_field_optnumber(&f, "rotate", OCLUA_FINITE, 0);
  x.scale = oclua_field_optnumber(&f, "scale", OCLUA_POSITIVE, 1);
  x.vscale = oclua_field_optnumber(&f, "vscale", OCLUA_NONZERO, 1);
  x.voffset = oclua_field_optnumber(&f, "voffset", OCLUA_FINITE, 0);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_transform(e, &x, &err), &err, fname);
}

/* ---- lake and image --------------------------------------------------- */

static int l_lake(lua_State *L) {
  static const char *const known[] = {
      "center", "radius", "contour", "level",    "falloff",
      "depth",  "bank",   "profile", "profiles", NULL};
  const char *fname = "outcrop.elevation.lake";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_enode_lake_params p = {0};
  double c[2];
  if (!oclua_field_numbers(&f, "center", 2, c, "must be {x, y}"))
    oclua_field_missing(&f, "center", "must be {x, y}");
  p.cx = c[0];
  p.cy = c[1];
  int tr = oclua_field_push(&f, "radius"), ir = lua_gettop(L);
  int tc = oclua_field_push(&f, "contour"), ic = lua_gettop(L);
  if ((tr == LUA_TNIL) == (tc == LUA_TNIL))
    oclua_error(L, fname,
                "give either 'radius' = r or {r1, r2, ...} (at "
                "equal angles from +x) or 'contour' = {{x, y}, ...}");
  if (tr == LUA_TNUMBER) {
    double *r = lua_newuserdatauv(L, sizeof *r, 0);
    *r = lua_tonumber(L, ir);
    if (!(isfinite(*r) && *r > 0))
      oclua_field_error(&f, "radius", ir, "must be a positive number");
    p.radii = r;
    p.nradii = 1;
  } else if (tr == LUA_TTABLE) {
    lua_Integer m = (lua_Integer)lua_rawlen(L, ir);
    if (m < 3 || m > MAX_POINTS)
      oclua_error(L, fname,
                  "'radius' must be a number or hold 3 to %d radii "
                  "(got %I)",
                  MAX_POINTS, m);
    double *r = lua_newuserdatauv(L, (size_t)m * sizeof *r, 0);
    for (lua_Integer i = 1; i <= m; i++) {
      lua_rawgeti(L, ir, i);
      r[i - 1] = lua_tonumber(L, -1);
      if (lua_type(L, -1) != LUA_TNUMBER ||
          !(isfinite(r[i - 1]) && r[i - 1] > 0))
        oclua_error(L, fname, "'radius[%I]' must be a positive number (got %s)",
                    i, oclua_got(L, -1));
      lua_pop(L, 1);
    }
    p.radii = r;
    p.nradii = (size_t)m;
  } else if (tr != LUA_TNIL) {
    oclua_field_error(&f, "radius", ir, "must be a number or {r1, r2, ...}");
  } else {
    p.contour =
        oclua_read_xy(L, ic, fname, "contour", 3, MAX_POINTS, &p.ncontour);
  }
  p.level = oclua_field_optnumber(&f, "level", OCLUA_FINITE, 0);
  p.falloff = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, 0);
  p.depth = oclua_field_optnumber(&f, "depth", OCLUA_POSITIVE, 5);
  p.bank = oclua_field_optnumber(&f, "bank", OCLUA_FINITE, 2);
  if (p.bank < 0) oclua_error(L, fname, "'bank' must be >= 0 (got %f)", p.bank);
  int one = oclua_field_push(&f, "profile") != LUA_TNIL;
  int many = oclua_field_push(&f, "profiles") != LUA_TNIL;
  if (one && many)
    oclua_error(L, fname,
                "give 'profile' = {{d, v}, ...} or 'profiles' = "
                "{{angle =, knots = {{d, v}, ...}}, ...}, not both");
  oc_enode_profile *pr = NULL;
  if (one) {
    pr = lua_newuserdatauv(L, sizeof *pr, 0);
    pr->at = 0;
    pr->n = read_knots(L, lua_gettop(L) - 2, fname, "profile", &pr->d, &pr->v);
    p.nprofiles = 1;
  } else if (many) {
    pr = read_profiles(L, &f, "angle", "a number of degrees in [0, 360)", 1,
                       &p.nprofiles);
  }
  p.profiles = pr;
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_lake(&p, &err), &err, fname);
}

static int l_image(lua_State *L) {
  static const char *const known[] = {
      "heightfield", "weight", "quad",   "segment", "curve", "spline",
      "width",       "height", "offset", "falloff", NULL};
  const char *fname = "outcrop.elevation.image";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_enode_image_params p = {0};
  /* the grids stay on the stack and pinned until the node retains them:
  ** an option's metamethod could close them */
  int t = oclua_field_push(&f, "heightfield"), ih = lua_gettop(L);
  if (t == LUA_TNIL) oclua_field_missing(&f, "heightfield", "a heightfield");
  if (!oclua_isheightfield(L, ih))
    oclua_field_error(&f, "heightfield", ih, "must be a heightfield");
  p.heightfield = oclua_pinheightfield(L, ih, fname);
  t = oclua_field_push(&f, "weight");
  int iw = lua_gettop(L);
  if (t != LUA_TNIL) {
    if (!oclua_isheightfield(L, iw))
      oclua_field_error(&f, "weight", iw, "must be a heightfield");
    p.weight = oclua_pinheightfield(L, iw, fname);
  }
  int tq = oclua_field_push(&f, "quad"), iq = lua_gettop(L);
  int ts = oclua_field_push(&f, "segment"), is = lua_gettop(L);
  int tc = oclua_field_push(&f, "curve"), ic = lua_gettop(L);
  if ((tq != LUA_TNIL) + (ts != LUA_TNIL) + (tc != LUA_TNIL) != 1)
    oclua_error(L, fname,
                "give one of 'quad' = {{x, y} x 4} (convex, "
                "counter-clockwise), 'segment' = {{x0, y0}, {x1, y1}} with "
                "'width', or 'curve' = {{x, y}, ...} with 'width'");
  size_t n;
  if (tq != LUA_TNIL) {
    const double *q = oclua_read_xy(L, iq, fname, "quad", 4, 4, &n);
    for (int k = 0; k < 8; k++)
      p.quad[k] = q[k];
    if (oclua_field_push(&f, "width") != LUA_TNIL)
      oclua_error(L, fname,
                  "'width' goes with 'segment' or 'curve', not 'quad'");
    lua_pop(L, 1);
  } else {
    if (ts != LUA_TNIL) {
      const double *q = oclua_read_xy(L, is, fname, "segment", 2, 2, &n);
      for (int k = 0; k < 4; k++)
        p.seg[k] = q[k];
      p.segment = 1;
    } else {
      const double *q = oclua_read_xy(L, ic, fname, "curve", 2, MAX_POINTS, &n);
      oc_vec3 *c = lua_newuserdatauv(L, n * sizeof *c, 0);
      for (size_t k = 0; k < n; k++)
        c[k] = (oc_vec3){q[2 * k], q[2 * k + 1], 0};
      p.curve = c;
      p.ncurve = n;
    }
    if (oclua_field_push(&f, "width") == LUA_TNIL)
      oclua_field_missing(&f, "width",
                          tc != LUA_TNIL ? "the band's width across the curve"
                                         : "the rectangle's width across the "
                                           "segment");
    lua_pop(L, 1);
    p.width = oclua_field_number(&f, "width", OCLUA_POSITIVE);
  }
  if (oclua_field_push(&f, "spline") != LUA_TNIL && tc == LUA_TNIL)
    oclua_error(L, fname, "'spline' goes with 'curve'");
  lua_pop(L, 1);
  p.spline = read_spline(&f);
  p.height = oclua_field_optnumber(&f, "height", OCLUA_NONZERO, 1);
  p.offset = oclua_field_optnumber(&f, "offset", OCLUA_FINITE, 0);
  p.falloff = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, 0);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_image(&p, &err), &err, fname);
}

static int l_lod(lua_State *L) {
  static const char *const known[] = {"wavelength", "k0", "k1", NULL};
  const char *fname = "outcrop.elevation.lod";
  oclua_fields f;
  oc_enode *a = oclua_checkenode(L, 1, fname, "argument #1");
  oc_enode *b = oclua_checkenode(L, 2, fname, "argument #2");
  options(L, &f, fname, 3, "(a, b, {wavelength =, k0 = 0, k1 = 1})", known);
  oc_enode_lod_params p;
  p.wavelength = oclua_field_number(&f, "wavelength", OCLUA_POSITIVE);
  p.k0 = oclua_field_optnumber(&f, "k0", OCLUA_FINITE, 0);
  p.k1 = oclua_field_optnumber(&f, "k1", OCLUA_FINITE, 1);
  if (!(p.k0 >= 0 && p.k0 < p.k1 && p.k1 <= 1))
    oclua_error(L, fname,
                "'k0' and 'k1' must satisfy 0 <= k0 < k1 <= 1 (got %f, %f)",
                p.k0, p.k1);
  oc_error err = {OC_OK, ""};
  oclua_enode *u = newenode(L);
  return setenode(L, u, oc_enode_lod(a, b, &p, &err), &err, fname);
}

/* ---- methods ---------------------------------------------------------- */

static oc_enode *self(lua_State *L, const char *fname) {
  return oclua_checkenode(L, 1, fname, "self");
}

static void point(lua_State *L, const char *fname, double *x, double *y) {
  oclua_checkargs(L, 4, fname, "(x, y [, {eye = {x, y, z}, k =}])");
  for (int i = 2; i <= 3; i++)
    if (lua_type(L, i) != LUA_TNUMBER)
      oclua_error(L, fname, "argument #%d must be a number (got %s)", i - 1,
                  oclua_got(L, i));
  *x = lua_tonumber(L, 2);
  *y = lua_tonumber(L, 3);
}

/* The optional view at index 4: {eye = {x, y, z}, k = >= 0}. */
static int read_view(lua_State *L, const char *fname, oc_enode_view *v) {
  static const char *const known[] = {"eye", "k", NULL};
  if (lua_isnoneornil(L, 4)) return 0;
  if (!lua_istable(L, 4))
    oclua_error(L, fname,
                "argument #3 must be a view {eye = {x, y, z}, k =} (got %s)",
                oclua_got(L, 4));
  oclua_fields f;
  oclua_fields_open(&f, L, 4, fname, NULL, known, 0);
  oc_vec3 eye = oclua_field_vec(&f, "eye");
  v->eye[0] = eye.x, v->eye[1] = eye.y, v->eye[2] = eye.z;
  v->k = oclua_field_number(&f, "k", OCLUA_FINITE);
  if (v->k < 0) oclua_error(L, fname, "'k' must be >= 0 (got %f)", v->k);
  return 1;
}

/* self:<what>(x, y [, view]): the sample there. */
static void sample(lua_State *L, const char *fname, oc_enode_sample *s) {
  double x, y;
  oc_enode_view v;
  oc_enode *e = self(L, fname);
  point(L, fname, &x, &y);
  int has = read_view(L, fname, &v);
  oc_error err = {OC_OK, ""};
  if (oc_enode_eval_view(e, x, y, has ? &v : NULL, s, &err))
    oclua_liberror(L, fname, &err);
}

static int e_eval(lua_State *L) {
  oc_enode_sample s;
  sample(L, "elevation:eval", &s);
  lua_pushnumber(L, s.f);
  lua_pushnumber(L, s.a);
  return 2;
}

static int e_gradient(lua_State *L) {
  oc_enode_sample s;
  sample(L, "elevation:gradient", &s);
  lua_pushnumber(L, s.fx);
  lua_pushnumber(L, s.fy);
  return 2;
}

static int e_bounds(lua_State *L) {
  double b[4], lo, hi;
  oclua_checkargs(L, 1, "elevation:bounds", "()");
  oc_enode_get_bounds(self(L, "elevation:bounds"), b, &lo, &hi);
  lua_pushnumber(L, b[0]);
  lua_pushnumber(L, b[1]);
  lua_pushnumber(L, lo);
  lua_pushnumber(L, b[2]);
  lua_pushnumber(L, b[3]);
  lua_pushnumber(L, hi);
  return 6;
}

static int e_lipschitz(lua_State *L) {
  oclua_checkargs(L, 1, "elevation:lipschitz", "()");
  lua_pushnumber(L, oc_enode_lipschitz(self(L, "elevation:lipschitz")));
  return 1;
}

static int e_stats(lua_State *L) {
  oc_enode_stats st;
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 1, "elevation:stats", "()");
  if (oc_enode_get_stats(self(L, "elevation:stats"), &st, &err))
    return oclua_liberror(L, "elevation:stats", &err);
  oclua_pushstats(L, st.nodes, st.primitives, st.bytes);
  return 1;
}

static int e_kind(lua_State *L) {
  oclua_checkargs(L, 1, "elevation:kind", "()");
  lua_pushstring(L, oc_enode_kind(self(L, "elevation:kind")));
  return 1;
}

static int e_gc(lua_State *L) {
  oclua_enode *u = luaL_checkudata(L, 1, OCLUA_ELEVATION);
  oc_enode_release(u->e);
  u->e = NULL;
  return 0;
}

static int e_tostring(lua_State *L) {
  oclua_enode *u = luaL_checkudata(L, 1, OCLUA_ELEVATION);
  if (!u->e)
    lua_pushliteral(L, OCLUA_ELEVATION ": (collected)");
  else
    lua_pushfstring(L, OCLUA_ELEVATION ": %s", oc_enode_kind(u->e));
  return 1;
}

int oclua_toelevation(lua_State *L, int idx, const double *domain,
                      oc_elevation *src, oc_error *err) {
  oc_enode *e = oclua_testenode(L, idx);
  if (!e) {
    err->code = OC_EINVAL;
    snprintf(err->msg, sizeof err->msg, "not an elevation node");
    return OC_EINVAL;
  }
  return oc_enode_elevation(e, domain, src, err);
}

void oclua_open_elevation(lua_State *L) {
  static const luaL_Reg meta[] = {
      {"__gc", e_gc}, {"__tostring", e_tostring}, {NULL, NULL}};
  static const luaL_Reg methods[] = {
      {"eval", e_eval},     {"gradient", e_gradient},
      {"bounds", e_bounds}, {"lipschitz", e_lipschitz},
      {"stats", e_stats},   {"kind", e_kind},
      {NULL, NULL}};
  static const luaL_Reg funcs[] = {
      {"disc", l_disc}, {"curve", l_curve}, {"river", l_river},
      {"road", l_road}, {"blend", l_blend}, {"replace", l_replace},
      {"add", l_add},   {"warp", l_warp},   {"transform", l_transform},
      {"lake", l_lake}, {"image", l_image}, {"lod", l_lod},
      {NULL, NULL}};
  oclua_newmeta(L, OCLUA_ELEVATION, meta, methods);
  lua_pop(L, 1);
  luaL_newlib(L, funcs);
  lua_setfield(L, -2, "elevation");
}
