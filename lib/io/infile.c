/*
** infile.c — oc_infile_open: a regular file and its format from its
** signature, and oc_infile_sha256 (see infile.h).
*/
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/sha256.h"
#include "io/infile.h"

static const struct {
  const char *magic;
  size_t n;
  const char *format;
} signatures[] = {
    {"\x89PNG\r\n\x1a\n", 8, "png"},
    {"II*\0", 4, "tiff"},
    {"MM\0*", 4, "tiff"},
    {"II+\0", 4, "tiff"}, /* BigTIFF */
    {"MM\0+", 4, "tiff"},
    {"\x76\x2f\x31\x01", 4, "openexr"},
    {"\xff\xd8\xff", 3, "jpeg"},
};

static const char *kind_of(mode_t m) {
  return S_ISDIR(m)    ? "a folder"
         : S_ISFIFO(m) ? "a FIFO"
         : S_ISCHR(m)  ? "a character device"
         : S_ISBLK(m)  ? "a block device"
         : S_ISSOCK(m) ? "a socket"
                       : "not a file";
}

/* read() until n bytes or the end; the count read, or -1. */
static ssize_t read_full(int fd, unsigned char *p, size_t n) {
  size_t got = 0;
  while (got < n) {
    ssize_t k = read(fd, p + got, n - got);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) return -1;
    if (k == 0) break;
    got += (size_t)k;
  }
  return (ssize_t)got;
}

/* Opens a regular file for reading, blocking reads; the descriptor, or
** -1 with err set. */
static int open_regular(const char *path, oc_error *err) {
  /* O_NONBLOCK: opening a FIFO must not wait for a writer. */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(errno));
    return -1;
  }
  struct stat st;
  const char *why = NULL;
  int e = 0;
  if (fstat(fd, &st) != 0)
    e = errno;
  else if (!S_ISREG(st.st_mode))
    why = kind_of(st.st_mode);
  else if (fcntl(fd, F_SETFL, 0) != 0)
    e = errno;
  if (e || why) {
    close(fd);
    if (why)
      oc_seterr(err, OC_EIO, "cannot read '%s': not a regular file (%s)", path,
                why);
    else
      oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(e));
    return -1;
  }
  return fd;
}

int oc_infile_sha256(const char *path, char *hex, oc_error *err) {
  int fd = open_regular(path, err);
  if (fd < 0) return OC_EIO;
  oc_sha256 s;
  unsigned char buf[16384], d[OC_SHA256_BYTES];
  ssize_t n;
  oc_sha256_init(&s);
  while ((n = read_full(fd, buf, sizeof buf)) > 0) {
    oc_sha256_update(&s, buf, (size_t)n);
    if ((size_t)n < sizeof buf) break;
  }
  int e = n < 0 ? errno : 0;
  close(fd);
  if (e)
    return oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(e));
  oc_sha256_final(&s, d);
  oc_sha256_hex(d, hex);
  return OC_OK;
}

int oc_infile_open(const char *path, FILE **fp, const char **format,
                   oc_error *err) {
  *fp = NULL;
  *format = NULL;
  int fd = open_regular(path, err);
  if (fd < 0) return OC_EIO;
  int e;
  unsigned char head[8];
  ssize_t n = read_full(fd, head, sizeof head);
  if (n < 0 || lseek(fd, 0, SEEK_SET) != 0) {
    e = errno;
    close(fd);
    return oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(e));
  }
  for (size_t i = 0; i < sizeof signatures / sizeof *signatures; i++)
    if ((size_t)n >= signatures[i].n &&
        memcmp(head, signatures[i].magic, signatures[i].n) == 0)
      *format = signatures[i].format;
  if (!*format) {
    close(fd);
    return oc_seterr(err, OC_EIO,
                     "cannot read '%s': unrecognised image format (not PNG, "
                     "TIFF, EXR or JPEG)",
                     path);
  }
  *fp = fdopen(fd, "rb");
  if (!*fp) {
    e = errno;
    close(fd);
    return oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(e));
  }
  return OC_OK;
}
