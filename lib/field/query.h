/*
** query.h — the column queries of query.c (internal): the z-spans where
** a column's field may vary, and whether a single heightfield-like op
** governs the column's footprint alone (hfsurf.h has its surface).
*/
#ifndef OC_QUERY_H
#define OC_QUERY_H

#include <stdint.h>

#include "field/program.h"

/* oc_program_column_spans, and in *hf the op that alone makes the field
** over the footprint (every other op is 0 there, and it is reached
** through blends and unions only, so f is its value), when that op is
** heightfield-like in all the footprint; OC_NONE otherwise. */
int oc_program_column_query(const oc_program *P, double x0, double y0,
                            double x1, double y1, oc_zspan *out, int max,
                            uint32_t *hf);
/* The same, and in zout (*nz of them, at most max; -1 with the whole
** column) the z-spans outside which the field is constant along every
** column of the footprint: those are the samples a column must evaluate
** one by one. A subset of the spans' union: near a terrain's walls the
** field varies across the footprint at every z, but along a column only
** near the floor and the surface. */
int oc_program_column_query_z(const oc_program *P, double x0, double y0,
                              double x1, double y1, oc_zspan *out, int max,
                              uint32_t *hf, oc_zspan *zout, int *nz);

#endif
