/*
** runner.c — one scene in one sandboxed Lua state, as the interpreter
** runs it (runtime/run.c: module loaded, sandbox applied, writes under
** the output folder), plus the limits a fuzzer needs so that no input can
** hang or exhaust the machine: a cap on the Lua heap and an instruction
** budget enforced by a count hook. Work done in C by the engine is kept
** small by the generator instead. Also the folders scenes write to, and
** the check after each scene that no write left its temporary file or
** landed beside the output folder.
*/
#define _XOPEN_SOURCE 700
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sys/stat.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lualib.h>

#include "../../bindings/lua/oclua.h"
#include "../../runtime/ocrt.h"
#include "runner.h"

#define HOOK_EVERY 1000 /* instructions between two budget checks */

typedef struct state {
  const ocfz_limits *lim;
  size_t used;
  long steps; /* hook calls so far */
  const char *scene;
  size_t len;
  const char *outdir;
} state;

static void *capped_alloc(void *ud, void *p, size_t osize, size_t nsize) {
  state *s = ud;
  if (p == NULL) osize = 0; /* osize then holds a type tag */
  if (nsize > osize && s->lim->max_bytes &&
      nsize - osize > s->lim->max_bytes - s->used)
    return NULL;
  if (s->lim->alloc) {
    void *q = s->lim->alloc(s->lim->alloc_ud, p, osize, nsize);
    if (q != NULL || nsize == 0) s->used = s->used - osize + nsize;
    return q;
  }
  if (nsize == 0) {
    free(p);
    s->used -= osize;
    return NULL;
  }
  p = realloc(p, nsize);
  if (p != NULL) s->used = s->used - osize + nsize;
  return p;
}

/* Raises once the budget is spent, and at every check after that, so a
** scene that catches the error with pcall cannot go on. */
static void budget_hook(lua_State *L, lua_Debug *ar) {
  void *ud;
  state *s;
  (void)ar;
  lua_getallocf(L, &ud);
  s = ud;
  if (++s->steps > s->lim->max_steps)
    luaL_error(L, "fuzz: instruction budget spent");
}

static int pmain(lua_State *L) {
  state *s = lua_touserdata(L, 1);
  /* ocrt_stop_arm is not called: it would take over SIGALRM and SIGINT,
  ** which libFuzzer uses for its own timeouts and stops */
  lua_gc(L, LUA_GCSTOP);
  luaL_openlibs(L);
  lua_newtable(L);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS);
  lua_pushstring(L, s->outdir);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR);
  lua_pushboolean(L, 1);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  lua_pushinteger(L, 1);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SEED);
  lua_pushliteral(L, "fuzz");
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE);
  luaL_requiref(L, "outcrop", luaopen_outcrop, 0);
  lua_setglobal(L, "outcrop");
  ocrt_sandbox(L);
  ocrt_stop_open(L);
  lua_pushstring(L, s->outdir);
  lua_setglobal(L, "OUT");
  lua_gc(L, LUA_GCRESTART);
  lua_gc(L, LUA_GCGEN, 0, 0);
  if (luaL_loadbufferx(L, s->scene, s->len, "=fuzz", "t") != LUA_OK)
    return lua_error(L);
  if (s->lim->start) s->lim->start(s->lim->alloc_ud);
  if (s->lim->max_steps > 0)
    lua_sethook(L, budget_hook, LUA_MASKCOUNT, HOOK_EVERY);
  lua_call(L, 0, 0);
  return 0;
}

int ocfz_run(const char *scene, size_t len, const char *outdir,
             const ocfz_limits *lim, char *msg, size_t msgsize) {
  state s = {lim, 0, 0, scene, len, outdir};
  lua_State *L = lua_newstate(capped_alloc, &s);
  int st;
  if (msgsize) msg[0] = '\0';
  if (L == NULL) {
    snprintf(msg, msgsize, "cannot create the state: not enough memory");
    return LUA_ERRMEM;
  }
  lua_pushcfunction(L, pmain);
  lua_pushlightuserdata(L, &s);
  st = lua_pcall(L, 1, 0, 0);
  if (lim->stop) lim->stop(lim->alloc_ud);
  ocrt_stop_finish(L);
  if (st != LUA_OK) {
    const char *m = lua_tostring(L, -1);
    snprintf(msg, msgsize, "%s", m ? m : "(error object is not a string)");
  }
  lua_close(L);
  return st;
}

/* Removes what `dir` holds, depth first (not `dir` itself). Notes in msg
** the first entry that is a temporary file, or (`only` non-NULL) the
** first top-level entry not named `only`. Returns 1 when none was. */
static int sweep(const char *dir, const char *only, char *msg, size_t msgsize) {
  DIR *d = opendir(dir);
  struct dirent *e;
  int ok = 1;
  if (d == NULL) return 1;
  while ((e = readdir(d)) != NULL) {
    char path[4096];
    struct stat sb;
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    int bad = strstr(e->d_name, ".tmp-") != NULL ||
              (only != NULL && strcmp(e->d_name, only) != 0);
    if (bad && ok) snprintf(msg, msgsize, "%s", path);
    ok &= !bad;
    if (lstat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
      char sub[256];
      if (!sweep(path, NULL, sub, sizeof sub) && ok) {
        snprintf(msg, msgsize, "%s", sub);
        ok = 0;
      }
      if (only == NULL || strcmp(e->d_name, only) != 0) rmdir(path);
    } else {
      unlink(path);
    }
  }
  closedir(d);
  return ok;
}

int ocfz_dirs_open(ocfz_dirs *d, const char *prefix) {
  snprintf(d->base, sizeof d->base, "/tmp/%s.XXXXXX", prefix);
  if (mkdtemp(d->base) == NULL) return -1;
  snprintf(d->out, sizeof d->out, "%s/out", d->base);
  return mkdir(d->out, 0777);
}

int ocfz_dirs_check(ocfz_dirs *d, char *msg, size_t msgsize) {
  int ok = sweep(d->base, "out", msg, msgsize);
  mkdir(d->out, 0777); /* in case the scene removed it */
  return ok;
}

void ocfz_dirs_close(ocfz_dirs *d) {
  char msg[8];
  sweep(d->base, NULL, msg, sizeof msg);
  rmdir(d->base);
}
