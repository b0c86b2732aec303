/*
** l_gen_hoodoos.c — hoodoos and goblins from a parameterized grammar:
** outcrop.generate.hoodoos{heightfield=, ...} (Paris et al. 2019, section 6.3).
**
**   field        | default
**   -------------+----------------------------------------------------------
**   heightfield  | required: placement (slope, drainage) and ground level
**   terrain      | outcrop.terrain(heightfield) (the lib makes it:
**                | no_terrain = 0); false: the hoodoos alone
**   geology      | none (rho = 0.5): a resistance tree driving the grammar
**   mask         | none: a heightfield or a function (x, y) -> [0, 1]
**                | multiplying the placement probability
**   seed         | the scene seed
**   radius       | 5 cells: Poisson spacing of the hoodoos
**   height       | {4, 10} cells: the range of a full hoodoo's height
**   width        | 0.3 radius: half-width of the base symbol
**   margin       | 4 cells: kept free along the heightfield's edges
**   max_depth    | 6: most symbols per hoodoo (2 .. 64)
**   p_block      | 0.5: B -> b B (else b C), times 0.5 + rho
**   p_cone       | 0.5: C -> c B | c (else d), times 1.5 - rho
**   shrink       | 0.85: size ratio of successive symbols
**   tilt         | 0.1: largest tilt of a symbol, radians
**   roughness    | 0.3: perturbation of the symbols' surfaces, 0 .. 1
**   probability  | 1: largest placement probability
**   slope        | 0.6: favoured slope (rise over run)
**   slope_spread | 0.4: width of the slope preference
**   drainage     | 20 cells^2: A0 of the factor 1 / (1 + A / A0)
**
** Returns the node (a blend of the terrain and one primitive per symbol)
** and a table {hoodoos=, primitives=, blocks=, cones=, boxes=, seconds=}.
*/
#include <math.h>

#include "l_field.h"
#include "l_gen.h"
#include "l_heightfield.h"
#include "l_progress.h"

#define FNAME "outcrop.generate.hoodoos"

/* A Lua mask runs under lua_pcall, so its error cannot jump across the
** library: the error object waits in slot `err` while the library
** unwinds (the NaN returned stops it). */
typedef struct lmask {
  lua_State *L;
  int fn, err;
  int raised;
} lmask;

static double mask_fn(void *ud, double x, double y) {
  lmask *M = ud;
  lua_State *L = M->L;
  lua_pushvalue(L, M->fn);
  lua_pushnumber(L, x);
  lua_pushnumber(L, y);
  if (lua_pcall(L, 2, 1, 0) != LUA_OK) {
    lua_replace(L, M->err);
    M->raised = 1;
    return NAN;
  }
  double v = lua_type(L, -1) == LUA_TNUMBER ? lua_tonumber(L, -1) : NAN;
  lua_pop(L, 1);
  return v; /* the library reports a value out of [0, 1] */
}

static oc_node *optnode(oclua_fields *f, const char *name, int *off) {
  lua_State *L = f->L;
  oc_node *n = NULL;
  int t = oclua_field_push(f, name);
  if (off && t == LUA_TBOOLEAN && !lua_toboolean(L, -1))
    *off = 1;
  else if (t != LUA_TNIL) {
    oclua_node *u = oclua_testnode(L, -1);
    if (!u)
      oclua_field_error(f, name, -1,
                        off ? "must be a node or false" : "must be a node");
    n = u->node;
  }
  /* The value stays on the stack until the generator has run: an __index
  ** may have made it, or a finalizer drop it from the table. */
  return n;
}

static void setint(lua_State *L, const char *k, size_t v) {
  lua_pushinteger(L, (lua_Integer)v);
  lua_setfield(L, -2, k);
}

static int l_hoodoos(lua_State *L) {
  static const char *const known[] = {
      "heightfield", "terrain", "geology",      "mask",     "seed",
      "radius",      "height",  "width",        "margin",   "max_depth",
      "p_block",     "p_cone",  "shrink",       "tilt",     "roughness",
      "probability", "slope",   "slope_spread", "drainage", NULL};
  oclua_fields f;
  oc_gen_hoodoos_params p;
  oc_error err = {OC_OK, ""};
  lmask M = {L, 0, 0, 0};
  oclua_checkargs(L, 1, FNAME, "{heightfield =, terrain =, geology =, ...}");
  oclua_fields_open(&f, L, 1, FNAME, NULL, known, 0);
  if (oclua_field_push(&f, "heightfield") == LUA_TNIL)
    oclua_field_missing(&f, "heightfield", "a heightfield");
  if (!oclua_isheightfield(L, -1))
    oclua_field_error(&f, "heightfield", -1, "must be a heightfield");
  /* pinned, with the value, until the generator has run */
  oc_heightfield *hf = oclua_pinheightfield(L, -1, FNAME);
  oc_gen_hoodoos_defaults(&p, hf);
  /* nil: the lib's default terrain; false: none */
  p.terrain = optnode(&f, "terrain", &p.no_terrain);
  p.geology = optnode(&f, "geology", NULL);
  int t = oclua_field_push(&f, "mask");
  if (t == LUA_TFUNCTION) {
    M.fn = lua_gettop(L);
    p.mask_fn = mask_fn;
    p.mask_ud = &M;
  } else if (t != LUA_TNIL) {
    if (!oclua_isheightfield(L, -1))
      oclua_field_error(&f, "mask", -1,
                        "must be a heightfield or a function (x, y) -> "
                        "[0, 1]");
    p.mask = oclua_pinheightfield(L, -1, FNAME);
  } else {
    lua_pop(L, 1);
  }
  p.seed = oclua_field_seed(&f, "seed");
  p.radius = oclua_field_optnumber(&f, "radius", OCLUA_POSITIVE, p.radius);
  double h[2];
  if (oclua_field_numbers(&f, "height", 2, h, "must be {lo, hi}")) {
    if (!(h[0] > 0 && h[0] <= h[1]))
      oclua_error(L, FNAME,
                  "'height' must be {lo, hi} with 0 < lo <= hi (got {%f, "
                  "%f})",
                  h[0], h[1]);
    p.height_lo = h[0];
    p.height_hi = h[1];
  }
  p.width = oclua_field_optnumber(&f, "width", OCLUA_POSITIVE, p.width);
  p.margin = oclua_field_optnumber(&f, "margin", OCLUA_FINITE, p.margin);
  p.max_depth = (int)oclua_field_optint(&f, "max_depth", 2, OC_HOODOO_MAX_DEPTH,
                                        p.max_depth);
  p.p_block = oclua_field_optnumber(&f, "p_block", OCLUA_FINITE, p.p_block);
  p.p_cone = oclua_field_optnumber(&f, "p_cone", OCLUA_FINITE, p.p_cone);
  p.shrink = oclua_field_optnumber(&f, "shrink", OCLUA_FINITE, p.shrink);
  p.tilt = oclua_field_optnumber(&f, "tilt", OCLUA_FINITE, p.tilt);
  p.roughness =
      oclua_field_optnumber(&f, "roughness", OCLUA_FINITE, p.roughness);
  p.probability =
      oclua_field_optnumber(&f, "probability", OCLUA_FINITE, p.probability);
  p.slope = oclua_field_optnumber(&f, "slope", OCLUA_FINITE, p.slope);
  p.slope_spread =
      oclua_field_optnumber(&f, "slope_spread", OCLUA_POSITIVE, p.slope_spread);
  p.drainage =
      oclua_field_optnumber(&f, "drainage", OCLUA_POSITIVE, p.drainage);
  p.threshold = oclua_threshold(L, FNAME);
  lua_pushnil(L);
  M.err = lua_gettop(L);
  luaL_checkstack(L, 8, NULL);
  oclua_node *u = oclua_newnode(L);
  oclua_progress pl;
  oc_gen_hoodoos_stats st = {0};
  p.progress = oclua_progress_start(L, &pl, FNAME);
  oc_node *n = oc_generate_hoodoos(&p, &st, &err);
  oclua_progress_end(&pl);
  if (!n && M.raised) {
    lua_pushvalue(L, M.err); /* the mask's own error, as raised */
    return lua_error(L);
  }
  if (!n && err.code == OC_ECANCEL) return luaL_error(L, "interrupted");
  oclua_setnode(L, u, n, &err, FNAME);
  lua_createtable(L, 0, 6);
  setint(L, "hoodoos", st.hoodoos);
  setint(L, "primitives", st.primitives);
  setint(L, "blocks", st.blocks);
  setint(L, "cones", st.cones);
  setint(L, "boxes", st.boxes);
  lua_pushnumber(L, st.seconds);
  lua_setfield(L, -2, "seconds");
  return 2;
}

const luaL_Reg oclua_gen_hoodoos[] = {{"hoodoos", l_hoodoos}, {NULL, NULL}};
