/*
** l_gen_karst.c — karst networks by invasion percolation:
** outcrop.generate.karst{heightfield=, ...} (Paris et al. 2019, section 6.2).
**
**   field          | default
**   ---------------+--------------------------------------------------------
**   heightfield    | required: the surface cavities stay under, and sinks
**   terrain        | outcrop.terrain(heightfield) (the lib makes it:
**                  | no_terrain = 0); false: the cavities alone
**   geology        | strata of wavelength 8 radius, 3 octaves, the seed
**   sinks          | hf:sinks(): an array of {x, y, z} starting points
**   seed           | the scene seed
**   radius         | 2 cells: R of each negative point primitive
**   step           | radius: distance from a cavity to its candidates
**   spacing        | radius / 2: Poisson-sphere radius between candidates
**   cover          | radius / 4: least depth of a centre below the surface
**   floor          | lowest sample + radius: lowest centre
**   epsilon        | 0.1: range of the random perturbation of rho
**   rho0           | 0.5: carve only where rho < rho0
**   energy, beta   | 1.5, 0.5: energy -E (beta + (1 - beta) (1 - rho))
**   branches       | 6: candidates tried around each cavity
**   max_primitives | 100000: budget of cavities
**
** Returns the node (a blend of the terrain and the cavities) and a table
** {primitives=, candidates=, sinks=, seconds=}.
*/
#include <math.h>

#include "l_field.h"
#include "l_gen.h"
#include "l_heightfield.h"
#include "l_progress.h"
#include "l_terrain.h"

#define FNAME "outcrop.generate.karst"

/* Reads `sinks` into a userdata-backed array (collected with the call). */
static oc_vec3 *read_sinks(oclua_fields *f, size_t *n) {
  lua_State *L = f->L;
  *n = 0;
  int t = oclua_field_push(f, "sinks");
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return NULL;
  }
  if (t != LUA_TTABLE)
    oclua_field_error(f, "sinks", -1, "must be an array of {x, y, z}");
  int at = lua_gettop(L);
  lua_Integer len = luaL_len(L, at);
  if (len > 10000000)
    oclua_error(L, FNAME, "'sinks' has too many points (%I, at most 1e7)",
                (LUAI_UACINT)len);
  oc_vec3 *v = lua_newuserdatauv(L, (size_t)(len ? len : 1) * sizeof *v, 0);
  for (lua_Integer i = 1; i <= len; i++) {
    lua_geti(L, at, i);
    v[i - 1] = oclua_tovec(L, -1, FNAME, "sinks", i);
    lua_pop(L, 1);
  }
  lua_replace(L, at); /* keep the array alive in the table's slot */
  *n = (size_t)len;
  return v;
}

static int l_karst(lua_State *L) {
  static const char *const known[] = {
      "heightfield",    "terrain", "geology", "sinks", "seed",
      "radius",         "step",    "spacing", "cover", "floor",
      "epsilon",        "rho0",    "energy",  "beta",  "branches",
      "max_primitives", NULL};
  oclua_fields f;
  oc_gen_karst_params p;
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 1, FNAME, "{heightfield =, terrain =, geology =, ...}");
  oclua_fields_open(&f, L, 1, FNAME, NULL, known, 0);
  oc_gen_karst_defaults(&p);
  if (oclua_field_push(&f, "heightfield") == LUA_TNIL)
    oclua_field_missing(&f, "heightfield", "a heightfield");
  if (!oclua_isheightfield(L, -1))
    oclua_field_error(&f, "heightfield", -1, "must be a heightfield");
  /* Values read stay on the stack, and the grid pinned, until the
  ** generator has run: an __index may have made them, or a finalizer
  ** drop them from the table or close the grid. */
  p.heightfield = oclua_pinheightfield(L, -1, FNAME);
  /* nil: the lib's default terrain; false: none */
  int t = oclua_field_push(&f, "terrain");
  if (t == LUA_TBOOLEAN && !lua_toboolean(L, -1))
    p.no_terrain = 1;
  else if (t != LUA_TNIL) {
    oclua_node *u = oclua_testnode(L, -1);
    if (!u) oclua_field_error(&f, "terrain", -1, "must be a node or false");
    p.terrain = u->node;
  }
  if (oclua_field_push(&f, "geology") != LUA_TNIL) {
    oclua_node *u = oclua_testnode(L, -1);
    if (!u) oclua_field_error(&f, "geology", -1, "must be a node");
    p.geology = u->node;
  }
  p.sinks = read_sinks(&f, &p.nsinks);
  p.seed = oclua_field_seed(&f, "seed");
  p.radius = oclua_field_optnumber(&f, "radius", OCLUA_POSITIVE, 0);
  p.step = oclua_field_optnumber(&f, "step", OCLUA_POSITIVE, 0);
  p.spacing = oclua_field_optnumber(&f, "spacing", OCLUA_POSITIVE, 0);
  p.cover = oclua_field_optnumber(&f, "cover", OCLUA_FINITE, NAN);
  p.floor = oclua_field_optnumber(&f, "floor", OCLUA_FINITE, NAN);
  p.epsilon = oclua_field_optnumber(&f, "epsilon", OCLUA_FINITE, p.epsilon);
  p.rho0 = oclua_field_optnumber(&f, "rho0", OCLUA_FINITE, p.rho0);
  p.energy = oclua_field_optnumber(&f, "energy", OCLUA_POSITIVE, p.energy);
  p.beta = oclua_field_optnumber(&f, "beta", OCLUA_FINITE, p.beta);
  p.branches = (int)oclua_field_optint(&f, "branches", 1, 64, p.branches);
  p.max_primitives = (size_t)oclua_field_optint(
      &f, "max_primitives", 1, OC_KARST_MAX, (lua_Integer)p.max_primitives);
  oclua_node *u = oclua_newnode(L);
  oclua_progress pl;
  oc_gen_karst_stats st = {0};
  p.progress = oclua_progress_start(L, &pl, FNAME);
  oc_node *n = oc_generate_karst(&p, &st, &err);
  oclua_progress_end(&pl);
  if (!n && err.code == OC_ECANCEL) return luaL_error(L, "interrupted");
  oclua_setnode(L, u, n, &err, FNAME);
  lua_createtable(L, 0, 4);
  lua_pushinteger(L, (lua_Integer)st.primitives);
  lua_setfield(L, -2, "primitives");
  lua_pushinteger(L, (lua_Integer)st.candidates);
  lua_setfield(L, -2, "candidates");
  lua_pushinteger(L, (lua_Integer)st.sinks);
  lua_setfield(L, -2, "sinks");
  lua_pushnumber(L, st.seconds);
  lua_setfield(L, -2, "seconds");
  return 2;
}

const luaL_Reg oclua_gen_karst[] = {{"karst", l_karst}, {NULL, NULL}};
