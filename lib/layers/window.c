/*
** window.c — local edits: a rectangle of stacks copied out as a grid of
** its own, and spliced back (one copy of the layers, no re-encoding), so
** that tools and their stabilisation cost what their region holds, not
** the whole grid. The stabilisation of a region runs in a window around
** it, grown (doubled) and run again from the same state while any stack
** on the window's border changed, so the result is the one the whole
** grid would give whenever the material stays inside.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "layers/layers.h"

oc_stacks *oc_stacks_window(const oc_stacks *s, int i0, int j0, int i1, int j1,
                            oc_error *err) {
  int nx = i1 - i0 + 1, ny = j1 - j0 + 1;
  oc_stacks *w = oc_stacks_alloc(nx, ny, s->cell, s->x0 + i0 * s->cell,
                                 s->y0 + j0 * s->cell, s->zbase, err);
  if (!w) return NULL;
  size_t n = 0;
  for (int j = j0; j <= j1; j++)
    n += oc_soff(s, (size_t)j * s->nx + i1 + 1) -
         oc_soff(s, (size_t)j * s->nx + i0);
  uint32_t *off = malloc(((size_t)nx * ny + 1) * sizeof *off);
  w->lay = malloc((n ? n : 1) * sizeof *w->lay);
  w->cap = n ? n : 1;
  if (!off || !w->lay) {
    free(off);
    oc_stacks_free(w);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  size_t at = 0, k = 0;
  off[0] = 0;
  for (int j = j0; j <= j1; j++) {
    size_t a = (size_t)j * s->nx + i0;
    size_t l0 = oc_soff(s, a), l1 = oc_soff(s, a + nx);
    memcpy(w->lay + at, s->lay + l0, (l1 - l0) * sizeof *w->lay);
    for (int i = 0; i < nx; i++, k++)
      off[k + 1] = (uint32_t)(off[k] + oc_scount(s, a + i));
    at += l1 - l0;
  }
  oc_stacks_take_offsets(w, off);
  return w;
}

int oc_stacks_splice(oc_stacks *s, const oc_stacks *w, int i0, int j0,
                     oc_error *err) {
  size_t ns = (size_t)s->nx * s->ny, old = 0;
  for (int j = j0; j < j0 + w->ny; j++)
    old += oc_soff(s, (size_t)j * s->nx + i0 + w->nx) -
           oc_soff(s, (size_t)j * s->nx + i0);
  size_t total = oc_soff(s, ns) - old + oc_soff(w, (size_t)w->nx * w->ny);
  if (total > OC_STACKS_MAX_LAYERS)
    return oc_seterr(err, OC_ENOMEM, "more than %llu layers",
                     (unsigned long long)OC_STACKS_MAX_LAYERS);
  uint32_t *off = malloc((ns + 1) * sizeof *off);
  uint32_t *lay = malloc((total ? total : 1) * sizeof *lay);
  if (!off || !lay) {
    free(off);
    free(lay);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  size_t at = 0;
  off[0] = 0;
  /* copies stacks [a, b) of g (whose offsets are go) to the end */
#define RUN(g, a, b)                                                           \
  do {                                                                         \
    size_t l0 = oc_soff(g, a), l1 = oc_soff(g, b);                             \
    memcpy(lay + at, (g)->lay + l0, (l1 - l0) * sizeof *lay);                  \
    for (size_t q = (a); q < (b); q++, k++)                                    \
      off[k + 1] = (uint32_t)(off[k] + oc_scount(g, q));                       \
    at += l1 - l0;                                                             \
  } while (0)
  size_t k = 0;
  size_t top = (size_t)j0 * s->nx, bot = (size_t)(j0 + w->ny) * s->nx;
  RUN(s, 0, top);
  for (int j = 0; j < w->ny; j++) {
    size_t r = (size_t)(j0 + j) * s->nx;
    RUN(s, r, r + i0);
    RUN(w, (size_t)j * w->nx, (size_t)(j + 1) * w->nx);
    RUN(s, r + i0 + w->nx, r + s->nx);
  }
  RUN(s, bot, ns);
#undef RUN
  free(s->lay);
  oc_stacks_take_offsets(s, off);
  s->lay = lay;
  s->cap = total ? total : 1;
  return OC_OK;
}

/* Whether the stacks of a and b (same shape) within the longest stride of
** the border differ: material that reached them might have gone on
** past the window. */
static int border_changed(const oc_stacks *a, const oc_stacks *b) {
  const int B = OC_LAYERS_STRIDE_MAX;
  for (int j = 0; j < a->ny; j++)
    for (int i = 0; i < a->nx; i++) {
      if (j >= B && j < a->ny - B && i >= B && i < a->nx - B) i = a->nx - B;
      size_t k = (size_t)j * a->nx + i;
      size_t n = oc_scount(a, k);
      if (n != oc_scount(b, k) ||
          memcmp(a->lay + oc_soff(a, k), b->lay + oc_soff(b, k),
                 n * sizeof *a->lay))
        return 1;
    }
  return 0;
}

int oc_layers_stabilize_local(oc_stacks *s, const oc_stabilize_params *p,
                              oc_stabilize_result *res, oc_error *err) {
  const int *r = p->region;
  int m = r[2] - r[0] > r[3] - r[1] ? r[2] - r[0] : r[3] - r[1];
  m = m < 8 ? 8 : m;
  for (;;) {
    int i0 = r[0] - m < 0 ? 0 : r[0] - m, j0 = r[1] - m < 0 ? 0 : r[1] - m;
    int i1 = r[2] + m >= s->nx ? s->nx - 1 : r[2] + m;
    int j1 = r[3] + m >= s->ny ? s->ny - 1 : r[3] + m;
    int whole = i0 == 0 && j0 == 0 && i1 == s->nx - 1 && j1 == s->ny - 1;
    oc_stacks *w = oc_stacks_window(s, i0, j0, i1, j1, err);
    if (!w) return OC_ENOMEM;
    oc_stabilize_params q = *p;
    q.region[0] = r[0] - i0;
    q.region[1] = r[1] - j0;
    q.region[2] = r[2] - i0;
    q.region[3] = r[3] - j0;
    oc_stacks *w0 = whole ? NULL : oc_stacks_window(s, i0, j0, i1, j1, err);
    int rc = whole || w0 ? oc_stacks_stabilize(w, &q, res, err) : OC_ENOMEM;
    if (rc == OC_OK && !whole && border_changed(w, w0)) {
      oc_stacks_free(w);
      oc_stacks_free(w0);
      m *= 2;
      continue;
    }
    if (rc == OC_OK) rc = oc_stacks_splice(s, w, i0, j0, err);
    oc_stacks_free(w);
    oc_stacks_free(w0);
    return rc;
  }
}
