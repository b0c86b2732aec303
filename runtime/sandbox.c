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
**    and os.rename take paths through oclua_output_target: relative paths
**    land in the output folder, anything outside it or through a symbolic
**    link is an error, and the file is opened (or removed, renamed)
**    relative to the output folder's descriptor, folder by folder, so
**    nothing done meanwhile can lead it outside.
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
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

/* ---- writes: opened relative to the output folder's descriptor ---------- */

/* The open(2) flags of a C fopen mode ([rwa]+?b*), or -1. */
static int open_flags(const char *mode) {
  int flags;
  switch (*mode++) {
  case 'r':
    flags = 0;
    break;
  case 'w':
    flags = O_CREAT | O_TRUNC;
    break;
  case 'a':
    flags = O_CREAT | O_APPEND;
    break;
  default:
    return -1;
  }
  int plus = *mode == '+';
  if (plus) mode++;
  mode += strspn(mode, "b");
  if (*mode) return -1;
  return flags | (plus ? O_RDWR : flags ? O_WRONLY : O_RDONLY);
}

static int close_stream(lua_State *L) {
  luaL_Stream *p = luaL_checkudata(L, 1, LUA_FILEHANDLE);
  errno = 0;
  return luaL_fileresult(L, fclose(p->f) == 0, NULL);
}

/* Pushes a Lua file opened on `name` in the output folder, as io.open
** would, or fail, a message and an errno. */
static int open_output(lua_State *L, const char *fname, const char *path,
                       const char *mode) {
  oclua_target t;
  int flags = open_flags(mode);
  luaL_argcheck(L, flags >= 0, 2, "invalid mode");
  int e = oclua_output_target(L, fname, path, OCLUA_TARGET_CREATE, &t);
  int fd = -1;
  if (!e) {
    fd = openat(t.dir, t.name, flags | O_NOFOLLOW | O_CLOEXEC, 0666);
    e = fd < 0 ? errno : 0;
  }
  oclua_target_close(L, &t);
  lua_pop(L, 1);
  /* created closed, as liolib does, so an error meanwhile leaks nothing */
  luaL_Stream *p = lua_newuserdatauv(L, sizeof *p, 0);
  p->closef = NULL;
  luaL_setmetatable(L, LUA_FILEHANDLE);
  if (!e) {
    p->f = fdopen(fd, mode);
    if (p->f == NULL) {
      e = errno;
      close(fd);
    }
  }
  if (e) {
    errno = e;
    return luaL_fileresult(L, 0, path);
  }
  p->closef = close_stream;
  return 1;
}

static int sb_io_open(lua_State *L) {
  const char *path = luaL_checkstring(L, 1);
  const char *mode = luaL_optstring(L, 2, "r");
  if (mode[0] == 'r' && strchr(mode, '+') == NULL) return call_original(L);
  return open_output(L, "io.open", path, mode);
}

static int sb_io_output(lua_State *L) {
  if (lua_type(L, 1) == LUA_TSTRING) {
    const char *path = lua_tostring(L, 1);
    if (open_output(L, "io.output", path, "w") != 1)
      return luaL_error(L, "cannot open file '%s' (%s)", path,
                        lua_tostring(L, -2));
    lua_replace(L, 1);
    lua_settop(L, 1);
  }
  return call_original(L);
}

static int sb_os_remove(lua_State *L) {
  const char *path = luaL_checkstring(L, 1);
  oclua_target t;
  int e = oclua_output_target(L, "os.remove", path, OCLUA_TARGET_LINK, &t);
  /* remove(3) removes empty folders too */
  if (!e && unlinkat(t.dir, t.name, 0) != 0)
    e = errno == EISDIR && unlinkat(t.dir, t.name, AT_REMOVEDIR) == 0 ? 0
                                                                      : errno;
  oclua_target_close(L, &t);
  errno = e;
  return luaL_fileresult(L, e == 0, path);
}

static int sb_os_rename(lua_State *L) {
  const char *from = luaL_checkstring(L, 1);
  const char *to = luaL_checkstring(L, 2);
  oclua_target a, b;
  int e = oclua_output_target(L, "os.rename", from, OCLUA_TARGET_LINK, &a);
  if (!e)
    e = oclua_output_target(L, "os.rename", to, OCLUA_TARGET_LINK, &b);
  else
    b.owner = NULL;
  if (!e && renameat(a.dir, a.name, b.dir, b.name) != 0) e = errno;
  oclua_target_close(L, &a);
  oclua_target_close(L, &b);
  errno = e;
  return luaL_fileresult(L, e == 0, from);
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
  /* the output folder is resolved once, now, for the whole run */
  oclua_outdir_fd(L, "outcrop");
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
