/*
** trace.c — ray versus the surface f = T.
**
** Both tracers march from outside (f < T) and only take steps that the
** Lipschitz property proves free of the surface: f(t + s) <= f(t) + H s
** where H bounds the derivative of f along the ray, so f stays below T
** while s < (T - f) / H.
**  - Sphere tracing (Génevaux et al. 2015, section 7.1): H is the program's
** global
**    bound; the ray is clipped to the scene's box. A program whose field
**    jumps somewhere (an open terrain's sides) has a global bound that
**    holds only off the jumps: there each step is first checked against
**    the local bounds below, which are infinite across a jump, and
**    halved until it crosses none or is down to the tolerance. So no
**    step leaps over a jump (and the thin solid behind it) that the
**    segment tracer would not, and away from the jumps the steps are
**    plain sphere tracing's.
**  - Segment tracing (Génevaux et al. 2015, section 7.2; Galin et al. 2020): H
** bounds
**    only the growth of f along the candidate segment [t, t + delta],
**    from the nodes whose support the segment crosses (raybound.c); a
**    full step doubles the candidate. The ray is first cut into the
**    intervals where it crosses a support (Paris et al. 2019, section 7):
** outside
**    them f == 0 < T, and no step is spent there.
** Either gives up after OC_TRACE_MAX_STEPS steps (a miss): the minimum
** step grows with the distance, so a ray needs about ln(far / near) / eps_k
** steps at worst, which a scene whose box reaches 1e300 (a huge warp
** amplitude) turns into millions per pixel. Real scenes take hundreds
** (no ray of the 1920 x 1080 benchmark scene took 4096).
*/
#include <math.h>

#include "field/program.h"
#include "field/raybound.h"
#include "render/trace.h"

#define MAX_IV 64
#define GROW 2.0 /* candidate step after a step s: GROW s */

void oc_tracer_init(oc_tracer *tr, const oc_program *prog, double T,
                    oc_render_tracer mode, double eps_k, double eps_min) {
  tr->refine = 1;
  tr->prog = prog;
  tr->T = T;
  tr->L = oc_program_lipschitz(prog);
  tr->jumps = prog->njump > 0;
  tr->mode = mode;
  oc_box_to_float(oc_program_bounds(prog), tr->lo, tr->hi);
  tr->eps_k = eps_k;
  tr->eps_min = eps_min;
}

static inline oc_vec3 at(oc_vec3 o, oc_vec3 u, double t) {
  oc_vec3 p = {o.x + t * u.x, o.y + t * u.y, o.z + t * u.z};
  return p;
}

/* The tolerance at t: steps never go below it, so a ray that grazes the
** surface moves on instead of stopping short of it. A feature thinner
** than this (a fraction of a pixel) may be stepped over. */
static inline double tol(const oc_tracer *tr, double d0, double t) {
  return tr->eps_k * (d0 + t) + tr->eps_min;
}

/* f(a) = fa < T <= f(b) = fb: regula falsi (Illinois variant), down to a
** small fraction of the tolerance, keeping the outside end so that hits
** lie just in front of the surface. */
static double refine(const oc_tracer *tr, oc_vec3 o, oc_vec3 u, double a,
                     double fa, double b, double fb, double d0, double *n) {
  double stop = 1e-3 * tol(tr, d0, a);
  int side = 0;
  fa -= tr->T;
  fb -= tr->T;
  for (int k = 0; k < 24 && b - a > stop; k++) {
    double m = a + (b - a) * (fa / (fa - fb));
    /* stay strictly inside, and halve when the interpolation stalls */
    if (!(m > a && m < b) || k % 4 == 3) m = 0.5 * (a + b);
    double f = oc_program_eval(tr->prog, at(o, u, m)) - tr->T;
    (*n)++;
    if (f < 0) {
      a = m, fa = f;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = m, fb = f;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return a;
}

/* Called with f(t) >= T (or NaN) and f(prev) = fp < T: a hit at t,
** located from prev. */
static int found(const oc_tracer *tr, oc_vec3 o, oc_vec3 u, double prev,
                 double fp, double t, double f, double d0, double *thit,
                 double *n) {
  if (f != f) return 0; /* NaN: no surface can be located */
  *thit = prev < t && tr->refine ? refine(tr, o, u, prev, fp, t, f, d0, n) : t;
  return 1;
}

/* The step s from t, shortened while [t, t + s] crosses a jump of the
** field (an infinite local bound), down to the tolerance e. */
static double off_jumps(const oc_tracer *tr, const oc_ray *r, double t,
                        double s, double e) {
  while (s > e) {
    double lo, hi;
    oc_ray_dbound(tr->prog, r, t, t + s, &lo, &hi);
    if (!isinf(hi)) return s;
    s = fmax(0.5 * s, e);
  }
  return s;
}

static int sphere_trace(const oc_tracer *tr, const oc_ray *r, double t,
                        double t1, double d0, double *thit, double *evals) {
  oc_vec3 o = r->o, u = r->u;
  double prev = t, fp = 0;
  for (long k = 0; t <= t1 && k < OC_TRACE_MAX_STEPS; k++) {
    double f = oc_program_eval(tr->prog, at(o, u, t));
    *evals += 1;
    if (!(f < tr->T)) return found(tr, o, u, prev, fp, t, f, d0, thit, evals);
    if (!(tr->L > 0)) break; /* constant field below T */
    double e = tol(tr, d0, t), s = fmax((tr->T - f) / tr->L, e);
    if (tr->jumps) s = off_jumps(tr, r, t, s, e);
    if (t + s == t) break;
    prev = t, fp = f;
    t += s;
  }
  return 0;
}

/* One support interval [t, b]: returns 1 on a hit. */
static int segment_span(const oc_tracer *tr, const oc_ray *r, double t,
                        double b, double d0, double *thit, double *n,
                        long *steps) {
  double delta = b - t, prev = t, fp = 0;
  for (;;) {
    if (++*steps > OC_TRACE_MAX_STEPS) return 0;
    double f = oc_program_eval(tr->prog, at(r->o, r->u, t));
    (*n)++;
    if (!(f < tr->T)) return found(tr, r->o, r->u, prev, fp, t, f, d0, thit, n);
    double e = fmin(delta, b - t);
    double lo, hi;
    oc_ray_dbound(tr->prog, r, t, t + e, &lo, &hi);
    double s = hi > 0 ? fmin((tr->T - f) / hi, e) : e;
    s = fmax(s, tol(tr, d0, t));
    if (t + s >= b || t + s == t) return 0; /* left the support */
    prev = t, fp = f;
    t += s;
    delta = GROW * s;
  }
}

int oc_trace(const oc_tracer *tr, oc_vec3 o, oc_vec3 u, double t0, double t1,
             double d0, double *t, double *evals) {
  oc_ray r = oc_ray_make(o, u);
  double start = t0;
  *t = INFINITY;
  if (!oc_ray_clip(&r, tr->lo, tr->hi, &t0, &t1)) {
    /* outside the scene's box f == 0: a surface only when 0 >= T */
    if (tr->T > 0) return 0;
    *evals += 1;
    *t = start;
    return 1;
  }
  if (tr->mode == OC_TRACE_SPHERE || tr->T <= 0) {
    if (sphere_trace(tr, &r, t0, t1, d0, t, evals)) return 1;
    *t = INFINITY;
    return 0;
  }
  oc_zspan iv[MAX_IV];
  int n = oc_ray_supports(tr->prog, &r, t0, t1, iv, MAX_IV);
  long steps = 0;
  for (int k = 0; k < n; k++)
    if (segment_span(tr, &r, iv[k].lo, iv[k].hi, d0, t, evals, &steps))
      return 1;
  *t = INFINITY;
  return 0;
}
