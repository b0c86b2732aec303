/*
** l_geology.c — resistance trees (Paris et al. 2019, section 4) and the
** erosion node
** (section 6): the outcrop.geology table (strata, layer, sphere, curve,
** fold, taper, fault, clamp, slice) and outcrop.erosion.
**
** Resistance trees are ordinary nodes (blend them with +, query them with
** :eval); they are not clamped as built, so blends add up. Defaults:
**
**   strata   octaves 4, amplitude 1, offset 0, seed = the scene seed
**   layer    noise = none; noise = {wavelength =, amplitude = 1,
**            octaves = 4, offset = 0, seed =}
**   sphere   falloff = radius
**   fold     octaves 3 (a warp: outcrop.warp with no control)
**   taper    origin {0, 0, 0}, axis {0, 0, 1}, along {1, 0, 0}, from 0
**   clamp    lo 0, hi 1
**   slice    plane "xz", at 0, size {256, 256}, palette pale (hard) to
**            dark (soft), as Paris et al. 2019, figure 4; box required when the
**            tree's bounds are infinite (strata always are)
**   erosion  control = none (erode wherever there is rock)
*/
#include <math.h>

#include "l_field.h"
#include "l_geology.h"
#include "l_image.h"

static void begin(oclua_fields *f, lua_State *L, const char *fname,
                  const char *const *known) {
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields_open(f, L, 1, fname, NULL, known, 0);
}

/* (node, {options}): checks the node and opens the options at index 2. */
static oc_node *node_and_options(lua_State *L, oclua_fields *f,
                                 const char *fname, const char *usage,
                                 const char *const *known, int optional) {
  oclua_checkargs(L, 2, fname, usage);
  oc_node *n = oclua_checknode(L, 1, fname, "argument #1");
  if (optional && lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_newtable(L);
  }
  if (!lua_istable(L, 2))
    oclua_error(L, fname, "argument #2 must be a table %s (got %s)", usage,
                oclua_got(L, 2));
  oclua_fields_open(f, L, 2, fname, NULL, known, 0);
  return n;
}

/* ---- primitives ------------------------------------------------------- */

static int l_strata(lua_State *L) {
  static const char *const known[] = {"wavelength", "amplitude", "octaves",
                                      "offset",     "seed",      NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  begin(&f, L, "outcrop.geology.strata", known);
  oclua_field_noise(&f, &nz, 1.0, 4, 1);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_strata(&nz, &err), &err, f.fname);
}

static int l_layer(lua_State *L) {
  static const char *const known[] = {"origin",     "normal", "radius",
                                      "resistance", "noise",  NULL};
  static const char *const nknown[] = {"wavelength", "amplitude", "octaves",
                                       "offset",     "seed",      NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz, *pn = NULL;
  begin(&f, L, "outcrop.geology.layer", known);
  oc_vec3 o = oclua_field_vec(&f, "origin");
  oc_vec3 n = oclua_field_vec(&f, "normal");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double e = oclua_field_number(&f, "resistance", OCLUA_FINITE);
  if (n.x == 0 && n.y == 0 && n.z == 0)
    oclua_error(L, f.fname, "'normal' must be non-zero");
  int t = oclua_field_push(&f, "noise");
  if (t != LUA_TNIL) {
    oclua_fields nf;
    if (t != LUA_TTABLE)
      oclua_field_error(&f, "noise", -1,
                        "must be a table {wavelength =, amplitude =, ...}");
    oclua_fields_open(&nf, L, lua_gettop(L), f.fname, "noise.", nknown, 0);
    oclua_field_noise(&nf, &nz, 1.0, 4, 1);
    pn = &nz;
  }
  lua_pop(L, 1);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_geology_layer(o, n, r, e, pn, &err), &err,
                       f.fname);
}

static int l_sphere(lua_State *L) {
  static const char *const known[] = {"center", "radius", "falloff",
                                      "resistance", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  begin(&f, L, "outcrop.geology.sphere", known);
  oc_vec3 c = oclua_field_vec(&f, "center");
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  double fo = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, r);
  double e = oclua_field_number(&f, "resistance", OCLUA_FINITE);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_sphere(c, r, fo, e, &err), &err, f.fname);
}

static int l_curve(lua_State *L) {
  static const char *const known[] = {"points", "radius", "resistance",
                                      "bezier", NULL};
  oclua_fields f;
  begin(&f, L, "outcrop.geology.curve", known);
  return oclua_make_curve(&f, "resistance", 0);
}

/* ---- operators ------------------------------------------------------- */

static int l_fold(lua_State *L) {
  static const char *const known[] = {"wavelength", "amplitude", "octaves",
                                      "seed", NULL};
  const char *fname = "outcrop.geology.fold";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  oc_node *g = node_and_options(
      L, &f, fname, "{wavelength =, amplitude =, octaves =, seed =}", known, 0);
  oclua_field_noise(&f, &nz, NAN, 3, 0);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_warp(g, &nz, NULL, &err), &err, fname);
}

static int l_taper(lua_State *L) {
  static const char *const known[] = {"origin", "axis",   "along",  "from",
                                      "to",     "factor", "height", NULL};
  const char *fname = "outcrop.geology.taper";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_taper_params tp = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 0, 0, 1, 1};
  oc_node *g = node_and_options(L, &f, fname,
                                "{to =, factor =, height =, from =, origin "
                                "=, axis =, along =}",
                                known, 0);
  oclua_field_optvec(&f, "origin", &tp.origin);
  oclua_field_optvec(&f, "axis", &tp.axis);
  oclua_field_optvec(&f, "along", &tp.along);
  tp.from = oclua_field_optnumber(&f, "from", OCLUA_FINITE, 0.0);
  tp.to = oclua_field_number(&f, "to", OCLUA_FINITE);
  tp.factor = oclua_field_number(&f, "factor", OCLUA_POSITIVE);
  tp.height = oclua_field_number(&f, "height", OCLUA_POSITIVE);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_taper(g, &tp, &err), &err, fname);
}

/* The domain of a fault: a node, {min =, max =} or {origin =, normal =}.
** A node stays on the stack (pushed here) until the fault retains it. */
static void read_domain(const oclua_fields *f, oc_fault_domain *d) {
  static const char *const known[] = {"min", "max", "origin", "normal", NULL};
  const char *what = "must be a node, {min =, max =} or {origin =, normal =}";
  lua_State *L = f->L;
  int t = oclua_field_push(f, "domain");
  if (t == LUA_TNIL) oclua_field_missing(f, "domain", what + 8);
  oclua_node *u = oclua_testnode(L, -1);
  if (u) {
    d->kind = OC_FAULT_NODE;
    d->node = u->node;
    return;
  }
  if (t != LUA_TTABLE) oclua_field_error(f, "domain", -1, what);
  oclua_fields df;
  oclua_fields_open(&df, L, lua_gettop(L), f->fname, "domain.", known, 0);
  int box = oclua_field_push(&df, "min") != LUA_TNIL;
  box |= oclua_field_push(&df, "max") != LUA_TNIL;
  lua_pop(L, 2);
  if (box) {
    d->kind = OC_FAULT_BOX;
    d->lo = oclua_field_vec(&df, "min");
    d->hi = oclua_field_vec(&df, "max");
    if (!(d->lo.x < d->hi.x && d->lo.y < d->hi.y && d->lo.z < d->hi.z))
      oclua_error(L, f->fname,
                  "'domain.max' must be above 'domain.min' on every axis "
                  "(got min {%f, %f, %f}, max {%f, %f, %f})",
                  d->lo.x, d->lo.y, d->lo.z, d->hi.x, d->hi.y, d->hi.z);
  } else {
    d->kind = OC_FAULT_HALF;
    d->origin = oclua_field_vec(&df, "origin");
    d->normal = oclua_field_vec(&df, "normal");
    if (d->normal.x == 0 && d->normal.y == 0 && d->normal.z == 0)
      oclua_error(L, f->fname, "'domain.normal' must be non-zero");
  }
}

static int l_fault(lua_State *L) {
  static const char *const known[] = {"domain", "offset", NULL};
  const char *fname = "outcrop.geology.fault";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_fault_domain d = {OC_FAULT_BOX, {0, 0, 0}, {0, 0, 0},
                       {0, 0, 0},    {0, 0, 0}, NULL};
  oc_node *g = node_and_options(L, &f, fname,
                                "{domain =, offset = {dx, dy, dz}}", known, 0);
  oc_vec3 off = oclua_field_vec(&f, "offset");
  read_domain(&f, &d);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_fault(g, &d, off, &err), &err, fname);
}

static int l_clamp(lua_State *L) {
  static const char *const known[] = {"lo", "hi", NULL};
  const char *fname = "outcrop.geology.clamp";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_node *g = node_and_options(L, &f, fname, "{lo =, hi =}", known, 1);
  double lo = oclua_field_optnumber(&f, "lo", OCLUA_FINITE, 0.0);
  double hi = oclua_field_optnumber(&f, "hi", OCLUA_FINITE, 1.0);
  if (!(lo < hi))
    oclua_error(L, fname, "'lo' must be below 'hi' (got %f and %f)",
                (LUAI_UACNUMBER)lo, (LUAI_UACNUMBER)hi);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_clamp(g, lo, hi, &err), &err, fname);
}

static int l_erosion(lua_State *L) {
  static const char *const known[] = {"control", "depth", NULL};
  const char *fname = "outcrop.erosion";
  const char *usage = "(terrain, geology, {depth =, control =})";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_node *control = NULL;
  oclua_checkargs(L, 3, fname, usage);
  oc_node *terrain = oclua_checknode(L, 1, fname, "argument #1 (terrain)");
  oc_node *geology = oclua_checknode(L, 2, fname, "argument #2 (geology)");
  if (!lua_istable(L, 3))
    oclua_error(L, fname,
                "argument #3 must be a table {depth =, control =} "
                "(got %s)",
                oclua_got(L, 3));
  oclua_fields_open(&f, L, 3, fname, NULL, known, 0);
  double depth = oclua_field_number(&f, "depth", OCLUA_POSITIVE);
  /* stays on the stack until the erosion node retains it */
  if (oclua_field_push(&f, "control") != LUA_TNIL) {
    oclua_node *c = oclua_testnode(L, -1);
    if (c == NULL)
      oclua_field_error(&f, "control", -1, "must be an outcrop node");
    control = c->node;
  }
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_erosion(terrain, geology, control, depth, &err),
                       &err, fname);
}

/* ---- slices coloured by resistance --------------------------------------- */

/* outcrop.slice with a resistance palette by default. */
static int l_slice(lua_State *L) {
  int n;
  const double *stops = oc_palette_resistance(&n);
  return oclua_slice(L, "outcrop.geology.slice", stops, n);
}

static const luaL_Reg geology_funcs[] = {
    {"strata", l_strata}, {"layer", l_layer}, {"sphere", l_sphere},
    {"curve", l_curve},   {"fold", l_fold},   {"taper", l_taper},
    {"fault", l_fault},   {"clamp", l_clamp}, {"slice", l_slice},
    {NULL, NULL}};

void oclua_open_geology(lua_State *L) {
  luaL_newlib(L, geology_funcs);
  lua_setfield(L, -2, "geology");
  lua_pushcfunction(L, l_erosion);
  lua_setfield(L, -2, "erosion");
}
