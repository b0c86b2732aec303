/*
** tio.c — a fracture tile saved to a file and loaded back, so that a tile
** is made once and reused (Paris et al. 2020, section 4.1).
**
** The file, all numbers little-endian, doubles as their IEEE 754 bits:
**
**   "OCBTILE\n"  magic (8 bytes)
**   u32 version (1), u32 0
**   parameters: u32 type, f64 size, radius, neighbour, u64 fractures,
**     f64 spacing, disc_lo, disc_hi, rounding, width, u64 seed, ndiscs
**   counts: u64 points, discs, blocks, edges, cut, thick, separated,
**     merged, authored (the last blocks); f64 seconds
**   points: 3 f64 each; discs: 7 f64 each (centre, normal, radius)
**   blocks: u64 nplane, nvert, npts; f64 centroid (3), box (6),
**     thickness; planes (4 f64 each); vertices (3 f64 each)
**   SHA-256 of every byte before it (32 bytes)
**
** Written atomically (io/atomic.h): the file is whole or absent. A file is
** read whole (at most MAX_FILE bytes) and checked before anything is
** built from it: the magic, the version, the hash (a damaged file), then
** every count against what the rest of the file can hold and every
** number against its range (crafted files), so that no size read from it
** is allocated unchecked. The loaded tile keeps no neighbour graph (its
** edge counts only), and its blocks are the saved ones bit for bit.
*/
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "io/atomic.h"

#define MAGIC "OCBTILE\n"
#define VERSION 1u
#define MAX_FILE ((size_t)1 << 30)
#define MAX_POINTS 4000000u
#define MAX_DISCS 200000u
#define MAX_PLANES 65536u

/* ---- writing ------------------------------------------------------------- */

typedef struct wr {
  oc_atomic a;
  oc_sha256 h;
} wr;

static void put(wr *w, const void *p, size_t n) {
  oc_sha256_update(&w->h, p, n);
  oc_atomic_write(&w->a, p, n);
}

static void put_u64(wr *w, uint64_t v) {
  unsigned char b[8];
  for (int i = 0; i < 8; i++)
    b[i] = (unsigned char)(v >> (8 * i));
  put(w, b, 8);
}

static void put_u32(wr *w, uint32_t v) {
  unsigned char b[4];
  for (int i = 0; i < 4; i++)
    b[i] = (unsigned char)(v >> (8 * i));
  put(w, b, 4);
}

static void put_f64s(wr *w, const double *v, size_t n) {
  for (size_t i = 0; i < n; i++) {
    uint64_t u;
    memcpy(&u, &v[i], 8);
    put_u64(w, u);
  }
}

int oc_btile_save_at(const oc_btile *t, int dirfd, const char *path,
                     oc_error *err) {
  if (!t || !path)
    return oc_seterr(err, OC_EINVAL, "tile:save needs a tile and a path");
  wr w;
  if (oc_atomic_begin_at(&w.a, dirfd, path, err)) return err ? err->code : 1;
  oc_sha256_init(&w.h);
  const oc_btile_params *pp = &t->pp;
  put(&w, MAGIC, 8);
  put_u32(&w, VERSION);
  put_u32(&w, 0);
  put_u32(&w, (uint32_t)pp->type);
  const double p1[3] = {pp->size, pp->radius, pp->neighbour};
  put_f64s(&w, p1, 3);
  put_u64(&w, pp->fractures);
  const double p2[5] = {pp->spacing, pp->disc_lo, pp->disc_hi, pp->rounding,
                        pp->width};
  put_f64s(&w, p2, 5);
  put_u64(&w, pp->seed);
  put_u64(&w, pp->ndiscs);
  oc_btile_stats st;
  oc_btile_stats_get(t, &st);
  const uint64_t counts[9] = {t->np,    t->nd,   t->nb,     st.edges, st.cut,
                              t->thick, t->ncut, t->merged, t->nauth};
  for (int i = 0; i < 9; i++)
    put_u64(&w, counts[i]);
  put_f64s(&w, &t->seconds, 1);
  put_f64s(&w, t->pts, 3 * t->np);
  for (size_t i = 0; i < t->nd; i++) {
    const oc_bdisc *d = &t->disc[i];
    const double v[7] = {d->c.x, d->c.y, d->c.z, d->n.x, d->n.y, d->n.z, d->r};
    put_f64s(&w, v, 7);
  }
  for (size_t i = 0; i < t->nb; i++) {
    const oc_bblock *b = &t->block[i];
    put_u64(&w, b->nplane);
    put_u64(&w, b->nvert);
    put_u64(&w, b->npts);
    const double v[10] = {
        b->centroid.x, b->centroid.y, b->centroid.z, b->box.lo.x, b->box.lo.y,
        b->box.lo.z,   b->box.hi.x,   b->box.hi.y,   b->box.hi.z, b->thickness};
    put_f64s(&w, v, 10);
    put_f64s(&w, b->plane, 4 * b->nplane);
    put_f64s(&w, b->vert, 3 * b->nvert);
  }
  unsigned char d[OC_SHA256_BYTES];
  oc_sha256_final(&w.h, d);
  oc_atomic_write(&w.a, d, sizeof d);
  return oc_atomic_commit(&w.a, err);
}

int oc_btile_save(const oc_btile *t, const char *path, oc_error *err) {
  return oc_btile_save_at(t, AT_FDCWD, path, err);
}

/* ---- reading ------------------------------------------------------------- */

typedef struct rd {
  const unsigned char *p;
  size_t n, at;
  const char *path;
  oc_error *err;
  int bad; /* set once anything failed (err says what) */
} rd;

static int fail(rd *r, const char *what) {
  if (!r->bad)
    oc_seterr(r->err, OC_EINVAL, "'%s' is not a valid tile file: %s", r->path,
              what);
  r->bad = 1;
  return 0;
}

/* 1 when n more bytes are there */
static int have(rd *r, size_t n) {
  if (r->bad) return 0;
  if (n > r->n - r->at) return fail(r, "truncated");
  return 1;
}

static uint64_t get_u64(rd *r) {
  if (!have(r, 8)) return 0;
  uint64_t v = 0;
  for (int i = 7; i >= 0; i--)
    v = (v << 8) | r->p[r->at + (size_t)i];
  r->at += 8;
  return v;
}

static uint32_t get_u32(rd *r) {
  if (!have(r, 4)) return 0;
  uint32_t v = 0;
  for (int i = 3; i >= 0; i--)
    v = (v << 8) | r->p[r->at + (size_t)i];
  r->at += 4;
  return v;
}

/* n finite doubles into v */
static int get_f64s(rd *r, double *v, size_t n) {
  for (size_t i = 0; i < n; i++) {
    uint64_t u = get_u64(r);
    memcpy(&v[i], &u, 8);
    if (!r->bad && !isfinite(v[i])) return fail(r, "a number is not finite");
  }
  return !r->bad;
}

/* The whole file at path into a new buffer. */
static unsigned char *slurp(const char *path, size_t *n, oc_error *err) {
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(errno));
    return NULL;
  }
  struct stat st;
  unsigned char *buf = NULL;
  if (fstat(fd, &st) != 0 || fcntl(fd, F_SETFL, 0) != 0) {
    oc_seterr(err, OC_EIO, "cannot read '%s': %s", path, strerror(errno));
  } else if (!S_ISREG(st.st_mode)) {
    oc_seterr(err, OC_EIO, "cannot read '%s': not a regular file", path);
  } else if ((uint64_t)st.st_size > MAX_FILE) {
    oc_seterr(err, OC_EINVAL,
              "'%s' is not a valid tile file: %lld bytes (at most %zu)", path,
              (long long)st.st_size, MAX_FILE);
  } else if (!(buf = malloc(st.st_size ? (size_t)st.st_size : 1))) {
    oc_seterr(err, OC_ENOMEM, "out of memory reading '%s'", path);
  } else {
    size_t got = 0, want = (size_t)st.st_size;
    while (got < want) {
      ssize_t k = read(fd, buf + got, want - got);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) break;
      got += (size_t)k;
    }
    if (got != want) {
      oc_seterr(err, OC_EIO, "cannot read '%s': %s", path,
                got < want ? "the file shrank while read" : strerror(errno));
      free(buf);
      buf = NULL;
    }
    *n = want;
  }
  close(fd);
  return buf;
}

static int in_range(double v, double lo, double hi) {
  return v >= lo && v <= hi;
}

static int read_blocks(rd *r, oc_btile *t) {
  double s = t->pp.size;
  size_t pts = 0;
  for (size_t i = 0; i < t->nb; i++) {
    oc_bblock *b = &t->block[i];
    uint64_t np = get_u64(r), nv = get_u64(r), nq = get_u64(r);
    if (r->bad) return 0;
    if (np < 4 || np > MAX_PLANES || nv < 4 || nv > MAX_PLANES || nq > t->np ||
        nq > t->np - pts)
      return fail(r, "a block's counts are out of range");
    pts += nq;
    /* the bytes must be there before anything is allocated */
    if (!have(r, 8 * (10 + 4 * np + 3 * nv))) return 0;
    double v[10];
    get_f64s(r, v, 10);
    b->centroid = (oc_vec3){v[0], v[1], v[2]};
    b->box = (oc_aabb){{v[3], v[4], v[5]}, {v[6], v[7], v[8]}};
    b->thickness = v[9];
    b->plane = malloc(4 * np * sizeof *b->plane);
    b->vert = malloc(3 * nv * sizeof *b->vert);
    if (!b->plane || !b->vert) {
      oc_seterr(r->err, OC_ENOMEM, "out of memory reading '%s'", r->path);
      r->bad = 1;
      return 0;
    }
    b->nplane = np;
    b->nvert = nv;
    b->npts = nq;
    if (!get_f64s(r, b->plane, 4 * np) || !get_f64s(r, b->vert, 3 * nv))
      return 0;
    for (int a = 0; a < 3; a++)
      if (!in_range(v[a], 0, s) || !in_range(v[3 + a], -s, 2 * s) ||
          !in_range(v[6 + a], v[3 + a], 2 * s))
        return fail(r, "a block lies outside its tile");
    if (!in_range(b->thickness, 0, s))
      return fail(r, "a block's thickness is out of range");
    for (size_t k = 0; k < np; k++) {
      const double *h = b->plane + 4 * k;
      if (fabs(h[0] * h[0] + h[1] * h[1] + h[2] * h[2] - 1) > 1e-9 ||
          fabs(h[3]) > 4 * s)
        return fail(r, "a block's plane is not a unit normal and offset");
    }
    for (size_t k = 0; k < 3 * nv; k++)
      if (!in_range(b->vert[k], -s, 2 * s))
        return fail(r, "a block's vertex lies outside its tile");
  }
  return 1;
}

oc_btile *oc_btile_load(const char *path, oc_error *err) {
  if (!path) {
    oc_seterr(err, OC_EINVAL, "blocks.load needs a path");
    return NULL;
  }
  size_t n = 0;
  unsigned char *buf = slurp(path, &n, err);
  if (!buf) return NULL;
  rd r = {buf, n, 0, path, err, 0};
  oc_btile *t = NULL;
  int ok = 0;
  if (n < 8 || memcmp(buf, MAGIC, 8) != 0) {
    fail(&r, "no tile header (not written by tile:save)");
    goto done;
  }
  r.at = 8;
  uint32_t version = get_u32(&r);
  get_u32(&r);
  if (!r.bad && version != VERSION) {
    oc_seterr(err, OC_EINVAL,
              "'%s' is a tile file of version %u; this build reads version %u",
              path, version, VERSION);
    goto done;
  }
  if (n < 8 + OC_SHA256_BYTES) {
    fail(&r, "truncated");
    goto done;
  }
  unsigned char d[OC_SHA256_BYTES];
  oc_sha256 h;
  oc_sha256_init(&h);
  oc_sha256_update(&h, buf, n - OC_SHA256_BYTES);
  oc_sha256_final(&h, d);
  if (memcmp(d, buf + n - OC_SHA256_BYTES, OC_SHA256_BYTES) != 0) {
    fail(&r, "damaged (its checksum does not match)");
    goto done;
  }
  r.n = n - OC_SHA256_BYTES;
  if (!(t = calloc(1, sizeof *t))) {
    oc_seterr(err, OC_ENOMEM, "out of memory reading '%s'", path);
    goto done;
  }
  oc_btile_params *pp = &t->pp;
  uint32_t type = get_u32(&r);
  double p1[3], p2[5];
  get_f64s(&r, p1, 3);
  uint64_t fractures = get_u64(&r);
  get_f64s(&r, p2, 5);
  uint64_t seed = get_u64(&r), ndiscs = get_u64(&r);
  uint64_t c[9];
  for (int i = 0; i < 9; i++)
    c[i] = get_u64(&r);
  get_f64s(&r, &t->seconds, 1);
  if (r.bad) goto done;
  if (type >= OC_BLOCKS_NTYPES || fractures > MAX_DISCS || ndiscs > MAX_DISCS) {
    fail(&r, "its parameters are out of range");
    goto done;
  }
  pp->type = (oc_block_type)type;
  pp->size = p1[0], pp->radius = p1[1], pp->neighbour = p1[2];
  pp->fractures = (size_t)fractures;
  pp->spacing = p2[0], pp->disc_lo = p2[1], pp->disc_hi = p2[2];
  pp->rounding = p2[3], pp->width = p2[4];
  pp->seed = seed;
  if (oc_btile_check(pp, err)) {
    char why[OC_ERRMSG];
    snprintf(why, sizeof why, "%s", err ? err->msg : "bad parameters");
    r.bad = 0;
    fail(&r, why);
    goto done;
  }
  pp->ndiscs = (size_t)ndiscs; /* (the discs are in t->disc) */
  /* counts: points, discs, blocks, edges, cut, thick, separated, merged,
  ** authored */
  if (c[0] > MAX_POINTS || c[1] > MAX_DISCS || c[2] > c[0] || c[8] > c[2] ||
      c[3] > 64 * c[0] || c[4] > c[3] || c[5] > c[2] || c[7] > c[0] ||
      c[6] > c[2] * c[2] || t->seconds < 0) {
    fail(&r, "its counts are out of range");
    goto done;
  }
  if (!have(&r, 8 * (3 * c[0] + 7 * c[1] + 13 * c[2]))) goto done;
  t->np = (size_t)c[0];
  t->nd = (size_t)c[1];
  t->g.ne = (size_t)c[3];
  t->gcut = (size_t)c[4];
  t->thick = (size_t)c[5];
  t->ncut = (size_t)c[6];
  t->merged = (size_t)c[7];
  t->nauth = (size_t)c[8]; /* the count only: t->auth is for building */
  t->pts = malloc((t->np ? t->np : 1) * 3 * sizeof *t->pts);
  t->disc = malloc((t->nd ? t->nd : 1) * sizeof *t->disc);
  t->block = calloc(c[2] ? c[2] : 1, sizeof *t->block);
  if (!t->pts || !t->disc || !t->block) {
    oc_seterr(err, OC_ENOMEM, "out of memory reading '%s'", path);
    r.bad = 1;
    goto done;
  }
  t->nb = t->ncl = (size_t)c[2];
  if (!get_f64s(&r, t->pts, 3 * t->np)) goto done;
  for (size_t i = 0; i < 3 * t->np; i++)
    if (!in_range(t->pts[i], 0, pp->size)) {
      fail(&r, "a point lies outside the tile");
      goto done;
    }
  for (size_t i = 0; i < t->nd; i++) {
    double v[7];
    if (!get_f64s(&r, v, 7)) goto done;
    double l = v[3] * v[3] + v[4] * v[4] + v[5] * v[5];
    if (fabs(l - 1) > 1e-9 || !(v[6] > 0)) {
      fail(&r, "a disc has no unit normal or radius");
      goto done;
    }
    t->disc[i] = (oc_bdisc){{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, v[6]};
  }
  if (!read_blocks(&r, t)) goto done;
  if (r.at != r.n)
    fail(&r, "bytes after the last block");
  else
    ok = 1;
done:
  free(buf);
  if (!ok) {
    oc_btile_free(t);
    return NULL;
  }
  return t;
}
