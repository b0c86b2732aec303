/*
** replay.c — runs corpus files through the fuzzers' generator and runner
** outside libFuzzer (the gcc sanitizer build replays tests/corpus in
** `make test`), or prints the scene a file turns into (--show, used by
** scripts/fuzz-show).
**
**   replay [--show] [-v] FILE|DIR ...   (a DIR: its regular files)
**
** Exit status 0 when every scene ran to its end or failed with a Lua
** error, and left no temporary file and nothing outside the output
** folder; a sanitizer report ends the process with its own status.
*/
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gen.h"
#include "runner.h"

static int show, verbose, count;
static ocfz_dirs dirs;

static unsigned char *slurp(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  unsigned char *b = NULL;
  long sz;
  if (f == NULL) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (sz = ftell(f)) >= 0 &&
      fseek(f, 0, SEEK_SET) == 0 && (b = malloc((size_t)sz + 1)) != NULL)
    *n = fread(b, 1, (size_t)sz, f);
  fclose(f);
  return b;
}

static int one(const char *path) {
  static const ocfz_limits lim = {64u << 20, 2000, NULL, NULL, NULL, NULL};
  char msg[512];
  size_t n = 0, len = 0;
  unsigned char *b = slurp(path, &n);
  char *scene;
  int st;
  if (b == NULL) {
    fprintf(stderr, "replay: cannot read %s\n", path);
    return 1;
  }
  scene = ocfz_scene(b, n, ocfz_skip_from_env(), &len);
  free(b);
  if (scene == NULL) return 1;
  if (show) {
    fwrite(scene, 1, len, stdout);
  } else {
    if (verbose) fprintf(stderr, "replay: %s\n", path);
    st = ocfz_run(scene, len, dirs.out, &lim, msg, sizeof msg);
    if (verbose && st != 0) fprintf(stderr, "  error: %s\n", msg);
    if (!ocfz_dirs_check(&dirs, msg, sizeof msg)) {
      fprintf(stderr, "replay: %s: the scene left '%s' behind\n", path, msg);
      free(scene);
      return 1;
    }
    count++;
  }
  free(scene);
  return 0;
}

static int cmp(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The regular files of `dir`, in name order (so runs repeat). */
static int dir(const char *path) {
  DIR *d = opendir(path);
  struct dirent *e;
  char **names = NULL;
  size_t n = 0, i;
  int bad = 0;
  if (d == NULL) return 1;
  while ((e = readdir(d)) != NULL) {
    char *full;
    struct stat sb;
    if (e->d_name[0] == '.') continue;
    full = malloc(strlen(path) + strlen(e->d_name) + 2);
    char **t = realloc(names, (n + 1) * sizeof *names);
    if (full == NULL || t == NULL) {
      free(full);
      bad = 1;
      break;
    }
    names = t;
    sprintf(full, "%s/%s", path, e->d_name);
    if (stat(full, &sb) == 0 && S_ISREG(sb.st_mode))
      names[n++] = full;
    else
      free(full);
  }
  closedir(d);
  if (n) qsort(names, n, sizeof *names, cmp);
  for (i = 0; i < n; i++) {
    bad |= one(names[i]);
    free(names[i]);
  }
  free(names);
  return bad;
}

int main(int argc, char **argv) {
  int i, bad = 0;
  struct stat sb;
  if (ocfz_dirs_open(&dirs, "ocreplay") != 0) {
    perror("replay: output folder");
    return 2;
  }
  for (i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--show") == 0)
      show = 1;
    else if (strcmp(argv[i], "-v") == 0)
      verbose = 1;
    else if (stat(argv[i], &sb) == 0 && S_ISDIR(sb.st_mode))
      bad |= dir(argv[i]);
    else
      bad |= one(argv[i]);
  }
  ocfz_dirs_close(&dirs);
  if (!show) fprintf(stderr, "replay: %d scenes replayed\n", count);
  return bad;
}
