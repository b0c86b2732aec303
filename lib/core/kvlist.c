/*
** kvlist.c — owned key/value strings (see kvlist.h).
*/
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/kvlist.h"

static char *dupstr(const char *s) {
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

static int same(const char *a, const char *b, int nocase) {
  return (nocase ? strcasecmp(a, b) : strcmp(a, b)) == 0;
}

int oc_kvlist_set(oc_kvlist *l, const char *key, const char *value, int nocase,
                  size_t max, oc_error *err) {
  char *v = dupstr(value);
  if (!v)
    return oc_seterr(err, OC_ENOMEM, "out of memory for metadata '%s'", key);
  for (size_t i = 0; i < l->n; i++)
    if (same(l->v[i].key, key, nocase)) {
      free(l->v[i].value);
      l->v[i].value = v;
      return OC_OK;
    }
  if (l->n >= max) {
    free(v);
    return oc_seterr(err, OC_EINVAL, "too many metadata entries (limit %zu)",
                     max);
  }
  if (l->n == l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 8;
    oc_kv *m = realloc(l->v, cap * sizeof *m);
    if (!m) {
      free(v);
      return oc_seterr(err, OC_ENOMEM, "out of memory for metadata '%s'", key);
    }
    l->v = m;
    l->cap = cap;
  }
  char *k = dupstr(key);
  if (!k) {
    free(v);
    return oc_seterr(err, OC_ENOMEM, "out of memory for metadata '%s'", key);
  }
  l->v[l->n].key = k;
  l->v[l->n].value = v;
  l->n++;
  return OC_OK;
}

const char *oc_kvlist_get(const oc_kvlist *l, const char *key, int nocase) {
  for (size_t i = 0; i < l->n; i++)
    if (same(l->v[i].key, key, nocase)) return l->v[i].value;
  return NULL;
}

void oc_kvlist_free(oc_kvlist *l) {
  for (size_t i = 0; i < l->n; i++) {
    free(l->v[i].key);
    free(l->v[i].value);
  }
  free(l->v);
  l->v = NULL;
  l->n = l->cap = 0;
}
