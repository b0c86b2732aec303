/*
** options.c — the command line of `outcrop`: parsing, help and version.
**
**   outcrop [run] [options] SCENE.lua [options] [args...]
**
** Options may come before or after the scene; the first word that is not
** an option is the scene (a leading "run" is the command word and is
** skipped), further words go to the scene's `arg` table. "--" ends the
** options. Every option taking a value accepts "--opt VALUE" and
** "--opt=VALUE".
*/
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <lauxlib.h>

#include "outcrop.h"
#include "ocrt.h"

/* A thread count beyond this is a typo, not a machine. */
#define MAX_THREADS 1024

static const char usage_text[] =
    "usage: outcrop [run] [options] SCENE.lua [options] [args...]\n"
    "\n"
    "Runs a scene script. SCENE.lua may be '-' for standard input; args\n"
    "after the scene reach it as arg[1], arg[2]... (arg[0] is the scene).\n"
    "Options may come before or after the scene; '--opt=VALUE' is the\n"
    "same as '--opt VALUE'.\n"
    "\n"
    "options:\n"
    "  --set NAME=VALUE  scene parameter, read with outcrop.param "
    "(repeatable;\n"
    "                    the last value of a name wins)\n"
    "  --seed N          scene seed, an integer >= 0 (default 1)\n"
    "  --list-params     run the scene with its outputs sent to a temporary\n"
    "                    folder that is removed, its standard output\n"
    "                    discarded, then print every parameter it reads:\n"
    "                    NAME<tab>DEFAULT<tab>TYPE (sandboxed: not with\n"
    "                    --unsafe)\n"
    "  --threads N       worker threads, 1 to 1024 (default: OpenMP's, all\n"
    "                    cores unless OMP_NUM_THREADS says otherwise)\n"
    "  --out DIR         folder for outputs; relative output paths resolve\n"
    "                    against it (default: the current folder; created\n"
    "                    if missing)\n"
    "  --max-memory SIZE memory for the scene, Lua and engine together, in\n"
    "                    bytes or with a suffix K, M, G, T (powers of 1024:\n"
    "                    512M, 2G); 0 for no limit (default: half of the\n"
    "                    physical memory; no limit with --unsafe)\n"
    "  --timeout SECONDS stop the scene after this wall-clock time (decimals\n"
    "                    allowed; default and 0: no limit); one stuck in C\n"
    "                    code is ended 10 s later\n"
    "  --unsafe          lift the sandbox: allow os.execute, io.popen,\n"
    "                    C modules, binary chunks, writes outside --out, the\n"
    "                    debug library\n"
    "  -h, --help        print this help and exit\n"
    "  --version         print the version and exit\n"
    "  --                end of options\n"
    "\n"
    "Without --unsafe a scene may write only under the output folder\n"
    "(io.open for writing, io.output, os.remove, os.rename; relative paths\n"
    "resolve against --out, while relative paths opened for reading resolve\n"
    "against the current folder), cannot run programs or load C code or\n"
    "binary chunks (the scene itself included), and has only\n"
    "debug.traceback of the debug library; os.exit ends the scene cleanly,\n"
    "os.tmpname and io.tmpfile raise an error and os.setlocale is absent.\n"
    "With --unsafe, io.open and os.* take paths as plain Lua does (relative\n"
    "to the current folder); outcrop's own writers always use --out.\n"
    "\n"
    "Ctrl-C, SIGTERM, SIGHUP and SIGPIPE stop the scene (long engine work\n"
    "included) without leaving partial outputs; a second one kills the\n"
    "process. After a stop no script code runs any more (no finalizer\n"
    "either). Running out of --max-memory is an error the scene may catch\n"
    "with pcall.\n"
    "\n"
    "A --set NAME that no outcrop.param call read by the end of the run is\n"
    "an error (status 2) naming the closest name that was read.\n"
    "\n"
    "exit status: 0 success, 1 error in the scene (memory limit included),\n"
    "2 usage error (binary scene and unread --set included), 124 --timeout\n"
    "reached,\n"
    "128 + N stopped by signal N: 130 Ctrl-C, 143 SIGTERM, 129 SIGHUP,\n"
    "141 SIGPIPE;\n"
    "os.exit(n) in a scene exits with n.\n";

static int usage_error(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));

static int usage_error(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fputs("outcrop: ", stderr);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputs("\nTry 'outcrop --help' for more information.\n", stderr);
  fflush(stderr);
  return OCRT_EUSAGE;
}

/* Parses a decimal integer in [lo, hi], digits only (no sign, no blanks,
** so "-1", " 3" and "1e3" are refused rather than read loosely). */
static int parse_int(const char *s, long long lo, long long hi,
                     long long *out) {
  long long v = 0;
  if (*s == '\0') return 0;
  for (; *s; s++) {
    if (*s < '0' || *s > '9') return 0;
    if (v > (hi - (*s - '0')) / 10) return 0;
    v = v * 10 + (*s - '0');
  }
  if (v < lo) return 0;
  *out = v;
  return 1;
}

/* Parses SIZE for --max-memory: digits, then optionally one of K, M, G, T
** (binary multiples; "iB" or "B" may follow; any case); "none" is 0.
** At most 2^50 bytes, so no product overflows. */
static int parse_size(const char *s, long long *out) {
  static const char units[] = "KMGT";
  const char *u;
  long long v;
  char num[24];
  size_t n = strspn(s, "0123456789");
  if (strcmp(s, "none") == 0) {
    *out = 0;
    return 1;
  }
  if (n == 0 || n >= sizeof num) return 0;
  memcpy(num, s, n);
  num[n] = '\0';
  if (!parse_int(num, 0, 1LL << 50, &v)) return 0;
  s += n;
  if (*s != '\0') {
    u = strchr(units, *s >= 'a' ? *s - 'a' + 'A' : *s);
    if (u == NULL || *u == '\0') return 0;
    s++;
    if (*s != '\0' && strcasecmp(s, "B") != 0 && strcasecmp(s, "iB") != 0)
      return 0;
    for (n = 0; n <= (size_t)(u - units); n++) {
      if (v > (1LL << 50) / 1024) return 0;
      v *= 1024;
    }
  }
  *out = v;
  return 1;
}

/* Parses SECONDS for --timeout: a plain decimal number (no sign, no
** exponent, no hexadecimal), at most ten million seconds. */
static int parse_seconds(const char *s, double *out) {
  char *end;
  double v;
  if (s[0] == '\0' || strspn(s, "0123456789.") != strlen(s)) return 0;
  v = strtod(s, &end);
  if (*end != '\0' || !(v >= 0 && v <= 1e7)) return 0;
  *out = v;
  return 1;
}

/* Matches `arg` against option `name`; for options with a value, sets
** *val to the text after "=" or to the next word (advancing *i). Returns
** 1 on a match, 0 if `arg` is another option, -1 when the value is
** missing. */
static int match(const char *arg, const char *name, int hasval, int argc,
                 char **argv, int *i, const char **val) {
  size_t n = strlen(name);
  if (strncmp(arg, name, n) != 0) return 0;
  if (arg[n] == '\0') {
    if (!hasval) return 1;
    if (*i + 1 >= argc) return -1;
    *val = argv[++*i];
    return 1;
  }
  if (arg[n] == '=' && hasval) {
    *val = arg + n + 1;
    return 1;
  }
  return 0;
}

void ocrt_options_free(ocrt_options *o) {
  free(o->params);
  free(o->args);
  o->params = o->args = NULL;
}

/* Handles one option word at argv[*i]; returns OCRT_RUN to go on. */
static int option(ocrt_options *o, int argc, char **argv, int *i) {
  static const char *const valued[] = {"--set", "--seed",       "--threads",
                                       "--out", "--max-memory", "--timeout",
                                       NULL};
  const char *arg = argv[*i];
  const char *val = NULL;
  long long v;
  int k, m;
  if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
    fputs(usage_text, stdout);
    return OCRT_OK;
  }
  if (strcmp(arg, "--version") == 0) {
    printf("outcrop %s (%s)\n", OC_VERSION, LUA_RELEASE);
    return OCRT_OK;
  }
  if (strcmp(arg, "--unsafe") == 0) {
    o->unsafe = 1;
    return OCRT_RUN;
  }
  if (strcmp(arg, "--list-params") == 0) {
    o->list_params = 1;
    return OCRT_RUN;
  }
  for (k = 0; valued[k]; k++) {
    m = match(arg, valued[k], 1, argc, argv, i, &val);
    if (m < 0) return usage_error("option '%s' needs a value", valued[k]);
    if (m > 0) break;
  }
  switch (k) {
  case 0: /* --set */
    if (val[0] == '=' || strchr(val, '=') == NULL)
      return usage_error("--set expects NAME=VALUE with a non-empty NAME "
                         "(got '%s')",
                         val);
    o->params[o->nparams++] = val;
    return OCRT_RUN;
  case 1: /* --seed */
    if (!parse_int(val, 0, LUA_MAXINTEGER, &v))
      return usage_error("--seed expects an integer >= 0 (got '%s')", val);
    o->seed = (lua_Integer)v;
    return OCRT_RUN;
  case 2: /* --threads */
    if (!parse_int(val, 1, MAX_THREADS, &v))
      return usage_error("--threads expects an integer from 1 to 1024 "
                         "(got '%s')",
                         val);
    o->threads = (int)v;
    return OCRT_RUN;
  case 3: /* --out */
    if (val[0] == '\0') return usage_error("--out expects a folder name");
    o->outdir = val;
    return OCRT_RUN;
  case 4: /* --max-memory */
    if (!parse_size(val, &v))
      return usage_error("--max-memory expects a size such as 512M or 2G, "
                         "or 0 for no limit (got '%s')",
                         val);
    o->max_memory = v;
    return OCRT_RUN;
  case 5: /* --timeout */
    if (!parse_seconds(val, &o->timeout))
      return usage_error("--timeout expects seconds, a number from 0 (no "
                         "limit) to 10000000 (got '%s')",
                         val);
    o->timeout_text = val;
    return OCRT_RUN;
  default:
    return usage_error("unknown option '%s'", arg);
  }
}

int ocrt_parse(ocrt_options *o, int argc, char **argv) {
  int i, status, options = 1, command = 0;
  memset(o, 0, sizeof *o);
  o->seed = -1;
  o->max_memory = -1;
  /* at most one entry per word, so argc entries always suffice */
  o->params = malloc(sizeof *o->params * (size_t)(argc + 1));
  o->args = malloc(sizeof *o->args * (size_t)(argc + 1));
  if (!o->params || !o->args) {
    ocrt_options_free(o);
    fputs("outcrop: not enough memory\n", stderr);
    return OCRT_ESCRIPT;
  }
  for (i = 1; i < argc; i++) {
    const char *arg = argv[i];
    if (options && strcmp(arg, "--") == 0) {
      options = 0;
    } else if (options && arg[0] == '-' && arg[1] != '\0') {
      status = option(o, argc, argv, &i);
      if (status != OCRT_RUN) {
        ocrt_options_free(o);
        return status;
      }
    } else if (o->scene == NULL && !command && strcmp(arg, "run") == 0) {
      command = 1;
    } else if (o->scene == NULL) {
      o->scene = arg;
    } else {
      o->args[o->nargs++] = arg;
    }
  }
  if (o->scene == NULL) {
    ocrt_options_free(o);
    return usage_error("no scene given");
  }
  if (o->list_params && o->unsafe) {
    ocrt_options_free(o);
    /* its writes could land anywhere: the throw-away folder would not
    ** hold them all */
    return usage_error("--list-params runs the scene in the sandbox; it "
                       "cannot be combined with --unsafe");
  }
  return OCRT_RUN;
}
