/*
** grow.h — growable arrays: a pointer, a count kept by the caller and a
** capacity that doubles, in checked arithmetic.
*/
#ifndef OC_GROW_H
#define OC_GROW_H

#include <stddef.h>

/* Makes the array *arrp (elements of elem bytes, capacity *cap) hold at
** least need elements: the capacity doubles from *cap, or from first when
** *cap is 0, until it does. Returns 0, or -1 when memory runs out or the
** size overflows (then *arrp and *cap are unchanged). */
int oc_grow(void *arrp, size_t *cap, size_t need, size_t elem, size_t first);

/* OC_GROW's slow path: need = n + more, checked. */
int oc_grow_more(void *arrp, size_t *cap, size_t n, size_t more, size_t elem);

static inline int oc_grow_room(void *arrp, size_t *cap, size_t n, size_t more,
                               size_t elem) {
  if (more <= *cap && n <= *cap - more) return 1;
  return oc_grow_more(arrp, cap, n, more, elem) == 0;
}

/* 1 when arr (n elements used, capacity cap, a size_t) has room for more
** elements, growing it (from 16) if needed; 0 when out of memory. */
#define OC_GROW(arr, n, cap, more)                                             \
  oc_grow_room((void *)&(arr), &(cap), (n), (more), sizeof *(arr))

#endif
