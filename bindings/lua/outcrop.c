/*
** outcrop.c — luaopen_outcrop: the module table, outcrop.param and the
** scene settings every script sees.
**
** Module fields:
**   outcrop.version    OC_VERSION
**   outcrop.threshold  T, a plain field (default 0.5); queries compile
**                      with the value current at the time of the query
**   outcrop.seed       the scene seed (registry OCLUA_SEED, default 1),
**                      read through the module's metatable so it always
**                      shows what constructors use; assigning it raises
*/
#include <string.h>

#include "l_field.h"
#include "l_geology.h"
#include "l_handle.h"
#include "l_heightfield.h"
#include "l_image.h"
#include "l_mesh.h"
#include "l_render.h"
#include "l_terrain.h"
#include "l_gen.h"

/* outcrop.param(name, default): the --set value for name, as a number
** when it reads as one ("3", "1e-2", "0x10"), a boolean for "true" and
** "false", else the string; `default` when there is no such parameter. */
static int l_param(lua_State *L) {
  const char *fname = "outcrop.param";
  if (lua_type(L, 1) != LUA_TSTRING)
    oclua_error(L, fname, "the parameter name must be a string (got %s)",
                oclua_got(L, 1));
  oclua_checkargs(L, 2, fname, "(name [, default])");
  lua_settop(L, 2);
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) != LUA_TTABLE) {
    lua_settop(L, 2);
    return 1;
  }
  lua_pushvalue(L, 1);
  switch (lua_gettable(L, -2)) {
  case LUA_TNIL:
    lua_settop(L, 2);
    return 1;
  case LUA_TSTRING: {
    const char *s = lua_tostring(L, -1);
    if (strcmp(s, "true") == 0)
      lua_pushboolean(L, 1);
    else if (strcmp(s, "false") == 0)
      lua_pushboolean(L, 0);
    else
      lua_stringtonumber(L, s); /* on failure the string stays on top */
    return 1;
  }
  default: /* set by a host as a Lua value already */
    return 1;
  }
}

static int module_index(lua_State *L) {
  const char *key = lua_tostring(L, 2);
  if (lua_type(L, 2) == LUA_TSTRING && strcmp(key, "seed") == 0) {
    lua_pushinteger(L, oclua_scene_seed(L));
    return 1;
  }
  return 0;
}

static int module_newindex(lua_State *L) {
  if (lua_type(L, 2) == LUA_TSTRING && strcmp(lua_tostring(L, 2), "seed") == 0)
    oclua_error(L, "outcrop",
                "outcrop.seed is read-only (set the scene seed "
                "with --seed, or pass seed = n to a constructor)");
  lua_rawset(L, 1);
  return 0;
}

static const luaL_Reg module_funcs[] = {{"param", l_param}, {NULL, NULL}};

int luaopen_outcrop(lua_State *L) {
  luaL_checkversion(L);
  lua_newtable(L);
  luaL_setfuncs(L, module_funcs, 0);
  oclua_open_handle(L);
  oclua_open_field(L);
  oclua_open_prim(L);
  oclua_open_ops(L);
  oclua_open_image(L);
  oclua_open_mesh(L);
  oclua_open_heightfield(L); /* outcrop.heightfield */
  oclua_open_render(L);
  oclua_open_terrain(L); /* outcrop.terrain */
  oclua_open_gen(L);     /* outcrop.poisson2d/3d */
  oclua_open_geology(L); /* outcrop.geology, outcrop.erosion */
  lua_pushliteral(L, OC_VERSION);
  lua_setfield(L, -2, "version");
  lua_pushnumber(L, OC_DEFAULT_THRESHOLD);
  lua_setfield(L, -2, "threshold");

  lua_createtable(L, 0, 2);
  lua_pushcfunction(L, module_index);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, module_newindex);
  lua_setfield(L, -2, "__newindex");
  lua_setmetatable(L, -2);

  /* Queries find outcrop.threshold through the registry. */
  lua_pushvalue(L, -1);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_MODULE);
  return 1;
}
