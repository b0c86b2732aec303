/*
** l_path.c — oclua_output_target: where a script's output file really
** goes, resolved when the write starts.
**
** Outside the sandbox, relative paths land in the output folder (registry
** OCLUA_OUTDIR) and are written by name. In sandbox mode (OCLUA_SANDBOX)
** names are never looked up from the root again: the output folder is
** opened once per run, the path is made relative to it (lexically: ".."
** may not climb out), and each folder on the way is opened with
** openat(O_DIRECTORY | O_NOFOLLOW) from the one before, created when
** missing. A symbolic link on the way is refused, so a Lua callback that
** renames folders or swaps one for a link between a check and the write
** cannot send the file elsewhere: the writer creates its temporary file
** and renames it inside the descriptor of the final folder.
*/
#define _XOPEN_SOURCE 700 /* realpath, openat, mkdirat */

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "l_util.h"

#define HANDLE "outcrop.dirhandle"    /* metatable of descriptor owners */
#define OUTDIR_FD "outcrop.outdir.fd" /* registry: the output folder's */

/* ---- descriptors owned by Lua values ------------------------------------ */

static int handle_close(lua_State *L) {
  int *fd = luaL_checkudata(L, 1, HANDLE);
  if (*fd >= 0) close(*fd);
  *fd = -1;
  return 0;
}

/* Pushes a new owner of a descriptor (-1 for now), with `nuv` user
** values. */
static int *new_handle(lua_State *L, int nuv) {
  int *fd = lua_newuserdatauv(L, sizeof *fd, nuv);
  *fd = -1;
  if (luaL_newmetatable(L, HANDLE)) {
    lua_pushcfunction(L, handle_close);
    lua_setfield(L, -2, "__gc");
    lua_pushboolean(L, 0);
    lua_setfield(L, -2, "__metatable");
  }
  lua_setmetatable(L, -2);
  return fd;
}

void oclua_target_close(lua_State *L, oclua_target *t) {
  (void)L;
  if (t->owner && *t->owner >= 0) {
    close(*t->owner);
    *t->owner = -1;
  }
  t->dir = -1;
}

/* ---- paths -----------------------------------------------------------------
 */

/* Lexically removes "", "." and ".." components of the path after its
** leading '/', in place. Returns -1 when ".." would climb above the
** start; then p is garbage. */
static int normalize(char *p) {
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
      if (out == p) return -1;
      while (out > p && *--out != '/') {
      }
      continue;
    }
    *out++ = '/';
    memmove(out, seg, n);
    out += n;
  }
  *out = '\0';
  return 0;
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

/* Pushes a Lua-owned, writable copy of s. */
static char *pushbuf(lua_State *L, const char *s) {
  size_t n = strlen(s);
  char *p = lua_newuserdatauv(L, n + 2, 0);
  memcpy(p, s, n + 1);
  return p;
}

static int is_under(const char *p, const char *dir) {
  size_t n = strlen(dir);
  if (n == 1 && dir[0] == '/') return p[0] == '/' && p[1] != '\0';
  return strncmp(p, dir, n) == 0 && p[n] == '/' && p[n + 1] != '\0';
}

static int outside(lua_State *L, const char *fname, const char *path,
                   const char *outdir, const char *why) {
  return oclua_error(L, fname,
                     "'%s' is outside the output folder '%s'%s (sandbox: "
                     "write under the output folder, or run with --unsafe)",
                     path, outdir, why);
}

/* ---- the output folder
 * ------------------------------------------------------- */

int oclua_outdir_fd(lua_State *L, const char *fname) {
  const char *outdir = ".";
  int *fd;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR) == LUA_TSTRING)
    outdir = lua_tostring(L, -1);
  if (lua_getfield(L, LUA_REGISTRYINDEX, OUTDIR_FD) == LUA_TUSERDATA) {
    lua_getiuservalue(L, -1, 1);
    fd = lua_touserdata(L, -2);
    if (*fd >= 0 && strcmp(lua_tostring(L, -1), outdir) == 0) {
      lua_pop(L, 3);
      return *fd;
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  /* The interpreter creates and canonicalizes --out; under stock lua5.4
  ** the folder may not exist before the first write. */
  make_parents(pushbuf(L, outdir), 0);
  mkdir(outdir, 0777);
  lua_pop(L, 1);
  fd = new_handle(L, 2);
  *fd = open(outdir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  /* real paths go into buffers of ours: pushing may raise a memory error,
  ** which would leak realpath's own */
  char real[PATH_MAX];
  if (*fd < 0 || realpath(outdir, real) == NULL)
    oclua_error(L, fname, "the output folder '%s' is not usable: %s", outdir,
                strerror(errno));
  lua_pushstring(L, outdir);
  lua_setiuservalue(L, -2, 1);
  lua_pushstring(L, real);
  lua_setiuservalue(L, -2, 2);
  lua_setfield(L, LUA_REGISTRYINDEX, OUTDIR_FD);
  lua_pop(L, 1); /* OCLUA_OUTDIR */
  return *fd;
}

/* Pushes `path` relative to the output folder `real` (its real path),
** normalized, or raises. Absolute paths are taken lexically, or else
** through the real path of their longest existing folder (the output
** folder spelled through a symlink). */
static char *relative(lua_State *L, const char *fname, const char *path,
                      const char *real) {
  char *p;
  if (path[0] != '/') {
    lua_pushfstring(L, "/%s", path);
    p = pushbuf(L, lua_tostring(L, -1));
    lua_remove(L, -2);
    if (normalize(p) != 0) outside(L, fname, path, real, "");
    if (p[0] == '\0')
      oclua_error(L, fname, "'%s' names the output folder, not a file", path);
    return p + 1;
  }
  p = pushbuf(L, path);
  if (normalize(p) != 0) outside(L, fname, path, real, "");
  if (is_under(p, real)) return p + strlen(real) + 1;
  char *slash = strrchr(p, '/');
  while (slash && slash != p) {
    *slash = '\0';
    char r[PATH_MAX];
    char *ok = realpath(p, r);
    *slash = '/';
    if (ok) {
      lua_pushfstring(L, "%s%s", r, slash);
      char *c = pushbuf(L, lua_tostring(L, -1));
      lua_remove(L, -2);
      if (normalize(c) == 0 && is_under(c, real)) return c + strlen(real) + 1;
      break;
    }
    char *at = slash; /* look one folder up */
    *at = '\0';
    slash = strrchr(p, '/');
    *at = '/';
  }
  outside(L, fname, path, real, "");
  return NULL;
}

int oclua_output_target(lua_State *L, const char *fname, const char *path,
                        int flags, oclua_target *t) {
  int top = lua_gettop(L), sandbox, *fd;
  const char *outdir = NULL;
  if (path == NULL || path[0] == '\0')
    oclua_error(L, fname, "the output path is empty");
  t->path = path;
  t->owner = NULL;
  t->dir = AT_FDCWD;
  lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  sandbox = lua_toboolean(L, -1);
  lua_pop(L, 1);
  if (!sandbox) {
    if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR) == LUA_TSTRING)
      outdir = lua_tostring(L, -1);
    if (outdir == NULL || path[0] == '/') {
      lua_pushstring(L, path);
    } else {
      char *p = pushbuf(L, lua_pushfstring(L, "%s/%s", outdir, path));
      /* Folders are created only under the output folder. */
      if (flags & OCLUA_TARGET_CREATE) make_parents(p, 0);
      lua_pop(L, 1);
    }
    lua_replace(L, top + 1);
    lua_settop(L, top + 1);
    t->name = lua_tostring(L, -1);
    return 0;
  }

  int base = oclua_outdir_fd(L, fname);
  lua_getfield(L, LUA_REGISTRYINDEX, OUTDIR_FD);
  lua_getiuservalue(L, -1, 2);
  const char *real = lua_tostring(L, -1);
  char *rel = relative(L, fname, path, real);
  /* the owner goes to top + 1, then the walk */
  fd = new_handle(L, 1);
  lua_pushvalue(L, -2);
  lua_setiuservalue(L, -2, 1); /* keeps rel alive */
  lua_replace(L, top + 1);
  t->owner = fd;
  *fd = fcntl(base, F_DUPFD_CLOEXEC, 0);
  if (*fd < 0) {
    lua_settop(L, top + 1);
    t->name = rel;
    return errno;
  }
  for (char *slash; (slash = strchr(rel, '/')) != NULL; rel = slash + 1) {
    *slash = '\0';
    int next =
        openat(*fd, rel, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (next < 0 && errno == ENOENT && (flags & OCLUA_TARGET_CREATE) &&
        (mkdirat(*fd, rel, 0777) == 0 || errno == EEXIST))
      next = openat(*fd, rel, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    int e = errno;
    struct stat st;
    if (next < 0 && fstatat(*fd, rel, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
        S_ISLNK(st.st_mode))
      outside(L, fname, path, real,
              lua_pushfstring(L, ": '%s' is a symbolic link", rel));
    *slash = '/';
    if (next < 0) {
      lua_settop(L, top + 1);
      t->name = rel;
      return e;
    }
    close(*fd);
    *fd = next;
  }
  struct stat st;
  if (!(flags & OCLUA_TARGET_LINK) &&
      fstatat(*fd, rel, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode))
    outside(L, fname, path, real, ": it is a symbolic link");
  if (rel[0] == '\0') outside(L, fname, path, real, ": it names a folder");
  lua_settop(L, top + 1);
  t->dir = *fd;
  t->name = rel;
  return 0;
}

int oclua_output_fail(lua_State *L, const oclua_target *t, const char *msg) {
  size_t n = strlen(t->name);
  if (strncmp(msg, "cannot write '", 14) == 0 &&
      strncmp(msg + 14, t->name, n) == 0 &&
      strncmp(msg + 14 + n, "': ", 3) == 0)
    msg += 14 + n + 3;
  luaL_pushfail(L);
  lua_pushfstring(L, "%s: %s", t->path, msg);
  return 2;
}
