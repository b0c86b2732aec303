/*
** l_field.c — the node userdata: its metatable, its lazily compiled
** program, and the queries (eval, gradient, bounds, lipschitz, stats,
** kind). Constructors live in l_prim.c, operators in l_ops.c.
*/
#include <math.h>

#include "l_field.h"
#include "l_handle.h"

#define PROGRAM_BOX "outcrop.program"

/* A program box: the program, and the node userdata (its user value, so
** that the node's memory outlives the box) whose cache it may be. */
typedef struct program_box {
  oc_program *prog;
  oclua_node *owner;
} program_box;

static int box_gc(lua_State *L) {
  program_box *b = luaL_checkudata(L, 1, PROGRAM_BOX);
  if (b->prog) {
    if (b->owner && b->owner->prog == b->prog) b->owner->prog = NULL;
    oc_program_free(b->prog);
  }
  b->prog = NULL;
  return 0;
}

oclua_node *oclua_newnode(lua_State *L) {
  oclua_node *u = lua_newuserdatauv(L, sizeof *u, 1);
  u->node = NULL;
  u->prog = NULL;
  u->threshold = 0;
  luaL_setmetatable(L, OCLUA_NODE);
  return u;
}

int oclua_setnode(lua_State *L, oclua_node *u, oc_node *node,
                  const oc_error *err, const char *fname) {
  if (node == NULL) return oclua_liberror(L, fname, err);
  u->node = node;
  return 1;
}

oclua_node *oclua_testnode(lua_State *L, int idx) {
  oclua_node *u = luaL_testudata(L, idx, OCLUA_NODE);
  return u && u->node ? u : NULL;
}

oc_node *oclua_checknode(lua_State *L, int idx, const char *fname,
                         const char *what) {
  oclua_node *u = oclua_testnode(L, idx);
  if (u == NULL)
    oclua_error(L, fname, "%s must be an outcrop node (got %s)", what,
                oclua_got(L, idx));
  return u->node;
}

double oclua_threshold(lua_State *L, const char *fname) {
  double t = OC_DEFAULT_THRESHOLD;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_MODULE) == LUA_TTABLE) {
    lua_getfield(L, -1, "threshold");
    t = lua_tonumber(L, -1);
    if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(t) || t <= 0)
      oclua_error(L, fname,
                  "outcrop.threshold must be a positive number "
                  "(got %s)",
                  oclua_got(L, -1));
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return t;
}

const oc_program *oclua_program(lua_State *L, int idx, const char *fname) {
  return oclua_program_at(L, idx, fname, oclua_threshold(L, fname));
}

const oc_program *oclua_program_at(lua_State *L, int idx, const char *fname,
                                   double t) {
  oclua_node *u = luaL_checkudata(L, idx, OCLUA_NODE);
  oc_compile_options opts = {t, 0};
  oc_error err = {OC_OK, ""};
  idx = lua_absindex(L, idx);
  if (u->node == NULL) oclua_error(L, fname, "the node was collected");
  if (u->prog && u->threshold == t) {
    lua_getiuservalue(L, idx, 1);
    return u->prog;
  }
  /* The box before the program, so a raised error cannot leak it; its
  ** allocation may run finalizers, which may recompile this node: the
  ** cache is replaced only below. */
  program_box *b = lua_newuserdatauv(L, sizeof *b, 1);
  b->prog = NULL;
  b->owner = NULL;
  luaL_setmetatable(L, PROGRAM_BOX);
  lua_pushvalue(L, idx);
  lua_setiuservalue(L, -2, 1);
  if (u->node == NULL) oclua_error(L, fname, "the node was collected");
  b->prog = oc_compile(u->node, &opts, &err);
  if (b->prog == NULL) oclua_liberror(L, fname, &err);
  b->owner = u;
  lua_pushvalue(L, -1);
  lua_setiuservalue(L, idx, 1); /* the old box goes to the collector */
  u->prog = b->prog;
  u->threshold = t;
  return b->prog;
}

/* ---- queries --------------------------------------------------------- */

static oclua_node *checkself(lua_State *L, const char *fname) {
  oclua_node *u = luaL_checkudata(L, 1, OCLUA_NODE);
  if (u->node == NULL) oclua_error(L, fname, "the node was collected");
  return u;
}

/* A point is x, y, z or one table {x, y, z} / {x=, y=, z=}. */
static oc_vec3 checkpoint(lua_State *L, const char *fname) {
  double c[3];
  if (lua_istable(L, 2)) {
    oclua_checkargs(L, 2, fname, "(x, y, z) or ({x, y, z})");
    return oclua_tovec(L, 2, fname, "point", 0);
  }
  oclua_checkargs(L, 4, fname, "(x, y, z) or ({x, y, z})");
  for (int i = 0; i < 3; i++) {
    if (lua_type(L, 2 + i) != LUA_TNUMBER)
      oclua_error(L, fname,
                  "expected x, y, z or a table {x, y, z} "
                  "(argument #%d is %s)",
                  1 + i, oclua_got(L, 2 + i));
    c[i] = lua_tonumber(L, 2 + i);
    if (!isfinite(c[i]))
      oclua_error(L, fname,
                  "coordinates must be finite (argument #%d is "
                  "%f)",
                  1 + i, (LUAI_UACNUMBER)c[i]);
  }
  return (oc_vec3){c[0], c[1], c[2]};
}

static int node_eval(lua_State *L) {
  const oc_program *prog;
  oc_vec3 p;
  checkself(L, "node:eval");
  p = checkpoint(L, "node:eval");
  prog = oclua_program(L, 1, "node:eval");
  lua_pushnumber(L, oc_program_eval(prog, p));
  return 1;
}

static int node_gradient(lua_State *L) {
  const oc_program *prog;
  oc_vec3 p, g = {0, 0, 0};
  checkself(L, "node:gradient");
  p = checkpoint(L, "node:gradient");
  prog = oclua_program(L, 1, "node:gradient");
  oc_program_gradient(prog, p, &g);
  lua_pushnumber(L, g.x);
  lua_pushnumber(L, g.y);
  lua_pushnumber(L, g.z);
  return 3;
}

static int node_bounds(lua_State *L) {
  oc_aabb b;
  checkself(L, "node:bounds");
  b = oc_program_bounds(oclua_program(L, 1, "node:bounds"));
  lua_pushnumber(L, b.lo.x);
  lua_pushnumber(L, b.lo.y);
  lua_pushnumber(L, b.lo.z);
  lua_pushnumber(L, b.hi.x);
  lua_pushnumber(L, b.hi.y);
  lua_pushnumber(L, b.hi.z);
  return 6;
}

static int node_lipschitz(lua_State *L) {
  checkself(L, "node:lipschitz");
  lua_pushnumber(L,
                 oc_program_lipschitz(oclua_program(L, 1, "node:lipschitz")));
  return 1;
}

static int node_stats(lua_State *L) {
  oc_program_stats st = {0, 0, 0};
  checkself(L, "node:stats");
  oc_program_get_stats(oclua_program(L, 1, "node:stats"), &st);
  oclua_pushstats(L, st.nodes, st.primitives, st.bytes);
  size_t inst;
  if (oc_blocks_instances(oclua_testnode(L, 1)->node, &inst)) {
    lua_pushinteger(L, (lua_Integer)inst);
    lua_setfield(L, -2, "instances"); /* Table 2's #R */
  }
  if (oc_blocks_memory(oclua_testnode(L, 1)->node, &inst)) {
    lua_pushinteger(L, (lua_Integer)inst);
    lua_setfield(L, -2, "block_bytes"); /* Table 2's memory */
  }
  return 1;
}

static int node_kind(lua_State *L) {
  lua_pushstring(L, oc_node_kind(checkself(L, "node:kind")->node));
  return 1;
}

/* ---- metamethods ----------------------------------------------------- */

static int node_gc(lua_State *L) {
  oclua_node *u = luaL_checkudata(L, 1, OCLUA_NODE);
  /* Cleared so a resurrected userdata reads as collected, not freed; the
  ** program is its box's to free (it holds its own node references). */
  if (u->node) oc_node_release(u->node);
  u->prog = NULL;
  u->node = NULL;
  return 0;
}

static int node_tostring(lua_State *L) {
  oclua_node *u = luaL_checkudata(L, 1, OCLUA_NODE);
  if (u->node == NULL)
    lua_pushliteral(L, OCLUA_NODE ": (collected)");
  else
    lua_pushfstring(L, OCLUA_NODE ": %s", oc_node_kind(u->node));
  return 1;
}

static const luaL_Reg node_methods[] = {{"eval", node_eval},
                                        {"gradient", node_gradient},
                                        {"bounds", node_bounds},
                                        {"lipschitz", node_lipschitz},
                                        {"stats", node_stats},
                                        {"kind", node_kind},
                                        {NULL, NULL}};

static const luaL_Reg node_meta[] = {
    {"__gc", node_gc}, {"__tostring", node_tostring}, {NULL, NULL}};

void oclua_open_field(lua_State *L) {
  static const luaL_Reg box_meta[] = {{"__gc", box_gc}, {NULL, NULL}};
  oclua_newmeta(L, PROGRAM_BOX, box_meta, NULL);
  lua_pop(L, 1);
  oclua_newmeta(L, OCLUA_NODE, node_meta, node_methods);
  luaL_setfuncs(L, oclua_node_operators, 0);
  lua_pop(L, 1);
}
