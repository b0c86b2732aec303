/*
** ocrt.h — what the files of the `outcrop` interpreter share: the parsed
** command line, the exit statuses, and the entry point of each part.
*/
#ifndef OCRT_H
#define OCRT_H

#include <lua.h>

/* Exit statuses of the interpreter (an os.exit in a scene adds its own). */
enum {
  OCRT_OK = 0,
  OCRT_ESCRIPT = 1, /* the scene failed: syntax or runtime error */
  OCRT_EUSAGE = 2,  /* bad command line, unreadable scene, bad --out */
  OCRT_EINTR = 130  /* stopped by Ctrl-C, as shells report SIGINT */
};

/* The command line once parsed. Strings point into argv. */
typedef struct ocrt_options {
  const char *scene;   /* path as given; "-" reads standard input */
  const char **params; /* "NAME=VALUE" strings, in command-line order */
  int nparams;
  const char **args; /* positional arguments after the scene */
  int nargs;
  lua_Integer seed;   /* --seed, default 1 */
  int threads;        /* --threads, 0 when not given */
  const char *outdir; /* --out, NULL for the current folder */
  int unsafe;         /* --unsafe: no sandbox */
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

/* Runs the scene described by `o` in a fresh Lua state; returns the exit
** status. */
int ocrt_run(const ocrt_options *o);

/* Restricts the standard libraries of L to the scene sandbox. The module
** must already be loaded (writes go through oclua_output_target). */
void ocrt_sandbox(lua_State *L);

/* Stopping a running scene. ocrt_stop_open prepares L (once, before the
** scene runs); ocrt_stop_arm makes Ctrl-C stop the scene running in L (by
** raising an error from a count hook, and again at every Lua instruction
** until control is back in C); ocrt_stop_disarm undoes it. ocrt_stop_request
*does the same from inside the state (os.exit in
** the sandbox) with the exit status to report. */
void ocrt_stop_open(lua_State *L); /* wraps coroutine.resume and .wrap */
void ocrt_stop_arm(lua_State *L);
void ocrt_stop_disarm(lua_State *L);
int ocrt_stop_request(lua_State *L, int status);
/* The status requested with ocrt_stop_request, or OCRT_RUN if none. */
int ocrt_stop_status(lua_State *L);
int ocrt_interrupted(void);

#endif
