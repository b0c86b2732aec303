/*
** l_hfanalysis.c — heightfield analysis methods: slope, filling, drainage,
** stream power, sinks, accessibility, distance to a level.
**
** Each returns a new heightfield of the same size, cell and origin, except
** sinks (an array of {x, y, z}). Defaults: exponent 1.1 (Freeman's);
** accessibility rays 64, distance 50 cells, seed the scene seed. Long ones
** (filled, drainage, stream_power, accessibility) show progress on a
** terminal and stop on Ctrl-C under the interpreter ("interrupted").
*/
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "l_heightfield.h"
#include "l_progress.h"

#define MAX_RAYS 4096
#define DEFAULT_RAYS 64
#define SINKS_BOX "outcrop.sinks_box"

/* ---- helpers ------------------------------------------------------------ */

/* Opens the optional options table at 2 (nil or absent: none given). */
static void open_options(lua_State *L, oclua_fields *f, const char *fname,
                         const char *const *known, const char *usage) {
  oclua_checkargs(L, 2, fname, usage);
  if (lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_newtable(L);
  }
  oclua_fields_open(f, L, 2, fname, NULL, known, 0);
}

/* ---- methods ------------------------------------------------------------ */

static int hf_slope(lua_State *L) {
  const char *fname = "heightfield:slope";
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 1, fname, "()");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u, oc_heightfield_slope(hf, &err), &err, fname);
}

static int hf_filled(lua_State *L) {
  const char *fname = "heightfield:filled";
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  oclua_progress pl;
  oclua_checkargs(L, 1, fname, "()");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_progress pr = oclua_progress_start(L, &pl, fname);
  oc_heightfield *r = oc_heightfield_fill(hf, pr, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, r, &err, fname);
}

/* drainage and stream_power: {exponent = } */
static int flow(lua_State *L, const char *fname, int power) {
  static const char *const known[] = {"exponent", NULL};
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  oclua_fields f;
  oclua_progress pl;
  oc_heightfield_flow_params fp;
  memset(&fp, 0, sizeof fp);
  open_options(L, &f, fname, known, "([{exponent = 1.1}])");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  fp.exponent = oclua_field_optnumber(&f, "exponent", OCLUA_POSITIVE,
                                      OC_HEIGHTFIELD_FREEMAN_EXPONENT);
  oclua_heightfield *u = oclua_newheightfield(L);
  fp.progress = oclua_progress_start(L, &pl, fname);
  oc_heightfield *r = power ? oc_heightfield_stream_power(hf, &fp, &err)
                            : oc_heightfield_drainage(hf, &fp, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, r, &err, fname);
}

static int hf_drainage(lua_State *L) {
  return flow(L, "heightfield:drainage", 0);
}

static int hf_stream_power(lua_State *L) {
  return flow(L, "heightfield:stream_power", 1);
}

/* The C array of sinks lives in a box Lua owns while the result table is
** built, so a memory error there leaks nothing. */
static int sinks_box_gc(lua_State *L) {
  oc_vec3 **box = lua_touserdata(L, 1);
  free(*box);
  *box = NULL;
  return 0;
}

static int hf_sinks(lua_State *L) {
  const char *fname = "heightfield:sinks";
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  size_t n = 0;
  oclua_checkargs(L, 1, fname, "()");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oc_vec3 **box = lua_newuserdatauv(L, sizeof *box, 0);
  *box = NULL;
  if (luaL_newmetatable(L, SINKS_BOX)) {
    lua_pushcfunction(L, sinks_box_gc);
    lua_setfield(L, -2, "__gc");
    lua_pushliteral(L, "protected");
    lua_setfield(L, -2, "__metatable");
  }
  lua_setmetatable(L, -2);
  if (oc_heightfield_sinks(hf, box, &n, &err) != OC_OK)
    oclua_liberror(L, fname, &err);
  if (n > (size_t)INT32_MAX)
    oclua_error(L, fname, "too many sinks for a Lua table (%I)",
                (LUAI_UACINT)n);
  lua_createtable(L, (int)n, 0);
  for (size_t k = 0; k < n; k++) {
    const oc_vec3 *p = &(*box)[k];
    lua_createtable(L, 3, 0);
    lua_pushnumber(L, p->x);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, p->y);
    lua_rawseti(L, -2, 2);
    lua_pushnumber(L, p->z);
    lua_rawseti(L, -2, 3);
    lua_rawseti(L, -2, (lua_Integer)k + 1);
  }
  free(*box);
  *box = NULL;
  return 1;
}

static int hf_accessibility(lua_State *L) {
  static const char *const known[] = {"rays", "distance", "seed", NULL};
  const char *fname = "heightfield:accessibility";
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  oclua_fields f;
  oclua_progress pl;
  oc_heightfield_access_params ap;
  memset(&ap, 0, sizeof ap);
  open_options(L, &f, fname, known,
               "([{rays = 64, distance = 50 cells, seed = }])");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  ap.rays = (int)oclua_field_optint(&f, "rays", 1, MAX_RAYS, DEFAULT_RAYS);
  ap.distance = oclua_field_optnumber(&f, "distance", OCLUA_POSITIVE, 0);
  ap.seed = oclua_field_seed(&f, "seed");
  oclua_heightfield *u = oclua_newheightfield(L);
  ap.progress = oclua_progress_start(L, &pl, fname);
  oc_heightfield *r = oc_heightfield_accessibility(hf, &ap, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, r, &err, fname);
}

static int hf_distance_to_level(lua_State *L) {
  const char *fname = "heightfield:distance_to_level";
  oclua_checkheightfield(L, 1, fname); /* the message before the options */
  oc_error err = {OC_OK, ""};
  double z = lua_tonumber(L, 2);
  if (lua_type(L, 2) != LUA_TNUMBER || isnan(z))
    oclua_error(L, fname, "'z' must be a number (got %s)", oclua_got(L, 2));
  oclua_checkargs(L, 2, fname, "(z)");
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u, oc_heightfield_distance_to_level(hf, z, &err), &err,
                     fname);
}

const luaL_Reg oclua_heightfield_analysis[] = {
    {"slope", hf_slope},
    {"filled", hf_filled},
    {"drainage", hf_drainage},
    {"stream_power", hf_stream_power},
    {"sinks", hf_sinks},
    {"accessibility", hf_accessibility},
    {"distance_to_level", hf_distance_to_level},
    {NULL, NULL}};
