/*
** l_path.c — oclua_output_path: where a script's output file really goes.
**
** Relative paths land in the output folder (registry OCLUA_OUTDIR). In
** sandbox mode (OCLUA_SANDBOX) the path is normalised, its existing
** folders are resolved through realpath (so a symlink cannot lead out),
** and anything that ends outside the output folder raises. The checked
** path is the one returned, so what was checked is what gets written.
*/
#define _XOPEN_SOURCE 700 /* realpath */

#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "l_util.h"

/* Lexically removes "", "." and ".." components of an absolute path, in
** place. ".." at the root stays at the root, as the kernel does. */
static void normalize(char *p) {
  char *out = p, *in = p;
  while (*in) {
    char *seg;
    size_t n;
    while (*in == '/')
      in++;
    seg = in;
    while (*in && *in != '/')
      in++;
    n = (size_t)(in - seg);
    if (n == 0 || (n == 1 && seg[0] == '.')) continue;
    if (n == 2 && seg[0] == '.' && seg[1] == '.') {
      while (out > p && *--out != '/') {
      }
      continue;
    }
    *out++ = '/';
    memmove(out, seg, n);
    out += n;
  }
  if (out == p) *out++ = '/';
  *out = '\0';
}

/* Creates the missing folders of p's parent, starting after `from`
** characters (a prefix known to exist). Failures are left for the writer
** to report as an ordinary write error. */
static void make_parents(char *p, size_t from) {
  char *slash = p + from;
  while ((slash = strchr(slash + 1, '/')) != NULL) {
    *slash = '\0';
    if (mkdir(p, 0777) != 0 && errno != EEXIST) {
      *slash = '/';
      return;
    }
    *slash = '/';
  }
}

static int is_under(const char *p, const char *dir) {
  size_t n = strlen(dir);
  if (n == 1 && dir[0] == '/') return p[0] == '/' && p[1] != '\0';
  return strncmp(p, dir, n) == 0 && p[n] == '/' && p[n + 1] != '\0';
}

/* Pushes a Lua-owned, writable copy of s. */
static char *pushbuf(lua_State *L, const char *s) {
  size_t n = strlen(s);
  char *p = lua_newuserdatauv(L, n + 2, 0);
  memcpy(p, s, n + 1);
  return p;
}

/* Pushes an absolute, normalised copy of `path` (relative to `base`). */
static char *absolute(lua_State *L, const char *base, const char *path) {
  char *p;
  if (path[0] == '/') return (p = pushbuf(L, path)), normalize(p), p;
  lua_pushfstring(L, "%s/%s", base, path);
  p = pushbuf(L, lua_tostring(L, -1));
  lua_remove(L, -2);
  normalize(p);
  return p;
}

/* Replaces the longest existing folder prefix of p by its real path and
** pushes the result as a writable buffer; *known is the length of the
** part that exists. Returns NULL (nothing pushed) if realpath fails. */
static char *resolve(lua_State *L, char *p, size_t *known) {
  char *slash = strrchr(p, '/');
  for (;;) {
    struct stat st;
    char *prev, *out, real[PATH_MAX];
    if (slash == p) {
      *known = 0;
      return pushbuf(L, p);
    }
    *slash = '\0';
    if (stat(p, &st) == 0) {
      /* into a buffer of ours: pushing may raise a memory error */
      char *ok = realpath(p, real);
      *slash = '/';
      if (ok == NULL) return NULL;
      if (strcmp(real, "/") == 0) real[0] = '\0';
      *known = strlen(real);
      out = lua_newuserdatauv(L, *known + strlen(slash) + 2, 0);
      memcpy(out, real, *known);
      strcpy(out + *known, slash);
      return out;
    }
    prev = slash;
    slash = strrchr(p, '/');
    *prev = '/';
  }
}

static int outside(lua_State *L, const char *fname, const char *path,
                   const char *outdir) {
  return oclua_error(L, fname,
                     "'%s' is outside the output folder '%s' "
                     "(sandbox: write under the output folder, or run with "
                     "--unsafe)",
                     path, outdir);
}

/* Pushes the checked path. */
static void sandboxed(lua_State *L, const char *fname, const char *outdir,
                      const char *path) {
  struct stat st;
  size_t known = 0;
  char *real, *full, dir[PATH_MAX];
  const char *base;
  /* The output folder itself may not exist before the first write. */
  make_parents(pushbuf(L, outdir), 0);
  mkdir(outdir, 0777);
  lua_pop(L, 1);
  if (realpath(outdir, dir) == NULL)
    oclua_error(L, fname, "the output folder '%s' is not usable: %s", outdir,
                strerror(errno));
  base = lua_pushstring(L, dir);
  full = resolve(L, absolute(L, base, path), &known);
  if (full == NULL || !is_under(full, base)) outside(L, fname, path, outdir);
  if (lstat(full, &st) == 0 && S_ISLNK(st.st_mode)) {
    /* An existing link in place of the file must point inside too. */
    int ok;
    real = realpath(full, NULL);
    ok = real != NULL && is_under(real, base);
    free(real);
    if (!ok) outside(L, fname, path, outdir);
  }
  make_parents(full, known);
  lua_pushstring(L, full);
}

const char *oclua_output_path(lua_State *L, const char *fname,
                              const char *path) {
  const char *outdir = NULL;
  int top = lua_gettop(L), sandbox;
  if (path == NULL || path[0] == '\0')
    oclua_error(L, fname, "the output path is empty");
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR) == LUA_TSTRING)
    outdir = lua_tostring(L, -1);
  lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  sandbox = lua_toboolean(L, -1);
  if (sandbox) {
    sandboxed(L, fname, outdir ? outdir : ".", path);
  } else if (outdir == NULL || path[0] == '/') {
    lua_pushstring(L, path);
  } else {
    char *p = pushbuf(L, lua_pushfstring(L, "%s/%s", outdir, path));
    /* Folders are created only under the output folder. */
    make_parents(p, 0);
    lua_pop(L, 1);
  }
  /* Keep only the result; the strings it came from may now be collected. */
  lua_replace(L, top + 1);
  lua_settop(L, top + 1);
  return lua_tostring(L, -1);
}
