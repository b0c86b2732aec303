/*
** trace.h — finding where a ray first meets the surface f = T (internal):
** plain sphere tracing with the global Lipschitz bound, and segment
** tracing with local directional bounds and empty-space skipping.
*/
#ifndef OC_TRACE_H
#define OC_TRACE_H

#include "outcrop.h"

/* Steps one ray may take before it counts as a miss (see trace.c). */
#define OC_TRACE_MAX_STEPS 16384

typedef struct oc_tracer {
  const oc_program *prog;
  double T;  /* iso-value */
  double L;  /* global Lipschitz bound (off the field's jumps) */
  int jumps; /* the field jumps somewhere: sphere steps avoid the jumps */
  oc_render_tracer mode;
  float lo[3], hi[3]; /* the scene's box, rounded outwards */
  /* Steps are at least eps = eps_k * (distance from the eye) + eps_min,
  ** a fraction of the pixel's footprint: a hit is a sample with f >= T,
  ** then located by bisection. */
  double eps_k, eps_min;
  int refine; /* 1: locate hits by bisection (0 for shadow rays) */
} oc_tracer;

void oc_tracer_init(oc_tracer *tr, const oc_program *prog, double T,
                    oc_render_tracer mode, double eps_k, double eps_min);

/* Traces o + t u (u unit) over [t0, t1]; d0 is the distance of o from the
** eye (for the tolerance). Returns 1 and the distance in *t on a hit, 0 on
** a miss (or after OC_TRACE_MAX_STEPS steps); adds the field evaluations made
*to *evals. Allocation-free. */
int oc_trace(const oc_tracer *tr, oc_vec3 o, oc_vec3 u, double t0, double t1,
             double d0, double *t, double *evals);

#endif
