/*
** pmap.h — a map from pointers to 32-bit indices (open addressing,
** linear probing), for the compiler's memo of compiled nodes and its
** walks over node DAGs. A zero-initialised pmap is empty.
*/
#ifndef OC_PMAP_H
#define OC_PMAP_H

#include <stddef.h>
#include <stdint.h>

typedef struct oc_pmap {
  const void **key; /* NULL: a free slot */
  uint32_t *val;
  size_t cap, n;
} oc_pmap;

/* The value slot of key k (not NULL), or NULL when k is absent; with
** create, an absent k is added (its value left undefined) and NULL means
** out of memory. Slots move when the map grows: a slot is good until
** the next call with create. */
uint32_t *oc_pmap_slot(oc_pmap *m, const void *k, int create);

void oc_pmap_free(oc_pmap *m);

#endif
