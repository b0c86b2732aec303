/*
** access.c — oc_heightfield_accessibility: the fraction of the sky a sample
** sees,
** after Miller's (1994) accessibility shading.
**
** From each sample, `rays` directions are drawn uniformly over the solid
** angle of the upper hemisphere about the vertical (cos of the zenith
** angle uniform in (0, 1]: Archimedes) as a randomly shifted spherical
** Fibonacci lattice. A ray escapes unless the terrain is above it
** somewhere within `distance` (measured along the ray); the result is the
** fraction that escape. So a flat plane gives 1, a plane tilted by a
** gives 1 - a / pi and the bottom of a V valley with sides at a gives
** 1 - 2 a / pi. Rays are marched in steps of half a cell of horizontal
** travel over the bilinear surface of the samples; a ray that leaves the
** grid, or rises above its highest sample, escapes.
**
** The lattice's shift comes from a counter-based stream keyed by the seed
** and the sample index, so each sample's value depends on nothing else:
** rows are shared between threads freely and any thread count gives the
** same bytes.
*/
#include <math.h>
#include <omp.h>

#include "core/error.h"
#include "core/rng.h"
#include "terrain/analysis.h"

#define PI 3.14159265358979323846
#define GOLDEN 0.61803398874989484820 /* (sqrt 5 - 1) / 2 */
#define STEP 0.5 /* cells of horizontal travel per marching step */
#define DEFAULT_RAYS 64
#define MAX_RAYS 4096
#define DEFAULT_DISTANCE 50 /* cells */

typedef struct sky {
  const float *z;
  int nx, ny;
  double cell, distance, top;
  int rays;
  uint64_t seed;
} sky;

static double bilinear(const sky *s, double x, double y) {
  int i = (int)x, j = (int)y;
  if (i > s->nx - 2) i = s->nx - 2;
  if (j > s->ny - 2) j = s->ny - 2;
  double fx = x - i, fy = y - j;
  const float *r0 = s->z + (size_t)j * (size_t)s->nx + (size_t)i;
  const float *r1 = r0 + s->nx;
  /* differences, so that equal samples give exactly their value */
  double a = r0[0] + fx * ((double)r0[1] - r0[0]);
  double b = r1[0] + fx * ((double)r1[1] - r1[0]);
  return a + fy * (b - a);
}

/* 1 when the ray from sample (i, j) with zenith cosine u and azimuth phi
** escapes. */
static int escapes(const sky *s, int i, int j, double z0, double u,
                   double phi) {
  if (u >= 1) return 1;
  double sn = sqrt(1 - u * u);
  double rise = s->cell * u / sn; /* metres up per cell across */
  double reach = s->distance * sn / s->cell, dx = cos(phi), dy = sin(phi);
  for (int q = 1; q * STEP <= reach; q++) {
    double t = q * STEP, zr = z0 + t * rise;
    if (zr > s->top) return 1;
    double x = i + t * dx, y = j + t * dy;
    if (x < 0 || y < 0 || x > s->nx - 1 || y > s->ny - 1) return 1;
    if (zr < bilinear(s, x, y)) return 0;
  }
  return 1;
}

static float sample_sky(const sky *s, int i, int j) {
  size_t c = (size_t)j * (size_t)s->nx + (size_t)i;
  oc_rng r = oc_rng_stream(s->seed, c);
  int seen = 0;
  /* A spherical Fibonacci lattice (equal-area: u uniform, azimuths by
  ** the golden ratio) turned by a random shift per sample: low
  ** discrepancy, so few rays suffice, and no pattern shared by
  ** neighbouring samples. */
  double su = oc_rng_uniform(&r), sphi = oc_rng_uniform(&r);
  for (int k = 0; k < s->rays; k++) {
    double u = 1 - (k + su) / s->rays;
    double t = sphi + k * GOLDEN;
    seen += escapes(s, i, j, s->z[c], u, 2 * PI * (t - floor(t)));
  }
  return (float)((double)seen / s->rays);
}

oc_heightfield *
oc_heightfield_accessibility(const oc_heightfield *hf,
                             const oc_heightfield_access_params *ap,
                             oc_error *err) {
  if (!hf) {
    oc_seterr(err, OC_EINVAL, "accessibility needs a heightfield");
    return NULL;
  }
  oc_heightfield_access_params d = {0, 0, 0, {NULL, NULL}};
  if (!ap) ap = &d;
  sky s = {oc_heightfield_samples(hf),
           oc_heightfield_nx(hf),
           oc_heightfield_ny(hf),
           oc_heightfield_cell(hf),
           ap->distance,
           0,
           ap->rays ? ap->rays : DEFAULT_RAYS,
           ap->seed};
  if (s.rays < 1 || s.rays > MAX_RAYS) {
    oc_seterr(err, OC_EINVAL, "'rays' must be in 1..%d (got %d)", MAX_RAYS,
              s.rays);
    return NULL;
  }
  if (s.distance == 0) s.distance = DEFAULT_DISTANCE * s.cell;
  if (!(s.distance > 0) || !isfinite(s.distance)) {
    oc_seterr(err, OC_EINVAL, "'distance' must be > 0 (got %g)", ap->distance);
    return NULL;
  }
  oc_heightfield_minmax(hf, NULL, &s.top);
  oc_heightfield *out = oc_heightfield_like(hf, err);
  if (!out) return NULL;
  float *a = oc_heightfield_samples_mut(out);
  oc_heightfield_phase ph = {ap->progress, 0, 1};
  int stop = 0, rows = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (int j = 0; j < s.ny; j++) {
    int halt;
#pragma omp atomic read
    halt = stop;
    if (halt) continue;
    for (int i = 0; i < s.nx; i++)
      a[(size_t)j * (size_t)s.nx + (size_t)i] = sample_sky(&s, i, j);
    int done;
#pragma omp atomic capture
    done = ++rows;
    if (omp_get_thread_num() == 0 &&
        oc_heightfield_report(&ph, 0.99 * done / s.ny)) {
#pragma omp atomic write
      stop = 1;
    }
  }
  if (stop || oc_heightfield_report(&ph, 1.0)) {
    oc_seterr(err, OC_ECANCEL, "accessibility cancelled");
    oc_heightfield_release(out);
    return NULL;
  }
  return out;
}
