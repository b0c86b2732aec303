/*
** kvlist.h — a short list of owned key/value strings in the order first
** set: the metadata of images and meshes (provenance), one implementation.
*/
#ifndef OC_KVLIST_H
#define OC_KVLIST_H

#include <stddef.h>

#include "outcrop.h"

typedef struct oc_kv {
  char *key, *value;
} oc_kv;

typedef struct oc_kvlist {
  oc_kv *v;
  size_t n, cap;
} oc_kvlist; /* all zero: empty */

/* Sets key to a copy of value, replacing the value of an equal key
** (strcasecmp when nocase, else strcmp) in place; a new key goes last,
** refused once the list holds `max`. On failure nothing changes. The
** caller has checked key and value. */
int oc_kvlist_set(oc_kvlist *l, const char *key, const char *value, int nocase,
                  size_t max, oc_error *err);

/* The value of key, or NULL. */
const char *oc_kvlist_get(const oc_kvlist *l, const char *key, int nocase);

void oc_kvlist_free(oc_kvlist *l);

#endif
