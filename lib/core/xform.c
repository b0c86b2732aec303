/*
** xform.c — composing the 3x4 affine maps oc_transform takes (row-major,
** the implicit last row (0 0 0 1)): rotations from an axis and an angle
** or from Euler angles, products, and translate * rotate * scale. The
** front ends build their transforms here so that a C program and a
** script get the same matrix, to the bit.
*/
#include <math.h>
#include <string.h>

#include "core/error.h"
#include "outcrop.h"

#define PI 3.14159265358979323846

void oc_xform_identity(double m[12]) {
  memset(m, 0, 12 * sizeof *m);
  m[0] = m[5] = m[10] = 1;
}

void oc_xform_mul(const double a[12], const double b[12], double out[12]) {
  double r[12];
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 4; j++) {
      double s = j == 3 ? a[i * 4 + 3] : 0;
      for (int k = 0; k < 3; k++)
        s += a[i * 4 + k] * b[k * 4 + j];
      r[i * 4 + j] = s;
    }
  }
  memcpy(out, r, sizeof r); /* out may be a or b */
}

/* Rotation by `deg` degrees about the unit axis k (Rodrigues). */
static void rotation(oc_vec3 k, double deg, double m[12]) {
  double a = deg * (PI / 180.0), c = cos(a), s = sin(a), t = 1 - c;
  oc_xform_identity(m);
  m[0] = c + t * k.x * k.x;
  m[1] = t * k.x * k.y - s * k.z;
  m[2] = t * k.x * k.z + s * k.y;
  m[4] = t * k.y * k.x + s * k.z;
  m[5] = c + t * k.y * k.y;
  m[6] = t * k.y * k.z - s * k.x;
  m[8] = t * k.z * k.x - s * k.y;
  m[9] = t * k.z * k.y + s * k.x;
  m[10] = c + t * k.z * k.z;
}

int oc_xform_axis_angle(oc_vec3 axis, double degrees, double m[12],
                        oc_error *err) {
  double len = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
  if (!(len > 0) || !isfinite(len))
    return oc_seterr(err, OC_EINVAL, "'rotate.axis' must be a non-zero vector");
  if (!isfinite(degrees))
    return oc_seterr(err, OC_EINVAL, "'rotate.angle' must be finite");
  axis.x /= len, axis.y /= len, axis.z /= len;
  rotation(axis, degrees, m);
  return OC_OK;
}

/* X first, so R = Rz * Ry * Rx. */
int oc_xform_euler(oc_vec3 degrees, double m[12], oc_error *err) {
  static const oc_vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double e[3] = {degrees.x, degrees.y, degrees.z};
  if (!isfinite(e[0]) || !isfinite(e[1]) || !isfinite(e[2]))
    return oc_seterr(err, OC_EINVAL, "'rotate' angles must be finite");
  oc_xform_identity(m);
  for (int i = 0; i < 3; i++) {
    double r[12];
    rotation(axes[i], e[i], r);
    oc_xform_mul(r, m, m);
  }
  return OC_OK;
}

int oc_xform_compose(oc_vec3 translate, const double rotate[12], oc_vec3 scale,
                     double m[12], oc_error *err) {
  char a[OC_NUMSTR], b[OC_NUMSTR], c[OC_NUMSTR];
  if (scale.x == 0 || scale.y == 0 || scale.z == 0)
    return oc_seterr(
        err, OC_EINVAL, "'scale' factors must be non-zero (got {%s, %s, %s})",
        oc_numstr(scale.x, a), oc_numstr(scale.y, b), oc_numstr(scale.z, c));
  double rot[12], sc[12];
  if (rotate)
    memcpy(rot, rotate, sizeof rot);
  else
    oc_xform_identity(rot);
  oc_xform_identity(sc);
  sc[0] = scale.x, sc[5] = scale.y, sc[10] = scale.z;
  oc_xform_mul(rot, sc, m);
  m[3] = translate.x, m[7] = translate.y, m[11] = translate.z;
  return OC_OK;
}
