/*
** hull.c — the convex hull of each cluster (Paris et al. 2020, section
** 4.2) through qhull (reentrant libqhull_r): facet planes n . p + offset
** <= 0 inside, oriented outward, with coplanar facets merged (qhull's
** default C-0), and the hull's vertices.
**
** A cluster of fewer than 4 points, or a flat one (qhull fails on it), is
** made thick, as the paper makes it a thick polygon, segment or point:
** each point is replaced by itself and its six neighbours r/2 away along
** the axes, so the block is the cluster grown by an octahedron of radius
** r/2.
*/
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libqhull_r/qhull_ra.h>

#include "blocks/btile.h"
#include "core/error.h"

void oc_bblock_free(oc_bblock *b) {
  free(b->plane);
  free(b->vert);
  memset(b, 0, sizeof *b);
}

/* Runs qhull on the n points xyz; fills b's planes and vertices. Returns
** 0, 1 when qhull failed (flat input), OC_ENOMEM. qhull's messages go to
** `quiet`. */
static int hull(double *xyz, size_t n, oc_bblock *b, FILE *quiet) {
  qhT qh_qh, *qh = &qh_qh;
  char cmd[] = "qhull";
  int rc = 1;
  if (n < 4) return 1;
  qh_zero(qh, quiet);
  int ex = qh_new_qhull(qh, 3, (int)n, xyz, False, cmd, NULL, quiet);
  if (!ex) {
    facetT *facet;
    vertexT *vertex;
    size_t nf = 0, nv = 0;
    FORALLfacets nf++;
    FORALLvertices nv++;
    b->plane = malloc(4 * nf * sizeof *b->plane);
    b->vert = malloc(3 * nv * sizeof *b->vert);
    if (!b->plane || !b->vert) {
      rc = OC_ENOMEM;
    } else {
      b->nplane = b->nvert = 0;
      FORALLfacets {
        double *p = b->plane + 4 * b->nplane++;
        p[0] = facet->normal[0];
        p[1] = facet->normal[1];
        p[2] = facet->normal[2];
        p[3] = facet->offset;
      }
      FORALLvertices {
        memcpy(b->vert + 3 * b->nvert++, vertex->point, 3 * sizeof(double));
      }
      rc = 0;
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong, totlong;
  qh_memfreeshort(qh, &curlong, &totlong);
  return rc;
}

int oc_bhull_points(double *xyz, size_t n, oc_bblock *b) {
  FILE *quiet = fopen("/dev/null", "w");
  if (!quiet) return OC_ENOMEM;
  int rc = hull(xyz, n, b, quiet);
  fclose(quiet);
  return rc;
}

/* Box, thickness (the least extent of the hull across a face's normal). */
void oc_bblock_measure(oc_bblock *b) {
  b->box.lo = (oc_vec3){INFINITY, INFINITY, INFINITY};
  b->box.hi = (oc_vec3){-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < b->nvert; v++) {
    const double *p = b->vert + 3 * v;
    b->box.lo = (oc_vec3){fmin(b->box.lo.x, p[0]), fmin(b->box.lo.y, p[1]),
                          fmin(b->box.lo.z, p[2])};
    b->box.hi = (oc_vec3){fmax(b->box.hi.x, p[0]), fmax(b->box.hi.y, p[1]),
                          fmax(b->box.hi.z, p[2])};
  }
  b->thickness = INFINITY;
  for (size_t k = 0; k < b->nplane; k++) {
    const double *h = b->plane + 4 * k;
    double deep = 0;
    for (size_t v = 0; v < b->nvert; v++) {
      const double *p = b->vert + 3 * v;
      deep = fmax(deep, -(h[0] * p[0] + h[1] * p[1] + h[2] * p[2] + h[3]));
    }
    b->thickness = fmin(b->thickness, deep);
  }
}

int oc_bhulls_make(oc_btile *t, oc_error *err) {
  size_t n = t->np, nc = t->ncl;
  size_t *start = calloc(nc + 1, sizeof *start);
  double *xyz = malloc((n ? n : 1) * 3 * sizeof *xyz);
  double *thick = malloc((n ? n : 1) * 21 * sizeof *thick);
  size_t *fill = calloc(nc ? nc : 1, sizeof *fill);
  t->block = calloc(nc ? nc : 1, sizeof *t->block);
  FILE *quiet = fopen("/dev/null", "w");
  int rc = OC_ENOMEM;
  if (!start || !xyz || !thick || !fill || !t->block || !quiet) goto done;
  for (size_t i = 0; i < n; i++)
    start[t->label[i] + 1]++;
  for (size_t c = 0; c < nc; c++)
    start[c + 1] += start[c];
  for (size_t i = 0; i < n; i++) {
    size_t c = t->label[i];
    memcpy(xyz + 3 * (start[c] + fill[c]++), t->unwrap + 3 * i,
           3 * sizeof *xyz);
  }
  t->nb = 0;
  t->thick = 0;
  double half = 0.5 * t->pp.radius;
  for (size_t c = 0; c < nc; c++) {
    oc_bblock *b = &t->block[t->nb];
    double *p = xyz + 3 * start[c];
    size_t m = start[c + 1] - start[c];
    int h = hull(p, m, b, quiet);
    if (h == 1) {
      for (size_t i = 0; i < m; i++)
        for (int k = 0; k < 7; k++)
          for (int a = 0; a < 3; a++)
            thick[21 * i + 3 * k + a] =
                p[3 * i + a] +
                (k && (k - 1) / 2 == a ? (k & 1 ? -half : half) : 0);
      h = hull(thick, 7 * m, b, quiet);
      t->thick++;
    }
    if (h == OC_ENOMEM) goto done;
    if (h) continue; /* cannot happen: the octahedra are solid */
    double g[3] = {0, 0, 0};
    for (size_t i = 0; i < m; i++)
      for (int a = 0; a < 3; a++)
        g[a] += p[3 * i + a];
    b->centroid = (oc_vec3){g[0] / m, g[1] / m, g[2] / m};
    b->npts = m;
    oc_bblock_measure(b);
    t->nb++;
  }
  rc = 0;
done:
  if (rc) oc_seterr(err, OC_ENOMEM, "out of memory for block hulls");
  if (quiet) fclose(quiet);
  free(start);
  free(xyz);
  free(thick);
  free(fill);
  return rc;
}

int oc_bblock_hull(double *xyz, size_t n, oc_bblock *b, oc_error *err) {
  memset(b, 0, sizeof *b);
  int h = oc_bhull_points(xyz, n, b);
  if (h) {
    oc_bblock_free(b);
    return h == OC_ENOMEM
               ? oc_seterr(err, OC_ENOMEM, "out of memory for a hull")
               : oc_seterr(err, OC_EINVAL, "flat or too few points for a hull");
  }
  double g[3] = {0, 0, 0};
  for (size_t i = 0; i < n; i++)
    for (int a = 0; a < 3; a++)
      g[a] += xyz[3 * i + a];
  b->centroid = (oc_vec3){g[0] / n, g[1] / n, g[2] / n};
  b->npts = n;
  oc_bblock_measure(b);
  return OC_OK;
}
