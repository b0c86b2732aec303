/*
** outcrop.c — luaopen_outcrop: the module table and the scene settings
** every script sees (outcrop.param and outcrop.configure: l_config.c).
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

#include "l_blocks.h"
#include "l_config.h"
#include "l_diffusion.h"
#include "l_elevation.h"
#include "l_field.h"
#include "l_geology.h"
#include "l_handle.h"
#include "l_heightfield.h"
#include "l_image.h"
#include "l_layers.h"
#include "l_mesh.h"
#include "l_relief.h"
#include "l_render.h"
#include "l_terrain.h"
#include "l_gen.h"

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
                "with --seed or outcrop.configure{seed = n}, or pass "
                "seed = n to a constructor)");
  lua_rawset(L, 1);
  return 0;
}

int luaopen_outcrop(lua_State *L) {
  luaL_checkversion(L);
  lua_newtable(L);
  oclua_open_config(L); /* outcrop.param, outcrop.configure */
  oclua_open_handle(L);
  oclua_open_field(L);
  oclua_open_prim(L);
  oclua_open_ops(L);
  oclua_open_image(L);
  oclua_open_mesh(L);
  oclua_open_heightfield(L); /* outcrop.heightfield */
  oclua_open_render(L);
  oclua_open_terrain(L);   /* outcrop.terrain */
  oclua_open_gen(L);       /* outcrop.poisson2d/3d */
  oclua_open_geology(L);   /* outcrop.geology, outcrop.erosion */
  oclua_open_elevation(L); /* outcrop.elevation */
  oclua_open_diffusion(L); /* outcrop.feature_curve, outcrop.diffusion */
  oclua_open_blocks(L);    /* outcrop.blocks */
  oclua_open_relief(L);    /* outcrop.relief_warp */
  oclua_open_layers(L);    /* outcrop.layers */
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
