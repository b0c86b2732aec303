/*
** stacks.c — the material-stack grid (Peytavie et al. 2009, section 3.2):
** creation, the builder that packs stacks in order, reading and replacing
** one stack, statistics, volumes and the top of a material as a
** heightfield.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "field/kind.h"
#include "layers/layers.h"

static const char *const NAMES[OC_MAT_COUNT] = {"air", "water", "sand", "rocks",
                                                "bedrock"};

const char *oc_material_name(int m) {
  return m >= 0 && m < OC_MAT_COUNT ? NAMES[m] : NULL;
}

int oc_material_parse(const char *name) {
  for (int m = 0; name && m < OC_MAT_COUNT; m++)
    if (strcmp(name, NAMES[m]) == 0) return m;
  return -1;
}

oc_stacks *oc_stacks_alloc(int nx, int ny, double cell, double x0, double y0,
                           double zbase, oc_error *err) {
  if (nx < 1 || ny < 1 || nx > 65535 || ny > 65535 ||
      (unsigned long long)nx * (unsigned long long)ny > OC_STACKS_MAX) {
    oc_seterr(err, OC_EINVAL,
              "'size' must be 1 .. 65535 stacks a side and at most %llu in "
              "all (got %d x %d)",
              (unsigned long long)OC_STACKS_MAX, nx, ny);
    return NULL;
  }
  if (!oc_check_positive(cell, "cell", err)) return NULL;
  if (!isfinite(x0) || !isfinite(y0)) {
    oc_seterr(err, OC_EINVAL, "'origin' must be finite");
    return NULL;
  }
  if (!isfinite(zbase)) {
    oc_seterr(err, OC_EINVAL, "'base' must be finite (got %g)", zbase);
    return NULL;
  }
  oc_stacks *s = calloc(1, sizeof *s);
  if (!s) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  *s = (oc_stacks){nx, ny, cell, x0, y0, zbase, NULL, NULL, NULL, NULL, 0};
  return s;
}

oc_stacks *oc_stacks_new(int nx, int ny, double cell, double x0, double y0,
                         double zbase, oc_error *err) {
  oc_stacks *s = oc_stacks_alloc(nx, ny, cell, x0, y0, zbase, err);
  if (!s) return NULL;
  uint32_t *off = calloc((size_t)nx * ny + 1, sizeof *off);
  /* never NULL, as in grids made otherwise: the tools copy and compare
  ** ranges of it, empty ones too */
  s->lay = malloc(sizeof *s->lay);
  if (!off || !s->lay) {
    free(off);
    free(s->lay);
    free(s);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  s->cap = 1;
  oc_stacks_take_offsets(s, off);
  return s;
}

void oc_stacks_free(oc_stacks *s) {
  if (!s) return;
  free(s->off);
  free(s->cnt);
  free(s->base);
  free(s->lay);
  free(s);
}

int oc_stacks_nx(const oc_stacks *s) {
  return s->nx;
}
int oc_stacks_ny(const oc_stacks *s) {
  return s->ny;
}
double oc_stacks_cell(const oc_stacks *s) {
  return s->cell;
}
void oc_stacks_origin(const oc_stacks *s, double *x0, double *y0) {
  *x0 = s->x0;
  *y0 = s->y0;
}
double oc_stacks_base(const oc_stacks *s) {
  return s->zbase;
}

/* ---- the builder ------------------------------------------------------- */

int oc_builder_init(oc_stacks_builder *b, size_t nstacks, size_t cap,
                    oc_error *err) {
  memset(b, 0, sizeof *b);
  b->nstacks = nstacks;
  b->cap = cap < 16 ? 16 : cap;
  b->off = malloc((nstacks + 1) * sizeof *b->off);
  b->lay = malloc(b->cap * sizeof *b->lay);
  if (!b->off || !b->lay) {
    oc_builder_free(b);
    return oc_seterr(err, OC_ENOMEM, "out of memory");
  }
  b->off[0] = 0;
  return OC_OK;
}

int oc_builder_push(oc_stacks_builder *b, const oc_layer *l, size_t n,
                    oc_error *err) {
  if (b->n + n > OC_STACKS_MAX_LAYERS)
    return oc_seterr(err, OC_ENOMEM, "more than %llu layers",
                     (unsigned long long)OC_STACKS_MAX_LAYERS);
  if (b->n + n > b->cap) {
    size_t cap = b->cap;
    while (cap < b->n + n)
      cap += cap / 2;
    uint32_t *t = realloc(b->lay, cap * sizeof *t);
    if (!t) return oc_seterr(err, OC_ENOMEM, "out of memory");
    b->lay = t;
    b->cap = cap;
  }
  for (size_t i = 0; i < n; i++)
    b->lay[b->n + i] = oc_lay_pack(l[i].t, l[i].m);
  b->n += n;
  b->off[++b->k] = (uint32_t)b->n;
  return OC_OK;
}

void oc_stacks_take_offsets(oc_stacks *s, uint32_t *off) {
  size_t ns = (size_t)s->nx * s->ny, nb = ns / OC_SBLOCK + 1;
  int narrow = 1;
  for (size_t k = 0; k < ns && narrow; k++)
    narrow = off[k + 1] - off[k] <= 255;
  uint8_t *cnt = narrow ? malloc(ns) : NULL;
  uint32_t *base = cnt ? malloc(nb * sizeof *base) : NULL;
  free(s->off);
  free(s->cnt);
  free(s->base);
  s->off = NULL;
  s->cnt = NULL;
  s->base = NULL;
  if (!base) { /* a stack too tall for a byte (or no memory): as given */
    free(cnt);
    s->off = off;
    return;
  }
  for (size_t k = 0; k < ns; k++)
    cnt[k] = (uint8_t)(off[k + 1] - off[k]);
  for (size_t q = 0; q < nb; q++)
    base[q] = off[q * OC_SBLOCK];
  free(off);
  s->cnt = cnt;
  s->base = base;
}

void oc_builder_commit(oc_stacks_builder *b, oc_stacks *s) {
  free(s->lay);
  oc_stacks_take_offsets(s, b->off);
  s->lay = b->lay;
  s->cap = b->cap;
  memset(b, 0, sizeof *b);
}

void oc_builder_free(oc_stacks_builder *b) {
  free(b->off);
  free(b->lay);
  memset(b, 0, sizeof *b);
}

/* ---- one stack ---------------------------------------------------------- */

static int check_ij(const oc_stacks *s, int i, int j, oc_error *err) {
  if (i < 0 || i >= s->nx)
    return oc_seterr(err, OC_EINVAL, "'i' must be in 0 .. %d (got %d)",
                     s->nx - 1, i);
  if (j < 0 || j >= s->ny)
    return oc_seterr(err, OC_EINVAL, "'j' must be in 0 .. %d (got %d)",
                     s->ny - 1, j);
  return OC_OK;
}

static int check_layers(const uint8_t *mat, const double *thick, size_t n,
                        oc_error *err) {
  if (n > OC_STACKS_MAX_LAYERS)
    return oc_seterr(err, OC_EINVAL, "too many layers (%zu)", n);
  for (size_t l = 0; l < n; l++) {
    if (mat[l] >= OC_MAT_COUNT)
      return oc_seterr(err, OC_EINVAL,
                       "'material' of layer %zu is not a material (%d)", l + 1,
                       mat[l]);
    if (!isfinite(thick[l]) || thick[l] < 0)
      return oc_seterr(err, OC_EINVAL,
                       "'thickness' of layer %zu must be finite and >= 0 "
                       "(got %g)",
                       l + 1, thick[l]);
  }
  return OC_OK;
}

int oc_stacks_fill(oc_stacks *s, const uint8_t *mat, const double *thick,
                   size_t n, oc_error *err) {
  if (check_layers(mat, thick, n, err)) return OC_EINVAL;
  oc_layer *in = malloc((2 * n + 1) * sizeof *in);
  if (!in) return oc_seterr(err, OC_ENOMEM, "out of memory");
  for (size_t l = 0; l < n; l++)
    in[l] = (oc_layer){thick[l], mat[l]};
  size_t m = oc_layers_canon(in, n, in + n), ns = (size_t)s->nx * s->ny;
  oc_stacks_builder b = {0};
  int rc = (double)m * ns > (double)OC_STACKS_MAX_LAYERS
               ? oc_seterr(err, OC_ENOMEM, "more than %llu layers",
                           (unsigned long long)OC_STACKS_MAX_LAYERS)
               : oc_builder_init(&b, ns, m * ns, err);
  for (size_t k = 0; k < ns && rc == OC_OK; k++)
    rc = oc_builder_push(&b, in + n, m, err);
  if (rc == OC_OK)
    oc_builder_commit(&b, s);
  else if (b.off)
    oc_builder_free(&b);
  free(in);
  return rc;
}

int oc_stacks_set(oc_stacks *s, int i, int j, const uint8_t *mat,
                  const double *thick, size_t n, oc_error *err) {
  if (check_ij(s, i, j, err)) return OC_EINVAL;
  if (check_layers(mat, thick, n, err)) return OC_EINVAL;
  oc_layer *in = malloc((2 * n + 1) * sizeof *in);
  if (!in) return oc_seterr(err, OC_ENOMEM, "out of memory");
  oc_layer *out = in + n;
  for (size_t l = 0; l < n; l++)
    in[l] = (oc_layer){thick[l], mat[l]};
  size_t m = oc_layers_canon(in, n, out);
  size_t k = (size_t)j * s->nx + i, ns = (size_t)s->nx * s->ny;
  size_t old = oc_scount(s, k), total = oc_soff(s, ns) - old + m;
  if (total > OC_STACKS_MAX_LAYERS) {
    free(in);
    return oc_seterr(err, OC_ENOMEM, "more than %llu layers",
                     (unsigned long long)OC_STACKS_MAX_LAYERS);
  }
  if (total > s->cap) {
    size_t cap = total + total / 2 + 16;
    uint32_t *t = realloc(s->lay, cap * sizeof *t);
    if (!t) {
      free(in);
      return oc_seterr(err, OC_ENOMEM, "out of memory");
    }
    s->lay = t;
    s->cap = cap;
  }
  /* a count that no longer fits a byte: the offsets in full from now */
  if (!s->off && m > 255) {
    uint32_t *off = malloc((ns + 1) * sizeof *off);
    if (!off) {
      free(in);
      return oc_seterr(err, OC_ENOMEM, "out of memory");
    }
    off[0] = 0;
    for (size_t q = 0; q < ns; q++)
      off[q + 1] = (uint32_t)(off[q] + s->cnt[q]);
    free(s->cnt);
    free(s->base);
    s->cnt = NULL;
    s->base = NULL;
    s->off = off;
  }
  size_t at = oc_soff(s, k), tail = oc_soff(s, ns) - at - old;
  memmove(s->lay + at + m, s->lay + at + old, tail * sizeof *s->lay);
  for (size_t l = 0; l < m; l++)
    s->lay[at + l] = oc_lay_pack(out[l].t, out[l].m);
  if (s->off) {
    for (size_t q = k + 1; q <= ns; q++)
      s->off[q] = (uint32_t)(s->off[q] - old + m);
  } else {
    s->cnt[k] = (uint8_t)m;
    for (size_t q = k / OC_SBLOCK + 1; q <= ns / OC_SBLOCK; q++)
      s->base[q] = (uint32_t)(s->base[q] - old + m);
  }
  free(in);
  return OC_OK;
}

size_t oc_stacks_get(const oc_stacks *s, int i, int j, uint8_t *mat,
                     double *thick, size_t max) {
  if (i < 0 || i >= s->nx || j < 0 || j >= s->ny) return 0;
  size_t k = (size_t)j * s->nx + i, n = oc_scount(s, k), o = oc_soff(s, k);
  for (size_t l = 0; l < n && l < max; l++) {
    if (mat) mat[l] = (uint8_t)oc_lay_m(s->lay[o + l]);
    if (thick) thick[l] = oc_lay_t(s->lay[o + l]);
  }
  return n;
}

/* ---- summaries ---------------------------------------------------------- */

void oc_stacks_get_stats(const oc_stacks *s, oc_stacks_stats *st) {
  size_t ns = (size_t)s->nx * s->ny;
  st->stacks = ns;
  st->layers = oc_soff(s, ns);
  st->bytes = sizeof *s +
              (s->off ? (ns + 1) * sizeof *s->off
                      : ns + (ns / OC_SBLOCK + 1) * sizeof *s->base) +
              st->layers * sizeof *s->lay;
}

double oc_stacks_volume(const oc_stacks *s, int m) {
  size_t n = oc_soff(s, (size_t)s->nx * s->ny);
  double v = 0;
  for (size_t l = 0; l < n; l++)
    if (oc_lay_m(s->lay[l]) == m) v += oc_lay_t(s->lay[l]);
  return v * s->cell * s->cell;
}

oc_heightfield *oc_stacks_heightfield(const oc_stacks *s, int m,
                                      oc_error *err) {
  if (!oc_material_name(m)) {
    oc_seterr(err, OC_EINVAL, "'material' is not a material (%d)", m);
    return NULL;
  }
  oc_heightfield *hf =
      oc_heightfield_new(s->nx, s->ny, s->cell, s->x0, s->y0, NULL, err);
  if (!hf) return NULL;
  float *z = oc_heightfield_samples_mut(hf);
  size_t ns = (size_t)s->nx * s->ny;
  for (size_t k = 0; k < ns; k++) {
    double h = s->zbase, top = s->zbase;
    for (size_t l = oc_soff(s, k), lend = l + oc_scount(s, k); l < lend; l++) {
      h += oc_lay_t(s->lay[l]);
      if (oc_lay_m(s->lay[l]) == m) top = h;
    }
    z[k] = (float)top;
  }
  return hf;
}
