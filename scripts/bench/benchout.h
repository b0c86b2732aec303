/*
** benchout.h — what a benchmark keeps and which parts it runs, for
** scripts/compare_revisions.sh: with OUTCROP_BENCH_OUT=DIR set, a
** benchmark writes the meshes, images and values it computed into DIR
** (so two builds can be compared byte for byte); with
** OUTCROP_BENCH_ONLY=part,part set, it runs only the parts named (each
** benchmark's main says which names it knows). Unset, a benchmark runs
** every part and writes nothing, as before. OUTCROP_BENCH_ROUNDS=n sets
** how many renders the timed ones take the fastest of (bench_rounds).
*/
#ifndef BENCHOUT_H
#define BENCHOUT_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "outcrop.h"

/* 1 when `part` is to run: OUTCROP_BENCH_ONLY unset or empty, or the
** part is one of its comma-separated names. */
static inline int bench_wanted(const char *part) {
  const char *only = getenv("OUTCROP_BENCH_ONLY");
  if (!only || !*only) return 1;
  size_t n = strlen(part);
  for (const char *s = only; *s;) {
    const char *e = strchr(s, ',');
    size_t len = e ? (size_t)(e - s) : strlen(s);
    if (len == n && !memcmp(s, part, n)) return 1;
    if (!e) break;
    s = e + 1;
  }
  return 0;
}

/* How many times a benchmark times a render to keep its fastest (the
** renders are the same bits each time; a slow spell of a shared machine
** then rarely sets the figure): OUTCROP_BENCH_ROUNDS when it is a number
** from 1, at most BENCH_MAX_ROUNDS, else 3. */
#define BENCH_MAX_ROUNDS 20
static inline int bench_rounds(void) {
  const char *rn = getenv("OUTCROP_BENCH_ROUNDS");
  int n = rn ? atoi(rn) : 0;
  return n < 1 ? 3 : n > BENCH_MAX_ROUNDS ? BENCH_MAX_ROUNDS : n;
}

/* DIR/name in buf, or 0 when OUTCROP_BENCH_OUT is unset (nothing kept). */
static inline int bench_out_path(char *buf, size_t size, const char *name) {
  const char *dir = getenv("OUTCROP_BENCH_OUT");
  if (!dir || !*dir) return 0;
  int n = snprintf(buf, size, "%s/%s", dir, name);
  return n > 0 && (size_t)n < size;
}

static inline void bench_keep_mesh(const char *who, const char *name,
                                   const oc_mesh *m) {
  char path[4096];
  oc_error err;
  if (!bench_out_path(path, sizeof path, name)) return;
  if (oc_mesh_write(m, path, &err)) {
    fprintf(stderr, "%s: %s\n", who, err.msg);
    exit(1);
  }
}

/* Images are kept as EXR with float channels as computed (bits 32). */
static inline void bench_keep_image(const char *who, const char *name,
                                    const oc_image *img) {
  char path[4096];
  oc_error err;
  if (!bench_out_path(path, sizeof path, name)) return;
  if (oc_image_write(img, path, 32, &err)) {
    fprintf(stderr, "%s: %s\n", who, err.msg);
    exit(1);
  }
}

/* n doubles, raw (the host's byte order: both builds run here). */
static inline void bench_keep_values(const char *who, const char *name,
                                     const double *v, size_t n) {
  char path[4096];
  if (!bench_out_path(path, sizeof path, name)) return;
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(v, sizeof *v, n, f) != n || fclose(f)) {
    fprintf(stderr, "%s: cannot write '%s'\n", who, path);
    exit(1);
  }
}

#endif
