/*
** mcwork.c — the slab mesher's scratch: growable arrays, per-column range
** lists, and the per-thread work area.
*/
#include <stdlib.h>
#include <string.h>

#include "mesh/mcwork.h"

int oc_mc_rlist_columns(oc_mc_rlist *l, size_t ncol) {
  if (oc_mc_grow(&l->at, &l->capat, ncol + 1, sizeof *l->at)) return -1;
  l->at[0] = 0;
  l->n = 0;
  return 0;
}

int oc_mc_rlist_add(oc_mc_rlist *l, size_t first, int32_t lo, int32_t hi) {
  if (lo > hi) return 0;
  if (l->n > first && lo <= l->r[l->n - 1].hi + 1) {
    if (hi > l->r[l->n - 1].hi) l->r[l->n - 1].hi = hi;
    return 0;
  }
  if (oc_mc_grow(&l->r, &l->cap, l->n + 1, sizeof *l->r)) return -1;
  l->r[l->n].lo = lo;
  l->r[l->n].hi = hi;
  l->n++;
  return 0;
}

oc_mcwork *oc_mcwork_new(void) {
  return calloc(1, sizeof(oc_mcwork));
}

static void rlist_free(oc_mc_rlist *l) {
  free(l->r);
  free(l->at);
}

void oc_mcwork_free(oc_mcwork *w) {
  if (!w) return;
  rlist_free(&w->cube);
  rlist_free(&w->kept);
  rlist_free(&w->var);
  rlist_free(&w->cull);
  free(w->sr);
  free(w->srat);
  free(w->val);
  free(w->slot);
  free(w->tmp);
  free(w->flat);
  free(w->dsurf);
  free(w->delev);
  free(w->esurf);
  free(w->bsurf);
  free(w);
}

void oc_mcout_clear(oc_mcout *o) {
  free(o->pos);
  free(o->nrm);
  free(o->tri);
  free(o->key);
  free(o->kidx);
  memset(o, 0, sizeof *o);
}

void oc_mcout_reset(oc_mcout *o) {
  o->nv = o->nt = o->nk = o->nb = 0;
  o->calls = o->cells = 0;
}

void oc_mc_sort_ranges(oc_mc_irange *t, size_t n) {
  for (size_t i = 1; i < n; i++) {
    oc_mc_irange x = t[i];
    size_t j = i;
    while (j > 0 && t[j - 1].lo > x.lo) {
      t[j] = t[j - 1];
      j--;
    }
    t[j] = x;
  }
}
