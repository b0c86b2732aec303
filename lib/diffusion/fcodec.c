/*
** fcodec.c — the compact encoding of a feature curve, for storing scenes
** in the few kilobytes of Hnaidi et al. 2010, Table 1 (1.3–4.5 kB for 26
** to 74 curves). Bytes:
**
**   'F' (2 n + bezier) x0 y0 dx dy ...  m  (du has values)...
**
** ('F' marks version 1) every number a LEB128 varint, signed ones
** zigzag-coded: coordinates in 1/16 m, each point as the difference from
** the previous one; per constraint point the difference of u (in 1/4096)
** from the previous point's, the category bits, and each value the point gives
*as the
** difference from the last value given for it (heights, radii and
** extents in 1/16 m, angles in 1/64 degree, amplitudes in 1/64 m,
** roughness in 1/1024), so constant attributes cost a byte. Decoding
** gives the quantised curve: its encoding is the same bytes again.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define QXY 16.0
#define QU 4096.0
#define LIMIT 0x1p52

typedef struct wbuf {
  unsigned char *p;
  size_t cap, n;
  int bad;
} wbuf;

static void put(wbuf *w, uint64_t v) {
  do {
    unsigned char b = v & 0x7f;
    v >>= 7;
    if (v) b |= 0x80;
    if (w->n < w->cap) w->p[w->n] = b;
    w->n++;
  } while (v);
}

static void put_signed(wbuf *w, int64_t v) {
  put(w, ((uint64_t)v << 1) ^ (uint64_t)(v >> 63));
}

static int64_t quant(wbuf *w, double x, double q) {
  double v = nearbyint(x * q);
  if (!(fabs(v) < LIMIT)) {
    w->bad = 1;
    return 0;
  }
  return (int64_t)v;
}

/* The quantum of attribute a and its value at constraint k. */
static const double qattr[FA_COUNT] = {16, 16, 64, 64, 16, 16, 64, 1024};

static double value(const oc_fconstraint *k, int a) {
  const double v[FA_COUNT] = {k->height,    k->radius,   k->left,
                              k->right,     k->extent_a, k->extent_b,
                              k->amplitude, k->roughness};
  return v[a];
}

static unsigned category(int a) {
  static const unsigned cat[FA_COUNT] = {
      OC_FC_HEIGHT, OC_FC_RADIUS, OC_FC_SLOPE, OC_FC_SLOPE,
      OC_FC_SLOPE,  OC_FC_SLOPE,  OC_FC_NOISE, OC_FC_NOISE};
  return cat[a];
}

size_t oc_fcurve_encode(const oc_fcurve *c, unsigned char *buf, size_t cap) {
  wbuf w = {buf, buf ? cap : 0, 0, 0};
  put(&w, 'F');
  put(&w, 2 * (uint64_t)c->npoints + (uint64_t)c->bezier);
  int64_t px = 0, py = 0;
  for (size_t i = 0; i < c->npoints; i++) {
    int64_t x = quant(&w, c->xy[2 * i], QXY),
            y = quant(&w, c->xy[2 * i + 1], QXY);
    put_signed(&w, x - px);
    put_signed(&w, y - py);
    px = x, py = y;
  }
  put(&w, c->nk);
  int64_t pu = 0, last[FA_COUNT] = {0};
  for (size_t i = 0; i < c->nk; i++) {
    const oc_fconstraint *k = &c->k[i];
    int64_t u = quant(&w, k->u, QU);
    put_signed(&w, u - pu);
    pu = u;
    put(&w, k->has);
    for (int a = 0; a < FA_COUNT; a++) {
      if (!(k->has & category(a))) continue;
      int64_t v = quant(&w, value(k, a), qattr[a]);
      put_signed(&w, v - last[a]);
      last[a] = v;
    }
  }
  return w.bad ? 0 : w.n;
}

typedef struct rbuf {
  const unsigned char *p;
  size_t n, at;
  int bad;
} rbuf;

static uint64_t get(rbuf *r) {
  uint64_t v = 0;
  for (int s = 0; s < 64; s += 7) {
    if (r->at >= r->n) break;
    unsigned char b = r->p[r->at++];
    v |= (uint64_t)(b & 0x7f) << s;
    if (!(b & 0x80)) return v;
  }
  r->bad = 1;
  return 0;
}

static int64_t get_signed(rbuf *r) {
  uint64_t v = get(r);
  return (int64_t)(v >> 1) ^ -(int64_t)(v & 1);
}

static void set_value(oc_fconstraint *k, int a, double v) {
  double *f[FA_COUNT] = {&k->height,    &k->radius,   &k->left,
                         &k->right,     &k->extent_a, &k->extent_b,
                         &k->amplitude, &k->roughness};
  *f[a] = v;
}

oc_fcurve *oc_fcurve_decode(const unsigned char *buf, size_t n, oc_error *err) {
  rbuf r = {buf, buf ? n : 0, 0, 0};
  if (get(&r) != 'F') {
    oc_seterr(err, OC_EINVAL, "not a feature curve encoding (version 1)");
    return NULL;
  }
  oc_fcurve_params p = {0};
  uint64_t np = get(&r);
  p.bezier = (int)(np & 1);
  np >>= 1;
  if (r.bad || np < 2 || np > (1u << 20) || np * 2 > n * 8) {
    oc_seterr(err, OC_EINVAL, "feature curve encoding: bad point count");
    return NULL;
  }
  double *xy = malloc(2 * np * sizeof *xy);
  oc_fconstraint *k = NULL;
  oc_fcurve *c = NULL;
  if (!xy) goto nomem;
  int64_t x = 0, y = 0;
  for (uint64_t i = 0; i < np; i++) {
    x += get_signed(&r), y += get_signed(&r);
    xy[2 * i] = x / QXY, xy[2 * i + 1] = y / QXY;
  }
  uint64_t nk = get(&r);
  if (r.bad || nk > (1u << 20) || nk > n) {
    oc_seterr(err, OC_EINVAL, "feature curve encoding: bad constraint count");
    goto fail;
  }
  k = calloc(nk ? nk : 1, sizeof *k);
  if (!k) goto nomem;
  int64_t u = 0, last[FA_COUNT] = {0};
  for (uint64_t i = 0; i < nk; i++) {
    u += get_signed(&r);
    k[i].u = u / QU;
    k[i].has = (unsigned)get(&r);
    for (int a = 0; a < FA_COUNT; a++) {
      if (!(k[i].has & category(a))) continue;
      last[a] += get_signed(&r);
      set_value(&k[i], a, last[a] / qattr[a]);
    }
  }
  if (r.bad || r.at != r.n) {
    oc_seterr(err, OC_EINVAL,
              "feature curve encoding: truncated or trailing "
              "bytes");
    goto fail;
  }
  p.xy = xy, p.npoints = np, p.constraints = k, p.nconstraints = nk;
  c = oc_fcurve_new(&p, err);
  goto fail;
nomem:
  oc_seterr(err, OC_ENOMEM, "out of memory");
fail:
  free(xy);
  free(k);
  return c;
}
