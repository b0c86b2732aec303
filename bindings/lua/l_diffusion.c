/*
** l_diffusion.c — feature curves and multigrid diffusion (Hnaidi et al.
** 2010): outcrop.feature_curve and outcrop.diffusion.
**
**   feature_curve{points = {{x, y}, ...}, bezier = false,
**     constraints = {{u =, height =, radius =, slope = {left =, right =,
**     extent = {a, b}}, noise = {amplitude =, roughness = 0}}, ...}}
**   diffusion{size = {nx, ny}, cell = 1, origin = {0, 0}, curves = {...},
**     seed = scene seed, scheme = "upwind"|"paper", converged = false |
**     true | tolerance, noise = {wavelength =, octaves = 4, ratio = 2}}
**     -> heightfield, {smooth =, detail =, amplitude =, roughness =,
**        gradient =, levels =, cycles =, residuals = {...}, strict =,
**        slope =, conflict =}
**
** Methods of a curve: c:length(), c:sample(u) -> {x =, y =, tx =, ty =,
** height =, radius =, left =, right =, extent = {a, b}, amplitude =,
** roughness =} (the attributes the curve carries), c:save() -> the
** compact encoding (a binary string), read back by
** outcrop.feature_curve_load(s).
**
** Curves are immutable and reference counted: a diffusion reads them from
** its table, which keeps them alive for the call.
*/
#include <math.h>
#include <stdio.h>

#include "l_diffusion.h"
#include "l_heightfield.h"
#include "l_progress.h"
#include "l_util.h"

#define OCLUA_FCURVE "outcrop.feature_curve"
#define MAX_POINTS (1 << 20)
#define TOLERANCE 1e-4 /* converged = true */

typedef struct oclua_fcurve {
  oc_fcurve *c; /* NULL while the constructor runs, and once collected */
} oclua_fcurve;

static oc_fcurve *checkcurve(lua_State *L, int idx, const char *fname,
                             const char *what) {
  oclua_fcurve *u = luaL_testudata(L, idx, OCLUA_FCURVE);
  if (!u || !u->c)
    oclua_error(L, fname, "%s must be a feature curve (got %s)", what,
                oclua_got(L, idx));
  return u->c;
}

static oclua_fcurve *newcurve(lua_State *L) {
  oclua_fcurve *u = lua_newuserdatauv(L, sizeof *u, 0);
  u->c = NULL;
  luaL_setmetatable(L, OCLUA_FCURVE);
  return u;
}

/* slope = {left =, right =, extent = {a, b}} of the table at the top. */
static void read_slope(lua_State *L, const char *fname, const char *pre,
                       oc_fconstraint *k) {
  static const char *const known[] = {"left", "right", "extent", NULL};
  oclua_fields s;
  const char *p = lua_pushfstring(L, "%sslope.", pre);
  oclua_fields_open(&s, L, -2, fname, p, known, 0);
  k->left = oclua_field_number(&s, "left", OCLUA_FINITE);
  k->right = oclua_field_number(&s, "right", OCLUA_FINITE);
  double e[2];
  if (!oclua_field_numbers(&s, "extent", 2, e, "must be {a, b}"))
    oclua_field_missing(&s, "extent",
                        "{a, b}: the slopes' extents left and right");
  k->extent_a = e[0], k->extent_b = e[1];
  k->has |= OC_FC_SLOPE;
  lua_pop(L, 1);
}

static void read_noise(lua_State *L, const char *fname, const char *pre,
                       oc_fconstraint *k) {
  static const char *const known[] = {"amplitude", "roughness", NULL};
  oclua_fields s;
  const char *p = lua_pushfstring(L, "%snoise.", pre);
  oclua_fields_open(&s, L, -2, fname, p, known, 0);
  k->amplitude = oclua_field_number(&s, "amplitude", OCLUA_FINITE);
  k->roughness = oclua_field_optnumber(&s, "roughness", OCLUA_FINITE, 0);
  k->has |= OC_FC_NOISE;
  lua_pop(L, 1);
}

/* constraints = {{u =, ...}, ...} into a Lua-owned array pushed. */
static oc_fconstraint *read_constraints(oclua_fields *f, size_t *n) {
  static const char *const known[] = {"u",     "height", "radius",
                                      "slope", "noise",  NULL};
  lua_State *L = f->L;
  const char *fname = f->fname;
  if (oclua_field_push(f, "constraints") != LUA_TTABLE)
    oclua_field_error(f, "constraints", -1,
                      "must be an array of {u =, height =, ...}");
  int t = lua_gettop(L);
  lua_Integer m = (lua_Integer)lua_rawlen(L, t);
  if (m < 2)
    oclua_error(L, fname, "'constraints' must hold at least 2 points (got %I)",
                m);
  if (m > MAX_POINTS)
    oclua_error(L, fname, "'constraints': %I points, at most %d", m,
                MAX_POINTS);
  oc_fconstraint *k = lua_newuserdatauv(L, (size_t)m * sizeof *k, 0);
  for (lua_Integer i = 1; i <= m; i++) {
    oc_fconstraint *c = &k[i - 1];
    *c = (oc_fconstraint){0};
    lua_rawgeti(L, t, i);
    const char *pre = lua_pushfstring(L, "constraints[%I].", i);
    lua_pushvalue(L, -2);
    oclua_fields g;
    oclua_fields_open(&g, L, -1, fname, pre, known, 0);
    c->u = oclua_field_number(&g, "u", OCLUA_FINITE);
    if (oclua_field_push(&g, "height") != LUA_TNIL) {
      lua_pop(L, 1);
      c->height = oclua_field_number(&g, "height", OCLUA_FINITE);
      c->has |= OC_FC_HEIGHT;
    } else {
      lua_pop(L, 1);
    }
    if (oclua_field_push(&g, "radius") != LUA_TNIL) {
      lua_pop(L, 1);
      c->radius = oclua_field_number(&g, "radius", OCLUA_FINITE);
      c->has |= OC_FC_RADIUS;
    } else {
      lua_pop(L, 1);
    }
    if (oclua_field_push(&g, "slope") != LUA_TNIL) read_slope(L, fname, pre, c);
    lua_pop(L, 1);
    if (oclua_field_push(&g, "noise") != LUA_TNIL) read_noise(L, fname, pre, c);
    lua_pop(L, 1);
    lua_pop(L, 3); /* the copy, the prefix, the item */
  }
  *n = (size_t)m;
  return k; /* the table and the array stay on the stack */
}

static int l_feature_curve(lua_State *L) {
  static const char *const known[] = {"points", "bezier", "constraints", NULL};
  const char *fname = "outcrop.feature_curve";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_fcurve_params p = {0};
  oclua_field_push(&f, "points");
  p.xy = oclua_read_xy(L, lua_gettop(L), fname, "points", 2, MAX_POINTS,
                       &p.npoints);
  p.bezier = oclua_field_optbool(&f, "bezier", 0);
  p.constraints = read_constraints(&f, &p.nconstraints);
  oc_error err = {OC_OK, ""};
  oclua_fcurve *u = newcurve(L);
  u->c = oc_fcurve_new(&p, &err);
  if (!u->c) return oclua_liberror(L, fname, &err);
  return 1;
}

/* ---- methods ---------------------------------------------------------- */

static int c_length(lua_State *L) {
  oclua_checkargs(L, 1, "feature_curve:length", "()");
  lua_pushnumber(
      L, oc_fcurve_length(checkcurve(L, 1, "feature_curve:length", "self")));
  return 1;
}

static void setnum(lua_State *L, const char *k, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, k);
}

static int c_sample(lua_State *L) {
  const char *fname = "feature_curve:sample";
  oclua_checkargs(L, 2, fname, "(u)");
  oc_fcurve *c = checkcurve(L, 1, fname, "self");
  double u = lua_tonumber(L, 2);
  if (lua_type(L, 2) != LUA_TNUMBER || !(u >= 0 && u <= 1))
    oclua_error(L, fname, "argument #1 must be a number in [0, 1] (got %s)",
                oclua_got(L, 2));
  oc_fcurve_sample s;
  oc_fcurve_sample_at(c, u, &s);
  lua_createtable(L, 0, 12);
  setnum(L, "x", s.x);
  setnum(L, "y", s.y);
  setnum(L, "tx", s.tx);
  setnum(L, "ty", s.ty);
  if (s.has & OC_FC_HEIGHT) setnum(L, "height", s.height);
  setnum(L, "radius", s.radius);
  if (s.has & OC_FC_SLOPE) {
    setnum(L, "left", s.left);
    setnum(L, "right", s.right);
    lua_createtable(L, 2, 0);
    lua_pushnumber(L, s.extent_a);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, s.extent_b);
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "extent");
  }
  if (s.has & OC_FC_NOISE) {
    setnum(L, "amplitude", s.amplitude);
    setnum(L, "roughness", s.roughness);
  }
  return 1;
}

static int c_save(lua_State *L) {
  const char *fname = "feature_curve:save";
  oclua_checkargs(L, 1, fname, "()");
  oc_fcurve *c = checkcurve(L, 1, fname, "self");
  size_t n = oc_fcurve_encode(c, NULL, 0);
  if (!n) oclua_error(L, fname, "a coordinate or value is too large to encode");
  luaL_Buffer b;
  unsigned char *p = (unsigned char *)luaL_buffinitsize(L, &b, n);
  oc_fcurve_encode(c, p, n);
  luaL_pushresultsize(&b, n);
  return 1;
}

static int l_feature_curve_load(lua_State *L) {
  const char *fname = "outcrop.feature_curve_load";
  oclua_checkargs(L, 1, fname, "(string)");
  if (lua_type(L, 1) != LUA_TSTRING)
    oclua_error(L, fname,
                "argument #1 must be a string from curve:save() (got %s)",
                oclua_got(L, 1));
  size_t n;
  const char *s = lua_tolstring(L, 1, &n);
  oclua_fcurve *u = newcurve(L);
  oc_error err = {OC_OK, ""};
  u->c = oc_fcurve_decode((const unsigned char *)s, n, &err);
  if (!u->c) return oclua_liberror(L, fname, &err);
  return 1;
}

static int c_gc(lua_State *L) {
  oclua_fcurve *u = luaL_checkudata(L, 1, OCLUA_FCURVE);
  oc_fcurve_release(u->c);
  u->c = NULL;
  return 0;
}

static int c_tostring(lua_State *L) {
  oclua_fcurve *u = luaL_checkudata(L, 1, OCLUA_FCURVE);
  if (!u->c)
    lua_pushliteral(L, OCLUA_FCURVE ": (collected)");
  else
    lua_pushfstring(L, OCLUA_FCURVE ": %f m", oc_fcurve_length(u->c));
  return 1;
}

/* ---- outcrop.diffusion ----------------------------------------------------
 */

/* The curves of a diffusion, each retained: Lua code that may run before
** the call ends (a metamethod of the options, a finalizer at an
** allocation) could drop the script's last reference to one; the list's
** __gc releases them, also when a raise ends the call. */
#define OCLUA_CURVELIST "outcrop.diffusion.curves"

typedef struct curvelist {
  size_t n; /* curves retained so far */
  oc_fcurve *c[];
} curvelist;

static int list_gc(lua_State *L) {
  curvelist *l = luaL_checkudata(L, 1, OCLUA_CURVELIST);
  for (size_t i = 0; i < l->n; i++)
    oc_fcurve_release(l->c[i]);
  l->n = 0;
  return 0;
}

/* curves = {c1, c2, ...} into a retained list, pushed. */
static oc_fcurve **read_curves(oclua_fields *f, size_t *n) {
  lua_State *L = f->L;
  if (oclua_field_push(f, "curves") != LUA_TTABLE)
    oclua_field_error(f, "curves", -1, "must be an array of feature curves");
  int t = lua_gettop(L);
  lua_Integer m = (lua_Integer)lua_rawlen(L, t);
  if (m < 1 || m > 65534)
    oclua_error(L, f->fname, "'curves' must hold 1 to 65534 curves (got %I)",
                m);
  curvelist *l =
      lua_newuserdatauv(L, sizeof *l + (size_t)m * sizeof l->c[0], 0);
  l->n = 0;
  luaL_setmetatable(L, OCLUA_CURVELIST);
  for (lua_Integer i = 1; i <= m; i++) {
    lua_rawgeti(L, t, i);
    char what[40];
    snprintf(what, sizeof what, "'curves[%lld]'", (long long)i);
    oc_fcurve *c = checkcurve(L, -1, f->fname, what);
    oc_fcurve_retain(c);
    l->c[l->n++] = c;
    lua_pop(L, 1);
  }
  *n = (size_t)m;
  return l->c;
}

static void read_dnoise(oclua_fields *f, oc_diffusion_params *p) {
  static const char *const known[] = {"wavelength", "octaves", "ratio", NULL};
  lua_State *L = f->L;
  if (oclua_field_push(f, "noise") == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  oclua_fields n;
  oclua_fields_open(&n, L, -1, f->fname, "noise.", known, 0);
  p->wavelength = oclua_field_optnumber(&n, "wavelength", OCLUA_POSITIVE, 0);
  p->octaves = (int)oclua_field_optint(&n, "octaves", 1, 16, 4);
  p->ratio = oclua_field_optnumber(&n, "ratio", OCLUA_POSITIVE, 2);
  if (!(p->ratio > 1 && p->ratio <= 16))
    oclua_error(L, f->fname, "'noise.ratio' must be in (1, 16] (got %f)",
                (LUAI_UACNUMBER)p->ratio);
  lua_pop(L, 1);
}

static double read_converged(oclua_fields *f) {
  lua_State *L = f->L;
  int t = oclua_field_push(f, "converged");
  double tol = 0;
  if (t == LUA_TBOOLEAN)
    tol = lua_toboolean(L, -1) ? TOLERANCE : 0;
  else if (t == LUA_TNUMBER) {
    tol = lua_tonumber(L, -1);
    if (!(tol > 0 && tol < 1))
      oclua_field_error(f, "converged", -1,
                        "must be a boolean or a tolerance in (0, 1)");
  } else if (t != LUA_TNIL)
    oclua_field_error(f, "converged", -1,
                      "must be a boolean or a tolerance in (0, 1)");
  lua_pop(L, 1);
  return tol;
}

static int l_diffusion(lua_State *L) {
  static const char *const known[] = {"size",      "cell",  "origin",
                                      "curves",    "seed",  "scheme",
                                      "converged", "noise", NULL};
  static const char *const schemes[] = {"upwind", "paper", NULL};
  const char *fname = "outcrop.diffusion";
  oclua_fields f;
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_diffusion_params p = {0};
  p.grid = oclua_field_grid(&f);
  p.curves = read_curves(&f, &p.ncurves);
  p.seed = oclua_field_seed(&f, "seed");
  p.scheme =
      (oc_diffusion_scheme)oclua_field_optoption(&f, "scheme", schemes, 0);
  p.tolerance = read_converged(&f);
  read_dnoise(&f, &p);
  p.maps = 1;
  /* every userdata first, so that nothing made below can leak */
  static const char *const names[5] = {"smooth", "detail", "amplitude",
                                       "roughness", "gradient"};
  oclua_heightfield *u = oclua_newheightfield(L), *v[5];
  int ud = lua_gettop(L);
  lua_createtable(L, 0, 12);
  for (int k = 0; k < 5; k++) {
    v[k] = oclua_newheightfield(L);
    lua_setfield(L, -2, names[k]);
  }
  oclua_progress pl;
  p.progress = oclua_progress_start(L, &pl, fname);
  oc_diffusion_result r;
  oc_error err = {OC_OK, ""};
  int rc = oc_diffusion(&p, &r, &err);
  oclua_progress_end(&pl);
  if (rc) return oclua_sethf(L, u, NULL, &err, fname);
  u->hf = r.height;
  v[0]->hf = r.smooth, v[1]->hf = r.detail, v[2]->hf = r.amplitude;
  v[3]->hf = r.roughness, v[4]->hf = r.gradient;
  lua_pushinteger(L, r.levels);
  lua_setfield(L, -2, "levels");
  lua_pushinteger(L, r.cycles);
  lua_setfield(L, -2, "cycles");
  lua_createtable(L, r.cycles + 1, 0);
  for (int k = 0; k <= r.cycles; k++) {
    lua_pushnumber(L, r.residual[k]);
    lua_rawseti(L, -2, k + 1);
  }
  lua_setfield(L, -2, "residuals");
  lua_pushinteger(L, (lua_Integer)r.strict);
  lua_setfield(L, -2, "strict");
  lua_pushinteger(L, (lua_Integer)r.slope);
  lua_setfield(L, -2, "slope");
  lua_pushinteger(L, (lua_Integer)r.conflict);
  lua_setfield(L, -2, "conflict");
  lua_pushvalue(L, ud);
  lua_insert(L, -2);
  return 2;
}

void oclua_open_diffusion(lua_State *L) {
  static const luaL_Reg meta[] = {
      {"__gc", c_gc}, {"__tostring", c_tostring}, {NULL, NULL}};
  static const luaL_Reg methods[] = {{"length", c_length},
                                     {"sample", c_sample},
                                     {"save", c_save},
                                     {NULL, NULL}};
  static const luaL_Reg listmeta[] = {{"__gc", list_gc}, {NULL, NULL}};
  oclua_newmeta(L, OCLUA_FCURVE, meta, methods);
  lua_pop(L, 1);
  oclua_newmeta(L, OCLUA_CURVELIST, listmeta, NULL);
  lua_pop(L, 1);
  lua_pushcfunction(L, l_feature_curve);
  lua_setfield(L, -2, "feature_curve");
  lua_pushcfunction(L, l_feature_curve_load);
  lua_setfield(L, -2, "feature_curve_load");
  lua_pushcfunction(L, l_diffusion);
  lua_setfield(L, -2, "diffusion");
}
