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

/* table: name -> value (a --set string, or a Lua string, number or
** boolean given to outcrop.configure) */
#define OCLUA_PARAMS "outcrop.params"
/* string: folder that relative output paths resolve against (--out, or
** outcrop.configure's out, made absolute) */
#define OCLUA_OUTDIR "outcrop.outdir"
/* boolean: true when writes must stay under OCLUA_OUTDIR (no --unsafe) */
#define OCLUA_SANDBOX "outcrop.sandbox"
/* integer: the scene seed (--seed or configure's seed), default 1; also
** outcrop.seed */
#define OCLUA_SEED "outcrop.seed"
/* string: the scene file as given on the command line ("-" for standard
** input); written into image metadata as provenance */
#define OCLUA_SCENE "outcrop.scene"
/* string: the SHA-256 (hex) of the scene's bytes as the interpreter
** loaded them; without it the file named by the scene is hashed */
#define OCLUA_SCENE_SHA256 "outcrop.scene_sha256"
/* table kept by the module (l_config.c): what configure fixed, what
** outcrop.param read, the input files read, whether outputs were
** written. Hosts leave it alone (tests reset it by setting it to nil). */
#define OCLUA_STATE "outcrop.state"

/* outcrop.configure{seed =, params =, out =} on the table at idx: checks
** every field (raising errors prefixed with fname), refuses what
** conflicts with the configuration so far, then stores the values under
** OCLUA_SEED, OCLUA_PARAMS and OCLUA_OUTDIR. The interpreter configures
** --seed, --set and --out through it, before the sandbox is applied. */
void oclua_configure(lua_State *L, int idx, const char *fname);

/* Pushes the lines (each ending in a newline) naming the configured
** parameters no outcrop.param call read, with the closest name that was
** read when one is close: "--set stpes: no outcrop.param reads it (did
** you mean 'steps'?)". Returns their count (0: an empty string). */
int oclua_params_unread(lua_State *L);

/* Pushes one line per parameter outcrop.param read, in the order of the
** first reads: "NAME<tab>DEFAULT<tab>TYPE", the default as --set would
** spell it ("nil" when none) and its type (integer, number, string,
** boolean, nil). */
void oclua_params_list(lua_State *L);

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
