/*
** outdir.c — the output folder (--out): created like `mkdir -p`, then
** canonicalized so the module's "is this path under the output folder?"
** test compares real paths, not spellings with symlinks or "..". Also the
** throw-away output folder of --list-params.
*/
#define _XOPEN_SOURCE 700 /* realpath, mkdtemp, nftw */

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

char *ocrt_tmp_outdir(char *msg, size_t msgsize) {
  const char *tmp = getenv("TMPDIR");
  char path[4096];
  if (tmp == NULL || tmp[0] == '\0') tmp = "/tmp";
  if ((size_t)snprintf(path, sizeof path, "%s/outcrop-params.XXXXXX", tmp) >=
      sizeof path) {
    snprintf(msg, msgsize, "TMPDIR is too long");
    return NULL;
  }
  if (mkdtemp(path) == NULL) {
    snprintf(msg, msgsize, "cannot create a temporary folder in '%s': %s", tmp,
             strerror(errno));
    return NULL;
  }
  char *real = ocrt_outdir(path, msg, msgsize);
  if (real == NULL) rmdir(path);
  return real;
}

static int remove1(const char *path, const struct stat *st, int type,
                   struct FTW *ftw) {
  (void)st, (void)type, (void)ftw;
  remove(path); /* what cannot be removed stays: nothing else to do */
  return 0;
}

void ocrt_remove_tree(const char *dir) {
  /* depth first, links not followed, not into other file systems */
  nftw(dir, remove1, 16, FTW_DEPTH | FTW_PHYS | FTW_MOUNT);
}
