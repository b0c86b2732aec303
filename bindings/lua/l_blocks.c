/*
** l_blocks.c — outcrop.blocks (Paris et al. 2020, section 4): tile builds
** a periodic fracture tile, a userdata with :stats(), :block(i), :node()
** and :count().
**
** outcrop.blocks.tile{type =, size =, radius =, neighbour =, fractures =,
**   spacing =, disc_radius = {lo, hi}, rounding =, width =, seed =,
**   discs = {{center =, normal =, radius =}, ...}, blocks = {{box =} or
**   {points =} or {planes =}, ...}}
** Defaults: type "equidimensional" (or "rhombohedral", "polyhedral",
** "tabular"), size 20, radius 0.75, neighbour 2, fractures Table 1's
** (15, 24, 44, 30), spacing 2 (1 polyhedral), disc_radius {7, 11}
** equidimensional, {4, 6} rhombohedral, {2.5, 3.5} polyhedral,
** rounding 0.25, width 0.75, seed = the scene seed, discs none, blocks
** none (authored blocks: l_blocks_shapes.c). Also "prismatic" and
** "columnar" (extensions).
**
** outcrop.blocks.replicate(terrain, {tiles = {{tile =, resistance = {lo,
**   hi}}, ...}, geology =, slope = 1, distance = {-1, 1}, anchors = 9,
**   inset = 0})
** builds the replication node (presence decided now, with the current
** outcrop.threshold); resistance defaults to everything. node:stats()
** then has `instances`.
*/
#include <errno.h>
#include <math.h>
#include <string.h>

#include "l_blocks.h"
#include "l_config.h"
#include "l_field.h"
#include "l_handle.h"
#include "l_mesh.h"
#include "l_progress.h"

#define OCLUA_BTILE "outcrop.blocktile"

typedef struct oclua_btile {
  oclua_handle h; /* first (l_handle.h) */
  oc_btile *t;
} oclua_btile;

static void btile_release(oclua_handle *h) {
  oclua_btile *u = (oclua_btile *)h;
  oc_btile_free(u->t);
  u->t = NULL;
}

static oc_btile *check_tile(lua_State *L, const char *fname) {
  oclua_btile *u = luaL_checkudata(L, 1, OCLUA_BTILE);
  oclua_handle_check(L, &u->h, fname);
  if (!u->t) oclua_error(L, fname, "the tile is not made");
  return u->t;
}

/* Reads discs = {{center =, normal =, radius =}, ...} into a Lua-owned
** array, left on the stack. */
static oc_block_disc *read_discs(const oclua_fields *f, size_t *n) {
  static const char *const none[] = {NULL};
  static const char *const known[] = {"center", "normal", "radius", NULL};
  lua_State *L = f->L;
  *n = 0;
  if (oclua_field_push(f, "discs") == LUA_TNIL) {
    lua_pop(L, 1);
    lua_pushnil(L); /* keeps the stack shape */
    return NULL;
  }
  oclua_fields a;
  oclua_fields_open(&a, L, -1, f->fname, "discs.", none, 1);
  if (a.narray > 100000)
    oclua_error(L, f->fname, "'discs': at most 100000 (got %d)", (int)a.narray);
  oc_block_disc *d =
      lua_newuserdatauv(L, (a.narray ? (size_t)a.narray : 1) * sizeof *d, 0);
  for (lua_Integer i = 1; i <= a.narray; i++) {
    oclua_fields e;
    lua_geti(L, a.t, i);
    const char *pre = lua_pushfstring(L, "discs[%d].", (int)i);
    oclua_fields_open(&e, L, -2, f->fname, pre, known, 0);
    d[i - 1].center = oclua_field_vec(&e, "center");
    d[i - 1].normal = oclua_field_vec(&e, "normal");
    d[i - 1].radius = oclua_field_number(&e, "radius", OCLUA_POSITIVE);
    lua_pop(L, 2);
  }
  lua_remove(L, -2); /* the discs table stays reachable from the options */
  *n = (size_t)a.narray;
  return d;
}

static int l_tile(lua_State *L) {
  static const char *const known[] = {
      "type",    "size",        "radius",   "neighbour", "fractures",
      "spacing", "disc_radius", "rounding", "width",     "seed",
      "discs",   "blocks",      NULL};
  static const char *const types[] = {
      "equidimensional", "rhombohedral", "polyhedral", "tabular",
      "prismatic",       "columnar",     NULL};
  const char *fname = "outcrop.blocks.tile";
  oclua_fields f;
  oc_btile_params pp;
  oc_error err = {OC_OK, ""};
  oclua_fields_open_args(&f, L, fname, known);
  int type = oclua_field_optoption(&f, "type", types, 0);
  oc_btile_defaults((oc_block_type)type, &pp);
  pp.size = oclua_field_optnumber(&f, "size", OCLUA_POSITIVE, pp.size);
  pp.radius = oclua_field_optnumber(&f, "radius", OCLUA_POSITIVE, pp.radius);
  pp.neighbour =
      oclua_field_optnumber(&f, "neighbour", OCLUA_POSITIVE, pp.neighbour);
  pp.fractures = (size_t)oclua_field_optint(&f, "fractures", 0, 100000000,
                                            (lua_Integer)pp.fractures);
  pp.spacing = oclua_field_optnumber(&f, "spacing", OCLUA_FINITE, pp.spacing);
  double dr[2];
  if (oclua_field_numbers(&f, "disc_radius", 2, dr, "must be {lo, hi}")) {
    pp.disc_lo = dr[0];
    pp.disc_hi = dr[1];
  }
  pp.rounding =
      oclua_field_optnumber(&f, "rounding", OCLUA_FINITE, pp.rounding);
  pp.width = oclua_field_optnumber(&f, "width", OCLUA_POSITIVE, pp.width);
  pp.seed = oclua_field_seed(&f, "seed");
  pp.discs = read_discs(&f, &pp.ndiscs);
  pp.blocks = oclua_read_block_shapes(&f, &pp.nblocks);
  oclua_btile *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "tile", btile_release);
  u->t = NULL;
  luaL_setmetatable(L, OCLUA_BTILE);
  u->t = oc_btile_new(&pp, &err);
  if (!u->t) oclua_liberror(L, fname, &err);
  return 1;
}

static int tile_stats(lua_State *L) {
  oc_btile_stats st;
  oc_btile_stats_get(check_tile(L, "tile:stats"), &st);
  lua_createtable(L, 0, 9);
  lua_pushinteger(L, (lua_Integer)st.points);
  lua_setfield(L, -2, "points");
  lua_pushinteger(L, (lua_Integer)st.fractures);
  lua_setfield(L, -2, "fractures");
  lua_pushinteger(L, (lua_Integer)st.blocks);
  lua_setfield(L, -2, "blocks");
  lua_pushnumber(L, st.points_per_block);
  lua_setfield(L, -2, "points_per_block");
  lua_pushnumber(L, st.seconds);
  lua_setfield(L, -2, "seconds");
  lua_pushinteger(L, (lua_Integer)st.edges);
  lua_setfield(L, -2, "edges");
  lua_pushinteger(L, (lua_Integer)st.cut);
  lua_setfield(L, -2, "cut");
  lua_pushinteger(L, (lua_Integer)st.thick);
  lua_setfield(L, -2, "thick");
  lua_pushinteger(L, (lua_Integer)st.separated);
  lua_setfield(L, -2, "separated");
  lua_pushinteger(L, (lua_Integer)st.authored);
  lua_setfield(L, -2, "authored");
  return 1;
}

static int tile_count(lua_State *L) {
  oc_btile_stats st;
  oc_btile_stats_get(check_tile(L, "tile:count"), &st);
  lua_pushinteger(L, (lua_Integer)st.blocks);
  return 1;
}

static int tile_block(lua_State *L) {
  const char *fname = "tile:block";
  oc_error err = {OC_OK, ""};
  oc_btile *t = check_tile(L, fname);
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  lua_Integer i = luaL_checkinteger(L, 2);
  if (i < 1 || (lua_Unsigned)i > st.blocks)
    oclua_error(L, fname, "block %d out of range 1 .. %d", (int)i,
                (int)st.blocks);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_btile_block(t, (size_t)(i - 1), &err), &err,
                       fname);
}

static int tile_node(lua_State *L) {
  const char *fname = "tile:node";
  oc_error err = {OC_OK, ""};
  oc_btile *t = check_tile(L, fname);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_btile_node(t, &err), &err, fname);
}

/* tile:meshes([{cell = 0.1}]): {mesh, ...}, one per block. */
static int tile_meshes(lua_State *L) {
  static const char *const known[] = {"cell", NULL};
  const char *fname = "tile:meshes";
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 2, fname, "([{cell =}])");
  check_tile(L, fname);
  double cell = 0.1;
  if (!lua_isnoneornil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, cell);
  }
  double T = oclua_threshold(L, fname);
  oc_btile *t = check_tile(L, fname); /* again, after any Lua code */
  oclua_pin(L, 1, &((oclua_btile *)lua_touserdata(L, 1))->h, fname);
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  lua_createtable(L, (int)st.blocks, 0);
  for (size_t i = 0; i < st.blocks; i++) {
    oclua_progress pl;
    oc_progress pr = oclua_progress_start(L, &pl, fname);
    oclua_mesh *u = oclua_newmesh(L);
    u->mesh = oc_btile_mesh(t, i, cell, T, pr, &err);
    oclua_progress_end(&pl);
    if (!u->mesh && err.code == OC_ECANCEL) return luaL_error(L, "interrupted");
    if (!u->mesh) oclua_liberror(L, fname, &err);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

/* tile:save(path): true, or fail and a message when it cannot be
** written. */
static int tile_save(lua_State *L) {
  const char *fname = "tile:save";
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 2, fname, "(path)");
  oc_btile *t = check_tile(L, fname);
  if (lua_type(L, 2) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 2));
  oclua_target tg;
  int e = oclua_output_target(L, fname, lua_tostring(L, 2), OCLUA_TARGET_CREATE,
                              &tg);
  if (e) return oclua_output_fail(L, &tg, strerror(e));
  int rc = oc_btile_save_at(t, tg.dir, tg.name, &err);
  oclua_target_close(L, &tg);
  if (rc != OC_OK) {
    if (err.code == OC_EIO) return oclua_output_fail(L, &tg, err.msg);
    oclua_liberror(L, fname, &err);
  }
  lua_pushboolean(L, 1);
  return 1;
}

static int tile_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_BTILE));
  return 0;
}

static int tile_tostring(lua_State *L) {
  oclua_btile *u = luaL_checkudata(L, 1, OCLUA_BTILE);
  if (!u->t || u->h.closed) {
    lua_pushliteral(L, OCLUA_BTILE ": (closed)");
  } else {
    oc_btile_stats st;
    oc_btile_stats_get(u->t, &st);
    lua_pushfstring(L, OCLUA_BTILE ": %d blocks", (int)st.blocks);
  }
  return 1;
}

static const luaL_Reg tile_methods[] = {
    {"stats", tile_stats}, {"count", tile_count},   {"block", tile_block},
    {"node", tile_node},   {"meshes", tile_meshes}, {"save", tile_save},
    {NULL, NULL}};

static const luaL_Reg tile_meta[] = {{"__gc", tile_gc},
                                     {"__close", tile_gc},
                                     {"__tostring", tile_tostring},
                                     {NULL, NULL}};

/* outcrop.blocks.replicate(terrain, {tiles = {{tile =, resistance = {lo,
** hi}}, ...}, geology =, slope =, distance = {va, vb}, anchors =}) */
static int l_replicate(lua_State *L) {
  static const char *const known[] = {"tiles",   "geology", "slope", "distance",
                                      "anchors", "inset",   NULL};
  static const char *const none[] = {NULL};
  static const char *const tknown[] = {"tile", "resistance", NULL};
  const char *fname = "outcrop.blocks.replicate";
  oc_error err = {OC_OK, ""};
  oclua_fields f, a;
  oc_replicate_params rp;
  oclua_checkargs(L, 2, fname, "(terrain, {tiles = ...})");
  oc_node *ter = oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oc_replicate_defaults(&rp);
  rp.slope = oclua_field_optnumber(&f, "slope", OCLUA_POSITIVE, rp.slope);
  double d[2];
  if (oclua_field_numbers(&f, "distance", 2, d, "must be {va, vb}")) {
    rp.va = d[0];
    rp.vb = d[1];
  }
  rp.anchors = (int)oclua_field_optint(&f, "anchors", 1, 64, rp.anchors);
  rp.inset = oclua_field_optnumber(&f, "inset", OCLUA_FINITE, rp.inset);
  if (oclua_field_push(&f, "geology") != LUA_TNIL)
    rp.geology = oclua_checknode(L, -1, fname, "'geology'");
  /* the geology stays on the stack (reachable) */
  if (oclua_field_push(&f, "tiles") == LUA_TNIL)
    oclua_field_missing(&f, "tiles", "an array of {tile =, resistance =}");
  oclua_fields_open(&a, L, -1, fname, "tiles.", none, 1);
  if (a.narray < 1 || a.narray > 7)
    oclua_error(L, fname, "'tiles' must hold 1 .. 7 tiles (got %d)",
                (int)a.narray);
  oc_replicate_tile *rt =
      lua_newuserdatauv(L, (size_t)a.narray * sizeof *rt, 0);
  for (lua_Integer i = 1; i <= a.narray; i++) {
    oclua_fields e;
    lua_geti(L, a.t, i);
    const char *pre = lua_pushfstring(L, "tiles[%d].", (int)i);
    oclua_fields_open(&e, L, -2, fname, pre, tknown, 0);
    if (oclua_field_push(&e, "tile") == LUA_TNIL)
      oclua_field_missing(&e, "tile", "a tile of outcrop.blocks.tile");
    if (!luaL_testudata(L, -1, OCLUA_BTILE))
      oclua_field_error(&e, "tile", -1, "must be a block tile");
    lua_pop(L, 1);
    double r[2] = {-HUGE_VAL, HUGE_VAL};
    oclua_field_numbers(&e, "resistance", 2, r, "must be {lo, hi}");
    rt[i - 1].lo = r[0];
    rt[i - 1].hi = r[1];
    lua_pop(L, 2); /* the tiles stay reachable from the options */
  }
  rp.tiles = rt;
  rp.ntiles = (size_t)a.narray;
  rp.threshold = oclua_threshold(L, fname);
  oclua_node *u = oclua_newnode(L);
  /* the tiles last, by raw reads: no Lua code runs from here on */
  for (lua_Integer i = 1; i <= a.narray; i++) {
    lua_rawgeti(L, a.t, i);
    lua_pushliteral(L, "tile");
    lua_rawget(L, -2);
    oclua_btile *b = luaL_testudata(L, -1, OCLUA_BTILE);
    if (!b) oclua_error(L, fname, "'tiles[%d].tile' changed", (int)i);
    oclua_handle_check(L, &b->h, fname);
    rt[i - 1].tile = b->t;
    lua_pop(L, 2);
  }
  return oclua_setnode(L, u, oc_blocks_replicate(ter, &rp, &err), &err, fname);
}

oc_btile **oclua_newtile(lua_State *L) {
  oclua_btile *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "tile", btile_release);
  u->t = NULL;
  luaL_setmetatable(L, OCLUA_BTILE);
  return &u->t;
}

oc_btile *oclua_checktile(lua_State *L, int idx, const char *fname,
                          const char *what) {
  oclua_btile *u = luaL_testudata(L, idx, OCLUA_BTILE);
  if (!u)
    oclua_error(L, fname, "%s must be a block tile (got %s)", what,
                oclua_got(L, idx));
  oclua_handle_check(L, &u->h, fname);
  if (!u->t) oclua_error(L, fname, "the tile is not made");
  return u->t;
}

/* outcrop.blocks.load(path): a tile saved by tile:save. */
static int l_load(lua_State *L) {
  const char *fname = "outcrop.blocks.load";
  oc_error err = {OC_OK, ""};
  oclua_checkargs(L, 1, fname, "(path)");
  if (lua_type(L, 1) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 1));
  oc_btile **t = oclua_newtile(L);
  *t = oc_btile_load(lua_tostring(L, 1), &err);
  if (!*t) oclua_liberror(L, fname, &err);
  oclua_record_input(L, lua_tostring(L, 1), fname);
  return 1;
}

static const luaL_Reg blocks_funcs[] = {{"tile", l_tile},
                                        {"replicate", l_replicate},
                                        {"load", l_load},
                                        {NULL, NULL}};

void oclua_open_blocks(lua_State *L) {
  oclua_newmeta(L, OCLUA_BTILE, tile_meta, tile_methods);
  lua_pop(L, 1);
  luaL_newlib(L, blocks_funcs);
  lua_setfield(L, -2, "blocks");
}
