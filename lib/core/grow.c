/*
** grow.c — growable arrays (see grow.h).
*/
#include <stdint.h>
#include <stdlib.h>

#include "core/checked.h"
#include "core/grow.h"

int oc_grow(void *arrp, size_t *cap, size_t need, size_t elem, size_t first) {
  if (need <= *cap) return 0;
  size_t c = *cap ? *cap : first ? first : 1, bytes;
  while (c < need) {
    if (c > SIZE_MAX / 2) return -1;
    c *= 2;
  }
  if (!oc_mul_size(c, elem, &bytes)) return -1;
  void *p = realloc(*(void **)arrp, bytes);
  if (!p) return -1;
  *(void **)arrp = p;
  *cap = c;
  return 0;
}

int oc_grow_more(void *arrp, size_t *cap, size_t n, size_t more, size_t elem) {
  size_t need;
  if (!oc_add_size(n, more, &need)) return -1;
  return oc_grow(arrp, cap, need, elem, 16);
}
