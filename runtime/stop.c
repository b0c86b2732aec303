/*
** stop.c — stopping a running scene cleanly: Ctrl-C, and os.exit in the
** sandbox.
**
** Both work the same way: an error is raised inside the scene and a count
** hook raises it again before every Lua instruction, so a scene that
** catches errors with pcall cannot keep running; the error unwinds to the
** interpreter, which closes the state (closing files, running finalizers)
** and exits. A stop never interrupts C code: long work in the module runs
** to its end (or checks for itself), and a second Ctrl-C kills the process
** the default way.
**
** Hooks belong to one Lua thread, so the signal handler must reach the
** thread that is running: the main one, or the innermost coroutine being
** resumed, which the wrapped coroutine.resume and coroutine.wrap track.
** (A hook installed for good would be simpler but slows every Lua loop
** about twofold.) When a resume returns to a stopping scene, the wrapper
** hooks the resuming thread too, so every level unwinds.
**
** A signal handler can reach nothing but globals; these are the
** interpreter's only mutable globals and are set only around one scene.
*/
#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../bindings/lua/oclua.h"
#include "ocrt.h"

/* registry key of the status requested by ocrt_stop_request */
#define STOP_STATUS "outcrop.runtime.stop"

static lua_State *volatile running; /* main thread of the scene */
static lua_State *volatile current; /* innermost coroutine resumed, or NULL */
static volatile sig_atomic_t interrupted; /* Ctrl-C was pressed */
static volatile sig_atomic_t stopping;    /* Ctrl-C or os.exit */

static void stop_hook(lua_State *L, lua_Debug *ar) {
  (void)ar;
  if (interrupted)
    lua_pushliteral(L, "interrupted");
  else
    lua_pushliteral(L, "scene stopped by os.exit");
  lua_error(L);
}

/* Lua documents lua_sethook as safe to call from a signal handler; the
** handler runs at most once (SA_RESETHAND), then Ctrl-C is fatal again. */
static void on_sigint(int sig) {
  lua_State *co = current;
  (void)sig;
  interrupted = stopping = 1;
  if (running) lua_sethook(running, stop_hook, LUA_MASKCOUNT, 1);
  if (co) lua_sethook(co, stop_hook, LUA_MASKCOUNT, 1);
}

void ocrt_stop_arm(lua_State *L) {
  struct sigaction sa, old;
  interrupted = stopping = 0;
  current = NULL;
  running = L;
  /* long C work in the module polls the flag (see oclua.h) */
  lua_pushlightuserdata(L, (void *)(uintptr_t)&interrupted);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_INTERRUPT);
  /* a SIGINT ignored at startup (a background job of a script, nohup)
  ** stays ignored, as for any well-behaved Unix program */
  if (sigaction(SIGINT, NULL, &old) == 0 && old.sa_handler == SIG_IGN) return;
  sa.sa_handler = on_sigint;
  sa.sa_flags = SA_RESETHAND;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
}

void ocrt_stop_disarm(lua_State *L) {
  struct sigaction sa;
  if (sigaction(SIGINT, NULL, &sa) == 0 && sa.sa_handler == on_sigint) {
    sa.sa_handler = SIG_DFL;
    sa.sa_flags = 0;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
  }
  running = current = NULL;
  lua_sethook(L, NULL, 0, 0);
}

int ocrt_interrupted(void) {
  return interrupted != 0;
}

int ocrt_stop_request(lua_State *L, int status) {
  lua_pushinteger(L, status);
  lua_setfield(L, LUA_REGISTRYINDEX, STOP_STATUS);
  stopping = 1;
  lua_sethook(L, stop_hook, LUA_MASKCOUNT, 1);
  if (running && running != L)
    lua_sethook(running, stop_hook, LUA_MASKCOUNT, 1);
  lua_pushliteral(L, "scene stopped by os.exit");
  return lua_error(L);
}

int ocrt_stop_status(lua_State *L) {
  int isnum, status;
  lua_getfield(L, LUA_REGISTRYINDEX, STOP_STATUS);
  status = (int)lua_tointegerx(L, -1, &isnum);
  lua_pop(L, 1);
  return isnum ? status : OCRT_RUN;
}

/* Calls upvalue 1 (the original resume, or a wrap function) with the
** arguments on the stack while `co` is the thread Ctrl-C must reach.
** The originals run called from C, so they cannot see the Lua caller:
** the wrappers check arguments themselves, and a wrap function's error
** gets the caller's position here (`where`), as lcorolib would add it. */
static int tracked_call(lua_State *L, lua_State *co, int where) {
  lua_State *prev = current;
  int st;
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  current = co;
  st = lua_pcall(L, lua_gettop(L) - 1, LUA_MULTRET, 0);
  current = prev; /* before anything can raise: co may be collected */
  if (stopping) {
    lua_sethook(L, stop_hook, LUA_MASKCOUNT, 1);
    stop_hook(L, NULL);
  }
  if (st == LUA_OK) return lua_gettop(L);
  if (where && st != LUA_ERRMEM && lua_type(L, -1) == LUA_TSTRING) {
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
  }
  return lua_error(L);
}

static int co_resume(lua_State *L) {
  luaL_checktype(L, 1, LUA_TTHREAD);
  return tracked_call(L, lua_tothread(L, 1), 0);
}

/* upvalue 1: the function made by the original wrap; 2: its thread */
static int co_wrapped(lua_State *L) {
  return tracked_call(L, lua_tothread(L, lua_upvalueindex(2)), 1);
}

static int co_wrap(lua_State *L) {
  luaL_checktype(L, 1, LUA_TFUNCTION);
  lua_settop(L, 1);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, 1, 1);
  /* lcorolib keeps the thread as the wrapper's only upvalue; should that
  ** change, the plain wrapper is returned (Ctrl-C then reaches such a
  ** coroutine only when it yields) */
  if (lua_getupvalue(L, -1, 1) == NULL) return 1;
  if (lua_type(L, -1) != LUA_TTHREAD) {
    lua_pop(L, 1);
    return 1;
  }
  lua_pushcclosure(L, co_wrapped, 2);
  return 1;
}

void ocrt_stop_open(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  if (lua_getfield(L, -1, LUA_COLIBNAME) == LUA_TTABLE) {
    lua_getfield(L, -1, "resume");
    lua_pushcclosure(L, co_resume, 1);
    lua_setfield(L, -2, "resume");
    lua_getfield(L, -1, "wrap");
    lua_pushcclosure(L, co_wrap, 1);
    lua_setfield(L, -2, "wrap");
  }
  lua_pop(L, 2);
}
