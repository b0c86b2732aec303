/*
** etrace.h — finding where a ray first meets an elevation surface
** z = f(x, y) (internal): the accelerated tracer of Génevaux et al. 2015,
** section 7.2 (local slope bounds on the ray's segment, a doubling
** candidate step, elevation ranges to skip empty space) and the
** global-bound sphere tracing it is measured against.
*/
#ifndef OC_ETRACE_H
#define OC_ETRACE_H

#include "outcrop.h"

/* oc_esurface, what the renderer traces, is in outcrop.h. */

typedef struct oc_etracer {
  const oc_esurface *s;
  oc_render_tracer mode;
  double lo[3], hi[3]; /* the domain x [min f, max f], padded */
  double L;            /* slope bound over the whole domain */
  /* Steps are at least eps = eps_k * (distance from the eye) + eps_min, as
  ** the 3D tracers' (trace.h); a hit is the first sample below the
  ** surface, then located to OC_ETRACE_REFINE_STOP of eps. */
  double eps_k, eps_min;
  int refine; /* 1: locate hits (0 for shadow rays) */
} oc_etracer;

/* A hit is located to this fraction of the tolerance along the ray
** (etrace.c, where it was measured). */
#define OC_ETRACE_REFINE_STOP 5e-2

void oc_etracer_init(oc_etracer *tr, const oc_esurface *s,
                     oc_render_tracer mode, double eps_k, double eps_min);

/* Traces o + t u (u unit) over [t0, t1]; d0 is the distance of o from the
** eye. Returns 1 and the distance in *t on a hit of the surface, 2 on a
** hit of a wall (the ray entered the solid under the surface through a
** side of the domain's box or of a hole), 0 on a miss (or after
** OC_TRACE_MAX_STEPS steps); adds the height calls made to *evals.
** Allocation-free. */
/* [t0, t1] clipped to the box [lo, hi] (a tracer's, or a union of
** tracers'); 0 when the ray o + t u misses it there. */
int oc_etrace_clip(const double lo[3], const double hi[3], oc_vec3 o, oc_vec3 u,
                   double *t0, double *t1);

int oc_etrace(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t0, double t1,
              double d0, double *t, double *evals);

/* A first-order model of the height around (x, y) (oc_elevation's
** taylor, radius R): |f(q) - f - g.(q - (x, y))| <= E[0] + E[1] r + E[2]
** r^2 for r = |q - (x, y)| <= R. ok 0: none. */
typedef struct oc_emodel {
  int ok;
  double x, y, f, R, g[2], E[3];
} oc_emodel;

/* oc_etrace from t0, where the ray is known free of the surface, with
** step (> 0) the candidate step to begin with on the source's models (0:
** as oc_etrace), that also gives, on a hit of the surface (1), the unit
** upward normal there in *n (NULL: not wanted), from the height gradient
** of the refinement's last sample above the surface, where the hit is;
** where the model of the sample under the surface located the hit alone,
** that model's linear part (the gradient at that sample, a tenth of
** a tolerance or so past the hit) when the model is quadratic there, else
** a sample at the hit (one call); one more height call, counted in
** *evals, when no sample gave it. m
** (when not NULL and ok, with step > 0): a model the ray's first step
** may take without a call (its beam's last, oc_etrace_beam). */
int oc_etrace_hit(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t0,
                  double t1, double d0, double step, const oc_emodel *m,
                  double *t, oc_vec3 *n, double *evals);

/* A beam: the rays o + d (w + x r + y v) for (x, y) in [x0, x1] x
** [y0, y1] and depth d >= 0 (w, r, v the camera's orthonormal frame, so
** that |w + x r + y v| >= 1). */
typedef struct oc_ebeam {
  oc_vec3 o, w, r, v;
  double x0, x1, y0, y1;
} oc_ebeam;

/* The depth up to which every ray of the beam is proved free of the
** surface, from d on: beam tracing (cone marching) with the source's
** elevation ranges on the boxes of frustum pieces, no height call made;
** then, for a source with first-order models (and when evals is not
** NULL), on models queried on the beam's axis with a margin for its
** width (etrace.c, beam_models), each query a height call added to
** *evals. INFINITY when every ray leaves the domain, or passes depth
** dmax, unhit. *bounds (when not NULL) counts the range queries. *next
** (when not NULL): on entry a candidate step (in depth) to begin with, 0
** for the default (a part of a beam passes its beam's: with a model in
** *m, the part turns to models where its first range query fails); on
** return the candidate for the rays' march on models from there, 0 when
** the beam made no model step. *m (when not NULL): on entry a model the beam's
** first step on models may take without a call (its enclosing beam's
** last), on return the last model the beam queried (unchanged when it
** queried none). */
double oc_etrace_beam(const oc_etracer *tr, const oc_ebeam *b, double d,
                      double dmax, double *bounds, double *evals, double *next,
                      oc_emodel *m);

/* The outward normal of the wall hit at p by a ray along u: the nearest
** face of the box, or -u for a hole's wall. */
oc_vec3 oc_etracer_wall(const oc_etracer *tr, oc_vec3 p, oc_vec3 u);

#endif
