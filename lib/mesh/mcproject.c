/*
** mcproject.c — the projected size of a polygonization, before any of it
** is made, so that a request whose mesh could never fit in memory (a
** plane over 500 x 500 km at cell 1) is refused up front with the figure.
**
** Along each axis, PROBES x PROBES lines cross the box at the centres of
** a coarse grid over the other two axes, sampled at LEVELS points. A line
** crosses the surface wherever inside and outside alternate along it (for
** closed meshes the box's outside counts as outside, since caps are
** surface too). The mean crossings per line estimate how many times the
** surface covers the grid's face across that axis, and a surface
** covering a x b cells of a face makes about 2 a b triangles or more (a
** flat one exactly that): the largest of the three is the estimate.
** Features thinner or smaller than the probes lower it, never raise it,
** so the estimate refuses a mesh only when the mesh is surely huge.
*/
#include "mesh/mcgrid.h"

#define PROBES 16
#define LEVELS 32
/* Triangles per cube at most (the case table's largest case is 12). */
#define MAX_TRI_PER_CUBE 12

/* How many times the line along axis a through (u, v) of the other two
** axes b and c crosses the surface (as far as its samples tell). */
static int crossings(const oc_mcgrid *g, int a, double u, double v) {
  int b = (a + 1) % 3, c = (a + 2) % 3, n = 0;
  int prev = g->open ? -1 : 0; /* before the box: outside when closed */
  for (int k = 0; k < LEVELS; k++) {
    double p[3];
    p[a] = g->lo[a] + (k + 0.5) * (g->hi[a] - g->lo[a]) / LEVELS;
    p[b] = u;
    p[c] = v;
    int in = oc_program_eval(g->prog, (oc_vec3){p[0], p[1], p[2]}) > g->T;
    n += prev >= 0 && in != prev;
    prev = in;
  }
  return n + (!g->open && prev == 1); /* the cap at the far face */
}

double oc_mc_project_triangles(const oc_mcgrid *g, double limit) {
  double cubes = 1;
  for (int a = 0; a < 3; a++)
    cubes *= g->n[a] + 1.0;
  double most = MAX_TRI_PER_CUBE * cubes;
  if (most <= limit) return most;
  double best = 0;
  for (int a = 0; a < 3; a++) {
    int b = (a + 1) % 3, c = (a + 2) % 3, hit = 0;
    for (int j = 0; j < PROBES; j++)
      for (int i = 0; i < PROBES; i++) {
        double u = g->lo[b] + (i + 0.5) * (g->hi[b] - g->lo[b]) / PROBES;
        double v = g->lo[c] + (j + 0.5) * (g->hi[c] - g->lo[c]) / PROBES;
        hit += crossings(g, a, u, v);
      }
    double face = (g->n[b] + 1.0) * (g->n[c] + 1.0);
    double t = 2 * face * hit / (PROBES * PROBES);
    if (t > best) best = t;
  }
  return best < most ? best : most;
}
