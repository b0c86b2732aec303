/*
** l_rocks.c — rock piles (Peytavie et al. 2009, section 5) on material
** stacks.
**
**   outcrop.layers.rocks{size = 8, radius = 1.5, erosion = 0.3,
**        spread = 1, contacts = 1, rounding = 0.15, width = 0.75,
**        seed = the scene seed} -> a block tile (outcrop.blocks.tile's
**        userdata: :count(), :stats(), :block(i), :node(); usable in
**        outcrop.blocks.replicate) whose blocks are the rocks
**   s:rocks(tile [, {ground = node, depth = 2 reach, list = false}])
**        -> node, {instances =, depth =, reach =, list = {{block =,
**        offset = {x, y, z}}, ...} (with list = true)}
**
** erosion, spread and rounding are fractions of the radius. The node is
** the ground (default: the stacks' bedrock and sand convolution surface)
** with the rocks whose sites lie in a rocks layer at most `depth` below
** its top, placed now, with the current outcrop.threshold.
*/
#include <math.h>

#include "l_blocks.h"
#include "l_field.h"
#include "l_handle.h"
#include "l_layers.h"

static int l_rocks(lua_State *L) {
  static const char *const known[] = {"size",   "radius",   "erosion",
                                      "spread", "contacts", "rounding",
                                      "width",  "seed",     NULL};
  const char *fname = "outcrop.layers.rocks";
  oclua_fields f;
  oc_rocks_params rp;
  oc_error err = {OC_OK, ""};
  oclua_fields_open_args(&f, L, fname, known);
  oc_rocks_defaults(&rp);
  rp.size = oclua_field_optnumber(&f, "size", OCLUA_POSITIVE, rp.size);
  rp.radius = oclua_field_optnumber(&f, "radius", OCLUA_POSITIVE, rp.radius);
  rp.erosion = oclua_field_optnumber(&f, "erosion", OCLUA_FINITE, rp.erosion);
  rp.spread = oclua_field_optnumber(&f, "spread", OCLUA_POSITIVE, rp.spread);
  rp.contacts = (int)oclua_field_optint(&f, "contacts", 1, 8, rp.contacts);
  rp.rounding =
      oclua_field_optnumber(&f, "rounding", OCLUA_FINITE, rp.rounding);
  rp.width = oclua_field_optnumber(&f, "width", OCLUA_POSITIVE, rp.width);
  rp.seed = oclua_field_seed(&f, "seed");
  oc_btile **slot = oclua_newtile(L);
  *slot = oc_rocks_tile(&rp, &err);
  if (!*slot) oclua_liberror(L, fname, &err);
  return 1;
}

static int m_rocks(lua_State *L) {
  static const char *const known[] = {"ground", "depth", "list", NULL};
  const char *fname = "layers:rocks";
  oclua_checkargs(L, 3, fname, "(tile [, {ground=, depth=, list=}])");
  lua_settop(L, 3);
  oc_stacks *s = oclua_pinlayers(L, 1, fname);
  oclua_checktile(L, 2, fname, "argument #2");
  oc_stacks_rocks_params p = {NAN, 0};
  oc_node *ground = NULL;
  int list = 0;
  if (!lua_isnil(L, 3)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 3, fname, NULL, known, 0);
    if (oclua_field_push(&f, "depth") != LUA_TNIL) {
      lua_pop(L, 1);
      p.depth = oclua_field_number(&f, "depth", OCLUA_FINITE);
      if (!(p.depth >= 0))
        oclua_error(L, fname, "'depth' must be >= 0 (got %f)",
                    (LUAI_UACNUMBER)p.depth);
    } else {
      lua_pop(L, 1);
    }
    list = oclua_field_optbool(&f, "list", 0);
    if (oclua_field_push(&f, "ground") != LUA_TNIL)
      ground = oclua_checknode(L, -1, fname, "'ground'");
    /* the ground stays on the stack (reachable) */
  }
  p.threshold = oclua_threshold(L, fname);
  /* the tile last: no Lua code runs from here on */
  const oc_btile *tile = oclua_checktile(L, 2, fname, "argument #2");
  if (isnan(p.depth)) p.depth = 2 * oc_rocks_reach(tile);
  oclua_node *u = oclua_newnode(L);
  int top = lua_gettop(L);
  oc_error err = {OC_OK, ""};
  oclua_setnode(L, u, oc_stacks_rocks(s, tile, ground, &p, &err), &err, fname);
  lua_settop(L, top);
  size_t n = 0;
  oc_blocks_instances(u->node, &n);
  lua_createtable(L, 0, 4);
  lua_pushinteger(L, (lua_Integer)n);
  lua_setfield(L, -2, "instances");
  lua_pushnumber(L, p.depth);
  lua_setfield(L, -2, "depth");
  lua_pushnumber(L, oc_rocks_reach(tile));
  lua_setfield(L, -2, "reach");
  if (list) {
    lua_createtable(L, (int)(n < 1000000 ? n : 1000000), 0);
    for (size_t i = 0; i < n; i++) {
      size_t b;
      double off[3];
      oc_blocks_instance(u->node, i, &b, off);
      lua_createtable(L, 0, 2);
      lua_pushinteger(L, (lua_Integer)b + 1);
      lua_setfield(L, -2, "block");
      lua_createtable(L, 3, 0);
      for (int a = 0; a < 3; a++) {
        lua_pushnumber(L, off[a]);
        lua_rawseti(L, -2, a + 1);
      }
      lua_setfield(L, -2, "offset");
      lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "list");
  }
  return 2;
}

void oclua_open_rocks(lua_State *L) {
  lua_pushcfunction(L, l_rocks);
  lua_setfield(L, -2, "rocks");
  luaL_getmetatable(L, OCLUA_LAYERS);
  lua_getfield(L, -1, "__index");
  lua_pushcfunction(L, m_rocks);
  lua_setfield(L, -2, "rocks");
  lua_pop(L, 2);
}
