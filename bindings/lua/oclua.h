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

/* Resolves an output path given by a script: a relative path is joined to
** OCLUA_OUTDIR (when set); in sandbox mode a path that would land outside
** OCLUA_OUTDIR (absolute elsewhere, or escaping with "..", or through a
** symlink) raises a Lua error naming `fname`. Pushes the resolved path and
** returns it. Missing parent folders under the output folder are created. */
const char *oclua_output_path(lua_State *L, const char *fname,
                              const char *path);

#endif
