/*
** octmpfs.c — a size-limited tmpfs for the disk-full tests (octmpfs.h).
*/
#include <check.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <unistd.h>

#include "ocheck.h"
#include "octmpfs.h"

const char *oct_tmpfs(size_t bytes, const char *what) {
  static char dir[128];
  char opts[64];
  if (geteuid() != 0) {
    printf("%s: skipped (the disk-full test mounts a tmpfs: run as root)\n",
           what);
    return NULL;
  }
  snprintf(dir, sizeof dir, "%s", oct_tmpdir("full"));
  snprintf(opts, sizeof opts, "size=%zu,mode=0700", bytes);
  if (mount("octest", dir, "tmpfs", 0, opts) != 0) {
    printf("%s: skipped (cannot mount a tmpfs: %s)\n", what, strerror(errno));
    rmdir(dir);
    return NULL;
  }
  return dir;
}

void oct_tmpfs_done(const char *dir) {
  ck_assert_msg(umount(dir) == 0, "umount %s: %s", dir, strerror(errno));
  rmdir(dir);
}

void oct_assert_full(int rc, const char *msg, const char *name,
                     const char *dir) {
  char want[512], names[512] = "";
  snprintf(want, sizeof want, "cannot write '%s': %s", name, strerror(ENOSPC));
  ck_assert_msg(rc == OC_EIO && strcmp(msg, want) == 0,
                "%s: rc %d, message '%s'", name, rc, msg);
  ck_assert_msg(oct_count_entries(dir, names, sizeof names) == 0,
                "%s: left behind: %s", name, names);
}
