/*
** outdir.c — the output folder (--out): created like `mkdir -p`, then
** canonicalized so the module's "is this path under the output folder?"
** test compares real paths, not spellings with symlinks or "..".
*/
#define _XOPEN_SOURCE 700 /* realpath */

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ocrt.h"

/* mkdir for one component; an existing folder is fine. */
static int mkdir1(const char *path) {
  struct stat st;
  if (mkdir(path, 0777) == 0) return 0;
  if (errno == EEXIST && stat(path, &st) == 0) {
    if (S_ISDIR(st.st_mode)) return 0;
    errno = ENOTDIR;
  }
  return -1;
}

char *ocrt_outdir(const char *dir, char *msg, size_t msgsize) {
  char *path, *p, *real;
  int failed = 0;
  if (dir == NULL) dir = ".";
  path = strdup(dir);
  if (!path) {
    snprintf(msg, msgsize, "not enough memory");
    return NULL;
  }
  /* each prefix ending before a '/', then the whole path */
  for (p = path + 1; *p && !failed; p++) {
    if (*p == '/' && p[-1] != '/') {
      *p = '\0';
      failed = mkdir1(path) != 0;
      *p = '/';
    }
  }
  if (!failed) failed = mkdir1(path) != 0;
  real = failed ? NULL : realpath(path, NULL);
  if (!real)
    snprintf(msg, msgsize, "cannot create output folder '%s': %s", dir,
             strerror(errno));
  free(path);
  return real;
}
