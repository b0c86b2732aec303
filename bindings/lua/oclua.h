/*
** oclua.h — what the Lua module shares with the `outcrop` interpreter.
**
** The interpreter preloads the module and, before running a scene, stores
** its settings in the Lua registry under the keys below. Under stock
** lua5.4 none is set: no parameters, outputs relative to the current
** directory, no write restriction.
*/
#ifndef OCLUA_H
#define OCLUA_H

#include <lua.h>

int luaopen_outcrop(lua_State *L);

/* table: name -> string value, from --set NAME=VALUE */
#define OCLUA_PARAMS "outcrop.params"
/* string: folder that relative output paths resolve against (--out) */
#define OCLUA_OUTDIR "outcrop.outdir"
/* boolean: true when writes must stay under OCLUA_OUTDIR (no --unsafe) */
#define OCLUA_SANDBOX "outcrop.sandbox"
/* integer: the scene seed (--seed), default 1; also outcrop.seed */
#define OCLUA_SEED "outcrop.seed"
/* string: the scene file as given on the command line ("-" for standard
** input); written into image metadata as provenance */
#define OCLUA_SCENE "outcrop.scene"

/* light userdata: address of a `volatile sig_atomic_t` the interpreter sets
** to non-zero on Ctrl-C, SIGTERM, SIGHUP and --timeout; long work polls it
** through its progress callback and stops (OC_ECANCEL), after which the
** binding raises "interrupted" (the interpreter reports the real cause) */
#define OCLUA_INTERRUPT "outcrop.interrupt"

/* Where an output file goes: a folder descriptor and a name in it. */
typedef struct oclua_target {
  int dir;          /* AT_FDCWD, or a folder descriptor owned by the value
                    ** oclua_output_target pushed */
  const char *name; /* relative to dir (kept alive by that value too) */
  const char *path; /* the path as the script gave it, for messages */
  int *owner;       /* internal: where the pushed value keeps dir */
} oclua_target;

/* oclua_output_target flags. */
#define OCLUA_TARGET_CREATE 1 /* create missing parent folders */
#define OCLUA_TARGET_LINK                                                      \
  2 /* the last component may be a symbolic link                               \
    ** (os.remove, os.rename act on the link) */

/* Resolves an output path given by a script, at the moment of the write
** (call it after any Lua callback that precedes the write). Always pushes
** one value that owns t's descriptor (closed when it is collected or by
** oclua_target_close).
**
** Outside the sandbox: a relative path is joined to OCLUA_OUTDIR (when
** set) and t->dir is AT_FDCWD. In sandbox mode (OCLUA_SANDBOX) the path
** is taken relative to the output folder, opened once per run (see
** oclua_outdir_fd), and the folders on the way are opened one by one with
** O_NOFOLLOW from that descriptor, so no rename or symlink made meanwhile
** can lead a write outside it; a path outside the folder ("..", absolute
** elsewhere) or through a symbolic link raises a Lua error naming
** `fname`. Returns 0, or an errno value (e.g. a parent is a file) with t
** naming the path only: report it with oclua_output_fail. */
int oclua_output_target(lua_State *L, const char *fname, const char *path,
                        int flags, oclua_target *t);

/* Closes t's descriptor now (the pushed value stays, harmless). */
void oclua_target_close(lua_State *L, oclua_target *t);

/* Opens the output folder of the run, if not open yet, and returns its
** descriptor (kept in the registry for the run, reopened if OCLUA_OUTDIR
** changes). Raises when the folder cannot be created or opened. */
int oclua_outdir_fd(lua_State *L, const char *fname);

/* Pushes fail and "<t->path>: <reason>", where the reason is `msg` less a
** leading "cannot write '<t->name>': " from the library; returns 2. */
int oclua_output_fail(lua_State *L, const oclua_target *t, const char *msg);

#endif
