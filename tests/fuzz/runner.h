/*
** runner.h — runs one scene in a fresh, sandboxed Lua state with limits,
** in-process: the fuzz target, the corpus replayer and the
** allocation-failure harness share it.
*/
#ifndef OCFZ_RUNNER_H
#define OCFZ_RUNNER_H

#include <stddef.h>

#include <lua.h>

typedef struct ocfz_limits {
  size_t max_bytes;        /* Lua heap cap; 0: none */
  long max_steps;          /* Lua instructions, in thousands; 0: none */
  lua_Alloc alloc;         /* NULL: the runner's capped allocator */
  void *alloc_ud;          /* passed to `alloc`, `start` and `stop` */
  void (*start)(void *ud); /* called just before the scene runs, or NULL */
  void (*stop)(void *ud);  /* called once it returned or failed, before
                              the state is closed, or NULL */
} ocfz_limits;

/* Runs `scene` (Lua text, chunk name "=fuzz") with `outdir` as the
** output folder (it must exist; the scene sees it as the global OUT).
** Returns LUA_OK, or the status of the failed call with its message
** copied into msg. A failed state creation returns LUA_ERRMEM. */
int ocfz_run(const char *scene, size_t len, const char *outdir,
             const ocfz_limits *lim, char *msg, size_t msgsize);

/* Where scenes write: a new temporary folder `base` holding the output
** folder `out` (what the scene sees as OUT) and nothing else. */
typedef struct ocfz_dirs {
  char base[64];
  char out[72];
} ocfz_dirs;

/* Creates the folders (base named after `prefix`). Returns 0, or -1 with
** errno set. */
int ocfz_dirs_open(ocfz_dirs *d, const char *prefix);

/* Checks what the last scene left, then empties `out` and anything beside
** it: a temporary file of an atomic write (".tmp-" in its name) is a
** write that left its temporary behind, anything beside `out` a write
** outside the output folder. Returns 1 when all was well, else 0 with
** the first offending path in msg. */
int ocfz_dirs_check(ocfz_dirs *d, char *msg, size_t msgsize);

/* Removes the folders. */
void ocfz_dirs_close(ocfz_dirs *d);

#endif
