/*
** atomic.c — atomic file output: temporary file, checked writes, fsync,
** rename, all relative to one directory descriptor (see atomic.h).
**
** Where the kernel and file system allow it the temporary file is
** anonymous (O_TMPFILE) until the commit links it under its hidden name
** just before the rename, so a process killed while writing (a second
** Ctrl-C, SIGKILL) leaves nothing behind; elsewhere it is created under
** its hidden name at once.
*/
#define _GNU_SOURCE /* O_TMPFILE, linkat through /proc */

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "io/atomic.h"

/* The extension of the last path component ("" when there is none). */
static const char *extension(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = strrchr(base, '.');
  return dot && dot != base ? dot : "";
}

static char *copy(const char *s) {
  size_t n = strlen(s) + 1;
  char *c = malloc(n);
  return c ? memcpy(c, s, n) : NULL;
}

/* The malloc'ed name of temporary n next to `path`: hidden, unique among
** processes (pid) and threads (n), ending in the real extension. */
static char *temp_name(const char *path, unsigned n) {
  const char *slash = strrchr(path, '/');
  int dirlen = slash ? (int)(slash - path + 1) : 0;
  const char *ext = extension(path);
  size_t size = strlen(path) + strlen(ext) + 64;
  char *tmp = malloc(size);
  if (tmp)
    snprintf(tmp, size, "%.*s.%s.tmp-%ld-%u%s", dirlen, path, path + dirlen,
             (long)getpid(), n, ext);
  else
    errno = ENOMEM;
  return tmp;
}

/* Creates the temporary file under a new name (O_EXCL, trying the next n
** while one exists). Returns the fd and the name in *name, or -1 with
** errno set. */
static int make_temp(int dir, const char *path, char **name) {
  for (unsigned n = 0; n < 1000; n++) {
    char *tmp = temp_name(path, n);
    if (!tmp) return -1;
    int fd = openat(dir, tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      *name = tmp;
      return fd;
    }
    int e = errno;
    free(tmp);
    errno = e;
    if (e != EEXIST) break;
  }
  return -1;
}

#ifdef O_TMPFILE
/* An anonymous file in path's folder, or -1 when the system cannot make
** one or could not link it later (no /proc). */
static int anonymous_temp(int dir, const char *path) {
  const char *slash = strrchr(path, '/');
  /* malloc, not strndup: --max-memory and the allocation-failure tests
  ** see only the malloc family */
  size_t n = slash ? (size_t)(slash - path + 1) : 0;
  char *folder = slash ? malloc(n + 1) : NULL;
  if (slash && !folder) return -1;
  if (folder) memcpy(folder, path, n), folder[n] = '\0';
  int fd = openat(dir, folder ? folder : ".", O_WRONLY | O_TMPFILE | O_CLOEXEC,
                  0666);
  free(folder);
  char proc[64];
  snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
  if (fd >= 0 && access(proc, F_OK) != 0) {
    close(fd);
    fd = -1;
  }
  return fd;
}

/* Gives the anonymous file its hidden name (see make_temp). */
static int link_temp(oc_atomic *a) {
  char proc[64];
  snprintf(proc, sizeof proc, "/proc/self/fd/%d", fileno(a->fp));
  for (unsigned n = 0; n < 1000; n++) {
    char *tmp = temp_name(a->path, n);
    if (!tmp) return -1;
    if (linkat(AT_FDCWD, proc, a->dir, tmp, AT_SYMLINK_FOLLOW) == 0) {
      a->tmp = tmp;
      return 0;
    }
    int e = errno;
    free(tmp);
    errno = e;
    if (e != EEXIST) break;
  }
  return -1;
}
#else
static int anonymous_temp(int dir, const char *path) {
  (void)dir, (void)path;
  return -1;
}

static int link_temp(oc_atomic *a) {
  (void)a;
  errno = ENOTSUP;
  return -1;
}
#endif

static void finish(oc_atomic *a) {
  free(a->tmp);
  free(a->path);
  a->tmp = a->path = NULL;
  a->fp = NULL;
}

int oc_atomic_begin_at(oc_atomic *a, int dirfd, const char *path,
                       oc_error *err) {
  a->dir = dirfd;
  a->tmp = NULL;
  a->fp = NULL;
  a->error = 0;
  a->path = copy(path);
  if (!a->path)
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  int fd = anonymous_temp(dirfd, path);
  if (fd < 0) fd = make_temp(dirfd, path, &a->tmp);
  if (fd < 0) {
    int rc = oc_seterr(err, errno == ENOMEM ? OC_ENOMEM : OC_EIO,
                       "cannot write '%s': %s", path, strerror(errno));
    finish(a);
    return rc;
  }
  a->fp = fdopen(fd, "wb");
  if (!a->fp) {
    int e = errno;
    close(fd);
    if (a->tmp) unlinkat(dirfd, a->tmp, 0);
    finish(a);
    return oc_seterr(err, OC_EIO, "cannot write '%s': %s", path, strerror(e));
  }
  return OC_OK;
}

int oc_atomic_begin(oc_atomic *a, const char *path, oc_error *err) {
  return oc_atomic_begin_at(a, AT_FDCWD, path, err);
}

int oc_atomic_write(oc_atomic *a, const void *p, size_t n) {
  if (a->error) return -1;
  if (n == 0) return 0;
  errno = 0;
  if (fwrite(p, 1, n, a->fp) == n) return 0;
  a->error = errno ? errno : EIO;
  return -1;
}

/* fsync that tolerates files that cannot be synced (special mounts). */
static int sync_fd(int fd) {
  if (fsync(fd) == 0) return 0;
  return errno == EINVAL || errno == ENOTSUP ? 0 : -1;
}

int oc_atomic_commit(oc_atomic *a, oc_error *err) {
  int e = 0;
  errno = 0;
  if (fflush(a->fp) != 0 || ferror(a->fp) || a->error)
    e = a->error ? a->error : errno ? errno : EIO;
  else if (sync_fd(fileno(a->fp)) != 0)
    e = errno ? errno : EIO;
  else if (!a->tmp && link_temp(a) != 0)
    e = errno ? errno : EIO;
  /* Some file systems (NFS) report write errors only at close. */
  errno = 0;
  if (fclose(a->fp) != 0 && !e) e = errno ? errno : EIO;
  if (!e && renameat(a->dir, a->tmp, a->dir, a->path) != 0) e = errno;
  if (!e) {
    finish(a);
    return OC_OK;
  }
  if (a->tmp) unlinkat(a->dir, a->tmp, 0);
  int rc =
      oc_seterr(err, OC_EIO, "cannot write '%s': %s", a->path, strerror(e));
  finish(a);
  return rc;
}

void oc_atomic_abort(oc_atomic *a) {
  if (a->fp) fclose(a->fp);
  if (a->tmp) unlinkat(a->dir, a->tmp, 0);
  finish(a);
}
