/*
** prim.h — distance to the skeleton or solid of a primitive (internal).
**
** Parameters follow the oc_node.par layout (node.h); a curve's polyline
** follows as par[2] = number of points, then x, y, z triples from par[3].
*/
#ifndef OC_PRIM_H
#define OC_PRIM_H

#include <stddef.h>

#include "field/node.h"

/* Distance d from p to the primitive's skeleton (point, segment, curve) or
** solid (sphere, box, cone, half-space); stores the closest point in *s.
** d = 0 (and s = p) inside solids. Callers only interested in distances
** below `cutoff` (where the field is non-zero) may get any value >= cutoff
** (and s unset) beyond it: curves use it to skip far chunks. */
double oc_prim_project(oc_kind kind, const double *par, oc_vec3 p, oc_vec3 *s,
                       double cutoff);

/* oc_prim_project (distance in *d), with the Jacobian of the closest
** point, ds/dp, in J (3 x 3, row-major; symmetric for every kind) where it
** moves smoothly with p. 0 for kinds without one (cones, planes): use
** oc_prim_project. */
int oc_prim_project_jac(oc_kind kind, const double *par, oc_vec3 p, oc_vec3 *s,
                        double cutoff, double *d, double J[9]);

/* Number of doubles a distance primitive needs in a program. */
size_t oc_prim_npar(const oc_node *n);
/* Writes those doubles. */
void oc_prim_pack(const oc_node *n, double *out);

/* A curve's segments come in chunks, each with the box of its points:
** returns the boxes (lo x, y, z, hi x, y, z per chunk) and their number in
** *n. */
const double *oc_prim_curve_boxes(const double *par, size_t *n);

/* Box of the skeleton/solid (not grown by R). Infinite for most planes. */
oc_aabb oc_prim_skeleton_box(oc_kind kind, const double *par);

#endif
