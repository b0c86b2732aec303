/*
** run.c — one scene in one Lua state, in the shape of lua.c: create the
** state, open the libraries with the collector stopped, load the scene,
** store the module's settings in the registry, preload the module, apply
** the sandbox, run the scene under a message handler that adds a
** traceback, report, close. All of it runs inside a protected call so that
** even a memory error while setting up is reported instead of aborting.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../bindings/lua/oclua.h"
#include "ocrt.h"

typedef struct run {
  const ocrt_options *opt;
  int status;   /* exit status, set by pmain */
  char *outdir; /* malloc'ed; freed after lua_close, so errors cannot leak */
} run;

static void report(const char *msg) {
  fprintf(stderr, "outcrop: %s\n",
          msg ? msg : "(error object is not a string)");
  fflush(stderr);
}

/* Message handler: the error message plus a traceback. */
static int msghandler(lua_State *L) {
  const char *msg = lua_tostring(L, 1);
  if (msg == NULL) {
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING)
      return 1;
    msg =
        lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  }
  luaL_traceback(L, L, msg, 1);
  return 1;
}

/* Registry settings read by the module (see oclua.h). */
static void set_registry(lua_State *L, const run *r) {
  const ocrt_options *o = r->opt;
  int i;
  lua_createtable(L, 0, o->nparams);
  for (i = 0; i < o->nparams; i++) {
    const char *p = o->params[i];
    const char *eq = strchr(p, '=');
    lua_pushlstring(L, p, (size_t)(eq - p));
    lua_pushstring(L, eq + 1);
    lua_rawset(L, -3); /* a repeated name: the last value wins */
  }
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS);
  lua_pushstring(L, r->outdir);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR);
  lua_pushboolean(L, !o->unsafe);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  lua_pushinteger(L, o->seed);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SEED);
  lua_pushstring(L, o->scene);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE);
}

/* package.preload.outcrop, package.loaded.outcrop and the global. */
static void open_module(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
  lua_pushcfunction(L, luaopen_outcrop);
  lua_setfield(L, -2, "outcrop");
  lua_pop(L, 1);
  luaL_requiref(L, "outcrop", luaopen_outcrop, 0);
  lua_setglobal(L, "outcrop");
}

/* The global `arg` as in lua.c (arg[0] the scene, arg[1..] the rest);
** the same strings are pushed as the chunk's arguments (`...`). */
static int push_args(lua_State *L, const ocrt_options *o) {
  int i;
  lua_createtable(L, o->nargs, 1);
  lua_pushstring(L, o->scene);
  lua_rawseti(L, -2, 0);
  for (i = 0; i < o->nargs; i++) {
    lua_pushstring(L, o->args[i]);
    lua_rawseti(L, -2, i + 1);
  }
  lua_setglobal(L, "arg");
  luaL_checkstack(L, o->nargs, "too many arguments to the scene");
  for (i = 0; i < o->nargs; i++)
    lua_pushstring(L, o->args[i]);
  return o->nargs;
}

/* Runs the loaded chunk (at the top) and sets r->status. */
static void run_scene(lua_State *L, run *r) {
  int nargs = push_args(L, r->opt);
  int base = lua_gettop(L) - nargs;
  int st, stop;
  lua_pushcfunction(L, msghandler);
  lua_insert(L, base);
  ocrt_stop_arm(L);
  st = lua_pcall(L, nargs, 0, base);
  ocrt_stop_disarm(L);
  stop = ocrt_stop_status(L);
  if (stop != OCRT_RUN) {
    r->status = stop; /* os.exit: a chosen status, nothing to report */
  } else if (st == LUA_OK) {
    r->status = OCRT_OK;
  } else if (ocrt_interrupted()) {
    report("interrupted");
    r->status = OCRT_EINTR;
  } else {
    report(lua_tostring(L, -1));
    r->status = OCRT_ESCRIPT;
  }
  lua_settop(L, base - 1);
}

static int pmain(lua_State *L) {
  run *r = lua_touserdata(L, 1);
  const ocrt_options *o = r->opt;
  char msg[512];
  int st;
  luaL_checkversion(L);
  lua_gc(L, LUA_GCSTOP);
  luaL_openlibs(L);
  /* the chunk name is "@" .. path, so messages read "scene.lua:3: ..." */
  st = luaL_loadfile(L, strcmp(o->scene, "-") == 0 ? NULL : o->scene);
  if (st == LUA_ERRMEM) return lua_error(L);
  if (st != LUA_OK) {
    report(lua_tostring(L, -1));
    r->status = st == LUA_ERRFILE ? OCRT_EUSAGE : OCRT_ESCRIPT;
    return 0;
  }
  r->outdir = ocrt_outdir(o->outdir, msg, sizeof msg);
  if (r->outdir == NULL) {
    report(msg);
    r->status = OCRT_EUSAGE;
    return 0;
  }
  set_registry(L, r); /* before the module: it reads the seed when opened */
  open_module(L);
  if (!o->unsafe) ocrt_sandbox(L);
  ocrt_stop_open(L);
  lua_gc(L, LUA_GCRESTART);
  lua_gc(L, LUA_GCGEN, 0, 0); /* as stock lua5.4 runs scripts */
  run_scene(L, r);
  return 0;
}

int ocrt_run(const ocrt_options *o) {
  run r = {o, OCRT_ESCRIPT, NULL};
  lua_State *L;
  if (o->threads > 0) omp_set_num_threads(o->threads);
  L = luaL_newstate();
  if (L == NULL) {
    report("cannot create the Lua state: not enough memory");
    return OCRT_ESCRIPT;
  }
  lua_pushcfunction(L, pmain);
  lua_pushlightuserdata(L, &r);
  if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
    report(lua_tostring(L, -1));
    r.status = OCRT_ESCRIPT;
  }
  lua_close(L);
  free(r.outdir);
  return r.status;
}
