/*
** convert.c — material stacks from a heightfield (bedrock under the
** surface, optional sand cover) and from any compiled field (every
** f = T crossing along each stack's axis: caves and arches of an implicit
** tree become air layers). Peytavie et al. 2009, sections 3.2 and 7.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/error.h"
#include "field/kind.h"
#include "layers/layers.h"

oc_stacks *oc_stacks_from_heightfield(const oc_heightfield *hf,
                                      const oc_stacks_hf_params *p,
                                      oc_error *err) {
  double lo, hi, x0, y0, sand = p ? p->sand : 0;
  oc_heightfield_minmax(hf, &lo, &hi);
  double zbase = p && !isnan(p->zbase) ? p->zbase : lo - 1;
  if (!isfinite(zbase)) {
    oc_seterr(err, OC_EINVAL, "'base' must be finite (got %g)", zbase);
    return NULL;
  }
  if (!(sand >= 0) || !isfinite(sand)) {
    oc_seterr(err, OC_EINVAL, "'sand' must be finite and >= 0 (got %g)", sand);
    return NULL;
  }
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  oc_stacks *s =
      oc_stacks_alloc(nx, ny, oc_heightfield_cell(hf), x0, y0, zbase, err);
  if (!s) return NULL;
  size_t ns = (size_t)nx * ny;
  oc_stacks_builder b;
  if (oc_builder_init(&b, ns, ns * (sand > 0 ? 2 : 1), err)) {
    oc_stacks_free(s);
    return NULL;
  }
  const float *z = oc_heightfield_samples(hf);
  for (size_t k = 0; k < ns; k++) {
    oc_layer l[2] = {{z[k] - zbase, OC_MAT_BEDROCK}, {sand, OC_MAT_SAND}}, c[2];
    if (oc_builder_push(&b, c, oc_layers_canon(l, 2, c), err)) {
      oc_builder_free(&b);
      oc_stacks_free(s);
      return NULL;
    }
  }
  oc_builder_commit(&b, s);
  return s;
}

/* ---- from a field ------------------------------------------------------- */

#define MAX_SPANS 64

/* A row's layers, gathered by one thread. */
typedef struct row {
  oc_layer *l;
  size_t n, cap;
  uint32_t *count; /* per stack of the row */
  int fail;
} row;

static void row_add(row *r, double t, int m) {
  if (r->fail) return;
  if (r->n == r->cap) {
    size_t cap = r->cap ? 2 * r->cap : 64;
    oc_layer *l = realloc(r->l, cap * sizeof *l);
    if (!l) {
      r->fail = 1;
      return;
    }
    r->l = l;
    r->cap = cap;
  }
  r->l[r->n++] = (oc_layer){t, m};
}

/* z in (a, b) where f crosses T, f(a) > T != f(b) > T. */
static double bisect(const oc_program *P, double x, double y, double a,
                     double b, double T, double eps) {
  int ina = oc_program_eval(P, (oc_vec3){x, y, a}) > T;
  for (int it = 0; it < 100 && b - a > eps; it++) {
    double m = 0.5 * (a + b);
    if ((oc_program_eval(P, (oc_vec3){x, y, m}) > T) == ina)
      a = m;
    else
      b = m;
  }
  return 0.5 * (a + b);
}

/* The crossings along one column, appended as alternating layers. */
static void column(const oc_program *P, const oc_stacks_node_params *p,
                   double x, double y, row *r) {
  double T = oc_program_threshold(P), z0 = p->box.lo.z, z1 = p->box.hi.z;
  double step = p->step > 0 ? p->step : p->cell / 4, eps = 1e-6 * p->cell;
  oc_zspan sp[MAX_SPANS];
  int ns = oc_program_column_spans(P, x, y, x, y, sp, MAX_SPANS);
  if (ns < 0) {
    sp[0] = (oc_zspan){z0, z1};
    ns = 1;
  }
  size_t first = r->n;
  double z = z0; /* the current layer's bottom */
  int in = oc_program_eval(P, (oc_vec3){x, y, z0}) > T;
  for (int k = 0; k < ns; k++) {
    double a = fmax(sp[k].lo, z0), b = fmin(sp[k].hi, z1);
    if (!(a < b)) continue;
    /* f is constant between spans: a crossing there is at the span's
    ** edge, found by the sampling that starts at it */
    double za = a;
    int ia = oc_program_eval(P, (oc_vec3){x, y, za}) > T;
    if (ia != in) { /* changed across the gap before this span */
      row_add(r, za - z, in ? p->material : OC_MAT_AIR);
      z = za;
      in = ia;
    }
    long nstep = (long)ceil((b - a) / step);
    for (long q = 1; q <= nstep; q++) {
      double zb = q == nstep ? b : a + q * step;
      int ib = oc_program_eval(P, (oc_vec3){x, y, zb}) > T;
      if (ib != in) {
        double c = bisect(P, x, y, za, zb, T, eps);
        row_add(r, c - z, in ? p->material : OC_MAT_AIR);
        z = c;
        in = ib;
      }
      za = zb;
    }
  }
  if (in) row_add(r, z1 - z, p->material);
  /* canonical in place (room: n layers in, at most n out) */
  size_t n = r->n - first;
  if (r->fail || n == 0) return;
  oc_layer *tmp = malloc(n * sizeof *tmp);
  if (!tmp) {
    r->fail = 1;
    return;
  }
  size_t m = oc_layers_canon(r->l + first, n, tmp);
  for (size_t i = 0; i < m; i++)
    r->l[first + i] = tmp[i];
  r->n = first + m;
  free(tmp);
}

oc_stacks *oc_stacks_from_program(const oc_program *P,
                                  const oc_stacks_node_params *p,
                                  oc_error *err) {
  if (!oc_check_positive(p->cell, "cell", err)) return NULL;
  const oc_aabb *b = &p->box;
  if (!isfinite(b->lo.x) || !isfinite(b->lo.y) || !isfinite(b->lo.z) ||
      !isfinite(b->hi.x) || !isfinite(b->hi.y) || !isfinite(b->hi.z) ||
      !(b->lo.x <= b->hi.x && b->lo.y <= b->hi.y && b->lo.z < b->hi.z)) {
    oc_seterr(err, OC_EINVAL,
              "'box' must be finite with lo <= hi (and lo.z < hi.z)");
    return NULL;
  }
  if (!(p->step >= 0) || !isfinite(p->step)) {
    oc_seterr(err, OC_EINVAL, "'step' must be > 0 (got %g)", p->step);
    return NULL;
  }
  if (p->material <= OC_MAT_AIR || p->material >= OC_MAT_COUNT) {
    oc_seterr(err, OC_EINVAL, "'material' must be a material other than air");
    return NULL;
  }
  double fx = floor((b->hi.x - b->lo.x) / p->cell) + 1;
  double fy = floor((b->hi.y - b->lo.y) / p->cell) + 1;
  double step = p->step > 0 ? p->step : p->cell / 4;
  if (fx > 65535 || fy > 65535 || fx * fy > (double)OC_STACKS_MAX ||
      (b->hi.z - b->lo.z) / step > 1e7) {
    oc_seterr(err, OC_EINVAL,
              "'cell' %g makes %.0f x %.0f stacks (or 'step' %g too many "
              "samples a column): at most 65535 a side and %llu in all",
              p->cell, fx, fy, step, (unsigned long long)OC_STACKS_MAX);
    return NULL;
  }
  int nx = (int)fx, ny = (int)fy;
  oc_stacks *s =
      oc_stacks_alloc(nx, ny, p->cell, b->lo.x, b->lo.y, b->lo.z, err);
  if (!s) return NULL;
  row *rows = calloc((size_t)ny, sizeof *rows);
  int fail = !rows, stop = 0, done = 0;
  for (int j = 0; j < ny && !fail; j++)
    fail = !(rows[j].count = malloc((size_t)nx * sizeof *rows[j].count));
  oc_progress pr = p->progress;
#pragma omp parallel for schedule(dynamic, 1) if (!fail)
  for (int j = 0; j < ny; j++) {
    int halt;
#pragma omp atomic read
    halt = stop;
    if (fail || halt) continue;
    row *r = &rows[j];
    for (int i = 0; i < nx; i++) {
      size_t n0 = r->n;
      column(P, p, b->lo.x + i * p->cell, b->lo.y + j * p->cell, r);
      r->count[i] = (uint32_t)(r->n - n0);
    }
    int d;
#pragma omp atomic capture
    d = ++done;
    /* the callback from one thread only (oc_progress's contract) */
    if (pr.fn && omp_get_thread_num() == 0 && pr.fn(pr.ud, 0.99 * d / ny)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (!fail && (stop || (pr.fn && pr.fn(pr.ud, 1.0)))) {
    for (int j = 0; j < ny; j++) {
      free(rows[j].l);
      free(rows[j].count);
    }
    free(rows);
    oc_stacks_free(s);
    oc_seterr(err, OC_ECANCEL, "from_node cancelled");
    return NULL;
  }
  size_t total = 0;
  for (int j = 0; rows && j < ny; j++) {
    fail |= rows[j].fail;
    total += rows[j].n;
  }
  oc_stacks_builder bd;
  if (!fail && oc_builder_init(&bd, (size_t)nx * ny, total, err) == OC_OK) {
    for (int j = 0; j < ny && !fail; j++) {
      const oc_layer *l = rows[j].l;
      for (int i = 0; i < nx && !fail; i++) {
        fail = oc_builder_push(&bd, l, rows[j].count[i], err) != OC_OK;
        if (rows[j].count[i]) l += rows[j].count[i]; /* l NULL: all air */
      }
    }
    if (!fail)
      oc_builder_commit(&bd, s);
    else
      oc_builder_free(&bd);
  } else if (fail) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
  } else {
    fail = 1;
  }
  for (int j = 0; rows && j < ny; j++) {
    free(rows[j].l);
    free(rows[j].count);
  }
  free(rows);
  if (fail) {
    oc_stacks_free(s);
    return NULL;
  }
  return s;
}
