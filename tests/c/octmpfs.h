/*
** octmpfs.h — a small tmpfs for the disk-full tests of every writer: a
** fresh folder with a size limit, so that writes fail with ENOSPC as on a
** full disk. Needs root (mount); elsewhere the tests skip with a message.
*/
#ifndef OCTMPFS_H
#define OCTMPFS_H

#include <stddef.h>

/* Mounts a tmpfs of `bytes` on a new folder and returns its path (static
** storage, valid until oct_tmpfs_done), or NULL after printing why the
** caller's test is skipped (`what` names it). */
const char *oct_tmpfs(size_t bytes, const char *what);
/* Unmounts and removes the folder. */
void oct_tmpfs_done(const char *dir);

/* Asserts that a write refused for lack of space said so: OC_EIO, the
** message "cannot write '<name>': No space left on device", and nothing
** (neither the file nor a temporary) left in `dir`. */
void oct_assert_full(int rc, const char *msg, const char *name,
                     const char *dir);

#endif
