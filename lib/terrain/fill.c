/*
** fill.c — oc_heightfield_fill: depression filling by Priority-Flood+epsilon
** (Barnes, Lehman and Mulla 2014, algorithm 3).
**
** The flood starts from every border sample (water leaves the grid there)
** and grows inwards, always from the lowest sample reached so far. A
** neighbour not above the sample it is reached from lies in a depression:
** it is raised to the next float above that sample and continues the
** flood from a plain queue, so flats and filled lakes get the smallest
** gradient a float can hold, towards their outlet. Every interior sample
** then has a strictly lower neighbour (the one it was reached from), so
** water drains from everywhere to the border.
**
** Ties between equal elevations are broken by sample index (the heap key
** holds both), so the result does not depend on anything but the grid.
** Priority-Flood is sequential by nature; it touches each sample once and
** the heap holds only the flood's front, so it stays fast.
*/
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "terrain/analysis.h"

#define REPORT_EVERY (1u << 16)

/* A float's bits mapped so that unsigned order is numeric order, above
** the sample index: one 64-bit comparison orders by elevation then index. */
static uint64_t key(float z, uint32_t idx) {
  uint32_t b;
  z += 0.0f; /* -0 becomes +0 */
  memcpy(&b, &z, sizeof b);
  b = (b & 0x80000000u) ? ~b : b | 0x80000000u;
  return (uint64_t)b << 32 | idx;
}

typedef struct heap {
  uint64_t *a;
  size_t n;
} heap;

static void heap_push(heap *h, uint64_t k) {
  size_t i = h->n++;
  while (i > 0) {
    size_t p = (i - 1) / 2;
    if (h->a[p] <= k) break;
    h->a[i] = h->a[p];
    i = p;
  }
  h->a[i] = k;
}

static uint64_t heap_pop(heap *h) {
  uint64_t top = h->a[0], last = h->a[--h->n];
  size_t i = 0, n = h->n;
  for (;;) {
    size_t c = 2 * i + 1;
    if (c >= n) break;
    if (c + 1 < n && h->a[c + 1] < h->a[c]) c++;
    if (h->a[c] >= last) break;
    h->a[i] = h->a[c];
    i = c;
  }
  h->a[i] = last;
  return top;
}

int oc_heightfield_fill_samples(float *z, int nx, int ny,
                                const oc_heightfield_phase *ph, oc_error *err) {
  size_t n = (size_t)nx * (size_t)ny;
  /* Each sample enters the heap or the queue once: n entries bound both.
  ** Only the flood's front is ever touched, so the pages mostly stay
  ** unmapped. */
  heap h = {malloc(n * sizeof(uint64_t)), 0};
  uint32_t *pit = malloc(n * sizeof *pit);
  unsigned char *closed = calloc(n, 1);
  if (!h.a || !pit || !closed) {
    free(h.a);
    free(pit);
    free(closed);
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory filling a %d x %d heightfield", nx, ny);
  }
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1) {
        size_t c = (size_t)j * (size_t)nx + (size_t)i;
        closed[c] = 1;
        heap_push(&h, key(z[c], (uint32_t)c));
      }
  size_t head = 0, tail = 0, done = 0;
  int rc = OC_OK;
  while (h.n > 0 || head < tail) {
    uint32_t c;
    /* On a tie the heap goes first: its sample is not in a depression,
    ** and taking it now keeps the flood from running ahead over it. */
    if (head < tail && h.n > 0 &&
        (uint32_t)(h.a[0] >> 32) == (uint32_t)(key(z[pit[head]], 0) >> 32))
      c = (uint32_t)heap_pop(&h);
    else if (head < tail) {
      c = pit[head++];
      if (head == tail) head = tail = 0;
    } else
      c = (uint32_t)heap_pop(&h);
    float zc = z[c], up = nextafterf(zc, INFINITY);
    if (isinf(up)) up = zc; /* at FLT_MAX there is no room above */
    int i = (int)(c % (uint32_t)nx), j = (int)(c / (uint32_t)nx);
    for (int k = 0; k < 8; k++) {
      int a = i + oc_heightfield_di[k], b = j + oc_heightfield_dj[k];
      if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
      size_t m = (size_t)b * (size_t)nx + (size_t)a;
      if (closed[m]) continue;
      closed[m] = 1;
      if (z[m] <= up) {
        z[m] = up;
        pit[tail++] = (uint32_t)m;
      } else
        heap_push(&h, key(z[m], (uint32_t)m));
    }
    if (++done % REPORT_EVERY == 0 &&
        oc_heightfield_report(ph, (double)done / n)) {
      rc = oc_seterr(err, OC_ECANCEL, "filling cancelled");
      break;
    }
  }
  free(h.a);
  free(pit);
  free(closed);
  return rc;
}

oc_heightfield *oc_heightfield_fill(const oc_heightfield *hf,
                                    oc_progress progress, oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "filled needs a heightfield");
    return NULL;
  }
  double x0, y0;
  oc_heightfield_origin(hf, &x0, &y0);
  oc_heightfield *out = oc_heightfield_new(
      oc_heightfield_nx(hf), oc_heightfield_ny(hf), oc_heightfield_cell(hf), x0,
      y0, oc_heightfield_samples(hf), err);
  if (!out) return NULL;
  oc_heightfield_phase ph = {progress, 0, 1};
  int rc = oc_heightfield_fill_samples(oc_heightfield_samples_mut(out),
                                       oc_heightfield_nx(hf),
                                       oc_heightfield_ny(hf), &ph, err);
  if (rc == OC_OK && oc_heightfield_report(&ph, 1.0))
    rc = oc_seterr(err, OC_ECANCEL, "filling cancelled");
  if (rc != OC_OK) {
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}
