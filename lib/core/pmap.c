/*
** pmap.c — pointer to index map (see pmap.h).
**
** The capacity is a power of two kept at least twice the count, so a
** probe ends at a free slot; the hash mixes the address bits (allocators
** align, so the low bits alone would collide).
*/
#include <stdint.h>
#include <stdlib.h>

#include "core/pmap.h"

static size_t phash(const void *p) {
  uint64_t x = (uint64_t)(uintptr_t)p;
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  return (size_t)x;
}

static int rehash(oc_pmap *m) {
  if (m->cap > SIZE_MAX / 2 / sizeof *m->key) return 0;
  size_t nc = m->cap ? m->cap * 2 : 64;
  const void **nk = calloc(nc, sizeof *nk);
  uint32_t *nv = malloc(nc * sizeof *nv);
  if (!nk || !nv) {
    free(nk);
    free(nv);
    return 0;
  }
  for (size_t i = 0; i < m->cap; i++)
    if (m->key[i]) {
      size_t h = phash(m->key[i]) & (nc - 1);
      while (nk[h])
        h = (h + 1) & (nc - 1);
      nk[h] = m->key[i];
      nv[h] = m->val[i];
    }
  free(m->key);
  free(m->val);
  m->key = nk;
  m->val = nv;
  m->cap = nc;
  return 1;
}

uint32_t *oc_pmap_slot(oc_pmap *m, const void *k, int create) {
  if (create && (m->n + 1) * 2 > m->cap && !rehash(m)) return NULL;
  if (!m->cap) return NULL;
  size_t h = phash(k) & (m->cap - 1);
  while (m->key[h]) {
    if (m->key[h] == k) return &m->val[h];
    h = (h + 1) & (m->cap - 1);
  }
  if (!create) return NULL;
  m->key[h] = k;
  m->n++;
  return &m->val[h];
}

void oc_pmap_free(oc_pmap *m) {
  free(m->key);
  free(m->val);
  m->key = NULL;
  m->val = NULL;
  m->cap = m->n = 0;
}
