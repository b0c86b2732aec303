/*
** error.h — filling an oc_error (which may be NULL) printf-style.
*/
#ifndef OC_ERROR_H
#define OC_ERROR_H

#include "outcrop.h"

#if defined(__GNUC__)
#define OC_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define OC_PRINTF(a, b)
#endif

/* Sets err (when not NULL) and returns code, so callers can
** `return oc_seterr(err, OC_EINVAL, "...")`. */
int oc_seterr(oc_error *err, oc_status code, const char *fmt, ...)
    OC_PRINTF(3, 4);
void oc_clearerr(oc_error *err);

/* x as the front ends print numbers in messages ("%.14g", and ".0" after
** a whole number: 2.0, 0.25, 1e+20, inf), so that a message made here
** reads as one made by the Lua bindings. Returns buf. */
#define OC_NUMSTR 48
const char *oc_numstr(double x, char buf[OC_NUMSTR]);

#endif
