/*
** atomic.c — atomic file output: temporary name, fsync, rename (see
** atomic.h for the protocol).
*/
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

/* Opens a new temporary file next to `path`: hidden, unique among
** processes (pid) and threads (O_EXCL, trying the next n), ending in the
** real extension. Returns the fd and the malloc'ed name in *name, or -1
** with errno set. */
static int make_temp(const char *path, char **name) {
  const char *slash = strrchr(path, '/');
  int dirlen = slash ? (int)(slash - path + 1) : 0;
  const char *base = path + dirlen;
  const char *ext = extension(path);
  size_t size = strlen(path) + strlen(ext) + 64;
  char *tmp = malloc(size);
  if (!tmp) {
    errno = ENOMEM;
    return -1;
  }
  for (unsigned n = 0; n < 1000; n++) {
    snprintf(tmp, size, "%.*s.%s.tmp-%ld-%u%s", dirlen, path, base,
             (long)getpid(), n, ext);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      *name = tmp;
      return fd;
    }
    if (errno != EEXIST) break;
  }
  int e = errno;
  free(tmp);
  errno = e;
  return -1;
}

static void finish(oc_atomic *a) {
  free(a->tmp);
  free(a->path);
  a->tmp = a->path = NULL;
  a->fp = NULL;
}

int oc_atomic_begin(oc_atomic *a, const char *path, oc_error *err) {
  a->tmp = NULL;
  a->fp = NULL;
  a->error = 0;
  a->path = copy(path);
  if (!a->path)
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  int fd = make_temp(path, &a->tmp);
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
    unlink(a->tmp);
    finish(a);
    return oc_seterr(err, OC_EIO, "cannot write '%s': %s", path, strerror(e));
  }
  return OC_OK;
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

/* Syncs the file now under the temporary name. A library given the name
** may have replaced the file rather than rewritten it; then the data is
** in another inode than our descriptor's, and that one is synced too. */
static int sync_temp(oc_atomic *a) {
  int fd = fileno(a->fp);
  if (sync_fd(fd) != 0) return -1;
  struct stat mine, named;
  if (fstat(fd, &mine) != 0 || stat(a->tmp, &named) != 0) return -1;
  if (mine.st_dev == named.st_dev && mine.st_ino == named.st_ino) return 0;
  int other = open(a->tmp, O_RDONLY | O_CLOEXEC);
  if (other < 0) return -1;
  int rc = sync_fd(other);
  int e = errno;
  close(other);
  errno = e;
  return rc;
}

int oc_atomic_commit(oc_atomic *a, oc_error *err) {
  int e = 0;
  errno = 0;
  if (fflush(a->fp) != 0 || ferror(a->fp) || a->error)
    e = a->error ? a->error : errno ? errno : EIO;
  else if (sync_temp(a) != 0)
    e = errno ? errno : EIO;
  /* Some file systems (NFS) report write errors only at close. */
  errno = 0;
  if (fclose(a->fp) != 0 && !e) e = errno ? errno : EIO;
  if (!e && rename(a->tmp, a->path) != 0) e = errno;
  if (!e) {
    finish(a);
    return OC_OK;
  }
  unlink(a->tmp);
  int rc =
      oc_seterr(err, OC_EIO, "cannot write '%s': %s", a->path, strerror(e));
  finish(a);
  return rc;
}

void oc_atomic_abort(oc_atomic *a) {
  if (a->fp) fclose(a->fp);
  if (a->tmp) unlink(a->tmp);
  finish(a);
}
