/*
** atomic.h — atomic file output, shared by every writer in lib/.
**
** A file is written as a temporary file in the destination's own folder
** (so the final rename never crosses file systems; anonymous where the
** system allows, so that a killed process leaves nothing), flushed and
** synced to disk, then renamed over the final name: readers see the old
** file or the whole new one, never a part. Every byte goes through the
** stream a.fp, so every failed write, flush, sync or close is seen; on
** any failure the temporary file is removed and nothing is left behind.
** Error messages read "cannot write 'name': reason" (strerror's text, e.g.
** "No space left on device").
**
** Names are relative to a directory descriptor (AT_FDCWD for the current
** folder), so a caller that resolved the destination folder once can
** write there without the path being looked up again.
**
**   oc_atomic a;
**   if (oc_atomic_begin_at(&a, dirfd, name, err)) return err->code;
**   ... oc_atomic_write(&a, buf, n) / fprintf(a.fp, ...) ...
**   return oc_atomic_commit(&a, err);   (or oc_atomic_abort(&a))
*/
#ifndef OC_ATOMIC_H
#define OC_ATOMIC_H

#include <stdio.h>

#include "outcrop.h"

typedef struct oc_atomic {
  int dir;    /* the directory descriptor names are relative to */
  char *path; /* the final name (a copy) */
  char *tmp;  /* the temporary name ".<base>.tmp-<pid>-<n><ext>", or NULL
              ** while the file is anonymous (O_TMPFILE) */
  FILE *fp;   /* open for writing on tmp, at offset 0 */
  int error;  /* errno of the first failed oc_atomic_write, or 0 */
} oc_atomic;

/* Creates the temporary file next to `name` (relative to `dirfd`, which
** stays the caller's and must stay open until commit or abort), with
** O_EXCL so it is unique among processes and threads, and opens a stream
** on it. The temporary name is hidden and ends in the final name's
** extension. On failure nothing exists and `a` needs no cleanup: OC_EIO
** (or OC_ENOMEM) with the message naming `name`. */
int oc_atomic_begin_at(oc_atomic *a, int dirfd, const char *name,
                       oc_error *err);

/* oc_atomic_begin_at(a, AT_FDCWD, path, err). */
int oc_atomic_begin(oc_atomic *a, const char *path, oc_error *err);

/* fwrite on a->fp that remembers the first failure's reason for commit.
** Returns 0, or -1 once any write has failed. */
int oc_atomic_write(oc_atomic *a, const void *p, size_t n);

/* Flushes, syncs to disk, closes and renames to the final name. On
** failure (of this or of any earlier write) the temporary file is removed
** and OC_EIO is returned with the reason. Either way `a` is finished. */
int oc_atomic_commit(oc_atomic *a, oc_error *err);

/* Closes and removes the temporary file; the final name is untouched. */
void oc_atomic_abort(oc_atomic *a);

#endif
