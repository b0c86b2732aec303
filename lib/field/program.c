/*
** program.c — what a compiled program answers without evaluating: its
** bounds, Lipschitz bound, threshold and statistics; and its release
** (the program is built by compile.c, see program.h).
*/
#include <stdlib.h>

#include "field/node.h"
#include "field/program.h"

void oc_program_free(oc_program *P) {
  if (!P) return;
  free(P->ops);
  free(P->par);
  free(P->kids);
  free(P->ent);
  free(P->bvh);
  free(P->ext);
  oc_node_release(P->node);
  free(P);
}

oc_aabb oc_program_bounds(const oc_program *P) {
  return P->bounds;
}
double oc_program_lipschitz(const oc_program *P) {
  return P->lip;
}
double oc_program_threshold(const oc_program *P) {
  return P->T;
}
void oc_program_get_stats(const oc_program *P, oc_program_stats *st) {
  *st = P->stats;
}
