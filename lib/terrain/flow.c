/*
** flow.c — oc_heightfield_drainage and oc_heightfield_stream_power: upstream
** area by
** Freeman's (1991) multiple-flow-direction model, on the filled grid.
**
** Every sample starts with its own area, cell^2, and passes all it holds
** to its strictly lower neighbours k in proportion to tan(b_k)^p, b_k the
** angle down to k (p = 1.1, Freeman's exponent). A sample with no lower
** neighbour keeps what it holds: after filling, only border samples do,
** and their areas are what leaves the grid (the sum is nx ny cell^2).
**
** The sum is computed pulling, not pushing: a sample's area is its own
** plus, over its higher neighbours in the fixed neighbour order, their
** area times the fraction they send it. So each value is one fixed
** sequence of floating-point operations whatever the order samples are
** visited in, and any thread count gives the same bytes. Samples are
** visited in parallel as a topological walk: each holds a count of its
** higher neighbours still to finish; the thread that finishes the last
** one continues with it. Slopes are taken in cell units (the cell size
** cancels in the fractions), which keeps the powers far from overflow.
*/
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/grow.h"
#include "terrain/analysis.h"

#define MAX_EXPONENT 4.0
#define REPORT_EVERY 4096
#define STACK0 4096

static int check_params(const oc_heightfield *hf,
                        const oc_heightfield_flow_params *fp, const char *what,
                        double *p, oc_error *err) {
  if (!hf) return oc_seterr(err, OC_EINVAL, "%s needs a heightfield", what);
  *p = fp && fp->exponent != 0 ? fp->exponent : OC_HEIGHTFIELD_FREEMAN_EXPONENT;
  if (!(*p > 0 && *p <= MAX_EXPONENT))
    return oc_seterr(err, OC_EINVAL, "'exponent' must be in (0, %g] (got %g)",
                     MAX_EXPONENT, *p);
  return OC_OK;
}

/* Freeman's weight of a drop dz > 0 to neighbour k: tan(b)^p in cell
** units. exp2(p log2 t) is a quarter faster than pow and, being the one
** function both sides of an edge call, gives the donor and the receiver
** the same value. */
static double weight(double dz, int k, double p) {
  return exp2(p * log2(dz / oc_heightfield_dist[k]));
}

/* A sample no neighbour is strictly above: where walks start. */
static int is_source(const float *z, int nx, int ny, int i, int j) {
  float zc = z[(size_t)j * (size_t)nx + (size_t)i];
  for (int k = 0; k < 8; k++) {
    int a = i + oc_heightfield_di[k], b = j + oc_heightfield_dj[k];
    if (a >= 0 && b >= 0 && a < nx && b < ny &&
        z[(size_t)b * (size_t)nx + (size_t)a] > zc)
      return 0;
  }
  return 1;
}

typedef struct walk {
  const float *z;
  int nx, ny;
  double p, own;     /* exponent, own area of a sample */
  double *q;         /* normaliser, then area / normaliser once finished */
  unsigned char *up; /* higher neighbours not finished yet */
  float *area;
  int stop;    /* set on error or cancel: every thread winds down */
  size_t done; /* samples finished (progress only) */
} walk;

/* Finishes sample c: pulls from its higher neighbours (all finished),
** then releases its lower ones, pushing those it was the last for. */
static int finish(walk *w, uint32_t c, uint32_t **st, size_t *ns, size_t *cap) {
  int nx = w->nx, ny = w->ny;
  int i = (int)(c % (uint32_t)nx), j = (int)(c / (uint32_t)nx);
  double zc = w->z[c], sum = w->own;
  for (int k = 0; k < 8; k++) {
    int a = i + oc_heightfield_di[k], b = j + oc_heightfield_dj[k];
    if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
    size_t u = (size_t)b * (size_t)nx + (size_t)a;
    if (w->z[u] > zc) sum += w->q[u] * weight(w->z[u] - zc, k, w->p);
  }
  w->area[c] = oc_heightfield_float(sum);
  w->q[c] = w->q[c] > 0 ? sum / w->q[c] : 0;
  for (int k = 0; k < 8; k++) {
    int a = i + oc_heightfield_di[k], b = j + oc_heightfield_dj[k];
    if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
    size_t m = (size_t)b * (size_t)nx + (size_t)a;
    if (!(w->z[m] < zc)) continue;
    /* release: our q[c] is seen by whoever takes m; acquire: we see the
    ** q of every other higher neighbour of m */
    if (__atomic_sub_fetch(&w->up[m], 1, __ATOMIC_ACQ_REL) != 0) continue;
    if (!OC_GROW(*st, *ns, *cap, 1)) return OC_ENOMEM;
    (*st)[(*ns)++] = (uint32_t)m;
  }
  return OC_OK;
}

/* Upstream area of every sample of z (which must drain: filled). */
static int drain(const float *z, int nx, int ny, double cell, double p,
                 float *area, const oc_heightfield_phase *ph, oc_error *err) {
  size_t n = (size_t)nx * (size_t)ny;
  walk w = {.z = z,
            .nx = nx,
            .ny = ny,
            .p = p,
            .own = cell * cell,
            .q = malloc(n * sizeof(double)),
            .up = malloc(n),
            .area = area};
  if (!w.q || !w.up) {
    free(w.q);
    free(w.up);
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory for the drainage of a %d x %d grid", nx,
                     ny);
  }
#pragma omp parallel for schedule(static)
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      size_t c = (size_t)j * (size_t)nx + (size_t)i;
      double zc = z[c], norm = 0;
      unsigned char up = 0;
      for (int k = 0; k < 8; k++) {
        int a = i + oc_heightfield_di[k], b = j + oc_heightfield_dj[k];
        if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
        double zm = z[(size_t)b * (size_t)nx + (size_t)a];
        if (zm < zc) norm += weight(zc - zm, k, p);
        up += zm > zc;
      }
      w.q[c] = norm;
      w.up[c] = up;
    }
  int rc = OC_OK;
  int cancelled = 0;
#pragma omp parallel
  {
    size_t cap = STACK0, ns = 0, mine = 0;
    uint32_t *st = malloc(cap * sizeof *st);
    int lrc = st ? OC_OK : OC_ENOMEM;
#pragma omp for schedule(dynamic, 8)
    for (int j = 0; j < ny; j++) {
      int halt;
#pragma omp atomic read
      halt = w.stop;
      if (halt || lrc) continue;
      for (int i = 0; i < nx && !lrc; i++) {
        if (!is_source(z, nx, ny, i, j)) continue;
        st[ns++] = (uint32_t)((size_t)j * (size_t)nx + (size_t)i);
        while (ns > 0 && !lrc) {
          lrc = finish(&w, st[--ns], &st, &ns, &cap);
          if (++mine < REPORT_EVERY) continue;
          size_t d;
#pragma omp atomic capture
          d = w.done += mine;
          mine = 0;
          if (omp_get_thread_num() == 0 &&
              oc_heightfield_report(ph, (double)d / n)) {
#pragma omp atomic write
            cancelled = 1;
#pragma omp atomic write
            w.stop = 1;
          }
#pragma omp atomic read
          halt = w.stop;
          if (halt) lrc = -1;
        }
      }
    }
    if (lrc > 0) {
#pragma omp atomic write
      w.stop = 1;
#pragma omp critical(oc_heightfield_drain_err)
      rc = lrc;
    }
    free(st);
  }
  free(w.q);
  free(w.up);
  if (rc != OC_OK)
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory for the drainage of a %d x %d grid", nx,
                     ny);
  if (cancelled) return oc_seterr(err, OC_ECANCEL, "drainage cancelled");
  return OC_OK;
}

/* Points *z at the filled samples of hf: a copy in *copy (to free), or
** hf's own samples when they are prefilled. */
static int filled(const oc_heightfield *hf, int prefilled, const float **z,
                  float **copy, const oc_heightfield_phase *ph, oc_error *err) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  size_t n = (size_t)nx * (size_t)ny;
  *z = oc_heightfield_samples(hf);
  *copy = NULL;
  if (prefilled) return OC_OK;
  *copy = malloc(n * sizeof **copy);
  if (!*copy)
    return oc_seterr(err, OC_ENOMEM,
                     "out of memory filling a %d x %d heightfield", nx, ny);
  memcpy(*copy, *z, n * sizeof **copy);
  int rc = oc_heightfield_fill_samples(*copy, nx, ny, ph, err);
  if (rc != OC_OK) {
    free(*copy);
    *copy = NULL;
  }
  *z = *copy;
  return rc;
}

/* Shared by both entry points: the area into `area`, and with `power`
** the stream power, both grids of hf's geometry. */
static int flow(const oc_heightfield *hf, const oc_heightfield_flow_params *fp,
                double p, float *area, float *power, oc_error *err) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double cell = oc_heightfield_cell(hf);
  oc_progress cb = fp ? fp->progress : (oc_progress){NULL, NULL};
  int prefilled = fp && fp->prefilled;
  double split = prefilled ? 0 : 0.4;
  oc_heightfield_phase fill_ph = {cb, 0, split},
                       drain_ph = {cb, split, 0.99 - split};
  float *copy;
  const float *z;
  int rc = filled(hf, prefilled, &z, &copy, &fill_ph, err);
  if (rc != OC_OK) return rc;
  rc = drain(z, nx, ny, cell, p, area, &drain_ph, err);
  if (rc == OC_OK && power) {
    size_t n = (size_t)nx * (size_t)ny;
    oc_heightfield_slope_samples(z, nx, ny, cell, power);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < n; k++)
      power[k] = oc_heightfield_float(sqrt((double)area[k]) * power[k]);
  }
  free(copy);
  if (rc == OC_OK && cb.fn && cb.fn(cb.ud, 1.0))
    rc = oc_seterr(err, OC_ECANCEL, "flow routing cancelled");
  return rc;
}

oc_heightfield *oc_heightfield_drainage(const oc_heightfield *hf,
                                        const oc_heightfield_flow_params *fp,
                                        oc_error *err) {
  double p;
  if (check_params(hf, fp, "drainage", &p, err)) return NULL;
  oc_heightfield *out = oc_heightfield_like(hf, err);
  if (!out) return NULL;
  if (flow(hf, fp, p, oc_heightfield_samples_mut(out), NULL, err) != OC_OK) {
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}

oc_heightfield *
oc_heightfield_stream_power(const oc_heightfield *hf,
                            const oc_heightfield_flow_params *fp,
                            oc_error *err) {
  double p;
  if (check_params(hf, fp, "stream_power", &p, err)) return NULL;
  oc_heightfield *out = oc_heightfield_like(hf, err);
  if (!out) return NULL;
  size_t n = (size_t)oc_heightfield_nx(hf) * (size_t)oc_heightfield_ny(hf);
  float *area = malloc(n * sizeof *area);
  int rc = area ? flow(hf, fp, p, area, oc_heightfield_samples_mut(out), err)
                : oc_seterr(err, OC_ENOMEM,
                            "out of memory for the stream power of a %d x %d "
                            "grid",
                            oc_heightfield_nx(hf), oc_heightfield_ny(hf));
  free(area);
  if (rc != OC_OK) {
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}
