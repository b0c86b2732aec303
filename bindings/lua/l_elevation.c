/*
** l_elevation.c — elevation trees (Génevaux et al. 2015): the
** outcrop.elevation table and the elevation userdata.
**
**   disc{center = {x, y}, radius =, height = 0, noise = {kind = "plain"|
**        "turbulence"|"ridged", amplitude =, wavelength = radius / 4,
**        octaves = 6, gain = 0.5, lacunarity = 2, seed = scene seed}}
**   blend{e1, e2, ...}
**   replace(a, b [, {weight = "a"|"lerp"}])             weight "a"
**   add(a, b [, {weight = "a"|"sum", below =, fade = 10}])
**   warp(e, {amplitude =, wavelength =, octaves = 3, seed =})
**   transform(e, {translate = {x, y}, rotate = degrees, scale = 1,
**        vscale = 1, voffset = 0})
**
** Methods: e:eval(x, y) -> f, alpha; e:gradient(x, y) -> df/dx, df/dy;
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
  static const char *const known[] = {"weight", "below", "fade", NULL};
  static const char *const weights[] = {"a", "sum", NULL};
  const char *fname = "outcrop.elevation.add";
  oclua_fields f;
  oc_enode *a = oclua_checkenode(L, 1, fname, "argument #1");
  oc_enode *b = oclua_checkenode(L, 2, fname, "argument #2");
  options(L, &f, fname, 3,
          "(a, b [, {weight = \"a\"|\"sum\", below =, fade =}])", known);
  oc_enode_add_params p = {0};
  p.sum_weight = oclua_field_optoption(&f, "weight", weights, 0);
  p.below = oclua_field_push(&f, "below") != LUA_TNIL;
  lua_pop(L, 1);
  if (p.below) p.below_z = oclua_field_number(&f, "below", OCLUA_FINITE);
  p.fade = oclua_field_optnumber(&f, "fade", OCLUA_POSITIVE, 10);
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

/* ---- methods ---------------------------------------------------------- */

static oc_enode *self(lua_State *L, const char *fname) {
  return oclua_checkenode(L, 1, fname, "self");
}

static void point(lua_State *L, const char *fname, double *x, double *y) {
  oclua_checkargs(L, 3, fname, "(x, y)");
  for (int i = 2; i <= 3; i++)
    if (lua_type(L, i) != LUA_TNUMBER)
      oclua_error(L, fname, "argument #%d must be a number (got %s)", i - 1,
                  oclua_got(L, i));
  *x = lua_tonumber(L, 2);
  *y = lua_tonumber(L, 3);
}

static int e_eval(lua_State *L) {
  double x, y;
  oc_enode *e = self(L, "elevation:eval");
  point(L, "elevation:eval", &x, &y);
  oc_enode_sample s;
  oc_enode_eval(e, x, y, &s);
  lua_pushnumber(L, s.f);
  lua_pushnumber(L, s.a);
  return 2;
}

static int e_gradient(lua_State *L) {
  double x, y;
  oc_enode *e = self(L, "elevation:gradient");
  point(L, "elevation:gradient", &x, &y);
  oc_enode_sample s;
  oc_enode_eval(e, x, y, &s);
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
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, (lua_Integer)st.nodes);
  lua_setfield(L, -2, "nodes");
  lua_pushinteger(L, (lua_Integer)st.primitives);
  lua_setfield(L, -2, "primitives");
  lua_pushinteger(L, (lua_Integer)st.bytes);
  lua_setfield(L, -2, "bytes");
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
      {"disc", l_disc}, {"blend", l_blend}, {"replace", l_replace},
      {"add", l_add},   {"warp", l_warp},   {"transform", l_transform},
      {NULL, NULL}};
  oclua_newmeta(L, OCLUA_ELEVATION, meta, methods);
  lua_pop(L, 1);
  luaL_newlib(L, funcs);
  lua_setfield(L, -2, "elevation");
}
