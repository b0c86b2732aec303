/*
** run.c — one scene in one Lua state, in the shape of lua.c: create the
** state, open the libraries with the collector stopped, load the scene,
** store the module's settings in the registry, preload the module, apply
** the sandbox, run the scene under a message handler that adds a
** traceback, report, close. All of it runs inside a protected call so that
** even a memory error while setting up is reported instead of aborting.
*/
#include <omp.h>
#include <signal.h>
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
  long long max_memory;   /* the limit in force, 0 for none */
  int warn_on, warn_cont; /* warn(): "@on" seen; a message continues */
} run;

/* Warnings as stock lua5.4 shows them: off until warn("@on"). */
static void on_warning(void *ud, const char *msg, int tocont) {
  run *r = ud;
  if (!r->warn_cont && !tocont && msg[0] == '@') { /* a control message */
    if (strcmp(msg, "@on") == 0) r->warn_on = 1;
    if (strcmp(msg, "@off") == 0) r->warn_on = 0;
    return;
  }
  if (r->warn_on) {
    if (!r->warn_cont) fputs("Lua warning: ", stderr);
    fputs(msg, stderr);
    if (!tocont) fputs("\n", stderr);
    fflush(stderr);
  }
  r->warn_cont = tocont;
}

static void report(const char *msg) {
  fprintf(stderr, "outcrop: %s\n",
          msg ? msg : "(error object is not a string)");
  fflush(stderr);
}

/* Message handler: the error message plus a traceback. */
static int msghandler(lua_State *L) {
  const char *msg = lua_tostring(L, 1);
  if (msg == NULL) {
    /* no script code after a stop, be it a __tostring */
    if (!ocrt_stopping() && luaL_callmeta(L, 1, "__tostring") &&
        lua_type(L, -1) == LUA_TSTRING)
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

/* Reports a stop by a signal or the timer; returns the exit status. */
static int report_stop(const run *r, int cause) {
  char msg[160];
  if (cause == OCRT_STOP_TIMEOUT) {
    snprintf(msg, sizeof msg, "timeout (--timeout %s s)", r->opt->timeout_text);
    report(msg);
    return OCRT_ETIMEOUT;
  }
  report(ocrt_stop_text(cause));
  return OCRT_ESIGNAL + cause;
}

/* Reports the scene's error (at the top), saying so when it came from
** the memory limit. */
static void report_error(lua_State *L, const run *r) {
  const char *msg = lua_tostring(L, -1), *at = NULL;
  char limit[48], note[80];
  if (msg && r->max_memory > 0 && ocrt_memory_exhausted()) {
    ocrt_memory_text(r->max_memory, limit, sizeof limit);
    snprintf(note, sizeof note, " (--max-memory %s reached)", limit);
    if ((at = strstr(msg, "not enough memory")) != NULL)
      at += strlen("not enough memory");
    else if ((at = strstr(msg, "out of memory")) != NULL)
      at += strlen("out of memory");
    if (at) {
      lua_pushlstring(L, msg, (size_t)(at - msg));
      lua_pushstring(L, note);
      lua_pushstring(L, at);
      lua_concat(L, 3);
      msg = lua_tostring(L, -1);
    }
  }
  report(msg);
  if (msg && r->max_memory > 0 && ocrt_memory_exhausted() && at == NULL)
    fprintf(stderr, "outcrop: (--max-memory %s was reached)\n", limit);
}

/* Runs the loaded chunk (at the top) and sets r->status. */
static void run_scene(lua_State *L, run *r) {
  int nargs = push_args(L, r->opt);
  int base = lua_gettop(L) - nargs;
  int st, stop;
  lua_pushcfunction(L, msghandler);
  lua_insert(L, base);
  ocrt_stop_arm(L, r->opt->timeout, r->opt->timeout_text);
  st = lua_pcall(L, nargs, 0, base);
  ocrt_stop_finish(L);
  stop = ocrt_stop_status(L);
  if (stop != OCRT_RUN) {
    r->status = stop; /* os.exit: a chosen status, nothing to report */
  } else if (ocrt_stop_cause() != 0) {
    r->status = report_stop(r, ocrt_stop_cause());
  } else if (st == LUA_OK) {
    r->status = OCRT_OK;
  } else {
    report_error(L, r);
    r->status = OCRT_ESCRIPT;
  }
  lua_settop(L, base - 1);
}

/* Loads the scene file (text only in the sandbox: Lua bytecode can be
** crafted to break out of the VM, and the scene is the first chunk an
** attacker controls). Returns a load status; a refused binary chunk is
** reported as LUA_ERRFILE, a usage error rather than a bug in the scene.
** The chunk name is "@" .. path, so messages read "scene.lua:3: ...". */
static int load_scene(lua_State *L, const ocrt_options *o) {
  int st = luaL_loadfilex(L, strcmp(o->scene, "-") == 0 ? NULL : o->scene,
                          o->unsafe ? NULL : "t");
  if (st == LUA_ERRSYNTAX && !o->unsafe &&
      strstr(lua_tostring(L, -1), "attempt to load a binary chunk")) {
    lua_pop(L, 1);
    lua_pushfstring(L,
                    "%s: is a binary chunk (precompiled Lua); scenes must be "
                    "Lua source unless --unsafe is given",
                    strcmp(o->scene, "-") == 0 ? "stdin" : o->scene);
    return LUA_ERRFILE;
  }
  return st;
}

static int pmain(lua_State *L) {
  run *r = lua_touserdata(L, 1);
  const ocrt_options *o = r->opt;
  char msg[512];
  int st;
  luaL_checkversion(L);
  lua_gc(L, LUA_GCSTOP);
  luaL_openlibs(L);
  st = load_scene(L, o);
  if (st == LUA_ERRMEM) return lua_error(L);
  if (st != LUA_OK) {
    report(lua_tostring(L, -1));
    r->status = st == LUA_ERRSYNTAX ? OCRT_ESCRIPT : OCRT_EUSAGE;
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

static int panic(lua_State *L) {
  report(lua_tostring(L, -1));
  return 0; /* Lua then aborts */
}

int ocrt_run(const ocrt_options *o) {
  run r = {o, OCRT_ESCRIPT, NULL, o->max_memory, 0, 0};
  lua_State *L;
  if (o->threads > 0) omp_set_num_threads(o->threads);
  if (r.max_memory < 0) r.max_memory = o->unsafe ? 0 : ocrt_memory_default();
  ocrt_memory_limit(r.max_memory);
  L = lua_newstate(ocrt_lua_alloc, NULL);
  if (L == NULL) {
    report("cannot create the Lua state: not enough memory");
    return OCRT_ESCRIPT;
  }
  lua_atpanic(L, panic);
  lua_setwarnf(L, on_warning, &r);
  lua_pushcfunction(L, pmain);
  lua_pushlightuserdata(L, &r);
  if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
    report(lua_tostring(L, -1));
    r.status = OCRT_ESCRIPT;
  }
  lua_close(L);
  ocrt_stop_release();
  if (r.status == OCRT_OK && ocrt_stop_cause() != 0) /* while closing */
    r.status = report_stop(&r, ocrt_stop_cause());
  ocrt_memory_limit(0);
  free(r.outdir);
  return r.status;
}
