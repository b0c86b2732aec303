/*
** fcodec.c — the compact encoding of a feature curve, for storing scenes
** in the few kilobytes of Hnaidi et al. 2010, Table 1 (1.3–4.5 kB for 26
** to 74 curves).
**
** Version 2 (written): a bit stream, most significant bit first, padded
** with zero bits to a whole byte. Integers are Exp-Golomb codes of order
** k (EG_k: v + 2^k in binary, preceded by as many zeros as it has bits
** beyond k + 1), signed ones zigzag-coded first; each field has its own
** k, the size its values usually have.
**
**   111                 marker (version 1 starts with 'F', bits 010)
**   b                   1: Bezier pieces, 0: polyline
**   EG_0(n - 2)         n control points
**   EG_0(m)             m constraint points
**   s                   1: u_i = i / (m - 1) (evenly spaced, omitted)
**   x0 y0               first point, EG_14 signed, in 1/8 m
**   dx dy ...           the others: the change of the step from the
**                       previous step (second difference), EG_9 signed
**   per constraint point:
**     du                unless s: u from the previous, 1/4096, EG_10
**     has               4 bits, the OC_FC_* categories
**     e                 with a slope: 1 when right = left and b = a
**                       (the right side omitted)
**     values            each from the last value given for it, signed:
**                       height (1/8 m, EG_10), radius (1/8 m, EG_5),
**                       left, right (1/64 degree, EG_9), extents a, b
**                       (1/8 m, EG_8), amplitude (1/64 m, EG_8),
**                       roughness (1/1024, EG_8)
**
** Version 1 (still read): 'F' (2 n + bezier) x0 y0 dx dy ... m (du has
** values)..., LEB128 varints, coordinates, heights, radii, extents in
** 1/16 m, the rest as version 2 with plain differences.
**
** Decoding gives the quantised curve: its encoding is the same bytes
** again.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define QXY 16.0
#define QU 4096.0
#define LIMIT 0x1p52

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

static oc_fcurve *decode_v1(const unsigned char *buf, size_t n, oc_error *err) {
  rbuf r = {buf, n, 0, 0};
  get(&r); /* 'F' */
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

/* ---- version 2 ---- */

#define Q2XY 8.0
static const double q2attr[FA_COUNT] = {8, 8, 64, 64, 8, 8, 64, 1024};
static const int k2attr[FA_COUNT] = {10, 5, 9, 9, 8, 8, 8, 8};
#define K_XY0 14
#define K_DXY 9
#define K_U 10

typedef struct wbits {
  unsigned char *p;
  size_t cap;
  uint64_t n; /* bits written */
  int bad;
} wbits;

static void put_bit(wbits *w, unsigned v) {
  size_t at = (size_t)(w->n >> 3);
  if (at < w->cap) {
    if (!(w->n & 7)) w->p[at] = 0;
    if (v) w->p[at] |= (unsigned char)(0x80u >> (w->n & 7));
  }
  w->n++;
}

/* EG_k(v): v + 2^k in binary after as many zeros as it has bits beyond
** k + 1. */
static void put_eg(wbits *w, uint64_t v, int k) {
  uint64_t x = v + ((uint64_t)1 << k);
  int nb = 0;
  for (uint64_t t = x; t; t >>= 1)
    nb++;
  for (int i = 0; i < nb - k - 1; i++)
    put_bit(w, 0);
  for (int i = nb - 1; i >= 0; i--)
    put_bit(w, (unsigned)(x >> i) & 1);
}

static void put_seg(wbits *w, int64_t v, int k) {
  put_eg(w, ((uint64_t)v << 1) ^ (uint64_t)(v >> 63), k);
}

static int64_t quant2(wbits *w, double x, double q) {
  double v = nearbyint(x * q);
  if (!(fabs(v) < LIMIT)) {
    w->bad = 1;
    return 0;
  }
  return (int64_t)v;
}

/* Whether the constraint points' u are i / (m - 1) once quantised. */
static int even_u(const oc_fconstraint *k, size_t m) {
  if (m < 2) return 0;
  for (size_t i = 0; i < m; i++)
    if (nearbyint(k[i].u * QU) != nearbyint((double)i / (double)(m - 1) * QU))
      return 0;
  return 1;
}

size_t oc_fcurve_encode(const oc_fcurve *c, unsigned char *buf, size_t cap) {
  wbits w = {buf, buf ? cap : 0, 0, 0};
  for (int i = 0; i < 3; i++)
    put_bit(&w, 1);
  put_bit(&w, c->bezier != 0);
  put_eg(&w, c->npoints - 2, 0);
  put_eg(&w, c->nk, 0);
  int even = even_u(c->k, c->nk);
  put_bit(&w, (unsigned)even);
  int64_t px = 0, py = 0, sx = 0, sy = 0;
  for (size_t i = 0; i < c->npoints; i++) {
    int64_t x = quant2(&w, c->xy[2 * i], Q2XY),
            y = quant2(&w, c->xy[2 * i + 1], Q2XY);
    if (i == 0) {
      put_seg(&w, x, K_XY0);
      put_seg(&w, y, K_XY0);
    } else {
      put_seg(&w, (x - px) - sx, K_DXY);
      put_seg(&w, (y - py) - sy, K_DXY);
      sx = x - px, sy = y - py;
    }
    px = x, py = y;
  }
  int64_t pu = 0, last[FA_COUNT] = {0};
  for (size_t i = 0; i < c->nk; i++) {
    const oc_fconstraint *k = &c->k[i];
    if (!even) {
      int64_t u = quant2(&w, k->u, QU);
      put_seg(&w, u - pu, K_U);
      pu = u;
    }
    unsigned has = k->has & 15u;
    for (int b = 3; b >= 0; b--)
      put_bit(&w, (has >> b) & 1);
    int64_t q[FA_COUNT];
    for (int a = 0; a < FA_COUNT; a++)
      q[a] = (has & category(a)) ? quant2(&w, value(k, a), q2attr[a]) : 0;
    int same = 0;
    if (has & OC_FC_SLOPE) {
      same = q[FA_RIGHT] == q[FA_LEFT] && q[FA_EXTB] == q[FA_EXTA];
      put_bit(&w, (unsigned)same);
    }
    for (int a = 0; a < FA_COUNT; a++) {
      if (!(has & category(a))) continue;
      if (!(same && (a == FA_RIGHT || a == FA_EXTB)))
        put_seg(&w, q[a] - last[a], k2attr[a]);
      last[a] = q[a];
    }
  }
  return w.bad ? 0 : (size_t)((w.n + 7) >> 3);
}

typedef struct rbits {
  const unsigned char *p;
  uint64_t n, at; /* bits */
  int bad;
} rbits;

static unsigned get_bit(rbits *r) {
  if (r->at >= r->n) {
    r->bad = 1;
    return 0;
  }
  unsigned v = (r->p[r->at >> 3] >> (7 - (r->at & 7))) & 1u;
  r->at++;
  return v;
}

static uint64_t get_eg(rbits *r, int k) {
  int z = 0;
  while (!get_bit(r)) {
    if (r->bad || ++z > 56) {
      r->bad = 1;
      return 0;
    }
  }
  uint64_t x = 1;
  for (int i = 0; i < z + k; i++)
    x = (x << 1) | get_bit(r);
  return x - ((uint64_t)1 << k);
}

static int64_t get_seg(rbits *r, int k) {
  uint64_t v = get_eg(r, k);
  return (int64_t)(v >> 1) ^ -(int64_t)(v & 1);
}

static oc_fcurve *decode_v2(const unsigned char *buf, size_t n, oc_error *err) {
  rbits r = {buf, (uint64_t)n * 8, 3, 0};
  oc_fcurve_params p = {0};
  p.bezier = (int)get_bit(&r);
  uint64_t np = get_eg(&r, 0) + 2, nk = get_eg(&r, 0);
  int even = (int)get_bit(&r);
  if (r.bad || np > (1u << 20) || np > n * 8) {
    oc_seterr(err, OC_EINVAL, "feature curve encoding: bad point count");
    return NULL;
  }
  if (nk > (1u << 20) || nk > n * 8 || (even && nk < 2)) {
    oc_seterr(err, OC_EINVAL, "feature curve encoding: bad constraint count");
    return NULL;
  }
  double *xy = malloc(2 * np * sizeof *xy);
  oc_fconstraint *k = calloc(nk ? nk : 1, sizeof *k);
  oc_fcurve *c = NULL;
  if (!xy || !k) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    goto done;
  }
  int64_t x = 0, y = 0, sx = 0, sy = 0;
  for (uint64_t i = 0; i < np; i++) {
    if (i == 0) {
      x = get_seg(&r, K_XY0), y = get_seg(&r, K_XY0);
    } else {
      sx += get_seg(&r, K_DXY), sy += get_seg(&r, K_DXY);
      x += sx, y += sy;
    }
    xy[2 * i] = x / Q2XY, xy[2 * i + 1] = y / Q2XY;
  }
  int64_t u = 0, last[FA_COUNT] = {0};
  for (uint64_t i = 0; i < nk && !r.bad; i++) {
    if (even) {
      k[i].u = (double)i / (double)(nk - 1);
    } else {
      u += get_seg(&r, K_U);
      k[i].u = u / QU;
    }
    unsigned has = 0;
    for (int b = 0; b < 4; b++)
      has = (has << 1) | get_bit(&r);
    k[i].has = has;
    int same = (has & OC_FC_SLOPE) ? (int)get_bit(&r) : 0;
    for (int a = 0; a < FA_COUNT; a++) {
      if (!(has & category(a))) continue;
      if (same && a == FA_RIGHT)
        last[a] = last[FA_LEFT];
      else if (same && a == FA_EXTB)
        last[a] = last[FA_EXTA];
      else
        last[a] += get_seg(&r, k2attr[a]);
      set_value(&k[i], a, last[a] / q2attr[a]);
    }
  }
  /* the padding: fewer than 8 bits, all zero */
  int pad_ok = !r.bad && r.n - r.at < 8;
  while (pad_ok && r.at < r.n)
    pad_ok = !get_bit(&r);
  if (!pad_ok) {
    oc_seterr(err, OC_EINVAL,
              "feature curve encoding: truncated or trailing bytes");
    goto done;
  }
  p.xy = xy, p.npoints = np, p.constraints = k, p.nconstraints = nk;
  c = oc_fcurve_new(&p, err);
done:
  free(xy);
  free(k);
  return c;
}

oc_fcurve *oc_fcurve_decode(const unsigned char *buf, size_t n, oc_error *err) {
  if (buf && n && buf[0] == 'F') return decode_v1(buf, n, err);
  if (buf && n && (buf[0] & 0xe0) == 0xe0) return decode_v2(buf, n, err);
  oc_seterr(err, OC_EINVAL, "not a feature curve encoding (version 1 or 2)");
  return NULL;
}
