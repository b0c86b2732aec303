/*
** sandbox.c — what a scene may do without --unsafe.
**
** The aim is that running someone else's scene cannot touch files outside
** its output folder or run other code than Lua source:
**  - os.execute, io.popen and package.loadlib are removed; package.searchers
**    keeps the preload and Lua searchers only (no C modules), and the Lua
**    searcher, load, loadfile and dofile accept text chunks only, since
**    Lua bytecode can be crafted to break out of the VM (run.c loads the
**    scene itself, or standard input, as text too);
**  - io.open for writing ("w", "a", any "+"), io.output(name), os.remove
**    and os.rename take paths through oclua_output_path: relative paths
**    land in the output folder and anything outside it is an error.
**    Reading is not restricted and relative read paths resolve against the
**    current folder, as in plain Lua;
**  - os.tmpname and io.tmpfile raise an error (they create files in /tmp,
**    outside --out and without limit); os.setlocale is removed (outputs
**    must not depend on the C locale);
**  - os.exit ends the scene through the interpreter, which closes the state
**    first, so outputs are flushed and closed;
**  - of the debug library only debug.traceback remains: the rest could
**    read the registry (and turn the sandbox off) or the upvalues holding
**    the original functions, or remove the Ctrl-C hook.
** What stays is harmless by itself or bounded elsewhere: reading any file
** the user can read (io.open, io.lines, io.read, dofile, require through
** package.path), os.getenv, os.clock, os.time, os.date, os.difftime,
** string.dump (its output cannot be loaded back), collectgarbage; reading
** special files such as /dev/zero or huge strings is bounded by
** --max-memory, blocking reads (a FIFO) and long loops by --timeout and
** Ctrl-C (see stop.c for what else the stop wraps: coroutine.resume, .wrap,
** .close, xpcall, setmetatable).
** The tables are changed in place, so package.loaded sees the same thing.
*/
#include <stdlib.h>
#include <string.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../bindings/lua/oclua.h"
#include "ocrt.h"

/* Calls upvalue 1 with the arguments now on the stack; returns all its
** results. */
static int call_original(lua_State *L) {
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

/* Replaces argument `arg` (a path) by its resolved output path. */
static void output_arg(lua_State *L, int arg, const char *fname) {
  oclua_output_path(L, fname, luaL_checkstring(L, arg));
  lua_replace(L, arg);
}

static int sb_io_open(lua_State *L) {
  const char *mode = luaL_optstring(L, 2, "r");
  luaL_checkstring(L, 1);
  if (mode[0] != 'r' || strchr(mode, '+') != NULL) output_arg(L, 1, "io.open");
  return call_original(L);
}

static int sb_io_output(lua_State *L) {
  if (lua_type(L, 1) == LUA_TSTRING) output_arg(L, 1, "io.output");
  return call_original(L);
}

static int sb_os_remove(lua_State *L) {
  output_arg(L, 1, "os.remove");
  return call_original(L);
}

static int sb_os_rename(lua_State *L) {
  output_arg(L, 1, "os.rename");
  output_arg(L, 2, "os.rename");
  return call_original(L);
}

static int sb_os_tmpname(lua_State *L) {
  return luaL_error(L, "os.tmpname is not allowed in scenes; "
                       "write under the output folder instead");
}

static int sb_io_tmpfile(lua_State *L) {
  return luaL_error(L, "io.tmpfile is not allowed in scenes; "
                       "write under the output folder instead");
}

static int sb_os_exit(lua_State *L) {
  int status;
  if (lua_isboolean(L, 1))
    status = lua_toboolean(L, 1) ? EXIT_SUCCESS : EXIT_FAILURE;
  else
    status = (int)luaL_optinteger(L, 1, EXIT_SUCCESS);
  return ocrt_stop_request(L, status);
}

/* Calls the original load or loadfile with its mode argument (at index
** `arg`) forced to text. */
static int text_only(lua_State *L, int arg) {
  const char *mode = luaL_optstring(L, arg, "bt");
  if (strchr(mode, 't') == NULL) {
    luaL_pushfail(L);
    lua_pushliteral(L, "binary chunks are not allowed in scenes");
    return 2;
  }
  if (lua_gettop(L) < arg) lua_settop(L, arg);
  lua_pushliteral(L, "t");
  lua_replace(L, arg);
  return call_original(L);
}

static int sb_load(lua_State *L) {
  return text_only(L, 3);
}

static int sb_loadfile(lua_State *L) {
  return text_only(L, 2);
}

static int dofile_cont(lua_State *L, int status, lua_KContext ctx) {
  (void)status;
  (void)ctx;
  return lua_gettop(L) - 1;
}

static int sb_dofile(lua_State *L) {
  const char *name = luaL_optstring(L, 1, NULL);
  lua_settop(L, 1);
  if (luaL_loadfilex(L, name, "t") != LUA_OK) return lua_error(L);
  lua_callk(L, 0, LUA_MULTRET, 0, dofile_cont);
  return dofile_cont(L, LUA_OK, 0);
}

/* package.searchers[2] for text files only; upvalue 1 is package. */
static int sb_search_lua(lua_State *L) {
  const char *name = luaL_checkstring(L, 1);
  const char *file;
  lua_getfield(L, lua_upvalueindex(1), "searchpath");
  lua_pushvalue(L, 1);
  if (lua_getfield(L, lua_upvalueindex(1), "path") != LUA_TSTRING)
    return luaL_error(L, "'package.path' must be a string");
  lua_call(L, 2, 2);
  if (lua_isnil(L, -2)) return 1; /* the message listing the files tried */
  lua_pop(L, 1);
  file = lua_tostring(L, -1);
  if (luaL_loadfilex(L, file, "t") != LUA_OK)
    return luaL_error(L, "error loading module '%s' from file '%s':\n\t%s",
                      name, file, lua_tostring(L, -1));
  lua_insert(L, -2); /* loader, then the file name as its extra value */
  return 2;
}

/* Sets t[name] (t at the top) to a wrapper around the current t[name]. */
static void wrap(lua_State *L, const char *name, lua_CFunction f) {
  lua_getfield(L, -1, name);
  lua_pushcclosure(L, f, 1);
  lua_setfield(L, -2, name);
}

static void set_function(lua_State *L, const char *name, lua_CFunction f) {
  lua_pushcfunction(L, f);
  lua_setfield(L, -2, name);
}

static void remove_field(lua_State *L, const char *name) {
  lua_pushnil(L);
  lua_setfield(L, -2, name);
}

static void sandbox_base(lua_State *L) {
  lua_pushglobaltable(L);
  wrap(L, "load", sb_load);
  wrap(L, "loadfile", sb_loadfile);
  set_function(L, "dofile", sb_dofile);
  lua_pop(L, 1);
}

static void sandbox_io(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_getfield(L, -1, LUA_IOLIBNAME);
  remove_field(L, "popen");
  set_function(L, "tmpfile", sb_io_tmpfile);
  wrap(L, "open", sb_io_open);
  wrap(L, "output", sb_io_output);
  lua_pop(L, 1);
  lua_getfield(L, -1, LUA_OSLIBNAME);
  remove_field(L, "execute");
  /* the C locale changes how numbers print and parse in every C writer:
  ** outputs must not depend on it */
  remove_field(L, "setlocale");
  wrap(L, "remove", sb_os_remove);
  wrap(L, "rename", sb_os_rename);
  set_function(L, "tmpname", sb_os_tmpname);
  set_function(L, "exit", sb_os_exit);
  lua_pop(L, 2);
}

static void sandbox_package(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_getfield(L, -1, LUA_LOADLIBNAME);
  remove_field(L, "loadlib");
  lua_pushliteral(L, "");
  lua_setfield(L, -2, "cpath");
  /* searchers: 1 preload stays, 2 becomes text-only, 3 and 4 (C) go */
  lua_getfield(L, -1, "searchers");
  lua_pushvalue(L, -2);
  lua_pushcclosure(L, sb_search_lua, 1);
  lua_rawseti(L, -2, 2);
  lua_pushnil(L);
  lua_rawseti(L, -2, 4);
  lua_pushnil(L);
  lua_rawseti(L, -2, 3);
  lua_pop(L, 3);
}

static void sandbox_debug(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_getfield(L, -1, LUA_DBLIBNAME);
  lua_pushnil(L);
  while (lua_next(L, -2)) {
    lua_pop(L, 1);
    if (lua_type(L, -1) != LUA_TSTRING ||
        strcmp(lua_tostring(L, -1), "traceback") != 0) {
      lua_pushvalue(L, -1);
      lua_pushnil(L);
      lua_rawset(L, -4); /* clearing a visited field is allowed in next */
    }
  }
  lua_pop(L, 2);
}

void ocrt_sandbox(lua_State *L) {
  sandbox_base(L);
  sandbox_io(L);
  sandbox_package(L);
  sandbox_debug(L);
}
