/*
** fcurve.c — feature curves (Hnaidi et al. 2010, section 3.1): a planar
** skeleton (core/curve.h: the one implementation of Bézier evaluation,
** arc length, closest point and frames) with constraint points
** P_i = ((h_i, r_i), (a_i, b_i, theta_i, phi_i), (A_i, R_i), u_i) at
** normalised arc length u_i. Each attribute is interpolated among the
** points that give it: h by a natural cubic spline, the others linearly,
** constant beyond the first and last of those points.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "diffusion/diffusion.h"

#define DEG 0.017453292519943295769
#define MAX_ANGLE 89.0

static int check_point(const oc_fconstraint *k, size_t i, double prev,
                       oc_error *err) {
  char b[OC_NUMSTR];
  size_t n = i + 1;
  if (!(k->u >= 0 && k->u <= 1))
    return oc_seterr(err, OC_EINVAL,
                     "'constraints[%zu].u' must be in [0, 1] (got %s)", n,
                     oc_numstr(k->u, b));
  if (i > 0 && !(k->u > prev))
    return oc_seterr(err, OC_EINVAL,
                     "'constraints[%zu].u' must be greater than the previous "
                     "point's u (got %s)",
                     n, oc_numstr(k->u, b));
  if (k->has &
      ~(unsigned)(OC_FC_HEIGHT | OC_FC_RADIUS | OC_FC_SLOPE | OC_FC_NOISE))
    return oc_seterr(err, OC_EINVAL, "'constraints[%zu]': unknown categories",
                     n);
  if ((k->has & OC_FC_HEIGHT) && !isfinite(k->height))
    return oc_seterr(err, OC_EINVAL,
                     "'constraints[%zu].height' must be finite (got %s)", n,
                     oc_numstr(k->height, b));
  if ((k->has & OC_FC_RADIUS) && !(k->radius >= 0 && isfinite(k->radius)))
    return oc_seterr(err, OC_EINVAL,
                     "'constraints[%zu].radius' must be >= 0 (got %s)", n,
                     oc_numstr(k->radius, b));
  if (k->has & OC_FC_SLOPE) {
    const char *name[2] = {"left", "right"};
    double ang[2] = {k->left, k->right}, ext[2] = {k->extent_a, k->extent_b};
    for (int s = 0; s < 2; s++) {
      if (!(fabs(ang[s]) <= MAX_ANGLE))
        return oc_seterr(err, OC_EINVAL,
                         "'constraints[%zu].slope.%s' must be in [-89, 89] "
                         "degrees (got %s)",
                         n, name[s], oc_numstr(ang[s], b));
      if (!(ext[s] >= 0 && isfinite(ext[s])))
        return oc_seterr(err, OC_EINVAL,
                         "'constraints[%zu].slope.extent[%d]' must be >= 0 "
                         "(got %s)",
                         n, s + 1, oc_numstr(ext[s], b));
    }
  }
  if (k->has & OC_FC_NOISE) {
    if (!(k->amplitude >= 0 && isfinite(k->amplitude)))
      return oc_seterr(err, OC_EINVAL,
                       "'constraints[%zu].noise.amplitude' must be >= 0 (got "
                       "%s)",
                       n, oc_numstr(k->amplitude, b));
    if (!(k->roughness >= 0 && k->roughness <= 1))
      return oc_seterr(err, OC_EINVAL,
                       "'constraints[%zu].noise.roughness' must be in [0, 1] "
                       "(got %s)",
                       n, oc_numstr(k->roughness, b));
  }
  return OC_OK;
}

static int check(const oc_fcurve_params *p, oc_error *err) {
  if (!p || !p->xy)
    return oc_seterr(err, OC_EINVAL, "feature curve: no 'points'");
  if (p->npoints < 2 || p->npoints > (1u << 20))
    return oc_seterr(err, OC_EINVAL,
                     "'points' must hold 2 to 1048576 points (got %zu)",
                     p->npoints);
  if (p->bezier && (p->npoints < 4 || (p->npoints - 1) % 3 != 0))
    return oc_seterr(err, OC_EINVAL,
                     "'points' of a Bézier curve must number 3 k + 1 (4, 7, "
                     "10, ...; got %zu)",
                     p->npoints);
  for (size_t i = 0; i < 2 * p->npoints; i++)
    if (!isfinite(p->xy[i]))
      return oc_seterr(err, OC_EINVAL, "'points[%zu]' must hold finite numbers",
                       i / 2 + 1);
  if (!p->constraints || p->nconstraints < 2)
    return oc_seterr(err, OC_EINVAL,
                     "'constraints' must hold at least 2 points (got %zu)",
                     p->constraints ? p->nconstraints : 0);
  if (p->nconstraints > (1u << 20))
    return oc_seterr(err, OC_EINVAL,
                     "'constraints': %zu points, at most 1048576",
                     p->nconstraints);
  for (size_t i = 0; i < p->nconstraints; i++) {
    int rc = check_point(&p->constraints[i], i, i ? p->constraints[i - 1].u : 0,
                         err);
    if (rc) return rc;
  }
  return OC_OK;
}

/* The value of attribute a at constraint point k (angles in degrees,
** interpolated as such). */
static double attr_value(const oc_fconstraint *k, int a) {
  switch (a) {
  case FA_HEIGHT:
    return k->height;
  case FA_RADIUS:
    return k->radius;
  case FA_LEFT:
    return k->left;
  case FA_RIGHT:
    return k->right;
  case FA_EXTA:
    return k->extent_a;
  case FA_EXTB:
    return k->extent_b;
  case FA_AMP:
    return k->amplitude;
  default:
    return k->roughness;
  }
}

static unsigned attr_category(int a) {
  static const unsigned cat[FA_COUNT] = {
      OC_FC_HEIGHT, OC_FC_RADIUS, OC_FC_SLOPE, OC_FC_SLOPE,
      OC_FC_SLOPE,  OC_FC_SLOPE,  OC_FC_NOISE, OC_FC_NOISE};
  return cat[a];
}

static int build_attrs(oc_fcurve *c, oc_error *err) {
  for (int a = 0; a < FA_COUNT; a++) {
    oc_fattr *t = &c->attr[a];
    unsigned cat = attr_category(a);
    for (size_t i = 0; i < c->nk; i++)
      t->n += (c->k[i].has & cat) != 0;
    if (!t->n) continue;
    t->u = malloc(3 * t->n * sizeof *t->u);
    double *work = a == FA_HEIGHT ? malloc(2 * t->n * sizeof *work) : NULL;
    if (!t->u || (a == FA_HEIGHT && !work)) {
      free(work);
      return oc_seterr(err, OC_ENOMEM, "out of memory");
    }
    t->v = t->u + t->n;
    t->m = t->v + t->n;
    size_t j = 0;
    for (size_t i = 0; i < c->nk; i++)
      if (c->k[i].has & cat) {
        t->u[j] = c->k[i].u;
        t->v[j++] = attr_value(&c->k[i], a);
      }
    if (a == FA_HEIGHT)
      oc_nspline_fit(t->u, t->v, t->n, t->m, work);
    else
      memset(t->m, 0, t->n * sizeof *t->m);
    free(work);
  }
  return OC_OK;
}

oc_fcurve *oc_fcurve_new(const oc_fcurve_params *p, oc_error *err) {
  if (check(p, err)) return NULL;
  oc_fcurve *c = calloc(1, sizeof *c);
  oc_vec3 *pts = c ? malloc(p->npoints * sizeof *pts) : NULL;
  if (c) {
    c->refs = 1;
    c->xy = malloc(2 * p->npoints * sizeof *c->xy);
    c->k = malloc(p->nconstraints * sizeof *c->k);
  }
  if (!c || !pts || !c->xy || !c->k) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    goto fail;
  }
  memcpy(c->xy, p->xy, 2 * p->npoints * sizeof *c->xy);
  memcpy(c->k, p->constraints, p->nconstraints * sizeof *c->k);
  c->npoints = p->npoints;
  c->nk = p->nconstraints;
  c->bezier = p->bezier != 0;
  for (size_t i = 0; i < p->npoints; i++)
    pts[i] = (oc_vec3){p->xy[2 * i], p->xy[2 * i + 1], 0};
  c->c = oc_curve_from_points(pts, p->npoints, c->bezier ? 3 : 1, err);
  if (!c->c) goto fail;
  c->length = oc_curve_length(c->c);
  for (size_t i = 0; i < c->nk; i++)
    c->has |= c->k[i].has;
  if (build_attrs(c, err)) goto fail;
  free(pts);
  return c;
fail:
  free(pts);
  if (c) c->refs = 1;
  oc_fcurve_release(c);
  return NULL;
}

void oc_fcurve_retain(oc_fcurve *c) {
  if (c) __atomic_add_fetch(&c->refs, 1, __ATOMIC_RELAXED);
}

void oc_fcurve_release(oc_fcurve *c) {
  if (!c || __atomic_sub_fetch(&c->refs, 1, __ATOMIC_ACQ_REL) != 0) return;
  oc_curve_free(c->c);
  for (int a = 0; a < FA_COUNT; a++)
    free(c->attr[a].u);
  free(c->xy);
  free(c->k);
  free(c);
}

double oc_fcurve_length(const oc_fcurve *c) {
  return c->length;
}

unsigned oc_fcurve_has(const oc_fcurve *c) {
  return c->has;
}

void oc_fcurve_attrs(const oc_fcurve *c, double u, unsigned want, double *v) {
  for (int a = 0; a < FA_COUNT; a++) {
    const oc_fattr *t = &c->attr[a];
    if (!(want & (1u << a))) continue;
    if (!t->n)
      v[a] = 0;
    else if (a == FA_HEIGHT)
      v[a] = oc_nspline_eval(t->u, t->v, t->m, t->n, u);
    else
      v[a] = oc_linear_eval(t->u, t->v, t->n, u);
  }
  if (want & (1u << FA_LEFT)) v[FA_LEFT] = tan(v[FA_LEFT] * DEG);
  if (want & (1u << FA_RIGHT)) v[FA_RIGHT] = tan(v[FA_RIGHT] * DEG);
}

int oc_fcurve_sample_at(const oc_fcurve *c, double u, oc_fcurve_sample *out) {
  if (!c || !out || isnan(u)) return OC_EINVAL;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  oc_curve_point pt;
  oc_curve_at(c->c, u * c->length, &pt);
  double v[FA_COUNT];
  oc_fcurve_attrs(c, u, ~0u, v);
  out->x = pt.q.x, out->y = pt.q.y, out->tx = pt.tx, out->ty = pt.ty;
  out->has = c->has;
  out->height = v[FA_HEIGHT];
  out->radius = v[FA_RADIUS];
  out->left = atan(v[FA_LEFT]) / DEG;
  out->right = atan(v[FA_RIGHT]) / DEG;
  out->extent_a = v[FA_EXTA];
  out->extent_b = v[FA_EXTB];
  out->amplitude = v[FA_AMP];
  out->roughness = v[FA_ROUGH];
  return OC_OK;
}
