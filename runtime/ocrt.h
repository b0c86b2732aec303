/*
** ocrt.h — what the files of the `outcrop` interpreter share: the parsed
** command line, the exit statuses, and the entry point of each part.
*/
#ifndef OCRT_H
#define OCRT_H

#include <stddef.h>

#include <lua.h>

/* Exit statuses of the interpreter (an os.exit in a scene adds its own). */
enum {
  OCRT_OK = 0,
  OCRT_ESCRIPT = 1,    /* the scene failed: syntax or runtime error */
  OCRT_EUSAGE = 2,     /* bad command line, unreadable scene, bad --out */
  OCRT_ETIMEOUT = 124, /* --timeout reached, as timeout(1) reports it */
  OCRT_ESIGNAL = 128   /* stopped by signal N (SIGINT, SIGTERM, SIGHUP,
                       ** SIGPIPE):
                       ** 128 + N, as shells report a death by signal */
};

/* The command line once parsed. Strings point into argv. */
typedef struct ocrt_options {
  const char *scene;   /* path as given; "-" reads standard input */
  const char **params; /* "NAME=VALUE" strings, in command-line order */
  int nparams;
  const char **args; /* positional arguments after the scene */
  int nargs;
  lua_Integer seed;         /* --seed, -1 when not given (the scene seed
                            ** is then 1 unless the scene configures it) */
  int threads;              /* --threads, 0 when not given */
  const char *outdir;       /* --out, NULL for the current folder */
  int unsafe;               /* --unsafe: no sandbox */
  int list_params;          /* --list-params: list, write nothing */
  long long max_memory;     /* --max-memory in bytes; 0 none, -1 the default */
  double timeout;           /* --timeout in seconds, 0 for none */
  const char *timeout_text; /* --timeout as given, for the message */
} ocrt_options;

/* What ocrt_parse decided: run the scene, or stop with a status. */
enum { OCRT_RUN = -1 };

/* Fills `o` from argv. Returns OCRT_RUN, or an exit status after having
** printed help, the version, or a usage error. On OCRT_RUN the caller
** frees the arrays with ocrt_options_free. */
int ocrt_parse(ocrt_options *o, int argc, char **argv);
void ocrt_options_free(ocrt_options *o);

/* Creates `dir` (NULL: the current folder) and its missing parents, as
** mkdir -p, and returns its canonical absolute path, malloc'ed. On failure
** returns NULL with a message in `msg`. */
char *ocrt_outdir(const char *dir, char *msg, size_t msgsize);

/* A new empty folder under $TMPDIR (else /tmp) for --list-params, as
** ocrt_outdir returns it; ocrt_remove_tree removes it and all it holds
** (symbolic links themselves, never what they point to). */
char *ocrt_tmp_outdir(char *msg, size_t msgsize);
void ocrt_remove_tree(const char *dir);

/* Runs the scene described by `o` in a fresh Lua state; returns the exit
** status. */
int ocrt_run(const ocrt_options *o);

/* Restricts the standard libraries of L to the scene sandbox. The module
** must already be loaded (writes go through oclua_output_target). */
void ocrt_sandbox(lua_State *L);

/* Stopping a running scene (stop.c). ocrt_stop_open prepares L (once,
** before the scene runs: wraps coroutine.resume, .wrap, .close, xpcall and
** setmetatable); ocrt_stop_arm makes Ctrl-C, SIGTERM, SIGHUP, SIGPIPE and,
** when `timeout` > 0, a timer after that many seconds (written
** `timeout_text` on the command line) stop the scene running in L (by
** raising an error from a count hook, and again at every Lua instruction
** until control is back in C); ocrt_stop_finish, once the scene returned,
** makes sure no script code runs after a stop (not even finalizers in
** lua_close); ocrt_stop_release, after lua_close, restores the signals
** and cancels the timer. ocrt_stop_request does the same as a signal
** from inside the state (os.exit in the sandbox) with the exit status to
** report. */
void ocrt_stop_open(lua_State *L);
void ocrt_stop_arm(lua_State *L, double timeout, const char *timeout_text);
void ocrt_stop_finish(lua_State *L);
void ocrt_stop_release(void);
int ocrt_stop_request(lua_State *L, int status);
/* The status requested with ocrt_stop_request, or OCRT_RUN if none. */
int ocrt_stop_status(lua_State *L);
/* What stopped the scene: 0 nothing (or os.exit), the signal number, or
** OCRT_STOP_TIMEOUT. */
enum { OCRT_STOP_TIMEOUT = -1 };
int ocrt_stop_cause(void);
/* The message for a cause: "interrupted", "terminated", "timeout"... */
const char *ocrt_stop_text(int cause);
/* Non-zero once any stop began (signal, timeout, os.exit). */
int ocrt_stopping(void);

/* --max-memory (memory.c). The Lua allocator to give lua_newstate; every
** allocation of the engine and the bindings is counted with it. */
void *ocrt_lua_alloc(void *ud, void *p, size_t osize, size_t nsize);
/* Sets the limit in bytes (0: none) and clears the exhausted flag. */
void ocrt_memory_limit(long long bytes);
/* Non-zero when an allocation was refused since the limit was set. */
int ocrt_memory_exhausted(void);
/* The default limit of sandboxed scenes: half of the physical memory. */
long long ocrt_memory_default(void);
/* Writes `bytes` for messages: "512 MiB", "3 GiB", "1000 bytes". */
void ocrt_memory_text(long long bytes, char *buf, size_t size);

#endif
