/*
** stop.c — stopping a running scene cleanly: Ctrl-C, SIGTERM, SIGHUP,
** SIGPIPE (print to a closed pipe: stock Lua dies of it, here the scene
** stops cleanly), --timeout, and os.exit in the sandbox.
**
** All of them work the same way: an error is raised inside the scene and a
** count hook raises it again before every Lua instruction, so a scene that
** catches errors with pcall cannot keep running; the error unwinds to the
** interpreter, which closes the state (closing files) and exits. Long work
** in the engine polls the same flag (OCLUA_INTERRUPT) through its progress
** callback and is cancelled; a second signal of a kind kills the process
** the default way, and a scene still running GRACE seconds after its
** timeout (stuck in C: a pattern match, table.move over 2^63 slots) exits
** at once with the timeout status.
**
** Hooks belong to one Lua thread, so the signal handler must reach the
** thread that is running: the main one, or the innermost coroutine being
** resumed or closed, which the wrapped coroutine.resume, coroutine.wrap
** and coroutine.close track. (A hook installed for good would be simpler
** but slows every Lua loop about twofold.) When such a call returns to a
** stopping scene, the wrapper hooks the calling thread too, so every level
** unwinds.
**
** Lua turns hooks off in two places where script code still runs: in the
** message handler of an error raised by a hook (the stop's own error),
** and in finalizers (__gc). So xpcall is wrapped to skip the script's
** handler once a stop began, and setmetatable records every metatable
** holding a __gc field (the only way a table gets a finalizer; a weak-keyed
** table, from which Lua removes a metatable only after its objects were
** finalized): at the stop their __gc fields are cleared, so no finalizer
** runs script code after a stop, not even in lua_close. C finalizers of
** the module and of io only free and close.
**
** A signal handler can reach nothing but globals; these are the
** interpreter's only mutable globals and are set only around one scene.
*/
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/time.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../bindings/lua/oclua.h"
#include "ocrt.h"

/* registry key of the status requested by ocrt_stop_request */
#define STOP_STATUS "outcrop.runtime.stop"
/* registry key of the weak-keyed set of metatables holding __gc */
#define FINALIZERS "outcrop.runtime.finalizers"

#define GRACE 10 /* seconds a timed-out scene has to unwind */

/* the signals that stop a scene; SIGALRM is the --timeout timer */
static const int stop_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGALRM};
#define NSIGNALS (int)(sizeof stop_signals / sizeof stop_signals[0])

static lua_State *volatile running; /* main thread of the scene */
static lua_State *volatile current; /* innermost coroutine resumed, or NULL */
static volatile sig_atomic_t interrupted; /* a signal or the timer: polled */
static volatile sig_atomic_t cause;       /* see ocrt_stop_cause */
static volatile sig_atomic_t stopping;    /* any stop, os.exit included */
static int finalizers_cleared;            /* touched from Lua only */
static char killed_text[96];              /* the message when GRACE is over */

/* Clears __gc in every metatable setmetatable recorded (see the top). No
** Lua code runs and nothing is allocated, so this is safe in a hook. */
static void clear_finalizers(lua_State *L) {
  if (finalizers_cleared) return;
  finalizers_cleared = 1;
  if (lua_getfield(L, LUA_REGISTRYINDEX, FINALIZERS) == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, -2)) {
      lua_pop(L, 1);
      lua_pushliteral(L, "__gc");
      lua_pushnil(L);
      lua_rawset(L, -3); /* in the metatable, the key */
    }
  }
  lua_pop(L, 1);
}

const char *ocrt_stop_text(int why) {
  switch (why) {
  case 0:
    return "scene stopped by os.exit";
  case SIGTERM:
    return "terminated";
  case SIGHUP:
    return "hangup";
  case SIGPIPE:
    return "broken pipe";
  case OCRT_STOP_TIMEOUT:
    return "timeout";
  default:
    return "interrupted";
  }
}

static void stop_hook(lua_State *L, lua_Debug *ar) {
  (void)ar;
  clear_finalizers(L);
  lua_pushstring(L, ocrt_stop_text(cause));
  lua_error(L);
}

/* Lua documents lua_sethook as safe to call from a signal handler; the
** handler runs at most once per signal (SA_RESETHAND), then that signal
** is fatal again, except SIGALRM: its second expiry, GRACE seconds after
** the timeout, ends the process with the timeout status. */
static void on_signal(int sig) {
  lua_State *co = current;
  if (sig == SIGALRM && cause == OCRT_STOP_TIMEOUT) { /* GRACE is over */
    ssize_t n = write(2, killed_text, strlen(killed_text));
    (void)n;
    _exit(OCRT_ETIMEOUT);
  }
  if (cause == 0) cause = sig == SIGALRM ? OCRT_STOP_TIMEOUT : sig;
  interrupted = stopping = 1;
  if (sig == SIGALRM) alarm(GRACE);
  if (running) lua_sethook(running, stop_hook, LUA_MASKCOUNT, 1);
  if (co) lua_sethook(co, stop_hook, LUA_MASKCOUNT, 1);
}

void ocrt_stop_arm(lua_State *L, double timeout, const char *text) {
  struct sigaction sa, old;
  int i;
  snprintf(killed_text, sizeof killed_text,
           "outcrop: timeout (--timeout %.40s s), still running %d s later: "
           "killed\n",
           text ? text : "", GRACE);
  interrupted = stopping = cause = 0;
  current = NULL;
  running = L;
  /* long C work in the module polls the flag (see oclua.h) */
  lua_pushlightuserdata(L, (void *)(uintptr_t)&interrupted);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_INTERRUPT);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (i = 0; i < NSIGNALS; i++)
    sigaddset(&sa.sa_mask, stop_signals[i]);
  for (i = 0; i < NSIGNALS; i++) {
    if (stop_signals[i] == SIGALRM) {
      sa.sa_flags = 0; /* the second expiry ends GRACE */
    } else {
      sa.sa_flags = SA_RESETHAND; /* no SA_RESTART: a blocked read returns */
      /* a signal ignored at startup (a background job of a script,
      ** nohup) stays ignored, as for any well-behaved Unix program */
      if (sigaction(stop_signals[i], NULL, &old) == 0 &&
          old.sa_handler == SIG_IGN)
        continue;
    }
    sigaction(stop_signals[i], &sa, NULL);
  }
  if (timeout > 0) {
    struct itimerval t = {{0, 0}, {0, 0}};
    t.it_value.tv_sec = (time_t)timeout;
    t.it_value.tv_usec =
        (suseconds_t)((timeout - (double)(time_t)timeout) * 1e6);
    if (t.it_value.tv_sec == 0 && t.it_value.tv_usec == 0)
      t.it_value.tv_usec = 1;
    setitimer(ITIMER_REAL, &t, NULL);
  }
}

void ocrt_stop_finish(lua_State *L) {
  if (stopping) {
    clear_finalizers(L);
    /* any Lua code still reached (a __close in lua_close) raises */
    lua_sethook(L, stop_hook, LUA_MASKCOUNT, 1);
  }
  running = current = NULL; /* the state is about to go */
}

void ocrt_stop_release(void) {
  struct itimerval off = {{0, 0}, {0, 0}};
  struct sigaction sa;
  int i;
  setitimer(ITIMER_REAL, &off, NULL);
  for (i = 0; i < NSIGNALS; i++) {
    if (sigaction(stop_signals[i], NULL, &sa) == 0 &&
        sa.sa_handler == on_signal) {
      sa.sa_handler = SIG_DFL;
      sa.sa_flags = 0;
      sigemptyset(&sa.sa_mask);
      sigaction(stop_signals[i], &sa, NULL);
    }
  }
}

int ocrt_stop_cause(void) {
  return cause;
}

int ocrt_stopping(void) {
  return stopping != 0;
}

int ocrt_stop_request(lua_State *L, int status) {
  lua_pushinteger(L, status);
  lua_setfield(L, LUA_REGISTRYINDEX, STOP_STATUS);
  stopping = 1;
  clear_finalizers(L);
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

/* Calls the function at `fn` (the original resume or close) with the
** arguments on the stack while `co` is the thread a stop must reach.
** The originals run called from C, so they cannot see the Lua caller:
** the wrappers check arguments themselves, and an error gets the caller's
** position here (`where`), as lcorolib would add it. */
static int tracked_call(lua_State *L, int fn, lua_State *co, int where) {
  lua_State *prev = current;
  int st;
  if (stopping) stop_hook(L, NULL);
  lua_pushvalue(L, fn);
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

/* upvalue 1: the original resume */
static int co_resume(lua_State *L) {
  luaL_checktype(L, 1, LUA_TTHREAD);
  return tracked_call(L, lua_upvalueindex(1), lua_tothread(L, 1), 0);
}

/* upvalue 1: the original close */
static int co_close(lua_State *L) {
  luaL_checktype(L, 1, LUA_TTHREAD);
  return tracked_call(L, lua_upvalueindex(1), lua_tothread(L, 1), 1);
}

/* A function made by coroutine.wrap; upvalues: 1 the original resume, 2
** the coroutine, 3 the original close. As lcorolib's, it closes the
** coroutine when it fails, but not after a stop: the coroutine died from
** an error raised in a hook, so Lua would run its __close handlers with
** hooks off, where nothing could stop them. */
static int co_wrapped(lua_State *L) {
  lua_State *co = lua_tothread(L, lua_upvalueindex(2));
  int st;
  lua_pushvalue(L, lua_upvalueindex(2));
  lua_insert(L, 1);
  tracked_call(L, lua_upvalueindex(1), co, 0);
  if (lua_toboolean(L, 1)) return lua_gettop(L) - 1;
  st = lua_status(co);
  if (st != LUA_OK && st != LUA_YIELD) { /* died: close its variables */
    lua_settop(L, 0);
    lua_pushvalue(L, lua_upvalueindex(2));
    tracked_call(L, lua_upvalueindex(3), co, 0);
  }
  if (st != LUA_ERRMEM && lua_type(L, -1) == LUA_TSTRING) {
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
  }
  return lua_error(L);
}

/* upvalues: the original create, resume and close */
static int co_wrap(lua_State *L) {
  luaL_checktype(L, 1, LUA_TFUNCTION);
  lua_settop(L, 1);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, 1, 1);
  lua_pushvalue(L, lua_upvalueindex(2));
  lua_insert(L, -2);
  lua_pushvalue(L, lua_upvalueindex(3));
  lua_pushcclosure(L, co_wrapped, 3);
  return 1;
}

/* The message handler given to xpcall; upvalue 1 is the script's. */
static int guarded_handler(lua_State *L) {
  if (stopping) { /* maybe called from the stop hook: hooks are off */
    lua_settop(L, 1);
    return 1;
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

/* The results of xpcall: true and the function's, or false and the
** error; `extra` values below them (the function, handler, true) stay. */
static int xpcall_done(lua_State *L, int status, lua_KContext extra) {
  if (status != LUA_OK && status != LUA_YIELD) {
    lua_pushboolean(L, 0);
    lua_pushvalue(L, -2);
    return 2;
  }
  return lua_gettop(L) - (int)extra;
}

/* xpcall(f, msgh, ...) as in the base library, with msgh guarded. */
static int sb_xpcall(lua_State *L) {
  int n = lua_gettop(L);
  luaL_checktype(L, 2, LUA_TFUNCTION);
  lua_pushvalue(L, 2);
  lua_pushcclosure(L, guarded_handler, 1);
  lua_replace(L, 2);
  lua_pushboolean(L, 1); /* the first result on success */
  lua_pushvalue(L, 1);   /* the function, above it its arguments */
  lua_rotate(L, 3, 2);
  return xpcall_done(L, lua_pcallk(L, n - 2, LUA_MULTRET, 2, 2, xpcall_done),
                     2);
}

/* setmetatable(t, mt) as in the base library, recording mt when it holds
** __gc (Lua marks t for finalization only when it does). */
static int sb_setmetatable(lua_State *L) {
  int t = lua_type(L, 2);
  luaL_checktype(L, 1, LUA_TTABLE);
  luaL_argexpected(L, t == LUA_TNIL || t == LUA_TTABLE, 2, "nil or table");
  if (luaL_getmetafield(L, 1, "__metatable") != LUA_TNIL)
    return luaL_error(L, "cannot change a protected metatable");
  lua_settop(L, 2);
  if (t == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    if (lua_rawget(L, 2) != LUA_TNIL) {
      luaL_getsubtable(L, LUA_REGISTRYINDEX, FINALIZERS);
      lua_pushvalue(L, 2);
      lua_pushboolean(L, 1);
      lua_rawset(L, -3);
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_setmetatable(L, 1);
  return 1;
}

/* The weak-keyed set of metatables holding __gc. */
static void open_finalizers(lua_State *L) {
  lua_newtable(L);
  lua_createtable(L, 0, 1);
  lua_pushliteral(L, "k");
  lua_setfield(L, -2, "__mode");
  lua_setmetatable(L, -2);
  lua_setfield(L, LUA_REGISTRYINDEX, FINALIZERS);
  finalizers_cleared = 0;
}

void ocrt_stop_open(lua_State *L) {
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  if (lua_getfield(L, -1, LUA_COLIBNAME) == LUA_TTABLE) {
    lua_getfield(L, -1, "create");
    lua_getfield(L, -2, "resume");
    lua_getfield(L, -3, "close");
    lua_pushcclosure(L, co_wrap, 3);
    lua_setfield(L, -2, "wrap");
    lua_getfield(L, -1, "close");
    lua_pushcclosure(L, co_close, 1);
    lua_setfield(L, -2, "close");
    /* last: the two above take the original */
    lua_getfield(L, -1, "resume");
    lua_pushcclosure(L, co_resume, 1);
    lua_setfield(L, -2, "resume");
  }
  lua_pop(L, 2);
  open_finalizers(L);
  lua_pushglobaltable(L);
  lua_pushcfunction(L, sb_xpcall);
  lua_setfield(L, -2, "xpcall");
  lua_pushcfunction(L, sb_setmetatable);
  lua_setfield(L, -2, "setmetatable");
  lua_pop(L, 1);
}
