/*
** oiio_load.c — oc_oiio_encode, oc_oiio_read and oc_oiio_read_raw for the
** rest of lib/: each loads liboutcrop_oiio.so (io/oiio_glue.h) on its
** first call, once per process, and calls through the object's table.
**
** Loading OpenImageIO and its ~260 libraries took most of the start-up of
** the interpreter (about 170 ms, 128 MB resident) for scripts that write
** no image at all; now only the first image read or write pays for it.
**
** The object is looked for next to the object this file is linked into
** (the interpreter, the Lua module outcrop.so, liboutcrop.so), then one
** folder up (the test, benchmark and fuzzing programs, built in
** sub-folders of the build folder), then by the dynamic linker's search
** for a bare name (LD_LIBRARY_PATH, the system's folders). Not by a run
** path: dlopen searches the run path of its caller, and under the
** sanitizers the caller is their interceptor. The object is never
** closed: OpenImageIO keeps threads and caches until exit.
*/
#define _GNU_SOURCE /* dladdr1, Dl_info, RTLD_DL_LINKMAP */
#include <dlfcn.h>
#include <link.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "io/metatext.h"
#include "io/oiio_glue.h"

static const oc_oiio_host host = {
    oc_image_new,      oc_image_free,
    oc_image_data,     oc_image_set_channel_name,
    oc_image_set_meta, oc_meta_quoted_size,
    oc_meta_quote,     oc_meta_unfold,
};

/* The loader's outcome, written once under `once` and read-only after:
** process-wide by nature (one dynamic linker per process), so not a
** handle of its own. */
static pthread_once_t once = PTHREAD_ONCE_INIT;
static const oc_oiio_glue *glue;
static char why[OC_ERRMSG];

/* The folder of the object holding this code, with a trailing '/', in
** out (size n); "" when unknown. The main program's link map has no name:
** its path is /proc/self/exe's. */
static void own_folder(char *out, size_t n) {
  Dl_info info;
  struct link_map *map = NULL;
  char path[PATH_MAX];
  out[0] = '\0';
  if (!dladdr1((void *)own_folder, &info, (void **)&map, RTLD_DL_LINKMAP) ||
      !map)
    return;
  if (map->l_name && map->l_name[0]) {
    snprintf(path, sizeof path, "%s", map->l_name);
  } else {
    ssize_t k = readlink("/proc/self/exe", path, sizeof path - 1);
    if (k <= 0) return;
    path[k] = '\0';
  }
  char *slash = strrchr(path, '/');
  if (!slash) return; /* a bare name: the linker's search below finds it */
  slash[1] = '\0';
  if (strlen(path) + 1 <= n) memcpy(out, path, strlen(path) + 1);
}

/* dlopen of `dir` `up` `name`; the first failure's reason kept in `why`
** (it names the path looked at first). */
static void *try_open(const char *dir, const char *up) {
  char file[PATH_MAX + sizeof "../" OC_OIIO_GLUE_FILE];
  snprintf(file, sizeof file, "%s%s%s", dir, up, OC_OIIO_GLUE_FILE);
  void *h = dlopen(file, RTLD_LAZY | RTLD_LOCAL);
  if (!h && !why[0]) snprintf(why, sizeof why, "%s", dlerror());
  return h;
}

static void load(void) {
  char dir[PATH_MAX];
  void *h = NULL;
  own_folder(dir, sizeof dir);
  if (dir[0]) h = try_open(dir, "");
  if (dir[0] && !h) h = try_open(dir, "../");
  if (!h) {
    h = dlopen(OC_OIIO_GLUE_FILE, RTLD_LAZY | RTLD_LOCAL);
    /* the first reason names the path looked at; keep it */
    if (!h && !why[0]) snprintf(why, sizeof why, "%s", dlerror());
  }
  if (!h) return;
  why[0] = '\0';
  oc_oiio_glue_open_fn open;
  void *sym = dlsym(h, OC_OIIO_GLUE_ENTRY);
  memcpy(&open, &sym, sizeof open); /* (object to function pointer) */
  if (!sym) {
    snprintf(why, sizeof why, "%s", dlerror());
    return;
  }
  glue = open(&host, OC_OIIO_GLUE_ABI);
  if (!glue)
    snprintf(why, sizeof why, "%s is of another build (interface %d wanted)",
             OC_OIIO_GLUE_FILE, OC_OIIO_GLUE_ABI);
}

/* The bridge's table, or NULL with the reason in *reason. */
static const oc_oiio_glue *bridge(const char **reason) {
  pthread_once(&once, load);
  *reason = why;
  return glue;
}

#define UNAVAILABLE "image support unavailable: %s"

int oc_oiio_encode(const oc_oiio_out *im, oc_oiio_sink sink, void *ud,
                   char *whyout, size_t whysize) {
  const char *r;
  const oc_oiio_glue *g = bridge(&r);
  if (!g) {
    if (whyout && whysize) snprintf(whyout, whysize, UNAVAILABLE, r);
    return OC_EIO;
  }
  return g->encode(im, sink, ud, whyout, whysize);
}

oc_image *oc_oiio_read(const char *path, oc_error *err) {
  const char *r;
  const oc_oiio_glue *g = bridge(&r);
  if (!g) {
    oc_seterr(err, OC_EIO, "cannot read '%s': " UNAVAILABLE, path, r);
    return NULL;
  }
  return g->read(path, err);
}

int oc_oiio_read_raw(const char *path, const oc_oiio_raw *r, oc_error *err) {
  const char *reason;
  const oc_oiio_glue *g = bridge(&reason);
  if (!g)
    return oc_seterr(err, OC_EIO, "cannot read '%s': " UNAVAILABLE, path,
                     reason);
  return g->read_raw(path, r, err);
}
