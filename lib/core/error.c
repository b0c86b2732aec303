/*
** error.c — error reporting into caller-provided buffers (no global state).
*/
#include <stdarg.h>
#include <stdio.h>

#include "core/error.h"

int oc_seterr(oc_error *err, oc_status code, const char *fmt, ...) {
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    err->code = code;
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
  }
  return (int)code;
}

void oc_clearerr(oc_error *err) {
  if (err) {
    err->code = OC_OK;
    err->msg[0] = '\0';
  }
}
