/*
** triplanar.c — texturing by material (Peytavie et al. 2009, section 6):
** the colour at a point is T(p) = a T(y, z) + b T(x, z) + c T(x, y), the
** weights |n_x|^p, |n_y|^p, |n_z|^p normalised with p = 8 (each paired
** with the plane orthogonal to its axis), and materials blend by their
** ratio around the point. The ratio is the weight programs' value there,
** normalised: for material stacks, each material's visible ratio (its
** share of the exposed surface in the box of half-side sigma around p,
** oc_stacks_visible), or its volume ratio (oc_stacks_field).
** Renders use it as a colour source (OC_COLOR_BLEND), meshes as vertex
** colours (oc_mesh_color_by_blend).
*/
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/noise.h"
#include "render/triplanar.h"

#define MAX_BLEND 16

/* A 2D texture in [0, 1]: two octaves of simplex noise, stretched along
** u so that steep faces show horizontal bands like strata. */
static double tex2(double u, double v, uint64_t plane) {
  oc_vec3 q = {u * 0.35, v * 2.0, 0.5};
  return oc_turb3(0x7e57u + plane, 3, q, NULL) / oc_turb3_max(3);
}

double oc_triplanar(oc_vec3 p, oc_vec3 n, double s, uint64_t seed) {
  double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
  /* weights |n_i|^8, normalised (p = 8 as in the paper) */
  double wx = ax * ax, wy = ay * ay, wz = az * az;
  wx *= wx, wy *= wy, wz *= wz;
  wx *= wx, wy *= wy, wz *= wz;
  double sum = wx + wy + wz;
  if (!(sum > 0)) return NAN;
  uint64_t b = 3 * seed;
  /* the projection along x sees (y, z), and so on */
  return (wx * tex2(p.y * s, p.z * s, b) + wy * tex2(p.x * s, p.z * s, b + 1) +
          wz * tex2(p.x * s, p.y * s, b + 2)) /
         sum;
}

double oc_triplanar_gain(double t, double amp, double nz) {
  double steep = 0.35 + 0.65 * (1 - fabs(nz));
  double k = 1 + amp * steep * 2 * (t - 0.5);
  return k < 0 ? 0 : k;
}

void oc_blend_albedo(const oc_program *const *f, const double *col, int n,
                     double amp, double s, oc_vec3 p, oc_vec3 nrm,
                     double rgb[3], double *evals) {
  double acc[3] = {0, 0, 0}, sum = 0;
  for (int i = 0; i < n; i++) {
    double w = oc_program_eval(f[i], p);
    *evals += 1;
    if (!(w > 0)) continue;
    double k = 1;
    if (amp > 0) {
      double t = oc_triplanar(p, nrm, s, (uint64_t)i + 1);
      if (t == t) k = oc_triplanar_gain(t, amp, nrm.z);
    }
    for (int c = 0; c < 3; c++)
      acc[c] += w * col[3 * i + c] * k;
    sum += w;
  }
  for (int c = 0; c < 3; c++)
    rgb[c] = sum > 0 ? acc[c] / sum : col[c];
}

int oc_blend_check(const oc_program *const *f, const double *col, int n,
                   oc_error *err) {
  if (n < 1 || n > MAX_BLEND)
    return oc_seterr(err, OC_EINVAL,
                     "'blend' must have 1 .. %d colours (got %d)", MAX_BLEND,
                     n);
  if (!f || !col) return oc_seterr(err, OC_EINVAL, "'blend' is NULL");
  for (int i = 0; i < n; i++) {
    if (!f[i])
      return oc_seterr(err, OC_EINVAL, "'blend[%d]' has no field", i + 1);
    for (int c = 0; c < 3; c++)
      if (!(col[3 * i + c] >= 0 && col[3 * i + c] <= 1))
        return oc_seterr(err, OC_EINVAL,
                         "'blend[%d]' colour must be r, g, b in [0, 1]", i + 1);
  }
  return OC_OK;
}

int oc_mesh_color_by_blend(oc_mesh *mesh, const oc_program *const *fields,
                           const double *colors, int n, double texture,
                           double texture_scale, oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  int rc = oc_blend_check(fields, colors, n, err);
  if (rc) return rc;
  if (!(texture >= 0 && texture <= 1))
    return oc_seterr(err, OC_EINVAL, "'texture' must be in [0, 1] (got %g)",
                     texture);
  if (!(texture_scale > 0) || !isfinite(texture_scale))
    return oc_seterr(err, OC_EINVAL, "'texture_scale' must be > 0 (got %g)",
                     texture_scale);
  size_t nv = oc_mesh_vertex_count(mesh);
  float *rgb = malloc((nv ? nv : 1) * 3 * sizeof *rgb);
  if (!rgb) return oc_seterr(err, OC_ENOMEM, "out of memory");
  const float *P = oc_mesh_positions(mesh), *N = oc_mesh_normals(mesh);
  ptrdiff_t m = (ptrdiff_t)nv;
  /* each vertex on its own: the result cannot depend on the schedule */
#pragma omp parallel for schedule(static)
  for (ptrdiff_t i = 0; i < m; i++) {
    oc_vec3 p = {P[3 * i], P[3 * i + 1], P[3 * i + 2]};
    oc_vec3 q = {N[3 * i], N[3 * i + 1], N[3 * i + 2]};
    double c[3], ev = 0;
    oc_blend_albedo(fields, colors, n, texture, 1 / texture_scale, p, q, c,
                    &ev);
    for (int k = 0; k < 3; k++)
      rgb[3 * i + k] = (float)(c[k] > 1 ? 1 : c[k]);
  }
  rc = oc_mesh_set_colors(mesh, rgb, err);
  free(rgb);
  return rc;
}
