/*
** error.c — error reporting into caller-provided buffers (no global state).
*/
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

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

const char *oc_numstr(double x, char buf[OC_NUMSTR]) {
  int n = snprintf(buf, OC_NUMSTR, "%.14g", x);
  if (n > 0 && n < OC_NUMSTR - 2 && buf[strspn(buf, "-0123456789")] == '\0') {
    buf[n] = '.', buf[n + 1] = '0', buf[n + 2] = '\0';
  }
  return buf;
}
