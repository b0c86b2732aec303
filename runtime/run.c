/*
** run.c — one scene in one Lua state, in the shape of lua.c: create the
** state, open the libraries with the collector stopped, load the scene,
** store the module's settings in the registry, preload the module, apply
** the sandbox, run the scene under a message handler that adds a
** traceback, report, close. All of it runs inside a protected call so that
** even a memory error while setting up is reported instead of aborting.
** The scene's bytes are hashed as they are loaded (provenance), and the
** command line reaches the module through oclua_configure, the path of
** outcrop.configure.
*/
#include <errno.h>
#include <fcntl.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../bindings/lua/oclua.h"
#include "outcrop.h"
#include "ocrt.h"

typedef struct run {
  const ocrt_options *opt;
  int status;   /* exit status, set by pmain */
  char *outdir; /* malloc'ed; freed after lua_close, so errors cannot leak */
  long long max_memory;       /* the limit in force, 0 for none */
  int warn_on, warn_cont;     /* warn(): "@on" seen; a message continues */
  char sha256[OC_SHA256_HEX]; /* of the scene's bytes, once loaded */
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

/* Registry settings read by the module (see oclua.h): --seed, --set and
** --out go through oclua_configure, as outcrop.configure would take them
** (the seed only when given, so that a scene may configure its own), then
** the sandbox flag, the scene and its hash. */
static void set_registry(lua_State *L, const run *r) {
  const ocrt_options *o = r->opt;
  int i;
  lua_createtable(L, 0, 3);
  if (o->nparams > 0) {
    lua_createtable(L, 0, o->nparams);
    for (i = 0; i < o->nparams; i++) {
      const char *p = o->params[i];
      const char *eq = strchr(p, '=');
      lua_pushlstring(L, p, (size_t)(eq - p));
      lua_pushstring(L, eq + 1);
      lua_rawset(L, -3); /* a repeated name: the last value wins */
    }
    lua_setfield(L, -2, "params");
  }
  if (o->seed >= 0) {
    lua_pushinteger(L, o->seed);
    lua_setfield(L, -2, "seed");
  }
  lua_pushstring(L, r->outdir);
  lua_setfield(L, -2, "out");
  oclua_configure(L, -1, "outcrop");
  lua_pop(L, 1);
  lua_pushboolean(L, !o->unsafe);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  lua_pushstring(L, o->scene);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE);
  lua_pushstring(L, r->sha256);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE_SHA256);
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

/* The scene as lua_load reads it, hashed on the way. As luaL_loadfilex
** does, a UTF-8 byte order mark and a first line starting with '#' are
** skipped (the newline stays, so line numbers hold; before a binary
** chunk it goes too). */
typedef struct scene_reader {
  FILE *f;
  oc_sha256 sha;
  int state; /* 0 at the start, 1 in a first-line comment, 2 past it */
  int err;   /* errno of a failed read */
  char buf[BUFSIZ];
} scene_reader;

static const char *read_scene(lua_State *L, void *ud, size_t *size) {
  scene_reader *r = ud;
  (void)L;
  for (;;) {
    size_t n = fread(r->buf, 1, sizeof r->buf, r->f);
    char *p = r->buf, *end = r->buf + n;
    if (n == 0) {
      if (ferror(r->f)) r->err = errno ? errno : EIO;
      *size = 0;
      return NULL;
    }
    oc_sha256_update(&r->sha, r->buf, n);
    if (r->state == 0) {
      if (n >= 3 && memcmp(p, "\xEF\xBB\xBF", 3) == 0) p += 3;
      r->state = p < end && *p == '#' ? 1 : 2;
    }
    if (r->state == 1) {
      char *nl = memchr(p, '\n', (size_t)(end - p));
      if (nl == NULL) continue; /* all comment so far */
      p = nl;
      r->state = 2;
      if (p + 1 < end && p[1] == LUA_SIGNATURE[0]) p++;
    }
    if (p < end) {
      *size = (size_t)(end - p);
      return p;
    }
  }
}

/* Loads the scene file (text only in the sandbox: Lua bytecode can be
** crafted to break out of the VM, and the scene is the first chunk an
** attacker controls) and sets r->sha256. Returns a load status; a
** refused binary chunk is reported as LUA_ERRFILE, a usage error rather
** than a bug in the scene. The chunk name is "@" .. path, so messages
** read "scene.lua:3: ...". */
static int load_scene(lua_State *L, run *r) {
  const ocrt_options *o = r->opt;
  int from_stdin = strcmp(o->scene, "-") == 0;
  const char *name = from_stdin ? "stdin" : o->scene;
  scene_reader *sr = lua_newuserdatauv(L, sizeof *sr, 0);
  const char *chunkname = from_stdin ? lua_pushliteral(L, "=stdin")
                                     : lua_pushfstring(L, "@%s", name);
  /* nothing raises between the open and the close */
  sr->f = from_stdin ? stdin : fopen(o->scene, "r");
  if (sr->f == NULL) {
    lua_pushfstring(L, "cannot open %s: %s", name, strerror(errno));
    return LUA_ERRFILE;
  }
  oc_sha256_init(&sr->sha);
  sr->state = 0;
  sr->err = 0;
  int st = lua_load(L, read_scene, sr, chunkname, o->unsafe ? NULL : "t");
  if (st == LUA_OK) { /* a binary chunk may end before the file */
    size_t n;
    while ((n = fread(sr->buf, 1, sizeof sr->buf, sr->f)) > 0)
      oc_sha256_update(&sr->sha, sr->buf, n);
    if (ferror(sr->f) && !sr->err) sr->err = errno ? errno : EIO;
  }
  if (!from_stdin) fclose(sr->f);
  int err = sr->err;
  if (st == LUA_OK && !err) {
    unsigned char d[OC_SHA256_BYTES];
    oc_sha256_final(&sr->sha, d);
    oc_sha256_hex(d, r->sha256);
  }
  lua_replace(L, -3); /* the chunk or the message, in the userdata's slot */
  lua_pop(L, 1);
  if (err) {
    lua_pop(L, 1);
    lua_pushfstring(L, "cannot read %s: %s", name, strerror(err));
    return LUA_ERRFILE;
  }
  if (st == LUA_ERRSYNTAX && !o->unsafe &&
      strstr(lua_tostring(L, -1), "attempt to load a binary chunk")) {
    lua_pop(L, 1);
    lua_pushfstring(L,
                    "%s: is a binary chunk (precompiled Lua); scenes must be "
                    "Lua source unless --unsafe is given",
                    name);
    return LUA_ERRFILE;
  }
  return st;
}

/* After a scene that ran to its end: a --set that nothing read is an
** error (a typo would otherwise be silently ignored and recorded as if
** applied). */
static void check_params(lua_State *L, run *r) {
  if (oclua_params_unread(L) > 0) {
    const char *msg = lua_tostring(L, -1);
    for (const char *nl; (nl = strchr(msg, '\n')) != NULL; msg = nl + 1)
      fprintf(stderr, "outcrop: %.*s\n", (int)(nl - msg), msg);
    fflush(stderr);
    r->status = OCRT_EUSAGE;
  }
  lua_pop(L, 1);
}

/* --list-params: the scene's standard output goes to /dev/null (its
** prints would mix with the list); returns the saved descriptor, or -1. */
static int mute_stdout(void) {
  fflush(stdout);
  int saved = fcntl(1, F_DUPFD_CLOEXEC, 3);
  int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (saved < 0 || null < 0 || dup2(null, 1) < 0) {
    if (saved >= 0) close(saved);
    saved = -1;
  }
  if (null >= 0) close(null);
  return saved;
}

static void unmute_stdout(int saved) {
  fflush(stdout);
  clearerr(stdout);
  if (saved < 0) return;
  dup2(saved, 1);
  close(saved);
}

static int pmain(lua_State *L) {
  run *r = lua_touserdata(L, 1);
  const ocrt_options *o = r->opt;
  char msg[512];
  int st;
  luaL_checkversion(L);
  lua_gc(L, LUA_GCSTOP);
  luaL_openlibs(L);
  st = load_scene(L, r);
  if (st == LUA_ERRMEM) return lua_error(L);
  if (st != LUA_OK) {
    report(lua_tostring(L, -1));
    r->status = st == LUA_ERRSYNTAX ? OCRT_ESCRIPT : OCRT_EUSAGE;
    return 0;
  }
  r->outdir = o->list_params ? ocrt_tmp_outdir(msg, sizeof msg)
                             : ocrt_outdir(o->outdir, msg, sizeof msg);
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
  if (o->list_params) {
    int saved = mute_stdout();
    run_scene(L, r);
    unmute_stdout(saved);
    if (saved < 0 && r->status == OCRT_OK) {
      report("--list-params: cannot set standard output aside");
      r->status = OCRT_ESCRIPT;
    }
  } else {
    run_scene(L, r);
  }
  if (r->status == OCRT_OK && ocrt_stop_status(L) == OCRT_RUN) {
    if (o->list_params) {
      oclua_params_list(L);
      fputs(lua_tostring(L, -1), stdout);
      lua_pop(L, 1);
    }
    check_params(L, r);
  }
  return 0;
}

static int panic(lua_State *L) {
  report(lua_tostring(L, -1));
  return 0; /* Lua then aborts */
}

int ocrt_run(const ocrt_options *o) {
  run r = {o, OCRT_ESCRIPT, NULL, o->max_memory, 0, 0, "(none)"};
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
  if (o->list_params && r.outdir) ocrt_remove_tree(r.outdir);
  free(r.outdir);
  return r.status;
}
