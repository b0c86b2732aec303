/*
** l_prim.c — primitive constructors: outcrop.point, sphere, box, segment,
** curve, cone, plane, turbulence.
**
** Each reads its one table of named fields completely (so every mistake
** is reported before anything is allocated), then creates the userdata,
** then the node. Defaults (docs/fields.md gives the formulas):
**
**   field      | default
**   -----------+---------------------------------------------------------
**   energy     | 1 (every primitive)
**   falloff    | sphere: its radius; cone: its base radius; box, plane: 1
**   bezier     | false (curve)
**   amplitude  | 1 (turbulence)
**   octaves    | 4 (turbulence)
**   offset     | 0 (turbulence)
**   seed       | the scene seed (outcrop.seed: --seed, or 1)
**
** Required: point{center, radius}, sphere{center, radius},
** box{min, max}, segment{a, b, radius}, curve{points, radius},
** cone{base, apex, radius}, plane{origin, normal},
** turbulence{wavelength}.
*/
#include "l_field.h"

static void begin(oclua_fields *f, lua_State *L, const char *fname,
                  const char *const *known) {
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(f, L, 1, fname, NULL, known, 0);
}

static int l_point(lua_State *L) {
  static const char *const known[] = {"center", "radius", "energy", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.point", known);
  oc_vec3 c = oclua_field_vec(&f, "center");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_point(c, r, e, &err), &err, f.fname);
}

static int l_sphere(lua_State *L) {
  static const char *const known[] = {"center", "radius", "falloff", "energy",
                                      NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.sphere", known);
  oc_vec3 c = oclua_field_vec(&f, "center");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double fo = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, r);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_sphere(c, r, fo, e, &err), &err, f.fname);
}

static int l_box(lua_State *L) {
  static const char *const known[] = {"min", "max", "falloff", "energy", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.box", known);
  oc_vec3 lo = oclua_field_vec(&f, "min");
  oc_vec3 hi = oclua_field_vec(&f, "max");
  double fo = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, 1.0);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z)
    oclua_error(L, f.fname,
                "'max' must be >= 'min' on every axis (got "
                "min {%f, %f, %f}, max {%f, %f, %f})",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_box(lo, hi, fo, e, &err), &err, f.fname);
}

static int l_segment(lua_State *L) {
  static const char *const known[] = {"a", "b", "radius", "energy", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.segment", known);
  oc_vec3 a = oclua_field_vec(&f, "a");
  oc_vec3 b = oclua_field_vec(&f, "b");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_segment(a, b, r, e, &err), &err, f.fname);
}

int oclua_make_curve(oclua_fields *f, const char *energy, int optional) {
  lua_State *L = f->L;
  oc_error err = {OC_OK, ""};
  if (oclua_field_push(f, "points") == LUA_TNIL)
    oclua_field_missing(f, "points", "an array of {x, y, z} points");
  if (!lua_istable(L, -1))
    oclua_field_error(f, "points", -1, "must be an array of {x, y, z} points");
  lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
  if (n < 2)
    oclua_error(L, f->fname, "'points' must hold at least 2 points (got %I)",
                (LUAI_UACINT)n);
  if ((size_t)n > ((size_t)-1) / sizeof(oc_vec3) / 2)
    oclua_error(L, f->fname, "'points' is too long");
  /* Scratch space owned by Lua: freed by the collector even on error. */
  oc_vec3 *pts = lua_newuserdatauv(L, (size_t)n * sizeof *pts, 0);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_geti(L, -2, i);
    pts[i - 1] = oclua_tovec(L, -1, f->fname, "points", i);
    lua_pop(L, 1);
  }
  double r = oclua_field_number(f, "radius", OCLUA_POSITIVE);
  double e = optional ? oclua_field_optnumber(f, energy, OCLUA_FINITE, 1.0)
                      : oclua_field_number(f, energy, OCLUA_FINITE);
  int bezier = oclua_field_optbool(f, "bezier", 0);
  if (bezier && (n - 1) % 3 != 0)
    oclua_error(L, f->fname,
                "'points' of a bezier curve must number 3k+1 "
                "(4, 7, 10, ...; got %I)",
                (LUAI_UACINT)n);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_curve(pts, (size_t)n, bezier, r, e, &err), &err,
                       f->fname);
}

static int l_curve(lua_State *L) {
  static const char *const known[] = {"points", "radius", "energy", "bezier",
                                      NULL};
  oclua_fields f;
  begin(&f, L, "outcrop.curve", known);
  return oclua_make_curve(&f, "energy", 1);
}

static int l_cone(lua_State *L) {
  static const char *const known[] = {"base",    "apex",   "radius",
                                      "falloff", "energy", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.cone", known);
  oc_vec3 base = oclua_field_vec(&f, "base");
  oc_vec3 apex = oclua_field_vec(&f, "apex");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double fo = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, r);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  if (base.x == apex.x && base.y == apex.y && base.z == apex.z)
    oclua_error(L, f.fname, "'apex' must differ from 'base'");
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_cone(base, apex, r, fo, e, &err), &err,
                       f.fname);
}

static int l_plane(lua_State *L) {
  static const char *const known[] = {"origin", "normal", "falloff", "energy",
                                      NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.plane", known);
  oc_vec3 o = oclua_field_vec(&f, "origin");
  oc_vec3 n = oclua_field_vec(&f, "normal");
  double fo = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, 1.0);
  double e = oclua_field_optnumber(&f, "energy", OCLUA_FINITE, 1.0);
  if (n.x == 0 && n.y == 0 && n.z == 0)
    oclua_error(L, f.fname, "'normal' must be non-zero");
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_plane(o, n, fo, e, &err), &err, f.fname);
}

static int l_turbulence(lua_State *L) {
  static const char *const known[] = {"wavelength", "amplitude", "octaves",
                                      "offset",     "seed",      NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  begin(&f, L, "outcrop.turbulence", known);
  oclua_field_noise(&f, &nz, 1.0, 4, 1);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_turbulence(&nz, &err), &err, f.fname);
}

static const luaL_Reg prim_funcs[] = {
    {"point", l_point},     {"sphere", l_sphere},         {"box", l_box},
    {"segment", l_segment}, {"curve", l_curve},           {"cone", l_cone},
    {"plane", l_plane},     {"turbulence", l_turbulence}, {NULL, NULL}};

void oclua_open_prim(lua_State *L) {
  luaL_setfuncs(L, prim_funcs, 0);
}
